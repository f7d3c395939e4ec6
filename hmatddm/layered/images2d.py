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

Reflection and transmission at an interface ``y3 = d`` of a pair emanating from ``z``
(ref. Eqs 3.25-3.28, with ``h = z - d`` signed, ``D = d/dy3``, ``gamma = G_far/G_near``,
``delta_1`` near side, ``delta_2`` far side): the reflected pair emanates from
``2d - z`` and is ``R`` applied to the mirrored incident pair; the transmitted pair keeps
``z`` and is ``T`` applied to the incident pair:

    R = [[2 d1 c1 h D,  c2 - 4 d1^2 c1 h^2 D^2],     T = [[c4, 2 (d1 c4 - d2 c5) h D],
         [c1,           -2 d1 c1 h D          ]]          [0,  c5                    ]]

(ref. Eq. 3.27 prints ``-2 (d1 c4 - d2 c5)``; that sign violates the continuity of
traction and displacement at the interface, which the ``+`` sign satisfies exactly.)

The same formulas hold for a pair hitting an interface from below (flip the vertical
axis: ``h D`` is unchanged). Applied repeatedly (ref. Fig. 3.4), each pair is a sum of
``A[j, n] D^n`` of the source's kernel, ``A`` polynomial in the source height ``t``;
``dA/dt`` is carried along (forward differentiation) because a displacement
discontinuity is a force dipole: the stress at ``y`` of a unit DD density ``b`` on a
plane of normal ``n`` at ``x`` is ``sum_pq M_pq d/dx_q sigma^(p)(y; x)`` with
``M_pq = lambda (b.n) delta_pq + G (b_p n_q + b_q n_p)`` of the source's layer and
``sigma^(p)`` the stress of a unit force along ``p`` (Aki & Richards, Eq. 3.20).

The 2D constant displacement of ref. Sec. 3.3.1 (Eqs 3.34-3.39) is a rigid translation
that does not depend on the source point: every DD quantity differentiates it away, so
it needs no correction here (it matters for a point-force displacement kernel only).

What is "complementary": in the source's layer, every image pair (the original is the
closed-form kernel of :mod:`hmatddm.kernels.line2d`); in any other layer, the
transmitted and reflected pairs minus the source layer's whole-plane (Kelvin) field,
because the callers add the closed-form kernel of the source's material at every
receiver. So with equal layers the complementary stress is exactly zero.

Length (over ~400 lines): the derivative tables of the Hansen potentials (checked by
``_derive_images2d``), the tracer of images through interfaces and the quadrature are
numba code that compiles as one unit; splitting them would spread one derivation.
"""
import math

import numpy as np
from numba import njit

from ..kernels import line2d
from ..kernels.drivers import KernelKind, kernel_record, register_kind

_INV_4PI = 1.0 / (4.0 * math.pi)


# -- tracing the image pairs (ref. Fig. 3.4) -------------------------------------------
@njit(cache=True)
def trace_capacity(source_layer, shear_modulus, n_images):
    """``(n_pairs, n_orders)``: room the tracer needs for a source in ``source_layer``
    (counted without pruning, so an upper bound)."""
    n_layers = shear_modulus.shape[0]
    cap = 2
    stack_layer = [source_layer, source_layer]
    stack_dir = [1, -1]
    stack_ref = [0, 0]
    stack_order = [0, 0]
    max_order = 0
    while len(stack_layer) > 0:
        layer = stack_layer.pop()
        direction = stack_dir.pop()
        nref = stack_ref.pop()
        order = stack_order.pop()
        far = layer - 1 if direction > 0 else layer + 1
        if far < 0 or far >= n_layers:
            continue
        if nref < n_images:
            cap += 1
            max_order = max(max_order, order + 2)
            stack_layer.append(layer)
            stack_dir.append(-direction)
            stack_ref.append(nref + 1)
            stack_order.append(order + 2)
        if shear_modulus[far] > 0.0:
            cap += 1
            max_order = max(max_order, order + 1)
            stack_layer.append(far)
            stack_dir.append(direction)
            stack_ref.append(nref)
            stack_order.append(order + 1)
    return cap, max_order + 1


@njit(cache=True)
def _apply(coef, power, h, dh, src, dsrc, dst, ddst, n_orders):
    """``dst += coef h^power D^power src`` and its derivative in the source height."""
    if coef == 0.0:
        return
    hp = h ** power
    dhp = power * h ** (power - 1) * dh if power > 0 else 0.0
    for n in range(n_orders - power):
        dst[n + power] += coef * hp * src[n]
        ddst[n + power] += coef * (dhp * src[n] + hp * dsrc[n])


#: The reflection (ref. Eq. 3.26) and transmission (Eq. 3.27) operators of
#: :func:`trace_potentials` as rows ``(potential receiving, potential applied, power of h D)``
#: (their coefficients are set per interface): one call of :func:`_apply` in a loop, so
#: its loop is compiled once rather than once per term (ten copies, a quarter of the
#: tracer's compile time).
_REFLECTION_ROWS = np.array([[0, 0, 1], [0, 1, 0], [0, 1, 2], [1, 0, 0], [1, 1, 1], [2, 2, 0]], dtype=np.int64)
_TRANSMISSION_ROWS = np.array([[0, 0, 0], [0, 1, 1], [1, 1, 0], [2, 2, 0]], dtype=np.int64)


@njit(cache=True)
def trace_potentials(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, original, parity, pair_layer,
                     pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef):
    """Reflect and transmit the potentials of a unit point force at height ``t`` in
    ``source_layer`` through the interfaces (ref. Fig. 3.4, Eqs 3.25-3.28): 2D pairs
    (``pair_coef`` (C, 2, 2, O)) and 3D triples ((C, 3, 3, O), the third potential
    reflected by ``c3`` and transmitted by ``c6``) alike.

    ``original[e]`` (2, F, J): the source's coefficients of ``D^0`` travelling up
    (``e = 0``) and down (``e = 1``); ``parity[f]``: sign of force ``f``'s potentials
    under mirroring in a horizontal plane (times ``(-1)^n`` for ``D^n``). Fills
    ``pair_layer[k]`` (layer the potentials live in), ``pair_z[k]`` (height they emanate
    from), ``pair_eps[k] = dz/dt`` (+-1), ``pair_sigma[k]`` (direction of travel: +1
    upward), ``pair_coef[k, f, j, n]`` (coefficient of ``D^n`` of potential ``j`` for a
    force along ``f``) and ``pair_dcoef`` = d/dt. Returns their number (the original
    excluded)."""
    n_layers = shear_modulus.shape[0]
    n_f = pair_coef.shape[1]
    n_j = pair_coef.shape[2]
    n_orders = pair_coef.shape[3]
    cap = pair_coef.shape[0]
    # work queue: the original twice (up and down), then every new image
    q_layer = np.empty(cap + 2, dtype=np.int64)
    q_dir = np.empty(cap + 2, dtype=np.int64)
    q_ref = np.empty(cap + 2, dtype=np.int64)
    q_z = np.empty(cap + 2)
    q_eps = np.empty(cap + 2)
    q_coef = np.zeros((cap + 2, n_f, n_j, n_orders))
    q_dcoef = np.zeros((cap + 2, n_f, n_j, n_orders))
    for e in range(2):
        q_layer[e] = source_layer
        q_dir[e] = 1 if e == 0 else -1
        q_ref[e] = 0
        q_z[e] = t
        q_eps[e] = 1.0
        q_coef[e, :, :, 0] = original[e]
    n_queue = 2
    mirrored = np.empty((n_f, n_j, n_orders))
    dmirrored = np.empty((n_f, n_j, n_orders))
    row_coef = np.empty(6)
    reflection_rows = 5 if n_j == 2 else 6  # the third potential (3D) has one more
    transmission_rows = 3 if n_j == 2 else 4
    i = 0
    while i < n_queue:
        layer = q_layer[i]
        direction = q_dir[i]
        far = layer - 1 if direction > 0 else layer + 1
        if far < 0 or far >= n_layers:
            i += 1
            continue
        d = interfaces[layer - 1] if direction > 0 else interfaces[layer]
        h = q_z[i] - d
        dh = q_eps[i]
        g1 = shear_modulus[layer]
        g2 = shear_modulus[far]
        d1 = 1.0 / (3.0 - 4.0 * poisson_ratio[layer])
        d2 = 1.0 / (3.0 - 4.0 * poisson_ratio[far])
        gamma = g2 / g1
        c1 = (gamma - 1.0) / (gamma + d1)                 # ref. Eq. 3.28
        c2 = (gamma * d2 - d1) / (gamma * d2 + 1.0)
        c3 = (1.0 - gamma) / (1.0 + gamma)                # (3D; zero only where c1 is)
        c4 = 1.0 - c1
        c5 = 1.0 - c2
        c6 = 1.0 + c3
        if q_ref[i] < n_images and (c1 != 0.0 or c2 != 0.0):
            k = n_queue
            for f in range(n_f):
                for j in range(n_j):
                    for n in range(n_orders):
                        sign = parity[f] if n % 2 == 0 else -parity[f]
                        mirrored[f, j, n] = sign * q_coef[i, f, j, n]
                        dmirrored[f, j, n] = sign * q_dcoef[i, f, j, n]
            # the mirrored potentials emanate from z' = 2d - z (dz'/dt = -dz/dt, below)
            # ref. Eq. 3.26, rows of _REFLECTION_ROWS
            row_coef[0] = 2.0 * d1 * c1
            row_coef[1] = c2
            row_coef[2] = -4.0 * d1 * d1 * c1
            row_coef[3] = c1
            row_coef[4] = -2.0 * d1 * c1
            row_coef[5] = c3
            for f in range(n_f):
                for r in range(reflection_rows):
                    to, of, power = _REFLECTION_ROWS[r, 0], _REFLECTION_ROWS[r, 1], _REFLECTION_ROWS[r, 2]
                    _apply(row_coef[r], power, h, dh, mirrored[f, of], dmirrored[f, of], q_coef[k, f, to],
                           q_dcoef[k, f, to], n_orders)
            q_layer[k] = layer
            q_dir[k] = -direction
            q_ref[k] = q_ref[i] + 1
            q_z[k] = 2.0 * d - q_z[i]
            q_eps[k] = -q_eps[i]
            n_queue += 1
        if g2 > 0.0:
            k = n_queue
            # ref. Eq. 3.27, but T12 = +2 (d1 c4 - d2 c5) h D: the reference prints a minus
            # sign, which breaks the interface conditions (_derive_images2d.py derives +)
            row_coef[0] = c4
            row_coef[1] = 2.0 * (d1 * c4 - d2 * c5)
            row_coef[2] = c5
            row_coef[3] = c6
            for f in range(n_f):
                for r in range(transmission_rows):
                    to, of, power = _TRANSMISSION_ROWS[r, 0], _TRANSMISSION_ROWS[r, 1], _TRANSMISSION_ROWS[r, 2]
                    _apply(row_coef[r], power, h, dh, q_coef[i, f, of], q_dcoef[i, f, of], q_coef[k, f, to],
                           q_dcoef[k, f, to], n_orders)
            q_layer[k] = far
            q_dir[k] = direction
            q_ref[k] = q_ref[i]
            q_z[k] = q_z[i]
            q_eps[k] = q_eps[i]
            n_queue += 1
        i += 1
    n_out = 0
    for k in range(2, n_queue):
        pair_layer[n_out] = q_layer[k]
        pair_z[n_out] = q_z[k]
        pair_eps[n_out] = q_eps[k]
        pair_sigma[n_out] = float(q_dir[k])
        pair_coef[n_out] = q_coef[k]
        pair_dcoef[n_out] = q_dcoef[k]
        n_out += 1
    return n_out


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


# -- stress of one pair ------------------------------------------------------------------
@njit(cache=True)
def _potential_table(coef, dcoef, beta, n_orders, table, dtable):
    """``table[j, a, b] = sum_n coef[j, n] beta[a, b + n]`` (derivative d1^a d3^b of
    potential j) for ``a + b`` = 3, 4, and ``dtable`` the same with ``dcoef`` for
    ``a + b`` = 2, 3: the entries :func:`_pair_stress_gradient` reads."""
    for j in range(2):
        for a in range(5):
            for b in range(max(0, 2 - a), 5 - a):
                order = a + b
                if order >= 3:
                    s = 0.0
                    for n in range(n_orders):
                        s += coef[j, n] * beta[a, b + n]
                    table[j, a, b] = s
                if order <= 3:
                    ds = 0.0
                    for n in range(n_orders):
                        ds += dcoef[j, n] * beta[a, b + n]
                    dtable[j, a, b] = ds


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
def pair_stress_gradient(r1, r3, eps, coef, dcoef, n_orders, delta, shear_modulus, lame, out):
    """``out[f, q, c] +=`` derivative along the source coordinate ``q`` (0: x, 1: y) of
    the stress component ``c`` (0: xx, 1: xy, 2: yy) at a receiver ``(r1, r3)`` from the
    point the pair emanates from, for a unit force along ``f``. ``delta``, shear modulus
    and Lame constant are the receiver layer's; ``eps = dz/dt``."""
    work = Workspace(n_orders)
    _pair_stress_gradient(r1, r3, eps, coef, dcoef, n_orders, delta, shear_modulus, lame, out, work)


@njit(cache=True)
def Workspace(n_orders):
    """Scratch arrays of :func:`_pair_stress_gradient` (allocated once per caller)."""
    return (np.empty(n_orders + 6, dtype=np.complex128), np.zeros((5, n_orders + 5)), np.empty((2, 5, 5)),
            np.empty((2, 5, 5)), np.empty(4))


@njit(cache=True)
def _pair_stress_gradient(r1, r3, eps, coef, dcoef, n_orders, delta, shear_modulus, lame, out, work):
    gk, beta, table, dtable, grad = work
    # highest order of D with a non-zero coefficient (most pairs stop well below n_orders)
    used = 1
    for f in range(2):
        for j in range(2):
            for n in range(n_orders - 1, used - 1, -1):
                if coef[f, j, n] != 0.0 or dcoef[f, j, n] != 0.0:
                    used = n + 1
                    break
    n_orders = used
    w = complex(r1, r3)
    inv = 1.0 / w
    kmax = 3 + n_orders  # a + b <= 4 in the tables, plus D^(n_orders - 1)
    gk[2] = inv
    power = inv
    fact = 1.0
    for k in range(3, kmax + 1):
        power = power * inv
        fact *= (k - 2)
        gk[k] = fact * power if k % 2 == 0 else -fact * power
    for f in range(2):
        for a in range(5):
            ib = complex(1.0, 0.0)
            for b in range(kmax + 1 - a):
                if a + b >= 2:
                    v = ib * gk[a + b]
                    beta[a, b] = -v.real if f == 0 else -v.imag
                ib = ib * 1j
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
    n_orders = pair_coef.shape[-1]
    g_r = shear_modulus[receiver_layer]
    nu_r = poisson_ratio[receiver_layer]
    delta_r = 1.0 / (3.0 - 4.0 * nu_r)
    lame_r = _lame(g_r, nu_r)
    for k in range(n_pairs):
        if pair_layer[k] == receiver_layer:
            _pair_stress_gradient(y1 - x1, y3 - pair_z[k], pair_eps[k], pair_coef[k], pair_dcoef[k], n_orders,
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
        _pair_stress_gradient(y1 - x1, y3 - t, 1.0, coef, dcoef, 1, delta_s, g_s, _lame(g_s, nu_s), gradient, work1)


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
    pair_stress_gradient(y1 - x1, y3 - x3, 1.0, coef, dcoef, 1, delta, shear_modulus, lame, gradient)
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
def trace_points(p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, untraced=False):
    """The image pairs of the source points ``x(xi)`` of the element ``p0 -> p1``:
    ``(n_pairs (G,), layer (G, P), z (G, P), eps (G, P), coef (G, P, 2, 2, O), dcoef)``.
    ``untraced``: only allocate (fill ranges later with :func:`_trace_range`)."""
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    n_points = xi.shape[0]
    traced = (np.zeros(n_points, dtype=np.int64), np.empty((n_points, cap), dtype=np.int64),
              np.empty((n_points, cap)), np.empty((n_points, cap)), np.zeros((n_points, cap, 2, 2, n_orders)),
              np.zeros((n_points, cap, 2, 2, n_orders)))
    if not untraced:
        _trace_range(p0, p1, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, 0, n_points,
                     traced)
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


@njit(cache=True)
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
               0, out, np.empty((2, 2, 3)), Workspace(traced[4].shape[-1]), Workspace(1))


# -- quadrature ----------------------------------------------------------------------------
@njit(cache=True)
def gauss_legendre(n):
    """Nodes and weights of the ``n``-point Gauss-Legendre rule on [-1, 1] (Newton on
    the Legendre recurrence)."""
    x = np.empty(n)
    w = np.empty(n)
    for i in range(n):
        z = math.cos(math.pi * (i + 0.75) / (n + 0.5))
        for _ in range(100):
            p0 = 1.0
            p1 = 0.0
            for k in range(1, n + 1):
                p2 = p1
                p1 = p0
                p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k
            dp = n * (z * p0 - p1) / (z * z - 1.0)
            dz = p0 / dp
            z -= dz
            if abs(dz) < 1e-15:
                break
        x[i] = z
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp)
    return x, w


@njit(cache=True)
def composite_rule(n_gauss, n_sub):
    """``n_gauss`` Gauss points on each of ``n_sub`` equal sub-segments of [-1, 1]."""
    x, w = gauss_legendre(n_gauss)
    xi = np.empty(n_gauss * n_sub)
    wt = np.empty(n_gauss * n_sub)
    for s in range(n_sub):
        lo = -1.0 + 2.0 * s / n_sub
        for g in range(n_gauss):
            xi[s * n_gauss + g] = lo + (x[g] + 1.0) / n_sub
            wt[s * n_gauss + g] = w[g] / n_sub
    return xi, wt


@njit(cache=True)
def _segment_distance(px, py, ax, ay, bx, by):
    ex = bx - ax
    ey = by - ay
    ll = ex * ex + ey * ey
    u = ((px - ax) * ex + (py - ay) * ey) / ll if ll > 0.0 else 0.0
    u = min(1.0, max(0.0, u))
    dx = px - ax - u * ex
    dy = py - ay - u * ey
    return math.sqrt(dx * dx + dy * dy)


@njit(cache=True)
def subdivisions(y1, y3, receiver_layer, p0, p1, source_layer, interfaces, max_sub):
    """Sub-segments so that each is at most half as long as the distance from the
    receiver to the nearest singular point of the integrand: the element's mirror
    images in the interfaces bounding the source's and the receiver's layers, and the
    element itself when the receiver is in another layer."""
    length = math.sqrt((p1[0] - p0[0]) ** 2 + (p1[1] - p0[1]) ** 2)
    dmin = np.inf
    if receiver_layer != source_layer:
        dmin = _segment_distance(y1, y3, p0[0], p0[1], p1[0], p1[1])
    n_if = interfaces.shape[0]
    for layer in (source_layer, receiver_layer):
        for k in (layer - 1, layer):
            if 0 <= k < n_if:
                d = interfaces[k]
                dmin = min(dmin, _segment_distance(y1, y3, p0[0], 2.0 * d - p0[1], p1[0], 2.0 * d - p1[1]))
    if dmin <= 0.0:
        return max_sub
    n = int(math.ceil(2.0 * length / dmin))
    return min(max(n, 1), max_sub)


# -- constant elements: the kernel data and the per-pair functions of the drivers -----------
#: Sub-segment levels (2^level sub-segments) whose traced pairs a source keeps.
_CACHED_LEVELS = 4


@njit(cache=True)
def _level(n_sub):
    """The smallest level with 2^level >= n_sub sub-segments."""
    level = 0
    while 2 ** level < n_sub:
        level += 1
    return level


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
        xi[start[level]:start[level + 1]] = x
        w[start[level]:start[level + 1]] = wt
    return xi, w, start


#: The medium fields of every record of 2D segments in a layered medium (after the geometry).
LAYERED_FIELDS = (
    ("layer", np.ndarray, "(N,) int64 layer of each element"),
    ("interfaces", np.ndarray, "(L - 1,) interface heights, top down"),
    ("shear_modulus", np.ndarray, "(L,) per layer (0: void)"),
    ("poisson_ratio", np.ndarray, "(L,) per layer"),
    ("n_images", int, "reflections per interface (ref. Fig. 3.4)"),
    ("gauss_points", int, "Gauss-Legendre points per sub-segment of the image quadrature (ref. Table 3.2)"),
    ("max_subdivisions", int, "largest number of sub-segments (:func:`hmatddm.layered.images2d.subdivisions`)"))
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
    traced = trace_points(p0, p1, ls, data.interfaces, data.shear_modulus, data.poisson_ratio, data.n_images,
                          xi, True)
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
        level = _level(subdivisions(point[0], point[1], lr, p0, p1, ls, interfaces, data.max_subdivisions))
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
    g = data.shear_modulus
    nu = data.poisson_ratio
    if g[point_layer] <= 0.0:
        out[:] = 0.0
        return
    ls = data.layer[j]
    a = data.half_length[j]
    line2d.stress_pair(point, data.centers[j], data.frames[j], a, g[ls], nu[ls], data.singular_shift, out,
                       local, data.near_fraction * a)
    if data.interfaces.shape[0] > 0:
        p0 = data.centers[j] - a * data.frames[j, 0]
        p1 = data.centers[j] + a * data.frames[j, 0]
        level = _level(subdivisions(point[0], point[1], point_layer, p0, p1, ls, data.interfaces,
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
