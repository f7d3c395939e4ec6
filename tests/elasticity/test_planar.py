"""hmatddm.elasticity.planar: a planar crack's operator compressed as its opening and shear
parts, against the dense 3 x 3 operator of the same mesh."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.coupled.contact import ContactRows
from hmatddm.errors import InputError
from hmatddm.elasticity.extended import ExtendedElasticityOperator
from hmatddm.elasticity.planar import PlanarElasticityOperator, PlanarExtendedOperator, is_planar
from hmatddm.simulation import growing_operator

MATERIAL = hd.Elastic(10e9, 0.25)
# a horizontal plane, and one tilted about every axis (its frames in global components are
# not exact, so projections leave round-off)
_TILTED_U = np.array([1.0, 1.0, 0.3]) / np.linalg.norm([1.0, 1.0, 0.3])
_TILTED_V = np.cross(_TILTED_U, [0.2, -0.4, 1.0])
_TILTED_V /= np.linalg.norm(_TILTED_V)
PLANES = {"horizontal": ([1.0, 0, 0], [0, 1.0, 0]), "tilted": (_TILTED_U, _TILTED_V)}


def _mesh(plane, n=12):
    u, v = PLANES[plane]
    return hd.mesh.rectangle([1.0, 2.0, 3.0], u, v, 6.0, 4.0, n, n - 4)


@pytest.fixture(scope="module", params=sorted(PLANES))
def pair(request):
    mesh = _mesh(request.param)
    return mesh, hd.ElasticityOperator(mesh, MATERIAL).to_dense()


def test_planar_meshes_are_recognised():
    assert is_planar(_mesh("horizontal")) and is_planar(_mesh("tilted"))
    bent = _mesh("tilted")
    bent.centers[5] += 1e-6 * bent.normals[5]
    assert not is_planar(bent)
    two_planes = hd.mesh.concatenate([_mesh("horizontal"), hd.mesh.rectangle([0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0],
                                                                       2.0, 2.0, 2, 2)])
    assert not is_planar(two_planes)
    assert not is_planar(hd.mesh.line([0, 0], [1, 0], 4))


def test_an_opening_product_needs_no_shear_operator_and_matches_dense(pair):
    mesh, dense = pair
    op = PlanarElasticityOperator(mesh, MATERIAL, eps=1e-6)
    opening = (np.cos(mesh.centers[:, 0])[:, None] * mesh.normals).ravel()
    exact = dense @ opening
    assert np.linalg.norm(op @ opening - exact) <= 1e-5 * np.linalg.norm(exact)
    preconditioned = op.approximate_inverse(exact)
    assert op.shear_hmatrix is None and op.stats["parts"] == "normal"
    # the preconditioned opening load stays an opening: no shear part
    shear = np.einsum("eak,ek->ea", mesh.frames[:, :2], preconditioned.reshape(-1, 3))
    assert np.abs(shear).max() <= 1e-12 * np.abs(preconditioned).max()


def test_every_product_and_solve_matches_the_dense_operator(pair):
    mesh, dense = pair
    op = PlanarElasticityOperator(mesh, MATERIAL, eps=1e-6)
    x = np.random.default_rng(0).normal(size=dense.shape[0])
    assert np.linalg.norm(op @ x - dense @ x) <= 1e-5 * np.linalg.norm(dense @ x)
    assert op.shear_hmatrix is not None and op.stats["parts"] == "normal+shear"
    stats = op.stats
    assert stats["memory_bytes"] == op.hmatrix.stats["memory_bytes"] + op.shear_hmatrix.stats["memory_bytes"]
    assert stats["dense_bytes"] == 8 * dense.size and stats["compression"] == 8 * dense.size / stats["memory_bytes"]
    assert np.abs(op.to_dense() - dense).max() <= 1e-5 * np.abs(dense).max()
    assert op.check_against_dense() <= 1e-5
    n = mesh.n_elements
    index = np.arange(n)
    np.testing.assert_array_equal(op.element_diagonal_blocks(), dense.reshape(n, 3, n, 3)[index, :, index, :])
    product = op @ x
    np.testing.assert_allclose(op.matmat(np.column_stack([x, 2 * x])), np.column_stack([product, 2 * product]),
                               rtol=0, atol=1e-13 * np.abs(product).max())
    rhs = dense @ x
    solution, info = op.solve(rhs, rtol=1e-10)
    assert info["converged"]
    assert np.linalg.norm(solution - x) <= 1e-5 * np.linalg.norm(x)


def _closed_rows(mesh, every, mixed=False):
    """Contact rows (global components) closing every ``every``-th element: its normal row
    replaced by ``k n.DD``; ``mixed``: also a friction-like row that couples its opening and
    shear (a slipping element's ``(m + mu n).c``), which does not split."""
    n = mesh.n_elements
    frames = mesh.frames
    select_frame = np.tile(np.eye(3), (n, 1, 1))
    direct_frame = np.zeros((n, 3, 3))
    select_frame[::every] = np.diag([1.0, 1.0, 0.0])
    direct_frame[::every, 2, 2] = 1e12
    if mixed:
        select_frame[1::every, 0] = [1.0, 0.0, 0.6]
    # frame -> global: S = F^T S_f F
    select = np.einsum("epi,epq,eqj->eij", frames, select_frame, frames)
    direct = np.einsum("epi,epq,eqj->eij", frames, direct_frame, frames)
    return ContactRows(select, direct, np.zeros((n, 3)), ("closed", every, mixed))


def _modified_dense(rows, dense):
    return rows.modify_dense(dense)


@pytest.mark.parametrize("plane", sorted(PLANES))
def test_contact_rows_that_keep_the_modes_apart_use_each_part(plane):
    """Closed elements (normal rows replaced): each part's modified ILU (the shear part's
    only for a right-hand side with shear), and GMRES with it solves ``S A + D`` as the dense
    LU does; rows that mix the modes take the whole-tensor operator's."""
    from hmatddm.coupled.elastic import ElasticSolver
    from hmatddm.elasticity.planar import split_rows

    mesh = _mesh(plane, n=8)
    dense = hd.ElasticityOperator(mesh, MATERIAL).to_dense()
    op = PlanarElasticityOperator(mesh, MATERIAL, eps=1e-8)
    full = hd.ElasticityOperator(mesh, MATERIAL, backend="hmatrix", eps=1e-8)
    n, rng = mesh.n_elements, np.random.default_rng(1)
    rows = _closed_rows(mesh, 3)
    assert split_rows(rows, mesh.frames) is not None
    opening_rhs = (rng.normal(size=n)[:, None] * mesh.normals).ravel()
    op.modified_inverse(rows)(opening_rhs)
    assert op.shear_hmatrix is None  # an opening right-hand side never builds the shear part
    for rhs in (opening_rhs, rng.normal(size=3 * n)):
        exact = np.linalg.solve(_modified_dense(rows, dense), rhs)
        solution, iterations = ElasticSolver(op, rtol=1e-11).solve(rhs, rows=rows)
        assert np.linalg.norm(solution - exact) <= 1e-6 * np.linalg.norm(exact)
        # as good a preconditioner as the whole tensor's ILU of the same rows
        assert iterations <= ElasticSolver(full, rtol=1e-11).solve(rhs, rows=rows)[1] + 1
    assert op._full is None  # the 3 x 3 operator was never built
    mixed = _closed_rows(mesh, 3, mixed=True)
    assert split_rows(mixed, mesh.frames) is None
    r = rng.normal(size=3 * n)
    np.testing.assert_array_equal(op.modified_inverse(mixed)(r), full.modified_inverse(mixed)(r))
    exact = np.linalg.solve(_modified_dense(mixed, dense), r)
    solution, _ = ElasticSolver(op, rtol=1e-11).solve(r, rows=mixed)
    assert np.linalg.norm(solution - exact) <= 1e-6 * np.linalg.norm(exact)


def test_a_grown_planar_operator_matches_the_dense_one_and_reuses_the_last_border(pair):
    mesh, dense = pair
    n = mesh.n_elements
    sizes = (n - 30, n - 12, n)  # the base, a first growth pass, a second
    base = PlanarElasticityOperator(mesh.subset(np.arange(sizes[0])), MATERIAL, eps=1e-6)
    first = PlanarExtendedOperator(base, mesh.subset(np.arange(sizes[1])))
    grown = PlanarExtendedOperator(base, mesh, previous=first)
    fresh = PlanarExtendedOperator(base, mesh)
    assert grown._normal.n_reused == sizes[1] - sizes[0]
    opening = (np.cos(mesh.centers[:, 0])[:, None] * mesh.normals).ravel()
    x = np.random.default_rng(2).normal(size=3 * n)
    for vector, parts in ((opening, None), (x, "shear")):
        exact = dense @ vector
        product = grown @ vector
        assert np.linalg.norm(product - exact) <= 1e-5 * np.linalg.norm(exact)
        np.testing.assert_allclose(product, fresh @ vector, rtol=0, atol=1e-12 * np.abs(exact).max())
        assert (grown._shear is None) == (parts is None)
    index = np.arange(n)
    np.testing.assert_array_equal(grown.element_diagonal_blocks(), dense.reshape(n, 3, n, 3)[index, :, index, :])
    rhs = dense @ x
    solution, info = grown.solve(rhs, rtol=1e-10)
    assert info["converged"] and np.linalg.norm(solution - x) <= 1e-5 * np.linalg.norm(x)
    # contact rows that keep the modes apart: each part's block-triangular modified inverse,
    # and GMRES with it solves S A + D as the dense LU does
    from hmatddm.coupled.elastic import ElasticSolver

    rows = _closed_rows(mesh, 4)
    for rhs in (opening, x):
        exact = np.linalg.solve(_modified_dense(rows, dense), rhs)
        solution, iterations = ElasticSolver(grown, rtol=1e-11).solve(rhs, rows=rows)
        assert np.linalg.norm(solution - exact) <= 1e-5 * np.linalg.norm(exact)
        whole = ElasticSolver(ExtendedElasticityOperator(base, mesh), rtol=1e-11).solve(rhs, rows=rows)[1]
        assert iterations <= whole + 1, (iterations, whole)
    assert grown._full is None
    # rows that mix them: the whole-tensor extension of the same base
    mixed = _closed_rows(mesh, 4, mixed=True)
    np.testing.assert_array_equal(grown.modified_inverse(mixed)(x),
                                  ExtendedElasticityOperator(base, mesh).modified_inverse(mixed)(x))


def test_refuses_what_does_not_split():
    with pytest.raises(InputError, match="one plane"):
        PlanarElasticityOperator(hd.mesh.concatenate([_mesh("horizontal"), _mesh("tilted")]), MATERIAL)
    with pytest.raises(InputError, match="backend"):
        PlanarElasticityOperator(_mesh("horizontal"), MATERIAL, backend="dense")
    medium = hd.LayeredMedium([10.0], [10e9, 20e9], [0.25, 0.25])
    with pytest.raises(InputError, match="homogeneous"):
        PlanarElasticityOperator(_mesh("horizontal"), medium)


def test_a_growing_planar_run_is_the_same_with_the_parts_apart_or_together(monkeypatch):
    """Without the lattice operator, the simulation builds the split operator for a planar
    mesh; the run matches the one with the 3 x 3 operator to the GMRES tolerance (the
    H-matrices differ within eps), and both match the lattice's FFT operator (exact), which
    the simulation takes by default for this mesh."""
    from hmatddm.elasticity.lattice import LatticePlanarOperator

    runs = {"grown": []}
    grow = growing_operator.GrowingOperator.__call__

    def recorded(self, mesh):
        operator = grow(self, mesh)
        runs["grown"].append(operator)
        return operator

    monkeypatch.setattr(growing_operator.GrowingOperator, "__call__", recorded)
    for split in ("lattice", True, False):
        monkeypatch.setattr(growing_operator, "LATTICE_PLANAR", split == "lattice")
        monkeypatch.setattr(growing_operator, "SPLIT_PLANAR_MODES", bool(split))
        start = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 6.0, 6.0, 3, 3)
        simulation = hd.Simulation(start, hd.Elastic(24e9, 0.25), hd.Fluid(1e-3, 4.4e-10),
                                   [hd.Cluster((0, 0, 0), 0.01, 0.005)], far_field_stress=np.diag([0, 0, -8e6]),
                                   time_step=1.0, propagation=hd.Propagation(toughness=5e6),
                                   initial_pressure=10e6, initial_opening=1e-5, backend="hmatrix", eps=1e-6)
        records = simulation.run(6.0)
        runs[split] = records, simulation.operators.base
    (split_records, split_base), (whole_records, whole_base) = runs[True], runs[False]
    lattice_records, lattice_base = runs["lattice"]
    assert isinstance(lattice_base, LatticePlanarOperator) and lattice_base.shear_hmatrix is None
    assert isinstance(split_base, PlanarElasticityOperator) and split_base.shear_hmatrix is None
    assert not isinstance(split_base, LatticePlanarOperator)
    assert any(isinstance(o, PlanarExtendedOperator) for o in runs["grown"])
    assert not isinstance(whole_base, PlanarElasticityOperator)
    assert split_records[-1]["n_elements"] > 9  # it grew
    for records in (whole_records, lattice_records):
        assert [r["n_elements"] for r in split_records] == [r["n_elements"] for r in records]
        for a, b in zip(split_records, records):
            np.testing.assert_allclose(a["wellbore_pressure"], b["wellbore_pressure"], rtol=1e-6)
            np.testing.assert_allclose(a["max_opening"], b["max_opening"], rtol=1e-5)


def _planar_run(**kwargs):
    start = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 6.0, 6.0, 3, 3)
    return hd.Simulation(start, hd.Elastic(24e9, 0.25), hd.Fluid(1e-3, 4.4e-10), [hd.Cluster((0, 0, 0), 0.01, 0.005)],
                         far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                         propagation=hd.Propagation(toughness=5e6), initial_pressure=10e6, initial_opening=1e-5,
                         backend="hmatrix", eps=1e-6, **kwargs)


@pytest.mark.parametrize("split", ["lattice", True, False])
def test_a_resumed_planar_run_repeats_the_uninterrupted_one(tmp_path, monkeypatch, split):
    """The resumed run rebuilds the interrupted run's split base (GrowingOperator.restore);
    the lattice operator's kernel table depends on the mesh's box alone."""
    monkeypatch.setattr(growing_operator, "LATTICE_PLANAR", split == "lattice")
    monkeypatch.setattr(growing_operator, "SPLIT_PLANAR_MODES", bool(split))
    whole = _planar_run().run(6.0)
    _planar_run(checkpoint_dir=tmp_path).run(3.0)
    resumed = _planar_run(checkpoint_dir=tmp_path).run(6.0, resume=True)
    assert [r["step"] for r in resumed] == [r["step"] for r in whole]
    assert resumed[-1]["n_elements"] == whole[-1]["n_elements"] > 9
    for a, b in zip(whole, resumed):
        assert a["wellbore_pressure"] == b["wellbore_pressure"] and a["max_opening"] == b["max_opening"]


def test_the_border_of_a_grown_planar_crack_is_counted_by_the_parts_built():
    """A grown planar operator's border stores 1 entry per element pair for the opening
    part (and 4 more with the shear part), not the whole tensor's 9: the rebuild rule
    (RebuildSettings.border_fits) counts what is stored."""
    mesh = _mesh("horizontal")
    op = PlanarElasticityOperator(mesh, MATERIAL, eps=1e-6)
    assert op.border_entries_per_pair == 1
    op @ np.ones(op.shape[1])  # a product with shear: the shear part is built
    assert op.shear_hmatrix is not None and op.border_entries_per_pair == 5
