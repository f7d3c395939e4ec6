"""Run a scene into an output folder: what ``hmatddm run`` and ``hmatddm render`` do.

The folder (``--out DIR``) holds::

    summary.json        scene (validated echo, SI), versions, steps (one record per
                        step), reference (closed form at each step, or null),
                        wall_seconds; rewritten atomically after every step, so a
                        partial or interrupted run is always readable
    scene.toml          the validated scene (every default filled in); `--resume`
                        without a SCENE reads it
    fractures.pvd       ParaView time series of the .vtu files
    vtu/step-NNNNNN.vtu cell data: opening (m), slip (vector, m), pressure (Pa),
                        net_pressure (Pa, pressure minus the compressive normal far-field
                        stress), fracture_id, state (0 hydraulic, 1 intact natural,
                        2 activated or failed natural), dd (vector, m)
    checkpoints/        the simulation's atomic checkpoints (one per step, newest kept)
    snapshots/step-NNNNNN_plan.png, _oblique.png   views of the last state (plan
                        only in 2D; the plan view of vertical 3D fractures shows their
                        traces, coloured by the largest opening over the height)
    history.png         size, opening and wellbore pressure against time, with the
                        closed form overlaid when the scene has a [reference]

Progress goes to stderr (:class:`Progress`); nothing is printed with ``quiet=True``.
"""
import json
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np

from .errors import HmatddmError, InputError, OutputError
from .io import atomic_output, read_vtu, write_pvd, write_vtu
from .mesh import Mesh2D, Mesh3D
from .progress import Progress
from .simulation import checkpoint as checkpoints

SUMMARY = "summary.json"
SCENE_FILE = "scene.toml"
PVD = "fractures.pvd"
VTU_DIR = "vtu"
CHECKPOINT_DIR = "checkpoints"
SNAPSHOT_DIR = "snapshots"
HISTORY = "history.png"
SUMMARY_KEYS = ("scene", "versions", "steps", "reference", "wall_seconds")
HYDRAULIC = 0


# ---------------------------------------------------------------------------------
# Small helpers
# ---------------------------------------------------------------------------------

def versions():
    """Versions of hmatddm, numpy, scipy, numba and python."""
    import numba
    import scipy

    from . import __version__

    return {"hmatddm": __version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "numba": numba.__version__, "python": platform.python_version()}


def _json_safe(value):
    """Plain JSON: numpy scalars and arrays converted, NaN and inf written as null."""
    if isinstance(value, dict):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return _json_safe(value.tolist())
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else None
    return value


def write_json(path, document):
    text = json.dumps(_json_safe(document), indent=1, allow_nan=False)
    with atomic_output(path) as temporary:
        temporary.write_text(text + "\n", encoding="utf-8")


def read_summary(out):
    """The summary.json of an output folder, or None when there is none."""
    path = Path(out) / SUMMARY
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise InputError(f"{path} is not a readable summary.json: {error}") from None


def _vtu_name(step):
    return f"{VTU_DIR}/step-{step:06d}.vtu"


def _vtu_steps(out):
    folder = Path(out) / VTU_DIR
    if not folder.is_dir():
        return []
    steps = []
    for path in folder.glob("step-*.vtu"):
        try:
            steps.append(int(path.stem.split("-", 1)[1]))
        except ValueError:
            continue
    return sorted(steps)


# ---------------------------------------------------------------------------------
# ---------------------------------------------------------------------------------
# Fields, VTU and pictures
# ---------------------------------------------------------------------------------

def cell_fields(mesh, dd, pressure, stress, state=None):
    """Per-element fields written to the .vtu files (see the module docstring)."""
    from .solve import opening, slip  # numba: loaded when a run writes, not when it is checked

    dd = np.asarray(dd, dtype=float).reshape(mesh.n_elements, mesh.dim)
    normal_stress = np.einsum("ei,ij,ej->e", mesh.normals, stress, mesh.normals)
    return {"opening": opening(mesh, dd), "slip": slip(mesh, dd), "pressure": np.asarray(pressure, dtype=float),
            "net_pressure": np.asarray(pressure, dtype=float) + normal_stress,
            "fracture_id": mesh.fracture_id,
            "state": np.full(mesh.n_elements, HYDRAULIC, dtype=np.int64) if state is None else state,
            "dd": dd}


def _visible_slip(mesh, slip_vectors, opening_values):
    """Slip worth drawing as arrows: None when it is round-off next to the opening."""
    largest = float(np.max(np.linalg.norm(slip_vectors, axis=1))) if len(slip_vectors) else 0.0
    scale = float(np.max(np.abs(opening_values))) if len(opening_values) else 0.0
    return slip_vectors if largest > 1e-3 * scale and largest > 0.0 else None


def snapshot_views(mesh):
    """The views worth drawing: the plan view only in 2D, plan and oblique in 3D. A
    plan view of (mostly) vertical 3D fractures, which looking down z would see edge
    on, draws their horizontal traces coloured by the largest opening over the height
    (:func:`hmatddm.render.layout.plan_traces`)."""
    if mesh.dim == 2:
        return ("plan",)
    return ("plan", "oblique")


def snapshot_title(name, time_value, mesh, state=None):
    """The title of a snapshot: the run's element count (``n_elements`` of its record:
    hydraulic and activated or failed natural elements, the unknowns), and apart from it
    the intact natural elements drawn as stress targets."""
    intact = 0 if state is None else int(np.count_nonzero(np.asarray(state) == 1))
    text = f"{name}: t = {time_value:g} s, {mesh.n_elements - intact} elements"
    return text + (f" (+ {intact} intact natural)" if intact else "")


def layer_interfaces(scene):
    """Interface heights (m) of a scene's ``[[layer]]`` tables (validated data); () without layers."""
    layers = (scene or {}).get("layer") or []
    return tuple(float(layer["bottom"]) for layer in layers[:-1])


def write_snapshots(out, mesh, fields, step, time_value, title_prefix, interfaces=()):
    """``snapshots/step-NNNNNN_{plan,oblique}.png`` of one state; returns the paths.
    ``interfaces``: layer interface heights, drawn across a 2D section."""
    from .render import snapshot

    title = snapshot_title(title_prefix, time_value, mesh, fields.get("state"))
    slip_vectors = _visible_slip(mesh, fields["slip"], fields["opening"])
    return [snapshot(mesh, Path(out) / SNAPSHOT_DIR / f"step-{step:06d}_{view}.png", opening=fields["opening"],
                     state=fields.get("state"), slip=slip_vectors, view=view, title=title, interfaces=interfaces)
            for view in snapshot_views(mesh)]


def write_history(out, records, scene):
    """``history.png`` with the closed form overlaid; None when there is nothing to plot."""
    from .render import plot_history
    from .scene import confining_stress, reference_curves

    if not records:
        return None
    reference = reference_curves(scene, end_time=max(r["time"] for r in records)) if scene is not None else None
    confining = confining_stress(scene) if scene is not None and reference is not None else 0.0
    if reference is not None and "net_pressure" not in reference:
        confining = 0.0
    return plot_history(records, Path(out) / HISTORY, reference=reference, confining_stress=confining)


# ---------------------------------------------------------------------------------
# A run
# ---------------------------------------------------------------------------------

class SceneRun:
    """One run of a scene into an output folder.

    Parameters
    ----------
    scene : hmatddm.scene.Scene
    out : path
        Output folder (created).
    resume : bool
        Continue from the newest checkpoint in ``out/checkpoints`` (a fresh start when
        there is none). The scene must be the one that wrote the checkpoints.
    overwrite : bool
        Start over in a folder that already holds a run (its files are replaced).
    quiet : bool
        No progress and no notes.
    stream : text stream for progress and notes (default stderr).

    After :meth:`execute` (or an exception in it), ``simulation``, ``records`` and
    ``last_record`` describe how far the run got.
    """

    def __init__(self, scene, out, resume=False, overwrite=False, quiet=False, stream=None):
        self.scene = scene
        self.out = Path(out)
        self.resume = resume
        self.overwrite = overwrite
        self.quiet = quiet
        self.stream = stream
        self.simulation = None
        self.progress = None
        self.written = {"vtu": 0, "snapshots": [], "history": None}
        self._pvd_entries = []
        self._wall_before = 0.0
        self._started = None
        self._last_vtu_step = None
        self._stress = None

    # -- public -----------------------------------------------------------------------
    @property
    def records(self):
        return [] if self.simulation is None else self.simulation.records

    @property
    def last_record(self):
        return self.records[-1] if self.records else None

    def note(self, text):
        if self.progress is not None:
            self.progress.note(text)
        elif not self.quiet:
            print(text, file=self.stream or sys.stderr)

    def execute(self):
        """Run to ``numerics.end_time``; returns the summary dict.

        Raises InputError (bad scene, folder already holding a run), CheckpointError
        (checkpoints of another run), OutputError (a file could not be written: full
        disk, folder not writable; a failed checkpoint leaves the previous one as the
        newest, so a resume after freeing space continues from it), ConvergenceError
        (after writing the outputs of the last converged step) and lets
        KeyboardInterrupt through (the checkpoint of the last finished step is on disk).
        """
        from .errors import ConvergenceError, SizeLimitError
        from .scene import build_simulation

        if self.resume and self.overwrite:
            raise InputError("--resume continues the run in the folder and --overwrite starts it over: give one "
                             "of them, not both")
        self._started = time.perf_counter()
        scene = self.scene.data
        numerics = scene["numerics"]
        simulation = build_simulation(scene, checkpoint_dir=self.out / CHECKPOINT_DIR)
        self._stress = simulation.far_field_stress
        self._prepare_folder(simulation)
        self.simulation = simulation
        start_time = simulation.state.time
        self.progress = Progress(numerics["end_time"], numerics["time_step"], stream=self.stream,
                                 enabled=not self.quiet, start_time=start_time)
        step = simulation.state.step
        if step == 0 or (step % scene["output"]["every"] == 0 and self._last_vtu_step != step):
            self._write_vtu(simulation.state)  # t = 0, or a step whose .vtu an interruption cut off
        self._write_summary()
        if start_time > numerics["end_time"] + 1e-9 * numerics["time_step"]:
            raise InputError(f"the run in {str(self.out)!r} is already at t = {start_time:g} s, past "
                             f"numerics.end_time = {numerics['end_time']:g} s; give a later end time (--set "
                             "numerics.end_time=...) or --overwrite to start over")
        try:
            simulation.run(numerics["end_time"], callback=self._after_step)
        except (ConvergenceError, SizeLimitError):
            self.progress.close()
            self._finish()
            raise
        except BaseException:
            self.progress.close()
            raise
        self.progress.close()
        return self._finish()

    # -- folder -------------------------------------------------------------------------
    def _holds_a_run(self):
        """Whether the folder holds a run worth keeping: at least one finished step (a
        checkpoint, a summary with steps, or a .vtu past step 0). A run refused or failed
        before its first step does not claim the folder."""
        if checkpoints.list_checkpoints(self.out / CHECKPOINT_DIR) or any(step > 0 for step in _vtu_steps(self.out)):
            return True
        try:
            summary = read_summary(self.out)
        except InputError:  # unreadable: not ours to judge, keep it
            return True
        return bool(summary and summary.get("steps"))

    def _clear(self):
        """Remove the files an earlier run wrote (only ours, by name)."""
        names = [self.out / SUMMARY, self.out / PVD, self.out / HISTORY, self.out / SCENE_FILE]
        names += [self.out / name for name in ("events.csv", "microseismic_map.png")]  # hmatddm.microseismic
        folder = self.out / CHECKPOINT_DIR
        names += list(folder.glob("step-*.json")) + list(folder.glob("step-*.npz"))
        names += list((self.out / VTU_DIR).glob("step-*.vtu")) + list((self.out / SNAPSHOT_DIR).glob("step-*.png"))
        for path in names:
            path.unlink(missing_ok=True)

    def _prepare_folder(self, simulation):
        from .scene import to_toml

        out = self.out
        if out.exists() and not out.is_dir():
            raise InputError(f"--out {str(out)!r} exists and is not a folder")
        try:  # an unwritable or full output folder is reported before any step is computed
            checkpoints.check_writable(out, what="output folder")
        except checkpoints.CheckpointWriteError as error:  # not a checkpoint problem: a plain OutputError
            raise OutputError(str(error), path=error.path, errno=error.errno) from None
        has_checkpoint = bool(checkpoints.list_checkpoints(out / CHECKPOINT_DIR))
        if self.resume and has_checkpoint:
            simulation.load_checkpoint()
            step = simulation.state.step
            summary = read_summary(out)
            if summary is not None:
                self._wall_before = float(summary.get("wall_seconds") or 0.0)
            times = {0: 0.0, **{int(r["step"]): float(r["time"]) for r in simulation.records}}
            for old in _vtu_steps(out):
                if old > step or old not in times:  # written after the checkpoint we resume from
                    (out / _vtu_name(old)).unlink(missing_ok=True)
                else:
                    self._pvd_entries.append((times[old], _vtu_name(old)))
                    self._last_vtu_step = old
            self.note(f"resuming {self.scene.name} from step {step} (t = {simulation.state.time:g} s) in {out}")
        else:
            holds = self._holds_a_run()
            if holds and not self.resume and not self.overwrite:
                raise InputError(f"--out {str(out)!r} already holds a run; add --resume to continue it or "
                                 "--overwrite to start over (or choose another folder)")
            if holds and self.resume:
                self.note(f"no checkpoint in {out / CHECKPOINT_DIR}: starting {self.scene.name} from t = 0")
            self._clear()  # our own files only (a run without a finished step is no run); others stay
        out.mkdir(parents=True, exist_ok=True)
        from . import __version__

        header = (f"Scene {self.scene.name!r} as validated by hmatddm {__version__} (SI units, stresses compressive "
                  f"positive, every default filled in).\nContinue this run with: hmatddm run --out {out} --resume")
        with atomic_output(out / SCENE_FILE) as temporary:
            temporary.write_text(to_toml(self.scene.data, header), encoding="utf-8")

    # -- per step ------------------------------------------------------------------------
    def _write_vtu(self, state):
        if not self.scene.data["output"]["vtu"]:
            return
        mesh, dd, pressure, codes = self.simulation.view()
        fields = cell_fields(mesh, dd, pressure, self._stress, codes)
        write_vtu(self.out / _vtu_name(state.step), mesh, fields)
        self._pvd_entries = [(t, name) for t, name in self._pvd_entries if name != _vtu_name(state.step)]
        self._pvd_entries.append((state.time, _vtu_name(state.step)))
        write_pvd(self.out / PVD, self._pvd_entries)
        self._last_vtu_step = state.step
        self.written["vtu"] += 1

    def _is_last(self, record):
        numerics = self.scene.data["numerics"]
        return record["time"] >= numerics["end_time"] - 1e-9 * numerics["time_step"]

    def _after_step(self, simulation, record):
        every = self.scene.data["output"]["every"]
        if record["step"] % every == 0 or self._is_last(record):
            self._write_vtu(simulation.state)
        self._write_summary()
        self.progress.update(record)

    def summary(self):
        from .scene import reference_values

        wall = self._wall_before + (time.perf_counter() - self._started if self._started else 0.0)
        return {"scene": self.scene.to_dict(), "versions": versions(), "steps": self.records,
                "reference": reference_values(self.scene.data, self.records), "wall_seconds": wall}

    def _write_summary(self):
        document = self.summary()
        write_json(self.out / SUMMARY, document)
        return document

    # -- the end -------------------------------------------------------------------------
    def _finish(self):
        """Last VTU, snapshots and history of the last converged state; final summary."""
        state = self.simulation.state
        output = self.scene.data["output"]
        if output["vtu"] and self._last_vtu_step != state.step:
            self._write_vtu(state)
        if output["snapshots"]:
            mesh, dd, pressure, codes = self.simulation.view()
            fields = cell_fields(mesh, dd, pressure, self._stress, codes)
            try:
                self.written["snapshots"] = write_snapshots(self.out, mesh, fields, state.step, state.time,
                                                            self.scene.name, layer_interfaces(self.scene.data))
            except OutputError:
                raise
            except HmatddmError as error:  # e.g. no offscreen OpenGL on this machine
                self.note(f"hmatddm: warning: no snapshots written: {error}")
        if output["history_plot"]:
            self.written["history"] = write_history(self.out, self.records, self.scene.data)
        if "microseismic" in self.scene.data:  # events.csv and the event map (ref. Ch. 7)
            from .microseismic.catalogue import write_catalogue

            try:
                self.written["microseismic"], _ = write_catalogue(self.out, self.scene.data["microseismic"],
                                                                  name=self.scene.name)
            except OutputError:
                raise
            except HmatddmError as error:  # e.g. a receiver on an event: the run itself is fine
                self.note(f"hmatddm: warning: no microseismic catalogue written: {error}")
        return self._write_summary()


def run_scene(scene, out, resume=False, overwrite=False, quiet=False, stream=None):
    """Run ``scene`` (a Scene, an embedded name or a .toml path) into ``out``; returns
    the summary dict. See :class:`SceneRun`."""
    from .scene import load_scene

    return SceneRun(load_scene(scene), out, resume=resume, overwrite=overwrite, quiet=quiet,
                    stream=stream).execute()


# ---------------------------------------------------------------------------------
# Render a finished or partial run
# ---------------------------------------------------------------------------------

def _mesh_from_checkpoint(arrays):
    if "half_a" in arrays:
        return Mesh3D(arrays["centers"], arrays["frames"], arrays["half_a"], arrays["half_b"],
                      arrays["fracture_id"].astype(np.int64))
    return Mesh2D(arrays["centers"], arrays["frames"], arrays["half_length"], arrays["fracture_id"].astype(np.int64))


def mesh_from_vtu(points, cells, cell_data):
    """Rebuild a mesh from the cells that :func:`hmatddm.io.write_vtu` writes (quads in
    3D with corners counter-clockwise about the normal, lines at z = 0 in 2D)."""
    fracture_id = np.asarray(cell_data.get("fracture_id", np.zeros(len(cells))), dtype=np.int64)
    if cells.shape[1] == 4:
        corners = points[cells]                       # (N, 4, 3)
        side_a = corners[:, 1] - corners[:, 0]
        side_b = corners[:, 3] - corners[:, 0]
        length_a = np.linalg.norm(side_a, axis=1)
        length_b = np.linalg.norm(side_b, axis=1)
        return Mesh3D.from_rectangles(corners.mean(axis=1), side_a / length_a[:, None], side_b / length_b[:, None],
                                      0.5 * length_a, 0.5 * length_b, fracture_id=fracture_id)
    if cells.shape[1] == 2:
        return Mesh2D.from_segments(points[cells[:, 0], :2], points[cells[:, 1], :2], fracture_id=fracture_id)
    raise InputError(f"cannot rebuild a mesh from cells with {cells.shape[1]} points")


def latest_state(out):
    """``(mesh, fields, step, time)`` of the newest state in an output folder: the newest
    good checkpoint, else the newest .vtu file."""
    out = Path(out)
    stress = None
    summary = read_summary(out)
    if summary is not None and "scene" in summary:
        from .scene import far_field_stress, scene_from_dict

        stress = far_field_stress(scene_from_dict(summary["scene"]).data)
    if checkpoints.list_checkpoints(out / CHECKPOINT_DIR):
        arrays, metadata = checkpoints.load_latest(out / CHECKPOINT_DIR)
        mesh = _mesh_from_checkpoint(arrays)
        if stress is None:
            stress = np.zeros((mesh.dim, mesh.dim))
        state = np.where(arrays["origin"] >= 1, 2, 0).astype(np.int64) if "origin" in arrays else None
        fields = cell_fields(mesh, arrays["dd"], arrays["pressure"], stress, state)
        return mesh, fields, int(metadata["step"]), float(metadata["time"])
    steps = _vtu_steps(out)
    if not steps:
        raise InputError(f"{str(out)!r} holds no checkpoint and no .vtu file; give the --out folder of an "
                         "`hmatddm run`")
    step = steps[-1]
    points, cells, data = read_vtu(out / _vtu_name(step))
    mesh = mesh_from_vtu(points, cells, data)
    fields = {"opening": np.asarray(data["opening"], dtype=float),
              "slip": np.asarray(data["slip"], dtype=float)[:, :mesh.dim],
              "state": np.asarray(data.get("state", np.zeros(mesh.n_elements)), dtype=np.int64)}
    times = dict(read_pvd_entries(out))
    return mesh, fields, step, float(times.get(_vtu_name(step), float("nan")))


def read_pvd_entries(out):
    from .io import read_pvd

    path = Path(out) / PVD
    return [(name, time_value) for time_value, name in read_pvd(path)] if path.is_file() else []


def render_folder(out):
    """Snapshots of the newest state and the history plot of an output folder (a
    finished or partial run); returns the written paths."""
    from .scene import scene_from_dict

    out = Path(out)
    if not out.is_dir():
        raise InputError(f"{str(out)!r} is not a folder; give the --out folder of an `hmatddm run`")
    mesh, fields, step, time_value = latest_state(out)
    summary = read_summary(out)
    scene = scene_from_dict(summary["scene"]).data if summary is not None and "scene" in summary else None
    name = scene["name"] if scene is not None else out.name
    written = list(write_snapshots(out, mesh, fields, step, time_value, name, layer_interfaces(scene)))
    if summary is not None and summary.get("steps"):
        written.append(write_history(out, summary["steps"], scene))
    return written


__all__ = ["SceneRun", "run_scene", "render_folder", "latest_state", "Progress", "cell_fields", "versions",
           "read_summary", "SUMMARY_KEYS"]
