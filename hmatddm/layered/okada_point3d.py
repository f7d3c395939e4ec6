"""The image and surface terms of a point displacement discontinuity in an elastic
half-space in closed form, and their Gauss sum over a rectangle of any orientation
(issue 32): Okada's (1992) internal deformation of a *point* source, Y. Okada, "Internal
deformation due to shear and tensile faults in a half-space", BSSA 82(2), 1018-1040,
written here from the paper's point-source expressions (its parts A, B and C of the
displacement derivatives for the strike, dip and tensile potencies, with the notation
``p, q, s, t, A3, A5, A7, B5, B7, C5, C7, D7, U, V, W`` of the point source, and the
``d/dz`` of ``z C`` carried as ``C + z dC/dz``).

Why: a rectangle with no horizontal side has no strike in Okada's sense, so the finite
source of :mod:`.okada3d` does not apply to it; its image terms used the general image
method's quadrature (:mod:`.images3d`), about 3 us per Gauss point, because the Hansen
potentials of a general layered medium are evaluated to high derivative order. A point
source has a strike whatever the rectangle's sides: the horizontal direction of its plane.
Its image terms here cost a few hundred floating-point operations per Gauss point, and the
quadrature keeps the rule of :func:`.rectangle_quadrature._image_order` (sub-squares near
the rectangle's mirror, fewer points far from it, the entry error bound), so the entries
agree with the image method's quadrature to round-off at the same rule (tests); its points
being cheap, the point form takes up to 8 per side (:func:`point_rule`), which brings the
entries next to the free surface within 1e-11 of the converged quadrature.

Okada's frame, as in :mod:`.okada3d`: ``z`` up with the free surface ``z = 0``, ``x``
along the strike (the horizontal direction of the plane), the up-dip direction ``(0, cos
dip, sin dip)``, the normal ``(0, -sin dip, cos dip)``; the potencies (strike, up-dip,
tensile) are the DD in that frame times the area (docs/conventions.md §1). The real
source stays the uniform-rock kernel of the rectangle (:mod:`hmatddm.kernels.rectangle3d`).
"""
import math

import numpy as np
from numba import njit

from ..compiled import FAST
from ..kernels.rectangle3d import distance_to_rectangle
from .okada_stress3d import (accumulate_strain, accumulate_traction, add_traction, dip_and_medium, global_stress,
                             set_strain)
from .rectangle_quadrature import IMAGE_BOUND, nearest_singularity, square_rule

_INV_2PI = 1.0 / (2.0 * math.pi)

#: Gauss points per side of the point form's rule (the image method's is 4: its points cost
#: ~30x more, :mod:`.images3d`)
POINT_GAUSS_POINTS = 8
#: Next to the mirror, each (sub-)square of the point form is at least this many of its half
#: sides from it: 8 x 8 points there leave 1.5e-11 of the largest entry at 2.6 half sides
#: (benchmarks/RESULTS.md, issue 32)
POINT_NEAR_RATIO = 2.5


@njit(cache=True, inline="always")
def _point_image(x, y, z, depth, sd, cd, alpha):
    """The 27 values ``du_i / dx_j`` at ``(x, y, z)`` (Okada's frame, ``z <= 0``) of the image
    source's parts A + B + z C (Okada 1992, point source, ``d = depth - z``) for a unit
    potency ``k`` (strike, dip, tensile) at depth ``depth``, times ``2 pi``: ``9 k + m``,
    ``m = 3 j + i`` in Okada's order (:func:`_combined`, :func:`.okada_stress3d.accumulate`).
    ``d > 0`` (the source below the surface) keeps ``R + d > 0``. Returned, not stored, so
    that the Gauss sums of :func:`setup_image_stress` and :func:`setup_image_traction` stay
    in registers and are vectorised over their points."""
    alp1 = 0.5 * (1.0 - alpha)
    alp2 = 0.5 * alpha
    alp3 = (1.0 - alpha) / alpha
    alp4 = 1.0 - alpha
    alp5 = alpha
    sdsd = sd * sd
    sdcd = sd * cd
    s2d = 2.0 * sdcd
    c2d = cd * cd - sdsd
    d = depth - z
    c = d + z  # = depth
    p = y * cd + d * sd
    q = y * sd - d * cd
    ss = p * sd + q * cd
    t = p * cd - q * sd
    xy = x * y
    x2 = x * x
    y2 = y * y
    d2 = d * d
    r2 = x2 + y2 + d2
    r = math.sqrt(r2)
    ir2 = 1.0 / r2
    ir3 = 1.0 / (r * r2)
    ir5 = ir3 * ir2
    ir7 = ir5 * ir2
    a3 = 1.0 - 3.0 * x2 * ir2
    a5 = 1.0 - 5.0 * x2 * ir2
    a7 = 1.0 - 7.0 * x2 * ir2
    b5 = 1.0 - 5.0 * y2 * ir2
    b7 = 1.0 - 7.0 * y2 * ir2
    c5 = 1.0 - 5.0 * d2 * ir2
    c7 = 1.0 - 7.0 * d2 * ir2
    d7 = 2.0 - 7.0 * q * q * ir2
    qr = 3.0 * q * ir5
    qrx = 5.0 * qr * x * ir2
    qr5 = 5.0 * q * ir2
    qr7 = 7.0 * q * ir2
    dr5 = 5.0 * d * ir2
    uy = sd - 5.0 * y * q * ir2
    uz = cd + 5.0 * d * q * ir2
    vy = ss - 5.0 * y * p * q * ir2
    vz = t + 5.0 * d * p * q * ir2
    wy = uy + sd
    wz = uz + cd
    x3r5 = 3.0 * x * ir5
    # part B's functions of R + d
    rd = r + d
    d12 = 1.0 / (r * rd * rd)
    d32 = d12 * (2.0 * r + d) * ir2
    d33 = d12 * (3.0 * r + d) * ir2 / rd
    d53 = d12 * (8.0 * r2 + 9.0 * r * d + 3.0 * d2) * ir2 * ir2 / rd
    d54 = d12 * (5.0 * r2 + 4.0 * r * d + d2) * ir3 * d12
    fj1 = -3.0 * xy * (d33 - x2 * d54)
    fj2 = ir3 - 3.0 * d12 + 3.0 * x2 * y2 * d54
    fj3 = a3 * ir3 - fj2
    fj4 = -3.0 * xy * ir5 - fj1
    fk1 = -y * (d32 - x2 * d53)
    fk2 = -x * (d32 - y2 * d53)
    fk3 = -3.0 * x * d * ir5 - fk2

    # strike: part A (derivatives, order u_x,x u_y,x u_z,x u_x,y ... u_z,z), B, C
    sa0 = x * qr * (-alp1 + alp2 * (1.0 + a5))
    sa1 = alp1 * a3 * ir3 * sd + alp2 * y * qr * a5
    sa2 = -alp1 * a3 * ir3 * cd + alp2 * d * qr * a5
    sa3 = alp1 * (sd * ir3 - y * qr) + alp2 * 3.0 * x2 * ir5 * uy
    sa4 = x3r5 * (-alp1 * y * sd + alp2 * (y * uy + q))
    sa5 = x3r5 * (alp1 * y * cd + alp2 * d * uy)
    sa6 = alp1 * (cd * ir3 + d * qr) + alp2 * 3.0 * x2 * ir5 * uz
    sa7 = x3r5 * (alp1 * d * sd + alp2 * y * uz)
    sa8 = x3r5 * (-alp1 * d * cd + alp2 * (d * uz - q))
    sb0 = -x * qr * (1.0 + a5) - alp3 * fj1 * sd
    sb1 = -y * qr * a5 - alp3 * fj2 * sd
    sb2 = -c * qr * a5 - alp3 * fk1 * sd
    sb3 = -3.0 * x2 * ir5 * uy - alp3 * fj2 * sd
    sb4 = -3.0 * xy * ir5 * uy - x * qr - alp3 * fj4 * sd
    sb5 = -3.0 * c * x * ir5 * uy - alp3 * fk2 * sd
    sb6 = -3.0 * x2 * ir5 * uz + alp3 * fk1 * sd
    sb7 = -3.0 * xy * ir5 * uz + alp3 * fk2 * sd
    sb8 = x3r5 * (-c * uz + alp3 * y * sd)
    su0 = -alp4 * a3 * ir3 * cd + alp5 * c * qr * a5
    su1 = x3r5 * (alp4 * y * cd + alp5 * c * (sd - y * qr5))
    su2 = x3r5 * (-alp4 * y * sd + alp5 * c * (cd + d * qr5))
    sc0 = alp4 * x3r5 * (2.0 + a5) * cd - alp5 * c * qrx * (2.0 + a7)
    sc1 = 3.0 * ir5 * (alp4 * y * a5 * cd + alp5 * c * (a5 * sd - y * qr5 * a7))
    sc2 = 3.0 * ir5 * (-alp4 * y * a5 * sd + alp5 * c * (a5 * cd + d * qr5 * a7))
    sc3 = sc1
    sc4 = x3r5 * (alp4 * b5 * cd - alp5 * 5.0 * c * ir2 * (2.0 * y * sd + q * b7))
    sc5 = x3r5 * (-alp4 * b5 * sd + alp5 * 5.0 * c * ir2 * (d * b7 * sd - y * c7 * cd))
    sc6 = 3.0 * ir5 * (-alp4 * d * a5 * cd + alp5 * c * (a5 * cd + d * qr5 * a7))
    sc7 = 15.0 * x * ir7 * (alp4 * y * d * cd + alp5 * c * (d * b7 * sd - y * c7 * cd))
    sc8 = 15.0 * x * ir7 * (-alp4 * y * d * sd + alp5 * c * (2.0 * d * cd - q * c7))
    strike = _combined(z, sa0 + sb0, sa1 + sb1, sa2 + sb2, sa3 + sb3, sa4 + sb4, sa5 + sb5, sa6 + sb6,
                      sa7 + sb7, sa8 + sb8, sc0, sc1, sc2, sc3, sc4, sc5, sc6, sc7, sc8, su0, su1, su2)

    # dip
    da0 = alp2 * p * qr * a5
    da1 = -alp1 * 3.0 * x * ss * ir5 - alp2 * y * p * qrx
    da2 = alp1 * 3.0 * x * t * ir5 - alp2 * d * p * qrx
    da3 = alp2 * x3r5 * vy
    da4 = alp1 * (s2d * ir3 - 3.0 * y * ss * ir5) + alp2 * (3.0 * y * ir5 * vy + p * qr)
    da5 = -alp1 * (c2d * ir3 - 3.0 * y * t * ir5) + alp2 * 3.0 * d * ir5 * vy
    da6 = alp2 * x3r5 * vz
    da7 = alp1 * (c2d * ir3 + 3.0 * d * ss * ir5) + alp2 * 3.0 * y * ir5 * vz
    da8 = alp1 * (s2d * ir3 - 3.0 * d * t * ir5) + alp2 * (3.0 * d * ir5 * vz - p * qr)
    db0 = -p * qr * a5 + alp3 * fj3 * sdcd
    db1 = y * p * qrx + alp3 * fj1 * sdcd
    db2 = c * p * qrx + alp3 * fk3 * sdcd
    db3 = -x3r5 * vy + alp3 * fj1 * sdcd
    db4 = -3.0 * y * ir5 * vy - p * qr + alp3 * fj2 * sdcd
    db5 = -3.0 * c * ir5 * vy + alp3 * fk1 * sdcd
    db6 = -x3r5 * vz - alp3 * fk3 * sdcd
    db7 = -3.0 * y * ir5 * vz - alp3 * fk1 * sdcd
    db8 = -3.0 * c * ir5 * vz + alp3 * a3 * ir3 * sdcd
    du0 = alp4 * 3.0 * x * t * ir5 - alp5 * c * p * qrx
    du1 = -alp4 * ir3 * (c2d - 3.0 * y * t * ir2) + alp5 * 3.0 * c * ir5 * (ss - y * p * qr5)
    du2 = -alp4 * a3 * ir3 * sdcd + alp5 * 3.0 * c * ir5 * (t + d * p * qr5)
    dc0 = alp4 * 3.0 * t * ir5 * a5 - alp5 * 5.0 * c * p * qr * ir2 * a7
    dc1 = x3r5 * (alp4 * (c2d - 5.0 * y * t * ir2) - alp5 * 5.0 * c * ir2 * (ss - y * p * qr7))
    dc2 = x3r5 * (alp4 * (2.0 + a5) * sdcd - alp5 * 5.0 * c * ir2 * (t + d * p * qr7))
    dc3 = dc1
    dc4 = 3.0 * ir5 * (alp4 * (2.0 * y * c2d + t * b5) + alp5 * c * (s2d - 10.0 * y * ss * ir2 - p * qr5 * b7))
    dc5 = 3.0 * ir5 * (alp4 * y * a5 * sdcd - alp5 * c * ((3.0 + a5) * c2d + y * p * dr5 * qr7))
    dc6 = x3r5 * (-alp4 * (s2d - t * dr5) - alp5 * 5.0 * c * ir2 * (t + d * p * qr7))
    dc7 = 3.0 * ir5 * (-alp4 * (d * b5 * c2d + y * c5 * s2d) - alp5 * c * ((3.0 + a5) * c2d + y * p * dr5 * qr7))
    dc8 = 3.0 * ir5 * (-alp4 * d * a5 * sdcd - alp5 * c * (s2d - 10.0 * d * t * ir2 + p * qr5 * c7))
    dip = _combined(z, da0 + db0, da1 + db1, da2 + db2, da3 + db3, da4 + db4, da5 + db5, da6 + db6,
                   da7 + db7, da8 + db8, dc0, dc1, dc2, dc3, dc4, dc5, dc6, dc7, dc8, du0, du1, du2)

    # tensile
    ta0 = alp1 * a3 * ir3 - alp2 * q * qr * a5
    ta1 = -alp1 * 3.0 * x * t * ir5 + alp2 * y * q * qrx
    ta2 = -alp1 * 3.0 * x * ss * ir5 + alp2 * d * q * qrx
    ta3 = -alp1 * 3.0 * xy * ir5 - alp2 * x * qr * wy
    ta4 = alp1 * (c2d * ir3 - 3.0 * y * t * ir5) - alp2 * (y * wy + q) * qr
    ta5 = alp1 * (s2d * ir3 - 3.0 * y * ss * ir5) - alp2 * d * qr * wy
    ta6 = alp1 * 3.0 * x * d * ir5 - alp2 * x * qr * wz
    ta7 = -alp1 * (s2d * ir3 - 3.0 * d * t * ir5) - alp2 * y * qr * wz
    ta8 = alp1 * (c2d * ir3 + 3.0 * d * ss * ir5) - alp2 * (d * wz - q) * qr
    tb0 = q * qr * a5 - alp3 * fj3 * sdsd
    tb1 = -y * q * qrx - alp3 * fj1 * sdsd
    tb2 = -c * q * qrx - alp3 * fk3 * sdsd
    tb3 = x * qr * wy - alp3 * fj1 * sdsd
    tb4 = qr * (y * wy + q) - alp3 * fj2 * sdsd
    tb5 = c * qr * wy - alp3 * fk1 * sdsd
    tb6 = x * qr * wz + alp3 * fk3 * sdsd
    tb7 = y * qr * wz + alp3 * fk1 * sdsd
    tb8 = c * qr * wz - alp3 * a3 * ir3 * sdsd
    tu0 = x3r5 * (-alp4 * ss + alp5 * (c * q * qr5 - z))
    tu1 = alp4 * ir3 * (s2d - 3.0 * y * ss * ir2) + alp5 * 3.0 * ir5 * (c * (t - y + y * q * qr5) - y * z)
    tu2 = -alp4 * ir3 * (1.0 - a3 * sdsd) - alp5 * 3.0 * ir5 * (c * (ss - d + d * q * qr5) - d * z)
    tc0 = -alp4 * 3.0 * ss * ir5 * a5 + alp5 * (c * qr * qr5 * a7 - 3.0 * z * ir5 * a5)
    tc1 = x3r5 * (-alp4 * (s2d - 5.0 * y * ss * ir2) - alp5 * 5.0 * ir2 * (c * (t - y + y * q * qr7) - y * z))
    tc2 = x3r5 * (alp4 * (1.0 - (2.0 + a5) * sdsd) + alp5 * 5.0 * ir2 * (c * (ss - d + d * q * qr7) - d * z))
    tc3 = tc1
    tc4 = 3.0 * ir5 * (-alp4 * (2.0 * y * s2d + ss * b5)
                       - alp5 * (c * (2.0 * sdsd + 10.0 * y * (t - y) * ir2 - q * qr5 * b7) + z * b5))
    tc5 = 3.0 * ir5 * (alp4 * y * (1.0 - a5 * sdsd) + alp5 * (c * (3.0 + a5) * s2d - y * dr5 * (c * d7 + z)))
    tc6 = x3r5 * (-alp4 * (c2d + ss * dr5) + alp5 * (5.0 * c * ir2 * (ss - d + d * q * qr7) - 1.0 - z * dr5))
    tc7 = 3.0 * ir5 * (alp4 * (d * b5 * s2d - y * c5 * c2d)
                       + alp5 * (c * ((3.0 + a5) * s2d - y * dr5 * d7) - y * (1.0 + z * dr5)))
    tc8 = 3.0 * ir5 * (-alp4 * d * (1.0 - a5 * sdsd)
                       - alp5 * (c * (c2d + 10.0 * d * (ss - d) * ir2 - q * qr5 * c7) + z * (1.0 + c5)))
    tensile = _combined(z, ta0 + tb0, ta1 + tb1, ta2 + tb2, ta3 + tb3, ta4 + tb4, ta5 + tb5, ta6 + tb6,
                       ta7 + tb7, ta8 + tb8, tc0, tc1, tc2, tc3, tc4, tc5, tc6, tc7, tc8, tu0, tu1, tu2)
    return strike + dip + tensile


@njit(cache=True, inline="always")
def _combined(z, ab0, ab1, ab2, ab3, ab4, ab5, ab6, ab7, ab8, c0, c1, c2, c3, c4, c5, c6, c7, c8, u0, u1, u2):
    """``(A + B + z C)_{i,j}``, ``m = 3 j + i`` in Okada's order (``u_x,x u_y,x u_z,x u_x,y
    ... u_z,z``); the ``z`` derivatives add ``C``'s displacement (``d(z C)/dz = C + z
    dC/dz``)."""
    return (ab0 + z * c0, ab1 + z * c1, ab2 + z * c2, ab3 + z * c3, ab4 + z * c4, ab5 + z * c5,
            ab6 + z * c6 + u0, ab7 + z * c7 + u1, ab8 + z * c8 + u2)


@njit(cache=True)
def point_rule(dmin, a, b, max_sub, far_tol, entry_tol):
    """``(n_gauss, n_sub)``: Gauss points per side and equal sub-squares per side of the point
    form's rule for a rectangle of half sides ``a``, ``b`` whose mirror is ``dmin`` from the
    receiver: on one square (``dmin`` at least :data:`POINT_NEAR_RATIO` half sides) the image
    method's rules (:func:`.rectangle_quadrature.far_order`, and
    :func:`.rectangle_quadrature.entry_order` with ``entry_tol > 0``) up to
    :data:`POINT_GAUSS_POINTS`; nearer, :data:`POINT_GAUSS_POINTS` on the fewest sub-squares
    (a power of two, at most ``max_sub``) each that far from the mirror. The image method's
    rule (4 points on sub-squares at most half as large as ``dmin``) leaves up to 4e-8 of the
    largest entry next to the free surface (issue 32 asks 1e-8); this one, 1e-11. The two
    rules' bounds ``40 n ratio^(-2n)`` (times the entry's size for the second) in one pass
    over the same powers: the smallest ``n`` either allows, as the smaller of the two
    orders, with two divisions and two calls fewer (not inlined: inlined into the pair loop
    it cost 15 s of its cold compile for ~1% of a pair, benchmarks/RESULTS.md, issue 32)."""
    half = max(a, b)
    if dmin >= POINT_NEAR_RATIO * half:
        ratio = dmin / half
        step = 1.0 / (ratio * ratio)
        size = IMAGE_BOUND * 4.0 * a * b / (dmin * dmin * dmin)
        power = step
        for n in range(1, POINT_GAUSS_POINTS):
            bound = 40.0 * n * power
            if bound <= far_tol or (entry_tol > 0.0 and bound * size <= entry_tol):
                return n, 1
            power *= step
        return POINT_GAUSS_POINTS, 1
    n_sub = 2
    while n_sub < max_sub and dmin * n_sub < POINT_NEAR_RATIO * half:
        n_sub *= 2
    return POINT_GAUSS_POINTS, n_sub


def point_frames(normals):
    """Okada's rows ``(strike, up-dip, normal)`` of planes from their unit ``normals`` (N, 3)
    alone: ``(rows (N, 3, 3), has_strike (N,) bool)``, the strike ``e_z x n`` (horizontal),
    the up-dip ``n x strike`` (``z >= 0``); a horizontal plane has no strike (such a rectangle
    has horizontal sides, :mod:`.okada3d`): its rows are zeros."""
    n = np.asarray(normals, dtype=float).reshape(-1, 3)
    strike = np.stack([-n[:, 1], n[:, 0], np.zeros(len(n))], axis=1)
    size = np.linalg.norm(strike, axis=1)
    has_strike = size > 1e-12
    strike[has_strike] /= size[has_strike, None]
    rows = np.stack([strike, np.cross(n, strike), n], axis=1)
    rows[~has_strike] = 0.0
    return rows, has_strike


def point_frame(normal):
    """:func:`point_frames` of one plane: its rows, or None for a horizontal plane."""
    rows, has_strike = point_frames(normal)
    return rows[0] if has_strike[0] else None


#: Length of a point-form source's setup (:func:`point_setup`)
POINT_SETUP = 14


@njit(cache=True, inline="always")
def point_setup(center, frame, a, b, okada, surface, shear_modulus, poisson_ratio, setup):
    """``setup[:14]``: what the receivers of a point-form source share: the strike ``(s0,
    s1)``, ``(sin dip, cos dip, lambda, alpha)`` (:func:`.okada_stress3d.dip_and_medium`),
    the Jacobian ``a b / (2 pi)``, the rectangle's sides ``e1``, ``e2`` turned into Okada's
    frame ``(ax, ay, az, bx, by, bz)`` and the depth of its centre under the surface. Made
    once per source (:func:`.images3d.source_state`): per pair, with its square root and
    three divisions, it cost ~7% of a half-space entry (benchmarks/RESULTS.md, issue 32)."""
    s0 = okada[0, 0]
    s1 = okada[0, 1]
    sd, cd, lam, alpha = dip_and_medium(s0, s1, okada, shear_modulus, poisson_ratio)
    setup[0] = s0
    setup[1] = s1
    setup[2] = sd
    setup[3] = cd
    setup[4] = lam
    setup[5] = alpha
    setup[6] = a * b * _INV_2PI
    setup[7] = s0 * frame[0, 0] + s1 * frame[0, 1]
    setup[8] = -s1 * frame[0, 0] + s0 * frame[0, 1]
    setup[9] = frame[0, 2]
    setup[10] = s0 * frame[1, 0] + s1 * frame[1, 1]
    setup[11] = -s1 * frame[1, 0] + s0 * frame[1, 1]
    setup[12] = frame[1, 2]
    setup[13] = surface - center[2]


@njit(cache=True, inline="always")
def _receiver(point, center, setup, surface):
    """The receiver from the rectangle's centre in Okada's frame, ``(x, y)`` horizontal, and
    its height ``z`` over the surface (each Gauss point moves the source: :func:`_image_at`)."""
    rx = point[0] - center[0]
    ry = point[1] - center[1]
    return setup[0] * rx + setup[1] * ry, -setup[1] * rx + setup[0] * ry, point[2] - surface


@njit(cache=True, inline="always")
def _image_at(g, x0, y0, z, a, b, setup, xi, eta):
    """:func:`_point_image` of the Gauss point ``(xi[g] a, eta[g] b)`` of the source whose
    :func:`point_setup` is ``setup``, at the receiver ``(x0, y0, z)`` of :func:`_receiver`."""
    ua = xi[g] * a
    ub = eta[g] * b
    return _point_image(x0 - ua * setup[7] - ub * setup[10], y0 - ua * setup[8] - ub * setup[11], z,
                        setup[13] - ua * setup[9] - ub * setup[12], setup[2], setup[3], setup[5])


@njit(cache=True, fastmath=FAST, error_model="numpy")
def setup_image_stress(point, center, a, b, setup, okada, surface, shear_modulus, xi, eta, wt, work, out):
    """:func:`point_image_stress` of the source whose :func:`point_setup` is ``setup``: the
    Gauss sum of the strains (:func:`.okada_stress3d.accumulate_strain`), then Hooke's law.
    Compiled with :data:`FAST` and numpy's error model, the sum over the points is a
    vectorised loop (its terms carried in a tuple, benchmarks/RESULTS.md, issue 32)."""
    x0, y0, z = _receiver(point, center, setup, surface)
    jac = setup[6]
    acc = (0.0,) * 18
    for g in range(xi.shape[0]):
        acc = accumulate_strain(acc, wt[g] * jac, _image_at(g, x0, y0, z, a, b, setup, xi, eta))
    set_strain(acc, work[3])
    global_stress(work, setup[0], setup[1], setup[4], shear_modulus, okada, out)


@njit(cache=True, fastmath=FAST, error_model="numpy")
def setup_image_traction(point, normal, center, a, b, setup, okada, surface, shear_modulus, xi, eta, wt, work,
                         block):
    """:func:`point_image_traction` of the source whose :func:`point_setup` is ``setup``: the
    Gauss sum of the traction on the normal turned into Okada's frame
    (:func:`.okada_stress3d.accumulate_traction`: 9 sums, not 27 derivatives). ``work``
    unused (the signature of :func:`setup_image_stress`)."""
    s0 = setup[0]
    s1 = setup[1]
    x0, y0, z = _receiver(point, center, setup, surface)
    n0 = s0 * normal[0] + s1 * normal[1]
    n1 = -s1 * normal[0] + s0 * normal[1]
    n2 = normal[2]
    lam = setup[4]
    jac = setup[6]
    acc = (0.0,) * 9
    for g in range(xi.shape[0]):
        acc = accumulate_traction(acc, wt[g] * jac, _image_at(g, x0, y0, z, a, b, setup, xi, eta), n0, n1, n2,
                                  shear_modulus, lam)
    add_traction(acc, s0, s1, okada, block)


@njit(cache=True)
def point_image_stress(point, center, frame, a, b, okada, surface, shear_modulus, poisson_ratio, xi, eta, wt,
                       work, out):
    """``out[q, i, j]``: the image and surface terms of the global stress at ``point`` (below
    the free surface ``z = surface``) of a unit global DD ``q`` on the rectangle (``center``,
    rows ``frame``, half sides ``a``, ``b``), by the Gauss rule ``(xi, eta, wt)`` on [-1,
    1]^2 of Okada's point source (:func:`_point_image`) at each point; ``okada``: the rows of
    :func:`point_frame`. ``work``: (5, 3, 3, 3) scratch (:func:`.okada_stress3d.global_stress`)."""
    setup = np.empty(POINT_SETUP)
    point_setup(center, frame, a, b, okada, surface, shear_modulus, poisson_ratio, setup)
    setup_image_stress(point, center, a, b, setup, okada, surface, shear_modulus, xi, eta, wt, work, out)


@njit(cache=True)
def point_image_traction(point, normal, center, frame, a, b, okada, surface, shear_modulus, poisson_ratio, xi, eta,
                         wt, work, block):
    """``block[p, q] +=`` the traction ``sigma . normal`` (global component ``p``) of the terms
    of :func:`point_image_stress` (no stress tensor: the traction summed over the points,
    :func:`.okada_stress3d.accumulate_traction`)."""
    setup = np.empty(POINT_SETUP)
    point_setup(center, frame, a, b, okada, surface, shear_modulus, poisson_ratio, setup)
    setup_image_traction(point, normal, center, a, b, setup, okada, surface, shear_modulus, xi, eta, wt, work, block)


@njit(cache=True, inline="always")
def point_form_terms(data, point, lr, j, setup, rules, okada_work, entry_tol, normal, out, traction):
    """A ``point_form`` source ``j`` of the kernel record ``data``
    (:class:`.images3d.LayeredRectangles`; a half-space, no horizontal side): its image and
    surface terms at ``point`` (in layer ``lr``) by Okada's point source at the points of
    :func:`point_rule`; ``traction``: ``out[p, q] +=`` the traction on ``normal``
    (:func:`point_image_traction`), else ``out[q, i, k] =`` the stress
    (:func:`point_image_stress`); ``setup``: the source's :func:`point_setup` (in its
    :func:`.images3d.source_state`); ``rules``, ``okada_work``: the cached rules and Okada's
    scratch of :func:`.images3d.workspace` (not the whole workspace: numba takes and drops a
    reference to each of its arrays for each inlined function it is passed to, code that
    LLVM optimises in every caller, benchmarks/RESULTS.md, issue 32). Inlined into the
    callers (no record passed across a call, not held). On issue 32's lattice (2 x 2 points for 95% of
    the pairs) a whole entry, real source included, costs 0.31-0.32 us, 2.8-2.9x a
    uniform-rock entry (Intel Xeon, dgemm 73-80 GFLOP/s, one thread; benchmarks/RESULTS.md,
    issue 32)."""
    xi, eta, wt, start = rules
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    if lr == ls and data.interfaces.shape[0] == 1:
        # the mirror in the free surface, the one singular point: what nearest_singularity
        # gives there
        dmin = distance_to_rectangle(point[0], point[1], 2.0 * data.interfaces[0] - point[2], center, frame, a, b)
    else:
        dmin = nearest_singularity(point, lr, center, frame, a, b, ls, data.interfaces, np.int64(-1))
    n_gauss, n_sub = point_rule(dmin, a, b, data.max_subdivisions, data.far_tol, entry_tol)
    if n_sub == 1 and n_gauss <= data.gauss_points:
        lo, hi = start[n_gauss - 1], start[n_gauss]
        xs, es, ws = xi[lo:hi], eta[lo:hi], wt[lo:hi]
    else:
        xs, es, ws = square_rule(n_gauss, n_sub)
    g = data.shear_modulus[ls]
    if traction:
        setup_image_traction(point, normal, center, a, b, setup, data.okada[j], data.surface, g, xs, es, ws,
                             okada_work, out)
    else:
        setup_image_stress(point, center, a, b, setup, data.okada[j], data.surface, g, xs, es, ws, okada_work, out)
