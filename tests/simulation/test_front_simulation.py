"""Simulations with the asymptotic front (Propagation(front="asymptotic")): radial and KGD
fractures against the closed-form vertex solutions, a round front, both backends, resume
from a checkpoint, and the setups it refuses."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError

MATERIAL = hd.Elastic(24e9, 0.25)


def radial(h=1.0, backend="hmatrix", toughness=1e6, viscosity=1e-3, opening=4e-6, time_step=1.0, **kwargs):
    """Ref. Table 4.1 (M case by default) with 3 x 3 initial elements of side h."""
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3 * h, 3 * h, 3, 3)
    return hd.Simulation(mesh, MATERIAL, hd.Fluid(viscosity, 4.4e-10), [hd.Cluster((0, 0, 0), 0.01, 0.005)],
                         far_field_stress=np.diag([0, 0, -8e6]), time_step=time_step,
                         propagation=hd.Propagation(toughness=toughness, front="asymptotic"),
                         initial_pressure=10e6, initial_opening=opening, backend=backend, **kwargs)


def test_radial_m_vertex_early_growth_is_round_and_conserves_volume():
    sim = radial(backend="dense")  # ~180 elements: dense is the faster backend (hmatrix: the next test)
    records = sim.run(6.0)
    radius, width = hd.analytical.radial_m_vertex(6.0, 0.01, 1e-3, MATERIAL)
    last = records[-1]
    injection = sim.injection_elements[0]
    centre = float(sim.state.dd[injection] @ sim.state.mesh.normals[injection])
    # R ~ 8 elements at 6 s: -2.2% / +1.6% against the M vertex computed to 1e-7 (-1.7% / +1.9%
    # against Dontsov's constants, 0.49% / 0.26% low, before issue 39); the h = 1 m run at 30 s
    # is in benchmarks/RESULTS.md; the element switch gives +7% here
    assert abs(last["radius"] / radius - 1.0) < 0.025
    assert abs(centre / width - 1.0) < 0.03
    assert last["front_circularity"] < 1.05
    assert last["fracture_volume"] == pytest.approx(last["injected_volume"], rel=0.01)
    assert np.all(np.isfinite(sim.state.front_distance[np.isfinite(sim.state.front_distance)]))


def test_auto_steps_reproduce_the_m_vertex_and_the_fixed_steps():
    """Front-following steps (numerics.time_step = "auto") on the radial M case: the same
    closed-form tolerance as the fixed 1 s steps and close to their answer, in fewer
    element-sized steps. Its first 0.1 s step from the 3 x 3 start cycles with period two and
    is split (issue 33: the asymptotic front's steps go through the retry of the element
    front's); -2.3% / +1.1% against -2.2% / +1.6% for the fixed steps at 6 s."""
    from hmatddm.simulation.step_control import StepControl

    runs = {}
    for label, options in (("fixed", {}), ("auto", dict(time_step="auto", step_control=StepControl(first=0.1)))):
        sim = radial(backend="dense", **options)
        records = sim.run(6.0)
        injection = sim.injection_elements[0]
        runs[label] = (records, float(sim.state.dd[injection] @ sim.state.mesh.normals[injection]))
    radius, width = hd.analytical.radial_m_vertex(6.0, 0.01, 1e-3, MATERIAL)
    for records, centre in runs.values():
        assert records[-1]["time"] == 6.0
        assert abs(records[-1]["radius"] / radius - 1.0) < 0.025
        assert abs(centre / width - 1.0) < 0.03
    (fixed, fixed_centre), (auto, auto_centre) = runs["fixed"], runs["auto"]
    assert auto[-1]["radius"] == pytest.approx(fixed[-1]["radius"], rel=0.005)
    assert auto_centre == pytest.approx(fixed_centre, rel=0.01)
    assert auto[0]["time_step"] < 0.1 and auto[0]["step_retries"] >= 1  # the split first step
    steps = [r["time_step"] for r in auto[:-1]]  # (the last one cut to end at 6 s)
    assert max(steps) > 1.0  # the steps grow with the front's pace


def test_dense_and_hmatrix_runs_agree():
    # each run's nonlinear solves stop within the tolerance 1e-6 of their fixed point, on
    # iterates that differ with the backend (the forcing term solves them to the changes'
    # accuracy, not to 1e-9): the two runs agree to twice the tolerance, the mesh exactly
    runs = [radial(h=2.0, backend=backend).run(3.0) for backend in ("dense", "hmatrix")]
    for dense, hmatrix in zip(*runs):
        assert dense["n_elements"] == hmatrix["n_elements"]
        assert hmatrix["radius"] == pytest.approx(dense["radius"], rel=2e-6)
        assert hmatrix["wellbore_pressure"][0] == pytest.approx(dense["wellbore_pressure"][0], rel=2e-6)


def test_a_front_iteration_after_an_easy_solve_starts_at_a_grown_relaxation(monkeypatch):
    # the alpha one trial front needed is not kept for the next trial fronts: each solve that
    # converged without a restart lets the next start at relaxation_growth times its alpha (as a
    # step does). Kept, an alpha of 1/128 from one bad trial front contracted the radial M~ run's
    # iteration by ~0.996 per iteration, and its full-tolerance solves failed one after the other
    # (tests/scene/test_leak_off_reference.py, benchmarks/RESULTS.md issue 33)
    from dataclasses import replace
    from hmatddm.simulation.asymptotic import AsymptoticFront

    calls = []
    solve = AsymptoticFront._solve

    def recorded(self, sim, trial, start, prescribed, width, t_old, t_new, relaxation, *args, **kwargs):
        out = solve(self, sim, trial, start, prescribed, width, t_old, t_new, relaxation, *args, **kwargs)
        calls.append((relaxation, out[1]["relaxation"], out[1]["restarts"]))
        return out

    monkeypatch.setattr(AsymptoticFront, "_solve", recorded)
    sim = radial(h=2.0, backend="dense")
    sim.state = replace(sim.state, relaxation=0.25)
    sim.run(1.0)
    assert len(calls) >= 3 and calls[0][0] == 0.25
    for (_, alpha, restarts), (start, _, _) in zip(calls, calls[1:]):
        assert start == (min(1.0, 2.0 * alpha) if restarts == 0 else alpha)
    assert calls[-1][0] > calls[0][0]


def test_an_asymptotic_front_step_that_does_not_converge_is_split(monkeypatch):
    """The asymptotic front's steps go through the same retry as the element front's: a
    step whose solve raises ConvergenceError is redone in halves from the same state (the
    radial-m scene with auto steps at 1 m elements: its first 0.1 s step from the 3 x 3 start
    cycled with period two, its halves converge), and the run comes back to its grid."""
    from hmatddm.errors import ConvergenceError
    from hmatddm.simulation.asymptotic import AsymptoticFront

    solve = AsymptoticFront._solve

    def refuses_long_steps(self, sim, trial, start, prescribed, width, t_old, t_new, *args):
        if t_new - t_old > 1.5:
            raise ConvergenceError("too long a step for this test", iterations=1)
        return solve(self, sim, trial, start, prescribed, width, t_old, t_new, *args)

    monkeypatch.setattr(AsymptoticFront, "_solve", refuses_long_steps)
    split = radial(h=2.0, backend="dense", time_step=2.0)
    first = split.step()
    assert first["time"] == 1.0 and first["step_retries"] == 1
    dd = split.state.dd.copy()
    records = split.run(4.0)  # (every record of the run)
    assert [r["time"] for r in records] == [1.0, 2.0, 3.0, 4.0]  # back on the grid of 2 s steps
    monkeypatch.setattr(AsymptoticFront, "_solve", solve)
    halves = radial(h=2.0, backend="dense", time_step=1.0)
    assert halves.step()["step_retries"] == 0
    np.testing.assert_array_equal(dd, halves.state.dd)  # the same step as a fresh 1 s one


def test_resume_from_checkpoint_gives_the_same_run(tmp_path):
    whole = radial(h=2.0, backend="dense").run(3.0)
    first = radial(h=2.0, backend="dense", checkpoint_dir=tmp_path)
    first.run(2.0)
    resumed = radial(h=2.0, backend="dense", checkpoint_dir=tmp_path)
    records = resumed.run(3.0, resume=True)
    assert records[-1]["radius"] == pytest.approx(whole[-1]["radius"], rel=1e-9)
    assert records[-1]["n_elements"] == whole[-1]["n_elements"]


@pytest.mark.parametrize("toughness, tolerance", [(5e6, 0.02), (0.2e6, 0.03)])
def test_kgd_vertices(toughness, tolerance):
    # ref. Table 4.2 setup with K_Ic 5 MPa m^1/2 (K_m = 4.9: K-vertex) and 0.2 MPa m^1/2 (K_m =
    # 0.2: M-vertex), 1 m segments, 24 s (half-length ~7 and ~13 elements): measured +0.3% / +0.7%
    # (K) and +1.9% / +0.6% (M; +1.2% / 0.0% at 100 s, benchmarks/RESULTS.md). The semi-infinite
    # asymptote without the finite-fracture factor gives -3.4% / +3.0% for the K-vertex here
    material = hd.Elastic(10e9, 0.25)
    sim = hd.Simulation(hd.mesh.line([-1.5, 0.0], [1.5, 0.0], 3), material, hd.Fluid(1e-3, 4.5e-10),
                        [hd.Cluster((0.0, 0.0), 5e-4, 0.5)], far_field_stress=np.diag([-1e6, -0.5e6]), time_step=2.0,
                        propagation=hd.Propagation(toughness=toughness, front="asymptotic"), initial_pressure=1e6,
                        initial_opening=1e-4, backend="dense")
    records = sim.run(24.0)
    if toughness > 1e6:
        half_length, width, _ = hd.analytical.kgd_k_vertex(24.0, 5e-4, toughness, material)
    else:
        half_length, width, _ = hd.analytical.kgd_m_vertex(24.0, 5e-4, 1e-3, material)
    assert abs(records[-1]["half_length"] / half_length - 1.0) < tolerance
    assert abs(records[-1]["max_opening"] / width - 1.0) < 0.02


@pytest.mark.parametrize("front", ["asymptotic", "element"])
def test_growth_past_max_elements_is_refused_and_keeps_the_last_step(front):
    # 3 x 3 elements of 2 m: the first step's growth needs more than 12 elements
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 6.0, 6.0, 3, 3)
    sim = hd.Simulation(mesh, MATERIAL, hd.Fluid(1e-3, 4.4e-10), [hd.Cluster((0, 0, 0), 0.01, 0.005)],
                        far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                        propagation=hd.Propagation(toughness=1e6, front=front), initial_pressure=10e6,
                        initial_opening=4e-6, backend="dense", max_elements=12)
    with pytest.raises(hd.errors.SizeLimitError, match="max_elements = 12") as caught:
        sim.run(3.0)
    assert caught.value.limit == 12 and caught.value.elements > 12
    assert sim.state.mesh.n_elements <= 12 and len(sim.records) == sim.state.step


def test_unsupported_setups_are_refused():
    with pytest.raises(InputError, match="front"):
        hd.Propagation(toughness=1e6, front="level-set")
    power_law = hd.Fluid(compressibility=4.4e-10, rheology="power-law", consistency=0.01, flow_index=0.5)
    with pytest.raises(InputError, match="leak-off.*power-law"):
        hd.Simulation(hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 3), MATERIAL, power_law,
                      [hd.Cluster((0, 0, 0), 0.01)], np.diag([0, 0, -8e6]), 1.0,
                      propagation=hd.Propagation(toughness=1e6, front="asymptotic"),
                      leak_off=hd.LeakOff(coefficient=1e-12))
    with pytest.raises(InputError, match="contact"):
        radial(contact="all")
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 3)
    other = hd.mesh.rectangle([0, 0, 5], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 3)
    two = hd.mesh.concatenate([mesh, hd.Mesh3D(other.centers, other.frames, other.half_a, other.half_b,
                                               np.ones(9, np.int64))])
    with pytest.raises(InputError, match="one planar fracture"):
        hd.Simulation(two, MATERIAL, hd.Fluid(1e-3), [hd.Cluster((0, 0, 0), 0.01)], np.diag([0, 0, -8e6]), 1.0,
                      propagation=hd.Propagation(toughness=1e6, front="asymptotic"))
    oblong = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 6)
    with pytest.raises(InputError, match="square"):
        hd.Simulation(oblong, MATERIAL, hd.Fluid(1e-3), [hd.Cluster((0, 0, 0), 0.01)], np.diag([0, 0, -8e6]), 1.0,
                      propagation=hd.Propagation(toughness=1e6, front="asymptotic"))


def kgd_k_errors(h, end=40.0):
    """RMS relative errors (half-length, opening at the well, opening-weighted net pressure)
    over 20 s..end of the KGD K-vertex run (the kgd scene: K_m 8.7) on segments of h."""
    material = hd.Elastic(10e9, 0.25)
    n = int(round(3.0 / h)) | 1  # an odd count: the well at an element's centre
    sim = hd.Simulation(hd.mesh.line([-n * h / 2, 0.0], [n * h / 2, 0.0], n), material, hd.Fluid(1e-4, 4.5e-10),
                        [hd.Cluster((0.0, 0.0), 5e-4, 0.5)], far_field_stress=np.diag([-1e6, -0.5e6]),
                        time_step=1.0, propagation=hd.Propagation(toughness=5e6, front="asymptotic"),
                        initial_pressure=1e6, initial_opening=1e-6, backend="dense")
    errors = []
    for record in sim.run(end):
        if record["time"] >= 20.0:
            exact = hd.analytical.kgd_k_vertex(record["time"], 5e-4, 5e6, material)
            measured = (record["half_length"], record["max_opening"], record["mean_pressure"] - 0.5e6)
            errors.append([m / e - 1.0 for m, e in zip(measured, exact)])
    return np.sqrt(np.mean(np.square(errors), axis=0))


def test_kgd_k_vertex_errors_fall_when_the_mesh_is_refined():
    # issue 39: with the ribbon read next to the front (a filled segment joined the channel at
    # once) the front ran an element ahead after each crossing, then stalled, and the errors
    # grew with refinement: RMS over 20-60 s 0.98 / 1.26 / 2.54% at 1 m, 1.17 / 1.31 / 2.58% at
    # 0.5 m (half-length, opening, net pressure). Measured now over 20-40 s: 0.85 / 0.13 / 1.06%
    # at 1 m, 0.77 / 0.09 / 0.78% at 0.5 m (2.7 s and 2.4 s CPU)
    coarse, fine = kgd_k_errors(1.0), kgd_k_errors(0.5)
    assert np.all(fine < coarse), (coarse, fine)
    assert np.all(coarse < [0.01, 0.02, 0.03])


def test_kgd_m_vertex_has_no_offset_from_the_ribbon():
    # issue 39: the ribbon read next to a viscous front (s_r in [0.5, 1.5] h) is +7% too wide on
    # average whatever h (an independent solve: +26% at 0.5 h, +2.6% at h), and the KGD M-vertex
    # run converged to a fracture ~0.4% too long and ~0.25% too thin. With the ribbon 1.5 h behind
    # the front once the half-length is 20 elements: K_m 0.003, incompressible, no wellbore
    # storage (the vertex has none), 0.25 m, 0.5 s steps, 40 s (l = 34 h): measured l -0.14%, w0
    # +0.07%, p(0) +0.06% (the near ribbon: +0.59%, -0.46%, -0.73%); 3 s CPU
    material = hd.Elastic(10e9, 0.25)
    sim = hd.Simulation(hd.mesh.line([-1.625, 0.0], [1.625, 0.0], 13), material, hd.Fluid(0.1, 0.0),
                        [hd.Cluster((0.0, 0.0), 5e-4, 0.0)], far_field_stress=np.diag([-1e6, -0.5e6]), time_step=0.5,
                        propagation=hd.Propagation(toughness=1e4, front="asymptotic"), initial_pressure=1e6,
                        initial_opening=1e-6, backend="dense")
    record = sim.run(40.0)[-1]
    half_length, width, pressure = hd.analytical.kgd_m_vertex(40.0, 5e-4, 0.1, material)
    assert abs(record["half_length"] / half_length - 1.0) < 0.003
    assert abs(record["max_opening"] / width - 1.0) < 0.002
    assert abs((record["wellbore_pressure"][0] - 0.5e6) / pressure - 1.0) < 0.003


def test_3d_ribbon_stays_c_h_behind_the_front_once_resolved(monkeypatch):
    # issue 39: in 3D too a filled element joins the channel only c h behind the front (1.5 h at
    # a viscous tip) once the radius is resolved_tip elements; lowered here to 4 so that a 1 m
    # run of ~8 elements in radius shows it (bench_asymptotic_ribbon.py --penny: the ribbon next
    # to the front, s_r in [0.5, 1.5] h, reads +4-5% wide at a viscous tip, +2-3% at Sneddon's).
    # Measured: the ribbon 2.6, 2.4, 2.2 h behind the front at 4, 5, 6 s; with the near ribbon
    # (far_ribbon_3d = False) 1.04, 1.51, 1.27 h; ~1 s CPU
    from hmatddm.fracture.front import FILLED
    from hmatddm.simulation.asymptotic import AsymptoticFront

    monkeypatch.setattr(AsymptoticFront, "resolved_tip", 4.0)
    seen = []

    def check(sim, record):
        ribbon = np.isfinite(sim.state.front_distance)
        seen.append((record["radius"], float(np.min(sim.state.front_distance[ribbon])),
                     int(np.count_nonzero(sim.state.front_class == FILLED))))

    sim = radial(backend="dense")
    sim.run(6.0, callback=check)
    far = [i for i, (radius, _, _) in enumerate(seen) if radius >= 4.0]
    assert len(far) >= 3
    # the steps after the first far one: the ribbon the near rule left behind is passed by then
    assert all(seen[i][1] >= 1.5 - 1e-9 for i in far[2:]), seen
    assert all(seen[i][2] > 0 for i in far[1:]), seen  # filled elements kept out of the channel
    assert seen[-1][0] == pytest.approx(hd.analytical.radial_m_vertex(6.0, 0.01, 1e-3, MATERIAL)[0], rel=0.03)
