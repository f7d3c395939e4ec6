"""The one set of kernel drivers (hmatddm.kernels.drivers) against loops written here over
the per-pair kernels of each kind of element, and the kinds against each other."""
from typing import NamedTuple

import numpy as np
import pytest

import hmatddm as hd
from hmatddm.kernels import drivers, element_data, line2d, line2d_higher_order, rectangle3d
from hmatddm.layered import LayeredMedium, influence2d

MATERIAL = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)


def segments(n=9, element_order=0, seed=0):
    rng = np.random.default_rng(seed)
    p0 = rng.uniform(-2.0, 2.0, (n, 2))
    return hd.Mesh2D.from_segments(p0, p0 + rng.normal(0.0, 0.4, (n, 2)), element_order=element_order)


def rectangles(n=8, seed=1):
    rng = np.random.default_rng(seed)
    q = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    return hd.Mesh3D.from_rectangles(rng.uniform(-2, 2, (n, 3)), q[:, :, 0], q[:, :, 1], rng.uniform(0.2, 0.8, n),
                                     rng.uniform(0.2, 0.8, n))


def record(mesh, alpha=0.0, shift=1e-3, near_fraction=0.5):
    self_max = None
    if alpha > 0.0:
        self_max = drivers.self_block_maxima(element_data(mesh, MATERIAL, singular_shift=shift,
                                                          near_fraction=near_fraction))
    return element_data(mesh, MATERIAL, singular_shift=shift, alpha=alpha, self_max=self_max,
                        near_fraction=near_fraction)


def pair_block(data, i, j):
    """The element block of receiver i and source j from the per-pair kernels, near-miss
    distance and Eq. 6.11 scaling written out here."""
    near = 0.0
    if isinstance(data, rectangle3d.Rectangles):
        if i != j:
            near = data.near_fraction * min(data.half_a[i], data.half_b[i], data.half_a[j], data.half_b[j])
        block = np.empty((3, 3))
        rectangle3d.traction_pair(data.centers[i], data.frames[i, 2], data.centers[j], data.frames[j], data.half_a[j],
                                  data.half_b[j], data.shear_modulus, data.poisson_ratio, data.singular_shift, block,
                                  np.empty((3, 3, 3)), near)
    elif isinstance(data, line2d.Segments):
        if i != j:
            near = data.near_fraction * min(data.half_length[i], data.half_length[j])
        block = np.empty((2, 2))
        line2d.traction_pair(data.centers[i], data.frames[i, 1], data.centers[j], data.frames[j], data.half_length[j],
                             data.shear_modulus, data.poisson_ratio, data.singular_shift, block, np.empty((2, 2, 2)),
                             near)
    else:
        n = len(data.nodes)
        outer = 1.0 - np.max(np.abs(data.nodes))
        if i != j:
            near = data.near_fraction * outer * min(data.half_length[i], data.half_length[j])
        block = np.empty((2 * n, 2 * n))
        pair = np.empty((n, 2, 2))
        for r in range(n):
            point = data.centers[i] + data.half_length[i] * data.nodes[r] * data.frames[i, 0]
            line2d_higher_order.traction_nodes(point, data.frames[i, 1], data.centers[j], data.frames[j],
                                               data.half_length[j], data.coefficients, data.shear_modulus,
                                               data.poisson_ratio, data.singular_shift, pair, np.empty((n, 2, 2, 2)),
                                               near)
            block[2 * r:2 * r + 2] = pair.transpose(1, 0, 2).reshape(2, 2 * n)
    largest = np.max(np.abs(block))
    limit = data.alpha * data.self_max[j]
    if data.alpha > 0.0 and i != j and largest > limit:
        block = block * (limit / largest)
    return block


MESHES = {"segments": lambda: segments(), "quadratic": lambda: segments(element_order=2),
          "linear": lambda: segments(element_order=1), "rectangles": lambda: rectangles()}


@pytest.mark.parametrize("kind", sorted(MESHES))
@pytest.mark.parametrize("alpha", [0.0, 1.0])
def test_matrix_is_the_per_pair_blocks(kind, alpha):
    mesh = MESHES[kind]()
    data = record(mesh, alpha)
    d = drivers.element_unknowns(data)
    assert d == mesh.dim * mesh.n_nodes
    matrix = drivers.influence_matrix(data)
    for i in range(mesh.n_elements):
        for j in range(mesh.n_elements):
            np.testing.assert_array_equal(matrix[d * i:d * i + d, d * j:d * j + d], pair_block(data, i, j))
    if alpha > 0.0:  # ref. Eq. 6.11: no off-diagonal block above its source's self block
        index = np.arange(mesh.n_elements)
        blocks = np.abs(matrix.reshape(mesh.n_elements, d, mesh.n_elements, d)).max(axis=(1, 3))
        np.testing.assert_array_equal(blocks[index, index], data.self_max)
        assert np.all(blocks <= data.self_max[None, :] * (1.0 + 1e-15))


def layered_meshes():
    medium = LayeredMedium([0.0], [10e9, 4e9], [0.25, 0.3], images=1)
    constant = hd.mesh.concatenate([hd.mesh.line([-1, -0.4], [1, -0.3], 5), hd.mesh.line([0.3, 0.2], [0.5, 1.0], 3)])
    return medium, constant


@pytest.mark.parametrize("kind", ["segments", "quadratic", "rectangles", "layered", "layered quadratic"])
def test_block_is_the_matrix_restricted(kind):
    """traction_block (row requests, column requests, any order) and the dense assembly
    (parallel over sources) give the same entries, bit for bit."""
    if kind.startswith("layered"):
        from hmatddm.layered import higher_order2d as layered_higher_order

        medium, mesh = layered_meshes()
        if kind == "layered":
            data = influence2d.influence_data(mesh, medium, 1e-3, 1.0, 0.5, 1)
        else:
            mesh = mesh.with_element_order(2)
            data = layered_higher_order.influence_data(mesh, medium, 1e-3, 1.0, 0.5, 1)
    else:
        mesh = MESHES[kind]()
        data = record(mesh, 1.0)
    d = drivers.element_unknowns(data)
    matrix = drivers.influence_matrix(data)
    rng = np.random.default_rng(4)
    for rows, cols in ((rng.permutation(mesh.n_elements)[:3], rng.permutation(mesh.n_elements)[:5]),
                       (np.array([2]), np.arange(mesh.n_elements)), (np.arange(mesh.n_elements), np.array([1]))):
        block = np.empty((d * len(rows), d * len(cols)))
        drivers.traction_block(data, rows, cols, block)
        unknown_rows = (d * rows[:, None] + np.arange(d)).ravel()
        unknown_cols = (d * cols[:, None] + np.arange(d)).ravel()
        np.testing.assert_array_equal(block, matrix[np.ix_(unknown_rows, unknown_cols)])


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_stress_is_the_sum_of_pair_stresses(kind):
    mesh = MESHES[kind]()
    data = record(mesh, near_fraction=0.0)
    d = drivers.element_unknowns(data)
    rng = np.random.default_rng(5)
    points = rng.uniform(-2.5, 2.5, (6, mesh.dim))
    dd = rng.standard_normal((mesh.n_elements, d))
    expected = np.zeros((len(points), mesh.dim, mesh.dim))
    for m, point in enumerate(points):
        for j in range(mesh.n_elements):
            if isinstance(data, rectangle3d.Rectangles):
                pair = np.empty((3, 3, 3))
                rectangle3d.stress_pair(point, data.centers[j], data.frames[j], data.half_a[j], data.half_b[j],
                                        data.shear_modulus, data.poisson_ratio, data.singular_shift, pair,
                                        np.empty((3, 3, 3)))
            elif isinstance(data, line2d.Segments):
                pair = np.empty((2, 2, 2))
                line2d.stress_pair(point, data.centers[j], data.frames[j], data.half_length[j], data.shear_modulus,
                                   data.poisson_ratio, data.singular_shift, pair, np.empty((2, 2, 2)))
            else:
                n = len(data.nodes)
                nodal = np.empty((n, 2, 2, 2))
                line2d_higher_order.stress_nodes(point, data.centers[j], data.frames[j], data.half_length[j],
                                                 data.coefficients, data.shear_modulus, data.poisson_ratio,
                                                 data.singular_shift, nodal, np.empty((n, 2, 2, 2)))
                pair = nodal.reshape(2 * n, 2, 2)
            expected[m] += np.einsum("qik,q->ik", pair, dd[j])
    np.testing.assert_allclose(drivers.stress_sum(data, points, dd), expected, rtol=1e-12,
                               atol=1e-12 * np.abs(expected).max())


def test_equal_layers_give_the_homogeneous_kernels():
    """A layered medium whose layers are equal has no complementary field: its kind of data
    gives the homogeneous matrix and stress (a check across two kinds)."""
    medium = LayeredMedium([0.0], [10e9, 10e9], [0.25, 0.25], images=2)
    _, mesh = layered_meshes()
    layered = influence2d.influence_data(mesh, medium, 1e-3, 0.0, 0.5, 2)
    homogeneous = record(mesh)
    np.testing.assert_allclose(drivers.influence_matrix(layered), drivers.influence_matrix(homogeneous),
                               rtol=0, atol=1e-9 * 10e9)
    points = np.array([[0.1, 0.7], [-0.5, -1.0], [1.5, 0.05]])
    dd = np.random.default_rng(6).standard_normal((mesh.n_elements, 2))
    np.testing.assert_allclose(drivers.stress_sum(layered, points, dd, np.array([0, 1, 0])),
                               drivers.stress_sum(homogeneous, points, dd), rtol=0, atol=1e-9 * 10e9)


@pytest.mark.parametrize("gap", [0.0, 0.2])
def test_singular_pairs_and_edge_distance_of_a_t_junction(gap):
    """The branch's end element reaches (or nearly reaches, ``gap`` below) the centre of
    the main crack's element 2: that pair, only, is singular, at the gap."""
    main = hd.mesh.line([-2.5, 0.0], [2.5, 0.0], 5)  # centres at -2 .. 2
    branch = hd.mesh.line([0.0, 2.0 + gap], [0.0, gap], 2)  # element 6 ends at (0, gap)
    mesh = hd.mesh.concatenate([main, branch])
    data = record(mesh, shift=0.0)
    rows, cols = np.meshgrid(np.arange(mesh.n_elements), np.arange(mesh.n_elements), indexing="ij")
    rows, cols = rows.ravel(), cols.ravel()
    bad = np.zeros(len(rows), dtype=np.bool_)
    drivers.singular_pairs(data, rows, cols, bad)
    assert [(int(i), int(j)) for i, j in zip(rows[bad], cols[bad])] == [(2, 6)]
    assert drivers.edge_distance(data, 2, 6) == pytest.approx(gap, abs=1e-12)
    assert drivers.edge_distance(data, 0, 1) == pytest.approx(0.5)


def test_an_unregistered_record_is_refused():
    class Unknown(NamedTuple):
        centers: np.ndarray

    with pytest.raises(TypeError, match="no kernel kind is registered for Unknown"):
        drivers.element_unknowns(Unknown(np.zeros((1, 2))))
