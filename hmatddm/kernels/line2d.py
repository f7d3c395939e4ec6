"""Constant displacement discontinuity on a straight segment (2D plane strain), in closed form.

The element lies on its local axis ``y = 0`` from ``x = -a`` to ``x = a``. With

    g(x, y) = 1/(4 pi (1 - nu)) [I(x, y, a) - I(x, y, -a)]       ref. App. A eqs 10-12

the stresses per unit DD are (ref. Eq. 2.59 reduced to 2D; Crouch 1976 with the sign of
``g`` flipped for DD = u(+) - u(-)):

    shear DD:   s_xx = 2G[2 g_xy - y g_xxx],  s_xy = 2G[g_yy - y g_xxy],  s_yy = 2G[y g_xxx]
    normal DD:  s_xx = 2G[g_yy - y g_xxy],    s_xy = 2G[y g_xxx],         s_yy = 2G[g_yy + y g_xxy]

using ``g_yy = -g_xx``, ``g_xyy = -g_xxx``, ``g_yyy = -g_xxy`` (harmonicity) and
ref. App. A eqs 15-19 (eqs 18-19 there print ``r^2`` where ``r^4`` belongs). The only
singular points are the segment's two end points (dislocations), handled as in
:mod:`hmatddm.kernels.rectangle3d`; points on the extension of the segment are regular.
Points merely *near* an end point (a near-miss junction) are treated as on it when the
caller passes a ``near`` distance (see :func:`element_traction`). The loops over element
pairs are :mod:`hmatddm.kernels.drivers`; :class:`Segments` is the kernel data.
"""
import math
import numpy as np
from numba import njit

from .drivers import HOMOGENEOUS_FIELDS, KernelKind, kernel_record, no_source_state, register_kind

_INV_4PI = 1.0 / (4.0 * math.pi)


@njit(cache=True)
def on_tip(x, y, a):
    """True when the local point coincides with an end point of the segment."""
    tol = 1e-12 * a
    return abs(y) <= tol and abs(abs(x) - a) <= tol


@njit(cache=True)
def local_stress(x, y, a, shear_modulus, poisson_ratio, out):
    """``out[k, i, j]`` (2x2x2): local stress for unit local DD k (0 shear, 1 normal)."""
    gxx = 0.0
    gxy = 0.0
    gxxx = 0.0
    gxxy = 0.0
    ysq = y * y
    for end in range(2):
        xi = a if end == 0 else -a
        sign = 1.0 if end == 0 else -1.0
        X = x - xi
        inv_r2 = 1.0 / (X * X + ysq)
        inv_r4 = inv_r2 * inv_r2
        gxx -= sign * X * inv_r2
        gxy -= sign * y * inv_r2
        gxxx += sign * (X * X - ysq) * inv_r4
        gxxy += sign * 2.0 * X * y * inv_r4
    c = 2.0 * shear_modulus * _INV_4PI / (1.0 - poisson_ratio)  # 2G times the factor of g
    gxx *= c
    gxy *= c
    gxxx *= c
    gxxy *= c
    gyy = -gxx
    out[0, 0, 0] = 2.0 * gxy - y * gxxx
    out[0, 0, 1] = gyy - y * gxxy
    out[0, 1, 1] = y * gxxx
    out[1, 0, 0] = gyy - y * gxxy
    out[1, 0, 1] = y * gxxx
    out[1, 1, 1] = gyy + y * gxxy
    out[0, 1, 0] = out[0, 0, 1]
    out[1, 1, 0] = out[1, 0, 1]


@njit(cache=True)
def tip_distance(x, y, a):
    """Distance from the local point ``(x, y)`` to the nearer end point of the segment."""
    d = abs(x) - a
    return math.sqrt(d * d + y * y)


#: Cases of :func:`tip_averaging`.
REGULAR, UNDEFINED, AVERAGED = 0, 1, 2


@njit(cache=True, inline="always")
def tip_averaging(x, y, a, singular_shift, near):
    """How the stress at local ``(x, y)`` of a segment of half length ``a`` is evaluated
    (ref. Sec. 6.2.3): ``(REGULAR, x, x)`` away from the end points; ``(UNDEFINED, ...)``
    on an end point (or within ``near > 0`` of one) when ``singular_shift <= 0``; else
    ``(AVERAGED, x_plus, x_minus)``, the two points ``tip +- singular_shift * a`` on the
    segment's line whose mean value replaces the singular one."""
    if not (on_tip(x, y, a) or (near > 0.0 and tip_distance(x, y, a) <= near)):
        return REGULAR, x, x
    if singular_shift <= 0.0:
        return UNDEFINED, x, x
    tip = a if x >= 0.0 else -a
    delta = singular_shift * a
    return AVERAGED, tip + delta, tip - delta


@njit(cache=True)
def local_stress_corrected(x, y, a, shear_modulus, poisson_ratio, singular_shift, out, near=0.0):
    """:func:`local_stress`, with singular points handled by the reference's averaging
    (ref. Sec. 6.2.3).

    A point is singular when it lies on an end point (:func:`on_tip`) or, for
    ``near > 0``, within the distance ``near`` of one (a near-miss junction, where the
    exact value is ~1/gap). Such points give NaN when ``singular_shift <= 0`` (the
    caller reports them); otherwise the point is moved onto the end point and the
    stress is the mean of the values ``+-singular_shift * a`` along the segment from it.
    """
    case, x_plus, x_minus = tip_averaging(x, y, a, singular_shift, near)
    if case == REGULAR:
        local_stress(x, y, a, shear_modulus, poisson_ratio, out)
        return
    if case == UNDEFINED:
        out[:] = np.nan
        return
    tmp = np.empty((2, 2, 2))
    local_stress(x_plus, 0.0, a, shear_modulus, poisson_ratio, out)
    local_stress(x_minus, 0.0, a, shear_modulus, poisson_ratio, tmp)
    for k in range(2):
        for i in range(2):
            for j in range(2):
                out[k, i, j] = 0.5 * (out[k, i, j] + tmp[k, i, j])


@njit(cache=True)
def traction_pair(point, normal, center, frame, a, shear_modulus, poisson_ratio, singular_shift, out, work,
                  near=0.0):
    """``out[p, q]``: global traction component p at ``point`` (receiver ``normal``) for a
    unit global DD component q of the segment (ref. Eqs 2.57-2.58). ``near``: see
    :func:`local_stress_corrected`."""
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    x = frame[0, 0] * dx + frame[0, 1] * dy
    y = frame[1, 0] * dx + frame[1, 1] * dy
    local_stress_corrected(x, y, a, shear_modulus, poisson_ratio, singular_shift, work, near)
    m0 = frame[0, 0] * normal[0] + frame[0, 1] * normal[1]
    m1 = frame[1, 0] * normal[0] + frame[1, 1] * normal[1]
    t00 = work[0, 0, 0] * m0 + work[0, 0, 1] * m1
    t10 = work[0, 1, 0] * m0 + work[0, 1, 1] * m1
    t01 = work[1, 0, 0] * m0 + work[1, 0, 1] * m1
    t11 = work[1, 1, 0] * m0 + work[1, 1, 1] * m1
    for q in range(2):
        c0 = t00 * frame[0, q] + t01 * frame[1, q]
        c1 = t10 * frame[0, q] + t11 * frame[1, q]
        for p in range(2):
            out[p, q] = frame[0, p] * c0 + frame[1, p] * c1


@njit(cache=True)
def stress_pair(point, center, frame, a, shear_modulus, poisson_ratio, singular_shift, out, work, near=0.0):
    """Global stress at ``point`` from unit global DD components: ``out[q, i, j]``
    (``near``: see :func:`local_stress_corrected`)."""
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    x = frame[0, 0] * dx + frame[0, 1] * dy
    y = frame[1, 0] * dx + frame[1, 1] * dy
    local_stress_corrected(x, y, a, shear_modulus, poisson_ratio, singular_shift, work, near)
    rotate_to_global(frame, work, out)


@njit(cache=True)
def rotate_to_global(frame, local, out):
    """``out[q, i, j]`` (global stress per unit global DD component q) from ``local[k, p, s]``
    (local stress per unit local DD component k) and the element's ``frame`` rows."""
    for q in range(2):
        for i in range(2):
            for j in range(2):
                acc = 0.0
                for k in range(2):
                    for p in range(2):
                        for s in range(2):
                            acc += frame[k, q] * frame[p, i] * local[k, p, s] * frame[s, j]
                out[q, i, j] = acc


#: The geometry fields of every record of 2D segments (:func:`.drivers.kernel_record`).
SEGMENT_FIELDS = (("centers", np.ndarray, "(N, 2) element midpoints"),
                  ("frames", np.ndarray, "(N, 2, 2) rows: unit tangent, unit normal"),
                  ("half_length", np.ndarray, "(N,) half lengths a"))
Segments = kernel_record("Segments", __name__, "Kernel data of constant 2D elements (the record :mod:`.drivers` take).",
                         SEGMENT_FIELDS + HOMOGENEOUS_FIELDS)


@njit(cache=True)
def workspace(data):
    """Scratch of :func:`traction_pair` / :func:`stress_pair`: the local stress (2, 2, 2)."""
    return np.empty((2, 2, 2))


@njit(cache=True, inline="always")
def element_traction(data, i, j, state, work, block):
    """``block`` (2, 2): :func:`traction_pair` at the centre of element ``i`` (its normal)
    from element ``j``; a centre closer than ``near_fraction * min(a_i, a_j)`` to an end of
    ``j`` counts as on it (see :func:`local_stress_corrected`)."""
    near = 0.0
    if i != j:
        near = data.near_fraction * min(data.half_length[i], data.half_length[j])
    traction_pair(data.centers[i], data.frames[i, 1], data.centers[j], data.frames[j], data.half_length[j],
                  data.shear_modulus, data.poisson_ratio, data.singular_shift, block, work, near)


@njit(cache=True, inline="always")
def element_stress(data, point, point_layer, j, work, out):
    """``out`` (2, 2, 2): :func:`stress_pair` of element ``j`` at ``point``."""
    a = data.half_length[j]
    stress_pair(point, data.centers[j], data.frames[j], a, data.shear_modulus, data.poisson_ratio,
                data.singular_shift, out, work, data.near_fraction * a)


@njit(cache=True)
def edge_distance(data, i, j):
    """Distance from element ``i``'s centre to the nearer end of element ``j`` (any record
    with ``centers``, ``frames`` and ``half_length``)."""
    centers, frames = data.centers, data.frames
    dx = centers[i, 0] - centers[j, 0]
    dy = centers[i, 1] - centers[j, 1]
    x = frames[j, 0, 0] * dx + frames[j, 0, 1] * dy
    y = frames[j, 1, 0] * dx + frames[j, 1, 1] * dy
    return tip_distance(x, y, data.half_length[j])


@njit(cache=True)
def mean_stress_pair(point, center, frame, a, shear_modulus, poisson_ratio, out):
    """In-plane mean-stress influence ``out[q]`` (2,) of unit global DD components
    (ref. Eqs 5.25, 5.27: ``(s_xx + s_yy)/2 = 2G [g_xy, g_yy]`` in the local frame)."""
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    x = frame[0, 0] * dx + frame[0, 1] * dy
    y = frame[1, 0] * dx + frame[1, 1] * dy
    gxx = 0.0
    gxy = 0.0
    for end in range(2):
        X = x - (a if end == 0 else -a)
        sign = 1.0 if end == 0 else -1.0
        inv_r2 = 1.0 / (X * X + y * y)
        gxx -= sign * X * inv_r2
        gxy -= sign * y * inv_r2
    c = 2.0 * shear_modulus * _INV_4PI / (1.0 - poisson_ratio)
    m0 = c * gxy
    m1 = -c * gxx
    for q in range(2):
        out[q] = frame[0, q] * m0 + frame[1, q] * m1


register_kind(Segments, KernelKind(workspace, no_source_state, element_traction, element_stress, edge_distance))
