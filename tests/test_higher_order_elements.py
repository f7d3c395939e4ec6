"""Linear and quadratic 2D DD elements (ref. Sec. 3.5, App. B; Crawford & Curran 1982):
the closed-form kernel against an independent quadrature, the Griffith crack, both
backends, the induced stress and bad input."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm import shape_functions
from hmatddm.analytical import griffith_opening
from hmatddm.kernels import line2d, line2d_higher_order
from hmatddm.nodal import opening_at

MATERIAL = hd.Elastic(shear_modulus=1.0, poisson_ratio=0.25)


def point_kernel(x, y, g, nu):
    """Local stress (2, 2, 2) at (x, y) of a unit DD concentrated at the origin, taken
    from the constant element of :mod:`hmatddm.kernels.line2d` shrunk to a point
    (stress / length, Richardson-extrapolated in the length)."""
    delta = 1e-2 * np.hypot(x, y)
    coarse, fine = np.empty((2, 2, 2)), np.empty((2, 2, 2))
    line2d.local_stress(x, y, delta, g, nu, coarse)
    line2d.local_stress(x, y, 0.5 * delta, g, nu, fine)
    return (4.0 * fine / delta - coarse / (2.0 * delta)) / 3.0


def gauss_element(x, y, a, order, g, nu, points=40):
    """(n, 2, 2, 2): the point kernel times each shape function, integrated over the
    segment |s| <= a by Gauss-Legendre quadrature."""
    xi, weight = np.polynomial.legendre.leggauss(points)
    shape = shape_functions.values(order, xi)
    out = np.zeros((order + 1, 2, 2, 2))
    for k in range(points):
        out += a * weight[k] * shape[k][:, None, None, None] * point_kernel(x - a * xi[k], y, g, nu)
    return out


@pytest.mark.parametrize("order", [1, 2])
def test_element_field_matches_quadrature_of_the_point_kernel(order):
    a, g, nu = 0.7, 2.0, 0.3
    coefficients = shape_functions.coefficients(order)
    # near the element (closed form) and far from it (the kernel's own Gauss rule)
    for x, y in [(0.2, 0.45), (1.05, 0.0), (-1.4, 0.3), (2.1, -0.35), (3.6, 0.2), (3.4, 0.9), (21.0, 7.0),
                 (-280.0, 35.0)]:
        ours = np.empty((order + 1, 2, 2, 2))
        line2d_higher_order.local_stress_nodes(x, y, a, coefficients, g, nu, ours)
        reference = gauss_element(x, y, a, order, g, nu)
        assert np.max(np.abs(ours - reference)) <= 1e-8 * np.max(np.abs(reference)), (x, y)


@pytest.mark.parametrize("order", [1, 2])
def test_shape_functions_sum_to_the_constant_element(order):
    """Partition of unity: unit DD at every node is a constant DD over the element,
    including on the element itself (y = 0) where the collocation happens."""
    a, g, nu = 1.3, 1.0, 0.2
    coefficients = shape_functions.coefficients(order)
    for x, y in [(0.3, 0.0), (-0.9, 0.0), (2.0, 0.0), (0.4, 0.01), (-3.0, 2.0), (40.0, -3.0)]:
        ours = np.empty((order + 1, 2, 2, 2))
        line2d_higher_order.local_stress_nodes(x, y, a, coefficients, g, nu, ours)
        constant = np.empty((2, 2, 2))
        line2d.local_stress(x, y, a, g, nu, constant)
        assert np.allclose(ours.sum(axis=0), constant, rtol=0.0, atol=1e-13 * np.abs(constant).max())


def test_shape_functions_are_one_at_their_node_and_zero_at_the_others():
    for order in (0, 1, 2):
        assert np.allclose(shape_functions.values(order, shape_functions.nodes(order)), np.eye(order + 1),
                           atol=1e-15)
    assert np.allclose(shape_functions.nodes(1), [-2 ** -0.5, 2 ** -0.5])
    assert np.allclose(shape_functions.nodes(2), [-3 ** 0.5 / 2, 0.0, 3 ** 0.5 / 2])


def griffith_error(order, unknown_nodes, inner=0.5):
    """Largest relative opening error at the nodes with |x| < inner * a (away from the
    tips) of a pressurised crack of half length a = 1 with ``unknown_nodes`` nodes."""
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], unknown_nodes // (order + 1), element_order=order)
    dd = hd.solve(hd.ElasticityOperator(mesh, MATERIAL), -1e-3 * mesh.normals)
    x = mesh.collocation_points[:, 0]
    exact = griffith_opening(x, 1.0, 1e-3, MATERIAL)
    error = np.abs(hd.opening(mesh, dd).reshape(-1) - exact) / exact
    return float(np.max(error[np.abs(x) < inner]))


@pytest.mark.parametrize("unknown_nodes", [48, 96])
def test_griffith_opening_is_more_accurate_with_higher_order_elements(unknown_nodes):
    """Same number of unknowns (2 x nodes), error at |x| < a/2. Measured: constant 1.4e-2
    and 6.9e-3, linear 5.2e-3 and 3.1e-3 (2.6x, 2.2x), quadratic 1.7e-3 and 8.4e-4 (8.0x,
    8.2x). All converge like h: the crack tips' square root, which no polynomial
    element holds, sets the error everywhere; linear elements gain less there."""
    constant = griffith_error(0, unknown_nodes)
    linear = griffith_error(1, unknown_nodes)
    quadratic = griffith_error(2, unknown_nodes)
    assert constant / quadratic >= 7.5
    assert constant / linear >= 2.0
    assert quadratic < 2e-3 * 48 / unknown_nodes


@pytest.mark.parametrize("order", [1, 2])
def test_hmatrix_equals_dense(order):
    mesh = hd.mesh.concatenate([hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 90, element_order=order, fracture_id=0),
                                hd.mesh.line([-1.5, 0.6], [0.5, 2.6], 90, element_order=order, fracture_id=1)])
    dense = hd.ElasticityOperator(mesh, MATERIAL)
    compressed = hd.ElasticityOperator(mesh, MATERIAL, backend="hmatrix", eps=1e-6, leaf_size=16)
    assert dense.dof == compressed.dof == 2 * (order + 1)
    assert compressed.stats["n_admissible"] > 0
    a, b = dense.to_dense(), compressed.to_dense()
    assert np.linalg.norm(a - b) <= 1e-6 * np.linalg.norm(a)
    traction = -1e-3 * mesh.normals
    dd_dense = hd.solve(dense, traction)
    dd_compressed = hd.solve(compressed, traction, rtol=1e-12)
    assert dd_dense.shape == (mesh.n_elements, order + 1, 2)
    assert np.max(np.abs(dd_compressed - dd_dense)) <= 1e-5 * np.max(np.abs(dd_dense))


@pytest.mark.parametrize("order", [1, 2])
def test_stress_at_collocation_points_gives_the_operator_traction(order):
    mesh = hd.mesh.concatenate([hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 6, element_order=order, fracture_id=0),
                                hd.mesh.line([-1.5, 0.5], [0.5, 2.5], 5, element_order=order, fracture_id=1)])
    operator = hd.ElasticityOperator(mesh, MATERIAL)
    dd = np.random.default_rng(3).normal(size=(mesh.n_elements, order + 1, 2))
    stress = hd.stress_at(mesh, MATERIAL, dd, mesh.collocation_points)
    normals = np.repeat(mesh.normals, order + 1, axis=0)
    traction = np.einsum("mij,mj->mi", stress, normals).reshape(-1)
    expected = operator @ dd.reshape(-1)
    assert np.max(np.abs(traction - expected)) <= 1e-12 * np.max(np.abs(expected))
    mean = hd.mean_stress_at(mesh, MATERIAL, dd, mesh.collocation_points)
    assert np.allclose(mean, 1.25 * (stress[:, 0, 0] + stress[:, 1, 1]) / 3.0, rtol=1e-14, atol=0.0)


def test_unknowns_are_element_major_then_node_then_component():
    mesh = hd.mesh.line([0.0, 0.0], [3.0, 1.0], 3, element_order=2)
    matrix = hd.ElasticityOperator(mesh, MATERIAL).to_dense()
    element, node, component = 1, 2, 1  # a unit DD there
    column = matrix[:, (element * 3 + node) * 2 + component]
    dd = np.zeros((3, 3, 2))
    dd[element, node, component] = 1.0
    stress = hd.stress_at(mesh, MATERIAL, dd, mesh.collocation_points)
    traction = np.einsum("mij,mj->mi", stress, np.repeat(mesh.normals, 3, axis=0))
    assert np.allclose(column.reshape(9, 2), traction, rtol=0.0, atol=1e-12 * np.abs(column).max())


def test_opening_along_elements_interpolates_the_nodes():
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 4, element_order=1)
    dd = np.random.default_rng(1).normal(size=(4, 2, 2))
    nodal = hd.opening(mesh, dd)
    assert nodal.shape == (4, 2)
    assert np.allclose(opening_at(mesh, dd, shape_functions.nodes(1)), nodal)
    assert np.allclose(opening_at(mesh, dd, [0.0])[:, 0], nodal.mean(axis=1))
    assert mesh.points_at([-1.0, 1.0]).shape == (4, 2, 2)


def test_constant_order_keeps_todays_kernel():
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 8)
    assert mesh.element_order == 0 and hd.kernels.kernel_module(mesh) is line2d
    assert len(hd.kernels.element_data(mesh, MATERIAL)) == 6
    assert np.array_equal(mesh.collocation_points, mesh.centers)


def test_bad_element_order_is_refused_by_name():
    with pytest.raises(hd.InputError, match="element_order must be one of"):
        hd.mesh.line([0.0, 0.0], [1.0, 0.0], 4, element_order=3)
    with pytest.raises(hd.InputError, match="element_order must be one of"):
        hd.mesh.line([0.0, 0.0], [1.0, 0.0], 4).with_element_order(1.5)
    penny = hd.mesh.penny([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], radius=1.0, h=0.5)
    with pytest.raises(hd.InputError, match="element_order must be 0 for a Mesh3D"):
        penny.with_element_order(1)
    with pytest.raises(hd.InputError, match="same element_order"):
        hd.mesh.concatenate([hd.mesh.line([0.0, 0.0], [1.0, 0.0], 2, element_order=1),
                             hd.mesh.line([0.0, 1.0], [1.0, 1.0], 2)])
    mesh = hd.mesh.line([0.0, 0.0], [1.0, 0.0], 4, element_order=2)
    operator = hd.ElasticityOperator(mesh, MATERIAL)
    with pytest.raises(hd.InputError, match=r"traction must have shape \(4, 3, 2\)"):
        hd.solve(operator, np.ones(10))
    with pytest.raises(hd.InputError, match="method must be 'auto' or 'direct'"):
        hd.stress_at(mesh, MATERIAL, np.zeros((4, 3, 2)), [[0.5, 1.0]], method="tree")
    with pytest.raises(hd.InputError, match="lies on an element end"):
        hd.stress_at(mesh, MATERIAL, np.ones((4, 3, 2)), [[0.25, 0.0]])
