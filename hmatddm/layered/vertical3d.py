"""The image triples of a vertical rectangle in closed form (issue 32, item 1): the reduction
derived and checked in ``_derive_closed_form3d.py`` (item 4), compiled.

A vertical rectangle, turned about the vertical so that its horizontal side runs along x
(the layers are invariant under that turn), has points ``(c1 + xi, c2, t)``; a triple of
the image method emanates from ``(c1 + xi, c2, z0 + eps t)`` with coefficients of ``D^n``
quadratic in ``t`` (at most: ``_derive_closed_form3d.coefficient_degrees``), fitted
exactly from the triples traced at the bottom, middle and top heights. Every term of the
triple's stress (:func:`.potentials3d._pair_stress_gradient`) is ``P(t) d1^a d2^b d3^c B``
with ``B`` the base function ``F`` or ``L`` of the triple's gauge and ``deg P <= c``, so:

* along the height, ``d3 = -eps d/dt``: by parts, the integral is a sum over the top and
  bottom edges of ``P^(i) d3^(c-1-i) B`` (``d3^-1 F = K``, ``d3^-1 L = -sigma F``;
  :func:`_vertical_primitive`);
* along the strike, ``d1^-1`` of ``d1^a`` (``a >= 1``) is the difference of ``d1^(a-1)``
  at the two ends; the terms without ``d1`` are turned by the Laplace equation into terms
  with ``d1^2`` and terms ``d2^(0 or 1) d3^m`` of a derivative of ``1/r``, whose ``d1^-1``
  is a derivative of ``log(r + r1)`` (:func:`_log_table`).

The potential tables of the triple integrated over the rectangle replace the point tables
of :func:`.potentials3d._pair_stress_gradient`, and its ``_stress`` and the moment
contraction are used as they are (:func:`vertical_image_stress`).
"""
import math

import numpy as np
from numba import njit

from .potentials3d import (Workspace, _axis_series, _base_table, _contract, _pair_stress_gradient, _stress,
                           base_derivatives, inverse_distance_scratch, inverse_distance_step,
                           potential_base)
from .rectangle_quadrature import entry_order, far_order
from .segment_quadrature import gauss_legendre

#: Largest vertical derivative order held in the edge tables (D orders up to 5 and the
#: Laplace turns of the terms without d1: 4 + 5 + 4 + 1).
M_MAX = 15
#: Gauss points per side from which a triple is taken in closed form rather than by
#: quadrature (:func:`vertical_image_stress`).
CLOSED_FROM = 4
#: |e_z| of a side above which the rectangle counts as vertical (as okada3d.COS_ZERO).
VERTICAL = 1.0 - 1e-12


@njit(cache=True)
def _low_inverse_distance(r1, r2, r3, q):
    """``q[a, b, c] = d1^a d2^b d3^c (1/r)`` for ``a < q.shape[0]`` and a total order
    ``a + b + c < q.shape[1]`` (``q`` (na, n, n)): the recurrence of
    :func:`.potentials3d.inverse_distance_derivatives` by total order, for the ``a <= 1``
    entries that :func:`_log_table` reads (the whole table to its orders cost ten times
    as much: 13.5 us of the 41 us of an :func:`_edge_table`)."""
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    inv = 1.0 / r
    x0 = r1 * inv
    x1 = r2 * inv
    x2 = r3 * inv
    na = q.shape[0]
    top = q.shape[1]
    q[0, 0, 0] = 1.0
    for n in range(1, top):
        for a in range(min(na, n + 1)):
            for b in range(n - a + 1):
                q[a, b, n - a - b] = inverse_distance_step(q, a, b, n - a - b, n, x0, x1, x2)
    # t_k / r^(n+1) * a! b! c!, from the highest order down (the recurrence read the unscaled)
    for n in range(top):
        for a in range(min(na, n + 1)):
            for b in range(n - a + 1):
                c = n - a - b
                f = inv ** (n + 1)
                for k in range(2, a + 1):
                    f *= k
                for k in range(2, b + 1):
                    f *= k
                for k in range(2, c + 1):
                    f *= k
                q[a, b, c] *= f


@njit(cache=True)
def _log_table(r1, r2, r3, flip, out, q, ser):
    """``out[b, k] = d2^b d3^k`` of ``s log(r + s r1)`` (``s = -1`` when ``flip``, the
    primitive in r1 of ``1/r`` without cancellation where ``r1 < 0``) for ``b + k <
    out.shape[0]``: along r2 from the Taylor series of ``W = 1/(R (R + s r1))``
    (:func:`.potentials3d._axis_series` with the axes turned), ``d3`` once from
    ``d2^b d3 = b! r3 w_b``, and beyond by the Laplace equation
    ``d3^2 = -d2^2 - d1^2`` with ``d1 (s log(r + s r1)) = 1/r`` (``q``: the derivatives of
    ``1/r`` at ``r``, ``q[1, b, k]`` used)."""
    n = out.shape[0]
    s = -1.0 if flip else 1.0
    u3 = s * r1
    r = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
    _axis_series(r2, u3, r, n + 1, ser)
    w = ser[3]
    fact = 1.0
    for b in range(n):
        if b == 0:
            out[0, 0] = s * math.log(r + u3)
        else:
            if b > 1:
                fact *= b - 1
            out[b, 0] = s * fact * (r2 * w[b - 1] + (w[b - 2] if b >= 2 else 0.0))
    fact = 1.0
    for b in range(n - 1):
        if b > 0:
            fact *= b
        out[b, 1] = s * fact * r3 * w[b]
    for k in range(2, n):
        for b in range(n - k):
            out[b, k] = -q[1, b, k - 2] - out[b + 2, k - 2]


@njit(cache=True)
def _vertical_primitive(kind, a, b, m, r1, r2, r3s, sigma, sf, sl, base):
    """``d1^a d2^b d3^m B`` at a point for ``m >= -1`` from its tables (``base`` of
    :func:`.potentials3d._base_table`, ``sf``, ``sl`` at the flipped point ``(r1, r2,
    sigma r3)``; ``r3s = sigma r3``): ``d3^-1 F = K`` of the gauge (``sigma K(r1, r2,
    sigma r3)``, ``K = 3/4 r3 r + (rho^2/4 - r3^2/2) L - rho^2/8``), ``d3^-1 L = -sigma F``."""
    if m >= 0:
        return base[kind, a, b, m]
    if kind == 1:
        return -sigma * sf[a, b]
    if a >= 1:  # d1 K = (r3 d1 F + r1 L) / 2, d2 K = (r3 d2 F + r2 L) / 2 (gauge +1)
        v = r3s * sf[a, b] + r1 * sl[a - 1, b] + ((a - 1) * sl[a - 2, b] if a >= 2 else 0.0)
    elif b >= 1:
        v = r3s * sf[0, b] + r2 * sl[0, b - 1] + ((b - 1) * sl[0, b - 2] if b >= 2 else 0.0)
    else:
        rho2 = r1 * r1 + r2 * r2
        r = math.sqrt(rho2 + r3s * r3s)
        return sigma * (0.75 * r3s * r + (0.25 * rho2 - 0.5 * r3s * r3s) * sl[0, 0] - 0.125 * rho2)
    return sigma * 0.5 * v


@njit(cache=True)
def _edge_table(ends, r2, r3, sigma, sj, work):
    """``sj[kind, a, b, m + 1]``: the strike integral (``r1`` from ``ends[0]`` to
    ``ends[1]``) of ``d1^a d2^b d3^m B`` along one edge (height ``r3``) for ``m`` from -1,
    ``a + b <= 5``; NaN where the reduction does not reach (never read by the stress)."""
    sf, sl, ser, q, base, logs, qlog, serlog, pad = work
    n_m = sj.shape[3]
    sj[:] = 0.0
    for e in range(2):
        sign = 1.0 if e == 1 else -1.0
        full = q.shape[0] + q.shape[2]  # every entry of q
        base_derivatives(ends[e], r2, sigma * r3, sf, sl, q, ser, pad, full)
        _base_table(sigma, base.shape[3], sf, sl, q, base, full)
        for kind in range(2):
            for a in range(1, 6):
                for b in range(6 - a):
                    # m = -1 from the primitive in the height; m >= 0 the tables as they are
                    sj[kind, a, b, 0] += sign * _vertical_primitive(kind, a - 1, b, -1, ends[e], r2, sigma * r3,
                                                                    sigma, sf, sl, base)
                    for m in range(n_m - 1):
                        if m < base.shape[3]:
                            sj[kind, a, b, m + 1] += sign * base[kind, a - 1, b, m]
                        else:
                            sj[kind, a, b, m + 1] = math.nan
    # the terms without d1: d2^(0, 1) d3^m of 1/r through log(r + r1); both ends on one branch
    flip = max(ends[0], ends[1]) < 0.0
    n_log = logs.shape[0]
    for e in range(2):
        sign = 1.0 if e == 1 else -1.0
        _low_inverse_distance(ends[e], r2, r3, qlog)
        _log_table(ends[e], r2, r3, flip, logs, qlog, serlog)
        for b in range(2):
            for m in range(-1, n_m - 1):
                # d3^m F = -d3^(m-2) (1/r) for m >= 2; d3^m L = sigma d3^(m-1) (1/r) for m >= 1
                for kind in range(2):
                    k = m - 2 if kind == 0 else m - 1
                    if k < 0 or b + k >= n_log:
                        sj[kind, 0, b, m + 1] = math.nan
                    else:
                        sj[kind, 0, b, m + 1] += sign * (-1.0 if kind == 0 else sigma) * logs[b, k]
    for kind in range(2):
        for b in range(2, 6):
            for m in range(-1, n_m - 1):
                if m + 3 < n_m:
                    sj[kind, 0, b, m + 1] = -sj[kind, 2, b - 2, m + 1] - sj[kind, 0, b - 2, m + 3]
                else:
                    sj[kind, 0, b, m + 1] = math.nan


@njit(cache=True)
def _poly_derivative(p, i, t):
    """``P^(i)(t)`` of the cubic ``p[0] + p[1] t + p[2] t^2 + p[3] t^3``."""
    if i == 0:
        return p[0] + t * (p[1] + t * (p[2] + t * p[3]))
    if i == 1:
        return p[1] + t * (2.0 * p[2] + 3.0 * t * p[3])
    if i == 2:
        return 2.0 * p[2] + 6.0 * t * p[3]
    return 6.0 * p[3]


@njit(cache=True)
def _integrated_table(polys, s0, s1, weighted, order, eps, t_bot, t_top, sj_bot, sj_top, out):
    """``out[f, j, a, b, c] +=`` the potential table of :func:`.potentials3d._potential_table`
    integrated over the rectangle, ``polys[f, j, n]`` the quadratic coefficients of ``D^n``
    (times ``s = s0 + s1 t`` when ``weighted``, for the entries the ``s`` term reads)."""
    p = np.zeros(4)
    for f in range(3):
        for j in range(3):
            if f == 2 and j == 2:
                continue
            if weighted and j != 1:
                continue
            kind, ia, ib = potential_base(f, j)
            first = order + 1 if weighted else order
            last = order + 1 if j == 1 else order
            for n in range(polys.shape[2]):
                p[:] = 0.0
                for d in range(3):
                    p[d] += polys[f, j, n, d] * s0 if weighted else polys[f, j, n, d]
                    if weighted:
                        p[d + 1] += polys[f, j, n, d] * s1
                degree = 3
                while degree >= 0 and p[degree] == 0.0:
                    degree -= 1
                if degree < 0:
                    continue
                for o in range(first, last + 1):
                    for a in range(o + 1):
                        for b in range(o + 1 - a):
                            c = o - a - b
                            if weighted and c == 0:
                                continue
                            v = 0.0
                            for i in range(degree + 1):
                                m = c + n - 1 - i
                                if m < -1:  # deg P above the d3 order: no total derivative
                                    v = math.nan
                                    break
                                w = (-1.0) ** i * (-eps) ** (i + 1)
                                v += w * (_poly_derivative(p, i, t_top) * sj_top[kind, a + ia, b + ib, m + 1]
                                          - _poly_derivative(p, i, t_bot) * sj_bot[kind, a + ia, b + ib, m + 1])
                            out[f, j, a, b, c] += v


@njit(cache=True)
def _far_triple(yr, hs, hd, t_mid, z0, e, sg, polys, dpolys, n_gauss, delta, shear_modulus, lame, coef_t, dcoef_t,
                work, gradient):
    """``gradient +=`` the source-derivative gradient of one triple (point ``z0 + e t``,
    gauge ``sg``) integrated over the rectangle by ``n_gauss`` Gauss points per side
    (:func:`.potentials3d._pair_stress_gradient` at each, its coefficients at the point's
    height ``t`` from the quadratic fits ``polys``, ``dpolys``, times the weight: the
    gradient is linear in them). ``yr``: the receiver in the turned frame."""
    x, w = gauss_legendre(n_gauss)
    n_orders = polys.shape[2]
    for ia in range(n_gauss):
        r1 = yr[0] - hs * x[ia]
        for ib in range(n_gauss):
            t = t_mid + hd * x[ib]
            weight = w[ia] * w[ib] * hs * hd
            for f in range(3):
                for j in range(3):
                    for n in range(n_orders):
                        p = polys[f, j, n]
                        coef_t[f, j, n] = weight * (p[0] + t * (p[1] + t * p[2]))
                        p = dpolys[f, j, n]
                        dcoef_t[f, j, n] = weight * (p[0] + t * (p[1] + t * p[2]))
            _pair_stress_gradient(r1, yr[1], yr[2] - (z0 + e * t), e, sg, coef_t, dcoef_t, delta, shear_modulus,
                                  lame, gradient, work)


@njit(cache=True)
def vertical_workspace(n_orders):
    """Scratch of :func:`vertical_image_stress` for triples of up to ``n_orders`` orders of
    ``D`` (the tracer's buffer)."""
    n_log = M_MAX - 1
    edge = (np.empty((6, 6)), np.empty((6, 6)), np.empty((4, 6)), np.empty((6, 6, M_MAX - 2)),
            np.empty((2, 6, 6, M_MAX - 1)), np.empty((n_log, n_log)), np.empty((2, n_log - 1, n_log - 1)),
            np.empty((4, n_log + 1)), inverse_distance_scratch(M_MAX - 2))
    tables = (np.empty((2, 6, 6, M_MAX)), np.empty((2, 6, 6, M_MAX)), np.zeros((2, 4, 3, 3, 6, 6, 6)))
    return (edge, tables, np.zeros((3, 3, 3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3, 3)), np.zeros(3),
            Workspace(n_orders), np.zeros((3, 3, n_orders)), np.zeros((3, 3, n_orders)))


@njit(cache=True)
def vertical_image_stress(y, receiver_layer, center, strike, hs, hd, heights, traced, shear_modulus, poisson_ratio,
                          source_layer, far_tol, triple_tol, work, out):
    """``out[b, i, k] +=`` the stress at ``y`` (global) of a unit global DD ``b`` on the
    vertical rectangle (centre ``center``, horizontal side along ``strike``, half sides
    ``hs`` along it and ``hd`` up) of the triples ``traced`` (three points: the heights
    ``heights`` = bottom, middle, top; the same triples at each) acting in
    ``receiver_layer``, in closed form (module docstring). A triple whose image of the
    rectangle is far enough from ``y`` to need fewer than :data:`CLOSED_FROM` Gauss points
    per side takes those points instead, its coefficients at their heights from the same
    quadratic fit (:func:`_far_triple`): the rule of
    :func:`.rectangle_quadrature._image_order` for that triple alone, :func:`far_order`
    to the relative error ``far_tol`` (0: every triple in closed form), or fewer by
    :func:`entry_order` when ``triple_tol > 0`` (the error allowed per unit largest shear
    modulus). Returns False, adding nothing, where the triples differ between the heights
    or a table does not reach."""
    return _vertical_stress(y, receiver_layer, center, strike, hs, hd, heights, traced, shear_modulus, poisson_ratio,
                            source_layer, far_tol, triple_tol, work, out)


@njit(cache=True, inline="always")
def _vertical_stress(y, receiver_layer, center, strike, hs, hd, heights, traced, shear_modulus, poisson_ratio,
                     source_layer, far_tol, triple_tol, work, out):
    """:func:`vertical_image_stress`, inlined into it and into the record's held
    :func:`.images3d._vertical_terms` (the closed forms compiled once for every caller of
    the image terms, not again in each: benchmarks/RESULTS.md, issue 32)."""
    edge, tables, gradient, with_s, without, local, yr, far_work, coef_t, dcoef_t = work
    sj_bot, sj_top, integrated = tables
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    s0, s1 = strike[0], strike[1]
    dx = y[0] - center[0]
    dy = y[1] - center[1]
    yr[0] = s0 * dx + s1 * dy  # the turned frame: x along the strike, y = z x strike
    yr[1] = -s1 * dx + s0 * dy
    yr[2] = y[2]
    if n_pairs[0] != n_pairs[1] or n_pairs[0] != n_pairs[2]:
        return False
    t_bot, t_mid, t_top = heights[0], heights[1], heights[2]
    g_r = shear_modulus[receiver_layer]
    nu_r = poisson_ratio[receiver_layer]
    delta_r = 1.0 / (3.0 - 4.0 * nu_r)
    lame_r = 2.0 * g_r * nu_r / (1.0 - 2.0 * nu_r)
    gradient[:] = 0.0
    n_orders = coef.shape[4]
    polys = np.zeros((3, 3, n_orders, 3))
    dpolys = np.zeros((3, 3, n_orders, 3))
    ends = np.array([yr[0] - hs, yr[0] + hs])
    # the integrated tables of every triple of one eps summed (the stress is linear in
    # them, and eps is all it needs of the triple besides): one _stress pass per sign
    used = np.zeros(2, dtype=np.bool_)
    for k in range(n_pairs[0]):
        if layer[0, k] != receiver_layer:
            continue
        e = eps[0, k]
        sg = sigma[0, k]
        z0 = z[1, k] - e * t_mid
        for p in (0, 2):
            if layer[p, k] != layer[0, k] or eps[p, k] != e or sigma[p, k] != sg:
                return False
            if abs(z[p, k] - (z0 + e * heights[p])) > 1e-9 * (1.0 + abs(z0)):
                return False
        # quadratic in t through the three heights (Lagrange), the degrees above min(n, 2) dropped
        h = 0.5 * (t_top - t_bot)
        for f in range(3):
            for j in range(3):
                for n in range(n_orders):
                    for which in range(2):
                        source = coef if which == 0 else dcoef
                        target = polys if which == 0 else dpolys
                        v0, v1, v2 = source[0, k, f, j, n], source[1, k, f, j, n], source[2, k, f, j, n]
                        c2 = (v2 - 2.0 * v1 + v0) / (2.0 * h * h)
                        c1 = (v2 - v0) / (2.0 * h) - 2.0 * c2 * t_mid
                        c0 = v1 - c1 * t_mid - c2 * t_mid * t_mid
                        top = min(n, 2) - which
                        target[f, j, n, 0] = c0 if top >= 0 else 0.0
                        target[f, j, n, 1] = c1 if top >= 1 else 0.0
                        target[f, j, n, 2] = c2 if top >= 2 else 0.0
        if far_tol > 0.0:
            # distance from y to the triple's image of the rectangle (x along the strike)
            z_lo = min(z0 + e * t_bot, z0 + e * t_top)
            z_hi = max(z0 + e * t_bot, z0 + e * t_top)
            along = max(abs(yr[0]) - hs, 0.0)
            up = max(z_lo - yr[2], yr[2] - z_hi, 0.0)
            distance = math.sqrt(along * along + yr[1] * yr[1] + up * up)
            n_gauss = far_order(distance / max(hs, hd), np.int64(CLOSED_FROM), far_tol)
            if triple_tol > 0.0:
                n_gauss = min(n_gauss, entry_order(distance, hs, hd, np.int64(CLOSED_FROM), triple_tol))
            if n_gauss < CLOSED_FROM:
                _far_triple(yr, hs, hd, t_mid, z0, e, sg, polys, dpolys, n_gauss, delta_r, g_r, lame_r, coef_t,
                            dcoef_t, far_work, gradient)
                continue
        _edge_table(ends, yr[1], yr[2] - (z0 + e * t_bot), sg, sj_bot, edge)
        _edge_table(ends, yr[1], yr[2] - (z0 + e * t_top), sg, sj_top, edge)
        sa = yr[2] - z0  # s = y3 - z(t) = sa - e t
        side = 0 if e > 0.0 else 1
        if not used[side]:
            integrated[side] = 0.0
            used[side] = True
        # run-time flags and orders: one compiled _integrated_table, not one per literal
        for which in range(4):
            order = 3 - which // 2
            _integrated_table(polys if order == 3 else dpolys, sa, -e, which % 2 == 1, order, e, t_bot, t_top,
                              sj_bot, sj_top, integrated[side, which])
    for side in range(2):
        if not used[side]:
            continue
        e = 1.0 if side == 0 else -1.0
        plain, weighted, dplain, dweighted = (integrated[side, 0], integrated[side, 1], integrated[side, 2],
                                              integrated[side, 3])
        for f in range(3):
            for v in range(4):
                da = 1 if v == 0 else 0
                db = 1 if v == 1 else 0
                dc = 1 if v == 3 else 0
                scale = -e if v == 3 else (1.0 if v == 2 else -1.0)
                q = min(v, 2)
                table = dplain if v == 2 else plain
                stable = dweighted if v == 2 else weighted
                _stress(table, f, da, db, dc, scale, 0.0, delta_r, g_r, lame_r, gradient[f, q])
                with_s[:] = 0.0
                without[:] = 0.0
                _stress(stable, f, da, db, dc, scale, 1.0, delta_r, g_r, lame_r, with_s)
                _stress(stable, f, da, db, dc, scale, 0.0, delta_r, g_r, lame_r, without)
                for i in range(3):
                    for kk in range(3):
                        gradient[f, q, i, kk] += with_s[i, kk] - without[i, kk]
            for i in range(3):
                for kk in range(3):
                    a = (1 if i == 0 else 0) + (1 if kk == 0 else 0)
                    b = (1 if i == 1 else 0) + (1 if kk == 1 else 0)
                    c = (1 if i == 2 else 0) + (1 if kk == 2 else 0)
                    gradient[f, 2, i, kk] += 4.0 * g_r * delta_r * e * plain[f, 1, a, b, c + 1]
    for f in range(3):
        for q in range(3):
            for i in range(3):
                for kk in range(3):
                    if not math.isfinite(gradient[f, q, i, kk]):
                        return False
    g_s = shear_modulus[source_layer]
    nu_s = poisson_ratio[source_layer]
    normal = np.array([0.0, -1.0, 0.0])  # strike x up = -y in the turned frame
    local[:] = 0.0
    _contract(gradient, normal, g_s, 2.0 * g_s * nu_s / (1.0 - 2.0 * nu_s), 1.0, local)
    # back to the global frame: rows of the turn x' = strike, y' = (-s1, s0, 0), z
    rot = np.array([[s0, s1, 0.0], [-s1, s0, 0.0], [0.0, 0.0, 1.0]])
    for bg in range(3):
        for i in range(3):
            for kk in range(3):
                acc = 0.0
                for b in range(3):
                    if rot[b, bg] == 0.0:
                        continue
                    for p in range(3):
                        for qq in range(3):
                            acc += rot[b, bg] * rot[p, i] * rot[qq, kk] * local[b, p, qq]
                out[bg, i, kk] += acc
    return True
