"""Okada's (1992) point source in a half-space (hmatddm.layered.okada_point3d): its Gauss
sum over a rectangle against Okada's finite rectangle (okada3d), a half-space operator of
rectangles without a horizontal side against the image method's quadrature at the same
rule and at many points, the frame it takes from the normal, and the free surface."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.elasticity import operator as operators
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium, okada3d, okada_point3d
from hmatddm.layered.rectangle_quadrature import image_rectangle_stress, square_rule

G, NU = 1.3, 0.27


def _strike_dip_frame(rng):
    strike, dip = rng.uniform(0.0, 2.0 * np.pi), rng.uniform(0.05, np.pi - 0.05)
    e1 = np.array([np.cos(strike), np.sin(strike), 0.0])
    up = np.cos(dip) * np.array([-e1[1], e1[0], 0.0])
    up[2] = np.sin(dip)
    if rng.random() < 0.5:  # the horizontal side along e2 instead
        e1, up = up, -e1
    return np.stack([e1, up, np.cross(e1, up)])


def test_gauss_sum_of_the_point_source_is_okadas_rectangle():
    """For rectangles with a horizontal side both forms apply: 12 x 12 points on 4 x 4
    sub-squares of the point source reproduce the finite source's image and surface terms."""
    rng = np.random.default_rng(1)
    xi, eta, wt = square_rule(12, 4)
    for _ in range(12):
        frame = _strike_dip_frame(rng)
        a, b = 0.3, 0.2
        center = np.array([0.1, -0.2, -rng.uniform(0.8, 3.0)])
        point = np.array([rng.uniform(-2, 2), rng.uniform(-2, 2), -rng.uniform(0.2, 3.0)])
        closed, rows, half = okada3d.halfspace_geometry(frame[None], np.array([a]), np.array([b]))
        assert closed[0]
        expected = np.empty((3, 3, 3))
        okada3d.okada_stress(point, center, rows[0], half[0, 0], half[0, 1], 0.0, G, NU, False, True,
                             np.empty((5, 3, 3, 3)), np.empty((30, 4)), expected)
        got = np.empty((3, 3, 3))
        okada_point3d.point_image_stress(point, center, frame, a, b, okada_point3d.point_frame(frame[2]), 0.0, G, NU,
                                         xi, eta, wt, np.empty((5, 3, 3, 3)), got)
        assert np.abs(got - expected).max() <= 1e-11 * np.abs(expected).max()


def test_point_frame_is_strike_updip_normal():
    rng = np.random.default_rng(2)
    for _ in range(20):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        rows = okada_point3d.point_frame(n)
        assert np.allclose(rows @ rows.T, np.eye(3), atol=1e-14)
        assert rows[0, 2] == 0.0 and rows[1, 2] >= 0.0
        assert np.allclose(np.cross(rows[0], rows[1]), n, atol=1e-14)
    assert okada_point3d.point_frame([0.0, 0.0, 1.0]) is None


def _skewed_mesh(n_side=3, levels=3, seed=3, top=-1.0):
    """Randomly turned 0.5 m squares (no horizontal side) on a 1.5 m lattice below ``top``."""
    rng = np.random.default_rng(seed)
    xs = np.arange(n_side) * 1.5
    centers = np.array([[x, y, top - 1.5 * k] for k in range(levels) for x in xs for y in xs])
    frames = np.linalg.qr(rng.normal(size=(len(centers), 3, 3)))[0]
    half = np.full(len(centers), 0.25)
    return hd.Mesh3D.from_rectangles(centers, frames[:, :, 0], frames[:, :, 1], half, half)


def _block(data, n):
    out = np.empty((3 * n, 3 * n))
    every = np.arange(n, dtype=np.int64)
    drivers.traction_block(data, every, every, out)
    return out


def test_point_source_is_the_image_methods_integrand():
    """At one Gauss rule the point form and the image method's quadrature of the half-space's
    image triple give the same stress to round-off."""
    mesh = _skewed_mesh(top=-0.45)
    half_space = LayeredMedium([0.0], [0.0, G], [NU, NU], images=1)
    data = operators.influence_data(mesh, half_space)
    assert data.point_form.all() and not data.closed_form.any()
    for i, j, n_gauss, n_sub in ((0, 0, 4, 2), (0, 4, 3, 1), (8, 1, 2, 1), (4, 4, 6, 4)):
        rule = square_rule(n_gauss, n_sub)
        got = np.empty((3, 3, 3))
        okada_point3d.point_image_stress(mesh.centers[i], mesh.centers[j], data.frames[j], 0.25, 0.25, data.okada[j],
                                         0.0, G, NU, *rule, np.empty((5, 3, 3, 3)), got)
        expected = np.empty((3, 3, 3))
        image_rectangle_stress(mesh.centers[i], 1, mesh.centers[j], data.frames[j], 0.25, 0.25, 1, data.interfaces,
                               data.shear_modulus, data.poisson_ratio, 1, n_gauss, n_sub, expected, False,
                               np.zeros(2), np.zeros(2))
        assert np.abs(got - expected).max() <= 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("top", [-1.0, -0.45])
def test_half_space_entries_without_horizontal_side_are_within_1e8_of_the_converged_quadrature(top):
    """Issue 32's accuracy, next to the free surface too (the squares 0.1 m from it at
    ``top = -0.45``): the point form's rule against 16 x 16 points on up to 64 x 64
    sub-squares of the image method."""
    mesh = _skewed_mesh(top=top)
    n = mesh.n_elements
    data = operators.influence_data(mesh, LayeredMedium([0.0], [0.0, G], [NU, NU], images=1))
    quadrature = operators.influence_data(mesh, LayeredMedium([0.0], [0.0, G], [NU, NU], images=1,
                                                              method="quadrature"))
    assert not quadrature.point_form.any()
    got = _block(data, n)
    converged = _block(quadrature._replace(gauss_points=16, max_subdivisions=64, far_tol=0.0, entry_tol=0.0), n)
    assert np.abs(got - converged).max() <= 1e-8 * np.abs(converged).max()


def test_free_surface_is_traction_free_next_to_a_skewed_source():
    mesh = _skewed_mesh(n_side=1, levels=1, top=-0.6)
    half_space = LayeredMedium([0.0], [0.0, G], [NU, NU], images=1)
    assert operators.influence_data(mesh, half_space).point_form.all()
    x, y = np.meshgrid(np.linspace(-1.0, 1.0, 5), np.linspace(-1.0, 1.0, 5))
    points = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    for r in range(3):
        dd = np.zeros((1, 3))
        dd[0, r] = 1e-3
        stress = hd.stress_at(mesh, half_space, dd, points)
        assert np.abs(stress[:, :, 2]).max() <= 1e-6 * np.abs(stress).max()
