"""Run a scene into an output folder: what ``hmatddm run`` and ``hmatddm render`` do.

The folder (``--out DIR``) holds::

    summary.json        scene (validated echo, SI), versions, steps (the record of the
                        initial state, step 0, then one record per step, each with its
                        fluid budget), reference (closed form at each step, or null;
                        null values at t = 0, where the closed forms are singular),
                        wall_seconds (every session of the run together); rewritten
                        atomically after every step, so a partial or interrupted run
                        is always readable
    scene.toml          the validated scene (every default filled in); `--resume`
                        without a SCENE reads it
    fractures.pvd       ParaView time series of the .vtu files
    vtu/step-NNNNNN.vtu cell data: opening (m), slip (vector, m), pressure (Pa),
                        net_pressure (Pa, pressure minus the compressive normal far-field
                        stress), fracture_id, state (0 hydraulic, 1 intact natural,
                        2 activated or failed natural), dd (vector, m); with [proppant]
                        proppant_fraction (volume fraction) and propped_width (m, the
                        packed bed's width V / (c_max S))
    checkpoints/        the simulation's atomic checkpoints (one per step, newest kept)
    snapshots/step-NNNNNN_plan.png, _oblique.png   views of the last state (plan
                        only in 2D; the plan view of vertical 3D fractures shows their
                        traces, coloured by the largest opening over the height)
    snapshots/step-NNNNNN_profile.png   every saved step (those with a .vtu): the
                        opening and net pressure along each fracture (2D) or along
                        both in-plane axes through the injection point (3D), with
                        the closed form of a [reference] and its relative error
    snapshots/step-NNNNNN_front.png     the last state of an asymptotic front: the tip
                        regime K^ = K' s^(1/2) / (E' w) of its ribbon elements round
                        the injection point (1 toughness, 0 viscosity)
    snapshots/step-NNNNNN_proppant.png  with [proppant]: the proppant volume fraction of
                        the last state on the fractures (side view of vertical 3D fractures)
    proppant_history.png  with [proppant]: proppant mass pumped and in the fractures
                        against time (summary.json's proppant_injected_mass, proppant_mass)
    rate_split.png      with a [well]: the rate into each cluster, its share and the
                        perforation friction against time (summary.json's cluster_rates,
                        cluster_pressures, perforation_friction, heel_pressure)
    history.png         size, opening and wellbore pressure against time, with the
                        closed form overlaid when the scene has a [reference]; the
                        tips against the interfaces in a layered run; the fluid budget
    movie.gif           (hmatddm render DIR --movie) the profile pictures in turn
    monitor.csv, .png   with [[monitor]] tables: displacement and tilt at their
                        positions after every step (:mod:`hmatddm.app.monitor`)

Progress goes to stderr (:class:`Progress`); nothing is printed with ``quiet=True``.
The folder's names, fields, pictures and reading a run back are :mod:`hmatddm.app.run_folder`'s
(re-exported here); this module runs a scene into it.
"""
import sys
import time
from pathlib import Path

from ..errors import HmatddmError, InputError, OutputError
from ..io import atomic_output, write_pvd, write_vtu
from ..simulation.progress import Progress
from .run_folder import (CHECKPOINT_DIR, HISTORY, MOVIE, PROPPANT_HISTORY, PVD, RATE_SPLIT,  # noqa: F401  (re-exported)
                         SCENE_FILE, SNAPSHOT_DIR, SUMMARY, SUMMARY_KEYS, VTU_DIR,
                         cell_fields, latest_state, layer_interfaces, mesh_from_vtu, read_pvd_entries,
                         read_summary, render_folder, snapshot_title, snapshot_views, versions, vtu_name,
                         vtu_steps, write_history, write_json, write_snapshots)
from .proppant import proppant_fields, write_proppant_history, write_proppant_snapshot
from ..simulation import checkpoint as checkpoints


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
        self._last_saved_step = None
        self._stress = None
        self._monitor = None
        self._initial = None  # the record of step 0 (hmatddm.simulation.records.initial_record)
        self.resumed = False  # whether this session continued a run from a checkpoint
        self._plotter = None  # the ProfilePlotter of the profile pictures, made at the first
        self.profile_seconds = 0.0  # CPU seconds spent on the profile pictures of this session
        self._encoded_records = {}  # summary.json's step records, encoded once (_write_summary)

    # -- public -----------------------------------------------------------------------
    @property
    def records(self):
        return [] if self.simulation is None else self.simulation.records

    @property
    def last_record(self):
        return self.records[-1] if self.records else None

    @property
    def steps(self):
        """The records of summary.json: the initial state (step 0), then every step."""
        return ([] if self._initial is None else [self._initial]) + list(self.records)

    @property
    def session_seconds(self):
        """Wall seconds of this session of the run (a resumed run's own time)."""
        return time.perf_counter() - self._started if self._started else 0.0

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
        from ..errors import ConvergenceError, SizeLimitError
        from ..scene import build_simulation

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
        if "monitor" in scene:  # displacement and tilt at points (hmatddm.app.monitor)
            from .monitor import Monitor

            self._monitor = Monitor(self.out, scene["monitor"], simulation.state.mesh.dim, note=self.note)
            if self.resume:
                self._monitor.resume(simulation.state.step)
        from ..simulation.records import initial_record

        self._initial = initial_record(simulation)
        start_time = simulation.state.time
        self.progress = Progress(numerics["end_time"], simulation.time_step, stream=self.stream,
                                 enabled=not self.quiet, start_time=start_time)
        self._warn_reference()
        step = simulation.state.step
        if step == 0 or (step % scene["output"]["every"] == 0 and self._last_vtu_step != step):
            self._write_vtu(simulation.state)  # t = 0, or a step whose .vtu an interruption cut off
        self._write_summary()
        if start_time > numerics["end_time"] + 1e-9 * simulation.time_step:
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

    def _warn_reference(self):
        """One line when the scene's [reference] closed form does not apply over the run
        (hmatddm.scene.reference_warning: its regime number), naming the one that does."""
        from ..scene import reference_warning

        warning = reference_warning(self.scene.data)
        if warning:
            self.note(f"hmatddm: warning: {warning}")

    # -- folder -------------------------------------------------------------------------
    def _holds_a_run(self):
        """Whether the folder holds a run worth keeping: at least one finished step (a
        checkpoint, a summary with steps, or a .vtu past step 0). A run refused or failed
        before its first step does not claim the folder."""
        if checkpoints.list_checkpoints(self.out / CHECKPOINT_DIR) or any(step > 0 for step in vtu_steps(self.out)):
            return True
        try:
            summary = read_summary(self.out)
        except InputError:  # unreadable: not ours to judge, keep it
            return True
        return any(int(step.get("step", 1)) > 0 for step in (summary or {}).get("steps") or ())

    def _clear(self):
        """Remove the files an earlier run wrote (only ours, by name)."""
        names = [self.out / SUMMARY, self.out / PVD, self.out / HISTORY, self.out / SCENE_FILE, self.out / MOVIE,
                 self.out / PROPPANT_HISTORY, self.out / RATE_SPLIT]
        names += [self.out / name for name in ("events.csv", "microseismic_map.png", "events.xml")]  # microseismic
        names += [self.out / name for name in ("monitor.csv", "monitor.png")]  # hmatddm.app.monitor
        folder = self.out / CHECKPOINT_DIR
        names += list(folder.glob("step-*.json")) + list(folder.glob("step-*.npz"))
        names += list((self.out / VTU_DIR).glob("step-*.vtu")) + list((self.out / SNAPSHOT_DIR).glob("step-*.png"))
        for path in names:
            path.unlink(missing_ok=True)

    def _prepare_folder(self, simulation):
        from ..scene import to_toml

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
            self.resumed = True
            step = simulation.state.step
            summary = read_summary(out)
            if summary is not None:
                self._wall_before = float(summary.get("wall_seconds") or 0.0)
            times = {0: 0.0, **{int(r["step"]): float(r["time"]) for r in simulation.records}}
            for old in vtu_steps(out):
                if old > step or old not in times:  # written after the checkpoint we resume from
                    (out / vtu_name(old)).unlink(missing_ok=True)
                else:
                    self._pvd_entries.append((times[old], vtu_name(old)))
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
        from .._version import __version__

        header = (f"Scene {self.scene.name!r} as validated by hmatddm {__version__} (SI units, stresses compressive "
                  f"positive, every default filled in).\nContinue this run with: hmatddm run --out {out} --resume")
        with atomic_output(out / SCENE_FILE) as temporary:
            temporary.write_text(to_toml(self.scene.data, header), encoding="utf-8")

    # -- per step ------------------------------------------------------------------------
    def _write_vtu(self, state):
        """The .vtu file (``output.vtu``) and the profile picture (``output.snapshots``) of
        a saved step (every ``output.every``-th step and the last).

        Every saved step gets its picture: 0.13 s of CPU each (matplotlib on one reused
        figure; the closed form of a [reference] is tabulated in time,
        :mod:`hmatddm.analytical.transition_table`), 15 % of the default run of 50 saved
        steps on an Intel Xeon at dgemm 67 GFLOP/s (``benchmarks/bench_pictures.py``,
        RESULTS.md, issue 38)."""
        output = self.scene.data["output"]
        profile = output["snapshots"]
        if not (output["vtu"] or profile):
            return
        mesh, dd, pressure, codes = self.simulation.view()
        fields = cell_fields(mesh, dd, pressure, self._stress, codes)
        fields.update(proppant_fields(self.simulation))  # proppant_fraction, propped_width ([proppant])
        if profile:
            self._write_profile(mesh, fields, state)
        self._last_saved_step = state.step
        if not output["vtu"]:
            return
        write_vtu(self.out / vtu_name(state.step), mesh, fields)
        self._pvd_entries = [(t, name) for t, name in self._pvd_entries if name != vtu_name(state.step)]
        self._pvd_entries.append((state.time, vtu_name(state.step)))
        write_pvd(self.out / PVD, self._pvd_entries)
        self._last_vtu_step = state.step
        self.written["vtu"] += 1

    def _write_profile(self, mesh, fields, state):
        from ..render.profiles import ProfilePlotter
        from .profiles import write_profile

        clock = time.process_time()
        if self._plotter is None:
            self._plotter = ProfilePlotter()
        title = snapshot_title(self.scene.name, state.time, mesh, fields.get("state"))
        try:
            path = write_profile(self.out / SNAPSHOT_DIR, mesh, fields, state.step, state.time, self.scene.data,
                                 title, plotter=self._plotter)
        except OutputError:
            raise
        except HmatddmError as error:  # a picture that cannot be drawn does not stop the run
            self.note(f"hmatddm: warning: no profile picture of step {state.step}: {error}")
            return
        finally:
            self.profile_seconds += time.process_time() - clock
        if path is not None:
            self.written.setdefault("profiles", []).append(path)

    def _is_last(self, record):
        numerics = self.scene.data["numerics"]
        return record["time"] >= numerics["end_time"] - 1e-9 * record["time_step"]

    def _after_step(self, simulation, record):
        every = self.scene.data["output"]["every"]
        if record["step"] % every == 0 or self._is_last(record):
            self._write_vtu(simulation.state)
        if self._monitor is not None:
            self._monitor.record(simulation, record)
        self._write_summary()
        self.progress.update(record)

    def summary(self):
        from ..scene import reference_values

        wall = self._wall_before + self.session_seconds
        reference = reference_values(self.scene.data, self.records)
        if reference is not None and self._initial is not None:  # the closed forms are singular at t = 0
            keys = reference[0] if reference else {"time": None}
            initial = {key: None for key in keys}
            initial["time"] = 0.0
            if "relative_error" in keys:
                initial["relative_error"] = {key: None for key in keys["relative_error"]}
            reference = [initial] + reference
        return {"scene": self.scene.to_dict(), "versions": versions(), "steps": self.steps,
                "reference": reference, "wall_seconds": wall}

    def _write_summary(self, final=False):
        """summary.json after a step, each record encoded once (:func:`.run_folder.json_text`:
        a record does not change once its step is accepted); the final one from scratch."""
        document = self.summary()
        write_json(self.out / SUMMARY, document, None if final else self._encoded_records)
        return document

    # -- the end -------------------------------------------------------------------------
    def _finish(self):
        """Last VTU, snapshots and history of the last converged state; final summary."""
        state = self.simulation.state
        output = self.scene.data["output"]
        if self._last_saved_step != state.step:  # the last converged state's .vtu and profile
            self._write_vtu(state)
        if output["snapshots"]:
            mesh, dd, pressure, codes = self.simulation.view()
            fields = cell_fields(mesh, dd, pressure, self._stress, codes)
            try:
                front = None if state.front_class is None else (state.front_distance, state.front_velocity,
                                                                    state.front_class)
                self.written["snapshots"] = write_snapshots(self.out, mesh, fields, state.step, state.time,
                                                            self.scene.name, layer_interfaces(self.scene.data),
                                                            self.scene.data, front)
                from .fronts import write_tip_regime

                regime = write_tip_regime(self.out / SNAPSHOT_DIR, mesh, fields, front, self.scene.data, state.step,
                                          state.time, snapshot_title(self.scene.name, state.time, mesh))
                if regime is not None:
                    self.written["snapshots"].append(regime)
            except OutputError:
                raise
            except HmatddmError as error:  # e.g. no offscreen OpenGL on this machine
                self.note(f"hmatddm: warning: no snapshots written: {error}")
        if output["snapshots"] and self.simulation.proppant is not None:  # concentration on the fractures
            self.written["snapshots"].append(write_proppant_snapshot(self.out, self.simulation, self.scene.name))
        if output["history_plot"]:
            self.written["history"] = write_history(self.out, self.steps, self.scene.data)
            if self.simulation.proppant is not None:  # proppant mass pumped and in place
                self.written["proppant_history"] = write_proppant_history(self.out, self.steps, self.scene.name)
            if self.simulation.well is not None:  # the rate split of the clusters (issue 35)
                from ..render.well import plot_rate_split

                self.written["rate_split"] = plot_rate_split(self.steps, self.out / RATE_SPLIT,
                                                             title=f"{self.scene.name}: rate split")
        if self._monitor is not None:
            self.written["monitor"] = self._monitor.plot(self.scene.name)
        if "microseismic" in self.scene.data:  # events.csv and the event map (ref. Ch. 7)
            from .catalogue import write_catalogue

            try:
                self.written["microseismic"], _ = write_catalogue(self.out, self.scene.data["microseismic"],
                                                                  name=self.scene.name)
            except OutputError:
                raise
            except HmatddmError as error:  # e.g. a receiver on an event: the run itself is fine
                self.note(f"hmatddm: warning: no microseismic catalogue written: {error}")
        return self._write_summary(final=True)


def run_scene(scene, out, resume=False, overwrite=False, quiet=False, stream=None):
    """Run ``scene`` (a Scene, an embedded name or a .toml path) into ``out``; returns
    the summary dict. See :class:`SceneRun`."""
    from ..scene import load_scene

    return SceneRun(load_scene(scene), out, resume=resume, overwrite=overwrite, quiet=quiet,
                    stream=stream).execute()


__all__ = ["SceneRun", "run_scene", "render_folder", "latest_state", "Progress", "cell_fields", "versions",
           "read_summary", "SUMMARY_KEYS"]
