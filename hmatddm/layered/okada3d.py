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


@njit(cache=True, inline="always")
def _add_real(s, k, j, sign, cd, sd, a0, a1, a2):
    """Real source: ``s[3, k, :, j] += sign * (-a0, -a1 cd + a2 sd, -a1 sd - a2 cd)``
    (the fault's components turned to Okada's frame; ``sign`` carries Chinnery's sign and,
    for ``j = 2``, the real source's ``d = depth + z``)."""
    s[3, k, 0, j] -= sign * a0
    s[3, k, 1, j] += sign * (a2 * sd - a1 * cd)
    s[3, k, 2, j] -= sign * (a1 * sd + a2 * cd)


@njit(cache=True, inline="always")
def _add_image(s, k, j, sign, cd, sd, z, ab0, ab1, ab2, c0, c1, c2):
    """Image source: ``A + B`` (``ab``) and ``z C`` (``c``) turned to Okada's frame (the
    ``z C`` term flips sign in the vertical turn), added with Chinnery's ``sign``."""
    s[3, k, 0, j] += sign * (ab0 + z * c0)
    s[3, k, 1, j] += sign * ((ab1 + z * c1) * cd - (ab2 + z * c2) * sd)
    s[3, k, 2, j] += sign * ((ab1 - z * c1) * sd + (ab2 - z * c2) * cd)


@njit(cache=True, inline="always", fastmath={"contract", "arcp"})
def _corner(xi, eta, q, z, sd, cd, alpha, image, sign, s):
    """Add ``sign`` times the derivatives of one corner to ``s[3, k, i, j]`` (``du_i /
    dx_j`` in Okada's frame for a unit dislocation ``k``: strike, dip, tensile): part A
    (whole space) of the real source (``image`` False: ``d = depth + z`` in the caller)
    or parts A + B + z C of the image source (``image`` True: ``d = depth - z``), with the
    components turned from the fault's ``(x, y', z')`` to Okada's ``(x, y, z)`` as the
    paper does for each source. The parts' 27 derivatives are scalars (``A kij``, ``B kij``,
    ``W kij`` for C: dislocation ``k``, component ``i`` in the fault's ``(x, y', z')``, by
    ``x_j``); ``s`` is indexed, never sliced (a view costs two atomic reference counts)."""
    r2 = xi * xi + eta * eta + q * q
    if r2 == 0.0:
        return
    r = math.sqrt(r2)
    ir = 1.0 / r
    ir2 = ir * ir
    ir3 = ir * ir2
    ir5 = ir3 * ir2
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
        x32 = (r + rx) * x11 * x11 * ir
    re = _plus(eta, xi, q, r)
    if re == 0.0:
        y11 = 0.0
        y32 = 0.0
    else:
        y11 = 1.0 / (r * re)
        y32 = (r + re) * y11 * y11 * ir
    ey = sd * ir - y * q * ir3
    ez = cd * ir + d * q * ir3
    fy = d * ir3 + xi2 * y32 * sd
    fz = y * ir3 + xi2 * y32 * cd
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
    A000 = -a1 * qy - a2 * xi2 * q * y32
    A010 = -a2 * xi * q * ir3
    A020 = a1 * xy + a2 * xi * q2 * y32
    A001 = a1 * xy * sd + a2 * xi * fy + 0.5 * d * x11
    A011 = a2 * ey
    A021 = a1 * (cd * ir + qy * sd) - a2 * q * fy
    A002 = a1 * xy * cd + a2 * xi * fz + 0.5 * y * x11
    A012 = a2 * ez
    A022 = -a1 * (sd * ir - qy * cd) - a2 * q * fz
    # dip slip
    A100 = -a2 * xi * q * ir3
    A110 = -0.5 * qy - a2 * eta * q * ir3
    A120 = a1 * ir + a2 * q2 * ir3
    A101 = a2 * ey
    A111 = a1 * d * x11 + 0.5 * xy * sd + a2 * eta * gy
    A121 = a1 * y * x11 - a2 * q * gy
    A102 = a2 * ez
    A112 = a1 * y * x11 + 0.5 * xy * cd + a2 * eta * gz
    A122 = -a1 * d * x11 - a2 * q * gz
    # tensile
    A200 = -a1 * xy + a2 * xi * q2 * y32
    A210 = -a1 * ir + a2 * q2 * ir3
    A220 = -a1 * qy - a2 * q * q2 * y32
    A201 = -a1 * (cd * ir + qy * sd) - a2 * q * fy
    A211 = -a1 * y * x11 - a2 * q * gy
    A221 = a1 * (d * x11 + xy * sd) + a2 * q * hy
    A202 = a1 * (sd * ir - qy * cd) - a2 * q * fz
    A212 = a1 * d * x11 - a2 * q * gz
    A222 = a1 * (y * x11 + xy * cd) + a2 * q * hz
    if not image:
        _add_real(s, 0, 0, sign, cd, sd, A000, A010, A020)
        _add_real(s, 0, 1, sign, cd, sd, A001, A011, A021)
        _add_real(s, 0, 2, sign * -1.0, cd, sd, A002, A012, A022)
        _add_real(s, 1, 0, sign, cd, sd, A100, A110, A120)
        _add_real(s, 1, 1, sign, cd, sd, A101, A111, A121)
        _add_real(s, 1, 2, sign * -1.0, cd, sd, A102, A112, A122)
        _add_real(s, 2, 0, sign, cd, sd, A200, A210, A220)
        _add_real(s, 2, 1, sign, cd, sd, A201, A211, A221)
        _add_real(s, 2, 2, sign * -1.0, cd, sd, A202, A212, A222)
        return
    # part B (surface deformation terms)
    a3 = (1.0 - alpha) / alpha
    rd = r + d
    ird = 1.0 / rd
    d11 = ir * ird
    j2 = xi * y * ird * d11
    j5 = -(d + y * y * ird) * d11
    if cd != 0.0:
        icd = 1.0 / cd
        k1 = xi * (d11 - y11 * sd) * icd
        k3 = (q * y11 - y * d11) * icd
        j3 = (k1 - j2 * sd) * icd
        j6 = (k3 - j5 * sd) * icd
    else:
        ird2 = ird * ird
        k1 = xi * q * ird * d11
        k3 = sd * ird * (xi2 * d11 - 1.0)
        j3 = -xi * ird2 * (q2 * d11 - 0.5)
        j6 = -y * ird2 * (xi2 * d11 - 0.5)
    k2 = 1.0 * ir + k3 * sd
    k4 = xy * cd - k1 * sd
    j1 = j5 * cd - j6 * sd
    j4 = -xy - j2 * cd + j3 * sd
    B000 = xi2 * q * y32 - a3 * j1 * sd
    B010 = xi * q * ir3 - a3 * j2 * sd
    B020 = -xi * q2 * y32 - a3 * j3 * sd
    B001 = -xi * fy - d * x11 + a3 * (xy + j4) * sd
    B011 = -ey + a3 * (1.0 * ir + j5) * sd
    B021 = q * fy - a3 * (qy - j6) * sd
    B002 = -xi * fz - y * x11 + a3 * k1 * sd
    B012 = -ez + a3 * y * d11 * sd
    B022 = q * fz + a3 * k2 * sd
    B100 = xi * q * ir3 + a3 * j4 * sdcd
    B110 = eta * q * ir3 + qy + a3 * j5 * sdcd
    B120 = -q2 * ir3 + a3 * j6 * sdcd
    B101 = -ey + a3 * j1 * sdcd
    B111 = -eta * gy - xy * sd + a3 * j2 * sdcd
    B121 = q * gy + a3 * j3 * sdcd
    B102 = -ez - a3 * k3 * sdcd
    B112 = -eta * gz - xy * cd - a3 * xi * d11 * sdcd
    B122 = q * gz - a3 * k4 * sdcd
    B200 = -xi * q2 * y32 - a3 * j4 * sdsd
    B210 = -q2 * ir3 - a3 * j5 * sdsd
    B220 = q * q2 * y32 - a3 * j6 * sdsd
    B201 = q * fy - a3 * j1 * sdsd
    B211 = q * gy - a3 * j2 * sdsd
    B221 = -q * hy - a3 * j3 * sdsd
    B202 = q * fz + a3 * k3 * sdsd
    B212 = q * gz + a3 * xi * d11 * sdsd
    B222 = -q * hz + a3 * k4 * sdsd
    # part C (the terms multiplied by the depth of the observation point)
    a4 = 1.0 - alpha
    a5 = alpha
    c = d + z
    eta2 = eta * eta
    x53 = (8.0 * r2 + 9.0 * r * xi + 3.0 * xi2) * x11 * x11 * x11 * ir2
    y53 = (8.0 * r2 + 9.0 * r * eta + 3.0 * eta2) * y11 * y11 * y11 * ir2
    h = q * cd - z
    z32 = sd * ir3 - h * y32
    z53 = 3.0 * sd * ir5 - h * y53
    y0 = y11 - xi2 * y32
    z0 = z32 - xi2 * z53
    ppy = cd * ir3 + q * y32 * sd
    ppz = sd * ir3 - q * y32 * cd
    qq = z * y32 + z32 + z0
    qqy = 3.0 * c * d * ir5 - qq * sd
    qqz = 3.0 * c * y * ir5 - qq * cd + q * y32
    qr = 3.0 * q * ir5
    cdr = (c + d) * ir3
    yy0 = y * ir3 - y0 * cd
    W000 = a4 * y0 * cd - a5 * q * z0
    W010 = -a4 * xi * (cd * ir3 + 2.0 * q * y32 * sd) + a5 * c * xi * qr
    W020 = -a4 * xi * q * y32 * cd + a5 * xi * (3.0 * c * eta * ir5 - qq)
    W001 = -a4 * xi * ppy * cd - a5 * xi * qqy
    W011 = a4 * 2.0 * (d * ir3 - y0 * sd) * sd - y * ir3 * cd - a5 * (cdr * sd - eta * ir3 - c * y * qr)
    W021 = -a4 * q * ir3 + yy0 * sd + a5 * (cdr * cd + c * d * qr - (y0 * cd + q * z0) * sd)
    W002 = a4 * xi * ppz * cd - a5 * xi * qqz
    W012 = a4 * 2.0 * (y * ir3 - y0 * cd) * sd + d * ir3 * cd - a5 * (cdr * cd + c * d * qr)
    W022 = yy0 * cd - a5 * (cdr * sd - c * y * qr - y0 * sdsd + q * z0 * cd)
    W100 = -a4 * xi * ir3 * cd + a5 * c * xi * qr + xi * q * y32 * sd
    W110 = -a4 * y * ir3 + a5 * c * eta * qr
    W120 = d * ir3 - y0 * sd + a5 * c * ir3 * (1.0 - 3.0 * q2 * ir2)
    W101 = -a4 * eta * ir3 + y0 * sdsd - a5 * (cdr * sd - c * y * qr)
    W111 = a4 * (x11 - y * y * x32) - a5 * c * ((d + 2.0 * q * cd) * x32 - y * eta * q * x53)
    W121 = xi * ppy * sd + y * d * x32 + a5 * c * ((y + 2.0 * q * sd) * x32 - y * q2 * x53)
    W102 = -q * ir3 + y0 * sdcd - a5 * (cdr * cd + c * d * qr)
    W112 = a4 * y * d * x32 - a5 * c * ((y - 2.0 * q * sd) * x32 + d * eta * q * x53)
    W122 = -xi * ppz * sd + x11 - d * d * x32 - a5 * c * ((d - 2.0 * q * cd) * x32 - d * q2 * x53)
    W200 = a4 * xi * ir3 * sd + xi * q * y32 * cd + a5 * xi * (3.0 * c * eta * ir5 - 2.0 * z32 - z0)
    W210 = a4 * 2.0 * y0 * sd - d * ir3 + a5 * c * ir3 * (1.0 - 3.0 * q2 * ir2)
    W220 = -a4 * yy0 - a5 * (c * eta * qr - q * z0)
    W201 = a4 * (q * ir3 + y0 * sdcd) + a5 * (z * ir3 * cd + c * d * qr - q * z0 * sd)
    W211 = -a4 * 2.0 * xi * ppy * sd - y * d * x32 + a5 * c * ((y + 2.0 * q * sd) * x32 - y * q2 * x53)
    W221 = (-a4 * (xi * ppy * cd - x11 + y * y * x32) + a5 * (c * ((d + 2.0 * q * cd) * x32 - y * eta * q * x53) + xi * qqy))
    W202 = -eta * ir3 + y0 * cdcd - a5 * (z * ir3 * sd - c * y * qr - y0 * sdsd + q * z0 * cd)
    W212 = a4 * 2.0 * xi * ppz * sd - x11 + d * d * x32 - a5 * c * ((d - 2.0 * q * cd) * x32 - d * q2 * x53)
    W222 = a4 * (xi * ppz * cd + y * d * x32) + a5 * (c * ((y - 2.0 * q * sd) * x32 + d * eta * q * x53) + xi * qqz)
    _add_image(s, 0, 0, sign, cd, sd, z, A000 + B000, A010 + B010, A020 + B020,
               W000, W010, W020)
    _add_image(s, 0, 1, sign, cd, sd, z, A001 + B001, A011 + B011, A021 + B021,
               W001, W011, W021)
    _add_image(s, 0, 2, sign, cd, sd, z, A002 + B002, A012 + B012, A022 + B022,
               W002, W012, W022)
    _add_image(s, 1, 0, sign, cd, sd, z, A100 + B100, A110 + B110, A120 + B120,
               W100, W110, W120)
    _add_image(s, 1, 1, sign, cd, sd, z, A101 + B101, A111 + B111, A121 + B121,
               W101, W111, W121)
    _add_image(s, 1, 2, sign, cd, sd, z, A102 + B102, A112 + B112, A122 + B122,
               W102, W112, W122)
    _add_image(s, 2, 0, sign, cd, sd, z, A200 + B200, A210 + B210, A220 + B220,
               W200, W210, W220)
    _add_image(s, 2, 1, sign, cd, sd, z, A201 + B201, A211 + B211, A221 + B221,
               W201, W211, W221)
    _add_image(s, 2, 2, sign, cd, sd, z, A202 + B202, A212 + B212, A222 + B222,
               W202, W212, W222)
    # d(z C)/dz = C + z dC/dz: C's displacement joins the z-derivatives
    c0 = a4 * xy * cd - a5 * xi * q * z32
    c1 = a4 * (cd * ir + 2.0 * qy * sd) - a5 * c * q * ir3
    c2 = a4 * qy * cd - a5 * (c * eta * ir3 - z * y11 + xi2 * z32)
    s[3, 0, 0, 2] += sign * c0
    s[3, 0, 1, 2] += sign * (c1 * cd - c2 * sd)
    s[3, 0, 2, 2] -= sign * (c1 * sd + c2 * cd)
    c0 = a4 * cd * ir - qy * sd - a5 * c * q * ir3
    c1 = a4 * y * x11 - a5 * c * eta * q * x32
    c2 = -d * x11 - xy * sd - a5 * c * (x11 - q2 * x32)
    s[3, 1, 0, 2] += sign * c0
    s[3, 1, 1, 2] += sign * (c1 * cd - c2 * sd)
    s[3, 1, 2, 2] -= sign * (c1 * sd + c2 * cd)
    c0 = -a4 * (sd * ir + qy * cd) - a5 * (z * y11 - q2 * z32)
    c1 = a4 * 2.0 * xy * sd + d * x11 - a5 * c * (x11 - q2 * x32)
    c2 = a4 * (y * x11 + xy * cd) + a5 * q * (c * eta * x32 + xi * z32)
    s[3, 2, 0, 2] += sign * c0
    s[3, 2, 1, 2] += sign * (c1 * cd - c2 * sd)
    s[3, 2, 2, 2] -= sign * (c1 * sd + c2 * cd)


@njit(cache=True, fastmath={"contract", "arcp"})
def gradient(x, y, z, depth, sd, cd, al1, al2, aw1, aw2, alpha, real, image, s):
    """``s[3, k, i, j] = du_i / dx_j`` at ``(x, y, z)`` (Okada's frame, ``z <= 0``) for a
    unit dislocation ``k`` (strike, dip, tensile) on the rectangle ``al1 <= xi <= al2``,
    ``aw1 <= eta <= aw2`` whose reference point is at depth ``depth``: the real source's
    part A (the whole space) when ``real``, plus the image source's parts A + B + z C
    when ``image`` (Okada 1992, finite source; Chinnery's sum over the corners).
    ``s``: (4, 3, 3, 3), ``s[0:3]`` scratch."""
    for k in range(3):
        for i in range(3):
            for j in range(3):
                s[3, k, i, j] = 0.0
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
                _corner(xi, eta, q, z, sd, cd, alpha, source == 1, sign, s)
    for k in range(3):
        for i in range(3):
            for j in range(3):
                s[3, k, i, j] *= _INV_2PI


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


@njit(cache=True, inline="always")
def _gradient(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work):
    """:func:`gradient` into ``work[3]`` at a global ``point`` for the rectangle of
    :func:`okada_stress`; returns the strike's ``(s_x, s_y)`` and Lame's lambda."""
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
    gradient(x, y, z, depth, sd, cd, -hs, hs, -hd, hd, alpha, real, image, work)
    return s0, s1, lam


@njit(cache=True)
def okada_stress(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work, out):
    """``out[q, i, j]``: global stress at ``point`` for a unit global DD ``q`` of the
    rectangle (``center``, Okada rows ``okada`` = strike, up-dip, normal as
    :func:`halfspace_geometry` gives them, half sides ``hs``, ``hd``) under the free
    surface ``z = surface``: :func:`gradient` (``real``: the whole-space part, ``image``:
    the image and surface terms) through Hooke's law, turned from Okada's frame (``x`` =
    strike, ``y = z x strike``, ``z``) to the global one. ``work``: (5, 3, 3, 3) scratch."""
    s0, s1, lam = _gradient(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work)
    # Hooke's law into work[4], then about z to the global frame: R^T sigma R, R rows the
    # (x, y, z) axes of Okada's frame, each step through the other slot
    for k in range(3):
        tr = lam * (work[3, k, 0, 0] + work[3, k, 1, 1] + work[3, k, 2, 2])
        for i in range(3):
            for j in range(3):
                work[4, k, i, j] = shear_modulus * (work[3, k, i, j] + work[3, k, j, i])
            work[4, k, i, i] += tr
        for i in range(3):
            a0 = work[4, k, i, 0] * s0 - work[4, k, i, 1] * s1
            a1 = work[4, k, i, 0] * s1 + work[4, k, i, 1] * s0
            work[3, k, i, 0] = a0
            work[3, k, i, 1] = a1
            work[3, k, i, 2] = work[4, k, i, 2]
        for j in range(3):
            b0 = work[3, k, 0, j] * s0 - work[3, k, 1, j] * s1
            b1 = work[3, k, 0, j] * s1 + work[3, k, 1, j] * s0
            work[4, k, 0, j] = b0
            work[4, k, 1, j] = b1
            work[4, k, 2, j] = work[3, k, 2, j]
    for q in range(3):
        f0 = okada[0, q]
        f1 = okada[1, q]
        f2 = okada[2, q]
        for i in range(3):
            for j in range(3):
                out[q, i, j] = f0 * work[4, 0, i, j] + f1 * work[4, 1, i, j] + f2 * work[4, 2, i, j]


@njit(cache=True)
def okada_traction(point, normal, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work,
                   block):
    """``block[p, q] +=`` traction ``sigma . normal`` component ``p`` (global) at ``point``
    for a unit global DD ``q`` of the rectangle of :func:`okada_stress` (the same terms),
    through the traction in Okada's frame: the normal turned into it once, no stress
    tensor turned back."""
    s0, s1, lam = _gradient(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work)
    n0 = s0 * normal[0] + s1 * normal[1]
    n1 = -s1 * normal[0] + s0 * normal[1]
    n2 = normal[2]
    for k in range(3):
        tr = lam * (work[3, k, 0, 0] + work[3, k, 1, 1] + work[3, k, 2, 2])
        t0 = (shear_modulus * (2.0 * work[3, k, 0, 0] * n0 + (work[3, k, 0, 1] + work[3, k, 1, 0]) * n1
                               + (work[3, k, 0, 2] + work[3, k, 2, 0]) * n2) + tr * n0)
        t1 = (shear_modulus * ((work[3, k, 1, 0] + work[3, k, 0, 1]) * n0 + 2.0 * work[3, k, 1, 1] * n1
                               + (work[3, k, 1, 2] + work[3, k, 2, 1]) * n2) + tr * n1)
        t2 = (shear_modulus * ((work[3, k, 2, 0] + work[3, k, 0, 2]) * n0 + (work[3, k, 2, 1] + work[3, k, 1, 2]) * n1
                               + 2.0 * work[3, k, 2, 2] * n2) + tr * n2)
        work[4, k, 0, 0] = t0 * s0 - t1 * s1
        work[4, k, 0, 1] = t0 * s1 + t1 * s0
        work[4, k, 0, 2] = t2
    for q in range(3):
        f0 = okada[0, q]
        f1 = okada[1, q]
        f2 = okada[2, q]
        for p in range(3):
            block[p, q] += f0 * work[4, 0, 0, p] + f1 * work[4, 1, 0, p] + f2 * work[4, 2, 0, p]
