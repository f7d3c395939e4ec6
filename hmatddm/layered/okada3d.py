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
singular and near-miss handling); :func:`okada_traction` and :func:`okada_stress` with
``real=False`` add the rest (cost: benchmarks/RESULTS.md, issue 32, Okada 1992).

Only the displacement derivatives are computed (the stress needs no ``log`` and no
``atan``). Numerical safety, as the paper advises: ``xi``, ``eta`` and ``q`` smaller than
:data:`SNAP` times the rectangle's size are set to zero; ``R + xi`` and ``R + eta`` are
computed without cancellation; where one is zero (the point on the negative extension
of an edge) ``X11 = X32 = 0`` (``Y11 = Y32 = 0``), the limits whose differences over the
corners are finite; ``|cos(dip)| < COS_ZERO`` takes the vertical forms of part B.

Where the closed form does not apply: a rectangle with no horizontal edge (neither
``e1`` nor ``e2`` horizontal) has no strike in Okada's sense; such elements take Okada's
point source at Gauss points (:mod:`.okada_point3d`). Beyond the half-space it gives the top layer's
reflection in the free surface exactly (``real=False``; :mod:`.images3d` ``surface_form``);
a reflection in an interface between solids is no reweighting of these terms
(``_derive_closed_form3d.py``; vertical rectangles: :mod:`.vertical3d`).
"""
import math

import numpy as np
from numba import njit

from ..compiled import FAST
from .okada_stress3d import COS_ZERO, accumulate, add_gradient, dip_and_medium, global_stress, global_traction  # noqa: F401 (COS_ZERO: re-exported)

#: Coordinates ``xi``, ``eta``, ``q`` smaller than this fraction of the rectangle's size
#: are set to zero (Okada 1992 sets them below 1e-6 of its unit).
SNAP = 1e-9
#: ``|e_z|`` below this makes an element's side horizontal (as ``engine._has_horizontal_edge``).
HORIZONTAL = 1e-9

_INV_2PI = 1.0 / (2.0 * math.pi)


@njit(cache=True, inline="always")
def _geometry(xi, eta, q, sd, cd):
    """The finite source's notation at one corner (Okada 1992): ``R`` and its inverse
    powers, ``y~``, ``d~``, ``X11``, ``X32``, ``Y11``, ``Y32`` (zero on the negative
    extension of an edge, ``R + xi = 0`` or ``R + eta = 0``, computed without cancellation
    elsewhere), ``E``, ``F``, ``G``, ``H``; selects rather than branches."""
    xi2 = xi * xi
    q2 = q * q
    r2 = xi2 + eta * eta + q2
    r = math.sqrt(r2)
    ir = 1.0 / r
    ir2 = ir * ir
    ir3 = ir * ir2
    ir5 = ir3 * ir2
    y = eta * cd + q * sd  # y-tilde
    d = eta * sd - q * cd  # d-tilde
    rx = r + xi if xi >= 0.0 else (eta * eta + q2) / (r - xi)
    x11 = 1.0 / (r * rx) if rx != 0.0 else 0.0
    x32 = (r + rx) * x11 * x11 * ir
    re = r + eta if eta >= 0.0 else (xi2 + q2) / (r - eta)
    y11 = 1.0 / (r * re) if re != 0.0 else 0.0
    y32 = (r + re) * y11 * y11 * ir
    ey = sd * ir - y * q * ir3
    ez = cd * ir + d * q * ir3
    fy = d * ir3 + xi2 * y32 * sd
    fz = y * ir3 + xi2 * y32 * cd
    gy = 2.0 * x11 * sd - y * q * x32
    gz = 2.0 * x11 * cd + d * q * x32
    hy = d * q * x32 + xi * q * y32 * sd
    hz = y * q * x32 + xi * q * y32 * cd
    return (xi2, q2, r2, r, ir, ir2, ir3, ir5, y, d, x11, x32, y11, y32, ey, ez, fy, fz, gy, gz, hy, hz)


@njit(cache=True, inline="always")
def _part_a(xi, eta, q, sd, cd, a1, a2, g):
    """Part A (the infinite medium) of the derivatives at one corner (Okada 1992, finite
    source): 27 values ``A kij``, dislocation ``k`` (strike, dip, tensile), component ``i``
    in the fault's ``(x, y', z')``, derivative by ``x_j``, in that order; ``g`` from
    :func:`_geometry`, ``a1 = (1 - alpha) / 2``, ``a2 = alpha / 2``."""
    xi2, q2, r2, r, ir, ir2, ir3, ir5, y, d, x11, x32, y11, y32, ey, ez, fy, fz, gy, gz, hy, hz = g
    xy = xi * y11
    qy = q * y11
    A000 = -a1 * qy - a2 * xi2 * q * y32
    A010 = -a2 * xi * q * ir3
    A020 = a1 * xy + a2 * xi * q2 * y32
    A001 = a1 * xy * sd + a2 * xi * fy + 0.5 * d * x11
    A011 = a2 * ey
    A021 = a1 * (cd * ir + qy * sd) - a2 * q * fy
    A002 = a1 * xy * cd + a2 * xi * fz + 0.5 * y * x11
    A012 = a2 * ez
    A022 = -a1 * (sd * ir - qy * cd) - a2 * q * fz
    A100 = -a2 * xi * q * ir3
    A110 = -0.5 * qy - a2 * eta * q * ir3
    A120 = a1 * ir + a2 * q2 * ir3
    A101 = a2 * ey
    A111 = a1 * d * x11 + 0.5 * xy * sd + a2 * eta * gy
    A121 = a1 * y * x11 - a2 * q * gy
    A102 = a2 * ez
    A112 = a1 * y * x11 + 0.5 * xy * cd + a2 * eta * gz
    A122 = -a1 * d * x11 - a2 * q * gz
    A200 = -a1 * xy + a2 * xi * q2 * y32
    A210 = -a1 * ir + a2 * q2 * ir3
    A220 = -a1 * qy - a2 * q * q2 * y32
    A201 = -a1 * (cd * ir + qy * sd) - a2 * q * fy
    A211 = -a1 * y * x11 - a2 * q * gy
    A221 = a1 * (d * x11 + xy * sd) + a2 * q * hy
    A202 = a1 * (sd * ir - qy * cd) - a2 * q * fz
    A212 = a1 * d * x11 - a2 * q * gz
    A222 = a1 * (y * x11 + xy * cd) + a2 * q * hz
    return (A000, A001, A002, A010, A011, A012, A020, A021, A022, A100, A101, A102, A110, A111, A112, A120, A121,
            A122, A200, A201, A202, A210, A211, A212, A220, A221, A222)


@njit(cache=True)
def _real_corners(xs, p, q, aw1, aw2, snap, sd, cd, alpha, s):
    """Add part A of the real source (the whole space) over the four corners to
    ``s[3, k, i, j]`` (``du_i / dx_j`` in Okada's frame, dislocation ``k``): the fault's
    components turned to Okada's frame, and the z-derivatives' sign of ``d = depth + z``
    (Okada 1992, finite source)."""
    for jj in range(2):
        for kk in range(2):
            xi = xs[jj]
            eta = p - (aw1 if kk == 0 else aw2)
            xi = 0.0 if abs(xi) < snap else xi
            eta = 0.0 if abs(eta) < snap else eta
            if xi * xi + eta * eta + q * q == 0.0:
                continue
            sign = 1.0 if jj == kk else -1.0
            a = _part_a(xi, eta, q, sd, cd, 0.5 * (1.0 - alpha), 0.5 * alpha, _geometry(xi, eta, q, sd, cd))
            for k in range(3):
                for j in range(3):
                    u = sign if j < 2 else -sign
                    a0 = a[9 * k + j]
                    a1 = a[9 * k + 3 + j]
                    a2 = a[9 * k + 6 + j]
                    s[3, k, 0, j] -= u * a0
                    s[3, k, 1, j] += u * (a2 * sd - a1 * cd)
                    s[3, k, 2, j] -= u * (a1 * sd + a2 * cd)


@njit(cache=True, inline="always")
def _turned(cd, sd, ab0, ab1, ab2, zc0, zc1, zc2):
    """Image source at one corner: ``A + B`` (``ab``) and ``z C`` (``zc``, with C's own
    displacement in the z-derivatives: d(z C)/dz = C + z dC/dz) turned from the fault's
    ``(x, y', z')`` to Okada's frame (``z C`` flips in the vertical turn): three of the 27
    values of :func:`.okada_stress3d.accumulate`'s order."""
    return (ab0 + zc0, (ab1 + zc1) * cd - (ab2 + zc2) * sd, (ab1 - zc1) * sd + (ab2 - zc2) * cd)


@njit(cache=True, fastmath=FAST, error_model="numpy")
def _image_corners(q, z, sd, cd, alpha, c4):
    """Parts A + B + z C of the image source (Okada 1992, finite source) summed over the
    four corners ``(c4[27, c], c4[28, c])`` with Chinnery's signs ``c4[29, c]`` (0:
    skipped): 27 values ``9 k + 3 j + i`` (``du_i / dx_j``, Okada's frame, dislocation
    ``k``), times ``2 pi``. One straight loop without branches or calls, its sum carried in
    registers (:func:`.okada_stress3d.accumulate`) and divisions without Python's zero
    check (numpy's error model), so that LLVM vectorises it over the corners (it did not
    while the corners were stored to an array and divisions checked: scalar
    ``divsd``/``sqrtsd`` only)."""
    a1 = 0.5 * (1.0 - alpha)
    a2 = 0.5 * alpha
    a3 = (1.0 - alpha) / alpha
    a4 = 1.0 - alpha
    a5 = alpha
    tilted = cd != 0.0
    icd = 1.0 / cd if tilted else 0.0
    sdcd = sd * cd
    sdsd = sd * sd
    cdcd = cd * cd
    acc = (0.0,) * 27
    for corner in range(4):
        xi = c4[27, corner]
        eta = c4[28, corner]
        sign = c4[29, corner]
        g = _geometry(xi, eta, q, sd, cd)
        xi2, q2, r2, r, ir, ir2, ir3, ir5, y, d, x11, x32, y11, y32, ey, ez, fy, fz, gy, gz, hy, hz = g
        a = _part_a(xi, eta, q, sd, cd, a1, a2, g)
        xy = xi * y11
        qy = q * y11
        # part B (surface deformation terms)
        rd = r + d
        ird = 1.0 / rd
        d11 = ir * ird
        j2 = xi * y * ird * d11
        j5 = -(d + y * y * ird) * d11
        # cos(dip) = 0 takes the vertical forms
        ird2 = ird * ird
        k1 = xi * (d11 - y11 * sd) * icd if tilted else xi * q * ird * d11
        k3 = (q * y11 - y * d11) * icd if tilted else sd * ird * (xi2 * d11 - 1.0)
        j3 = (k1 - j2 * sd) * icd if tilted else -xi * ird2 * (q2 * d11 - 0.5)
        j6 = (k3 - j5 * sd) * icd if tilted else -y * ird2 * (xi2 * d11 - 0.5)
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
        W221 = (-a4 * (xi * ppy * cd - x11 + y * y * x32)
                + a5 * (c * ((d + 2.0 * q * cd) * x32 - y * eta * q * x53) + xi * qqy))
        W202 = -eta * ir3 + y0 * cdcd - a5 * (z * ir3 * sd - c * y * qr - y0 * sdsd + q * z0 * cd)
        W212 = a4 * 2.0 * xi * ppz * sd - x11 + d * d * x32 - a5 * c * ((d - 2.0 * q * cd) * x32 - d * q2 * x53)
        W222 = a4 * (xi * ppz * cd + y * d * x32) + a5 * (c * ((y - 2.0 * q * sd) * x32 + d * eta * q * x53) + xi * qqz)
        U00 = a4 * xy * cd - a5 * xi * q * z32
        U01 = a4 * (cd * ir + 2.0 * qy * sd) - a5 * c * q * ir3
        U02 = a4 * qy * cd - a5 * (c * eta * ir3 - z * y11 + xi2 * z32)
        U10 = a4 * cd * ir - qy * sd - a5 * c * q * ir3
        U11 = a4 * y * x11 - a5 * c * eta * q * x32
        U12 = -d * x11 - xy * sd - a5 * c * (x11 - q2 * x32)
        U20 = -a4 * (sd * ir + qy * cd) - a5 * (z * y11 - q2 * z32)
        U21 = a4 * 2.0 * xy * sd + d * x11 - a5 * c * (x11 - q2 * x32)
        U22 = a4 * (y * x11 + xy * cd) + a5 * q * (c * eta * x32 + xi * z32)
        v0 = _turned(cd, sd, a[0] + B000, a[3] + B010, a[6] + B020, z * W000, z * W010, z * W020)
        v1 = _turned(cd, sd, a[1] + B001, a[4] + B011, a[7] + B021, z * W001, z * W011, z * W021)
        v2 = _turned(cd, sd, a[2] + B002, a[5] + B012, a[8] + B022, z * W002 + U00, z * W012 + U01, z * W022 + U02)
        v3 = _turned(cd, sd, a[9] + B100, a[12] + B110, a[15] + B120, z * W100, z * W110, z * W120)
        v4 = _turned(cd, sd, a[10] + B101, a[13] + B111, a[16] + B121, z * W101, z * W111, z * W121)
        v5 = _turned(cd, sd, a[11] + B102, a[14] + B112, a[17] + B122, z * W102 + U10, z * W112 + U11, z * W122 + U12)
        v6 = _turned(cd, sd, a[18] + B200, a[21] + B210, a[24] + B220, z * W200, z * W210, z * W220)
        v7 = _turned(cd, sd, a[19] + B201, a[22] + B211, a[25] + B221, z * W201, z * W211, z * W221)
        v8 = _turned(cd, sd, a[20] + B202, a[23] + B212, a[26] + B222, z * W202 + U20, z * W212 + U21, z * W222 + U22)
        acc = accumulate(acc, sign, v0 + v1 + v2 + v3 + v4 + v5 + v6 + v7 + v8)
    return acc


@njit(cache=True)
def gradient(x, y, z, depth, sd, cd, al1, al2, aw1, aw2, alpha, real, image, s, c4):
    """``s[3, k, i, j] = du_i / dx_j`` at ``(x, y, z)`` (Okada's frame, ``z <= 0``) for a
    unit dislocation ``k`` (strike, dip, tensile) on the rectangle ``al1 <= xi <= al2``,
    ``aw1 <= eta <= aw2`` whose reference point is at depth ``depth``: the real source's
    part A (the whole space, ``d = depth + z``) when ``real``, plus the image source's
    parts A + B + z C (``d = depth - z``) when ``image`` (Okada 1992, finite source;
    Chinnery's sum over the corners ``f(al1, aw1) - f(al1, aw2) - f(al2, aw1) + f(al2,
    aw2)`` in ``(x - al, p - aw)``). ``s``: (5, 3, 3, 3), ``c4``: (30, 4) scratch."""
    for k in range(3):
        for i in range(3):
            for j in range(3):
                s[3, k, i, j] = 0.0
    snap = SNAP * ((al2 - al1) + (aw2 - aw1))
    xs = (x - al1, x - al2)
    if real:
        d = depth + z
        q = y * sd - d * cd
        _real_corners(xs, y * cd + d * sd, 0.0 if abs(q) < snap else q, aw1, aw2, snap, sd, cd, alpha, s)
    if image:
        d = depth - z
        p = y * cd + d * sd
        q = y * sd - d * cd
        q = 0.0 if abs(q) < snap else q
        for jj in range(2):
            for kk in range(2):
                c = 2 * jj + kk
                xi = xs[jj]
                eta = p - (aw1 if kk == 0 else aw2)
                xi = 0.0 if abs(xi) < snap else xi
                eta = 0.0 if abs(eta) < snap else eta
                sign = 1.0 if jj == kk else -1.0
                if xi * xi + eta * eta + q * q == 0.0:  # the point on a corner: skipped
                    xi = 1.0
                    sign = 0.0
                c4[27, c] = xi
                c4[28, c] = eta
                c4[29, c] = sign
        add_gradient(_image_corners(q, z, sd, cd, alpha, c4), s[3])
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
def _gradient(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work, c4):
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
    sd, cd, lam, alpha = dip_and_medium(s0, s1, okada, shear_modulus, poisson_ratio)
    gradient(x, y, z, depth, sd, cd, -hs, hs, -hd, hd, alpha, real, image, work, c4)
    return s0, s1, lam


@njit(cache=True)
def okada_stress(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work, c4,
                 out):
    """``out[q, i, j]``: global stress at ``point`` for a unit global DD ``q`` of the
    rectangle (``center``, Okada rows ``okada`` = strike, up-dip, normal as
    :func:`halfspace_geometry` gives them, half sides ``hs``, ``hd``) under the free
    surface ``z = surface``: :func:`gradient` (``real``: the whole-space part, ``image``:
    the image and surface terms) through Hooke's law, turned from Okada's frame (``x`` =
    strike, ``y = z x strike``, ``z``) to the global one. ``work``: (5, 3, 3, 3), ``c4``: (30, 4) scratch."""
    s0, s1, lam = _gradient(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work, c4)
    global_stress(work, s0, s1, lam, shear_modulus, okada, out)


@njit(cache=True)
def okada_traction(point, normal, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work,
                   c4, block):
    """``block[p, q] +=`` traction ``sigma . normal`` component ``p`` (global) at ``point``
    for a unit global DD ``q`` of the rectangle of :func:`okada_stress` (the same terms),
    through the traction in Okada's frame: the normal turned into it once, no stress
    tensor turned back."""
    s0, s1, lam = _gradient(point, center, okada, hs, hd, surface, shear_modulus, poisson_ratio, real, image, work, c4)
    global_traction(work, s0, s1, lam, shear_modulus, okada, normal, block)
