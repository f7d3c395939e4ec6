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
    mesh, extended, _ = grown
    with pytest.raises(ValueError, match="extend"):
        ExtendedElasticityOperator(extended.base, mesh.subset(np.arange(50)))
