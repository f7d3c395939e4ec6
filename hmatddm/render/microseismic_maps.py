"""Microseismic event maps (ref. Figs 7.6, 7.9-7.10): plan view of the located events
coloured by moment magnitude over the fracture traces, observation wells marked.
matplotlib with the Agg canvas (no window, no pyplot); written atomically."""
from pathlib import Path

import numpy as np

from ..io import atomic_output

TRACE_STYLE = {1: dict(color="0.75", linewidth=0.8),            # intact natural fracture
               2: dict(color="0.35", linewidth=1.2),            # failed / activated natural fracture
               0: dict(color="tab:blue", linewidth=1.6)}        # hydraulic fracture


def draw_map(axis, traces, wells, located, magnitude, true_positions=None, magnitude_range=None, title=None):
    """Draw one map on a matplotlib axis; returns the scatter (for a colour bar).

    ``traces``: ``(p0 (M, 2), p1 (M, 2), state (M,))`` plan segments of the run's elements
    (state 0 hydraulic, 1 intact natural, 2 failed natural); ``wells`` (W, 2); ``located``
    (E, 2 or 3) and ``magnitude`` (E,); ``true_positions`` drawn as small dots when given.
    """
    from matplotlib.collections import LineCollection

    p0, p1, state = traces
    for code, style in TRACE_STYLE.items():
        mask = np.asarray(state) == code
        if np.any(mask):
            axis.add_collection(LineCollection(np.stack([p0[mask], p1[mask]], axis=1), zorder=1, **style))
    if true_positions is not None and len(true_positions):
        axis.plot(true_positions[:, 0], true_positions[:, 1], ".", color="black", markersize=2, zorder=2,
                  label="true event")
    low, high = magnitude_range if magnitude_range is not None else (
        (float(np.min(magnitude)), float(np.max(magnitude))) if len(magnitude) else (-3.0, -1.0))
    scatter = axis.scatter(located[:, 0] if len(located) else [], located[:, 1] if len(located) else [],
                           c=magnitude if len(magnitude) else [], cmap="viridis", vmin=low, vmax=high, s=18,
                           edgecolors="none", zorder=3)
    wells = np.asarray(wells, dtype=float).reshape(-1, 2)
    axis.plot(wells[:, 0], wells[:, 1], "x", color="black", markersize=9, markeredgewidth=2.2, zorder=4,
              label="observation well")
    points = [np.vstack([p0, p1]), wells] + ([located[:, :2]] if len(located) else [])
    everything = np.vstack(points)
    margin = 0.05 * max(np.ptp(everything[:, 0]), np.ptp(everything[:, 1]), 1.0)
    axis.set_xlim(everything[:, 0].min() - margin, everything[:, 0].max() + margin)
    axis.set_ylim(everything[:, 1].min() - margin, everything[:, 1].max() + margin)
    axis.set_aspect("equal")
    axis.set_xlabel("x (m)")
    axis.set_ylabel("y (m)")
    if title:
        axis.set_title(title, fontsize=9)
    return scatter


def plot_event_map(path, traces, wells, located, magnitude, true_positions=None, title=None):
    """One map as a PNG at ``path``; returns the path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.0, 8.0), dpi=110, layout="constrained")
    FigureCanvasAgg(figure)
    axis = figure.subplots()
    scatter = draw_map(axis, traces, wells, np.atleast_2d(located) if len(located) else np.zeros((0, 3)),
                       np.asarray(magnitude, dtype=float), true_positions, title=title)
    figure.colorbar(scatter, ax=axis, label="moment magnitude Mw", shrink=0.8)
    axis.legend(loc="upper right", fontsize=8)
    path = Path(path)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png")
    return path
