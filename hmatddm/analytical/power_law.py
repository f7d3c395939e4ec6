"""Viscosity-dominated plane-strain (KGD) hydraulic fracture driven by a power-law fluid:
the zero-toughness, zero-leak-off similarity solution of Adachi and Detournay (2002, Int. J.
Numer. Anal. Meth. Geomech. 26:579-604), computed here for any flow index n in (0, 1].

The reference (ref. Sec. 8.2) stops at Newtonian fluids; this module is the closed form the
power-law flow of :mod:`hmatddm.flow.lubrication` is validated against, written apart from it
(nothing here reads the flow code or the tip asymptote of the asymptotic front).

The problem. A power-law fluid (``tau = K gamma_dot^n``) flows between the crack faces with
``q = -(w^(2n+1) / M')^(1/n) |dp/dx|^(1/n - 1) dp/dx``, ``M' = 2^(n+1) (2n+1)^n / n^n K``; it is
injected at the rate ``Q`` (per unit height, both wings) into a crack of half-length ``l(t)`` in
an elastic solid of plane-strain modulus ``E'``. With the scales

    L = (E' Q^(n+2) t^(2n+2) / M')^(1/(2n+4)),   eps = (M' / (E' t^n))^(1/(n+2)) = Q t / L^2,

the solution is self-similar: ``l = gamma L``, ``w = eps L gamma Omega(xi)``,
``p_net = eps E' Pi(xi)``, ``xi = x / l``, and the length grows as ``t^((n+1)/(n+2))``. The
pair ``(Omega, Pi)`` is an elastic pair, ``Pi(xi) = 1/(4 pi) PV int_-1^1 Omega'(s) / (xi - s) ds``,
and satisfies (volume balance of the fluid between ``x`` and the tip, integrated in time with
the similarity form ``d/dt = (1/(n+2) - (n+1)/(n+2) xi d/dxi) / t``)::

    Omega^(2n+1) (-Pi') = [ int_xi^1 Omega + a xi Omega ]^n,   a = (n+1)/(n+2),   0 < xi < 1,
    gamma^2 int_0^1 Omega = 1/2                                (global volume: Q t / 2 per wing)

(``gamma`` drops out of the first equation). Following Adachi and Detournay, ``Omega`` is the
series of exact elastic pairs

    Omega = sum_j A_j (1 - xi^2)^alpha C_(2j-2)^(alpha - 1/2)(xi) + B Omega**(xi),
    Pi    = sum_j A_j Pi*_j(xi) + B (2 - pi |xi|),

``alpha = 2/(n+2)`` the viscous tip exponent, ``C`` Gegenbauer polynomials, ``Pi*_j`` their
pressures (Gauss hypergeometric functions), ``Omega** = 4 (1 - xi^2)^(1/2) + 2 xi^2
ln|(1 - (1 - xi^2)^(1/2)) / (1 + (1 - xi^2)^(1/2))|`` the opening of the point-source pressure
``2 - pi |xi|`` (the kink of the pressure at the injection point, where the flux is ``Q/2``).
Adachi and Detournay tabulate the coefficients; here they are computed for the given ``n``:
``A_j, B`` minimise the lubrication residual, relative, at collocation points (Gauss-Newton,
:func:`scipy.optimize.least_squares`), then ``gamma`` follows from the volume balance. With the
default 8 terms the relative residual is ~1e-3 for ``xi <= 0.95`` and 1-2% within 1% of
the tip (``solve(n).residual``: the higher-order tip terms; the global quantities change by
less than 1e-4 from 6 to 12 terms); at n = 1 this
reproduces the Newtonian series of :func:`hmatddm.analytical.kgd_m_vertex` (Adachi and
Detournay's seven tabulated terms) to 0.03% in ``gamma``, 0.2% in the opening and 0.1% in the
net pressure at the injection point.
"""
import functools
from dataclasses import dataclass

import numpy as np
from scipy import integrate, optimize, special

from .._validation import finite_array, positive_scalar
from ..errors import InputError

N_TERMS = 8          # Gegenbauer terms of the series
N_COLLOCATION = 120  # collocation points of the lubrication residual


def consistency_prime(consistency, flow_index):
    """``M' = 2^(n+1) (2n+1)^n / n^n K`` (Pa s^n): 12 K at n = 1."""
    n = _flow_index(flow_index)
    return 2.0 ** (n + 1.0) * (2.0 * n + 1.0) ** n / n**n * positive_scalar("consistency", consistency)


def _flow_index(flow_index):
    n = positive_scalar("flow_index", flow_index)
    if n > 1.0:
        raise InputError(f"flow_index must be in (0, 1], got {n}")
    return n


# -- the elastic pairs ---------------------------------------------------------------------

def gegenbauer_opening(j, alpha, xi):
    """``Omega*_j = (1 - xi^2)^alpha C_(2j-2)^(alpha - 1/2)(xi)``, j >= 1."""
    xi = np.asarray(xi, float)
    return (1.0 - xi * xi) ** alpha * special.eval_gegenbauer(2 * j - 2, alpha - 0.5, xi)


def gegenbauer_pressure(j, alpha, xi):
    """``Pi*_j``, the net pressure whose opening is :func:`gegenbauer_opening` (Adachi and
    Detournay 2002, their pairs of the Gegenbauer series, any ``alpha`` in (1/2, 1))."""
    xi = np.asarray(xi, float)
    x2 = xi * xi
    a = alpha
    if j == 1:
        return a / (2.0 * np.pi) * special.beta(0.5, a) * special.hyp2f1(0.5 - a, 1.0, 0.5, x2)
    prefactor = (2.0 * a - 1.0) * (2 * j - 1) / (4.0 * np.pi * (j - 1 + a)) * special.beta(0.5 - j, a + j)
    return prefactor * (a * x2 * special.hyp2f1(2.5 - j - a, j, 1.5, x2)
                        - 0.5 * special.hyp2f1(1.5 - j - a, j - 1, 0.5, x2))


def point_source_opening(xi):
    """``Omega** = 4 (1 - xi^2)^(1/2) + 2 xi^2 ln|(1 - r)/(1 + r)|``, ``r = (1 - xi^2)^(1/2)``."""
    xi = np.asarray(xi, float)
    root = np.sqrt(1.0 - xi * xi)
    # (1 - r)/(1 + r) = xi^2/(1 + r)^2: no cancellation at small xi
    with np.errstate(divide="ignore", invalid="ignore"):
        log_term = np.where(xi == 0.0, 0.0, 4.0 * xi * xi * np.log(np.abs(xi) / (1.0 + root)))
    return 4.0 * root + log_term


def point_source_pressure(xi):
    """``Pi** = 2 - pi |xi|``."""
    return 2.0 - np.pi * np.abs(np.asarray(xi, float))


def _basis_opening(k, alpha, xi):
    return point_source_opening(xi) if k == N_TERMS else gegenbauer_opening(k + 1, alpha, xi)


def _basis_pressure(k, alpha, xi):
    return point_source_pressure(xi) if k == N_TERMS else gegenbauer_pressure(k + 1, alpha, xi)


def _tail_integral(k, alpha, xi):
    """``int_xi^1`` of the basis opening ``k`` (adaptive quadrature; the Gegenbauer terms with
    the algebraic weight ``(1 - s)^alpha`` of their tip)."""
    if k == N_TERMS:
        return integrate.quad(point_source_opening, xi, 1.0, epsabs=1e-13, epsrel=1e-11, limit=200)[0]
    order = 2 * k

    def smooth(s):  # (1 + s)^alpha C(s): the weight (1 - s)^alpha is the quadrature's
        return (1.0 + s) ** alpha * special.eval_gegenbauer(order, alpha - 0.5, s)

    return integrate.quad(smooth, xi, 1.0, weight="alg", wvar=(0.0, alpha), epsabs=1e-13, epsrel=1e-11)[0]


# -- the solution --------------------------------------------------------------------------

@dataclass(frozen=True)
class PowerLawKGD:
    """The similarity solution of one flow index (module docstring): ``coefficients``
    ``(A_1, ..., A_8, B)``, ``gamma``, and ``residual`` the largest relative lubrication
    residual at the collocation points."""

    flow_index: float
    coefficients: np.ndarray
    gamma: float
    residual: float

    @property
    def alpha(self):
        return 2.0 / (self.flow_index + 2.0)

    def opening(self, xi):
        """``Omega(xi)`` (the opening in units of ``eps L gamma``)."""
        xi = np.asarray(xi, float)
        return sum(c * _basis_opening(k, self.alpha, xi) for k, c in enumerate(self.coefficients))

    def pressure(self, xi):
        """``Pi(xi)`` (the net pressure in units of ``eps E'``)."""
        xi = np.asarray(xi, float)
        return sum(c * _basis_pressure(k, self.alpha, xi) for k, c in enumerate(self.coefficients))


def _collocation_points():
    # clustered at both ends (the tip and the source), inside (0, 1)
    theta = np.pi * (np.arange(N_COLLOCATION) + 0.5) / N_COLLOCATION
    return 0.5 * (1.0 - np.cos(theta))


@functools.lru_cache(maxsize=32)
def solve(flow_index):
    """:class:`PowerLawKGD` of the flow index ``n`` in (0, 1] (cached: ~1 s per ``n``)."""
    n = _flow_index(flow_index)
    alpha = 2.0 / (n + 2.0)
    a = (n + 1.0) / (n + 2.0)
    xi = _collocation_points()
    size = N_TERMS + 1
    opening = np.column_stack([_basis_opening(k, alpha, xi) for k in range(size)])
    step = 1e-6 * np.minimum(xi, 1.0 - xi)
    slope = np.column_stack([(_basis_pressure(k, alpha, xi + step) - _basis_pressure(k, alpha, xi - step))
                             / (2.0 * step) for k in range(size)])
    tail = np.array([[_tail_integral(k, alpha, x) for k in range(size)] for x in xi])
    whole = np.array([_tail_integral(k, alpha, 0.0) for k in range(size)])

    def residual(c):
        omega = opening @ c
        flux = tail @ c + a * xi * omega
        return np.abs(omega) ** (2.0 * n + 1.0) * (-(slope @ c)) / np.abs(flux) ** n - 1.0

    # start from the Newtonian series (Adachi and Detournay 2002, n = 1)
    start = np.zeros(size)
    start[:7] = (1.61750, 0.39650, 1.00297e-2, 1.06179e-2, -2.97947e-3, -0.74268e-3, -1.34675e-3)
    start[N_TERMS] = 0.06858
    fit = optimize.least_squares(residual, start, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=20000)
    coefficients = fit.x
    volume = float(whole @ coefficients)
    if not (np.all(np.isfinite(coefficients)) and volume > 0.0):
        raise RuntimeError(f"the power-law KGD series did not converge for n = {n}")  # pragma: no cover
    return PowerLawKGD(n, coefficients, float(np.sqrt(0.5 / volume)), float(np.max(np.abs(fit.fun))))


def _scaling_inputs(t, injection_rate, consistency, flow_index, material):
    """The checked ``(t, Q, n, M', E')`` both scalings start from."""
    t = finite_array("t", t)
    if np.any(t <= 0.0):
        raise InputError(f"t must be > 0 (time since the start of injection), got min {t.min()}")
    n = _flow_index(flow_index)
    return (t, positive_scalar("injection_rate", injection_rate), n, consistency_prime(consistency, n),
            material.plane_strain_modulus)


def scales(t, injection_rate, consistency, flow_index, material):
    """``(E', eps, L)`` of the module docstring (arrays like ``t``)."""
    t, q, n, m_prime, e_prime = _scaling_inputs(t, injection_rate, consistency, flow_index, material)
    length = (e_prime * q ** (n + 2.0) * t ** (2.0 * n + 2.0) / m_prime) ** (1.0 / (2.0 * n + 4.0))
    return e_prime, (m_prime / (e_prime * t**n)) ** (1.0 / (n + 2.0)), length


def kgd_power_law_vertex(t, injection_rate, consistency, flow_index, material):
    """Viscosity-dominated KGD fracture of a power-law fluid (module docstring):
    ``(half_length, max_width, net_pressure)`` at times ``t`` (arrays like ``t``), the opening
    and net pressure at the injection point. ``injection_rate`` is per unit height into both
    wings, ``consistency`` K in Pa s^n, ``flow_index`` n in (0, 1]. The half-length grows as
    ``t^((n+1)/(n+2))``, the opening as ``t^(1/(n+2))``, the pressure as ``t^(-n/(n+2))``."""
    solution = solve(_flow_index(flow_index))
    e_prime, eps, length = scales(t, injection_rate, consistency, flow_index, material)
    gamma = solution.gamma
    return (gamma * length, eps * length * gamma * float(solution.opening(0.0)),
            eps * e_prime * float(solution.pressure(0.0)))


def kgd_power_law_profile(xi, t, injection_rate, consistency, flow_index, material):
    """Opening and net pressure at ``xi = x / l`` in (-1, 1) and the scalar time ``t`` (see
    :func:`kgd_power_law_vertex`): ``(width, net_pressure)`` shaped like ``xi``."""
    xi = finite_array("xi", xi)
    if np.any(np.abs(xi) >= 1.0):
        raise InputError(f"xi must be in (-1, 1) (inside the fracture), got {xi[np.abs(xi) >= 1.0].ravel()[0]}")
    solution = solve(_flow_index(flow_index))
    e_prime, eps, length = scales(positive_scalar("t", t), injection_rate, consistency, flow_index, material)
    return eps * length * solution.gamma * solution.opening(xi), eps * e_prime * solution.pressure(xi)


def kgd_power_law_regime(t, injection_rate, consistency, flow_index, fracture_toughness, material):
    """Dimensionless toughness ``K_m = K' / (eps E' L^(1/2))`` of a power-law KGD fracture
    (scales of the module docstring, ``K' = 4 (2/pi)^(1/2) K_Ic``): the toughness over the
    viscous stress intensity. It grows as ``t^((2 - 2n)/(2(n+2)))`` (constant at n = 1, where it
    is :func:`hmatddm.analytical.kgd_regime`); the similarity solution holds for ``K_m << 1``."""
    e_prime, eps, length = scales(t, injection_rate, consistency, flow_index, material)
    k_prime = 4.0 * np.sqrt(2.0 / np.pi) * positive_scalar("fracture_toughness", fracture_toughness)
    return k_prime / (eps * e_prime * np.sqrt(length))


# -- the radial (penny-shaped) M-vertex ------------------------------------------------------
#
# The same problem on a disc of radius R = gamma L, L = (E' Q^(n+2) t^(2n+2) / M')^(1/(3n+6)),
# eps = Q t / L^3, w = eps L gamma Omega(rho), p_net = eps E' Pi(rho), rho = r / R; the radius grows
# as t^((2n+2)/(3n+6)) (t^(4/9) at n = 1: Savitski and Detournay 2002). Lubrication (the fluid
# between r and the tip, per unit circumference) and the global volume:
#
#     Omega^(2n+1) (-Pi') = [ (int_rho^1 s Omega ds + a rho^2 Omega) / rho ]^n,  a = (2n+2)/(3n+6),
#     2 pi gamma^3 int_0^1 rho Omega = 1.
#
# Elasticity of the disc (Sneddon): Omega(rho) = 8/pi int_rho^1 s G(s) / (s^2 - rho^2)^(1/2) ds with
# G(s) = int_0^1 x Pi(x s) / (1 - x^2)^(1/2) dx; zero toughness is G(1) = 0 (no square-root
# opening at the tip). The pressure is a series with closed-form G (m = 0, 1, ..., 5 in each sum):
#
#     Pi = sum_m c_m rho^m (1 - rho^2)^(alpha - 1)           (viscous tip, alpha = 2/(n+2))
#        + c_s (rho^(1-n) - 1) / (1 - n)                     (point source, flux ~ rho^-n: ln rho at n = 1)
#        + sum_m d_m rho^m                                    (regular part)
#
# G of rho^m (1 - rho^2)^(alpha-1) is s^m B(m/2 + 1, 1/2)/2 2F1(1 - alpha, m/2 + 1; m/2 + 3/2; s^2)
# (Euler's integral), of rho^m it is s^m B(m/2 + 1, 1/2)/2. The integrals over s are Gauss-Jacobi
# rules in v = (s^2 - rho^2)/(1 - rho^2): Omega = 4/pi (1 - rho^2)^(1/2) int_0^1 G v^(-1/2) dv and
# int_rho^1 s Omega ds = 4/pi (1 - rho^2)^(3/2) int_0^1 G v^(1/2) dv (the order of the two
# integrals swapped). The coefficients minimise the relative lubrication residual (Gauss-Newton)
# with G(1) = 0 held by a weighted row. The residual is < 1e-3 at every collocation point
# for n = 0.5, 0.8 and 1, and gamma changes by < 1e-5 between 4, 5 and 6 terms per sum. At
# n = 1: gamma = 0.6978, gamma Omega(0) = 1.1928, against 0.6955 and 1.1977 of Savitski and
# Detournay's zero-order M-vertex (:func:`hmatddm.analytical.radial_m_vertex_profile`, which holds
# the lubrication only to 1.4%): +0.34% and -0.41%.

RADIAL_TIP_TERMS = 6
RADIAL_REGULAR_TERMS = 6
_RADIAL_NODES = 200


def _radial_basis_g(s, n, alpha):
    """``G(s)`` of every basis pressure, shape ``(len(s), size)`` (tip terms, source, regular)."""
    s = np.asarray(s, float)

    def half_beta(m):  # G of rho^m is s^m B(m/2 + 1, 1/2) / 2
        return 0.5 * special.beta(0.5 * m + 1.0, 0.5)

    columns = [s**m * half_beta(m) * special.hyp2f1(1.0 - alpha, 0.5 * m + 1.0, 0.5 * m + 1.5, s * s)
               for m in range(RADIAL_TIP_TERMS)]
    if n == 1.0:
        with np.errstate(divide="ignore"):
            columns.append(np.log(s) + np.log(2.0) - 1.0)
    else:
        columns.append((s ** (1.0 - n) * half_beta(1.0 - n) - half_beta(0.0)) / (1.0 - n))
    columns += [s**m * half_beta(m) for m in range(RADIAL_REGULAR_TERMS)]
    return np.column_stack(columns)


def _radial_basis_slope(rho, n, alpha):
    """``Pi'`` of every basis pressure at ``rho`` in (0, 1)."""
    rho = np.asarray(rho, float)
    base = 1.0 - rho * rho
    columns = [(m * rho ** (m - 1) if m else 0.0 * rho) * base ** (alpha - 1.0)
               - 2.0 * (alpha - 1.0) * rho ** (m + 1) * base ** (alpha - 2.0) for m in range(RADIAL_TIP_TERMS)]
    columns.append(rho ** (-n))
    columns += [m * rho ** (m - 1) if m else 0.0 * rho for m in range(RADIAL_REGULAR_TERMS)]
    return np.column_stack(columns)


def _radial_basis_pressure(rho, n, alpha):
    rho = np.asarray(rho, float)
    columns = [rho**m * (1.0 - rho * rho) ** (alpha - 1.0) for m in range(RADIAL_TIP_TERMS)]
    with np.errstate(divide="ignore"):
        columns.append(np.log(rho) if n == 1.0 else (rho ** (1.0 - n) - 1.0) / (1.0 - n))
    columns += [rho**m for m in range(RADIAL_REGULAR_TERMS)]
    return np.column_stack(columns)


def _radial_integrals(rho, n, alpha):
    """``(Omega, int_rho^1 s Omega ds)`` of every basis pressure at ``rho`` (rows) by the Gauss-Jacobi
    rules of the block comment."""
    rho = np.asarray(rho, float)[:, None]
    result = []
    for power in (-0.5, 0.5):  # the weight v^power on [0, 1]
        v, weights = _jacobi_rule(power)
        s = np.sqrt(rho * rho + (1.0 - rho * rho) * v[None, :])  # (points, nodes)
        g = _radial_basis_g(s.ravel(), n, alpha).reshape(s.shape + (-1,))
        integral = np.einsum("pjb,j->pb", g, weights)
        factor = 4.0 / np.pi * (1.0 - rho * rho) ** (1.5 if power > 0 else 0.5)
        result.append(factor * integral)
    return result[0], result[1]


@functools.lru_cache(maxsize=4)
def _jacobi_rule(power):
    """Gauss-Jacobi nodes and weights on [0, 1] for the weight ``v^power``."""
    nodes, weights = special.roots_jacobi(_RADIAL_NODES, 0.0, power)  # (1 - x)^0 (1 + x)^power on [-1, 1]
    return 0.5 * (nodes + 1.0), weights * 0.5 ** (power + 1.0)


@dataclass(frozen=True)
class PowerLawRadial:
    """The radial similarity solution of one flow index (block comment above): ``coefficients``
    of the pressure series, ``gamma``, ``residual`` (largest relative lubrication residual at
    the collocation points) and ``tip_intensity`` (``G(1)``, zero toughness: ~0)."""

    flow_index: float
    coefficients: np.ndarray
    gamma: float
    residual: float
    tip_intensity: float

    @property
    def alpha(self):
        return 2.0 / (self.flow_index + 2.0)

    def opening(self, rho):
        """``Omega(rho)`` (the opening in units of ``eps L gamma``), ``rho`` in [0, 1)."""
        rho = np.atleast_1d(np.asarray(rho, float))
        return _radial_integrals(rho, self.flow_index, self.alpha)[0] @ self.coefficients

    def pressure(self, rho):
        """``Pi(rho)`` (the net pressure in units of ``eps E'``); finite at ``rho = 0`` for n < 1
        (+inf at n = 1, the logarithm of the point source)."""
        rho = np.atleast_1d(np.asarray(rho, float))
        return _radial_basis_pressure(rho, self.flow_index, self.alpha) @ self.coefficients


@functools.lru_cache(maxsize=32)
def solve_radial(flow_index):
    """:class:`PowerLawRadial` of the flow index ``n`` in (0, 1] (cached: ~1 s per ``n``)."""
    n = _flow_index(flow_index)
    alpha = 2.0 / (n + 2.0)
    a = (2.0 * n + 2.0) / (3.0 * n + 6.0)
    rho = _collocation_points()
    opening, tail = _radial_integrals(rho, n, alpha)
    slope = _radial_basis_slope(rho, n, alpha)
    tip = _radial_basis_g(np.array([1.0]), n, alpha)[0]
    volume_row = 8.0 / np.pi * _gauss_legendre_moment(n, alpha)

    def residual(c):
        omega = opening @ c
        flux = (tail @ c + a * rho * rho * omega) / rho
        lubrication = np.abs(omega) ** (2.0 * n + 1.0) * (-(slope @ c)) / np.abs(flux) ** n - 1.0
        return np.append(lubrication, 1e3 * (tip @ c))

    start = np.zeros(RADIAL_TIP_TERMS + 1 + RADIAL_REGULAR_TERMS)
    start[0], start[RADIAL_TIP_TERMS], start[RADIAL_TIP_TERMS + 1] = -0.30, -0.0927, 0.86  # ~ Savitski-Detournay
    fit = optimize.least_squares(residual, start, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=20000)
    c = fit.x
    volume = float(volume_row @ c)
    if not (np.all(np.isfinite(c)) and volume > 0.0):
        raise RuntimeError(f"the power-law radial series did not converge for n = {n}")  # pragma: no cover
    return PowerLawRadial(n, c, float((2.0 * np.pi * volume) ** (-1.0 / 3.0)), float(np.max(np.abs(fit.fun[:-1]))),
                          float(tip @ c))


def _gauss_legendre_moment(n, alpha):
    """``int_0^1 s^2 G(s) ds`` of every basis (the volume ``int_0^1 rho Omega`` is 8/pi times it)."""
    nodes, weights = special.roots_jacobi(_RADIAL_NODES, 0.0, 0.0)
    s = 0.5 * (nodes + 1.0)
    return (0.5 * weights * s * s) @ _radial_basis_g(s, n, alpha)


def radial_scales(t, injection_rate, consistency, flow_index, material):
    """``(E', eps, L)`` of the radial problem (block comment above), arrays like ``t``."""
    t, q, n, m_prime, e_prime = _scaling_inputs(t, injection_rate, consistency, flow_index, material)
    length = (e_prime * q ** (n + 2.0) * t ** (2.0 * n + 2.0) / m_prime) ** (1.0 / (3.0 * n + 6.0))
    return e_prime, q * t / length**3, length


def radial_power_law_vertex(t, injection_rate, consistency, flow_index, material):
    """Viscosity-dominated radial (penny) fracture of a power-law fluid, zero toughness and
    leak-off: ``(radius, opening at the injection point)`` at times ``t`` (arrays like ``t``).
    ``injection_rate`` in m^3/s; the radius grows as ``t^((2n+2)/(3n+6))``, the opening as
    ``t^((2-n)/(3n+6))`` (``t^(1/9)`` at n = 1)."""
    solution = solve_radial(_flow_index(flow_index))
    _, eps, length = radial_scales(t, injection_rate, consistency, flow_index, material)
    return solution.gamma * length, eps * length * solution.gamma * float(solution.opening(0.0)[0])


def radial_power_law_profile(rho, t, injection_rate, consistency, flow_index, material):
    """Opening and net pressure at ``rho = r / R`` in [0, 1) and the scalar time ``t``:
    ``(width, net_pressure)`` (1D arrays)."""
    rho = finite_array("rho", rho)
    if np.any((rho < 0.0) | (rho >= 1.0)):
        raise InputError(f"rho must be in [0, 1) (inside the fracture), got {rho[(rho < 0) | (rho >= 1)].ravel()[0]}")
    solution = solve_radial(_flow_index(flow_index))
    e_prime, eps, length = radial_scales(positive_scalar("t", t), injection_rate, consistency, flow_index, material)
    return eps * length * solution.gamma * solution.opening(rho), eps * e_prime * solution.pressure(rho)


def radial_power_law_regime(t, injection_rate, consistency, flow_index, fracture_toughness, material):
    """Dimensionless toughness ``K_m = K' / (eps E' L^(1/2))`` of a power-law radial fracture
    (:func:`radial_scales`; at n = 1 Savitski and Detournay's ``K_m``, growing as ``t^(1/9)``);
    the M-vertex holds for ``K_m << 1``."""
    e_prime, eps, length = radial_scales(t, injection_rate, consistency, flow_index, material)
    k_prime = 4.0 * np.sqrt(2.0 / np.pi) * positive_scalar("fracture_toughness", fracture_toughness)
    return k_prime / (eps * e_prime * np.sqrt(length))
