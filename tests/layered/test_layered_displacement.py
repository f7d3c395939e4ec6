"""Displacements at points in layered rock (hmatddm.layered.displacement, behind
hd.displacement_at): the 3D half-space against Okada's (1985) closed-form surface
displacement of rectangular tensile and shear dislocations (tests/okada_reference.py,
written from the paper) and against quadrature of Mindlin's point force
(tests/_mindlin.py); bonded interfaces: continuity of the displacement across them and
equal layers reproducing uniform rock; 2D: the closed-form half-plane surface
displacement of a horizontal segment; and the refusals."""
import math

import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.layered import LayeredMedium

import _mindlin
import okada_reference as okada

G, NU = 10e9, 0.25
HALF_SPACE = LayeredMedium([0.0], [0.0, G], [NU, NU])
#: Relative error allowed against an independent closed form: the image quadrature keeps
#: 1e-6 of the image field (rectangle_quadrature.FAR_TOL); measured 5e-9 to 3.4e-7.
TOL = 2e-6


def _worst(ours, ref):
    return np.abs(ours - ref).max() / np.abs(ref).max()


# -- 3D half-space against Okada (1985) ----------------------------------------------------
@pytest.mark.parametrize("dip_deg, depth, length, width, nu", [(0.0, 1.0, 2.0, 1.5, 0.25), (40.0, 1.2, 2.0, 1.0, 0.3),
                                                               (90.0, 1.5, 1.6, 1.0, 0.2)])
def test_half_space_surface_displacement_is_okadas(dip_deg, depth, length, width, nu):
    """A sill (dip 0), a dipping fault and a vertical dike (Okada's cos(dip) = 0 branch),
    each DD component, at surface points around them."""
    medium = LayeredMedium([0.0], [0.0, G], [nu, nu])
    dip = math.radians(dip_deg)
    center, frame, a, b = okada.rectangle(depth, dip, length, width)
    mesh = hd.mesh.rectangle(center, frame[0], frame[1], 2 * a, 2 * b, 1, 1)
    rng = np.random.default_rng(1)
    points = np.c_[rng.uniform(-2, 4, 5), rng.uniform(-3, 3, 5), np.zeros(5)]
    for component in np.eye(3):
        ours = hd.displacement_at(mesh, medium, (component @ frame)[None], points)
        ref = np.array([okada.surface_displacement(x, y, depth, dip, length, width, *component, nu)
                        for x, y, _ in points])
        assert _worst(ours, ref) <= TOL
    # the free surface doubles what uniform rock gives, roughly: a check that the images act
    uniform = hd.displacement_at(mesh, hd.Elastic(G, nu), frame[2][None], points)
    assert _worst(uniform, hd.displacement_at(mesh, medium, frame[2][None], points)) > 0.2


def test_sill_uplift_on_a_mesh_is_okadas_and_sums_its_elements():
    """A 3 x 2 sill mesh of uniform opening at 0.8 m depth: the uplift and the horizontal
    displacement at the surface are Okada's for the whole rectangle (the sum over
    elements), including a point right above an element edge."""
    depth, length, width = 0.8, 1.2, 1.0
    center, frame, a, b = okada.rectangle(depth, 0.0, length, width)
    mesh = hd.mesh.rectangle(center, frame[0], frame[1], 2 * a, 2 * b, 3, 2)
    points = np.array([[0.6, 0.5, 0.0], [0.4, 0.5, 0.0], [-1.0, 2.0, 0.0], [3.0, -0.5, 0.0]])
    ours = hd.displacement_at(mesh, HALF_SPACE, np.tile([0.0, 0.0, 1e-3], (mesh.n_elements, 1)), points)
    ref = np.array([okada.surface_displacement(x, y, depth, 0.0, length, width, 0.0, 0.0, 1e-3, NU)
                    for x, y, _ in points])
    assert _worst(ours, ref) <= TOL
    assert ours[0, 2] > 0.4e-3  # uplift above the centre: about half the opening


def test_half_space_inside_is_mindlins():
    """Inside the rock (below and beside a tilted rectangle) and at the surface: the
    quadrature of Mindlin's point force (an independent reference)."""
    frame = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(0.5), math.sin(0.5)], [0.0, -math.sin(0.5), math.cos(0.5)]])
    center, a, b = np.array([0.2, -0.1, -1.2]), 0.5, 0.3
    mesh = hd.mesh.rectangle(center, frame[0], frame[1], 2 * a, 2 * b, 1, 1)
    points = np.array([[0.3, 0.4, 0.0], [0.1, 0.2, -0.5], [0.0, 0.0, -2.0], [1.5, -2.0, -0.1]])
    for k in range(3):
        ours = hd.displacement_at(mesh, HALF_SPACE, np.eye(3)[k][None], points)
        ref = np.array([_mindlin.dd_fields(p, center, frame, a, b, 0.0, NU, G)[0][k]
                        for p in points])
        assert _worst(ours, ref) <= TOL


# -- 3D interfaces ---------------------------------------------------------------------------
def _three_layers(images):
    return LayeredMedium([1.0, 0.0], [2.0 * G, G, 5.0 * G], [0.3, 0.2, 0.25], images=images)


def _mismatch(mesh, medium, dd, points, up):
    """Largest jump of the displacement across an interface (``points`` on it: the layer
    above) relative to its largest component."""
    on = hd.displacement_at(mesh, medium, dd, points)
    below = hd.displacement_at(mesh, medium, dd, points - 1e-9 * up)
    return np.abs(on - below).max() / np.abs(on).max(), on


def test_displacement_is_continuous_across_interfaces():
    """A tilted rectangle in a bi-material (one interface: the images are exact) and in
    the middle layer of three (the image series converges, ref. Fig. 3.4: measured jumps
    9e-5, 3e-7, 5e-9 with 6, 12, 24 images): the displacement on each interface (the
    layer above) equals the one just below, while the contrast changes it by a finite
    amount (against uniform rock of the source layer)."""
    mesh = hd.mesh.rectangle([0.1, 0.2, 0.5], [1.0, 0.0, 0.0], [0.0, math.cos(0.3), math.sin(0.3)], 0.4, 0.3, 1, 1)
    dd = np.array([[0.3, -0.2, 1.0]])
    up = np.array([0.0, 0.0, 1.0])
    bimaterial = LayeredMedium([0.0], [G, 3.0 * G], [0.2, 0.3])
    points = np.array([[x, 0.3, 0.0] for x in (-0.8, 0.15, 0.9)])
    assert _mismatch(mesh, bimaterial, dd, points, up)[0] <= 1e-8
    for level in (1.0, 0.0):
        points = np.array([[x, 0.3, level] for x in (-0.8, 0.15, 0.9)])
        coarse = _mismatch(mesh, _three_layers(6), dd, points, up)[0]
        fine, on = _mismatch(mesh, _three_layers(24), dd, points, up)
        assert fine <= 1e-7 < 1e-5 < coarse
        uniform = hd.displacement_at(mesh, hd.Elastic(G, 0.2), dd, points)
        assert np.abs(on - uniform).max() > 1e-2 * np.abs(uniform).max()


def test_equal_layers_are_uniform_rock():
    mesh = hd.mesh.rectangle([0.1, 0.2, 0.5], [1.0, 0.0, 0.0], [0.0, math.cos(0.3), math.sin(0.3)], 0.4, 0.3, 2, 1)
    dd = np.array([[0.3, -0.2, 1.0], [0.0, 0.5, 0.7]])
    points = np.array([[0.3, 0.1, 1.5], [0.3, 0.1, 0.7], [-0.4, 0.0, -0.6]])
    equal = LayeredMedium([1.0, 0.0], [G, G, G], [0.2, 0.2, 0.2], images=3)
    uniform = hd.displacement_at(mesh, hd.Elastic(G, 0.2), dd, points)
    assert np.abs(hd.displacement_at(mesh, equal, dd, points) - uniform).max() <= 1e-13 * np.abs(uniform).max()


# -- 2D ---------------------------------------------------------------------------------------
def test_half_plane_surface_displacement_is_the_closed_form():
    """A horizontal segment 1 m deep, opening and shear: the closed form of
    okada_reference.plane_strain_surface_displacement, itself checked against Okada's
    rectangle 2e4 m long."""
    depth, x1, x2 = 1.0, -0.5, 1.3
    for x in (-2.0, 0.3):
        for u in ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
            long_fault = okada.surface_displacement(1e4, x - x1, depth, 0.0, 2e4, x2 - x1, *u, NU)[1:]
            assert np.abs(okada.plane_strain_surface_displacement(x, depth, x1, x2, u[1], u[2])
                          - long_fault).max() <= 1e-7
    medium = LayeredMedium([0.0], [0.0, G], [NU, NU])
    mesh = hd.mesh.Mesh2D.from_segments(np.array([[x1, -depth]]), np.array([[x2, -depth]]))
    points = np.c_[np.linspace(-3.0, 4.0, 6), np.zeros(6)]
    for dd in np.eye(2):
        ours = hd.displacement_at(mesh, medium, dd[None], points)
        ref = np.array([okada.plane_strain_surface_displacement(x, depth, x1, x2, *dd) for x, _ in points])
        assert _worst(ours, ref) <= TOL


def test_2d_interfaces_continuity_and_equal_layers():
    """As the 3D test (measured jumps with 6, 12, 24 images: 2e-3, 1.5e-5, 2.5e-9)."""
    mesh = hd.mesh.Mesh2D.from_segments(np.array([[-0.3, 0.3]]), np.array([[0.4, 0.7]]))
    dd = np.array([[0.4, 1.0]])
    up = np.array([0.0, 1.0])
    bimaterial = LayeredMedium([0.0], [G, 3.0 * G], [0.2, 0.3])
    points = np.array([[x, 0.0] for x in (-0.8, 0.15, 0.9)])
    assert _mismatch(mesh, bimaterial, dd, points, up)[0] <= 1e-8
    for level in (1.0, 0.0):
        points = np.array([[x, level] for x in (-0.8, 0.15, 0.9)])
        coarse = _mismatch(mesh, _three_layers(6), dd, points, up)[0]
        fine, on = _mismatch(mesh, _three_layers(24), dd, points, up)
        assert fine <= 1e-7 < 1e-5 < coarse
        uniform = hd.displacement_at(mesh, hd.Elastic(G, 0.2), dd, points)
        assert np.abs(on - uniform).max() > 1e-2 * np.abs(uniform).max()
    equal = LayeredMedium([1.0, 0.0], [G, G, G], [0.2, 0.2, 0.2], images=3)
    points = np.array([[0.3, 1.5], [0.3, 0.5], [-0.4, -0.6]])
    uniform = hd.displacement_at(mesh, hd.Elastic(G, 0.2), dd, points)
    assert np.abs(hd.displacement_at(mesh, equal, dd, points) - uniform).max() <= 1e-13 * np.abs(uniform).max()


# -- refusals -----------------------------------------------------------------------------------
def test_points_in_the_void_and_the_tree_method_are_refused():
    mesh = hd.mesh.rectangle([0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, 1.0, 1, 1)
    dd = np.array([[0.0, 0.0, 1.0]])
    with pytest.raises(InputError, match=r"points\[1\] lies in the void layer 0"):
        hd.displacement_at(mesh, HALF_SPACE, dd, [[0.0, 0.0, 0.0], [0.0, 0.0, 0.5]])
    with pytest.raises(InputError, match="method='tree'"):
        hd.displacement_at(mesh, HALF_SPACE, dd, [[0.0, 0.0, 0.0]], method="tree")
    with pytest.raises(InputError, match=r"points\[0\] lies on an element edge"):
        hd.displacement_at(mesh, HALF_SPACE, dd, [[0.5, 0.0, -1.0]])
    info = {}
    assert np.isfinite(hd.displacement_at(mesh, HALF_SPACE, dd, [[0.0, 0.0, 0.0]], info=info)).all()
    assert info["method"] == "direct"


def test_image_rule_matches_a_fine_quadrature_between_interfaces():
    """A surface point over a sill twice as deep as the interface between them (where the
    receiver's mirror in that interface lies on the sill, but no triple of the receiver's
    layer does: displacement3d.image_order takes no subdivision for it): the image
    displacement equals a fine quadrature (8 x 8 points on 16 x 16 sub-squares), with the
    rule of the whole sum and with a rule per triple."""
    from hmatddm.layered import displacement3d

    medium = LayeredMedium([0.0, -500.0, -1500.0], [0.0, G, 2 * G, 0.5 * G], [NU, NU, 0.3, 0.2], images=4)
    interfaces, g, nu = medium.arrays()
    center, frame, a, b = np.array([30.0, -20.0, -1000.0]), np.eye(3), 250.0, 200.0
    triples = displacement3d._buffers(g, 4)
    for y in ([0.0, 0.0, 0.0], [400.0, 100.0, 0.0]):
        y = np.asarray(y, dtype=float)
        n_pairs = displacement3d.trace(center[2], 2, interfaces, g, nu, 4, *triples)
        n_gauss, n_sub = displacement3d.image_order(y, 1, center, frame, a, b, 2, n_pairs, triples, 4, 16, 1e-6)
        assert n_sub == 1
        rule, fine = np.empty((3, 3)), np.empty((3, 3))
        displacement3d.image_rectangle_displacement(y, 1, center, frame, a, b, 2, interfaces, g, nu, 4, n_gauss, n_sub,
                                                    triples, displacement3d._height_cache(g, 4, 2), rule)
        displacement3d.image_rectangle_displacement(y, 1, center, frame, a, b, 2, interfaces, g, nu, 4, 8, 16,
                                                    triples, displacement3d._height_cache(g, 4, 0), fine)
        # far_order's error model (rectangle_quadrature.FAR_TOL = 1e-6 of the image field): measured 1.3e-6
        assert np.abs(rule - fine).max() <= 5e-6 * np.abs(fine).max()
        # the horizontal rectangle's rule per triple (what displacement_at takes for it)
        per_triple = np.empty((3, 3))
        displacement3d.horizontal_image_displacement(y, 1, center, frame, a, b, 2, g, nu, n_pairs, triples, 4, 16,
                                                     1e-6, per_triple)
        assert np.abs(per_triple - fine).max() <= 5e-6 * np.abs(fine).max()


def test_traced_heights_are_shared_by_the_receivers_of_a_tilted_rectangle():
    """A vertical and a tilted rectangle in three layers: displacement_at (each rectangle's
    heights traced once, for all the points) equals each point computed alone with nothing
    cached (every height traced for it)."""
    from hmatddm.layered import displacement3d
    from hmatddm.layered.influence3d import influence_data, with_images

    medium = _three_layers(3)
    for e2 in ([0.0, 0.0, 1.0], [0.0, math.cos(0.6), math.sin(0.6)]):
        mesh = hd.mesh.rectangle([0.1, 0.2, 0.5], [1.0, 0.0, 0.0], e2, 0.8, 0.6, 2, 2)
        dd = np.tile([0.4, -0.2, 1.0], (4, 1))
        points = np.array([[2.0, 0.3, 1.4], [-1.0, 1.5, 0.4], [0.5, -2.0, -0.7]])
        together = hd.displacement_at(mesh, medium, dd, points)
        data = with_images(influence_data(mesh, medium, 0.0, 0.0, 0.0, 0), 3)
        interfaces, g, nu = medium.arrays()
        alone = np.zeros((3, 3))
        for m, point in enumerate(points):
            layer = int(medium.layer_of(point[2]))
            for j in range(mesh.n_elements):
                triples = displacement3d._buffers(g, 3)
                n_center = displacement3d.trace(mesh.centers[j, 2], int(data.layer[j]), interfaces, g, nu, 3, *triples)
                pair = np.empty((3, 3))
                displacement3d.element_displacement(data, point, layer, j, np.empty((3, 3)), np.empty((3, 3)), triples,
                                                    n_center, displacement3d._buffers(g, 3),
                                                    displacement3d._height_cache(g, 3, 0), pair)
                alone[m] += dd[j] @ pair
        assert np.abs(together - alone).max() <= 1e-13 * np.abs(alone).max()
