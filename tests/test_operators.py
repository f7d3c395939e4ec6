import numpy as np
import pytest
from scipy.sparse.linalg import LinearOperator

import hmatddm as hd


def t_junction_2d():
    """A segment ends exactly on another element's collocation point (ref. Fig. 6.5)."""
    main = hd.mesh.line([-1, 0], [1, 0], 4)            # centres at -0.75, -0.25, 0.25, 0.75
    branch = hd.mesh.line([0.25, 0], [0.25, 1], 4, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


def t_junction_3d():
    main = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 2.0, 4, 2)  # centres x = +-0.5, +-1.5
    branch = hd.mesh.rectangle([0.5, 0, 1.0], [0, 1, 0], [0, 0, 1], 2.0, 2.0, 2, 2, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


def test_dense_operator_is_a_linear_operator(material):
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 1.0, 4, 2)
    op = hd.ElasticityOperator(mesh, material, backend="dense")
    assert isinstance(op, LinearOperator)
    assert op.shape == (24, 24)
    x = np.random.default_rng(0).normal(size=24)
    A = op.to_dense()
    assert np.allclose(op @ x, A @ x) and np.allclose(op.matvec(x), A @ x)
    assert np.allclose(op.matmat(np.eye(24)[:, :3]), A[:, :3])
    assert np.allclose(op.exact_block(np.array([1, 2]), np.array([0, 5])), A[3:9][:, np.r_[0:3, 15:18]])
    for key in ("memory_bytes", "dense_bytes", "compression", "build_seconds", "n_admissible",
                "n_dense_blocks", "max_rank", "eps", "eta", "leaf_size"):
        assert key in op.stats
    assert op.check_against_dense() == 0.0


@pytest.mark.parametrize("kwargs, message", [
    (dict(backend="sparse"), "backend must be one of"),
    (dict(eps=0.0), r"eps must be in \(0, 1\)"),
    (dict(eps=1.5), r"eps must be in \(0, 1\)"),
    (dict(eta=-1.0), "eta must be > 0"),
    (dict(leaf_size=0), "leaf_size must be an integer >= 1"),
    (dict(singular_correction="ignore"), "singular_correction must be one of"),
    (dict(alpha=0.5), "alpha must be >= 1"),
])
def test_bad_operator_arguments_are_refused(material, kwargs, message):
    mesh = hd.mesh.line([0, 0], [1, 0], 4)
    with pytest.raises(hd.InputError, match=message):
        hd.ElasticityOperator(mesh, material, **kwargs)


def test_bad_solve_arguments_are_refused(material):
    mesh = hd.mesh.line([0, 0], [1, 0], 4)
    op = hd.ElasticityOperator(mesh, material)
    with pytest.raises(hd.InputError, match=r"traction must have shape \(4, 2\) or \(8,\)"):
        hd.solve(op, np.ones(5))
    with pytest.raises(hd.InputError, match="traction must contain only finite"):
        hd.solve(op, np.full(8, np.nan))
    with pytest.raises(hd.InputError, match=r"rtol must be in \(0, 1\)"):
        hd.solve(op, np.ones(8), rtol=0.0)
    with pytest.raises(hd.InputError, match="operator must be an ElasticityOperator"):
        hd.solve(np.eye(8), np.ones(8))


@pytest.mark.parametrize("make_mesh", [t_junction_2d, t_junction_3d])
def test_singular_intersections_are_refused_by_default(material, make_mesh):
    with pytest.raises(hd.InputError, match="singular_correction='average'"):
        hd.ElasticityOperator(make_mesh(), material)


@pytest.mark.parametrize("make_mesh", [t_junction_2d, t_junction_3d])
def test_reference_correction_makes_intersections_solvable(material, make_mesh):
    """NaN averaging plus alpha scaling (ref. Sec. 6.2.3, Eq. 6.11)."""
    mesh = make_mesh()
    averaged = hd.ElasticityOperator(mesh, material, singular_correction="average")
    scaled = hd.ElasticityOperator(mesh, material, singular_correction="average", alpha=1.0)
    A, B = averaged.to_dense(), scaled.to_dense()
    assert np.all(np.isfinite(A)) and np.all(np.isfinite(B))
    d = mesh.dim
    self_max = np.array([np.abs(B[d * j:d * j + d, d * j:d * j + d]).max() for j in range(mesh.n_elements)])
    blocks = np.abs(B).reshape(mesh.n_elements, d, mesh.n_elements, d).max(axis=(1, 3))
    assert np.all(blocks <= self_max[None, :] * (1 + 1e-12))  # no block exceeds its column's self block
    assert np.array_equal(np.diag(blocks), self_max)  # self blocks untouched
    dd = hd.solve(scaled, -1e6 * mesh.normals)
    w = hd.opening(mesh, dd)
    assert np.all(np.isfinite(w)) and np.all(w > 0)


def test_stress_at_refuses_points_on_edges(material):
    mesh = hd.mesh.line([-1, 0], [1, 0], 2)
    dd = np.tile([0.0, 1e-4], (2, 1))
    with pytest.raises(hd.InputError, match=r"points\[1\] lies on an element edge"):
        hd.stress_at(mesh, material, dd, [[0.0, 1.0], [1.0, 0.0]])
    with pytest.raises(hd.InputError, match="singular_correction must be one of"):
        hd.stress_at(mesh, material, dd, [[0.0, 1.0]], singular_correction="ignore")
    assert np.all(np.isfinite(hd.stress_at(mesh, material, dd, [[1.0, 0.0]], singular_correction="average")))
    with pytest.raises(hd.InputError, match=r"points must have shape \(N, 2\)"):
        hd.stress_at(mesh, material, dd, [[0.0, 1.0, 2.0]])
