"""The rate split of clusters sharing a well (issue 35, :mod:`hmatddm.flow.well`), with
matplotlib (Agg canvas, no window): :func:`plot_rate_split` draws the records'
``cluster_rates`` against time with the pump's rate, the share of each cluster, and the
heel pressure with each cluster's perforation friction."""
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_output


def plot_rate_split(records, path, title=""):
    """``path`` (PNG): three panels against time from the records that hold ``cluster_rates``
    (a run with a [well]): the rate into each cluster and the pump's rate (m^3/s), each
    cluster's share of their sum, and the heel pressure with the perforation friction of each
    cluster (MPa). Returns the path."""
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
    bottom.plot(time, np.array([r["heel_pressure"] for r in rows]) / 1e6, color="black", label="heel pressure")
    for k in range(rates.shape[1]):
        bottom.plot(time, friction[:, k] / 1e6, color=colours[k], linestyle="--")
    bottom.plot([], [], color="0.3", linestyle="--", label="perforation friction (per cluster)")
    bottom.set_ylabel("pressure (MPa)")
    bottom.set_xlabel("time (s)")
    bottom.legend(loc="best", fontsize=7)
    top.set_title(title or "rate split", fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png")
    return path


__all__ = ["plot_rate_split"]
