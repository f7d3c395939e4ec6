"""The embedded scene `stage` (issue 35): five clusters on one pump in a three-layer
formation through a natural-fracture network. A short run writes every output (the rate
split in summary.json and rate_split.png, plan, oblique and side snapshots, events.csv, the
microseismic map and, with ObsPy, events.xml); the slow tests check the physics it is there to
show: interior clusters starved without limited entry and fed with it, and the middle
fracture's height held by the stiffer, more stressed bounding layers against the same run in
uniform rock."""
import json

import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.app import runner
from hmatddm.simulation.records import fluid_moved


def not_blank(path):
    from PIL import Image

    image = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    return image.std() > 5.0


def run(tmp_path, *overrides):
    scene = hs.load_scene("stage", overrides=list(overrides))
    runner.run_scene(scene, tmp_path, quiet=True)
    return json.loads((tmp_path / "summary.json").read_text())["steps"], scene.data


def test_the_stage_scene_is_a_well_with_five_clusters_in_three_layers():
    scene = hs.load_scene("stage").data
    assert len(scene["cluster"]) == 5 and all("rate" not in c for c in scene["cluster"])
    assert len(scene["layer"]) == 3 and scene["layer"][0]["s_hmin"] > scene["stress"]["s_hmin"]
    pay, bounding = scene["layer"][1], (scene["layer"][0], scene["layer"][2])
    assert all(layer["shear_modulus"] > pay["shear_modulus"] for layer in bounding)  # stiffer bounding layers
    assert scene["well"]["direction"] == [1.0, 0.0, 0.0]  # along s_hmin (x)
    assert "microseismic" in scene and scene["network"]["density"] > 0.0


def test_a_short_stage_run_writes_the_rate_split_and_the_pictures(tmp_path):
    steps, scene = run(tmp_path, "numerics.end_time=4", "output.every=1")
    pump = scene["well"]["schedule"][0][1]
    c_f, volume = scene["fluid"]["compressibility"], scene["well"]["volume"]
    for before, step in zip(steps, steps[1:]):
        storage = c_f * volume * (step["heel_pressure"] - before["heel_pressure"]) / step["time_step"]
        assert step["pump_rate"] == pump
        assert sum(step["cluster_rates"]) + storage == pytest.approx(pump, rel=1e-9)
        assert len(step["cluster_pressures"]) == 5 and len(step["perforation_friction"]) == 5
        assert abs(step["budget"]["residual"]) <= 1e-6 * fluid_moved(step["budget"])
    for name in ("rate_split.png", "microseismic_map.png", "snapshots/step-000002_plan.png",
                 "snapshots/step-000002_side.png", "snapshots/step-000002_oblique.png"):
        assert not_blank(tmp_path / name), name
    assert (tmp_path / "events.csv").exists()
    obspy = pytest.importorskip("obspy")
    rows = (tmp_path / "events.csv").read_text().splitlines()
    assert len(obspy.read_events(str(tmp_path / "events.xml"))) == len(rows) - 1


def fracture_extent(out, fracture):
    """(length, height) of hydraulic fracture ``fracture`` in the last .vtu of ``out``."""
    from hmatddm.app.run_folder import latest_state

    mesh, fields = latest_state(out)[:2]
    chosen = (mesh.fracture_id == fracture) & (np.asarray(fields["state"]) == 0)
    corners = mesh.subset(np.flatnonzero(chosen)).corners()
    return float(np.ptp(corners[..., 1])), float(np.ptp(corners[..., 2]))


@pytest.mark.slow
def test_limited_entry_feeds_the_interior_clusters_the_stress_shadow_starves(tmp_path):
    open_hole, _ = run(tmp_path / "open", "numerics.end_time=30", "output.snapshots=false")
    limited, _ = run(tmp_path / "limited", "numerics.end_time=30", "well.perforations=1", "output.snapshots=false")
    share = np.array(open_hole[-1]["cluster_rates"]) / open_hole[-1]["pump_rate"]
    assert np.all(share[1:4] < 0.05) and share[0] + share[4] > 0.8
    share = np.array(limited[-1]["cluster_rates"]) / limited[-1]["pump_rate"]
    assert np.all(np.abs(share - 0.2) < 0.05)
    assert min(limited[-1]["perforation_friction"]) > 1e6 > max(open_hole[-1]["perforation_friction"])
    fed, starved = fracture_extent(tmp_path / "limited", 2), fracture_extent(tmp_path / "open", 2)
    assert fed[0] * fed[1] > 2.0 * starved[0] * starved[1]  # the middle fracture's length x height


@pytest.mark.slow
def test_the_bounding_layers_hold_the_middle_fractures_height(tmp_path):
    """The middle cluster's fracture with limited entry in the three-layer stack, against the
    same run with the bounding layers' stress and modulus equal to the pay zone's (uniform rock),
    after the scene's 70 s: 14 m against 16 m, at least one row of 2 m elements taller in uniform
    rock (benchmarks/RESULTS.md, issue 33, eighth session: the 22 m of issue 35's uniform run came
    on a path that held one element violating its contact conditions in 60 of its 84 solves)."""
    run(tmp_path / "layers", "well.perforations=1", "output.snapshots=false")
    run(tmp_path / "uniform", "well.perforations=1", "output.snapshots=false", "layer[0].s_hmin=35.85e6",
        "layer[2].s_hmin=35.85e6", "layer[0].shear_modulus=6.62e9", "layer[2].shear_modulus=6.62e9")
    _, held = fracture_extent(tmp_path / "layers", 2)
    _, free = fracture_extent(tmp_path / "uniform", 2)
    assert held <= 12.0 + 4.0  # the pay zone, and at most one row of 2 m elements into each bounding layer
    assert free >= held + 2.0
