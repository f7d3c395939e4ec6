"""The command line: run, scenes, validate, bench, render; exit codes 0/1/2/3/130."""
import json
import os

import numpy as np
import py_compile
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from hmatddm.app import bench as bench_cli, cli, runner
from conftest import child_environment
from scene_texts import KGD_2D_HEAD

ROOT = Path(__file__).resolve().parents[2]

TINY_2D = KGD_2D_HEAD + """end_time = 2.0
backend = "dense"
initial_pressure = 0.6e6
[reference]
kind = "kgd-k"
"""


@pytest.fixture
def tiny(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_2D)
    return path


def test_scenes_lists_names_with_descriptions(capsys):
    assert cli.main(["scenes"]) == cli.EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    names = [line.split()[0] for line in lines]
    assert names[0] == "default" and {"radial-k", "radial-m", "kgd"} <= set(names)
    assert all(len(line.split(maxsplit=1)) == 2 for line in lines)  # a description on every line
    assert cli.main(["scenes", "kgd"]) == cli.EXIT_OK
    assert tomllib.loads(capsys.readouterr().out)["dimension"] == 2
    assert cli.main(["scenes", "--json"]) == cli.EXIT_OK
    assert "radial-m" in json.loads(capsys.readouterr().out)
    assert cli.main(["scenes", "nope"]) == cli.EXIT_BAD_INPUT
    assert "unknown scene 'nope'" in capsys.readouterr().err


def test_run_writes_the_outputs_and_exits_0(tiny, tmp_path, capsys):
    out = tmp_path / "out"
    assert cli.main(["run", str(tiny), "--out", str(out)]) == cli.EXIT_OK
    captured = capsys.readouterr()
    assert "hmatddm: done in" in captured.out and "vs closed form: half_length" in captured.out
    assert "running 'tiny'" in captured.err and "step    2  t 2/2 s" in captured.err
    summary = json.loads((out / "summary.json").read_text())
    assert tuple(summary) == ("scene", "versions", "steps", "reference", "wall_seconds")
    assert len(summary["steps"]) == 3 and len(summary["reference"]) == 3  # step 0: the initial state
    assert len(list((out / "vtu").glob("*.vtu"))) == 3 and (out / "fractures.pvd").is_file()
    assert (out / "snapshots/step-000002_plan.png").is_file() and (out / "history.png").is_file()

    # --resume with no SCENE continues the scene stored in DIR, here to a later end time
    assert cli.main(["run", "--out", str(out), "--resume", "--set", "numerics.end_time=3", "--quiet"]) == 0
    assert capsys.readouterr().out == ""
    summary = json.loads((out / "summary.json").read_text())
    assert [s["step"] for s in summary["steps"]] == [0, 1, 2, 3]
    # the run was a different scene: its checkpoints are refused
    assert cli.main(["run", str(tiny), "--out", str(out), "--resume", "--set", "fluid.viscosity=1e-3"]) == 2
    assert "belong to a different run" in capsys.readouterr().err

    # render a finished run
    assert cli.main(["render", str(out)]) == cli.EXIT_OK
    assert "history.png" in capsys.readouterr().out


def test_bad_input_exits_2_with_a_one_line_message(tiny, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(TINY_2D.replace("[numerics]", "[numerics]\ntme_step = 1.0"))
    assert cli.main(["run", str(bad), "--out", str(tmp_path / "o")]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.strip() == ("hmatddm: error: unknown key 'numerics.tme_step'; did you mean 'numerics.time_step'?")
    assert not (tmp_path / "o").exists()

    natural = tmp_path / "natural.toml"
    natural.write_text(TINY_2D + "\n[[natural_fracture]]\np0 = [2.0, -1.0]\np1 = [2.0, 1.0]\n")
    assert cli.main(["run", str(natural), "--check", "--quiet"]) == cli.EXIT_OK
    capsys.readouterr()

    assert cli.main(["run", str(tiny), "--backend", "dense", "--set", "material.poisson_ratio=0.6"]) == 2
    assert "material.poisson_ratio must be in [0, 0.5), got 0.6" in capsys.readouterr().err
    assert cli.main(["run", "no-such-scene"]) == cli.EXIT_BAD_INPUT
    assert cli.main(["render", str(tmp_path / "missing")]) == cli.EXIT_BAD_INPUT
    with pytest.raises(SystemExit) as error:  # argparse: unknown option
        cli.main(["run", "--backend", "fast"])
    assert error.value.code == 2


def test_run_check_prints_the_validated_scene(capsys):
    assert cli.main(["run", "kgd", "--check"]) == cli.EXIT_OK
    scene = json.loads(capsys.readouterr().out)
    assert scene["name"] == "kgd" and scene["numerics"]["scheme"] == "krylov"


def test_a_run_that_does_not_converge_exits_3(tiny, tmp_path, capsys):
    out = tmp_path / "out"
    code = cli.main(["run", str(tiny), "--out", str(out), "--quiet", "--set", "numerics.max_iterations=1",
                     "--set", "numerics.min_relaxation=1.0", "--set", "numerics.tolerance_pressure=1e-15"])
    assert code == cli.EXIT_NOT_CONVERGED
    err = capsys.readouterr().err
    assert "did not converge in the first step" in err
    summary = json.loads((out / "summary.json").read_text())  # readable, with the steps that converged
    assert [s["step"] for s in summary["steps"]] == [0]  # the initial state only


def test_interrupt_exits_130_and_says_how_to_resume(tiny, tmp_path, capsys, monkeypatch):
    def interrupt(progress, record):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner.Progress, "update", interrupt)
    out = tmp_path / "out"
    assert cli.main(["run", str(tiny), "--out", str(out)]) == cli.EXIT_INTERRUPTED
    err = capsys.readouterr().err
    assert "interrupted; the newest checkpoint is step 1 (t = 1 s)" in err
    assert f"hmatddm run --out {out} --resume" in err
    monkeypatch.undo()
    assert cli.main(["run", "--out", str(out), "--resume", "--quiet"]) == cli.EXIT_OK
    assert len(json.loads((out / "summary.json").read_text())["steps"]) == 3
    assert cli.main(["run", str(tiny), "--out", str(out)]) == cli.EXIT_BAD_INPUT  # no silent overwrite
    assert "already holds a run" in capsys.readouterr().err
    assert cli.main(["run", str(tiny), "--out", str(out), "--overwrite", "--quiet"]) == cli.EXIT_OK


def test_bench_prints_a_table_or_json(capsys, monkeypatch):
    monkeypatch.setattr(bench_cli, "QUICK_SIDES", (4, 6))
    assert cli.main(["bench", "--quick", "--json"]) == cli.EXIT_OK
    rows = json.loads(capsys.readouterr().out)
    assert [(r["elements"], r["backend"]) for r in rows] == [(16, "dense"), (16, "hmatrix"), (36, "dense"),
                                                             (36, "hmatrix")]
    assert all(r["relative_error"] < 1e-3 for r in rows if r["backend"] == "hmatrix")
    assert all(r["build_seconds"] >= 0 and r["memory_mb"] > 0 and r["matvec_ms"] > 0 for r in rows)
    assert cli.main(["bench", "--quick", "--quiet"]) == cli.EXIT_OK
    captured = capsys.readouterr()
    assert "error (smooth)" in captured.out and captured.err == ""
    assert cli.main(["bench", "--quick"]) == cli.EXIT_OK  # progress on stderr, one line per operator
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("[1/5] compiling the numba kernels") and lines[-2].startswith(
        "[5/5] 36 elements, hmatrix (eps 0.0001) ... build ")
    assert " s wall, " in lines[-1] and lines[-1].endswith(" s CPU")


def test_validate_keeps_its_exit_codes(capsys, monkeypatch):
    import hmatddm.app.validate as validate

    rows = [dict(name="check", error=1e-3, tolerance=1e-2, passed=True, seconds=0.1)]
    monkeypatch.setattr(validate, "run_checks", lambda stream=None: rows)
    assert cli.main(["validate", "--json"]) == cli.EXIT_OK
    assert json.loads(capsys.readouterr().out) == rows
    monkeypatch.setattr(validate, "run_checks", lambda stream=None: [dict(rows[0], passed=False)])
    assert cli.main(["validate"]) == cli.EXIT_FAILED
    assert "FAIL" in capsys.readouterr().out


def test_console_script_and_examples_compile():
    result = subprocess.run([sys.executable, "-m", "hmatddm.app.cli", "scenes"], capture_output=True, text=True,
                            cwd=ROOT, env=child_environment(), timeout=1800)  # a hang guard only: a loaded CI took > 120 s
    assert result.returncode == 0 and "radial-k" in result.stdout
    examples = sorted((ROOT / "examples").glob("*.py"))
    assert len(examples) >= 3
    for path in examples:
        py_compile.compile(str(path), doraise=True)


def test_run_check_validates_natural_fracture_scenes(tiny, capsys):
    text = tiny.read_text() + "\n[network]\nfriction_coefficient = 0.3\n[[natural_fracture]]\np0 = [2.0, -1.0]\np1 = [2.0, 1.0]\n"
    tiny.write_text(text)
    assert cli.main(["run", str(tiny), "--check"]) == cli.EXIT_OK
    captured = capsys.readouterr()
    assert json.loads(captured.out)["network"]["friction_coefficient"] == 0.3


@pytest.mark.slow  # end to end (issue 18 item 8); the crossing itself: tests/fracture/test_crossing.py
def test_crossing_scene_runs_and_reports_the_crossing(tmp_path, capsys):
    out = tmp_path / "x"
    assert cli.main(["run", "crossing", "--out", str(out), "--quiet", "--set", "numerics.end_time=25"]) == cli.EXIT_OK
    summary = json.loads((out / "summary.json").read_text())
    assert sum(step["natural_crossed"] for step in summary["steps"]) >= 1
    from hmatddm.io import read_vtu

    vtus = sorted((out / "vtu").glob("*.vtu"))
    _, _, data = read_vtu(vtus[-1])
    assert set(np.unique(data["state"]).tolist()) >= {0, 1}  # hydraulic and intact natural elements


def test_exit_codes_are_distinct_and_documented_in_the_help():
    codes = (cli.EXIT_OK, cli.EXIT_FAILED, cli.EXIT_BAD_INPUT, cli.EXIT_NOT_CONVERGED, cli.EXIT_OUTPUT,
             cli.EXIT_INTERRUPTED)
    assert codes == (0, 1, 2, 3, 4, 130)
    parser = cli.build_parser()
    assert "4 output not written (disk full or folder not writable" in parser.epilog
    run = parser._subparsers._group_actions[0].choices["run"]
    assert "4 an output could not be written (disk full" in run.epilog
    assert "4 an output could not be written" in cli.__doc__


T_JUNCTION = TINY_2D + '[[initial_fracture]]\nshape = "line"\np0 = [0.0, 0.0]\np1 = [0.0, 0.5]\nelement_size = 0.25\n'


def test_quick_answers_import_nothing_heavy_and_change_no_environment(tmp_path):
    """`import hmatddm`, `--help`, `scenes` and a refused scene (here a T junction, found
    by the operator only once built) load neither numba, the H-matrix engine, the
    simulation, matplotlib nor pyvista; the library sets no environment variable."""
    scene = tmp_path / "t.toml"
    scene.write_text(T_JUNCTION)
    code = f"""
import contextlib, io, os, sys
import hmatddm, hmatddm.hmatrix
assert "OMP_WAIT_POLICY" not in os.environ
heavy = ("numba", "scipy", "matplotlib", "pyvista", "hmatddm.hmatrix.hmatrix", "hmatddm.simulation.simulation",
         )
def loaded():
    return [m for m in heavy if m in sys.modules]
assert not loaded() and "scipy.special" not in sys.modules, loaded()
from hmatddm import cli
with contextlib.redirect_stdout(io.StringIO()):
    try:
        cli.main(["--help"])
    except SystemExit:
        pass
    assert cli.main(["scenes"]) == 0
assert not loaded(), loaded()
err = io.StringIO()
with contextlib.redirect_stderr(err):
    code = cli.main(["run", {str(scene)!r}, "--out", {str(tmp_path / "out")!r}])
assert code == 2 and "lie on or near another element's edge" in err.getvalue(), (code, err.getvalue())
assert len(err.getvalue().strip().splitlines()) == 1
assert not loaded(), loaded()
print("ok")
"""
    env = {k: v for k, v in child_environment().items() if k != "OMP_WAIT_POLICY"}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    assert result.returncode == 0 and result.stdout.strip() == "ok", result.stderr
    assert not (tmp_path / "out").exists()  # refused before anything was written


def test_the_command_asks_numba_workers_to_wait_passively(monkeypatch, capsys):
    monkeypatch.delenv("OMP_WAIT_POLICY", raising=False)
    assert cli.main(["scenes", "--json"]) == cli.EXIT_OK
    assert os.environ["OMP_WAIT_POLICY"] == "PASSIVE"
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")  # an explicit setting wins
    assert cli.main(["scenes", "--json"]) == cli.EXIT_OK
    assert os.environ["OMP_WAIT_POLICY"] == "ACTIVE"
    capsys.readouterr()


def test_the_last_step_lands_on_end_time(tiny, tmp_path, capsys):
    """end_time shorter than a step, or not a whole number of steps: the last step is
    shortened to end exactly there, and nothing reports a time past it (issue 19 item 3)."""
    out = tmp_path / "short"
    assert cli.main(["run", str(tiny), "--out", str(out), "--set", "numerics.end_time=0.5"]) == cli.EXIT_OK
    captured = capsys.readouterr()
    assert "t 0.5/0.5 s" in captured.err and "t = 0.5 s, " in captured.out
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert [s["time"] for s in steps] == [0.0, 0.5]
    assert steps[1]["injected_volume"] == pytest.approx(0.5 * 5e-4, rel=1e-12)
    out = tmp_path / "uneven"
    assert cli.main(["run", str(tiny), "--out", str(out), "--quiet", "--set", "numerics.end_time=2.5"]) == 0
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert [s["time"] for s in steps] == [0.0, 1.0, 2.0, 2.5]
    assert steps[-1]["injected_volume"] == pytest.approx(2.5 * 5e-4, rel=1e-12)
    # a resume to an end time the run has already passed is refused, not reported
    assert cli.main(["run", "--out", str(out), "--resume", "--set", "numerics.end_time=2"]) == cli.EXIT_BAD_INPUT
    assert "already at t = 2.5 s, past numerics.end_time = 2 s" in capsys.readouterr().err
    assert [s["time"] for s in json.loads((out / "summary.json").read_text())["steps"]] == [0.0, 1.0, 2.0, 2.5]


def test_a_folder_without_a_finished_step_is_not_claimed(tiny, tmp_path, capsys):
    """A run that stopped before its first step leaves no run behind: the corrected scene
    runs into the same folder without --overwrite; foreign files stay (issue 19 item 4)."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (out / "vtu").mkdir()
    (out / "vtu" / "mine.vtu.txt").write_text("mine too")
    failing = ["--set", "numerics.max_iterations=1", "--set", "numerics.min_relaxation=1.0",
               "--set", "numerics.tolerance_pressure=1e-15"]
    assert cli.main(["run", str(tiny), "--out", str(out), "--quiet", *failing]) == cli.EXIT_NOT_CONVERGED
    assert [s["step"] for s in json.loads((out / "summary.json").read_text())["steps"]] == [0]
    capsys.readouterr()
    assert cli.main(["run", str(tiny), "--out", str(out), "--quiet"]) == cli.EXIT_OK  # no --overwrite needed
    assert len(json.loads((out / "summary.json").read_text())["steps"]) == 3
    assert cli.main(["run", str(tiny), "--out", str(out), "--quiet"]) == cli.EXIT_BAD_INPUT  # now it holds a run
    assert "already holds a run" in capsys.readouterr().err
    assert cli.main(["run", str(tiny), "--out", str(out), "--quiet", "--overwrite"]) == cli.EXIT_OK
    assert (out / "notes.txt").read_text() == "mine" and (out / "vtu" / "mine.vtu.txt").read_text() == "mine too"
    # --resume and --overwrite contradict each other: refused before anything is touched
    before = sorted(p.name for p in out.rglob("*"))
    assert cli.main(["run", str(tiny), "--out", str(out), "--resume", "--overwrite"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "--resume continues the run in --out and --overwrite starts it over" in err
    assert len(err.strip().splitlines()) == 1 and sorted(p.name for p in out.rglob("*")) == before


def test_check_prints_the_size_estimate_and_a_huge_scene_is_refused(tiny, tmp_path, capsys):
    assert cli.main(["run", str(tiny), "--check"]) == cli.EXIT_OK
    captured = capsys.readouterr()
    assert json.loads(captured.out)["numerics"]["max_elements"] == 200_000
    assert "hmatddm: estimate: elements: 3 initial + 0 natural = 3" in captured.err
    assert "memory at the start: dense" in captured.err and "per step" in captured.err
    out = tmp_path / "huge"
    assert cli.main(["run", str(tiny), "--out", str(out), "--set", "initial_fracture[0].element_size=7.5e-7"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "about 1,000,000 elements" in err
    assert "more than numerics.max_elements = 200,000" in err and "initial_fracture[0].element_size" in err
    assert not out.exists()


def test_growth_past_max_elements_stops_resumably(tiny, tmp_path, capsys):
    """A run that would outgrow numerics.max_elements stops with the outputs and the
    checkpoint of its last step, and continues with a higher limit (issue 19 item 2)."""
    out = tmp_path / "out"
    code = cli.main(["run", str(tiny), "--out", str(out), "--quiet", "--set", "numerics.end_time=4",
                     "--set", "numerics.max_elements=8"])  # the mesh grows 3 -> 7 -> 11 -> 15 -> 17
    assert code == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "stopped: growth in step 2 (t = 2 s) would take the mesh to 9 elements, more than max_elements = 8" in err
    assert "every step up to step 1 is checkpointed" in err
    assert f"hmatddm run --out {out} --resume --set numerics.max_elements=16" in err
    summary = json.loads((out / "summary.json").read_text())
    assert [s["n_elements"] for s in summary["steps"]] == [3, 7]
    assert (out / "snapshots" / "step-000001_plan.png").is_file()
    assert cli.main(["run", "--out", str(out), "--resume", "--quiet", "--set", "numerics.max_elements=12"]) == 2
    capsys.readouterr()
    assert cli.main(["run", "--out", str(out), "--resume", "--quiet", "--set", "numerics.max_elements=100"]) == 0
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert [s["step"] for s in steps] == [0, 1, 2, 3, 4] and steps[-1]["n_elements"] > 10


def test_validate_prints_progress_per_check(capsys, monkeypatch):
    import hmatddm.app.validate as validate

    monkeypatch.setattr(validate, "checks", lambda: [("first", lambda: 1e-3, 1e-2), ("second", lambda: 0.5, 1e-2)])
    assert cli.main(["validate"]) == cli.EXIT_FAILED
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("[1/2] first ... error 1.00e-03 PASS (") and err[1].startswith("[2/2] second ... error")
    assert "FAIL" in err[1] and err[2].startswith("2 task(s) in ") and err[2].endswith(" s CPU")
    assert cli.main(["validate", "--quiet"]) == cli.EXIT_FAILED
    assert capsys.readouterr().err == ""


def test_interrupt_between_a_step_and_its_checkpoint_names_the_checkpointed_step(tiny, tmp_path, capsys,
                                                                               monkeypatch):
    """Ctrl-C after step 2 was computed but before its checkpoint was written: the message
    names step 1, where a resume starts (issue 19 item 8: it said 'after step 24' with 23 on disk)."""
    from hmatddm.simulation.simulation import Simulation

    save = Simulation.save_checkpoint

    def interrupted_save(simulation):
        if simulation.state.step == 2:
            raise KeyboardInterrupt
        save(simulation)

    monkeypatch.setattr(Simulation, "save_checkpoint", interrupted_save)
    out = tmp_path / "out"
    assert cli.main(["run", str(tiny), "--out", str(out), "--quiet"]) == cli.EXIT_INTERRUPTED
    err = capsys.readouterr().err
    assert "interrupted; the newest checkpoint is step 1 (t = 1 s)" in err


def test_simulation_run_prints_progress_when_asked(tiny):
    import io

    import hmatddm.scene as hs

    stream = io.StringIO()
    simulation = hs.build_simulation(hs.load_scene(str(tiny)).data)
    simulation.run(2.0, progress=stream)
    lines = stream.getvalue().splitlines()
    assert [line.split()[:2] for line in lines] == [["step", "1"], ["step", "2"]]  # not a terminal: plain lines
    assert "t 2/2 s" in lines[-1] and "elements" in lines[-1]
    quiet = hs.build_simulation(hs.load_scene(str(tiny)).data)
    assert len(quiet.run(1.0)) == 1  # silent by default


def test_run_with_auto_steps_says_so_and_records_the_steps(tmp_path, capsys):
    out = tmp_path / "auto"
    assert cli.main(["run", "kgd", "--out", str(out), "--set", "numerics.end_time=2",
                     "--set", "numerics.time_step=auto", "--set", "numerics.first_time_step=0.5"]) == cli.EXIT_OK
    assert "dt = auto from 0.5 s" in capsys.readouterr().err
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert steps[1]["time_step"] == 0.5 and steps[-1]["time"] == 2.0
