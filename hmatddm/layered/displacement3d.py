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
  rectangle's mirror images (:func:`.rectangle_quadrature._image_order`, the rule of the
  stress: the displacement is one order smoother, so it is at least as accurate).

A point on an interface below a void layer (the free surface) is in the solid layer: the
surface displacement is what a tiltmeter or a GPS station measures. A point inside a
void layer has no displacement: :func:`hmatddm.layered.displacement.point_layers` refuses it.
"""
import numpy as np
from numba import njit

from ..kernels.displacement import rectangle_local_displacement
from .image_tracer import trace_capacity
from .image_tracer3d import _trace_range, _traced_buffer
from .images2d import _lame
from .potentials3d import Workspace, _original, _pair_displacement_gradient
from .rectangle_quadrature import _image_order, square_rule

__all__ = ["image_rectangle_displacement", "element_displacement", "displacement_block"]


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
                    m = 0.0
                    if p == b:
                        m += shear_modulus * normal[q]
                    if q == b:
                        m += shear_modulus * normal[p]
                    if p == q:
                        m += lame * normal[b]
                    acc += m * gradient[p, q, i]
            out[b, i] += weight * acc


@njit(cache=True)
def image_rectangle_displacement(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                                 poisson_ratio, n_images, n_gauss, n_sub, out):
    """Complementary displacement ``out[b, i]`` (3, 3) at ``y`` of a unit global DD ``b``
    on the rectangle (``n_gauss^2`` points on each of ``n_sub^2`` sub-squares)."""
    xi, eta, wt = square_rule(n_gauss, n_sub)
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    traced = _traced_buffer(xi.shape[0], cap, n_orders)
    first = np.int64(0)
    _trace_range(center, frame, a, b, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, eta, first,
                 xi.shape[0], traced)
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    normal = frame[2]
    g_s = shear_modulus[source_layer]
    lame_s = _lame(g_s, poisson_ratio[source_layer])
    jac = a * b
    gradient = np.empty((3, 3, 3))
    work = Workspace(n_orders)
    work1 = Workspace(1)
    kelvin = np.zeros((2, 3, 3, 1))
    x = np.empty(3)
    out[:] = 0.0
    for g in range(xi.shape[0]):
        for c in range(3):
            x[c] = center[c] + xi[g] * a * frame[0, c] + eta[g] * b * frame[1, c]
        _complementary_displacement_gradient(y, receiver_layer, x, n_pairs[g], source_layer, layer[g], z[g], eps[g],
                                             sigma[g], coef[g], dcoef[g], shear_modulus, poisson_ratio, gradient,
                                             work, work1, kelvin)
        _contract_displacement(gradient, normal, g_s, lame_s, wt[g] * jac, out)


@njit(cache=True)
def element_displacement(data, point, point_layer, j, local, image, out):
    """``out[q, i]``: displacement ``u_i`` at ``point`` (in the solid ``point_layer``) of a
    unit global DD ``q`` of rectangle ``j`` of the :class:`.images3d.LayeredRectangles`
    ``data``: closed form of the source layer's material plus images. ``local``,
    ``image``: (3, 3) scratch. NaN on an edge of the rectangle (log-singular)."""
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
    # global: u_i = sum_p F[p, i] sum_k l_k local[k, p], with l_k = F[k, q] for a unit global DD q
    for q in range(3):
        for i in range(3):
            acc = 0.0
            for k in range(3):
                for p in range(3):
                    acc += frame[k, q] * local[k, p] * frame[p, i]
            out[q, i] = acc
    if data.interfaces.shape[0] > 0:
        n_gauss, n_sub = _image_order(point, point_layer, center, frame, a, b, ls, data.interfaces,
                                      data.gauss_points, data.max_subdivisions, data.far_tol, 0.0)
        image_rectangle_displacement(point, point_layer, center, frame, a, b, ls, data.interfaces,
                                     data.shear_modulus, data.poisson_ratio, data.n_images, n_gauss, n_sub, image)
        for q in range(3):
            for i in range(3):
                out[q, i] += image[q, i]


@njit(cache=True, nogil=True)
def displacement_block(data, points, point_layer, dd, out):
    """Global displacement ``out`` (M, 3) at ``points`` (M, 3) in the solid layers
    ``point_layer`` (M,) induced by the global DDs ``dd`` (N, 3) of every rectangle
    (direct sum, elements in order)."""
    local = np.empty((3, 3))
    image = np.empty((3, 3))
    pair = np.empty((3, 3))
    for m in range(points.shape[0]):
        acc = np.zeros(3)
        for j in range(data.centers.shape[0]):
            element_displacement(data, points[m], point_layer[m], j, local, image, pair)
            for q in range(3):
                d = dd[j, q]
                for i in range(3):
                    acc[i] += pair[q, i] * d
        for i in range(3):
            out[m, i] = acc[i]
