"""The stress of a constant rectangular displacement discontinuity in an elastic
half-space in closed form (issue 32): Okada's (1992) internal deformation of a finite
rectangular source, Y. Okada, "Internal deformation due to shear and tensile faults in
a half-space", BSSA 82(2), 1018-1040, written here from the paper's finite-source
expressions (its parts A, B and C of the displacement derivatives, with the notation of
the finite source: ``R``, ``X11``, ``Y11``, ``X32``, ``Y32``, ``X53``, ``Y53``, ``Z32``,
``Z53``, ``E``, ``F``, ``G``, ``H``, ``I``, ``J``, ``K``; the cos(dip) = 0 forms of the
``J`` and ``K`` of part B, and the treatment of ``R + xi = 0`` / ``R + eta = 0`` on the
negative extension of an edge, from the same paper's section on singularities).

Okada's frame (used inside this module only): ``z`` up with the free surface ``z = 0``,
the fault strikes along ``x``; its points are ``(xi, eta cos(dip), -depth + eta
sin(dip))`` for ``al1 <= xi <= al2`` and ``aw1 <= eta <= aw2``; the dislocation
``(U1, U2, U3)`` (strike, up-dip, tensile) is the motion of the side the normal
``(0, -sin(dip), cos(dip))`` points to relative to the other side: with ``e1 = (1, 0,
0)``, ``e2 = (0, cos(dip), sin(dip))`` and ``n = e1 x e2`` that is exactly our
``DD = u(+) - u(-)`` in the frame ``(e1, e2, n)`` (docs/conventions.md §1; checked in
tests/layered/test_okada3d.py against the uniform-rock kernel, not assumed).

The half-space field is ``A(real) + [A + B + z C](image)`` summed over the rectangle's
corners with Chinnery's signs, ``f(al1, aw1) - f(al1, aw2) - f(al2, aw1) + f(al2, aw2)``
in ``(x - al, p - aw)`` (Okada 1992, the finite-source section). ``A(real)`` alone is
the whole-space field (:func:`gradient` with ``real=True, image=False``): it equals
:mod:`hmatddm.kernels.rectangle3d`, which the operator keeps for the real source (its
singular and near-miss handling); :func:`image_stress` adds the rest.

Only the displacement derivatives are computed (the stress needs no ``log`` and no
``atan``). Numerical safety, as the paper advises: ``xi``, ``eta`` and ``q`` smaller than
:data:`SNAP` times the rectangle's size are set to zero; ``R + xi`` and ``R + eta`` are
computed without cancellation; where one is zero (the point on the negative extension
of an edge) ``X11 = X32 = 0`` (``Y11 = Y32 = 0``), the limits whose differences over the
corners are finite; ``|cos(dip)| < COS_ZERO`` takes the vertical forms of part B.

Where the closed form does not apply: a rectangle with no horizontal edge (neither
``e1`` nor ``e2`` horizontal) has no strike in Okada's sense; such elements keep the
image quadrature (:mod:`.images3d`). The closed form is for a half-space only (one solid
layer under a void); two solid layers keep the image method.
"""
import math

import numpy as np
from numba import njit

#: Coordinates ``xi``, ``eta``, ``q`` smaller than this fraction of the rectangle's size
#: are set to zero (Okada 1992 sets them below 1e-6 of its unit).
SNAP = 1e-9
#: ``|cos(dip)|`` below this is vertical (Okada 1992's 1e-6).
COS_ZERO = 1e-6
#: ``|e_z|`` below this makes an element's side horizontal (as ``engine._has_horizontal_edge``).
HORIZONTAL = 1e-9

_INV_2PI = 1.0 / (2.0 * math.pi)


@njit(cache=True, inline="always")
def _plus(a, b, c, r):
    """``r + a`` with ``r^2 = a^2 + b^2 + c^2``, without cancellation when ``a < 0``."""
    if a >= 0.0:
        return r + a
    return (b * b + c * c) / (r - a)


@njit(cache=True)
def _corner(xi, eta, q, z, sd, cd, alpha, image, sign, out, t, b, w):
    """Add ``sign`` times the derivatives of one corner to ``out[k, i, j]`` (``du_i /
    dx_j`` in Okada's frame for a unit dislocation ``k``: strike, dip, tensile): part A
    (whole space) of the real source (``image`` False: ``d = depth + z`` in the caller)
    or parts A + B + z C of the image source (``image`` True: ``d = depth - z``), with the
    components turned from the fault's ``(x, y', z')`` to Okada's ``(x, y, z)`` as the
    paper does for each source. ``t``, ``b``, ``w``: (3, 3, 3) scratch."""
    r2 = xi * xi + eta * eta + q * q
    if r2 == 0.0:
        return
    r = math.sqrt(r2)
    r3 = r * r2
    r5 = r3 * r2
    xi2 = xi * xi
    q2 = q * q
    y = eta * cd + q * sd  # y-tilde
    d = eta * sd - q * cd  # d-tilde
    rx = _plus(xi, eta, q, r)
    if rx == 0.0:  # on the negative extension of an edge along xi
        x11 = 0.0
        x32 = 0.0
    else:
        x11 = 1.0 / (r * rx)
        x32 = (r + rx) * x11 * x11 / r
    re = _plus(eta, xi, q, r)
    if re == 0.0:
        y11 = 0.0
        y32 = 0.0
    else:
        y11 = 1.0 / (r * re)
        y32 = (r + re) * y11 * y11 / r
    ey = sd / r - y * q / r3
    ez = cd / r + d * q / r3
    fy = d / r3 + xi2 * y32 * sd
    fz = y / r3 + xi2 * y32 * cd
    gy = 2.0 * x11 * sd - y * q * x32
    gz = 2.0 * x11 * cd + d * q * x32
    hy = d * q * x32 + xi * q * y32 * sd
    hz = y * q * x32 + xi * q * y32 * cd
    a1 = 0.5 * (1.0 - alpha)
    a2 = 0.5 * alpha
    xy = xi * y11
    qy = q * y11
    sdcd = sd * cd
    sdsd = sd * sd
    cdcd = cd * cd
    # part A (infinite medium): rows are u_x', u_y', u_z' derivatives by x, y, z
    # strike slip
    t[0, 0, 0] = -a1 * qy - a2 * xi2 * q * y32
    t[0, 1, 0] = -a2 * xi * q / r3
    t[0, 2, 0] = a1 * xy + a2 * xi * q2 * y32
    t[0, 0, 1] = a1 * xy * sd + a2 * xi * fy + 0.5 * d * x11
    t[0, 1, 1] = a2 * ey
    t[0, 2, 1] = a1 * (cd / r + qy * sd) - a2 * q * fy
    t[0, 0, 2] = a1 * xy * cd + a2 * xi * fz + 0.5 * y * x11
    t[0, 1, 2] = a2 * ez
    t[0, 2, 2] = -a1 * (sd / r - qy * cd) - a2 * q * fz
    # dip slip
    t[1, 0, 0] = -a2 * xi * q / r3
    t[1, 1, 0] = -0.5 * qy - a2 * eta * q / r3
    t[1, 2, 0] = a1 / r + a2 * q2 / r3
    t[1, 0, 1] = a2 * ey
    t[1, 1, 1] = a1 * d * x11 + 0.5 * xy * sd + a2 * eta * gy
    t[1, 2, 1] = a1 * y * x11 - a2 * q * gy
    t[1, 0, 2] = a2 * ez
    t[1, 1, 2] = a1 * y * x11 + 0.5 * xy * cd + a2 * eta * gz
    t[1, 2, 2] = -a1 * d * x11 - a2 * q * gz
    # tensile
    t[2, 0, 0] = -a1 * xy + a2 * xi * q2 * y32
    t[2, 1, 0] = -a1 / r + a2 * q2 / r3
    t[2, 2, 0] = -a1 * qy - a2 * q * q2 * y32
    t[2, 0, 1] = -a1 * (cd / r + qy * sd) - a2 * q * fy
    t[2, 1, 1] = -a1 * y * x11 - a2 * q * gy
    t[2, 2, 1] = a1 * (d * x11 + xy * sd) + a2 * q * hy
    t[2, 0, 2] = a1 * (sd / r - qy * cd) - a2 * q * fz
    t[2, 1, 2] = a1 * d * x11 - a2 * q * gz
    t[2, 2, 2] = a1 * (y * x11 + xy * cd) + a2 * q * hz
    if not image:
        for k in range(3):
            for j in range(3):
                v0 = -t[k, 0, j]
                v1 = -t[k, 1, j] * cd + t[k, 2, j] * sd
                v2 = -t[k, 1, j] * sd - t[k, 2, j] * cd
                if j == 2:  # the real source's z-derivatives change sign (d = depth + z)
                    v0, v1, v2 = -v0, -v1, -v2
                out[k, 0, j] += sign * v0
                out[k, 1, j] += sign * v1
                out[k, 2, j] += sign * v2
        return
    # part B (surface deformation terms)
    a3 = (1.0 - alpha) / alpha
    rd = r + d
    d11 = 1.0 / (r * rd)
    j2 = xi * y / rd * d11
    j5 = -(d + y * y / rd) * d11
    if cd != 0.0:
        k1 = xi * (d11 - y11 * sd) / cd
        k3 = (q * y11 - y * d11) / cd
        j3 = (k1 - j2 * sd) / cd
        j6 = (k3 - j5 * sd) / cd
    else:
        rd2 = rd * rd
        k1 = xi * q / rd * d11
        k3 = sd / rd * (xi2 * d11 - 1.0)
        j3 = -xi / rd2 * (q2 * d11 - 0.5)
        j6 = -y / rd2 * (xi2 * d11 - 0.5)
    k2 = 1.0 / r + k3 * sd
    k4 = xy * cd - k1 * sd
    j1 = j5 * cd - j6 * sd
    j4 = -xy - j2 * cd + j3 * sd
    b[0, 0, 0] = xi2 * q * y32 - a3 * j1 * sd
    b[0, 1, 0] = xi * q / r3 - a3 * j2 * sd
    b[0, 2, 0] = -xi * q2 * y32 - a3 * j3 * sd
    b[0, 0, 1] = -xi * fy - d * x11 + a3 * (xy + j4) * sd
    b[0, 1, 1] = -ey + a3 * (1.0 / r + j5) * sd
    b[0, 2, 1] = q * fy - a3 * (qy - j6) * sd
    b[0, 0, 2] = -xi * fz - y * x11 + a3 * k1 * sd
    b[0, 1, 2] = -ez + a3 * y * d11 * sd
    b[0, 2, 2] = q * fz + a3 * k2 * sd
    b[1, 0, 0] = xi * q / r3 + a3 * j4 * sdcd
    b[1, 1, 0] = eta * q / r3 + qy + a3 * j5 * sdcd
    b[1, 2, 0] = -q2 / r3 + a3 * j6 * sdcd
    b[1, 0, 1] = -ey + a3 * j1 * sdcd
    b[1, 1, 1] = -eta * gy - xy * sd + a3 * j2 * sdcd
    b[1, 2, 1] = q * gy + a3 * j3 * sdcd
    b[1, 0, 2] = -ez - a3 * k3 * sdcd
    b[1, 1, 2] = -eta * gz - xy * cd - a3 * xi * d11 * sdcd
    b[1, 2, 2] = q * gz - a3 * k4 * sdcd
    b[2, 0, 0] = -xi * q2 * y32 - a3 * j4 * sdsd
    b[2, 1, 0] = -q2 / r3 - a3 * j5 * sdsd
    b[2, 2, 0] = q * q2 * y32 - a3 * j6 * sdsd
    b[2, 0, 1] = q * fy - a3 * j1 * sdsd
    b[2, 1, 1] = q * gy - a3 * j2 * sdsd
    b[2, 2, 1] = -q * hy - a3 * j3 * sdsd
    b[2, 0, 2] = q * fz + a3 * k3 * sdsd
    b[2, 1, 2] = q * gz + a3 * xi * d11 * sdsd
    b[2, 2, 2] = -q * hz + a3 * k4 * sdsd
    # part C (the terms multiplied by the depth of the observation point)
    a4 = 1.0 - alpha
    a5 = alpha
    c = d + z
    eta2 = eta * eta
    x53 = (8.0 * r2 + 9.0 * r * xi + 3.0 * xi2) * x11 * x11 * x11 / r2
    y53 = (8.0 * r2 + 9.0 * r * eta + 3.0 * eta2) * y11 * y11 * y11 / r2
    h = q * cd - z
    z32 = sd / r3 - h * y32
    z53 = 3.0 * sd / r5 - h * y53
    y0 = y11 - xi2 * y32
    z0 = z32 - xi2 * z53
    ppy = cd / r3 + q * y32 * sd
    ppz = sd / r3 - q * y32 * cd
    qq = z * y32 + z32 + z0
    qqy = 3.0 * c * d / r5 - qq * sd
    qqz = 3.0 * c * y / r5 - qq * cd + q * y32
    qr = 3.0 * q / r5
    cdr = (c + d) / r3
    yy0 = y / r3 - y0 * cd
    w[0, 0, 0] = a4 * y0 * cd - a5 * q * z0
    w[0, 1, 0] = -a4 * xi * (cd / r3 + 2.0 * q * y32 * sd) + a5 * c * xi * qr
    w[0, 2, 0] = -a4 * xi * q * y32 * cd + a5 * xi * (3.0 * c * eta / r5 - qq)
    w[0, 0, 1] = -a4 * xi * ppy * cd - a5 * xi * qqy
    w[0, 1, 1] = a4 * 2.0 * (d / r3 - y0 * sd) * sd - y / r3 * cd - a5 * (cdr * sd - eta / r3 - c * y * qr)
    w[0, 2, 1] = -a4 * q / r3 + yy0 * sd + a5 * (cdr * cd + c * d * qr - (y0 * cd + q * z0) * sd)
    w[0, 0, 2] = a4 * xi * ppz * cd - a5 * xi * qqz
    w[0, 1, 2] = a4 * 2.0 * (y / r3 - y0 * cd) * sd + d / r3 * cd - a5 * (cdr * cd + c * d * qr)
    w[0, 2, 2] = yy0 * cd - a5 * (cdr * sd - c * y * qr - y0 * sdsd + q * z0 * cd)
    w[1, 0, 0] = -a4 * xi / r3 * cd + a5 * c * xi * qr + xi * q * y32 * sd
    w[1, 1, 0] = -a4 * y / r3 + a5 * c * eta * qr
    w[1, 2, 0] = d / r3 - y0 * sd + a5 * c / r3 * (1.0 - 3.0 * q2 / r2)
    w[1, 0, 1] = -a4 * eta / r3 + y0 * sdsd - a5 * (cdr * sd - c * y * qr)
    w[1, 1, 1] = a4 * (x11 - y * y * x32) - a5 * c * ((d + 2.0 * q * cd) * x32 - y * eta * q * x53)
    w[1, 2, 1] = xi * ppy * sd + y * d * x32 + a5 * c * ((y + 2.0 * q * sd) * x32 - y * q2 * x53)
    w[1, 0, 2] = -q / r3 + y0 * sdcd - a5 * (cdr * cd + c * d * qr)
    w[1, 1, 2] = a4 * y * d * x32 - a5 * c * ((y - 2.0 * q * sd) * x32 + d * eta * q * x53)
    w[1, 2, 2] = -xi * ppz * sd + x11 - d * d * x32 - a5 * c * ((d - 2.0 * q * cd) * x32 - d * q2 * x53)
    w[2, 0, 0] = a4 * xi / r3 * sd + xi * q * y32 * cd + a5 * xi * (3.0 * c * eta / r5 - 2.0 * z32 - z0)
    w[2, 1, 0] = a4 * 2.0 * y0 * sd - d / r3 + a5 * c / r3 * (1.0 - 3.0 * q2 / r2)
    w[2, 2, 0] = -a4 * yy0 - a5 * (c * eta * qr - q * z0)
    w[2, 0, 1] = a4 * (q / r3 + y0 * sdcd) + a5 * (z / r3 * cd + c * d * qr - q * z0 * sd)
    w[2, 1, 1] = -a4 * 2.0 * xi * ppy * sd - y * d * x32 + a5 * c * ((y + 2.0 * q * sd) * x32 - y * q2 * x53)
    w[2, 2, 1] = (-a4 * (xi * ppy * cd - x11 + y * y * x32)
                  + a5 * (c * ((d + 2.0 * q * cd) * x32 - y * eta * q * x53) + xi * qqy))
    w[2, 0, 2] = -eta / r3 + y0 * cdcd - a5 * (z / r3 * sd - c * y * qr - y0 * sdsd + q * z0 * cd)
    w[2, 1, 2] = a4 * 2.0 * xi * ppz * sd - x11 + d * d * x32 - a5 * c * ((d - 2.0 * q * cd) * x32 - d * q2 * x53)
    w[2, 2, 2] = a4 * (xi * ppz * cd + y * d * x32) + a5 * (c * ((y - 2.0 * q * sd) * x32 + d * eta * q * x53)
                                                             + xi * qqz)
    for k in range(3):
        for j in range(3):
            s0 = t[k, 0, j] + b[k, 0, j]
            s1 = t[k, 1, j] + b[k, 1, j]
            s2 = t[k, 2, j] + b[k, 2, j]
            zc0 = z * w[k, 0, j]
            zc1 = z * w[k, 1, j]
            zc2 = z * w[k, 2, j]
            out[k, 0, j] += sign * (s0 + zc0)
            out[k, 1, j] += sign * ((s1 + zc1) * cd - (s2 + zc2) * sd)
            out[k, 2, j] += sign * ((s1 - zc1) * sd + (s2 - zc2) * cd)
    # d(z C)/dz = C + z dC/dz: C's displacement joins the z-derivatives
    c0 = a4 * xy * cd - a5 * xi * q * z32
    c1 = a4 * (cd / r + 2.0 * qy * sd) - a5 * c * q / r3
    c2 = a4 * qy * cd - a5 * (c * eta / r3 - z * y11 + xi2 * z32)
    out[0, 0, 2] += sign * c0
    out[0, 1, 2] += sign * (c1 * cd - c2 * sd)
    out[0, 2, 2] -= sign * (c1 * sd + c2 * cd)
    c0 = a4 * cd / r - qy * sd - a5 * c * q / r3
    c1 = a4 * y * x11 - a5 * c * eta * q * x32
    c2 = -d * x11 - xy * sd - a5 * c * (x11 - q2 * x32)
    out[1, 0, 2] += sign * c0
    out[1, 1, 2] += sign * (c1 * cd - c2 * sd)
    out[1, 2, 2] -= sign * (c1 * sd + c2 * cd)
    c0 = -a4 * (sd / r + qy * cd) - a5 * (z * y11 - q2 * z32)
    c1 = a4 * 2.0 * xy * sd + d * x11 - a5 * c * (x11 - q2 * x32)
    c2 = a4 * (y * x11 + xy * cd) + a5 * q * (c * eta * x32 + xi * z32)
    out[2, 0, 2] += sign * c0
    out[2, 1, 2] += sign * (c1 * cd - c2 * sd)
    out[2, 2, 2] -= sign * (c1 * sd + c2 * cd)


@njit(cache=True)
def gradient(x, y, z, depth, sd, cd, al1, al2, aw1, aw2, alpha, real, image, out, scratch):
    """``out[k, i, j] = du_i / dx_j`` at ``(x, y, z)`` (Okada's frame, ``z <= 0``) for a
    unit dislocation ``k`` (strike, dip, tensile) on the rectangle ``al1 <= xi <= al2``,
    ``aw1 <= eta <= aw2`` whose reference point is at depth ``depth``: the real source's
    part A (the whole space) when ``real``, plus the image source's parts A + B + z C
    when ``image`` (Okada 1992, finite source; Chinnery's sum over the corners).
    ``scratch``: (3, 3, 3, 3)."""
    out[:] = 0.0
    snap = SNAP * ((al2 - al1) + (aw2 - aw1))
    xs = (x - al1, x - al2)
    for source in range(2):
        if source == 0 and not real:
            continue
        if source == 1 and not image:
            continue
        d = depth + z if source == 0 else depth - z
        p = y * cd + d * sd
        q = y * sd - d * cd
        if abs(q) < snap:
            q = 0.0
        for jj in range(2):
            xi = xs[jj]
            if abs(xi) < snap:
                xi = 0.0
            for kk in range(2):
                eta = p - (aw1 if kk == 0 else aw2)
                if abs(eta) < snap:
                    eta = 0.0
                sign = 1.0 if jj == kk else -1.0
                _corner(xi, eta, q, z, sd, cd, alpha, source == 1, sign, out, scratch[0], scratch[1], scratch[2])
    for k in range(3):
        for i in range(3):
            for j in range(3):
                out[k, i, j] *= _INV_2PI


@njit(cache=True, inline="always")
def _hooke(grad, shear_modulus, poisson_ratio, out):
    """``out[k] = lambda tr(e) I + 2 mu e`` with ``e`` the symmetric part of ``grad[k]``."""
    lam = 2.0 * shear_modulus * poisson_ratio / (1.0 - 2.0 * poisson_ratio)
    for k in range(3):
        tr = grad[k, 0, 0] + grad[k, 1, 1] + grad[k, 2, 2]
        for i in range(3):
            for j in range(3):
                out[k, i, j] = shear_modulus * (grad[k, i, j] + grad[k, j, i])
            out[k, i, i] += lam * tr


def okada_frame(frame, half_a, half_b):
    """Okada's frame of one rectangle (``frame`` rows e1, e2, n): ``(strike, dip_vector,
    half_strike, half_dip)`` with ``strike`` a horizontal side direction, ``dip_vector``
    the other side pointing up (or horizontal), ``strike x dip_vector = n``; None when no
    side is horizontal (|e_z| > :data:`HORIZONTAL`)."""
    e1, e2 = np.asarray(frame[0], dtype=float), np.asarray(frame[1], dtype=float)
    if abs(e1[2]) <= HORIZONTAL:
        strike, dip, hs, hd = e1, e2, half_a, half_b
    elif abs(e2[2]) <= HORIZONTAL:
        strike, dip, hs, hd = e2, -e1, half_b, half_a
    else:
        return None
    if dip[2] < 0.0:
        strike, dip = -strike, -dip
    return strike, dip, hs, hd


def halfspace_geometry(frames, half_a, half_b):
    """Per element: ``(closed (N,) bool, okada (N, 3, 3), half (N, 2))`` with ``okada[e]``
    the rows ``(strike, up-dip, n)`` and ``half[e]`` the half sides along them, for the
    elements with a horizontal side (``closed``); the others keep zeros (no closed form)."""
    n = frames.shape[0]
    closed = np.zeros(n, dtype=np.bool_)
    okada = np.zeros((n, 3, 3))
    half = np.zeros((n, 2))
    for e in range(n):
        found = okada_frame(frames[e], half_a[e], half_b[e])
        if found is None:
            continue
        strike, dip, hs, hd = found
        s = np.array([strike[0], strike[1], 0.0])
        s /= np.linalg.norm(s)
        t = dip - (dip @ s) * s
        t /= np.linalg.norm(t)
        okada[e, 0] = s
        okada[e, 1] = t
        okada[e, 2] = np.cross(s, t)
        half[e] = hs, hd
        closed[e] = True
    return closed, okada, half


@njit(cache=True)
def okada_stress(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work, out):
    """``out[q, i, j]``: global stress at ``point`` for a unit global DD ``q`` of the
    rectangle (``center``, Okada rows ``okada`` = strike, up-dip, normal as
    :func:`halfspace_geometry` gives them, half sides ``hs``, ``hd``) under the free
    surface ``z = surface``: :func:`gradient` (``real``: the whole-space part, ``image``:
    the image and surface terms) through Hooke's law, turned from Okada's frame (``x`` =
    strike, ``y = z x strike``, ``z``) to the global one. ``work``: (5, 3, 3, 3) scratch."""
    grad = work[0]
    local = work[1]
    s0 = okada[0, 0]
    s1 = okada[0, 1]
    # Okada's horizontal axes: x = strike, y = (-s1, s0)
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    x = s0 * dx + s1 * dy
    y = -s1 * dx + s0 * dy
    z = point[2] - surface
    depth = surface - center[2]
    t1 = -s1 * okada[1, 0] + s0 * okada[1, 1]
    t2 = okada[1, 2]
    norm = math.sqrt(t1 * t1 + t2 * t2)
    cd = t1 / norm
    sd = t2 / norm
    if abs(cd) < COS_ZERO:
        cd = 0.0
        sd = 1.0
    lam = 2.0 * shear_modulus * poisson_ratio / (1.0 - 2.0 * poisson_ratio)
    alpha = (lam + shear_modulus) / (lam + 2.0 * shear_modulus)
    gradient(x, y, z, depth, sd, cd, -hs, hs, -hd, hd, alpha, real, image, grad, work[2:])
    _hooke(grad, shear_modulus, poisson_ratio, local)
    # rotate about z: global = R^T local R, R rows (x, y, z axes of Okada's frame)
    for k in range(3):
        for i in range(3):
            # rows: sigma . R  (columns to global)
            a0 = local[k, i, 0] * s0 - local[k, i, 1] * s1
            a1 = local[k, i, 0] * s1 + local[k, i, 1] * s0
            a2 = local[k, i, 2]
            grad[k, i, 0] = a0
            grad[k, i, 1] = a1
            grad[k, i, 2] = a2
        for j in range(3):
            b0 = grad[k, 0, j] * s0 - grad[k, 1, j] * s1
            b1 = grad[k, 0, j] * s1 + grad[k, 1, j] * s0
            b2 = grad[k, 2, j]
            local[k, 0, j] = b0
            local[k, 1, j] = b1
            local[k, 2, j] = b2
    for q in range(3):
        f0 = okada[0, q]
        f1 = okada[1, q]
        f2 = okada[2, q]
        for i in range(3):
            for j in range(3):
                out[q, i, j] = f0 * local[0, i, j] + f1 * local[1, i, j] + f2 * local[2, i, j]
