"""The half-space in closed form (issue 32, :mod:`hmatddm.layered.okada3d`, Okada 1992):
its whole-space part against the uniform-rock kernel, the whole against the image
quadrature (``method="quadrature"``, which tests/layered/test_layered_halfspace3d.py
checks against Mindlin), the free surface free of traction, and the operator."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.kernels import rectangle3d
from hmatddm.layered import LayeredMedium, influence3d, okada3d

G, NU = 10e9, 0.25
CLOSED = LayeredMedium([0.0], [0.0, G], [0.0, NU], images=1)
QUADRATURE = LayeredMedium([0.0], [0.0, G], [0.0, NU], images=1, method="quadrature", gauss_points=8)


def _frame(e1, e2):
    e1, e2 = np.asarray(e1, float), np.asarray(e2, float)
    e1, e2 = e1 / np.linalg.norm(e1), e2 / np.linalg.norm(e2)
    return np.array([e1, e2, np.cross(e1, e2)])


def _dipping(strike_angle, dip, e2_horizontal=False):
    """A frame with a horizontal side at ``strike_angle`` dipping ``dip`` (radians); with
    ``e2_horizontal`` the horizontal side is e2 (e1 runs down the dip)."""
    s = np.array([np.cos(strike_angle), np.sin(strike_angle), 0.0])
    up = np.cos(dip) * np.array([-s[1], s[0], 0.0]) + np.sin(dip) * np.array([0.0, 0.0, 1.0])
    return _frame(-up, s) if e2_horizontal else _frame(s, up)


def _okada(point, center, frame, a, b, real, image, nu=NU):
    closed, okada, half = okada3d.halfspace_geometry(frame[None], np.array([a]), np.array([b]))
    assert closed[0]
    out = np.empty((3, 3, 3))
    okada3d.okada_stress(np.asarray(point, float), np.asarray(center, float), okada[0], half[0, 0], half[0, 1], 0.0,
                         G, nu, real, image, np.empty((5, 3, 3, 3)), np.empty((30, 4)), out)
    return out


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.45])
def test_part_a_alone_is_the_uniform_rock_rectangle(nu):
    rng = np.random.default_rng(7)
    worst = 0.0
    for trial in range(12):
        dip = [0.0, np.pi / 2, np.pi][trial] if trial < 3 else rng.uniform(0.0, np.pi)
        frame = _dipping(rng.uniform(0.0, 2.0 * np.pi), dip, e2_horizontal=trial % 2 == 1)
        a, b = rng.uniform(0.3, 2.0, 2)
        center = np.array([0.3, -0.2, -4.0])
        for point in center + rng.normal(size=(4, 3)) * 2.0:
            expected = np.empty((3, 3, 3))
            rectangle3d.stress_pair(point, center, frame, a, b, G, nu, 0.0, expected, np.empty((3, 3, 3)))
            got = _okada(point, center, frame, a, b, True, False, nu)
            worst = max(worst, np.abs(got - expected).max() / np.abs(expected).max())
    assert worst <= 1e-10


RECTANGLES = {  # centre, frame, half sides
    "vertical": ([0.0, 0.1, -1.2], _dipping(0.3, np.pi / 2), 0.4, 0.3),
    "horizontal": ([0.3, -0.2, -0.9], _frame([1, 0, 0], [0, 1, 0]), 0.4, 0.3),
    "dip 30": ([0.2, 0.0, -1.1], _dipping(0.7, np.radians(30.0)), 0.4, 0.3),
    "dip 120": ([0.2, 0.0, -1.1], _dipping(-0.4, np.radians(120.0)), 0.4, 0.3),
    "dip 60, e2 horizontal": ([0.1, 0.2, -1.0], _dipping(1.1, np.radians(60.0), e2_horizontal=True), 0.3, 0.4),
    "0.25 m under the surface": ([0.0, 0.0, -0.25 - 0.3 * np.sin(1.0)], _dipping(0.0, 1.0), 0.4, 0.3),
    "touching the surface": ([0.0, 0.0, -0.3], _dipping(0.5, np.pi / 2), 0.4, 0.3),
}


@pytest.mark.parametrize("name", sorted(RECTANGLES))
def test_half_space_closed_form_is_the_quadrature(name):
    center, frame, a, b = RECTANGLES[name]
    center = np.asarray(center, float)
    mesh = hd.Mesh3D.from_rectangles(center[None], frame[0][None], frame[1][None], np.array([a]), np.array([b]))
    rng = np.random.default_rng(1)
    points = np.vstack([center + rng.normal(size=(8, 3)) * [0.6, 0.6, 0.4],      # near
                        center + rng.normal(size=(4, 3)) * [4.0, 4.0, 2.0],      # far
                        center + [[0.5, -0.3, 0.0], [-0.2, 0.4, 0.0]] + [0, 0, -center[2] - 1e-3]])  # at the surface
    points = points[points[:, 2] < -1e-4]
    assert len(points) >= 8
    scale = 0.0
    worst = 0.0
    for q in range(3):
        dd = np.zeros((1, 3))
        dd[0, q] = 1.0
        got = hd.stress_at(mesh, CLOSED, dd, points)
        expected = hd.stress_at(mesh, QUADRATURE, dd, points)
        worst = max(worst, np.abs(got - expected).max())
        scale = max(scale, np.abs(expected).max())
    assert worst <= 1e-8 * scale


def test_closed_form_on_the_singular_lines_of_okada():
    """Points on the negative extension of an edge (``R + xi = 0``, ``R + eta = 0`` of the
    real or image source) and a vertical rectangle (``cos(dip) = 0``)."""
    center = np.array([0.0, 0.0, -1.2])
    mesh = hd.Mesh3D.from_rectangles(center[None], np.array([[1.0, 0, 0]]), np.array([[0, 0, 1.0]]), np.array([0.4]),
                                     np.array([0.3]))
    points = np.array([[0.4, 0.0, -2.5], [0.4, 0.0, -0.6], [1.0, 0.0, -1.5], [1.0, 0.0, -0.9], [-0.7, 0.0, -0.3],
                       [0.4, 1e-13, -2.0]])
    for q in range(3):
        dd = np.zeros((1, 3))
        dd[0, q] = 1.0
        got = hd.stress_at(mesh, CLOSED, dd, points)
        expected = hd.stress_at(mesh, QUADRATURE, dd, points)
        assert np.all(np.isfinite(got))
        assert np.abs(got - expected).max() <= 1e-8 * np.abs(expected).max()


@pytest.mark.parametrize("name", sorted(RECTANGLES))
def test_free_surface_is_free_of_traction(name):
    center, frame, a, b = RECTANGLES[name]
    rng = np.random.default_rng(2)
    for xy in rng.normal(size=(5, 2)) * 1.5:
        point = np.array([center[0] + xy[0], center[1] + xy[1], 0.0])
        stress = _okada(point, center, frame, a, b, True, True)
        assert np.abs(stress[:, :, 2]).max() <= 1e-13 * np.abs(stress).max()


def _mixed_mesh():
    """Dipping squares of both side orders near the surface, and one without a horizontal side."""
    rng = np.random.default_rng(3)
    centers = np.array([[x, y, -0.6 - 0.9 * k] for k in range(3) for x in (0.0, 1.0) for y in (0.0, 0.9)])
    frames = np.array([_dipping(rng.uniform(0, 2 * np.pi), rng.uniform(0, np.pi), e2_horizontal=e % 2 == 1)
                       for e in range(len(centers))])
    frames[5] = _frame([1.0, 0.0, 0.4], [-0.12, 1.0, 0.3])  # no horizontal side: quadrature
    return hd.Mesh3D.from_rectangles(centers, frames[:, 0], frames[:, 1], np.full(len(centers), 0.3),
                                     np.full(len(centers), 0.2))


def test_operator_of_a_half_space_mesh_is_the_quadrature_one():
    mesh = _mixed_mesh()
    closed = hd.ElasticityOperator(mesh, CLOSED, backend="dense")
    assert closed.data.closed_form.sum() == mesh.n_elements - 1 and not closed.data.closed_form[5]
    reference = hd.ElasticityOperator(mesh, QUADRATURE, backend="dense")
    assert not reference.data.closed_form.any()
    expected = reference.to_dense()
    assert np.abs(closed.to_dense() - expected).max() <= 1e-8 * np.abs(expected).max()


def test_half_space_takes_one_image_without_sampling():
    mesh = _mixed_mesh()
    auto = LayeredMedium([0.0], [0.0, G], [0.0, NU])
    assert influence3d.choose_images(mesh, auto, None) == 1


def test_okada_frame_needs_a_horizontal_side():
    assert okada3d.okada_frame(_frame([1.0, 0.0, 0.4], [0.0, 1.0, 0.3]), 1.0, 1.0) is None
    strike, dip, hs, hd_ = okada3d.okada_frame(_dipping(0.2, np.radians(100.0), e2_horizontal=True), 1.0, 2.0)
    assert abs(strike[2]) == 0.0 and dip[2] > 0.0 and (hs, hd_) == (2.0, 1.0)
