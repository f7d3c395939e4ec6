"""The tabulated layered remainder of the 3D image method (issue 32, item 2,
:mod:`hmatddm.layered.remainder_table3d`, built by :mod:`hmatddm.layered.remainder_build3d`): the table path against the quadrature of every
image triple (the cross-check, ``method="quadrature"``, with many points), the split into
near and far triples, the table's convergence as it is refined, interface conditions on
the table path, and the cases that build no table."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium
from hmatddm.layered import remainder_build3d as build
from hmatddm.layered import remainder_table3d as rt
from hmatddm.layered.image_points3d import _complementary_gradient, image_point_stress
from hmatddm.layered.image_tracer3d import trace_points
from hmatddm.layered.images2d import _lame
from hmatddm.layered.influence3d import element_layers, influence_data
from hmatddm.layered.potentials3d import Workspace, _contract

G, NU = 1.0, 0.25
INTERFACES = [0.0, -1.5, -3.0]


@pytest.fixture(autouse=True)
def _tables_for_small_meshes(monkeypatch):
    """These meshes are a few squares: let them build tables (influence3d.TABLE_MIN_ELEMENTS)."""
    from hmatddm.layered import influence3d

    monkeypatch.setattr(influence3d, "TABLE_MIN_ELEMENTS", 0)


def _medium(method="table", images=3, gauss_points=6, **options):
    return LayeredMedium(INTERFACES, [0.0, G, 2.0 * G, G], [NU, 0.3, 0.2, NU], images=images,
                         gauss_points=gauss_points, method=method, **options)


def _random_mesh(seed, centers, half):
    rng = np.random.default_rng(seed)
    frames = np.linalg.qr(rng.normal(size=(len(centers), 3, 3)))[0]
    half = np.broadcast_to(np.asarray(half, float), (len(centers),))
    return hd.Mesh3D.from_rectangles(np.asarray(centers, float), frames[:, :, 0], frames[:, :, 1], half, half)


def _matrix(data, rows=None):
    every = np.arange(data.centers.shape[0], dtype=np.int64)
    rows = every if rows is None else np.asarray(rows, dtype=np.int64)
    out = np.empty((3 * rows.size, 3 * every.size))
    drivers.traction_block(data, rows, every, out)
    return out


def _many_points(data):
    """6 Gauss points per side on every (sub-)square (within 7e-11 of the largest entry next
    to interfaces: tests/layered/test_layered_fast3d.py)."""
    return data._replace(gauss_points=6, far_tol=0.0, entry_tol=0.0)


# squares 0.25 m from each interface and the free surface, in all three layers
CENTERS = [[x, y, z] for z in (-0.25, -1.25, -1.75, -2.75, -3.25, -4.0) for x, y in ((0.0, 0.0), (1.1, 0.5))]


@pytest.fixture(scope="module")
def mesh():
    return _random_mesh(5, CENTERS[::2], 0.15)


def _compare_with_the_quadrature(mesh, images):
    data = influence_data(mesh, _medium(images=images), 0.0, 0.0, 0.0, images)
    assert np.any(data.table.pair_index >= 0)
    reference = _matrix(_many_points(influence_data(mesh, _medium("quadrature", images=images), 0.0, 0.0, 0.0,
                                                    images)))
    got = _matrix(data)
    assert np.abs(got - reference).max() <= 1e-8 * np.abs(reference).max()


def test_table_entries_match_the_many_point_quadrature_of_every_triple(mesh):
    """Randomly oriented 0.3 m squares within one element size of the free surface and of
    both interfaces, two images: every entry of the table path (default tolerance) within
    1e-8 of the largest entry of the quadrature of every triple with 6 points per side on
    every (sub-)square, and the table holds far triples for this medium."""
    _compare_with_the_quadrature(mesh, 2)


@pytest.mark.slow
def test_table_entries_match_the_many_point_quadrature_three_images():
    """As above, three images and twelve squares (two per depth)."""
    _compare_with_the_quadrature(_random_mesh(5, CENTERS, 0.15), 3)


def test_near_triples_plus_the_table_give_the_image_sum_at_points():
    """At random source and receiver points of every pair of layers: the near triples
    (quadrature's share) plus the table's remainder equal the sum of every triple, to the
    table's tolerance (two layers apart, the table carries it all)."""
    medium = _medium()
    mesh = _random_mesh(2, CENTERS, 0.15)
    interfaces, g, nu = medium.arrays()
    layers = element_layers(mesh, medium)
    table, stats = build.build_table(mesh, layers, interfaces, g, nu, 3, 1e-6, 10.0)
    assert stats["table_pairs"] == 9 and stats["table_error"] <= 1e-6
    bottoms, tops = rt.layer_bounds(interfaces)
    ranges = {1: (-1.5, 0.0), 2: (-3.0, -1.5), 3: (-4.4, -3.0)}
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(60):
        ls, lr = rng.integers(1, 4, size=2)
        x = np.array([rng.uniform(-0.5, 1.5), rng.uniform(-0.5, 1.0), rng.uniform(*ranges[ls])])
        y = np.array([rng.uniform(-0.5, 1.5), rng.uniform(-0.5, 1.0), rng.uniform(*ranges[lr])])
        normal = rng.normal(size=3)
        normal /= np.linalg.norm(normal)
        full = np.zeros((3, 3, 3))
        image_point_stress(y, lr, x, ls, normal, interfaces, g, nu, 3, full)
        near = np.zeros((3, 3, 3))
        if abs(lr - ls) < 2:
            n_pairs, layer, z, eps, sigma, coef, dcoef = trace_points(np.array([x[2]]), ls, interfaces, g, nu, 3)
            kept = rt.keep_near(n_pairs[0], layer[0], z[0], eps[0], sigma[0], coef[0], dcoef[0], x[2], ls, bottoms,
                                tops)
            assert kept < n_pairs[0]
            gradient = np.empty((3, 3, 3, 3))
            _complementary_gradient(y, lr, x, kept, ls, layer[0], z[0], eps[0], sigma[0], coef[0], dcoef[0], g, nu,
                                    gradient, Workspace(coef.shape[-1]), Workspace(1), np.zeros((2, 3, 3, 1)))
            _contract(gradient, normal, g[ls], _lame(g[ls], nu[ls]), 1.0, near)
        remainder = np.zeros((3, 3, 3))
        assert rt.covers(table, ls, lr, x[2], y[2], np.hypot(*(y - x)[:2]))
        rt.remainder_point_stress(table, y, lr, x, ls, normal, g[ls], _lame(g[ls], nu[ls]), 1.0, remainder,
                                  np.empty(len(rt.COMPONENTS)), np.empty((3, rt.STENCIL)))
        worst = max(worst, np.abs(full - near - remainder).max())
    assert worst <= 1e-6 * 10.0 / 0.09


def test_the_table_converges_as_it_is_refined(mesh):
    """The measured error of the table (relative to the largest entry) stays below the
    tolerance asked, and the table grows as the tolerance falls."""
    interfaces, g, nu = _medium().arrays()
    layers = element_layers(mesh, _medium())
    sizes, errors = [], []
    for tol in (1e-5, 1e-6, 1e-7):
        _, stats = build.build_table(mesh, layers, interfaces, g, nu, 3, tol, 10.0)
        assert 0.0 < stats["table_error"] <= tol
        sizes.append(stats["table_values"])
        errors.append(stats["table_error"])
    assert sizes[0] <= sizes[1] <= sizes[2] and sizes[0] < sizes[2]
    assert errors[2] < errors[0]


@pytest.mark.slow
def test_interface_conditions_on_the_table_path_are_those_of_the_quadrature():
    """Horizontal receiver squares just above and below the interface z = -1.5 and just
    below the free surface, sources of every orientation in all layers: the jump of the
    vertical traction across the interface and the traction at the surface (the image
    series truncated at ``images`` reflections leaves both, falling as images are added)
    are those of the quadrature of every triple, to 1e-8 of the largest entry (the table's
    tolerance, ``entry_scale``), and fall from two images to four (~200 s: receivers 1e-6 m from a plane take 16 x 16
    sub-squares)."""
    rng = np.random.default_rng(9)
    sources = np.column_stack([rng.uniform(-1.0, 1.0, 6), rng.uniform(-1.0, 1.0, 6),
                               [-0.6, -0.9, -2.0, -2.4, -3.6, -3.9]])
    eps = 1e-6
    receivers = np.array([[0.2, 0.1, -1.5 + eps], [0.2, 0.1, -1.5 - eps], [0.3, -0.2, -eps]])
    frames = np.linalg.qr(rng.normal(size=(6, 3, 3)))[0]
    e1 = np.vstack([frames[:, :, 0], np.tile([1.0, 0.0, 0.0], (3, 1))])
    e2 = np.vstack([frames[:, :, 1], np.tile([0.0, 1.0, 0.0], (3, 1))])
    half = np.r_[np.full(6, 0.2), np.full(3, 0.15)]
    mesh = hd.Mesh3D.from_rectangles(np.vstack([sources, receivers]), e1, e2, half, half)
    mismatch = []
    for images in (2, 4):
        blocks = {}
        for method in ("table", "quadrature"):
            data = influence_data(mesh, _medium(method, images=images), 0.0, 0.0, 0.0, images)
            blocks[method] = _matrix(data, rows=[6, 7, 8])[:, :18]
        largest_entry = data.entry_scale * 2.0 * G  # entry_scale is per the stiffest layer's modulus
        residuals = {m: np.r_[(b[0:3] - b[3:6]).ravel(), b[6:9].ravel()] for m, b in blocks.items()}
        assert np.abs(residuals["table"] - residuals["quadrature"]).max() <= 1e-8 * largest_entry
        mismatch.append(np.abs(residuals["table"]).max() / np.abs(blocks["quadrature"]).max())
    assert mismatch[1] < 0.2 * mismatch[0]


@pytest.mark.parametrize("medium", [LayeredMedium([0.0], [0.0, G], [NU, NU], images=1),
                                    LayeredMedium([0.0], [2.0 * G, G], [NU, NU], images=3)],
                         ids=["half-space", "bi-material"])
def test_media_without_far_triples_build_no_table_and_equal_the_quadrature(medium, mesh):
    """A half-space or a bi-material (one interface: every image is a first reflection or
    the transmitted source): no far triple, so no table, and the same entries as the
    quadrature path, bit for bit, in the bi-material. In the half-space the images are
    Okada's forms (okada3d, okada_point3d), within issue 32's 1e-8 of the largest entry of
    the converged quadrature (16 points on up to 64 x 64 sub-squares), which the default
    quadrature, 4.3e-8 away next to the surface here, is not."""
    shallow = _random_mesh(5, [c for c in CENTERS if c[2] > -1.5], 0.15)
    fields = dict(interfaces=medium.interfaces, shear_modulus=medium.shear_modulus,
                  poisson_ratio=medium.poisson_ratio, images=medium.images)
    table = influence_data(shallow, LayeredMedium(**fields, method="table"), 0.0, 0.0, 0.0, medium.images)
    quadrature = influence_data(shallow, LayeredMedium(**fields, method="quadrature"), 0.0, 0.0, 0.0, medium.images)
    assert np.all(table.table.pair_index < 0)
    got = _matrix(table)
    if table.point_form.any() or table.closed_form.any():
        converged = _matrix(quadrature._replace(gauss_points=16, max_subdivisions=64, far_tol=0.0, entry_tol=0.0))
        assert np.abs(got - converged).max() <= 1e-8 * np.abs(converged).max()
    else:
        assert np.array_equal(got, _matrix(quadrature))


def test_equal_layers_reproduce_uniform_rock_on_the_table_path(mesh):
    """Three equal layers (with the images forced on) give the uniform-rock entries to
    round-off: the table holds zeros."""
    equal = LayeredMedium([-1.5, -3.0], [G, G, G], [NU] * 3, images=3)
    data = influence_data(mesh, equal, 0.0, 0.0, 0.0, 3)
    uniform = hd.ElasticityOperator(mesh, hd.Elastic(G, NU), backend="dense").to_dense()
    got = _matrix(data)
    assert np.abs(got - uniform).max() <= 1e-12 * np.abs(uniform).max()


@pytest.mark.parametrize("field, value", [("table_tol", 0.0), ("table_tol", 1e-3), ("table_tol", -1e-9),
                                          ("method", "chebyshev")])
def test_bad_table_options_are_refused_by_name(field, value):
    with pytest.raises(InputError, match=field):
        LayeredMedium(INTERFACES, [0.0, G, 2.0 * G, G], [NU] * 4, **{field: value})


def test_small_meshes_build_no_table(monkeypatch, mesh):
    """Below TABLE_MIN_ELEMENTS the table path integrates every triple (its build would cost
    more than it saves): no table, the quadrature's entries bit for bit."""
    from hmatddm.layered import influence3d

    monkeypatch.setattr(influence3d, "TABLE_MIN_ELEMENTS", mesh.n_elements + 1)
    table = influence_data(mesh, _medium(), 0.0, 0.0, 0.0, 2)
    assert np.all(table.table.pair_index < 0)
    assert np.array_equal(_matrix(table), _matrix(influence_data(mesh, _medium("quadrature"), 0.0, 0.0, 0.0, 2)))


def test_a_table_depends_on_the_domain_not_on_the_history(mesh):
    """A mesh grown by one square within the same rounded-up extent has the same
    :func:`table_domain`, and its table built afresh equals the first mesh's value for
    value (a resumed run interpolates the table of the run it resumes)."""
    from hmatddm.layered import influence3d

    grown = _random_mesh(5, CENTERS[::2] + [[0.4, 0.3, -2.2]], 0.15)
    interfaces, g, _ = _medium().arrays()
    first = build.table_domain(mesh, element_layers(mesh, _medium()), interfaces, g)
    assert build.table_domain(grown, element_layers(grown, _medium()), interfaces, g) == first
    influence3d._TABLES.clear()
    a = influence_data(mesh, _medium(), 0.0, 0.0, 0.0, 2).table
    influence3d._TABLES.clear()
    b = influence_data(grown, _medium(), 0.0, 0.0, 0.0, 2).table
    assert np.array_equal(a.values, b.values) and np.array_equal(a.grid, b.grid)


def test_near_triples_are_traced_with_one_reflection_and_give_the_same_entries(mesh):
    """A table's sources trace their near triples with one reflection
    (remainder_build3d.near_images, ~6x cheaper than the medium's images): no deeper image of
    this stack merges with a near triple, and the entries equal those of the near triples
    taken from the trace with every reflection (near_images 0: the medium's own) to round-off."""
    data = influence_data(mesh, _medium(images=3), 0.0, 0.0, 0.0, 3)
    assert data.table.near_images == 1
    every = _matrix(data._replace(table=data.table._replace(near_images=0)))
    assert np.abs(_matrix(data) - every).max() <= 1e-13 * np.abs(every).max()


def test_near_images_keep_every_reflection_where_a_deeper_image_merges(monkeypatch):
    """Where the trace with every reflection holds a near triple that the one-reflection trace
    lacks or holds otherwise (a deeper image merged into it), the near triples keep every
    reflection: a deeper contribution is imitated on the first near triple of the full trace."""
    medium = _medium()
    interfaces, g, nu = medium.arrays()
    bottoms, tops = rt.layer_bounds(interfaces)
    ranges = [(0.0, 0.0), (-1.5, 0.0), (-3.0, -1.5), (-6.0, -3.0)]
    assert build.near_images(interfaces, g, nu, 3, ranges, bottoms, tops, [1, 2, 3]) == 1
    traced = build.trace

    def merged(t, ls, interfaces, g, nu, images, layer, z, eps, sigma, coef, dcoef):
        n = traced(t, ls, interfaces, g, nu, images, layer, z, eps, sigma, coef, dcoef)
        if images > 1:
            coef[0] *= 1.0 + 1e-9
        return n

    monkeypatch.setattr(build, "trace", merged)
    assert build.near_images(interfaces, g, nu, 3, ranges, bottoms, tops, [1, 2, 3]) == 3


def test_a_rule_contracted_once_along_the_receiver_height_equals_its_points_one_by_one():
    """:func:`remainder_table3d.remainder_rectangle_stress` contracts the values along
    ``y3`` once for the nodes that the stencils of the rule's points share: the same as
    :func:`remainder_table3d.remainder_point_stress` at each point (one-point rules take
    that path; 2 x 2 and 3 x 3 rules the shared one), tilted rectangles, in and across
    layers."""
    from hmatddm.layered.rectangle_quadrature import square_rule
    medium = _medium()
    mesh = _random_mesh(2, CENTERS, 0.15)
    interfaces, g, nu = medium.arrays()
    table, _ = build.build_table(mesh, element_layers(mesh, medium), interfaces, g, nu, 3, 1e-6, 10.0)
    ranges = {1: (-1.3, -0.2), 2: (-2.8, -1.7), 3: (-4.2, -3.2)}
    rng = np.random.default_rng(3)
    compared = 0
    for _ in range(30):
        ls, lr = rng.integers(1, 4, size=2)
        center = np.array([rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.5), rng.uniform(*ranges[ls])])
        y = np.array([rng.uniform(-0.5, 1.5), rng.uniform(-0.5, 1.0), rng.uniform(*ranges[lr])])
        frame = np.linalg.qr(rng.normal(size=(3, 3)))[0].T.copy()
        a, b = 0.1, 0.07
        if not rt.rectangle_covered(table, y, lr, center, frame, a, b, ls):
            continue
        lame = _lame(g[ls], nu[ls])
        for n_gauss in (1, 2, 3):
            xi, eta, wt = square_rule(n_gauss, 1)
            rule = np.zeros((3, 3, 3))
            rt.remainder_rectangle_stress(table, y, lr, center, frame, a, b, ls, g[ls], lame, xi, eta, wt, rule)
            points = np.zeros((3, 3, 3))
            for k in range(len(xi)):
                x = center + xi[k] * a * frame[0] + eta[k] * b * frame[1]
                rt.remainder_point_stress(table, y, lr, x, ls, frame[2], g[ls], lame, wt[k] * a * b, points,
                                          np.empty(len(rt.COMPONENTS)), rt.interpolation_scratch())
            assert np.abs(rule - points).max() <= 1e-14 * np.abs(points).max()
            compared += 1
    assert compared >= 30
