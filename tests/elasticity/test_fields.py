"""Stress fields at points (hmatddm.elasticity.fields, behind hd.stress_at / hd.mean_stress_at): the
exact sum against an independent per-pair sum of the kernels' ``stress_pair``, and the
points x elements H-matrix against the exact sum (2D and 3D, points near and far)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.elasticity.fields import StressField
from hmatddm.kernels import line2d, rectangle3d
from hmatddm.network import NetworkSpec, generate_network


@pytest.fixture(scope="module")
def material():
    return hd.Elastic(6.62e9, 0.25)


def _random_mesh3d(rng, n=30):
    centers = rng.uniform(-5, 5, (n, 3))
    e1 = rng.normal(size=(n, 3))
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(e1, rng.normal(size=(n, 3)))
    e2 /= np.linalg.norm(e2, axis=1)[:, None]
    return hd.Mesh3D.from_rectangles(centers, e1, e2, rng.uniform(0.2, 1.0, n), rng.uniform(0.2, 1.0, n))


def _reference(mesh, material, dd, points, shift=0.0):
    """Sum over elements of the kernels' per-pair global stress (``stress_pair``: unit
    global DD components, rotated component by component), written apart from
    hmatddm.elasticity.fields: (M, d, d)."""
    g, nu, d = material.shear_modulus, material.poisson_ratio, mesh.dim
    pair, work = np.empty((d, d, d)), np.empty((d, d, d))
    out = np.zeros((len(points), d, d))
    for t, point in enumerate(np.asarray(points, dtype=float)):
        for j in range(mesh.n_elements):
            if d == 3:
                rectangle3d.stress_pair(point, mesh.centers[j], mesh.frames[j], mesh.half_a[j], mesh.half_b[j], g,
                                        nu, shift, pair, work)
            else:
                line2d.stress_pair(point, mesh.centers[j], mesh.frames[j], mesh.half_length[j], g, nu, shift, pair,
                                   work)
            out[t] += np.einsum("qij,q->ij", pair, dd[j])
    return out


def test_direct_3d_matches_component_kernel(material):
    rng = np.random.default_rng(0)
    mesh = _random_mesh3d(rng)
    dd = rng.normal(size=(mesh.n_elements, 3)) * 1e-3
    points = rng.uniform(-6, 6, (200, 3))
    reference = _reference(mesh, material, dd, points)
    stress = hd.stress_at(mesh, material, dd, points, method="direct")
    assert np.max(np.abs(stress - reference)) <= 1e-12 * np.max(np.abs(reference))
    assert np.allclose(stress, np.transpose(stress, (0, 2, 1)), rtol=0, atol=0)
    mean = hd.mean_stress_at(mesh, material, dd, points, method="direct")
    trace = np.trace(reference, axis1=1, axis2=2) / 3.0
    assert np.max(np.abs(mean - trace)) <= 1e-12 * np.max(np.abs(reference))


def test_edge_points_3d_average_or_refuse(material):
    rng = np.random.default_rng(1)
    mesh = _random_mesh3d(rng, 8)
    dd = rng.normal(size=(mesh.n_elements, 3)) * 1e-3
    on_edge = mesh.centers[:4] + mesh.half_a[:4, None] * mesh.frames[:4, 0]
    reference = _reference(mesh, material, dd, on_edge, shift=1e-3)
    stress = hd.stress_at(mesh, material, dd, on_edge, singular_correction="average", method="direct")
    assert np.max(np.abs(stress - reference)) <= 1e-12 * np.max(np.abs(reference))
    mean = hd.mean_stress_at(mesh, material, dd, on_edge, singular_correction="average")
    assert np.allclose(mean, np.trace(reference, axis1=1, axis2=2) / 3.0, rtol=1e-12, atol=0)
    for function in (hd.stress_at, hd.mean_stress_at):
        with pytest.raises(hd.InputError, match="edge"):
            function(mesh, material, dd, on_edge)


def test_near_miss_points_are_averaged_like_edge_points(material):
    """A point a hair's breadth beyond an element edge (a near miss, stress ~1/gap) is
    treated as on the edge with ``near_fraction``: the remote-failure check must not see a
    spurious near-singular stress at a natural element whose centre sits at a hydraulic
    element's edge. 3D and 2D."""
    rng = np.random.default_rng(2)
    mesh = _random_mesh3d(rng, 8)
    dd = rng.normal(size=(mesh.n_elements, 3)) * 1e-3
    on_edge = mesh.centers[:4] + mesh.half_a[:4, None] * mesh.frames[:4, 0]
    near = on_edge + 1e-7 * mesh.half_a[:4, None] * mesh.frames[:4, 0]  # just outside
    edge_value = hd.stress_at(mesh, material, dd, on_edge, singular_correction="average")
    plain = hd.stress_at(mesh, material, dd, near, singular_correction="average")
    scale = np.max(np.abs(edge_value))
    assert np.max(np.abs(plain - edge_value)) > 10.0 * scale  # ~1/gap without the treatment
    for method in ("direct", "tree"):
        treated = hd.stress_at(mesh, material, dd, near, singular_correction="average", method=method,
                               near_fraction=0.5)
        assert np.max(np.abs(treated - edge_value)) <= 1e-4 * scale
    mean = hd.mean_stress_at(mesh, material, dd, near, singular_correction="average", near_fraction=0.5)
    np.testing.assert_allclose(mean, np.trace(edge_value, axis1=1, axis2=2) / 3.0, rtol=0, atol=1e-4 * scale)
    with pytest.raises(hd.InputError, match="near_fraction"):
        hd.stress_at(mesh, material, dd, near, near_fraction=0.5)
    with pytest.raises(hd.InputError, match="near_fraction"):
        hd.stress_at(mesh, material, dd, near, near_fraction=1.5)
    # 2D: a point just beyond a segment's end
    line = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 4)
    dd2 = rng.normal(size=(4, 2)) * 1e-3
    tip, beyond = np.array([[1.0, 0.0]]), np.array([[1.0 + 1e-8, 1e-8]])
    tip_value = hd.stress_at(line, material, dd2, tip, singular_correction="average")
    treated = hd.stress_at(line, material, dd2, beyond, singular_correction="average", near_fraction=0.5)
    assert np.max(np.abs(treated - tip_value)) <= 1e-4 * np.max(np.abs(tip_value))


def test_direct_2d_matches_component_kernel(material):
    rng = np.random.default_rng(2)
    mesh = hd.mesh.line([0.0, 0.0], [3.0, 1.0], 12)
    dd = rng.normal(size=(12, 2)) * 1e-3
    points = rng.uniform(-3, 4, (150, 2))
    reference = _reference(mesh, material, dd, points)
    assert np.max(np.abs(hd.stress_at(mesh, material, dd, points) - reference)) <= 1e-12 * np.max(np.abs(reference))
    mean = hd.mean_stress_at(mesh, material, dd, points)
    expected = (1.0 + material.poisson_ratio) * np.trace(reference, axis1=1, axis2=2) / 3.0
    assert np.max(np.abs(mean - expected)) <= 1e-12 * np.max(np.abs(reference))


@pytest.fixture(scope="module")
def dfn_scene():
    """Three vertical hydraulic fractures (elliptical opening plus some slip) and the
    centres of a full-height natural-fracture network as targets (ref. Sec. 6.3)."""
    spec = NetworkSpec(region=(-30.0, 30.0, -40.0, 40.0), density=0.05, length_exponent=2.0, l_min=1.0,
                       l_max=20.0, mean_azimuths_deg=(45.0,), kappas=(5.0,), height=4.0, seed=3)
    natural = generate_network(spec).to_mesh3d(1.0, 4)
    length = 30
    parts = [hd.mesh.rectangle([x, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], length, 4.0, length, 4,
                               fracture_id=k) for k, x in enumerate((-10.0, 0.0, 10.0))]
    mesh = hd.mesh.concatenate(parts)
    y, z = mesh.centers[:, 1], mesh.centers[:, 2]
    opening = 1e-3 * np.sqrt(np.clip(1 - (y / (length / 2)) ** 2, 0, 1)) * np.sqrt(np.clip(1 - (z / 2) ** 2, 0.05, 1))
    dd = opening[:, None] * mesh.normals + 0.2 * opening[:, None] * np.array([0.0, 1.0, 0.3])
    return mesh, dd, natural.centers


# the DFN scene's tree evaluations at a second eps, for three eps and on 1 and 2 threads are
# slow (issue 18 item 8); tree against direct at eps 1e-4 here and the two smaller scenes below
# stay in the default set
@pytest.mark.parametrize("eps", [1e-4, pytest.param(1e-6, marks=pytest.mark.slow)])
def test_tree_matches_direct_on_dfn_scene(material, dfn_scene, eps):
    mesh, dd, points = dfn_scene
    exact = hd.stress_at(mesh, material, dd, points, singular_correction="average", method="direct")
    info = {}
    approx = hd.stress_at(mesh, material, dd, points, singular_correction="average", method="tree", eps=eps,
                          info=info)
    assert info["method"] == "tree" and info["pairs_compressed"] > 0.25 * len(points) * mesh.n_elements
    scale = np.max(np.abs(exact))
    assert np.max(np.abs(approx - exact)) <= eps * scale
    exact_mean = hd.mean_stress_at(mesh, material, dd, points, method="direct")
    approx_mean = hd.mean_stress_at(mesh, material, dd, points, method="tree", eps=eps)
    assert np.max(np.abs(approx_mean - exact_mean)) <= eps * np.max(np.abs(exact_mean))


@pytest.mark.slow
def test_tree_error_follows_eps(material, dfn_scene):
    mesh, dd, points = dfn_scene
    exact = hd.stress_at(mesh, material, dd, points, method="direct")
    errors = [np.max(np.abs(hd.stress_at(mesh, material, dd, points, method="tree", eps=eps) - exact))
              for eps in (1e-3, 1e-5, 1e-7)]
    assert errors[0] > errors[1] > errors[2]


def test_tree_coplanar_targets_and_zero_dd(material):
    """Points in the plane of the elements (ahead of a planar crack) and elements without
    DD: the compressed sum must not stop on zero pivots nor lose the far field."""
    mesh = hd.mesh.rectangle([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 40.0, 6.0, 40, 6)
    dd = 1e-3 * mesh.normals
    dd[mesh.centers[:, 1] > 10.0] = 0.0
    y = np.linspace(25.0, 80.0, 400)
    z = np.linspace(-2.5, 2.5, 6)
    yy, zz = np.meshgrid(y, z)
    points = np.column_stack([np.zeros(yy.size), yy.ravel(), zz.ravel()])
    points = np.concatenate([points, points + [3.0, 0.0, 0.0]])
    exact = hd.stress_at(mesh, material, dd, points, method="direct")
    approx = hd.stress_at(mesh, material, dd, points, method="tree", eps=1e-6)
    assert np.max(np.abs(approx - exact)) <= 1e-6 * np.max(np.abs(exact))


@pytest.mark.slow
def test_results_do_not_depend_on_thread_count(material, dfn_scene):
    numba = pytest.importorskip("numba")
    mesh, dd, points = dfn_scene
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two numba threads")
    results = []
    previous = numba.get_num_threads()
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            results.append([hd.stress_at(mesh, material, dd, points, method=method) for method in ("direct", "tree")])
    finally:
        numba.set_num_threads(previous)
    for one, two in zip(*results):
        assert np.array_equal(one, two)


def test_auto_method_and_bad_input(material, dfn_scene):
    mesh, dd, points = dfn_scene
    info = {}
    hd.stress_at(mesh, material, dd, points[:10], info=info)
    assert info["method"] == "direct"
    with pytest.raises(hd.InputError, match="method"):
        hd.stress_at(mesh, material, dd, points, method="fmm")
    with pytest.raises(hd.InputError, match="eps"):
        hd.mean_stress_at(mesh, material, dd, points, eps=2.0)
    assert hd.stress_at(mesh, material, dd, np.zeros((0, 3))).shape == (0, 3, 3)


def test_tree_mixed_element_sizes(material):
    """Blocks mixing a large fracture's 1 m elements with a few small fractures of 0.1 m
    elements (the case that defeats a stop test looking only at the last cross): every
    component within eps of the largest, against the exact sum."""
    rng = np.random.default_rng(5)
    parts = [hd.mesh.rectangle([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 40.0, 8.0, 40, 8)]
    for k in range(6):
        center = [rng.uniform(-3, 3), rng.uniform(-20, 20), rng.uniform(-4, 4)]
        parts.append(hd.mesh.rectangle(center, [1.0, 1.0, 0.0], [0.0, 0.0, 1.0], 0.3, 0.3, 3, 3, fracture_id=k + 1))
    mesh = hd.mesh.concatenate(parts)
    dd = 1e-3 * mesh.normals
    small = mesh.fracture_id > 0
    dd[small] = 0.3 * rng.normal(size=(int(small.sum()), 3))  # small fractures with large DDs
    points = np.column_stack([rng.uniform(-60, 60, 6000), rng.uniform(-80, 80, 6000), rng.uniform(-4, 4, 6000)])
    points = points[np.abs(points[:, 0]) > 5.0]
    exact = hd.stress_at(mesh, material, dd, points, method="direct")
    for eps in (1e-3, 1e-5):
        approx = hd.stress_at(mesh, material, dd, points, method="tree", eps=eps)
        assert np.max(np.abs(approx - exact)) <= eps * np.max(np.abs(exact))


def test_tree_matches_direct_in_2d_near_and_far(material):
    """2D (plane strain): a branched set of segments, points on a grid around them (near
    and far, some within an element length of a tip): the H-matrix sum within eps of the
    largest component of the exact sum, stress and mean stress."""
    parts = [hd.mesh.line([-20.0, 0.0], [20.0, 0.0], 160), hd.mesh.line([5.0, -10.0], [12.0, 8.0], 70)]
    mesh = hd.mesh.concatenate(parts)
    rng = np.random.default_rng(7)
    dd = 1e-3 * mesh.normals + 1e-4 * rng.normal(size=(mesh.n_elements, 2))
    x, y = np.meshgrid(np.linspace(-60.0, 60.0, 90), np.linspace(-40.0, 40.0, 61) + 0.013)
    points = np.column_stack([x.ravel(), y.ravel()])
    exact = hd.stress_at(mesh, material, dd, points, singular_correction="average", method="direct")
    for eps in (1e-4, 1e-6):
        info = {}
        approx = hd.stress_at(mesh, material, dd, points, singular_correction="average", method="tree", eps=eps,
                              info=info)
        assert info["method"] == "tree" and info["pairs_compressed"] > 0.25 * len(points) * mesh.n_elements
        assert np.max(np.abs(approx - exact)) <= eps * np.max(np.abs(exact))
    exact_mean = hd.mean_stress_at(mesh, material, dd, points, singular_correction="average", method="direct")
    approx_mean = hd.mean_stress_at(mesh, material, dd, points, singular_correction="average", method="tree",
                                    eps=1e-6)
    assert np.max(np.abs(approx_mean - exact_mean)) <= 1e-6 * np.max(np.abs(exact_mean))


def test_stress_field_applies_to_any_dd(material, dfn_scene):
    """One StressField (the H-matrix built once) applied to two different DDs gives the
    exact sum of each; the direct field gives the same as hd.stress_at."""
    mesh, dd, points = dfn_scene
    points = points[::4]
    tree = StressField(mesh, material, points, "stress", "average", method="tree", eps=1e-6)
    direct = StressField(mesh, material, points, "stress", "average", method="direct")
    assert tree.hmatrix is not None and tree.hmatrix.rectangular and direct.hmatrix is None
    for k, scaled in enumerate((dd, np.roll(dd, 7, axis=0) * [1.0, -2.0, 0.5])):
        exact = direct(scaled)
        if k == 0:
            stress = hd.stress_at(mesh, material, scaled, points, singular_correction="average", method="direct")
            np.testing.assert_array_equal(exact[:, 0], stress[:, 0, 0])
        assert np.max(np.abs(tree(scaled) - exact)) <= 1e-6 * np.max(np.abs(exact))

