"""The Hansen potentials of a point force in 3D and the field of one image triple (ref.
Secs 3.2-3.3, Eqs 3.14-3.17, 3.22, 3.24): the point-force potentials in a gauge, the
derivatives of their base functions, the stress and displacement gradients of one traced
triple at a receiver, and the moment-tensor contraction that makes them the field of a DD
density. The tracer of the triples is :mod:`.image_tracer3d`, their sum at a receiver
:mod:`.image_points3d`, the entry of the 3D image method :mod:`.images3d`.

Coordinates: ``(x, y, z)`` with ``z`` vertical (the reference's ``x3``); interfaces are
the planes ``z = d_k`` (see :class:`LayeredMedium`, docs/conventions.md §3).

Hansen potentials (ref. Eqs 3.14-3.17, 3.22). A potential triple ``(phi1, phi2, phi3)``
in a layer of ``delta = 1/(3 - 4 nu)`` gives the displacement

    u_i = phi1,i - phi2,i - 2 delta s phi2,i3 + 2 delta_i3 phi2,3 + eps_ij3 phi3,j

with ``s = y3 - z`` the height above the point ``z`` the triple emanates from. (Ref. Eq.
3.22 prints ``+Phi_i3,1`` in ``U_i2``; Eq. 3.17 gives ``-phi3,1``, which is what
reproduces Kelvin's solution.) The point-force kernel of ref. Eq. 3.24 is written with two
harmonic base functions in a *gauge* ``sigma = +-1`` (``u = r + sigma r3``):

    F = r - sigma r3 log u,   L = log u          (singular on the half-line sigma r3 < 0)

    force x: phi = K (d1 F, -d1 F,  2 (1 + delta) d2 F)
    force y: phi = K (d2 F, -d2 F, -2 (1 + delta) d1 F)
    force z: phi = K sigma (L, L, 0),            K = 1/(8 pi G (1 + delta))

Eq. 3.24's ``r1 r / rh^2`` equals ``d1 F`` plus ``d1 (sigma r3 log rh)``, a term singular on
the whole vertical that produces no displacement; the gauge moves the singular line to
the half-line pointing away from the receivers, so every image is regular where it is
evaluated (``_derive_images3d.py`` checks these coefficients against Kelvin's solution).

Derivatives. ``D F = -sigma L``, ``D L = sigma / r``, so every derivative with a vertical
part is a derivative of ``1/r``, whose Taylor coefficients follow a three-term recurrence
(any order). Horizontal derivatives (up to order 5) of ``F`` and ``L`` come from
one-variable Taylor series along x of the closed forms of ``d1 F``, ``d2 F``, ``d1 L``,
``d2 L`` and from Laplace's equation (both are harmonic) for the higher ``d2`` powers.

Cost (issue 32). The field of one triple at one point is the inner loop of the near-image
quadrature and of the remainder table's sampling. Its functions compile with
:data:`hmatddm.compiled.FAST` and numpy's error model (their divisions are by ``r > 0``,
``r + sigma r3 > 0`` and integer orders: nothing to check), and everything
:func:`_pair_stress_gradient` calls is inlined (numba's ``inline="always"``) and indexes
its arrays whole: a call, or a view such as ``table[f, j]``, makes numba take and drop a
reference count on each array (atomic operations: 36 a triple, a third of its cost
before). One table of ``F`` serves both base functions (:func:`gauge_table`).
"""
import math

import numpy as np
from numba import njit

from ..compiled import FAST
from .image_tracer import orders_used
from .inverse_distance3d import (inverse_distance_derivatives, inverse_distance_recurrence,  # noqa: F401 (re-exported)
                                 inverse_distance_scratch, inverse_distance_step, scaled_inverse_distance)

_INV_8PI = 1.0 / (8.0 * math.pi)


@njit(cache=True)
def _original(coef, delta, shear_modulus, sigma, scale):
    """``coef[f, j, 0] += scale *`` the point-force potentials of gauge ``sigma`` (ref. Eq. 3.24)."""
    k = _INV_8PI / (shear_modulus * (1.0 + delta))
    coef[0, 0, 0] += scale * k
    coef[0, 1, 0] -= scale * k
    coef[0, 2, 0] += scale * 2.0 * (1.0 + delta) * k
    coef[1, 0, 0] += scale * k
    coef[1, 1, 0] -= scale * k
    coef[1, 2, 0] -= scale * 2.0 * (1.0 + delta) * k
    coef[2, 0, 0] += scale * sigma * k
    coef[2, 1, 0] += scale * sigma * k


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def _axis_series(r1, r3, r, m, ser):
    """Taylor coefficients (``k < m``) in ``t`` at ``(r1 + t, r2, r3)``, gauge +1, ``U = R + r3``:
    ``ser[0] = R``, ``ser[1] = 1/R``, ``ser[2] = V = 1/U``, ``ser[3] = W = V/R``. Its callers
    keep ``r > 0`` and ``U > 0`` (numpy's error model: no check of the divisions); ``ser``
    indexed whole, not by row views (each view a reference count taken and dropped)."""
    u0 = r + r3
    ser[0, 0] = r
    ser[1, 0] = 1.0 / r
    ser[2, 0] = 1.0 / u0
    for k in range(1, m):
        s = 2.0 * r1 if k == 1 else (1.0 if k == 2 else 0.0)  # R^2 = r^2 + 2 r1 t + t^2
        for i in range(1, k):
            s -= ser[0, i] * ser[0, k - i]
        ser[0, k] = s / (2.0 * r)
        s_ir = 0.0
        s_v = 0.0
        for i in range(1, k + 1):
            s_ir += ser[0, i] * ser[1, k - i]
            s_v += ser[0, i] * ser[2, k - i]  # U_i = R_i for i >= 1
        ser[1, k] = -s_ir / r
        ser[2, k] = -s_v / u0
    for k in range(m):
        s = 0.0
        for i in range(k + 1):
            s += ser[2, i] * ser[1, k - i]
        ser[3, k] = s


@njit(cache=True)
def base_derivatives(r1, r2, r3, sf, sl, q, ser, pad, top):
    """Derivatives of the gauge +1 base functions at ``(r1, r2, r3)``, ``r3 >= 0`` (away
    from the singular half-line): ``q[a, b, c] = d1^a d2^b d3^c (1/r)`` (``q``'s shape up
    to the total order ``top``, at least 4, :func:`inverse_distance_derivatives`),
    ``sf[a, b] = d1^a d2^b F`` and ``sl[a, b] = d1^a d2^b L`` for ``a + b <= 5``
    (:func:`_axis_derivatives`), the higher ``d2`` powers from Laplace's equation,
    ``d2^2 F = -d1^2 F + 1/r``, ``d2^2 L = -d1^2 L - d3 (1/r)`` (``F`` and ``L`` are
    harmonic; ``ser``: (4, 6) scratch; ``pad``: the scratch of
    :func:`inverse_distance_derivatives`)."""
    inverse_distance_derivatives(r1, r2, r3, q, pad, top)
    _axis_derivatives(r1, r2, r3, sf, sl, ser)
    for b in range(2, 6):
        for a in range(6 - b):
            sf[a, b] = -sf[a + 2, b - 2] + q[a, b - 2, 0]
            sl[a, b] = -sl[a + 2, b - 2] - q[a, b - 2, 1]


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def _axis_derivatives(r1, r2, r3, sf, sl, ser):
    """``sf[a, b] = d1^a d2^b F``, ``sl[a, b] = d1^a d2^b L`` of gauge +1 for ``b <= 1``,
    ``a + b <= 5`` (:func:`base_derivatives`), along x from one-variable Taylor series of
    the closed forms ``d1 F = r1 / U``, ``d1 L = r1 / (R U)``, ``d2 F = r2 / U``,
    ``d2 L = r2 / (R U)`` (``U = r + r3``, no cancelling terms). Numpy's error model: the
    divisions are by ``r > 0`` and ``r + r3 > 0`` (``r3 >= 0``)."""
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    _axis_series(r1, r3, r, 5, ser)
    sf[0, 0] = r - r3 * math.log(r + r3)
    sl[0, 0] = math.log(r + r3)
    fact = 1.0  # (a - 1)!
    for a in range(1, 6):
        if a > 1:
            fact *= a - 1
        sf[a, 0] = fact * (r1 * ser[2, a - 1] + (ser[2, a - 2] if a >= 2 else 0.0))
        sl[a, 0] = fact * (r1 * ser[3, a - 1] + (ser[3, a - 2] if a >= 2 else 0.0))
    fact = 1.0  # a!
    for a in range(5):
        if a > 0:
            fact *= a
        sf[a, 1] = fact * r2 * ser[2, a]
        sl[a, 1] = fact * r2 * ser[3, a]


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def gauge_table(r1, r2, r3, sigma, n_c, top, sf, sl, ser, h, pad):
    """``h[a, b, c] = d1^a d2^b d3^c F`` of gauge ``sigma`` at ``(r1, r2, r3)`` (``sigma r3
    >= 0``) for ``a + b <= 5``, ``c <= n_c`` and a total order up to ``top + 2`` (the
    other entries not written): every table a triple reads, ``L`` included, since ``D F
    = -sigma L`` (the ``L`` table is ``-sigma h`` shifted by one in ``c``). ``c <= 1`` from
    :func:`_axis_derivatives` at the flipped point (``d3 F = -sigma L``), ``c >= 2`` from
    ``d3^2 F = -1/r`` (:func:`inverse_distance_recurrence` at the receiver: ``1/r``'s
    vertical derivatives at the flipped point are ``sigma^c`` times those, which the
    tables of :func:`_base_table` multiply back) written straight into ``h`` -- no
    copy, no ``L`` table. The same entries as :func:`_base_table`'s, to the signs (exact)."""
    inv = inverse_distance_recurrence(r1, r2, r3, pad, 6, n_c - 1, top)
    scaled_inverse_distance(pad, inv, h, 2, -1.0, 6, n_c - 1, top)
    _axis_derivatives(r1, r2, sigma * r3, sf, sl, ser)
    for b in range(2, 6):  # Laplace (base_derivatives): 1/r at the flipped point is -h[..., 2], sigma h[..., 3]
        for a in range(6 - b):
            sf[a, b] = -sf[a + 2, b - 2] - h[a, b - 2, 2]
            sl[a, b] = -sl[a + 2, b - 2] + sigma * h[a, b - 2, 3]
    for a in range(6):
        for b in range(6 - a):
            h[a, b, 0] = sf[a, b]
            h[a, b, 1] = -sigma * sl[a, b]


@njit(cache=True)
def _base_table(sigma, n_c, sf, sl, q, base, q_top):
    """``base[kind, a, b, c] = d1^a d2^b d3^c`` of ``F`` (kind 0) or ``L`` (kind 1) of
    gauge ``sigma`` (``a + b <= 5``, ``c < n_c``), from the gauge +1 derivatives at the
    flipped point: ``sigma^c`` times ``sf``/``sl``/``q`` (``d3 F = -L``, ``d3 L = 1/r``),
    where ``q`` holds them (its total order up to ``q_top``; the other entries not written).
    The bound is the array's size, not the constant 6: LLVM unrolls constant loops of this
    copy into ~17k instructions, a third of the compile time of every caller."""
    top = sf.shape[0]
    flip = -1.0 if sigma < 0.0 else 1.0
    for a in range(top):
        for b in range(top - a):
            base[0, a, b, 0] = sf[a, b]
            base[1, a, b, 0] = sl[a, b]
            sign = flip
            if n_c > 1:
                base[0, a, b, 1] = -sign * sl[a, b]
                if a + b <= q_top:
                    base[1, a, b, 1] = sign * q[a, b, 0]
            for c in range(2, min(n_c, q_top + 3 - a - b)):
                sign *= flip
                base[0, a, b, c] = -sign * q[a, b, c - 2]
                if c - 1 + a + b <= q_top:
                    base[1, a, b, c] = sign * q[a, b, c - 1]


@njit(cache=True, inline="always")
def potential_base(f, j):
    """``(kind, ia, ib)``: the base function of force ``f``'s potential ``phi_j`` -- ``L``
    (``kind`` 1) for ``f = 2``, else ``F`` (``kind`` 0) differentiated once along ``x1``
    (``ia``) or ``x2`` (``ib``) -- as the indices into a base table ``base[kind, a + ia, b +
    ib, ...]`` (ref. Eqs 3.14-3.17)."""
    if f == 2:
        return 1, 0, 0
    if (f == 0) == (j < 2):
        return 0, 1, 0
    return 0, 0, 1


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def _potential_table(coef, h, sigma, order, used, table):
    """``table[f, j, a, b, c] = d1^a d2^b d3^c phi_j`` of force ``f`` for the triple
    ``coef`` (``phi_j = sum_n coef[f, j, n] D^n`` of its base function ``d1 F``, ``d2 F``
    or ``L = -sigma D F``, from the gauge table ``h`` of :func:`gauge_table`; ``used``:
    :func:`.image_tracer.orders_used`): the orders the stress needs, ``a + b + c =
    order``, and ``order + 1`` for ``phi_2``, the only one with the ``s`` term of ref. Eq.
    3.22. The up to three terms of most triples (near ones: 1 to 3) are written out, the
    missing ones with a zero coefficient: ``h``'s entries past those computed are zero or
    left by an earlier triple, finite (:func:`Workspace`), so the sum is the same; LLVM
    unrolls it (a loop of run-time length was 1.4x slower)."""
    for f in range(3):
        for j in range(3):
            if f == 2 and j == 2:
                continue
            kind, ia, ib = potential_base(f, j)
            n0 = 0
            while n0 < used and coef[f, j, n0] == 0.0:
                n0 += 1
            n1 = used
            while n1 > n0 and coef[f, j, n1 - 1] == 0.0:
                n1 -= 1
            m = n1 - n0
            ic = kind + n0  # L = -sigma D F
            scale = -sigma if kind == 1 else 1.0
            k0 = scale * coef[f, j, n0] if m >= 1 else 0.0
            k1 = scale * coef[f, j, n0 + 1] if m >= 2 else 0.0
            k2 = scale * coef[f, j, n0 + 2] if m >= 3 else 0.0
            top = order + 1 if j == 1 else order
            for o in range(order, top + 1):
                for a in range(o + 1):
                    for b in range(o + 1 - a):
                        c = o - a - b
                        e = c + ic
                        if m <= 3:
                            v = (k0 * h[a + ia, b + ib, e] + k1 * h[a + ia, b + ib, e + 1]
                                 + k2 * h[a + ia, b + ib, e + 2])
                        else:
                            v = 0.0
                            for n in range(m):
                                v += scale * coef[f, j, n0 + n] * h[a + ia, b + ib, e + n]
                        table[f, j, a, b, c] = v


@njit(cache=True, inline="always")
def Workspace(n_orders):
    """Scratch arrays of :func:`_pair_stress_gradient` for triples of up to ``n_orders``:
    ``sf, sl`` (6, 6), the series (4, 6), the gauge table (6, 6, n_orders + 7) of
    :func:`gauge_table` (zeroed, and two more entries than it writes, read with a zero
    coefficient by :func:`_potential_table`), the potential tables (3, 3, 6, 6, 6) and
    the recurrence's zero-padded scratch (:func:`inverse_distance_scratch`)."""
    return (np.empty((6, 6)), np.empty((6, 6)), np.empty((4, 6)), np.zeros((6, 6, n_orders + 7)),
            np.zeros((3, 3, 6, 6, 6)), np.zeros((3, 3, 6, 6, 6)), inverse_distance_scratch(n_orders + 4))


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def _pair_tables(r1, r2, r3, sigma, coef, dcoef, order, work):
    """Fill ``work``'s potential tables of the triple at the receiver ``r`` (relative to
    the triple's point): ``coef`` at ``order`` (3 for the stress, 2 for the displacement),
    ``dcoef`` one lower."""
    sf, sl, ser, h, table, dtable, pad = work
    used = orders_used(coef, dcoef)
    n_c = order + used + 1
    # the tables read F's derivatives up to the total order n_c, that is 1/r's up to
    # n_c - 2 (d3^2 F = -1/r), and the Laplace relations 1/r's up to 4: computing no
    # more halves the recurrence
    top = max(n_c - 2, 4)
    gauge_table(r1, r2, r3, sigma, n_c, top, sf, sl, ser, h, pad)
    for d in range(2):  # one inlined _potential_table for both
        _potential_table(dcoef if d else coef, h, sigma, order - d, used, dtable if d else table)


@njit(cache=True)
def _stress(table, f, da, db, dc, scale, s, delta, shear_modulus, lame, out):
    """``out[i, k] += scale *`` the stress of force ``f`` from the potential derivatives
    ``table`` shifted by ``(da, db, dc)`` (:func:`_stress_at`, ``out`` (3, 3))."""
    _stress_at(table, f, da, db, dc, scale, s, delta, shear_modulus, lame, out.reshape((1, 1, 3, 3)), 0, 0)


@njit(cache=True, fastmath=FAST, error_model="numpy", inline="always")
def _stress_at(table, f, da, db, dc, scale, s, delta, shear_modulus, lame, out, p, q):
    """``out[p, q, i, k] += scale *`` the stress of force ``f`` from the potential derivatives
    ``table`` shifted by ``(da, db, dc)``: ref. Eq. 3.22's displacement, with harmonic
    potentials (so ``div u = 2 (1 - delta) phi2,33``),
    ``sigma_ik = G (2 phi1,ik - 2 phi2,ik - 4 delta s phi2,ik3 + 2 (1 - delta)
    (delta_k3 phi2,i3 + delta_i3 phi2,k3) + eps_ij3 phi3,jk + eps_kj3 phi3,ji)
    + 2 lambda (1 - delta) delta_ik phi2,33`` (``s`` the height above the triple's point).
    The arrays are indexed whole, not through views (``table[f, j]``, ``out[f, q]``): each
    view took and dropped a reference count, atomic operations that cost as much as the
    arithmetic. No division: numpy's error model changes nothing."""
    g = shear_modulus
    w = 2.0 * (1.0 - delta)
    d33 = w * table[f, 1, da, db, dc + 2]
    for i in range(3):
        for k in range(i, 3):
            # conditional expressions (sums of comparisons compile faster, but LLVM then
            # associates the FAST sums differently: not the same round-off, RESULTS.md)
            a = da + (1 if i == 0 else 0) + (1 if k == 0 else 0)
            b = db + (1 if i == 1 else 0) + (1 if k == 1 else 0)
            c = dc + (1 if i == 2 else 0) + (1 if k == 2 else 0)
            v = 2.0 * (table[f, 0, a, b, c] - table[f, 1, a, b, c]) - 4.0 * delta * s * table[f, 1, a, b, c + 1]
            if k == 2:
                v += w * table[f, 1, da + (1 if i == 0 else 0), db + (1 if i == 1 else 0),
                               dc + (1 if i == 2 else 0) + 1]
                if i == 2:
                    v += w * table[f, 1, da, db, dc + 2]
            if i == 0 and k == 0:
                v += 2.0 * table[f, 2, da + 1, db + 1, dc]
            elif i == 1 and k == 1:
                v -= 2.0 * table[f, 2, da + 1, db + 1, dc]
            elif i == 0 and k == 1:
                v += table[f, 2, da, db + 2, dc] - table[f, 2, da + 2, db, dc]
            elif i == 0 and k == 2:
                v += table[f, 2, da, db + 1, dc + 1]
            elif i == 1 and k == 2:
                v -= table[f, 2, da + 1, db, dc + 1]
            v *= g
            if i == k:
                v += lame * d33
            out[p, q, i, k] += scale * v
            if i != k:
                out[p, q, k, i] += scale * v


@njit(cache=True, fastmath=FAST, error_model="numpy")
def _pair_stress_gradient(r1, r2, r3, eps, sigma, coef, dcoef, delta, shear_modulus, lame, out, work):
    """``out[f, q, i, k] +=`` derivative along the source coordinate ``q`` of the stress
    ``(i, k)`` at the receiver ``r`` (relative to the triple's point) of a unit force
    along ``f``; ``delta``, moduli: the receiver layer's; ``eps = dz/dt``. Horizontal
    source derivatives are minus receiver derivatives; the vertical one differentiates
    the coefficients (``dcoef``), the triple's height ``z`` and ``s = y3 - z``. The bodies of
    :func:`_pair_tables` and :func:`gauge_table` written here, not inlined: numba's inlining
    copies each block of the inlined function with its whole scope, and those hold everything
    they inline (about 5 s of this function's cold compile, more in a process that has
    compiled much already: the copies' garbage collection, benchmarks/RESULTS.md, issue 32)."""
    sf, sl, ser, h, table, dtable, pad = work
    order = 3
    used = orders_used(coef, dcoef)
    n_c = order + used + 1
    top = max(n_c - 2, 4)  # as in _pair_tables
    # gauge_table's body (the same reason)
    inv = inverse_distance_recurrence(r1, r2, r3, pad, 6, n_c - 1, top)
    scaled_inverse_distance(pad, inv, h, 2, -1.0, 6, n_c - 1, top)
    _axis_derivatives(r1, r2, sigma * r3, sf, sl, ser)
    for b in range(2, 6):
        for a in range(6 - b):
            sf[a, b] = -sf[a + 2, b - 2] - h[a, b - 2, 2]
            sl[a, b] = -sl[a + 2, b - 2] + sigma * h[a, b - 2, 3]
    for a in range(6):
        for b in range(6 - a):
            h[a, b, 0] = sf[a, b]
            h[a, b, 1] = -sigma * sl[a, b]
    for d in range(2):
        _potential_table(dcoef if d else coef, h, sigma, order - d, used, dtable if d else table)
    for f in range(3):
        # literal shifts, four inlined copies (LLVM folds the shifts): 10% of a triple's CPU
        # against one copy in a loop over the four, for 3 s more compile
        _stress_at(table, f, 1, 0, 0, -1.0, r3, delta, shear_modulus, lame, out, f, 0)
        _stress_at(table, f, 0, 1, 0, -1.0, r3, delta, shear_modulus, lame, out, f, 1)
        _stress_at(dtable, f, 0, 0, 0, 1.0, r3, delta, shear_modulus, lame, out, f, 2)
        _stress_at(table, f, 0, 0, 1, -eps, r3, delta, shear_modulus, lame, out, f, 2)
        for i in range(3):
            for k in range(3):
                a = (1 if i == 0 else 0) + (1 if k == 0 else 0)
                b = (1 if i == 1 else 0) + (1 if k == 1 else 0)
                c = (1 if i == 2 else 0) + (1 if k == 2 else 0)
                out[f, 2, i, k] += 4.0 * shear_modulus * delta * eps * table[f, 1, a, b, c + 1]


@njit(cache=True, fastmath=FAST, error_model="numpy")
def _displacement(table, f, da, db, dc, scale, s, delta, out):
    """``out[i] += scale * u_i`` of force ``f`` (ref. Eq. 3.22) from ``table`` shifted by
    ``(da, db, dc)``."""
    for i in range(3):
        a = da + (1 if i == 0 else 0)
        b = db + (1 if i == 1 else 0)
        c = dc + (1 if i == 2 else 0)
        v = table[f, 0, a, b, c] - table[f, 1, a, b, c] - 2.0 * delta * s * table[f, 1, a, b, c + 1]
        if i == 2:
            v += 2.0 * table[f, 1, a, b, c]
        if i == 0:  # M_1 = phi3,2
            v += table[f, 2, da, db + 1, dc]
        elif i == 1:  # M_2 = -phi3,1
            v -= table[f, 2, da + 1, db, dc]
        out[i] += scale * v


@njit(cache=True, fastmath=FAST, error_model="numpy")
def _pair_displacement_gradient(r1, r2, r3, eps, sigma, coef, dcoef, delta, out, work):
    """``out[f, q, i] +=`` derivative along the source coordinate ``q`` of the
    displacement ``u_i`` at the receiver ``r`` of a unit force along ``f``."""
    _pair_tables(r1, r2, r3, sigma, coef, dcoef, 2, work)
    table = work[4]
    dtable = work[5]
    for f in range(3):
        for v in range(4):  # as in _pair_stress_gradient
            _displacement(dtable if v == 2 else table, f, 1 if v == 0 else 0, 1 if v == 1 else 0, 1 if v == 3 else 0,
                          -eps if v == 3 else (1.0 if v == 2 else -1.0), r3, delta, out[f, min(v, 2)])
        for i in range(3):
            a = 1 if i == 0 else 0
            b = 1 if i == 1 else 0
            c = 1 if i == 2 else 0
            out[f, 2, i] += 2.0 * delta * eps * table[f, 1, a, b, c + 1]


@njit(cache=True, inline="always")
def unit_moment(b, p, q, normal, shear_modulus, lame):
    """``M_pq`` of a unit DD along global ``b`` on a plane of ``normal``: ``lame (b.n)
    delta_pq + G (b_p n_q + b_q n_p)`` (Aki and Richards, Eq. 3.20)."""
    m = 0.0
    if p == b:
        m += shear_modulus * normal[q]
    if q == b:
        m += shear_modulus * normal[p]
    if p == q:
        m += lame * normal[b]
    return m


@njit(cache=True)
def _contract(gradient, normal, shear_modulus, lame, weight, out):
    """``out[b, i, k] += weight *`` stress of a unit DD density along global ``b`` on a
    plane of ``normal``: ``M_pq = lame (b.n) delta_pq + G (b_p n_q + b_q n_p)`` applied
    to ``gradient[p, q, i, k]`` (any number of ``k``), written out as
    ``lame n_b sum_p g[p, p] + G sum_q n_q (g[b, q] + g[q, b])`` (4x faster than the 81
    terms of :func:`unit_moment`, of which 60 are zero)."""
    n0, n1, n2 = normal[0], normal[1], normal[2]
    for i in range(3):
        for k in range(gradient.shape[3]):
            trace = gradient[0, 0, i, k] + gradient[1, 1, i, k] + gradient[2, 2, i, k]
            for b in range(3):
                acc = (n0 * (gradient[b, 0, i, k] + gradient[0, b, i, k])
                       + n1 * (gradient[b, 1, i, k] + gradient[1, b, i, k])
                       + n2 * (gradient[b, 2, i, k] + gradient[2, b, i, k]))
                out[b, i, k] += weight * (lame * normal[b] * trace + shear_modulus * acc)


@njit(cache=True)
def _contract_vector(gradient, normal, shear_modulus, lame, out):
    """``out[b, i] =`` the moment contraction (see :func:`_contract`) of ``gradient[p, q, i]``."""
    contracted = np.zeros((3, 3, 1))
    _contract(gradient.reshape((3, 3, 3, 1)), normal, shear_modulus, lame, 1.0, contracted)
    # element by element, not by slice assignment (docs/conventions.md, §5)
    for b in range(3):
        for i in range(3):
            out[b, i] = contracted[b, i, 0]
