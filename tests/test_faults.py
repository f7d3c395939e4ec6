"""Faults while writing output: a disk that fills up during a run (ENOSPC).

Issue 7 asks that an unwritable or full output folder is reported before work is lost.
A write that fails with ``ENOSPC`` is simulated by letting the file be half written and
then raising ``OSError(errno.ENOSPC)``, inside the real atomic writers (the checkpoint's
``_atomic_write`` and :func:`hmatddm.io.atomic_output`), so that their clean-up runs as
it would on a full disk. For each file that can fail we check that:

* the error reaches the user as a message naming the file's folder and saying the disk
  is full; ``hmatddm run`` exits with ``EXIT_OUTPUT`` (4) and prints the --resume command;
* no partial checkpoint is left as the newest: the previous one loads and verifies, no
  temporary file is left behind, summary.json is the previous complete one;
* after space is freed, ``--resume`` finishes the run with the numbers of a run that
  never failed.
"""
import contextlib
import errno
import importlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

import hmatddm as hd
from hmatddm.app import cli
from hmatddm import io as hio
from hmatddm.errors import OutputError
from hmatddm.simulation import checkpoint as checkpoints
from hmatddm.simulation.checkpoint import CheckpointWriteError
from scene_texts import KGD_2D_HEAD

# 4 steps of a plane-strain crack; a .vtu every 2 steps; PNGs at the end
TINY_2D = KGD_2D_HEAD + """end_time = 4.0
backend = "dense"
initial_pressure = 0.6e6
[output]
every = 2
"""
FAILING_STEP = 3


def _disk_full(path):
    return OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))


@pytest.fixture
def disk(monkeypatch):
    """``disk.fill(predicate)``: from now on, a write whose target path satisfies
    ``predicate(path, temporary)`` stops half way with ENOSPC; ``disk.free()`` undoes it."""

    class Disk:
        predicate = None
        failures = []

        def fill(self, predicate):
            self.predicate = predicate

        def free(self):
            self.predicate = None

        def full_for(self, path, temporary=None):
            if self.predicate is not None and self.predicate(Path(path), temporary):
                self.failures.append(Path(path))
                return True
            return False

    state = Disk()
    real_atomic_write = checkpoints._atomic_write
    real_atomic_output = hio.atomic_output

    def atomic_write(path, write):
        if not state.full_for(path):
            return real_atomic_write(path, write)

        def half_then_full(stream):
            import io

            buffer = io.BytesIO()
            write(buffer)
            stream.write(buffer.getvalue()[:len(buffer.getvalue()) // 2])
            raise _disk_full(path)

        return real_atomic_write(path, half_then_full)

    @contextlib.contextmanager
    def atomic_output(path):
        with real_atomic_output(path) as temporary:
            yield temporary
            if state.full_for(path, temporary):
                size = temporary.stat().st_size
                with open(temporary, "r+b") as stream:
                    stream.truncate(size // 2)
                raise _disk_full(temporary)

    monkeypatch.setattr(checkpoints, "_atomic_write", atomic_write)
    for name in ("hmatddm.app.runner", "hmatddm.app.run_folder", "hmatddm.io.vtk", "hmatddm.render.offscreen",
                 "hmatddm.render.plots", "hmatddm.app.catalogue", "hmatddm.render.microseismic_maps"):
        module = importlib.import_module(name)
        monkeypatch.setattr(module, "atomic_output", atomic_output)
    return state


def _summary_steps(out):
    return [s["step"] for s in json.loads((out / "summary.json").read_text())["steps"]]


def _no_temporaries(out):
    return [p for p in Path(out).rglob(".*") if p.is_file()]


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("full")
    scene = folder / "tiny.toml"
    scene.write_text(TINY_2D)
    assert cli.main(["run", str(scene), "--out", str(folder / "out"), "--quiet"]) == cli.EXIT_OK
    return json.loads((folder / "out" / "summary.json").read_text())["steps"]


def _same_run(steps, reference):
    assert [s["step"] for s in steps] == [s["step"] for s in reference]
    for a, b in zip(steps, reference):
        assert a["n_elements"] == b["n_elements"]
        assert a["max_opening"] == pytest.approx(b["max_opening"], rel=1e-9)
        assert a["wellbore_pressure"] == pytest.approx(b["wellbore_pressure"], rel=1e-9)


# which write fails: (name, predicate on the target path, the newest complete checkpoint
# after the failure, the steps summary.json holds after the failure)
FAULTS = {  # (summary.json starts with step 0, the initial state)
    "checkpoint arrays": (lambda p, t: p.name == f"step-{FAILING_STEP:06d}.npz", 2, [0, 1, 2]),
    "checkpoint metadata": (lambda p, t: p.name == f"step-{FAILING_STEP:06d}.json", 2, [0, 1, 2]),
    "summary.json": (lambda p, t: p.name == "summary.json" and len(json.loads(t.read_text())["steps"]) == 4,
                     3, [0, 1, 2]),
    "vtu": (lambda p, t: p.name == "step-000004.vtu", 4, [0, 1, 2, 3]),
    "snapshot png": (lambda p, t: p.name.endswith("_plan.png") and p.parent.name == "snapshots", 4, [0, 1, 2, 3, 4]),
}


@pytest.mark.parametrize("fault", list(FAULTS))
def test_full_disk_is_reported_and_the_run_resumes_after_freeing_space(tmp_path, capsys, disk, uninterrupted,
                                                                       fault):
    predicate, newest, summary_steps = FAULTS[fault]
    scene = tmp_path / "tiny.toml"
    scene.write_text(TINY_2D)
    out = tmp_path / "out"
    disk.fill(predicate)
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == cli.EXIT_OUTPUT == 4
    assert disk.failures, "the fault was never triggered"
    err = capsys.readouterr().err
    folder = str(disk.failures[0].parent)
    assert f"no space left on the disk holding {folder!r} (the disk is full)" in err
    assert f"Every step up to step {newest} is checkpointed in {out / 'checkpoints'}; free disk space" in err
    assert f"hmatddm run --out {out} --resume" in err
    assert "Traceback" not in err

    # nothing half written is left, and the newest checkpoint is the previous complete one
    assert not _no_temporaries(out), "a temporary file was left behind"
    assert checkpoints.list_checkpoints(out / "checkpoints")[-1] == newest
    arrays, metadata = checkpoints.load_latest(out / "checkpoints")
    assert metadata["step"] == newest
    assert not (out / "checkpoints" / f"step-{newest + 1:06d}.npz").exists()
    assert _summary_steps(out) == summary_steps  # the previous summary.json, complete and readable

    # space freed: --resume finishes the run with the numbers of a run that never failed
    disk.free()
    assert cli.main(["run", "--out", str(out), "--resume", "--quiet"]) == cli.EXIT_OK
    steps = json.loads((out / "summary.json").read_text())["steps"]
    _same_run(steps, uninterrupted)
    assert (out / "snapshots" / "step-000004_plan.png").is_file() and (out / "history.png").is_file()
    assert sorted(p.name for p in (out / "vtu").iterdir()) == ["step-000000.vtu", "step-000002.vtu",
                                                               "step-000004.vtu"]
    assert not _no_temporaries(out)


def test_a_full_output_folder_is_reported_before_any_step(tmp_path, capsys, disk):
    scene = tmp_path / "tiny.toml"
    scene.write_text(TINY_2D)
    out = tmp_path / "out"
    disk.fill(lambda p, t: p.name == ".write-test")
    assert cli.main(["run", str(scene), "--out", str(out)]) == cli.EXIT_OUTPUT
    err = capsys.readouterr().err
    assert f"output folder {str(out)!r} is not writable: no space left on the disk holding {str(out)!r} " \
           "(the disk is full)" in err
    assert "No step was lost" in err and "step    1" not in err
    assert not (out / "summary.json").exists() and not (out / "checkpoints").exists()


def test_simulation_checkpoint_on_a_full_disk_raises_an_output_error_and_resumes(tmp_path, disk):
    def simulation():
        mesh = hd.mesh.line([-0.375, 0], [0.375, 0], 3)
        return hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-4, 4.5e-10), [hd.Cluster((0, 0), 5e-4, 0.01)],
                             far_field_stress=np.diag([0.0, -0.5e6]), time_step=1.0,
                             propagation=hd.Propagation(toughness=5e6), initial_pressure=0.6e6,
                             initial_opening=1e-5, backend="dense", checkpoint_dir=tmp_path / "ck")

    reference = simulation().run(4.0)
    for path in (tmp_path / "ck").iterdir():
        path.unlink()
    disk.fill(lambda p, t: p.name == "step-000003.json")
    first = simulation()
    with pytest.raises(CheckpointWriteError) as caught:
        first.run(4.0)
    error = caught.value
    assert isinstance(error, OutputError) and isinstance(error, hd.CheckpointError) and isinstance(error, OSError)
    assert error.disk_full and error.errno == errno.ENOSPC
    assert str(error) == (f"could not write checkpoint step-000003: no space left on the disk holding "
                          f"{str(tmp_path / 'ck')!r} (the disk is full); the newest complete checkpoint is "
                          "step 2, which a resume continues from")
    assert sorted(p.name for p in (tmp_path / "ck").iterdir()) == ["step-000001.json", "step-000001.npz",
                                                                    "step-000002.json", "step-000002.npz"]
    disk.free()
    second = simulation()
    records = second.run(4.0, resume=True)
    assert [r["step"] for r in records] == [1, 2, 3, 4]
    for a, b in zip(records, reference):
        assert a["max_opening"] == b["max_opening"] and a["wellbore_pressure"] == b["wellbore_pressure"]


def test_atomic_output_turns_a_full_disk_into_an_output_error_and_keeps_the_old_file(tmp_path):
    path = tmp_path / "data" / "table.json"
    path.parent.mkdir()
    path.write_text("old")
    with pytest.raises(OutputError) as caught:
        with hio.atomic_output(path) as temporary:
            temporary.write_text("half of the new")
            raise _disk_full(temporary)
    assert caught.value.disk_full and caught.value.path == str(path)
    assert str(caught.value) == (f"could not write {path}: no space left on the disk holding "
                                 f"{str(path.parent)!r} (the disk is full)")
    assert path.read_text() == "old" and sorted(p.name for p in path.parent.iterdir()) == ["table.json"]
    with pytest.raises(OSError):  # still an OSError for callers that catch those
        with hio.atomic_output(path):
            raise _disk_full(path)
