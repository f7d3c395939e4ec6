"""A grown mesh's operator: H-matrix base plus exact borders equals the dense operator."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.coupled import ElasticSolver
from hmatddm.extended_operator import ExtendedElasticityOperator


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
