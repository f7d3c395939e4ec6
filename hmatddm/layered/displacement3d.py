"""Displacement at points of constant rectangular DDs in a plane-layered 3D medium (ref.
Eqs 2.43, 2.55-2.57 for the closed form; Secs 3.2-3.3, Eq. 3.22 for the images): the
counterpart of the stress of :mod:`.images3d` (``element_stress``) for
:func:`hmatddm.displacement_at` and the ``[[monitor]]`` section in layered rock.

As for the stress, the displacement at a receiver ``y`` of a unit global DD ``b`` on a
rectangle is

* the closed-form whole-space displacement of the source layer's material
  (:func:`hmatddm.kernels.displacement.rectangle_local_displacement`, ref. Eq. 2.56,
  rotated to the global frame, ref. Eq. 2.57), plus
* the complementary (image) displacement: the moment-tensor contraction
  ``M_pq = lambda (b.n) delta_pq + G (b_p n_q + b_q n_p)`` (source layer's moduli) of the
  source derivative ``d/dx_q u^(p)(y; x)`` of the displacement of a unit point force
  along ``p``, ref. Eq. 3.22 applied to every image triple in the receiver's layer
  (:func:`.potentials3d._pair_displacement_gradient`, the same potential tables the stress
  differentiates once more), minus the source material's whole-space field when the
  receiver is in another layer; Gauss quadrature over the rectangle, subdivided near the
  rectangle's images (:func:`image_order`: the triples that reach the receiver's layer;
  the displacement is one order smoother than the stress, whose Gauss rules it takes).

A point on an interface below a void layer (the free surface) is in the solid layer: the
surface displacement is what a tiltmeter or a GPS station measures. A point inside a
void layer has no displacement: :func:`hmatddm.layered.displacement.point_layers` refuses it.
"""
import numpy as np
from numba import njit

from ..kernels.displacement import local_to_global, rectangle_local_displacement
from ..kernels.rectangle3d import distance_to_rectangle, rectangle_distance
from .image_tracer import largest_trace_capacity
from .image_tracer3d import trace
from .images2d import _lame
from .potentials3d import Workspace, _original, _pair_displacement_gradient, unit_moment
from .rectangle_quadrature import _sub_count, far_order, square_rule
from .segment_quadrature import subdivision_level

__all__ = ["image_order", "image_rectangle_displacement", "horizontal_image_displacement", "element_displacement",
           "displacement_block"]


@njit(cache=True, inline="always")
def _complementary_displacement_gradient(y, receiver_layer, x, n_pairs, source_layer, pair_layer, pair_z, pair_eps,
                                         pair_sigma, pair_coef, pair_dcoef, shear_modulus, poisson_ratio, gradient,
                                         work, work1, kelvin):
    """``gradient[f, q, i]``: source derivative ``q`` of the complementary displacement
    ``u_i`` at ``y`` of a unit force ``f`` at ``x`` (bookkeeping of
    :func:`.image_points3d._complementary_gradient`)."""
    gradient[:] = 0.0
    delta_r = 1.0 / (3.0 - 4.0 * poisson_ratio[receiver_layer])
    for k in range(n_pairs):
        if pair_layer[k] == receiver_layer:
            _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - pair_z[k], pair_eps[k], pair_sigma[k],
                                        pair_coef[k], pair_dcoef[k], delta_r, gradient, work)
    if receiver_layer != source_layer:
        g_s = shear_modulus[source_layer]
        delta_s = 1.0 / (3.0 - 4.0 * poisson_ratio[source_layer])
        side = 1.0 if y[2] >= x[2] else -1.0
        kelvin[:] = 0.0
        _original(kelvin[0], delta_s, g_s, side, -1.0)
        _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, side, kelvin[0], kelvin[1], delta_s,
                                    gradient, work1)


@njit(cache=True, inline="always")
def _contract_displacement(gradient, normal, shear_modulus, lame, weight, out):
    """``out[b, i] += weight * sum_pq M_pq gradient[p, q, i]`` with the moment of a unit DD
    along global ``b`` on a plane of ``normal`` (Aki & Richards, Eq. 3.20)."""
    for b in range(3):
        for i in range(3):
            acc = 0.0
            for p in range(3):
                for q in range(3):
                    acc += unit_moment(b, p, q, normal, shear_modulus, lame) * gradient[p, q, i]
            out[b, i] += weight * acc


@njit(cache=True)
def _buffers(shear_modulus, n_images):
    """Room for the triples of one source height in any solid layer: ``(layer, z, eps,
    sigma, coef, dcoef)``."""
    cap, n_orders = largest_trace_capacity(shear_modulus, n_images)
    return (np.empty(cap, dtype=np.int64), np.empty(cap), np.empty(cap), np.empty(cap),
            np.zeros((cap, 3, 3, n_orders)), np.zeros((cap, 3, 3, n_orders)))


@njit(cache=True)
def _height_cache(shear_modulus, n_images, rows):
    """Room for the triples of ``rows`` source heights of one rectangle, traced when first
    needed: ``(heights, n_pairs, layer, z, eps, sigma, coef, dcoef, used)`` (``used[0]``
    rows filled; 0 for a new rectangle)."""
    layer, z, eps, sigma, coef, dcoef = _buffers(shear_modulus, n_images)
    cap = z.shape[0]
    n_orders = coef.shape[-1]
    return (np.empty(rows), np.zeros(rows, dtype=np.int64), np.empty((rows, cap), dtype=np.int64),
            np.empty((rows, cap)), np.empty((rows, cap)), np.empty((rows, cap)),
            np.empty((rows, cap, 3, 3, n_orders)), np.empty((rows, cap, 3, 3, n_orders)),
            np.zeros(1, dtype=np.int64))


@njit(cache=True)
def image_order(y, receiver_layer, center, frame, a, b, source_layer, n_pairs, triples, gauss_points, max_sub,
                far_tol):
    """``(n_gauss, n_sub)`` of the image quadrature at ``y``: sub-squares so that each is at
    most half as large as the distance to the nearest singular point of the integrand,
    Gauss points by :func:`.rectangle_quadrature.far_order` on one square. The singular
    points are those of the triples that reach the receiver's layer (``triples``: traced
    at the centre's height; a triple of point ``z(t) = z_c + eps (t - t_c)`` is singular
    where the receiver, moved back to ``t_c + (y3 - z_c) / eps``, meets the rectangle) and,
    in another layer, the rectangle itself (the subtracted whole-space field). Sharper than
    :func:`.rectangle_quadrature.nearest_singularity`, which takes the receiver's mirror
    in every interface of both layers: with interfaces between a surface receiver and the
    source most of those mirrors are not where any triple of the receiver's layer is, and
    their subdivision cost ~100x (a sill twice as deep as an interface)."""
    layer, z, eps = triples[0], triples[1], triples[2]
    dmin = np.inf
    if receiver_layer != source_layer:
        dmin = rectangle_distance(y, center, frame, a, b)
    for k in range(n_pairs):
        if layer[k] == receiver_layer:
            height = center[2] + (y[2] - z[k]) / eps[k]
            dmin = min(dmin, distance_to_rectangle(y[0], y[1], height, center, frame, a, b))
    n_sub = 2 ** subdivision_level(_sub_count(dmin, a, b, max_sub))
    if n_sub == 1:
        return far_order(dmin / max(a, b), gauss_points, far_tol), 1
    return gauss_points, n_sub


@njit(cache=True)
def image_rectangle_displacement(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                                 poisson_ratio, n_images, n_gauss, n_sub, triples, cache, out):
    """Complementary displacement ``out[b, i]`` (3, 3) at ``y`` of a unit global DD ``b``
    on the rectangle (``n_gauss^2`` points on each of ``n_sub^2`` sub-squares). The points
    are taken in order of height; each distinct height's triples come from ``cache``
    (:func:`_height_cache` of this rectangle: traced there the first time a receiver needs
    that height, so a vertical rectangle's rows are traced once for all receivers) or,
    once the cache is full, are traced into ``triples`` (:func:`_buffers`). Tracing with
    several interfaces costs milliseconds per height (9 ms with two interfaces and 8
    images): traced per pair it dominated (9.7 ms per pair for a vertical fracture)."""
    xi, eta, wt = square_rule(n_gauss, n_sub)
    n_points = xi.shape[0]
    heights = np.empty(n_points)
    for g in range(n_points):
        heights[g] = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
    order = np.argsort(heights, kind="mergesort")
    cached_heights, cached_n, c_layer, c_z, c_eps, c_sigma, c_coef, c_dcoef, used = cache
    layer, z, eps, sigma, coef, dcoef = triples
    normal = frame[2]
    g_s = shear_modulus[source_layer]
    lame_s = _lame(g_s, poisson_ratio[source_layer])
    jac = a * b
    gradient = np.empty((3, 3, 3))
    work = Workspace(coef.shape[-1])
    work1 = Workspace(1)
    kelvin = np.zeros((2, 3, 3, 1))
    x = np.empty(3)
    out[:] = 0.0
    current = np.nan
    row = -1  # the cache row of ``current`` (-1: the triples buffer)
    n_pairs = 0
    for g in order:
        if heights[g] != current:
            current = heights[g]
            row = -1
            for r in range(used[0]):
                if cached_heights[r] == current:
                    row = r
                    break
            if row < 0 and used[0] < cached_heights.shape[0]:
                row = used[0]
                cached_heights[row] = current
                cached_n[row] = trace(current, source_layer, interfaces, shear_modulus, poisson_ratio, n_images,
                                      c_layer[row], c_z[row], c_eps[row], c_sigma[row], c_coef[row], c_dcoef[row])
                used[0] += 1
            if row < 0:
                n_pairs = trace(current, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer, z,
                                eps, sigma, coef, dcoef)
        for c in range(3):
            x[c] = center[c] + xi[g] * a * frame[0, c] + eta[g] * b * frame[1, c]
        if row >= 0:
            _complementary_displacement_gradient(y, receiver_layer, x, cached_n[row], source_layer, c_layer[row],
                                                 c_z[row], c_eps[row], c_sigma[row], c_coef[row], c_dcoef[row],
                                                 shear_modulus, poisson_ratio, gradient, work, work1, kelvin)
        else:
            _complementary_displacement_gradient(y, receiver_layer, x, n_pairs, source_layer, layer, z, eps, sigma,
                                                 coef, dcoef, shear_modulus, poisson_ratio, gradient, work, work1,
                                                 kelvin)
        _contract_displacement(gradient, normal, g_s, lame_s, wt[g] * jac, out)


@njit(cache=True)
def _triple_rule(dmin, a, b, gauss_points, max_sub, far_tol):
    """``(n_gauss, n_sub)`` for a singular point ``dmin`` away (:func:`image_order`'s rule)."""
    n_sub = 2 ** subdivision_level(_sub_count(dmin, a, b, max_sub))
    if n_sub == 1:
        return far_order(dmin / max(a, b), gauss_points, far_tol), 1
    return gauss_points, n_sub


@njit(cache=True)
def horizontal_image_displacement(y, receiver_layer, center, frame, a, b, source_layer, shear_modulus,
                                  poisson_ratio, n_pairs, triples, gauss_points, max_sub, far_tol, out):
    """:func:`image_rectangle_displacement` of a horizontal rectangle (every point at the
    centre's height, so one set of ``n_pairs`` traced ``triples`` for all), each triple on
    its own rule: :func:`image_order`'s criterion applied to that triple's own singular
    point: the triples reflected many times are farther away and may take fewer points per
    side than the nearest one (measured 1.3x cheaper with two interfaces under a free
    surface, benchmarks/RESULTS.md), each triple's error within ``far_tol`` of itself."""
    layer, z, eps, sigma, coef, dcoef = triples
    delta_r = 1.0 / (3.0 - 4.0 * poisson_ratio[receiver_layer])
    g_s = shear_modulus[source_layer]
    nu_s = poisson_ratio[source_layer]
    lame_s = _lame(g_s, nu_s)
    jac = a * b
    work = Workspace(coef.shape[-1])
    work1 = Workspace(1)
    point = np.empty((3, 3, 3))
    total = np.zeros((3, 3, 3))
    kelvin = np.zeros((2, 3, 3, 1))
    for k in range(-1, n_pairs):
        if k < 0:  # in another layer: minus the whole-space field of the source's material
            if receiver_layer == source_layer:
                continue
            dmin = rectangle_distance(y, center, frame, a, b)
            side = 1.0 if y[2] >= center[2] else -1.0
            _original(kelvin[0], 1.0 / (3.0 - 4.0 * nu_s), g_s, side, -1.0)
        elif layer[k] != receiver_layer:
            continue
        else:
            dmin = distance_to_rectangle(y[0], y[1], center[2] + (y[2] - z[k]) / eps[k], center, frame, a, b)
        n_gauss, n_sub = _triple_rule(dmin, a, b, gauss_points, max_sub, far_tol)
        xi, eta, wt = square_rule(n_gauss, n_sub)
        for g in range(xi.shape[0]):
            x0 = center[0] + xi[g] * a * frame[0, 0] + eta[g] * b * frame[1, 0]
            x1 = center[1] + xi[g] * a * frame[0, 1] + eta[g] * b * frame[1, 1]
            point[:] = 0.0
            if k < 0:
                _pair_displacement_gradient(y[0] - x0, y[1] - x1, y[2] - center[2], 1.0, side, kelvin[0], kelvin[1],
                                            1.0 / (3.0 - 4.0 * nu_s), point, work1)
            else:
                _pair_displacement_gradient(y[0] - x0, y[1] - x1, y[2] - z[k], eps[k], sigma[k], coef[k], dcoef[k],
                                            delta_r, point, work)
            w = wt[g] * jac
            for f in range(3):
                for q in range(3):
                    for i in range(3):
                        total[f, q, i] += w * point[f, q, i]
        if k < 0:
            kelvin[:] = 0.0
    out[:] = 0.0
    _contract_displacement(total, frame[2], g_s, lame_s, 1.0, out)


@njit(cache=True)
def element_displacement(data, point, point_layer, j, local, image, center_triples, n_center, work_triples, cache,
                         out):
    """``out[q, i]``: displacement ``u_i`` at ``point`` (in the solid ``point_layer``) of a
    unit global DD ``q`` of rectangle ``j`` of the :class:`.images3d.LayeredRectangles`
    ``data``: closed form of the source layer's material plus images. ``local``,
    ``image``: (3, 3) scratch; ``center_triples``: the ``n_center`` triples traced at the
    rectangle's centre height (:func:`_buffers`, :func:`trace`); ``work_triples``: room for
    other heights and ``cache`` (:func:`_height_cache`) this rectangle's traced heights (a
    tilted rectangle). NaN on an edge of the rectangle (log-singular)."""
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    dz = point[2] - center[2]
    rectangle_local_displacement(frame[0, 0] * dx + frame[0, 1] * dy + frame[0, 2] * dz,
                                 frame[1, 0] * dx + frame[1, 1] * dy + frame[1, 2] * dz,
                                 frame[2, 0] * dx + frame[2, 1] * dy + frame[2, 2] * dz, a, b,
                                 data.poisson_ratio[ls], local)
    local_to_global(frame, local, out)  # u_i = sum_p F[p, i] sum_k F[k, q] local[k, p], unit global DD q
    if data.interfaces.shape[0] > 0:
        if frame[0, 2] == 0.0 and frame[1, 2] == 0.0:  # horizontal: every point at the centre's height
            horizontal_image_displacement(point, point_layer, center, frame, a, b, ls, data.shear_modulus,
                                          data.poisson_ratio, n_center, center_triples, data.gauss_points,
                                          data.max_subdivisions, data.far_tol, image)
        else:
            n_gauss, n_sub = image_order(point, point_layer, center, frame, a, b, ls, n_center, center_triples,
                                         data.gauss_points, data.max_subdivisions, data.far_tol)
            image_rectangle_displacement(point, point_layer, center, frame, a, b, ls, data.interfaces,
                                         data.shear_modulus, data.poisson_ratio, data.n_images, n_gauss, n_sub,
                                         work_triples, cache, image)
        for q in range(3):
            for i in range(3):
                out[q, i] += image[q, i]


@njit(cache=True, nogil=True)
def displacement_block(data, points, point_layer, dd, out):
    """Global displacement ``out`` (M, 3) at ``points`` (M, 3) in the solid layers
    ``point_layer`` (M,) induced by the global DDs ``dd`` (N, 3) of every rectangle
    (direct sum; each point's sum in element order). Elements outside, points inside: a
    rectangle's triples are traced once for all the points."""
    local = np.empty((3, 3))
    image = np.empty((3, 3))
    pair = np.empty((3, 3))
    center_triples = _buffers(data.shear_modulus, data.n_images)  # one height at a time
    work_triples = _buffers(data.shear_modulus, data.n_images)
    rows = 0
    for n in range(1, data.gauss_points + 1):  # the heights of the one-square rules of a tilted rectangle
        rows += n * n
    cache = _height_cache(data.shear_modulus, data.n_images, rows)
    layer, z, eps, sigma, coef, dcoef = center_triples
    for m in range(points.shape[0]):
        for i in range(3):
            out[m, i] = 0.0
    for j in range(data.centers.shape[0]):
        cache[-1][0] = 0  # a new rectangle: nothing traced
        n_center = 0
        if data.interfaces.shape[0] > 0:
            n_center = trace(data.centers[j, 2], data.layer[j], data.interfaces, data.shear_modulus,
                             data.poisson_ratio, data.n_images, layer, z, eps, sigma, coef, dcoef)
        for m in range(points.shape[0]):
            element_displacement(data, points[m], point_layer[m], j, local, image, center_triples, n_center,
                                 work_triples, cache, pair)
            for i in range(3):
                acc = 0.0
                for q in range(3):
                    acc += pair[q, i] * dd[j, q]
                out[m, i] += acc
