"""What a hydraulic fracture does when its tip reaches a natural fracture (ref. Sec. 5.2).

Three criteria decide between *crossing* (the tip goes on through the natural
fracture) and *deflection* (the fluid enters the natural fracture, which then opens
along its length and the hydraulic fracture leaves from its end):

* ``"mohr-coulomb"`` (ref. Eqs 5.1-5.10, Gu and Weng 2010 with a critical radius):
  the near-tip stress at ``(r_c, phi)`` (far field plus the K_I, K_II asymptotic
  fields of Eqs 5.6-5.8) loads the natural fracture plane; it is deflected into when
  ``sigma_n >= T_0`` or ``|sigma_t| >= S_0 - C (sigma_n + p)``.
* ``"sif"`` (ref. Sec. 5.2.3): crosses when ``K-bar_I(theta_0) / K_Ic,rock >
  K-bar_I(phi) / K_Ic,NF``.
* ``"energy"`` (ref. Eqs 5.11-5.16): crosses when ``G(theta_0) / G_c,rock >
  G(phi) / G_c,NF`` with ``G = (K-bar_I^2 + K-bar_II^2) / E'`` and ``G_c = (K_Ic^2 +
  K_IIc^2) / E'`` (the squares are missing in the printed Eqs 5.11 and 5.15), K_Ic and
  K_IIc those of the rock ahead (``theta_0``) and of the natural fracture along it
  (``phi``, Eq. 5.16). The modulus E'(theta) of Eq. 5.12 (the natural fracture's along
  ``phi``) divides both ``G`` and ``G_c`` of one direction, so it cancels from each ratio:
  the criterion does not depend on it, and no separate modulus is taken.

Angles live in the tip frame of :mod:`hmatddm.fracture.criteria`: ``x`` ahead,
``y`` the hydraulic fracture's normal. A natural fracture through the tip runs in
two directions, ``phi`` and ``phi - pi``; both are checked and the more critical
one decides (the reference draws one).
"""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_scalar
from ..settings import NATURAL_FRACTURE
from ..errors import InputError
from .criteria import equivalent_mode_one

CROSSING_CRITERIA = ("mohr-coulomb", "sif", "energy")


@dataclass(frozen=True)
class NaturalFractureProperties:
    """Strength of the natural fractures (ref. Sec. 5.2-5.3).

    Defaults, ranges and units are those of :data:`hmatddm.settings.NATURAL_FRACTURE`, the
    one source that scenes (``[network]``) read too: the natural-fracture network runs of
    ref. Table 6.2 (friction 0.25, r_c = 0.005 m, K_Ic = 0.5 MPa m^1/2, no cohesion). The
    crossing experiments of ref. Table 5.1 use other values (friction 0.38, cohesion
    3.2 MPa, T_0 = 0.5 MPa, r_c = 1 cm): pass them explicitly.

    Parameters
    ----------
    friction : float, friction coefficient C (>= 0)
    cohesion : float, S_0 in Pa (>= 0)
    tensile_strength : float, T_0 in Pa (>= 0)
    toughness : float, K_Ic of the natural fracture in Pa m^1/2 (> 0)
    critical_radius : float, r_c of the Mohr-Coulomb crossing criterion in m (> 0)
    pore_pressure : float, p in Pa (reservoir pore pressure acting on the planes)
    crossing : {"mohr-coulomb", "sif", "energy"}
    skempton : float in [0, 1], Skempton's B of the undrained pore-pressure change
        ``dp = -B d sigma_m`` (ref. Eq. 5.18) used by the remote-failure check
    shear_toughness, rock_shear_toughness : float, K_IIc of the natural fractures and of
        the rock in Pa m^1/2 (>= 0; ref. Eqs 5.15-5.16), read by the energy criterion only
        (0: ``G_c = K_Ic^2 / E'``)
    """

    friction: float = NATURAL_FRACTURE["friction_coefficient"].default
    cohesion: float = NATURAL_FRACTURE["cohesion"].default
    tensile_strength: float = NATURAL_FRACTURE["tensile_strength"].default
    toughness: float = NATURAL_FRACTURE["toughness"].default
    critical_radius: float = NATURAL_FRACTURE["critical_radius"].default
    pore_pressure: float = 0.0
    crossing: str = "mohr-coulomb"
    skempton: float = NATURAL_FRACTURE["skempton"].default
    shear_toughness: float = NATURAL_FRACTURE["shear_toughness"].default
    rock_shear_toughness: float = NATURAL_FRACTURE["rock_shear_toughness"].default

    def __post_init__(self):
        for name in ("friction", "cohesion", "tensile_strength", "toughness", "critical_radius", "skempton",
                     "shear_toughness", "rock_shear_toughness"):
            setting = NATURAL_FRACTURE["friction_coefficient" if name == "friction" else name]
            object.__setattr__(self, name, setting.value(f"natural.{name}", getattr(self, name)))
        object.__setattr__(self, "pore_pressure", finite_scalar("natural.pore_pressure", self.pore_pressure))
        if self.crossing not in CROSSING_CRITERIA:
            raise InputError(f"natural.crossing must be one of {CROSSING_CRITERIA}, got {self.crossing!r}")


def near_tip_stress(k_1, k_2, radius, theta):
    """``(sigma_xx, sigma_yy, sigma_xy)`` of the K_I and K_II fields at ``(r, theta)`` in
    the tip frame (ref. Eqs 5.6-5.8, without the far field)."""
    factor = 1.0 / np.sqrt(2.0 * np.pi * radius)
    half, three_half = 0.5 * theta, 1.5 * theta
    c, s = np.cos(half), np.sin(half)
    f_xx = c * (1.0 - s * np.sin(three_half))
    f_yy = c * (1.0 + s * np.sin(three_half))
    f_xy = s * c * np.cos(three_half)
    g_xx = s * (-2.0 - c * np.cos(three_half))
    g_yy = s * c * np.cos(three_half)
    g_xy = c * (1.0 - s * np.sin(three_half))
    return (factor * (k_1 * f_xx + k_2 * g_xx), factor * (k_1 * f_yy + k_2 * g_yy),
            factor * (k_1 * f_xy + k_2 * g_xy))


def plane_tractions(sigma_xx, sigma_yy, sigma_xy, phi):
    """Normal and shear stress on a plane along direction ``phi`` (ref. Eqs 5.3-5.4)."""
    mean, half_difference = 0.5 * (sigma_xx + sigma_yy), 0.5 * (sigma_xx - sigma_yy)
    normal = mean - half_difference * np.cos(2 * phi) - sigma_xy * np.sin(2 * phi)
    shear = half_difference * np.sin(2 * phi) - sigma_xy * np.cos(2 * phi)
    return normal, shear


def _equivalent_mode_two(k_1, k_2, theta):
    """K-bar_II in direction theta (ref. Eq. 5.14)."""
    return 0.5 * np.cos(0.5 * theta) * (k_1 * np.sin(theta) + k_2 * (3.0 * np.cos(theta) - 1.0))


def crosses(k_1, k_2, theta_0, phi, far_field_tip, rock_toughness, natural):
    """True when the hydraulic fracture crosses the natural fracture.

    ``phi``: direction of the natural fracture in the tip frame (radians);
    ``far_field_tip``: (2, 2) in-situ stress in the tip frame ``(x, y)``, tension positive.
    """
    branches = (phi, phi - np.pi) if phi > 0 else (phi, phi + np.pi)
    if natural.crossing == "mohr-coulomb":
        for angle in branches:
            sxx, syy, sxy = near_tip_stress(k_1, k_2, natural.critical_radius, angle)
            sxx, syy, sxy = sxx + far_field_tip[0, 0], syy + far_field_tip[1, 1], sxy + far_field_tip[0, 1]
            normal, shear = plane_tractions(sxx, syy, sxy, angle)
            strength = natural.cohesion - natural.friction * (normal + natural.pore_pressure)
            if normal >= natural.tensile_strength or abs(shear) >= strength:
                return False
        return True
    ahead = equivalent_mode_one(k_1, k_2, theta_0)
    along = max(equivalent_mode_one(k_1, k_2, angle) for angle in branches)
    if natural.crossing == "sif":
        return ahead / rock_toughness > along / natural.toughness
    ahead_g = ahead**2 + _equivalent_mode_two(k_1, k_2, theta_0) ** 2
    along_g = max(equivalent_mode_one(k_1, k_2, a) ** 2 + _equivalent_mode_two(k_1, k_2, a) ** 2 for a in branches)
    return ahead_g / (rock_toughness**2 + natural.rock_shear_toughness**2) > \
        along_g / (natural.toughness**2 + natural.shear_toughness**2)
