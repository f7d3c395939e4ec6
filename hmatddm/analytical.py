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


# --- propagating hydraulic fractures (ref. Sec. 4.5) --------------------------------------
# Notation: E' plane-strain modulus, K' = 4 sqrt(2/pi) K_Ic (ref. Eq. 4.68),
# mu' = 12 mu, Q injection rate (m^3/s; per unit height for KGD).


def toughness_scale(fracture_toughness):
    """K' = 4 (2/pi)^(1/2) K_Ic (ref. Eq. 4.68)."""
    return 4.0 * np.sqrt(2.0 / np.pi) * finite_scalar("fracture_toughness", fracture_toughness)


def radial_k_vertex(t, injection_rate, fracture_toughness, material):
    """Toughness-dominated radial fracture, no leak-off (ref. Eqs 4.65-4.67).

    Exact for zero viscosity: uniform net pressure p, Sneddon's opening, K_I = 2 p (R/pi)^(1/2)
    equal to K_Ic and the volume 16 p R^3 / (3 E') equal to Q t. Returns
    ``(radius, max_width, net_pressure)`` (arrays like ``t``); the constants reproduce
    0.8546, 0.6537 and 0.3004 of the reference.
    """
    t = np.asarray(t, dtype=float)
    e_prime = material.plane_strain_modulus
    k_ic = finite_scalar("fracture_toughness", fracture_toughness)
    radius = (3.0 * e_prime * injection_rate * t / (8.0 * np.sqrt(np.pi) * k_ic)) ** 0.4
    pressure = k_ic * np.sqrt(np.pi) / (2.0 * np.sqrt(radius))
    return radius, 8.0 * pressure * radius / (np.pi * e_prime), pressure


def radial_m_vertex(t, injection_rate, viscosity, material):
    """Viscosity-dominated radial fracture, no leak-off (ref. Eqs 4.62-4.63, Savitski and
    Detournay 2002). Returns ``(radius, max_width)``; the net pressure is log-singular at
    the injection point and is not a single number."""
    t = np.asarray(t, dtype=float)
    e_prime = material.plane_strain_modulus
    mu_prime = 12.0 * finite_scalar("viscosity", viscosity)
    q = injection_rate
    radius = 0.6944 * (q**3 * e_prime * t**4 / mu_prime) ** (1.0 / 9.0)
    max_width = 1.1901 * (mu_prime**2 * q**3 * t / e_prime**2) ** (1.0 / 9.0)
    return radius, max_width


def kgd_k_vertex(t, injection_rate, fracture_toughness, material):
    """Toughness-dominated plane-strain (KGD) fracture, no leak-off, exact for zero viscosity.

    ``injection_rate`` is per unit height into both wings. Uniform net pressure p with
    K_I = p (pi l)^(1/2) = K_Ic and volume 2 pi p l^2 / E' = Q t. Returns
    ``(half_length, max_width, net_pressure)``: l = 0.9324 (E' Q t / K')^(2/3).
    """
    t = np.asarray(t, dtype=float)
    e_prime = material.plane_strain_modulus
    k_ic = finite_scalar("fracture_toughness", fracture_toughness)
    half_length = (e_prime * injection_rate * t / (2.0 * np.sqrt(np.pi) * k_ic)) ** (2.0 / 3.0)
    pressure = k_ic / np.sqrt(np.pi * half_length)
    return half_length, 4.0 * pressure * half_length / e_prime, pressure
