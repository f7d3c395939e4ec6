"""Rectangular H-matrices (hmatddm.hmatrix with separate row and column cluster trees and
different unknowns per row and per column element) against the dense matrix of the same
generator: block partition, ACA with d_r x d_c pivots, matvec, to_dense."""
import numpy as np
import pytest

from hmatddm.errors import InputError
from hmatddm.hmatrix import BlockGenerator, HMatrix
from hmatddm.hmatrix.aca import aca_tensor
from hmatddm.hmatrix.block_tree import block_tree
from hmatddm.hmatrix.cluster_tree import cluster_tree
from hmatddm.hmatrix.example_kernels import field_generator, field_kernel


def scene(dim, n_targets, n_sources, seed=0):
    """Targets on a large box, sources on a smaller slab inside it (near and far pairs),
    no target on a source."""
    rng = np.random.default_rng(seed)
    targets = rng.uniform(-10.0, 10.0, (n_targets, dim))
    sources = rng.uniform(-3.0, 3.0, (n_sources, dim))
    sources[:, 0] *= 0.1
    sources += 0.05  # off the targets
    return targets, sources


def test_block_tree_of_two_trees_covers_every_pair_once():
    targets, sources = scene(3, 700, 150)
    rows, cols = cluster_tree(targets, 0.0, 32), cluster_tree(sources, 0.0, 16)
    blocks = block_tree(rows, 2.0, col_tree=cols)
    count = np.zeros((700, 150), dtype=int)
    for r, c in zip(np.concatenate((blocks.admissible_rows, blocks.near_rows)),
                    np.concatenate((blocks.admissible_cols, blocks.near_cols))):
        count[np.ix_(rows.permutation[rows.start[r]:rows.stop[r]], cols.permutation[cols.start[c]:cols.stop[c]])] += 1
    assert np.all(count == 1)
    assert blocks.admissible_rows.size > 0
    # near blocks are leaf x leaf
    assert np.all(rows.left[blocks.near_rows] < 0) and np.all(cols.left[blocks.near_cols] < 0)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("eps", [1e-4, 1e-7])
def test_rectangular_hmatrix_matches_dense(dim, eps):
    targets, sources = scene(dim, 900, 260, seed=dim)
    generator = field_generator(targets, sources)
    assert generator.shape == (900 * dim, 260 * 2)
    hmatrix = HMatrix.build(generator, eps=eps, eta=2.0, leaf_size=32, col_leaf_size=16, factor_dtype=np.float64)
    dense = generator.to_dense()
    assert hmatrix.shape == dense.shape and hmatrix.rectangular
    stats = hmatrix.stats
    assert stats["n_lowrank_blocks"] > 0 and stats["memory_bytes"] < dense.nbytes
    assert hmatrix.check_against_dense(n_samples=4096) <= 10.0 * eps  # per block, as the square tests
    approx = hmatrix.to_dense()
    assert np.linalg.norm(approx - dense) <= 2.0 * eps * np.linalg.norm(dense)
    x = np.random.default_rng(1).normal(size=(dense.shape[1], 3))
    assert np.linalg.norm(hmatrix @ x - dense @ x) <= 2.0 * eps * np.linalg.norm(dense @ x)
    np.testing.assert_allclose(hmatrix.matvec(x[:, 0]), (hmatrix @ x)[:, 0], rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(hmatrix.matvec(x[:, 0]), approx @ x[:, 0], rtol=1e-10,
                               atol=1e-12 * np.abs(approx @ x[:, 0]).max())


def test_aca_with_rectangular_pivots_of_a_far_block():
    """A far block with 3 rows per target and 2 columns per source: the whole-element ACA
    (3 x 2 pivots) meets eps and its rank is far below the block size."""
    rng = np.random.default_rng(3)
    targets = rng.uniform(-1.0, 1.0, (80, 3))
    sources = rng.uniform(-1.0, 1.0, (60, 3)) + [8.0, 0.0, 0.0]
    data = (targets, sources)
    rows, cols = np.arange(80, dtype=np.int64), np.arange(60, dtype=np.int64)
    block = np.empty((240, 120))
    field_kernel(data, rows, cols, block)
    for eps in (1e-3, 1e-6):
        u, v, rank = aca_tensor(field_kernel, data, rows, cols, 3, eps, 2)
        assert u.shape == (240, rank) and v.shape == (120, rank)
        assert rank < 60
        assert np.linalg.norm(u @ v.T - block) <= 10.0 * eps * np.linalg.norm(block)


def test_square_only_parts_refuse_a_rectangular_matrix():
    targets, sources = scene(2, 300, 100)
    hmatrix = HMatrix.build(field_generator(targets, sources), eps=1e-4, leaf_size=32)
    for call in (hmatrix.near_field_csr, hmatrix.near_field_bsr, hmatrix.element_diagonal_blocks):
        with pytest.raises(InputError, match="rectangular"):
            call()
    with pytest.raises(ValueError):
        hmatrix.matvec(np.zeros(300 * 2))  # rows, not columns


def test_block_generator_column_geometry_comes_whole():
    targets, sources = scene(3, 20, 10)
    with pytest.raises(InputError, match="col_points, col_radii and col_dof"):
        BlockGenerator(field_kernel, (targets, sources), targets, 0.0, 3, col_points=sources)
    with pytest.raises(InputError, match="col_points must have dimension"):
        BlockGenerator(field_kernel, (targets, sources), targets, 0.0, 3, col_points=sources[:, :2], col_radii=0.0,
                       col_dof=2)
    with pytest.raises(InputError, match="col_dof"):
        BlockGenerator(field_kernel, (targets, sources), targets, 0.0, 3, col_points=sources, col_radii=0.0,
                       col_dof=0)


def _product_case(kind, dim):
    if kind == "rectangular":
        from hmatddm.hmatrix.example_kernels import field_generator as make

        targets, sources = scene(dim, 900, 260, seed=dim)
        return make(targets, sources), dict(eta=2.0, leaf_size=32, col_leaf_size=16)
    from hmatddm.hmatrix.example_kernels import tensor_generator

    points = np.random.default_rng(dim).uniform(-5.0, 5.0, (700, dim))
    return tensor_generator(points), dict(eta=2.0, leaf_size=32)


@pytest.mark.parametrize("kind", ["rectangular", "square"])
@pytest.mark.parametrize("dim", [2, 3])
def test_build_free_product_equals_the_built_matvec_and_the_dense_product(kind, dim):
    """The one-shot product (hmatrix.product, no storage) runs the ACA of the build on
    the same block tree: at the ACA tolerance of the build (ACA_TOLERANCE_FACTOR * eps,
    before recompression) it is within eps of the dense product, and of the built
    H-matrix's matvec; exact blocks only (min_aca_elements above every block) give the
    dense product to rounding."""
    from hmatddm.hmatrix.aca import ACA_TOLERANCE_FACTOR
    from hmatddm.hmatrix.product import build_free_product

    generator, options = _product_case(kind, dim)
    dense = generator.to_dense()
    x = np.random.default_rng(2).normal(size=dense.shape[1])
    exact = dense @ x
    eps = 1e-6
    y, info = build_free_product(generator, x, ACA_TOLERANCE_FACTOR * eps, **options)
    assert info["n_far"] > 0 and info["pairs_compressed"] > 0
    assert np.linalg.norm(y - exact) <= eps * np.linalg.norm(exact)
    built = HMatrix.build(generator, eps=eps, factor_dtype=np.float64, **options)
    assert np.linalg.norm(y - built.matvec(x)) <= 2.0 * eps * np.linalg.norm(exact)
    # ACA at a looser eps: error bounded by it, and larger than at the tight one
    loose, _ = build_free_product(generator, x, 1e-3, **options)
    assert np.linalg.norm(y - exact) < np.linalg.norm(loose - exact) <= 1e-3 * np.linalg.norm(exact)
    everything_exact, info = build_free_product(generator, x, 1e-3, min_aca_elements=10**6, **options)
    assert info["pairs_compressed"] == 0
    np.testing.assert_allclose(everything_exact, exact, rtol=0, atol=1e-12 * np.abs(exact).max())


def test_build_free_product_refuses_bad_input():
    from hmatddm.hmatrix.product import build_free_product

    generator, options = _product_case("rectangular", 2)
    with pytest.raises(InputError, match="x must have"):
        build_free_product(generator, np.ones(3), 1e-4, **options)
    with pytest.raises(InputError, match="eps"):
        build_free_product(generator, np.ones(generator.shape[1]), 2.0, **options)
    with pytest.raises(InputError, match="BlockGenerator"):
        build_free_product(object(), np.ones(3), 1e-4)


def test_offsets_take_slices_of_a_larger_kernel_and_trees_can_be_given():
    """A generator over consecutive slices of a square kernel's elements (row_offset,
    col_offset) compresses exactly that block of the full matrix; an H-matrix built on a
    given row tree uses it; products in tree order are the permuted products; bad offsets
    and trees are refused naming the argument."""
    from hmatddm.hmatrix.example_kernels import inverse_distance_generator, inverse_distance_kernel

    rng = np.random.default_rng(7)
    points = rng.uniform(-5.0, 5.0, (900, 2))
    full = inverse_distance_generator(points, diagonal=3.0).to_dense()
    data = (points, np.array([3.0]))
    rows, cols = slice(0, 700), slice(700, 900)
    tree = cluster_tree(points[rows], 0.0, 32)
    generator = BlockGenerator(inverse_distance_kernel, data, points[rows], 0.0, 1, col_points=points[cols],
                               col_radii=0.0, col_dof=1, row_offset=0, col_offset=700)
    block = HMatrix.build(generator, eps=1e-8, leaf_size=32, row_tree=tree)
    assert block.tree is tree
    np.testing.assert_allclose(block.to_dense(), full[rows, cols], rtol=0, atol=1e-7 * np.abs(full[rows, cols]).max())
    x = rng.normal(size=200)
    y = block.matvec(x)
    np.testing.assert_array_equal(block.matvec_in_tree_order(x[block.col_order]), y[block.row_order])
    transposed = BlockGenerator(inverse_distance_kernel, data, points[cols], 0.0, 1, col_points=points[rows],
                                col_radii=0.0, col_dof=1, row_offset=700, col_offset=0)
    np.testing.assert_array_equal(transposed.fill(np.arange(3), np.arange(4)), full[700:703, 0:4])
    with pytest.raises(InputError, match="row_offset"):
        BlockGenerator(inverse_distance_kernel, data, points, 0.0, 1, row_offset=-1)
    with pytest.raises(InputError, match="col_offset"):
        BlockGenerator(inverse_distance_kernel, data, points, 0.0, 1, col_offset=3)  # square: no column slice
    with pytest.raises(InputError, match="row_tree"):
        HMatrix.build(generator, row_tree=cluster_tree(points, 0.0, 32))
