"""3D half-space (a void top layer, ref. Sec. 3.4.1 with gamma = 0): the independent
reference of tests/_mindlin.py (Mindlin's point force, Gauss quadrature by reciprocity)
checked on its own: Kelvin near the source and at depth, a traction-free surface,
equilibrium, reciprocity, and the DD quadrature against tests/kelvin_reference.py."""
import numpy as np
import pytest

import kelvin_reference
import _mindlin

G, NU = 10e9, 0.25


def _kelvin_green(field, source):
    r = field - source
    rn = np.linalg.norm(r, axis=1)
    k = 1.0 / (16.0 * np.pi * G * (1.0 - NU))
    return k * ((3.0 - 4.0 * NU) * np.eye(3)[None] / rn[:, None, None]
                + r[:, :, None] * r[:, None, :] / rn[:, None, None] ** 3)


# -- the reference on its own: the three properties that determine Mindlin's solution ----
def test_reference_is_kelvin_near_the_source_and_deep_below_the_surface():
    rng = np.random.default_rng(0)
    source = np.array([0.3, -0.2, -1e6])
    field = source + rng.normal(size=(8, 3))
    green = np.array(_mindlin.green(field, source, 0.0, NU, G)).transpose(2, 0, 1)
    kelvin = _kelvin_green(field, source)
    assert np.abs(green - kelvin).max() <= 1e-5 * np.abs(kelvin).max()  # image terms ~ |r| / depth
    # near a source 1 m deep, the difference (the image field) is smooth: it tends to its
    # value at the source as r -> 0 while Kelvin's part grows like 1/r
    source = np.array([0.0, 0.0, -1.0])
    directions = np.array([[0.6, 0.0, 0.8], [0.0, -1.0, 0.0]])
    diffs = []
    for r in (1e-3, 1e-5):
        field = source + r * directions
        kelvin = _kelvin_green(field, source)
        diffs.append(np.array(_mindlin.green(field, source, 0.0, NU, G)).transpose(2, 0, 1) - kelvin)
        assert np.abs(diffs[-1]).max() < 1e-2 * r * np.abs(kelvin).max() / 1e-3
    assert np.abs(diffs[0] - diffs[1]).max() <= 1e-2 * np.abs(diffs[1]).max()


def test_reference_surface_is_traction_free_and_in_equilibrium():
    rng = np.random.default_rng(1)
    source = np.array([0.3, -0.2, 0.5])  # surface at z = 2.5: 2 m deep
    surface = 2.5
    points = np.c_[2.0 * rng.normal(size=(8, 2)), np.full(8, surface)]
    stress = _mindlin.point_force_stress(points, source, surface, NU, G)  # (Q, k, i, j)
    assert np.abs(stress[..., 2]).max() <= 1e-13 * np.abs(stress).max()
    assert np.abs(stress[..., :2, :2]).max() > 1e-3 / (4 * np.pi)  # the surface is loaded in-plane
    # div sigma = 0 inside the solid (central differences of the exact stress)
    points = source + rng.normal(size=(6, 3))
    points[:, 2] = np.minimum(points[:, 2], surface - 0.3)
    h, div = 1e-4, 0.0
    for j, step in enumerate(h * np.eye(3)):
        div = div + (_mindlin.point_force_stress(points + step, source, surface, NU, G)[..., j]
                     - _mindlin.point_force_stress(points - step, source, surface, NU, G)[..., j]) / (2 * h)
    scale = np.abs(_mindlin.point_force_stress(points, source, surface, NU, G)).max()
    assert np.abs(div).max() <= 1e-6 * scale / np.linalg.norm(points - source, axis=1).min()


def test_reference_green_function_is_reciprocal():
    y, x = np.array([[0.5, 0.7, -0.4]]), np.array([-0.2, 0.1, -1.3])
    g_yx = np.array(_mindlin.green(y, x, 0.0, NU, G))[:, :, 0]
    g_xy = np.array(_mindlin.green(x[None], y[0], 0.0, NU, G))[:, :, 0]
    assert np.allclose(g_yx, g_xy.T, rtol=1e-13, atol=0.0)


@pytest.mark.parametrize("frame", [np.eye(3), np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])])
def test_reference_dd_stress_deep_is_the_kelvin_reference(frame):
    center = np.array([0.0, 0.0, -1e5])
    x = center + np.array([0.4, 1.3, 0.5])
    _, stress = _mindlin.dd_fields(x, center, frame, 0.5, 0.3, 0.0, NU, G)
    points, weights = kelvin_reference.rectangle_quadrature(center, frame[0], frame[1], 0.5, 0.3, 24)
    kelvin = kelvin_reference.stress_from_dd(x, points, weights, frame[2], NU, G)
    assert np.abs(stress - kelvin).max() <= 1e-6 * np.abs(kelvin).max()


def test_reference_dd_quadrature_has_converged_near_the_element():
    frame = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])
    center = np.array([0.0, 0.0, -0.8])
    for offset in ([0.2, 0.3, 0.1], [0.6, 0.1, 0.6], [3.0, 2.0, 0.5]):
        x = center + np.array(offset)
        u1, s1 = _mindlin.dd_fields(x, center, frame, 0.5, 0.5, 0.0, NU, G)
        u2, s2 = _mindlin.dd_fields(x, center, frame, 0.5, 0.5, 0.0, NU, G, order=16, panels=8)
        assert np.abs(u1 - u2).max() <= 1e-12 * np.abs(u2).max()
        assert np.abs(s1 - s2).max() <= 1e-12 * np.abs(s2).max()
