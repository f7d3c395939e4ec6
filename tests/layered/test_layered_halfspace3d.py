"""3D half-space (a void top layer, ref. Sec. 3.4.1 with gamma = 0): the independent
reference of tests/_mindlin.py (Mindlin's point force, Gauss quadrature by reciprocity)
checked on its own, and the layered rectangle kernels checked against it."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.layered import LayeredMedium

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


# -- the layered rectangle kernels against the reference ------------------------------
# void above z = 0: a free surface. gauss_points=8: the default 4 leaves 1.1e-6 (stress) and
# 1.2e-6 (entries) on the horizontal rectangle's near points; 8 gives 3e-13 (max over all three).
HALF_SPACE = LayeredMedium([0.0], [0.0, G], [NU, NU], gauss_points=8)


def _frame(e1, e2):
    e1, e2 = np.asarray(e1, float), np.asarray(e2, float)
    e1, e2 = e1 / np.linalg.norm(e1), e2 / np.linalg.norm(e2)
    return np.array([e1, e2, np.cross(e1, e2)])


RECTANGLES = {  # center, frame, half sizes: a 0.8 x 0.6 m rectangle 0.7-1.5 m below the surface
    "horizontal": ([0.3, -0.2, -0.9], _frame([1, 0, 0], [0, 1, 0]), 0.4, 0.3),
    "vertical": ([0.0, 0.1, -1.2], _frame([0, 1, 0], [0, 0, 1]), 0.4, 0.3),
    "tilted": ([0.2, 0.0, -1.1], _frame([1, 1, 0], [-0.5, 0.5, 1.0]), 0.4, 0.3),
    # no horizontal side: Okada's point source at the Gauss points (okada_point3d)
    "skewed": ([0.1, 0.2, -1.3], _frame([1, 0, 0.5], [-0.2, 1, 0.4]), 0.4, 0.3),
}
OFFSETS = np.array([[0.0, 0.0, 0.35], [0.55, -0.3, 0.2], [-0.2, 0.6, -0.4],  # near field (in the element frame)
                    [2.5, 1.0, -0.6], [-3.0, -2.0, -2.5]])                      # far field


def _points(center, frame):
    points = np.asarray(center) + OFFSETS @ frame
    return points[points[:, 2] < -0.05]  # in the rock, off the surface


@pytest.mark.parametrize("name", sorted(RECTANGLES))
def test_half_space_stress_of_a_rectangle_matches_mindlin(name):
    center, frame, a, b = RECTANGLES[name]
    mesh = hd.Mesh3D.from_rectangles(np.array([center], float), frame[0][None], frame[1][None], np.array([a]),
                                     np.array([b]))
    points = _points(center, frame)
    assert len(points) >= 4
    for r in range(3):
        dd = np.zeros((1, 3))
        dd[0, r] = 1e-3
        got = hd.stress_at(mesh, HALF_SPACE, dd, points)
        for k, x in enumerate(points):
            _, reference = _mindlin.dd_fields(x, center, frame, a, b, 0.0, NU, G)
            expected = 1e-3 * reference[r]
            assert np.abs(got[k] - expected).max() <= 1e-6 * np.abs(expected).max(), (name, r, k)


@pytest.mark.parametrize("backend", ["dense", "hmatrix"])
@pytest.mark.parametrize("name", sorted(RECTANGLES))
def test_half_space_operator_entries_match_mindlin(name, backend):
    """Traction at a small receiver element (normal tilted) from the rectangle's DD."""
    center, frame, a, b = RECTANGLES[name]
    receiver = np.asarray(center) + np.array([0.55, -0.3, 0.2]) @ frame
    r_frame = _frame([1, 0, 0.3], [0, 1, 0])
    mesh = hd.Mesh3D.from_rectangles(np.array([center, receiver], float), np.array([frame[0], r_frame[0]]),
                                     np.array([frame[1], r_frame[1]]), np.array([a, 0.05]), np.array([b, 0.05]))
    block = hd.ElasticityOperator(mesh, HALF_SPACE, backend=backend).to_dense()[3:6, 0:3]
    _, reference = _mindlin.dd_fields(receiver, center, frame, a, b, 0.0, NU, G)
    expected = np.einsum("rij,j->ir", reference, r_frame[2])  # traction component i of DD component r
    assert np.abs(block - expected).max() <= 1e-6 * np.abs(expected).max()
