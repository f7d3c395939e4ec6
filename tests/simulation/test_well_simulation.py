"""A well shared by clusters in the time loop (issue 35, hmatddm.flow.well): the fluid budget
closes every step, the rates and the well's storage add up to the pump's schedule, one
cluster without perforation friction is the fixed-rate run, perforation friction is the
orifice law at the converged rates, a checkpoint resumes to the same numbers."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.flow import PumpRate, Well
from hmatddm.simulation.records import fluid_moved

C_F = 4.5e-10
VOLUME = 0.5
SPACING = 5.0


def three_fractures(n_fractures=3):
    """Parallel plane-strain fractures 3 m long, ``SPACING`` apart along y (plan view)."""
    ys = SPACING * (np.arange(n_fractures) - (n_fractures - 1) / 2.0)
    xs = np.linspace(-1.5, 1.5, 4)
    p0 = np.array([[a, y] for y in ys for a in xs[:-1]])
    p1 = np.array([[b, y] for y in ys for b in xs[1:]])
    return hd.Mesh2D.from_segments(p0, p1, fracture_id=np.repeat(np.arange(n_fractures), 3)), ys


def shared_run(perforations=4, schedule=None, checkpoint_dir=None, friction_factor=0.0, n_fractures=3, scheme=None,
               grow=True):
    mesh, ys = three_fractures(n_fractures)
    clusters = [hd.Cluster((0.0, y), perforations=perforations, perforation_diameter=0.01) for y in ys]
    schedule = PumpRate((0.0,), (1.5e-3,)) if schedule is None else schedule
    well = Well(schedule, heel=(0.0, -20.0), direction=(0.0, 1.0), volume=VOLUME, diameter=0.1,
                friction_factor=friction_factor)
    extra = {} if scheme is None else dict(scheme=scheme)
    return hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, C_F), clusters, -np.diag([0.5e6, 1.0e6]), 1.0,
                         propagation=hd.Propagation(toughness=5e6) if grow else None, initial_pressure=1e6,
                         initial_opening=1e-4, backend="dense", well=well, checkpoint_dir=checkpoint_dir, **extra)


TIGHT = hd.SchemeSettings(scheme="krylov", linear_rtol=1e-12, first_linear_rtol=1e-12, tolerance_pressure=1e-9,
                          tolerance_opening=1e-9)


@pytest.fixture(scope="module")
def linear_pump():
    """Eight steps of a ramped pump (linear schedule) with wellbore friction, tight tolerances."""
    schedule = PumpRate((0.0, 4.0, 8.0), (0.5e-3, 2e-3, 1e-3), interpolation="linear")
    sim = shared_run(schedule=schedule, friction_factor=0.02, scheme=TIGHT)
    records = [sim.step() for _ in range(8)]
    return sim, records


def test_the_fluid_budget_closes_every_step_to_1e_8(linear_pump):
    sim, records = linear_pump
    schedule = sim.well.schedule
    for record in records:
        budget = record["budget"]
        assert budget["injected"] == pytest.approx(schedule.volume(0.0, record["time"]), rel=1e-13)
        assert budget["wellbore"] == pytest.approx(VOLUME * (1.0 + C_F * (record["heel_pressure"] - 1e6)), rel=1e-14)
        assert abs(budget["residual"]) <= 1e-8 * fluid_moved(budget), record["step"]


def test_the_rates_and_the_storage_add_up_to_the_pump(linear_pump):
    """sum q_c + c_f V (p_h - p_h^n) / dt = the schedule's mean rate over the step."""
    sim, records = linear_pump
    heel_old = 1e6
    for record in records:
        dt = record["time_step"]
        mean = sim.well.schedule.volume(record["time"] - dt, record["time"]) / dt
        assert record["pump_rate"] == pytest.approx(mean, rel=1e-14)
        storage = C_F * VOLUME * (record["heel_pressure"] - heel_old) / dt
        assert sum(record["cluster_rates"]) + storage == pytest.approx(mean, rel=1e-12)
        heel_old = record["heel_pressure"]


def test_the_perforation_and_wellbore_friction_are_those_of_the_converged_rates(linear_pump):
    sim, records = linear_pump
    a = 8.0 * 1000.0 / (np.pi**2 * 0.6**2 * 4**2 * 0.01**4)
    b = 8.0 * 0.02 * 1000.0 / (np.pi**2 * 0.1**5)
    for record in records:
        q = np.array(record["cluster_rates"])
        np.testing.assert_allclose(record["perforation_friction"], a * q * np.abs(q), rtol=1e-12)
        # heel at y = -20: 15 m to the first cluster carrying all three, then 5 m carrying two, one
        carried = np.cumsum(q[::-1])[::-1]
        expected = np.cumsum(b * np.array([15.0, 5.0, 5.0]) * carried * np.abs(carried))
        np.testing.assert_allclose(record["wellbore_friction"], expected, rtol=1e-5)
        np.testing.assert_allclose(record["cluster_pressures"], record["heel_pressure"] - expected, rtol=1e-9)
        # the drop across the perforations: wellbore pressure at the cluster less the fracture's
        drop = np.array(record["cluster_pressures"]) - np.array(record["wellbore_pressure"])
        np.testing.assert_allclose(record["perforation_friction"], drop, rtol=1e-5, atol=1e-3)


def test_the_outer_clusters_of_a_symmetric_well_take_equal_rates_and_the_middle_one_less(linear_pump):
    _, records = linear_pump
    rates = records[-1]["cluster_rates"]
    assert rates[1] < rates[0] and rates[1] < rates[2]
    # friction in the well favours the heel's side a little (1e-9 of the rates: the toe is 10 m further)
    assert rates[0] == pytest.approx(rates[2], rel=1e-2)


def test_one_cluster_without_perforation_friction_is_the_fixed_rate_run():
    mesh, _ = three_fractures(1)
    common = dict(propagation=hd.Propagation(toughness=5e6), initial_pressure=1e6, initial_opening=1e-4,
                  backend="dense")
    args = (mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, C_F))
    fixed = hd.Simulation(*args, [hd.Cluster((0.0, 0.0), rate=1e-3, wellbore_volume=VOLUME)], -np.diag([0.5e6, 1e6]),
                          1.0, **common)
    well = Well(PumpRate((0.0,), (1e-3,)), heel=(-10.0, 0.0), direction=(1.0, 0.0), volume=VOLUME)
    shared = hd.Simulation(*args, [hd.Cluster((0.0, 0.0))], -np.diag([0.5e6, 1e6]), 1.0, well=well, **common)
    for _ in range(5):
        a, b = fixed.step(), shared.step()
        np.testing.assert_array_equal(fixed.state.pressure, shared.state.pressure)
        np.testing.assert_array_equal(fixed.state.dd, shared.state.dd)
        assert b["heel_pressure"] == a["wellbore_pressure"][0]
        assert b["budget"] == a["budget"]
        storage = C_F * VOLUME * (b["heel_pressure"] - (shared.records[-2]["heel_pressure"] if len(shared.records) > 1
                                                         else 1e6))
        assert b["cluster_rates"][0] == pytest.approx(1e-3 - storage, rel=1e-12)


def test_one_perforated_cluster_takes_the_pump_rate_behind_its_orifice():
    mesh, _ = three_fractures(1)
    well = Well(PumpRate((0.0,), (1e-3,)), heel=(0.0, 0.0), direction=(1.0, 0.0), volume=0.0)
    sim = hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, C_F),
                        [hd.Cluster((0.0, 0.0), perforations=2, perforation_diameter=0.008, discharge_coefficient=0.8)],
                        -np.diag([0.5e6, 1e6]), 1.0, initial_pressure=1e6, initial_opening=1e-4, backend="dense",
                        well=well, scheme=TIGHT)
    a = 8.0 * 1000.0 / (np.pi**2 * 0.8**2 * 2**2 * 0.008**4)
    for _ in range(3):
        record = sim.step()
        assert record["cluster_rates"][0] == pytest.approx(1e-3, rel=1e-12)
        assert record["heel_pressure"] - record["wellbore_pressure"][0] == pytest.approx(a * 1e-6, rel=1e-8)


def test_a_checkpoint_resumes_the_well(tmp_path):
    straight = shared_run(grow=False)
    straight.run(4.0)
    first = shared_run(checkpoint_dir=tmp_path, grow=False)
    first.run(2.0)
    second = shared_run(checkpoint_dir=tmp_path, grow=False)
    second.run(4.0, resume=True)
    assert second.state.heel_pressure == straight.state.heel_pressure
    np.testing.assert_array_equal(second.state.pressure, straight.state.pressure)
    assert second.records[-1]["cluster_rates"] == straight.records[-1]["cluster_rates"]


def test_clusters_need_a_rate_without_a_well_and_none_with_one():
    mesh, ys = three_fractures(1)
    args = (mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, C_F))
    with pytest.raises(InputError, match=r"cluster\[0\]\.rate is required"):
        hd.Simulation(*args, [hd.Cluster((0.0, 0.0))], -np.diag([0.5e6, 1e6]), 1.0)
    well = Well(PumpRate((0.0,), (1e-3,)), heel=(0.0, 0.0), direction=(1.0, 0.0))
    with pytest.raises(InputError, match=r"cluster\[0\]\.rate must be left out"):
        hd.Simulation(*args, [hd.Cluster((0.0, 0.0), rate=1e-3)], -np.diag([0.5e6, 1e6]), 1.0, well=well)


def test_every_scheme_gives_the_same_split():
    """The well's block in the flow matrix serves the segregated schemes as well as the coupled
    ones (fixed mesh, three steps)."""
    splits = {}
    for scheme in ("krylov", "fully-coupled", "fracture-compliance", "fixed-width"):
        sim = shared_run(scheme=scheme, grow=False)
        for _ in range(3):
            record = sim.step()
        splits[scheme] = np.array(record["cluster_rates"])
    for scheme, split in splits.items():
        np.testing.assert_allclose(split, splits["krylov"], rtol=1e-4, err_msg=scheme)
    assert splits["krylov"][1] < splits["krylov"][0]
