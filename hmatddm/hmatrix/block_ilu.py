"""Block incomplete LU, ILU(0) on d x d element blocks (numba).

The factors keep the block pattern of the matrix they factor (no fill-in), and every
operation is a product or inverse of whole d x d blocks. So the factorisation
commutes with a rotation of each element's unknowns: for Q = diag(Q_1, ..., Q_N)
with orthogonal Q_i, the ILU(0) of Q A Q^T is Q L Q^T, Q U Q^T. A preconditioner
built this way (on a pattern chosen by block norms) gives the same GMRES iterations
whatever the frame of the unknowns, unlike a scalar ILU whose entry-wise drop rules
see a tilted element's couplings spread over all d^2 entries of its blocks.

Layout: BSR arrays (``indptr``, ``indices`` sorted within each block row, ``data``
of shape (nnz_blocks, d, d)); the factors overwrite a copy of ``data``: strictly
lower blocks hold L (unit block diagonal implied), the others U, and the inverses of
the diagonal blocks of U are stored apart.
"""

import numpy as np
from numba import njit, prange


@njit(cache=True, nogil=True)
def _invert(block, out):
    """out = block^-1 (d x d, Gauss-Jordan with partial pivoting); False when singular."""
    d = block.shape[0]
    work = np.empty((d, 2 * d))
    for p in range(d):
        for q in range(d):
            work[p, q] = block[p, q]
            work[p, d + q] = 1.0 if p == q else 0.0
    scale = 0.0
    for p in range(d):
        for q in range(d):
            scale = max(scale, abs(block[p, q]))
    if not (scale > 0.0) or not np.isfinite(scale):
        return False
    for k in range(d):
        pivot = k
        for p in range(k + 1, d):
            if abs(work[p, k]) > abs(work[pivot, k]):
                pivot = p
        if abs(work[pivot, k]) <= 1e-14 * scale:
            return False
        if pivot != k:
            for q in range(2 * d):
                work[k, q], work[pivot, q] = work[pivot, q], work[k, q]
        inverse = 1.0 / work[k, k]
        for q in range(2 * d):
            work[k, q] *= inverse
        for p in range(d):
            if p != k and work[p, k] != 0.0:
                factor = work[p, k]
                for q in range(2 * d):
                    work[p, q] -= factor * work[k, q]
    for p in range(d):
        for q in range(d):
            out[p, q] = work[p, d + q]
    return True


@njit(cache=True, nogil=True)
def block_ilu0(indptr, indices, data):
    """Block ILU(0) of a BSR matrix with sorted block rows (IKJ order).

    Returns (values, inverse_diagonal, diagonal_position, failed_row): the factors
    (see the module docstring), the inverses of U's diagonal blocks, the position of
    each diagonal block in the row, and -1, or the first block row whose pivot block
    is missing or singular (the factors are then unusable). Cost O(sum over block
    rows of (lower blocks x upper blocks of the rows they meet) * d^3).
    """
    n_blocks = indptr.size - 1
    d = data.shape[1]
    values = data.copy()
    inverse_diagonal = np.zeros((n_blocks, d, d))
    diagonal_position = np.full(n_blocks, -1, dtype=np.int64)
    marker = np.full(n_blocks, -1, dtype=np.int64)
    multiplier = np.empty((d, d))
    for i in range(n_blocks):
        for p in range(indptr[i], indptr[i + 1]):
            marker[indices[p]] = p
            if indices[p] == i:
                diagonal_position[i] = p
        if diagonal_position[i] < 0:
            return values, inverse_diagonal, diagonal_position, i
        for p in range(indptr[i], diagonal_position[i]):
            k = indices[p]
            # L_ik = A_ik U_kk^-1
            for r in range(d):
                for c in range(d):
                    total = 0.0
                    for t in range(d):
                        total += values[p, r, t] * inverse_diagonal[k, t, c]
                    multiplier[r, c] = total
            for r in range(d):
                for c in range(d):
                    values[p, r, c] = multiplier[r, c]
            # A_ij -= L_ik U_kj for the blocks j > k of row k that row i has
            for q in range(diagonal_position[k] + 1, indptr[k + 1]):
                target = marker[indices[q]]
                if target < 0:
                    continue
                for r in range(d):
                    for c in range(d):
                        total = 0.0
                        for t in range(d):
                            total += multiplier[r, t] * values[q, t, c]
                        values[target, r, c] -= total
        if not _invert(values[diagonal_position[i]], inverse_diagonal[i]):
            return values, inverse_diagonal, diagonal_position, i
        for p in range(indptr[i], indptr[i + 1]):
            marker[indices[p]] = -1
    return values, inverse_diagonal, diagonal_position, -1


@njit(cache=True, nogil=True, inline="always")
def _subtract_blocks(values, indices, first, stop, x, i, d):
    """``x_i -= sum_p values[p] x_{indices[p]}`` over the stored blocks ``first <= p < stop``
    of block row ``i`` (one sweep of a block triangular solve)."""
    for p in range(first, stop):
        j = indices[p]
        for r in range(d):
            total = 0.0
            for c in range(d):
                total += values[p, r, c] * x[d * j + c]
            x[d * i + r] -= total


@njit(cache=True, nogil=True, inline="always")
def _apply_inverse_diagonal(inverse_diagonal, x, i, d, work):
    """``x_i = (U_ii)^-1 x_i`` (the last operation on a row of the backward sweep)."""
    for r in range(d):
        total = 0.0
        for c in range(d):
            total += inverse_diagonal[i, r, c] * x[d * i + c]
        work[r] = total
    for r in range(d):
        x[d * i + r] = work[r]


@njit(cache=True, nogil=True)
def block_ilu_solve(indptr, indices, values, inverse_diagonal, diagonal_position, rhs):
    """x = U^-1 L^-1 rhs for the factors of :func:`block_ilu0`; rhs (n_blocks * d,)."""
    n_blocks = indptr.size - 1
    d = values.shape[1]
    x = rhs.copy()
    for i in range(n_blocks):  # forward: unit block lower triangle
        _subtract_blocks(values, indices, indptr[i], diagonal_position[i], x, i, d)
    work = np.empty(d)
    for i in range(n_blocks - 1, -1, -1):  # backward
        _subtract_blocks(values, indices, diagonal_position[i] + 1, indptr[i + 1], x, i, d)
        _apply_inverse_diagonal(inverse_diagonal, x, i, d, work)
    return x


@njit(parallel=True, cache=True, nogil=True)
def block_ilu_solve_staged(indptr, indices, values, inverse_diagonal, diagonal_position, rhs, stage_ptr,
                           range_start, range_stop):
    """:func:`block_ilu_solve` for factors in a nested-dissection ordering
    (:mod:`hmatddm.hmatrix.dissection`): each sweep runs stage by stage, the ranges of a
    stage in parallel (they are not coupled), the rows of a range in order. Every row
    does the arithmetic of the sequential sweep, so the result is the same bit for bit
    on any number of threads. (On one thread it runs as fast as a copy compiled without
    parallel launches: 3.8 ms against 5.7 ms at 10 000 planar elements, so it has none.)"""
    d = values.shape[1]
    x = rhs.copy()
    n_stages = stage_ptr.shape[0] - 1
    for stage in range(n_stages):  # forward: domains first, the root's separator last
        for r in prange(stage_ptr[stage], stage_ptr[stage + 1]):
            for i in range(range_start[r], range_stop[r]):
                _subtract_blocks(values, indices, indptr[i], diagonal_position[i], x, i, d)
    for stage in range(n_stages - 1, -1, -1):  # backward
        for r in prange(stage_ptr[stage], stage_ptr[stage + 1]):
            work = np.empty(d)
            for i in range(range_stop[r] - 1, range_start[r] - 1, -1):
                _subtract_blocks(values, indices, diagonal_position[i] + 1, indptr[i + 1], x, i, d)
                _apply_inverse_diagonal(inverse_diagonal, x, i, d, work)
    return x

