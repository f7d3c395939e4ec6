"""Complementary (image) stress of rectangular displacement discontinuities in a
plane-layered 3D medium by the general image method (ref. Secs 3.2-3.3).

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
Mirroring a potential in a horizontal plane maps ``F, L`` of gauge ``sigma`` to those of
gauge ``-sigma``: the mirrored coefficient of ``D^n`` (``D = d/dy3``) only changes by
``(-1)^n``.

Reflection and transmission at an interface ``y3 = d`` (ref. Eqs 3.25-3.28, with
``h = z - d``, ``gamma = G_far / G_near``; derived and checked in ``_derive_images3d.py``):
the reflected triple emanates from ``2d - z`` and is ``R`` applied to the mirrored
incident triple, the transmitted one keeps ``z`` and is ``T`` applied to the incident one:

    R = [[2 d1 c1 h D, c2 - 4 d1^2 c1 h^2 D^2, 0],  T = [[c4, 2 (d1 c4 - d2 c5) h D, 0],
         [c1,          -2 d1 c1 h D,          0],       [0,  c5,                    0],
         [0,           0,                    c3]]       [0,  0,                    c6]]

(ref. Eq. 3.27 prints ``-2 (d1 c4 - d2 c5)``: the interface conditions need ``+``, as
in 2D.) The stress of a DD density is the moment-tensor contraction of the source
derivative of the point-force stress, exactly as in :mod:`.images2d`, and the
bookkeeping (complementary = every image pair in the source's layer; transmitted minus
the source material's whole-space field elsewhere) is the same.

Derivatives. ``D F = -sigma L``, ``D L = sigma / r``, so every derivative with a vertical
part is a derivative of ``1/r``, whose Taylor coefficients follow a three-term recurrence
(any order). Horizontal derivatives (up to order 5) of ``F`` and ``L`` come from
one-variable Taylor series along x of the closed forms of ``d1 F``, ``d2 F``, ``d1 L``,
``d2 L`` and from Laplace's equation (both are harmonic) for the higher ``d2`` powers.

Compile cost (issue 18: a cold numba cache). numba links every njit function a function
calls into its compiled library and LLVM optimises and generates machine code for all of
it again there, so each njit function above the per-pair stress
(:func:`_pair_stress_gradient`) costs one more compile of everything below it: the chain is
kept short (``_complementary_gradient``, ``image_rectangle_stress`` and ``Workspace`` are
inlined by numba, not compiled on their own); loops LLVM would unroll into thousands of
instructions (``_base_table``) run to array sizes; and no njit function takes a literal int
argument where another call passes a variable (numba compiles one specialization per
literal: ``first = np.int64(0)``). ``benchmarks/bench_layered3d_compile.py`` measures it.

Length (over ~400 lines): the 3D derivative tables of the Hansen potentials (checked by
``_derive_images3d``), the tracer of images through interfaces and the rectangle quadrature
are numba code that compiles as one unit; splitting them would spread one derivation.
"""
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..kernels import rectangle3d
from ..kernels.rectangle3d import distance_to_rectangle as _distance, rectangle_distance  # noqa: F401 (re-export)
from ..kernels.drivers import KernelKind, register_kind
from .image_tracer import trace_capacity, trace_potentials
from .images2d import _lame
from .segment_quadrature import gauss_legendre, subdivision_level

_INV_8PI = 1.0 / (8.0 * math.pi)


# -- tracing the image triples (ref. Fig. 3.4) ------------------------------------------------
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


@njit(cache=True)
def trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, pair_layer, pair_z, pair_eps,
          pair_sigma, pair_coef, pair_dcoef):
    """Image triples of a unit point force at height ``t`` in ``source_layer``
    (:func:`.image_tracer.trace_potentials`): ``pair_sigma[k]`` is the triple's gauge (its
    direction of travel: +1 upward, receivers above ``z``), ``pair_coef[k, f, j, n]`` the
    coefficient of ``D^n`` of the base function of potential ``j`` for a force along
    ``f``. Returns the number of triples (the original excluded)."""
    delta_s = 1.0 / (3.0 - 4.0 * poisson_ratio[source_layer])
    original = np.zeros((2, 3, 3, 1))
    for e in range(2):
        _original(original[e], delta_s, shear_modulus[source_layer], 1.0 if e == 0 else -1.0, 1.0)
    return trace_potentials(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images,
                            np.ascontiguousarray(original[:, :, :, 0]),
                            np.ones(3), pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef)


# -- derivatives of the base functions -----------------------------------------------------
@njit(cache=True)
def _axis_series(r1, r3, r, m, ser):
    """Taylor coefficients (``k < m``) in ``t`` at ``(r1 + t, r2, r3)``, gauge +1, ``U = R + r3``:
    ``ser[0] = R``, ``ser[1] = 1/R``, ``ser[2] = V = 1/U``, ``ser[3] = W = V/R``."""
    rs, ir, v, w = ser[0], ser[1], ser[2], ser[3]
    u0 = r + r3
    rs[0] = r
    ir[0] = 1.0 / r
    v[0] = 1.0 / u0
    for k in range(1, m):
        s = 2.0 * r1 if k == 1 else (1.0 if k == 2 else 0.0)  # R^2 = r^2 + 2 r1 t + t^2
        for i in range(1, k):
            s -= rs[i] * rs[k - i]
        rs[k] = s / (2.0 * r)
        s_ir = 0.0
        s_v = 0.0
        for i in range(1, k + 1):
            s_ir += rs[i] * ir[k - i]
            s_v += rs[i] * v[k - i]  # U_i = R_i for i >= 1
        ir[k] = -s_ir / r
        v[k] = -s_v / u0
    for k in range(m):
        s = 0.0
        for i in range(k + 1):
            s += v[i] * ir[k - i]
        w[k] = s


@njit(cache=True)
def base_derivatives(r1, r2, r3, sf, sl, q, ser):
    """Derivatives of the gauge +1 base functions at ``(r1, r2, r3)``, ``r3 >= 0`` (away
    from the singular half-line): ``q[a, b, c] = d1^a d2^b d3^c (1/r)`` (all of ``q``'s
    shape, :func:`inverse_distance_derivatives`), ``sf[a, b] = d1^a d2^b F`` and
    ``sl[a, b] = d1^a d2^b L`` for ``a + b <= 5``. Along x from one-variable Taylor series
    of the closed forms ``d1 F = r1 / U``, ``d1 L = r1 / (R U)``, ``d2 F = r2 / U``,
    ``d2 L = r2 / (R U)`` (``U = r + r3``, no cancelling terms); the other horizontal
    derivatives from Laplace's equation, ``d2^2 F = -d1^2 F + 1/r``,
    ``d2^2 L = -d1^2 L - d3 (1/r)`` (``F`` and ``L`` are harmonic; ``ser``: (4, 6) scratch)."""
    inverse_distance_derivatives(r1, r2, r3, q)
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    _axis_series(r1, r3, r, 5, ser)
    v = ser[2]
    w = ser[3]
    sf[0, 0] = r - r3 * math.log(r + r3)
    sl[0, 0] = math.log(r + r3)
    fact = 1.0  # (a - 1)!
    for a in range(1, 6):
        if a > 1:
            fact *= a - 1
        sf[a, 0] = fact * (r1 * v[a - 1] + (v[a - 2] if a >= 2 else 0.0))
        sl[a, 0] = fact * (r1 * w[a - 1] + (w[a - 2] if a >= 2 else 0.0))
    fact = 1.0  # a!
    for a in range(5):
        if a > 0:
            fact *= a
        sf[a, 1] = fact * r2 * v[a]
        sl[a, 1] = fact * r2 * w[a]
    for b in range(2, 6):
        for a in range(6 - b):
            sf[a, b] = -sf[a + 2, b - 2] + q[a, b - 2, 0]
            sl[a, b] = -sl[a + 2, b - 2] - q[a, b - 2, 1]


@njit(cache=True)
def inverse_distance_derivatives(r1, r2, r3, q):
    """``q[a, b, c] = d1^a d2^b d3^c (1/r)`` for ``a + b < q.shape[0]``, ``c < q.shape[2]``
    by the recurrence of the Taylor coefficients ``t_k = d^k (1/r) / k!``:
    ``n r^2 t_k + (2n - 1) sum_i r_i t_(k - e_i) + (n - 1) sum_i t_(k - 2 e_i) = 0``
    (here on the unit vector, then scaled)."""
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    inv = 1.0 / r
    x0 = r1 * inv
    x1 = r2 * inv
    x2 = r3 * inv
    ha = q.shape[0]
    nc = q.shape[2]
    for c in range(nc):
        for a in range(ha):
            for b in range(ha - a):
                n = a + b + c
                if n == 0:
                    q[0, 0, 0] = 1.0
                    continue
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
                q[a, b, c] = -(s + (n - 1) * t) / n
    # t_k / r^(n+1) * a! b! c!
    fc = inv
    for c in range(nc):
        if c > 0:
            fc *= c * inv
        fa = fc
        for a in range(ha):
            if a > 0:
                fa *= a * inv
            fb = fa
            for b in range(ha - a):
                if b > 0:
                    fb *= b * inv
                q[a, b, c] *= fb


@njit(cache=True)
def _base_table(sigma, n_c, sf, sl, q, base):
    """``base[kind, a, b, c] = d1^a d2^b d3^c`` of ``F`` (kind 0) or ``L`` (kind 1) of
    gauge ``sigma`` (``a + b <= 5``, ``c < n_c``), from the gauge +1 derivatives at the
    flipped point: ``sigma^c`` times ``sf``/``sl``/``q`` (``d3 F = -L``, ``d3 L = 1/r``).
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
                base[1, a, b, 1] = sign * q[a, b, 0]
            for c in range(2, n_c):
                sign *= flip
                base[0, a, b, c] = -sign * q[a, b, c - 2]
                base[1, a, b, c] = sign * q[a, b, c - 1]


@njit(cache=True)
def _potential_table(coef, base, order, table):
    """``table[f, j, a, b, c] = d1^a d2^b d3^c phi_j`` of force ``f`` for the triple
    ``coef`` (``phi_j = sum_n coef[f, j, n] D^n`` of its base function ``d1 F``, ``d2 F``
    or ``L``): the orders the stress needs, ``a + b + c = order`` (and ``order + 1`` for
    ``phi_2``, the only one with the ``s`` term of ref. Eq. 3.22)."""
    n_orders = coef.shape[2]
    for f in range(3):
        for j in range(3):
            if f == 2 and j == 2:
                continue
            if f == 2:
                kind, ia, ib = 1, 0, 0
            elif (f == 0) == (j < 2):
                kind, ia, ib = 0, 1, 0
            else:
                kind, ia, ib = 0, 0, 1
            n0 = 0
            while n0 < n_orders and coef[f, j, n0] == 0.0:
                n0 += 1
            n1 = n_orders
            while n1 > n0 and coef[f, j, n1 - 1] == 0.0:
                n1 -= 1
            top = order + 1 if j == 1 else order
            for o in range(order, top + 1):
                for a in range(o + 1):
                    for b in range(o + 1 - a):
                        c = o - a - b
                        s = 0.0
                        for n in range(n0, n1):
                            s += coef[f, j, n] * base[kind, a + ia, b + ib, c + n]
                        table[f, j, a, b, c] = s


@njit(cache=True, inline="always")
def Workspace(n_orders):
    """Scratch arrays of :func:`_pair_stress_gradient` for triples of up to ``n_orders``:
    ``sf, sl`` (6, 6), the series (4, 6), ``q`` (6, 6, n_orders + 4), the base table
    (2, 6, 6, n_orders + 5) and the potential tables (3, 3, 6, 6, 6)."""
    return (np.empty((6, 6)), np.empty((6, 6)), np.empty((4, 6)), np.empty((6, 6, n_orders + 4)),
            np.empty((2, 6, 6, n_orders + 5)), np.zeros((3, 3, 6, 6, 6)), np.zeros((3, 3, 6, 6, 6)))


@njit(cache=True)
def _pair_tables(r1, r2, r3, sigma, coef, dcoef, order, work):
    """Fill ``work``'s potential tables of the triple at the receiver ``r`` (relative to
    the triple's point): ``coef`` at ``order`` (3 for the stress, 2 for the displacement),
    ``dcoef`` one lower."""
    sf, sl, ser, q, base, table, dtable = work
    n_orders = coef.shape[2]
    used = 1
    for f in range(3):
        for j in range(3):
            for n in range(n_orders - 1, used - 1, -1):
                if coef[f, j, n] != 0.0 or dcoef[f, j, n] != 0.0:
                    used = n + 1
                    break
    n_c = order + used + 1
    base_derivatives(r1, r2, sigma * r3, sf, sl, q[:, :, :n_c - 1], ser)
    _base_table(sigma, n_c, sf, sl, q, base)
    lower = order - 1  # a run-time int: one compiled _potential_table for both orders
    _potential_table(coef, base, lower + 1, table)
    _potential_table(dcoef, base, lower, dtable)


@njit(cache=True)
def _stress(table, f, da, db, dc, scale, s, delta, shear_modulus, lame, out):
    """``out[i, k] += scale *`` the stress of force ``f`` from the potential derivatives
    ``table`` shifted by ``(da, db, dc)``: ref. Eq. 3.22's displacement, with harmonic
    potentials (so ``div u = 2 (1 - delta) phi2,33``),
    ``sigma_ik = G (2 phi1,ik - 2 phi2,ik - 4 delta s phi2,ik3 + 2 (1 - delta)
    (delta_k3 phi2,i3 + delta_i3 phi2,k3) + eps_ij3 phi3,jk + eps_kj3 phi3,ji)
    + 2 lambda (1 - delta) delta_ik phi2,33`` (``s`` the height above the triple's point)."""
    t0 = table[f, 0]
    t1 = table[f, 1]
    t2 = table[f, 2]
    g = shear_modulus
    w = 2.0 * (1.0 - delta)
    d33 = w * t1[da, db, dc + 2]
    for i in range(3):
        for k in range(i, 3):
            a = da + (1 if i == 0 else 0) + (1 if k == 0 else 0)
            b = db + (1 if i == 1 else 0) + (1 if k == 1 else 0)
            c = dc + (1 if i == 2 else 0) + (1 if k == 2 else 0)
            v = 2.0 * (t0[a, b, c] - t1[a, b, c]) - 4.0 * delta * s * t1[a, b, c + 1]
            if k == 2:
                v += w * t1[da + (1 if i == 0 else 0), db + (1 if i == 1 else 0), dc + (1 if i == 2 else 0) + 1]
                if i == 2:
                    v += w * t1[da, db, dc + 2]
            if i == 0 and k == 0:
                v += 2.0 * t2[da + 1, db + 1, dc]
            elif i == 1 and k == 1:
                v -= 2.0 * t2[da + 1, db + 1, dc]
            elif i == 0 and k == 1:
                v += t2[da, db + 2, dc] - t2[da + 2, db, dc]
            elif i == 0 and k == 2:
                v += t2[da, db + 1, dc + 1]
            elif i == 1 and k == 2:
                v -= t2[da + 1, db, dc + 1]
            v *= g
            if i == k:
                v += lame * d33
            out[i, k] += scale * v
            if i != k:
                out[k, i] += scale * v


@njit(cache=True)
def _pair_stress_gradient(r1, r2, r3, eps, sigma, coef, dcoef, delta, shear_modulus, lame, out, work):
    """``out[f, q, i, k] +=`` derivative along the source coordinate ``q`` of the stress
    ``(i, k)`` at the receiver ``r`` (relative to the triple's point) of a unit force
    along ``f``; ``delta``, moduli: the receiver layer's; ``eps = dz/dt``. Horizontal
    source derivatives are minus receiver derivatives; the vertical one differentiates
    the coefficients (``dcoef``), the triple's height ``z`` and ``s = y3 - z``."""
    _pair_tables(r1, r2, r3, sigma, coef, dcoef, 3, work)
    table = work[5]
    dtable = work[6]
    for f in range(3):
        # literal shifts: numba compiles four _stress (LLVM inlines them with the shifts folded);
        # one compiled _stress with run-time shifts measured ~30% more CPU per pair
        _stress(table, f, 1, 0, 0, -1.0, r3, delta, shear_modulus, lame, out[f, 0])
        _stress(table, f, 0, 1, 0, -1.0, r3, delta, shear_modulus, lame, out[f, 1])
        _stress(dtable, f, 0, 0, 0, 1.0, r3, delta, shear_modulus, lame, out[f, 2])
        _stress(table, f, 0, 0, 1, -eps, r3, delta, shear_modulus, lame, out[f, 2])
        t1 = table[f, 1]
        for i in range(3):
            for k in range(3):
                a = (1 if i == 0 else 0) + (1 if k == 0 else 0)
                b = (1 if i == 1 else 0) + (1 if k == 1 else 0)
                c = (1 if i == 2 else 0) + (1 if k == 2 else 0)
                out[f, 2, i, k] += 4.0 * shear_modulus * delta * eps * t1[a, b, c + 1]


@njit(cache=True)
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


@njit(cache=True)
def _pair_displacement_gradient(r1, r2, r3, eps, sigma, coef, dcoef, delta, out, work):
    """``out[f, q, i] +=`` derivative along the source coordinate ``q`` of the
    displacement ``u_i`` at the receiver ``r`` of a unit force along ``f``."""
    _pair_tables(r1, r2, r3, sigma, coef, dcoef, 2, work)
    table = work[5]
    dtable = work[6]
    for f in range(3):
        for v in range(4):  # as in _pair_stress_gradient
            _displacement(dtable if v == 2 else table, f, 1 if v == 0 else 0, 1 if v == 1 else 0, 1 if v == 3 else 0,
                          -eps if v == 3 else (1.0 if v == 2 else -1.0), r3, delta, out[f, min(v, 2)])
        for i in range(3):
            a = 1 if i == 0 else 0
            b = 1 if i == 1 else 0
            c = 1 if i == 2 else 0
            out[f, 2, i] += 2.0 * delta * eps * table[f, 1, a, b, c + 1]


@njit(cache=True)
def _contract(gradient, normal, shear_modulus, lame, weight, out):
    """``out[b, i, k] += weight *`` stress of a unit DD density along global ``b`` on a
    plane of ``normal``: ``M_pq = lame (b.n) delta_pq + G (b_p n_q + b_q n_p)`` applied
    to ``gradient[p, q, i, k]`` (any number of ``k``)."""
    for b in range(3):
        for i in range(3):
            for k in range(gradient.shape[3]):
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
                        if m != 0.0:
                            acc += m * gradient[p, q, i, k]
                out[b, i, k] += weight * acc


@njit(cache=True, inline="always")
def _complementary_gradient(y, receiver_layer, x, n_pairs, source_layer, pair_layer, pair_z, pair_eps, pair_sigma,
                            pair_coef, pair_dcoef, shear_modulus, poisson_ratio, gradient, work, work1, kelvin):
    """``gradient[f, q, i, k]`` of the complementary field at receiver ``y`` from the
    traced triples of the source point ``x`` (see :mod:`.images2d` for the bookkeeping);
    ``work``: a :func:`Workspace` of the triples' order, ``work1`` one of order 1,
    ``kelvin`` (2, 3, 3, 1) scratch."""
    gradient[:] = 0.0
    g_r = shear_modulus[receiver_layer]
    nu_r = poisson_ratio[receiver_layer]
    delta_r = 1.0 / (3.0 - 4.0 * nu_r)
    lame_r = _lame(g_r, nu_r)
    for k in range(n_pairs):
        if pair_layer[k] == receiver_layer:
            _pair_stress_gradient(y[0] - x[0], y[1] - x[1], y[2] - pair_z[k], pair_eps[k], pair_sigma[k],
                                  pair_coef[k], pair_dcoef[k], delta_r, g_r, lame_r, gradient, work)
    if receiver_layer != source_layer:
        # minus the whole-space field of the source's material (added in closed form)
        g_s = shear_modulus[source_layer]
        nu_s = poisson_ratio[source_layer]
        delta_s = 1.0 / (3.0 - 4.0 * nu_s)
        sigma = 1.0 if y[2] >= x[2] else -1.0
        kelvin[:] = 0.0
        _original(kelvin[0], delta_s, g_s, sigma, -1.0)
        _pair_stress_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, sigma, kelvin[0], kelvin[1], delta_s, g_s,
                              _lame(g_s, nu_s), gradient, work1)


@njit(cache=True)
def kelvin_point_stress(y, x, normal, shear_modulus, poisson_ratio, out):
    """``out[b, i, k]``: whole-space stress at ``y`` of a unit DD density along global
    ``b`` at the point ``x`` of a plane of ``normal``, through the Hansen-potential path
    of the images (a check of the machinery against :mod:`hmatddm.kernels.rectangle3d`)."""
    delta = 1.0 / (3.0 - 4.0 * poisson_ratio)
    sigma = 1.0 if y[2] >= x[2] else -1.0
    coef = np.zeros((3, 3, 1))
    _original(coef, delta, shear_modulus, sigma, 1.0)
    gradient = np.zeros((3, 3, 3, 3))
    lame = _lame(shear_modulus, poisson_ratio)
    _pair_stress_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, sigma, coef, np.zeros((3, 3, 1)), delta,
                          shear_modulus, lame, gradient, Workspace(1))
    out[:] = 0.0
    _contract(gradient, normal, shear_modulus, lame, 1.0, out)


@njit(cache=True)
def image_point_stress(y, receiver_layer, x, source_layer, normal, interfaces, shear_modulus, poisson_ratio,
                       n_images, out):
    """Complementary stress ``out[b, i, k]`` (3, 3, 3) at the receiver ``y`` (in
    ``receiver_layer``) of a unit DD density along global ``b`` at the source point
    ``x`` (in ``source_layer``) of a plane of ``normal``. The total stress is this plus
    the closed-form whole-space kernel of the source layer's material."""
    traced = trace_points(x[2:3], source_layer, interfaces, shear_modulus, poisson_ratio, n_images)
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    gradient = np.empty((3, 3, 3, 3))
    _complementary_gradient(y, receiver_layer, x, n_pairs[0], source_layer, layer[0], z[0], eps[0], sigma[0],
                            coef[0], dcoef[0], shear_modulus, poisson_ratio, gradient, Workspace(coef.shape[-1]),
                            Workspace(1), np.zeros((2, 3, 3, 1)))
    out[:] = 0.0
    g_s = shear_modulus[source_layer]
    _contract(gradient, normal, g_s, _lame(g_s, poisson_ratio[source_layer]), 1.0, out)


@njit(cache=True)
def _contract_vector(gradient, normal, shear_modulus, lame, out):
    """``out[b, i] =`` the moment contraction (see :func:`_contract`) of ``gradient[p, q, i]``."""
    contracted = np.zeros((3, 3, 1))
    _contract(gradient.reshape((3, 3, 3, 1)), normal, shear_modulus, lame, 1.0, contracted)
    # element by element, not by slice assignment (docs/conventions.md, §5)
    for b in range(3):
        for i in range(3):
            out[b, i] = contracted[b, i, 0]


@njit(cache=True)
def kelvin_point_displacement(y, x, normal, shear_modulus, poisson_ratio, out):
    """``out[b, i]``: whole-space displacement at ``y`` of a unit DD density along global
    ``b`` at the point ``x`` of a plane of ``normal`` (Hansen-potential path)."""
    delta = 1.0 / (3.0 - 4.0 * poisson_ratio)
    sigma = 1.0 if y[2] >= x[2] else -1.0
    coef = np.zeros((3, 3, 1))
    _original(coef, delta, shear_modulus, sigma, 1.0)
    gradient = np.zeros((3, 3, 3))
    _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, sigma, coef, np.zeros((3, 3, 1)), delta,
                                gradient, Workspace(1))
    _contract_vector(gradient, normal, shear_modulus, _lame(shear_modulus, poisson_ratio), out)


@njit(cache=True)
def image_point_displacement(y, receiver_layer, x, source_layer, normal, interfaces, shear_modulus, poisson_ratio,
                             n_images, out):
    """Complementary displacement ``out[b, i]`` (3, 3) at ``y`` of a unit DD density
    along global ``b`` at the source point ``x`` of a plane of ``normal`` (ref. Eq.
    3.22; the total is this plus the whole-space field of the source layer's material)."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = trace_points(x[2:3], source_layer, interfaces, shear_modulus,
                                                              poisson_ratio, n_images)
    gradient = np.zeros((3, 3, 3))
    work = Workspace(coef.shape[-1])
    nu_r = poisson_ratio[receiver_layer]
    delta_r = 1.0 / (3.0 - 4.0 * nu_r)
    for k in range(n_pairs[0]):
        if layer[0, k] == receiver_layer:
            _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - z[0, k], eps[0, k], sigma[0, k], coef[0, k],
                                        dcoef[0, k], delta_r, gradient, work)
    g_s = shear_modulus[source_layer]
    nu_s = poisson_ratio[source_layer]
    if receiver_layer != source_layer:
        delta_s = 1.0 / (3.0 - 4.0 * nu_s)
        side = 1.0 if y[2] >= x[2] else -1.0
        kelvin = np.zeros((3, 3, 1))
        _original(kelvin, delta_s, g_s, side, -1.0)
        _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, side, kelvin, np.zeros((3, 3, 1)),
                                    delta_s, gradient, Workspace(1))
    _contract_vector(gradient, normal, g_s, _lame(g_s, nu_s), out)


@njit(cache=True)
def trace_points(heights, source_layer, interfaces, shear_modulus, poisson_ratio, n_images):
    """The image triples of source points at ``heights`` (P,): ``(n_pairs (P,), layer,
    z, eps, sigma (P, C), coef, dcoef (P, C, 3, 3, O))``."""
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    traced = _traced_buffer(heights.shape[0], cap, n_orders)
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(heights.shape[0]):
        n_pairs[g] = trace(heights[g], source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer[g],
                           z[g], eps[g], sigma[g], coef[g], dcoef[g])
    return traced


# -- quadrature over a rectangle -----------------------------------------------------------------
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
def nearest_singularity(y, receiver_layer, center, frame, a, b, source_layer, interfaces):
    """Distance from the receiver ``y`` to the nearest singular point of the image
    integrand: the rectangle's mirror images in the interfaces bounding the source's and
    the receiver's layers (the distance of the mirrored receiver to the rectangle), and
    the rectangle itself when the receiver is in another layer."""
    dmin = np.inf
    if receiver_layer != source_layer:
        dmin = rectangle_distance(y, center, frame, a, b)
    n_if = interfaces.shape[0]
    for layer in (source_layer, receiver_layer):
        for k in (layer - 1, layer):
            if 0 <= k < n_if:
                dmin = min(dmin, _distance(y[0], y[1], 2.0 * interfaces[k] - y[2], center, frame, a, b))
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
    for n in range(1, n_max):
        if 40.0 * n * ratio ** (-2.0 * n) <= tol:
            return n
    return n_max


@njit(cache=True)
def _integrate(y, receiver_layer, center, frame, a, b, source_layer, shear_modulus, poisson_ratio, xi, eta, wt,
               traced, offset, out, gradient, work, work1, kelvin):
    """``out[b, i, k] +=`` the Gauss sum of the complementary stress over the rectangle
    with the triples traced at the points ``offset ... offset + len(xi)`` of ``traced``."""
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
                                coef[k], dcoef[k], shear_modulus, poisson_ratio, gradient, work, work1, kelvin)
        _contract(gradient, normal, g_s, lame_s, wt[g] * jac, out)


@njit(cache=True)
def _trace_range(center, frame, a, b, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, eta, lo,
                 hi, traced):
    """Trace the points ``lo .. hi - 1`` of the rule ``(xi, eta)`` into ``traced``, once
    per distinct height (a horizontal rectangle is traced once, a vertical one once per
    row)."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(lo, hi):
        t = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
        same = -1
        for k in range(lo, g):
            if center[2] + xi[k] * a * frame[0, 2] + eta[k] * b * frame[1, 2] == t:
                same = k
                break
        if same < 0:
            n_pairs[g] = trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer[g], z[g],
                               eps[g], sigma[g], coef[g], dcoef[g])
        else:
            n = n_pairs[same]
            n_pairs[g] = n
            # element by element, not by slice assignment (docs/conventions.md, §5)
            for k in range(n):
                layer[g, k] = layer[same, k]
                z[g, k] = z[same, k]
                eps[g, k] = eps[same, k]
                sigma[g, k] = sigma[same, k]
                for f in range(coef.shape[2]):
                    for j in range(coef.shape[3]):
                        for o in range(coef.shape[4]):
                            coef[g, k, f, j, o] = coef[same, k, f, j, o]
                            dcoef[g, k, f, j, o] = dcoef[same, k, f, j, o]


@njit(cache=True)
def _traced_buffer(n_points, cap, n_orders):
    """Room for the triples of ``n_points`` source points (see :func:`trace_points`)."""
    return (np.zeros(n_points, dtype=np.int64), np.empty((n_points, cap), dtype=np.int64),
            np.empty((n_points, cap)), np.empty((n_points, cap)), np.empty((n_points, cap)),
            np.empty((n_points, cap, 3, 3, n_orders)), np.empty((n_points, cap, 3, 3, n_orders)))


@njit(cache=True, inline="always")
def image_rectangle_stress(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                           poisson_ratio, n_images, n_gauss, n_sub, out):
    """Complementary stress ``out[b, i, k]`` at ``y`` of a unit global DD ``b`` on the
    rectangle, by ``n_gauss^2`` points on each of ``n_sub^2`` sub-squares."""
    xi, eta, wt = square_rule(n_gauss, n_sub)
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    traced = _traced_buffer(xi.shape[0], cap, n_orders)
    first = np.int64(0)  # not a literal 0: the same compiled _trace_range and _integrate as element_traction's
    _trace_range(center, frame, a, b, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, eta, first,
                 xi.shape[0], traced)
    out[:] = 0.0
    _integrate(y, receiver_layer, center, frame, a, b, source_layer, shear_modulus, poisson_ratio, xi, eta, wt,
               traced, first, out, np.empty((3, 3, 3, 3)), Workspace(n_orders), Workspace(1),
               np.zeros((2, 3, 3, 1)))


@njit(cache=True)
def _image_order(y, receiver_layer, center, frame, a, b, source_layer, interfaces, gauss_points, max_sub, far_tol):
    """``(n_gauss, n_sub)`` of the image quadrature of a rectangle at ``y``: sub-squares
    by :func:`subdivisions` rounded up to a power of two, and, on one square,
    :func:`far_order` points per side."""
    dmin = nearest_singularity(y, receiver_layer, center, frame, a, b, source_layer, interfaces)
    n_sub = 2 ** subdivision_level(_sub_count(dmin, a, b, max_sub))
    if n_sub == 1:
        return far_order(dmin / max(a, b), gauss_points, far_tol), 1
    return gauss_points, n_sub


# -- constant rectangles: the kernel data and the per-pair functions of the drivers ---------------
class LayeredRectangles(NamedTuple):
    """Kernel data of constant rectangles in a layered medium (the record
    :mod:`hmatddm.kernels.drivers` take; built by
    :func:`hmatddm.layered.influence3d.influence_data`). No translation invariance is
    assumed anywhere: every entry is computed from both elements' absolute positions."""

    centers: np.ndarray  #: (N, 3) element centres
    frames: np.ndarray  #: (N, 3, 3) rows: e1, e2, normal e1 x e2
    half_a: np.ndarray  #: (N,) half sides along e1
    half_b: np.ndarray  #: (N,) half sides along e2
    layer: np.ndarray  #: (N,) int64 layer of each element
    interfaces: np.ndarray  #: (L - 1,) interface heights (z), top down
    shear_modulus: np.ndarray  #: (L,) per layer (0: void)
    poisson_ratio: np.ndarray  #: (L,) per layer
    n_images: int  #: reflections per interface (ref. Fig. 3.4)
    gauss_points: int  #: Gauss-Legendre points per side of a sub-square near images (fewer far away: :func:`far_order`)
    max_subdivisions: int  #: largest number of sub-squares per side (:func:`subdivisions`)
    singular_shift: float  #: see :mod:`hmatddm.kernels.drivers` (singular points)
    near_fraction: float  #: near-miss distance, fraction of the smaller half size
    alpha: float  #: ref. Eq. 6.11 scaling (0: none)
    self_max: np.ndarray  #: (N,) largest |entry| of each self block (ref. Eq. 6.11)
    far_tol: float = FAR_TOL  #: error allowed to :func:`far_order` (0: ``gauss_points`` everywhere)


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


@njit(cache=True)
def workspace(data):
    """Scratch: local stress (3, 3, 3), image stress (3, 3, 3), gradient (3, 3, 3, 3), the
    Kelvin scratch (2, 3, 3, 1), the :func:`Workspace` of order 1 and of the largest order
    of any source layer's triples, the tracer's room per layer ``(cap, n_orders)`` and the
    :func:`_cached_rules`."""
    n_layers = data.shear_modulus.shape[0]
    room = np.zeros((n_layers, 2), dtype=np.int64)
    n_orders = 1
    if data.interfaces.shape[0] > 0:
        for layer in range(n_layers):
            if data.shear_modulus[layer] > 0.0:
                room[layer, 0], room[layer, 1] = trace_capacity(layer, data.shear_modulus, data.n_images)
                n_orders = max(n_orders, room[layer, 1])
    return (np.empty((3, 3, 3)), np.zeros((3, 3, 3)), np.empty((3, 3, 3, 3)), np.zeros((2, 3, 3, 1)), Workspace(1),
            Workspace(n_orders), room, _cached_rules(data.gauss_points))


@njit(cache=True)
def source_state(data, j, work):
    """What the receivers of source ``j`` share: room for the image triples at the points
    of the cached rules, traced when a receiver first needs a rule."""
    room = work[6]
    start = work[7][3]
    ls = data.layer[j]
    return _traced_buffer(start[-1], max(room[ls, 0], 1), max(room[ls, 1], 1)), np.zeros(start.shape[0] - 1,
                                                                                         dtype=np.bool_)


@njit(cache=True)
def element_traction(data, i, j, state, work, block):
    """``block`` (3, 3): traction at the centre of element ``i`` (its normal) for a unit
    global DD of rectangle ``j``: closed form of the source layer's material (with the
    closed-form kernel's singular and near-miss handling) plus images (:func:`_image_order`),
    the source's traced triples reused across receivers."""
    traced, is_traced = state
    local, image, gradient, kelvin, ws1, ws, room, rules = work
    xi, eta, wt, start = rules
    g = data.shear_modulus
    nu = data.poisson_ratio
    interfaces = data.interfaces
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    point = data.centers[i]
    normal = data.frames[i, 2]
    near = 0.0
    if i != j:
        near = data.near_fraction * min(data.half_a[i], data.half_b[i], a, b)
    rectangle3d.traction_pair(point, normal, center, frame, a, b, g[ls], nu[ls], data.singular_shift, block, local,
                              near)
    if interfaces.shape[0] > 0:
        lr = data.layer[i]
        n_gauss, n_sub = _image_order(point, lr, center, frame, a, b, ls, interfaces, data.gauss_points,
                                      data.max_subdivisions, data.far_tol)
        image[:] = 0.0
        if n_sub <= 2:
            slot = n_gauss - 1 if n_sub == 1 else data.gauss_points
            lo, hi = start[slot], start[slot + 1]
            if not is_traced[slot]:
                _trace_range(center, frame, a, b, ls, interfaces, g, nu, data.n_images, xi, eta, lo, hi, traced)
                is_traced[slot] = True
            _integrate(point, lr, center, frame, a, b, ls, g, nu, xi[lo:hi], eta[lo:hi], wt[lo:hi], traced, lo, image,
                       gradient, ws, ws1, kelvin)
        else:
            image_rectangle_stress(point, lr, center, frame, a, b, ls, interfaces, g, nu, data.n_images, n_gauss,
                                   n_sub, image)
        for p in range(3):
            for q in range(3):
                block[p, q] += image[q, p, 0] * normal[0] + image[q, p, 1] * normal[1] + image[q, p, 2] * normal[2]


@njit(cache=True)
def element_stress(data, point, point_layer, j, work, out):
    """``out[q, i, k]``: stress at ``point`` (in ``point_layer``; zero in a void layer)
    for a unit global DD ``q`` of rectangle ``j``, closed form plus images (the
    quadrature of :func:`element_traction`). A point within ``near_fraction`` smaller
    half sides of an edge counts as on it."""
    local, image = work[0], work[1]
    g = data.shear_modulus
    nu = data.poisson_ratio
    if g[point_layer] <= 0.0:
        out[:] = 0.0
        return
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    rectangle3d.stress_pair(point, center, frame, a, b, g[ls], nu[ls], data.singular_shift, out, local,
                            data.near_fraction * min(a, b))
    if data.interfaces.shape[0] > 0:
        n_gauss, n_sub = _image_order(point, point_layer, center, frame, a, b, ls, data.interfaces,
                                      data.gauss_points, data.max_subdivisions, data.far_tol)
        image_rectangle_stress(point, point_layer, center, frame, a, b, ls, data.interfaces, g, nu, data.n_images,
                               n_gauss, n_sub, image)
        for q in range(3):
            for i in range(3):
                for k in range(3):
                    out[q, i, k] += image[q, i, k]


register_kind(LayeredRectangles, KernelKind(workspace, source_state, element_traction, element_stress,
                                            rectangle3d.edge_distance))
