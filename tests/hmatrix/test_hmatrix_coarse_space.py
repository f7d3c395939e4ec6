"""Two-level preconditioner: aggregates, the Galerkin coarse matrix from the stored
blocks, and preconditioned solutions against dense ones."""

import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.hmatrix import default_preconditioner, gmres, two_level
from hmatddm.hmatrix.coarse_space import aggregates, coarse_functions, galerkin_coarse_matrix

MATERIAL = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)


@pytest.fixture(scope="module")
def crack():
    """A 24 x 24 planar crack, small leaves so that the H-matrix has many far blocks."""
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 24.0, 24.0, 24, 24)
    op = hd.ElasticityOperator(mesh, MATERIAL, backend="hmatrix", eps=1e-6, leaf_size=16)
    dense = hd.ElasticityOperator(mesh, MATERIAL, backend="dense")
    return mesh, op, dense


def test_aggregates_partition_the_tree_positions(crack):
    _, op, _ = crack
    tree = op.hmatrix.tree
    of_position, boundaries = aggregates(tree, 40)
    assert boundaries[0] == 0 and boundaries[-1] == tree.n_elements
    assert np.all(np.diff(boundaries) >= 1) and np.all(np.diff(boundaries) <= 40)
    assert np.array_equal(of_position, np.repeat(np.arange(boundaries.size - 1), np.diff(boundaries)))
    # every aggregate is a cluster of the tree
    clusters = set(zip(tree.start.tolist(), tree.stop.tolist()))
    assert all((int(a), int(b)) in clusters for a, b in zip(boundaries[:-1], boundaries[1:]))
    with pytest.raises(InputError, match="aggregate_size"):
        aggregates(tree, 0)


def test_galerkin_matrix_equals_projection_of_the_expanded_hmatrix(crack):
    """P^T A P summed block by block from the storage equals the same product formed
    with the dense expansion of the H-matrix and an explicit prolongation."""
    mesh, op, _ = crack
    h = op.hmatrix
    d = h.dof
    of_position, boundaries = aggregates(h.tree, 40)
    phi = coarse_functions(mesh.centers[h.tree.permutation], boundaries, 3)
    coarse = galerkin_coarse_matrix(h, of_position, phi)
    n_agg = boundaries.size - 1
    prolongation = np.zeros((h.shape[0], n_agg * 3 * d))
    for k, element in enumerate(h.tree.permutation):
        for f in range(3):
            for p in range(d):
                prolongation[d * element + p, (of_position[k] * 3 + f) * d + p] = phi[k, f]
    expected = prolongation.T @ h.to_dense() @ prolongation
    assert np.allclose(coarse, expected, rtol=1e-10, atol=1e-10 * np.abs(expected).max())


@pytest.mark.parametrize("multiplicative", [True, False])
def test_two_level_solution_equals_dense_solution(crack, multiplicative):
    mesh, op, dense = crack
    b = (-1e6 * mesh.normals).ravel()
    exact = np.linalg.solve(dense.to_dense(), b)
    M = two_level(op.hmatrix, aggregate_size=40, multiplicative=multiplicative)
    x, info = gmres(op, b, M=M, rtol=1e-10, restart=100, maxiter=5)
    assert np.linalg.norm(x - exact) / np.linalg.norm(exact) < 1e-5  # eps 1e-6 H-matrix
    if multiplicative:  # the additive form only pays at larger N
        _, ilu_info = gmres(op, b, M=default_preconditioner(op.hmatrix), rtol=1e-10, restart=100, maxiter=5)
        assert info["iterations"] < ilu_info["iterations"]
    assert M.coarse["coarse_size"] == M.coarse["n_aggregates"] * 3 * 3


def test_two_level_on_a_straight_2d_crack_with_vanishing_coarse_functions():
    """A straight 2D crack has one principal axis: the third coarse function is zero on
    every aggregate; the coarse matrix stays invertible and the solve exact."""
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 600)
    op = hd.ElasticityOperator(mesh, MATERIAL, backend="hmatrix", eps=1e-8, leaf_size=16)
    dense = hd.ElasticityOperator(mesh, MATERIAL, backend="dense")
    b = (-1e6 * mesh.normals).ravel()
    exact = np.linalg.solve(dense.to_dense(), b)
    x, _ = gmres(op, b, M=two_level(op.hmatrix, aggregate_size=32), rtol=1e-11, restart=100, maxiter=5)
    assert np.linalg.norm(x - exact) / np.linalg.norm(exact) < 1e-6


def test_two_level_bad_input(crack):
    _, op, _ = crack
    with pytest.raises(InputError, match="n_functions"):
        two_level(op.hmatrix, n_functions=4)
    with pytest.raises(InputError, match="hmatrix"):
        two_level(np.eye(3))


def test_grown_mesh_with_a_two_level_base_matches_dense(monkeypatch):
    """The block lower-triangular preconditioner of a grown mesh applies the base
    operator's default preconditioner, here the two-level one."""
    import hmatddm.hmatrix.preconditioners as preconditioners
    from hmatddm.coupled import ElasticSolver
    from hmatddm.elasticity.extended import ExtendedElasticityOperator

    monkeypatch.setattr(preconditioners, "TWO_LEVEL_MIN_ELEMENTS", 0)
    full = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 16.0, 16.0, 16, 16)
    order = np.argsort(np.max(np.abs(full.centers), axis=1), kind="stable")  # inner square first
    mesh = full.subset(order)
    base = hd.ElasticityOperator(mesh.subset(np.arange(196)), MATERIAL, backend="hmatrix", eps=1e-8, leaf_size=16)
    assert hasattr(base.preconditioner(), "coarse")
    extended = ExtendedElasticityOperator(base, mesh)
    dense = hd.ElasticityOperator(mesh, MATERIAL)
    load = -1e6 * mesh.normals.ravel()
    x, iterations = ElasticSolver(extended, rtol=1e-10).solve(load)
    np.testing.assert_allclose(x, hd.solve(dense, load).ravel(), atol=1e-6 * np.abs(x).max())
    assert 0 < iterations < 60
