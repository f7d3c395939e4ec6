"""The four coupling schemes on one time step (ref. Sec. 4.4): same answer, dense twin,
scaling of ref. Eqs 4.53-4.61 (Fig. 4.13)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.mesh import topology
from hmatddm.coupled import ElasticSolver, SchemeSettings, StepProblem, solve_step
from hmatddm.coupled import step_problem
from hmatddm.coupled.scaled_system import FlowFactor, _CoupledLinearSystem
from hmatddm.flow import LeakOff, LubricationModel, fracture_compliance


def _problem(mesh, backend="dense", dt=1.0, height=1.0, rate=5e-4, leak=0.0, viscosity=1e-3):
    mat = hd.Elastic(10e9, 0.25)
    fluid = hd.Fluid(viscosity=viscosity, compressibility=4.5e-10)
    faces = topology.element_faces(mesh, height=height)
    areas = mesh.areas * (height if mesh.dim == 2 else 1.0)
    flow = LubricationModel(areas=areas, normals=mesh.normals, faces=faces, fluid=fluid,
                            leak_off=LeakOff(coefficient=leak, pore_pressure=0.5e6),
                            injection_elements=np.array([mesh.n_elements // 2]), injection_rates=np.array([rate]),
                            wellbore_volumes=np.array([0.5]), minimum_width=1e-5)
    op = hd.ElasticityOperator(mesh, mat, backend=backend, eps=1e-8, leaf_size=8)
    stress = np.zeros((mesh.dim, mesh.dim))
    stress[-1, -1] = -0.5e6
    n = mesh.n_elements
    width_old = 1e-4 * (1 - (mesh.centers[:, 0] / (1.05 * np.abs(mesh.centers[:, 0]).max())) ** 2)
    problem = StepProblem(elastic=ElasticSolver(op, rtol=1e-11), normals=mesh.normals,
                          far_field=-(mesh.normals @ stress.T).ravel(), flow=flow,
                          compliance=fracture_compliance(mesh, mat), dt=dt, width_old=width_old,
                          pressure_old=np.full(n, 1e6), leak_off_rate=flow.leak_off_rate(np.zeros(n), 0.0, dt))
    guess = (width_old[:, None] * mesh.normals).ravel()
    return problem, guess, np.full(n, 1e6)


@pytest.fixture(scope="module")
def reference_step():
    mesh = hd.mesh.line([-5, 0], [5, 0], 20)
    problem, dd0, p0 = _problem(mesh, leak=1e-12)
    settings = SchemeSettings(scheme="krylov", tolerance_pressure=1e-9, tolerance_opening=1e-9, linear_rtol=1e-12)
    dd, p, info = solve_step(problem, settings, dd0, p0, 1.0)
    return mesh, dd, p, info


@pytest.mark.parametrize("scheme", ["fixed-width", "fracture-compliance", "fully-coupled"])
def test_schemes_reach_the_same_step_solution(reference_step, scheme):
    mesh, dd_ref, p_ref, _ = reference_step
    problem, dd0, p0 = _problem(mesh, leak=1e-12)
    settings = SchemeSettings(scheme=scheme, tolerance_pressure=1e-9, tolerance_opening=1e-9,
                              linear_rtol=1e-12, max_iterations=3000)
    dd, p, info = solve_step(problem, settings, dd0, p0, 1.0)
    # a converged relaxed iteration stops within about tol/alpha of the fixed point
    tolerance = 1e-9 / info["relaxation"] * 20
    np.testing.assert_allclose(p, p_ref, rtol=tolerance)
    np.testing.assert_allclose(dd, dd_ref, atol=tolerance * np.abs(dd_ref).max())


def test_step_conserves_mass(reference_step):
    mesh, dd, p, _ = reference_step
    problem, _, _ = _problem(mesh, leak=1e-12)
    width = problem.width(dd)
    flow = problem.flow
    stored = np.sum(flow.areas * (width - problem.width_old))
    compressed = np.sum(4.5e-10 * (flow.areas * np.maximum(width, 1e-5) + flow.wellbore_storage()) * (p - 1e6))
    leaked = np.sum(flow.areas * problem.leak_off_rate * (p - 0.5e6)) * problem.dt
    np.testing.assert_allclose(stored + compressed + leaked, 5e-4 * problem.dt, rtol=1e-6)


def test_relaxation_ordering_of_the_segregated_schemes():
    # ref. Figs 4.11-4.15: the fixed-width split needs more relaxation than the
    # fracture-compliance split, and the coupled schemes none
    mesh = hd.mesh.line([-5, 0], [5, 0], 20)
    alphas = {}
    for scheme in ("fixed-width", "fracture-compliance", "krylov"):
        problem, dd0, p0 = _problem(mesh)
        _, _, info = solve_step(problem, SchemeSettings(scheme=scheme, max_iterations=3000), dd0, p0, 1.0)
        alphas[scheme] = info["relaxation"]
    assert alphas["fixed-width"] < alphas["fracture-compliance"] <= alphas["krylov"] == 1.0


def test_hmatrix_step_matches_dense():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    results = {}
    for backend in ("dense", "hmatrix"):
        problem, dd0, p0 = _problem(mesh, backend=backend, rate=1e-2)
        settings = SchemeSettings(scheme="krylov", tolerance_pressure=1e-9, tolerance_opening=1e-9, linear_rtol=1e-11)
        results[backend] = solve_step(problem, settings, dd0, p0, 1.0)
    np.testing.assert_allclose(results["hmatrix"][1], results["dense"][1], rtol=1e-6)
    np.testing.assert_allclose(results["hmatrix"][0], results["dense"][0], atol=1e-6 * np.abs(results["dense"][0]).max())


def test_scaling_makes_the_coupled_matrix_well_conditioned():
    # ref. Fig. 4.13: cond(A) ~ 1e19 falls to O(100) after M_1^-1 A M_2
    mesh = hd.mesh.line([-1.5, 0], [1.5, 0], 3)
    problem, dd0, p0 = _problem(mesh)
    matrix, _ = problem.flow_matrices(dd0)
    system = _CoupledLinearSystem(problem, matrix, dd0, p0)
    a = problem.elastic.operator.to_dense()
    b = np.zeros((a.shape[0], mesh.n_elements))
    for i in range(mesh.n_elements):
        b[2 * i:2 * i + 2, i] = mesh.normals[i]
    full = np.block([[a, b], [problem.coupling.toarray(), matrix.toarray()]])
    scaled = np.column_stack([system.operator @ e for e in np.eye(full.shape[0])])
    assert np.linalg.cond(full) > 1e12
    assert np.linalg.cond(scaled) < 1e3



@pytest.mark.parametrize("scheme", ["krylov", "fully-coupled"])
def test_contraction_stopping_matches_the_change_rule_within_the_tolerance(scheme, monkeypatch):
    # the default rule (stop on the extrapolated next change, first GMRES solve at
    # first_linear_rtol) against the plain one (change between iterates, every GMRES solve
    # at linear_rtol), both at the default tolerance 1e-6, and against a tight solve. A thin
    # fluid (K-vertex-like) contracts fast: the contraction rule saves an iteration there.
    # Each iterate factors its own flow block, so that the GMRES counts compare the rules
    # alone (a reused factor is tested below); the compliance split, not the exact Schur
    # complement, which solves with no GMRES iteration at any tolerance.
    monkeypatch.setattr(FlowFactor, "REUSE_LIMIT", 0)
    monkeypatch.setattr(step_problem, "EXACT_SCHUR_MAX_ELEMENTS", 0)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    tight = SchemeSettings(scheme="krylov", tolerance_pressure=1e-10, tolerance_opening=1e-10, linear_rtol=1e-12,
                           stopping="change")
    problem, dd0, p0 = _problem(mesh, rate=1e-2, viscosity=1e-5)
    dd_ref, p_ref, _ = solve_step(problem, tight, dd0, p0, 1.0)
    results = {}
    for stopping, first in (("change", 1e-12), ("contraction", 1e-6)):
        problem, dd0, p0 = _problem(mesh, rate=1e-2, viscosity=1e-5)
        settings = SchemeSettings(scheme=scheme, linear_rtol=1e-12, stopping=stopping, first_linear_rtol=first,
                                  max_iterations=3000, linear_forcing=0.0)  # the rules alone (forcing below)
        results[stopping] = solve_step(problem, settings, dd0, p0, 1.0)
    (dd_c, p_c, info_c), (dd_s, p_s, info_s) = results["contraction"], results["change"]
    tolerance = 1e-6 / info_s["relaxation"]  # a relaxed iteration stops within about tol/alpha
    for dd, p in ((dd_c, p_c), (dd_s, p_s)):
        np.testing.assert_allclose(p, p_ref, atol=tolerance * np.abs(p_ref).max())
        np.testing.assert_allclose(dd, dd_ref, atol=tolerance * np.abs(dd_ref).max())
    np.testing.assert_allclose(p_c, p_s, atol=tolerance * np.abs(p_ref).max())
    assert info_c["nonlinear_iterations"] <= info_s["nonlinear_iterations"]
    if scheme == "krylov":
        assert info_c["nonlinear_iterations"] == info_s["nonlinear_iterations"] - 1
        assert info_c["linear_iterations"] < info_s["linear_iterations"]


def test_contraction_rule_needs_a_fast_contraction():
    from hmatddm.coupled.schemes import _converged

    assert _converged("change", 0.9, []) and _converged("contraction", 0.9, [])
    assert not _converged("contraction", 100.0, [])           # no rate yet
    assert _converged("contraction", 100.0, [1e6])            # rate 1e-4: next change 0.01 tolerance
    assert _converged("contraction", 100.0, [1e5])            # rate 1e-3: 0.1 tolerance, x3 safety
    assert not _converged("contraction", 100.0, [2e4])        # rate 5e-3: 0.5 tolerance, x3 safety: no
    assert not _converged("contraction", 100.0, [2e6, 1e6])   # the rate before was 0.5: slow
    assert not _converged("contraction", 1.5, [2.0])          # rate 0.75 > 1/2: too slow to extrapolate
    assert not _converged("change", 100.0, [1e6])
    with pytest.raises(hd.errors.InputError, match="stopping"):
        SchemeSettings(stopping="guess")


def test_a_loose_first_solve_is_never_accepted():
    # a guess whose residual is already below first_linear_rtol comes back unchanged from
    # the first GMRES solve (change 0): it must still be checked at linear_rtol
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    problem, dd0, p0 = _problem(mesh, rate=1e-2, viscosity=1e-5)
    tight = SchemeSettings(scheme="krylov", tolerance_pressure=1e-10, tolerance_opening=1e-10, linear_rtol=1e-12,
                           stopping="change")
    dd_ref, p_ref, _ = solve_step(problem, tight, dd0, p0, 1.0)
    problem, _, _ = _problem(mesh, rate=1e-2, viscosity=1e-5)
    loose = SchemeSettings(scheme="krylov", linear_rtol=1e-12, first_linear_rtol=0.5)
    dd, p, info = solve_step(problem, loose, 1.01 * dd_ref, 1.001 * p_ref, 1.0)
    assert info["nonlinear_iterations"] >= 2
    np.testing.assert_allclose(p, p_ref, atol=1e-6 * np.abs(p_ref).max())
    np.testing.assert_allclose(dd, dd_ref, atol=1e-6 * np.abs(dd_ref).max())


def test_the_forcing_term_solves_loosely_but_accepts_only_an_accurate_iterate(monkeypatch):
    # linear_forcing: iterates after the first are solved to forcing x the last change
    # (fewer GMRES iterations in all), and the iterate a solve ends on to linear_rtol: the
    # same solution as every iterate at linear_rtol, within the nonlinear tolerance, and the
    # flow equations of the accepted iterate hold to linear_rtol's accuracy. (The diagonal
    # compliance split, as the hmatrix backend's: with the exact Schur complement of this small
    # dense mesh every GMRES solve takes ~2 iterations, loose or not -- 17 and 17.)
    from hmatddm.coupled import schemes

    monkeypatch.setattr(step_problem, "EXACT_SCHUR_MAX_ELEMENTS", 0)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    tolerances = []
    original = schemes._coupled_iteration

    def recorded(*args, rtol=None, **kwargs):
        tolerances.append(rtol)
        return original(*args, rtol=rtol, **kwargs)

    monkeypatch.setattr(schemes, "_coupled_iteration", recorded)
    results = {}
    for forcing in (0.0, 0.1):
        problem, dd0, p0 = _problem(mesh, rate=1e-2, viscosity=1e-3)
        settings = SchemeSettings(scheme="krylov", linear_rtol=1e-12, linear_forcing=forcing)
        tolerances.clear()
        dd, p, info = solve_step(problem, settings, dd0, p0, 1.0)
        matrix, rhs = problem.flow_matrices(dd, p)
        flow_residual = np.abs(problem.coupling @ dd + matrix @ p - rhs).max() / np.abs(rhs).max()
        results[forcing] = dd, p, info, list(tolerances), flow_residual
    dd_0, p_0, info_0, rtols_0, residual_0 = results[0.0]
    dd_f, p_f, info_f, rtols_f, residual_f = results[0.1]
    assert all(rtol is None for rtol in rtols_0)
    assert any(rtol is not None and rtol > 1e-12 for rtol in rtols_f)  # some iterates were solved loosely
    assert rtols_f[-1] is None  # ... not the accepted one
    assert info_f["linear_iterations"] < info_0["linear_iterations"]
    np.testing.assert_allclose(p_f, p_0, atol=2e-6 * np.abs(p_0).max())
    np.testing.assert_allclose(dd_f, dd_0, atol=2e-6 * np.abs(dd_0).max())
    assert residual_f < 1e-6 and residual_0 < 1e-6
    with pytest.raises(hd.errors.InputError, match="linear_forcing"):
        SchemeSettings(linear_forcing=1.0)


@pytest.mark.parametrize("backend", ["dense", "hmatrix"])
def test_a_provisional_solve_finishes_with_the_iterates_of_a_plain_one(backend):
    # solve_step(provisional=True) stops after the loose first iterate; finish() continues
    # the same iteration: the converged result is bit for bit the plain solve's, and the
    # two infos add up to its counts. The hmatrix backend is checked against the dense one.
    # (provisional_linear_rtol = first_linear_rtol: the provisional iterate is the plain
    # solve's first one; a looser one is tested below.)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    settings = SchemeSettings(scheme="krylov", provisional_linear_rtol=1e-6)
    problem, dd0, p0 = _problem(mesh, backend=backend, rate=1e-2, viscosity=1e-5)
    dd_plain, p_plain, info_plain = solve_step(problem, settings, dd0, p0, 1.0)
    assert info_plain["pending"] is None
    problem, dd0, p0 = _problem(mesh, backend=backend, rate=1e-2, viscosity=1e-5)
    dd_first, p_first, info_first = solve_step(problem, settings, dd0, p0, 1.0, provisional=True)
    assert info_first["pending"] is not None and info_first["nonlinear_iterations"] == 1
    assert np.all(np.isfinite(p_first)) and not np.array_equal(p_first, p_plain)  # an iterate, not the answer
    dd, p, info = info_first["pending"].finish()
    assert info["pending"] is None
    np.testing.assert_array_equal(dd, dd_plain)
    np.testing.assert_array_equal(p, p_plain)
    for key in ("nonlinear_iterations", "linear_iterations", "restarts"):
        assert info_first[key] + info[key] == info_plain[key]
    if backend == "hmatrix":
        problem, dd0, p0 = _problem(mesh, backend="dense", rate=1e-2, viscosity=1e-5)
        dd_dense, p_dense, _ = solve_step(problem, settings, dd0, p0, 1.0)
        np.testing.assert_allclose(p, p_dense, atol=1e-5 * np.abs(p_dense).max())
        np.testing.assert_allclose(dd, dd_dense, atol=1e-5 * np.abs(dd_dense).max())


@pytest.mark.parametrize("backend", ["dense", "hmatrix"])
def test_a_paused_provisional_iterate_finishes_with_the_iterates_of_a_plain_one(backend, monkeypatch):
    # provisional_linear_rtol > first_linear_rtol (the default): the provisional iterate is
    # the first GMRES solve paused at provisional_linear_rtol (fewer GMRES iterations);
    # refine() continues that solve to the plain first iterate, finish() to the converged
    # one: bit for bit the plain solve's, with its counts (also when refine() is skipped).
    # (The diagonal compliance split: with the exact Schur complement of a dense mesh every
    # solve takes 2 GMRES iterations, and a pause saves none.)
    monkeypatch.setattr(step_problem, "EXACT_SCHUR_MAX_ELEMENTS", 0)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    settings = SchemeSettings(scheme="krylov", provisional_linear_rtol=1e-3)
    assert SchemeSettings().provisional_linear_rtol > SchemeSettings().first_linear_rtol
    problem, dd0, p0 = _problem(mesh, backend=backend, rate=1e-2, viscosity=1e-5)
    dd_plain, p_plain, info_plain = solve_step(problem, settings, dd0, p0, 1.0)
    problem, dd0, p0 = _problem(mesh, backend=backend, rate=1e-2, viscosity=1e-5)
    tight = SchemeSettings(scheme="krylov", provisional_linear_rtol=1e-6)
    dd_tight, p_tight, info_tight = solve_step(problem, tight, dd0, p0, 1.0, provisional=True)
    for refine in (False, True):
        problem, dd0, p0 = _problem(mesh, backend=backend, rate=1e-2, viscosity=1e-5)
        dd_first, p_first, info_first = solve_step(problem, settings, dd0, p0, 1.0, provisional=True)
        pending = info_first["pending"]
        assert pending.refinable and info_first["nonlinear_iterations"] == 1
        assert info_first["linear_iterations"] < info_tight["linear_iterations"]
        # the paused iterate is the tight first one to within the looser tolerance
        np.testing.assert_allclose(p_first, p_tight, rtol=0, atol=1e-2 * np.abs(p_tight).max())
        levels = [pending.paused_level]  # a GMRES iteration may pass more than one level
        infos = [info_first]
        if refine:  # pauses at 1e-3, 1e-4, 1e-5, then the plain first iterate (1e-6)
            while pending.refinable:
                dd_refined, p_refined, info_refined = pending.refine()
                assert info_refined["pending"] is pending and info_refined["nonlinear_iterations"] == 0
                levels.append(pending.paused_level)
                infos.append(info_refined)
            assert levels[-1] is None and set(levels[:-1]) <= {1e-3, 1e-4, 1e-5} and len(levels) >= 3
            assert levels[:-1] == sorted(levels[:-1], reverse=True)
            assert sum(i["linear_iterations"] for i in infos) == info_tight["linear_iterations"]
            np.testing.assert_array_equal(dd_refined, dd_tight)
            np.testing.assert_array_equal(p_refined, p_tight)
        dd, p, info = pending.finish()
        assert info["pending"] is None
        infos.append(info)
        np.testing.assert_array_equal(dd, dd_plain)
        np.testing.assert_array_equal(p, p_plain)
        for key in ("nonlinear_iterations", "linear_iterations", "restarts"):
            assert sum(i[key] for i in infos) == info_plain[key]
    if backend == "hmatrix":
        problem, dd0, p0 = _problem(mesh, backend="dense", rate=1e-2, viscosity=1e-5)
        dd_dense, p_dense, _ = solve_step(problem, settings, dd0, p0, 1.0)
        np.testing.assert_allclose(p, p_dense, atol=1e-5 * np.abs(p_dense).max())
        np.testing.assert_allclose(dd, dd_dense, atol=1e-5 * np.abs(dd_dense).max())


def test_a_provisional_solve_converges_at_once_without_a_loose_first_iteration():
    # segregated schemes, or first_linear_rtol == linear_rtol: nothing to stop early
    from hmatddm.coupled.schemes import PendingSolve

    mesh = hd.mesh.line([-5, 0], [5, 0], 20)
    problem, dd0, p0 = _problem(mesh, leak=1e-12)
    _, _, info = solve_step(problem, SchemeSettings(scheme="krylov", first_linear_rtol=1e-9), dd0, p0, 1.0,
                            provisional=True)
    assert info["pending"] is None and info["nonlinear_iterations"] >= 2
    for scheme in ("fixed-width", "fracture-compliance"):
        assert not PendingSolve(problem, SchemeSettings(scheme=scheme), dd0, p0, 1.0).loose_first
    with pytest.raises(hd.errors.InputError, match="growth_check"):
        SchemeSettings(growth_check="never")


@pytest.mark.parametrize("limit", [0, FlowFactor.REUSE_LIMIT])
def test_a_reused_flow_factor_gives_the_fresh_factors_solution(monkeypatch, limit):
    """The split preconditioner's flow LU kept across the iterates of a step problem: the
    same solution as a new LU at every iterate, to the solver's tolerance, and fewer
    factorisations. (The diagonal compliance split, which a dense mesh of at most
    EXACT_SCHUR_MAX_ELEMENTS replaces by the exact Schur complement and keeps no factor.)"""
    from hmatddm.coupled import scaled_system

    monkeypatch.setattr(step_problem, "EXACT_SCHUR_MAX_ELEMENTS", 0)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    factorisations = []
    splu = scaled_system.spla.splu
    monkeypatch.setattr(scaled_system.spla, "splu", lambda *a, **k: factorisations.append(1) or splu(*a, **k))
    tight = SchemeSettings(scheme="krylov", tolerance_pressure=1e-10, tolerance_opening=1e-10, linear_rtol=1e-12,
                           stopping="change")
    problem, dd0, p0 = _problem(mesh, rate=1e-2, viscosity=1e-3)
    dd_ref, p_ref, _ = solve_step(problem, tight, dd0, p0, 1.0)
    monkeypatch.setattr(FlowFactor, "REUSE_LIMIT", limit)
    factorisations.clear()
    problem, dd0, p0 = _problem(mesh, rate=1e-2, viscosity=1e-3)
    dd, p, info = solve_step(problem, SchemeSettings(scheme="krylov"), dd0, p0, 1.0)
    tolerance = 1e-6 / info["relaxation"]
    np.testing.assert_allclose(p, p_ref, atol=tolerance * np.abs(p_ref).max())
    np.testing.assert_allclose(dd, dd_ref, atol=tolerance * np.abs(dd_ref).max())
    if limit == 0:
        assert len(factorisations) == info["nonlinear_iterations"]
    else:
        assert info["nonlinear_iterations"] > 2 and len(factorisations) < info["nonlinear_iterations"]


def test_an_attempt_whose_changes_stagnate_is_given_up():
    """An attempt is given up once its changes (in tolerance units) cannot fall below 1 in
    the iterations it has left at the rate of its last iterations: stuck on an oscillation
    (the dfn-3cluster scene at t = 24 s ran 380 iterations at 4.5e-2 / 1e-6) or contracting
    too slowly; a contraction fast enough, or too short a history, goes on."""
    from hmatddm.coupled.schemes import STAGNATION_WINDOW, _stagnated

    plateau = [4.5e4 * (1.0 - 1e-3 * k) for k in range(2 * STAGNATION_WINDOW)]
    assert _stagnated(plateau, left=380)
    assert not _stagnated(plateau[:-1], left=380)  # too short to judge
    halving = [1e6 * 0.5**k for k in range(2 * STAGNATION_WINDOW)]
    assert not _stagnated(halving, left=380)
    slow = [1e6 * 0.97**k for k in range(2 * STAGNATION_WINDOW)]  # 0.97 per iteration: ~390 more to go
    assert _stagnated(slow, left=300) and not _stagnated(slow, left=1000)
    assert _stagnated([5.0, 6.0] * STAGNATION_WINDOW, left=1000)  # oscillating without contraction


def test_the_exact_schur_complement_gives_the_same_step_with_no_gmres_iteration(monkeypatch):
    """With a dense (exact) elasticity solve the "krylov" split uses the exact Schur
    complement ``D - C A^-1 B`` and the whole block LU: the system's inverse, applied once and
    checked by its residual (:class:`hmatddm.hmatrix.solvers.ExactPreconditionerSolve`), no
    GMRES iteration (the dfn-3cluster scene took 24-50 a solve with the diagonal compliance
    ``C'``), for the same step solution to the solver tolerance."""
    mesh = hd.mesh.line([-5, 0], [5, 0], 20)
    settings = SchemeSettings(scheme="krylov", tolerance_pressure=1e-9, tolerance_opening=1e-9, linear_rtol=1e-12)
    results = {}
    for limit in (0, step_problem.EXACT_SCHUR_MAX_ELEMENTS):
        monkeypatch.setattr(step_problem, "EXACT_SCHUR_MAX_ELEMENTS", limit)
        problem, dd0, p0 = _problem(mesh, leak=1e-12)
        results[limit] = solve_step(problem, settings, dd0, p0, 1.0)
    (dd_diag, p_diag, info_diag), (dd, p, info) = results.values()
    assert info["linear_iterations"] == 0 and info_diag["linear_iterations"] > 3 * info["nonlinear_iterations"]
    np.testing.assert_allclose(p, p_diag, rtol=1e-8)
    np.testing.assert_allclose(dd, dd_diag, atol=1e-8 * np.abs(dd_diag).max())


class _Oscillating:
    """A stand-in step problem and iteration whose iterates swing about 1 by
    ``amplitude(alpha)`` (relative), without ever converging: a mode the relaxation damps
    only as fast as ``amplitude`` falls with alpha."""

    contact = elastic = None

    def __init__(self, amplitude):
        self.amplitude, self.sign = amplitude, 1.0

    def update_contact(self, dd, p):
        return 0

    def iterate(self, problem, settings, dd, p, alpha, counters, **kwargs):
        self.sign = -self.sign
        return np.full_like(dd, 1.0 + self.sign * self.amplitude(alpha)), p


@pytest.mark.parametrize("damped", [False, True])
def test_a_splittable_solve_gives_up_a_relaxation_that_does_not_help(damped):
    """With ``splittable=True`` a solve whose stagnated change only halves with alpha (a
    mode the relaxation does not damp) stops after two stagnated attempts instead of going
    down to ``min_relaxation``; where halving alpha cuts it by more than RELAXATION_HELPS
    (here 8x) the ladder goes on as without the flag, to the same converged attempt."""
    from hmatddm.coupled.schemes import STAGNATION_WINDOW, PendingSolve
    from hmatddm.errors import ConvergenceError

    settings = SchemeSettings(scheme="krylov", max_iterations=400)
    counts = {}
    for splittable in (False, True):
        model = _Oscillating((lambda a: 1e-2 * a**3) if damped else (lambda a: 1e-2 * a))
        pending = PendingSolve(model, settings, np.ones(4), np.ones(2), 1.0, splittable=splittable)
        pending.iterate = model.iterate
        try:
            pending.run()
            message = "converged"
        except ConvergenceError as error:
            message = str(error)
        counts[splittable] = (pending.counters["nonlinear"], pending.alpha, message)
    segregated = SchemeSettings(scheme="fixed-width")  # its slow convergence at small alpha needs the ladder
    assert not PendingSolve(_Oscillating(abs), segregated, np.ones(4), np.ones(2), 1.0, splittable=True).splittable
    ladder = counts[False]
    if damped:  # converges at a small alpha, the same way with the flag
        assert ladder[2] == "converged" and ladder[1] <= 1.0 / 16.0
        assert counts[True] == ladder
    else:
        assert ladder[1] == settings.min_relaxation  # the whole ladder, 1 .. 1/256
        assert counts[True][0] == 2 * 2 * STAGNATION_WINDOW and counts[True][1] == 0.5
        assert "does not help" in counts[True][2] and ladder[0] > 4 * counts[True][0]


def test_drained_rows_of_the_flow_matrix_are_the_scaled_identity_rows():
    # StepProblem.flow_matrices with drained elements (fixed_pressure finite): their rows of
    # D become ``scale`` on the diagonal (the other rows' mean |diagonal|) and the right-hand
    # side ``scale p_fixed``, the other rows unchanged; the rows rescaled in the CSR arrays
    # in place give the sparse-product formula's matrix.
    import scipy.sparse as sp

    mesh = hd.mesh.line([-5, 0], [5, 0], 12)
    problem, dd, p = _problem(mesh)
    plain, plain_rhs = problem.flow_matrices(dd, p)
    fixed_pressure = np.full(mesh.n_elements, np.nan)
    fixed_pressure[[0, 5, 11]] = [1e6, 2e6, 3e6]
    problem.fixed_pressure = fixed_pressure
    problem.fixed = np.isfinite(fixed_pressure)
    matrix, rhs = problem.flow_matrices(dd, p)
    free = ~problem.fixed
    scale = np.mean(np.abs(plain.diagonal()[free]))
    expected = (sp.diags(free.astype(float)) @ plain + sp.diags(scale * problem.fixed)).toarray()
    np.testing.assert_array_equal(matrix.toarray(), expected)
    np.testing.assert_array_equal(rhs[free], plain_rhs[free])
    np.testing.assert_allclose(rhs[problem.fixed], scale * fixed_pressure[problem.fixed], rtol=1e-15)
    assert matrix.has_canonical_format and not np.shares_memory(matrix.data, plain.data)


def test_a_kept_schur_factor_refines_to_round_off_and_factorises_anew_when_refinement_fails():
    # SchurFactor: the LU of one complement serves a nearby one through iterative refinement
    # (same answer as a fresh solve to REFINED), and a complement too far from it for
    # MAX_SWEEPS sweeps is factorised anew; a different C A^-1 B array is not served.
    from hmatddm.coupled.scaled_system import SchurFactor

    rng = np.random.default_rng(3)
    n = 40
    coupled = rng.standard_normal((n, n)) * 0.1
    first = np.diag(rng.uniform(1.0, 2.0, n)) - coupled
    factor = SchurFactor(coupled)
    factor.use(first)
    r = rng.standard_normal(n)
    np.testing.assert_allclose(first @ factor.solve(r), r, rtol=0, atol=1e-12 * np.linalg.norm(r))
    near = first + np.diag(rng.uniform(0.0, 1e-5, n))  # the flow block of the next iterate
    factor.use(near)
    p = factor.solve(r)
    assert factor.factorisations == 1
    assert np.linalg.norm(r - near @ p) <= SchurFactor.REFINED * np.linalg.norm(r)
    far = first + np.diag(rng.uniform(5.0, 10.0, n))  # refinement cannot converge from the first LU
    factor.use(far)
    p = factor.solve(r)
    assert factor.factorisations == 2 and factor.factored is far
    np.testing.assert_allclose(far @ p, r, rtol=0, atol=1e-12 * np.linalg.norm(r))
    assert factor.serves(coupled) and not factor.serves(coupled.copy())
