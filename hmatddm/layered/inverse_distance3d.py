"""The derivatives of ``1/r`` in 3D to any order (ref. Sec. 3.2: every vertical derivative
of the base functions of :mod:`.potentials3d` is one of them), by the three-term recurrence
of their Taylor coefficients: the whole table (:func:`inverse_distance_derivatives`), its
unscaled recurrence and its scaling written into any table, shifted and signed
(:func:`inverse_distance_recurrence`, :func:`scaled_inverse_distance`: the gauge table of
:func:`.potentials3d.gauge_table`), and one entry from the lower orders
(:func:`inverse_distance_step`).

The recurrence and the scaling compile with :data:`hmatddm.compiled.FAST` and numpy's
error model: their divisions are by ``r > 0`` (a receiver is never at a triple's point)
and by the order ``n >= 1``, so no division by zero is checked for; the reassociated sums
change the entries by round-off only.
"""
import math

import numpy as np
from numba import njit

from ..compiled import FAST


@njit(cache=True, inline="always")
def inverse_distance_step(q, a, b, c, n, x0, x1, x2):
    """One entry (orders ``a, b, c``, ``n = a + b + c``) of the recurrence of the unscaled
    derivatives of ``1/r`` from the lower orders already in ``q`` (``x_k = r_k / r``)."""
    s = 0.0
    if a >= 1:
        s += x0 * q[a - 1, b, c]
    if b >= 1:
        s += x1 * q[a, b - 1, c]
    if c >= 1:
        s += x2 * q[a, b, c - 1]
    s *= 2 * n - 1
    t = 0.0
    if a >= 2:
        t += q[a - 2, b, c]
    if b >= 2:
        t += q[a, b - 2, c]
    if c >= 2:
        t += q[a, b, c - 2]
    return -(s + (n - 1) * t) / n


@njit(cache=True, inline="always")
def inverse_distance_scratch(n_c):
    """The zeroed scratch of :func:`inverse_distance_derivatives` for ``q`` of up to
    ``(6, 6, n_c)``."""
    return np.zeros((8, 8, n_c + 2))


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def inverse_distance_recurrence(r1, r2, r3, pad, ha, nc, top):
    """The unscaled Taylor coefficients ``t_k = d^k (1/r) / k!`` on the unit vector of
    ``(r1, r2, r3)`` into ``pad[a + 2, b + 2, c + 2]`` for ``a + b < ha``, ``c < nc`` and
    ``a + b + c <= top`` (:func:`inverse_distance_derivatives`); returns ``1/r``. By total
    order, one reciprocal each: the entries of an order are independent, where the loops
    along ``b`` chained every entry's division to the previous one (3x slower)."""
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    inv = 1.0 / r
    x0 = r1 * inv
    x1 = r2 * inv
    x2 = r3 * inv
    pad[2, 2, 2] = 1.0
    for n in range(1, top + 1):  # by total order: the entries of one order are independent
        rn = 1.0 / n
        w1 = 2 * n - 1
        w2 = n - 1
        for c in range(max(0, n - ha + 1), min(nc, n + 1)):
            for a in range(n - c + 1):
                i = a + 2
                j = n - c - a + 2
                k = c + 2
                s = (x0 * pad[i - 1, j, k] + x1 * pad[i, j - 1, k] + x2 * pad[i, j, k - 1]) * w1
                t = pad[i - 2, j, k] + pad[i, j - 2, k] + pad[i, j, k - 2]
                pad[i, j, k] = -(s + w2 * t) * rn
    return inv


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def scaled_inverse_distance(pad, inv, q, shift, sign, ha, nc, top):
    """``q[a, b, c + shift] = sign d1^a d2^b d3^c (1/r)`` from the coefficients of
    :func:`inverse_distance_recurrence` (``t_k / r^(n+1) a! b! c!``), for its ranges."""
    fc = inv
    for c in range(min(nc, top + 1)):
        if c > 0:
            fc *= c * inv
        fa = fc
        for a in range(min(ha, top - c + 1)):
            if a > 0:
                fa *= a * inv
            fb = fa
            for b in range(min(ha - a, top - c - a + 1)):
                if b > 0:
                    fb *= b * inv
                q[a, b, c + shift] = sign * pad[a + 2, b + 2, c + 2] * fb


@njit(cache=True)
def inverse_distance_derivatives(r1, r2, r3, q, pad, top):
    """``q[a, b, c] = d1^a d2^b d3^c (1/r)`` for ``a + b < q.shape[0]``, ``c < q.shape[2]``
    and a total order ``a + b + c <= top`` (the entries above it are not written) by the
    recurrence of the Taylor coefficients ``t_k = d^k (1/r) / k!``:
    ``n r^2 t_k + (2n - 1) sum_i r_i t_(k - e_i) + (n - 1) sum_i t_(k - 2 e_i) = 0``
    (here on the unit vector, then scaled). The recurrence runs in ``pad`` (at least
    ``(q.shape[0] + 2, q.shape[0] + 2, q.shape[2] + 2)``, :func:`inverse_distance_scratch`)
    shifted by two in every index, whose entries below index 2 stay zero: the terms of
    orders below zero read zeros instead of branching (1.8x faster than the branches of
    :func:`inverse_distance_step`)."""
    inv = inverse_distance_recurrence(r1, r2, r3, pad, q.shape[0], q.shape[2], top)
    scaled_inverse_distance(pad, inv, q, 0, 1.0, q.shape[0], q.shape[2], top)
