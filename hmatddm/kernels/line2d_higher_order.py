"""Linear and quadratic displacement-discontinuity elements on a straight segment (2D
plane strain), in closed form (ref. Sec. 3.5; Crawford & Curran 1982).

The element lies on its local axis ``y = 0`` from ``x = -a`` to ``x = a``; its DD varies
as ``D(s) = sum_k N_k(s/a) D_k`` with the shape functions of ref. App. B
(:mod:`hmatddm.shape_functions`), nodes inside the element where it is collocated. The
stress formulas of the constant element (:mod:`.line2d`, ref. App. A eqs 10-19) hold for
any DD density along ``y = 0`` once ``g`` is the potential of that density:

    g_k(x, y) = 1/(4 pi (1 - nu)) int_{-a}^{a} ln r(x - s, y) N_k(s/a) ds,

so each node needs ``g_xx, g_xy, g_xxx, g_xxy`` of its shape function. With
``X = x - s``, ``r^2 = X^2 + y^2``, ``L = ln r``, ``T = atan(X / y)`` and ``phi = ln r``,
the moments ``M_j[F] = int_{x-a}^{x+a} F(X) X^j dX`` of the four derivatives of ``phi``
are elementary (derived by parts, checked by differentiation):

    F = phi_XX  = (y^2-X^2)/r^4 : X/r^2,            X^2/r^2 - L,             X^3/r^2 - 2X + 2yT
    F = phi_Xy  = -2Xy/r^4      : y/r^2,            Xy/r^2 - T,              X^2 y/r^2 - 2yL
    F = phi_XXX                 : (y^2-X^2)/r^4,    X phi_XX - X/r^2,        X^2 phi_XX - 2X^2/r^2 + 2L
    F = phi_XXy                 : -2Xy/r^4,         X phi_Xy - y/r^2,        X^2 phi_Xy - 2Xy/r^2 + 2T

and ``int (s/a)^m F(x - s) ds`` follows from ``s = x - X`` by the binomial expansion. The
jump of ``T`` across the element (``[T] = +-pi`` inside it) is the jump of ``s_xx``
that a varying DD carries; on the element (``|y| <= 1e-12 a``) the mean of the two faces
is returned (``[T] = 0``). The traction on the element's line is continuous.

Far from the element (``x^2 + y^2 > FAR_RATIO^2 a^2``) the closed form loses digits to
cancellation (its terms grow like ``(R/a)^m`` against a result that decays), so there
the same integrals are taken by Gauss-Legendre quadrature of the point kernel with
``FAR_GAUSS_POINTS`` (fewer the farther), exact to round-off at that distance.

Data layout of the block generator (:func:`traction_block`):
``(centers, frames, half_length, half_length, params, self_max, coefficients, nodes)`` --
the six arrays of :func:`hmatddm.kernels.element_data` plus the shape functions'
monomial coefficients ``(n, 3)`` and nodes ``(n,)``. Unknowns of element ``e`` are
``(e * n + k) * 2 + q`` for node ``k`` and global component ``q`` (docs/conventions.md §2).
"""
import math

import numpy as np
from numba import njit, prange

from .correction import scale_to_self
from .line2d import on_tip, rotate_to_global, tip_distance

_INV_4PI = 1.0 / (4.0 * math.pi)

#: Beyond this distance from the centre, in half lengths, integrals use Gauss quadrature.
FAR_RATIO = 5.0
#: Gauss-Legendre points of the far-field quadrature beyond ``FAR_RATIO``, 12 and 30
#: half lengths: measured against 40-digit quadrature, the largest relative error of any
#: integral is 4e-16, 2e-15 and 1e-15 at those bounds (and falls farther out).
FAR_GAUSS_POINTS = (10, 7, 6)
_GAUSS_X0, _GAUSS_W0 = np.polynomial.legendre.leggauss(FAR_GAUSS_POINTS[0])
_GAUSS_X1, _GAUSS_W1 = np.polynomial.legendre.leggauss(FAR_GAUSS_POINTS[1])
_GAUSS_X2, _GAUSS_W2 = np.polynomial.legendre.leggauss(FAR_GAUSS_POINTS[2])


@njit(cache=True)
def monomial_integrals(x, y, a, out):
    """``out[d, m] = int_{-a}^{a} D_d phi(x - s, y) (s/a)^m ds`` for ``m = 0, 1, 2`` and
    ``D_d = (d_XX, d_Xy, d_XXX, d_XXy)`` of ``phi = ln r``; closed form near the
    element, Gauss quadrature far from it (see the module docstring)."""
    ysq = y * y
    distance_sq = x * x + ysq
    if distance_sq > (FAR_RATIO * a) ** 2:
        if distance_sq > (30.0 * a) ** 2:
            gauss_x, gauss_w = _GAUSS_X2, _GAUSS_W2
        elif distance_sq > (12.0 * a) ** 2:
            gauss_x, gauss_w = _GAUSS_X1, _GAUSS_W1
        else:
            gauss_x, gauss_w = _GAUSS_X0, _GAUSS_W0
        for d in range(4):
            for m in range(3):
                out[d, m] = 0.0
        for g in range(gauss_x.shape[0]):
            xi = gauss_x[g]
            X = x - a * xi
            inv_r2 = 1.0 / (X * X + ysq)
            inv_r4 = inv_r2 * inv_r2
            inv_r6 = inv_r4 * inv_r2
            f0 = (ysq - X * X) * inv_r4
            f1 = -2.0 * X * y * inv_r4
            f2 = 2.0 * X * (X * X - 3.0 * ysq) * inv_r6
            f3 = 2.0 * y * (3.0 * X * X - ysq) * inv_r6
            w = a * gauss_w[g]
            for m in range(3):
                out[0, m] += w * f0
                out[1, m] += w * f1
                out[2, m] += w * f2
                out[3, m] += w * f3
                w *= xi
        return
    x1 = x - a
    x2 = x + a
    r1 = x1 * x1 + ysq
    r2 = x2 * x2 + ysq
    # [L] and [T] between the ends X1 = x - a and X2 = x + a
    dlog = 0.5 * math.log(r2 / r1)
    dangle = 0.0
    if abs(y) > 1e-12 * a:  # on the element's line to round-off: the mean of both faces
        dangle = math.atan2(y * (x2 - x1), ysq + x1 * x2)
    moments = np.empty((4, 3))
    for d in range(4):
        for j in range(3):
            moments[d, j] = 0.0
    for end in range(2):
        X = x2 if end == 0 else x1
        sign = 1.0 if end == 0 else -1.0
        inv_r2 = 1.0 / (X * X + ysq)
        inv_r4 = inv_r2 * inv_r2
        fxx = (ysq - X * X) * inv_r4
        fxy = -2.0 * X * y * inv_r4
        moments[0, 0] += sign * X * inv_r2
        moments[0, 1] += sign * X * X * inv_r2
        moments[0, 2] += sign * (X * X * X * inv_r2 - 2.0 * X)
        moments[1, 0] += sign * y * inv_r2
        moments[1, 1] += sign * X * y * inv_r2
        moments[1, 2] += sign * X * X * y * inv_r2
        moments[2, 0] += sign * fxx
        moments[2, 1] += sign * (X * fxx - X * inv_r2)
        moments[2, 2] += sign * (X * X * fxx - 2.0 * X * X * inv_r2)
        moments[3, 0] += sign * fxy
        moments[3, 1] += sign * (X * fxy - y * inv_r2)
        moments[3, 2] += sign * (X * X * fxy - 2.0 * X * y * inv_r2)
    moments[0, 1] -= dlog
    moments[0, 2] += 2.0 * y * dangle
    moments[1, 1] -= dangle
    moments[1, 2] -= 2.0 * y * dlog
    moments[2, 2] += 2.0 * dlog
    moments[3, 2] += 2.0 * dangle
    inv_a = 1.0 / a
    for d in range(4):
        m0 = moments[d, 0]
        m1 = moments[d, 1]
        m2 = moments[d, 2]
        out[d, 0] = m0
        out[d, 1] = (x * m0 - m1) * inv_a
        out[d, 2] = (x * x * m0 - 2.0 * x * m1 + m2) * inv_a * inv_a


@njit(cache=True)
def local_stress_nodes(x, y, a, coefficients, shear_modulus, poisson_ratio, out):
    """``out[n, k, i, j]`` (n_nodes x 2 x 2 x 2): local stress at ``(x, y)`` for a unit
    local DD component k (0 shear, 1 normal) at node n of the segment, all other nodal
    DDs zero. Same formulas as :func:`hmatddm.kernels.line2d.local_stress` with ``g`` of
    the node's shape function."""
    integrals = np.empty((4, 3))
    monomial_integrals(x, y, a, integrals)
    c = 2.0 * shear_modulus * _INV_4PI / (1.0 - poisson_ratio)  # 2G times the factor of g
    for n in range(coefficients.shape[0]):
        gxx = 0.0
        gxy = 0.0
        gxxx = 0.0
        gxxy = 0.0
        for m in range(3):
            w = c * coefficients[n, m]
            gxx += w * integrals[0, m]
            gxy += w * integrals[1, m]
            gxxx += w * integrals[2, m]
            gxxy += w * integrals[3, m]
        gyy = -gxx
        out[n, 0, 0, 0] = 2.0 * gxy - y * gxxx
        out[n, 0, 0, 1] = gyy - y * gxxy
        out[n, 0, 1, 1] = y * gxxx
        out[n, 1, 0, 0] = gyy - y * gxxy
        out[n, 1, 0, 1] = y * gxxx
        out[n, 1, 1, 1] = gyy + y * gxxy
        out[n, 0, 1, 0] = out[n, 0, 0, 1]
        out[n, 1, 1, 0] = out[n, 1, 0, 1]


@njit(cache=True)
def local_stress_nodes_corrected(x, y, a, coefficients, shear_modulus, poisson_ratio, singular_shift, out,
                                 near=0.0):
    """:func:`local_stress_nodes` with the end points (and, for ``near > 0``, points
    within ``near`` of one) handled as :func:`hmatddm.kernels.line2d.local_stress_corrected`:
    NaN when ``singular_shift <= 0``, else the mean of the values ``+-singular_shift * a``
    along the segment from the end point (ref. Sec. 6.2.3)."""
    if not (on_tip(x, y, a) or (near > 0.0 and tip_distance(x, y, a) <= near)):
        local_stress_nodes(x, y, a, coefficients, shear_modulus, poisson_ratio, out)
        return
    if singular_shift <= 0.0:
        out[:] = np.nan
        return
    tip = a if x >= 0.0 else -a
    delta = singular_shift * a
    tmp = np.empty_like(out)
    local_stress_nodes(tip + delta, 0.0, a, coefficients, shear_modulus, poisson_ratio, out)
    local_stress_nodes(tip - delta, 0.0, a, coefficients, shear_modulus, poisson_ratio, tmp)
    for n in range(out.shape[0]):
        for k in range(2):
            for i in range(2):
                for j in range(2):
                    out[n, k, i, j] = 0.5 * (out[n, k, i, j] + tmp[n, k, i, j])


@njit(cache=True)
def _local(point, center, frame):
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    return frame[0, 0] * dx + frame[0, 1] * dy, frame[1, 0] * dx + frame[1, 1] * dy


@njit(cache=True)
def traction_nodes(point, normal, center, frame, a, coefficients, shear_modulus, poisson_ratio, singular_shift,
                   out, work, near=0.0):
    """``out[n, p, q]``: global traction component p at ``point`` (receiver ``normal``)
    for a unit global DD component q at node n of the segment (ref. Eqs 2.57-2.58)."""
    x, y = _local(point, center, frame)
    local_stress_nodes_corrected(x, y, a, coefficients, shear_modulus, poisson_ratio, singular_shift, work, near)
    m0 = frame[0, 0] * normal[0] + frame[0, 1] * normal[1]
    m1 = frame[1, 0] * normal[0] + frame[1, 1] * normal[1]
    for n in range(coefficients.shape[0]):
        t00 = work[n, 0, 0, 0] * m0 + work[n, 0, 0, 1] * m1
        t10 = work[n, 0, 1, 0] * m0 + work[n, 0, 1, 1] * m1
        t01 = work[n, 1, 0, 0] * m0 + work[n, 1, 0, 1] * m1
        t11 = work[n, 1, 1, 0] * m0 + work[n, 1, 1, 1] * m1
        for q in range(2):
            c0 = t00 * frame[0, q] + t01 * frame[1, q]
            c1 = t10 * frame[0, q] + t11 * frame[1, q]
            for p in range(2):
                out[n, p, q] = frame[0, p] * c0 + frame[1, p] * c1


@njit(cache=True)
def stress_nodes(point, center, frame, a, coefficients, shear_modulus, poisson_ratio, singular_shift, out, work,
                 near=0.0):
    """``out[n, q, i, j]``: global stress at ``point`` for a unit global DD component q at
    node n of the segment."""
    x, y = _local(point, center, frame)
    local_stress_nodes_corrected(x, y, a, coefficients, shear_modulus, poisson_ratio, singular_shift, work, near)
    for n in range(coefficients.shape[0]):
        rotate_to_global(frame, work[n], out[n])


@njit(cache=True)
def node_point(center, frame, a, xi, out):
    """``out`` (2,) = the point at intrinsic coordinate ``xi`` of the segment."""
    out[0] = center[0] + a * xi * frame[0, 0]
    out[1] = center[1] + a * xi * frame[0, 1]


@njit(cache=True)
def near_distance(near_fraction, a_receiver, a_source, nodes):
    """Distance below which a collocation node counts as on a source's end point: the
    operator's ``near_fraction`` of the smaller half length, scaled by the gap between an
    element's outer node and its own end (``1 - max|xi|``), so that the nodes next to a
    shared end point of a conforming mesh are never affected."""
    outer = 0.0
    for k in range(nodes.shape[0]):
        outer = max(outer, abs(nodes[k]))
    return near_fraction * (1.0 - outer) * min(a_receiver, a_source)


@njit(cache=True)
def traction_block(data, rows, cols, out):
    """Block generator kernel (see :mod:`hmatddm.hmatrix.generator`) with ``2 n`` unknowns
    per element: ``out[(a n + r) 2 + p, (b n + k) 2 + q]`` is the traction component p at
    node r of element ``rows[a]`` for a unit DD component q at node k of ``cols[b]``.
    ``data`` as in the module docstring; ``params = [G, nu, singular_shift, alpha,
    near_fraction]`` as for :func:`hmatddm.kernels.line2d.traction_block`."""
    centers, frames, half_length, _unused, params, self_max, coefficients, nodes = data
    g = params[0]
    nu = params[1]
    shift = params[2]
    alpha = params[3]
    near_fraction = params[4]
    n_nodes = nodes.shape[0]
    work = np.empty((n_nodes, 2, 2, 2))
    pair = np.empty((n_nodes, 2, 2))
    block = np.empty((2 * n_nodes, 2 * n_nodes))
    point = np.empty(2)
    for ia in range(rows.shape[0]):
        i = rows[ia]
        normal = frames[i, 1]
        for jb in range(cols.shape[0]):
            j = cols[jb]
            near = 0.0
            if i != j:
                near = near_distance(near_fraction, half_length[i], half_length[j], nodes)
            for r in range(n_nodes):
                node_point(centers[i], frames[i], half_length[i], nodes[r], point)
                traction_nodes(point, normal, centers[j], frames[j], half_length[j], coefficients, g, nu, shift, pair,
                               work, near)
                set_node_rows(block, pair, r)
            store_block(block, out, ia, jb, i, j, alpha, self_max)


@njit(cache=True)
def set_node_rows(block, pair, r):
    """The rows of receiver node ``r`` in an element block: ``block[2 r + p, 2 k + q] =
    pair[k, p, q]`` (traction p for a unit DD q at source node k)."""
    for k in range(pair.shape[0]):
        for p in range(2):
            for q in range(2):
                block[2 * r + p, 2 * k + q] = pair[k, p, q]


@njit(cache=True)
def store_block(block, out, ia, jb, i, j, alpha, self_max):
    """Scale an off-diagonal element block by ref. Eq. 6.11 (``alpha > 0``), then copy it
    to its place ``(ia, jb)`` in ``out``."""
    dof = block.shape[0]
    if alpha > 0.0 and i != j:
        scale_to_self(block, alpha * self_max[j])
    for p in range(dof):
        for q in range(dof):
            out[dof * ia + p, dof * jb + q] = block[p, q]


@njit(cache=True, parallel=True)
def traction_matrix(data, out):
    """Dense assembly of the whole traction matrix, parallel over row elements."""
    centers = data[0]
    dof = 2 * data[-1].shape[0]
    n = centers.shape[0]
    cols = np.arange(n)
    for i in prange(n):
        rows = np.array([i])
        traction_block(data, rows, cols, out[dof * i:dof * i + dof, :])


@njit(cache=True)
def edge_distance(data, i, j):
    """Distance from the collocation nodes of element ``i`` to the nearer end of element
    ``j`` (any data tuple that starts with centres, frames, half lengths and ends with
    the nodes, as the layered one of :mod:`hmatddm.layered_higher_order`)."""
    centers, frames, half_length, nodes = data[0], data[1], data[2], data[-1]
    point = np.empty(2)
    best = np.inf
    for r in range(nodes.shape[0]):
        node_point(centers[i], frames[i], half_length[i], nodes[r], point)
        x, y = _local(point, centers[j], frames[j])
        best = min(best, tip_distance(x, y, half_length[j]))
    return best


@njit(cache=True)
def singular_pairs(data, rows, cols, out):
    """``out[k]`` = True when the influence block of receiver ``rows[k]`` and source
    ``cols[k]`` (from :func:`traction_block`) is not finite: a singular pair."""
    dof = 2 * data[-1].shape[0]
    block = np.empty((dof, dof))
    for k in range(rows.shape[0]):
        traction_block(data, rows[k:k + 1], cols[k:k + 1], block)
        out[k] = not np.all(np.isfinite(block))


@njit(cache=True, parallel=True)
def stress_at_points(points, centers, frames, half_length, coefficients, params, dd, out):
    """Induced global stress ``out`` (M, 2, 2) at ``points`` (M, 2) by the nodal DDs
    ``dd`` (N, n, 2). ``params = [G, nu, singular_shift, _, near_fraction]``: a point
    within ``near_fraction`` half lengths of an end point counts as on it."""
    g = params[0]
    nu = params[1]
    shift = params[2]
    near_fraction = params[4]
    n_nodes = coefficients.shape[0]
    for m in prange(points.shape[0]):
        work = np.empty((n_nodes, 2, 2, 2))
        pair = np.empty((n_nodes, 2, 2, 2))
        acc = np.zeros((2, 2))
        for j in range(centers.shape[0]):
            stress_nodes(points[m], centers[j], frames[j], half_length[j], coefficients, g, nu, shift, pair, work,
                         near_fraction * half_length[j])
            for n in range(n_nodes):
                for q in range(2):
                    dq = dd[j, n, q]
                    for i in range(2):
                        for k in range(2):
                            acc[i, k] += pair[n, q, i, k] * dq
        out[m] = acc
