"""Equilibrium height of a fracture in a symmetric three-layer stack: a pay zone of
thickness ``H`` between two bounding layers whose minimum horizontal stress is larger by
``d_sigma`` (Simonson, Abou-Sayed and Clifton 1978, "Containment of massive hydraulic
fractures", SPE J. 18(1):27-32; the stress-contrast case of ref. Ch. 3's height growth).

A plane-strain crack ``|y| < a`` (``y`` vertical, centred in the pay zone) under a
uniform fluid pressure ``p``, with the closing stress ``sigma_pay`` for ``|y| < H/2`` and
``sigma_pay + d_sigma`` beyond, has at both tips

    K_I = sqrt(pi a) [p_net - (2 d_sigma / pi) arccos(H / (2 a))],   p_net = p - sigma_pay

(the weight function of a centre crack, ``int_{-a}^{a} q(y) sqrt((a+y)/(a-y)) dy /
sqrt(pi a)``, with ``q = -d_sigma`` on ``H/2 < |y| < a``). The fracture stands still where
``K_I = K_Ic``: its equilibrium height ``2a`` for the net pressure ``p_net``. The moduli are
uniform (the layers' modulus contrast is not part of it) and the pressure uniform (no
viscous drop).
"""
import numpy as np

from .._validation import finite_scalar, positive_scalar

FORMULA = "K_Ic = sqrt(pi a) [p_net - (2 d_sigma / pi) arccos(H / 2a)], height 2a"
SOURCE = "Simonson, Abou-Sayed and Clifton (1978), SPE J. 18(1):27-32"


def three_layer_stress_intensity(half_height, net_pressure, stress_contrast, pay_thickness):
    """``K_I`` (Pa m^0.5) at the tips of a crack of half-height ``a`` (m) centred in the pay
    zone (see the module docstring); ``a`` below ``H/2``: the plain ``p_net sqrt(pi a)``."""
    a = np.asarray(half_height, dtype=float)
    ratio = np.clip(pay_thickness / (2.0 * a), -1.0, 1.0)
    barrier = np.where(2.0 * a > pay_thickness, 2.0 * stress_contrast / np.pi * np.arccos(ratio), 0.0)
    return np.sqrt(np.pi * a) * (net_pressure - barrier)


def equilibrium_height(net_pressure, stress_contrast, pay_thickness, toughness):
    """The stable equilibrium height ``2a`` (m) for the net pressure ``p_net`` (Pa, the
    fluid pressure minus the pay zone's closing stress), the contrast ``d_sigma`` (Pa,
    > 0), the pay thickness ``H`` (m) and ``K_Ic`` (Pa m^0.5): the root of ``K_I = K_Ic``
    (module docstring) where ``K_I`` falls with ``a``, so that a taller fracture stops and
    a shorter one grows to it. ``K_I`` rises with ``a`` inside the pay zone and beyond it
    up to a maximum, then falls to zero at ``a_0 = H / (2 cos(pi p_net / (2 d_sigma)))``;

    * ``p_net >= d_sigma``: ``K_I`` grows without bound: no equilibrium, the height grows
      through the barriers (returns ``inf``);
    * the maximum of ``K_I`` below ``K_Ic`` (or ``p_net <= 0``): the pressure drives no
      tip, no height follows from it (returns ``nan``);
    * otherwise the root in ``[a_max, a_0]``.
    """
    from scipy.optimize import brentq, minimize_scalar

    p = finite_scalar("net_pressure", net_pressure)
    d_sigma = positive_scalar("stress_contrast", stress_contrast)
    thickness = positive_scalar("pay_thickness", pay_thickness)
    k_ic = positive_scalar("toughness", toughness)
    if p <= 0.0:
        return float("nan")
    if p >= d_sigma:
        return float("inf")

    def excess(a):
        return float(three_layer_stress_intensity(a, p, d_sigma, thickness)) - k_ic

    zero = thickness / (2.0 * np.cos(0.5 * np.pi * p / d_sigma))
    peak = minimize_scalar(lambda a: -excess(a), bounds=(0.5 * thickness, zero), method="bounded",
                           options=dict(xatol=1e-10 * zero)).x
    if excess(peak) < 0.0:
        return float("nan")
    return 2.0 * brentq(excess, peak, zero, xtol=1e-12 * thickness, rtol=1e-12)


__all__ = ["FORMULA", "SOURCE", "three_layer_stress_intensity", "equilibrium_height"]
