"""The stress at points (``hd.stress_at``) of vertical rectangles in layered rock with their
image triples in closed form (issue 32: :mod:`hmatddm.layered.vertical3d` through
:func:`hmatddm.layered.images3d.element_stress`), against the quadrature of every triple
(``method="quadrature"``, 8 Gauss points per side on every (sub-)square): points next to
the free surface and to both sides of the interfaces; equal layers are uniform rock; the
traction is continuous across an interface."""
import numpy as np

import hmatddm as hd
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium
from hmatddm.layered.influence3d import _prepared, influence_data

THREE = dict(interfaces=[0.0, -2.0, -4.0], shear_modulus=[0.0, 1.0, 2.0, 1.0], poisson_ratio=[0.25, 0.3, 0.2, 0.25],
             images=2)


def _vertical_mesh(depths, seed=4):
    """Vertical 0.5 m squares of random strike (every other one with its first side
    vertical) at ``depths``, three per depth."""
    rng = np.random.default_rng(seed)
    centers = np.array([[x, y, z] for z in depths for x, y in ((0.0, 0.0), (1.2, 0.5), (-0.3, 1.0))])
    n = len(centers)
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    e1 = np.stack([np.cos(angle), np.sin(angle), np.zeros(n)], axis=1)
    e2 = np.tile([0.0, 0.0, 1.0], (n, 1))
    swap = np.arange(n) % 2 == 1
    e1[swap], e2[swap] = e2[swap].copy(), -e1[swap].copy()
    return hd.Mesh3D.from_rectangles(centers, e1, e2, np.full(n, 0.25), np.full(n, 0.25))


def _points(seed=5):
    """Points beside the squares, 0.01 m under the free surface and 0.01 m either side of
    both interfaces, and a few farther away."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-0.8, 1.5, size=(14, 2))
    z = np.array([-0.01, -1.99, -2.01, -3.99, -4.01, -0.3, -1.0, -1.6, -2.4, -3.0, -3.5, -4.5, -5.5, -2.2])
    return np.column_stack([xy, z])


def _reference(mesh, dd, points):
    medium = LayeredMedium(**{**THREE, "gauss_points": 8}, method="quadrature")
    data = influence_data(mesh, medium, 0.0, 0.0, 0.0, THREE["images"], with_table=False)._replace(far_tol=0.0)
    return drivers.stress_sum(data, points, dd, medium.layer_of(points[:, 2]).astype(np.int64))


def test_stress_at_points_matches_the_quadrature_of_every_triple():
    """The default path (closed form next to the images, the few-point quadrature far from
    them, and within the closed form the triples far from the point by a few Gauss points)
    within 1e-10 of the largest stress (measured 6.2e-11), the closed form of every triple
    (``far_tol = 0`` keeps four Gauss points for every pair, the closed form's threshold;
    ``entry_tol = 0``: no triple by quadrature) within 1e-12 (measured 1.4e-15); both far
    closer than the default quadrature (6.3e-8: sub-squares next to the interfaces)."""
    mesh = _vertical_mesh((-0.5, -1.5, -2.5, -3.6))
    points = _points()
    dd = np.random.default_rng(6).normal(size=(mesh.n_elements, 3))
    medium = LayeredMedium(**THREE)
    got = hd.stress_at(mesh, medium, dd, points)
    want = _reference(mesh, dd, points)
    scale = np.abs(want).max()
    assert np.abs(got - want).max() <= 1e-10 * scale  # measured 6.2e-11
    points_, dd_, data = _prepared(mesh, medium, dd, points, "none", 0.0, None)
    assert data.vertical_form.all() and data.surface_form.sum() == 6  # the top solid layer
    layers = medium.layer_of(points[:, 2]).astype(np.int64)
    closed = drivers.stress_sum(data._replace(far_tol=0.0, entry_tol=0.0), points, dd, layers)
    assert np.abs(closed - want).max() <= 1e-12 * scale
    before = hd.stress_at(mesh, LayeredMedium(**THREE, method="quadrature"), dd, points)
    assert np.abs(before - want).max() > 10.0 * np.abs(got - want).max()


def test_equal_layers_are_uniform_rock():
    medium = LayeredMedium(interfaces=[-2.0, -4.0], shear_modulus=[1.0, 1.0, 1.0], poisson_ratio=[0.25] * 3,
                           images=2)
    mesh = _vertical_mesh((-1.5, -2.5, -3.6))
    points = _points()
    points[:, 2] -= 0.5  # below the (absent) free surface of THREE: every point in rock
    dd = np.random.default_rng(7).normal(size=(mesh.n_elements, 3))
    _, _, data = _prepared(mesh, medium, dd, points, "none", 0.0, None)
    assert data.vertical_form.all()
    got = hd.stress_at(mesh, medium, dd, points)
    want = hd.stress_at(mesh, hd.Elastic(1.0, 0.25), dd, points)
    assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()


def test_traction_is_continuous_across_an_interface():
    """One interface, one image (the exact answer): sigma_iz on both sides of the interface
    agree to round-off on the closed form, sigma_xx jumps."""
    medium = LayeredMedium(interfaces=[-2.0], shear_modulus=[2.0, 1.0], poisson_ratio=[0.3, 0.25], images=1)
    mesh = _vertical_mesh((-1.5, -2.5))
    dd = np.random.default_rng(8).normal(size=(mesh.n_elements, 3))
    xy = np.random.default_rng(9).uniform(-0.5, 1.2, size=(5, 2))
    h = 1e-9
    above = hd.stress_at(mesh, medium, dd, np.column_stack([xy, np.full(5, -2.0 + h)]))
    below = hd.stress_at(mesh, medium, dd, np.column_stack([xy, np.full(5, -2.0 - h)]))
    scale = max(np.abs(above).max(), np.abs(below).max())
    assert np.abs(above[:, :, 2] - below[:, :, 2]).max() <= 1e-7 * scale
    assert np.abs(above[:, 0, 0] - below[:, 0, 0]).max() > 1e-2 * scale
