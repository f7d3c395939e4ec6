"""Two-level preconditioner: the near-field block ILU plus a coarse correction whose
matrix is the Galerkin projection of the H-matrix itself.

A near-field preconditioner (block ILU) resolves the short-range couplings; what it
misses are the smooth, long-range modes, whose number grows with N, so its GMRES
iterations grow too (planar crack: 18 / 31 / 40 at 10k / 40k / 100k elements). Those
modes live on a coarse space: the elements are grouped into *aggregates* (the clusters
of the cluster tree with at most ``aggregate_size`` elements), and the coarse basis
holds, per aggregate and per unknown component, ``n_functions`` functions of the
element centre (1: the constant; 3 or 4: plus the linear functions of the centre in
the aggregate's principal axes). With the prolongation P (N d x n_c) the coarse matrix

    A_c = P^T A P

is computed from the stored H-matrix blocks directly -- dense blocks by summation,
low-rank blocks U V^T as (P^T U)(P^T V)^T -- in one pass over the storage, O(memory)
work, no extra kernel evaluation; A_c is factored by a dense LU. The aggregates keep a
fixed size, so the ratio of coarse to fine scale does not change with N and neither
do the iterations (two-level Schwarz theory for the hypersingular operator; Heuer &
Stephan; measured in benchmarks/RESULTS.md).

Applied multiplicatively (the "balancing" form, one extra H-matvec per application)::

    z = Q r + M (r - A Q r),     Q = P A_c^{-1} P^T,  M the block ILU

or additively (``z = Q r + M r``, no extra matvec, more iterations).
"""

import time

import numpy as np
import scipy.linalg
import scipy.sparse.linalg as spla
from numba import njit

from ..errors import InputError

from ._threads import single_threaded_blas
from .factor_precision import factor_columns


def aggregates(tree, aggregate_size):
    """Aggregate of each tree position: the largest clusters with at most
    ``aggregate_size`` elements (a partition of [0, N) into contiguous ranges).

    Returns (aggregate_of_position (N,), aggregate_start (n_agg + 1,)).
    """
    if isinstance(aggregate_size, bool) or not isinstance(aggregate_size, (int, np.integer)) or aggregate_size < 1:
        raise InputError(f"aggregate_size must be an integer >= 1, got {aggregate_size!r}")
    chosen, stack = [], [0]
    while stack:  # outermost clusters that fit (or leaves that do not)
        c = stack.pop()
        if tree.stop[c] - tree.start[c] <= aggregate_size or tree.left[c] < 0:
            chosen.append(c)
        else:
            stack += [int(tree.right[c]), int(tree.left[c])]
    starts = np.sort(tree.start[np.array(chosen, dtype=np.int64)])
    boundaries = np.concatenate((starts, [tree.n_elements])).astype(np.int64)
    of_position = np.repeat(np.arange(starts.size, dtype=np.int64), np.diff(boundaries))
    return of_position, boundaries


def coarse_functions(points_permuted, boundaries, n_functions):
    """(N, n_functions) values of the coarse functions at each tree position: the
    constant 1, then the centre's coordinates along the aggregate's principal axes,
    scaled to [-1, 1] (orthogonal to the constant)."""
    n = points_permuted.shape[0]
    phi = np.zeros((n, n_functions))
    phi[:, 0] = 1.0
    if n_functions == 1:
        return phi
    for a in range(boundaries.size - 1):
        lo, hi = boundaries[a], boundaries[a + 1]
        centred = points_permuted[lo:hi] - points_permuted[lo:hi].mean(axis=0)
        if hi - lo < 2:
            continue
        _, _, vt = np.linalg.svd(centred, full_matrices=False)
        local = centred @ vt.T
        for f in range(1, min(n_functions, local.shape[1] + 1)):
            scale = np.abs(local[:, f - 1]).max()
            if scale > 0:
                phi[lo:hi, f] = local[:, f - 1] / scale
    return phi


@njit(cache=True)
def _project_factor(d, n_f, agg, phi, columns, start, stop):
    """P^T F restricted to the aggregates of tree positions [start, stop), for a low-rank
    factor F (d (stop - start) x k) given as its k columns (rows of ``columns``)."""
    first = agg[start]
    m = d * (stop - start)
    k = columns.shape[0]
    out = np.zeros(((agg[stop - 1] - first + 1) * n_f * d, k))
    for q in range(k):
        for i in range(m):
            element = start + i // d
            value = columns[q, i]
            for f in range(n_f):
                out[((agg[element] - first) * n_f + f) * d + i % d, q] += phi[element, f] * value
    return out


@njit(cache=True)
def _galerkin(d, n_f, agg, phi, n_coarse, dense_row_start, dense_row_stop, dense_col_start, dense_col_stop,
              dense_offset, dense_values, lowrank_row_start, lowrank_row_stop, lowrank_col_start,
              lowrank_col_stop, lowrank_rank, u_offset, v_offset, u_values, v_values, lowrank_head, u_fixed_offset,
              v_fixed_offset, u_fixed, v_fixed, u_scale, v_scale, rank_offset):
    """A_c = P^T A P from the stored blocks (P: agg, phi; coarse index (agg * n_f + f) * d + p)."""
    coarse = np.zeros((n_coarse, n_coarse))
    for b in range(dense_row_start.shape[0]):
        r0, r1 = dense_row_start[b], dense_row_stop[b]
        c0, c1 = dense_col_start[b], dense_col_stop[b]
        nc = d * (c1 - c0)
        a_first = agg[c0]
        n_cols_coarse = (agg[c1 - 1] - a_first + 1) * n_f * d
        t = np.zeros(n_cols_coarse)
        for i in range(d * (r1 - r0)):
            for j in range(n_cols_coarse):
                t[j] = 0.0
            base = dense_offset[b] + i * nc
            for c in range(c1 - c0):
                ac = (agg[c0 + c] - a_first) * n_f
                for q in range(d):
                    value = dense_values[base + d * c + q]
                    for g in range(n_f):
                        t[(ac + g) * d + q] += value * phi[c0 + c, g]
            element = r0 + i // d
            p = i % d
            for f in range(n_f):
                row = (agg[element] * n_f + f) * d + p
                weight = phi[element, f]
                if weight == 0.0:
                    continue
                for j in range(n_cols_coarse):
                    coarse[row, a_first * n_f * d + j] += weight * t[j]
    for b in range(lowrank_rank.shape[0]):
        k = lowrank_rank[b]
        r0, r1 = lowrank_row_start[b], lowrank_row_stop[b]
        c0, c1 = lowrank_col_start[b], lowrank_col_stop[b]
        ar, ac = agg[r0], agg[c0]
        head, first = lowrank_head[b], rank_offset[b]
        ut = factor_columns(u_values, u_offset[b], u_fixed, u_fixed_offset[b], u_scale, first, k, head, d * (r1 - r0))
        vt = factor_columns(v_values, v_offset[b], v_fixed, v_fixed_offset[b], v_scale, first, k, head, d * (c1 - c0))
        pu = _project_factor(d, n_f, agg, phi, ut, r0, r1)
        pv = _project_factor(d, n_f, agg, phi, vt, c0, c1)
        nr, ncc = pu.shape[0], pv.shape[0]
        row0 = ar * n_f * d
        col0 = ac * n_f * d
        for i in range(nr):
            for j in range(ncc):
                total = 0.0
                for q in range(k):
                    total += pu[i, q] * pv[j, q]
                coarse[row0 + i, col0 + j] += total
    return coarse


@njit(cache=True)
def _transfer(d, n_f, agg, phi, element_order, source, n_out, restrict):
    """P^T source (``restrict``, fine -> coarse) or P source (coarse -> fine); fine
    vectors in the original ordering."""
    out = np.zeros(n_out)
    for k in range(agg.shape[0]):
        e = element_order[k]
        for f in range(n_f):
            weight = phi[k, f]
            base = (agg[k] * n_f + f) * d
            for p in range(d):
                if restrict:
                    out[base + p] += weight * source[d * e + p]
                else:
                    out[d * e + p] += weight * source[base + p]
    return out


def galerkin_coarse_matrix(hmatrix, of_position, phi):
    """P^T A P (n_agg * n_f * d square) from the blocks stored in ``hmatrix``."""
    s = hmatrix.storage
    d = hmatrix.dof
    n_f = phi.shape[1]
    n_coarse = int(of_position[-1] + 1) * n_f * d
    return _galerkin(d, n_f, of_position, np.ascontiguousarray(phi), n_coarse, s.dense_row_start,
                     s.dense_row_stop, s.dense_col_start, s.dense_col_stop, s.dense_offset, s.dense_values,
                     s.lowrank_row_start, s.lowrank_row_stop, s.lowrank_col_start, s.lowrank_col_stop,
                     s.lowrank_rank, s.u_offset, s.v_offset, s.u_values, s.v_values, s.lowrank_head, s.u_fixed_offset,
                     s.v_fixed_offset, s.u_fixed, s.v_fixed, s.u_scale, s.v_scale, s.rank_offset)


class TwoLevel:
    """Prolongation, restriction and coarse solve of the two-level preconditioner."""

    def __init__(self, hmatrix, aggregate_size=64, n_functions=1):
        tree = hmatrix.tree
        self.d = hmatrix.dof
        self.of_position, boundaries = aggregates(tree, aggregate_size)
        points = hmatrix.generator.points[tree.permutation]
        self.phi = coarse_functions(points, boundaries, n_functions)
        self.n_f = n_functions
        self.n_aggregates = boundaries.size - 1
        self.element_order = tree.permutation
        coarse = galerkin_coarse_matrix(hmatrix, self.of_position, self.phi)
        # A coarse function that vanishes on its aggregate (a linear function of a single
        # element, or of a straight 2D crack's second axis) gives a zero row and column:
        # put 1 on its diagonal, which leaves Q = P A_c^-1 P^T unchanged (P's column is 0).
        empty = ~(np.any(coarse != 0.0, axis=1) | np.any(coarse != 0.0, axis=0))
        coarse[empty, empty] = 1.0
        self.coarse_size = coarse.shape[0]
        with single_threaded_blas():  # the LU's round-off must not depend on the BLAS thread count
            self.lu = scipy.linalg.lu_factor(coarse, overwrite_a=True, check_finite=False)
        self.nbytes = self.lu[0].nbytes

    def restrict(self, r):
        """P^T r for r in the original ordering."""
        return _transfer(self.d, self.n_f, self.of_position, self.phi, self.element_order,
                         np.ascontiguousarray(r, dtype=np.float64), self.coarse_size, True)

    def prolong(self, c):
        """P c in the original ordering."""
        return _transfer(self.d, self.n_f, self.of_position, self.phi, self.element_order, c,
                         self.of_position.size * self.d, False)

    def coarse_correction(self, r):
        """Q r = P A_c^{-1} P^T r."""
        return self.prolong(scipy.linalg.lu_solve(self.lu, self.restrict(r), check_finite=False))


def two_level_preconditioner(hmatrix, smoother, aggregate_size=256, n_functions=3, multiplicative=True):
    """LinearOperator ``z = Q r + M (r - A Q r)`` (``multiplicative``) or ``Q r + M r``
    with M = ``smoother`` (see the module docstring)."""
    if isinstance(n_functions, bool) or n_functions not in (1, 2, 3):
        raise InputError(f"n_functions must be 1, 2 or 3, got {n_functions!r}")
    started = time.perf_counter()
    level = TwoLevel(hmatrix, aggregate_size, int(n_functions))
    seconds = time.perf_counter() - started

    def apply_one(r):
        z = level.coarse_correction(r)
        if multiplicative:
            return z + smoother @ (r - hmatrix @ z)
        return z + smoother @ r

    def apply(x):
        x = np.asarray(x, dtype=np.float64)
        if x.ndim == 1 or x.shape[-1] == 1 and x.ndim == 2:
            return apply_one(x.reshape(-1)).reshape(x.shape)
        return np.column_stack([apply_one(np.ascontiguousarray(column)) for column in x.T])

    operator = spla.LinearOperator(hmatrix.shape, matvec=apply, matmat=apply, dtype=np.float64)
    operator.coarse = {"n_aggregates": level.n_aggregates, "coarse_size": level.coarse_size,
                       "coarse_bytes": level.nbytes, "multiplicative": bool(multiplicative),
                       "setup_seconds": seconds}
    return operator
