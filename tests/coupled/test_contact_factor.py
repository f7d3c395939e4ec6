"""The low-rank (Woodbury) update of the contact-modified dense matrix ``S A + D``
(hmatddm.coupled.contact_factor) against a fresh dense factorisation of the same rows."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.coupled import ElasticSolver, SchemeSettings, solve_step
from hmatddm.coupled import contact_factor as cf
from hmatddm.coupled.contact import OPEN, SLIP, STICK, ContactLaw, ContactModel

MATERIAL = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)


def _model(mesh, elastic, status, seed):
    n, d = mesh.n_elements, mesh.dim
    rng = np.random.default_rng(seed)
    law = ContactLaw(np.ones(n, bool), np.full(n, 0.6), np.full(n, 1e5))
    direction = np.zeros((n, d))
    slip = status == SLIP
    tangent = np.stack([-mesh.normals[:, 1], mesh.normals[:, 0]], axis=1) if d == 2 else None
    if d == 2:
        direction[slip] = tangent[slip] * rng.choice([-1.0, 1.0], size=(np.count_nonzero(slip), 1))
    return ContactModel(law, mesh.normals, rng.normal(scale=1e-4, size=(n, d)), status, direction,
                        elastic.normal_stiffness(mesh.normals))


def _dense_modified(operator, rows):
    return operator.to_dense() if rows is None else rows.modify_dense(operator.to_dense())


def _schur_columns(mesh, rows):
    n, d = mesh.n_elements, mesh.dim
    columns = np.zeros((n, d, n))
    columns[np.arange(n), :, np.arange(n)] = mesh.normals
    columns = columns.reshape(n * d, n)
    return columns if rows is None else rows.modify_rows(columns, 0)


def _check_against_dense(operator, mesh, updated, rows, rng, tolerance=1e-10):
    """``updated``'s solve and ``(S A + D)^-1 S B`` against numpy's dense solves."""
    dense = _dense_modified(operator, rows)
    r = rng.normal(size=dense.shape[0])
    exact = np.linalg.solve(dense, r)
    np.testing.assert_allclose(updated.solve(r), exact, rtol=0, atol=tolerance * np.abs(exact).max())
    x0, w, f = updated.inverse_times_b(mesh.normals)
    columns = x0 if w is None else x0 + w @ f
    expected = np.linalg.solve(dense, _schur_columns(mesh, rows))
    np.testing.assert_allclose(columns, expected, rtol=0, atol=tolerance * np.abs(expected).max())


def test_updated_solves_and_schur_columns_match_a_fresh_factorisation(monkeypatch):
    """Statuses that change a few elements at a time (the base kept), then many at once
    (a new base): every solve and ``(S A + D)^-1 S B`` agree with the LU of the same rows."""
    mesh = hd.mesh.line([-5.0, 0.0], [5.0, 0.0], 40)
    operator = hd.ElasticityOperator(mesh, MATERIAL, backend="dense")
    elastic = ElasticSolver(operator)
    n = mesh.n_elements
    rng = np.random.default_rng(3)
    status = np.full(n, OPEN)
    ranks = []
    for it in range(12):
        if it == 8:  # past MAX_RANK_FRACTION: a new base
            status = rng.choice([OPEN, STICK, SLIP], size=n)
        else:
            flip = rng.choice(n, size=3, replace=False)
            status[flip] = rng.choice([OPEN, STICK, SLIP], size=3)
        rows = _model(mesh, elastic, status.copy(), it).rows()
        updated = elastic.contact_update(rows)
        ranks.append(updated.rank)
        _check_against_dense(operator, mesh, updated, rows, rng, tolerance=1e-9)
    assert max(ranks[:8]) > 0           # updates did serve
    assert elastic.contact_factor.bases_made >= 2        # ... and the big change made a new base
    assert ranks[8] == 0


def test_an_ill_conditioned_update_makes_a_new_base(monkeypatch):
    """A capacitance matrix below MIN_RCOND is not used: the rows become a new base."""
    mesh = hd.mesh.line([-5.0, 0.0], [5.0, 0.0], 20)
    operator = hd.ElasticityOperator(mesh, MATERIAL, backend="dense")
    elastic = ElasticSolver(operator)
    n = mesh.n_elements
    status = np.full(n, OPEN)
    elastic.contact_update(_model(mesh, elastic, status, 0).rows() if status.any() else None)
    status[4] = STICK
    monkeypatch.setattr(cf, "MIN_RCOND", 2.0)  # no capacitance is that well conditioned
    updated = elastic.contact_update(_model(mesh, elastic, status, 0).rows())
    assert updated.rank == 0 and elastic.contact_factor.bases_made == 2


def test_a_growth_pass_borders_the_previous_solves_base():
    """A mesh grown by appended elements (a growth pass of the same step): its first base is
    the previous solve's, bordered by the new rows (no new factorisation), and its solves,
    its ``(S A + D)^-1 S B`` and the columns solved for the updates (bordered too) agree
    with the LU of the same rows; statuses changed meanwhile are the update's rows."""
    line = hd.mesh.line([-5.0, 0.0], [5.0, 0.0], 40)
    grown = hd.mesh.concatenate([line, hd.mesh.line([5.0, 0.0], [6.0, 0.0], 4)])
    rng = np.random.default_rng(11)
    bases = cf.ContactBases()
    operator = hd.ElasticityOperator(line, MATERIAL, backend="dense")
    elastic = ElasticSolver(operator, contact_bases=bases)
    status = rng.choice([OPEN, STICK, SLIP], size=line.n_elements)
    rows = _model(line, elastic, status, 0).rows()
    _check_against_dense(operator, line, elastic.contact_update(rows), rows, rng)
    flip = np.flatnonzero(status != SLIP)[:2]  # (the slip directions' draws stay the same)
    status[flip] = np.where(status[flip] == OPEN, STICK, OPEN)  # an update: columns of M_0^-1 solved for them
    rows = _model(line, elastic, status, 0).rows()
    assert elastic.contact_update(rows).rank > 0
    _check_against_dense(operator, line, elastic.contact_update(rows), rows, rng)
    assert bases.last is elastic.contact_factor and elastic.contact_factor.bases_made == 1

    operator_grown = hd.ElasticityOperator(grown, MATERIAL, backend="dense")
    np.testing.assert_array_equal(operator_grown.to_dense()[:80, :80], operator.to_dense())  # the leading block
    elastic_grown = ElasticSolver(operator_grown, contact_bases=bases)
    status_grown = np.concatenate([status, [OPEN, OPEN, STICK, STICK]])
    changed = np.flatnonzero(status != SLIP)[5]
    status_grown[changed] = np.where(status_grown[changed] == OPEN, STICK, OPEN)
    rows = _model(grown, elastic_grown, status_grown, 0).rows()
    updated = elastic_grown.contact_update(rows)
    factor = elastic_grown.contact_factor
    assert factor.bases_made == 0 and factor.bases_bordered == 1
    assert len(factor.base.levels.levels) == 2  # the previous LU and one border level
    assert set(updated.changed) >= {flip[0], flip[1], changed}
    _check_against_dense(operator_grown, grown, updated, rows, rng)

    # the same mesh again (a pass that only linked elements): the same factors, no new level
    again = ElasticSolver(operator_grown, contact_bases=bases)
    updated = again.contact_update(rows)
    assert again.contact_factor.bases_bordered == 1 and len(again.contact_factor.base.levels.levels) == 2
    _check_against_dense(operator_grown, grown, updated, rows, rng)

    # a matrix whose leading block is not the previous one's: a new factorisation
    other = ElasticSolver(hd.ElasticityOperator(grown, hd.Elastic(shear_modulus=11e9, poisson_ratio=0.25),
                                                backend="dense"), contact_bases=bases)
    rows = _model(grown, other, status_grown, 0).rows()
    other.contact_update(rows)
    assert other.contact_factor.bases_made == 1 and other.contact_factor.bases_bordered == 0


def _pressurised_step(pressure_peak):
    """One "krylov" step of an inclined crack, closed and stuck at the start, drained at a
    pressure that peaks at its centre: its middle opens, its flanks slip or stick, and the
    statuses settle over several iterations, a few elements at a time."""
    from test_contact import MATERIAL as material, STRESS_2D, _inclined_crack
    from hmatddm.coupled import StepProblem
    from hmatddm.flow import LeakOff, LubricationModel, fracture_compliance
    from hmatddm.mesh import topology

    mesh, _ = _inclined_crack(n=60)
    n, d = mesh.n_elements, mesh.dim
    operator = hd.ElasticityOperator(mesh, material, backend="dense")
    faces = topology.element_faces(mesh, topology.element_edges(mesh, 1.0))
    flow = LubricationModel(areas=mesh.areas, normals=mesh.normals, faces=faces, fluid=hd.Fluid(1e-3, 1e-9),
                            leak_off=LeakOff(), injection_elements=np.array([0]), injection_rates=np.zeros(1),
                            wellbore_volumes=np.zeros(1), minimum_width=1e-5)
    elastic = ElasticSolver(operator)
    s = np.linspace(-1.0, 1.0, n)
    pressure = 5e6 + pressure_peak * np.exp(-(s / 0.3) ** 2)
    law = ContactLaw(np.ones(n, bool), np.full(n, 0.6), np.full(n, 1e5))
    contact = ContactModel(law, mesh.normals, np.zeros((n, d)), np.full(n, STICK), np.zeros((n, d)),
                           elastic.normal_stiffness(mesh.normals))
    problem = StepProblem(elastic=elastic, normals=mesh.normals, far_field=-(mesh.normals @ STRESS_2D.T).ravel(),
                          flow=flow, compliance=fracture_compliance(mesh, material), dt=1.0, width_old=np.zeros(n),
                          pressure_old=pressure, leak_off_rate=np.zeros(n), contact=contact, fixed_pressure=pressure)
    settings = SchemeSettings(scheme="krylov", tolerance_pressure=1e-9, tolerance_opening=1e-9, linear_rtol=1e-12)
    dd, p, info = solve_step(problem, settings, np.zeros(n * d), pressure, 1.0)
    return dd, p, info, contact, elastic.contact_factor


def test_a_step_with_updated_factors_matches_one_with_fresh_factorisations(monkeypatch):
    """The coupled "krylov" step whose statuses change over its iterations: with updates
    (the default) and with a new factorisation for every set of statuses
    (``MAX_RANK_FRACTION`` 0, the path before the updates) the same statuses, DDs and
    pressures to the solver tolerance, in as many iterations."""
    results = {}
    for fraction in (0.0, cf.MAX_RANK_FRACTION):
        monkeypatch.setattr(cf, "MAX_RANK_FRACTION", fraction)
        results[fraction] = _pressurised_step(20e6)
    (dd_fresh, p_fresh, info_fresh, contact_fresh, factor_fresh), (dd, p, info, contact, factor) = results.values()
    assert info_fresh["contact_changes"] > 0 and info["nonlinear_iterations"] > 2
    assert 0 < np.count_nonzero(contact.status == OPEN) < contact.n  # a mixed active set
    np.testing.assert_array_equal(contact.status, contact_fresh.status)
    assert info["nonlinear_iterations"] == info_fresh["nonlinear_iterations"]
    # (the all-stuck start and the statuses after its first iterate: two bases either way;
    # the three sets after them are updates of the second)
    assert factor_fresh.bases_made >= 4 and factor.bases_made == 2
    assert info["linear_iterations"] == info_fresh["linear_iterations"]
    np.testing.assert_allclose(p, p_fresh, rtol=1e-9)
    np.testing.assert_allclose(dd, dd_fresh, rtol=0, atol=1e-8 * np.abs(dd_fresh).max())


def test_a_3d_growth_pass_borders_the_previous_solves_base():
    """The same in 3D (three unknowns an element): a vertical fracture of 6 x 4 squares grown
    by a column of 4, open and stuck elements."""
    plane = hd.mesh.rectangle([0.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 6.0, 4.0, 6, 4)
    grown = hd.mesh.concatenate([plane, hd.mesh.rectangle([3.5, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 1.0, 4.0, 1, 4)])
    rng = np.random.default_rng(12)
    bases = cf.ContactBases()
    operator = hd.ElasticityOperator(plane, MATERIAL, backend="dense")
    elastic = ElasticSolver(operator, contact_bases=bases)
    status = rng.choice([OPEN, STICK], size=plane.n_elements)
    rows = _model(plane, elastic, status, 0).rows()
    _check_against_dense(operator, plane, elastic.contact_update(rows), rows, rng)
    operator_grown = hd.ElasticityOperator(grown, MATERIAL, backend="dense")
    elastic_grown = ElasticSolver(operator_grown, contact_bases=bases)
    status_grown = np.concatenate([status, [OPEN, STICK, OPEN, STICK]])
    status_grown[7] = OPEN if status_grown[7] == STICK else STICK
    rows = _model(grown, elastic_grown, status_grown, 0).rows()
    updated = elastic_grown.contact_update(rows)
    assert elastic_grown.contact_factor.bases_bordered == 1 and elastic_grown.contact_factor.bases_made == 0
    assert list(updated.changed) == [7]
    _check_against_dense(operator_grown, grown, updated, rows, rng)


@pytest.mark.filterwarnings("ignore::hmatddm.errors.MeshQualityWarning")  # (the scene's near pair, expected)
def test_a_network_run_with_bordered_bases_matches_one_that_factorises_every_base(monkeypatch):
    """The dfn-3cluster scene's first 12 s (23 growth passes through the network, contact
    on every element): with the growth passes' bases bordered (the default) and with a new
    factorisation for every solve, the same mesh, DDs and pressures to round-off."""
    import hmatddm.scene as hs

    bordered = []
    original = cf.ContactFactor._bordered

    def counted(self, select, direct):
        base = original(self, select, direct)
        bordered.append(base is not None)
        return base

    def run():
        simulation = hs.build_simulation(hs.load_scene("dfn-3cluster", overrides=["numerics.end_time=12"]).data)
        simulation.run(12.0)
        return simulation.state

    monkeypatch.setattr(cf.ContactFactor, "_bordered", counted)
    state = run()
    assert sum(bordered) >= 10
    monkeypatch.setattr(cf.ContactFactor, "_bordered", lambda self, select, direct: None)
    fresh = run()
    assert state.mesh.n_elements == fresh.mesh.n_elements
    np.testing.assert_allclose(state.pressure, fresh.pressure, rtol=0, atol=1e-10 * np.abs(fresh.pressure).max())
    np.testing.assert_allclose(state.dd, fresh.dd, rtol=0, atol=1e-9 * np.abs(fresh.dd).max())
