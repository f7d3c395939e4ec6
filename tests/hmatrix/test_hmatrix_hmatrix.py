"""HMatrix build, matvec and checks against the dense twin (docs/conventions.md §7).

Every compressed result is compared with the exact matrix: sampled entries of EACH
admissible block, matvecs on random vectors, and the full matrix for small N.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hmatddm.errors import InputError
from hmatddm.hmatrix import BlockGenerator, HMatrix
from hmatddm.hmatrix.example_kernels import (inverse_distance_generator, inverse_distance_kernel,
                                             matrix_generator, tensor_generator)


def cube(n, seed=0):
    return np.random.default_rng(seed).random((n, 3))


def plane(n, seed=0):
    points = np.random.default_rng(seed).random((n, 3))
    points[:, 2] = 0.0
    return points


def tilted_plane(n, seed=0):
    e1 = np.array([1.0, 0.0, 0.3])
    e1 /= np.linalg.norm(e1)
    e2 = np.array([0.2, 1.0, 0.5])
    e2 -= (e2 @ e1) * e1
    e2 /= np.linalg.norm(e2)
    uv = np.random.default_rng(seed).random((n, 2))
    return uv[:, :1] * e1 + uv[:, 1:] * e2


@pytest.fixture(scope="module")
def scalar_problems():
    """1/r on 3000 random points in a cube and on a plane, with their dense twins."""
    problems = {}
    for name, points in (("cube", cube(3000)), ("plane", plane(3000))):
        generator = inverse_distance_generator(points, diagonal=50.0)
        problems[name] = (generator, generator.to_dense())
    return problems


def relative(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


# ----------------------------------------------------------------------------- scalar kernel


@pytest.mark.parametrize("name", ["cube", "plane"])
@pytest.mark.parametrize("eps", [1e-3, 1e-6])
def test_scalar_matvec_and_blocks_within_eps(scalar_problems, name, eps):
    generator, dense = scalar_problems[name]
    h = HMatrix.build(generator, eps=eps, leaf_size=32)
    rng = np.random.default_rng(1)
    x = rng.standard_normal(dense.shape[0])
    assert relative(h @ x, dense @ x) <= 2 * eps
    X = rng.standard_normal((dense.shape[0], 3))
    assert relative(h.matmat(X), dense @ X) <= 2 * eps
    errors = h.admissible_block_errors()
    assert errors.shape == (h.stats["n_admissible"],)
    assert h.stats["n_admissible"] > 100
    assert errors.max() <= 10 * eps
    assert h.check_against_dense() == errors.max()


def test_scalar_compression_and_rank_growth(scalar_problems):
    stats = {}
    for name in ("cube", "plane"):
        generator, _ = scalar_problems[name]
        for eps in (1e-3, 1e-6):
            stats[name, eps] = HMatrix.build(generator, eps=eps, leaf_size=32).stats
    assert stats["plane", 1e-3]["compression"] > 5
    assert stats["cube", 1e-3]["compression"] > 2.5
    for name in ("cube", "plane"):
        coarse, fine = stats[name, 1e-3], stats[name, 1e-6]
        # ranks grow slowly (polylogarithmically) with 1/eps
        assert coarse["max_rank"] < fine["max_rank"] <= 4 * coarse["max_rank"]
        assert coarse["mean_rank"] < fine["mean_rank"] <= 4 * coarse["mean_rank"]
        assert fine["memory_bytes"] < 4 * coarse["memory_bytes"]


def test_compression_at_4000_points_on_a_plane():
    h = HMatrix.build(inverse_distance_generator(plane(4000, seed=3), diagonal=50.0), eps=1e-4, leaf_size=32)
    assert h.stats["compression"] > 5


def test_to_dense_and_original_ordering():
    points = cube(600, seed=2)
    generator = inverse_distance_generator(points, diagonal=30.0)
    dense = generator.to_dense()
    h = HMatrix.build(generator, eps=1e-8, leaf_size=16, factor_dtype=np.float64)
    assert h.stats["n_admissible"] > 0
    assert relative(h.to_dense(), dense) <= 1e-8
    # a unit vector picks the column of the same (original) element
    e = np.zeros(600)
    e[123] = 1.0
    assert relative(h @ e, dense[:, 123]) <= 1e-8


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(min_value=1, max_value=400),
    dim=st.sampled_from([2, 3]),
    leaf_size=st.integers(min_value=1, max_value=48),
    eta=st.sampled_from([0.5, 1.0, 3.0, 10.0]),
    eps=st.sampled_from([1e-2, 1e-4, 1e-8]),
    seed=st.integers(min_value=0, max_value=2**31),
)
def test_random_clouds_match_the_dense_matrix(n, dim, leaf_size, eta, eps, seed):
    points = np.random.default_rng(seed).random((n, dim)) * np.array([1.0, 0.3, 2.0][:dim])
    generator = inverse_distance_generator(points, diagonal=100.0)
    h = HMatrix.build(generator, eps=eps, eta=eta, leaf_size=leaf_size)
    dense = generator.to_dense()
    assert np.linalg.norm(h.to_dense() - dense) <= 10 * eps * np.linalg.norm(dense)
    x = np.random.default_rng(seed + 1).standard_normal(n)
    assert np.allclose(h @ x, h.to_dense() @ x, rtol=1e-10, atol=1e-10 * np.abs(h.to_dense()).sum(axis=1).max())


def test_stats_are_complete_and_consistent(scalar_problems):
    generator, _ = scalar_problems["cube"]
    h = HMatrix.build(generator, eps=1e-4, eta=2.0, leaf_size=32)
    st = h.stats
    for key in ("memory_bytes", "dense_bytes", "compression", "build_seconds", "n_admissible", "n_dense_blocks",
                "max_rank", "eps", "eta", "leaf_size", "n_elements", "dof"):
        assert key in st
    s = h.storage
    factor_bytes = sum(a.nbytes for a in (s.u_values, s.v_values, s.u_fixed, s.v_fixed, s.u_scale, s.v_scale))
    assert st["memory_bytes"] == s.dense_values.nbytes + factor_bytes == s.dense_values.nbytes + s.lowrank_bytes
    assert st["dense_bytes"] == 8 * 3000**2
    assert st["compression"] == pytest.approx(st["dense_bytes"] / st["memory_bytes"])
    assert (st["eps"], st["eta"], st["leaf_size"], st["n_elements"], st["dof"]) == (1e-4, 2.0, 32, 3000, 1)
    assert st["n_dense_blocks"] >= st["n_near_blocks"] == h.blocks.near_rows.size
    assert st["n_admissible"] == h.blocks.admissible_rows.size
    assert st["factor_dtype"] == "float32+int16"  # eps >= 1e-5: adaptive precision
    assert st["build_seconds"] > 0
    assert h.shape == (3000, 3000)
    assert h.is_finite()


# ----------------------------------------------------------------------------- tensor kernels


@pytest.fixture(scope="module")
def tensor_problems():
    points = tilted_plane(1200, seed=5)
    kelvin = tensor_generator(points, coupling=1.0, exponent=1.0)
    # shear and normal components never couple, with different scales (planar-crack DDM)
    decoupled = tensor_generator(points, scales=[1.0, 0.6, 3.0], coupling=0.0, exponent=3.0)
    return {"kelvin": kelvin, "decoupled": decoupled}


@pytest.mark.parametrize("name", ["kelvin", "decoupled"])
@pytest.mark.parametrize("eps", [1e-3, 1e-6])
def test_tensor_kernel_every_block_within_eps(tensor_problems, name, eps):
    generator = tensor_problems[name]
    h = HMatrix.build(generator, eps=eps, leaf_size=32)
    assert h.stats["dof"] == 3 and h.stats["n_admissible"] > 100
    errors = h.admissible_block_errors()
    assert errors.max() <= 10 * eps
    dense = generator.to_dense()
    x = np.random.default_rng(0).standard_normal(dense.shape[0])
    assert relative(h @ x, dense @ x) <= 2 * eps


@pytest.mark.parametrize("eps", [1e-3, 1e-6])
def test_tensor_kernel_in_2d(eps):
    points = np.random.default_rng(7).random((1500, 2))
    generator = tensor_generator(points, scales=[1.0, 2.0], coupling=-2.0, exponent=2.0)
    h = HMatrix.build(generator, eps=eps, leaf_size=32)
    assert h.shape == (3000, 3000) and h.stats["n_admissible"] > 50
    assert h.admissible_block_errors().max() <= 10 * eps
    dense = generator.to_dense()
    x = np.random.default_rng(1).standard_normal(3000)
    assert relative(h @ x, dense @ x) <= 2 * eps


def test_zero_blocks_between_uncoupled_groups():
    """Two groups of elements that do not interact: their cross blocks are exactly zero."""
    rng = np.random.default_rng(8)
    points = np.r_[rng.random((500, 3)), rng.random((500, 3)) + [3.0, 0.0, 0.0]]
    groups = np.r_[np.zeros(500, dtype=np.int64), np.ones(500, dtype=np.int64)]
    generator = tensor_generator(points, groups=groups)
    h = HMatrix.build(generator, eps=1e-6, leaf_size=32)
    st = h.stats
    assert st["n_zero_blocks"] > 0
    assert h.is_finite()
    errors = h.admissible_block_errors()
    assert np.all(np.isfinite(errors)) and errors.max() <= 10 * 1e-6
    dense = generator.to_dense()
    x = rng.standard_normal(3000)
    assert relative(h @ x, dense @ x) <= 2e-6
    # the cross-group part of the result is exactly zero for a one-group input
    x[1500:] = 0.0
    assert np.all((h @ x)[1500:] == 0.0)


def test_rank_one_kernel_is_exact():
    rng = np.random.default_rng(9)
    points = rng.random((400, 3))
    f, g = rng.standard_normal(1200), rng.standard_normal(1200)
    generator = matrix_generator(np.outer(f, g), points, dof=3)
    h = HMatrix.build(generator, eps=1e-10, leaf_size=16)
    s = h.storage
    assert s.lowrank_rank.size > 0 and np.all(s.lowrank_rank == 1)
    assert relative(h.to_dense(), np.outer(f, g)) < 1e-12


def test_single_cluster_is_dense_and_exact():
    points = cube(20)
    generator = inverse_distance_generator(points, diagonal=5.0)
    h = HMatrix.build(generator, eps=1e-4, leaf_size=64)
    assert h.stats["n_admissible"] == 0 and h.stats["n_dense_blocks"] == 1
    assert np.array_equal(h.to_dense(), generator.to_dense())
    one = HMatrix.build(inverse_distance_generator(cube(1), diagonal=2.0), eps=1e-4)
    assert np.array_equal(one @ np.array([3.0]), np.array([6.0]))


# ----------------------------------------------------------------------------- near field


def test_near_field_csr_holds_exact_near_blocks(tensor_problems):
    generator = tensor_problems["kelvin"]
    h = HMatrix.build(generator, eps=1e-4, leaf_size=32)
    dense = generator.to_dense()
    near = h.near_field_csr()
    assert near.shape == dense.shape
    rows, cols = near.nonzero()
    assert np.array_equal(np.asarray(near[rows, cols]).ravel(), dense[rows, cols])
    # every stored near entry is kept except the zero off-diagonals of the self blocks
    assert near.nnz == h.stats["near_field_bytes"] // 8 - 6 * 1200
    # element diagonal blocks
    diagonal = h.near_field_csr(part="element_diagonal").toarray()
    mask = np.kron(np.eye(1200), np.ones((3, 3))) > 0
    assert np.array_equal(diagonal[mask], dense[mask]) and not diagonal[~mask].any()
    assert np.array_equal(h.element_diagonal_blocks(), dense[mask].reshape(1200, 3, 3))
    leaf = h.near_field_csr(part="leaf_diagonal")
    assert diagonal.nonzero()[0].size < leaf.nnz < near.nnz
    thinned = h.near_field_csr(threshold=1.0)  # 1/r with a weak self term: blocks rival the diagonal
    assert thinned.nnz < near.nnz
    with pytest.raises(InputError, match="part"):
        h.near_field_csr(part="far")


def ddm_like_generator(side, seed=0):
    """A planar-crack-like tensor kernel (d = 3): 1/r^3, shear and normal uncoupled, on a
    jittered side x side grid of a tilted unit square, with a self term ~ 1/h^3 like the
    hypersingular DDM kernel (the near field decays like (h/r)^3 of the diagonal)."""
    rng = np.random.default_rng(seed)
    h = 1.0 / side
    u, v = np.meshgrid((np.arange(side) + 0.5) * h, (np.arange(side) + 0.5) * h)
    uv = np.column_stack([u.ravel(), v.ravel()]) + rng.uniform(-0.2, 0.2, (side * side, 2)) * h
    e1 = np.array([1.0, 0.0, 0.3]) / np.sqrt(1.09)
    e2 = np.array([0.0, 1.0, 0.5])
    e2 -= (e2 @ e1) * e1
    e2 /= np.linalg.norm(e2)
    scales = np.array([1.0, 0.6, 3.0])
    return tensor_generator(uv[:, :1] * e1 + uv[:, 1:] * e2, scales=scales, coupling=0.0, exponent=3.0,
                            self_value=4.0 * scales / h**3)


def element_block_pattern(matrix):
    """Set of (row element, column element) pairs of a BSR matrix."""
    rows = np.repeat(np.arange(matrix.shape[0] // matrix.blocksize[0]), np.diff(matrix.indptr))
    return set(zip(rows.tolist(), matrix.indices.tolist()))


def rotate_elements(dense, rotations):
    """Q A Q^T for Q = diag(rotations): every element's unknowns in another frame."""
    n, d = rotations.shape[:2]
    blocks = dense.reshape(n, d, n, d)
    return np.einsum("iab,ibjc,jdc->iajd", rotations, blocks, rotations).reshape(dense.shape)


def random_rotations(n, rng):
    q, r = np.linalg.qr(rng.standard_normal((n, 3, 3)))
    q *= np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q


def test_near_field_threshold_keeps_whole_blocks_by_frobenius_norm_in_any_frame():
    """Element block (i, j) is kept when ||A_ij||_F >= t sqrt(||A_ii||_F ||A_jj||_F): the
    same blocks whatever the frame of each element's unknowns (an entry-wise rule keeps
    a tilted element's couplings differently from an aligned one's)."""
    generator = ddm_like_generator(30)
    n, d, threshold = 900, 3, 1e-2
    h = HMatrix.build(generator, eps=1e-4, leaf_size=32)
    dense = generator.to_dense()
    norms = np.linalg.norm(dense.reshape(n, d, n, d), axis=(1, 3))
    diagonal = np.diag(norms)
    full = h.near_field_bsr()
    kept = h.near_field_bsr(threshold=threshold)
    expected = {(i, j) for i, j in element_block_pattern(full)
                if i == j or norms[i, j] >= threshold * np.sqrt(diagonal[i] * diagonal[j])}
    assert element_block_pattern(kept) == expected and len(expected) < 0.5 * len(element_block_pattern(full))
    assert kept.blocksize == (d, d) and kept.has_sorted_indices
    assert all(np.all(np.diff(kept.indices[a:b]) > 0) for a, b in zip(kept.indptr[:-1], kept.indptr[1:]))
    mask = kept.toarray() != 0
    assert np.array_equal(kept.toarray()[mask], dense[mask])  # exact entries
    csr = h.near_field_csr(threshold=threshold)  # the same blocks, without their exact zeros
    assert abs(csr - kept.tocsr()).max() == 0 and csr.nnz == np.count_nonzero(kept.data)
    rotations = random_rotations(n, np.random.default_rng(7))
    rotated = HMatrix.build(matrix_generator(rotate_elements(dense, rotations), generator.points, dof=d),
                            eps=1e-4, leaf_size=32)
    assert element_block_pattern(rotated.near_field_bsr(threshold=threshold)) == expected
    assert h.near_field_bsr(part="element_diagonal").nnz == n * d * d
    with pytest.raises(InputError, match="threshold"):
        h.near_field_bsr(threshold=-1.0)


# ----------------------------------------------------------------------------- validation


def test_build_refuses_bad_arguments(scalar_problems):
    generator, _ = scalar_problems["plane"]
    for eps in (0.0, 1.0, -1e-3, np.nan, "1e-3", True):
        with pytest.raises(InputError, match="eps"):
            HMatrix.build(generator, eps=eps)
    for eta in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(InputError, match="eta"):
            HMatrix.build(generator, eta=eta)
    for leaf_size in (0, -4, 8.5, True):
        with pytest.raises(InputError, match="leaf_size"):
            HMatrix.build(generator, leaf_size=leaf_size)
    with pytest.raises(InputError, match="factor_dtype"):
        HMatrix.build(generator, factor_dtype=np.int32)
    with pytest.raises(InputError, match="generator"):
        HMatrix.build(np.eye(3))


@pytest.mark.parametrize("where", ["near", "far"])
def test_build_refuses_a_kernel_returning_nan(where):
    rng = np.random.default_rng(10)
    points = rng.random((400, 3))
    matrix = np.exp(-np.linalg.norm(points[:, None] - points[None], axis=2)) + np.eye(400)
    h = HMatrix.build(matrix_generator(matrix, points), eps=1e-6, leaf_size=16)
    tree, blocks = h.tree, h.blocks
    rows, cols = (blocks.near_rows, blocks.near_cols) if where == "near" else (blocks.admissible_rows,
                                                                                 blocks.admissible_cols)
    i = tree.permutation[tree.start[rows[0]]]
    j = tree.permutation[tree.start[cols[0]]]
    matrix[i, j] = np.nan
    with pytest.raises(InputError, match="NaN"):
        HMatrix.build(matrix_generator(matrix, points), eps=1e-6, leaf_size=16, check_finite=True)
    if where == "near":  # unchecked: built, and is_finite() tells
        assert not HMatrix.build(matrix_generator(matrix, points), eps=1e-6, leaf_size=16).is_finite()


def test_block_generator_refuses_bad_input():
    points = cube(10)
    data = (points, np.array([1.0]))
    with pytest.raises(InputError, match="kernel"):
        BlockGenerator(lambda *a: None, data, points, np.zeros(10), 1)
    with pytest.raises(InputError, match="points"):
        BlockGenerator(inverse_distance_kernel, data, points[:, :1], np.zeros(10), 1)
    with pytest.raises(InputError, match="radii"):
        BlockGenerator(inverse_distance_kernel, data, points, np.zeros(9), 1)
    with pytest.raises(InputError, match="dof"):
        BlockGenerator(inverse_distance_kernel, data, points, np.zeros(10), 0)
    with pytest.raises(InputError, match="data"):
        BlockGenerator(inverse_distance_kernel, [points], points, np.zeros(10), 1)
    generator = BlockGenerator(inverse_distance_kernel, data, points, 0.0, 1)
    assert generator.shape == (10, 10) and generator.fill([0, 1], [2]).shape == (2, 1)


def test_matvec_refuses_wrong_shape(scalar_problems):
    generator, _ = scalar_problems["plane"]
    h = HMatrix.build(generator, eps=1e-3, leaf_size=32)
    with pytest.raises(ValueError):
        h.matvec(np.ones(5))
