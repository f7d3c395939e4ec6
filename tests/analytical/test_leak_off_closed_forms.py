"""Leak-off-dominated sizes (K~ / M~ vertices) and the plane-strain K-K~ edge
(hmatddm.analytical.leak_off) against mass balance integrated apart and their limits."""
import numpy as np
import pytest
from scipy.integrate import quad

import hmatddm as hd
from hmatddm.analytical import (kgd_k_vertex, kgd_leak_off_half_length, kgd_toughness_leak_off_edge,
                                radial_leak_off_radius)
from hmatddm.errors import InputError

MAT = hd.Elastic(8e9, 0.25)


def test_vertex_sizes_leak_the_injection():
    """Q = int C' / (t - t_0)^(1/2) dA with the front's arrival times t_0 of the closed
    forms, integrated by quadrature."""
    q, c, t = 2e-3, 3e-4, 50.0
    length = float(kgd_leak_off_half_length(t, q, c))
    arrival = lambda x: t * (x / length) ** 2  # l ~ t^(1/2)
    leaked = 2 * quad(lambda x: c / np.sqrt(t - arrival(x)), 0, length, limit=200)[0]
    assert leaked == pytest.approx(q, rel=1e-6)
    radius = float(radial_leak_off_radius(t, q, c))
    arrival = lambda r: t * (r / radius) ** 4  # R ~ t^(1/4)
    leaked = quad(lambda r: 2 * np.pi * r * c / np.sqrt(t - arrival(r)), 0, radius, limit=200)[0]
    assert leaked == pytest.approx(q, rel=1e-6)


def test_edge_joins_the_k_and_k_tilde_vertices():
    t = np.array([1.0, 10.0, 100.0, 1e3, 1e4])
    q, k_ic, e = 1e-4, 1e6, MAT.plane_strain_modulus
    # no leak-off: the K vertex, l = (E' Q t / (2 pi^1/2 K_Ic))^(2/3)
    length, net = kgd_toughness_leak_off_edge(t, q, 1e-24, 5e6, k_ic, e)
    vertex, _, vertex_net = kgd_k_vertex(t, q, k_ic, MAT)
    np.testing.assert_allclose(length, vertex, rtol=2e-5)
    np.testing.assert_allclose(net, vertex_net, rtol=2e-5)
    # strong leak-off: below the leak-off vertex (some fluid is stored) and closing on it
    length, net = kgd_toughness_leak_off_edge(t, q, 1e-10, 5e6, k_ic, e)
    ratio = length / kgd_leak_off_half_length(t, q, 1.0) * (1e-10 * (5e6 + net))
    assert np.all(ratio < 1.0) and np.all(np.diff(ratio) > 0) and ratio[-1] > 0.985
    # converged in the step count
    fine, _ = kgd_toughness_leak_off_edge(t, q, 1e-10, 5e6, k_ic, e, substeps=6000)
    coarse, _ = kgd_toughness_leak_off_edge(t, q, 1e-10, 5e6, k_ic, e, substeps=1000)
    np.testing.assert_allclose(coarse, fine, rtol=2e-3)


def test_bad_input():
    with pytest.raises(InputError, match="carter"):
        kgd_leak_off_half_length(1.0, 1e-3, 0.0)
    with pytest.raises(InputError, match="times must be finite and > 0"):
        kgd_toughness_leak_off_edge([0.0, 1.0], 1e-3, 1e-11, 1e6, 1e6, 1e10)


def test_radial_edge_joins_the_k_and_k_tilde_vertices():
    from hmatddm.analytical import radial_k_vertex, radial_toughness_leak_off_edge

    t = np.array([1.0, 10.0, 100.0, 1e3, 1e4])
    q, k_ic, e = 1e-3, 1e6, MAT.plane_strain_modulus
    radius, _ = radial_toughness_leak_off_edge(t, q, 1e-24, 5e6, k_ic, e, substeps=1000)
    np.testing.assert_allclose(radius, radial_k_vertex(t, q, k_ic, MAT)[0], rtol=1e-4)
    radius, net = radial_toughness_leak_off_edge(t, q, 1e-9, 5e6, k_ic, e, substeps=1000)
    ratio = radius / np.array([float(radial_leak_off_radius(ti, q, 1e-9 * (5e6 + pi))) for ti, pi in zip(t, net)])
    assert np.all(ratio < 1.0) and np.all(np.diff(ratio) > 0) and ratio[-1] > 0.97
