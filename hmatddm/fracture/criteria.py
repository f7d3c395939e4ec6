"""Stress intensity factors from tip DDs and the propagation criteria (ref. Sec. 4.2.2).

Frame at a tip edge: ``x`` ahead of the tip (outward, in the element plane and
perpendicular to the edge), ``y`` the element normal (the ``+`` face), ``z`` along
the edge. With ``DD = u(+) - u(-)``, the near-tip field of linear elastic fracture
mechanics gives ``DD_y = 8 (1 - nu^2) / E  K_I sqrt(r / 2 pi)`` and the same for
``DD_x`` with ``K_II``, so the sign conventions of Erdogan and Sih hold in ``(x, y)``.
"""
import numpy as np

from ..settings import OLSON_CORRECTION  # noqa: E402,F401  C_cor of ref. Eqs 4.18-4.19 (Olson 1991)


def stress_intensity_factors(opening, slip_ahead, slip_along, half_width, material,
                             correction=OLSON_CORRECTION):
    """``(K_I, K_II, K_III)`` from the DDs of tip elements (ref. Eqs 4.18-4.19).

    ``K = C_cor E / (4 (1 - nu^2)) (pi / (2 a))^(1/2) DD`` with ``a`` the element half
    size perpendicular to the tip edge; K_III takes the slip along the edge with the
    same factor times ``1 - nu`` (the mode-III jump is ``4 K_III sqrt(r/2pi) / G``).
    """
    e, nu = material.youngs_modulus, material.poisson_ratio
    factor = correction * e / (4.0 * (1.0 - nu * nu)) * np.sqrt(np.pi / (2.0 * np.asarray(half_width)))
    return factor * opening, factor * slip_ahead, factor * (1.0 - nu) * slip_along


def circumferential_stress_direction(k_1, k_2):
    """theta_0 of the maximum circumferential stress (ref. Eq. 4.11), radians in (-pi, pi).

    ``tan(theta_0/2) = (K_I/K_II - sgn(K_II) sqrt((K_I/K_II)^2 + 8)) / 4``; written as
    ``2 K_II / (K_I + sqrt(K_I^2 + 8 K_II^2))`` so that ``K_II -> 0`` gives 0 smoothly
    (the same root, multiplied out; for K_I <= 0 and K_II = 0 the direction is undefined
    and 0 is returned). Pure mode II gives -+70.5 degrees.
    """
    k_1 = np.asarray(k_1, dtype=float)
    k_2 = np.asarray(k_2, dtype=float)
    root = np.sqrt(k_1 * k_1 + 8.0 * k_2 * k_2)
    denominator = k_1 + root
    safe = np.where(denominator > 0.0, denominator, 1.0)
    tangent = np.where(denominator > 0.0, -2.0 * k_2 / safe, 0.0)
    return 2.0 * np.arctan(tangent)


def equivalent_mode_one(k_1, k_2, theta):
    """K-bar_I in the direction theta (ref. Eq. 4.10)."""
    return 0.5 * np.cos(0.5 * theta) * (k_1 * (1.0 + np.cos(theta)) - 3.0 * k_2 * np.sin(theta))


def energy_release_rate(k_bar_1, k_3, material):
    """G = K-bar_I^2 / E' + K_III^2 / (2 G) (ref. Eqs 4.13 and 4.15)."""
    return k_bar_1**2 / material.plane_strain_modulus + k_3**2 / (2.0 * material.shear_modulus)
