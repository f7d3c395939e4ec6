"""Closed-form reference solutions (SI units, tension positive, opening positive).

Static cracks:
* :func:`griffith_opening`: plane-strain line crack of half length ``a`` under uniform
  net load (pressure for opening, remote shear for slip).
* :func:`sneddon_opening`, :func:`sneddon_volume`: penny-shaped crack of radius ``c``
  under uniform pressure (Sneddon 1946).
* :func:`sneddon_axis_stress`: stresses on the axis of a pressurised penny crack,
  ref. Eqs 5.30-5.32, and their mean (ref. Fig. 5.15).
"""
import numpy as np

from ._validation import finite_scalar


def griffith_opening(x, half_length, load, material):
    """Opening (or slip) ``2 (1 - nu) load / G sqrt(a^2 - x^2)`` of a plane-strain crack
    ``|x| < a`` under a uniform net ``load`` (pressure or remote shear), zero outside."""
    a = finite_scalar("half_length", half_length)
    x = np.asarray(x, dtype=float)
    nu, g = material.poisson_ratio, material.shear_modulus
    return 2.0 * (1.0 - nu) * load / g * np.sqrt(np.clip(a * a - x * x, 0.0, None))


def sneddon_opening(r, radius, pressure, material):
    """Opening ``4 (1 - nu) p / (pi G) sqrt(c^2 - r^2)`` of a penny crack (Sneddon 1946)."""
    c = finite_scalar("radius", radius)
    r = np.asarray(r, dtype=float)
    nu, g = material.poisson_ratio, material.shear_modulus
    return 4.0 * (1.0 - nu) * pressure / (np.pi * g) * np.sqrt(np.clip(c * c - r * r, 0.0, None))


def sneddon_volume(radius, pressure, material):
    """Volume ``8 (1 - nu) p c^3 / (3 G)`` of a pressurised penny crack."""
    nu, g = material.poisson_ratio, material.shear_modulus
    return 8.0 * (1.0 - nu) * pressure * radius**3 / (3.0 * g)


def sneddon_axis_stress(z, radius, pressure, poisson_ratio):
    """Stresses on the axis ``r = 0`` of a penny crack under internal pressure ``p``
    (ref. Eqs 5.30-5.31, tension positive). Returns ``(sigma_r, sigma_z, sigma_mean)``
    with ``sigma_theta = sigma_r`` and ``sigma_mean = (2 sigma_r + sigma_z)/3``."""
    zeta = np.abs(np.asarray(z, dtype=float)) / radius
    nu = poisson_ratio
    p = pressure
    sigma_r = p / np.pi * ((1 + 2 * nu) * (zeta / (1 + zeta**2) - np.arctan(1 / zeta)) + 2 * zeta / (1 + zeta**2) ** 2)
    sigma_z = 2 * p / np.pi * (zeta * (zeta**2 - 1) / (1 + zeta**2) ** 2 - np.arctan(1 / zeta))
    return sigma_r, sigma_z, (2 * sigma_r + sigma_z) / 3.0
