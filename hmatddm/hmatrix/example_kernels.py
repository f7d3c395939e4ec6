"""Simple kernels for tests, examples and benchmarks of the H-matrix engine.

Each kernel follows the BlockGenerator contract ``kernel(data, rows, cols, out)``
and fills each element pair independently (no elasticity here).
"""

import numpy as np
from numba import njit

from .generator import BlockGenerator


@njit(cache=True, nogil=True)
def inverse_distance_kernel(data, rows, cols, out):
    """Scalar kernel 1/|x_i - x_j| (d = 1); ``data = (points, diagonal)``, the i == j
    entry is ``diagonal[0]``."""
    points, diagonal = data
    dim = points.shape[1]
    for a in range(rows.shape[0]):
        i = rows[a]
        for b in range(cols.shape[0]):
            j = cols[b]
            if i == j:
                out[a, b] = diagonal[0]
                continue
            r2 = 0.0
            for k in range(dim):
                r2 += (points[i, k] - points[j, k]) ** 2
            out[a, b] = 1.0 / np.sqrt(r2)


@njit(cache=True, nogil=True)
def tensor_kernel(data, rows, cols, out):
    """d x d tensor kernel on points of dimension d (d = 2 or 3).

    ``data = (points, scales, coupling, exponent, groups, self_value)``; for i != j
    in the same group, with r = x_i - x_j,

        K_pq = (scales[p] * delta_pq + coupling[0] * r_p r_q / |r|^2) / |r|^exponent[0]

    (coupling 1, scales 1, exponent 1: a Kelvin-type tensor; coupling 0 with unequal
    scales: components that never couple, like the shear/normal blocks of a DDM
    kernel of a planar crack). Pairs in different groups give 0; i == j gives
    ``self_value[p] * delta_pq``.
    """
    points, scales, coupling, exponent, groups, self_value = data
    d = points.shape[1]
    r = np.empty(d)
    for a in range(rows.shape[0]):
        i = rows[a]
        for b in range(cols.shape[0]):
            j = cols[b]
            for p in range(d):
                for q in range(d):
                    out[d * a + p, d * b + q] = 0.0
            if i == j:
                for p in range(d):
                    out[d * a + p, d * b + p] = self_value[p]
                continue
            if groups[i] != groups[j]:
                continue
            r2 = 0.0
            for k in range(d):
                r[k] = points[i, k] - points[j, k]
                r2 += r[k] * r[k]
            factor = r2 ** (-0.5 * exponent[0])
            for p in range(d):
                for q in range(d):
                    value = coupling[0] * r[p] * r[q] / r2
                    if p == q:
                        value += scales[p]
                    out[d * a + p, d * b + q] = value * factor


@njit(cache=True, nogil=True)
def matrix_kernel(data, rows, cols, out):
    """Entries of an explicit dense matrix ``data = (matrix, dof)``: any test matrix."""
    matrix, dof = data
    d = dof[0]
    for a in range(rows.shape[0]):
        for b in range(cols.shape[0]):
            for p in range(d):
                for q in range(d):
                    out[d * a + p, d * b + q] = matrix[d * rows[a] + p, d * cols[b] + q]


@njit(cache=True, nogil=True)
def field_kernel(data, rows, cols, out):
    """Rectangular kernel: targets (rows, ``row_dof`` = dim values each) x sources
    (columns, 2 strengths each), ``data = (targets, sources)``; with r = x_t - y_s,

        K_p0 = r_p / |r|^3   (the field of a point charge),
        K_p1 = r_p r_0 / |r|^4  (an anisotropic second source type).

    Like the stress at points induced by elements: different points for rows and
    columns, different unknowns per row and per column element."""
    targets, sources = data
    dim = targets.shape[1]
    for a in range(rows.shape[0]):
        i = rows[a]
        for b in range(cols.shape[0]):
            j = cols[b]
            r2 = 0.0
            for k in range(dim):
                r2 += (targets[i, k] - sources[j, k]) ** 2
            inverse = 1.0 / np.sqrt(r2)
            for p in range(dim):
                rp = (targets[i, p] - sources[j, p]) * inverse
                out[dim * a + p, 2 * b] = rp * inverse * inverse
                out[dim * a + p, 2 * b + 1] = rp * (targets[i, 0] - sources[j, 0]) * inverse * inverse * inverse


def field_generator(targets, sources, source_radii=0.0):
    """Rectangular BlockGenerator of :func:`field_kernel` (targets x sources)."""
    targets = np.ascontiguousarray(targets, dtype=np.float64)
    sources = np.ascontiguousarray(sources, dtype=np.float64)
    return BlockGenerator(field_kernel, (targets, sources), targets, 0.0, targets.shape[1], col_points=sources,
                          col_radii=source_radii, col_dof=2)


def inverse_distance_generator(points, diagonal=1.0):
    """BlockGenerator of the 1/r kernel with ``diagonal`` on the diagonal (d = 1)."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    return BlockGenerator(inverse_distance_kernel, (points, np.array([float(diagonal)])), points,
                          np.zeros(points.shape[0]), 1)


def tensor_generator(points, scales=None, coupling=1.0, exponent=1.0, groups=None, self_value=None):
    """BlockGenerator of :func:`tensor_kernel` with d = points.shape[1]."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    n, d = points.shape
    scales = np.ones(d) if scales is None else np.asarray(scales, dtype=np.float64)
    groups = np.zeros(n, dtype=np.int64) if groups is None else np.asarray(groups, dtype=np.int64)
    self_value = 10.0 * scales if self_value is None else np.asarray(self_value, dtype=np.float64)
    data = (points, scales, np.array([float(coupling)]), np.array([float(exponent)]), groups, self_value)
    return BlockGenerator(tensor_kernel, data, points, np.zeros(n), d)


def matrix_generator(matrix, points, dof=1, radii=None):
    """BlockGenerator reading the entries of an explicit (N*dof, N*dof) matrix."""
    matrix = np.ascontiguousarray(matrix, dtype=np.float64)
    points = np.ascontiguousarray(points, dtype=np.float64)
    radii = np.zeros(points.shape[0]) if radii is None else radii
    return BlockGenerator(matrix_kernel, (matrix, np.array([int(dof)], dtype=np.int64)), points, radii, int(dof))
