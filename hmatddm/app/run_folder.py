"""The output folder of a run (see :mod:`hmatddm.app.runner` for its layout): file names,
summary.json, the per-element fields of the .vtu files, the pictures of a state, and
reading a finished or partial run back (``hmatddm render``).
"""
import json
import math
import platform
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_output, read_vtu
from ..mesh import Mesh2D, Mesh3D
from ..simulation import checkpoint as checkpoints


SUMMARY = "summary.json"
SCENE_FILE = "scene.toml"
PVD = "fractures.pvd"
VTU_DIR = "vtu"
CHECKPOINT_DIR = "checkpoints"
SNAPSHOT_DIR = "snapshots"
HISTORY = "history.png"
MOVIE = "movie.gif"
PROPPANT_HISTORY = "proppant_history.png"
RATE_SPLIT = "rate_split.png"  # a run with a [well] (issue 35): hmatddm.render.well
SUMMARY_KEYS = ("scene", "versions", "steps", "reference", "wall_seconds")
HYDRAULIC = 0


# ---------------------------------------------------------------------------------
# Small helpers
# ---------------------------------------------------------------------------------

def versions():
    """Versions of hmatddm, numpy, scipy, numba and python."""
    import numba
    import scipy

    from .._version import __version__

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


def _compact(value):
    return json.dumps(_json_safe(value), allow_nan=False)


def json_text(document, encoded=None):
    """The text of a JSON document (a dict): indented, except that each entry of a list
    of dicts at the top level (summary.json's ``steps`` and ``reference``) takes one compact
    line. json's indenting encoder is pure Python, ~3x slower than its compact one, and
    summary.json is written after every step: re-encoding every record each time made its
    cost grow as the steps squared (1.4 s of CPU in the 203 writes of a 203-step run).
    ``encoded`` (a dict the caller keeps between writes): the text of each record of
    ``steps`` already encoded, by identity; only for records that no longer change once
    written (the ``reference`` entries are made anew each time and encoded each time)."""
    parts = []
    for key, value in document.items():
        if isinstance(value, list) and value and all(isinstance(entry, dict) for entry in value):
            lines = checkpoints.encoded_once(value, encoded if key == "steps" else None, _compact)
            body = "[\n  " + ",\n  ".join(lines) + "\n ]"
        else:
            body = json.dumps(_json_safe(value), indent=1, allow_nan=False)
        parts.append(f" {json.dumps(str(key))}: {body}")
    return "{\n" + ",\n".join(parts) + "\n}" if parts else "{}"


def write_json(path, document, encoded=None):
    """Write ``document`` (a dict) as plain JSON (:func:`json_text`), atomically."""
    text = json_text(document, encoded)
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


def vtu_name(step):
    return f"{VTU_DIR}/step-{step:06d}.vtu"


def vtu_steps(out):
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
# Fields, VTU and pictures
# ---------------------------------------------------------------------------------

def cell_fields(mesh, dd, pressure, stress, state=None):
    """Per-element fields written to the .vtu files (see the docstring of :mod:`hmatddm.app.runner`)."""
    from ..elasticity.solve import opening, slip  # numba: loaded when a run writes, not when it is checked

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


def write_snapshots(out, mesh, fields, step, time_value, title_prefix, interfaces=(), scene=None, front=None):
    """``snapshots/step-NNNNNN_{plan,oblique}.png`` of one state (and ``_side.png``, each
    cluster's fracture face on, for a 3D scene with a [well]); returns the paths.
    ``interfaces``: layer interface heights, drawn across a 2D section. The plan view
    draws the tracked front (``front``: the asymptotic front's arrays ``(front_distance,
    front_velocity, front_class)``, else the element front) and the closed form's front
    of ``scene``'s [reference] (:func:`hmatddm.app.fronts.front_curves`)."""
    from ..render import snapshot
    from .fronts import front_curves

    title = snapshot_title(title_prefix, time_value, mesh, fields.get("state"))
    slip_vectors = _visible_slip(mesh, fields["slip"], fields["opening"])
    curves = front_curves(mesh, fields.get("state"), scene, time_value, front)
    written = [snapshot(mesh, Path(out) / SNAPSHOT_DIR / f"step-{step:06d}_{view}.png", opening=fields["opening"],
                        state=fields.get("state"), slip=slip_vectors, view=view, title=title, interfaces=interfaces,
                        curves=curves if view == "plan" else ())
               for view in snapshot_views(mesh)]
    if mesh.dim == 3 and scene is not None and "well" in scene:  # each cluster's fracture face on (issue 35)
        from ..render.well import plot_side_view

        state = fields.get("state")
        hydraulic = np.ones(mesh.n_elements, bool) if state is None else np.asarray(state) == 0
        ids = np.unique(mesh.fracture_id[hydraulic])
        ids = ids[ids < len(scene["initial_fracture"])]  # the fractures of the clusters, in scene order
        written.append(plot_side_view(mesh.subset(np.flatnonzero(hydraulic)), np.asarray(fields["opening"])[hydraulic],
                                      ids, Path(out) / SNAPSHOT_DIR / f"step-{step:06d}_side.png",
                                      scene["well"]["direction"], interfaces, title=title))
    return written


def write_history(out, records, scene):
    """``history.png`` with the closed form overlaid; None when there is nothing to plot."""
    from ..render import plot_history
    from ..scene import confining_stress, reference_curves

    if not records:
        return None
    interfaces = layer_interfaces(scene)
    if scene is not None and scene.get("reference", {}).get("kind") == "three-layer-height":  # equilibrium tips
        from ..scene.height_reference import equilibrium_tips

        return plot_history(records, Path(out) / HISTORY, reference=equilibrium_tips(scene, records),
                            interfaces=interfaces)
    end_time = max(r["time"] for r in records)
    # (a run stopped in its first step has the initial state only: no closed form at t = 0)
    reference = reference_curves(scene, end_time=end_time) if scene is not None and end_time > 0.0 else None
    confining = confining_stress(scene) if scene is not None and reference is not None else 0.0
    if reference is not None and "net_pressure" not in reference:
        confining = 0.0
    return plot_history(records, Path(out) / HISTORY, reference=reference, confining_stress=confining,
                        interfaces=interfaces)


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
        from ..scene import far_field_stress, scene_from_dict

        stress = far_field_stress(scene_from_dict(summary["scene"]).data)
    if checkpoints.list_checkpoints(out / CHECKPOINT_DIR):
        arrays, metadata = checkpoints.load_latest(out / CHECKPOINT_DIR)
        mesh = _mesh_from_checkpoint(arrays)
        if stress is None:
            stress = np.zeros((mesh.dim, mesh.dim))
        state = np.where(arrays["origin"] >= 1, 2, 0).astype(np.int64) if "origin" in arrays else None
        fields = cell_fields(mesh, arrays["dd"], arrays["pressure"], stress, state)
        if "front_class" in arrays:  # the asymptotic front's arrays (hmatddm.app.fronts)
            fields["front"] = (arrays["front_distance"], arrays["front_velocity"], arrays["front_class"])
        if "proppant_volume" in arrays:  # a run with [proppant] (issue 34)
            fields["proppant_volume"] = np.asarray(arrays["proppant_volume"], dtype=float)
        return mesh, fields, int(metadata["step"]), float(metadata["time"])
    steps = vtu_steps(out)
    if not steps:
        raise InputError(f"{str(out)!r} holds no checkpoint and no .vtu file; give the --out folder of an "
                         "`hmatddm run`")
    step = steps[-1]
    points, cells, data = read_vtu(out / vtu_name(step))
    mesh = mesh_from_vtu(points, cells, data)
    fields = {"opening": np.asarray(data["opening"], dtype=float),
              "slip": np.asarray(data["slip"], dtype=float)[:, :mesh.dim],
              "state": np.asarray(data.get("state", np.zeros(mesh.n_elements)), dtype=np.int64)}
    if "proppant_fraction" in data:  # a run with [proppant] (issue 34)
        fields["proppant_fraction"] = np.asarray(data["proppant_fraction"], dtype=float)
    times = dict(read_pvd_entries(out))
    return mesh, fields, step, float(times.get(vtu_name(step), float("nan")))


def read_pvd_entries(out):
    from ..io import read_pvd

    path = Path(out) / PVD
    return [(name, time_value) for time_value, name in read_pvd(path)] if path.is_file() else []


def saved_states(out):
    """``(mesh, fields, step, time)`` of every saved step of an output folder, read from its
    .vtu files (oldest first; ``fields``: opening, net_pressure, state; time from the .pvd,
    NaN when it does not list the file)."""
    out = Path(out)
    times = dict(read_pvd_entries(out))
    for step in vtu_steps(out):
        points, cells, data = read_vtu(out / vtu_name(step))
        mesh = mesh_from_vtu(points, cells, data)
        fields = {"opening": np.asarray(data["opening"], dtype=float),
                  "net_pressure": np.asarray(data["net_pressure"], dtype=float),
                  "state": np.asarray(data.get("state", np.zeros(mesh.n_elements)), dtype=np.int64)}
        yield mesh, fields, step, float(times.get(vtu_name(step), float("nan")))


def write_profiles(out, scene, name):
    """``snapshots/step-NNNNNN_profile.png`` of every saved step (:func:`saved_states`);
    returns the paths."""
    from ..render.profiles import ProfilePlotter
    from .profiles import write_profile

    plotter, written = ProfilePlotter(), []
    for mesh, fields, step, time_value in saved_states(out):
        title = snapshot_title(name, time_value, mesh, fields["state"])
        path = write_profile(Path(out) / SNAPSHOT_DIR, mesh, fields, step, time_value, scene, title, plotter=plotter)
        if path is not None:
            written.append(path)
    return written


def write_movie(out, pictures, seconds_per_frame=0.4):
    """``movie.gif``: the ``pictures`` (PNG paths, in order) as an animated GIF (Pillow, a
    dependency of pyvista), each shown ``seconds_per_frame`` and the last one a second
    longer; returns its path."""
    from PIL import Image

    from ..io import atomic_output

    if not pictures:
        raise InputError(f"{str(out)!r} holds no saved step to animate (no .vtu file)")
    frames = [Image.open(path).convert("RGB") for path in pictures]
    size = frames[0].size
    frames = [frame if frame.size == size else frame.resize(size) for frame in frames]
    durations = [int(1000 * seconds_per_frame)] * len(frames)
    durations[-1] += 1000
    path = Path(out) / MOVIE
    with atomic_output(path) as temporary:
        frames[0].save(temporary, format="GIF", save_all=True, append_images=frames[1:], duration=durations, loop=0)
    return path


def _proppant_snapshot(out, mesh, fields, step, time_value, scene, name):
    """``snapshots/step-NNNNNN_proppant.png`` of a state read back (a checkpoint's proppant
    volumes, or a .vtu's ``proppant_fraction``); None when the state holds neither."""
    from ..render.proppant import plot_proppant
    from ..simulation.proppant_step import volume_fraction

    section = scene["proppant"]
    fraction = fields.get("proppant_fraction")
    if fraction is None and "proppant_volume" in fields:
        numerics = scene["numerics"]
        areas = mesh.areas * (scene.get("height", 1.0) if mesh.dim == 2 else 1.0)
        minimum = numerics.get("minimum_width", numerics["initial_opening"])
        fraction = volume_fraction(fields["proppant_volume"], fields["opening"], areas, minimum,
                                   section["packing_limit"])
    if fraction is None:
        return None
    title = f"{snapshot_title(name, time_value, mesh)}: proppant volume fraction"
    return plot_proppant(mesh, fraction, Path(out) / SNAPSHOT_DIR / f"step-{step:06d}_proppant.png",
                         section["packing_limit"], title, hydraulic=np.asarray(fields.get("state", 0)) != 1)


def render_folder(out, movie=False):
    """Snapshots and profile of the newest state, the profile pictures of every saved step,
    the history plot of an output folder (a finished or partial run), and with
    ``movie=True`` ``movie.gif`` of the profile pictures; returns the written paths."""
    from ..scene import scene_from_dict

    out = Path(out)
    if not out.is_dir():
        raise InputError(f"{str(out)!r} is not a folder; give the --out folder of an `hmatddm run`")
    mesh, fields, step, time_value = latest_state(out)
    summary = read_summary(out)
    scene = scene_from_dict(summary["scene"]).data if summary is not None and "scene" in summary else None
    name = scene["name"] if scene is not None else out.name
    written = list(write_snapshots(out, mesh, fields, step, time_value, name, layer_interfaces(scene), scene,
                                   fields.get("front")))
    if fields.get("front") is not None:  # the tip regime along an asymptotic front
        from .fronts import write_tip_regime

        regime = write_tip_regime(out / SNAPSHOT_DIR, mesh, fields, fields["front"], scene, step, time_value,
                                  snapshot_title(name, time_value, mesh))
        written += [regime] if regime is not None else []
    if scene is not None and "proppant" in scene:  # the proppant snapshot of the newest state
        picture = _proppant_snapshot(out, mesh, fields, step, time_value, scene, name)
        written += [picture] if picture is not None else []
    profiles = write_profiles(out, scene, name)
    if step not in vtu_steps(out) and "net_pressure" in fields:  # the newest state is a checkpoint's
        from .profiles import write_profile

        newest = write_profile(out / SNAPSHOT_DIR, mesh, fields, step, time_value, scene,
                               snapshot_title(name, time_value, mesh, fields.get("state")))
        profiles += [newest] if newest is not None else []
    written += profiles
    if summary is not None and summary.get("steps"):
        written.append(write_history(out, summary["steps"], scene))
        if any("proppant_mass" in step for step in summary["steps"]):  # a run with [proppant]
            from ..render.proppant import plot_proppant_history

            written.append(plot_proppant_history(summary["steps"], out / PROPPANT_HISTORY,
                                                 title=f"{name}: proppant mass"))
        if any("cluster_rates" in step for step in summary["steps"]):  # a run with a [well]
            from ..render.well import plot_rate_split

            written.append(plot_rate_split(summary["steps"], out / RATE_SPLIT, title=f"{name}: rate split"))
    if movie:
        written.append(write_movie(out, profiles))
    return written


__all__ = ["SUMMARY", "SCENE_FILE", "PVD", "VTU_DIR", "CHECKPOINT_DIR", "SNAPSHOT_DIR", "HISTORY", "SUMMARY_KEYS",
           "versions", "write_json", "json_text", "read_summary", "vtu_name", "vtu_steps", "cell_fields", "snapshot_views",
           "snapshot_title", "layer_interfaces", "write_snapshots", "write_history", "mesh_from_vtu", "latest_state",
           "read_pvd_entries", "render_folder", "saved_states", "write_profiles", "write_movie", "MOVIE",
           "PROPPANT_HISTORY", "RATE_SPLIT"]
