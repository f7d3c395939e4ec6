"""Pictures of the proppant of a run (issue 34), with matplotlib (Agg canvas, no window):

* :func:`plot_proppant`: the proppant volume fraction on the fractures. In 3D each element is
  drawn in the plane that shows the fractures face on: a side view (the horizontal in-plane
  direction against z, docs/conventions.md §3) when the fractures are mostly vertical, the plan
  view (x, y) otherwise; elements without proppant are drawn empty, so a clean (bridged) tip
  ring shows. In 2D the fraction against the position along each fracture.
* :func:`plot_proppant_history`: proppant mass pumped, in the fractures and screened out
  against time (the records' ``proppant_injected_mass``, ``proppant_mass``,
  ``proppant_screened_mass``: :mod:`hmatddm.simulation.proppant_step`).
"""
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_output


def _figure(size):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, dpi=110, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def _save(figure, path):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png")
    return path


def face_on_axes(normals):
    """The two unit axes (3,) that show 3D elements of these ``normals`` face on, and their
    labels: (horizontal in-plane direction, z) for mostly vertical fractures, else (x, y)."""
    mean = np.mean(np.abs(np.asarray(normals, float)), axis=0)
    if mean[2] < 0.5:  # vertical: look along the mean horizontal normal
        normal = np.asarray(normals, float)[0].copy()
        normal[2] = 0.0
        normal /= np.linalg.norm(normal)
        horizontal = np.cross([0.0, 0.0, 1.0], normal)
        return horizontal, np.array([0.0, 0.0, 1.0]), ("along the fracture (m)", "z (m)")
    return np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), ("x (m)", "y (m)")


def plot_proppant(mesh, fraction, path, packing_limit, title="", hydraulic=None):
    """``path`` (PNG): the proppant volume fraction ``fraction`` (N,) of ``mesh``'s elements,
    coloured from 0 to ``packing_limit``; ``hydraulic`` (N,) bool: the elements drawn (default
    all). Returns the path."""
    fraction = np.asarray(fraction, float)
    if fraction.shape != (mesh.n_elements,) or not np.all(np.isfinite(fraction)):
        raise InputError(f"fraction must be {mesh.n_elements} finite values, one per element")
    keep = np.ones(mesh.n_elements, bool) if hydraulic is None else np.asarray(hydraulic, bool)
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    norm = Normalize(0.0, packing_limit)
    cmap = colormaps["YlOrBr"]
    figure = _figure((7.0, 5.0))
    axes = figure.add_subplot()
    if mesh.dim == 3:
        from matplotlib.collections import PolyCollection

        first, second, labels = face_on_axes(mesh.normals[keep])
        corners = mesh.corners()[keep]  # (n, 4, 3)
        polygons = np.stack([corners @ first, corners @ second], axis=-1)
        values = fraction[keep]
        colours = cmap(norm(values))
        colours[values <= 0.0] = (1.0, 1.0, 1.0, 1.0)  # no proppant: empty
        axes.add_collection(PolyCollection(polygons, facecolors=colours, edgecolors="0.6", linewidths=0.3))
        axes.set_xlim(polygons[..., 0].min(), polygons[..., 0].max())
        axes.set_ylim(polygons[..., 1].min(), polygons[..., 1].max())
        axes.set_aspect("equal")
        axes.set_xlabel(labels[0])
        axes.set_ylabel(labels[1])
        figure.colorbar(ScalarMappable(norm, cmap), ax=axes, label="proppant volume fraction")
    else:
        for fracture in np.unique(mesh.fracture_id[keep]):
            chosen = np.flatnonzero(keep & (mesh.fracture_id == fracture))
            along = mesh.tangents[chosen[0]]
            position = (mesh.centers[chosen] - mesh.centers[chosen].mean(axis=0)) @ along
            order = np.argsort(position)
            axes.step(position[order], fraction[chosen][order], where="mid", label=f"fracture {fracture}")
        axes.axhline(packing_limit, color="black", linestyle=":", linewidth=1.0, label="packing limit")
        axes.set_ylim(0.0, 1.05 * packing_limit)
        axes.set_xlabel("position along the fracture (m)")
        axes.set_ylabel("proppant volume fraction")
        axes.legend(loc="upper right", fontsize=8)
    axes.set_title(title or "proppant volume fraction", fontsize=10)
    return _save(figure, path)


def plot_proppant_history(records, path, title=""):
    """``path`` (PNG): proppant mass pumped, in the fractures and screened out (kg) against
    time, from the records (those without proppant keys are skipped). Returns the path."""
    rows = [r for r in records if "proppant_mass" in r]
    if not rows:
        raise InputError("the records hold no proppant masses (a run without [proppant])")
    time = np.array([r["time"] for r in rows], float)
    figure = _figure((7.0, 4.0))
    axes = figure.add_subplot()
    axes.plot(time, [r["proppant_injected_mass"] for r in rows], color="black", linestyle="--", label="pumped")
    axes.plot(time, [r["proppant_mass"] for r in rows], color="tab:orange", marker="o", markersize=3,
              label="in the fractures")
    screened = np.array([r.get("proppant_screened_mass", 0.0) for r in rows], float)
    if np.any(screened > 0.0):
        axes.plot(time, screened, color="tab:red", label="screened out (in the wellbore)")
    axes.set_xlabel("time (s)")
    axes.set_ylabel("proppant mass (kg)")
    axes.legend(loc="upper left", fontsize=8)
    axes.set_title(title or "proppant mass", fontsize=10)
    return _save(figure, path)
