"""Every image triple of a vertical rectangle in closed form (issue 32, item 1:
:mod:`hmatddm.layered.vertical3d`, the reduction of ``_derive_closed_form3d.py``), against the
image quadrature (:func:`hmatddm.layered.rectangle_quadrature.image_rectangle_stress`,
``method="quadrature"``), in a bi-material and in a free surface over two interfaces."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.kernels import drivers, rectangle3d
from hmatddm.layered import LayeredMedium
from hmatddm.layered.image_tracer3d import trace_points
from hmatddm.layered.influence3d import influence_data
from hmatddm.layered.rectangle_quadrature import image_rectangle_stress
from hmatddm.layered.vertical3d import vertical_image_stress, vertical_workspace

BI = (np.array([0.0]), np.array([2.0, 1.0]), np.array([0.3, 0.25]))
THREE = (np.array([0.0, -2.0, -4.0]), np.array([0.0, 1.0, 2.0, 1.0]), np.array([0.25, 0.3, 0.2, 0.25]))


def _frame(angle, e1_vertical):
    s = np.array([np.cos(angle), np.sin(angle), 0.0])
    up = np.array([0.0, 0.0, 1.0])
    return np.array([up, -s, np.cross(up, -s)]) if e1_vertical else np.array([s, up, np.cross(s, up)])


def _closed(y, receiver_layer, center, frame, a, b, source_layer, medium, n_images):
    """The complementary stress of the rectangle by vertical_image_stress (the strike, half
    sides and heights as the operator passes them)."""
    interfaces, g, nu = medium
    vertical_e1 = abs(frame[0, 2]) > 0.5
    strike = -frame[1] if vertical_e1 else frame[0]
    hs, hd_ = (b, a) if vertical_e1 else (a, b)
    heights = center[2] + hd_ * np.array([-1.0, 0.0, 1.0])
    traced = trace_points(heights, source_layer, interfaces, g, nu, n_images)
    out = np.zeros((3, 3, 3))
    assert vertical_image_stress(y, receiver_layer, center, strike, hs, hd_, heights, traced, g, nu, source_layer,
                                 0.0, 0.0, vertical_workspace(traced[5].shape[-1]), out)
    if receiver_layer != source_layer:
        uniform = np.empty((3, 3, 3))
        rectangle3d.stress_pair(y, center, frame, a, b, g[source_layer], nu[source_layer], 0.0, uniform,
                                np.empty((3, 3, 3)))
        out -= uniform
    return out


@pytest.mark.parametrize("case", ["bi-material", "three layers, images=4"])
def test_closed_form_is_the_image_quadrature(case):
    """Receivers in every layer the triples reach, the square 0.25 m from an interface,
    random strike, either side vertical; every triple (D orders up to 5 at images=4)."""
    rng = np.random.default_rng(11)
    if case == "bi-material":
        medium, n_images, layer, center, layers = BI, 1, 1, np.array([0.1, 0.05, -0.5]), (0, 1)
    else:
        medium, n_images, layer, center, layers = THREE, 4, 2, np.array([0.3, -0.2, -2.5]), (1, 2, 3)
    interfaces, g, nu = medium
    worst = scale = 0.0
    for trial, receiver_layer in enumerate(np.repeat(layers, 3)):
        frame = _frame(rng.uniform(0.0, 2.0 * np.pi), trial % 2 == 1)
        top = interfaces[receiver_layer - 1] if receiver_layer > 0 else interfaces[0] + 2.0
        bottom = interfaces[receiver_layer] if receiver_layer < len(interfaces) else interfaces[-1] - 2.0
        y = np.array([rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(bottom + 0.05, top - 0.05)])
        got = _closed(y, receiver_layer, center, frame, 0.25, 0.25, layer, medium, n_images)
        want = np.empty((3, 3, 3))
        image_rectangle_stress(y, receiver_layer, center, frame, 0.25, 0.25, layer, interfaces, g, nu, n_images, 12,
                               16, want, False, np.zeros(len(g)), np.zeros(len(g)))
        worst = max(worst, np.abs(got - want).max())
        scale = max(scale, np.abs(want).max())
    assert worst <= 1e-12 * scale


def test_traction_is_continuous_across_a_bi_material_interface():
    """One interface, one image: the reflection and transmission are the whole answer, so
    the traction on the interface is continuous to round-off on the closed form (the
    uniform-rock kernel added for the real source, as the operator adds it)."""
    interfaces, g, nu = BI
    center = np.array([0.1, 0.05, -0.5])
    frame = _frame(0.7, False)
    rng = np.random.default_rng(12)
    h = 1e-9
    for xy in rng.normal(size=(4, 2)) * 0.6:
        below = np.array([xy[0], xy[1], -h])
        above = np.array([xy[0], xy[1], h])
        real = np.empty((3, 3, 3))
        rectangle3d.stress_pair(below, center, frame, 0.25, 0.25, g[1], nu[1], 0.0, real, np.empty((3, 3, 3)))
        stress_below = real + _closed(below, 1, center, frame, 0.25, 0.25, 1, BI, 1)
        rectangle3d.stress_pair(above, center, frame, 0.25, 0.25, g[1], nu[1], 0.0, real, np.empty((3, 3, 3)))
        stress_above = real + _closed(above, 0, center, frame, 0.25, 0.25, 1, BI, 1)
        scale = np.abs(stress_below).max()
        assert np.abs(stress_below[:, :, 2] - stress_above[:, :, 2]).max() <= 1e-7 * scale
        assert np.abs(stress_below[:, 0, 0] - stress_above[:, 0, 0]).max() > 1e-3 * scale  # sigma_xx jumps


def test_equal_layers_leave_no_image():
    equal = (np.array([0.0]), np.array([1.0, 1.0]), np.array([0.25, 0.25]))
    center = np.array([0.1, 0.05, -0.5])
    frame = _frame(0.3, True)
    for y, layer in ((np.array([0.4, 0.3, -0.7]), 1), (np.array([0.4, 0.3, 0.6]), 0)):
        got = _closed(y, layer, center, frame, 0.25, 0.25, 1, equal, 1)
        real = np.empty((3, 3, 3))
        rectangle3d.stress_pair(y, center, frame, 0.25, 0.25, 1.0, 0.25, 0.0, real, np.empty((3, 3, 3)))
        assert np.abs(got).max() <= 1e-13 * np.abs(real).max()


def _vertical_mesh(depths, seed=4):
    rng = np.random.default_rng(seed)
    centers = np.array([[x, y, z] for z in depths for x, y in ((0.0, 0.0), (1.2, 0.5), (-0.3, 1.0))])
    n = len(centers)
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    e1 = np.stack([np.cos(angle), np.sin(angle), np.zeros(n)], axis=1)
    e2 = np.tile([0.0, 0.0, 1.0], (n, 1))
    swap = np.arange(n) % 2 == 1  # e1 vertical
    e1[swap], e2[swap] = e2[swap].copy(), -e1[swap].copy()
    return hd.Mesh3D.from_rectangles(centers, e1, e2, np.full(n, 0.25), np.full(n, 0.25))


def _matrix(data):
    every = np.arange(data.centers.shape[0], dtype=np.int64)
    out = np.empty((3 * every.size, 3 * every.size))
    drivers.traction_block(data, every, every, out)
    return out


@pytest.mark.parametrize("case", ["surface + 2 interfaces", "bi-material"])
def test_operator_entries_match_the_quadrature_of_every_triple(case):
    """Vertical squares with random strike 0.25 m from the free surface and the interfaces
    (their edges), in the layers on both sides: every entry within 1e-9 of the largest of
    the quadrature with 8 points on every (sub-)square."""
    if case == "bi-material":
        options = dict(interfaces=[-2.0], shear_modulus=[2.0, 1.0], poisson_ratio=[0.3, 0.25], images=1)
        depths = (-1.5, -2.5, -3.2)
    else:
        options = dict(interfaces=[0.0, -2.0, -4.0], shear_modulus=[0.0, 1.0, 2.0, 1.0],
                       poisson_ratio=[0.25, 0.3, 0.2, 0.25], images=2)
        depths = (-0.5, -1.5, -2.5, -3.6)
    mesh = _vertical_mesh(depths)
    data = influence_data(mesh, LayeredMedium(**options), 0.0, 0.0, 0.0, options["images"])
    assert data.vertical_form.all()
    reference = influence_data(mesh, LayeredMedium(**options, method="quadrature"), 0.0, 0.0, 0.0,
                               options["images"])
    assert not reference.vertical_form.any()
    want = _matrix(reference._replace(gauss_points=8, far_tol=0.0, entry_tol=0.0))
    got = _matrix(data)
    assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()
    # without the closed form the default rule is further off (the check can fail)
    before = _matrix(data._replace(vertical_form=np.zeros(mesh.n_elements, dtype=bool)))
    assert np.abs(before - want).max() > 10.0 * np.abs(got - want).max()


def test_vertical_form_only_for_vertical_rectangles_in_layered_media():
    mesh = _vertical_mesh((-1.5, -2.5))
    tilted = hd.Mesh3D.from_rectangles(np.array([[0.0, 0.0, -1.0]]), np.array([[1.0, 0.0, 0.0]]),
                                       np.array([[0.0, 0.6, 0.8]]), np.array([0.25]), np.array([0.25]))
    layered = LayeredMedium([-2.0], [2.0, 1.0], [0.3, 0.25], images=1)
    assert not influence_data(tilted, layered, 0.0, 0.0, 0.0, 1).vertical_form.any()
    for medium, n in ((LayeredMedium([-2.0], [2.0, 1.0], [0.3, 0.25], images=1, method="quadrature"), 1),
                      (LayeredMedium([-2.0], [2.0, 1.0], [0.3, 0.25], images=0), 0),
                      (LayeredMedium([0.0], [0.0, 1.0], [0.25, 0.25], images=1), 1)):  # half-space: okada3d
        assert not influence_data(mesh, medium, 0.0, 0.0, 0.0, n).vertical_form.any()
