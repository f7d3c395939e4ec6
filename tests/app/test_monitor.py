"""[[monitor]]: displacement and tilt at points through a run (monitor.csv, monitor.png),
the values of hmatddm.displacement_at on the run's state, resumable."""
import csv

import numpy as np
import pytest

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.app import runner
from hmatddm.app.monitor import displacement_and_tilt
from hmatddm.errors import InputError
from scene_texts import KGD_2D_HEAD, RADIAL_3D_BODY

# the 3 m x 3 m horizontal sill of the runner tests, two steps, three monitor points
MONITORED = 'name = "monitored"\n' + RADIAL_3D_BODY + """
[output]
snapshots = false
history_plot = false
[[monitor]]
position = [0.0, 0.0, 4.0]
[[monitor]]
position = [5.0, 1.0, 3.0]
[[monitor]]
position = [-2.0, -2.0, -6.0]
"""


def _rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_a_run_writes_displacement_and_tilt(tmp_path):
    from PIL import Image

    out = tmp_path / "run"
    summary = runner.run_scene(hs.parse_scene(MONITORED), out, quiet=True)
    rows = _rows(out / "monitor.csv")
    assert [(int(r["step"]), int(r["monitor"])) for r in rows] == [(s, k) for s in (1, 2) for k in range(3)]
    assert [float(r["time"]) for r in rows[::3]] == [s["time"] for s in summary["steps"] if s["step"] > 0]
    last = {int(r["monitor"]): r for r in rows if int(r["step"]) == 2}
    # the values are those of hd.displacement_at on the last state (its checkpoint)
    from hmatddm.app.run_folder import latest_state

    mesh, fields, step, _ = latest_state(out)
    assert step == 2
    positions = np.array([[0.0, 0.0, 4.0], [5.0, 1.0, 3.0], [-2.0, -2.0, -6.0]])
    material = hd.Elastic(24e9, 0.25)
    expected = hd.displacement_at(mesh, material, fields["dd"], positions)
    got = np.array([[float(last[k][f"u_{a}"]) for a in "xyz"] for k in range(3)])
    np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-15)
    # above the opening sill the ground rises, below it sinks; on its axis no tilt
    assert got[0, 2] > 0 and got[2, 2] < 0
    assert abs(float(last[0]["tilt_x"])) < 1e-3 * abs(float(last[1]["tilt_x"]))
    # tilt: the slope of u_z, checked by a coarser difference of displacement_at
    h = 1e-2
    du = hd.displacement_at(mesh, material, fields["dd"], positions[1:2] + [[h, 0, 0]])[0, 2] - \
        hd.displacement_at(mesh, material, fields["dd"], positions[1:2] - [[h, 0, 0]])[0, 2]
    assert float(last[1]["tilt_x"]) == pytest.approx(du / (2 * h), rel=1e-3)
    image = np.asarray(Image.open(out / "monitor.png").convert("RGB"), dtype=float)
    assert image.std() > 5.0


def test_monitor_rows_are_cut_back_on_resume(tmp_path):
    out = tmp_path / "run"
    text = MONITORED.replace("end_time = 2.0", "end_time = 1.0")
    runner.run_scene(hs.parse_scene(text), out, quiet=True)
    assert {int(r["step"]) for r in _rows(out / "monitor.csv")} == {1}
    runner.run_scene(hs.parse_scene(MONITORED), out, quiet=True, resume=True)
    assert [int(r["step"]) for r in _rows(out / "monitor.csv")] == [1, 1, 1, 2, 2, 2]


def test_2d_tilt_and_refusals():
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 4)
    dd = np.tile([0.0, 1e-3], (4, 1))
    u, tilt = displacement_and_tilt(mesh, hd.Elastic(1e9, 0.25), dd, np.array([[0.5, 2.0], [1.0, 0.0]]))
    assert tilt.shape == (2, 1) and np.all(np.isfinite(u[0])) and u[0, 1] > 0 and tilt[0, 0] < 0
    assert np.all(np.isnan(u[1])) and np.all(np.isnan(tilt[1]))  # on the crack's end: singular, blank in the csv
    with pytest.raises(InputError, match=r"monitor\[0\]\.position must be a list of 2"):
        hs.parse_scene('name = "m"\n' + KGD_2D_HEAD + 'end_time = 1.0\n[[monitor]]\nposition = [0.0, 1.0, 2.0]\n')


def _shallow_sill(monitors, end_time=2.0):
    from pathlib import Path

    text = (Path(hs.__file__).parent / "scenes" / "shallow-sill.toml").read_text()
    text = text.replace("end_time = 12.0", f"end_time = {end_time}")
    text = text.replace("[output]\nevery = 4", "[output]\nsnapshots = false\nhistory_plot = false")
    return 'name = "shallow-sill-monitored"\n' + text + "".join(
        f"[[monitor]]\nposition = [{x}, {y}, {z}]\n" for x, y, z in monitors)


def test_a_layered_run_records_the_surface_uplift_and_tilt(tmp_path):
    """The shallow sill (a free surface 4 m above it): monitors on the ground record the
    layered displacement (hd.displacement_at in the scene's LayeredMedium) and its tilt;
    the surface rises above the sill and tilts away from it."""
    out = tmp_path / "run"
    positions = np.array([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, -6.0, -2.0]])
    runner.run_scene(hs.parse_scene(_shallow_sill(positions)), out, quiet=True)
    rows = _rows(out / "monitor.csv")
    from hmatddm.app.run_folder import latest_state

    mesh, fields, step, _ = latest_state(out)
    last = {int(r["monitor"]): r for r in rows if int(r["step"]) == step}
    medium = hd.LayeredMedium([0.0], [0.0, 10e9], [0.25, 0.25])
    expected = hd.displacement_at(mesh, medium, fields["dd"], positions)
    got = np.array([[float(last[k][f"u_{a}"]) for a in "xyz"] for k in range(3)])
    np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-15)
    uniform = hd.displacement_at(mesh, hd.Elastic(10e9, 0.25), fields["dd"], positions)
    assert got[0, 2] > 1.5 * uniform[0, 2] > 0  # the free surface amplifies the uplift
    assert float(last[1]["tilt_x"]) < 0 and abs(float(last[0]["tilt_x"])) < 1e-3 * abs(float(last[1]["tilt_x"]))
    h = 1e-2
    du = hd.displacement_at(mesh, medium, fields["dd"], positions[1:2] + [[h, 0, 0]])[0, 2] - \
        hd.displacement_at(mesh, medium, fields["dd"], positions[1:2] - [[h, 0, 0]])[0, 2]
    assert float(last[1]["tilt_x"]) == pytest.approx(du / (2 * h), rel=1e-3)
    assert (out / "monitor.png").is_file()


def test_a_monitor_in_the_air_is_refused():
    with pytest.raises(InputError, match=r"monitor\[1\]\.position\[2\] must be at most 0 \(the free surface"):
        hs.parse_scene(_shallow_sill([(0.0, 0.0, 0.0), (1.0, 0.0, 0.5)]))


def test_layered_2d_tilt_and_a_position_on_an_end():
    """A 2D vertical section with a free surface (y = 0) over a dipping segment: the tilt
    is the slope of hd.displacement_at's u_y along the surface; a position on the
    segment's end is blank (NaN), as in uniform rock."""
    medium = hd.LayeredMedium([0.0], [0.0, 10e9], [0.25, 0.25])
    mesh = hd.mesh.line([-1.0, -2.0], [1.0, -1.5], 2)
    dd = np.tile([1e-4, 1e-3], (2, 1))
    positions = np.array([[0.5, 0.0], [-3.0, 0.0], [1.0, -1.5]])
    u, tilt = displacement_and_tilt(mesh, medium, dd, positions)
    np.testing.assert_allclose(u[:2], hd.displacement_at(mesh, medium, dd, positions[:2]), rtol=1e-12)
    h = 1e-3
    slope = (hd.displacement_at(mesh, medium, dd, positions[:2] + [h, 0.0])[:, 1]
             - hd.displacement_at(mesh, medium, dd, positions[:2] - [h, 0.0])[:, 1]) / (2 * h)
    np.testing.assert_allclose(tilt[:2, 0], slope, rtol=1e-4)
    assert np.all(np.isnan(u[2])) and np.all(np.isnan(tilt[2]))
