"""Proppant in the time loop (issue 34, hmatddm.simulation.proppant_step): the mass balance of
every step, concentrations within [0, c_max], a bridged tip that stays clean, new elements that
start empty, the slurry viscosity fed to the flow, the packed bed's width in the contact rows,
and a checkpoint that resumes to the same proppant."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.coupled.contact import OPEN, STICK, ContactLaw, ContactModel
from hmatddm.errors import InputError
from hmatddm.flow import LubricationModel, Proppant, PumpSchedule
from hmatddm.flow.proppant import slurry_viscosity_factor
from hmatddm.mesh import topology

SAND = Proppant(diameter=2e-4, bridging_factor=2.0)
SCHEDULE = PumpSchedule((0.0, 2.0, 5.0), (0.0, 0.15, 0.3))


def vertical_run(checkpoint_dir=None, proppant=SAND, schedule=SCHEDULE, fluid=None):
    """A vertical fracture (x-z plane) growing radially from a 3 m square: pad for 2 s, then sand."""
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 3.0, 3.0, 3, 3)
    fluid = hd.Fluid(viscosity=0.02, compressibility=4.4e-10) if fluid is None else fluid
    return hd.Simulation(mesh, hd.Elastic(10e9, 0.25), fluid, [hd.Cluster((0, 0, 0), rate=0.01, wellbore_volume=0.005)],
                         -np.diag([10e6, 8e6, 12e6]), 1.0, propagation=hd.Propagation(toughness=1e6),
                         initial_pressure=8e6, initial_opening=1e-4, backend="dense", proppant=proppant,
                         pump_schedule=schedule, checkpoint_dir=checkpoint_dir)


def opening(sim):
    return np.sum(sim.state.dd * sim.state.mesh.normals, axis=1)


@pytest.fixture(scope="module")
def stepped():
    """Eight steps, with the state before and after each."""
    sim = vertical_run()
    steps = []
    for _ in range(8):
        before = (opening(sim), sim.state.proppant_volume.copy())
        record = sim.step()
        steps.append((before, (opening(sim), sim.state.proppant_volume.copy()), record))
    return sim, steps


def test_mass_is_balanced_to_round_off_every_step(stepped):
    sim, steps = stepped
    density = SAND.density
    for _, (_, volume), record in steps:
        # pumped by hand: q c(t) over the step, from the stage table (0 before t = 2 s)
        pumped = 0.01 * (0.15 * (min(record["time"], 5.0) - 2.0 if record["time"] > 2.0 else 0.0)
                         + 0.3 * max(record["time"] - 5.0, 0.0))
        assert record["proppant_injected_mass"] == pytest.approx(density * pumped, rel=1e-12, abs=1e-12)
        assert record["proppant_mass"] == pytest.approx(density * volume.sum(), rel=1e-15)
        total = record["proppant_mass"] + record["proppant_screened_mass"]
        assert abs(record["proppant_injected_mass"] - total) <= 1e-10 * max(record["proppant_injected_mass"], 1e-30)
        assert record["proppant_residual"] == pytest.approx(record["proppant_injected_mass"] - total, abs=1e-12)
    assert steps[-1][2]["proppant_mass"] > 30.0 and steps[-1][2]["proppant_screened_mass"] == 0.0


def test_no_negative_or_over_packed_concentration(stepped):
    sim, steps = stepped
    for _, (width, volume), record in steps:
        mesh_areas = sim.state.mesh.areas[:len(volume)]
        slurry = mesh_areas * np.maximum(width, sim.minimum_width)
        assert np.all(volume >= 0.0)
        assert np.all(volume <= SAND.packing_limit * slurry * (1.0 + 1e-12))
        assert 0.0 <= record["max_proppant_fraction"] <= SAND.packing_limit
    # the pumped stage is carried: the injection element holds about the pumped 0.3
    assert steps[-1][2]["max_proppant_fraction"] == pytest.approx(0.3, rel=0.05)


def test_proppant_stays_behind_a_bridged_tip(stepped):
    sim, steps = stepped
    bridge = SAND.bridging_factor * SAND.diameter
    clean_tips = 0
    for (width_old, volume_old), (width_new, volume_new), _ in steps:
        n_old = len(width_old)
        old = np.concatenate([width_old, np.zeros(len(width_new) - n_old)])
        before = np.concatenate([volume_old, np.zeros(len(width_new) - n_old)])
        narrow = np.maximum(np.maximum(old, width_new), sim.minimum_width) < bridge
        # every face of a narrow element is bridged: its proppant does not change in the step
        np.testing.assert_array_equal(volume_new[narrow], before[narrow])
        clean_tips += int(np.count_nonzero(narrow & (volume_new == 0.0)))
    assert clean_tips > 0
    # at the end: the narrow tip ring holds no sand, the wide channel does
    width, volume = steps[-1][1]
    assert np.all(volume[width < bridge] == 0.0) and np.count_nonzero(width < bridge) >= 8
    assert np.all(volume[width > 2.0 * bridge] > 0.0)


def test_grown_elements_start_empty_and_resume_gives_the_same_proppant(tmp_path):
    whole = vertical_run()
    whole.run(6.0)
    parted = vertical_run(checkpoint_dir=tmp_path)
    parted.run(4.0)
    n4 = parted.state.mesh.n_elements
    resumed = vertical_run(checkpoint_dir=tmp_path)
    resumed.load_checkpoint()
    assert resumed.state.proppant_injected_volume == parted.state.proppant_injected_volume
    np.testing.assert_array_equal(resumed.state.proppant_volume, parted.state.proppant_volume)
    resumed.run(6.0)
    np.testing.assert_array_equal(resumed.state.proppant_volume, whole.state.proppant_volume)
    assert resumed.records[-1]["proppant_mass"] == whole.records[-1]["proppant_mass"]
    assert resumed.state.mesh.n_elements > n4  # it grew after the resume
    # a checkpoint of another schedule is another run
    other = vertical_run(checkpoint_dir=tmp_path, schedule=PumpSchedule((0.0,), (0.1,)))
    with pytest.raises(hd.CheckpointError):
        other.load_checkpoint()


def test_state_joined_appends_empty_elements():
    sim = vertical_run()
    state = sim.state
    state.proppant_volume[:] = 1e-4
    from hmatddm.simulation.state import NewElements

    new = NewElements.hydraulic(hd.mesh.rectangle([5, 0, 0], [1, 0, 0], [0, 0, 1], 2.0, 1.0, 2, 1),
                                np.array([0, 1]))
    joined = state.joined(new, np.zeros((2, 3)), 1.0)
    np.testing.assert_array_equal(joined.proppant_volume, np.concatenate([np.full(9, 1e-4), [0.0, 0.0]]))


def test_slurry_viscosity_scales_the_conductivity_like_a_thicker_fluid():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 4.0, 1.0, 4, 1)
    faces = topology.element_faces(mesh)
    width = np.array([1e-3, 2e-3, 1.5e-3, 1e-3])
    pressure = np.array([4e5, 3e5, 2.5e5, 1e5])
    c = np.array([0.1, 0.3, 0.3, 0.0])
    factor = slurry_viscosity_factor(c, 0.6)
    assert factor[1] == pytest.approx((1.0 - 0.5) ** -2)  # Maron-Pierce by hand
    for fluid, thicker in ((hd.Fluid(viscosity=0.02), lambda f: hd.Fluid(viscosity=0.02 * f)),
                           (hd.Fluid(rheology="power-law", consistency=0.1, flow_index=0.5),
                            lambda f: hd.Fluid(rheology="power-law", consistency=0.1 * f, flow_index=0.5))):
        def model(fl, f=None):
            return LubricationModel(mesh.areas, mesh.normals, faces, fl, hd.LeakOff(), np.array([0]),
                                    np.array([0.0]), np.array([0.0]), 1e-5, viscosity_factor=f)
        slurry = model(fluid, factor).face_flux(width, pressure)
        for e in range(faces.n_faces):  # each face against a clean fluid of its mean viscosity
            mean = 0.5 * (factor[faces.first[e]] + factor[faces.second[e]])
            assert slurry[e] == pytest.approx(model(thicker(mean)).face_flux(width, pressure)[e], rel=1e-12)
        np.testing.assert_array_equal(model(fluid, np.ones(4)).face_flux(width, pressure),
                                      model(fluid).face_flux(width, pressure))


def test_a_closed_element_keeps_the_width_of_its_packed_bed():
    normals = np.array([[0.0, 1.0], [0.0, 1.0]])
    law = ContactLaw(np.ones(2, bool), np.zeros(2), np.zeros(2))
    propped = np.array([4e-4, 0.0])
    contact = ContactModel(law, normals, np.zeros((2, 2)), np.array([STICK, STICK]), np.zeros((2, 2)),
                           np.array([1e10, 1e10]), propped_width=propped)
    rows = contact.rows()
    dd = np.array([[0.0, 4e-4], [0.0, 0.0]])  # opening = the bed's width; the other closed shut
    traction = np.random.default_rng(1).normal(size=4)
    np.testing.assert_allclose(rows.apply(traction, dd.ravel()), rows.rhs(traction), rtol=1e-12)
    # an open element with a bed closes when it opens less than the bed's width
    opened = ContactModel(law, normals, np.zeros((2, 2)), np.array([OPEN, OPEN]), np.zeros((2, 2)),
                          np.array([1e10, 1e10]), propped_width=propped)
    opened.update(np.array([0.0, 1e-4, 0.0, 5e-3]), np.zeros(4))
    assert list(opened.status) == [STICK, OPEN]


def test_bad_proppant_arguments_are_refused():
    with pytest.raises(InputError, match=r"proppant\.diameter must be > 0"):
        Proppant(diameter=-1e-4)
    with pytest.raises(InputError, match=r"pump_schedule must be an hmatddm\.flow\.PumpSchedule"):
        vertical_run(schedule=None)
    with pytest.raises(InputError, match=r"pump_schedule concentrations must be below proppant\.packing_limit"):
        vertical_run(proppant=Proppant(diameter=2e-4, packing_limit=0.25))


def test_packed_bed_stays_when_the_fracture_closes_on_it():
    # a fixed KGD crack (plan view) pumped with slurry for 6 s, then shut in: leak-off drains it
    # and its elements close (contact = "all") onto the proppant they hold, at its packed width
    sand = Proppant(diameter=1e-4, bridging_factor=1.0)
    sim = hd.Simulation(hd.mesh.line([-5.0, 0.0], [5.0, 0.0], 10), hd.Elastic(10e9, 0.25),
                        hd.Fluid(viscosity=0.05, compressibility=4.4e-10), [hd.Cluster((0.0, 0.0), rate=2e-3)],
                        -np.diag([10e6, 5e6]), 1.0, leak_off=hd.LeakOff(coefficient=1e-11),
                        initial_pressure=5e6, initial_opening=1e-4, minimum_width=1e-6, contact="all",
                        backend="dense", proppant=sand, pump_schedule=PumpSchedule((0.0,), (0.3,)))
    sim.run(6.0)
    pumped = sim.records[-1]["proppant_injected_mass"]
    assert np.count_nonzero(sim.state.proppant_volume > 0.0) >= 8  # spread along the open crack
    assert sim.records[-1]["proppant_mass"] == pytest.approx(pumped)
    sim.clusters = [hd.Cluster((0.0, 0.0), rate=0.0)]  # shut-in
    sim.run(40.0)
    from hmatddm.simulation.proppant_step import propped_width

    closed = sim.state.contact_status != OPEN
    width = opening(sim)
    bed = propped_width(sim, sim.state)
    assert np.count_nonzero(closed) >= 5
    assert np.all(bed[closed] > 2e-5)  # they hold proppant: closed, not shut
    np.testing.assert_allclose(width[closed], bed[closed], rtol=1e-6)  # at the packed bed's width
    assert sim.records[-1]["proppant_injected_mass"] == pumped  # nothing pumped after the shut-in
    assert abs(sim.records[-1]["proppant_mass"] - pumped) <= 1e-10 * pumped  # the bed stays


def test_asymptotic_front_with_a_power_law_slurry_balances_its_mass():
    # the kgd-power-law set-up (plan view: no settling), sand from 3 s on; the front's own step
    # path (hmatddm.simulation.asymptotic) moves the proppant too
    fluid = hd.Fluid(compressibility=4.5e-10, rheology="power-law", consistency=0.1, flow_index=0.5)
    sand = Proppant(diameter=1e-4, bridging_factor=2.0)
    sim = hd.Simulation(hd.mesh.line([-1.5, 0.0], [1.5, 0.0], 3), hd.Elastic(10e9, 0.25), fluid,
                        [hd.Cluster((0.0, 0.0), 5e-4, 0.5)], far_field_stress=np.diag([-1e6, -0.5e6]), time_step=3.0,
                        propagation=hd.Propagation(toughness=0.05e6, front="asymptotic"), initial_pressure=1e6,
                        initial_opening=1e-4, backend="dense", proppant=sand,
                        pump_schedule=PumpSchedule((0.0, 3.0), (0.0, 0.2)))
    records = sim.run(18.0)
    assert records[-1]["n_elements"] > 6
    for record in records:
        pumped = record["proppant_injected_mass"]
        assert pumped == pytest.approx(2650.0 * 5e-4 * 0.2 * max(record["time"] - 3.0, 0.0), rel=1e-12, abs=1e-12)
        assert abs(pumped - record["proppant_mass"] - record["proppant_screened_mass"]) <= 1e-10 * max(pumped, 1e-30)
        assert 0.0 <= record["max_proppant_fraction"] <= sand.packing_limit
    assert records[-1]["proppant_mass"] > 0.0 and records[-1]["propped_elements"] >= 3


def test_sand_settles_down_a_vertical_fracture_and_neutral_grains_do_not():
    def centroid(density):
        sim = vertical_run(proppant=Proppant(diameter=3e-4, density=density, bridging_factor=2.0),
                           schedule=PumpSchedule((0.0,), (0.1,)))
        sim.run(6.0)
        volume = sim.state.proppant_volume
        return float(volume @ sim.state.mesh.centers[:, 2] / volume.sum()), volume.sum()

    neutral, _ = centroid(1000.0)  # as dense as the fluid: no settling, symmetric about z = 0
    sinking, _ = centroid(2650.0)  # v_Stokes = 1650 g d^2 / (18 * 0.02) = 4 mm/s
    assert abs(neutral) < 1e-9
    assert -0.2 < sinking < -1e-3


def test_the_next_step_sees_the_slurry_viscosity(stepped):
    from hmatddm.simulation.proppant_step import viscosity_factor

    sim, steps = stepped
    width, volume = steps[-1][1]
    factor = viscosity_factor(sim, sim.state, width)
    c = volume / (sim.state.mesh.areas * np.maximum(width, sim.minimum_width))
    np.testing.assert_allclose(factor, (1.0 - c / 0.6) ** -2, rtol=1e-12)  # Maron-Pierce, below its cap
    assert factor.max() == pytest.approx(4.0, rel=0.1)  # the 0.3 stage at the well: (1 - 0.5)^-2
    assert np.all(factor[volume == 0.0] == 1.0)
