import numpy as np
import pytest

import hmatddm as hd

MAT = hd.Elastic(shear_modulus=24e9, poisson_ratio=0.25)  # ref. Table 4.1


def test_radial_k_vertex_reproduces_the_reference_constants():
    """ref. Eqs 4.65-4.67 written with K' = 4 (2/pi)^(1/2) K_Ic (Eq. 4.68)."""
    t, q, k_ic = np.array([1.0, 10.0, 50.0]), 0.01, 5e6
    e, kp = MAT.plane_strain_modulus, hd.analytical.toughness_scale(k_ic)
    radius, width, pressure = hd.analytical.radial_k_vertex(t, q, k_ic, MAT)
    assert np.allclose(radius, 0.8546 * (q * e * t / kp) ** 0.4, rtol=2e-4)
    assert np.allclose(width, 0.6537 * (kp**4 * q * t / e**4) ** 0.2, rtol=2e-4)
    assert np.allclose(pressure, 0.3004 * (kp**6 / (e * q * t)) ** 0.2, rtol=2e-4)


def test_radial_k_vertex_is_a_sneddon_crack_at_toughness():
    radius, width, pressure = hd.analytical.radial_k_vertex(20.0, 0.01, 1e6, MAT)
    assert hd.analytical.sneddon_volume(radius, pressure, MAT) == pytest.approx(0.01 * 20.0, rel=1e-12)
    assert 2 * pressure * np.sqrt(radius / np.pi) == pytest.approx(1e6, rel=1e-12)
    assert width == pytest.approx(hd.analytical.sneddon_opening(0.0, radius, pressure, MAT), rel=1e-12)


def test_kgd_k_vertex_is_a_griffith_crack_at_toughness():
    half, width, pressure = hd.analytical.kgd_k_vertex(30.0, 1e-3, 1e6, MAT)
    kp = hd.analytical.toughness_scale(1e6)
    assert half == pytest.approx(0.9324 * (MAT.plane_strain_modulus * 1e-3 * 30.0 / kp) ** (2 / 3), rel=2e-4)
    assert np.pi * width * half / 2 == pytest.approx(1e-3 * 30.0, rel=1e-12)  # volume of the ellipse
    assert pressure * np.sqrt(np.pi * half) == pytest.approx(1e6, rel=1e-12)
    assert width == pytest.approx(hd.analytical.griffith_opening(0.0, half, pressure, MAT), rel=1e-12)


def test_radial_m_vertex_grows_as_t_to_the_four_ninths():
    r1, w1 = hd.analytical.radial_m_vertex(10.0, 0.01, 1e-3, MAT)
    r2, w2 = hd.analytical.radial_m_vertex(20.0, 0.01, 1e-3, MAT)
    assert r2 / r1 == pytest.approx(2 ** (4 / 9)) and w2 / w1 == pytest.approx(2 ** (1 / 9))


def test_sneddon_axis_stress_limits():
    """At the crack face sigma_z = -p; far away every component decays."""
    _, sigma_z, _ = hd.analytical.sneddon_axis_stress(1e-9, 1.0, 1e6, 0.25)
    assert sigma_z == pytest.approx(-1e6, rel=1e-6)
    far = hd.analytical.sneddon_axis_stress(1e3, 1.0, 1e6, 0.25)
    assert all(abs(v) < 1e-3 * 1e6 for v in far)
