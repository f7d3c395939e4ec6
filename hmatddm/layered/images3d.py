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

Derivatives. Horizontal derivatives (up to order 5) of ``F`` and ``L`` come from
truncated bivariate Taylor series; ``D F = -sigma L``, ``D L = sigma / r``, so every
derivative with a vertical part is a derivative of ``1/r``, whose Taylor coefficients
follow a three-term recurrence (any order).

Length (over ~400 lines): the 3D derivative tables of the Hansen potentials (checked by
``_derive_images3d``), the tracer of images through interfaces and the rectangle quadrature
are numba code that compiles as one unit; splitting them would spread one derivation.
"""
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..kernels import rectangle3d
from ..kernels.drivers import KernelKind, register_kind
from .images2d import _apply, _lame, gauss_legendre, trace_capacity

_INV_8PI = 1.0 / (8.0 * math.pi)
#: Order of the horizontal Taylor series of ``F`` and ``L``.
_SERIES = 5


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
    """Image triples of a unit point force at height ``t`` in ``source_layer``.

    Fills ``pair_layer[k]``, ``pair_z[k]`` (height the triple emanates from),
    ``pair_eps[k] = dz/dt``, ``pair_sigma[k]`` (gauge = direction of travel: +1 upward,
    receivers above ``z``) and ``pair_coef[k, f, j, n]`` (coefficient of ``D^n`` of the
    base function of potential ``j`` for a force along ``f``), ``pair_dcoef`` = d/dt.
    Returns the number of triples (the original excluded)."""
    n_layers = shear_modulus.shape[0]
    n_orders = pair_coef.shape[3]
    cap = pair_coef.shape[0]
    q_layer = np.empty(cap + 2, dtype=np.int64)
    q_dir = np.empty(cap + 2, dtype=np.int64)
    q_ref = np.empty(cap + 2, dtype=np.int64)
    q_z = np.empty(cap + 2)
    q_eps = np.empty(cap + 2)
    q_coef = np.zeros((cap + 2, 3, 3, n_orders))
    q_dcoef = np.zeros((cap + 2, 3, 3, n_orders))
    delta_s = 1.0 / (3.0 - 4.0 * poisson_ratio[source_layer])
    for e in range(2):
        q_layer[e] = source_layer
        q_dir[e] = 1 if e == 0 else -1
        q_ref[e] = 0
        q_z[e] = t
        q_eps[e] = 1.0
        _original(q_coef[e], delta_s, shear_modulus[source_layer], float(q_dir[e]), 1.0)
    n_queue = 2
    mirrored = np.empty((3, 3, n_orders))
    dmirrored = np.empty((3, 3, n_orders))
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
        c3 = (1.0 - gamma) / (1.0 + gamma)
        c4 = 1.0 - c1
        c5 = 1.0 - c2
        c6 = 1.0 + c3
        if q_ref[i] < n_images and (c1 != 0.0 or c2 != 0.0 or c3 != 0.0):
            k = n_queue
            for f in range(3):
                for j in range(3):
                    for n in range(n_orders):
                        sign = 1.0 if n % 2 == 0 else -1.0
                        mirrored[f, j, n] = sign * q_coef[i, f, j, n]
                        dmirrored[f, j, n] = sign * q_dcoef[i, f, j, n]
            for f in range(3):
                # ref. Eq. 3.26 (the mirrored triple emanates from z' = 2d - z)
                _apply(2.0 * d1 * c1, 1, h, dh, mirrored[f, 0], dmirrored[f, 0], q_coef[k, f, 0], q_dcoef[k, f, 0],
                       n_orders)
                _apply(c2, 0, h, dh, mirrored[f, 1], dmirrored[f, 1], q_coef[k, f, 0], q_dcoef[k, f, 0], n_orders)
                _apply(-4.0 * d1 * d1 * c1, 2, h, dh, mirrored[f, 1], dmirrored[f, 1], q_coef[k, f, 0],
                       q_dcoef[k, f, 0], n_orders)
                _apply(c1, 0, h, dh, mirrored[f, 0], dmirrored[f, 0], q_coef[k, f, 1], q_dcoef[k, f, 1], n_orders)
                _apply(-2.0 * d1 * c1, 1, h, dh, mirrored[f, 1], dmirrored[f, 1], q_coef[k, f, 1],
                       q_dcoef[k, f, 1], n_orders)
                _apply(c3, 0, h, dh, mirrored[f, 2], dmirrored[f, 2], q_coef[k, f, 2], q_dcoef[k, f, 2], n_orders)
            q_layer[k] = layer
            q_dir[k] = -direction
            q_ref[k] = q_ref[i] + 1
            q_z[k] = 2.0 * d - q_z[i]
            q_eps[k] = -q_eps[i]
            n_queue += 1
        if g2 > 0.0:
            k = n_queue
            for f in range(3):
                # ref. Eq. 3.27 with T12 = +2 (d1 c4 - d2 c5) h D (see the module docstring)
                _apply(c4, 0, h, dh, q_coef[i, f, 0], q_dcoef[i, f, 0], q_coef[k, f, 0], q_dcoef[k, f, 0], n_orders)
                _apply(2.0 * (d1 * c4 - d2 * c5), 1, h, dh, q_coef[i, f, 1], q_dcoef[i, f, 1], q_coef[k, f, 0],
                       q_dcoef[k, f, 0], n_orders)
                _apply(c5, 0, h, dh, q_coef[i, f, 1], q_dcoef[i, f, 1], q_coef[k, f, 1], q_dcoef[k, f, 1], n_orders)
                _apply(c6, 0, h, dh, q_coef[i, f, 2], q_dcoef[i, f, 2], q_coef[k, f, 2], q_dcoef[k, f, 2], n_orders)
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


# -- derivatives of the base functions -----------------------------------------------------
@njit(cache=True)
def _series_mul(x, y, out):
    """Truncated product of bivariate Taylor series (``[i, j]``, ``i + j <= order``)."""
    m = x.shape[0] - 1
    out[:] = 0.0
    for i1 in range(m + 1):
        for j1 in range(m + 1 - i1):
            xv = x[i1, j1]
            if xv == 0.0:
                continue
            for i2 in range(m + 1 - i1 - j1):
                for j2 in range(m + 1 - i1 - j1 - i2):
                    out[i1 + i2, j1 + j2] += xv * y[i2, j2]


@njit(cache=True)
def horizontal_derivatives(r1, r2, r3, sf, sl, scratch):
    """``sf[a, b] = d1^a d2^b F``, ``sl[a, b] = d1^a d2^b L`` of gauge +1 at ``(r1, r2, r3)``,
    ``r3 >= 0`` (away from the singular half-line), ``a + b <= 5``; ``scratch``: (4, 6, 6)."""
    w = scratch[0]
    power = scratch[1]
    tmp = scratch[2]
    acc = scratch[3]
    rr = r1 * r1 + r2 * r2 + r3 * r3
    r = math.sqrt(rr)
    w[:] = 0.0
    w[1, 0] = 2.0 * r1 / rr
    w[0, 1] = 2.0 * r2 / rr
    w[2, 0] = 1.0 / rr
    w[0, 2] = 1.0 / rr
    # R = r sqrt(1 + w); its increment R - r
    acc[:] = 0.0
    power[:] = w
    binom = 0.5
    for k in range(1, _SERIES + 1):
        for i in range(_SERIES + 1):
            for j in range(_SERIES + 1 - i):
                acc[i, j] += r * binom * power[i, j]
        binom *= (0.5 - k) / (k + 1.0)
        if k < _SERIES:
            _series_mul(power, w, tmp)
            power[:] = tmp
    u0 = r + r3
    # log(u0 + (R - r)) = log u0 + log(1 + v), v = (R - r)/u0
    for i in range(_SERIES + 1):
        for j in range(_SERIES + 1 - i):
            w[i, j] = acc[i, j] / u0
    sl[:] = 0.0
    power[:] = w
    for k in range(1, _SERIES + 1):
        c = 1.0 / k if k % 2 == 1 else -1.0 / k
        for i in range(_SERIES + 1):
            for j in range(_SERIES + 1 - i):
                sl[i, j] += c * power[i, j]
        if k < _SERIES:
            _series_mul(power, w, tmp)
            power[:] = tmp
    sl[0, 0] = math.log(u0)
    fi = 1.0
    for i in range(_SERIES + 1):
        if i > 0:
            fi *= i
        fj = 1.0
        for j in range(_SERIES + 1 - i):
            if j > 0:
                fj *= j
            f = acc[i, j] - r3 * sl[i, j]
            if i == 0 and j == 0:
                f += r
            sf[i, j] = fi * fj * f
            sl[i, j] = fi * fj * sl[i, j]


@njit(cache=True)
def inverse_distance_derivatives(r1, r2, r3, q):
    """``q[a, b, c] = d1^a d2^b d3^c (1/r)`` for ``a + b < q.shape[0]``, ``c < q.shape[2]``
    by the recurrence of the Taylor coefficients ``t_k = d^k (1/r) / k!``:
    ``n r^2 t_k + (2n - 1) sum_i r_i t_(k - e_i) + (n - 1) sum_i t_(k - 2 e_i) = 0``
    (here on the unit vector, then scaled)."""
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    x = (r1 / r, r2 / r, r3 / r)
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
                    s += (2 * n - 1) * x[0] * q[a - 1, b, c]
                if b >= 1:
                    s += (2 * n - 1) * x[1] * q[a, b - 1, c]
                if c >= 1:
                    s += (2 * n - 1) * x[2] * q[a, b, c - 1]
                if a >= 2:
                    s += (n - 1) * q[a - 2, b, c]
                if b >= 2:
                    s += (n - 1) * q[a, b - 2, c]
                if c >= 2:
                    s += (n - 1) * q[a, b, c - 2]
                q[a, b, c] = -s / n
    # t_k / r^(n+1) * a! b! c!
    fc = 1.0
    for c in range(nc):
        if c > 0:
            fc *= c
        fa = 1.0
        for a in range(ha):
            if a > 0:
                fa *= a
            fb = 1.0
            for b in range(ha - a):
                if b > 0:
                    fb *= b
                q[a, b, c] *= fa * fb * fc / r ** (a + b + c + 1)


@njit(cache=True, inline="always")
def _base(kind, a, b, c, sf, sl, q):
    """``d1^a d2^b d3^c`` of ``F`` (kind 0) or ``L`` (kind 1), gauge +1."""
    if kind == 0:
        if c == 0:
            return sf[a, b]
        if c == 1:
            return -sl[a, b]
        return -q[a, b, c - 2]
    if c == 0:
        return sl[a, b]
    return q[a, b, c - 1]


@njit(cache=True)
def _potential_table(coef, n_orders, sigma, max_order, sf, sl, q, table):
    """``table[f, j, a, b, c] = d1^a d2^b d3^c phi_j`` of force ``f`` (``a + b + c <= max_order``)
    for the triple ``coef`` of gauge ``sigma`` (derivatives of gauge +1 taken at the
    flipped point, hence ``sigma^(c + n)``)."""
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
            for a in range(max_order + 1):
                for b in range(max_order + 1 - a):
                    for c in range(max_order + 1 - a - b):
                        s = 0.0
                        for n in range(n_orders):
                            cn = coef[f, j, n]
                            if cn != 0.0:
                                v = cn * _base(kind, a + ia, b + ib, c + n, sf, sl, q)
                                s += v if (c + n) % 2 == 0 or sigma > 0.0 else -v
                        table[f, j, a, b, c] = s


@njit(cache=True)
def _displacement_gradient(table, f, da, db, dc, scale, s, delta, out):
    """``out[i, k] += scale * d_k u_i`` of force ``f`` from the potential derivatives
    ``table`` shifted by ``(da, db, dc)`` (ref. Eq. 3.22, ``s`` the height above the
    triple's point)."""
    for i in range(3):
        for k in range(3):
            a = da + (1 if i == 0 else 0) + (1 if k == 0 else 0)
            b = db + (1 if i == 1 else 0) + (1 if k == 1 else 0)
            c = dc + (1 if i == 2 else 0) + (1 if k == 2 else 0)
            v = table[f, 0, a, b, c] - table[f, 1, a, b, c] - 2.0 * delta * s * table[f, 1, a, b, c + 1]
            if k == 2:
                v -= 2.0 * delta * table[f, 1, a, b, c]
            if i == 2:
                v += 2.0 * table[f, 1, a, b, c]
            if i == 0:  # M_1 = phi3,2
                v += table[f, 2, a - (1 if i == 0 else 0), b + 1, c]
            elif i == 1:  # M_2 = -phi3,1
                v -= table[f, 2, a + 1, b - 1, c]
            out[i, k] += scale * v


@njit(cache=True)
def Workspace(n_orders):
    """Scratch arrays of :func:`_pair_stress_gradient` for triples of up to ``n_orders``."""
    return (np.empty((6, 6)), np.empty((6, 6)), np.empty((4, 6, 6)), np.empty((6, 6, n_orders + 4)),
            np.zeros((3, 3, 6, 6, 6)), np.zeros((3, 3, 6, 6, 6)), np.empty((3, 3)))


@njit(cache=True)
def _pair_tables(r1, r2, r3, sigma, coef, dcoef, work):
    """Fill ``work``'s potential tables (derivatives up to order 4, of ``dcoef`` up to 3)
    of the triple at the receiver ``r`` (relative to the triple's point)."""
    sf, sl, scratch, q, table, dtable, grad = work
    n_orders = coef.shape[2]
    used = 1
    for f in range(3):
        for j in range(3):
            for n in range(n_orders - 1, used - 1, -1):
                if coef[f, j, n] != 0.0 or dcoef[f, j, n] != 0.0:
                    used = n + 1
                    break
    rho3 = sigma * r3
    horizontal_derivatives(r1, r2, rho3, sf, sl, scratch)
    inverse_distance_derivatives(r1, r2, rho3, q[:, :, :used + 3])
    _potential_table(coef, used, sigma, 4, sf, sl, q, table)
    _potential_table(dcoef, used, sigma, 3, sf, sl, q, dtable)


@njit(cache=True)
def _pair_stress_gradient(r1, r2, r3, eps, sigma, coef, dcoef, delta, shear_modulus, lame, out, work):
    """``out[f, q, i, k] +=`` derivative along the source coordinate ``q`` of the stress
    ``(i, k)`` at the receiver ``r`` (relative to the triple's point) of a unit force
    along ``f``; ``delta``, moduli: the receiver layer's; ``eps = dz/dt``."""
    _pair_tables(r1, r2, r3, sigma, coef, dcoef, work)
    table = work[4]
    dtable = work[5]
    grad = work[6]
    for f in range(3):
        for qq in range(3):
            grad[:] = 0.0
            if qq < 2:
                _displacement_gradient(table, f, 1 if qq == 0 else 0, 1 if qq == 1 else 0, 0, -1.0, r3, delta, grad)
            else:
                _displacement_gradient(dtable, f, 0, 0, 0, 1.0, r3, delta, grad)
                _displacement_gradient(table, f, 0, 0, 1, -eps, r3, delta, grad)
                for i in range(3):
                    for k in range(3):
                        a = (1 if i == 0 else 0) + (1 if k == 0 else 0)
                        b = (1 if i == 1 else 0) + (1 if k == 1 else 0)
                        c = (1 if i == 2 else 0) + (1 if k == 2 else 0)
                        grad[i, k] += 2.0 * delta * eps * table[f, 1, a, b, c + 1]
            trace_strain = grad[0, 0] + grad[1, 1] + grad[2, 2]
            for i in range(3):
                for k in range(3):
                    v = shear_modulus * (grad[i, k] + grad[k, i])
                    if i == k:
                        v += lame * trace_strain
                    out[f, qq, i, k] += v


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
    _pair_tables(r1, r2, r3, sigma, coef, dcoef, work)
    table = work[4]
    dtable = work[5]
    for f in range(3):
        _displacement(table, f, 1, 0, 0, -1.0, r3, delta, out[f, 0])
        _displacement(table, f, 0, 1, 0, -1.0, r3, delta, out[f, 1])
        _displacement(dtable, f, 0, 0, 0, 1.0, r3, delta, out[f, 2])
        _displacement(table, f, 0, 0, 1, -eps, r3, delta, out[f, 2])
        for i in range(3):
            a = 1 if i == 0 else 0
            b = 1 if i == 1 else 0
            c = 1 if i == 2 else 0
            out[f, 2, i] += 2.0 * delta * eps * table[f, 1, a, b, c + 1]


@njit(cache=True)
def _contract(gradient, normal, shear_modulus, lame, weight, out):
    """``out[b, i, k] += weight *`` stress of a unit DD density along global ``b`` on a
    plane of ``normal``: ``M_pq = lame (b.n) delta_pq + G (b_p n_q + b_q n_p)`` applied
    to ``gradient[p, q, i, k]``."""
    for b in range(3):
        for i in range(3):
            for k in range(3):
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


@njit(cache=True)
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
            out[b, i] = acc


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
    n_points = heights.shape[0]
    traced = (np.zeros(n_points, dtype=np.int64), np.empty((n_points, cap), dtype=np.int64),
              np.empty((n_points, cap)), np.empty((n_points, cap)), np.empty((n_points, cap)),
              np.zeros((n_points, cap, 3, 3, n_orders)), np.zeros((n_points, cap, 3, 3, n_orders)))
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(n_points):
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
def rectangle_distance(y, center, frame, a, b):
    """Distance from ``y`` to the rectangle (centre, frame rows e1 e2 n, half sides a b)."""
    d0 = y[0] - center[0]
    d1 = y[1] - center[1]
    d2 = y[2] - center[2]
    x1 = frame[0, 0] * d0 + frame[0, 1] * d1 + frame[0, 2] * d2
    x2 = frame[1, 0] * d0 + frame[1, 1] * d1 + frame[1, 2] * d2
    x3 = frame[2, 0] * d0 + frame[2, 1] * d1 + frame[2, 2] * d2
    o1 = max(abs(x1) - a, 0.0)
    o2 = max(abs(x2) - b, 0.0)
    return math.sqrt(o1 * o1 + o2 * o2 + x3 * x3)


@njit(cache=True)
def subdivisions(y, receiver_layer, center, frame, a, b, source_layer, interfaces, max_sub):
    """Sub-squares per side so that each is at most half as large as the distance from
    the receiver to the nearest singular point of the integrand: the rectangle's mirror
    images in the interfaces bounding the source's and the receiver's layers, and the
    rectangle itself when the receiver is in another layer."""
    dmin = np.inf
    if receiver_layer != source_layer:
        dmin = rectangle_distance(y, center, frame, a, b)
    n_if = interfaces.shape[0]
    mirrored = np.empty(3)
    mframe = frame.copy()
    for r in range(3):
        mframe[r, 2] = -frame[r, 2]
    for layer in (source_layer, receiver_layer):
        for k in (layer - 1, layer):
            if 0 <= k < n_if:
                mirrored[0] = center[0]
                mirrored[1] = center[1]
                mirrored[2] = 2.0 * interfaces[k] - center[2]
                dmin = min(dmin, rectangle_distance(y, mirrored, mframe, a, b))
    if dmin <= 0.0:
        return max_sub
    n = int(math.ceil(4.0 * max(a, b) / dmin))
    return min(max(n, 1), max_sub)


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
def _heights(center, frame, a, b, xi, eta):
    t = np.empty(xi.shape[0])
    for g in range(xi.shape[0]):
        t[g] = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
    return t


@njit(cache=True)
def image_rectangle_stress(y, receiver_layer, center, frame, a, b, source_layer, interfaces, shear_modulus,
                           poisson_ratio, n_images, n_gauss, n_sub, out):
    """Complementary stress ``out[b, i, k]`` at ``y`` of a unit global DD ``b`` on the
    rectangle, by ``n_gauss^2`` points on each of ``n_sub^2`` sub-squares."""
    xi, eta, wt = square_rule(n_gauss, n_sub)
    traced = trace_points(_heights(center, frame, a, b, xi, eta), source_layer, interfaces, shear_modulus,
                          poisson_ratio, n_images)
    out[:] = 0.0
    _integrate(y, receiver_layer, center, frame, a, b, source_layer, shear_modulus, poisson_ratio, xi, eta, wt,
               traced, 0, out, np.empty((3, 3, 3, 3)), Workspace(traced[5].shape[-1]), Workspace(1),
               np.zeros((2, 3, 3, 1)))


# -- constant rectangles: the kernel data and the per-pair functions of the drivers ---------------
#: Sub-square levels (2^level per side) whose traced triples a source keeps.
_CACHED_LEVELS = 2


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
    gauss_points: int  #: Gauss-Legendre points per side of a sub-square of the image quadrature
    max_subdivisions: int  #: largest number of sub-squares per side (:func:`subdivisions`)
    singular_shift: float  #: see :mod:`hmatddm.kernels.drivers` (singular points)
    near_fraction: float  #: near-miss distance, fraction of the smaller half size
    alpha: float  #: ref. Eq. 6.11 scaling (0: none)
    self_max: np.ndarray  #: (N,) largest |entry| of each self block (ref. Eq. 6.11)


@njit(cache=True)
def _level(n_sub):
    level = 0
    while 2 ** level < n_sub:
        level += 1
    return level


@njit(cache=True)
def workspace(data):
    """Scratch: local stress (3, 3, 3), image stress (3, 3, 3), gradient (3, 3, 3, 3), the
    Kelvin scratch (2, 3, 3, 1) and the one-order :func:`Workspace`."""
    return np.empty((3, 3, 3)), np.zeros((3, 3, 3)), np.empty((3, 3, 3, 3)), np.zeros((2, 3, 3, 1)), Workspace(1)


@njit(cache=True)
def source_state(data, j, work):
    """What the receivers of source ``j`` share: the rules of the cached levels (2^level
    sub-squares per side) and their image triples (traced when a receiver first needs a
    level)."""
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    rules = []
    traced_levels = []
    for level in range(_CACHED_LEVELS):
        xi, eta, wt = square_rule(data.gauss_points, 2 ** level)
        rules.append((xi, eta, wt))
        traced_levels.append(trace_points(_heights(center, frame, a, b, xi[:0], eta[:0]), ls, data.interfaces,
                                          data.shear_modulus, data.poisson_ratio, data.n_images))
    is_traced = np.zeros(_CACHED_LEVELS, dtype=np.bool_)
    n_orders = trace_capacity(ls, data.shear_modulus, data.n_images)[1]
    return rules, traced_levels, is_traced, Workspace(n_orders)


@njit(cache=True)
def element_traction(data, i, j, state, work, block):
    """``block`` (3, 3): traction at the centre of element ``i`` (its normal) for a unit
    global DD of rectangle ``j``: closed form of the source layer's material (with the
    closed-form kernel's singular and near-miss handling) plus images, the source's
    traced triples reused across receivers."""
    rules, traced_levels, is_traced, ws = state
    local, image, gradient, kelvin, ws1 = work
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
        level = _level(subdivisions(point, lr, center, frame, a, b, ls, interfaces, data.max_subdivisions))
        image[:] = 0.0
        if level < _CACHED_LEVELS:
            xi, eta, wt = rules[level]
            if not is_traced[level]:
                traced_levels[level] = trace_points(_heights(center, frame, a, b, xi, eta), ls, interfaces, g, nu,
                                                    data.n_images)
                is_traced[level] = True
            _integrate(point, lr, center, frame, a, b, ls, g, nu, xi, eta, wt, traced_levels[level], 0, image,
                       gradient, ws, ws1, kelvin)
        else:
            image_rectangle_stress(point, lr, center, frame, a, b, ls, interfaces, g, nu, data.n_images,
                                   data.gauss_points, 2 ** level, image)
        for p in range(3):
            for q in range(3):
                block[p, q] += image[q, p, 0] * normal[0] + image[q, p, 1] * normal[1] + image[q, p, 2] * normal[2]


@njit(cache=True)
def element_stress(data, point, point_layer, j, work, out):
    """``out[q, i, k]``: stress at ``point`` (in ``point_layer``; zero in a void layer)
    for a unit global DD ``q`` of rectangle ``j``, closed form plus images (the
    quadrature of :func:`element_traction`). A point within ``near_fraction`` smaller
    half sides of an edge counts as on it."""
    local, image, gradient, kelvin, ws1 = work
    g = data.shear_modulus
    nu = data.poisson_ratio
    if g[point_layer] <= 0.0:
        out[:] = 0.0
        return
    ls = data.layer[j]
    a = data.half_a[j]
    b = data.half_b[j]
    rectangle3d.stress_pair(point, data.centers[j], data.frames[j], a, b, g[ls], nu[ls], data.singular_shift, out,
                            local, data.near_fraction * min(a, b))
    if data.interfaces.shape[0] > 0:
        level = _level(subdivisions(point, point_layer, data.centers[j], data.frames[j], a, b, ls, data.interfaces,
                                    data.max_subdivisions))
        image_rectangle_stress(point, point_layer, data.centers[j], data.frames[j], a, b, ls, data.interfaces, g, nu,
                               data.n_images, data.gauss_points, 2 ** level, image)
        for q in range(3):
            for i in range(3):
                for k in range(3):
                    out[q, i, k] += image[q, i, k]


register_kind(LayeredRectangles, KernelKind(workspace, source_state, element_traction, element_stress,
                                            rectangle3d.edge_distance))
