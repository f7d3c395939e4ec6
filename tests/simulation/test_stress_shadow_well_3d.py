"""Stress shadow among radial fractures fed by one well (issue 35), in 3D: the published
trends of tests/simulation/test_stress_shadow_well.py (Bunger, Zhang and Jeffrey 2012;
Lecampion and Desroches 2015; Peirce and Bunger 2015), on the setting of those papers:
parallel radial (here square-started) fractures across a horizontal well along s_hmin (y),
4 m apart, 1 m elements, uniform rock. Three fractures: without limited entry the middle one
is starved and stays small; with it every cluster takes a third of the pump. Two fractures,
one with a head start: without limited entry the larger one takes the pump; with it both
grow. The checks are these trends (ratios), not the papers' numbers (about 10 s a run)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.flow import PumpRate, Well
from hmatddm.mesh import concatenate, rectangle

RATE = 0.012
OPEN_HOLE = dict(perforations=40, perforation_diameter=0.01)    # ~5 kPa of perforation friction
LIMITED_ENTRY = dict(perforations=3, perforation_diameter=0.006)  # ~3 MPa, above the net pressure


def array_run(sizes, perforations, spacing=4.0, steps=12):
    """Parallel square fractures of initial side ``sizes`` (m), normal to the well (y),
    ``spacing`` apart; their rate share (of an even split) and areas after ``steps`` s."""
    n = len(sizes)
    ys = spacing * (np.arange(n) - (n - 1) / 2.0)
    mesh = concatenate([rectangle([0.0, y, 0.0], [1, 0, 0], [0, 0, 1], side, side, int(side), int(side),
                                  fracture_id=k) for k, (y, side) in enumerate(zip(ys, sizes))])
    clusters = [hd.Cluster((0.0, y, 0.0), **perforations) for y in ys]
    well = Well(PumpRate((0.0,), (RATE,)), heel=(0.0, -50.0, 0.0), direction=(0.0, 1.0, 0.0), volume=0.5)
    sim = hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, 4.4e-10), clusters,
                        -np.diag([2e6, 1e6, 3e6]), 1.0, propagation=hd.Propagation(toughness=1e6, turning="none"),
                        initial_pressure=1.5e6, initial_opening=1e-5, backend="dense", well=well)
    for _ in range(steps):
        record = sim.step()
    mesh = sim.state.mesh
    areas = np.array([np.sum(mesh.areas[mesh.fracture_id == k]) for k in range(n)])
    return np.array(record["cluster_rates"]) / (RATE / n), areas, record


@pytest.fixture(scope="module")
def three():
    return {name: array_run([3.0, 3.0, 3.0], perfs) for name, perfs in
            (("open", OPEN_HOLE), ("limited", LIMITED_ENTRY))}


def test_the_middle_of_three_radial_fractures_is_starved_without_limited_entry(three):
    share, area, _ = three["open"]
    assert share[1] < 0.05 and share[0] > 1.4 and share[2] > 1.4
    assert area[1] < 0.25 * min(area[0], area[2])


def test_limited_entry_feeds_the_middle_radial_fracture(three):
    share, area, record = three["limited"]
    assert np.all(np.abs(share - 1.0) < 0.05)
    assert area[1] > 0.8 * max(area[0], area[2]) and area[1] > 4.0 * three["open"][1][1]
    assert min(record["perforation_friction"]) > 1e6 > max(three["open"][2]["perforation_friction"])


@pytest.mark.slow
def test_two_radial_fractures_with_a_head_start_one_takes_all_without_limited_entry():
    share, area, _ = array_run([3.0, 4.0], OPEN_HOLE)
    assert share[0] < 0.1 and share[1] > 1.9 and area[0] < 0.25 * area[1]
    share, area, _ = array_run([3.0, 4.0], LIMITED_ENTRY)
    assert np.all(np.abs(share - 1.0) < 0.1) and area[0] > 0.6 * area[1]
