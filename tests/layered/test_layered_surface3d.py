"""The free surface's reflection in closed form beyond the half-space (issue 32, item 1):
in a medium of two or more solid layers under a void, a source of the top solid layer with
a horizontal side takes its reflection in the free surface from :mod:`hmatddm.layered.okada3d`
(that triple is the half-space's image triple, coefficient for coefficient) and the rest of
its image triples by quadrature (:func:`hmatddm.layered.image_tracer3d.drop_surface_range`),
against the quadrature of every triple (``method="quadrature"``)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium, influence3d
from hmatddm.layered.image_tracer3d import drop_surface_range, trace_points
from hmatddm.layered.influence3d import influence_data

G, NU = 1.0, 0.25
# a free surface and two interfaces, G, 2G, G (the contrast), thinner layers;
# gauss_points=6 as in test_layered_fast3d.py: the default 4 leaves 2.6e-6 of the largest
# entry on the self entry of a square 0.25 m under an interface (the quadrature of the
# other triples, with or without the closed form; 6 leaves 1.2e-9)
LAYERS = dict(interfaces=[0.0, -2.0, -4.0], shear_modulus=[0.0, G, 2.0 * G, G], poisson_ratio=[NU, 0.3, 0.2, NU],
              images=2, gauss_points=6)
HALF = 0.25  # 0.5 m squares


def _dipping(strike_angle, dip):
    s = np.array([np.cos(strike_angle), np.sin(strike_angle), 0.0])
    up = np.cos(dip) * np.array([-s[1], s[0], 0.0]) + np.sin(dip) * np.array([0.0, 0.0, 1.0])
    return s, up


def _mesh(seed=5):
    """Squares with a horizontal side (random strike and dip): in the top layer with their
    upper edge 0.25 m under the free surface, their lower edge 0.25 m above the first
    interface, and in its middle; in the second layer 0.25 m under the first interface; one
    square of the top layer without a horizontal side (it keeps the quadrature)."""
    rng = np.random.default_rng(seed)
    frames = [_dipping(rng.uniform(0.0, 2.0 * np.pi), rng.uniform(0.0, np.pi)) for _ in range(7)]
    frames[6] = (np.array([1.0, 0.0, 0.4]) / np.linalg.norm([1.0, 0.0, 0.4]),
                 np.array([-0.12, 1.0, 0.3]) / np.linalg.norm([-0.12, 1.0, 0.3]))
    reach = [HALF * abs(f[1][2]) + HALF * abs(f[0][2]) for f in frames]  # half the vertical extent
    centers = np.array([[0.0, 0.0, -0.25 - reach[0]], [1.1, 0.3, -0.25 - reach[1]],  # under the surface
                        [0.2, 0.9, -2.0 + 0.25 + reach[2]],  # above the first interface
                        [-0.4, -0.6, -1.0],  # mid-layer
                        [0.5, -0.2, -2.0 - 0.25 - reach[4]],  # under the first interface
                        [1.6, 1.4, -1.0],
                        [-1.0, 0.7, -1.2]])  # no horizontal side
    return hd.Mesh3D.from_rectangles(centers, np.array([f[0] for f in frames]), np.array([f[1] for f in frames]),
                                     np.full(7, HALF), np.full(7, HALF))


def _matrix(data):
    every = np.arange(data.centers.shape[0], dtype=np.int64)
    out = np.empty((3 * every.size, 3 * every.size))
    drivers.traction_block(data, every, every, out)
    return out


def _many_points(data):
    return data._replace(gauss_points=8, far_tol=0.0, entry_tol=0.0)


@pytest.fixture(scope="module")
def matrices():
    mesh = _mesh()
    default = influence_data(mesh, LayeredMedium(**LAYERS), 0.0, 0.0, 0.0, LAYERS["images"])
    reference = influence_data(mesh, LayeredMedium(**LAYERS, method="quadrature"), 0.0, 0.0, 0.0, LAYERS["images"])
    return default, _matrix(_many_points(default)), _matrix(default), _matrix(_many_points(reference))


def test_top_layer_sources_with_a_horizontal_side_take_the_surface_in_closed_form(matrices):
    default = matrices[0]
    assert default.surface_form.tolist() == [True, True, True, True, False, True, False]
    assert not default.closed_form.any()  # the whole-image closed form is the half-space's


def test_entries_match_the_quadrature_of_every_triple(matrices):
    """Near (0.25 m from) the free surface and the first interface, in both layers: the
    surface in closed form with the other triples on the reference's rule is the
    reference to round-off; the default rule within the issue's 1e-8."""
    _, fine, default, reference = matrices
    scale = np.abs(reference).max()
    assert np.abs(fine - reference).max() <= 1e-10 * scale
    assert np.abs(default - reference).max() <= 1e-8 * scale


def test_without_the_closed_form_the_dropped_triple_is_missed(matrices):
    """The surface triple dropped from the quadrature and its closed form zeroed (a
    rectangle of no size) leaves the entries off by the half-space image: the check
    above can fail."""
    default, _, _, reference = matrices
    rows = np.arange(7, dtype=np.int64)
    columns = np.array([0, 1], dtype=np.int64)
    off = np.empty((21, 6))
    drivers.traction_block(_many_points(default)._replace(okada_half=default.okada_half * 0.0), rows, columns, off)
    assert np.abs(off - reference[:, :6]).max() > 1e-3 * np.abs(reference).max()


def test_stress_at_points_matches_the_quadrature():
    mesh = _mesh()
    rng = np.random.default_rng(8)
    points = np.vstack([mesh.centers[:4] + rng.normal(size=(4, 3)) * [0.5, 0.5, 0.1],
                        [[0.3, 0.2, -1e-3], [1.0, 0.4, -1.999], [0.6, -0.1, -2.001], [2.0, 2.0, -3.0]]])
    points[:, 2] = np.minimum(points[:, 2], -1e-3)
    default = LayeredMedium(**LAYERS)
    reference = LayeredMedium(**{**LAYERS, "gauss_points": 8}, method="quadrature")
    worst = scale = 0.0
    for q in range(3):
        dd = np.zeros((7, 3))
        dd[:, q] = 1.0
        got = hd.stress_at(mesh, default, dd, points)
        want = hd.stress_at(mesh, reference, dd, points)
        worst = max(worst, np.abs(got - want).max())
        scale = max(scale, np.abs(want).max())
    assert worst <= 1e-9 * scale


def test_interface_conditions_are_the_image_sums():
    """Traction across the first interface and at the free surface, from the sources of
    the top layer on the new path: the same as the quadrature of every triple (to 1e-9 of
    the stress), and continuous (free) up to the image sum's truncation, which falls with
    the number of images (measured 1e-3 at 2 images, 1.5e-6 at 8, either path)."""
    mesh = _mesh()
    rng = np.random.default_rng(9)
    xy = rng.normal(size=(4, 2)) * 0.8
    h = 1e-7
    above = np.column_stack([xy, np.full(4, -2.0 + h)])
    below = np.column_stack([xy, np.full(4, -2.0 - h)])
    top = np.column_stack([xy, np.full(4, -h)])
    residual = {}
    for images in (2, 8):
        for method in ("table", "quadrature"):
            medium = LayeredMedium(**{**LAYERS, "images": images}, method=method)
            for q in range(3):
                dd = np.zeros((7, 3))
                dd[:4, q] = 1.0  # the sources of the top layer (closed form on the default path)
                up, down = hd.stress_at(mesh, medium, dd, above), hd.stress_at(mesh, medium, dd, below)
                surface = hd.stress_at(mesh, medium, dd, top)
                scale = max(np.abs(up).max(), np.abs(down).max())
                jump = up[:, :, 2] - down[:, :, 2]
                assert np.abs(up[:, :2, :2] - down[:, :2, :2]).max() > 1e-2 * scale  # a contrast: sigma_xx jumps
                residual[images, method, q] = (jump / scale, surface[:, :, 2] / np.abs(surface).max())
    for images in (2, 8):
        for q in range(3):
            for got, want in zip(residual[images, "table", q], residual[images, "quadrature", q]):
                assert np.abs(got - want).max() <= 1e-9
            for coarse, fine in zip(residual[2, "table", q], residual[8, "table", q]):
                assert np.abs(fine).max() <= 1e-5 and np.abs(fine).max() <= 0.05 * np.abs(coarse).max()


def test_equal_layers_under_a_surface_are_the_half_space():
    mesh = _mesh()
    equal = LayeredMedium([0.0, -2.0, -4.0], [0.0, G, G, G], [NU] * 4, images=2)
    half = LayeredMedium([0.0], [0.0, G], [NU, NU], images=1)
    data = influence_data(mesh, equal, 0.0, 0.0, 0.0, 2)
    assert data.surface_form[:4].all()
    got = _matrix(data)
    want = _matrix(influence_data(mesh, half, 0.0, 0.0, 0.0, 1))
    # receivers of the top layer from sources with the surface in closed form: the other
    # triples vanish (no contrast); the other entries (a receiver in the second layer, whose
    # surface triple is transmitted, a source without a horizontal side or in the second
    # layer) are the quadrature against the half-space's closed form, or, for a source
    # without a horizontal side, against Okada's point source on the finer rule of
    # okada_point3d.point_rule (8 points per side where the image method takes 4): the
    # difference is the image method's own quadrature error
    closed = np.repeat(data.surface_form, 3)
    top = np.repeat(data.layer == 1, 3)
    assert np.abs(got - want)[np.ix_(top, closed)].max() <= 1e-13 * np.abs(want).max()
    assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()


def test_surface_form_is_off_for_the_cross_check_and_without_images():
    mesh = _mesh()
    for medium, n in ((LayeredMedium(**LAYERS, method="quadrature"), 2), (LayeredMedium(**LAYERS), 0),
                      (LayeredMedium([-3.0], [G, 2.0 * G], [NU, NU], images=2), 2)):
        assert not influence_data(mesh, medium, 0.0, 0.0, 0.0, n).surface_form.any()
    assert influence3d.surface_form(LayeredMedium(**LAYERS), 2)


def test_drop_surface_range_removes_exactly_the_mirror_triple():
    interfaces = np.array(LAYERS["interfaces"])
    g = np.array(LAYERS["shear_modulus"])
    nu = np.array(LAYERS["poisson_ratio"])
    xi = np.array([-0.5, 0.5, 0.0])
    eta = np.array([0.3, -0.2, 0.9])
    center = np.array([0.0, 0.0, -1.0])
    frame = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8], [0.0, -0.8, 0.6]])
    heights = center[2] + eta * 0.25 * 0.8
    traced = trace_points(heights, 1, interfaces, g, nu, 2)
    before = traced[0].copy()
    def triples(p):
        n = traced[0][p]
        return sorted(zip(traced[1][p, :n], np.round(traced[2][p, :n], 12), traced[3][p, :n]))

    every = [triples(p) for p in range(3)]
    drop_surface_range(traced, 0, 3, center, frame, 0.25, 0.25, xi, eta, 1, 0.0)
    assert (traced[0] == before - 1).all()
    for p, t in enumerate(heights):
        left = triples(p)
        gone = list(every[p])
        for kept in left:
            gone.remove(kept)
        assert gone == [(1, np.round(-t, 12), -1.0)]


def test_triple_coefficients_are_at_most_quadratic_in_the_source_height():
    """The structure a closed form of the other triples would rest on
    (hmatddm/layered/_derive_closed_form3d.py): the coefficient of D^n of every triple is a
    polynomial of degree <= min(n, 2) in the source height, up to 4 images in three solid
    layers, while the D order grows (to 5)."""
    from hmatddm.layered._derive_closed_form3d import coefficient_degrees
    found = coefficient_degrees(images=(4,), n_heights=9)
    for counts in found.values():
        assert all(degree <= min(order, 2) for order, degree in counts)
        assert max(order for order, _ in counts) == 5 and max(degree for _, degree in counts) == 2
