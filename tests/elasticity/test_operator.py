import warnings

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


# --------------------------------------------------------------- near-miss junctions
def near_miss_2d(gap):
    """t_junction_2d with the branch starting ``gap`` (m) above the main crack's centre
    at x = 0.25 (negative: crossing it); main half length 0.25, branch ~0.125."""
    main = hd.mesh.line([-1, 0], [1, 0], 4)
    branch = hd.mesh.line([0.25, gap], [0.25, 1], 4, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


def near_miss_3d(gap):
    """t_junction_3d with the branch's bottom edge ``gap`` (m) above the main crack's
    centres at x = 0.5 (half sizes 0.5 both)."""
    main = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 2.0, 4, 2)
    branch = hd.mesh.rectangle([0.5, 0, 1.0 + gap], [0, 1, 0], [0, 0, 1], 2.0, 2.0, 2, 2, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


@pytest.mark.parametrize("make_mesh, gap, pair", [(near_miss_2d, 1e-7, (2, 4)), (near_miss_2d, -1e-7, (2, 4)),
                                                  (near_miss_2d, 0.05, (2, 4)), (near_miss_3d, 1e-7, (4, 8)),
                                                  (near_miss_3d, -0.2, (4, 8))])
@pytest.mark.parametrize("backend", ["dense", "hmatrix"])
def test_near_miss_junctions_are_refused_by_name(material, make_mesh, gap, pair, backend):
    """A collocation point closer than NEAR_SINGULAR_FRACTION half sizes to another
    element's edge is refused like an exact hit, naming the pair, the gap and the fixes."""
    i, j = pair
    pattern = (rf"element {i} \(fracture 0\) has its centre {abs(gap):.3g} m \(.* of the smaller half size\) "
               rf"from an edge of element {j} \(fracture 1\).*singular_correction='average'.*split_at_intersections")
    with pytest.raises(hd.InputError, match=pattern):
        hd.ElasticityOperator(make_mesh(gap), material, backend=backend, leaf_size=2)


def test_near_singular_distance_is_a_fraction_of_the_smaller_half_size(material):
    """Refused just inside NEAR_SINGULAR_FRACTION x min(receiver, source half size),
    the plain kernel just outside; the receiver's size counts too, so a conforming
    mesh with neighbours 1000 x apart is never affected."""
    fraction = hd.operators.NEAR_SINGULAR_FRACTION
    assert fraction == 0.5
    source_half = lambda gap: (1.0 - gap) / 8  # noqa: E731  (branch half length, the smaller)
    inside, outside = (c / (1 + c) for c in (0.98 * fraction / 8, 1.02 * fraction / 8))  # gap = c (1 - gap)
    assert inside < fraction * source_half(inside) and outside > fraction * source_half(outside)
    with pytest.raises(hd.InputError, match="of the smaller half size"):
        hd.ElasticityOperator(near_miss_2d(inside), material)
    mesh = near_miss_2d(outside)
    op = hd.ElasticityOperator(mesh, material)
    out, work = np.empty((2, 2)), np.empty((2, 2, 2))
    hd.kernels.line2d.traction_pair(mesh.centers[2], mesh.normals[2], mesh.centers[4], mesh.frames[4],
                                    mesh.half_length[4], material.shear_modulus, material.poisson_ratio, 0.0,
                                    out, work)  # the plain kernel, near = 0
    np.testing.assert_array_equal(op.exact_block([2], [4]), out)
    assert np.abs(out).max() > np.abs(op.exact_block([2], [2])).max()  # larger than the self term (1.7 x)
    nodes = np.array([-1.0, 0.0, 1e-3, 1.0])
    graded = hd.Mesh2D.from_segments(np.column_stack([nodes[:-1], 0 * nodes[:-1]]),
                                     np.column_stack([nodes[1:], 0 * nodes[1:]]))
    assert np.all(np.isfinite(hd.ElasticityOperator(graded, material).to_dense()))


@pytest.mark.parametrize("make_mesh, touching", [(near_miss_2d, t_junction_2d), (near_miss_3d, t_junction_3d)])
@pytest.mark.parametrize("alpha", [None, 1.0])
def test_averaged_near_miss_is_the_touching_junction(material, make_mesh, touching, alpha):
    """With "average" a near miss gets the entries of the exact junction (the point is
    moved onto the edge), in both backends: the near-field blocks are equal bit for bit,
    and the whole matrix equals the touching mesh's up to the O(gap) change of geometry."""
    mesh = make_mesh(1e-9)
    dense = hd.ElasticityOperator(mesh, material, singular_correction="average", alpha=alpha)
    hmat = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=1e-8, leaf_size=2,
                                 singular_correction="average", alpha=alpha)
    assert hmat.stats["n_admissible"] > 0
    A, H = dense.to_dense(), hmat.to_dense()
    assert np.all(np.isfinite(A))
    receivers, sources = hd.operators.singular_pairs(mesh, hd.operators.influence_data(mesh, material))
    assert len(receivers) > 0
    d = mesh.dim
    for i, j in zip(receivers, sources):
        np.testing.assert_array_equal(H[d * i:d * i + d, d * j:d * j + d], A[d * i:d * i + d, d * j:d * j + d])
    assert np.abs(H - A).max() < 1e-6 * np.abs(A).max()
    reference = hd.ElasticityOperator(touching(), material, singular_correction="average", alpha=alpha).to_dense()
    np.testing.assert_allclose(A, reference, rtol=0, atol=1e-6 * np.abs(reference).max())


# ------------------------------------------------------------ close parallel cracks
def parallel_lines(spacing, n=20, m=21):
    """Two parallel 2 m cracks (n and m elements: misaligned meshes) ``spacing`` apart."""
    return hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], n),
                                hd.mesh.line([-1, spacing], [1, spacing], m, fracture_id=1)])


@pytest.mark.parametrize("backend", ["dense", "hmatrix"])
def test_close_parallel_cracks_warn_when_the_operator_is_built(material, backend):
    with pytest.warns(hd.errors.MeshQualityWarning, match=r"fracture 0\) and \d+ \(fracture 1\)"):
        hd.ElasticityOperator(parallel_lines(0.05), material, backend=backend)
    with warnings.catch_warnings():
        warnings.simplefilter("error", hd.errors.MeshQualityWarning)
        hd.ElasticityOperator(parallel_lines(0.3), material, backend=backend)
        hd.ElasticityOperator(hd.mesh.line([-1, 0], [1, 0], 20), material, backend=backend)


def test_the_warned_spacing_is_where_openings_go_negative(material):
    """Independent check of the bound: misaligned parallel cracks (20 and 21 elements,
    L/h = 20, bound 1.27 h) solved densely. Below h the openings go negative (measured
    down to -0.95 x max), which the check flags; from 1.5 h on they are positive."""
    h = 0.1
    for ratio in (0.5, 0.8, 1.0, 1.5, 2.0):
        mesh = parallel_lines(ratio * h)
        flagged = len(hd.mesh.close_parallel_pairs(mesh).first) > 0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", hd.errors.MeshQualityWarning)
            w = hd.opening(mesh, hd.solve(hd.ElasticityOperator(mesh, material), -1e6 * mesh.normals))
        assert flagged == (ratio < 1.27)
        if ratio <= 1.0:
            assert w.min() < 0  # wrong: what the warning is about
        else:
            assert w.min() > 0


def test_coincident_or_overlapping_elements_of_one_plane_are_refused():
    # a centre inside another element of the same plane makes the matrix singular to round-off
    # (the property test found two 77 km x 2 m squares 3 m apart: a zero pivot, then NaN);
    # elements that only touch, or overlap from parallel planes, are accepted
    mat = hd.Elastic(10e9, 0.25)
    e1, e2 = np.tile([1.0, 0, 0], (2, 1)), np.tile([0.0, 1, 0], (2, 1))
    centers = np.array([[0.0, 0, 0], [3.0, 0, 0]])
    for half_a, kind in ((np.full(2, 38528.0), "overlap"), (np.full(2, 1.5), None)):
        mesh = hd.Mesh3D.from_rectangles(centers, e1, e2, half_a, np.ones(2))
        if kind is None:
            hd.ElasticityOperator(mesh, mat, backend="dense")
        else:
            with pytest.raises(hd.InputError, match=r"elements 0 and 1 overlap \(the centre of element 1"):
                hd.ElasticityOperator(mesh, mat, backend="dense")
    same = hd.Mesh3D.from_rectangles(np.zeros((2, 3)), e1, e2, np.ones(2), np.ones(2))
    with pytest.raises(hd.InputError, match="elements 0 and 1 coincide"):
        hd.ElasticityOperator(same, mat, backend="dense")
    parallel = hd.Mesh3D.from_rectangles(np.array([[0.0, 0, 0], [0.5, 0, 0.5]]), e1, e2, np.ones(2), np.ones(2))
    hd.ElasticityOperator(parallel, mat, backend="dense")
    segments = hd.Mesh2D.from_segments(np.array([[-2.0, 0.0], [0.5, 0.0]]), np.array([[2.0, 0.0], [1.5, 0.0]]))
    with pytest.raises(hd.InputError, match="elements 0 and 1 overlap"):
        hd.ElasticityOperator(segments, mat, backend="dense")
