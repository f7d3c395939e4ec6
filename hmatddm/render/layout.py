"""What a fracture picture shows and where, without pyvista: the state codes and colours,
the checks of the fields drawn, the opening colour range, the legend, the size of slip
arrows, the frame and length scale of a plan view, and the plan-view traces of a mesh of
(mostly) vertical fractures. :mod:`hmatddm.render.snapshots` draws with these.
"""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..mesh import Mesh2D, Mesh3D
from ..settings import integer

HYDRAULIC, INTACT_NATURAL, FAILED_NATURAL = 0, 1, 2
VIEWS = ("plan", "oblique")

OPENING_COLORMAP = "viridis"
PLAIN_SURFACE_COLOR = "tan"
INTACT_COLOR = "darkgrey"  # light grey, still readable as legend text on white
FAILED_COLOR = "red"
SLIP_ARROW_COLOR = "magenta"  # stands out on dark (closed) and bright (open) elements
SLIP_VISIBLE_FRACTION = 1e-3  # arrows where |slip| > this fraction of the largest slip
MAX_ELEMENTS_WITH_EDGES = 2000  # element borders drawn on smaller meshes only
MAX_SLIP_ARROWS = 400  # more slipping elements than this: every k-th gets an arrow
VERTICAL_NORMAL_Z = 0.05  # an element is vertical when |n_z| <= this (within ~2.9 degrees)
MOSTLY_VERTICAL_AREA = 0.5  # plan view as traces when vertical elements hold this share of the area
PLAN_STYLES = ("auto", "traces", "surfaces")
# layout of a picture, in fractions of its width and height: the colour bar stands at
# x in [BAR_LEFT, BAR_LEFT + 0.08]; a plan view puts the fractures inside PLAN_BOX
# (left, right, bottom, top), left of the bar, above the legend and the length scale
# (SCALE_Y) and below the title
BAR_LEFT = 0.86
PLAN_BOX = (0.04, 0.82, 0.19, 0.90)
PLAN_BOX_WITHOUT_BAR_RIGHT = 0.96
PLAN_BOX_WITHOUT_TITLE_TOP = 0.96
SCALE_Y = 0.07
# a column of elements shows its highest-ranked state: failed > hydraulic > intact
_RANK_OF_STATE = np.array([1, 0, 2])                     # indexed by state code 0, 1, 2
_STATE_OF_RANK = np.array([INTACT_NATURAL, HYDRAULIC, FAILED_NATURAL])


def check_mesh_type(mesh):
    if not isinstance(mesh, (Mesh2D, Mesh3D)):
        raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
    return mesh


def check_state(state, n_elements):
    array = np.asarray(state)
    if array.shape != (n_elements,) or not (np.issubdtype(array.dtype, np.integer) or array.dtype == bool):
        raise InputError(f"state must be an integer array of shape ({n_elements},), "
                         f"got {array.dtype} {array.shape}")
    bad = np.flatnonzero(~np.isin(array, (HYDRAULIC, INTACT_NATURAL, FAILED_NATURAL)))
    if bad.size:
        raise InputError(f"state values must be 0 (hydraulic), 1 (intact natural) or 2 (failed natural); "
                         f"element {int(bad[0])} has {int(array[bad[0]])}")
    return array.astype(np.int64)


def check_window_size(window_size):
    try:
        width, height = window_size
    except (TypeError, ValueError):
        raise InputError(f"window_size must be a pair (width, height) of pixels, got {window_size!r}") from None
    for name, value in (("width", width), ("height", height)):
        integer(f"window_size {name}", value, 16, 16384)
    return int(width), int(height)


def check_fields(mesh, opening, state, slip):
    n = mesh.n_elements
    opening = None if opening is None else finite_array("opening", opening, (n,))
    state = None if state is None else check_state(state, n)
    slip = None if slip is None else finite_array("slip", slip, (n, mesh.dim))
    return opening, state, slip


def mesh_diagonal(mesh):
    extent = np.ptp(mesh.centers, axis=0)
    return float(np.hypot.reduce(extent)) + 2.0 * float(np.max(mesh.radii))


def opening_colour_range(opening_mm):
    """``(clim, bar_title)`` of the opening colour bar: from 0 to the largest opening
    (mm). Negative openings (closed elements pressed a little into each other, or the
    round-off of contact) are drawn in the colour of 0 and the bar title says so,
    with the smallest value, instead of stretching the scale below zero."""
    low = float(np.min(opening_mm))
    high = max(float(np.max(opening_mm)), 0.0)
    if high <= 1e-12:
        high = 1e-9
    title = "opening (mm)"
    if low < 0.0:
        title = f"opening (mm)\n< 0 drawn as 0\n(min {low:.2g})"
    return [0.0, high], title


def slip_arrow_length(mesh, slipping, n_arrows):
    """Length of the arrow of the largest slip: about 1.5 arrow spacings (the
    ``slipping`` elements' area, or length in 2D, shared among ``n_arrows``), within
    3-12% of the mesh diagonal."""
    covered = float(np.sum(mesh.areas[slipping]))
    spacing = covered / n_arrows if isinstance(mesh, Mesh2D) else np.sqrt(covered / n_arrows)
    diagonal = mesh_diagonal(mesh)
    return float(np.clip(1.5 * spacing, 0.03 * diagonal, 0.12 * diagonal))


RIBBON_SHARE = 0.04  # the widest opening of a 2D picture drawn as this share of the mesh diagonal


def opening_ribbon(mesh, opening, diagonal, share=RIBBON_SHARE):
    """The opening of 2D elements as a band across each segment: ``(points (4N, 2), quads
    (N, 4), exaggeration)``, element ``i`` the quad of its end points moved by ``+-
    exaggeration * max(w_i, 0) / 2`` along its normal (the DD is constant along an element,
    so the band steps at element ends), ``exaggeration = share * diagonal / max(w)``;
    ``(None, None, None)`` when no element is open. ``diagonal``: of the whole picture
    (:func:`mesh_diagonal`), so that parts drawn apart share one scale when their widest
    openings do."""
    if not isinstance(mesh, Mesh2D):
        raise InputError("opening_ribbon needs a Mesh2D")
    opening = np.clip(np.asarray(opening, dtype=float), 0.0, None)
    widest = float(np.max(opening)) if opening.size else 0.0
    if not widest > 0.0:
        return None, None, None
    exaggeration = share * float(diagonal) / widest
    start, end = mesh.endpoints
    offset = 0.5 * exaggeration * opening[:, None] * mesh.frames[:, 1, :]
    points = np.stack([start - offset, end - offset, end + offset, start + offset], axis=1).reshape(-1, 2)
    quads = np.arange(4 * mesh.n_elements).reshape(-1, 4)
    return points, quads, exaggeration


def ribbon_text(exaggeration):
    """The note of a 2D picture's opening band, e.g. ``band width: opening x 1.2e+03
    (colour: true opening)``."""
    return f"band width: opening x {exaggeration:.3g} (colour: true opening)"


def legend_labels(state, slip_shown=False):
    """``[[text, colour], ...]`` of the legend: the natural-fracture states present and
    the slip arrows when drawn."""
    labels = []
    if state is not None and np.any(state == INTACT_NATURAL):
        labels.append(["natural fracture, intact", INTACT_COLOR])
    if state is not None and np.any(state == FAILED_NATURAL):
        labels.append(["natural fracture, activated or failed", FAILED_COLOR])
    if slip_shown:
        labels.append(["slip (arrow length ~ slip)", SLIP_ARROW_COLOR])
    return labels


def slip_shown(slip):
    return slip is not None and bool(np.any(slip))


def plan_extent(mesh):
    """``(x_min, x_max, y_min, y_max)`` of the elements seen from above (their corners, or
    segment ends)."""
    if isinstance(mesh, Mesh2D):
        points = np.concatenate(mesh.endpoints)
    else:
        points = mesh.corners().reshape(-1, 3)[:, :2]
    low, high = points.min(axis=0), points.max(axis=0)
    pad = 0.02 * max(float(np.max(high - low)), float(np.max(mesh.radii)))  # room for tubes and arrows
    return low[0] - pad, high[0] + pad, low[1] - pad, high[1] + pad


def plan_frame(extent, window_size, colour_bar=True, title=True):
    """The camera of a plan view: ``(centre_x, centre_y, parallel_scale, box)`` so that
    ``extent`` (x_min, x_max, y_min, y_max, m) fills ``box`` (fractions of the window,
    :data:`PLAN_BOX`; wider without a colour bar, taller without a title) at the same
    scale in x and y -- never under the colour bar, the legend or the title."""
    left, right, bottom, top = PLAN_BOX
    right = right if colour_bar else PLAN_BOX_WITHOUT_BAR_RIGHT
    top = top if title else PLAN_BOX_WITHOUT_TITLE_TOP
    width, height = window_size
    aspect = width / height
    x_min, x_max, y_min, y_max = extent
    span_x = max(x_max - x_min, 1e-12 * max(1.0, abs(x_max)))
    span_y = max(y_max - y_min, 1e-12 * max(1.0, abs(y_max)))
    scale = max(span_x / (2.0 * aspect * (right - left)), span_y / (2.0 * (top - bottom)))
    centre_x = 0.5 * (x_min + x_max) - (0.5 * (left + right) - 0.5) * 2.0 * scale * aspect
    centre_y = 0.5 * (y_min + y_max) - (0.5 * (bottom + top) - 0.5) * 2.0 * scale
    return centre_x, centre_y, scale, (left, right, bottom, top)


def scale_bar_length(span):
    """A round length (1, 2 or 5 x 10^k m) of about a fifth of ``span`` (m, > 0)."""
    target = 0.2 * float(span)
    power = 10.0 ** np.floor(np.log10(target))
    return float(max(m * power for m in (1.0, 2.0, 5.0) if m * power <= target))


def plan_scale_bar(extent, window_size, colour_bar=True, title=True):
    """The length scale of a plan view (m): a round length of about a fifth of the width
    the plot box shows at :func:`plan_frame`'s scale -- not of the fractures' own x
    extent, which is ~0 for a vertical 2D section (it made the bar a dot there)."""
    _, _, scale, box = plan_frame(extent, window_size, colour_bar, title)
    aspect = window_size[0] / window_size[1]
    return scale_bar_length(2.0 * scale * aspect * (box[1] - box[0]))


def length_text(length):
    return f"{length * 1e3:g} mm" if length < 1e-2 else (f"{length:g} m" if length < 1e3 else f"{length / 1e3:g} km")


@dataclass(frozen=True)
class Curve:
    """A line drawn over the fractures of a snapshot: ``points`` (n, 2 or 3), m, joined in
    order, or with ``pairs=True`` taken two by two as separate segments."""

    points: np.ndarray
    colour: str = "black"
    dashed: bool = False
    label: str = ""
    width: float = 3.0
    pairs: bool = False


def check_curves(curves, dim):
    """``curves`` as a list of :class:`Curve` with finite (n >= 2, 2 or 3) points (2D: 2 or 3)."""
    checked = []
    for index, curve in enumerate(curves or ()):
        if not isinstance(curve, Curve):
            raise InputError(f"curves[{index}] must be an hmatddm.render.Curve, got {type(curve).__name__}")
        points = finite_array(f"curves[{index}].points", curve.points)
        if points.ndim != 2 or points.shape[1] not in (2, 3) or (dim == 3 and points.shape[1] != 3):
            raise InputError(f"curves[{index}].points must have shape (n, {dim}), got {points.shape}")
        if curve.pairs and len(points) % 2:
            raise InputError(f"curves[{index}].points must hold pairs of points (pairs=True), got {len(points)}")
        checked.append(Curve(points, curve.colour, curve.dashed, curve.label, curve.width, curve.pairs))
    return checked


def dashes(points, length):
    """The polyline ``points`` (n, 3) cut into dashes: pieces of ``length`` (m) separated by
    gaps of the same length, measured along the line."""
    points = np.asarray(points, dtype=float)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    if arc[-1] <= 0.0:
        return []
    pieces = []
    for start in np.arange(0.0, arc[-1], 2.0 * length):
        stops = np.concatenate([[start], arc[(arc > start) & (arc < start + length)], [min(start + length, arc[-1])]])
        pieces.append(np.column_stack([np.interp(stops, arc, points[:, k]) for k in range(points.shape[1])]))
    return pieces


def plan_ticks(low, high):
    """Round tick values (m) between ``low`` and ``high``: steps of 1, 2 or 5 x 10^k, 3 to 8 ticks."""
    span = float(high - low)
    if not span > 0.0:
        return np.array([low])
    power = 10.0 ** np.floor(np.log10(span / 8.0))
    step = next(m * power for m in (1.0, 2.0, 5.0, 10.0) if span / (m * power) <= 8.0)
    return np.arange(np.ceil(low / step) * step, high + 1e-9 * span, step)


def vertical_elements(mesh):
    """Boolean mask of the elements of a Mesh3D that stand vertical (``|n_z| <=
    VERTICAL_NORMAL_Z``, within ~2.9 degrees), which a plan view sees edge on."""
    return np.abs(mesh.normals[:, 2]) <= VERTICAL_NORMAL_Z


def is_mostly_vertical(mesh):
    """Whether a plan view of ``mesh`` should draw traces: a Mesh3D whose vertical
    elements hold at least ``MOSTLY_VERTICAL_AREA`` of its area."""
    if not isinstance(mesh, Mesh3D):
        return False
    areas = mesh.areas
    return float(np.sum(areas[vertical_elements(mesh)])) >= MOSTLY_VERTICAL_AREA * float(np.sum(areas))


def plan_traces(mesh, opening=None, state=None, slip=None):
    """The vertical elements of a Mesh3D as plan-view line elements, one per column.

    Each vertical element's horizontal mid-line (:func:`hmatddm.simulation.natural.plan_segments`)
    is its trace; the elements of one fracture with the same trace (a column stacked
    over the height) become one line. Per line:

    * ``opening``: the LARGEST opening of the column (max over the height: the plan
      view shows where the fracture is open at all, as the DFN maps of ref. Figs
      6.10-6.14 do);
    * ``state``: failed natural (2) when any element of the column failed or was
      activated, else hydraulic (0) when any is hydraulic, else intact natural (1);
    * ``slip``: the horizontal (x, y) part of the slip of the column's element that
      slips most (dip-slip is invisible in plan).

    Returns ``(traces, opening, state, slip, column)``: ``traces`` a Mesh2D (same
    ``fracture_id``), the per-line fields (None where not given) and ``column`` (for
    each vertical element in mesh order, the index of its line). Non-vertical
    elements are left out (see :func:`vertical_elements`).
    """
    from ..simulation.natural import plan_segments

    check_mesh_type(mesh)
    if not isinstance(mesh, Mesh3D):
        raise InputError("plan_traces needs a Mesh3D (a Mesh2D already is a plan view)")
    opening, state, slip = check_fields(mesh, opening, state, slip)
    vertical = np.flatnonzero(vertical_elements(mesh))
    if vertical.size == 0:
        raise InputError("plan_traces: the mesh has no vertical element (|n_z| <= "
                         f"{VERTICAL_NORMAL_Z})")
    part = mesh.subset(vertical)
    p0, p1, _ = plan_segments(part)
    # one key per column: fracture id and the trace's end points (ordered, rounded)
    ends = np.stack([p0, p1], axis=1)                                   # (n, 2, 2)
    swap = (ends[:, 0, 0] > ends[:, 1, 0]) | ((ends[:, 0, 0] == ends[:, 1, 0]) & (ends[:, 0, 1] > ends[:, 1, 1]))
    ends[swap] = ends[swap][:, ::-1]
    tolerance = 1e-6 * mesh_diagonal(mesh)
    key = np.column_stack([part.fracture_id, np.round(ends.reshape(-1, 4) / tolerance).astype(np.int64)])
    _, first, column = np.unique(key, axis=0, return_index=True, return_inverse=True)
    column = column.reshape(-1)
    n_lines = first.size
    traces = Mesh2D.from_segments(p0[first], p1[first], fracture_id=part.fracture_id[first])
    line_opening = line_state = line_slip = None
    if opening is not None:
        line_opening = np.full(n_lines, -np.inf)
        np.maximum.at(line_opening, column, opening[vertical])
    if state is not None:
        top = np.zeros(n_lines, dtype=np.int64)
        np.maximum.at(top, column, _RANK_OF_STATE[state[vertical]])
        line_state = _STATE_OF_RANK[top].astype(np.int64)
    if slip is not None:
        magnitude = np.linalg.norm(slip[vertical], axis=1)
        order = np.lexsort((magnitude, column))          # by column, largest slip last
        is_last = np.r_[column[order][1:] != column[order][:-1], True]
        line_slip = np.zeros((n_lines, 2))
        line_slip[column[order][is_last]] = slip[vertical][order[is_last], :2]
    return traces, line_opening, line_state, line_slip, column


__all__ = ["Curve", "check_curves", "dashes", "plan_ticks",
           "HYDRAULIC", "INTACT_NATURAL", "FAILED_NATURAL", "VIEWS", "PLAN_STYLES", "opening_colour_range",
           "legend_labels", "slip_arrow_length", "plan_frame", "plan_scale_bar", "scale_bar_length",
           "vertical_elements", "is_mostly_vertical", "plan_traces", "opening_ribbon", "ribbon_text", "RIBBON_SHARE"]
