"""Pictures of clusters sharing a well (issue 35, :mod:`hmatddm.flow.well`), with matplotlib
(Agg canvas, no window): :func:`plot_rate_split` draws the records' ``cluster_rates`` against
time with the pump's rate, the share of each cluster, and the heel pressure with each
cluster's perforation friction; :func:`plot_side_view` the hydraulic fractures of a 3D run
face on, one panel per fracture along the well, with the layer interfaces (how high each
grew, and which the stress shadow starved)."""
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_output


def plot_rate_split(records, path, title=""):
    """``path`` (PNG): three panels against time from the records that hold ``cluster_rates``
    (a run with a [well]): the rate into each cluster and the pump's rate (m^3/s), each
    cluster's share of their sum, and the heel pressure with the perforation friction of each
    cluster (MPa, dashed) with the heel pressure (right axis). Returns the path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    rows = [r for r in records if r.get("cluster_rates") is not None and r.get("time", 0.0) > 0.0]
    if not rows:
        raise InputError("the records hold no cluster rates (a run without a [well])")
    time = np.array([r["time"] for r in rows], float)
    rates = np.array([r["cluster_rates"] for r in rows], float)        # (steps, clusters)
    friction = np.array([r["perforation_friction"] for r in rows], float)
    figure = Figure(figsize=(7.5, 8.0), dpi=110, layout="constrained")
    FigureCanvasAgg(figure)
    top, middle, bottom = figure.subplots(3, 1, sharex=True)
    colours = [f"C{k % 10}" for k in range(rates.shape[1])]
    top.plot(time, [r["pump_rate"] for r in rows], color="black", linestyle="--", label="pump")
    for k in range(rates.shape[1]):
        top.plot(time, rates[:, k], color=colours[k], marker="o", markersize=2.5, label=f"cluster {k}")
    top.axhline(0.0, color="0.6", linewidth=0.6)
    top.set_ylabel("rate (m$^3$/s)")
    top.legend(loc="best", fontsize=7, ncol=2)
    total = np.sum(rates, axis=1)
    share = np.divide(rates, total[:, None], out=np.zeros_like(rates), where=total[:, None] != 0.0)
    for k in range(rates.shape[1]):
        middle.plot(time, share[:, k], color=colours[k])
    middle.axhline(1.0 / rates.shape[1], color="0.5", linestyle=":", label="even split")
    middle.set_ylabel("share of the rate")
    middle.legend(loc="best", fontsize=7)
    for k in range(rates.shape[1]):
        bottom.plot(time, friction[:, k] / 1e6, color=colours[k], linestyle="--")
    bottom.set_ylabel("perforation friction (MPa)")
    bottom.set_xlabel("time (s)")
    heel = bottom.twinx()
    heel.plot(time, np.array([r["heel_pressure"] for r in rows]) / 1e6, color="black", label="heel pressure")
    heel.set_ylabel("heel pressure (MPa)")
    heel.legend(loc="best", fontsize=7)
    top.set_title(title or "rate split", fontsize=10)
    return _save(figure, path)


def plot_side_view(mesh, opening, fracture_ids, path, well_direction, interfaces=(), title=""):
    """``path`` (PNG): the elements of each fracture of ``fracture_ids`` (the hydraulic
    fractures, in the order along the well) seen face on, looking along the well: the
    horizontal axis perpendicular to ``well_direction``, z up (docs/conventions.md §3), each
    element a rectangle coloured by its opening (mm), the layer ``interfaces`` dashed. One
    panel per fracture, sharing the axes and the colour scale. Returns the path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    if mesh.dim != 3:
        raise InputError("a side view draws a 3D mesh")
    direction = np.asarray(well_direction, dtype=float)
    across = np.cross([0.0, 0.0, 1.0], direction)
    if np.linalg.norm(across) < 1e-9:
        raise InputError("a side view looks along a horizontal well; the well is vertical")
    across /= np.linalg.norm(across)
    corners = mesh.corners()                                   # (n, 4, 3)
    polygons = np.stack([corners @ across, corners[..., 2]], axis=-1)
    millimetres = 1e3 * np.maximum(np.asarray(opening, dtype=float), 0.0)
    shown = [np.flatnonzero(mesh.fracture_id == k) for k in fracture_ids]
    chosen = np.concatenate(shown) if shown else np.zeros(0, np.int64)
    if chosen.size == 0:
        raise InputError("no element of the fractures to draw")
    norm = Normalize(0.0, max(float(np.max(millimetres[chosen])), 1e-12))
    low, high = polygons[chosen].reshape(-1, 2).min(axis=0), polygons[chosen].reshape(-1, 2).max(axis=0)
    pad = 0.05 * max(high - low)
    figure = Figure(figsize=(2.2 * len(shown) + 1.2, 3.4), dpi=110, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(1, len(shown), sharex=True, sharey=True, squeeze=False)[0]
    collection = None
    for k, (axis, elements) in enumerate(zip(axes, shown)):
        collection = PolyCollection(polygons[elements], array=millimetres[elements], cmap="viridis", norm=norm,
                                    edgecolors="0.3", linewidths=0.3)
        axis.add_collection(collection)
        for height in interfaces:
            axis.axhline(height, color="black", linestyle="--", linewidth=0.8)
        axis.set_xlim(low[0] - pad, high[0] + pad)
        axis.set_ylim(min(low[1], min(interfaces, default=low[1])) - pad,
                      max(high[1], max(interfaces, default=high[1])) + pad)
        axis.set_aspect("equal")
        axis.set_title(f"cluster {k}", fontsize=9)
        axis.set_xlabel("across the well (m)", fontsize=8)
    axes[0].set_ylabel("z (m)")
    figure.colorbar(collection, ax=list(axes), label="opening (mm)", shrink=0.8)
    figure.suptitle(title or "side view", fontsize=10)
    return _save(figure, path)


def _save(figure, path):
    """Write ``figure`` to ``path`` (PNG, atomically, its folder made); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png")
    return path


__all__ = ["plot_rate_split", "plot_side_view"]
