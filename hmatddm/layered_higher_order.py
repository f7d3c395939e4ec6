"""Linear and quadratic 2D DD elements in a layered medium (ref. Sec. 3.5, Table 3.2).

The influence of a node's shape function is the sum of

* the *original* part: the closed-form kernel of the element in the whole plane with
  the material of the source's layer (:mod:`hmatddm.kernels.line2d_higher_order`), at
  any receiver, and
* the *complementary* (image) part: the point-DD image kernel of the general image
  method (:func:`hmatddm.layered.images2d.image_element_stress`, ref. Secs 3.2-3.3)
  integrated along the element against the node's shape function by Gauss-Legendre
  quadrature: ``gauss_points`` per sub-segment, with up to ``max_subdivisions``
  sub-segments where an image lies close to the receiver
  (:func:`hmatddm.layered.images2d.subdivisions`); ``max_subdivisions = 1`` is the
  reference's plain rule (ref. Table 3.2: 1-3 Gauss points).

Block-generator data (same contract as :mod:`hmatddm.kernels.line2d_higher_order`,
``2 n`` unknowns per element, node-major): the tuple of
:func:`hmatddm.layered.influence2d.influence_data` followed by the shape functions'
``coefficients`` (n, 3) and ``nodes`` (n,):
``(centers, frames, half_length, half_length, params, self_max, layer, settings,
interfaces, shear_modulus, poisson_ratio, coefficients, nodes)`` with ``settings =
[n_images, gauss_points, max_subdivisions]``.
"""
import numpy as np
from numba import njit, prange

from .kernels.line2d_higher_order import (edge_distance, near_distance, node_point, set_node_rows,
                                          store_block, stress_nodes, traction_nodes)
from .layered.images2d import composite_rule, image_element_stress, subdivisions


@njit(cache=True)
def _shape_values(coefficients, xi):
    """(len(xi), n) values of the shape functions at ``xi``."""
    out = np.empty((xi.shape[0], coefficients.shape[0]))
    for g in range(xi.shape[0]):
        for k in range(coefficients.shape[0]):
            out[g, k] = coefficients[k, 0] + xi[g] * (coefficients[k, 1] + xi[g] * coefficients[k, 2])
    return out


@njit(cache=True)
def image_nodes(point, receiver_layer, center, frame, a, source_layer, coefficients, settings, interfaces,
                shear_modulus, poisson_ratio, out):
    """``out[k, b, i, j]``: complementary stress at ``point`` (in ``receiver_layer``) for
    a unit global DD ``b`` at node ``k`` of the segment (in ``source_layer``)."""
    p0 = np.empty(2)
    p1 = np.empty(2)
    for c in range(2):
        p0[c] = center[c] - a * frame[0, c]
        p1[c] = center[c] + a * frame[0, c]
    n_sub = subdivisions(point[0], point[1], receiver_layer, p0, p1, source_layer, interfaces, int(settings[2]))
    xi, weight = composite_rule(int(settings[1]), n_sub)
    image_element_stress(point[0], point[1], receiver_layer, p0, p1, source_layer, interfaces, shear_modulus,
                         poisson_ratio, int(settings[0]), xi, weight, _shape_values(coefficients, xi), out)


@njit(cache=True)
def traction_block(data, rows, cols, out):
    """Block generator: ``out[(a n + r) 2 + p, (b n + k) 2 + q]`` is the traction p at
    node r of element ``rows[a]`` for a unit global DD q at node k of ``cols[b]``
    (original + complementary parts; ``data``: see the module docstring)."""
    (centers, frames, half_length, _unused, params, self_max, layer, settings, interfaces, shear_modulus,
     poisson_ratio, coefficients, nodes) = data
    shift = params[2]
    alpha = params[3]
    near_fraction = params[4]
    n_nodes = nodes.shape[0]
    work = np.empty((n_nodes, 2, 2, 2))
    pair = np.empty((n_nodes, 2, 2))
    image = np.empty((n_nodes, 2, 2, 2))
    block = np.empty((2 * n_nodes, 2 * n_nodes))
    point = np.empty(2)
    for ia in range(rows.shape[0]):
        i = rows[ia]
        normal = frames[i, 1]
        lr = layer[i]
        for jb in range(cols.shape[0]):
            j = cols[jb]
            ls = layer[j]
            near = 0.0
            if i != j:
                near = near_distance(near_fraction, half_length[i], half_length[j], nodes)
            for r in range(n_nodes):
                node_point(centers[i], frames[i], half_length[i], nodes[r], point)
                traction_nodes(point, normal, centers[j], frames[j], half_length[j], coefficients, shear_modulus[ls],
                               poisson_ratio[ls], shift, pair, work, near)
                if interfaces.shape[0] > 0:
                    image_nodes(point, lr, centers[j], frames[j], half_length[j], ls, coefficients, settings,
                                interfaces, shear_modulus, poisson_ratio, image)
                    for k in range(n_nodes):
                        for p in range(2):
                            for q in range(2):
                                pair[k, p, q] += image[k, q, p, 0] * normal[0] + image[k, q, p, 1] * normal[1]
                set_node_rows(block, pair, r)
            store_block(block, out, ia, jb, i, j, alpha, self_max)


@njit(cache=True, parallel=True)
def traction_matrix(data, out):
    """Dense assembly, parallel over row elements."""
    n = data[0].shape[0]
    dof = 2 * data[-1].shape[0]
    cols = np.arange(n)
    for i in prange(n):
        rows = np.array([i])
        traction_block(data, rows, cols, out[dof * i:dof * i + dof, :])


@njit(cache=True)
def singular_pairs(data, rows, cols, out):
    """``out[k]`` = True when the block of receiver ``rows[k]`` and source ``cols[k]`` is not finite."""
    dof = 2 * data[-1].shape[0]
    block = np.empty((dof, dof))
    for k in range(rows.shape[0]):
        traction_block(data, rows[k:k + 1], cols[k:k + 1], block)
        out[k] = not np.all(np.isfinite(block))


@njit(cache=True, parallel=True)
def stress_at_points(points, point_layer, data, dd, out):
    """Stress ``out`` (M, 2, 2) at ``points`` (in layers ``point_layer``; void layers give
    zero) of the nodal DDs ``dd`` (N, n, 2). ``params[4]`` (near_fraction): points within
    that fraction of a half length of an element end count as on it."""
    (centers, frames, half_length, _unused, params, _self_max, layer, settings, interfaces, shear_modulus,
     poisson_ratio, coefficients, nodes) = data
    shift = params[2]
    near_fraction = params[4]
    n_nodes = nodes.shape[0]
    for m in prange(points.shape[0]):
        work = np.empty((n_nodes, 2, 2, 2))
        pair = np.empty((n_nodes, 2, 2, 2))
        image = np.empty((n_nodes, 2, 2, 2))
        acc = np.zeros((2, 2))
        lr = point_layer[m]
        if shear_modulus[lr] > 0.0:
            for j in range(centers.shape[0]):
                ls = layer[j]
                stress_nodes(points[m], centers[j], frames[j], half_length[j], coefficients, shear_modulus[ls],
                             poisson_ratio[ls], shift, pair, work, near_fraction * half_length[j])
                if interfaces.shape[0] > 0:
                    image_nodes(points[m], lr, centers[j], frames[j], half_length[j], ls, coefficients, settings,
                                interfaces, shear_modulus, poisson_ratio, image)
                    pair += image
                for k in range(n_nodes):
                    for q in range(2):
                        dq = dd[j, k, q]
                        for i in range(2):
                            for c in range(2):
                                acc[i, c] += pair[k, q, i, c] * dq
        out[m] = acc


def _constant_data(mesh, medium, singular_shift, near_fraction, n_images, gauss_points, max_subdivisions):
    """The data of :func:`hmatddm.layered.influence2d.influence_data` (no Eq. 6.11
    scaling), with the image quadrature's Gauss points and largest number of
    sub-segments replaced where given."""
    from .layered import influence2d

    data = influence2d.influence_data(mesh, medium, singular_shift, 0.0, near_fraction, n_images)
    if gauss_points is not None:
        data[7][1] = float(gauss_points)
    if max_subdivisions is not None:
        data[7][2] = float(max_subdivisions)
    return data


def influence_data(mesh, medium, singular_shift, alpha, near_fraction, n_images, gauss_points=None,
                   max_subdivisions=None):
    """The data tuple of :func:`traction_block` for a linear or quadratic 2D ``mesh`` in
    ``medium``; ``gauss_points`` (default ``medium.gauss_points``) and
    ``max_subdivisions`` (default that of :mod:`hmatddm.layered.influence2d`) set the
    image quadrature; ``alpha > 0`` fills ``self_max`` for ref. Eq. 6.11."""
    from .shape_functions import coefficients, nodes

    data = _constant_data(mesh, medium, singular_shift, near_fraction, n_images, gauss_points, max_subdivisions)
    data[4][3] = float(alpha)
    data = data + (coefficients(mesh.element_order), nodes(mesh.element_order))
    if alpha > 0.0:
        self_max = data[5]
        dof = 2 * mesh.n_nodes
        block = np.empty((dof, dof))
        for i in range(mesh.n_elements):
            index = np.array([i], dtype=np.int64)
            traction_block(data, index, index, block)
            self_max[i] = np.max(np.abs(block))
    return data


def image_count(mesh, medium, singular_shift=0.0):
    """The number of images for ``mesh``: ``medium.images``, or for ``"auto"`` the count
    :func:`hmatddm.layered.influence2d.choose_images` picks on the same segments as
    constant elements (a property of the geometry and the medium)."""
    from .layered import influence2d
    from .operators import NEAR_SINGULAR_FRACTION

    constant = mesh.with_element_order(0)
    data = influence2d.influence_data(constant, medium, singular_shift, 0.0, NEAR_SINGULAR_FRACTION, 0)
    return influence2d.choose_images(constant, medium, data)


def stress_at(mesh, medium, dd, points, singular_correction="none", near_fraction=0.0, n_images=None):
    """Stress (M, 2, 2) at ``points`` in ``medium`` from the nodal DDs of a linear or
    quadratic 2D mesh (direct sum; a point on an interface belongs to the layer above).
    ``n_images``: None = :func:`image_count` (what the operator uses)."""
    from ._validation import finite_array
    from .nodal import nodal_array

    if n_images is None:
        n_images = image_count(mesh, medium)
    points = np.ascontiguousarray(finite_array("points", points, (None, 2)))
    dd = np.ascontiguousarray(nodal_array("dd", dd, mesh))
    data = influence_data(mesh, medium, 1e-3 if singular_correction == "average" else 0.0, 0.0, near_fraction,
                          n_images)
    out = np.zeros((len(points), 2, 2))
    stress_at_points(points, medium.layer_of(points[:, 1]).astype(np.int64), data, dd, out)
    bad = np.flatnonzero(~np.all(np.isfinite(out.reshape(len(points), -1)), axis=1))
    if bad.size:
        from .errors import InputError

        raise InputError(f"points[{int(bad[0])}] lies on an element end, where the stress is singular; move it or "
                         "pass singular_correction='average'")
    return out




def dense_matrix(mesh, medium, n_images, gauss_points=None, max_subdivisions=None):
    """The dense traction matrix of a 2D mesh of any element order in ``medium`` with a
    given number of images and image quadrature (``max_subdivisions = 1``: the plain
    ``gauss_points``-point rule of ref. Table 3.2), for studies of those settings."""
    from .layered import images2d
    from .operators import NEAR_SINGULAR_FRACTION

    if mesh.element_order == 0:
        data = _constant_data(mesh, medium, 0.0, NEAR_SINGULAR_FRACTION, n_images, gauss_points, max_subdivisions)
        assemble = images2d.traction_matrix
    else:
        data = influence_data(mesh, medium, 0.0, 0.0, NEAR_SINGULAR_FRACTION, n_images, gauss_points,
                              max_subdivisions)
        assemble = traction_matrix
    n = mesh.n_elements * 2 * mesh.n_nodes
    out = np.empty((n, n))
    assemble(data, out)
    return out


__all__ = ["traction_block", "traction_matrix", "edge_distance", "singular_pairs", "stress_at_points", "influence_data",
           "image_count", "stress_at", "image_nodes", "dense_matrix"]
