"""Running a scene into an output folder: summary.json after every step, VTU/PVD,
checkpoints, PNGs, resume after an interruption, render of a partial run, progress."""
import io
import json

import numpy as np
import pytest

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.app import runner
from hmatddm.errors import InputError
from hmatddm.io import read_pvd, read_vtu
from scene_texts import KGD_2D_HEAD, RADIAL_3D_BODY

TINY_3D = 'name = "tiny"\n' + RADIAL_3D_BODY

TINY_2D = 'name = "tiny-kgd"\n' + KGD_2D_HEAD + """end_time = 6.0
backend = "dense"
initial_pressure = 0.6e6
[output]
every = 2
snapshots = false
[reference]
kind = "kgd-k"
"""


def interrupt_after(step):
    """A Progress.update that raises KeyboardInterrupt after step ``step`` (its checkpoint
    and summary are written, as after a Ctrl-C during the next step)."""

    def update(progress, record):
        if record["step"] == step:
            raise KeyboardInterrupt

    return update


def png_is_not_blank(path):
    from PIL import Image

    image = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    return image.std() > 5.0


@pytest.fixture(scope="module")
def finished_3d(tmp_path_factory):
    out = tmp_path_factory.mktemp("run3d")
    summary = runner.run_scene(hs.parse_scene(TINY_3D), out, quiet=True)
    return out, summary


def test_a_run_writes_every_output(finished_3d):
    out, summary = finished_3d
    document = json.loads((out / "summary.json").read_text())
    assert tuple(document) == runner.SUMMARY_KEYS
    assert document["scene"]["name"] == "tiny" and document["scene"]["numerics"]["backend"] == "dense"
    assert set(document["versions"]) == {"hmatddm", "numpy", "scipy", "numba", "python"}
    assert [s["step"] for s in document["steps"]] == [0, 1, 2]  # step 0: the initial state
    assert all(set(hd.simulation.RECORD_KEYS) <= set(step) for step in document["steps"])
    assert len(document["reference"]) == 3 and document["reference"][0]["radius"] is None
    assert {"radius", "max_opening", "net_pressure", "relative_error"} <= set(document["reference"][1])
    assert document["wall_seconds"] > 0
    assert document["steps"][-1]["n_elements"] > 9  # it grew
    # ParaView time series: one .vtu per step (every = 1), listed in the .pvd with their times
    assert read_pvd(out / "fractures.pvd") == [(0.0, "vtu/step-000000.vtu"), (1.0, "vtu/step-000001.vtu"),
                                               (2.0, "vtu/step-000002.vtu")]
    points, cells, data = read_vtu(out / "vtu/step-000002.vtu")
    n = document["steps"][-1]["n_elements"]
    assert {"opening", "slip", "pressure", "fracture_id", "state", "net_pressure"} <= set(data)
    assert data["opening"].shape == (n,) and data["slip"].shape == (n, 3) and cells.shape == (n, 4)
    assert np.all(data["opening"] > 0) and np.all(data["state"] == 0)
    assert np.allclose(data["net_pressure"], data["pressure"] - 8e6)
    # checkpoints, snapshots (horizontal fracture: plan and oblique) and the history plot
    assert sorted(p.name for p in (out / "checkpoints").glob("*.json"))[-1] == "step-000002.json"
    for name in ("step-000002_plan.png", "step-000002_oblique.png"):
        assert png_is_not_blank(out / "snapshots" / name)
    assert png_is_not_blank(out / "history.png")
    assert hs.load_scene(str(out / "scene.toml")).data == document["scene"]


def test_a_vertical_3d_run_writes_the_plan_view_of_its_traces(tmp_path):
    """A vertical fracture is edge on from above: the plan view draws its trace."""
    from PIL import Image

    text = TINY_3D.replace('name = "tiny"', 'name = "tiny-vertical"').replace(
        "e2 = [0.0, 1.0, 0.0]", "e2 = [0.0, 0.0, 1.0]").replace("s_hmin = 10e6", "s_hmin = 8e6").replace(
        "s_v = 8e6", "s_v = 10e6").replace("end_time = 2.0", "end_time = 1.0")
    assert runner.snapshot_views(hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 3, 3, 3, 3)) == (
        "plan", "oblique")
    summary = runner.run_scene(hs.parse_scene(text), tmp_path, quiet=True)
    assert [s["step"] for s in summary["steps"]] == [0, 1]
    plan = tmp_path / "snapshots" / "step-000001_plan.png"
    assert png_is_not_blank(plan) and png_is_not_blank(tmp_path / "snapshots" / "step-000001_oblique.png")
    image = np.asarray(Image.open(plan).convert("RGB"), dtype=float) / 255.0
    coloured = np.ptp(image[:, :int(0.8 * image.shape[1])], axis=2) > 0.15  # left of the scalar bar
    rows, columns = np.nonzero(coloured)
    assert np.ptp(columns) > 0.3 * image.shape[1], "the trace along x should span the picture"


def test_a_folder_holding_a_run_is_not_overwritten_by_accident(finished_3d, tmp_path):
    out, _ = finished_3d
    with pytest.raises(InputError, match="already holds a run; add --resume to continue it or --overwrite"):
        runner.run_scene(hs.parse_scene(TINY_3D), out, quiet=True)


def test_interrupted_run_is_readable_and_resumes_to_the_same_result(tmp_path, monkeypatch):
    scene = hs.parse_scene(TINY_2D)
    full = runner.run_scene(scene, tmp_path / "full", quiet=True)

    monkeypatch.setattr(runner.Progress, "update", interrupt_after(3))
    run = runner.SceneRun(scene, tmp_path / "part", quiet=True)
    with pytest.raises(KeyboardInterrupt):
        run.execute()
    partial = json.loads((tmp_path / "part/summary.json").read_text())
    assert [s["step"] for s in partial["steps"]] == [0, 1, 2, 3] and len(partial["reference"]) == 4
    assert run.last_record["step"] == 3
    monkeypatch.undo()

    # render reads a partial run (newest checkpoint)
    written = runner.render_folder(tmp_path / "part")
    # the plan view of the newest state (a checkpoint), the profiles of the saved steps (every 2) and of it
    assert [p.name for p in written] == ["step-000003_plan.png", "step-000000_profile.png", "step-000002_profile.png",
                                         "step-000003_profile.png", "history.png"]
    assert all(png_is_not_blank(p) for p in written)

    resumed = runner.run_scene(scene, tmp_path / "part", resume=True, quiet=True)
    assert [s["step"] for s in resumed["steps"]] == list(range(0, 7))
    for a, b in zip(resumed["steps"], full["steps"]):
        assert a["n_elements"] == b["n_elements"]
        assert a["max_opening"] == pytest.approx(b["max_opening"], rel=1e-9)
        assert a["wellbore_pressure"] == pytest.approx(b["wellbore_pressure"], rel=1e-9)
    entries = read_pvd(tmp_path / "part/fractures.pvd")
    assert [name for _, name in entries] == ["vtu/step-000000.vtu", "vtu/step-000002.vtu", "vtu/step-000004.vtu",
                                             "vtu/step-000006.vtu"]
    assert resumed["wall_seconds"] >= partial["wall_seconds"]
    # a different scene cannot continue these checkpoints
    other = hs.parse_scene(TINY_2D, overrides=["numerics.initial_pressure=0.7e6"])
    with pytest.raises(hd.CheckpointError, match="belong to a different run"):
        runner.run_scene(other, tmp_path / "part", resume=True, quiet=True)


def test_resume_without_checkpoints_starts_from_zero(tmp_path):
    stream = io.StringIO()
    summary = runner.run_scene(hs.parse_scene(TINY_2D, overrides=["numerics.end_time=1"]), tmp_path, resume=True,
                               stream=stream)
    assert [s["step"] for s in summary["steps"]] == [0, 1]


def test_render_from_vtu_files_only(tmp_path):
    out = tmp_path / "run"
    runner.run_scene(hs.parse_scene(TINY_2D, overrides=["numerics.end_time=2"]), out, quiet=True)
    for path in (out / "checkpoints").iterdir():
        path.unlink()
    mesh, fields, step, time_value = runner.latest_state(out)
    assert step == 2 and time_value == 2.0 and isinstance(mesh, hd.Mesh2D)
    written = runner.render_folder(out)
    assert all(png_is_not_blank(p) for p in written)
    with pytest.raises(InputError, match="holds no checkpoint and no .vtu file"):
        runner.render_folder(tmp_path)


def test_meshes_rebuild_from_their_vtu_cells(tmp_path):
    from hmatddm.io import write_vtu

    rotation = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    mesh3 = hd.mesh.rectangle([1.0, 2.0, 3.0], rotation[0], rotation[1], 4.0, 2.0, 4, 3, fracture_id=5)
    mesh2 = hd.mesh.line([-1.0, 0.5], [2.0, 1.5], 5)
    for mesh in (mesh3, mesh2):
        write_vtu(tmp_path / "m.vtu", mesh)
        rebuilt = runner.mesh_from_vtu(*read_vtu(tmp_path / "m.vtu"))
        assert np.allclose(rebuilt.centers, mesh.centers) and np.allclose(rebuilt.frames, mesh.frames)
        assert np.array_equal(rebuilt.fracture_id, mesh.fracture_id)


def test_progress_lines():
    record = dict(step=1, time=1.0, n_elements=9, nonlinear_iterations=4, linear_iterations=20, solve_seconds=0.5)
    stream = io.StringIO()
    progress = runner.Progress(end_time=100.0, time_step=1.0, stream=stream)
    for step in range(1, 101):
        progress.update(dict(record, step=step, time=float(step)))
    lines = stream.getvalue().splitlines()
    assert len(lines) == 10  # not a terminal: one line every 10 steps
    assert lines[-1].startswith("step  100  t 100/100 s [####################] 100%  elements 9  iterations 4")
    quiet = io.StringIO()
    runner.Progress(end_time=10.0, time_step=1.0, stream=quiet, enabled=False).update(record)
    assert quiet.getvalue() == ""

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    terminal = Terminal()
    progress = runner.Progress(end_time=10.0, time_step=1.0, stream=terminal)
    progress.update(record)
    progress.note("a message")
    assert terminal.getvalue().startswith("\rstep    1") and terminal.getvalue().endswith("\na message\n")


def test_snapshot_titles_count_the_elements_of_the_record(tmp_path):
    """The title gives the run's element count (its record's n_elements) and the intact
    natural elements apart (issue 19 item 7: crossing said 21 for 15)."""
    text = TINY_2D.replace("end_time = 6.0", "end_time = 2.0") + (
        "[[natural_fracture]]\np0 = [2.0, -1.0]\np1 = [2.0, 1.0]\n")
    run = runner.SceneRun(hs.parse_scene(text), tmp_path, quiet=True)
    run.execute()
    mesh, _, _, state = run.simulation.view()
    title = runner.snapshot_title("tiny", 2.0, mesh, state)
    intact = int(np.count_nonzero(state == 1))
    assert intact > 0 and mesh.n_elements > run.last_record["n_elements"]
    assert title == f"tiny: t = 2 s, {run.last_record['n_elements']} elements (+ {intact} intact natural)"


def test_layer_interfaces_of_a_scene_are_what_its_snapshots_draw():
    from hmatddm.app.runner import layer_interfaces

    assert layer_interfaces(hs.load_scene("layered-height").data) == (3.0, -3.0)
    assert layer_interfaces(hs.load_scene("kgd").data) == ()
