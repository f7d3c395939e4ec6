"""Constant 2D elements in a layered medium: the kernel record :class:`LayeredSegments` and the
per-pair functions :mod:`hmatddm.kernels.drivers` call (closed form of the source's layer,
:mod:`hmatddm.kernels.line2d`, plus the complementary image stress of
:mod:`hmatddm.layered.images2d`, ref. Secs 3.2-3.3); a source's traced image pairs are kept
for its receivers (``source_state``).
"""
import numpy as np
from numba import njit

from ..kernels import line2d
from ..kernels.drivers import KernelKind, kernel_record, register_kind
from .images2d import Workspace, _integrate, _trace_range, image_element_stress, traced_buffer, zero_in_void
from .segment_quadrature import composite_rule, subdivision_level, subdivisions


#: Sub-segment levels (2^level sub-segments) whose traced pairs a source keeps.
_CACHED_LEVELS = 4


@njit(cache=True)
def _level_rule(n_gauss, max_level):
    """Composite rules of 2^level sub-segments, levels 0..max_level, stacked:
    ``(xi, w, start)`` with level l at ``start[l]:start[l + 1]``."""
    start = np.zeros(max_level + 2, dtype=np.int64)
    for level in range(max_level + 1):
        start[level + 1] = start[level] + n_gauss * 2 ** level
    xi = np.empty(start[-1])
    w = np.empty(start[-1])
    for level in range(max_level + 1):
        x, wt = composite_rule(n_gauss, 2 ** level)
        # element by element, not by slice assignment (docs/conventions.md, §5)
        for q in range(x.shape[0]):
            xi[start[level] + q] = x[q]
            w[start[level] + q] = wt[q]
    return xi, w, start


#: The medium fields of every record of 2D segments in a layered medium (after the geometry).
LAYERED_FIELDS = (
    ("layer", np.ndarray, "(N,) int64 layer of each element"),
    ("interfaces", np.ndarray, "(L - 1,) interface heights, top down"),
    ("shear_modulus", np.ndarray, "(L,) per layer (0: void)"),
    ("poisson_ratio", np.ndarray, "(L,) per layer"),
    ("n_images", int, "reflections per interface (ref. Fig. 3.4)"),
    ("gauss_points", int, "Gauss-Legendre points per sub-segment of the image quadrature (ref. Table 3.2)"),
    ("max_subdivisions", int,
     "largest number of sub-segments (:func:`hmatddm.layered.segment_quadrature.subdivisions`)"))


LayeredSegments = kernel_record(
    "LayeredSegments", __name__,
    "Kernel data of constant 2D elements in a layered medium (the record :mod:`hmatddm.kernels.drivers` take; built "
    "by :func:`hmatddm.layered.influence2d.influence_data`).", line2d.SEGMENT_FIELDS + LAYERED_FIELDS)


@njit(cache=True)
def workspace(data):
    """Scratch: local stress (2, 2, 2), image stress (1, 2, 2, 2), gradient (2, 2, 3) and
    the one-order :func:`Workspace`."""
    return np.empty((2, 2, 2)), np.zeros((1, 2, 2, 2)), np.empty((2, 2, 3)), Workspace(1)


@njit(cache=True)
def source_state(data, j, work):
    """What the receivers of source ``j`` share: its end points, the stacked composite
    rules of the cached levels and their image pairs (traced when a receiver first needs
    a level: a lone receiver traces one)."""
    ls = data.layer[j]
    p0 = data.centers[j] - data.half_length[j] * data.frames[j, 0]
    p1 = data.centers[j] + data.half_length[j] * data.frames[j, 0]
    xi, wt, start = _level_rule(data.gauss_points, _CACHED_LEVELS - 1)
    traced = traced_buffer(ls, data.shear_modulus, data.n_images, xi.shape[0])
    is_traced = np.zeros(_CACHED_LEVELS, dtype=np.bool_)
    return p0, p1, xi, wt, start, traced, is_traced, Workspace(traced[4].shape[-1])


@njit(cache=True, inline="always")
def element_traction(data, i, j, state, work, block):
    """``block`` (2, 2): traction at the centre of element ``i`` for a unit global DD of
    constant element ``j``: closed form (source layer's material) plus images, the
    source's traced pairs reused across receivers. Sub-segments come in powers of two
    (:func:`subdivisions` rounded up)."""
    p0, p1, xi, wt, start, traced, is_traced, ws = state
    local, image, gradient, ws1 = work
    g = data.shear_modulus
    nu = data.poisson_ratio
    interfaces = data.interfaces
    half_length = data.half_length
    ls = data.layer[j]
    point = data.centers[i]
    normal = data.frames[i, 1]
    near = 0.0
    if i != j:
        near = data.near_fraction * min(half_length[i], half_length[j])
    line2d.traction_pair(point, normal, data.centers[j], data.frames[j], half_length[j], g[ls], nu[ls],
                         data.singular_shift, block, local, near)
    if interfaces.shape[0] > 0:
        lr = data.layer[i]
        level = subdivision_level(subdivisions(point[0], point[1], lr, p0, p1, ls, interfaces, data.max_subdivisions))
        image[:] = 0.0
        if level < _CACHED_LEVELS:
            a, b = start[level], start[level + 1]
            if not is_traced[level]:
                _trace_range(p0, p1, ls, interfaces, g, nu, data.n_images, xi, a, b, traced)
                is_traced[level] = True
            _integrate(point[0], point[1], lr, p0, p1, ls, g, nu, xi[a:b], wt[a:b], np.ones((b - a, 1)), traced, a,
                       image, gradient, ws, ws1)
        else:
            x, w = composite_rule(data.gauss_points, 2 ** level)
            image_element_stress(point[0], point[1], lr, p0, p1, ls, interfaces, g, nu, data.n_images, x, w,
                                 np.ones((x.shape[0], 1)), image)
        for p in range(2):
            for q in range(2):
                block[p, q] += image[0, q, p, 0] * normal[0] + image[0, q, p, 1] * normal[1]


@njit(cache=True, inline="always")
def element_stress(data, point, point_layer, j, work, out):
    """``out[q, i, k]``: stress at ``point`` (in ``point_layer``; zero in a void layer)
    for a unit global DD ``q`` of constant element ``j``, closed form plus images (the
    quadrature of :func:`element_traction`). A point within ``near_fraction`` half
    lengths of an end counts as on it."""
    local, image, gradient, ws1 = work
    if zero_in_void(data.shear_modulus, point_layer, out):
        return
    g = data.shear_modulus
    nu = data.poisson_ratio
    ls = data.layer[j]
    a = data.half_length[j]
    line2d.stress_pair(point, data.centers[j], data.frames[j], a, g[ls], nu[ls], data.singular_shift, out,
                       local, data.near_fraction * a)
    if data.interfaces.shape[0] > 0:
        p0 = data.centers[j] - a * data.frames[j, 0]
        p1 = data.centers[j] + a * data.frames[j, 0]
        level = subdivision_level(subdivisions(point[0], point[1], point_layer, p0, p1, ls, data.interfaces,
                                    data.max_subdivisions))
        xi, wt = composite_rule(data.gauss_points, 2 ** level)  # as the block generator
        image_element_stress(point[0], point[1], point_layer, p0, p1, ls, data.interfaces, g, nu,
                             data.n_images, xi, wt, np.ones((xi.shape[0], 1)), image)
        for q in range(2):
            for i in range(2):
                for k in range(2):
                    out[q, i, k] += image[0, q, i, k]


register_kind(LayeredSegments, KernelKind(workspace, source_state, element_traction, element_stress,
                                          line2d.edge_distance))
