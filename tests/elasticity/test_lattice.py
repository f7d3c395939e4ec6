"""hmatddm.elasticity.lattice: the FFT operator of a planar lattice mesh, against the
dense 3 x 3 operator of the same mesh (an independent assembly, pair by pair)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.coupled.elastic import ElasticSolver
from hmatddm.elasticity.lattice import NEAR_REACH, LatticePlanarOperator, fft_length, lattice_of
from hmatddm.elasticity.planar import PlanarElasticityOperator
from hmatddm.errors import InputError
from hmatddm.simulation import growing_operator
from hmatddm.simulation.settings import OperatorSettings, RebuildSettings

from test_planar import PLANES, _closed_rows

MATERIAL = hd.Elastic(10e9, 0.25)


def _disc(plane, n=14, radius=2.6, order=None):
    """Cells of an ``n`` x ``n - 3`` lattice of 6 m x 4.3 m within ``radius`` of its centre
    (a ragged front, as the asymptotic front's), in the order ``order`` takes them."""
    u, v = PLANES[plane]
    box = hd.mesh.rectangle([1.0, 2.0, 3.0], u, v, 6.0, 6.0 * (n - 3) / n, n, n - 3)
    inside = np.flatnonzero(np.linalg.norm(box.centers - [1.0, 2.0, 3.0], axis=1) < radius)
    return box.subset(inside if order is None else order(inside))


@pytest.fixture(scope="module", params=sorted(PLANES))
def pair(request):
    mesh = _disc(request.param, order=lambda index: np.random.default_rng(3).permutation(index))
    return mesh, hd.ElasticityOperator(mesh, MATERIAL).to_dense()


def test_lattices_are_recognised_and_other_meshes_refused():
    mesh = _disc("tilted")
    lattice = lattice_of(mesh)
    assert lattice is not None and len(lattice.cells) == mesh.n_elements
    assert lattice_of(hd.mesh.penny([0, 0, 0], [0, 0, 1.0], 2.0, 0.3)) is not None
    off = _disc("tilted")
    off.centers[4] += 0.3 * off.frames[4, 0]  # a third of a cell along e1
    assert lattice_of(off) is None
    bigger = _disc("horizontal")
    bigger.half_a[2] *= 1.5
    assert lattice_of(bigger) is None
    flipped = _disc("horizontal")
    flipped.frames[3] = flipped.frames[3] * [[1.0], [-1.0], [-1.0]]  # the same plane, the normal turned
    assert lattice_of(flipped) is None
    two_planes = hd.mesh.concatenate([_disc("horizontal"), hd.mesh.rectangle([0, 0, 9.0], [1.0, 0, 0], [0, 1.0, 0],
                                                                            2.0, 2.0, 2, 2)])
    assert lattice_of(two_planes) is None
    twice = _disc("horizontal")
    assert lattice_of(twice.subset(np.concatenate([np.arange(twice.n_elements), [0]]))) is None
    with pytest.raises(InputError, match="lattice"):
        LatticePlanarOperator(off, MATERIAL)


def test_products_match_the_dense_operator_to_round_off(pair):
    mesh, dense = pair
    op = LatticePlanarOperator(mesh, MATERIAL)
    rng = np.random.default_rng(0)
    opening = (rng.normal(size=mesh.n_elements)[:, None] * mesh.normals).ravel()
    assert np.abs(op @ opening - dense @ opening).max() <= 1e-13 * np.abs(dense @ opening).max()
    assert op.shear_hmatrix is None  # an opening product never builds the shear part
    x = rng.normal(size=dense.shape[0])
    assert np.abs(op @ x - dense @ x).max() <= 1e-13 * np.abs(dense @ x).max()
    assert np.abs(op.to_dense() - dense).max() <= 1e-13 * np.abs(dense).max()
    n, index = mesh.n_elements, np.arange(mesh.n_elements)
    np.testing.assert_allclose(op.element_diagonal_blocks(), dense.reshape(n, 3, n, 3)[index, :, index, :],
                               rtol=0, atol=1e-13 * np.abs(dense).max())
    assert op.stats["backend"] == "lattice" and op.check_against_dense() == 0.0


def test_solves_match_the_dense_lu_with_and_without_contact_rows(pair):
    """Plain and modified (closed elements) solves against the dense LU, with as few GMRES
    iterations as the H-matrix planar operator's near-field ILU of the same rows."""
    mesh, dense = pair
    op = LatticePlanarOperator(mesh, MATERIAL)
    hmatrix = PlanarElasticityOperator(mesh, MATERIAL, eps=1e-8)
    rng = np.random.default_rng(1)
    rhs = rng.normal(size=dense.shape[0])
    solution, info = op.solve(rhs, rtol=1e-11)
    assert info["converged"]
    exact = np.linalg.solve(dense, rhs)
    assert np.linalg.norm(solution - exact) <= 1e-8 * np.linalg.norm(exact)
    rows = _closed_rows(mesh, 3)
    exact = np.linalg.solve(rows.modify_dense(dense), rhs)
    solution, iterations = ElasticSolver(op, rtol=1e-11).solve(rhs, rows=rows)
    assert np.linalg.norm(solution - exact) <= 1e-8 * np.linalg.norm(exact)
    assert iterations <= ElasticSolver(hmatrix, rtol=1e-11).solve(rhs, rows=rows)[1] + 1


def test_a_growing_crack_shares_its_kernel_table_and_gets_the_same_products():
    mesh = _disc("tilted", n=16, radius=3.0)
    n = mesh.n_elements
    small = LatticePlanarOperator(mesh.subset(np.arange(n - 20)), MATERIAL)
    grown = LatticePlanarOperator(mesh, MATERIAL, previous=small)
    fresh = LatticePlanarOperator(mesh, MATERIAL)
    assert small.tables_computed == 1 and fresh.tables_computed == 1
    assert grown.tables_computed == (0 if grown.stats["fft_shape"] == small.stats["fft_shape"] else 1)
    x = np.random.default_rng(2).normal(size=3 * n)
    np.testing.assert_array_equal(grown @ x, fresh @ x)  # a table depends on its box only: resumes are exact
    other = hd.Elastic(20e9, 0.25)
    assert LatticePlanarOperator(mesh, other, previous=small).tables_computed == 1  # another material: its own


def test_the_growing_operator_takes_the_lattice_for_lattice_meshes_only(monkeypatch):
    grow = growing_operator.GrowingOperator(MATERIAL, OperatorSettings(), RebuildSettings())
    disc = _disc("horizontal")
    assert isinstance(grow(disc), LatticePlanarOperator)
    builds = grow.builds
    bigger = _disc("horizontal", radius=2.9)
    assert isinstance(grow(bigger), LatticePlanarOperator) and grow.builds - builds <= 1
    two_sizes = hd.mesh.concatenate([disc, hd.mesh.rectangle([9.0, 2.0, 3.0], [1.0, 0, 0], [0, 1.0, 0], 2.0, 2.0,
                                                             3, 3)])
    assert not isinstance(growing_operator.GrowingOperator(MATERIAL, OperatorSettings(), RebuildSettings())(two_sizes),
                          LatticePlanarOperator)
    monkeypatch.setattr(growing_operator, "LATTICE_PLANAR", False)
    fresh = growing_operator.GrowingOperator(MATERIAL, OperatorSettings(), RebuildSettings())
    assert not isinstance(fresh(disc), LatticePlanarOperator)


def test_box_sizes_leave_room_for_the_convolution_and_the_near_field():
    for span in (1, 5, 16, 17, 100, 333):
        length = fft_length(span)
        assert length >= 2 * span - 1 and length >= 2 * NEAR_REACH + 1
        assert fft_length(span + 1) >= length
    assert fft_length(100) <= 1.3 * (2 * 100 - 1)
