"""The universal tip asymptote (Dontsov and Peirce 2015) against its vertices, and its inversion."""
import numpy as np
import pytest

from hmatddm.fracture.tip_asymptote import TipAsymptote, g_delta, toughness_prime

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
