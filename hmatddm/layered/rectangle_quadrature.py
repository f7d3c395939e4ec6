"""The image quadrature over a source rectangle in 3D (ref. Sec. 3.3; the 2D counterpart is
:mod:`.segment_quadrature`): Gauss rules on equal sub-squares (:func:`square_rule`), how
many sub-squares a receiver needs (:func:`subdivisions`: the integrand is singular at
the rectangle's mirror images in the interfaces, and on the rectangle itself for a
receiver in another layer), fewer Gauss points for a distant receiver
(:func:`far_order`), the rules a source keeps traced (:func:`_cached_rules`), and the
Gauss sum of the complementary stress of :mod:`.image_points3d` over the rectangle
(:func:`_integrate`, :func:`image_rectangle_stress`).
"""
import math

import numpy as np
from numba import njit

from ..kernels.rectangle3d import distance_to_rectangle as _distance, rectangle_distance
from ..kernels.rectangle3d import traction_pair as _traction_pair
from .image_points3d import _complementary_gradient
from .image_tracer import trace_capacity
from .image_tracer3d import _trace_range, _traced_buffer, drop_surface_range
from .images2d import _lame
from .potentials3d import Workspace, _contract
from .remainder_table3d import keep_near_range
from .segment_quadrature import gauss_legendre, subdivision_level


@njit(cache=True)
def square_rule(n_gauss, n_sub):
    """``(xi, eta, w)``: ``n_gauss^2`` Gauss points on each of ``n_sub^2`` equal
    sub-squares of [-1, 1]^2 (weights sum to 4)."""
    x, w = gauss_legendre(n_gauss)
    m = n_gauss * n_sub
    xi1 = np.empty(m)
    w1 = np.empty(m)
    for s in range(n_sub):
        lo = -1.0 + 2.0 * s / n_sub
        for g in range(n_gauss):
            xi1[s * n_gauss + g] = lo + (x[g] + 1.0) / n_sub
            w1[s * n_gauss + g] = w[g] / n_sub
    xi = np.empty(m * m)
    eta = np.empty(m * m)
    wt = np.empty(m * m)
    for i in range(m):
        for j in range(m):
            xi[i * m + j] = xi1[i]
            eta[i * m + j] = xi1[j]
            wt[i * m + j] = w1[i] * w1[j]
    return xi, eta, wt


@njit(cache=True)
def nearest_singularity(y, receiver_layer, center, frame, a, b, source_layer, interfaces, skip=-1):
    """Distance from the receiver ``y`` to the nearest singular point of the image
    integrand: the rectangle's mirror images in the interfaces bounding the source's and
    the receiver's layers (the distance of the mirrored receiver to the rectangle), and
    the rectangle itself when the receiver is in another layer. ``skip``: an interface
    whose mirror is left out (-1: none), the free surface whose reflection is integrated
    in closed form (:func:`.image_tracer3d.drop_surface_range`)."""
    dmin = np.inf
    if receiver_layer != source_layer:
        dmin = rectangle_distance(y, center, frame, a, b)
    n_if = interfaces.shape[0]
    for layer in (source_layer, receiver_layer):
        for k in (layer - 1, layer):
            if 0 <= k < n_if and k != skip:
                dmin = min(dmin, _distance(y[0], y[1], 2.0 * interfaces[k] - y[2], center, frame, a, b))
        if receiver_layer == source_layer:  # the same interfaces: once
            break
    return dmin


@njit(cache=True)
def subdivisions(y, receiver_layer, center, frame, a, b, source_layer, interfaces, max_sub):
    """Sub-squares per side so that each is at most half as large as the distance from
    the receiver to the nearest singular point of the integrand (:func:`nearest_singularity`)."""
    return _sub_count(nearest_singularity(y, receiver_layer, center, frame, a, b, source_layer, interfaces), a, b,
                      max_sub)


@njit(cache=True)
def _sub_count(dmin, a, b, max_sub):
    if dmin <= 0.0:
        return max_sub
    n = int(math.ceil(4.0 * max(a, b) / dmin))
    return min(max(n, 1), max_sub)


#: Relative error of the image stress of a rectangle that :func:`far_order` allows when it
#: lowers the Gauss order for a distant receiver (what ``gauss_points = 4`` leaves near
#: images, at 4 to 8 half sides: 5e-6).
FAR_TOL = 1e-6


@njit(cache=True)
def far_order(ratio, n_max, tol):
    """Gauss points per side (at most ``n_max``) for a square of half side ``a`` whose
    nearest singular point is ``ratio a`` away: the smallest ``n`` with
    ``40 n ratio^(-2n) <= tol`` (default :data:`FAR_TOL`). That expression bounds the
    measured relative error of the ``n x n`` Gauss rule on the image stress of horizontal, vertical and tilted
    squares below a free surface, ``C_n ratio^(-2n)`` with ``C_n`` = 12, 32, 62, 103 for
    ``n`` = 1-4 (``ratio`` 8-128; the error of a Gauss rule on a function regular within
    a distance ``d`` falls like ``(a / d)^(2n)``). Thresholds at :data:`FAR_TOL`: 4 points
    from ratio 10.6, 3 from 22.3, 2 from 95."""
    return _bounded_order(ratio, 1.0, n_max, tol)


@njit(cache=True, inline="always")
def _bounded_order(ratio, size, n_max, tol):
    """The smallest ``n < n_max`` with ``40 n ratio^(-2n) size <= tol``, else ``n_max``: the
    powers by products (a ``pow`` a term cost more than the rest of a far pair's rule)."""
    if ratio <= 0.0:
        return n_max
    step = 1.0 / (ratio * ratio)
    power = step
    for n in range(1, n_max):
        if 40.0 * n * power * size <= tol:
            return n
        power *= step
    return n_max


#: Error of an influence entry's images allowed relative to the largest entry of the
#: matrix (:func:`entry_order`): ten times below the 1e-8 that issue 32 asks for.
ENTRY_TOL = 1e-9
#: Bound of the image stress of a rectangle of sides ``2a x 2b`` whose nearest singular
#: point is ``d`` away, in units of ``G_max 4 a b / d^3`` (``G_max``: the stiffest
#: layer): measured up to 1.9 (half-space), 0.5 (three layers, 2G middle layer), 1.3 (5G
#: middle layer), 0.9 (a 5:1 bi-material) on randomly oriented squares at 2 to 100 half
#: sides; five times the largest. The point form's rule (:mod:`.okada_point3d`) uses it.
IMAGE_BOUND = 10.0
#: ``K_n`` of :func:`entry_order`'s bound ``K_n ratio^(-2n) G_max 4 a b / d^3`` of the error
#: of ``n x n`` Gauss points on one square (``n`` = 1, 2, ...; the last for every larger
#: ``n``): four times the largest error measured (7.4, 5.4, 3.5, 2.3, 1.3 for ``n`` = 1-5)
#: on 2,700 randomly oriented rectangles (aspect 1 to 2) at 4 to 100 half sides from their
#: singular point, in a half-space, 2:1, 1:5 and 5:1 bi-materials (reflected and
#: transmitted fields) and three layers (G, 2G, G and G, 5G, G; four images), against 14
#: points on 2 x 2 sub-squares (benchmarks/RESULTS.md, issue 32, twelfth session).
ENTRY_BOUND = (30.0, 22.0, 14.0, 10.0, 6.0, 5.0)
#: Gauss points per side on a (sub-)square next to the images when an entry tolerance is
#: set (``entry_tol > 0``; the medium's ``gauss_points`` when larger): 4 left up to 8e-8 of
#: the largest entry next to an interface (a 5:1 bi-material), 5 leaves at most 2e-9 and 6
#: 2e-11 at 1.5-2x the CPU of 5 next to the interfaces (benchmarks/RESULTS.md, issue 32,
#: twelfth session): 5 keeps the 1e-8 that issue 32 asks for.
NEAR_GAUSS_POINTS = 5


@njit(cache=True)
def entry_order(dmin, a, b, n_max, tol):
    """Gauss points per side (at most ``n_max``) of one square so that the error of its image
    stress, bounded by ``K_n ratio^(-2n)`` (:data:`ENTRY_BOUND`) times its size ``4 a b /
    dmin^3`` (per unit ``G_max``; ``ratio = dmin / max(a, b)``), is at most ``tol``: the
    error allowed relative to the largest entry times that entry over ``G_max`` (what
    :func:`_image_order` passes). The bound is the measured error's, with a margin of four:
    an entry far from the images is small against the largest one: for 0.5 m squares in one
    material at the default :data:`ENTRY_TOL`, 5 points from 6.5 half sides, 4 from 9.6, 3
    from 16.5, 2 from 41 and one from ~180."""
    if tol <= 0.0 or dmin <= 0.0:
        return n_max
    ratio = dmin / max(a, b)
    size = 4.0 * a * b / (dmin * dmin * dmin)
    step = 1.0 / (ratio * ratio)
    power = step
    last = len(ENTRY_BOUND) - 1
    for n in range(1, n_max):
        if ENTRY_BOUND[min(n - 1, last)] * power * size <= tol:
            return n
        power *= step
    return n_max


@njit(cache=True)
def entry_scale(half_a, half_b, layer, shear_modulus, poisson_ratio):
    """The scale of the largest entry of a traction matrix: the largest uniform-rock self
    entry of its rectangles (the normal traction at the centre of a rectangle of unit
    opening, in its layer's material; images change it by a fraction)."""
    work = np.empty((3, 3, 3))
    block = np.empty((3, 3))
    frame = np.eye(3)
    origin = np.zeros(3)
    largest = 0.0
    for e in range(half_a.shape[0]):
        g = shear_modulus[layer[e]]
        if g > 0.0:
            _traction_pair(origin, frame[2], origin, frame, half_a[e], half_b[e], g, poisson_ratio[layer[e]], 0.0,
                           block, work, 0.0)
            largest = max(largest, abs(block[2, 2]))
    return largest


@njit(cache=True)
def _integrate(y, receiver_layer, center, frame, a, b, source_layer, shear_modulus, poisson_ratio, xi, eta, wt,
               traced, offset, out, gradient, work, work1, kelvin, z_lo, z_hi):
    """``out[b, i, k] +=`` the Gauss sum of the complementary stress over the rectangle
    with the triples traced at the points ``offset ... offset + len(xi)`` of ``traced``
    whose heights are in ``[z_lo, z_hi)``."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    normal = frame[2]
    g_s = shear_modulus[source_layer]
    lame_s = _lame(g_s, poisson_ratio[source_layer])
    jac = a * b
    x = np.empty(3)
    for g in range(xi.shape[0]):
        for c in range(3):
            x[c] = center[c] + xi[g] * a * frame[0, c] + eta[g] * b * frame[1, c]
        k = offset + g
        _complementary_gradient(y, receiver_layer, x, n_pairs[k], source_layer, layer[k], z[k], eps[k], sigma[k],
                                coef[k], dcoef[k], shear_modulus, poisson_ratio, gradient, work, work1, kelvin, z_lo,
                                z_hi)
        _contract(gradient, normal, g_s, lame_s, wt[g] * jac, out)


@njit(cache=True, inline="always")
def image_rectangle_stress(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                           poisson_ratio, n_images, n_gauss, n_sub, out, near_only, bottoms, tops):
    """Complementary stress ``out[b, i, k]`` at ``y`` of a unit global DD ``b`` on the
    rectangle, by ``n_gauss^2`` points on each of ``n_sub^2`` sub-squares; ``near_only``:
    of the near triples only (:func:`.remainder_table3d.keep_near`, layers bounded by
    ``bottoms``, ``tops``), the remainder being tabulated."""
    image_rectangle_stress_without(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                                   poisson_ratio, n_images, n_gauss, n_sub, out, near_only, bottoms, tops, False, 0.0)


@njit(cache=True, inline="always")
def image_rectangle_stress_without(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                                   poisson_ratio, n_images, n_gauss, n_sub, out, near_only, bottoms, tops,
                                   drop_surface, surface):
    """:func:`image_rectangle_stress`, without the source's reflection in the free surface
    ``z = surface`` when ``drop_surface`` (:func:`.image_tracer3d.drop_surface_range`: it
    is added in closed form, :mod:`.okada3d`)."""
    xi, eta, wt = square_rule(n_gauss, n_sub)
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    traced = _traced_buffer(xi.shape[0], cap, n_orders)
    first = np.int64(0)  # not a literal 0: the same compiled _trace_range and _integrate as element_traction's
    _trace_range(center, frame, a, b, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, eta, first,
                 xi.shape[0], traced)
    if near_only:
        keep_near_range(traced, first, xi.shape[0], center, frame, a, b, xi, eta, source_layer, bottoms, tops)
    if drop_surface:
        drop_surface_range(traced, first, xi.shape[0], center, frame, a, b, xi, eta, source_layer, surface)
    out[:] = 0.0
    _integrate(y, receiver_layer, center, frame, a, b, source_layer, shear_modulus, poisson_ratio, xi, eta, wt,
               traced, first, out, np.empty((3, 3, 3, 3)), Workspace(n_orders), Workspace(1),
               np.zeros((2, 3, 3, 1)), -np.inf, np.inf)


@njit(cache=True)
def _image_order(y, receiver_layer, center, frame, a, b, source_layer, interfaces, gauss_points, max_sub, far_tol,
                 entry_tol, skip):
    """``(n_gauss, n_sub)`` of the image quadrature of a rectangle at ``y``: sub-squares
    by :func:`subdivisions` rounded up to a power of two, ``gauss_points`` on each, and, on
    one square, :func:`one_square_order`: :func:`entry_order` when ``entry_tol > 0`` (the
    error allowed relative to the largest entry, over ``G_max``), else :func:`far_order`;
    ``skip``: an interface whose mirror is no singular point of the triples integrated
    (:func:`nearest_singularity`; -1: none)."""
    dmin = nearest_singularity(y, receiver_layer, center, frame, a, b, source_layer, interfaces, skip)
    n_sub = 2 ** subdivision_level(_sub_count(dmin, a, b, max_sub))
    if n_sub == 1:
        return one_square_order(dmin, a, b, gauss_points, far_tol, entry_tol), 1
    return gauss_points, n_sub


@njit(cache=True)
def one_square_order(dmin, a, b, gauss_points, far_tol, entry_tol):
    """Gauss points per side on one square (no sub-squares) whose nearest singular point is
    ``dmin`` away (a receiver's rule, a group of its triples', the tabulated remainder's):
    :func:`entry_order` when ``entry_tol > 0`` (issue 32's criterion, the error against the
    largest entry), else :func:`far_order` (the relative rule, the cross-check's). Up to
    issue 32's eleventh session the smaller of the two: the relative rule then took fewer
    points than the entries needed next to the images (up to 8e-8 of the largest entry)."""
    if entry_tol > 0.0:
        return entry_order(dmin, a, b, gauss_points, entry_tol)
    return far_order(dmin / max(a, b), gauss_points, far_tol)


@njit(cache=True)
def mirror_distance(y, interface, center, frame, a, b):
    """Distance from ``y`` to the rectangle's mirror image in the plane ``z = interface``
    (the receiver's mirror to the rectangle): the singular points of a first reflection."""
    return _distance(y[0], y[1], 2.0 * interface - y[2], center, frame, a, b)


@njit(cache=True)
def _cached_rules(n_gauss):
    """The rules a source keeps traced, stacked ``(xi, eta, w, start)``: slot ``s < n_gauss``
    is one square with ``s + 1`` points per side (far receivers, :func:`far_order`), slot
    ``n_gauss`` is 2 x 2 sub-squares of ``n_gauss`` points per side."""
    start = np.zeros(n_gauss + 2, dtype=np.int64)
    for s in range(n_gauss):
        start[s + 1] = start[s] + (s + 1) ** 2
    start[n_gauss + 1] = start[n_gauss] + 4 * n_gauss ** 2
    xi = np.empty(start[-1])
    eta = np.empty(start[-1])
    wt = np.empty(start[-1])
    for s in range(n_gauss + 1):
        x, e, w = square_rule(s + 1 if s < n_gauss else n_gauss, 1 if s < n_gauss else 2)  # one specialization
        # element by element, not by slice assignment (docs/conventions.md, §5)
        for q in range(x.shape[0]):
            xi[start[s] + q] = x[q]
            eta[start[s] + q] = e[q]
            wt[start[s] + q] = w[q]
    return xi, eta, wt, start
