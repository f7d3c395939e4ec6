"""The image triples a 3D layered source keeps for its receivers (ref. Sec. 3.2, issue 32):
traced once per rule of :func:`.rectangle_quadrature._cached_rules` on first use
(:func:`traced_slot`), and at a vertical source's bottom, middle and top heights for the
closed forms of :mod:`.vertical3d` (:func:`three_heights`). With a tabulated remainder
(:mod:`.remainder_table3d`) only the near triples are kept, traced with the table's
``near_images`` reflections (:func:`traced_images`); a source whose reflection in the free
surface is in closed form drops it. The record ``data`` is
:class:`.images3d.LayeredRectangles`, the state :func:`.images3d.source_state`'s."""
import numpy as np
from numba import njit

from .image_tracer3d import _trace_range, _traced_buffer, drop_surface_range
from .remainder_table3d import keep_near_range


@njit(cache=True, inline="always")
def traced_slot(data, j, slot, state, rules):
    """``(lo, hi)``: the points of the cached rule ``slot``
    (:func:`.rectangle_quadrature._cached_rules`) in the source's traced triples, traced on
    first use (near ones only with a table, without the free surface's reflection when it
    is in closed form)."""
    traced, is_traced, near_only = state[0], state[1], state[2]
    xi, eta, start = rules[0], rules[1], rules[3]
    lo, hi = start[slot], start[slot + 1]
    if not is_traced[slot]:
        _trace_kept(data, j, near_only, xi, eta, lo, hi, traced)
        is_traced[slot] = True
    return lo, hi


@njit(cache=True)
def _trace_kept(data, j, near_only, xi, eta, lo, hi, traced):
    """Trace source ``j`` at the points ``lo ... hi`` of the rule ``(xi, eta)`` into
    ``traced`` and keep what its receivers integrate: the near triples only with a table,
    without the free surface's reflection when it is in closed form."""
    ls = data.layer[j]
    center, frame, a, b = data.centers[j], data.frames[j], data.half_a[j], data.half_b[j]
    _trace_range(center, frame, a, b, ls, data.interfaces, data.shear_modulus, data.poisson_ratio,
                 traced_images(data, near_only), xi, eta, lo, hi, traced)
    if near_only:
        keep_near_range(traced, lo, hi, center, frame, a, b, xi, eta, ls, data.table.bottoms, data.table.tops)
    if data.surface_form[j]:
        drop_surface_range(traced, lo, hi, center, frame, a, b, xi, eta, ls, data.surface)


@njit(cache=True, inline="always")
def traced_images(data, near_only):
    """Reflections a source's cached triples are traced with: the table's ``near_images``
    when only the near ones are kept (:func:`.remainder_build3d.near_images`), else the
    medium's."""
    near = data.table.near_images
    return near if near_only and near > 0 else data.n_images


@njit(cache=True)
def three_heights(data, j, near_only, cap, n_orders):
    """``(traced, heights)``: the triples of a ``vertical_form`` source at its bottom,
    middle and top heights (:mod:`.vertical3d`), near ones only with a table, without the
    free surface's when it is in closed form; one empty point otherwise."""
    heights = np.zeros(3)
    if not data.vertical_form[j]:
        return _traced_buffer(np.int64(3), np.int64(1), np.int64(1)), heights
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    xi = np.zeros(3)
    eta = np.zeros(3)
    for p in range(3):
        if abs(frame[1, 2]) > abs(frame[0, 2]):
            eta[p] = (p - 1.0) * frame[1, 2]
        else:
            xi[p] = (p - 1.0) * frame[0, 2]
        heights[p] = center[2] + xi[p] * a * frame[0, 2] + eta[p] * b * frame[1, 2]
    three = _traced_buffer(np.int64(3), cap, n_orders)
    # not literals: the same compiled functions as element_traction's
    _trace_kept(data, j, near_only, xi, eta, np.int64(0), np.int64(3), three)
    return three, heights
