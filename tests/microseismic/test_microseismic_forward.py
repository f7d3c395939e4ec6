"""Forward model (ref. Sec. 7.2.2): radiation factors over the focal sphere, far-field
amplitudes against Aki & Richards' closed form, travel times, invariance, bad input."""
import numpy as np
import pytest

from hmatddm.errors import InputError
from hmatddm.microseismic import forward
from hmatddm.microseismic.forward import Well, observe, radiation_factors, receivers_of, wells_from_positions
from hmatddm.microseismic.sources import Medium, point_sources

MEDIUM = Medium()


def _double_couple(slip_direction=(1.0, 0, 0), normal=(0, 0, 1.0)):
    return point_sources([0.0, 0.0, 0.0], 1e-3 * np.asarray(slip_direction), normal, 4.0, MEDIUM)


def _sphere(n_theta=40, n_phi=80):
    """Gauss-Legendre in cos(theta) x trapezoid in phi: directions (Q, 3) and weights summing to 1."""
    x, w = np.polynomial.legendre.leggauss(n_theta)
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    cos, p = np.meshgrid(x, phi, indexing="ij")
    sin = np.sqrt(1 - cos ** 2)
    directions = np.stack([sin * np.cos(p), sin * np.sin(p), cos], axis=-1).reshape(-1, 3)
    weights = (np.repeat(w, n_phi) / n_phi / 2.0)
    return directions, weights


def test_rms_radiation_factors_of_a_double_couple_by_quadrature():
    events = _double_couple()
    directions, weights = _sphere()
    f_p, f_s = radiation_factors(events.moment_tensor, directions[None], events.seismic_moment, MEDIUM.shear_modulus)
    assert np.sum(weights) == pytest.approx(1.0)
    assert np.sqrt(np.sum(weights * f_p[0] ** 2)) == pytest.approx(np.sqrt(4 / 15), rel=1e-10)  # 0.516
    assert np.sqrt(np.sum(weights * f_s[0] ** 2)) == pytest.approx(np.sqrt(2 / 5), rel=1e-10)   # 0.632
    assert round(np.sqrt(4 / 15), 2) == 0.52 and round(np.sqrt(2 / 5), 2) == 0.63  # the reference's values


def test_maxima_and_nodal_directions_of_a_double_couple():
    events = _double_couple()  # slip along x on the plane z = 0
    s2 = 1 / np.sqrt(2)
    directions = np.array([[s2, 0, s2], [s2, 0, -s2], [1, 0, 0], [0, 0, 1], [0, 1, 0]])
    f_p, f_s = radiation_factors(events.moment_tensor, directions[None], events.seismic_moment, MEDIUM.shear_modulus)
    # P: largest (1) on the T and P axes, zero on both nodal planes and the null axis
    np.testing.assert_allclose(f_p[0], [1, 1, 0, 0, 0], atol=1e-14)
    # S: largest (1) along the slip and the normal, zero on the T, P and null axes
    np.testing.assert_allclose(f_s[0], [0, 0, 1, 1, 0], atol=1e-14)
    directions, _ = _sphere(20, 40)
    f_p, f_s = radiation_factors(events.moment_tensor, directions[None], events.seismic_moment, MEDIUM.shear_modulus)
    assert f_p.max() <= 1 + 1e-12 and f_s.max() <= 1 + 1e-12


def test_amplitudes_match_aki_richards_far_field_closed_form():
    events = _double_couple()
    rng = np.random.default_rng(1)
    receivers = rng.normal(size=(30, 3)) * 40.0
    obs = observe(events, receivers, MEDIUM)
    r = np.linalg.norm(receivers, axis=1)
    theta = np.arccos(receivers[:, 2] / r)
    phi = np.arctan2(receivers[:, 1], receivers[:, 0])
    m0 = events.seismic_moment[0]
    # Aki & Richards (2002) Eq. 4.33 for slip along x on z = 0: P ~ sin 2theta cos phi,
    # S ~ cos 2theta cos phi (theta direction) and -cos theta sin phi (phi direction)
    p_closed = m0 * np.abs(np.sin(2 * theta) * np.cos(phi)) / (
        4 * np.pi * MEDIUM.density * MEDIUM.p_wave_speed ** 3 * r)
    s_closed = m0 * np.hypot(np.cos(2 * theta) * np.cos(phi), np.cos(theta) * np.sin(phi)) / (
        4 * np.pi * MEDIUM.density * MEDIUM.s_wave_speed ** 3 * r)
    np.testing.assert_allclose(obs.amplitude_p[0], p_closed, rtol=1e-10, atol=1e-12 * p_closed.max())
    np.testing.assert_allclose(obs.amplitude_s[0], s_closed, rtol=1e-10, atol=1e-12 * s_closed.max())
    np.testing.assert_allclose(obs.travel_time_p[0], r / MEDIUM.p_wave_speed, rtol=1e-14)
    np.testing.assert_allclose(obs.s_minus_p[0], r / MEDIUM.s_wave_speed - r / MEDIUM.p_wave_speed, rtol=1e-12)
    # Eqs 7.17-7.18: Omega = M0 F / (4 pi rho v^3 r)
    np.testing.assert_allclose(obs.amplitude_p[0], m0 * obs.factor_p[0] / (
        4 * np.pi * MEDIUM.density * MEDIUM.p_wave_speed ** 3 * r), rtol=1e-12)


def test_factors_are_invariant_under_rotating_source_and_receivers_together():
    rng = np.random.default_rng(2)
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    normal = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
    slip = np.cross(normal, [1.0, 0, 0])
    dd = 1e-3 * (slip / np.linalg.norm(slip) + 0.3 * normal)  # with a tensile part
    receivers = rng.normal(size=(12, 3)) * 30.0
    a = observe(point_sources([0, 0, 0], dd, normal, 2.0, MEDIUM), receivers, MEDIUM)
    b = observe(point_sources([0, 0, 0], q @ dd, q @ normal, 2.0, MEDIUM), receivers @ q.T, MEDIUM)
    for name in ("factor_p", "factor_s", "amplitude_p", "amplitude_s", "travel_time_s"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-10, atol=1e-14)


def test_chunked_evaluation_equals_one_chunk(monkeypatch):
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(11, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    events = point_sources(rng.normal(size=(11, 3)), 1e-3 * rng.normal(size=(11, 3)), normals, 1.0, MEDIUM)
    receivers, well = receivers_of([Well(50, 0), Well(50, -20)])
    whole = observe(events, receivers, MEDIUM, well)
    monkeypatch.setattr(forward, "CHUNK", 3)
    chunked = observe(events, receivers, MEDIUM, well)
    for name in ("amplitude_p", "amplitude_s", "direction", "distance"):
        np.testing.assert_array_equal(getattr(whole, name), getattr(chunked, name))


def test_wells_and_receivers():
    receivers, well = receivers_of([Well(50, 0), Well(50, -20)])
    assert receivers.shape == (18, 3) and list(np.bincount(well)) == [9, 9]
    np.testing.assert_allclose(receivers[:9, 2], np.arange(-20, 21, 5))
    with pytest.raises(InputError, match="wells must hold at least one"):
        wells_from_positions([])
    with pytest.raises(InputError, match="microseismic.receiver_spacing"):
        wells_from_positions([[0, 0]], spacing=0.0, prefix="microseismic.")
    with pytest.raises(InputError, match="receiver_bottom"):
        wells_from_positions([[0, 0]], top=-30.0)
    events = _double_couple()
    with pytest.raises(InputError, match="wells: receiver .* lies on a source"):
        observe(events, Well(0.0, 0.0).receivers(), MEDIUM)
