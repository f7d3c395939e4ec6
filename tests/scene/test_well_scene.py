"""A shared well in scenes (issue 35): the [well] section and the clusters' perforations, bad
input refused through the CLI with one line naming the field (exit 2), and a run that writes
the rate split to summary.json and rate_split.png."""
import json

import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.app import cli
from hmatddm.errors import InputError
from hmatddm.scene.build import build_simulation

WELL_2D = """name = "well-2d"
dimension = 2
[material]
shear_modulus = 10e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-3
compressibility = 4.5e-10
[stress]
s_hmin = 0.5e6
s_hmax = 1.0e6
[well]
schedule = [[0.0, 1e-3], [2.0, 1.5e-3]]
heel = [0.0, -20.0]
direction = [0.0, 1.0]
volume = 0.5
[[cluster]]
position = [0.0, -5.0]
perforations = 2
perforation_diameter = 0.01
[[cluster]]
position = [0.0, 0.0]
perforations = 2
perforation_diameter = 0.01
[[cluster]]
position = [0.0, 5.0]
perforations = 2
perforation_diameter = 0.01
discharge_coefficient = 0.8
[[initial_fracture]]
p0 = [-1.5, -5.0]
p1 = [1.5, -5.0]
element_size = 1.0
[[initial_fracture]]
p0 = [-1.5, 0.0]
p1 = [1.5, 0.0]
element_size = 1.0
[[initial_fracture]]
p0 = [-1.5, 5.0]
p1 = [1.5, 5.0]
element_size = 1.0
[propagation]
toughness = 5e6
[numerics]
time_step = 1.0
end_time = 4.0
backend = "dense"
initial_pressure = 1e6
initial_opening = 1e-4
[output]
vtu = false
snapshots = false
"""


def not_blank(path):
    from PIL import Image

    image = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    return image.std() > 5.0


def test_the_well_section_builds_the_well_and_the_perforated_clusters():
    scene = hs.parse_scene(WELL_2D).data
    assert scene["well"]["interpolation"] == "constant" and scene["well"]["friction_factor"] == 0.0
    assert scene["fluid"]["density"] == 1000.0
    assert "rate" not in scene["cluster"][0]
    sim = build_simulation(scene)
    assert sim.well.schedule.rows() == [[0.0, 1e-3], [2.0, 1.5e-3]]
    assert [c.discharge_coefficient for c in sim.clusters] == [0.6, 0.6, 0.8]
    np.testing.assert_allclose(sim.well_system.depths, [15.0, 20.0, 25.0])
    assert hs.parse_scene(hs.Scene(scene).to_toml()).data == scene


@pytest.mark.parametrize("override, field", [
    ("cluster[1].position=[0.5, 0.0]", "cluster[1].position"),
    ("cluster[0].perforations=0", "cluster[0].perforations"),
    ("cluster[2].perforations=-4", "cluster[2].perforations"),
    ("cluster[1].perforation_diameter=0", "cluster[1].perforation_diameter"),
    ("cluster[1].perforation_diameter=-0.01", "cluster[1].perforation_diameter"),
    ("cluster[2].discharge_coefficient=1.5", "cluster[2].discharge_coefficient"),
    ("cluster[2].discharge_coefficient=0", "cluster[2].discharge_coefficient"),
    ("well.schedule=[[0.0, 1e-3], [2.0, 1e-3], [1.0, 1e-3]]", "well.schedule[2] time"),
    ("well.schedule=[[0.0, -1e-3]]", "well.schedule[0] rate"),
    ("well.interpolation='cubic'", "well.interpolation"),
    ("well.friction_factor=0.02", "well.diameter"),
    ("cluster[0].rate=1e-3", "cluster[0].rate"),
    ("fluid.density=0", "fluid.density"),
])
def test_bad_input_exits_2_with_one_line_naming_the_field(tmp_path, capsys, override, field):
    path = tmp_path / "well.toml"
    path.write_text(WELL_2D)
    assert cli.main(["run", str(path), "--out", str(tmp_path / "o"), "--set", override]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("hmatddm: error: ") and field in err, err
    assert not (tmp_path / "o").exists()


def test_clusters_without_a_well_need_their_rate_and_no_perforations():
    plain = WELL_2D.split("[well]")[0] + "[[cluster]]" + WELL_2D.split("[[cluster]]", 1)[1]
    with pytest.raises(InputError, match=r"cluster\[0\]\.perforations needs a \[well\]"):
        hs.parse_scene(plain)
    without = plain.replace("perforations = 2\nperforation_diameter = 0.01\n", "").replace(
        "discharge_coefficient = 0.8\n", "")
    with pytest.raises(InputError, match=r"cluster\[0\]\.rate \(m\^3/s\) is required"):
        hs.parse_scene(without)
    with pytest.raises(InputError, match=r"cluster\[1\]\.perforation_diameter is required"):
        hs.parse_scene(WELL_2D.replace("position = [0.0, 0.0]\nperforations = 2\nperforation_diameter = 0.01",
                                       "position = [0.0, 0.0]\nperforations = 2"))


def test_a_run_writes_the_rate_split(tmp_path, capsys):
    path = tmp_path / "well.toml"
    path.write_text(WELL_2D)
    out = tmp_path / "run"
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == cli.EXIT_OK
    summary = json.loads((out / "summary.json").read_text())
    steps = summary["steps"]
    assert steps[0]["cluster_rates"] == [0.0, 0.0, 0.0] and steps[0]["pump_rate"] == 1e-3
    for step in steps[1:]:
        assert len(step["cluster_rates"]) == 3 and len(step["perforation_friction"]) == 3
        assert len(step["cluster_pressures"]) == 3 and step["heel_pressure"] > 0.0
        assert step["pump_rate"] == (1e-3 if step["time"] <= 2.0 else 1.5e-3)
    assert not_blank(out / "rate_split.png")
    assert cli.main(["render", str(out)]) == cli.EXIT_OK
    assert "rate_split.png" in capsys.readouterr().out


def test_the_well_gives_its_perforations_to_every_cluster_without_its_own():
    shared = WELL_2D.replace("volume = 0.5\n", "volume = 0.5\nperforations = 5\nperforation_diameter = 0.012\n")
    shared = shared.replace("perforations = 2\nperforation_diameter = 0.01\n", "", 2)
    scene = hs.parse_scene(shared).data
    sim = build_simulation(scene)
    assert [c.perforations for c in sim.clusters] == [5, 5, 2]
    assert [c.perforation_diameter for c in sim.clusters] == [0.012, 0.012, 0.01]
    changed = build_simulation(hs.parse_scene(shared, overrides=["well.perforations=1"]).data)
    assert [c.perforations for c in changed.clusters] == [1, 1, 2]
    with pytest.raises(InputError, match=r"well\.perforation_diameter is required"):
        hs.parse_scene(shared.replace("perforation_diameter = 0.012\n", ""))
