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
  (:func:`hmatddm.layered.segment_quadrature.subdivisions`); ``max_subdivisions = 1`` is the
  reference's plain rule (ref. Table 3.2: 1-3 Gauss points).

Kernel data: :class:`LayeredNodalSegments` (``2 n`` unknowns per element, node-major),
served by the drivers of :mod:`hmatddm.kernels.drivers`.
"""
import numpy as np
from numba import njit

from ..kernels.drivers import (KernelKind, finite_stress_sum, influence_matrix, kernel_record, no_source_state,
                               register_kind, with_self_max)
from ..kernels.line2d import SEGMENT_FIELDS
from ..kernels.line2d_higher_order import (SHAPE_FIELDS, edge_distance, near_distance, node_point,
                                           set_node_rows, stress_nodes, traction_nodes)
from .images2d import image_element_stress, zero_in_void
from .segment_quadrature import composite_rule, subdivisions
from .segments2d import LAYERED_FIELDS
from ..options import AVERAGE_SHIFT, NEAR_SINGULAR_FRACTION


@njit(cache=True)
def _shape_values(coefficients, xi):
    """(len(xi), n) values of the shape functions at ``xi``."""
    out = np.empty((xi.shape[0], coefficients.shape[0]))
    for g in range(xi.shape[0]):
        for k in range(coefficients.shape[0]):
            out[g, k] = coefficients[k, 0] + xi[g] * (coefficients[k, 1] + xi[g] * coefficients[k, 2])
    return out


@njit(cache=True, inline="always")  # one njit level less above the image quadrature (issue 18)
def image_nodes(point, receiver_layer, center, frame, a, source_layer, coefficients, n_images, gauss_points,
                max_subdivisions, interfaces, shear_modulus, poisson_ratio, out):
    """``out[k, b, i, j]``: complementary stress at ``point`` (in ``receiver_layer``) for
    a unit global DD ``b`` at node ``k`` of the segment (in ``source_layer``), with
    ``n_images`` images and ``gauss_points`` per sub-segment (at most ``max_subdivisions``)."""
    p0 = np.empty(2)
    p1 = np.empty(2)
    for c in range(2):
        p0[c] = center[c] - a * frame[0, c]
        p1[c] = center[c] + a * frame[0, c]
    n_sub = subdivisions(point[0], point[1], receiver_layer, p0, p1, source_layer, interfaces, max_subdivisions)
    xi, weight = composite_rule(gauss_points, n_sub)
    image_element_stress(point[0], point[1], receiver_layer, p0, p1, source_layer, interfaces, shear_modulus,
                         poisson_ratio, n_images, xi, weight, _shape_values(coefficients, xi), out)


LayeredNodalSegments = kernel_record(
    "LayeredNodalSegments", __name__,
    "Kernel data of linear and quadratic 2D elements in a layered medium (the record :mod:`hmatddm.kernels.drivers` "
    "take): :class:`hmatddm.layered.segments2d.LayeredSegments` plus the shape functions.",
    SEGMENT_FIELDS + LAYERED_FIELDS, SHAPE_FIELDS)


@njit(cache=True)
def workspace(data):
    """Scratch: local stress per node (n, 2, 2, 2), traction per node (n, 2, 2), image
    stress per node (n, 2, 2, 2) and a point."""
    n_nodes = data.nodes.shape[0]
    return np.empty((n_nodes, 2, 2, 2)), np.empty((n_nodes, 2, 2)), np.empty((n_nodes, 2, 2, 2)), np.empty(2)


@njit(cache=True, inline="always")
def element_traction(data, i, j, state, work, block):
    """``block[2 r + p, 2 k + q]``: traction p at node r of element ``i`` for a unit
    global DD q at node k of element ``j`` (original + complementary parts)."""
    local, pair, image, point = work
    nodes = data.nodes
    half_length = data.half_length
    g = data.shear_modulus
    nu = data.poisson_ratio
    n_nodes = nodes.shape[0]
    normal = data.frames[i, 1]
    lr = data.layer[i]
    ls = data.layer[j]
    near = 0.0
    if i != j:
        near = near_distance(data.near_fraction, half_length[i], half_length[j], nodes)
    for r in range(n_nodes):
        node_point(data.centers[i], data.frames[i], half_length[i], nodes[r], point)
        traction_nodes(point, normal, data.centers[j], data.frames[j], half_length[j], data.coefficients, g[ls],
                       nu[ls], data.singular_shift, pair, local, near)
        if data.interfaces.shape[0] > 0:
            image_nodes(point, lr, data.centers[j], data.frames[j], half_length[j], ls, data.coefficients,
                        data.n_images, data.gauss_points, data.max_subdivisions, data.interfaces, g, nu, image)
            for k in range(n_nodes):
                for p in range(2):
                    for q in range(2):
                        pair[k, p, q] += image[k, q, p, 0] * normal[0] + image[k, q, p, 1] * normal[1]
        set_node_rows(block, pair, r)


@njit(cache=True, inline="always")
def element_stress(data, point, point_layer, j, work, out):
    """``out[2 k + q]`` (2n, 2, 2): stress at ``point`` (in ``point_layer``; zero in a void
    layer) for a unit global DD q at node k of element ``j``; a point within
    ``near_fraction`` half lengths of an end counts as on it."""
    local, pair, image, point_work = work
    if zero_in_void(data.shear_modulus, point_layer, out):
        return
    g = data.shear_modulus
    nu = data.poisson_ratio
    n_nodes = data.nodes.shape[0]
    nodal = out.reshape((n_nodes, 2, 2, 2))
    ls = data.layer[j]
    a = data.half_length[j]
    stress_nodes(point, data.centers[j], data.frames[j], a, data.coefficients, g[ls], nu[ls],
                 data.singular_shift, nodal, local, data.near_fraction * a)
    if data.interfaces.shape[0] > 0:
        image_nodes(point, point_layer, data.centers[j], data.frames[j], a, ls, data.coefficients, data.n_images,
                    data.gauss_points, data.max_subdivisions, data.interfaces, g, nu, image)
        nodal += image


register_kind(LayeredNodalSegments, KernelKind(workspace, no_source_state, element_traction, element_stress,
                                               edge_distance))


def _constant_data(mesh, medium, singular_shift, near_fraction, n_images, gauss_points, max_subdivisions):
    """The data of :func:`hmatddm.layered.influence2d.influence_data` (no Eq. 6.11
    scaling), with the image quadrature's Gauss points and largest number of
    sub-segments replaced where given."""
    from . import influence2d

    data = influence2d.influence_data(mesh, medium, singular_shift, 0.0, near_fraction, n_images)
    if gauss_points is not None:
        data = data._replace(gauss_points=int(gauss_points))
    if max_subdivisions is not None:
        data = data._replace(max_subdivisions=int(max_subdivisions))
    return data


def influence_data(mesh, medium, singular_shift, alpha, near_fraction, n_images, gauss_points=None,
                   max_subdivisions=None):
    """The kernel data (:class:`LayeredNodalSegments`) of a linear or quadratic 2D
    ``mesh`` in ``medium``; ``gauss_points`` (default ``medium.gauss_points``) and
    ``max_subdivisions`` (default that of :mod:`hmatddm.layered.influence2d`) set the
    image quadrature; ``alpha > 0`` fills ``self_max`` for ref. Eq. 6.11."""
    from ..mesh.shape_functions import coefficients, nodes

    constant = _constant_data(mesh, medium, singular_shift, near_fraction, n_images, gauss_points, max_subdivisions)
    return with_self_max(LayeredNodalSegments(*constant._replace(alpha=float(alpha)), coefficients(mesh.element_order),
                                              nodes(mesh.element_order)))


def image_count(mesh, medium, singular_shift=0.0):
    """The number of images for ``mesh``: ``medium.images``, or for ``"auto"`` the count
    :func:`hmatddm.layered.influence2d.choose_images` picks on the same segments as
    constant elements (a property of the geometry and the medium)."""
    from . import influence2d

    constant = mesh.with_element_order(0)
    data = influence2d.influence_data(constant, medium, singular_shift, 0.0, NEAR_SINGULAR_FRACTION, 0)
    return influence2d.choose_images(constant, medium, data)


def stress_at(mesh, medium, dd, points, singular_correction="none", near_fraction=0.0, n_images=None):
    """Stress (M, 2, 2) at ``points`` in ``medium`` from the nodal DDs of a linear or
    quadratic 2D mesh (direct sum; a point on an interface belongs to the layer above).
    ``n_images``: None = :func:`image_count` (what the operator uses)."""
    from .._validation import finite_array
    from ..mesh import nodal_array

    if n_images is None:
        n_images = image_count(mesh, medium)
    points = np.ascontiguousarray(finite_array("points", points, (None, 2)))
    dd = np.ascontiguousarray(nodal_array("dd", dd, mesh))
    data = influence_data(mesh, medium, AVERAGE_SHIFT if singular_correction == "average" else 0.0, 0.0, near_fraction,
                          n_images)
    return finite_stress_sum(data, points, dd, medium.layer_of(points[:, 1]).astype(np.int64), "element end")




def dense_matrix(mesh, medium, n_images, gauss_points=None, max_subdivisions=None):
    """The dense traction matrix of a 2D mesh of any element order in ``medium`` with a
    given number of images and image quadrature (``max_subdivisions = 1``: the plain
    ``gauss_points``-point rule of ref. Table 3.2), for studies of those settings."""

    if mesh.element_order == 0:
        data = _constant_data(mesh, medium, 0.0, NEAR_SINGULAR_FRACTION, n_images, gauss_points, max_subdivisions)
    else:
        data = influence_data(mesh, medium, 0.0, 0.0, NEAR_SINGULAR_FRACTION, n_images, gauss_points,
                              max_subdivisions)
    return influence_matrix(data)


__all__ = ["LayeredNodalSegments", "influence_data", "image_count", "stress_at", "image_nodes", "dense_matrix"]
