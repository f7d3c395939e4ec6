"""3D image kernels (hmatddm.layered.images3d, ref. Secs 3.2-3.3): the Hansen-potential
machinery against closed forms, and the image terms against the exact interface
conditions (free surface, bi-material, three layers)."""
import numpy as np
import pytest

from hmatddm.kernels import rectangle3d
from hmatddm.layered import images3d

SHAPES = {  # (centre, e1, e2, a, b): horizontal, vertical, tilted rectangles
    "horizontal": ([0.1, 0.2, -0.8], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.5, 0.3),
    "vertical": ([0.1, 0.2, -0.8], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.5, 0.3),
    "tilted": ([0.1, 0.2, -0.8], [np.cos(0.5), 0.0, np.sin(0.5)], [0.0, 1.0, 0.0], 0.5, 0.3),
}


def _frame(e1, e2):
    e1, e2 = np.asarray(e1, float), np.asarray(e2, float)
    return np.array([e1, e2, np.cross(e1, e2)])


def _total(y, receiver_layer, shape, source_layer, medium, n_images, dz=0.0):
    """Closed form of the source layer's material + images, (3, 3, 3) [DD b, i, k]."""
    center, e1, e2, a, b = shape
    center = np.asarray(center, float) + [0.0, 0.0, dz]
    frame = _frame(e1, e2)
    interfaces, g, nu = (np.asarray(v, float) for v in medium)
    out = np.zeros((3, 3, 3))
    rectangle3d.stress_pair(np.asarray(y, float), center, frame, a, b, g[source_layer], nu[source_layer], 0.0, out,
                            np.empty((3, 3, 3)))
    image = np.zeros((3, 3, 3))
    images3d.image_rectangle_stress(np.asarray(y, float), receiver_layer, center, frame, a, b, source_layer,
                                    interfaces, g, nu, n_images, 6, 4, image, False, interfaces, interfaces)
    return out + image


def test_base_function_derivatives_are_harmonic_and_closed_form():
    """Horizontal derivatives of F and L against closed forms and central differences,
    and the Laplacian of the recurrence's derivatives of 1/r (to high vertical order)
    vanishing."""
    r1, r2, r3 = 0.3, -0.4, 0.7
    r = np.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    sf, sl = np.zeros((6, 6)), np.zeros((6, 6))
    images3d.base_derivatives(r1, r2, r3, sf, sl, np.zeros((6, 6, 4)), np.zeros((4, 6)),
                                  images3d.inverse_distance_scratch(4), 10)
    assert sf[0, 0] == pytest.approx(r - r3 * np.log(r + r3), rel=1e-14)
    assert sf[1, 0] == pytest.approx(r1 / (r + r3), rel=1e-13)  # d1 F (ref. Eq. 3.24 gauge +1)
    assert sl[0, 1] == pytest.approx(r2 / (r * (r + r3)), rel=1e-13)
    assert sf[2, 0] + sf[0, 2] == pytest.approx(1.0 / r, rel=1e-12)  # = -d33 F
    assert sl[2, 0] + sl[0, 2] == pytest.approx(r3 / r ** 3, rel=1e-12)  # = -d3 (1/r)
    h = 1e-4  # d1^a d2^b of order 5 from order 4 by a central difference of each variable
    for var in range(2):
        step = np.array([h, 0.0]) if var == 0 else np.array([0.0, h])
        plus, minus = (np.zeros((6, 6)) for _ in range(2))
        sfp, sfm = np.zeros((6, 6)), np.zeros((6, 6))
        images3d.base_derivatives(r1 + step[0], r2 + step[1], r3, sfp, plus, np.zeros((6, 6, 4)), np.zeros((4, 6)),
                                  images3d.inverse_distance_scratch(4), 10)
        images3d.base_derivatives(r1 - step[0], r2 - step[1], r3, sfm, minus, np.zeros((6, 6, 4)), np.zeros((4, 6)),
                                  images3d.inverse_distance_scratch(4), 10)
        for a in range(5):
            b = 4 - a
            da, db = (a + 1, b) if var == 0 else (a, b + 1)
            assert sl[da, db] == pytest.approx((plus[a, b] - minus[a, b]) / (2 * h), rel=1e-6, abs=1e-6)
            assert sf[da, db] == pytest.approx((sfp[a, b] - sfm[a, b]) / (2 * h), rel=1e-6, abs=1e-6)
    q = np.zeros((6, 6, 24))
    images3d.inverse_distance_derivatives(r1, r2, r3, q, images3d.inverse_distance_scratch(q.shape[2]), 30)
    # (d11 + d22)^2 = d3^4 on harmonic functions; d3 L = 1/r, d3^2 F = -1/r
    assert sl[4, 0] + 2 * sl[2, 2] + sl[0, 4] == pytest.approx(q[0, 0, 3], rel=1e-11)
    assert sf[5, 0] + 2 * sf[3, 2] + sf[1, 4] == pytest.approx(-q[1, 0, 2], rel=1e-11)
    assert q[1, 1, 0] == pytest.approx(3 * r1 * r2 / r ** 5, rel=1e-13)
    assert q[0, 0, 2] == pytest.approx((3 * r3 ** 2 - r ** 2) / r ** 5, rel=1e-13)
    for a, b in ((0, 0), (1, 0), (2, 1), (1, 2)):
        for c in range(18):
            laplacian = q[a + 2, b, c] + q[a, b + 2, c] + q[a, b, c + 2]
            assert abs(laplacian) < 1e-11 * abs(q[a, b, c + 2]) + 1e-300


@pytest.mark.parametrize("y", [[1.5, -0.7, 1.2], [0.5, 0.1, -1.5]])
def test_hansen_whole_space_path_matches_closed_form_rectangle(y):
    """The original potentials of ref. Eq. 3.24 (gauge chosen by side) through ref. Eq.
    3.22 and the moment contraction, integrated over a tilted rectangle, reproduce the
    closed-form rectangle kernel (checks the potentials, derivatives and DD signs)."""
    center, e1, e2, a, b = SHAPES["tilted"]
    frame = _frame(e1, e2)
    center = np.asarray(center, float)
    g, nu = 1.3, 0.27
    exact = np.zeros((3, 3, 3))
    rectangle3d.stress_pair(np.asarray(y, float), center, frame, a, b, g, nu, 0.0, exact, np.empty((3, 3, 3)))
    xi, eta, wt = images3d.square_rule(6, 4)
    total, point = np.zeros((3, 3, 3)), np.zeros((3, 3, 3))
    for k in range(len(xi)):
        x = center + xi[k] * a * frame[0] + eta[k] * b * frame[1]
        images3d.kelvin_point_stress(np.asarray(y, float), x, frame[2], g, nu, point)
        total += wt[k] * a * b * point
    assert np.max(np.abs(total - exact)) < 1e-11 * np.max(np.abs(exact))  # the Gauss rule's error


@pytest.mark.parametrize("shape", SHAPES)
def test_free_surface_is_traction_free(shape):
    """Half-space (void layer above z = 0): one image makes sigma.e_z vanish on the surface."""
    medium = ([0.0], [0.0, 1.0], [0.25, 0.25])
    for y in ([0.3, 0.1, 0.0], [-1.0, 0.5, 0.0], [2.0, -1.0, 0.0]):
        s = _total(y, 1, SHAPES[shape], 1, medium, 1)
        scale = np.max(np.abs(_total([0.3, 0.1, 0.0], 1, SHAPES[shape], 1, medium, 1)))
        assert np.max(np.abs(s[:, :, 2])) < 1e-10 * scale


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("source_layer, dz", [(1, 0.0), (0, 1.6)])
def test_bimaterial_traction_is_continuous(shape, source_layer, dz):
    """One image is the exact bi-material solution: sigma.e_z equal on both sides of the
    interface (source below or above it) while sigma_xx jumps."""
    medium = ([0.0], [1.0, 2.5], [0.2, 0.35])
    for y in ([0.3, 0.1, 0.0], [-1.0, 0.5, 0.0]):
        above = _total(y, 0, SHAPES[shape], source_layer, medium, 1, dz)
        below = _total(y, 1, SHAPES[shape], source_layer, medium, 1, dz)
        assert np.max(np.abs(above[:, :, 2] - below[:, :, 2])) < 1e-13 * np.max(np.abs(above))
        assert np.max(np.abs(above[:, 0, 0] - below[:, 0, 0])) > 1e-2 * np.max(np.abs(above))


def test_bimaterial_displacement_is_continuous():
    """The displacement of a point DD (ref. Eq. 3.22 through the images) is continuous
    across a bonded interface, for every DD direction; and zero contrast adds nothing."""
    interfaces, g, nu = np.array([0.0]), np.array([1.0, 2.5]), np.array([0.2, 0.35])
    x, normal = np.array([0.1, 0.2, -0.6]), np.array([np.sin(0.4), 0.0, np.cos(0.4)])
    for y in ([0.3, 0.1, 0.0], [-1.0, 0.5, 0.0]):
        y = np.asarray(y, float)
        kelvin, above, below = np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))
        images3d.kelvin_point_displacement(y, x, normal, g[1], nu[1], kelvin)
        images3d.image_point_displacement(y, 0, x, 1, normal, interfaces, g, nu, 1, above)
        images3d.image_point_displacement(y, 1, x, 1, normal, interfaces, g, nu, 1, below)
        assert np.max(np.abs((kelvin + above) - (kelvin + below))) < 1e-13 * np.max(np.abs(kelvin))
        assert np.max(np.abs(below)) > 1e-2 * np.max(np.abs(kelvin))
    images3d.kelvin_point_displacement(np.array([0.3, 0.1, 0.5]), x, normal, 1.0, 0.2, kelvin)
    images3d.image_point_displacement(np.array([0.3, 0.1, 0.5]), 0, x, 1, normal, interfaces, np.array([1.0, 1.0]),
                                      np.array([0.2, 0.2]), 3, above)
    assert np.max(np.abs(above)) < 1e-14 * np.max(np.abs(kelvin))  # transmitted - whole-space: round-off


def test_equal_layers_give_no_image_terms():
    """gamma = 1 at every interface: the complementary stress is exactly zero, in the
    source's layer and in the others."""
    medium = ([1.0, 0.0], [1.0, 1.0, 1.0], [0.25, 0.25, 0.25])
    center, e1, e2, a, b = SHAPES["tilted"]
    for y, layer in (([0.3, 0.1, 0.5], 1), ([0.3, 0.1, 1.5], 0), ([0.3, 0.1, -1.5], 2)):
        image = np.zeros((3, 3, 3))
        images3d.image_rectangle_stress(np.asarray(y, float), layer, np.array([0.1, 0.2, 0.5]), _frame(e1, e2), a, b,
                                        1, *(np.asarray(v, float) for v in medium), 3, 4, 1, image, False,
                                        np.zeros(2), np.zeros(2))
        assert np.all(np.abs(image) < 1e-15)


def test_three_layers_interface_conditions_converge_with_images():
    """Two interfaces: the traction mismatch at both falls with the number of images
    (ref. Fig. 3.4), for a source in the middle layer."""
    medium = ([1.0, 0.0], [2.0, 1.0, 5.0], [0.3, 0.2, 0.25])
    shape = ([0.1, 0.2, 0.6], [1.0, 0.0, 0.0], [0.0, np.cos(0.3), np.sin(0.3)], 0.15, 0.1)
    mismatch = []
    for n_images in (1, 4, 12):
        worst = 0.0
        for height, upper, lower in ((1.0, 0, 1), (0.0, 1, 2)):
            for x in (-1.0, 0.4):
                a = _total([x, 0.3, height], upper, shape, 1, medium, n_images)
                b = _total([x, 0.3, height], lower, shape, 1, medium, n_images)
                worst = max(worst, np.max(np.abs(a[:, :, 2] - b[:, :, 2])) / np.max(np.abs(a)))
        mismatch.append(worst)
    assert mismatch[0] > 1e-3
    assert mismatch[1] < 0.1 * mismatch[0]
    assert mismatch[2] < 1e-3 * mismatch[0]


@pytest.mark.parametrize("sigma", [1.0, -1.0])
def test_the_gauge_table_holds_the_base_tables_of_f_and_l(sigma):
    """:func:`potentials3d.gauge_table` (one table of F of the gauge, at the receiver; what
    the triples read) against the tables of F and L of :func:`potentials3d._base_table`
    (at the flipped point, as the closed-form vertical rectangles read them): ``F`` as it
    is, ``L = -sigma D F`` one order up in ``d3``, every entry both write."""
    from hmatddm.layered import potentials3d as p3
    rng = np.random.default_rng(5)
    for n_c in (5, 7, 9):
        top = max(n_c - 2, 4)  # as _pair_tables: the Laplace relations read 1/r's to order 4
        for _ in range(10):
            r1, r2 = rng.uniform(-2.0, 2.0, size=2)
            r3 = sigma * rng.uniform(0.05, 2.0)
            sf, sl, q = np.zeros((6, 6)), np.zeros((6, 6)), np.zeros((6, 6, n_c + 3))
            base = np.full((2, 6, 6, n_c + 4), np.nan)
            p3.base_derivatives(r1, r2, sigma * r3, sf, sl, q[:, :, :n_c - 1], np.zeros((4, 6)),
                                p3.inverse_distance_scratch(n_c + 3), top)
            p3._base_table(sigma, n_c, sf, sl, q, base, top)
            h = np.full((6, 6, n_c + 4), np.nan)
            p3.gauge_table(r1, r2, r3, sigma, n_c, top, np.zeros((6, 6)), np.zeros((6, 6)), np.zeros((4, 6)), h,
                           p3.inverse_distance_scratch(n_c + 3))
            compared = 0
            for a in range(6):
                for b in range(6 - a):
                    for c in range(n_c):
                        for kind, value in ((0, h[a, b, c]), (1, -sigma * h[a, b, c + 1])):
                            expected = base[kind, a, b, c]
                            if np.isfinite(expected):
                                assert value == pytest.approx(expected, rel=1e-13, abs=1e-13 * abs(q).max())
                                compared += 1
            assert compared > 2 * 21 * 3
