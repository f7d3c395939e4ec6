"""Adaptive-precision storage of low-rank factors: leading columns in floating point,
trailing columns as 16-bit fixed point.

After recompression a far block is U V^T = sum_q sigma_q u_q v_q^T with the singular
values folded into U (``recompression.recompress_transposed``): column q of the factors carries
a share sigma_q of the block, and the trailing columns carry little. A column stored
with a relative rounding delta contributes an error of about sigma_q * delta, so the
columns with small sigma_q can be stored with fewer bits for the same block accuracy
(the adaptive-precision low-rank format of Amestoy et al. 2023, "Mixed precision
low-rank approximations and their application to block low-rank LU factorization",
and Kriemann 2023, "Hierarchical lowrank arithmetic with binary compression").

Here a trailing column is stored as int16 with one float64 scale per column
(``value = integer * scale``, ``scale = max|column| / 32767``): about 15 bits of the
column's largest entry, i.e. a relative column error of ~3e-5 on smooth columns. Each
block stores in fixed point the longest run of trailing columns whose summed error bound

    sum_q ( ||du_q|| (||v_q|| + ||dv_q||) + ||u_q|| ||dv_q|| )

(the exact rounding errors du_q, dv_q, measured while rounding) stays within
``FIXED_POINT_SHARE * eps * ||U V^T||_F``; the leading columns stay in the float store
(float32 at eps >= 1e-5). Each block is then within (1 + FIXED_POINT_SHARE) eps of the
kernel instead of eps. Measured on the planar crack (N = 4000, eps 1e-4): the low-rank
factors take 0.57x their float32 memory and the smooth-field error moves from 7.4e-7 to
7.6e-7; at N = 250 000 the H-matrix takes 10.9 GB instead of 16.2 (``benchmarks/RESULTS.md``,
"Issue 17 items 2 and 5: adaptive-precision low-rank factors").
"""

import numpy as np
from numba import njit

#: Share of a block's accuracy eps spent on the fixed-point rounding of trailing columns.
FIXED_POINT_SHARE = 0.25
#: Largest magnitude of the int16 codes (symmetric range).
FIXED_POINT_TOP = 32767.0


@njit(cache=True, nogil=True)
def _column_norm(values, start, length):
    total = 0.0
    for i in range(length):
        total += values[start + i] * values[start + i]
    return np.sqrt(total)


@njit(cache=True, nogil=True)
def _fixed_point_scale(values, start, length):
    largest = 0.0
    for i in range(length):
        a = abs(values[start + i])
        if a > largest:
            largest = a
    return largest / FIXED_POINT_TOP


@njit(cache=True, nogil=True)
def _rounding_error(values, start, length, scale):
    """||column - round(column / scale) * scale|| (0 for a zero column)."""
    if scale == 0.0:
        return 0.0
    total = 0.0
    for i in range(length):
        x = values[start + i]
        e = x - np.rint(x / scale) * scale
        total += e * e
    return np.sqrt(total)


@njit(cache=True, nogil=True)
def fixed_point_columns(ut, vt, offset_u, offset_v, rank, m, n, eps, share):
    """Number of leading columns of one block to keep in floating point.

    ``ut[offset_u:]`` holds U^T (``rank`` rows of length ``m``), ``vt[offset_v:]`` V^T
    (rows of length ``n``). Returns the head count h: columns h..rank-1 go to fixed
    point, their summed rounding error bound within ``share * eps * ||U V^T||_F``
    (Frobenius norm estimated as sqrt(sum_q ||u_q||^2 ||v_q||^2), exact for the
    orthogonal factors of a recompression).
    """
    u_norms = np.empty(rank)
    v_norms = np.empty(rank)
    norm2 = 0.0
    for q in range(rank):
        u_norms[q] = _column_norm(ut, offset_u + q * m, m)
        v_norms[q] = _column_norm(vt, offset_v + q * n, n)
        norm2 += (u_norms[q] * v_norms[q]) ** 2
    budget = share * eps * np.sqrt(norm2)
    if not np.isfinite(budget):  # NaN or inf entries stay visible in the float store
        return rank
    used = 0.0
    head = rank
    while head > 0:
        q = head - 1
        du = _rounding_error(ut, offset_u + q * m, m, _fixed_point_scale(ut, offset_u + q * m, m))
        dv = _rounding_error(vt, offset_v + q * n, n, _fixed_point_scale(vt, offset_v + q * n, n))
        error = du * (v_norms[q] + dv) + u_norms[q] * dv
        if used + error > budget:
            break
        used += error
        head -= 1
    return head


@njit(cache=True, nogil=True)
def split_factors(ranks, rows, cols, ut, vt, eps, share):
    """Split the factors of a batch of low-rank blocks into float and fixed-point parts.

    ``ranks[b]``, ``rows[b]`` = m, ``cols[b]`` = n of each low-rank block of the batch, in
    the order their U^T / V^T rows follow each other in ``ut`` / ``vt``. Returns
    (head, u_head, v_head, u_fixed, v_fixed, u_scale, v_scale): the head count of every
    block, the leading columns (float64, cast by the store), the trailing columns as
    int16 codes, and one scale per column of every block (0 for head columns), in the
    same order. ``share`` 0 keeps every column in floating point.
    """
    count = ranks.shape[0]
    head = np.zeros(count, dtype=np.int64)
    offset_u = 0
    offset_v = 0
    for b in range(count):
        k, m, n = ranks[b], rows[b], cols[b]
        head[b] = fixed_point_columns(ut, vt, offset_u, offset_v, k, m, n, eps, share) if share > 0.0 else k
        offset_u += k * m
        offset_v += k * n
    u_head, u_fixed, u_scale = _split_factor(ut, rows, ranks, head)
    v_head, v_fixed, v_scale = _split_factor(vt, cols, ranks, head)
    return head, u_head, v_head, u_fixed, v_fixed, u_scale, v_scale


@njit(cache=True, nogil=True)
def _split_factor(values, lengths, ranks, head):
    """One factor of a batch (``ranks[b]`` columns of ``lengths[b]`` each, block after
    block): (the first ``head[b]`` columns of every block, the others as int16 codes,
    one scale per column with 0 for the float ones)."""
    head_size = 0
    total = 0
    for b in range(ranks.shape[0]):
        head_size += head[b] * lengths[b]
        total += ranks[b] * lengths[b]
    float_part = np.empty(head_size)
    fixed_part = np.empty(total - head_size, dtype=np.int16)
    scales = np.zeros(ranks.sum())
    source = 0
    used_float = 0
    used_fixed = 0
    column = 0
    for b in range(ranks.shape[0]):
        length = lengths[b]
        for q in range(ranks[b]):
            if q < head[b]:
                for i in range(length):
                    float_part[used_float + i] = values[source + i]
                used_float += length
            else:
                scales[column] = _round_column(values, source, length, fixed_part, used_fixed)
                used_fixed += length
            source += length
            column += 1
    return float_part, fixed_part, scales


@njit(cache=True, nogil=True)
def _round_column(values, start, length, out, out_start):
    """out[out_start:+length] = round(column / scale) as int16; returns the scale."""
    scale = _fixed_point_scale(values, start, length)
    if scale == 0.0:
        for i in range(length):
            out[out_start + i] = 0
        return 0.0
    for i in range(length):
        out[out_start + i] = np.int16(np.rint(values[start + i] / scale))
    return scale


@njit(cache=True, nogil=True)
def factor_columns(values, offset, fixed, fixed_offset, scale, scale_start, rank, head, length):
    """The ``rank`` columns (length ``length``) of one stored factor as float64 rows
    (rank x length): the first ``head`` from ``values[offset:]``, the others decoded from
    ``fixed[fixed_offset:]`` with ``scale[scale_start + q]``."""
    out = np.empty((rank, length))
    for q in range(rank):
        if q < head:
            base = offset + q * length
            for i in range(length):
                out[q, i] = values[base + i]
        else:
            base = fixed_offset + (q - head) * length
            s = scale[scale_start + q]
            for i in range(length):
                out[q, i] = fixed[base + i] * s
    return out
