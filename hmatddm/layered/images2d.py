"""Complementary (image) stress of displacement discontinuities in a plane-layered
medium, 2D plane strain, by the general image method (ref. Secs 3.2-3.3).

Coordinates: ``(x, y)`` with ``y`` vertical; the reference's ``(x1, x3)`` (``x2`` is
its antiplane axis). Interfaces are the lines ``y = d_k`` (see :class:`LayeredMedium`).

Hansen potentials (ref. Eqs 3.14-3.16, 3.22). A potential pair ``(phi1, phi2)`` in a
layer of ``delta = 1/(3 - 4 nu)`` gives the displacement

    u1 = phi1,1 - phi2,1 - 2 delta s phi2,13
    u3 = phi1,3 + phi2,3 - 2 delta s phi2,33

where ``s = y3 - z`` is the height above the point ``z`` the pair emanates from (the
source, or its image). The point-force kernels of ref. Eq. 3.23 are real and imaginary
parts of one analytic function of ``w = r1 + i r3``: with ``f(w) = w log w``,

    Phi_11 = -Phi_12 = K Re-part:  K [-Re f(w) + (1 + delta) r1]   (force along x1)
    Phi_31 =  Phi_32 = K [-Im f(w) + r3]                           (force along x3)

``K = 1/(4 pi G (1 + delta))``. Every quantity a displacement discontinuity produces is
at least a second derivative of a potential, where the linear terms, the logarithm and
the angle drop out: ``d1^a d3^b f = i^b f^(a+b)``, ``f'' = 1/w``,
``f^(k) = (-1)^k (k-2)! / w^(k-1)``. So every derivative is closed form; the sympy
script ``_derive_images2d.py`` derives the reflection/transmission operators below from
the interface conditions and checks these derivatives.

Reflection and transmission of the pairs at the interfaces (ref. Eqs 3.25-3.28, Fig. 3.4)
are :mod:`hmatddm.layered.image_tracer` (shared with 3D); the Gauss rules and the
subdivision of the element are :mod:`hmatddm.layered.segment_quadrature`; the kernel
record of constant elements and the per-pair functions the drivers call are
:mod:`hmatddm.layered.segments2d`.

The 2D constant displacement of ref. Sec. 3.3.1 (Eqs 3.34-3.39) is a rigid translation
that does not depend on the source point: every DD quantity differentiates it away, so
it needs no correction here (it matters for a point-force displacement kernel only).

What is "complementary": in the source's layer, every image pair (the original is the
closed-form kernel of :mod:`hmatddm.kernels.line2d`); in any other layer, the
transmitted and reflected pairs minus the source layer's whole-plane (Kelvin) field,
because the callers add the closed-form kernel of the source's material at every
receiver. So with equal layers the complementary stress is exactly zero.

Compile cost (issue 18): numba links every njit function a function calls into its
compiled library and optimises all of it again there, so each njit level above the per-pair
stress costs one more compile of everything below it, and numba compiles one specialization
per literal argument (``0``) where another call passes a variable. So the short functions
above the quadrature (:func:`trace_points`, :func:`image_element_stress`) are inlined by
numba, not compiled on their own, and calls pass run-time values (``np.int64(0)``).
``benchmarks/bench_layered3d_compile.py --2d`` measures it.
"""
import math

import numpy as np
from numba import njit

from .image_tracer import orders_used, trace_capacity, trace_potentials

_INV_4PI = 1.0 / (4.0 * math.pi)


@njit(cache=True)
def trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, pair_layer, pair_z, pair_eps,
          pair_coef, pair_dcoef):
    """Image pairs of a unit point force at height ``t`` in ``source_layer``
    (:func:`trace_potentials`): ``pair_coef[k, f, j, n]`` is ``A`` of potential ``j``
    for a force along ``f`` = 0: x, 1: y (``n``: order of ``D``), of the kernels of
    ref. Eq. 3.23 (``Phi_11 = -Phi_12``, ``Phi_31 = Phi_32``; ``Phi_11`` even in ``r3``,
    ``Phi_31`` odd)."""
    g_s = shear_modulus[source_layer]
    delta_s = 1.0 / (3.0 - 4.0 * poisson_ratio[source_layer])
    k_2d = _INV_4PI / (g_s * (1.0 + delta_s))
    original = np.empty((2, 2, 2))
    for e in range(2):
        original[e, 0, 0] = k_2d        # Phi_11 (force x1)
        original[e, 0, 1] = -k_2d       # Phi_12 = -Phi_11
        original[e, 1, 0] = k_2d        # Phi_31 (force x3)
        original[e, 1, 1] = k_2d        # Phi_32 = Phi_31
    return trace_potentials(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, original,
                            np.array([1.0, -1.0]), pair_layer, pair_z, pair_eps, np.empty(pair_z.shape[0]), pair_coef,
                            pair_dcoef)


@njit(cache=True)
def _potential_table(coef, dcoef, beta, n_orders, table, dtable, top=4):
    """``table[j, a, b] = sum_n coef[j, n] beta[a, b + n]`` (derivative d1^a d3^b of
    potential j) for ``a + b`` = ``top - 1``, ``top``, and ``dtable`` the same with ``dcoef``
    for ``a + b`` = ``top - 2``, ``top - 1``: the entries :func:`_pair_stress_gradient` reads
    (``top`` 4), or the displacement gradient of :mod:`.displacement2d` (``top`` 3)."""
    for j in range(2):
        for a in range(top + 1):
            for b in range(max(0, top - 2 - a), top + 1 - a):
                order = a + b
                if order >= top - 1:
                    s = 0.0
                    for n in range(n_orders):
                        s += coef[j, n] * beta[a, b + n]
                    table[j, a, b] = s
                if order <= top - 1:
                    ds = 0.0
                    for n in range(n_orders):
                        ds += dcoef[j, n] * beta[a, b + n]
                    dtable[j, a, b] = ds


@njit(cache=True)
def potential_derivatives(gk, kmax, top, f, beta):
    """``beta[a, b]`` = ``-Re`` (``f`` 0) or ``-Im`` (``f`` 1) of ``i^b gk[a + b]``, the
    derivatives d1^a d3^b of the pair's analytic function (module docstring) for
    ``a <= top``, ``2 <= a + b <= kmax``."""
    for a in range(top + 1):
        ib = complex(1.0, 0.0)
        for b in range(kmax + 1 - a):
            if a + b >= 2:
                v = ib * gk[a + b]
                beta[a, b] = -v.real if f == 0 else -v.imag
            ib = ib * 1j


@njit(cache=True)
def _displacement_gradient(table, da, db, scale, s, delta, out):
    """``out += scale * [u1,1, u1,3, u3,1, u3,3]`` of the potentials' derivatives
    ``table[j, a + da, b + db]`` (ref. Eq. 3.22 with ``s`` the height above the point
    the pair emanates from)."""
    t1 = table[0]
    t2 = table[1]
    out[0] += scale * (t1[2 + da, db] - t2[2 + da, db] - 2.0 * delta * s * t2[2 + da, 1 + db])
    out[1] += scale * (t1[1 + da, 1 + db] - (1.0 + 2.0 * delta) * t2[1 + da, 1 + db]
                       - 2.0 * delta * s * t2[1 + da, 2 + db])
    out[2] += scale * (t1[1 + da, 1 + db] + t2[1 + da, 1 + db] - 2.0 * delta * s * t2[1 + da, 2 + db])
    out[3] += scale * (t1[da, 2 + db] + (1.0 - 2.0 * delta) * t2[da, 2 + db] - 2.0 * delta * s * t2[da, 3 + db])


@njit(cache=True)
def inverse_power_derivatives(w, kmax, gk):
    """``gk[k]`` = the ``(k - 2)``-th derivative of ``1/w``, ``(-1)^k (k-2)! / w^(k-1)``, for
    ``k = 2 .. kmax`` (the image pairs' potentials and their derivatives, ref. Eq. 3.22)."""
    inv = 1.0 / w
    gk[2] = inv
    power = inv
    fact = 1.0
    for k in range(3, kmax + 1):
        power = power * inv
        fact *= (k - 2)
        gk[k] = fact * power if k % 2 == 0 else -fact * power


@njit(cache=True)
def pair_stress_gradient(r1, r3, eps, coef, dcoef, n_orders, delta, shear_modulus, lame, out):
    """``out[f, q, c] +=`` derivative along the source coordinate ``q`` (0: x, 1: y) of
    the stress component ``c`` (0: xx, 1: xy, 2: yy) at a receiver ``(r1, r3)`` from the
    point the pair emanates from, for a unit force along ``f``. ``delta``, shear modulus
    and Lame constant are the receiver layer's; ``eps = dz/dt``."""
    work = Workspace(n_orders)
    _pair_stress_gradient(r1, r3, eps, coef, dcoef, delta, shear_modulus, lame, out, work)


@njit(cache=True)
def Workspace(n_orders):
    """Scratch arrays of :func:`_pair_stress_gradient` (allocated once per caller)."""
    return (np.empty(n_orders + 6, dtype=np.complex128), np.zeros((5, n_orders + 5)), np.empty((2, 5, 5)),
            np.empty((2, 5, 5)), np.empty(4))


@njit(cache=True)
def _pair_stress_gradient(r1, r3, eps, coef, dcoef, delta, shear_modulus, lame, out, work):
    gk, beta, table, dtable, grad = work
    # highest order of D with a non-zero coefficient (most pairs stop well below n_orders)
    n_orders = orders_used(coef, dcoef)
    kmax = 3 + n_orders  # a + b <= 4 in the tables, plus D^(n_orders - 1)
    inverse_power_derivatives(complex(r1, r3), kmax, gk)
    for f in range(2):
        potential_derivatives(gk, kmax, 4, f, beta)
        _potential_table(coef[f], dcoef[f], beta, n_orders, table, dtable)
        for q in range(2):
            grad[:] = 0.0
            if q == 0:
                # d/dx1 = -d/dr1
                _displacement_gradient(table, 1, 0, -1.0, r3, delta, grad)
            else:
                # d/dt: coefficients, r3 = y3 - z(t) inside the kernel and in s
                _displacement_gradient(dtable, 0, 0, 1.0, r3, delta, grad)
                _displacement_gradient(table, 0, 1, -eps, r3, delta, grad)
                t2 = table[1]
                grad[0] += 2.0 * delta * eps * t2[2, 1]
                grad[1] += 2.0 * delta * eps * t2[1, 2]
                grad[2] += 2.0 * delta * eps * t2[1, 2]
                grad[3] += 2.0 * delta * eps * t2[0, 3]
            trace_strain = grad[0] + grad[3]
            out[f, q, 0] += lame * trace_strain + 2.0 * shear_modulus * grad[0]
            out[f, q, 1] += shear_modulus * (grad[1] + grad[2])
            out[f, q, 2] += lame * trace_strain + 2.0 * shear_modulus * grad[3]


@njit(cache=True)
def _lame(shear_modulus, poisson_ratio):
    return 2.0 * shear_modulus * poisson_ratio / (1.0 - 2.0 * poisson_ratio)


@njit(cache=True, inline="always")
def zero_in_void(shear_modulus, layer, out):
    """True, with ``out`` set to zero, when ``layer`` is a void (zero shear modulus: a
    free surface's outside), where an element induces no stress."""
    if shear_modulus[layer] <= 0.0:
        out[:] = 0.0
        return True
    return False


@njit(cache=True, inline="always")
def receiver_constants(shear_modulus, poisson_ratio, layer):
    """``(G, delta = 1/(3 - 4 nu), lambda)`` of ``layer``: the material constants the image
    fields take at a receiver in that layer (ref. Eq. 3.14), in 2D and 3D alike."""
    g = shear_modulus[layer]
    nu = poisson_ratio[layer]
    return g, 1.0 / (3.0 - 4.0 * nu), _lame(g, nu)


@njit(cache=True)
def _contract(gradient, normal, shear_modulus, lame, weight, out):
    """``out[b, i, j] += weight *`` stress of a unit DD density along global ``b`` on a
    plane of ``normal``: the moment ``M_pq = lame (b.n) delta_pq + G (b_p n_q + b_q n_p)``
    applied to ``gradient[p, q, c]`` (d/dx_q of the stress of a force along p)."""
    for b in range(2):
        for c in range(3):
            acc = 0.0
            for p in range(2):
                for q in range(2):
                    m = shear_modulus * ((1.0 if p == b else 0.0) * normal[q] + (1.0 if q == b else 0.0) * normal[p])
                    if p == q:
                        m += lame * normal[b]
                    acc += m * gradient[p, q, c]
            if c == 0:
                out[b, 0, 0] += weight * acc
            elif c == 1:
                out[b, 0, 1] += weight * acc
                out[b, 1, 0] += weight * acc
            else:
                out[b, 1, 1] += weight * acc


@njit(cache=True)
def _complementary_gradient(y1, y3, receiver_layer, x1, n_pairs, source_layer, t, pair_layer, pair_z, pair_eps,
                            pair_coef, pair_dcoef, shear_modulus, poisson_ratio, gradient, work, work1):
    """``gradient[f, q, c]`` of the complementary field (see the module docstring) at a
    receiver from the traced pairs of a source point ``(x1, t)``; ``work``: a
    :func:`Workspace` of the pairs' order, ``work1`` one of order 1."""
    gradient[:] = 0.0
    g_r, delta_r, lame_r = receiver_constants(shear_modulus, poisson_ratio, receiver_layer)
    for k in range(n_pairs):
        if pair_layer[k] == receiver_layer:
            _pair_stress_gradient(y1 - x1, y3 - pair_z[k], pair_eps[k], pair_coef[k], pair_dcoef[k],
                                  delta_r, g_r, lame_r, gradient, work)
    if receiver_layer != source_layer:
        # minus the whole-plane field of the source's material (added in closed form)
        g_s = shear_modulus[source_layer]
        nu_s = poisson_ratio[source_layer]
        delta_s = 1.0 / (3.0 - 4.0 * nu_s)
        k_2d = _INV_4PI / (g_s * (1.0 + delta_s))
        coef = np.zeros((2, 2, 1))
        coef[0, 0, 0] = -k_2d
        coef[0, 1, 0] = k_2d
        coef[1, 0, 0] = -k_2d
        coef[1, 1, 0] = -k_2d
        dcoef = np.zeros((2, 2, 1))
        _pair_stress_gradient(y1 - x1, y3 - t, 1.0, coef, dcoef, delta_s, g_s, _lame(g_s, nu_s), gradient,
                              work1)


@njit(cache=True)
def kelvin_point_stress(y1, y3, x1, x3, normal, shear_modulus, poisson_ratio, out):
    """``out[b, i, j]``: whole-plane stress at ``(y1, y3)`` of a unit DD density along
    global ``b`` at the point ``(x1, x3)`` of a plane of ``normal``, through the same
    Hansen-potential path as the images (the original pair of ref. Eq. 3.23); a check of
    the machinery against the closed-form :mod:`hmatddm.kernels.line2d`."""
    delta = 1.0 / (3.0 - 4.0 * poisson_ratio)
    k_2d = _INV_4PI / (shear_modulus * (1.0 + delta))
    coef = np.zeros((2, 2, 1))
    coef[0, 0, 0] = k_2d
    coef[0, 1, 0] = -k_2d
    coef[1, 0, 0] = k_2d
    coef[1, 1, 0] = k_2d
    dcoef = np.zeros((2, 2, 1))
    gradient = np.zeros((2, 2, 3))
    lame = _lame(shear_modulus, poisson_ratio)
    pair_stress_gradient(y1 - x1, y3 - x3, 1.0, coef, dcoef, np.int64(1), delta, shear_modulus, lame, gradient)
    out[:] = 0.0
    _contract(gradient, normal, shear_modulus, lame, 1.0, out)


@njit(cache=True)
def image_point_stress(y1, y3, receiver_layer, x1, x3, source_layer, normal, interfaces, shear_modulus,
                       poisson_ratio, n_images, out):
    """Complementary stress ``out[b, i, j]`` (2, 2, 2) at the receiver ``(y1, y3)`` in
    ``receiver_layer`` of a unit DD density along global ``b`` (DD = u(+) - u(-), ``+``
    the side ``normal`` points to) at the source point ``(x1, x3)`` in ``source_layer``.

    The total stress is this plus the closed-form whole-plane kernel of the source
    layer's material (:mod:`hmatddm.kernels.line2d` integrated over the element).
    ``interfaces``, ``shear_modulus``, ``poisson_ratio``: :meth:`LayeredMedium.arrays`.
    """
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    pair_layer = np.empty(cap, dtype=np.int64)
    pair_z = np.empty(cap)
    pair_eps = np.empty(cap)
    pair_coef = np.zeros((cap, 2, 2, n_orders))
    pair_dcoef = np.zeros((cap, 2, 2, n_orders))
    n_pairs = trace(x3, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, pair_layer, pair_z,
                    pair_eps, pair_coef, pair_dcoef)
    gradient = np.empty((2, 2, 3))
    _complementary_gradient(y1, y3, receiver_layer, x1, n_pairs, source_layer, x3, pair_layer, pair_z, pair_eps,
                            pair_coef, pair_dcoef, shear_modulus, poisson_ratio, gradient, Workspace(n_orders),
                            Workspace(1))
    out[:] = 0.0
    g_s = shear_modulus[source_layer]
    _contract(gradient, normal, g_s, _lame(g_s, poisson_ratio[source_layer]), 1.0, out)


@njit(cache=True)
def traced_buffer(source_layer, shear_modulus, n_images, n_points):
    """Room for the image pairs of ``n_points`` source points, as :func:`trace_points`
    returns them, untraced (fill ranges with :func:`_trace_range`)."""
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    return (np.zeros(n_points, dtype=np.int64), np.empty((n_points, cap), dtype=np.int64),
            np.empty((n_points, cap)), np.empty((n_points, cap)), np.zeros((n_points, cap, 2, 2, n_orders)),
            np.zeros((n_points, cap, 2, 2, n_orders)))


@njit(cache=True, inline="always")
def trace_points(p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi):
    """The image pairs of the source points ``x(xi)`` of the element ``p0 -> p1``:
    ``(n_pairs (G,), layer (G, P), z (G, P), eps (G, P), coef (G, P, 2, 2, O), dcoef)``."""
    traced = traced_buffer(source_layer, shear_modulus, n_images, xi.shape[0])
    _trace_range(p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, np.int64(0),
                 xi.shape[0], traced)
    return traced


@njit(cache=True)
def _trace_range(p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, start, stop, traced):
    """Trace the points ``start:stop`` of ``xi`` into ``traced`` (see :func:`trace_points`)."""
    n_pairs, layer, z, eps, coef, dcoef = traced
    for g in range(start, stop):
        x3 = 0.5 * (p0[1] + p1[1]) + 0.5 * xi[g] * (p1[1] - p0[1])
        n_pairs[g] = trace(x3, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer[g], z[g],
                           eps[g], coef[g], dcoef[g])


@njit(cache=True)
def _integrate(y1, y3, receiver_layer, p0, p1, source_layer, shear_modulus, poisson_ratio, xi, weights, shape,
               traced, offset, out, gradient, work, work1):
    """``out += `` the Gauss sum of :func:`image_element_stress` with the pairs traced
    at the points ``offset ... offset + len(xi)`` of ``traced`` (:func:`trace_points`)."""
    n_pairs, layer, z, eps, coef, dcoef = traced
    tx = p1[0] - p0[0]
    ty = p1[1] - p0[1]
    length = math.sqrt(tx * tx + ty * ty)
    normal = np.array([-ty / length, tx / length])
    jac = 0.5 * length
    g_s = shear_modulus[source_layer]
    lame_s = _lame(g_s, poisson_ratio[source_layer])
    for g in range(xi.shape[0]):
        x1 = 0.5 * (p0[0] + p1[0]) + 0.5 * xi[g] * tx
        x3 = 0.5 * (p0[1] + p1[1]) + 0.5 * xi[g] * ty
        k = offset + g
        _complementary_gradient(y1, y3, receiver_layer, x1, n_pairs[k], source_layer, x3, layer[k], z[k], eps[k],
                                coef[k], dcoef[k], shear_modulus, poisson_ratio, gradient, work, work1)
        for m in range(shape.shape[1]):
            _contract(gradient, normal, g_s, lame_s, weights[g] * jac * shape[g, m], out[m])


@njit(cache=True, inline="always")
def image_element_stress(y1, y3, receiver_layer, p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio,
                         n_images, xi, weights, shape, out):
    """Complementary stress integrated over the straight element ``p0 -> p1`` (normal:
    the tangent turned +90 degrees) with shape functions: ``out[m, b, i, j]`` is the
    stress for a unit nodal DD value ``m`` along global ``b``, i.e.
    ``sum_g weights[g] J shape[g, m] image_point_stress(x(xi[g]))`` with
    ``x(xi) = (p0 + p1)/2 + xi (p1 - p0)/2`` and ``J = |p1 - p0|/2``; ``xi`` in [-1, 1].
    Constant elements: ``shape = ones((n_gauss, 1))``.
    """
    traced = trace_points(p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi)
    out[:] = 0.0
    _integrate(y1, y3, receiver_layer, p0, p1, source_layer, shear_modulus, poisson_ratio, xi, weights, shape, traced,
               np.int64(0), out, np.empty((2, 2, 3)), Workspace(traced[4].shape[-1]), Workspace(1))

