"""Regime numbers of a growing hydraulic fracture and which closed form applies to it.

A fracture driven by a Newtonian fluid at a constant rate ``Q`` spends the injected power
on fracturing the rock (toughness ``K_Ic``), on the viscous flow (viscosity ``mu``) and,
with leak-off, loses fluid to the rock. Scaled by the viscosity (M) scaling, the
solution depends on dimensionless numbers only; which vertex solution applies is read off
them (Savitski and Detournay 2002; Detournay 2004; Detournay 2016). Notation:
``E' = 2 G / (1 - nu)``, ``K' = 4 (2/pi)^(1/2) K_Ic`` (ref. Eq. 4.68), ``mu' = 12 mu``,
``C' = 2 C_L`` (Carter's coefficient of both faces together: a total leak-off rate
``C' / (t - tau)^(1/2)`` per unit fracture area).

Toughness numbers (zero leak-off):

* radial: ``K_m = K' (t^2 / (mu'^5 Q^3 E'^13))^(1/18)`` (Savitski and Detournay 2002),
  growing as ``t^(1/9)``: a radial fracture starts viscosity dominated and ends toughness
  dominated; ``K_m <= 1`` M-vertex, ``K_m >= 3.5`` K-vertex, in between the K-M transition
  (Dontsov 2016, :func:`hmatddm.analytical.radial_transition`);
* plane strain (KGD): ``K_m = K' / (E'^3 mu' Q)^(1/4)``, ``Q`` per unit height into both
  wings (Detournay 2004), constant in time; ``K_m <= 1`` M-vertex, ``K_m >= 4`` K-vertex,
  in between the transition (Garagash 2006, large-toughness expansion; Dontsov 2017,
  approximate solution; neither is in this package).

Leak-off numbers (the ratio ``C' t^(1/2) / W_m`` of the leak-off length to the
viscosity width scale ``W_m = eps_m L_m``; zero at a storage vertex):

* radial: ``C_m = (C'^18 E'^4 t^7 / (mu'^4 Q^6))^(1/18)`` (Madyarova 2003; Detournay 2016),
  growing as ``t^(7/18)``;
* plane strain: ``C_m = (C'^6 E' t / (mu' Q^3))^(1/6)`` (Adachi and Detournay 2008),
  growing as ``t^(1/6)``.

Every closed form of :mod:`.solutions` for a growing fracture is a zero-leak-off
solution, so a scene's ``[reference]`` with them refuses leak-off (:mod:`hmatddm.scene.schema`);
the leak-off numbers say how far a scene with leak-off is from them. A scene with leak-off
is judged by a K-K~ edge (``kgd-k-leak-off``, ``radial-k-leak-off``; :mod:`.leak_off`,
zero viscosity at any leak-off number): it applies where the toughness number says K (the
viscosity is negligible; :data:`LEAK_OFF_VERTEX`); by the M~ vertices
(``kgd-m-leak-off``, ``radial-m-leak-off``; they assume all the fluid leaked: they apply
where ``C_m`` is at least :data:`M_LEAK_OFF_LIMITS` and the toughness number of the M~
scaling at most :data:`M_LEAK_OFF_TOUGHNESS`, :func:`applicable_solution`); or by Dontsov's
solutions at any ``K_m`` and ``C_m`` (``kgd-km-leak-off``, ``radial-km-leak-off``;
:mod:`.viscous_leak_off`).
Its reference block records ``C_m`` beside ``K_m``, with ``C' = c_l (sigma_0 - p_r)``
(:func:`carter_prime`).
"""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array, positive_scalar
from ..errors import InputError

# Where the vertices apply (dimensionless toughness K_m): M-vertex at or below the first,
# K-vertex at or above the second (Savitski and Detournay 2002 for radial; Detournay 2004
# for plane strain).
RADIAL_LIMITS = (1.0, 3.5)
KGD_LIMITS = (1.0, 4.0)


def _times(t):
    t = finite_array("t", t)
    if np.any(t <= 0.0):
        raise InputError(f"t must be > 0 (time since the start of injection), got min {t.min()}")
    return t


def toughness_prime(fracture_toughness):
    """``K' = 4 (2/pi)^(1/2) K_Ic`` (ref. Eq. 4.68)."""
    return 4.0 * np.sqrt(2.0 / np.pi) * positive_scalar("fracture_toughness", fracture_toughness)


def radial_toughness_number(t, injection_rate, viscosity, fracture_toughness, material):
    """``K_m = K' (t^2 / (mu'^5 Q^3 E'^13))^(1/18)`` of a radial fracture, zero leak-off
    (Savitski and Detournay 2002). Returns an array like ``t`` (s, > 0)."""
    t = _times(t)
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    e_prime = material.plane_strain_modulus
    return toughness_prime(fracture_toughness) * (t**2 / (mu_prime**5 * q**3 * e_prime**13)) ** (1.0 / 18.0)


def kgd_toughness_number(injection_rate, viscosity, fracture_toughness, material):
    """``K_m = K' / (E'^3 mu' Q)^(1/4)`` of a plane-strain (KGD) fracture, zero leak-off
    (Detournay 2004); ``Q`` per unit height into both wings. Independent of time."""
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    e_prime = material.plane_strain_modulus
    return toughness_prime(fracture_toughness) / (e_prime**3 * mu_prime * q) ** 0.25


def radial_leak_off_number(t, injection_rate, viscosity, leak_off, material):
    """``C_m = (C'^18 E'^4 t^7 / (mu'^4 Q^6))^(1/18)`` of a radial fracture (Madyarova 2003;
    Detournay 2016), ``leak_off`` = ``C'`` in m/s^(1/2) (both faces; >= 0). An array like ``t``."""
    t = _times(t)
    c_prime = _leak_off(leak_off)
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    e_prime = material.plane_strain_modulus
    return c_prime * (e_prime**4 * t**7 / (mu_prime**4 * q**6)) ** (1.0 / 18.0)


def kgd_leak_off_number(t, injection_rate, viscosity, leak_off, material):
    """``C_m = (C'^6 E' t / (mu' Q^3))^(1/6)`` of a plane-strain fracture (Adachi and
    Detournay 2008), ``Q`` per unit height, ``leak_off`` = ``C'`` in m/s^(1/2). Like ``t``."""
    t = _times(t)
    c_prime = _leak_off(leak_off)
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    e_prime = material.plane_strain_modulus
    return c_prime * (e_prime * t / (mu_prime * q**3)) ** (1.0 / 6.0)


def carter_prime(carter_per_pressure, pressure_excess):
    """``C' = c_l (sigma_0 - p_r)`` (m/s^(1/2)) of this project's leak-off ``c_l (p - p_r) /
    (t - t_0)^(1/2)`` (ref. Eq. 4.25) at the confining stress ``sigma_0``: the net pressure,
    small against ``sigma_0 - p_r`` where leak-off matters, left out (``pressure_excess`` =
    ``sigma_0 - p_r`` in Pa, ``carter_per_pressure`` ``c_l`` in m/(s^(1/2) Pa), both >= 0)."""
    return _leak_off(float(carter_per_pressure) * max(float(pressure_excess), 0.0))


def _leak_off(value):
    value = float(value)
    if not np.isfinite(value) or value < 0.0:
        raise InputError(f"leak_off (C' = 2 C_L, m/s^0.5) must be finite and >= 0, got {value}")
    return value


def vertex(toughness_number, geometry):
    """``"M"``, ``"K"`` or ``"transition"`` for a dimensionless toughness (scalar), by
    :data:`RADIAL_LIMITS` (``geometry = "radial"``) or :data:`KGD_LIMITS` (``"kgd"``)."""
    low, high = _limits(geometry)
    if toughness_number <= low:
        return "M"
    if toughness_number >= high:
        return "K"
    return "transition"


def _limits(geometry):
    if geometry not in ("radial", "kgd"):
        raise InputError(f"geometry must be 'radial' or 'kgd', got {geometry!r}")
    return RADIAL_LIMITS if geometry == "radial" else KGD_LIMITS


@dataclass(frozen=True)
class Solution:
    """A closed form a scene is compared with: its ``[reference] kind``, a name, the
    formula of its radius (or half-length) and the published source."""

    kind: str
    name: str
    formula: str
    source: str

    def as_dict(self):
        return {"kind": self.kind, "name": self.name, "formula": self.formula, "source": self.source}


SOLUTIONS = {
    "radial-k": Solution(
        "radial-k", "radial K-vertex (zero viscosity, zero leak-off; exact)",
        "R = (3 E' Q t / (8 pi^(1/2) K_Ic))^(2/5), p = pi^(1/2) K_Ic / (2 R^(1/2)), w0 = 8 p R / (pi E')",
        "ref. Eqs 4.65-4.67; Savitski and Detournay 2002"),
    "radial-m": Solution(
        "radial-m", "radial M-vertex (zero toughness, zero leak-off)",
        "R = 0.6944 (Q^3 E' t^4 / mu')^(1/9), w0 = 1.1901 (mu'^2 Q^3 t / E'^2)^(1/9)",
        "ref. Eqs 4.62-4.63; Savitski and Detournay 2002; Dontsov 2016"),
    "radial-km": Solution(
        "radial-km", "radial K-M transition (any K_m, zero leak-off; approximate, ~1%)",
        "w = w_a (1 - rho)^delta ((1 + rho)/2)^lambda, w_a the universal tip asymptote at s = R, "
        "R such that the volume is Q t",
        "Dontsov 2016, R. Soc. open sci. 3:160737; tip asymptote of Dontsov and Peirce 2015"),
    "kgd-k": Solution(
        "kgd-k", "plane-strain (KGD) K-vertex (zero viscosity, zero leak-off; exact)",
        "l = (E' Q t / (2 pi^(1/2) K_Ic))^(2/3), p = K_Ic / (pi l)^(1/2), w0 = 4 p l / E'",
        "Garagash 2006; Detournay 2004"),
    "kgd-m": Solution(
        "kgd-m", "plane-strain (KGD) M-vertex (zero toughness, zero leak-off)",
        "l = 0.61524 (E' Q^3 t^4 / mu')^(1/6), w0 = 1.1233 (mu' Q^3 t^2 / E')^(1/6), "
        "p(0) = 0.5443 (mu' E'^2 / t)^(1/3)",
        "Spence and Sharp 1985; Adachi and Detournay 2002"),
}

# closed forms with Carter leak-off (hmatddm.analytical.leak_off): the K-K~ edges
SOLUTIONS.update({
    "kgd-k-leak-off": Solution(
        "kgd-k-leak-off", "plane-strain (KGD) K-K~ edge (zero viscosity, Carter leak-off; mass balance integrated "
        "in time)",
        "p = K_Ic / (pi l)^(1/2), w0 = 4 p l / E', Q t = 2 pi p l^2 / E' + int int c_l (sigma_0 - p_r + p) / "
        "(t' - t_0(x))^(1/2) dx dt'",
        "Carter 1957; Bunger, Detournay and Garagash 2005; hmatddm.analytical.kgd_toughness_leak_off_edge"),
    "radial-k-leak-off": Solution(
        "radial-k-leak-off", "radial K-K~ edge (zero viscosity, Carter leak-off; mass balance integrated in time)",
        "p = pi^(1/2) K_Ic / (2 R^(1/2)), w0 = 8 p R / (pi E'), Q t = 16 p R^3 / (3 E') + int int c_l (sigma_0 "
        "- p_r + p) / (t' - t_0(r))^(1/2) dA dt'",
        "Carter 1957; Madyarova 2003; Detournay 2016; hmatddm.analytical.radial_toughness_leak_off_edge"),
})
# viscous closed forms with leak-off (hmatddm.analytical.viscous_leak_off)
SOLUTIONS.update({
    "kgd-m-leak-off": Solution(
        "kgd-m-leak-off", "plane-strain (KGD) M~ vertex (zero toughness, all the fluid leaked off)",
        "l = Q t^(1/2) / (pi C'), w0 = 0.8165 (mu' Q^3 t / (E' C'^2))^(1/4), w = w0 (1 + xi)^0.520 (1 - xi)^(5/8), "
        "p(0) = 0.7515 (E'^3 mu' C'^2 / (Q t))^(1/4)",
        "Adachi and Detournay 2008; Dontsov 2017, Int. J. Fract. 205:221; the similarity solution "
        "(hmatddm.analytical.viscous_leak_off.kgd_m_leak_off_similarity)"),
    "kgd-km-leak-off": Solution(
        "kgd-km-leak-off", "plane-strain (KGD) fracture at any K_m and C_m (M, K, M~, K~ and between; approximate, "
        "~1%)",
        "w = w_a (1 - xi)^delta ((1 + xi)/2)^lambda, w_a the tip asymptote with leak-off at s = l, "
        "Q t = stored + 4 alpha B(alpha, 3/2) C' t^(1/2) l",
        "Dontsov 2017, Int. J. Fract. 205:221; hmatddm.analytical.viscous_leak_off.kgd_leak_off_transition"),
    "radial-km-leak-off": Solution(
        "radial-km-leak-off", "radial fracture at any K_m and C_m (M, K, M~, K~ and between; approximate, ~1%)",
        "w = w_a (1 - rho)^delta ((1 + rho)/2)^lambda, w_a the tip asymptote with leak-off at s = R, "
        "Q t = stored + 4 pi alpha B(2 alpha, 3/2) C' t^(1/2) R^2",
        "Dontsov 2016, R. Soc. open sci. 3:160737; hmatddm.analytical.radial_leak_off_transition"),
})
SOLUTIONS["radial-m-leak-off"] = Solution(
    "radial-m-leak-off", "radial M~ vertex (zero toughness, all the fluid leaked off)",
    "R = 0.4502 (Q^2 t / C'^2)^(1/4), w0 = 1.0600 (mu'^4 Q^6 t / (E'^4 C'^2))^(1/16), "
    "w = w0 (1 - rho)^(5/8) (1 + rho)^0.397",
    "Madyarova 2003; Detournay 2016; Dontsov 2016, R. Soc. open sci. 3:160737 (w0 1.0574, profile); the "
    "similarity solution (hmatddm.analytical.viscous_leak_off.radial_m_leak_off_similarity)")
# the vertex of the toughness number whose side each K-K~ edge lies on (zero viscosity: the K
# side at any leak-off number)
LEAK_OFF_VERTEX = {"kgd-k-leak-off": "kgd-k", "radial-k-leak-off": "radial-k"}
# Where the M~ vertices apply (issue 36): the leak-off number C_m at or above which Dontsov's
# solution at any C_m (kgd-km-leak-off, radial-km-leak-off) is within 1% of the vertex's size
# (the convention of the K_m limits; the size error is about the stored share of the fluid,
# KGD C_m^(-3/2), half that for radial: 2% at C_m 7.2 (KGD) and 6.1 (radial)), and the
# toughness number of the M~ scaling at or below which the vertex holds (K_m~ = K_m for KGD,
# K_m C_m^(-1/8) = K' (t / (mu'^4 Q^2 E'^12 C'^2))^(1/16) for radial; at K_m~ = 1 Dontsov's
# opening is +2.8% (KGD) and +1% (radial) from the vertex's, its size unchanged).
M_LEAK_OFF_LIMITS = {"kgd": 10.4, "radial": 11.4}
M_LEAK_OFF_TOUGHNESS = 1.0

# what applies where a vertex does not: the transition solutions
_TRANSITION = {
    "radial": "radial-km (Dontsov 2016, in this package)",
    "kgd": "the plane-strain K-M transition (Dontsov 2017, or Garagash 2006's large-toughness expansion; "
           "not in this package)",
}
_LEAK_OFF_TRANSITION = {
    "radial": "radial-km-leak-off (Dontsov 2016 with leak-off, in this package)",
    "kgd": "kgd-km-leak-off (Dontsov 2017 with leak-off, in this package)",
}


def m_leak_off_toughness_number(toughness_numbers, leak_off_numbers, geometry):
    """The toughness number of the M~ scaling from the M scaling's ``K_m`` and ``C_m``:
    ``K_m`` itself for plane strain (both scale as ``K' / (E'^3 mu' Q)^(1/4)``), ``K_m
    C_m^(-1/8)`` for radial (``= K' (t / (mu'^4 Q^2 E'^12 C'^2))^(1/16)``, Madyarova 2003)."""
    _limits(geometry)
    k_m = np.asarray(toughness_numbers, float)
    if geometry == "kgd":
        return k_m
    return k_m * np.asarray(leak_off_numbers, float) ** -0.125


def _m_leak_off_applies(kind, toughness_numbers, leak_off_numbers):
    """``(applies, instead)`` of an M~ vertex: every ``C_m`` at or above
    :data:`M_LEAK_OFF_LIMITS` and every toughness number of the M~ scaling at or below
    :data:`M_LEAK_OFF_TOUGHNESS`."""
    geometry = "radial" if kind.startswith("radial") else "kgd"
    if leak_off_numbers is None:
        raise InputError(f"leak_off_numbers (C_m at the run's times) are needed to judge {kind!r}")
    c_m = np.ravel(np.asarray(leak_off_numbers, float))
    k_mt = np.ravel(m_leak_off_toughness_number(toughness_numbers, c_m, geometry))
    if c_m.min() >= M_LEAK_OFF_LIMITS[geometry] and k_mt.max() <= M_LEAK_OFF_TOUGHNESS:
        return True, None
    return False, _LEAK_OFF_TRANSITION[geometry]


def applicable_solution(kind, toughness_numbers, leak_off_numbers=None):
    """Whether the closed form ``kind`` applies at every toughness number of
    ``toughness_numbers`` (the run's times) and, for an M~ vertex, every leak-off number
    ``leak_off_numbers`` (``C_m`` at the same times), and, where it does not, the solution that
    does.

    Returns ``(applies, name_of_the_solution_that_applies)`` (the name is None when it
    applies). A vertex applies when every number is on its side of the limits
    (:data:`RADIAL_LIMITS`, :data:`KGD_LIMITS`; the M~ vertices :data:`M_LEAK_OFF_LIMITS` and
    :data:`M_LEAK_OFF_TOUGHNESS`); the transition solutions apply at any ``K_m`` and ``C_m``.
    """
    if kind not in SOLUTIONS:
        raise InputError(f"reference kind must be one of {sorted(SOLUTIONS)}, got {kind!r}")
    geometry = "radial" if kind.startswith("radial") else "kgd"
    if kind in ("radial-km", "radial-km-leak-off", "kgd-km-leak-off"):
        return True, None
    if kind in ("kgd-m-leak-off", "radial-m-leak-off"):
        return _m_leak_off_applies(kind, toughness_numbers, leak_off_numbers)
    kind = LEAK_OFF_VERTEX.get(kind, kind)  # a K-K~ edge: where the K-vertex's toughness number says K
    vertices = {vertex(float(k), geometry) for k in np.ravel(toughness_numbers)}
    wanted = kind.rsplit("-", 1)[1].upper()
    if vertices == {wanted}:
        return True, None
    if vertices == {"M" if wanted == "K" else "K"}:  # the other vertex all along
        other = SOLUTIONS[f"{kind.split('-')[0]}-{'m' if wanted == 'K' else 'k'}"]
        return False, f"{other.kind} ({other.name}; {other.source})"
    return False, _TRANSITION[geometry]
