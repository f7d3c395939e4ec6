"""Viscous fractures with Carter leak-off: the plane-strain M~ vertex and Dontsov's (2016)
radial solution at any toughness, viscosity and leak-off (the M, K, M~ and K~ vertices and
the transitions between them).

Notation as :mod:`.regimes`: ``E'``, ``K' = 4 (2/pi)^(1/2) K_Ic``, ``mu' = 12 mu``, Carter's
two-face coefficient ``C' = 2 C_L`` (m/s^1/2; in this project ``C' = c_l (sigma_0 - p_r)``,
:func:`.regimes.carter_prime`), ``Q`` the injection rate (per unit height into both wings
for plane strain).

**Plane-strain M~ vertex** (zero toughness, all the fluid leaked off; Adachi and Detournay
2008; Detournay 2016): mass balance alone fixes ``l = Q t^(1/2) / (pi C')``
(:func:`.leak_off.kgd_leak_off_half_length`), and the opening scales as
``W = (mu' Q^3 t / (E' C'^2))^(1/4)`` -- the m~ tip asymptote ``w ~ (C' mu' / E')^(1/4)
V^(1/8) s^(5/8)`` with ``V ~ l / t`` and ``s ~ l``. :func:`kgd_m_leak_off_vertex` gives the
inlet opening ``w(0) = 0.8165 W`` and the profile ``w(xi) = w(0) (1 + xi)^0.520 (1 -
xi)^(5/8)`` (``xi = x / l``) of Dontsov's approximate plane-strain solution (Dontsov 2017,
Int. J. Fract. 205:221, its M~ vertex; about 1% from the similarity solution, as its
M vertex ``w(0) = 1.1265 (mu' Q^3 t^2 / E')^(1/6)`` is 0.3% from Spence and Sharp's 1.1233).
The approximation carries no net pressure; the similarity solution of the vertex
(:func:`kgd_m_leak_off_similarity`, computed here: the flux is known once all the fluid
leaks, and the opening and pressure follow from Poiseuille's law and the crack's elasticity)
gives ``p(0) = 0.7515 P``, ``P = (E'^3 mu' C'^2 / (Q t))^(1/4)``, and ``w(0) = 0.81639 W``,
Dontsov's constant to 0.01%.

**Radial fracture, any regime** (:func:`radial_leak_off_transition`; Dontsov 2016, R. Soc.
open sci. 3:160737): the opening is the universal tip asymptote with leak-off (Dontsov and
Peirce 2015, :class:`~hmatddm.analytical.tip_leak_off.LeakOffTipAsymptote`) at the distance
``R`` of the well from the front and the front velocity ``V = alpha R / t``, spread as

    w(rho) = w_a (1 - rho)^delta ((1 + rho)/2)^lambda,

with ``delta = (1 + Delta)/2``, ``Delta = beta_m^3/3 f(K^, b C^, beta_m^3/3) (1 + b C^)`` the
local exponent of the asymptote (1/3 at m, 1/4 at m~, 0 at k; ``b = beta_c`` of
:mod:`.tip_asymptote`), ``lambda = 0.487 (1 - K^4) eta_0 + 0.397 (1 - K^4) (1 - eta_0) + 0.5
K^4`` (M, M~ and K vertices; ``eta_0`` the efficiency with ``lambda = 1/2``), and ``R`` from
the global mass balance with the leak-off of a front ``R ~ t^alpha``,

    Q t = 2 pi R^2 w_a int_0^1 rho (1 - rho)^delta ((1 + rho)/2)^lambda d rho
          + 4 pi alpha B(2 alpha, 3/2) C' t^(1/2) R^2,

``alpha = d ln R / d ln t`` (4/9 at M, 2/5 at K, 1/4 at M~ and K~) by a fixed point on the
solution. Zero leak-off gives :func:`.solutions.radial_transition`; at large leak-off the
M~ vertex ``R = 0.4502 (Q^2 t / C'^2)^(1/4)``, ``w(0) = 1.0574 (mu'^4 Q^6 t / (E'^4
C'^2))^(1/16)`` (Dontsov 2016's vertex solutions; the radius is the exact mass balance,
:func:`.leak_off.radial_leak_off_radius`; the opening's constant computed here is 1.0600,
:func:`radial_m_leak_off_similarity`). Dontsov quotes about 1% between the vertices.
"""
import numpy as np
from scipy import special

from .._validation import finite_array, positive_scalar
from ..errors import InputError
from .leak_off import kgd_leak_off_half_length
from .tip_asymptote import BETA_C, BETA_M3, _f

KGD_M_LEAK_OFF_OPENING = 0.8165  # w(0) / W of the plane-strain M~ vertex (Dontsov 2017)
KGD_M_LEAK_OFF_PRESSURE = 0.7515  # p(0) / P of the plane-strain M~ vertex (kgd_m_leak_off_similarity)
KGD_M_LEAK_OFF_LAMBDA = 0.520    # exponent of (1 + xi) of its profile (Dontsov 2017)
RADIAL_M_LEAK_OFF_OPENING = 1.0600  # w(0) / W of the radial M~ vertex (radial_m_leak_off_similarity)
RADIAL_M_LEAK_OFF_OPENING_DONTSOV = 1.0574  # Dontsov 2016's, 0.25% lower
_LAMBDA = {"M": 0.487, "M~": 0.397, "K": 0.5}  # exponents of (1 + rho), radial (Dontsov 2016)


def _times(t):
    t = finite_array("t", t)
    if t.size == 0 or np.any(t <= 0.0):
        raise InputError("t must hold times > 0 (s since the start of injection)")
    return t


def _carter(value):
    return positive_scalar("carter", value)


def kgd_m_leak_off_scale(t, injection_rate, viscosity, carter, material):
    """``W = (mu' Q^3 t / (E' C'^2))^(1/4)``, the opening scale of the plane-strain M~ vertex
    (m; an array like ``t``): ``Q`` per unit height, ``carter`` C' (m/s^1/2)."""
    t = _times(t)
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    return (mu_prime * q**3 * t / (material.plane_strain_modulus * _carter(carter) ** 2)) ** 0.25


def kgd_m_leak_off_vertex(t, injection_rate, viscosity, carter, material, pressure=False):
    """Half-length and inlet opening of the plane-strain M~ vertex (module docstring):
    ``l = Q t^(1/2) / (pi C')``, ``w(0) = 0.8165 (mu' Q^3 t / (E' C'^2))^(1/4)``. Returns
    ``(l, w0)``, arrays like ``t``; with ``pressure`` also the inlet net pressure ``p(0) =
    0.7515 (E'^3 mu' C'^2 / (Q t))^(1/4)`` (:func:`kgd_m_leak_off_similarity`)."""
    t = _times(t)
    scale = kgd_m_leak_off_scale(t, injection_rate, viscosity, carter, material)
    out = (kgd_leak_off_half_length(t, injection_rate, carter), KGD_M_LEAK_OFF_OPENING * scale)
    if not pressure:
        return out
    # P = (E'^3 mu' C'^2 / (Q t))^(1/4) = E' W C' / (Q t^(1/2))
    scale_p = material.plane_strain_modulus * scale * _carter(carter) / (float(injection_rate) * np.sqrt(t))
    return out + (KGD_M_LEAK_OFF_PRESSURE * scale_p,)


def kgd_m_leak_off_similarity(terms=8, points=31):
    """``(w(0) / W, p(0) / P)`` of the plane-strain M~ vertex from its similarity solution, an
    independent check of Dontsov's (2017) opening and the source of the net pressure
    (:data:`KGD_M_LEAK_OFF_PRESSURE`); ``W = (mu' Q^3 t / (E' C'^2))^(1/4)``, ``P = (E'^3 mu'
    C'^2 / (Q t))^(1/4)``.

    With everything leaked the flux is known: ``q(xi) = (Q/2) (1 - (2/pi) arcsin xi)`` (the
    front reached ``x`` at ``t xi^2``). In units ``l = E' = mu' = Q = 1`` (then ``w = a Omega``,
    ``p = b Pi`` with ``a = (mu' Q l^2 / E')^(1/4) = W / pi^(1/2)``, ``b = E' a / l = pi^(1/2)
    P``): Poiseuille ``Omega^3 Pi' = -q``; elasticity ``Omega(xi) = (4/pi) int_0^1 Pi(s) ln|(r_xi
    + r_s) / (r_xi - r_s)| ds`` (``r = (1 - xi^2)^(1/2)``, the symmetric crack); zero toughness
    ``int_0^1 Pi / r ds = 0``. ``Pi = c_0 + (1 - s^2)^(-3/8) sum_k c_k s^k`` (the m~ tip's
    ``Omega ~ (1 - xi)^(5/8)``; odd powers for the kink at the inlet, where the flux splits),
    ``terms`` of them, fitted by least squares to the Poiseuille residual at ``points``
    collocation points (graded towards the tip) and the toughness condition. 6, 8 and 10 terms
    agree to 2e-6 in the opening and 2e-5 in the pressure: ``w(0) / W = 0.81639`` (Dontsov's 0.8165, 0.01% apart), ``p(0) / P =
    0.75147``. About 1 s."""
    from scipy import integrate, optimize

    if int(terms) != terms or not 2 <= terms <= 16:
        raise InputError(f"terms must be an integer in [2, 16], got {terms!r}")
    if int(points) != points or not terms + 4 <= points <= 400:
        raise InputError(f"points must be an integer in [terms + 4, 400], got {points!r}")
    terms, points = int(terms), int(points)

    def kernel(x, s):
        a, b = np.sqrt(1.0 - x * x), np.sqrt(1.0 - s * s)
        return np.log(abs((a + b) / (a - b))) if a != b else 0.0

    def term(s, k):
        return 1.0 if k < 0 else (1.0 - s * s) ** -0.375 * s**k

    def slope(s, k):
        if k < 0:
            return 0.0
        return 0.75 * s * (1.0 - s * s) ** -1.375 * s**k + ((1.0 - s * s) ** -0.375 * k * s ** (k - 1) if k else 0.0)

    n_tip = max(points - points * 2 // 5, 4)
    xi = np.concatenate([np.linspace(1e-6, 0.9, points - n_tip), 1.0 - np.geomspace(0.09, 1e-4, n_tip)])
    ks = range(-1, terms)
    opening = np.array([[4.0 / np.pi * integrate.quad(lambda s: term(s, k) * kernel(x, s), 0.0, 1.0,
                                                      points=[x] if 0.0 < x < 1.0 else None, limit=400)[0]
                         for k in ks] for x in np.concatenate([xi, [0.0]])])
    toughness = np.array([integrate.quad(lambda s: term(s, k) / np.sqrt(1.0 - s * s), 0.0, 1.0, limit=400)[0]
                          for k in ks])
    gradient = np.array([[slope(x, k) for k in ks] for x in xi])
    flux = 0.5 * (1.0 - 2.0 / np.pi * np.arcsin(xi))

    def residual(c):
        omega = opening[:-1] @ c
        return np.concatenate([(np.sign(omega) * np.abs(omega) ** 3 * (gradient @ c) + flux) / flux,
                               [10.0 * (toughness @ c)]])

    guess = np.zeros(terms + 1)
    guess[:2] = 1.0, -0.5
    c = optimize.least_squares(residual, guess, xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=20000).x
    at_inlet = np.array([term(0.0, k) for k in ks])
    return float(opening[-1] @ c) / np.sqrt(np.pi), float(at_inlet @ c) * np.sqrt(np.pi)


def kgd_m_leak_off_profile(xi, t, injection_rate, viscosity, carter, material):
    """Opening of the plane-strain M~ vertex at ``xi = |x| / l`` in [0, 1] at one time ``t``:
    ``w(0) (1 + xi)^0.520 (1 - xi)^(5/8)`` (Dontsov 2017). Returns ``(l, w)``."""
    return _m_leak_off_profile("xi", "|x| / l", xi, t, kgd_m_leak_off_vertex, KGD_M_LEAK_OFF_LAMBDA,
                               (injection_rate, viscosity, carter, material), "kgd_m_leak_off_profile")


def _m_leak_off_profile(name, meaning, coordinate, t, vertex, exponent, arguments, caller):
    """``(size, w(0) (1 + x)^exponent (1 - x)^(5/8))`` of an M~ ``vertex`` at one time ``t``,
    ``coordinate`` (named ``name``, ``meaning``) checked in [0, 1]."""
    x = finite_array(name, coordinate)
    if np.any((x < 0.0) | (x > 1.0)):
        raise InputError(f"{name} must be in [0, 1] ({meaning})")
    if np.size(t) != 1:
        raise InputError(f"t must be a scalar > 0 for {caller}")
    size, w0 = (float(np.ravel(v)[0]) for v in vertex(np.ravel(t), *arguments))
    return size, w0 * (1.0 + x) ** exponent * (1.0 - x) ** 0.625


# --- Dontsov (2016, radial; 2017, plane strain) with leak-off -----------------------------------

def _exponent(k_hat, c_hat):
    """``delta = (1 + Delta)/2``, ``Delta`` the local exponent of the asymptote with leak-off."""
    k_hat = np.clip(k_hat, 0.0, 1.0)
    c_hat = np.maximum(c_hat, 0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        delta = BETA_M3 / 3.0 * _f(k_hat, BETA_C * c_hat, BETA_M3 / 3.0) * (1.0 + BETA_C * c_hat)
    return 0.5 * (1.0 + np.clip(np.nan_to_num(delta, nan=1.0 / 3.0), 1e-6, 1.0 / 3.0 - 1e-6))


def _upper(a, b):
    """``B_(1/2)(a, b) = int_(1/2)^1 u^(a-1) (1 - u)^(b-1) du``."""
    return special.beta(a, b) * (1.0 - special.betainc(a, b, 0.5))


class _Geometry:
    """What differs between Dontsov's radial (2016) and plane-strain (2017) solutions: the
    stored volume per ``w_a``, the leaked volume per ``C' t^(1/2)``, the exponents ``lambda``
    of the M, M~ and K vertices and the power of ``K^`` that weighs them, the range of
    ``alpha``."""

    def __init__(self, radial):
        self.radial = radial
        self.lambdas = (0.487, 0.397, 0.5) if radial else (0.588, 0.520, 0.5)
        self.k_power = 4 if radial else 3
        self.alpha_range = (0.25, 4.0 / 9.0) if radial else (0.5, 2.0 / 3.0)

    def stored(self, size, w_a, delta, lam):
        """Radial: ``2 pi R^2 w_a int_0^1 rho (1 - rho)^delta ((1 + rho)/2)^lambda d rho``;
        plane strain (both wings, per unit height): ``2 l w_a int_0^1 (1 - xi)^delta ((1 +
        xi)/2)^lambda d xi`` (incomplete beta functions, ``u = (1 + rho)/2``)."""
        if self.radial:
            factor = 2.0 ** (1.0 + delta) * (_upper(lam + 2.0, delta + 1.0) - _upper(lam + 1.0, delta + 2.0))
            return 2.0 * np.pi * size**2 * w_a * factor
        return 2.0 * size * w_a * 2.0 ** (1.0 + delta) * _upper(lam + 1.0, delta + 1.0)

    def leaked(self, size, alpha, carter, t):
        """Carter's leak-off of a front ``L ~ t^alpha`` (arrival ``t (r/L)^(1/alpha)``):
        radial ``4 pi alpha B(2 alpha, 3/2) C' t^(1/2) R^2``, plane strain ``4 alpha B(alpha,
        3/2) C' t^(1/2) l``."""
        if self.radial:
            return 4.0 * np.pi * alpha * special.beta(2.0 * alpha, 1.5) * carter * np.sqrt(t) * size**2
        return 4.0 * alpha * special.beta(alpha, 1.5) * carter * np.sqrt(t) * size


def _state(size, t, alpha, q, asymptote, geometry):
    """``(injected-volume ratio, w_a, delta, lambda, efficiency)`` of sizes ``size`` at ``t``."""
    speed = alpha * size / t
    w_a = asymptote.width(size, speed)
    k_hat = asymptote.k_prime * np.sqrt(size) / (asymptote.e_prime * w_a)
    c_hat = 2.0 * asymptote.carter * np.sqrt(size) / (np.sqrt(speed) * w_a)
    delta = _exponent(k_hat, c_hat)
    leaked = geometry.leaked(size, alpha, asymptote.carter, t)
    stored_half = geometry.stored(size, w_a, delta, 0.5)
    eta_0 = stored_half / (stored_half + leaked)
    weight = np.clip(k_hat, 0.0, 1.0) ** geometry.k_power
    lam_m, lam_mt, lam_k = geometry.lambdas
    lam = lam_m * (1.0 - weight) * eta_0 + lam_mt * (1.0 - weight) * (1.0 - eta_0) + lam_k * weight
    stored = geometry.stored(size, w_a, delta, lam)
    return (stored + leaked) / (q * t), w_a, delta, lam, stored / (stored + leaked)


def _size(t, q, asymptote, geometry, alpha, guess, iterations=16):
    """Sizes holding ``Q t`` (stored + leaked): secant iterations in ``ln L``."""
    def excess(log_size):
        return np.log(_state(np.exp(log_size), t, alpha, q, asymptote, geometry)[0])
    x0 = np.log(guess)
    f0 = excess(x0)
    x1 = x0 - f0 / 2.0
    for _ in range(iterations):
        f1 = excess(x1)
        slope = np.where(np.abs(x1 - x0) > 1e-14, (f1 - f0) / np.where(x1 != x0, x1 - x0, 1.0), 2.0)
        x0, f0, x1 = x1, f1, x1 - f1 / np.clip(slope, 1.0, 3.0)
    return np.exp(x1)


def _solution(t, q, viscosity, toughness, carter, material, geometry, guess, profile=None):
    """Dontsov's solution on ``geometry``: ``(size, opening at the well, efficiency)``, or with
    ``profile`` (``rho``, one time) ``(size, opening at rho)``."""
    from .tip_leak_off import LeakOffTipAsymptote

    asymptote = LeakOffTipAsymptote(material.plane_strain_modulus, toughness, 12.0 * viscosity, carter)
    low, high = geometry.alpha_range
    alpha, step = np.full(t.shape, high), 0.01
    for _ in range(4):  # alpha from the sizes a little before and after t
        before = _size(t * np.exp(-step), q, asymptote, geometry, alpha, guess * np.exp(-step * alpha))
        after = _size(t * np.exp(step), q, asymptote, geometry, alpha, guess * np.exp(step * alpha))
        alpha = np.clip(np.log(after / before) / (2.0 * step), low, high)
    size = _size(t, q, asymptote, geometry, alpha, guess)
    _, w_a, delta, lam, efficiency = _state(size, t, alpha, q, asymptote, geometry)
    if profile is not None:
        return size, w_a * (1.0 - profile) ** delta * (0.5 * (1.0 + profile)) ** lam
    return size, w_a * 0.5**lam, efficiency


def _inputs(t, injection_rate, viscosity, fracture_toughness, carter):
    t = _times(t)
    return (t, positive_scalar("injection_rate", injection_rate), positive_scalar("viscosity", viscosity),
            positive_scalar("fracture_toughness", fracture_toughness), _carter(carter))


def radial_leak_off_transition(t, injection_rate, viscosity, fracture_toughness, carter, material, profile=None):
    """Radius, opening at the well and efficiency (stored / injected) of a radial fracture at
    any toughness, viscosity and Carter leak-off: Dontsov (2016), module docstring.

    ``carter`` C' = 2 C_L (m/s^1/2, > 0; :func:`radial_transition` is the zero-leak-off
    case). Returns ``(radius, max_width, efficiency)``, arrays like ``t`` (s, > 0); with
    ``profile`` (``rho``, one time): ``(radius, width at rho)``, :func:`radial_leak_off_profile`."""
    from .solutions import radial_k_vertex, radial_m_vertex
    from .leak_off import radial_leak_off_radius

    t, q, viscosity, toughness, carter = _inputs(t, injection_rate, viscosity, fracture_toughness, carter)
    shape, t = t.shape, t.ravel()
    guess = np.minimum(np.minimum(radial_k_vertex(t, q, toughness, material)[0],
                                  radial_m_vertex(t, q, viscosity, material)[0]),
                       radial_leak_off_radius(t, q, carter))
    out = _solution(t, q, viscosity, toughness, carter, material, _Geometry(True), guess, profile)
    return out if profile is not None else tuple(v.reshape(shape) for v in out)


def kgd_leak_off_transition(t, injection_rate, viscosity, fracture_toughness, carter, material, profile=None):
    """Half-length, inlet opening and efficiency of a plane-strain fracture at any toughness,
    viscosity and Carter leak-off: Dontsov (2017, Int. J. Fract. 205:221), the plane-strain
    form of the module's radial solution -- ``Q t = 2 l w_a int_0^1 (1 - xi)^delta ((1 +
    xi)/2)^lambda d xi + 4 alpha B(alpha, 3/2) C' t^(1/2) l`` (``Q`` per unit height into both
    wings), ``lambda`` 0.588, 0.520 and 0.5 at the M, M~ and K vertices weighed by ``K^3``,
    ``alpha`` between 1/2 and 2/3. Returns ``(l, w0, efficiency)``, arrays like ``t``; with
    ``profile`` (``xi``, one time) ``(l, width at xi)``."""
    from .solutions import kgd_k_vertex, kgd_m_vertex

    t, q, viscosity, toughness, carter = _inputs(t, injection_rate, viscosity, fracture_toughness, carter)
    shape, t = t.shape, t.ravel()
    guess = np.minimum(np.minimum(kgd_k_vertex(t, q, toughness, material)[0],
                                  kgd_m_vertex(t, q, viscosity, material)[0]),
                       kgd_leak_off_half_length(t, q, carter))
    out = _solution(t, q, viscosity, toughness, carter, material, _Geometry(False), guess, profile)
    return out if profile is not None else tuple(v.reshape(shape) for v in out)


def radial_leak_off_profile(rho, t, injection_rate, viscosity, fracture_toughness, carter, material):
    """Opening ``w_a (1 - rho)^delta ((1 + rho)/2)^lambda`` of :func:`radial_leak_off_transition`
    at ``rho = r / R`` in [0, 1] at one time ``t``. Returns ``(R, w)``."""
    rho = finite_array("rho", rho)
    if np.any((rho < 0.0) | (rho > 1.0)):
        raise InputError("rho must be in [0, 1] (r / R)")
    if np.size(t) != 1:
        raise InputError("t must be a scalar > 0 for radial_leak_off_profile")
    radius, width = radial_leak_off_transition(np.ravel(t), injection_rate, viscosity, fracture_toughness, carter,
                                               material, profile=rho)
    return float(radius[0]), width


def radial_m_leak_off_vertex(t, injection_rate, viscosity, carter, material):
    """The radial M~ vertex: ``R = 0.4502 (Q^2 t / C'^2)^(1/4)`` (the exact mass balance,
    :func:`.leak_off.radial_leak_off_radius`) and ``w(0) = 1.0600 (mu'^4 Q^6 t / (E'^4
    C'^2))^(1/16)`` (:func:`radial_m_leak_off_similarity`; Dontsov 2016's approximate solution
    gives 1.0574). Returns ``(R, w0)``, arrays like ``t``."""
    from .leak_off import radial_leak_off_radius

    t = _times(t)
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    e_prime = material.plane_strain_modulus
    c = _carter(carter)
    return radial_leak_off_radius(t, q, c), RADIAL_M_LEAK_OFF_OPENING * (mu_prime**4 * q**6 * t /
                                                                          (e_prime**4 * c * c)) ** (1.0 / 16.0)


def radial_m_leak_off_similarity(terms=6, logs=1):
    """``w(0) / W`` of the radial M~ vertex from its similarity solution, ``W = (mu'^4 Q^6 t /
    (E'^4 C'^2))^(1/16)``: the check of :data:`RADIAL_M_LEAK_OFF_OPENING`, written like
    :func:`kgd_m_leak_off_similarity`.

    All the fluid leaked, the front reached ``r`` at ``t rho^4``: the flux per unit
    circumference is ``q = Q F(rho) / (2 pi R rho)``, ``F = 1 - (2/pi) arcsin rho^2``. In units
    ``R = E' = mu' = 1`` and ``p = b Pi``, ``b = (E'^3 mu' Q / R^3)^(1/4)``: Poiseuille ``G^3 Pi'
    = -F / (2 pi rho)`` with Sneddon's opening ``G(rho) = (8/pi) int_rho^1 x f(x) / (x^2 -
    rho^2)^(1/2) dx``, ``f(x) = int_0^1 s Pi(s x) / (1 - s^2)^(1/2) ds``; zero toughness ``f(1) =
    0``; ``w = (R b / E') G``, so ``w(0) / W = 0.4502^(1/4) G(0)``. ``Pi = -B ln rho + c_0 + (1 -
    rho^2)^(-3/8) sum_k c_k rho^(2k)`` (the source's log; the m~ tip's ``(1 - rho)^(-3/8)``;
    ``terms`` of them) plus ``rho^2 ln rho`` and ``rho^4 ln rho`` (``logs`` of them, the
    source's next terms), fitted by least squares to the Poiseuille residual at 34 points
    (graded towards both ends) and the toughness condition. 6, 8 and 10 terms with one or two
    log terms give 1.05991, 1.05994 and 1.05996 (the residual 0.6%, 0.4%, 0.3%; ``B`` is ``1 /
    (2 pi G(0)^3)`` to 0.5%, 0.4%, 0.3%). About 5 s."""
    from scipy import integrate, optimize

    if int(terms) != terms or not 2 <= terms <= 12:
        raise InputError(f"terms must be an integer in [2, 12], got {terms!r}")
    if logs not in (0, 1, 2):
        raise InputError(f"logs must be 0, 1 or 2, got {logs!r}")

    def basis(k, x):  # k: -1 log source, 0 constant, 1.. tip terms, -2 / -3 rho^2 / rho^4 ln rho
        if k == -1:
            return -np.log(x)
        if k in (-2, -3):
            return x ** (-2 * k - 2) * np.log(x) if x > 0.0 else 0.0
        return 1.0 if k == 0 else (1.0 - x * x) ** -0.375 * x ** (2 * k - 2)

    def slope(k, x):
        if k == -1:
            return -1.0 / x
        if k in (-2, -3):
            m = -2 * k - 2
            return m * x ** (m - 1) * np.log(x) + x ** (m - 1)
        if k == 0:
            return 0.0
        m = 2 * k - 2
        return 0.75 * x * (1.0 - x * x) ** -1.375 * x**m + ((1.0 - x * x) ** -0.375 * m * x ** (m - 1) if m else 0.0)

    def inner(k, x):  # f(x) of one basis function, s = sin(theta)
        if k == -1:
            return np.log(2.0) - 1.0 - np.log(x)
        return integrate.quad(lambda th: np.sin(th) * basis(k, np.sin(th) * x), 0.0, 0.5 * np.pi, limit=200)[0]

    def opening(k, r):  # x = (r^2 + u^2)^(1/2)
        return 8.0 / np.pi * integrate.quad(lambda u: inner(k, np.sqrt(r * r + u * u)), 0.0, np.sqrt(1.0 - r * r),
                                            limit=200)[0]

    ks = [-1, 0] + list(range(1, terms + 1)) + [-2, -3][:logs]
    rho = np.concatenate([np.geomspace(1e-3, 0.05, 6), np.linspace(0.08, 0.9, 16), 1.0 - np.geomspace(0.08, 2e-4, 12)])
    with np.errstate(all="ignore"):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", integrate.IntegrationWarning)
            openings = np.array([[opening(k, r) for k in ks] for r in np.concatenate([rho, [0.0]])])
            toughness = np.array([inner(k, 1.0 - 1e-15) for k in ks])
    slopes = np.array([[slope(k, r) for k in ks] for r in rho])
    target = (1.0 - 2.0 / np.pi * np.arcsin(rho**2)) / (2.0 * np.pi * rho)

    def residual(c):
        g = openings[:-1] @ c
        return np.concatenate([(np.sign(g) * np.abs(g) ** 3 * (slopes @ c) + target) / target, [10.0 * (toughness @ c)]])

    guess = np.zeros(len(ks))
    guess[:3] = 0.07, 0.5, 0.3
    c = optimize.least_squares(residual, guess, xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=20000).x
    return float((np.sqrt(2.0) / np.pi) ** 0.25 * (openings[-1] @ c))


def radial_m_leak_off_profile(rho, t, injection_rate, viscosity, carter, material):
    """Opening of the radial M~ vertex at ``rho = r / R`` in [0, 1] at one time ``t``: ``w(0)
    (1 - rho)^(5/8) (1 + rho)^0.397`` (Dontsov 2016: the m~ tip asymptote times ``((1 +
    rho)/2)^lambda``, ``lambda`` = 0.397 at M~). Returns ``(R, w)``."""
    return _m_leak_off_profile("rho", "r / R", rho, t, radial_m_leak_off_vertex, 0.397,
                               (injection_rate, viscosity, carter, material), "radial_m_leak_off_profile")


__all__ = ["kgd_m_leak_off_scale", "radial_m_leak_off_profile", "radial_m_leak_off_similarity",
           "RADIAL_M_LEAK_OFF_OPENING", "kgd_m_leak_off_vertex", "kgd_m_leak_off_similarity", "KGD_M_LEAK_OFF_PRESSURE", "kgd_m_leak_off_profile", "radial_leak_off_transition",
           "kgd_leak_off_transition",
           "radial_leak_off_profile",
           "radial_m_leak_off_vertex", "KGD_M_LEAK_OFF_OPENING"]
