"""The image method's tracer (ref. Sec. 3.2, Fig. 3.4): the Hansen potentials of a point
force reflected and transmitted through the interfaces of a plane-layered medium, for the 2D
pairs of :mod:`hmatddm.layered.images2d` and the 3D triples of :mod:`hmatddm.layered.image_tracer3d`.

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
"""
import numpy as np
from numba import njit


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
def largest_trace_capacity(shear_modulus, n_images):
    """``(n_pairs, n_orders)`` enough for a source in any solid layer (:func:`trace_capacity`
    over the layers of positive shear modulus; at least ``(1, 1)``)."""
    cap = 1
    n_orders = 1
    for source_layer in range(shear_modulus.shape[0]):
        if shear_modulus[source_layer] > 0.0:
            c, o = trace_capacity(source_layer, shear_modulus, n_images)
            cap = max(cap, c)
            n_orders = max(n_orders, o)
    return cap, n_orders


@njit(cache=True, inline="always")
def orders_used(coef, dcoef):
    """One more than the highest power of ``D`` with a non-zero coefficient in ``coef`` or
    ``dcoef`` ``[f, j, n]`` (at least 1): most traced pairs and triples stop well below the
    buffer's order. Inlined: a call would make its caller take and drop a reference count
    on each of its array arguments (:func:`.potentials3d._pair_stress_gradient`)."""
    used = 1
    for f in range(coef.shape[0]):
        for j in range(coef.shape[1]):
            for n in range(coef.shape[2] - 1, used - 1, -1):
                if coef[f, j, n] != 0.0 or dcoef[f, j, n] != 0.0:
                    used = n + 1
                    break
    return used


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
        # element by element, not by slice assignment (docs/conventions.md, §5)
        for f in range(n_f):
            for j in range(n_j):
                q_coef[e, f, j, 0] = original[e, f, j]
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
        for f in range(n_f):
            for j in range(n_j):
                for n in range(n_orders):
                    pair_coef[n_out, f, j, n] = q_coef[k, f, j, n]
                    pair_dcoef[n_out, f, j, n] = q_dcoef[k, f, j, n]
        n_out += 1
    return n_out
