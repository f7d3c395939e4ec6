"""Displacement that a constant displacement discontinuity induces at a point, in closed
form (ref. Eqs 2.50, 2.53-2.57): the influence coefficients ``A_ij`` of ref. Eq. 2.43.

In the element's local frame (``x3`` its normal; ``x2`` absent in 2D), with the harmonic
potential ``g`` of ref. Eq. 2.54 (the one :mod:`.line2d` and :mod:`.rectangle3d` take the
stress from), ref. Eq. 2.56 reads, for the DD ``D``::

    u_1 = (2(1-nu) g_3 - x3 g_11) D_1 - x3 g_12 D_2 - ((1-2nu) g_1 + x3 g_13) D_3
    u_2 = -x3 g_12 D_1 + (2(1-nu) g_3 - x3 g_22) D_2 - ((1-2nu) g_2 + x3 g_23) D_3
    u_3 = ((1-2nu) g_1 - x3 g_13) D_1 + ((1-2nu) g_2 - x3 g_23) D_2 + (2(1-nu) g_3 - x3 g_33) D_3

so the displacement needs the first and second derivatives of ``g`` (the stress needs
the second and third). For the segment ``|x| <= a`` on ``y = 0`` (2D, ``x3`` read ``y``)
``g = 1/(4 pi (1-nu)) int ln r``, so ``g_x = (ln r_- - ln r_+) / (4 pi (1-nu))`` and
``g_y = (theta_+ - theta_-) / (4 pi (1-nu))`` with ``r_+-``, ``theta_+-`` the distance to
the end ``x = +-a`` and the angle ``atan2(y, x -+ a)``. For the rectangle
``|x1| <= a, |x2| <= b`` (3D), ``g = -1/(8 pi (1-nu)) sum_corners +-I`` with
``I_1 = ln(r + X2)``, ``I_2 = ln(r + X1)``, ``I_3 = -atan(X1 X2 / (x3 r))`` (the solid
angle the rectangle subtends) and the second derivatives of :mod:`.rectangle3d`.

``g_3`` jumps by ``1 / (2 (1-nu))`` across the element, so ``u(+) - u(-) = D``: on the
element itself (``x3 = 0`` inside it) the value returned is the ``+`` side's (``x3 -> 0+``,
the side the normal points to). On an edge (an end in 2D) the displacement is
log-singular: NaN there. As in :mod:`.rectangle3d` the point is reflected into the octant
``x1, x2, x3 >= 0`` first, where ``r + X`` vanishes only on an edge.
"""
import math

from numba import njit

from .rectangle3d import _r_plus, on_edge

_INV_4PI = 1.0 / (4.0 * math.pi)
_INV_8PI = 1.0 / (8.0 * math.pi)


@njit(cache=True)
def segment_local_displacement(x, y, a, poisson_ratio, out):
    """``out[k, i]`` (2x2): local displacement component ``i`` (0 along, 1 normal) at
    local point ``(x, y)`` per unit local DD component ``k`` (0 shear, 1 opening) of the
    segment ``|x| <= a`` on ``y = 0``. NaN at its ends."""
    nu = poisson_ratio
    if abs(y) <= 1e-12 * a and abs(abs(x) - a) <= 1e-12 * a:
        for k in range(2):
            for i in range(2):
                out[k, i] = math.nan
        return
    c = _INV_4PI / (1.0 - nu)
    xp, xm = x - a, x + a
    ysq = y * y
    rp2, rm2 = xp * xp + ysq, xm * xm + ysq
    gx = c * 0.5 * (math.log(rm2) - math.log(rp2))
    theta_p = math.atan2(y, xp)
    theta_m = math.atan2(y, xm)
    if y == 0.0 and abs(x) < a:  # on the element: the + side (y -> 0+)
        theta_p, theta_m = math.pi, 0.0
    gy = c * (theta_p - theta_m)
    gxx = c * (xm / rm2 - xp / rp2)
    gxy = c * (y / rm2 - y / rp2)
    gyy = -gxx
    out[0, 0] = 2.0 * (1.0 - nu) * gy - y * gxx
    out[0, 1] = (1.0 - 2.0 * nu) * gx - y * gxy
    out[1, 0] = -(1.0 - 2.0 * nu) * gx - y * gxy
    out[1, 1] = 2.0 * (1.0 - nu) * gy - y * gyy


@njit(cache=True)
def potential_gradient(x1, x2, x3, a, b):
    """First and second derivatives of ``sum_corners +-I`` at a point in the octant
    ``x1, x2, x3 >= 0`` of the element's local frame (the corner signs of
    :func:`hmatddm.kernels.rectangle3d.potential_derivatives`):
    ``(J1, J2, J3, J11, J22, J12, J13, J23)``; ``J33 = -J11 - J22``."""
    j1 = j2 = j3 = j11 = j22 = j12 = j13 = j23 = 0.0
    zsq = x3 * x3
    for corner in range(4):
        xi1 = a if (corner == 0 or corner == 2) else -a
        xi2 = b if corner < 2 else -b
        sign = 1.0 if (corner == 0 or corner == 3) else -1.0
        X = x1 - xi1
        Y = x2 - xi2
        r = math.sqrt(X * X + Y * Y + zsq)
        py = _r_plus(Y, X, zsq, r)  # r + Y
        px = _r_plus(X, Y, zsq, r)  # r + X
        inv_r = 1.0 / r
        j1 += sign * math.log(py)
        j2 += sign * math.log(px)
        j3 -= sign * math.atan2(X * Y, x3 * r)
        a_y = inv_r / py
        a_x = inv_r / px
        j11 += sign * X * a_y
        j22 += sign * Y * a_x
        j12 += sign * inv_r
        j13 += sign * x3 * a_y
        j23 += sign * x3 * a_x
    return j1, j2, j3, j11, j22, j12, j13, j23


@njit(cache=True)
def rectangle_local_displacement(x1, x2, x3, a, b, poisson_ratio, out):
    """``out[k, i]`` (3x3): local displacement component ``i`` at local point
    ``(x1, x2, x3)`` per unit local DD component ``k`` of the rectangle
    ``|x1| <= a, |x2| <= b`` on ``x3 = 0`` (ref. Eq. 2.56). NaN on its edges."""
    nu = poisson_ratio
    if on_edge(x1, x2, x3, a, b):
        for k in range(3):
            for i in range(3):
                out[k, i] = math.nan
        return
    s1 = 1.0 if x1 >= 0.0 else -1.0
    s2 = 1.0 if x2 >= 0.0 else -1.0
    s3 = 1.0 if x3 >= 0.0 else -1.0  # x3 = 0: the + side
    z = abs(x3)
    j1, j2, j3, j11, j22, j12, j13, j23 = potential_gradient(abs(x1), abs(x2), z, a, b)
    c = -_INV_8PI / (1.0 - nu)  # g = c sum_corners +-I
    g1 = c * s1 * j1
    g2 = c * s2 * j2
    g3 = c * s3 * j3
    # x3 g_ij with x3 = s3 z and the reflection signs of each index
    zg11 = s3 * c * z * j11
    zg22 = s3 * c * z * j22
    zg33 = -(zg11 + zg22)
    zg12 = s3 * c * s1 * s2 * z * j12
    zg13 = c * s1 * z * j13
    zg23 = c * s2 * z * j23
    t = 2.0 * (1.0 - nu) * g3
    m = 1.0 - 2.0 * nu
    out[0, 0] = t - zg11
    out[0, 1] = -zg12
    out[0, 2] = m * g1 - zg13
    out[1, 0] = -zg12
    out[1, 1] = t - zg22
    out[1, 2] = m * g2 - zg23
    out[2, 0] = -m * g1 - zg13
    out[2, 1] = -m * g2 - zg23
    out[2, 2] = t - zg33


__all__ = ["segment_local_displacement", "rectangle_local_displacement", "potential_gradient"]


@njit(cache=True)
def local_to_global(frame, local, out):
    """The displacement at a point of unit GLOBAL DD components: ``out[q, i] = sum_k sum_p
    F[k, q] local[k, p] F[p, i]``, with ``local[k, p]`` the displacement ``p`` (element frame)
    of a unit DD component ``k`` (element frame) and ``F`` the element's frame (rows: the
    element's axes in global coordinates), 2D or 3D."""
    d = frame.shape[0]
    for q in range(d):
        for i in range(d):
            acc = 0.0
            for k in range(d):
                for p in range(d):
                    acc += frame[k, q] * local[k, p] * frame[p, i]
            out[q, i] = acc
