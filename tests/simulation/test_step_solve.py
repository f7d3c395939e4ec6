"""One pass of a time step (hmatddm.simulation.step_solve): the growth decided on a
solve's first iterate (``growth_check = "first"``) against every solve converged."""
import numpy as np
import pytest

import hmatddm as hd


def radial(backend, growth_check, h=1.5):
    """Ref. Table 4.1's K case (thin fluid: toughness dominated) on a coarse mesh, 8 s."""
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3 * h, 3 * h, 3, 3)
    sim = hd.Simulation(mesh, hd.Elastic(24e9, 0.25), hd.Fluid(1e-5, 4.4e-10), [hd.Cluster((0, 0, 0), 0.01, 0.005)],
                        far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                        propagation=hd.Propagation(toughness=5e6), initial_pressure=10e6, initial_opening=1e-5,
                        backend=backend, eps=1e-6, scheme=hd.SchemeSettings(growth_check=growth_check))
    return sim, sim.run(8.0)


@pytest.mark.parametrize("backend", ["dense", "hmatrix"])
def test_growth_on_the_first_iterate_grows_the_same_mesh_for_fewer_iterations(backend):
    runs = {check: radial(backend, check) for check in ("converged", "first")}
    (sim_c, converged), (sim_f, first) = runs["converged"], runs["first"]
    assert sum(r["growth_passes"] for r in converged) >= 5  # the fracture grew, pass after pass
    assert [r["n_elements"] for r in first] == [r["n_elements"] for r in converged]
    np.testing.assert_array_equal(sim_f.state.mesh.centers, sim_c.state.mesh.centers)
    # every step still ends on a converged solve: the same state within the tolerance 1e-6
    for a, b in zip(converged, first):
        np.testing.assert_allclose(b["max_opening"], a["max_opening"], rtol=1e-5)
        np.testing.assert_allclose(b["wellbore_pressure"], a["wellbore_pressure"], rtol=1e-5)
    np.testing.assert_allclose(sim_f.state.dd, sim_c.state.dd, atol=1e-5 * np.abs(sim_c.state.dd).max())
    iterations = {check: sum(r["nonlinear_iterations"] for r in records) for check, (_, records) in runs.items()}
    assert iterations["first"] < iterations["converged"]
    if backend == "hmatrix":  # against the dense path
        sim_d, dense = radial("dense", "first")
        assert [r["n_elements"] for r in dense] == [r["n_elements"] for r in first]
        for a, b in zip(dense, first):
            np.testing.assert_allclose(b["max_opening"], a["max_opening"], rtol=1e-5)
            np.testing.assert_allclose(b["wellbore_pressure"], a["wellbore_pressure"], rtol=1e-5)


def test_growth_decided_on_a_paused_iterate_grows_the_same_mesh_for_fewer_gmres_iterations(monkeypatch):
    # the default: a provisional solve's first GMRES solve pauses at provisional_linear_rtol
    # (1e-4), its growth decided there unless a tip is within PAUSED_MARGIN of K_Ic;
    # provisional_linear_rtol = first_linear_rtol is the unpaused first iterate of before.
    # Same meshes, same states within the tolerance, fewer GMRES iterations. (The diagonal
    # compliance split, as the hmatrix backend's: with the exact Schur complement of a small
    # dense mesh every GMRES solve takes ~2 iterations, and a pause saves none -- 42 and 42.)
    from hmatddm.coupled import step_problem

    monkeypatch.setattr(step_problem, "EXACT_SCHUR_MAX_ELEMENTS", 0)
    runs = {}
    for name, rtol in (("paused", None), ("unpaused", 1e-6)):
        mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.5, 4.5, 3, 3)
        scheme = hd.SchemeSettings() if rtol is None else hd.SchemeSettings(provisional_linear_rtol=rtol)
        sim = hd.Simulation(mesh, hd.Elastic(24e9, 0.25), hd.Fluid(1e-5, 4.4e-10),
                            [hd.Cluster((0, 0, 0), 0.01, 0.005)], far_field_stress=np.diag([0, 0, -8e6]),
                            time_step=1.0, propagation=hd.Propagation(toughness=5e6), initial_pressure=10e6,
                            initial_opening=1e-5, backend="dense", scheme=scheme)
        runs[name] = sim, sim.run(8.0)
    (sim_p, paused), (sim_u, unpaused) = runs["paused"], runs["unpaused"]
    assert sum(r["growth_passes"] for r in paused) >= 5
    assert [r["n_elements"] for r in paused] == [r["n_elements"] for r in unpaused]
    np.testing.assert_array_equal(sim_p.state.mesh.centers, sim_u.state.mesh.centers)
    for a, b in zip(unpaused, paused):
        np.testing.assert_allclose(b["max_opening"], a["max_opening"], rtol=1e-5)
        np.testing.assert_allclose(b["wellbore_pressure"], a["wellbore_pressure"], rtol=1e-5)
    assert sum(r["linear_iterations"] for r in paused) < sum(r["linear_iterations"] for r in unpaused)


def test_a_growth_pass_with_a_margin_refuses_to_decide_near_the_threshold():
    from hmatddm.simulation import growth_pass
    from hmatddm.simulation.records import StepTally
    from hmatddm.simulation.step_solve import mesh_topology

    sim, _ = radial("dense", "first")
    state = sim.state
    edges, faces = mesh_topology(state.mesh, sim.height)
    decide = lambda margin: growth_pass.grow(sim, state, edges, faces, None, StepTally().events, margin)  # noqa: E731
    assert decide(10.0) is growth_pass.UNCERTAIN      # every tip is within 10 of K_Ic
    plain = decide(None)
    assert decide(0.0) is not growth_pass.UNCERTAIN   # no tip exactly at K_Ic
    assert (plain is None) == (decide(0.0) is None)
