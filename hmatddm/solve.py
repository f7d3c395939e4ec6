"""Solving the DDM system and evaluating its results (ref. Sec. 2.3, Eqs 2.47-2.49).

* :func:`solve` finds the DDs whose traction equals a given load: direct LU for the
  ``dense`` backend, GMRES preconditioned by the near field for ``hmatrix``.
* :func:`opening`, :func:`slip`: normal and tangential parts of the DD.
* :func:`stress_at`, :func:`mean_stress_at`: the stress the DDs induce anywhere
  (ref. Eq. 2.59; mean stress as in ref. Eqs 5.24-5.28), summed directly or, for many
  points and elements (remote failure of a natural-fracture network, ref. Sec. 5.3),
  with the far field compressed by adaptive cross approximation to a chosen accuracy.
"""
import hashlib
import math
import time

import numpy as np
from numba import njit, prange

from ._validation import finite_array, finite_scalar
from .errors import InputError
from .kernels import element_data
from .kernels.line2d import stress_pair as _stress_pair2d
from .kernels.rectangle3d import _INV_8PI, _r_plus
from .kernels.rectangle3d import local_stress_corrected as _local_stress_corrected
from .kernels.rectangle3d import on_edge as _on_edge
from .kernels.rectangle3d import g_derivatives as _g_derivatives
from .layered.medium import LayeredMedium
from .material import Elastic
from .mesh import Mesh2D, Mesh3D, check_mesh


def _as_element_major(name, values, n_elements, dof):
    array = finite_array(name, values)
    if array.shape == (n_elements, dof):
        return array.reshape(-1)
    if array.shape == (n_elements * dof,):
        return array
    raise InputError(f"{name} must have shape ({n_elements}, {dof}) or ({n_elements * dof},), got {array.shape}")


def solve(operator, traction, rtol=1e-10, maxiter=None, restart=100, x0=None, return_info=False):
    """DDs (N, d) in the global frame such that ``operator @ dd = traction``; nodal DDs
    (N, n, 2) for a 2D mesh of ``element_order`` 1 or 2 (n = order + 1 nodes).

    Parameters
    ----------
    operator : ElasticityOperator or ExtendedElasticityOperator
        Solved by its own ``solve`` (dense: LU; otherwise preconditioned GMRES).
    traction : (N, d) or (N*d,) array
        Traction sigma.n at the collocation points, element-major, global frame
        (``-p * mesh.normals`` for a crack under net pressure ``p``). Linear and quadratic
        elements: (N, n, 2), (N*n, 2) or flat at the nodes, or (N, 2) applied at every
        node of its element (:func:`hmatddm.nodal.nodal_array`).
    rtol : float
        Relative residual ``||b - A x|| / ||b||`` asked of GMRES (``hmatrix``), in (0, 1).
        The dense backend solves directly (LU) and ignores it.
    maxiter, restart : int
        GMRES limits (``maxiter`` counts restart cycles; default allows 20 cycles).
    x0 : optional initial guess, same shapes as ``traction``.
    return_info : bool
        Also return a dict with ``iterations`` and ``residual``.

    Raises
    ------
    ConvergenceError
        GMRES stopped above ``rtol``; the message and ``.residual`` give what was reached.
    """
    from .extended_operator import ExtendedElasticityOperator
    from .operators import ElasticityOperator

    if not isinstance(operator, (ElasticityOperator, ExtendedElasticityOperator)):
        raise InputError(f"operator must be an ElasticityOperator, got {type(operator).__name__}")
    rtol = finite_scalar("rtol", rtol)
    if not 0.0 < rtol < 1.0:
        raise InputError(f"rtol must be in (0, 1), got {rtol}")
    n, d = operator.mesh.n_elements, operator.dof
    guess = None
    if operator.mesh.n_nodes > 1:
        from .nodal import nodal_array

        b = nodal_array("traction", traction, operator.mesh, uniform=True).reshape(-1)
        if x0 is not None:
            guess = nodal_array("x0", x0, operator.mesh).reshape(-1)
    else:
        b = _as_element_major("traction", traction, n, d)
        if x0 is not None:
            guess = _as_element_major("x0", x0, n, d)
    x, info = operator.solve(b, x0=guess, rtol=rtol, restart=restart, maxiter=maxiter if maxiter is not None else 20)
    if "residual" not in info:  # a direct solve: measure it
        info["residual"] = float(np.linalg.norm(operator.matvec(x) - b) / max(np.linalg.norm(b), np.finfo(float).tiny))
    dd = x.reshape(n, d) if operator.mesh.n_nodes == 1 else x.reshape(n, operator.mesh.n_nodes, -1)
    return (dd, info) if return_info else dd


def _dd_array(mesh, dd):
    return _as_element_major("dd", dd, mesh.n_elements, mesh.dim).reshape(mesh.n_elements, mesh.dim)


def opening(mesh, dd):
    """Opening ``w = DD . n`` (N,), positive for an open crack (docs/conventions.md §1);
    nodal openings (N, n) for linear and quadratic elements (anywhere along the elements:
    :func:`hmatddm.nodal.opening_at`)."""
    if getattr(mesh, "n_nodes", 1) > 1:
        from . import nodal

        return nodal.opening(mesh, dd)
    dd = _dd_array(mesh, dd)
    return np.einsum("ij,ij->i", dd, mesh.normals)


def slip(mesh, dd):
    """Tangential part of the DD, ``DD - w n`` (N, d), in the global frame ((N, n, 2) at
    the nodes of linear and quadratic elements)."""
    if getattr(mesh, "n_nodes", 1) > 1:
        from . import nodal

        return nodal.slip(mesh, dd)
    dd = _dd_array(mesh, dd)
    return dd - opening(mesh, dd)[:, None] * mesh.normals


def _check_points(mesh, points):
    check_mesh(mesh)
    return np.ascontiguousarray(finite_array("points", points, (None, mesh.dim)))


# ---------------------------------------------------------------------------------------
# Induced stress at points (ref. Eq. 2.59). The kernels below contract each element's DD
# before rotating to the global frame (one rotation per point-element pair instead of one
# per DD component), run in parallel over a fixed split of the work (the sums do not
# depend on the thread count) and, for many points and elements, compress the far field
# by adaptive cross approximation (ACA) of the point x element contribution matrix.
# ---------------------------------------------------------------------------------------

# What is evaluated per (point, element): the six stress components (xx, yy, zz, xy, xz,
# yz) in 3D, (xx, yy, xy) in 2D, or the mean stress.
_STRESS3D, _MEAN3D, _STRESS2D, _MEAN2D = 0, 1, 2, 3
_N_OUT = {_STRESS3D: 6, _MEAN3D: 1, _STRESS2D: 3, _MEAN2D: 1}
_DIRECT_CHUNKS = 64   # fixed split of the point range in the direct sum
_TREE_CHUNKS = 16     # fixed split of the block list in the compressed sum
METHODS = ("auto", "direct", "tree")

#: Relative accuracy asked of every compressed far-field block (``method="tree"``, and
#: ``"auto"`` on large problems); see :func:`stress_at` for what it means for the result.
DEFAULT_STRESS_EPS = 1e-5
#: ``method="auto"`` compresses when (points x elements) reaches this.
AUTO_TREE_PAIRS = 2_000_000
#: Admissibility ``min(diam) <= eta * dist`` and leaf size of the compressed sum.
STRESS_ETA = 1.0
STRESS_LEAF_SIZE = 64
#: Leaf size of the element (source) tree.
STRESS_SOURCE_LEAF_SIZE = 64
#: Far blocks with fewer points or elements than this are summed exactly.
STRESS_MIN_ACA = 64


@njit(cache=True, inline="always")
def _second_derivatives(x1, x2, x3, a, b):
    """``(J11, J22, J13, J23)`` of ``sum_corners +-I`` at a point of the octant
    ``x1, x2, x3 >= 0``: the part of :func:`hmatddm.kernels.rectangle3d.potential_derivatives`
    that the mean stress needs."""
    j11 = j22 = j13 = j23 = 0.0
    zsq = x3 * x3
    for corner in range(4):
        xi1 = a if (corner == 0 or corner == 2) else -a
        xi2 = b if corner < 2 else -b
        sign = 1.0 if (corner == 0 or corner == 3) else -1.0
        X = x1 - xi1
        Y = x2 - xi2
        r = math.sqrt(X * X + Y * Y + zsq)
        a_y = 1.0 / (r * _r_plus(Y, X, zsq, r))
        a_x = 1.0 / (r * _r_plus(X, Y, zsq, r))
        j11 += sign * X * a_y
        j22 += sign * Y * a_x
        j13 += sign * x3 * a_y
        j23 += sign * x3 * a_x
    return j11, j22, j13, j23


@njit(cache=True, inline="always")
def _rotate_out3d(s00, s11, s22, s01, s02, s12, frame, out):
    """``out[:6]`` = (xx, yy, zz, xy, xz, yz) of ``F^T s F``: the global components of
    the symmetric local tensor ``s`` (``frame`` rows are the local axes, ref. Eq. 2.57)."""
    t00 = s00 * frame[0, 0] + s01 * frame[1, 0] + s02 * frame[2, 0]
    t01 = s00 * frame[0, 1] + s01 * frame[1, 1] + s02 * frame[2, 1]
    t02 = s00 * frame[0, 2] + s01 * frame[1, 2] + s02 * frame[2, 2]
    t10 = s01 * frame[0, 0] + s11 * frame[1, 0] + s12 * frame[2, 0]
    t11 = s01 * frame[0, 1] + s11 * frame[1, 1] + s12 * frame[2, 1]
    t12 = s01 * frame[0, 2] + s11 * frame[1, 2] + s12 * frame[2, 2]
    t20 = s02 * frame[0, 0] + s12 * frame[1, 0] + s22 * frame[2, 0]
    t21 = s02 * frame[0, 1] + s12 * frame[1, 1] + s22 * frame[2, 1]
    t22 = s02 * frame[0, 2] + s12 * frame[1, 2] + s22 * frame[2, 2]
    out[0] = frame[0, 0] * t00 + frame[1, 0] * t10 + frame[2, 0] * t20
    out[1] = frame[0, 1] * t01 + frame[1, 1] * t11 + frame[2, 1] * t21
    out[2] = frame[0, 2] * t02 + frame[1, 2] * t12 + frame[2, 2] * t22
    out[3] = frame[0, 0] * t01 + frame[1, 0] * t11 + frame[2, 0] * t21
    out[4] = frame[0, 0] * t02 + frame[1, 0] * t12 + frame[2, 0] * t22
    out[5] = frame[0, 1] * t02 + frame[1, 1] * t12 + frame[2, 1] * t22


@njit(cache=True)
def _pair3d_edge(mode, x1, x2, x3, d0, d1, d2, frame, a, b, g, nu, shift, near, out, work):
    """:func:`_pair3d` for a point on an edge of the element, or within the distance
    ``near`` of one: the reference's averaging across the edge (ref. Sec. 6.2.3), or NaN
    when ``shift`` is 0."""
    _local_stress_corrected(x1, x2, x3, a, b, g, nu, shift, work, near)
    t00 = work[0, 0, 0] * d0 + work[1, 0, 0] * d1 + work[2, 0, 0] * d2
    t11 = work[0, 1, 1] * d0 + work[1, 1, 1] * d1 + work[2, 1, 1] * d2
    t22 = work[0, 2, 2] * d0 + work[1, 2, 2] * d1 + work[2, 2, 2] * d2
    if mode == _MEAN3D:
        out[0] = (t00 + t11 + t22) / 3.0
        return
    t01 = work[0, 0, 1] * d0 + work[1, 0, 1] * d1 + work[2, 0, 1] * d2
    t02 = work[0, 0, 2] * d0 + work[1, 0, 2] * d1 + work[2, 0, 2] * d2
    t12 = work[0, 1, 2] * d0 + work[1, 1, 2] * d1 + work[2, 1, 2] * d2
    _rotate_out3d(t00, t11, t22, t01, t02, t12, frame, out)


@njit(cache=True, inline="always")
def _near_boundary(x1, x2, x3, a, b, distance):
    """Whether the local point may lie within ``distance`` of the rectangle's boundary
    (a cheap test; :func:`hmatddm.kernels.rectangle3d.local_stress_corrected` decides)."""
    if abs(x3) > distance:
        return False
    u = abs(x1)
    v = abs(x2)
    if u > a + distance or v > b + distance:
        return False
    return abs(u - a) <= distance or abs(v - b) <= distance


@njit(cache=True, inline="always")
def _pair3d(mode, px, py, pz, j, centers, frames, half_a, half_b, g, nu, shift, near_fraction, dd, out, work):
    """Contribution at the point ``(px, py, pz)`` of rectangle ``j`` carrying its global
    DD ``dd[j]``: ``out[:6]`` the global stress (xx, yy, zz, xy, xz, yz) for
    ``_STRESS3D`` (ref. Eqs 2.57-2.59: the rows of
    :func:`hmatddm.kernels.rectangle3d.local_stress` contracted with the local DD, then
    one rotation), ``out[0]`` the mean stress for ``_MEAN3D`` (ref. Eq. 5.28: the trace
    is ``2 (1 + nu) [g_13, g_23, g_33] . DD_local``). ``work``: (3, 3, 3) scratch for
    points on an edge, or within ``near_fraction`` of the element's smaller half size of
    one (a near miss, treated as on it)."""
    frame = frames[j]
    a = half_a[j]
    b = half_b[j]
    dx = px - centers[j, 0]
    dy = py - centers[j, 1]
    dz = pz - centers[j, 2]
    x1 = frame[0, 0] * dx + frame[0, 1] * dy + frame[0, 2] * dz
    x2 = frame[1, 0] * dx + frame[1, 1] * dy + frame[1, 2] * dz
    x3 = frame[2, 0] * dx + frame[2, 1] * dy + frame[2, 2] * dz
    e0 = dd[j, 0]
    e1 = dd[j, 1]
    e2 = dd[j, 2]
    d0 = frame[0, 0] * e0 + frame[0, 1] * e1 + frame[0, 2] * e2
    d1 = frame[1, 0] * e0 + frame[1, 1] * e1 + frame[1, 2] * e2
    d2 = frame[2, 0] * e0 + frame[2, 1] * e1 + frame[2, 2] * e2
    near = near_fraction * min(a, b)
    if _on_edge(x1, x2, x3, a, b) or (near > 0.0 and _near_boundary(x1, x2, x3, a, b, near)):
        _pair3d_edge(mode, x1, x2, x3, d0, d1, d2, frame, a, b, g, nu, shift, near, out, work)
        return
    s1 = 1.0 if x1 >= 0.0 else -1.0
    s2 = 1.0 if x2 >= 0.0 else -1.0
    s3 = 1.0 if x3 >= 0.0 else -1.0
    z = abs(x3)
    c = -2.0 * g * _INV_8PI / (1.0 - nu)  # 2G times the factor of g (rectangle3d.local_stress)
    if mode == _MEAN3D:
        j11, j22, j13, j23 = _second_derivatives(abs(x1), abs(x2), z, a, b)
        out[0] = 2.0 * (1.0 + nu) / 3.0 * c * (s1 * s3 * j13 * d0 + s2 * s3 * j23 * d1 - (j11 + j22) * d2)
        return
    (g11, g22, g33, g12, g13, g23, zg111, zg112, zg113, zg122, zg123, zg222, zg223, zg133, zg233,
     zg333) = _g_derivatives(x1, x2, x3, a, b, g, nu)
    m = 1.0 - 2.0 * nu
    s00 = d0 * (2.0 * g13 - zg111) + d1 * (2.0 * nu * g23 - zg112) + d2 * (g33 + m * g22 - zg113)
    s01 = d0 * ((1.0 - nu) * g23 - zg112) + d1 * ((1.0 - nu) * g13 - zg122) - d2 * (m * g12 + zg123)
    s02 = d0 * (nu * g22 + g33 - zg113) - d1 * (nu * g12 + zg123) - d2 * zg133
    s11 = d0 * (2.0 * nu * g13 - zg122) + d1 * (2.0 * g23 - zg222) + d2 * (g33 + m * g11 - zg223)
    s12 = -d0 * (nu * g12 + zg123) + d1 * (nu * g11 + g33 - zg223) - d2 * zg233
    s22 = -d0 * zg133 - d1 * zg233 + d2 * (g33 - zg333)
    _rotate_out3d(s00, s11, s22, s01, s02, s12, frame, out)


@njit(cache=True)
def _pair2d(mode, point, center, frame, a, g, nu, shift, near_fraction, dd, out, work, pair):
    """2D (plane strain) twin of :func:`_pair3d`: ``out[:3]`` = (xx, yy, xy) for
    ``_STRESS2D``, ``out[0]`` = ``(1 + nu)(s_xx + s_yy)/3`` for ``_MEAN2D``.
    ``work``, ``pair``: (2, 2, 2) scratch."""
    _stress_pair2d(point, center, frame, a, g, nu, shift, pair, work, near_fraction * a)
    sxx = pair[0, 0, 0] * dd[0] + pair[1, 0, 0] * dd[1]
    syy = pair[0, 1, 1] * dd[0] + pair[1, 1, 1] * dd[1]
    if mode == _MEAN2D:
        out[0] = (1.0 + nu) * (sxx + syy) / 3.0
        return
    out[0] = sxx
    out[1] = syy
    out[2] = pair[0, 0, 1] * dd[0] + pair[1, 0, 1] * dd[1]


# Contributions of many elements at one point, or of one element at many points. The
# mode test sits outside the loops, so that each loop inlines its own pair kernel (a
# dispatcher passed as an argument would do the same but defeats numba's on-disk cache).

@njit(cache=True, inline="always")
def _pair2d_at(mode, points, t, j, centers, frames, half_a, params, dd, out, work2, pair2):
    _pair2d(mode, points[t], centers[j], frames[j], half_a[j], params[0], params[1], params[2], params[4], dd[j],
            out, work2, pair2)


@njit(cache=True)
def _point_sum(mode, points, t, sources, centers, frames, half_a, half_b, params, dd, acc, value, work3, work2,
               pair2):
    """``acc[t] += sum_{j in sources} contribution(t, j)``."""
    px = points[t, 0]
    py = points[t, 1]
    if mode == _STRESS3D:
        pz = points[t, 2]
        for j in sources:
            _pair3d(_STRESS3D, px, py, pz, j, centers, frames, half_a, half_b, params[0], params[1], params[2],
                    params[4], dd, value, work3)
            for c in range(6):
                acc[t, c] += value[c]
    elif mode == _MEAN3D:
        pz = points[t, 2]
        for j in sources:
            _pair3d(_MEAN3D, px, py, pz, j, centers, frames, half_a, half_b, params[0], params[1], params[2],
                    params[4], dd, value, work3)
            acc[t, 0] += value[0]
    else:
        n_out = 3 if mode == _STRESS2D else 1
        for j in sources:
            _pair2d_at(mode, points, t, j, centers, frames, half_a, params, dd, value, work2, pair2)
            for c in range(n_out):
                acc[t, c] += value[c]


@njit(cache=True)
def _point_row(mode, points, t, sources, centers, frames, half_a, half_b, params, dd, row, value, work3, work2,
               pair2):
    """``row[c, b]`` = component ``c`` of the contribution of ``sources[b]`` at point ``t``."""
    px = points[t, 0]
    py = points[t, 1]
    if mode == _STRESS3D:
        pz = points[t, 2]
        for b in range(sources.size):
            _pair3d(_STRESS3D, px, py, pz, sources[b], centers, frames, half_a, half_b, params[0], params[1],
                    params[2], params[4], dd, value, work3)
            for c in range(6):
                row[c, b] = value[c]
    elif mode == _MEAN3D:
        pz = points[t, 2]
        for b in range(sources.size):
            _pair3d(_MEAN3D, px, py, pz, sources[b], centers, frames, half_a, half_b, params[0], params[1],
                    params[2], params[4], dd, value, work3)
            row[0, b] = value[0]
    else:
        n_out = 3 if mode == _STRESS2D else 1
        for b in range(sources.size):
            _pair2d_at(mode, points, t, sources[b], centers, frames, half_a, params, dd, value, work2, pair2)
            for c in range(n_out):
                row[c, b] = value[c]


@njit(cache=True)
def _element_column(mode, points, targets, j, centers, frames, half_a, half_b, params, dd, column, value, work3,
                    work2, pair2):
    """``column[n_out * a + c]`` = component ``c`` of the contribution of element ``j``
    at point ``targets[a]``."""
    if mode == _STRESS3D:
        for a in range(targets.size):
            t = targets[a]
            _pair3d(_STRESS3D, points[t, 0], points[t, 1], points[t, 2], j, centers, frames, half_a, half_b,
                    params[0], params[1], params[2], params[4], dd, value, work3)
            for c in range(6):
                column[6 * a + c] = value[c]
    elif mode == _MEAN3D:
        for a in range(targets.size):
            t = targets[a]
            _pair3d(_MEAN3D, points[t, 0], points[t, 1], points[t, 2], j, centers, frames, half_a, half_b,
                    params[0], params[1], params[2], params[4], dd, value, work3)
            column[a] = value[0]
    else:
        n_out = 3 if mode == _STRESS2D else 1
        for a in range(targets.size):
            _pair2d_at(mode, points, targets[a], j, centers, frames, half_a, params, dd, value, work2, pair2)
            for c in range(n_out):
                column[n_out * a + c] = value[c]


@njit(cache=True)
def _sum_block(mode, points, targets, centers, frames, half_a, half_b, params, dd, sources, acc, value, work3,
               work2, pair2):
    """``acc[t] += sum_{j in sources} contribution(t, j)`` for ``t in targets`` (exact)."""
    for t in targets:
        _point_sum(mode, points, t, sources, centers, frames, half_a, half_b, params, dd, acc, value, work3, work2,
                   pair2)


@njit(cache=True, parallel=True)
def _direct(mode, n_out, points, centers, frames, half_a, half_b, params, dd, out):
    """Direct summation ``out[t] = sum_j contribution(t, j)``, parallel over a fixed
    split of the points; the sum over ``j`` runs in element order."""
    m = points.shape[0]
    n_chunks = min(_DIRECT_CHUNKS, m)
    sources = np.arange(centers.shape[0])
    for chunk in prange(n_chunks):
        work3 = np.empty((3, 3, 3))
        work2 = np.empty((2, 2, 2))
        pair2 = np.empty((2, 2, 2))
        value = np.empty(6)
        targets = np.arange(chunk * m // n_chunks, (chunk + 1) * m // n_chunks)
        for t in targets:
            for c in range(n_out):
                out[t, c] = 0.0
        _sum_block(mode, points, targets, centers, frames, half_a, half_b, params, dd, sources, out, value, work3,
                   work2, pair2)


@njit(cache=True)
def _aca_block(mode, n_out, points, targets, centers, frames, half_a, half_b, params, dd, sources, eps, acc,
               value, work3, work2, pair2):
    """Add the ACA approximation of ``sum_{j in sources} contribution(t, j)`` to
    ``acc[t]`` for ``t in targets``; returns the rank, or -1 (nothing added) when the
    approximation would cost more than half the exact sum (the caller then sums exactly).

    The matrix approximated is ``C[(t, c), j]``: component ``c`` of the stress that
    element ``j`` (with its actual DD) induces at point ``t``; the result is ``C 1``.
    Partial ACA with rank-1 crosses: a pivot point's ``n_out`` rows are evaluated at once
    (one kernel call per element) and used for as many crosses as they carry; the next
    pivot point is the unvisited one with the largest entry of the last column; zero
    pivots are skipped, not taken as convergence. Convergence needs ``|u_k| |v_k| <= eps
    |C_k|_F`` (incremental Frobenius norm) for two crosses in a row, then two probe points
    (unvisited, farthest in cluster order from the visited ones) whose residual rows are
    at most an ``eps`` share of the block, ``m |r|^2 <= eps^2 |C_k|^2`` (as ACA+ does: the
    stop test alone sees only the last cross); a failing probe becomes the next pivot.
    """
    m = targets.size
    n = sources.size
    budget = (m * n) // 2  # kernel evaluations allowed before falling back
    max_rank = min(m * n_out, n, budget // max(1, m) + 1)
    u = np.empty((max_rank, m * n_out))
    v = np.empty((max_rank, n))
    residual = np.empty((n_out, n))
    row_done = np.zeros(m, dtype=np.bool_)
    row_gap = np.zeros(m, dtype=np.int64)
    col_done = np.zeros(n, dtype=np.bool_)
    rank = 0
    norm2 = 0.0
    largest = 0.0
    small = 0
    evaluations = 0
    row = m // 2
    rows_left = m
    probes = 0  # > 0: the current point is a convergence probe
    hop = 1
    while rows_left > 0:
        row_done[row] = True
        rows_left -= 1
        _point_row(mode, points, targets[row], sources, centers, frames, half_a, half_b, params, dd, residual, value,
                   work3, work2, pair2)
        for c in range(n_out):
            for jb in range(n):
                largest = max(largest, abs(residual[c, jb]))
        evaluations += n
        for k in range(rank):
            for c in range(n_out):
                weight = u[k, row * n_out + c]
                if weight != 0.0:
                    for jb in range(n):
                        residual[c, jb] -= weight * v[k, jb]
        if probes > 0:
            size = 0.0
            for c in range(n_out):
                for jb in range(n):
                    size += residual[c, jb] * residual[c, jb]
            if m * size <= eps * eps * norm2:
                if probes >= 2:
                    break
                probes += 1
            else:
                probes = 0
                small = 0
        while probes == 0:  # crosses from this point's rows
            best = 0.0
            best_c = -1
            best_j = -1
            for c in range(n_out):
                for jb in range(n):
                    if not col_done[jb] and abs(residual[c, jb]) > best:
                        best = abs(residual[c, jb])
                        best_c = c
                        best_j = jb
            if best_j < 0 or best <= 1e-13 * largest:
                break
            if rank == max_rank or evaluations + m > budget:
                return -1
            pivot = residual[best_c, best_j]
            for jb in range(n):
                v[rank, jb] = residual[best_c, jb] / pivot
            column = u[rank]
            _element_column(mode, points, targets, sources[best_j], centers, frames, half_a, half_b, params, dd,
                            column, value, work3, work2, pair2)
            for q in range(m * n_out):
                largest = max(largest, abs(column[q]))
            evaluations += m
            for k in range(rank):
                weight = v[k, best_j]
                if weight != 0.0:
                    for q in range(m * n_out):
                        u[rank, q] -= weight * u[k, q]
            col_done[best_j] = True
            for c in range(n_out):
                weight = u[rank, row * n_out + c]
                for jb in range(n):
                    residual[c, jb] -= weight * v[rank, jb]
            uu = 0.0
            for q in range(m * n_out):
                uu += u[rank, q] * u[rank, q]
            vv = 0.0
            for jb in range(n):
                vv += v[rank, jb] * v[rank, jb]
            cross = 0.0
            for k in range(rank):
                du = 0.0
                for q in range(m * n_out):
                    du += u[k, q] * u[rank, q]
                dv = 0.0
                for jb in range(n):
                    dv += v[k, jb] * v[rank, jb]
                cross += du * dv
            norm2 = max(norm2 + uu * vv + 2.0 * cross, uu * vv)
            rank += 1
            if uu * vv <= eps * eps * norm2:
                small += 1
            else:
                small = 0
            if small >= 2:
                probes = 1
                break
        if rows_left == 0:
            break
        if evaluations + n > budget:
            return -1
        next_row = -1
        if probes > 0:  # probe: the unvisited point farthest in cluster order from the visited
            best_gap = -1
            last = -m
            for tb in range(m):  # distance to the nearest visited point on the left ...
                if row_done[tb]:
                    last = tb
                else:
                    row_gap[tb] = tb - last
            last = 2 * m
            for tb in range(m - 1, -1, -1):  # ... and on the right
                if row_done[tb]:
                    last = tb
                else:
                    gap = min(row_gap[tb], last - tb)
                    if gap > best_gap:
                        best_gap = gap
                        next_row = tb
        elif rank > 0:  # next pivot: the largest entry of the last column among unvisited points
            best = 0.0
            for tb in range(m):
                if not row_done[tb]:
                    size = 0.0
                    for c in range(n_out):
                        size += u[rank - 1, tb * n_out + c] ** 2
                    if size > best:
                        best = size
                        next_row = tb
        if next_row < 0:  # none informative: walk the points with a large stride
            hop = (hop * 7 + 3) % m if m > 1 else 0
            next_row = hop
            while row_done[next_row]:
                next_row = (next_row + 1) % m
        row = next_row
    # C 1 = U (V^T 1)
    for k in range(rank):
        weight = 0.0
        for jb in range(n):
            weight += v[k, jb]
        for tb in range(m):
            t = targets[tb]
            for c in range(n_out):
                acc[t, c] += weight * u[k, tb * n_out + c]
    return rank


@njit(cache=True, parallel=True)
def _tree_sum(mode, n_out, points, centers, frames, half_a, half_b, params, dd, target_permutation, target_start,
              target_stop, source_permutation, source_start, source_stop, block_target, block_source, block_far,
              chunk_offsets, chunk_blocks, eps, out, ranks):
    """Sum of all blocks (target cluster x source cluster): far ones by ACA (exact when
    ACA gives up), near ones exactly; chunk ``k`` of the fixed block split accumulates
    into its own array, the chunks are added in order (deterministic)."""
    n_chunks = chunk_offsets.size - 1
    partial = np.zeros((n_chunks, points.shape[0], n_out))
    for chunk in prange(n_chunks):
        work3 = np.empty((3, 3, 3))
        work2 = np.empty((2, 2, 2))
        pair2 = np.empty((2, 2, 2))
        value = np.empty(6)
        acc = partial[chunk]
        for position in range(chunk_offsets[chunk], chunk_offsets[chunk + 1]):
            b = chunk_blocks[position]
            tau = block_target[b]
            sigma = block_source[b]
            targets = target_permutation[target_start[tau]:target_stop[tau]]
            sources = source_permutation[source_start[sigma]:source_stop[sigma]]
            rank = -1
            if block_far[b]:
                rank = _aca_block(mode, n_out, points, targets, centers, frames, half_a, half_b, params, dd, sources,
                                  eps, acc, value, work3, work2, pair2)
            if rank < 0:
                _sum_block(mode, points, targets, centers, frames, half_a, half_b, params, dd, sources, acc, value,
                           work3, work2, pair2)
            ranks[b] = rank
    for chunk in range(n_chunks):
        out += partial[chunk]


def _dual_blocks(targets, sources, eta):
    """Leaves of the block tree of two cluster trees: ``(target cluster, source cluster,
    far)`` arrays. A pair is far when ``min(diam) <= eta * dist`` of the bounding boxes;
    otherwise the cluster with the larger diameter is split (the other when it is a
    leaf), so that blocks keep clusters of similar size, until both are leaves."""
    t_diameter, s_diameter = targets.diameter, sources.diameter
    rows, cols = np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64)
    out_rows, out_cols, out_far = [], [], []
    while rows.size:
        gap = np.maximum(0.0, np.maximum(sources.bbox_min[cols] - targets.bbox_max[rows],
                                         targets.bbox_min[rows] - sources.bbox_max[cols]))
        distance = np.sqrt(np.einsum("ij,ij->i", gap, gap))
        far = (distance > 0.0) & (np.minimum(t_diameter[rows], s_diameter[cols]) <= eta * distance)
        row_leaf, col_leaf = targets.left[rows] < 0, sources.left[cols] < 0
        done = far | (row_leaf & col_leaf)
        out_rows.append(rows[done])
        out_cols.append(cols[done])
        out_far.append(far[done])
        rows, cols, row_leaf, col_leaf = rows[~done], cols[~done], row_leaf[~done], col_leaf[~done]
        split_row = ~row_leaf & (col_leaf | (t_diameter[rows] >= s_diameter[cols]))
        new_rows = np.concatenate((np.where(split_row, targets.left[rows], rows),
                                   np.where(split_row, targets.right[rows], rows)))
        new_cols = np.concatenate((np.where(split_row, cols, sources.left[cols]),
                                   np.where(split_row, cols, sources.right[cols])))
        rows, cols = new_rows, new_cols
    return np.concatenate(out_rows), np.concatenate(out_cols), np.concatenate(out_far)


_TREE_CACHE = {}
_TREE_CACHE_SIZE = 4


def _cached_tree(points, radii, leaf_size):
    """:func:`hmatddm.hmatrix.cluster_tree.cluster_tree`, remembered for the last few
    point sets (a time loop evaluates the stress and the mean stress at the same
    points, and the same targets step after step): keyed by the bytes of the points
    and radii, so a changed point set never reuses a tree."""
    from .hmatrix.cluster_tree import cluster_tree

    radii = np.broadcast_to(np.asarray(radii, dtype=np.float64), (len(points),))
    digest = hashlib.blake2b(points.tobytes(), digest_size=16)
    digest.update(np.ascontiguousarray(radii).tobytes())
    key = (points.shape, int(leaf_size), digest.hexdigest())
    tree = _TREE_CACHE.pop(key, None)
    if tree is None:
        tree = cluster_tree(points, radii, leaf_size)
    _TREE_CACHE[key] = tree  # most recent last
    while len(_TREE_CACHE) > _TREE_CACHE_SIZE:
        _TREE_CACHE.pop(next(iter(_TREE_CACHE)))
    return tree


def _split_blocks(cost, n_chunks):
    """Greedy split of the blocks into ``n_chunks`` lists of similar cost (largest first).
    Returns CSR-style ``(offsets, blocks)``."""
    order = np.argsort(-cost, kind="stable")
    load = np.zeros(n_chunks)
    owner = np.empty(cost.size, dtype=np.int64)
    for b in order:
        k = int(np.argmin(load))
        owner[b] = k
        load[k] += cost[b]
    blocks = np.argsort(owner, kind="stable").astype(np.int64)
    offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=n_chunks))]).astype(np.int64)
    return offsets, blocks


def _evaluate(mesh, material, dd, points, mode, singular_correction, method, eps, info, near_fraction=0.0):
    """Shared driver of :func:`stress_at` and :func:`mean_stress_at`: ``(M, n_out)``."""
    if not isinstance(mesh, (Mesh2D, Mesh3D)):
        raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
    if not isinstance(material, Elastic):
        raise InputError(f"material must be an hmatddm.Elastic, got {type(material).__name__}")
    if singular_correction not in ("none", "average"):
        raise InputError(f"singular_correction must be one of ('none', 'average'), got {singular_correction!r}")
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}, got {method!r}")
    near_fraction = finite_scalar("near_fraction", near_fraction)
    if not 0.0 <= near_fraction < 1.0:
        raise InputError(f"near_fraction must be in [0, 1), got {near_fraction}")
    eps = DEFAULT_STRESS_EPS if eps is None else finite_scalar("eps", eps)
    if not 0.0 < eps < 1.0:
        raise InputError(f"eps must be in (0, 1), got {eps}")
    dd = np.ascontiguousarray(_dd_array(mesh, dd))
    points = _check_points(mesh, points)
    shift = 1e-3 if singular_correction == "average" else 0.0
    # contiguous float64 arrays: one compiled specialisation of each driver, whatever
    # slicing or concatenation produced the mesh
    centers, frames, half_a, half_b, params = (np.ascontiguousarray(a, dtype=np.float64) for a in
                                               element_data(mesh, material, singular_shift=shift,
                                                            near_fraction=near_fraction)[:5])
    n_out = _N_OUT[mode]
    m, n = len(points), mesh.n_elements
    out = np.zeros((m, n_out))
    if method == "auto":
        method = "tree" if m * n >= AUTO_TREE_PAIRS and min(m, n) > 2 * STRESS_LEAF_SIZE else "direct"
    started = time.perf_counter()
    if m == 0:
        pass
    elif method == "direct" or min(m, n) <= STRESS_LEAF_SIZE:
        _direct(mode, n_out, points, centers, frames, half_a, half_b, params, dd, out)
        if info is not None:
            info.update(method="direct", n_far=0, n_near=1, pairs_exact=m * n)
    else:
        target_tree = _cached_tree(points, 0.0, STRESS_LEAF_SIZE)
        source_tree = _cached_tree(centers, mesh.radii, STRESS_SOURCE_LEAF_SIZE)
        block_target, block_source, block_far = _dual_blocks(target_tree, source_tree, STRESS_ETA)
        size_t = target_tree.size[block_target]
        size_s = source_tree.size[block_source]
        # ACA ranks are ~30-60 here (six stress components): smaller blocks are summed exactly
        block_far &= np.minimum(size_t, size_s) >= STRESS_MIN_ACA
        cost = np.where(block_far, 12.0 * (size_t + size_s), size_t * size_s).astype(float)
        offsets, blocks = _split_blocks(cost, _TREE_CHUNKS)
        ranks = np.zeros(block_target.size, dtype=np.int64)
        _tree_sum(mode, n_out, points, centers, frames, half_a, half_b, params, dd, target_tree.permutation,
                  target_tree.start, target_tree.stop, source_tree.permutation, source_tree.start, source_tree.stop,
                  block_target, block_source, block_far, offsets, blocks, float(eps), out, ranks)
        if info is not None:
            compressed = block_far & (ranks >= 0)
            info.update(method="tree", n_far=int(np.count_nonzero(block_far)), n_near=int(np.count_nonzero(~block_far)),
                        n_fallback=int(np.count_nonzero(block_far & (ranks < 0))),
                        max_rank=int(ranks[compressed].max()) if np.any(compressed) else 0,
                        pairs_exact=int(np.sum(size_t[~compressed] * size_s[~compressed])),
                        pairs_compressed=int(np.sum(size_t[compressed] * size_s[compressed])))
    if info is not None:
        info.update(seconds=time.perf_counter() - started, eps=float(eps), points=m, elements=n)
    return out


def _refuse_singular(values, near_fraction):
    """InputError naming the first point whose stress is singular (NaN: on an edge, or
    within ``near_fraction`` of one, without ``singular_correction='average'``)."""
    bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
    if bad.size:
        where = "on an element edge" if near_fraction == 0.0 else \
            f"on an element edge or within near_fraction = {near_fraction:g} half sizes of one"
        raise InputError(f"points[{int(bad[0])}] lies {where}, where the stress is singular; "
                         "move it or pass singular_correction='average'")


def stress_at(mesh, material, dd, points, singular_correction="none", method="auto", eps=None, info=None,
              near_fraction=0.0):
    """Stress (M, d, d) induced at ``points`` (M, d) by the DDs ``dd`` (global frame),
    ref. Eq. 2.59. In 2D the in-plane components of the plane-strain stress.

    Parameters
    ----------
    mesh : Mesh2D or Mesh3D
    material : Elastic or LayeredMedium
        A :class:`hmatddm.LayeredMedium` (2D constant elements) sums directly with the
        image terms (ref. Ch. 3); ``method``, ``eps`` and ``info`` do not apply.
    dd : (N, d) or (N*d,) DDs, global frame
    points : (M, d)
    singular_correction : ``"none"`` or ``"average"``
        Points on an element edge raise :class:`InputError` unless ``"average"``
        (the mean of two points moved across the edge, ref. Sec. 6.2.3).
    near_fraction : float in [0, 1)
        Points within ``near_fraction`` of an element's smaller half size of its edge
        (its end in 2D) count as on it (a near miss, where the exact stress is ~1/gap):
        averaged with ``"average"``, refused with ``"none"``. 0 (default): exact hits
        only, so the field close to a crack tip can be sampled. The remote-failure check
        of a simulation uses :data:`hmatddm.operators.NEAR_SINGULAR_FRACTION` (0.5), the
        threshold of the DDM operator.
    method : ``"auto"`` (default), ``"direct"`` or ``"tree"``
        ``"direct"``: exact summation over all elements, O(M N), parallel over points.
        ``"tree"``: cluster trees of the points and of the elements; blocks of clusters
        that are well separated (``min(diam) <= STRESS_ETA * dist``) are compressed by
        ACA, the others summed exactly; close to O((M + N) log) for a fixed accuracy.
        Each compressed block's contribution matrix (component c of the stress that
        element j, with its DD, induces at point t) is approximated to the relative
        Frobenius accuracy ``eps``. Measured on DFN scenes (35k points, 90-2400
        elements; tests/test_solve.py checks ``<= eps``): the largest error of any
        component is 0.01-0.1 ``eps`` times the largest induced stress component, at
        3-5 times less work than the direct sum for N >= 600. ``"auto"``: ``"tree"``
        when ``M * N >= AUTO_TREE_PAIRS`` and both exceed ``2 * STRESS_LEAF_SIZE``,
        else ``"direct"``.
    eps : float in (0, 1) or None
        Accuracy of the compressed blocks; None: ``DEFAULT_STRESS_EPS`` (1e-6).
    info : dict or None
        Filled with what was done: ``method``, ``seconds``, block counts, largest rank,
        ``pairs_exact`` / ``pairs_compressed`` (point-element pairs summed exactly / inside
        compressed blocks).

    Linear and quadratic elements (``mesh.element_order`` 1 or 2, ``dd`` nodal): summed
    directly (:func:`hmatddm.nodal.stress_at`; ``method="tree"`` is refused, ``eps``
    unused); on an element the mean of its two faces' ``s_xx`` (which jumps there).
    """
    if getattr(mesh, "n_nodes", 1) > 1:  # homogeneous or layered
        from . import nodal

        return nodal.stress_at(mesh, material, dd, points, singular_correction, method, info, near_fraction)
    if isinstance(material, LayeredMedium):  # ref. Ch. 3 image terms, direct sum
        from .layered.influence2d import stress_at as layered_stress_at

        return layered_stress_at(mesh, material, dd, points, singular_correction, near_fraction)
    mode = _STRESS3D if isinstance(mesh, Mesh3D) else _STRESS2D
    values = _evaluate(mesh, material, dd, points, mode, singular_correction, method, eps, info, near_fraction)
    _refuse_singular(values, near_fraction)
    if mesh.dim == 3:
        return values[:, [0, 3, 4, 3, 1, 5, 4, 5, 2]].reshape(-1, 3, 3)
    return values[:, [0, 2, 2, 1]].reshape(-1, 2, 2)


def mean_stress_at(mesh, material, dd, points, singular_correction="none", method="auto", eps=None, info=None,
                   near_fraction=0.0):
    """Mean stress ``tr(sigma)/3`` (M,) induced at ``points`` (ref. Eqs 5.24-5.28).

    In 2D (plane strain) ``sigma_zz = nu (sigma_xx + sigma_yy)`` is included, so the
    mean stress is ``(1 + nu)(sigma_xx + sigma_yy) / 3``. Parameters as in
    :func:`stress_at`; in 3D the kernel evaluates only the second derivatives of the
    potential the trace needs (about half the cost of the full stress).
    """
    if getattr(mesh, "n_nodes", 1) > 1:
        stress = stress_at(mesh, material, dd, points, singular_correction, method, eps, info, near_fraction)
        return (1.0 + material.poisson_ratio) * (stress[:, 0, 0] + stress[:, 1, 1]) / 3.0
    mode = _MEAN3D if isinstance(mesh, Mesh3D) else _MEAN2D
    values = _evaluate(mesh, material, dd, points, mode, singular_correction, method, eps, info, near_fraction)
    _refuse_singular(values, near_fraction)
    return values[:, 0]
