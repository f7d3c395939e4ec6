"""The universal tip asymptote (Dontsov and Peirce 2015) against its vertices, and its inversion."""
import numpy as np
import pytest

from hmatddm.analytical.tip_asymptote import TipAsymptote, g_delta, toughness_prime

E_PRIME, MU_PRIME = 64e9, 12e-3


def test_vertices_of_g_delta():
    # K^ = 1: the toughness vertex (s^ = 0); K^ = 0: the viscosity vertex s^ = 1/beta_m^3,
    # beta_m = 2^(1/3) 3^(5/6) (Desroches et al. 1994)
    assert g_delta(1.0, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert g_delta(0.0, 0.0) == pytest.approx(1.0 / (2.0 ** (1 / 3) * 3.0 ** (5 / 6)) ** 3, rel=1e-12)
    k = np.linspace(0.0, 1.0, 11)
    assert np.all(np.diff(g_delta(k, 0.0)) < 0.0)


def test_width_tends_to_the_toughness_and_viscosity_vertices():
    s = np.array([1e-3, 0.1, 1.0, 10.0])
    velocity = np.full(4, 0.2)
    viscous = TipAsymptote(E_PRIME, 1.0, MU_PRIME)  # K_Ic 1 Pa m^1/2: no toughness
    w_m = (2.0 ** (1 / 3) * 3.0 ** (5 / 6)) * (MU_PRIME * velocity / E_PRIME) ** (1 / 3) * s ** (2 / 3)
    np.testing.assert_allclose(viscous.width(s, velocity), w_m, rtol=1e-3)
    tough = TipAsymptote(E_PRIME, 5e7, MU_PRIME)
    w_k = 4.0 * np.sqrt(2.0 / np.pi) * 5e7 * np.sqrt(s) / E_PRIME
    np.testing.assert_allclose(tough.width(s, velocity), w_k, rtol=3e-3)
    np.testing.assert_allclose(tough.width(s, 0.0), w_k, rtol=1e-12)
    assert toughness_prime(1.0) == pytest.approx(4.0 * np.sqrt(2.0 / np.pi))


def test_width_between_vertices_is_wider_than_both():
    asymptote = TipAsymptote(E_PRIME, 1e6, MU_PRIME)
    s, velocity = np.logspace(-8, 8, 33), 0.2  # the k-m transition length is ~10 m here
    w = asymptote.width(s, velocity)
    w_k, w_m = asymptote.toughness_width(s), asymptote.viscosity_width(s, velocity)
    assert np.all(w >= np.maximum(w_k, w_m) * (1 - 1e-9))
    assert np.all(w <= w_k + w_m)
    # near the front toughness dominates, far from it viscosity (s^(1/2) vs s^(2/3))
    assert w[0] / w_k[0] < 1.001 and w[-1] / w_m[-1] < 1.001


def test_inversion_recovers_distance_and_velocity():
    asymptote = TipAsymptote(E_PRIME, 1e6, MU_PRIME)
    s_old, dt = np.array([0.3, 0.5, 1.2, 2.0]), 0.7
    s_true = s_old + np.array([0.01, 0.2, 0.8, 1.5])
    w = asymptote.width(s_true, (s_true - s_old) / dt)
    s, velocity = asymptote.front_distance(w, s_old, dt)
    np.testing.assert_allclose(s, s_true, rtol=1e-9)
    np.testing.assert_allclose(velocity, (s_true - s_old) / dt, rtol=1e-7)


def test_front_never_retreats():
    asymptote = TipAsymptote(E_PRIME, 1e6, MU_PRIME)
    s_old = np.array([1.0, 2.0])
    w = 0.5 * asymptote.toughness_width(s_old)  # below the toughness opening: no growth
    s, velocity = asymptote.front_distance(w, s_old, 1.0)
    np.testing.assert_array_equal(s, s_old)
    np.testing.assert_array_equal(velocity, 0.0)


def test_finite_fracture_asymptote_is_griffith_and_sneddon_near_the_front():
    # a crack of half-length (or radius) a under net pressure p at toughness, K' = 4 p (2a)^(1/2):
    # Griffith 4 p (a^2 - x^2)^(1/2) / E' and Sneddon 8 p (a^2 - r^2)^(1/2) / (pi E') with
    # K_I = 2 p (a/pi)^(1/2) both equal K' s^(1/2) (1 - s/(2a))^(1/2) / E' for s = a - x <= a/2
    from hmatddm.analytical.tip_asymptote import finite_fracture_factor

    a, p = 17.0, 1e6
    s = np.linspace(0.0, 0.5 * a, 9)
    griffith = TipAsymptote(E_PRIME, p * np.sqrt(np.pi * a), MU_PRIME)
    np.testing.assert_allclose(griffith.width(s, 0.0, length=a), 4.0 * p * np.sqrt(a * a - (a - s) ** 2) / E_PRIME,
                               rtol=1e-12, atol=1e-20)
    sneddon = TipAsymptote(E_PRIME, 2.0 * p * np.sqrt(a / np.pi), MU_PRIME)
    np.testing.assert_allclose(sneddon.width(s, 0.0, length=a),
                               8.0 * p * np.sqrt(a * a - (a - s) ** 2) / (np.pi * E_PRIME), rtol=1e-12, atol=1e-20)
    assert finite_fracture_factor(s, np.inf) == pytest.approx(1.0)
    assert finite_fracture_factor(a, a) == finite_fracture_factor(0.5 * a, a)  # held beyond a/2
    # the inversion of the finite-fracture asymptote, toughness and viscosity together
    asymptote = TipAsymptote(E_PRIME, 1e6, MU_PRIME)
    s_old, dt, length = np.array([0.3, 0.5, 1.2, 2.0, 3.0]), 0.7, 6.0
    s_true = s_old + np.array([0.01, 0.2, 0.8, 0.5, 1.5])  # the last beyond L/2
    w = asymptote.width(s_true, (s_true - s_old) / dt, length=length)
    distance, _ = asymptote.front_distance(w, s_old, dt, length=length)
    np.testing.assert_allclose(distance, s_true, rtol=1e-9)
    bare, _ = asymptote.front_distance(w, s_old, dt)
    assert np.all(bare < s_true)  # the semi-infinite asymptote reads the front short


@pytest.mark.skipif(np.finfo(np.longdouble).eps > 1e-18, reason="needs an extended-precision long double")
def test_f_series_beyond_c_10_is_the_closed_form_in_extended_precision():
    """Beyond C = 10, f is its series (the closed form cancels terms of size C^3): the
    closed form in 80-bit arithmetic (eps 1e-19: round-off ~1e-19 C^3) agrees with it."""
    from hmatddm.analytical.tip_asymptote import SERIES_FROM, _f

    c = np.array([SERIES_FROM * 1.0001, 30.0, 120.0, 340.0])[:, None]
    k = np.array([0.0, 0.5, 0.97, 0.999])[None, :]
    c_l, k_l = c.astype(np.longdouble), k.astype(np.longdouble)
    one = np.longdouble(1)
    closed = (one - k_l**3 - 1.5 * c_l * (one - k_l**2) + 3 * c_l**2 * (one - k_l)
              - 3 * c_l**3 * np.log((c_l + one) / (c_l + k_l))) / 3
    series = _f(np.broadcast_to(k, (4, 4)), np.broadcast_to(c, (4, 4)), 1.0)
    closed = closed.astype(float)
    assert np.all(np.abs(series - closed) <= 1e-12 * np.abs(closed) + 4e-19 * c**3)
    # the double-precision closed form is what the series replaces: 1e-6 off at C = 340
    closed_double = (1 - k**3 - 1.5 * c * (1 - k**2) + 3 * c**2 * (1 - k) - 3 * c**3 * np.log((c + 1) / (c + k))) / 3
    assert np.max(np.abs(closed_double / closed - 1.0)[-1]) > 1e-7
