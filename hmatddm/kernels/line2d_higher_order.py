"""Linear and quadratic displacement-discontinuity elements on a straight segment (2D
plane strain), in closed form (ref. Sec. 3.5; Crawford & Curran 1982).

The element lies on its local axis ``y = 0`` from ``x = -a`` to ``x = a``; its DD varies
as ``D(s) = sum_k N_k(s/a) D_k`` with the shape functions of ref. App. B
(:mod:`hmatddm.mesh.shape_functions`), nodes inside the element where it is collocated. The
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

Kernel data: :class:`NodalSegments` (the loops over element pairs are
:mod:`hmatddm.kernels.drivers`). Unknowns of element ``e`` are ``(e * n + k) * 2 + q``
for node ``k`` and global component ``q`` (docs/conventions.md §2).
"""
import math

import numpy as np
from numba import njit

from .drivers import HOMOGENEOUS_FIELDS, KernelKind, kernel_record, no_source_state, register_kind
from .line2d import REGULAR, SEGMENT_FIELDS, UNDEFINED, rotate_to_global, tip_averaging, tip_distance

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
    case, x_plus, x_minus = tip_averaging(x, y, a, singular_shift, near)
    if case == REGULAR:
        local_stress_nodes(x, y, a, coefficients, shear_modulus, poisson_ratio, out)
        return
    if case == UNDEFINED:
        out[:] = np.nan
        return
    tmp = np.empty_like(out)
    local_stress_nodes(x_plus, 0.0, a, coefficients, shear_modulus, poisson_ratio, out)
    local_stress_nodes(x_minus, 0.0, a, coefficients, shear_modulus, poisson_ratio, tmp)
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


#: The shape-function fields of every record of nodal segments (after the common ones).
SHAPE_FIELDS = (("coefficients", np.ndarray, "(n, 3) monomial coefficients of the n shape functions"),
                ("nodes", np.ndarray, "(n,) intrinsic coordinates of the collocation nodes"))
NodalSegments = kernel_record("NodalSegments", __name__,
                              "Kernel data of linear and quadratic 2D elements (the record :mod:`.drivers` take).",
                              SEGMENT_FIELDS + HOMOGENEOUS_FIELDS, SHAPE_FIELDS)


@njit(cache=True)
def workspace(data):
    """Scratch: local stress per node (n, 2, 2, 2), traction per node (n, 2, 2), a point."""
    n_nodes = data.nodes.shape[0]
    return np.empty((n_nodes, 2, 2, 2)), np.empty((n_nodes, 2, 2)), np.empty(2)


@njit(cache=True, inline="always")
def element_traction(data, i, j, state, work, block):
    """``block[2 r + p, 2 k + q]``: traction p at node r of element ``i`` for a unit DD q
    at node k of element ``j`` (:func:`traction_nodes`; near misses: :func:`near_distance`)."""
    local, pair, point = work
    nodes = data.nodes
    half_length = data.half_length
    near = 0.0
    if i != j:
        near = near_distance(data.near_fraction, half_length[i], half_length[j], nodes)
    normal = data.frames[i, 1]
    for r in range(nodes.shape[0]):
        node_point(data.centers[i], data.frames[i], half_length[i], nodes[r], point)
        traction_nodes(point, normal, data.centers[j], data.frames[j], half_length[j], data.coefficients,
                       data.shear_modulus, data.poisson_ratio, data.singular_shift, pair, local, near)
        set_node_rows(block, pair, r)


@njit(cache=True, inline="always")
def element_stress(data, point, point_layer, j, work, out):
    """``out[2 k + q]`` (2n, 2, 2): :func:`stress_nodes` of element ``j`` at ``point``; a
    point within ``near_fraction`` half lengths of an end counts as on it."""
    n_nodes = data.nodes.shape[0]
    a = data.half_length[j]
    stress_nodes(point, data.centers[j], data.frames[j], a, data.coefficients, data.shear_modulus,
                 data.poisson_ratio, data.singular_shift, out.reshape((n_nodes, 2, 2, 2)), work[0],
                 data.near_fraction * a)


@njit(cache=True)
def set_node_rows(block, pair, r):
    """The rows of receiver node ``r`` in an element block: ``block[2 r + p, 2 k + q] =
    pair[k, p, q]`` (traction p for a unit DD q at source node k)."""
    for k in range(pair.shape[0]):
        for p in range(2):
            for q in range(2):
                block[2 * r + p, 2 * k + q] = pair[k, p, q]


@njit(cache=True)
def edge_distance(data, i, j):
    """Distance from the collocation nodes of element ``i`` to the nearer end of element
    ``j`` (any record with ``centers``, ``frames``, ``half_length`` and ``nodes``, as the
    layered one of :mod:`hmatddm.layered.higher_order2d`)."""
    centers, frames, half_length, nodes = data.centers, data.frames, data.half_length, data.nodes
    point = np.empty(2)
    best = np.inf
    for r in range(nodes.shape[0]):
        node_point(centers[i], frames[i], half_length[i], nodes[r], point)
        x, y = _local(point, centers[j], frames[j])
        best = min(best, tip_distance(x, y, half_length[j]))
    return best


register_kind(NodalSegments, KernelKind(workspace, no_source_state, element_traction, element_stress, edge_distance))
