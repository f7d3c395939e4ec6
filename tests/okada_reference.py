"""Independent reference for the half-space displacement: Okada's (1985) closed-form
surface displacement of a finite rectangular dislocation in an elastic half-space
(Okada, Y., 1985, Surface deformation due to shear and tensile faults in a half-space,
BSSA 75(4), 1135-1154, Eqs 25-30 with Chinnery's notation, Eq. 24). Written from the
paper, no code shared with hmatddm.

Okada's frame: ``z`` up, the surface ``z = 0``, the fault strikes along ``x``; its
lower edge runs from ``(0, 0, -depth)`` to ``(length, 0, -depth)`` and it rises up-dip
along ``(0, cos(dip), sin(dip))`` over ``width``. ``U1`` (strike), ``U2`` (dip), ``U3``
(tensile) are the movement of the hanging wall relative to the foot wall, i.e.
``u(+) - u(-)`` with ``+`` the side of the normal ``(0, -sin(dip), cos(dip))``, along
``e1 = (1, 0, 0)``, ``e2 = (0, cos(dip), sin(dip))`` and that normal.
"""
import math

import numpy as np


def _f(xi, eta, q, dip, nu, u1, u2, u3):
    cs, sn = math.cos(dip), math.sin(dip)
    if abs(cs) < 1e-12:
        cs = 0.0
        sn = 1.0 if sn > 0 else -1.0
    ratio = 1.0 - 2.0 * nu  # mu / (lambda + mu)
    ytil = eta * cs + q * sn
    dtil = eta * sn - q * cs
    r = math.sqrt(xi * xi + eta * eta + q * q)
    x = math.sqrt(xi * xi + q * q)
    if cs != 0.0:
        i5 = 0.0 if xi == 0.0 else ratio * 2.0 / cs * math.atan(
            (eta * (x + q * cs) + x * (r + x) * sn) / (xi * (r + x) * cs))
        i4 = ratio / cs * (math.log(r + dtil) - sn * math.log(r + eta))
        i3 = ratio * (ytil / (cs * (r + dtil)) - math.log(r + eta)) + sn / cs * i4
        i2 = ratio * (-math.log(r + eta)) - i3
        i1 = ratio * (-xi / (cs * (r + dtil))) - sn / cs * i5
    else:
        i1 = -ratio / 2.0 * xi * q / (r + dtil) ** 2
        i3 = ratio / 2.0 * (eta / (r + dtil) + ytil * q / (r + dtil) ** 2 - math.log(r + eta))
        i2 = ratio * (-math.log(r + eta)) - i3
        i4 = -ratio * q / (r + dtil)
        i5 = -ratio * xi * sn / (r + dtil)
    theta = math.atan(xi * eta / (q * r))
    c = 1.0 / (2.0 * math.pi)
    ux = -u1 * c * (xi * q / (r * (r + eta)) + theta + i1 * sn)
    uy = -u1 * c * (ytil * q / (r * (r + eta)) + q * cs / (r + eta) + i2 * sn)
    uz = -u1 * c * (dtil * q / (r * (r + eta)) + q * sn / (r + eta) + i4 * sn)
    ux += -u2 * c * (q / r - i3 * sn * cs)
    uy += -u2 * c * (ytil * q / (r * (r + xi)) + cs * theta - i1 * sn * cs)
    uz += -u2 * c * (dtil * q / (r * (r + xi)) + sn * theta - i5 * sn * cs)
    ux += u3 * c * (q * q / (r * (r + eta)) - i3 * sn * sn)
    uy += u3 * c * (-dtil * q / (r * (r + xi)) - sn * (xi * q / (r * (r + eta)) - theta) - i1 * sn * sn)
    uz += u3 * c * (ytil * q / (r * (r + xi)) + cs * (xi * q / (r * (r + eta)) - theta) - i5 * sn * sn)
    return np.array([ux, uy, uz])


def surface_displacement(x, y, depth, dip, length, width, u1, u2, u3, nu):
    """Displacement (3,) at the surface point ``(x, y, 0)`` (Okada's frame, above)."""
    cs, sn = math.cos(dip), math.sin(dip)
    p = y * cs + depth * sn
    q = y * sn - depth * cs
    args = (q, dip, nu, u1, u2, u3)
    return (_f(x, p, *args) - _f(x, p - width, *args) - _f(x - length, p, *args)
            + _f(x - length, p - width, *args))


def rectangle(depth, dip, length, width):
    """The fault as a rectangle of the DDM: ``(center, frame (e1, e2, normal), a, b)``."""
    cs, sn = math.cos(dip), math.sin(dip)
    e1 = np.array([1.0, 0.0, 0.0])
    e2 = np.array([0.0, cs, sn])
    center = np.array([0.5 * length, 0.5 * width * cs, -depth + 0.5 * width * sn])
    return center, np.array([e1, e2, np.cross(e1, e2)]), 0.5 * length, 0.5 * width


def plane_strain_surface_displacement(x, depth, x1, x2, shear, opening):
    """Plane strain: surface displacement ``(u_x, u_y)`` at ``(x, 0)`` (``y`` up) of a
    horizontal segment ``x1 <= x <= x2`` at ``y = -depth`` with uniform DD ``(shear,
    opening)`` (``u(+) - u(-)``, ``+`` above): Okada's point sources (1985, Eqs 15-17 at
    dip 0: ``u_z = U3 3 d^3 / (2 pi R^5)``, ``u_y = U3 3 y d^2 / (2 pi R^5)``, and
    ``U2 3 d^2 y / (2 pi R^5)``, ``U2 3 d y^2 / (2 pi R^5)``) integrated along the strike
    (``int 3 dx / R^5 = 4 / r^4``) and across the segment in closed form. Independent of
    Poisson's ratio, as every surface displacement of a horizontal dislocation."""
    d = depth

    def atan_part(s):
        return math.atan(s / d)

    def rational(s):
        return d * s / (s * s + d * d)

    def bell(s):
        return d * d / (s * s + d * d)

    s1, s2 = x - x1, x - x2
    uy = opening / math.pi * (atan_part(s1) + rational(s1) - atan_part(s2) - rational(s2))
    ux = opening / math.pi * (bell(s2) - bell(s1))
    uy += shear / math.pi * (bell(s2) - bell(s1))
    ux += shear / math.pi * (atan_part(s1) - rational(s1) - atan_part(s2) + rational(s2))
    return np.array([ux, uy])
