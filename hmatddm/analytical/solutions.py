"""Closed-form reference solutions (SI units, tension positive, opening positive).

Static cracks:
* :func:`griffith_opening`: plane-strain line crack of half length ``a`` under uniform
  net load (pressure for opening, remote shear for slip).
* :func:`sneddon_opening`, :func:`sneddon_volume`: penny-shaped crack of radius ``c``
  under uniform pressure (Sneddon 1946).
* :func:`sneddon_axis_stress`: stresses on the axis of a pressurised penny crack,
  ref. Eqs 5.30-5.32, and their mean (ref. Fig. 5.15).

Growing hydraulic fractures, zero leak-off (ref. Sec. 4.5):
* toughness dominated (K-vertex, exact): :func:`radial_k_vertex`, :func:`kgd_k_vertex`;
* viscosity dominated (M-vertex): :func:`radial_m_vertex` (ref. Eqs 4.62-4.63),
  :func:`radial_m_vertex_profile` and :func:`radial_m_vertex_pressure` (Savitski and
  Detournay 2002), :func:`kgd_m_vertex` and :func:`kgd_m_vertex_profile` (Adachi and
  Detournay 2002);
* which vertex applies: :func:`radial_regime`, :func:`kgd_regime` (dimensionless toughness).
* between the vertices (any ``K_m``): :func:`radial_transition` and
  :func:`radial_transition_profile`, Dontsov's (2016) approximate solution without leak-off.

Comparing a discrete run with them:
* :func:`well_element_radius`: the radius at which the pressure of a finite-volume injection
  element on a square grid equals the radial (log) solution (Peaceman 1983).

Length (over ~400 lines): a catalogue of independent closed-form solutions, each a few
lines with its equation; tests, benchmarks and scenes look them up in one place.
"""
import functools

import numpy as np
from scipy import special

from .._validation import finite_array, finite_scalar, positive_scalar
from ..errors import InputError
from .m_vertex_numeric import (KGD_M_GAMMA_ACCURATE, KGD_M_OPENING_ACCURATE, KGD_M_PRESSURE_ACCURATE, MVertexSolution,
                               RADIAL_M_GAMMA_ACCURATE, RADIAL_M_OPENING_ACCURATE)


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
    Detournay 2002), with the constants computed to 1e-7 by
    :mod:`~hmatddm.analytical.m_vertex_numeric`: ``R = 0.6978376 (E' Q^3 t^4 / mu')^(1/9)``,
    ``w(0) = 1.1932560 (mu'^2 Q^3 t / E'^2)^(1/9)``. (Ref. Eqs 4.62-4.63 print Dontsov's
    approximate 0.6944 and 1.1901, 0.49% and 0.26% low; Savitski and Detournay's truncated
    series 0.6955 and 1.1977, -0.34% and +0.37%: issue 39, benchmarks/RESULTS.md.)
    Returns ``(radius, max_width)``; the net pressure is log-singular at
    the injection point and is not a single number: see :func:`radial_m_vertex_profile` and
    :func:`radial_m_vertex_pressure` for the profiles (and the meaning of ref. Eq. 4.64)."""
    t = np.asarray(t, dtype=float)
    e_prime = material.plane_strain_modulus
    mu_prime = 12.0 * finite_scalar("viscosity", viscosity)
    q = injection_rate
    radius = RADIAL_M_GAMMA_ACCURATE * (q**3 * e_prime * t**4 / mu_prime) ** (1.0 / 9.0)
    max_width = RADIAL_M_OPENING_ACCURATE * (mu_prime**2 * q**3 * t / e_prime**2) ** (1.0 / 9.0)
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


def _positive_times(t):
    """``t`` as a float array (any shape), every entry finite and > 0."""
    t = finite_array("t", t)
    if np.any(t <= 0.0):
        raise InputError(f"t must be > 0 (time since the start of injection), got min {t.min()}")
    return t


def _viscosity_scales(t, injection_rate, viscosity, material, length_exponent):
    """``(E', eps, L)`` of the viscosity (M) scaling of Savitski and Detournay (2002) and
    Adachi and Detournay (2002): ``eps = (mu'/(E' t))^(1/3)`` and
    ``L = (E' Q^3 t^4 / mu')^length_exponent`` (1/9 radial, 1/6 plane strain), with
    ``mu' = 12 mu``. Widths scale as ``eps L``, pressures as ``eps E'``."""
    t = _positive_times(t)
    q = positive_scalar("injection_rate", injection_rate)
    mu_prime = 12.0 * positive_scalar("viscosity", viscosity)
    e_prime = material.plane_strain_modulus
    eps = (mu_prime / (e_prime * t)) ** (1.0 / 3.0)
    length = (e_prime * q**3 * t**4 / mu_prime) ** length_exponent
    return e_prime, eps, length


def _open_interval(name, value, low, low_closed):
    """Array of normalised positions; ``low <= value < 1`` (or ``low < value < 1``)."""
    value = finite_array(name, value)
    bad = (value >= 1.0) | ((value < low) if low_closed else (value <= low))
    if np.any(bad):
        interval = f"[{low:g}, 1)" if low_closed else f"({low:g}, 1)"
        raise InputError(f"{name} must be in {interval} (inside the fracture), got "
                         f"{value[bad].ravel()[0]}")
    return value


@functools.lru_cache(maxsize=2)
def _computed_m_vertex(radial):
    """The M-vertex similarity solution computed once (32 points: constants to 1e-9)."""
    return MVertexSolution(radial, 32)


# The published zero-order series below are no longer what the profile functions return
# (the computed solution is, issue 39); they are kept for benchmarks/bench_m_vertex.py,
# which measures how far they are from it.
# Savitski and Detournay (2002), Int. J. Solids Struct. 39:6311-6337, zero-toughness
# (M-vertex) solution, Eqs for Omega_m0 and Pi_m0 with its published constants.
_RADIAL_M_GAMMA = 0.6955  # (benchmarks/bench_m_vertex.py)
_RADIAL_M_A1 = 0.3581
_RADIAL_M_B = 0.09269
_RADIAL_M_C1 = 0.6846
_RADIAL_M_C2 = 0.07098
_RADIAL_M_OMEGA1 = 2.479


def _radial_m_pressure_scaled(rho):
    """Pi_m0(rho) = A1 [omega1 - 2 / (3 (1 - rho)^(1/3))] - B [ln(rho/2) + 1]; +inf at rho = 0."""
    with np.errstate(divide="ignore"):
        log_term = np.log(rho / 2.0)
    return (_RADIAL_M_A1 * (_RADIAL_M_OMEGA1 - 2.0 / (3.0 * np.cbrt(1.0 - rho)))
            - _RADIAL_M_B * (log_term + 1.0))


def _radial_m_width_scaled(rho):
    """Omega_m0(rho) = gamma_m0 * Omega_bar(rho): the opening (in units of eps L) that
    elasticity gives for Pi_m0 on a disc of radius gamma_m0 L."""
    polynomial = np.sqrt(70.0) / 3.0 * _RADIAL_M_C1 + 4.0 * np.sqrt(5.0) / 9.0 * _RADIAL_M_C2 * (13.0 * rho - 6.0)
    cone = np.sqrt(1.0 - rho * rho) - rho * np.arccos(rho)
    return _RADIAL_M_GAMMA * (polynomial * (1.0 - rho) ** (2.0 / 3.0) + 8.0 / np.pi * _RADIAL_M_B * cone)


def radial_m_vertex_profile(rho, t, injection_rate, viscosity, material):
    """Opening and net pressure of a viscosity-dominated radial (penny) hydraulic fracture,
    zero toughness and zero leak-off: the M-vertex similarity solution (Savitski and
    Detournay 2002), computed to 1e-7 by :mod:`~hmatddm.analytical.m_vertex_numeric`.

    ``rho = r / R`` in ``[0, 1)`` with ``R = 0.6978376 L``; ``L = (E' Q^3 t^4 / mu')^(1/9)``,
    ``eps = (mu' / (E' t))^(1/3)``, ``mu' = 12 mu``. Then ``w = eps L Omega(rho)`` and
    ``p_net = eps E' Pi(rho)``. The width has the viscous tip asymptote ``(1 - rho)^(2/3)``;
    the pressure goes to ``-inf`` as ``(1 - rho)^(-1/3)`` at the tip and to ``+inf`` as
    ``-B ln rho`` (``B = 0.0936740``) at the injection point (a point source): at ``rho = 0``
    the pressure returned is ``+inf``.

    The published forms differ from it (benchmarks/RESULTS.md, "Issue 39: the M vertices
    computed to 1e-4"): Savitski and Detournay's zero-order series (``gamma = 0.6955``,
    ``Omega(0) = 1.1977``; its opening is what elasticity gives for its pressure only to 0.2%
    at ``rho <= 0.7`` and 2% at 0.97) and Dontsov's width ``1.1901 eps L (1 + rho)^0.487 (1 -
    rho)^(2/3)`` on a radius ``0.6944 L`` (ref. Eqs 4.62-4.64; Eq. 4.64's constant ``2.4019 =
    2^0.487 * 1.1901 / 0.6944`` is ``E' w_tip / R`` in units of ``eps E'``, and the ``(0.397,
    5/8)`` printed there are the M-tilde exponents of his code).

    Returns ``(width, net_pressure)`` shaped like ``rho``; ``t`` must be a scalar > 0.
    """
    rho = _open_interval("rho", rho, 0.0, low_closed=True)
    e_prime, eps, length = _viscosity_scales(positive_scalar("t", t), injection_rate, viscosity,
                                             material, 1.0 / 9.0)
    solution = _computed_m_vertex(True)
    return eps * length * solution.opening(rho), eps * e_prime * solution.pressure(rho)


def well_element_radius(element_size):
    """Peaceman's equivalent radius ``r_eq = exp(-pi/2) h ~ 0.208 h`` of an injection element.

    A point source in one cell of a square grid of side ``h``, with two-point fluxes between
    edge neighbours (:class:`hmatddm.flow.LubricationModel`) and a locally uniform opening,
    gives that cell the pressure of the radial flow ``p(r) = p_0 - q mu' ln(r) / (2 pi w^3)``
    at ``r = r_eq`` (Peaceman 1983, SPE J. 23(3):531-543, the infinite-grid value; his
    earlier numerical 0.2 h). The injection element's pressure of a simulation is therefore
    the net pressure of a log-singular solution such as :func:`radial_m_vertex_pressure` at
    ``rho = r_eq / R``, not at the radius ``h / sqrt(pi)`` of a disc of the element's area
    (which reads the M-vertex about 10% lower at h = 1 m, 50 s of ref. Table 4.1).
    ``tests/analytical/test_analytical.py`` checks it against the project's flow model.
    """
    return np.exp(-0.5 * np.pi) * positive_scalar("element_size", element_size)


def radial_m_vertex_pressure(rho, t, injection_rate, viscosity, material):
    """Net pressure ``eps E' Pi(rho)`` of the radial M-vertex at ``rho = r/R`` in ``[0, 1)``
    (see :func:`radial_m_vertex_profile`). The injection point is a log singularity:
    ``p ~ -B eps E' ln(rho)`` as ``rho -> 0`` and ``+inf`` is returned at ``rho = 0``; there is
    no finite "wellbore pressure" without a wellbore radius ``r_w`` (use ``rho = r_w / R``)."""
    return radial_m_vertex_profile(rho, t, injection_rate, viscosity, material)[1]


# Adachi and Detournay (2002), Int. J. Numer. Anal. Meth. Geomech. 26:579-604, Newtonian
# fluid (n = 1): plane-strain zero-toughness solution as a series of exact elastic pairs
# (opening Omega*_j, pressure Pi*_j) plus the point-source pair (Omega**, Pi**).
_KGD_M_GAMMA = 0.61524
_KGD_M_B = 0.06858
_KGD_M_A = (1.61750, 0.39650, 1.00297e-2, 1.06179e-2, -2.97947e-3, -0.74268e-3, -1.34675e-3)
_KGD_ALPHA = 2.0 / 3.0  # viscous tip exponent


def _kgd_m_width_bar(xi):
    """Omega_bar = sum A_j (1 - xi^2)^(2/3) C_(2j-2)^(1/6)(xi) + B Omega**(xi),
    Omega** = 4 sqrt(1 - xi^2) + 2 xi^2 ln|(1 - sqrt(1 - xi^2)) / (1 + sqrt(1 - xi^2))|."""
    root = np.sqrt(1.0 - xi * xi)
    # (1 - root) / (1 + root) = xi^2 / (1 + root)^2, written so to avoid cancellation at small xi
    with np.errstate(divide="ignore", invalid="ignore"):
        log_term = np.where(xi == 0.0, 0.0, 4.0 * xi * xi * np.log(np.abs(xi) / (1.0 + root)))
    point_source = 4.0 * root + log_term
    width = _KGD_M_B * point_source
    for j, a in enumerate(_KGD_M_A, start=1):
        width = width + a * (1.0 - xi * xi) ** _KGD_ALPHA * special.eval_gegenbauer(2 * j - 2, _KGD_ALPHA - 0.5, xi)
    return width


def _kgd_m_pressure_scaled(xi):
    """Pi = sum A_j Pi*_j(xi) + B (2 - pi |xi|), Pi*_j the elastic pressures of Omega*_j."""
    a, x2 = _KGD_ALPHA, xi * xi
    pressure = _KGD_M_B * (2.0 - np.pi * np.abs(xi))
    pressure = pressure + _KGD_M_A[0] * a / (2.0 * np.pi) * special.beta(0.5, a) * special.hyp2f1(0.5 - a, 1.0, 0.5, x2)
    for j, coefficient in enumerate(_KGD_M_A[1:], start=2):
        prefactor = (2 * a - 1) * (2 * j - 1) / (4.0 * np.pi * (j - 1 + a)) * special.beta(0.5 - j, a + j)
        pressure = pressure + coefficient * prefactor * (a * x2 * special.hyp2f1(2.5 - j - a, j, 1.5, x2)
                                                         - 0.5 * special.hyp2f1(1.5 - j - a, j - 1, 0.5, x2))
    return pressure


def kgd_m_vertex_profile(xi, t, injection_rate, viscosity, material):
    """Opening and net pressure of a viscosity-dominated plane-strain (KGD) hydraulic fracture,
    zero toughness and zero leak-off (Spence and Sharp 1985; Adachi and Detournay 2002): the
    similarity solution computed to 1e-7 by :mod:`~hmatddm.analytical.m_vertex_numeric`.

    ``injection_rate`` ``Q`` is per unit height and feeds both wings (``Q/2`` each).
    ``xi = x / l`` in ``(-1, 1)`` with ``l = 0.6154113 L``, ``L = (E' Q^3 t^4 / mu')^(1/6)``,
    ``eps = (mu' / (E' t))^(1/3)``, ``mu' = 12 mu``; ``w = eps L Omega(|xi|)``,
    ``p_net = eps E' Pi(|xi|)``. The pressure is finite at the injection point (a kink,
    ``Pi(0) = 0.5448171``) and goes to ``-inf`` as ``(1 - |xi|)^(-1/3)`` at the tips. Adachi
    and Detournay's seven-term series (``gamma = 0.61524``; its volume balance asks for
    0.6162) is 0.03% short in length and 0.23% low in opening at the source.

    Returns ``(width, net_pressure)`` shaped like ``xi``; ``t`` must be a scalar > 0.
    """
    xi = _open_interval("xi", xi, -1.0, low_closed=False)
    e_prime, eps, length = _viscosity_scales(positive_scalar("t", t), injection_rate, viscosity,
                                             material, 1.0 / 6.0)
    solution = _computed_m_vertex(False)
    return eps * length * solution.opening(np.abs(xi)), eps * e_prime * solution.pressure(np.abs(xi))


def kgd_m_vertex(t, injection_rate, viscosity, material):
    """Viscosity-dominated plane-strain (KGD) fracture, zero toughness and leak-off; see
    :func:`kgd_m_vertex_profile`. ``injection_rate`` is per unit height into both wings.

    Returns ``(half_length, max_width, net_pressure)`` (arrays like ``t``) with the
    opening and net pressure taken at the injection point, where the opening is largest and
    the (finite) pressure is highest::

        l    = 0.6154113 (E' Q^3 t^4 / mu')^(1/6)
        w(0) = 1.1258346 (mu' Q^3 t^2 / E')^(1/6)
        p(0) = 0.5448171 (mu' E'^2 / t)^(1/3)

    (``mu' = 12 mu``; the constants computed to 1e-7 by
    :mod:`~hmatddm.analytical.m_vertex_numeric`; the seven-term series of Adachi and
    Detournay gives 0.61524, 1.1233 and 0.5443: -0.03%, -0.23%, -0.10%).
    """
    e_prime, eps, length = _viscosity_scales(t, injection_rate, viscosity, material, 1.0 / 6.0)
    return (KGD_M_GAMMA_ACCURATE * length, KGD_M_OPENING_ACCURATE * eps * length,
            KGD_M_PRESSURE_ACCURATE * eps * e_prime)


def radial_regime(t, injection_rate, viscosity, fracture_toughness, material):
    """Dimensionless toughness ``K_m = K' (t^2 / (mu'^5 Q^3 E'^13))^(1/18)`` of a radial
    fracture (Savitski and Detournay 2002), zero leak-off; ``K' = 4 (2/pi)^(1/2) K_Ic``,
    ``mu' = 12 mu``. It grows as ``t^(1/9)``: a radial fracture starts viscosity dominated
    and ends toughness dominated. ``K_m <= 1``: M-vertex (:func:`radial_m_vertex`,
    :func:`radial_m_vertex_profile`); ``K_m >= 3.5``: K-vertex (:func:`radial_k_vertex`);
    in between the fracture is in transition and neither vertex is exact
    (:func:`radial_transition`, Dontsov 2016). ``K_m = (t / t_mk)^(1/9)`` with Dontsov's transition time
    ``t_mk = (mu'^5 E'^13 Q^3 / K'^18)^(1/2)``. Returns an array like ``t``; the same as
    :func:`hmatddm.analytical.regimes.radial_toughness_number`, where the limits live."""
    from .regimes import radial_toughness_number

    return radial_toughness_number(t, injection_rate, viscosity, fracture_toughness, material)


def kgd_regime(injection_rate, viscosity, fracture_toughness, material):
    """Dimensionless toughness ``K_m = K' / (E'^3 mu' Q)^(1/4)`` of a plane-strain (KGD)
    fracture, zero leak-off (Detournay 2004; Adachi and Detournay 2002), ``Q`` per unit
    height into both wings. It does not depend on time: ``K_m <= 1`` M-vertex
    (:func:`kgd_m_vertex`), ``K_m >= 4`` K-vertex (:func:`kgd_k_vertex`). The same as
    :func:`hmatddm.analytical.regimes.kgd_toughness_number`."""
    from .regimes import kgd_toughness_number

    return kgd_toughness_number(injection_rate, viscosity, fracture_toughness, material)


# --- the K-M transition of a radial fracture (Dontsov 2016) ----------------------------------
_LAMBDA_M, _LAMBDA_K = 0.487, 0.5  # exponents of (1 + rho) at the M and K vertices (Dontsov 2016)


def _transition_shape(k_hat):
    """Exponents ``(delta, lambda)`` of ``w = w_a (1 - rho)^delta ((1 + rho)/2)^lambda`` for the
    tip-asymptote toughness ratio ``K^ = K' R^(1/2) / (E' w_a)`` (no leak-off): ``delta = (1 +
    Delta)/2`` with the local exponent ``Delta = (1 - K^3)/3`` of the universal asymptote (Dontsov
    and Peirce 2015), ``lambda = 0.487 (1 - K^4) + 0.5 K^4``."""
    k_hat = np.clip(k_hat, 0.0, 1.0)
    delta = 0.5 * (1.0 + (1.0 - k_hat**3) / 3.0)
    return delta, _LAMBDA_M * (1.0 - k_hat**4) + _LAMBDA_K * k_hat**4


def _transition_volume_factor(delta, lam):
    """``int_0^1 rho (1 - rho)^delta ((1 + rho)/2)^lambda d rho`` in incomplete beta functions
    (``u = (1 + rho)/2``): ``2^(1+delta) [B_(1/2)(lambda+2, delta+1) - B_(1/2)(lambda+1, delta+2)]``
    with ``B_x(a, b) = int_x^1 u^(a-1) (1 - u)^(b-1) du``."""
    def upper(a, b):
        return special.beta(a, b) * (1.0 - special.betainc(a, b, 0.5))
    return 2.0 ** (1.0 + delta) * (upper(lam + 2.0, delta + 1.0) - upper(lam + 1.0, delta + 2.0))


def _transition_state(radius, t, alpha, asymptote):
    """``(volume, w_a, delta, lambda)`` (arrays) of the approximate solutions of radii ``radius``
    at times ``t`` whose radii grow as ``t^alpha`` (front velocity ``alpha R / t``)."""
    w_a = asymptote.width(radius, alpha * radius / t)
    k_hat = asymptote.k_prime * np.sqrt(radius) / (asymptote.e_prime * w_a)
    delta, lam = _transition_shape(k_hat)
    return 2.0 * np.pi * radius**2 * w_a * _transition_volume_factor(delta, lam), w_a, delta, lam


def _transition_radius(t, q, asymptote, alpha, guess, iterations=12):
    """Radii (arrays like ``t``) holding ``Q t``: secant iterations on ``ln V(ln R) = ln(Q t)``
    from ``guess`` (``V`` grows as ``R^2.5`` to ``R^(8/3)``, smoothly: a few iterations reach
    round-off)."""
    def excess(log_radius):
        return np.log(_transition_state(np.exp(log_radius), t, alpha, asymptote)[0] / (q * t))
    x0 = np.log(guess)
    f0 = excess(x0)
    x1 = x0 - f0 / 2.5
    for _ in range(iterations):
        f1 = excess(x1)
        slope = np.where(np.abs(x1 - x0) > 1e-14, (f1 - f0) / np.where(x1 != x0, x1 - x0, 1.0), 2.5)
        slope = np.clip(slope, 2.0, 3.0)
        x0, f0, x1 = x1, f1, x1 - f1 / slope
    return np.exp(x1)


def _radial_transition(t, injection_rate, viscosity, fracture_toughness, material):
    """``(radius, w_a, delta, lambda)`` of :func:`radial_transition_profile` at times ``t`` (1D)."""
    from .tip_asymptote import TipAsymptote

    q = positive_scalar("injection_rate", injection_rate)
    viscosity = positive_scalar("viscosity", viscosity)
    toughness = positive_scalar("fracture_toughness", fracture_toughness)
    asymptote = TipAsymptote(material.plane_strain_modulus, toughness, 12.0 * viscosity)
    r_k = radial_k_vertex(t, q, toughness, material)[0]
    r_m = radial_m_vertex(t, q, viscosity, material)[0]
    guess = np.minimum(r_k, r_m)  # both dissipations at once: below either vertex
    alpha, step = np.full(t.shape, 4.0 / 9.0), 0.01
    for _ in range(3):  # alpha from the radii a little before and after t
        before = _transition_radius(t * np.exp(-step), q, asymptote, alpha, guess * np.exp(-step * alpha))
        after = _transition_radius(t * np.exp(step), q, asymptote, alpha, guess * np.exp(step * alpha))
        alpha = np.clip(np.log(after / before) / (2.0 * step), 0.4, 4.0 / 9.0)
    radius = _transition_radius(t, q, asymptote, alpha, guess)
    return (radius,) + _transition_state(radius, t, alpha, asymptote)[1:]


def radial_transition_profile(rho, t, injection_rate, viscosity, fracture_toughness, material):
    """Opening of a radial hydraulic fracture at any dimensionless toughness, zero leak-off:
    the approximate solution of Dontsov (2016, R. Soc. open sci. 3:160737), without leak-off.

    The opening is the universal tip asymptote (Dontsov and Peirce 2015,
    :class:`hmatddm.analytical.tip_asymptote.TipAsymptote`) evaluated at the distance ``R`` of the
    well from the front, with the front velocity ``V = alpha R / t``, spread over the fracture as

        w(rho) = w_a (1 - rho)^delta ((1 + rho)/2)^lambda,   w_a = w_asymptote(s = R, V),

    with ``delta`` the local exponent of the asymptote (1/2 at K^ = K' R^(1/2)/(E' w_a) = 1,
    2/3 at K^ = 0), ``lambda = 0.487 (1 - K^4) + 0.5 K^4``, and ``R`` such that the fracture
    holds the injected volume ``Q t``; ``alpha = d ln R / d ln t`` (4/9 at the M-vertex, 2/5 at
    the K-vertex) by a fixed point on the solution itself. The K-vertex is exact (Sneddon's
    opening at toughness); the M-vertex gives Dontsov's ``R = 0.6944 L`` and ``w(0) = 1.1901 eps L``
    of ref. Eqs 4.62-4.63 (see ``tests/analytical/test_analytical.py``; Dontsov quotes about 1% between
    the vertices). The net pressure is not part of this approximation.

    Returns ``(radius, width)``, ``width`` shaped like ``rho`` in ``[0, 1]``; ``t`` a scalar > 0.
    """
    rho = finite_array("rho", rho)
    if np.any((rho < 0.0) | (rho > 1.0)):
        raise InputError(f"rho must be in [0, 1] (r / R), got {rho[(rho < 0.0) | (rho > 1.0)].ravel()[0]}")
    if np.size(t) != 1:
        raise InputError("t must be a scalar > 0 for radial_transition_profile")
    t = _positive_times(np.ravel(t))
    radius, w_a, delta, lam = (float(v[0]) for v in _radial_transition(t, injection_rate, viscosity,
                                                                        fracture_toughness, material))
    return radius, w_a * (1.0 - rho) ** delta * (0.5 * (1.0 + rho)) ** lam


def radial_transition(t, injection_rate, viscosity, fracture_toughness, material):
    """Radius and opening at the well of a radial fracture at any dimensionless toughness
    ``K_m`` (:func:`radial_regime`), zero leak-off: Dontsov's (2016) approximate solution, see
    :func:`radial_transition_profile`. Returns ``(radius, max_width)``, arrays like ``t``."""
    t = _positive_times(t)
    radius, w_a, _, lam = _radial_transition(t.ravel(), injection_rate, viscosity, fracture_toughness, material)
    return radius.reshape(t.shape), (w_a * 0.5**lam).reshape(t.shape)
