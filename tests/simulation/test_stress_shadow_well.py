"""Stress shadow among fractures fed by one well (issue 35), in plan view (plane strain, the
well along y = the s_hmin direction, fractures along x), against the published trends:

* Bunger, Zhang and Jeffrey (2012, SPE J. 17(1), "Parameters affecting the interaction among
  closely spaced hydraulic fractures") and Lecampion and Desroches (2015, J. Mech. Phys. Solids
  82, "Simultaneous initiation and growth of multiple radial hydraulic fractures from a
  horizontal wellbore"): without perforation friction the interior fracture of an array is
  suppressed by its neighbours' stress shadow and the flow goes to the outer ones; enough
  perforation friction (limited entry) keeps the flow near uniform and the interior fracture
  grows.
* Peirce and Bunger (2015, SPE J. 20(2), "Interference fracturing: nonuniform distributions of
  perforation clusters that promote simultaneous growth") and Lecampion and Desroches (2015):
  two fractures are unstable without entry friction, a small head start grows until one takes
  nearly all the fluid; limited entry holds both.

The checks are these trends (ratios), not the papers' numbers: their setups are radial 3D
fractures; ours are plane-strain fractures of a 1 m flow height (the scene three-clusters'
rock and fluid). A plan-view run takes about a second.
"""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.flow import PumpRate, Well

RATE = 1.5e-3
OPEN_HOLE = dict(perforations=40, perforation_diameter=0.01)   # ~100 Pa of perforation friction
LIMITED_ENTRY = dict(perforations=1, perforation_diameter=0.004)  # ~2-5 MPa, above the net pressure


def array_run(lengths, perforations, spacing=5.0, steps=20):
    """Parallel fractures of initial ``lengths`` (m), ``spacing`` apart along the well; their
    rate share (of an even split) and lengths after ``steps`` s."""
    n = len(lengths)
    ys = spacing * (np.arange(n) - (n - 1) / 2.0)
    p0, p1, ids = [], [], []
    for k, (y, length) in enumerate(zip(ys, lengths)):
        xs = np.linspace(-length / 2.0, length / 2.0, int(round(length)) + 1)
        p0 += [[a, y] for a in xs[:-1]]
        p1 += [[b, y] for b in xs[1:]]
        ids += [k] * (len(xs) - 1)
    mesh = hd.Mesh2D.from_segments(np.array(p0), np.array(p1), fracture_id=np.array(ids))
    clusters = [hd.Cluster((0.0, y), **perforations) for y in ys]
    well = Well(PumpRate((0.0,), (RATE,)), heel=(0.0, -50.0), direction=(0.0, 1.0), volume=0.5)
    sim = hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, 4.5e-10), clusters, -np.diag([0.5e6, 1.0e6]),
                        1.0, propagation=hd.Propagation(toughness=5e6, turning="none"), initial_pressure=1e6,
                        initial_opening=1e-4, backend="dense", well=well)
    for _ in range(steps):
        record = sim.step()
    mesh = sim.state.mesh
    grown = np.array([np.sum(mesh.areas[mesh.fracture_id == k]) for k in range(n)])
    return np.array(record["cluster_rates"]) / (RATE / n), grown, record


@pytest.fixture(scope="module")
def three():
    return {name: array_run([3.0, 3.0, 3.0], perfs) for name, perfs in
            (("open", OPEN_HOLE), ("limited", LIMITED_ENTRY))}


def test_the_middle_of_three_fractures_is_starved_without_limited_entry(three):
    share, length, _ = three["open"]
    assert share[1] < 0.1 and share[0] > 1.4 and share[2] > 1.4
    assert length[1] < 0.5 * min(length[0], length[2])


def test_limited_entry_feeds_the_middle_fracture(three):
    share, length, record = three["limited"]
    starved_share, starved_length, _ = three["open"]
    assert share[1] > 0.85 and np.all(np.abs(share - 1.0) < 0.15)
    assert length[1] > 2.0 * starved_length[1]
    # the perforation friction that evens the split is above the net pressure in the fractures
    assert min(record["perforation_friction"]) > 1e6 > max(three["open"][2]["perforation_friction"])


def test_identical_outer_fractures_take_identical_rates(three):
    for share, length, _ in three.values():
        assert share[0] == pytest.approx(share[2], rel=1e-9) and length[0] == length[2]


def test_two_fractures_with_a_head_start_one_takes_all_without_limited_entry():
    share, length, _ = array_run([3.0, 4.0], OPEN_HOLE)
    assert share[0] < 0.1 and share[1] > 1.9 and length[0] < 0.2 * length[1]
    share, length, _ = array_run([3.0, 4.0], LIMITED_ENTRY)
    assert np.all(np.abs(share - 1.0) < 0.05) and length[0] > 0.7 * length[1]


def test_two_identical_fractures_share_equally_either_way():
    for perforations in (OPEN_HOLE, LIMITED_ENTRY):
        share, length, _ = array_run([3.0, 3.0], perforations, steps=10)
        assert share[0] == pytest.approx(share[1], rel=1e-9) and length[0] == length[1]
