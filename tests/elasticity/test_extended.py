"""A grown mesh's operator: H-matrix base plus exact borders equals the dense operator."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.coupled import ElasticSolver
from hmatddm.elasticity.extended import ExtendedElasticityOperator


@pytest.fixture(scope="module")
def grown(material):
    full = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 12.0, 12.0, 12, 12)
    order = np.argsort(np.max(np.abs(full.centers), axis=1), kind="stable")  # inner square first
    mesh = full.subset(order)
    base = hd.ElasticityOperator(mesh.subset(np.arange(100)), material, backend="hmatrix", eps=1e-8, leaf_size=16)
    return mesh, ExtendedElasticityOperator(base, mesh), hd.ElasticityOperator(mesh, material)


def test_matvec_matches_dense(grown):
    mesh, extended, dense = grown
    rng = np.random.default_rng(0)
    x = rng.normal(size=dense.shape[0])
    np.testing.assert_allclose(extended @ x, dense @ x, rtol=0, atol=1e-6 * np.abs(dense @ x).max())
    blocks = extended.element_diagonal_blocks()
    np.testing.assert_allclose(blocks, ElasticSolver(dense).diagonal_blocks(), rtol=1e-12)


def test_solve_with_the_block_triangular_preconditioner_matches_dense(grown):
    mesh, extended, dense = grown
    load = -1e6 * mesh.normals.ravel()
    x, iterations = ElasticSolver(extended, rtol=1e-10).solve(load)
    np.testing.assert_allclose(x, hd.solve(dense, load).ravel(), atol=1e-6 * np.abs(x).max())
    assert 0 < iterations < 60


def test_mesh_that_does_not_extend_the_base_is_refused(grown, material):
    mesh, extended, dense = grown
    with pytest.raises(hd.InputError, match="extend"):
        ExtendedElasticityOperator(extended.base, mesh.subset(np.arange(50)))
    with pytest.raises(hd.InputError, match="base"):
        ExtendedElasticityOperator(dense.to_dense(), mesh)


def test_every_operator_solves_through_the_same_methods(grown):
    """Dense, H-matrix and extended operators answer solve / approximate_inverse alike;
    hd.solve takes any of them and agrees with an independent dense LU."""
    import scipy.linalg

    mesh, extended, dense = grown
    load = -1e6 * mesh.normals.ravel()
    reference = scipy.linalg.solve(dense.to_dense(), load)
    scale = np.abs(reference).max()
    x, info = dense.solve(load)
    assert info["iterations"] == 0 and dense.inverse_is_exact
    np.testing.assert_allclose(x, reference, rtol=0, atol=1e-9 * scale)
    np.testing.assert_array_equal(dense.approximate_inverse(load), x)
    for operator in (extended, extended.base):
        assert not operator.inverse_is_exact
        rhs = load[:operator.shape[0]]
        x, info = operator.solve(rhs, rtol=1e-10)
        assert info["iterations"] > 0 and info["residual"] <= 1e-10
        np.testing.assert_allclose(operator @ x, rhs, rtol=0, atol=1e-8 * np.abs(rhs).max())
        assert np.linalg.norm(operator @ operator.approximate_inverse(rhs) - rhs) < 0.8 * np.linalg.norm(rhs)
    dd, info = hd.solve(extended, load, return_info=True)
    np.testing.assert_allclose(dd.ravel(), reference, rtol=0, atol=1e-6 * scale)


def test_a_later_growth_pass_reuses_the_border_of_the_previous_one(grown, material):
    """Passing the previous pass's operator copies the border entries of the elements it
    shares and evaluates only the added ones: the blocks are exactly those of a fresh
    evaluation; a changed element ends the shared run; another base shares nothing."""
    mesh, extended, dense = grown
    base = extended.base
    first = ExtendedElasticityOperator(base, mesh.subset(np.arange(120)))
    assert first.n_reused == 0
    later = ExtendedElasticityOperator(base, mesh, previous=first)
    assert later.n_reused == 20
    for name in ("on", "no", "nn"):
        np.testing.assert_array_equal(getattr(later, name), getattr(extended, name))
    x = np.random.default_rng(2).normal(size=dense.shape[0])
    np.testing.assert_allclose(later @ x, dense @ x, rtol=0, atol=1e-6 * np.abs(dense @ x).max())

    order = np.concatenate([np.arange(110), np.arange(110, mesh.n_elements)[::-1]])  # elements 110.. changed
    changed = mesh.subset(order)
    partly = ExtendedElasticityOperator(base, changed, previous=first)
    assert partly.n_reused == 10
    fresh = ExtendedElasticityOperator(base, changed)
    for name in ("on", "no", "nn"):
        np.testing.assert_array_equal(getattr(partly, name), getattr(fresh, name))

    other_base = hd.ElasticityOperator(mesh.subset(np.arange(100)), material, backend="hmatrix", eps=1e-8,
                                       leaf_size=16)
    assert ExtendedElasticityOperator(other_base, mesh, previous=first).n_reused == 0


def _near_border(fresh, base):
    """``A_no`` without the element blocks below the preconditioner's threshold, written
    out block by block."""
    from hmatddm.elasticity.extended import NEAR_THRESHOLD

    d, n0, m = base.dof, fresh.n_base, fresh.n_new
    no = fresh.no.copy()
    old = base.element_diagonal_blocks()
    for i in range(m):
        own = np.linalg.norm(fresh.nn[d * i:d * i + d, d * i:d * i + d])
        for j in range(n0):
            block = no[d * i:d * i + d, d * j:d * j + d]
            if np.linalg.norm(block) < NEAR_THRESHOLD * np.sqrt(own * np.linalg.norm(old[j])):
                block[:] = 0.0
    return no


def test_growth_passes_share_border_chunks_and_the_base_product(grown, material):
    """A chain of growth passes over one base: every pass's matvec and block-triangular
    preconditioner equal those of a fresh operator of its mesh (the dense border and LU of
    A_nn, the near field of A_no, written out here), the shared chunks are the previous
    pass's arrays (not copies), and the base is multiplied once for a repeated old part."""
    import scipy.linalg

    mesh, extended, dense = grown
    base = extended.base
    rng = np.random.default_rng(4)
    previous = None
    for n in (104, 110, 111, 130, mesh.n_elements):
        grown_op = ExtendedElasticityOperator(base, mesh.subset(np.arange(n)), previous=previous)
        fresh = ExtendedElasticityOperator(base, mesh.subset(np.arange(n)))
        if previous is not None:
            assert grown_op.n_reused == previous.mesh.n_elements - 100
            assert all(mine.on_t is theirs.on_t and mine.no is theirs.no
                       for mine, theirs in zip(grown_op.chunks, previous.chunks))
        x = rng.normal(size=grown_op.shape[0])
        reference = fresh @ x
        np.testing.assert_allclose(grown_op @ x, reference, rtol=0, atol=1e-12 * np.abs(reference).max())
        np.testing.assert_allclose(grown_op @ x, dense.to_dense()[:x.size, :x.size] @ x, rtol=0,
                                   atol=1e-6 * np.abs(reference).max())
        k = 100 * base.dof
        x_old = base.approximate_inverse(x[:k])
        near = _near_border(fresh, base)
        assert 0 < np.count_nonzero(near) < 0.5 * near.size
        x_new = scipy.linalg.solve(fresh.nn, x[k:] - near @ x_old)
        np.testing.assert_allclose(grown_op.approximate_inverse(x), np.concatenate([x_old, x_new]), rtol=1e-9,
                                   atol=1e-12 * np.abs(x_new).max())
        previous = grown_op

    calls = []
    counted = ExtendedElasticityOperator(base, mesh, previous=previous)
    counted._base_product.matvec = lambda v: calls.append(1) or base.matvec(v)
    counted._base_product.x = None
    x = rng.normal(size=counted.shape[0])
    first = counted @ x
    x[-1] += 1.0  # the old part is the same: the base product is kept
    second = counted @ x
    assert len(calls) == 1 and not np.array_equal(first, second)
    x[0] += 1.0
    counted @ x
    assert len(calls) == 2


@pytest.fixture()
def compressed_border(monkeypatch, material):
    """A planar crack's opening part (dof 1) grown from 400 elements by rings, with the
    border compression thresholds lowered so that it applies at this size."""
    from hmatddm.elasticity import extended as extended_module
    from hmatddm.elasticity.planar import PlanarElasticityOperator

    monkeypatch.setattr(extended_module, "COMPRESS_MIN_BASE", 300)
    monkeypatch.setattr(extended_module, "COMPRESS_MIN_PAIRS", 2000)
    full = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 28.0, 28.0, 28, 28)
    order = np.argsort(np.linalg.norm(full.centers, axis=1), kind="stable")  # a growing disc
    mesh = full.subset(order)
    planar = PlanarElasticityOperator(mesh.subset(np.arange(400)), material, eps=1e-6, leaf_size=16)
    return mesh, planar.part("normal")


def test_compressed_border_chunks_match_the_dense_border(compressed_border):
    """Chunks of many added elements get rectangular H-matrices over the base's tree: the
    grown operator's product equals the dense one's to the compression's accuracy, the
    border holds far fewer entries than the dense border, the preconditioner's near rows
    are those of the dense border (the same blocks kept), and a chain of passes reuses
    whole compressed chunks and re-evaluates a chunk that a changed element cuts."""
    from hmatddm.elasticity.extended import ExtendedElasticityOperator
    from hmatddm.elasticity.operator import influence_data
    from hmatddm.elasticity.planar import normal_traction_block

    mesh, base = compressed_border
    data = influence_data(mesh, base.material, "none", None)
    dense = np.empty((mesh.n_elements, mesh.n_elements))
    normal_traction_block(data, np.arange(mesh.n_elements), np.arange(mesh.n_elements), dense)
    rng = np.random.default_rng(5)
    previous = None
    for n in (520, 523, 650):
        grown = ExtendedElasticityOperator(base, mesh.subset(np.arange(n)), previous=previous)
        assert grown.chunks[-1].compressed == (n != 523)  # 3 x 400 pairs: a dense chunk
        x = rng.normal(size=n)
        reference = dense[:n, :n] @ x
        np.testing.assert_allclose(grown @ x, reference, rtol=0, atol=2e-5 * np.abs(reference).max())
        if n == 650:
            assert grown.chunks[-1].on_t.stats["n_admissible"] > 0 and grown.chunks[-1].no.stats["n_admissible"] > 0
        # the near rows of a chunk: the blocks the dense border's threshold keeps
        chunk = grown.chunks[-1]
        rows = np.arange(400 + chunk.start, 400 + chunk.stop)
        dense_chunk = ExtendedElasticityOperator.__new__(ExtendedElasticityOperator)
        dense_chunk.dof, dense_chunk.n_base, dense_chunk._base_blocks = 1, 400, grown._base_blocks
        near = dense_chunk._near_rows(dense[rows][:, :400], dense[rows][:, rows])
        assert (near != chunk.near).nnz == 0 and near.nnz > 0
        if previous is not None:
            assert grown.n_reused == previous.mesh.n_elements - 400
            assert all(mine is theirs for mine, theirs in zip(grown.chunks, previous.chunks))
        previous = grown
    order = np.concatenate([np.arange(600), np.arange(600, 650)[::-1]])  # cuts the chunk 523..650
    cut = ExtendedElasticityOperator(base, mesh.subset(order), previous=previous)
    assert cut.n_reused == 123 and len(cut.chunks) == 3
    x = rng.normal(size=650)
    reference = dense[np.ix_(order, order)] @ x
    np.testing.assert_allclose(cut @ x, reference, rtol=0, atol=2e-5 * np.abs(reference).max())
