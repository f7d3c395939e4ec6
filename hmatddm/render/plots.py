"""History plots of a simulation with matplotlib (Agg canvas, no window, no pyplot).

:func:`plot_history` draws three panels against time: the fracture size (radius,
half-length, or the equivalent radius ``sqrt(area / pi)``), the maximum opening (mm)
and the wellbore pressure of each cluster (MPa), with closed-form solutions overlaid
as dashed lines; and, when the records carry a fluid ``budget``
(:func:`hmatddm.simulation.records.fluid_budget`), a fourth panel: where the fluid is
(fractures, leaked off, stored in the wellbores since t = 0, stacked) against the fluid
injected plus the fluid of the initial fractures.
"""
from pathlib import Path

import numpy as np

from .._validation import finite_scalar
from ..errors import InputError
from ..io import atomic_output

REQUIRED_KEYS = ("time", "fracture_area", "max_opening", "wellbore_pressure")
REFERENCE_KEYS = ("time", "radius", "half_length", "max_opening", "net_pressure", "top", "bottom")
CLOSED_FORM_STYLE = dict(color="black", linestyle="--", linewidth=1.2, label="closed form")


# ---------------------------------------------------------------------------------
# Inputs
# ---------------------------------------------------------------------------------

def _finite_number(value, where):
    return finite_scalar(where, value)


def _column(records, key):
    return np.array([_finite_number(record[key], f"records[{index}][{key!r}]")
                     for index, record in enumerate(records)])


def _pressures(records):
    """(n_records, n_clusters) wellbore pressures; a scalar counts as one cluster."""
    rows = []
    for index, record in enumerate(records):
        values = np.atleast_1d(np.asarray(record["wellbore_pressure"], dtype=object)).ravel()
        rows.append([_finite_number(v, f"records[{index}]['wellbore_pressure']") for v in values])
    counts = {len(row) for row in rows}
    if len(counts) != 1 or 0 in counts:
        raise InputError("records[i]['wellbore_pressure'] must hold the same number (>= 1) of values "
                         f"in every record, one per cluster; got counts {sorted(counts)}")
    return np.array(rows)


def _check_records(records):
    if isinstance(records, (str, bytes)) or not hasattr(records, "__len__") or len(records) == 0:
        raise InputError("records must be a non-empty list of dicts")
    for index, record in enumerate(records):
        if not hasattr(record, "keys"):
            raise InputError(f"records[{index}] must be a dict, got {type(record).__name__}")
        missing = [key for key in REQUIRED_KEYS if key not in record]
        if missing:
            raise InputError(f"records[{index}] lacks {missing}; every record needs {list(REQUIRED_KEYS)}")
    return list(records)


def _check_reference(reference):
    """Closed-form curves as float arrays, all as long as ``reference['time']``."""
    if reference is None:
        return {}
    if not hasattr(reference, "items"):
        raise InputError(f"reference must be a dict of arrays, got {type(reference).__name__}")
    unknown = sorted(set(reference) - set(REFERENCE_KEYS))
    if unknown:
        raise InputError(f"reference keys must be among {list(REFERENCE_KEYS)}, got {unknown}")
    curves = {}
    for key, values in reference.items():
        array = np.asarray(values, dtype=float).ravel()
        if not np.all(np.isfinite(array)):
            raise InputError(f"reference[{key!r}] must contain only finite numbers")
        curves[key] = array
    if curves and "time" not in curves:
        raise InputError("reference needs a 'time' array to plot its curves against")
    for key, array in curves.items():
        if len(array) != len(curves["time"]):
            raise InputError(f"reference[{key!r}] must have shape ({len(curves['time'])},) like "
                             f"reference['time'], got ({len(array)},)")
    return curves


# ---------------------------------------------------------------------------------
# Panels
# ---------------------------------------------------------------------------------

def _size_series(records):
    """(values, axis label) of the fracture size: radius, half-length or equivalent radius."""
    for key, label in (("height", "height, bottom to top (m)"), ("radius", "radius (m)"),
                       ("half_length", "half-length (m)")):
        if all(key in record for record in records):
            return _column(records, key), label
    area = _column(records, "fracture_area")
    if np.any(area < 0.0):
        raise InputError("records[i]['fracture_area'] must be >= 0")
    return np.sqrt(area / np.pi), "equivalent radius sqrt(A/π) (m)"


def _overlay(axis, curves, key, scale=1.0):
    if key in curves:
        axis.plot(curves["time"], scale * curves[key], **CLOSED_FORM_STYLE)


def _finish(axis, ylabel):
    axis.set_ylabel(ylabel)
    axis.grid(True, alpha=0.3)
    if axis.get_legend_handles_labels()[0]:
        axis.legend(loc="best", fontsize="small")


def _draw_size(axis, time, records, curves):
    size, label = _size_series(records)
    axis.plot(time, size, marker=".", label="simulation")
    _overlay(axis, curves, "radius")
    _overlay(axis, curves, "half_length")
    _finish(axis, label)


def _draw_opening(axis, time, records, curves):
    axis.plot(time, 1e3 * _column(records, "max_opening"), marker=".", label="simulation")
    _overlay(axis, curves, "max_opening", scale=1e3)
    _finish(axis, "max opening (mm)")


def _draw_pressure(axis, time, records, curves, confining_stress):
    pressure = _pressures(records)
    for cluster in range(pressure.shape[1]):
        label = "simulation" if pressure.shape[1] == 1 else f"cluster {cluster}"
        axis.plot(time, 1e-6 * pressure[:, cluster], marker=".", label=label)
    if "net_pressure" in curves:
        axis.plot(curves["time"], 1e-6 * (confining_stress + curves["net_pressure"]), **CLOSED_FORM_STYLE)
    _finish(axis, "wellbore pressure (MPa)")
    axis.set_xlabel("time (s)")


def _budgets(records):
    """``(time, budgets)`` of the records with a budget, when there are at least two."""
    rows = [(record["time"], record["budget"]) for record in records if record.get("budget")]
    return rows if len(rows) >= 2 else None


def _draw_budget(axis, rows):
    """Stacked: fluid in the fractures, leaked off, and the change of the wellbores'
    fluid since the first record (negative when the wellbores gave fluid back); dashed:
    injected plus the fluid in the fractures at the first record. The stack reaches the
    dashed line when the budget closes (the worst residual is in the legend)."""
    time = np.array([row[0] for row in rows], dtype=float)

    def column(key):
        return np.array([_finite_number(row[1].get(key, 0.0), f"budget[{key!r}]") for row in rows])

    fractures, leaked, wellbore = column("fractures"), column("leaked"), column("wellbore")
    sources = column("injected") + column("initial") + column("natural") - wellbore[0]
    stored = wellbore - wellbore[0]
    residual = column("residual")
    moved = np.maximum(column("injected"), fractures)
    worst = float(np.max(np.abs(residual) / np.where(moved > 0.0, moved, np.inf)))
    axis.stackplot(time, fractures, leaked, stored, labels=("in the fractures", "leaked off",
                                                            "stored in the wellbores since t0"),
                   colors=("tab:blue", "tab:orange", "tab:green"), alpha=0.6)
    axis.plot(time, sources, color="black", linestyle="--", linewidth=1.2,
              label=f"injected + initial fractures (worst residual {worst:.1e} of the fluid moved)")
    _finish(axis, "fluid volume (m³, reference density)")


def _draw_tips(axis, time, records, curves, interfaces):
    """Height growth in layers: the top and bottom of the fractures against time, the layer
    interfaces as grey lines, the closed form's tips (``top``, ``bottom``) dashed."""
    axis.plot(time, _column(records, "top"), marker=".", color="tab:red", label="top")
    axis.plot(time, _column(records, "bottom"), marker=".", color="tab:purple", label="bottom")
    for key in ("top", "bottom"):
        _overlay(axis, curves, key)
    for index, height in enumerate(interfaces):
        axis.axhline(height, color="grey", linewidth=1.0, label="layer interfaces" if index == 0 else None)
    _finish(axis, "fracture tips, vertical (m)")


def plot_history(records, path, reference=None, confining_stress=0.0, interfaces=()):
    """Plot a simulation history as a three-panel PNG.

    Parameters
    ----------
    records : list of dict
        One dict per time step with at least ``time`` (s), ``fracture_area`` (m²),
        ``max_opening`` (m) and ``wellbore_pressure`` (Pa; a list, one value per
        cluster, or a scalar); optionally ``radius`` or ``half_length`` (m), plotted
        instead of the equivalent radius ``sqrt(area / pi)`` when every record has it,
        and a fluid ``budget`` (a panel, when at least two records have one); ``top`` and
        ``bottom`` (m, in a layered medium: a panel of the tips against ``interfaces``).
    path : str or Path
        Output PNG (folder created if missing; written atomically).
    reference : dict of arrays, optional
        Closed-form curves, any subset of ``time`` (s), ``radius`` or
        ``half_length`` (m), ``max_opening`` (m), ``net_pressure`` (Pa), drawn dashed
        and labelled "closed form".
    confining_stress : float
        Magnitude of the compressive stress closing the fracture, Pa (a positive
        number; hmatddm counts tension positive, so this is ``-sigma_nn``). The
        closed-form curve on the pressure panel is
        ``confining_stress + net_pressure``, so it compares with the absolute
        wellbore pressure; leave 0 when the records hold net pressures.
    interfaces : sequence of float
        Heights of the layer interfaces (m), drawn in the panel of the tips.

    Returns
    -------
    Path
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    records = _check_records(records)
    curves = _check_reference(reference)
    confining_stress = _finite_number(confining_stress, "confining_stress")
    time = _column(records, "time")
    budgets = _budgets(records)
    tips = all("top" in record and "bottom" in record for record in records)
    panels = 3 + (budgets is not None) + tips
    figure = Figure(figsize=(7.0, 3.0 * panels), dpi=110, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(panels, 1, sharex=True)
    _draw_size(axes[0], time, records, curves)
    _draw_opening(axes[1], time, records, curves)
    _draw_pressure(axes[2], time, records, curves, confining_stress)
    extra = 3
    if tips:
        _draw_tips(axes[extra], time, records, curves, [float(h) for h in interfaces])
        extra += 1
    if budgets is not None:
        _draw_budget(axes[extra], budgets)
    for axis in axes[:-1]:
        axis.set_xlabel("")
    axes[-1].set_xlabel("time (s)")
    path = Path(path)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png")
    return path


__all__ = ["plot_history"]
