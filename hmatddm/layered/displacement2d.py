"""Displacement at points of constant 2D DDs (plane strain) in a plane-layered medium
(ref. Eqs 2.43, 2.55-2.57 for the closed form; Secs 3.2-3.3, Eqs 3.22-3.23 for the
images): the counterpart of the stress of :mod:`.segments2d` (``element_stress``) for
:func:`hmatddm.displacement_at` and the ``[[monitor]]`` section in layered rock.

The displacement at ``y`` of a unit global DD ``b`` on a segment is the closed-form
whole-plane displacement of the source layer's material
(:func:`hmatddm.kernels.displacement.segment_local_displacement`, rotated) plus the
complementary displacement: the moment contraction
``M_pq = lambda (b.n) delta_pq + G (b_p n_q + b_q n_p)`` of the source derivative of the
point-force displacement of ref. Eq. 3.22,

    u1 = phi1,1 - phi2,1 - 2 delta s phi2,13,    u3 = phi1,3 + phi2,3 - 2 delta s phi2,33,

summed over the image pairs of :func:`.images2d.trace` in the receiver's layer (minus
the source material's whole-plane pair in another layer), Gauss quadrature over the
segment subdivided near its mirror images (the rule of the stress). A DD displacement is
a source derivative of a point-force displacement, so it takes potential derivatives of
order two and three only, where the logarithm and the linear terms of ref. Eq. 3.23 and
the constant displacement of ref. Eqs 3.34-3.39 have dropped out: the closed forms
``d1^a d3^b f = i^b f^(a+b)`` of :mod:`.images2d` (the coefficients of ``D^0`` do not
depend on the source height, so the height derivative never reaches a first derivative).
"""
import math

import numpy as np
from numba import njit

from ..kernels.displacement import local_to_global, segment_local_displacement
from .image_tracer import largest_trace_capacity, orders_used
from .images2d import _INV_4PI, _lame, _potential_table, inverse_power_derivatives, potential_derivatives, trace
from .segment_quadrature import composite_rule, subdivision_level, subdivisions

__all__ = ["image_segment_displacement", "element_displacement", "displacement_block"]


@njit(cache=True)
def _work(n_orders):
    """Scratch of :func:`_pair_displacement_gradient`: ``g^(k)`` (complex), ``beta``
    (zeros: entries of order < 2 are never written and meet only zero coefficients),
    the potential tables and their height derivatives."""
    return (np.empty(n_orders + 6, dtype=np.complex128), np.zeros((5, n_orders + 5)), np.zeros((2, 5, 5)),
            np.zeros((2, 5, 5)))


@njit(cache=True, inline="always")
def _u(table, da, db, scale, s, delta, out):
    """``out += scale * (u1, u3)`` (ref. Eq. 3.22) from the potential derivatives
    ``table[j, a + da, b + db]``; ``s``: height above the pair's point."""
    t1 = table[0]
    t2 = table[1]
    out[0] += scale * (t1[1 + da, db] - t2[1 + da, db] - 2.0 * delta * s * t2[1 + da, 1 + db])
    out[1] += scale * (t1[da, 1 + db] + t2[da, 1 + db] - 2.0 * delta * s * t2[da, 2 + db])


@njit(cache=True)
def _pair_displacement_gradient(r1, r3, eps, coef, dcoef, delta, out, work):
    """``out[f, q, i] +=`` derivative along the source coordinate ``q`` (0: x, 1: height)
    of the displacement ``u_i`` at the receiver ``(r1, r3)`` (from the pair's point) of a
    unit force along ``f``; ``delta``: the receiver layer's; ``eps = dz/dt``."""
    gk, beta, table, dtable = work
    used = orders_used(coef, dcoef)
    kmax = 2 + used  # a + b <= 3 in the tables, plus D^(used - 1)
    inverse_power_derivatives(complex(r1, r3), kmax, gk)
    grad = np.zeros(2)
    for f in range(2):
        potential_derivatives(gk, kmax, 3, f, beta)
        _potential_table(coef[f], dcoef[f], beta, used, table, dtable, 3)
        # d/dx1 of the source = -d/dr1
        grad[:] = 0.0
        _u(table, 1, 0, -1.0, r3, delta, grad)
        out[f, 0, 0] += grad[0]
        out[f, 0, 1] += grad[1]
        # d/dt: the coefficients, r3 = y3 - z(t) in the kernel and in s
        grad[:] = 0.0
        _u(dtable, 0, 0, 1.0, r3, delta, grad)
        _u(table, 0, 1, -eps, r3, delta, grad)
        grad[0] += 2.0 * delta * eps * table[1, 1, 1]
        grad[1] += 2.0 * delta * eps * table[1, 0, 2]
        out[f, 1, 0] += grad[0]
        out[f, 1, 1] += grad[1]


@njit(cache=True)
def _buffers(shear_modulus, n_images):
    """Room for the image pairs of one source height in any solid layer: ``(layer, z, eps,
    coef, dcoef)`` (the arguments of :func:`.images2d.trace`)."""
    cap, n_orders = largest_trace_capacity(shear_modulus, n_images)
    return (np.empty(cap, dtype=np.int64), np.empty(cap), np.empty(cap), np.zeros((cap, 2, 2, n_orders)),
            np.zeros((cap, 2, 2, n_orders)))


@njit(cache=True)
def image_segment_displacement(y1, y3, receiver_layer, p0, p1, source_layer, interfaces, shear_modulus,
                               poisson_ratio, n_images, xi, weights, pairs, n_pairs, traced_height, out):
    """Complementary displacement ``out[b, i]`` (2, 2) at ``(y1, y3)`` of a unit global DD
    ``b`` on the straight element ``p0 -> p1`` (normal: the tangent turned +90 degrees),
    Gauss points ``xi`` in [-1, 1] with ``weights``. The pairs are traced into ``pairs``
    (:func:`_buffers`) once per distinct height, in order of height; ``pairs`` may hold the
    ``n_pairs`` pairs of ``traced_height`` already (NaN: none), so a horizontal element
    traced once serves all its receivers."""
    n_points = xi.shape[0]
    layer, z, eps, coef, dcoef = pairs
    tx = p1[0] - p0[0]
    ty = p1[1] - p0[1]
    heights = np.empty(n_points)
    for g in range(n_points):
        heights[g] = 0.5 * (p0[1] + p1[1]) + 0.5 * xi[g] * ty
    order = np.argsort(heights, kind="mergesort")
    length = math.sqrt(tx * tx + ty * ty)
    normal = np.array([-ty / length, tx / length])
    jac = 0.5 * length
    g_s = shear_modulus[source_layer]
    nu_s = poisson_ratio[source_layer]
    lame_s = _lame(g_s, nu_s)
    delta_s = 1.0 / (3.0 - 4.0 * nu_s)
    delta_r = 1.0 / (3.0 - 4.0 * poisson_ratio[receiver_layer])
    k_2d = _INV_4PI / (g_s * (1.0 + delta_s))
    kelvin = np.zeros((2, 2, 1))  # minus the whole-plane pair of the source's material
    kelvin[0, 0, 0] = -k_2d
    kelvin[0, 1, 0] = k_2d
    kelvin[1, 0, 0] = -k_2d
    kelvin[1, 1, 0] = -k_2d
    zero = np.zeros((2, 2, 1))
    work = _work(coef.shape[-1])
    work1 = _work(1)
    gradient = np.zeros((2, 2, 2))
    out[:] = 0.0
    for g in order:
        t = heights[g]
        if t != traced_height:
            traced_height = t
            n_pairs = trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer, z, eps, coef,
                            dcoef)
        x1 = 0.5 * (p0[0] + p1[0]) + 0.5 * xi[g] * tx
        gradient[:] = 0.0
        for k in range(n_pairs):
            if layer[k] == receiver_layer:
                _pair_displacement_gradient(y1 - x1, y3 - z[k], eps[k], coef[k], dcoef[k], delta_r, gradient, work)
        if receiver_layer != source_layer:
            _pair_displacement_gradient(y1 - x1, y3 - t, 1.0, kelvin, zero, delta_s, gradient, work1)
        weight = weights[g] * jac
        for b in range(2):
            for i in range(2):
                acc = 0.0
                for p in range(2):
                    for q in range(2):
                        m = shear_modulus[source_layer] * ((1.0 if p == b else 0.0) * normal[q]
                                                           + (1.0 if q == b else 0.0) * normal[p])
                        if p == q:
                            m += lame_s * normal[b]
                        acc += m * gradient[p, q, i]
                out[b, i] += weight * acc


@njit(cache=True)
def element_displacement(data, point, point_layer, j, local, image, center_pairs, n_center, work_pairs, out):
    """``out[q, i]``: displacement ``u_i`` at ``point`` (in the solid ``point_layer``) of a
    unit global DD ``q`` of segment ``j`` of the :class:`.segments2d.LayeredSegments`
    ``data``: closed form of the source layer's material plus images. ``center_pairs``:
    the ``n_center`` pairs traced at the segment's centre height (used for a horizontal
    segment); ``work_pairs``: room for other heights. NaN at its ends."""
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_length[j]
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    segment_local_displacement(frame[0, 0] * dx + frame[0, 1] * dy, frame[1, 0] * dx + frame[1, 1] * dy, a,
                               data.poisson_ratio[ls], local)
    local_to_global(frame, local, out)
    if data.interfaces.shape[0] > 0:
        p0 = center - a * frame[0]
        p1 = center + a * frame[0]
        level = subdivision_level(subdivisions(point[0], point[1], point_layer, p0, p1, ls, data.interfaces,
                                               data.max_subdivisions))
        xi, wt = composite_rule(data.gauss_points, 2 ** level)
        if frame[0, 1] == 0.0:  # horizontal: every point at the centre's height, traced already
            image_segment_displacement(point[0], point[1], point_layer, p0, p1, ls, data.interfaces,
                                       data.shear_modulus, data.poisson_ratio, data.n_images, xi, wt, center_pairs,
                                       n_center, center[1], image)
        else:
            image_segment_displacement(point[0], point[1], point_layer, p0, p1, ls, data.interfaces,
                                       data.shear_modulus, data.poisson_ratio, data.n_images, xi, wt, work_pairs, 0,
                                       np.nan, image)
        for q in range(2):
            for i in range(2):
                out[q, i] += image[q, i]


@njit(cache=True, nogil=True)
def displacement_block(data, points, point_layer, dd, out):
    """Global displacement ``out`` (M, 2) at ``points`` (M, 2) in the solid layers
    ``point_layer`` (M,) induced by the global DDs ``dd`` (N, 2) of every segment (each
    point's sum in element order; elements outside, so a horizontal segment's pairs are
    traced once for all the points)."""
    local = np.empty((2, 2))
    image = np.empty((2, 2))
    pair = np.empty((2, 2))
    center_pairs = _buffers(data.shear_modulus, data.n_images)
    work_pairs = _buffers(data.shear_modulus, data.n_images)
    layer, z, eps, coef, dcoef = center_pairs
    for m in range(points.shape[0]):
        out[m, 0] = 0.0
        out[m, 1] = 0.0
    for j in range(data.centers.shape[0]):
        n_center = 0
        if data.interfaces.shape[0] > 0:
            n_center = trace(data.centers[j, 1], data.layer[j], data.interfaces, data.shear_modulus,
                             data.poisson_ratio, data.n_images, layer, z, eps, coef, dcoef)
        for m in range(points.shape[0]):
            element_displacement(data, points[m], point_layer[m], j, local, image, center_pairs, n_center,
                                 work_pairs, pair)
            for i in range(2):
                out[m, i] += pair[0, i] * dd[j, 0] + pair[1, i] * dd[j, 1]
