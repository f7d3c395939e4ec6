"""An event catalogue from a finished run: what ``hmatddm run`` (with a ``[microseismic]``
scene section) and ``hmatddm microseismic OUT_DIR`` write (ref. Sec. 7.4).

    DIR/events.csv            one row per event (columns in :data:`CSV_COLUMNS`)
    DIR/microseismic_map.png  plan view: located events coloured by Mw over the fracture
                              traces, observation wells marked (ref. Figs 7.6, 7.9-7.10)
    DIR/events.xml            the catalogue as QuakeML (origins, Mw, moment tensors) when
                              ObsPy imports (`pip install ".[seismology]"`,
                              :mod:`hmatddm.app.quakeml`)

Events are the failed natural-fracture elements that pass the shear filter (ref. Eq.
7.29) in the last state of the run, with their final DD (ref. Eq. 7.14) and the time of
the first saved state (.vtu series) in which they slip; the forward model records them
at the receivers of the wells, noise is added (seeded) and they are located from the
S-P time and direction (ref. Eqs 7.23-7.25) and their moment estimated with Brune's
equation and the RMS radiation factors (ref. Eq. 7.26), as an analyst would.
A plane-strain (2D) run is embedded in the plane z = 0; each element's area is its
length times the scene's flow height.
"""
import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_output
from ..microseismic.forward import observe, receivers_of
from ..microseismic.inversion import brune_moment, locate
from ..microseismic.monitoring import MonitoringSettings, check_section, settings_from_section  # noqa: F401
from ..microseismic.noise import add_noise
from ..microseismic.sources import DEFAULT_SHEAR_RATIO, SlipOnset, shear_events

EVENTS_CSV = "events.csv"
MAP_PNG = "microseismic_map.png"
OUTPUT_FILES = (EVENTS_CSV, MAP_PNG)
FAILED_NATURAL = 2
CSV_COLUMNS = ("event", "time_s", "step", "fracture_id", "elements", "x_m", "y_m", "z_m", "located_x_m",
               "located_y_m", "located_z_m", "location_error_m", "M0_Nm", "Mw", "Mw_brune_p", "Mw_brune_s",
               "potency_m3", "area_m2", "M_xx", "M_yy", "M_zz", "M_xy", "M_xz", "M_yz", "iso", "dc", "clvd")


# ---------------------------------------------------------------------------------
# Reading a run
# ---------------------------------------------------------------------------------

@dataclass
class RunState:
    """The last state of a run with the slip onset of its elements.

    ``mesh`` (hmatddm mesh), ``dd`` (N, d), ``state`` (N,) element codes (0 hydraulic, 1
    intact natural, 2 failed natural), ``time``, ``step``, ``onset`` (:class:`SlipOnset`),
    ``height`` (2D flow height, m)."""

    mesh: object
    dd: np.ndarray
    state: np.ndarray
    time: float
    step: int
    onset: SlipOnset
    height: float

    def plan_traces(self):
        """``(p0, p1, state)``: the plan segments of every element (for maps)."""
        from ..simulation.natural import plan_segments

        p0, p1, _ = plan_segments(self.mesh)
        return p0, p1, self.state

    def element_areas(self):
        return self.mesh.areas * (self.height if self.mesh.dim == 2 else 1.0)


def _slipping(data):
    state = np.asarray(data.get("state", np.zeros(len(data["opening"]))), dtype=np.int64)
    return (state == FAILED_NATURAL) & (np.linalg.norm(np.asarray(data["slip"], dtype=float), axis=1) > 0.0)


def read_run(out, height=None):
    """The :class:`RunState` of a run folder from its .vtu series (``fractures.pvd``).

    ``height``: the 2D flow height (default: from the run's summary.json, else 1 m)."""
    from ..io import read_pvd, read_vtu
    from .run_folder import PVD, mesh_from_vtu, read_summary

    out = Path(out)
    if not out.is_dir():
        raise InputError(f"{str(out)!r} is not a folder; give the --out folder of an `hmatddm run`")
    if height is None:
        summary = read_summary(out)
        height = float((summary or {}).get("scene", {}).get("height", 1.0) or 1.0)
    if not (out / PVD).is_file():
        raise InputError(f"{str(out)!r} holds no {PVD}: the microseismic catalogue needs the .vtu series of a run "
                         "(output.vtu = true)")
    entries = sorted(read_pvd(out / PVD), key=lambda entry: entry[0])
    if not entries:
        raise InputError(f"{out / PVD} lists no .vtu file")
    onset = SlipOnset()
    for time_value, name in entries:
        points, cells, data = read_vtu(out / name)
        mesh = mesh_from_vtu(points, cells, data)
        suffix = Path(name).stem.rsplit("-", 1)[-1]  # vtu/step-NNNNNN.vtu
        step = int(suffix) if suffix.isdigit() else 0
        onset.tolerance = 1e-6 * float(np.max(mesh.radii))
        onset.observe(mesh.centers, _slipping(data), time_value, step)
    dd = np.asarray(data["dd"], dtype=float)[:, :mesh.dim]
    # orient each rebuilt normal so that DD.n is the stored opening (the + face convention)
    # (a safeguard: the writer keeps the orientation; closed elements, whose opening is
    # round-off, decide nothing)
    stored = np.asarray(data["opening"], dtype=float)
    along = np.sum(dd * mesh.normals, axis=1)
    flip = (along * stored < 0.0) & (np.abs(stored) > 1e-6 * np.linalg.norm(dd, axis=1))
    if np.any(flip):
        mesh = _flipped(mesh, flip)
    state = np.asarray(data.get("state", np.zeros(mesh.n_elements)), dtype=np.int64)
    return RunState(mesh=mesh, dd=dd, state=state, time=float(time_value), step=step, onset=onset,
                    height=float(height))


def _slip_magnitude(mesh, dd):
    dd = np.asarray(dd, dtype=float).reshape(mesh.n_elements, mesh.dim)
    normal_part = np.sum(dd * mesh.normals, axis=1)
    return np.linalg.norm(dd - normal_part[:, None] * mesh.normals, axis=1)


def onset_recorder(onset):
    """A ``callback(simulation, record)`` for :meth:`hmatddm.Simulation.run` that feeds
    :class:`SlipOnset` ``onset`` from ``simulation.view()`` after every step (the onset of
    each event to the step, where a run folder's .vtu series has ``output.every``)."""
    def record(simulation, step_record):
        mesh, dd, _, state = simulation.view()
        onset.tolerance = 1e-6 * float(np.max(mesh.radii))
        slipping = (state == FAILED_NATURAL) & (_slip_magnitude(mesh, dd) > 0.0)
        onset.observe(mesh.centers, slipping, step_record["time"], step_record["step"])
    return record


def run_state_from_simulation(simulation, onset=None, height=1.0):
    """The :class:`RunState` of a :class:`hmatddm.Simulation` after (part of) its run;
    ``onset`` as filled by :func:`onset_recorder` (None: every event at the last step)."""
    mesh, dd, _, state = simulation.view()
    return RunState(mesh=mesh, dd=np.asarray(dd, dtype=float).reshape(mesh.n_elements, mesh.dim),
                    state=np.asarray(state, dtype=np.int64), time=float(simulation.state.time),
                    step=int(simulation.state.step), onset=SlipOnset() if onset is None else onset,
                    height=float(height))


def _flipped(mesh, flip):
    """The mesh with the normals of elements ``flip`` reversed (frames' last axis)."""
    import copy

    frames = mesh.frames.copy()
    frames[flip, -1] *= -1.0
    if frames.shape[1] == 3:  # keep right-handed 3D frames: e1 x e2 = n
        frames[flip, 1] *= -1.0
    else:
        frames[flip, 0] *= -1.0
    mesh = copy.copy(mesh)
    object.__setattr__(mesh, "frames", frames)
    return mesh


def events_from_run(run, medium, shear_ratio=DEFAULT_SHEAR_RATIO, merge=False):
    """:class:`~hmatddm.microseismic.sources.Events` of a :class:`RunState`."""
    candidate = run.state == FAILED_NATURAL
    mesh = run.mesh
    return shear_events(mesh.centers[candidate], mesh.normals[candidate], run.dd[candidate],
                        run.element_areas()[candidate], medium, mesh.fracture_id[candidate], onset=run.onset,
                        final_time=run.time, final_step=run.step, shear_ratio=shear_ratio, merge=merge,
                        radius=mesh.radii[candidate])


# ---------------------------------------------------------------------------------
# Monitoring and output
# ---------------------------------------------------------------------------------

@dataclass
class Catalogue:
    """Events with what the monitoring makes of them: ``observations`` (noisy),
    ``located`` (E, 3), ``brune_p`` and ``brune_s`` (E,) moments with the RMS factors."""

    events: object
    observations: object
    located: np.ndarray
    brune_p: np.ndarray
    brune_s: np.ndarray


def monitor(events, wells, medium, noise=None, seed=0, field="wells"):
    """Record ``events`` at the receivers of ``wells``, add ``noise`` (seeded) and invert
    for the location and the Brune moments (RMS factors). ``field`` names the wells in the
    message refusing a receiver on an event."""
    receivers, well = receivers_of(list(wells))
    if len(events) == 0:
        empty = np.zeros(0)
        return Catalogue(events, None, np.zeros((0, 3)), empty, empty)
    observations = observe(events, receivers, medium, well, field=field)
    if noise is not None and not noise.is_zero:
        observations = add_noise(observations, noise, seed)
    return Catalogue(events, observations, locate(observations, medium),
                     brune_moment(observations, medium, "p"), brune_moment(observations, medium, "s"))


def _magnitude_or_blank(moment):
    from ..microseismic.sources import moment_magnitude

    return [f"{float(moment_magnitude(m)):.6f}" if np.isfinite(m) and m > 0.0 else "" for m in moment]


def write_events_csv(path, catalogue):
    """``events.csv`` of a :class:`Catalogue` (SI units; Mw_brune blank where noise made
    the Brune moment <= 0)."""
    events = catalogue.events
    iso, dc, clvd = events.decomposition() if len(events) else (np.zeros(0),) * 3
    error = np.linalg.norm(catalogue.located - events.position, axis=1) if len(events) else np.zeros(0)
    brune_p, brune_s = _magnitude_or_blank(catalogue.brune_p), _magnitude_or_blank(catalogue.brune_s)
    tensor = events.moment_tensor
    path = Path(path)
    with atomic_output(path) as temporary:
        with open(temporary, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(CSV_COLUMNS)
            magnitude = events.moment_magnitude if len(events) else np.zeros(0)
            for k in range(len(events)):
                writer.writerow([k, f"{events.time[k]:.9g}", int(events.step[k]), int(events.fracture_id[k]),
                                 int(events.elements[k]), *(f"{v:.6f}" for v in events.position[k]),
                                 *(f"{v:.6f}" for v in catalogue.located[k]), f"{error[k]:.6f}",
                                 f"{events.seismic_moment[k]:.6e}", f"{magnitude[k]:.6f}", brune_p[k], brune_s[k],
                                 f"{events.potency[k]:.6e}", f"{events.area[k]:.6g}",
                                 *(f"{tensor[k, i, j]:.6e}" for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2),
                                                                         (1, 2))),
                                 f"{iso[k]:.6f}", f"{dc[k]:.6f}", f"{clvd[k]:.6f}"])
    return path


def read_events_csv(path):
    """``events.csv`` as a dict of columns (floats; blanks as NaN)."""
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    return {name: np.array([float(row[name]) if row[name] != "" else np.nan for row in rows])
            for name in CSV_COLUMNS}


def write_catalogue(out, section, name=None, height=None):
    """Events, monitoring, ``events.csv`` and ``microseismic_map.png`` of the run in
    ``out`` with the settings of a validated ``[microseismic]`` ``section``; returns
    ``(paths, catalogue)``."""
    from ..render.microseismic_maps import plot_event_map

    settings = settings_from_section(section)
    run = read_run(out, height=height)
    events = events_from_run(run, settings.medium, settings.shear_ratio, settings.merge)
    catalogue = monitor(events, settings.wells, settings.medium, settings.noise, settings.seed,
                        field="microseismic.wells")
    out = Path(out)
    csv_path = write_events_csv(out / EVENTS_CSV, catalogue)
    wells = np.array([[w.x, w.y] for w in settings.wells])
    noise = settings.noise
    title = (f"{name or out.name}: {len(events)} events at t = {run.time:g} s, {len(wells)} well(s); noise "
             f"{noise.rotation_deg:g} deg, {1e3 * noise.travel_time:g} ms, {100 * noise.amplitude_share:g}%")
    map_path = plot_event_map(out / MAP_PNG, run.plan_traces(), wells, catalogue.located,
                              events.moment_magnitude if len(events) else np.zeros(0),
                              true_positions=None if noise.is_zero else events.position, title=title)
    paths = [csv_path, map_path]
    from .quakeml import QUAKEML, obspy_available, write_quakeml

    if obspy_available():  # the optional seismology extra: the catalogue as QuakeML too (issue 35)
        paths.append(write_quakeml(out / QUAKEML, catalogue, name=name or out.name))
    return paths, catalogue


def catalogue_for_folder(out, scene=None):
    """``hmatddm microseismic OUT_DIR [--scene FILE]``: the catalogue of the run in ``out``
    with the ``[microseismic]`` section of ``scene`` (a scene file or embedded name;
    default: the run's own scene from its summary.json). Returns ``(paths, catalogue)``."""
    from .run_folder import read_summary
    from ..scene import load_scene, scene_from_dict

    out = Path(out)
    if not out.is_dir():
        raise InputError(f"{str(out)!r} is not a folder; give the --out folder of an `hmatddm run`")
    summary = read_summary(out)
    own = scene_from_dict(summary["scene"]).data if summary is not None and "scene" in summary else None
    chosen = load_scene(scene).data if scene is not None else own
    if chosen is None:
        raise InputError(f"{str(out)!r} holds no summary.json with the run's scene: give --scene FILE with a "
                         "[microseismic] section")
    if "microseismic" not in chosen:
        where = f"scene {scene!r}" if scene is not None else f"the scene of the run in {str(out)!r}"
        raise InputError(f"{where} has no [microseismic] section (wells, receivers, wave speeds, noise); give "
                         "--scene FILE with one (e.g. `hmatddm scenes dfn-3cluster` shows one)")
    height = (own or chosen).get("height", 1.0)
    return write_catalogue(out, chosen["microseismic"], name=(own or chosen)["name"], height=height)
