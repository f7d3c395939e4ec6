"""Layered media (ref. Ch. 3): the medium, the image kernels against exact interface
conditions, the operator against the homogeneous one, and the reference's Table 3.1."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.kernels import line2d
from hmatddm.kernels.drivers import traction_block
from hmatddm.layered import LayeredMedium, images2d, segment_quadrature, split_at_interfaces


# -- the medium -------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, field", [
    (dict(interfaces=[0.0, 1.0], shear_modulus=[1, 1, 1], poisson_ratio=[.2, .2, .2]), "interfaces"),
    (dict(interfaces=[1.0, 1.0], shear_modulus=[1, 1, 1], poisson_ratio=[.2, .2, .2]), "interfaces"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1, 1], poisson_ratio=[.2, .2, .2]), "interfaces"),
    (dict(interfaces=[0.0], shear_modulus=[1, -1], poisson_ratio=[.2, .2]), "shear_modulus"),
    (dict(interfaces=[1.0, 0.0], shear_modulus=[1, 0, 1], poisson_ratio=[.2, .2, .2]), "shear_modulus"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2]), "poisson_ratio"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .5]), "poisson_ratio"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .2], images=-1), "images"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .2], toughness=[1.0]), "toughness"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .2], toughness=[1.0, 0.0]),
     r"toughness\[1\] must be > 0 Pa m\^0.5, got 0"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .2], gauss_points=33),
     r"gauss_points must be an integer in \[1, 32\], got 33"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .2], image_tol=1.0),
     r"image_tol must be in \(0, 1\), got 1"),
    (dict(interfaces=[0.0], shear_modulus=[1, 1], poisson_ratio=[.2, .2], in_situ_stress=np.zeros((3, 2, 2))),
     "in_situ_stress"),
])
def test_medium_refuses_bad_input_by_name(kwargs, field):
    with pytest.raises(InputError, match=field):
        LayeredMedium(**kwargs)


def test_medium_layers_and_materials():
    medium = LayeredMedium([1.0, -1.0], [0.0, 2.0, 3.0], [0.1, 0.2, 0.3], toughness=[0, 1e6, 2e6])
    assert list(medium.layer_of([2.0, 1.0, 0.0, -1.0, -5.0])) == [0, 0, 1, 1, 2]
    assert medium.material(2) == hd.Elastic(3.0, 0.3)
    with pytest.raises(InputError, match="void"):
        medium.material(0)


# -- the image kernels ------------------------------------------------------------------
def _total(point, receiver_layer, source, source_layer, normal, medium, n_images):
    """Whole-plane (Hansen path) + complementary stress of a unit DD density."""
    d, g, nu = medium.arrays()
    image = np.empty((2, 2, 2))
    kelvin = np.empty((2, 2, 2))
    images2d.image_point_stress(point[0], point[1], receiver_layer, source[0], source[1], source_layer, normal, d,
                                g, nu, n_images, image)
    images2d.kelvin_point_stress(point[0], point[1], source[0], source[1], normal, g[source_layer],
                                 nu[source_layer], kelvin)
    return image + kelvin


def test_hansen_whole_plane_path_matches_closed_form_segment():
    """The original pair of ref. Eq. 3.23 through the image machinery (derivatives of
    the potentials, the moment of the DD) integrated over a segment = line2d."""
    g, nu = 1.3, 0.27
    p0, p1 = np.array([-0.3, 0.2]), np.array([0.5, 0.9])
    tangent = (p1 - p0) / np.linalg.norm(p1 - p0)
    normal = np.array([-tangent[1], tangent[0]])
    a = 0.5 * np.linalg.norm(p1 - p0)
    center = 0.5 * (p0 + p1)
    point = np.array([2.1, -1.7])
    expected = np.empty((2, 2, 2))
    line2d.stress_pair(point, center, np.array([tangent, normal]), a, g, nu, 0.0, expected, np.empty((2, 2, 2)))
    xi, w = segment_quadrature.composite_rule(10, 4)
    got = np.zeros((2, 2, 2))
    value = np.empty((2, 2, 2))
    for x, weight in zip(xi, w):
        source = center + x * a * tangent
        images2d.kelvin_point_stress(point[0], point[1], source[0], source[1], normal, g, nu, value)
        got += weight * a * value
    assert np.max(np.abs(got - expected)) < 1e-12 * np.max(np.abs(expected))


SOURCE = np.array([0.1, 0.7])
NORMAL = np.array([0.6, 0.8])


@pytest.mark.parametrize("void_layer", [0, 1])
def test_free_surface_is_traction_free(void_layer):
    """gamma = 0 (ref. Sec. 3.4.1): the traction on the surface vanishes exactly, above
    or below the rock (Melan's half-plane)."""
    g = [0.0, 1.0] if void_layer == 0 else [1.0, 0.0]
    medium = LayeredMedium([1.5 if void_layer == 0 else 0.0], g, [0.2, 0.3])
    rock = 1 - void_layer
    source = SOURCE if void_layer == 1 else SOURCE - [0.0, 0.3]
    for x in (-1.0, 0.4, 2.0):
        stress = _total([x, medium.interfaces[0]], rock, source, rock, NORMAL, medium, 1)
        assert np.max(np.abs(stress[:, :, 1])) < 1e-14 * np.max(np.abs(stress))
        assert np.max(np.abs(stress)) > 1e-3


def test_bimaterial_interface_traction_is_continuous():
    """One image is the exact bi-material solution: sigma.e_y equal on both sides of the
    interface at every point, for every DD direction (with the corrected sign of T12)."""
    medium = LayeredMedium([0.0], [1.0, 3.0], [0.2, 0.35])
    for x in (-1.0, 0.4, 2.0):
        above = _total([x, 0.0], 0, SOURCE, 0, NORMAL, medium, 1)
        below = _total([x, 0.0], 1, SOURCE, 0, NORMAL, medium, 1)
        assert np.max(np.abs(above[:, :, 1] - below[:, :, 1])) < 1e-14 * np.max(np.abs(above))
        assert np.max(np.abs(above[:, 0, 0] - below[:, 0, 0])) > 1e-2 * np.max(np.abs(above))  # sxx jumps


def test_three_layers_interface_conditions_converge_with_images():
    """Several interfaces: the traction mismatch at both interfaces falls geometrically
    with the number of images (ref. Fig. 3.4), for a source in the middle layer."""
    medium = LayeredMedium([1.0, 0.0], [2.0, 1.0, 5.0], [0.3, 0.2, 0.25])
    source = np.array([0.1, 0.6])
    mismatch = []
    for n_images in (1, 4, 16):
        worst = 0.0
        for height, upper, lower in ((1.0, 0, 1), (0.0, 1, 2)):
            for x in (-1.0, 0.4, 2.0):
                a = _total([x, height], upper, source, 1, NORMAL, medium, n_images)
                b = _total([x, height], lower, source, 1, NORMAL, medium, n_images)
                worst = max(worst, np.max(np.abs(a[:, :, 1] - b[:, :, 1])) / np.max(np.abs(a)))
        mismatch.append(worst)
    assert mismatch[0] > 1e-2
    assert mismatch[1] < 0.1 * mismatch[0]
    assert mismatch[2] < 1e-6


# -- the operator ---------------------------------------------------------------------
def _crossing_mesh():
    """A tilted crack from layer 0 through layer 1 into layer 2, plus a horizontal one."""
    medium = LayeredMedium([0.5, -0.5], [1.0, 1.0, 1.0], [0.25, 0.25, 0.25])
    mesh = hd.mesh.concatenate([hd.mesh.line([0.2, -1.2], [0.6, 1.1], 9, fracture_id=0),
                                hd.mesh.line([-1.5, 0.1], [-0.3, 0.2], 4, fracture_id=1)])
    return split_at_interfaces(mesh, medium)[0], medium


def test_equal_layers_reproduce_the_homogeneous_operator():
    mesh, medium = _crossing_mesh()
    assert mesh.n_elements > 13  # split where the crack crosses the interfaces
    layered = hd.ElasticityOperator(mesh, medium).to_dense()
    homogeneous = hd.ElasticityOperator(mesh, hd.Elastic(1.0, 0.25)).to_dense()
    assert np.max(np.abs(layered - homogeneous)) <= 1e-12 * np.max(np.abs(homogeneous))


def test_straddling_element_is_refused_by_name():
    medium = LayeredMedium([0.0], [1.0, 2.0], [0.25, 0.25])
    mesh = hd.mesh.line([0.0, -1.0], [0.0, 1.0], 3)
    with pytest.raises(InputError, match="straddles interface 0.*split_at_interfaces"):
        hd.ElasticityOperator(mesh, medium)
    split, parent = split_at_interfaces(mesh, medium)
    assert split.n_elements == 4 and list(parent) == [0, 1, 1, 2]
    assert np.isclose(split.areas.sum(), mesh.areas.sum())


def test_image_quadrature_converges_with_gauss_points():
    """No subdivision: the image terms of a bi-material block converge as Gauss points
    increase (they are regular, ref. Eqs 3.12-3.13)."""
    medium = LayeredMedium([0.0], [1.0, 4.0], [0.25, 0.3], images=1)
    mesh = hd.mesh.concatenate([hd.mesh.line([-1, -0.4], [1, -0.4], 6), hd.mesh.line([0.3, -1.5], [0.3, -0.6], 3)])
    from hmatddm.layered import influence2d

    data = influence2d.influence_data(mesh, medium, 0.0, 0.0, 0.5, 1)
    rows = cols = np.arange(mesh.n_elements)
    blocks = []
    for n_gauss in (1, 2, 4, 8, 16):
        block = np.empty((2 * mesh.n_elements, 2 * mesh.n_elements))
        traction_block(data._replace(gauss_points=n_gauss, max_subdivisions=1), rows, cols, block)  # one sub-segment
        blocks.append(block)
    errors = [np.max(np.abs(b - blocks[-1])) / np.max(np.abs(blocks[-1])) for b in blocks[:-1]]
    assert errors[0] > 1e-3
    assert all(e1 < e0 for e0, e1 in zip(errors[:-1], errors[1:]))
    assert errors[-1] < 1e-6


def test_hmatrix_equals_dense_on_a_layered_mesh():
    medium = LayeredMedium([0.0, -1.0], [0.5, 1.0, 3.0], [0.2, 0.25, 0.3])
    mesh = hd.mesh.concatenate([hd.mesh.line([-3, -0.5], [3, -0.5], 24, fracture_id=0),
                                hd.mesh.line([-2.0, -0.9], [-2.0, 0.9], 8, fracture_id=1)])
    mesh = split_at_interfaces(mesh, medium)[0]
    dense = hd.ElasticityOperator(mesh, medium, backend="dense")
    hmat = hd.ElasticityOperator(mesh, medium, backend="hmatrix", eps=1e-8, leaf_size=8)
    assert hmat.stats["n_images"] == dense.stats["n_images"] >= 1
    assert hmat.stats["n_admissible"] > 0  # low-rank blocks exist (compression: benchmarks/bench_layered.py)
    a = dense.to_dense()
    assert np.max(np.abs(hmat.to_dense() - a)) <= 1e-6 * np.max(np.abs(a))
    x = np.random.default_rng(0).standard_normal(a.shape[0])
    assert np.linalg.norm(hmat @ x - a @ x) <= 1e-6 * np.linalg.norm(a @ x)


def test_stress_at_in_a_layered_medium_matches_the_operator():
    """stress_at at the collocation points, projected on the normals, = op @ dd."""
    medium = LayeredMedium([0.0], [1.0, 2.5], [0.1, 0.3], images=1)
    mesh = hd.mesh.line([-1, -1], [1, -1], 10)
    op = hd.ElasticityOperator(mesh, medium)
    dd = np.random.default_rng(1).standard_normal((mesh.n_elements, 2))
    stress = hd.stress_at(mesh, medium, dd, mesh.centers + 1e-9 * mesh.tangents)
    traction = np.einsum("mij,mj->mi", stress, mesh.normals)
    assert np.allclose(traction.ravel(), op @ dd.ravel(), rtol=1e-6, atol=1e-9 * np.abs(op @ dd.ravel()).max())


# -- ref. Table 3.1 ---------------------------------------------------------------------
TABLE_3_1 = {0.0: 1.6930, 0.25: 1.2411, 0.5: 1.1070, 0.75: 1.0406, 1.0: 1.0, 2.5: 0.9045, 5.0: 0.8598,
             7.5: 0.8418, 10.0: 0.8320}


def test_table_3_1_pressurised_crack_in_a_bimaterial():
    """Ref. Sec. 3.4.2: a crack of length 2h at depth h below the interface with the
    second material (gamma = G2/G1), 40 constant elements, nu = 0.1, p = 1e-3 G1: the
    strain energy W = (1/2) int p w dx relative to gamma = 1 within 1% of Table 3.1."""
    h = 1.0
    mesh = hd.mesh.line([-h, -h], [h, -h], 40)
    energy = {}
    for gamma in TABLE_3_1:
        medium = LayeredMedium([0.0], [gamma, 1.0], [0.1, 0.1])
        op = hd.ElasticityOperator(mesh, medium)
        w = hd.opening(mesh, hd.solve(op, -1e-3 * mesh.normals))
        energy[gamma] = 0.5 * 1e-3 * np.sum(w * mesh.areas)
    for gamma, expected in TABLE_3_1.items():
        assert abs(energy[gamma] / energy[1.0] - expected) < 0.01 * expected, gamma


# -- ref. Sec. 3.4.1 ---------------------------------------------------------------------
def _hole_hoop_stress(n, medium, shear_modulus, poisson_ratio, pressure, radius, depth):
    """Hoop stress on the rock side of a pressurised circular hole meshed by ``n``
    constant DD elements (counter-clockwise: normals point into the hole).

    A uniform DD on a closed contour (a rigid motion of the inside) produces no stress,
    so the system is singular: three rows fix the mean DD and its moment. On the contour
    the DD model gives the mean of the hoop stresses of both sides; the rock side is
    ``mean - G/(1 - nu) [d(DD.t)/ds - (DD.n)/R]`` (the jump of the tangential strain across
    the contour, plane strain, with traction continuous)."""
    theta = np.linspace(0.0, 2.0 * np.pi, n + 1)
    nodes = np.column_stack([radius * np.cos(theta), -depth + radius * np.sin(theta)])
    mesh = hd.Mesh2D.from_segments(nodes[:-1], nodes[1:])
    a = hd.ElasticityOperator(mesh, medium).to_dense()
    length, c = mesh.areas, mesh.centers
    rows = np.zeros((3, 2 * n))
    rows[0, 0::2] = length
    rows[1, 1::2] = length
    rows[2, 0::2] = -c[:, 1] * length
    rows[2, 1::2] = c[:, 0] * length
    rhs = np.concatenate([(-pressure * mesh.normals).ravel(), np.zeros(3)])
    dd = np.linalg.lstsq(np.vstack([a, rows * np.abs(a).max()]), rhs, rcond=None)[0].reshape(n, 2)
    stress = hd.stress_at(mesh, medium, dd, mesh.centers)
    mean = np.einsum("mi,mij,mj->m", mesh.tangents, stress, mesh.tangents)
    tangential = np.einsum("mi,mi->m", dd, mesh.tangents)
    normal = np.einsum("mi,mi->m", dd, mesh.normals)
    ds = 0.5 * np.roll(length, -1) + length + 0.5 * np.roll(length, 1)
    jump = (np.roll(tangential, -1) - np.roll(tangential, 1)) / ds - normal / radius
    return mesh.centers, mean - shear_modulus / (1.0 - poisson_ratio) * jump


def test_savin_pressurised_hole_near_a_free_surface():
    """Ref. Sec. 3.4.1: R = 1, centre at depth 2 below a free surface (gamma = 0),
    nu = 0.2, p = 0.2 G. The closed form of Eq. 3.40 needs the angle phi of the
    reference's Fig. 3.5 (not in the text). In bipolar coordinates (poles at
    (0, -+a), a^2 = h^2 - R^2; beta = the angle the poles subtend at the contour point)
    the hoop stress is p [1 + 2 (R/a)^2 sin^2 beta], i.e. Eq. 3.40 with
    tan^2 phi = 2 (R/a)^2 sin^2 beta: p on the vertical axis, and the classical maximum
    p (h^2 + R^2)/(h^2 - R^2) where beta = 90 deg (this form was also checked against a
    homogeneous DDM run with the free surface meshed explicitly: 0.4% apart).
    256 constant elements (the reference: 48 linear BEM elements; the rock-side hoop
    stress of constant DDs converges at first order: 5% off with 48): within 2%."""
    g, nu, p, radius, depth = 1.0, 0.2, 0.2, 1.0, 2.0
    medium = LayeredMedium([0.0], [0.0, g], [nu, nu])
    points, hoop = _hole_hoop_stress(256, medium, g, nu, p, radius, depth)
    a = np.sqrt(depth ** 2 - radius ** 2)
    to_lower = np.array([0.0, -a]) - points
    to_upper = np.array([0.0, a]) - points
    beta = np.arctan2(np.abs(to_lower[:, 0] * to_upper[:, 1] - to_lower[:, 1] * to_upper[:, 0]),
                      np.sum(to_lower * to_upper, axis=1))
    expected = p * (1.0 + 2.0 * (radius / a) ** 2 * np.sin(beta) ** 2)
    assert np.max(np.abs(hoop - expected) / expected) < 0.02
    assert abs(np.max(hoop) / p - (depth ** 2 + radius ** 2) / (depth ** 2 - radius ** 2)) < 0.02


def test_grown_mesh_border_blocks_keep_the_base_images():
    """A growing run's extended operator (hmatrix base + exact border blocks) uses the
    base's number of images, and equals a fresh dense operator with that number."""
    from hmatddm.elasticity.extended import ExtendedElasticityOperator

    medium = LayeredMedium([0.5, -0.5], [2.0, 1.0, 2.0], [0.25, 0.25, 0.25])
    full = split_at_interfaces(hd.mesh.line([0.0, -1.5], [0.0, 1.5], 24), medium)[0]
    inner = np.flatnonzero(np.abs(full.centers[:, 1]) < 1.0)
    outer = np.flatnonzero(np.abs(full.centers[:, 1]) >= 1.0)
    base_mesh, grown = full.subset(inner), full.subset(np.concatenate([inner, outer]))
    base = hd.ElasticityOperator(base_mesh, medium, backend="hmatrix", eps=1e-10, leaf_size=4)
    extended = ExtendedElasticityOperator(base, grown)
    fixed = LayeredMedium(medium.interfaces, medium.shear_modulus, medium.poisson_ratio,
                          images=base.stats["n_images"])
    dense = hd.ElasticityOperator(grown, fixed).to_dense()
    x = np.random.default_rng(2).standard_normal(dense.shape[0])
    assert np.linalg.norm(extended @ x - dense @ x) <= 1e-8 * np.linalg.norm(dense @ x)


def test_reference_three_layer_conclusions():
    """Ref. Sec. 3.5.1 (Table 3.2; gamma = G_outer/G_middle, crack length = middle-layer
    height, nu = 0.2, 20 constant elements): the vertical crack needs fewer images than the
    horizontal one, and gamma = 5 more than gamma = 2 (crack volume against 16 images)."""
    h = 1.0
    meshes = {"horizontal": hd.mesh.line([-h / 2, 0.0], [h / 2, 0.0], 20),
              "vertical": hd.mesh.line([0.0, -h / 2], [0.0, h / 2], 20)}

    def volume(mesh, gamma, images):
        medium = LayeredMedium([h / 2, -h / 2], [gamma, 1.0, gamma], [0.2, 0.2, 0.2], images=images,
                               gauss_points=3)
        dd = hd.solve(hd.ElasticityOperator(mesh, medium), -1e-3 * mesh.normals)
        return np.sum(hd.opening(mesh, dd) * mesh.areas)

    error = {}
    for gamma in (2.0, 5.0):
        for name, mesh in meshes.items():
            reference = volume(mesh, gamma, 16)
            error[gamma, name] = abs(volume(mesh, gamma, 1) / reference - 1.0)
    for gamma in (2.0, 5.0):
        assert error[gamma, "vertical"] < 0.25 * error[gamma, "horizontal"]
    for name in meshes:
        assert error[5.0, name] > 2.0 * error[2.0, name]
    assert error[2.0, "vertical"] < 0.01 < error[5.0, "horizontal"]  # one image: fine vs 10% off
