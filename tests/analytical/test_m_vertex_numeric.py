"""The numerically computed M-vertex similarity solutions (hmatddm/analytical/m_vertex_numeric.py)
checked against the equations they solve, written in forms the solver does not use: the
differential lubrication equation (finite differences of the returned profiles), the
toughness and volume integrals by adaptive quadrature, the source flux, the viscous tip
asymptote, and elasticity as Cauchy's integral of the opening slope (KGD) or Sneddon's
double integral of the pressure (radial, slow)."""
import numpy as np
import pytest
from scipy import integrate

from hmatddm.analytical import m_vertex_numeric as mv
from hmatddm.errors import InputError

BETA_M = 2.0 ** (1.0 / 3.0) * 3.0 ** (5.0 / 6.0)  # w = beta_m (mu' V / E')^(1/3) s^(2/3)


@pytest.fixture(scope="module")
def kgd():
    return mv.kgd_m_vertex_numeric(24)


@pytest.fixture(scope="module")
def radial():
    return mv.radial_m_vertex_numeric(24)


def test_two_resolutions_agree_and_give_the_module_constants(kgd, radial):
    coarse_kgd, coarse_radial = mv.kgd_m_vertex_numeric(16), mv.radial_m_vertex_numeric(16)
    for fine, coarse in ((kgd, coarse_kgd), (radial, coarse_radial)):
        assert coarse.gamma == pytest.approx(fine.gamma, rel=1e-7)
        assert coarse.opening_at_source == pytest.approx(fine.opening_at_source, rel=2e-6)
        x = np.array([0.2, 0.5, 0.8, 0.95])
        assert np.allclose(coarse.opening(x), fine.opening(x), rtol=1e-5)
        assert np.allclose(coarse.pressure(x), fine.pressure(x), rtol=1e-5, atol=1e-6)
    assert kgd.gamma == pytest.approx(mv.KGD_M_GAMMA_ACCURATE, abs=1e-7)
    assert kgd.opening_at_source == pytest.approx(mv.KGD_M_OPENING_ACCURATE, abs=1e-7)
    assert kgd.pressure_at_source == pytest.approx(mv.KGD_M_PRESSURE_ACCURATE, abs=1e-7)
    assert radial.gamma == pytest.approx(mv.RADIAL_M_GAMMA_ACCURATE, abs=1e-7)
    assert radial.opening_at_source == pytest.approx(mv.RADIAL_M_OPENING_ACCURATE, abs=1e-7)
    assert radial.log_coefficient == pytest.approx(mv.RADIAL_M_LOG_COEFFICIENT_ACCURATE, abs=1e-7)


@pytest.mark.parametrize("points", [9, 11, 17])
def test_odd_numbers_of_points_converge_too(points):
    """A node at tau = 1/2 (odd counts) once left a sliver panel in the graded rules."""
    assert mv.kgd_m_vertex_numeric(points).gamma == pytest.approx(mv.KGD_M_GAMMA_ACCURATE, rel=3e-6)
    assert mv.radial_m_vertex_numeric(points).gamma == pytest.approx(mv.RADIAL_M_GAMMA_ACCURATE, rel=3e-6)


def test_published_constants_agree_to_their_truncation(kgd, radial):
    """Adachi and Detournay's seven-term KGD series, Savitski and Detournay's zero-order radial
    solution and Dontsov's radial approximation, each within its own error (0.03-1%)."""
    assert kgd.gamma == pytest.approx(0.61524, rel=5e-4)
    assert kgd.opening_at_source == pytest.approx(1.1233, rel=3e-3)
    assert kgd.pressure_at_source == pytest.approx(0.5443, rel=1.5e-3)
    assert radial.gamma == pytest.approx(0.6955, rel=4e-3)
    assert radial.opening_at_source == pytest.approx(1.1977, rel=4e-3)
    assert radial.log_coefficient == pytest.approx(0.09269, rel=1.2e-2)
    assert radial.gamma == pytest.approx(0.6944, rel=6e-3)
    assert radial.opening_at_source == pytest.approx(1.1901, rel=3e-3)


def test_kgd_agrees_with_the_power_law_series_at_n_1(kgd):
    """An independent computation: the least-squares Gegenbauer series of
    hmatddm/analytical/power_law.py (Adachi and Detournay's basis, 8 terms) at n = 1."""
    from hmatddm.analytical import power_law

    series = power_law.solve(1.0)
    assert series.gamma == pytest.approx(kgd.gamma, rel=1e-6)
    opening = series.gamma * np.ravel(series.opening(np.array([0.0])))[0]
    assert opening == pytest.approx(kgd.opening_at_source, rel=1e-5)
    assert np.ravel(series.pressure(np.array([0.0])))[0] == pytest.approx(kgd.pressure_at_source, rel=1e-4)


@pytest.mark.slow
def test_radial_agrees_with_the_power_law_series_at_n_1(radial):
    """The same for the radial series of power_law.py (its opening at the source is the less
    accurate: 4e-4)."""
    from hmatddm.analytical import power_law

    series = power_law.solve_radial(1.0)
    assert series.gamma == pytest.approx(radial.gamma, rel=1e-6)
    opening = series.gamma * np.ravel(series.opening(np.array([0.0])))[0]
    assert opening == pytest.approx(radial.opening_at_source, rel=5e-4)


def test_volume_balance(kgd, radial):
    """gamma int_-1^1 Omega = 1 (KGD), 2 pi gamma^2 int_0^1 Omega rho d rho = 1 (radial)."""
    tip = 1.0 - 1e-13
    kgd_volume = 2.0 * kgd.gamma * integrate.quad(kgd.opening, 0.0, tip, limit=200, epsabs=1e-13)[0]
    radial_volume = 2.0 * np.pi * radial.gamma**2 * integrate.quad(
        lambda r: r * radial.opening(r), 0.0, tip, limit=200, epsabs=1e-13)[0]
    assert kgd_volume == pytest.approx(1.0, abs=1e-6)
    assert radial_volume == pytest.approx(1.0, abs=1e-6)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")  # the (1 - s)^(-5/6) ends
def test_zero_stress_intensity_factor(kgd, radial):
    """K = 0: int_0^1 Pi / sqrt(1 - xi^2) = 0 (KGD), int_0^1 Pi rho / sqrt(1 - rho^2) = 0."""
    kgd_k, kgd_error = integrate.quad(lambda s: kgd.pressure(s) / np.sqrt(1.0 - s * s), 0.0, 1.0,
                                      limit=400, points=[0.5, 0.9, 0.99])
    radial_k, radial_error = integrate.quad(lambda s: radial.pressure(s) * s / np.sqrt(1.0 - s * s), 0.0,
                                            1.0, limit=400, points=[0.5, 0.9, 0.99])
    assert max(kgd_error, radial_error) < 1e-7  # the quadrature's own estimate
    assert abs(kgd_k) < 1e-6 * kgd.pressure_at_source
    assert abs(radial_k) < 1e-6


def _slope(f, x, h):
    return (f(x + h) - f(x - h)) / (2.0 * h)


@pytest.mark.parametrize("x", [0.15, 0.4, 0.7, 0.9])
def test_lubrication_residual(kgd, radial, x):
    """1/3 Omega - 2/3 xi Omega' = gamma^-2 (Omega^3 Pi')' and 1/9 Omega - 4/9 rho Omega' =
    gamma^-2 rho^-1 (rho Omega^3 Pi')' by finite differences of the returned profiles."""
    h = 3e-4
    for sol, a, b, power in ((kgd, 1.0 / 3.0, 2.0 / 3.0, 0), (radial, 1.0 / 9.0, 4.0 / 9.0, 1)):
        def flux(s):
            return s**power * sol.opening(s) ** 3 * _slope(sol.pressure, s, 1e-5)
        left = a * sol.opening(x) - b * x * _slope(sol.opening, x, 1e-5)
        right = _slope(flux, x, h) / (sol.gamma**2 * x**power)
        assert right == pytest.approx(left, rel=5e-6, abs=1e-7)


def test_source_flux_and_tip_asymptote(kgd, radial):
    """Q/2 per wing and 2 pi rho Omega^3 Pi' -> -1 at the source; Omega -> beta_m (V t / L)^(1/3)
    gamma^(2/3) (1 - x)^(2/3) at the tip, V = 2/3 l/t (KGD), 4/9 R/t (radial)."""
    eps = 1e-5
    kgd_flux = -kgd.opening(eps) ** 3 * _slope(kgd.pressure, eps, 1e-6) / kgd.gamma
    assert kgd_flux == pytest.approx(0.5, rel=1e-4)
    rho = 1e-4
    radial_flux = -2.0 * np.pi * rho * radial.opening(rho) ** 3 * _slope(radial.pressure, rho, 1e-6)
    assert radial_flux == pytest.approx(1.0, rel=1e-3)
    assert 2.0 * np.pi * radial.log_coefficient * radial.opening_at_source**3 == pytest.approx(1.0, rel=1e-9)
    kgd_tip = BETA_M * (2.0 / 3.0) ** (1.0 / 3.0) * kgd.gamma
    radial_tip = BETA_M * (4.0 / 9.0) ** (1.0 / 3.0) * radial.gamma
    assert kgd.tip_coefficient == pytest.approx(kgd_tip, rel=1e-7)
    assert radial.tip_coefficient == pytest.approx(radial_tip, rel=1e-7)
    s = 1e-6
    assert kgd.opening(1.0 - s) / s ** (2.0 / 3.0) == pytest.approx(kgd_tip, rel=2e-3)
    assert radial.opening(1.0 - s) / s ** (2.0 / 3.0) == pytest.approx(radial_tip, rel=2e-3)


@pytest.mark.parametrize("xi", [0.2, 0.5, 0.8])
def test_kgd_elasticity_as_cauchy_integral(kgd, xi):
    """Pi(xi) = 1 / (4 pi gamma) int_-1^1 Omega'(eta) / (xi - eta) d eta (the hypersingular
    operator of a plane-strain crack; the solver uses the pressure-to-opening direction)."""
    def slope(eta):
        return _slope(lambda e: kgd.opening(abs(e)), eta, min(1e-6, 0.1 * (1.0 - eta)))
    near = 1.0 - 1e-9
    principal = integrate.quad(slope, 1e-9, near, weight="cauchy", wvar=xi, limit=400)[0]
    # the half eta < 0, mirrored: Omega' is odd
    mirror = integrate.quad(lambda e: slope(e) / (e + xi), 0.0, near, limit=400, points=[0.5, 0.9, 0.99])[0]
    pressure = -(principal + mirror) / (4.0 * np.pi * kgd.gamma)
    assert pressure == pytest.approx(kgd.pressure(xi), rel=1e-4)


@pytest.mark.slow
@pytest.mark.parametrize("rho", [0.0, 0.5, 0.9])
def test_radial_elasticity_as_sneddon_double_integral(radial, rho):
    """Omega(rho) = 8 gamma / pi int_rho^1 t / sqrt(t^2 - rho^2) int_0^1 s Pi(s t) / sqrt(1 - s^2)
    ds dt from the pressure profile (the solver uses its integrated-by-parts form)."""
    def inner(t):
        return integrate.quad(lambda th: np.sin(th) * radial.pressure(t * np.sin(th)), 0.0, 0.5 * np.pi,
                              limit=200)[0]
    outer = integrate.quad(lambda t: t * inner(t) / np.sqrt(t * t - rho * rho), rho, 1.0 - 1e-12,
                           limit=200)[0]
    assert 8.0 * radial.gamma / np.pi * outer == pytest.approx(radial.opening(rho), rel=1e-6)


@pytest.mark.parametrize("points", [0, 7, 129, 16.0, True, "16"])
def test_points_out_of_range_is_an_input_error(points):
    with pytest.raises(InputError, match="points"):
        mv.kgd_m_vertex_numeric(points)


@pytest.mark.parametrize("x", [-0.1, 1.0, np.nan])
def test_position_outside_the_fracture_is_an_input_error(kgd, x):
    with pytest.raises(InputError, match="in \\[0, 1\\)"):
        kgd.opening(x)
    with pytest.raises(InputError, match="in \\[0, 1\\)"):
        kgd.pressure(x)
