"""Microseismic sources (ref. Secs 7.2.1, 7.4.1): dynamic moduli, moment tensors, Mw,
ISO/DC/CLVD shares, the shear filter, slip onsets and merging."""
import numpy as np
import pytest

from hmatddm.errors import InputError
from hmatddm.microseismic.sources import (Medium, SlipOnset, decompose, is_shear_failure, moment_from_magnitude,
                                          moment_magnitude, moment_tensor, point_sources, seismic_moment,
                                          shear_events)


def _rotation(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def test_dynamic_moduli_of_table_7_1():
    medium = Medium(4000.0, 2350.0, 3000.0)
    assert medium.young_modulus == pytest.approx(40.97e9, rel=2e-4)
    assert medium.poisson_ratio == pytest.approx(0.2365, abs=1e-4)
    assert medium.shear_modulus == pytest.approx(16.57e9, rel=2e-4)
    # the same moduli from E and nu the way elasticity books write them
    e, nu = medium.young_modulus, medium.poisson_ratio
    assert medium.shear_modulus == pytest.approx(e / (2 * (1 + nu)), rel=1e-12)
    assert medium.lame_lambda == pytest.approx(e * nu / ((1 + nu) * (1 - 2 * nu)), rel=1e-12)


def test_pure_shear_moment_tensor_is_a_double_couple_with_m0_g_a_d():
    medium = Medium()
    mu, area, slip = medium.shear_modulus, 4.0, 1e-3
    tensor = moment_tensor([[slip, 0, 0]], [[0, 0, 1.0]], area, medium)[0]
    expected = np.zeros((3, 3))
    expected[0, 2] = expected[2, 0] = mu * area * slip
    np.testing.assert_allclose(tensor, expected, rtol=1e-14)
    m0 = seismic_moment([[slip, 0, 0]], area, medium)[0]
    assert m0 == pytest.approx(mu * area * slip, rel=1e-14)
    assert np.linalg.norm(tensor) / np.sqrt(2) == pytest.approx(m0, rel=1e-14)
    iso, dc, clvd = decompose(tensor[None])
    assert iso[0] == pytest.approx(0, abs=1e-14) and clvd[0] == pytest.approx(0, abs=1e-14) and dc[0] == 1.0


def test_tensile_opening_is_iso_plus_clvd_with_positive_iso():
    medium = Medium()
    lam, mu = medium.lame_lambda, medium.shear_modulus
    tensor = moment_tensor([[0, 0, 2e-3]], [[0, 0, 1.0]], 1.0, medium)
    np.testing.assert_allclose(np.diag(tensor[0]), 2e-3 * np.array([lam, lam, lam + 2 * mu]), rtol=1e-14)
    iso, dc, clvd = decompose(tensor)
    expected_iso = (3 * lam + 2 * mu) / (3 * (lam + 2 * mu))  # Vavrycuk (2015) for a tensile crack
    assert iso[0] == pytest.approx(expected_iso, rel=1e-12) and iso[0] > 0
    assert clvd[0] == pytest.approx(1 - expected_iso, rel=1e-12) and dc[0] == pytest.approx(0, abs=1e-12)
    # closing: negative ISO and CLVD
    iso, dc, clvd = decompose(-tensor)
    assert iso[0] == pytest.approx(-expected_iso) and clvd[0] == pytest.approx(-(1 - expected_iso))


def test_decomposition_shares_sum_to_one_and_do_not_depend_on_the_frame():
    rng = np.random.default_rng(3)
    raw = rng.standard_normal((50, 3, 3))
    tensors = raw + np.swapaxes(raw, 1, 2)
    iso, dc, clvd = decompose(tensors)
    np.testing.assert_allclose(np.abs(iso) + dc + np.abs(clvd), 1.0, atol=1e-12)
    rotation = _rotation(4)
    rotated = np.einsum("ij,ejk,lk->eil", rotation, tensors, rotation)
    for a, b in zip((iso, dc, clvd), decompose(rotated)):
        np.testing.assert_allclose(a, b, atol=1e-10)
    with pytest.raises(InputError, match="zero"):
        decompose(np.zeros((1, 3, 3)))


def test_moment_magnitude_eq_7_2():
    assert moment_magnitude(1e9) == pytest.approx(0.0)
    assert moment_magnitude(10 ** 4.5) == pytest.approx(-3.0)
    np.testing.assert_allclose(moment_from_magnitude(moment_magnitude([1e3, 2e7])), [1e3, 2e7], rtol=1e-12)
    with pytest.raises(InputError, match="moment"):
        moment_magnitude([1.0, 0.0])


def test_shear_filter_eq_7_29():
    normal = np.array([[0, 1.0, 0]] * 4)
    dd = np.array([[2.0, 1.0, 0], [1.9, 1.0, 0], [0.0, 0.0, 0], [1.0, -0.4, 0]])
    np.testing.assert_array_equal(is_shear_failure(dd, normal), [True, False, False, True])
    np.testing.assert_array_equal(is_shear_failure(dd, normal, shear_ratio=0.0), [True, True, False, True])


def test_events_from_elements_take_their_onset_and_can_be_merged():
    medium = Medium()
    centers = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [10.0, 0.0], [5.0, 5.0]])
    normals = np.tile([0.0, 1.0], (5, 1))
    dd = np.array([[1e-3, 0], [2e-3, 1e-4], [1e-3, 0], [1e-3, 0], [1e-4, 1e-3]])  # the last: tensile, filtered
    onset = SlipOnset()
    onset.observe(centers, [True, True, False, False, True], time=10.0, step=1)
    onset.observe(centers, [True, True, True, False, True], time=20.0, step=2)
    events = shear_events(centers, normals, dd, np.ones(5), medium, fracture_id=[7, 7, 7, 8, 9], onset=onset,
                          final_time=30.0, final_step=3)
    assert len(events) == 4
    np.testing.assert_array_equal(events.time, [10.0, 10.0, 20.0, 30.0])
    np.testing.assert_allclose(events.position[:, 2], 0.0)
    merged = shear_events(centers, normals, dd, np.ones(5), medium, fracture_id=[7, 7, 7, 8, 9], onset=onset,
                          final_time=30.0, final_step=3, merge=True, radius=np.full(5, 0.5))
    assert len(merged) == 3  # elements 0 and 1 (neighbours, same step) join; 2 started later; 3 is far
    np.testing.assert_array_equal(merged.elements, [2, 1, 1])
    np.testing.assert_allclose(merged.potency.sum(), events.potency.sum(), rtol=1e-14)
    np.testing.assert_allclose(merged.moment_tensor[0], events.moment_tensor[:2].sum(axis=0), rtol=1e-14)
    np.testing.assert_allclose(merged.position[0], [0.5, 0.0, 0.0])


def test_bad_medium_and_sources_are_refused_naming_the_field():
    with pytest.raises(InputError, match="p_wave_speed"):
        Medium(-4000.0, 2350.0, 3000.0)
    with pytest.raises(InputError, match="s_wave_speed"):
        Medium(4000.0, 4000.0, 3000.0)
    with pytest.raises(InputError, match="s_wave_speed"):
        Medium(4000.0, 5000.0, 3000.0)
    with pytest.raises(InputError, match="density"):
        Medium(4000.0, 2350.0, 0.0)
    with pytest.raises(InputError, match="normal"):
        point_sources([0, 0, 0], [1e-3, 0, 0], [0, 0, 2.0], 1.0, Medium())
    with pytest.raises(InputError, match="displacement_discontinuity"):
        point_sources([0, 0, 0], [0, 0, 0], [0, 0, 1.0], 1.0, Medium())
