"""Constant displacement discontinuity on a planar rectangle (3D), in closed form.

The element lies in its local plane ``x3 = 0`` with half sides ``a`` (along ``e1``)
and ``b`` (along ``e2``). The stress it induces follows from the harmonic potential

    g(x) = -1/(8 pi (1 - nu)) * sum_corners +-I(x; xi1, xi2)          ref. App. A eqs 21-23

through ref. Eq. 2.59 (stress per unit DD component, local frame), then rotated to the
global frame with ref. Eq. 2.57. Only second and third derivatives of ``I`` enter the
stress; they are rational functions of ``r`` (ref. App. A eqs 27-42; eqs 33, 40 and the
third-order terms are re-derived here: eq. 40 of the reference has ``r + x2`` where
``r + x1`` belongs). ``I_33``, ``I_133``, ``I_233`` and ``I_333`` are taken from
harmonicity (``I_11 + I_22 + I_33 = 0`` off the element), which also gives the correct
one-sided limits on the element plane.

Numerical safety: the point is first reflected into the octant ``x1, x2, x3 >= 0`` (the
rectangle is symmetric, so derivatives pick up a sign per reflected index). There the
terms ``r + x1bar`` and ``r + x2bar`` vanish only ON the element's edges, and are computed
as ``(x2bar^2 + x3^2)/(r - x1bar)`` when ``x1bar < 0`` to avoid cancellation. Points on the
extension of an edge are therefore regular; points exactly on an edge (a dislocation line,
where the stress is infinite) are singular and handled by :func:`local_stress_corrected`
(see :mod:`hmatddm.kernels.correction`), as are points within a caller-given ``near``
distance of an edge (near-miss junctions, where the exact value is ~1/gap).

The loops over element pairs are :mod:`hmatddm.kernels.drivers`; :class:`Rectangles` is
the kernel data.

Sign convention: DD = u(+) - u(-), + being the side ``n = e1 x e2`` points to; an opening
(DD . n > 0) induces compression on the element itself (docs/conventions.md §1).
"""
import math

import numpy as np
from numba import njit

from .drivers import HOMOGENEOUS_FIELDS, KernelKind, kernel_record, no_source_state, register_kind

_INV_8PI = 1.0 / (8.0 * math.pi)


@njit(cache=True, fastmath=False)
def _r_plus(xa, xb, x3sq, r):
    """``r + xa`` with ``r^2 = xa^2 + xb^2 + x3^2``, free of cancellation when ``xa < 0``."""
    if xa >= 0.0:
        return r + xa
    return (xb * xb + x3sq) / (r - xa)


@njit(cache=True)
def potential_derivatives(x1, x2, x3, a, b):
    """Second and third derivatives of ``sum_corners +-I`` (ref. App. A eqs 22-42) at a
    point in the octant ``x1, x2, x3 >= 0`` of the element's local frame.

    Returns ``(J11, J22, J12, J13, J23, J111, J112, J113, J122, J123, J222, J223)``;
    the others follow from harmonicity. Not defined on the element's edges.
    """
    j11 = j22 = j12 = j13 = j23 = 0.0
    j111 = j112 = j113 = j122 = j123 = j222 = j223 = 0.0
    zsq = x3 * x3
    for corner in range(4):
        xi1 = a if (corner == 0 or corner == 2) else -a
        xi2 = b if corner < 2 else -b
        sign = 1.0 if (corner == 0 or corner == 3) else -1.0
        X = x1 - xi1
        Y = x2 - xi2
        r = math.sqrt(X * X + Y * Y + zsq)
        inv_r = 1.0 / r
        inv_r3 = inv_r * inv_r * inv_r
        inv_py = 1.0 / _r_plus(Y, X, zsq, r)  # 1 / (r + Y)
        inv_px = 1.0 / _r_plus(X, Y, zsq, r)  # 1 / (r + X)
        a_y = inv_r * inv_py
        a_x = inv_r * inv_px
        j11 += sign * X * a_y
        j22 += sign * Y * a_x
        j12 += sign * inv_r
        j13 += sign * x3 * a_y
        j23 += sign * x3 * a_x
        t_y = (2.0 * r + Y) * inv_r3 * inv_py * inv_py
        t_x = (2.0 * r + X) * inv_r3 * inv_px * inv_px
        j111 += sign * (a_y - X * X * t_y)
        j113 -= sign * X * x3 * t_y
        j222 += sign * (a_x - Y * Y * t_x)
        j223 -= sign * Y * x3 * t_x
        j112 -= sign * X * inv_r3
        j122 -= sign * Y * inv_r3
        j123 -= sign * x3 * inv_r3
    return j11, j22, j12, j13, j23, j111, j112, j113, j122, j123, j222, j223


@njit(cache=True)
def on_edge(x1, x2, x3, a, b):
    """True when the local point lies on the rectangle's boundary (stress undefined)."""
    tol = 1e-12 * (a + b)
    if abs(x3) > tol:
        return False
    ax1 = abs(x1)
    ax2 = abs(x2)
    if abs(ax1 - a) <= tol and ax2 <= b + tol:
        return True
    if abs(ax2 - b) <= tol and ax1 <= a + tol:
        return True
    return False


@njit(cache=True, inline="always")
def g_derivatives(x1, x2, x3, a, b, shear_modulus, poisson_ratio):
    """The derivatives of ``g`` that the stress needs at local point ``(x1, x2, x3)``
    (ref. App. A eqs 22-42, scaled by 2G/(8 pi (1 - nu)) and reflected from the octant
    x >= 0 with the sign of each index; ``x3 g_ijk`` keeps ``|x3|``)::

        (g11, g22, g33, g12, g13, g23,
         zg111, zg112, zg113, zg122, zg123, zg222, zg223, zg133, zg233, zg333)
    """
    s1 = 1.0 if x1 >= 0.0 else -1.0
    s2 = 1.0 if x2 >= 0.0 else -1.0
    s3 = 1.0 if x3 >= 0.0 else -1.0
    z = abs(x3)
    (j11, j22, j12, j13, j23, j111, j112, j113, j122, j123, j222,
     j223) = potential_derivatives(abs(x1), abs(x2), z, a, b)
    c = -2.0 * shear_modulus * _INV_8PI / (1.0 - poisson_ratio)  # 2G times the factor of g
    g11 = c * j11
    g22 = c * j22
    zg111 = c * s3 * s1 * z * j111
    zg112 = c * s3 * s2 * z * j112
    zg113 = c * z * j113
    zg122 = c * s3 * s1 * z * j122
    zg222 = c * s3 * s2 * z * j222
    zg223 = c * z * j223
    return (g11, g22, -(g11 + g22), c * s1 * s2 * j12, c * s1 * s3 * j13, c * s2 * s3 * j23,
            zg111, zg112, zg113, zg122, c * s1 * s2 * z * j123, zg222, zg223,
            -(zg111 + zg122), -(zg112 + zg222), -(zg113 + zg223))


@njit(cache=True)
def local_stress(x1, x2, x3, a, b, shear_modulus, poisson_ratio, out):
    """Stress at local point ``(x1, x2, x3)`` from a unit DD along each local axis.

    ``out[k, i, j]`` (3x3x3) receives sigma_ij for DD_k = 1 (ref. Eq. 2.59), in Pa per m.
    """
    nu = poisson_ratio
    (g11, g22, g33, g12, g13, g23, zg111, zg112, zg113, zg122, zg123, zg222, zg223, zg133, zg233,
     zg333) = g_derivatives(x1, x2, x3, a, b, shear_modulus, poisson_ratio)
    # DD along e1
    out[0, 0, 0] = 2.0 * g13 - zg111
    out[0, 0, 1] = (1.0 - nu) * g23 - zg112
    out[0, 0, 2] = nu * g22 + g33 - zg113
    out[0, 1, 1] = 2.0 * nu * g13 - zg122
    out[0, 1, 2] = -nu * g12 - zg123
    out[0, 2, 2] = -zg133
    # DD along e2
    out[1, 0, 0] = 2.0 * nu * g23 - zg112
    out[1, 0, 1] = (1.0 - nu) * g13 - zg122
    out[1, 0, 2] = -nu * g12 - zg123
    out[1, 1, 1] = 2.0 * g23 - zg222
    out[1, 1, 2] = nu * g11 + g33 - zg223
    out[1, 2, 2] = -zg233
    # DD along n (opening)
    out[2, 0, 0] = g33 + (1.0 - 2.0 * nu) * g22 - zg113
    out[2, 0, 1] = -(1.0 - 2.0 * nu) * g12 - zg123
    out[2, 0, 2] = -zg133
    out[2, 1, 1] = g33 + (1.0 - 2.0 * nu) * g11 - zg223
    out[2, 1, 2] = -zg233
    out[2, 2, 2] = g33 - zg333
    for k in range(3):
        out[k, 1, 0] = out[k, 0, 1]
        out[k, 2, 0] = out[k, 0, 2]
        out[k, 2, 1] = out[k, 1, 2]


@njit(cache=True)
def _to_local(point, center, frame):
    d0 = point[0] - center[0]
    d1 = point[1] - center[1]
    d2 = point[2] - center[2]
    return (frame[0, 0] * d0 + frame[0, 1] * d1 + frame[0, 2] * d2,
            frame[1, 0] * d0 + frame[1, 1] * d1 + frame[1, 2] * d2,
            frame[2, 0] * d0 + frame[2, 1] * d1 + frame[2, 2] * d2)


@njit(cache=True)
def nearest_boundary_point(x1, x2, x3, a, b):
    """Nearest point of the rectangle's boundary (its four edges) to a local point.

    Returns ``(distance, p1, p2, u1, u2)``: the distance, the in-plane point ``(p1, p2)``
    (``p3 = 0``) and the unit in-plane direction ``(u1, u2)`` across the edge there
    (``e1`` on the ``x1 = +-a`` edges, ``e2`` on the ``x2 = +-b`` edges, the diagonal at a
    corner, as the reference's averaging needs).
    """
    ax1 = abs(x1)
    ax2 = abs(x2)
    zsq = x3 * x3
    tol = 1e-12 * (a + b)
    e1 = ax1 - a  # to the x1 = +-a edges (segments |x2| <= b)
    o2 = max(ax2 - b, 0.0)
    d1sq = e1 * e1 + o2 * o2 + zsq
    e2 = ax2 - b  # to the x2 = +-b edges (segments |x1| <= a)
    o1 = max(ax1 - a, 0.0)
    d2sq = e2 * e2 + o1 * o1 + zsq
    if d1sq <= d2sq:
        p1 = math.copysign(a, x1)
        p2 = math.copysign(min(ax2, b), x2)
        u1 = 1.0
        u2 = 1.0 if ax2 >= b - tol else 0.0
        distance = math.sqrt(d1sq)
    else:
        p1 = math.copysign(min(ax1, a), x1)
        p2 = math.copysign(b, x2)
        u1 = 1.0 if ax1 >= a - tol else 0.0
        u2 = 1.0
        distance = math.sqrt(d2sq)
    norm = math.sqrt(u1 * u1 + u2 * u2)
    return distance, p1, p2, u1 / norm, u2 / norm


@njit(cache=True)
def local_stress_corrected(x1, x2, x3, a, b, shear_modulus, poisson_ratio, singular_shift, out, near=0.0):
    """:func:`local_stress`, with singular points handled by the reference's averaging
    (ref. Sec. 6.2.3).

    A point is singular when it lies on an edge (:func:`on_edge`) or, for ``near > 0``,
    within the distance ``near`` of one (a near-miss junction, where the exact value is
    ~1/gap). Such points give NaN when ``singular_shift <= 0`` (the caller reports them);
    otherwise the point is moved onto the nearest boundary point and the stress is the
    mean of the values at two points ``+-singular_shift * min(a, b)`` across the edge
    from there, in the element plane (diagonally at a corner).
    """
    exact = on_edge(x1, x2, x3, a, b)
    if not exact and near <= 0.0:
        local_stress(x1, x2, x3, a, b, shear_modulus, poisson_ratio, out)
        return
    distance, p1, p2, u1, u2 = nearest_boundary_point(x1, x2, x3, a, b)
    if not exact and distance > near:
        local_stress(x1, x2, x3, a, b, shear_modulus, poisson_ratio, out)
        return
    if singular_shift <= 0.0:
        out[:] = np.nan
        return
    delta = singular_shift * min(a, b)
    tmp = np.empty((3, 3, 3))
    local_stress(p1 + delta * u1, p2 + delta * u2, 0.0, a, b, shear_modulus, poisson_ratio, out)
    local_stress(p1 - delta * u1, p2 - delta * u2, 0.0, a, b, shear_modulus, poisson_ratio, tmp)
    for k in range(3):
        for i in range(3):
            for j in range(3):
                out[k, i, j] = 0.5 * (out[k, i, j] + tmp[k, i, j])


@njit(cache=True)
def traction_pair(point, normal, center, frame, a, b, shear_modulus, poisson_ratio, singular_shift, out, work,
                  near=0.0):
    """Traction ``sigma . normal`` at ``point`` (global) from unit global DD components of
    one element: ``out[p, q]`` = traction component p for DD_q = 1 (ref. Eqs 2.57-2.58).
    ``work`` is a (3, 3, 3) scratch array; ``near``: see :func:`local_stress_corrected`."""
    x1, x2, x3 = _to_local(point, center, frame)
    local_stress_corrected(x1, x2, x3, a, b, shear_modulus, poisson_ratio, singular_shift, work, near)
    # receiver normal in the source's local frame
    m0 = frame[0, 0] * normal[0] + frame[0, 1] * normal[1] + frame[0, 2] * normal[2]
    m1 = frame[1, 0] * normal[0] + frame[1, 1] * normal[1] + frame[1, 2] * normal[2]
    m2 = frame[2, 0] * normal[0] + frame[2, 1] * normal[1] + frame[2, 2] * normal[2]
    # local traction T[i, k] for local DD k
    t00 = work[0, 0, 0] * m0 + work[0, 0, 1] * m1 + work[0, 0, 2] * m2
    t10 = work[0, 1, 0] * m0 + work[0, 1, 1] * m1 + work[0, 1, 2] * m2
    t20 = work[0, 2, 0] * m0 + work[0, 2, 1] * m1 + work[0, 2, 2] * m2
    t01 = work[1, 0, 0] * m0 + work[1, 0, 1] * m1 + work[1, 0, 2] * m2
    t11 = work[1, 1, 0] * m0 + work[1, 1, 1] * m1 + work[1, 1, 2] * m2
    t21 = work[1, 2, 0] * m0 + work[1, 2, 1] * m1 + work[1, 2, 2] * m2
    t02 = work[2, 0, 0] * m0 + work[2, 0, 1] * m1 + work[2, 0, 2] * m2
    t12 = work[2, 1, 0] * m0 + work[2, 1, 1] * m1 + work[2, 1, 2] * m2
    t22 = work[2, 2, 0] * m0 + work[2, 2, 1] * m1 + work[2, 2, 2] * m2
    # global: B = F^T T F, with F = frame (rows are the local axes)
    for q in range(3):
        f0 = frame[0, q]
        f1 = frame[1, q]
        f2 = frame[2, q]
        c0 = t00 * f0 + t01 * f1 + t02 * f2
        c1 = t10 * f0 + t11 * f1 + t12 * f2
        c2 = t20 * f0 + t21 * f1 + t22 * f2
        for p in range(3):
            out[p, q] = frame[0, p] * c0 + frame[1, p] * c1 + frame[2, p] * c2


@njit(cache=True)
def stress_pair(point, center, frame, a, b, shear_modulus, poisson_ratio, singular_shift, out, work, near=0.0):
    """Global stress at ``point`` from unit global DD components: ``out[q, i, j]``
    (``near``: see :func:`local_stress_corrected`)."""
    x1, x2, x3 = _to_local(point, center, frame)
    local_stress_corrected(x1, x2, x3, a, b, shear_modulus, poisson_ratio, singular_shift, work, near)
    for q in range(3):
        for i in range(3):
            for j in range(3):
                acc = 0.0
                for k in range(3):
                    fkq = frame[k, q]
                    for p in range(3):
                        fpi = frame[p, i]
                        for s in range(3):
                            acc += fkq * fpi * work[k, p, s] * frame[s, j]
                out[q, i, j] = acc


#: The geometry fields of every record of rectangles (:func:`.drivers.kernel_record`).
RECTANGLE_FIELDS = (("centers", np.ndarray, "(N, 3) element centres"),
                    ("frames", np.ndarray, "(N, 3, 3) rows: e1, e2, normal e1 x e2"),
                    ("half_a", np.ndarray, "(N,) half sides along e1"),
                    ("half_b", np.ndarray, "(N,) half sides along e2"))
Rectangles = kernel_record("Rectangles", __name__,
                           "Kernel data of constant 3D rectangles (the record :mod:`.drivers` take).",
                           RECTANGLE_FIELDS + HOMOGENEOUS_FIELDS)


@njit(cache=True)
def workspace(data):
    """Scratch of :func:`traction_pair` / :func:`stress_pair`: the local stress (3, 3, 3)."""
    return np.empty((3, 3, 3))


@njit(cache=True, inline="always")
def element_traction(data, i, j, state, work, block):
    """``block`` (3, 3): :func:`traction_pair` at the centre of element ``i`` (its normal)
    from element ``j``. A centre closer than ``near_fraction * min(size_i, size_j)``
    (``size = min(half_a, half_b)``) to an edge of ``j`` is singular (a near-miss
    junction): NaN without averaging, else the reference's averaging at the nearest edge
    point (:func:`local_stress_corrected`)."""
    near = 0.0
    if i != j:
        near = data.near_fraction * min(data.half_a[i], data.half_b[i], data.half_a[j], data.half_b[j])
    traction_pair(data.centers[i], data.frames[i, 2], data.centers[j], data.frames[j], data.half_a[j],
                  data.half_b[j], data.shear_modulus, data.poisson_ratio, data.singular_shift, block, work,
                  near)


@njit(cache=True, inline="always")
def element_stress(data, point, point_layer, j, work, out):
    """``out`` (3, 3, 3): :func:`stress_pair` of element ``j`` at ``point``."""
    a = data.half_a[j]
    b = data.half_b[j]
    stress_pair(point, data.centers[j], data.frames[j], a, b, data.shear_modulus, data.poisson_ratio,
                data.singular_shift, out, work, data.near_fraction * min(a, b))


@njit(cache=True)
def edge_distance(data, i, j):
    """Distance from element ``i``'s centre to the nearest edge of element ``j``."""
    x1, x2, x3 = _to_local(data.centers[i], data.centers[j], data.frames[j])
    return nearest_boundary_point(x1, x2, x3, data.half_a[j], data.half_b[j])[0]


@njit(cache=True)
def mean_stress_pair(point, center, frame, a, b, shear_modulus, poisson_ratio, out):
    """Mean-stress influence ``out[q]`` (3,) of unit global DD components (ref. Eqs 5.28-5.29):
    ``S_m = 4G(1+nu)/3 [g_13, g_23, g_33]`` in the local frame, rotated as a vector."""
    x1, x2, x3 = _to_local(point, center, frame)
    s1 = 1.0 if x1 >= 0.0 else -1.0
    s2 = 1.0 if x2 >= 0.0 else -1.0
    s3 = 1.0 if x3 >= 0.0 else -1.0
    j = potential_derivatives(abs(x1), abs(x2), abs(x3), a, b)
    c = -_INV_8PI / (1.0 - poisson_ratio) * 4.0 * shear_modulus * (1.0 + poisson_ratio) / 3.0
    m0 = c * s1 * s3 * j[3]
    m1 = c * s2 * s3 * j[4]
    m2 = -c * (j[0] + j[1])
    for q in range(3):
        out[q] = frame[0, q] * m0 + frame[1, q] * m1 + frame[2, q] * m2


register_kind(Rectangles, KernelKind(workspace, no_source_state, element_traction, element_stress, edge_distance))


@njit(cache=True)
def distance_to_rectangle(y0, y1, y2, center, frame, a, b):
    """Distance from the point ``(y0, y1, y2)`` to the rectangle (centre, frame rows e1 e2
    n, half sides a b)."""
    d0 = y0 - center[0]
    d1 = y1 - center[1]
    d2 = y2 - center[2]
    x1 = frame[0, 0] * d0 + frame[0, 1] * d1 + frame[0, 2] * d2
    x2 = frame[1, 0] * d0 + frame[1, 1] * d1 + frame[1, 2] * d2
    x3 = frame[2, 0] * d0 + frame[2, 1] * d1 + frame[2, 2] * d2
    o1 = max(abs(x1) - a, 0.0)
    o2 = max(abs(x2) - b, 0.0)
    return math.sqrt(o1 * o1 + o2 * o2 + x3 * x3)


@njit(cache=True)
def rectangle_distance(y, center, frame, a, b):
    """Distance from ``y`` to the rectangle (centre, frame rows e1 e2 n, half sides a b)."""
    return distance_to_rectangle(y[0], y[1], y[2], center, frame, a, b)
