"""The parallel matvec of the flat block storage (:mod:`.storage`, layout in its
docstring): Y = A X in the permuted ordering, threads owning whole segments (leaf
clusters) of Y so that they never race (:func:`_matmat_permuted`), and the same loops
on one thread (:func:`_matmat_serial`).
"""

import numpy as np
from numba import njit, prange

from ..compiled import FAST, serial_twin


@njit(parallel=True, cache=True, fastmath=FAST)
def _matmat_permuted(dof, col_dof, n_rows, dense_col_start, dense_row_start, dense_col_stop, dense_offset, dense_values,
                     lowrank_row_start, lowrank_row_stop, lowrank_col_start, lowrank_col_stop, lowrank_rank,
                     u_offset, v_offset, rank_offset, u_values, v_values, lowrank_head, u_fixed_offset,
                     v_fixed_offset, u_fixed, v_fixed, u_scale, v_scale, segment_start, segment_dense_ptr,
                     segment_dense_ids, segment_lowrank_ptr, segment_lowrank_ids, x):
    """Y = A X for X given TRANSPOSED, x of shape (nrhs, N_c*d_c), permuted ordering
    (``dof`` d_r unknowns per row element, ``col_dof`` d_c per column element,
    ``n_rows`` = N*d_r rows).

    Phase 1 (parallel over low-rank blocks): t_b = V_b^T x_cols (each block owns t_b);
    a fixed-point column is summed over its int16 codes, then scaled.
    Phase 2 (parallel over segments): y_seg = sum of dense rows and U_b rows times t_b
    over the blocks covering the segment. O(stored entries * nrhs) flops; all inner
    loops run over contiguous memory. Returns y of shape (nrhs, n_rows).
    """
    # Inner loops index slices (views) from 0: with computed offsets numba cannot
    # prove indices non-negative and its wrap-around checks block SIMD (3x slower).
    d = dof
    dc = col_dof
    nrhs = x.shape[0]
    n_lowrank = lowrank_rank.shape[0]
    t = np.zeros((nrhs, rank_offset[n_lowrank]))
    for b in prange(n_lowrank):
        k = lowrank_rank[b]
        c0 = dc * lowrank_col_start[b]
        nc = dc * (lowrank_col_stop[b] - lowrank_col_start[b])
        head = lowrank_head[b]
        t0 = rank_offset[b]
        for r in range(nrhs):
            x_cols = x[r, c0:c0 + nc]
            for q in range(head):
                v_column = v_values[v_offset[b] + q * nc:v_offset[b] + (q + 1) * nc]
                total = 0.0
                for j in range(nc):
                    total += v_column[j] * x_cols[j]
                t[r, t0 + q] = total
            for q in range(head, k):
                start = v_fixed_offset[b] + (q - head) * nc
                codes = v_fixed[start:start + nc]
                total = 0.0
                for j in range(nc):
                    total += codes[j] * x_cols[j]
                t[r, t0 + q] = total * v_scale[t0 + q]
    n_segments = segment_start.shape[0] - 1
    y = np.zeros((nrhs, n_rows))
    for s in prange(n_segments):
        r0 = d * segment_start[s]
        r1 = d * segment_start[s + 1]
        rows = r1 - r0
        for e in range(segment_dense_ptr[s], segment_dense_ptr[s + 1]):
            b = segment_dense_ids[e]
            c0 = dc * dense_col_start[b]
            nc = dc * (dense_col_stop[b] - dense_col_start[b])
            base = dense_offset[b] + (r0 - d * dense_row_start[b]) * nc
            for r in range(nrhs):
                x_cols = x[r, c0:c0 + nc]
                y_rows = y[r, r0:r1]
                for i in range(rows):
                    dense_row = dense_values[base + i * nc:base + (i + 1) * nc]
                    total = 0.0
                    for j in range(nc):
                        total += dense_row[j] * x_cols[j]
                    y_rows[i] += total
        for e in range(segment_lowrank_ptr[s], segment_lowrank_ptr[s + 1]):
            b = segment_lowrank_ids[e]
            k = lowrank_rank[b]
            head = lowrank_head[b]
            t0 = rank_offset[b]
            m = d * (lowrank_row_stop[b] - lowrank_row_start[b])
            shift = u_offset[b] + (r0 - d * lowrank_row_start[b])
            fixed_shift = u_fixed_offset[b] + (r0 - d * lowrank_row_start[b])
            for r in range(nrhs):
                y_rows = y[r, r0:r1]
                for q in range(head):
                    coefficient = t[r, t0 + q]
                    u_column = u_values[shift + q * m:shift + q * m + rows]
                    for i in range(rows):
                        y_rows[i] += coefficient * u_column[i]
                for q in range(head, k):
                    coefficient = t[r, t0 + q] * u_scale[t0 + q]
                    start = fixed_shift + (q - head) * m
                    codes = u_fixed[start:start + rows]
                    for i in range(rows):
                        y_rows[i] += coefficient * codes[i]
    return y


# The same loops compiled without parallel launches: the one-thread path skips the
# threading layer's fork/join (~0.5 ms per call measured under load at N = 1024). A
# renamed twin, with a numba cache of its own (hmatddm.compiled.serial_twin, issue 40).
_matmat_serial = serial_twin(_matmat_permuted, cache=True, fastmath=FAST)
