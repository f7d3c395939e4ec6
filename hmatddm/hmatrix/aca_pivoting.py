"""Whole-element pivots of the tensor ACA: the residual rows and columns of a pivot, the
choice of the next pivot (and of the convergence-check probes), and the cross C P^+ R a
pivot adds to the factors (grown when full, :func:`_grow`).

A scalar partial ACA is wrong for tensor kernels whose components decouple (a DDM
kernel of a planar crack couples shear only to shear and normal only to normal):
started on a shear row it never visits normal rows and stops with a large error
whatever the tolerance. Here every pivot is a whole element: the d rows of row
element i and the d columns of column element j are taken together and the d x d
pivot block is pseudo-inverted (SVD), adding its numerical rank (at most d) to the
approximation at once (:func:`_add_cross`). A d_r x d_c pivot with d_r > d_c, or a
weak direction left in the residual, leaves part of a visited element's rows in the
residual: :func:`_next_pivot_row` can pivot on an element again. The probes of the
convergence check (ACA+, Grasedyck 2005; Bebendorf's "ACA with a check") are the
unvisited elements farthest, in cluster-tree order, from every visited one
(:func:`_farthest_unvisited`).

The loop that calls these helpers, with its stopping test, check and give-up, is
:mod:`.aca_loop`; the conventions (transposed factors ``ut``, ``vt``, one vector per
contiguous row; residual updates as BLAS products on one BLAS thread) are those of
:mod:`.aca`.
"""

import numpy as np
from numba import njit

from ..compiled import FAST


# Pivot singular values below PIVOT_RTOL * largest are dropped (numerical rank).
PIVOT_RTOL = 1e-12


@njit(cache=True, nogil=True)
def _grow(factor, capacity):
    """Copy of a transposed factor (k x rows) with room for ``capacity`` vectors."""
    grown = np.zeros((capacity, factor.shape[1]))
    for k in range(factor.shape[0]):
        for i in range(factor.shape[1]):
            grown[k, i] = factor[k, i]
    return grown


@njit(cache=True, nogil=True)
def _grow_gram(gram, rank, capacity):
    """Copy of the Gram matrix U^T U (c x c) with room for ``capacity`` vectors."""
    grown = np.zeros((capacity, capacity))
    for a in range(rank):
        for b in range(rank):
            grown[a, b] = gram[a, b]
    return grown


@njit(cache=True, nogil=True, fastmath=FAST)
def _subtract_rows(residual, ut, vt, rank, first_row):
    """residual (d x n) -= U[first_row:first_row+d, :rank] @ V[:, :rank]^T.

    One BLAS product (d x rank) @ (rank x n) over the contiguous rows of V^T: the
    update reads V^T once for the d rows (a loop per row read it d times)."""
    if rank == 0:
        return
    d, n = residual.shape
    coefficients = np.empty((d, rank))
    for p in range(d):
        for l in range(rank):
            coefficients[p, l] = ut[l, first_row + p]
    update = np.dot(coefficients, vt[:rank])
    for p in range(d):
        for c in range(n):
            residual[p, c] -= update[p, c]


@njit(cache=True, nogil=True, fastmath=FAST)
def _subtract_cols(residual, ut, vt, rank, first_col):
    """residual (m x d) -= U[:, :rank] @ V[first_col:first_col+d, :rank]^T.

    One BLAS product U (m x rank, the transpose of the contiguous U^T rows) @ (rank x d):
    no stride-d loop over the residual per rank vector."""
    if rank == 0:
        return
    m, d = residual.shape
    coefficients = np.empty((rank, d))
    for l in range(rank):
        for q in range(d):
            coefficients[l, q] = vt[l, first_col + q]
    update = np.dot(ut[:rank].T, coefficients)
    for r in range(m):
        for q in range(d):
            residual[r, q] -= update[r, q]


@njit(cache=True, nogil=True)
def _best_element(residual_rows, visited, d):
    """Unvisited column element (``d`` unknowns each) with the largest |entry| in a
    d_r x n residual row block.

    Returns (element, largest |entry|); element = -1 when all are visited.
    """
    best = -1
    largest = -1.0
    for e in range(visited.shape[0]):
        if visited[e]:
            continue
        value = 0.0
        for p in range(residual_rows.shape[0]):
            for q in range(d):
                a = abs(residual_rows[p, e * d + q])
                if a > value:
                    value = a
        if value > largest:
            largest = value
            best = e
    return best, largest


@njit(cache=True, nogil=True)
def _best_row_element(residual_cols, visited, d):
    """Unvisited row element (``d`` unknowns each) with the largest squared norm in an
    m x d_c residual column block."""
    best = -1
    largest = -1.0
    for e in range(visited.shape[0]):
        if visited[e]:
            continue
        value = 0.0
        for p in range(d):
            for q in range(residual_cols.shape[1]):
                value += residual_cols[e * d + p, q] ** 2
        if value > largest:
            largest = value
            best = e
    return best, largest


@njit(cache=True, nogil=True)
def _next_pivot_row(residual_cols, visited, d, revisit, negligible):
    """Row element of the next pivot: the unvisited one with the largest residual in
    the m x d_c residual columns; when every row element was a pivot once (and
    ``revisit``), the one with the largest residual if it exceeds ``negligible`` (a
    d_r x d_c pivot with d_c < d_r, or a weak direction left by :func:`_add_cross`,
    captures only part of a row element's rows). -1 when there is none."""
    row, _ = _best_row_element(residual_cols, visited, d)
    if row < 0 and revisit:
        row, norm2 = _best_row_element(residual_cols, np.zeros(visited.shape[0], dtype=np.bool_), d)
        if row >= 0 and np.sqrt(norm2) <= negligible:
            row = -1
    return row


@njit(cache=True, nogil=True)
def _next_unvisited(visited, position, hop):
    """Next unvisited index after ``position`` walking by ``hop`` (coprime with len); -1 if none."""
    count = visited.shape[0]
    for _ in range(count):
        position = (position + hop) % count
        if not visited[position]:
            return position
    return -1


@njit(cache=True, nogil=True)
def _coprime_hop(count):
    """A step near 0.618*count that is coprime with count (visits every index)."""
    if count <= 2:
        return 1
    hop = max(1, int(0.618 * count))
    while True:
        a, b = hop, count
        while b:
            a, b = b, a % b
        if a == 1:
            return hop
        hop += 1


@njit(cache=True, nogil=True, fastmath=FAST)
def _max_abs(array):
    value = 0.0
    for x in array.ravel():
        a = abs(x)
        if a > value:
            value = a
    return value


@njit(cache=True, nogil=True, fastmath=FAST)
def _add_cross(ut, vt, gram, rank, residual_rows, residual_cols, first_col, threshold):
    """Append the cross C P^+ R of a whole-element pivot to the factors (vectors rank..).

    residual_rows R (d_r x n), residual_cols C (m x d_c), pivot P = R[:, first_col:+d_c].
    With P = W diag(s) Z^T the update is sum_k (C z_k / s_k)(R^T w_k)^T over the
    numerical rank of P (at most min(d_r, d_c)). The direction of the largest s_k is always kept; the others
    only when ||C z_k / s_k|| ||R^T w_k|| > threshold (a weak direction stays in the
    residual and is picked up by a later pivot if it matters). Returns (added rank,
    squared Frobenius norm of the update, 2 * inner product of the update with the
    previous approximation). O((m+n) k d). The product U^T U_new that the norms take
    also gives the new columns of the Gram matrix ``gram`` = U^T U, kept for the
    recompression (:func:`.recompression.recompress_gram`).
    """
    d = residual_rows.shape[0]
    dc = residual_cols.shape[1]
    pivot = np.empty((d, dc))
    for p in range(d):
        for q in range(dc):
            pivot[p, q] = residual_rows[p, first_col + q]
    w, s, zh = np.linalg.svd(pivot)
    added = 0
    for k in range(s.shape[0]):
        if s[k] > PIVOT_RTOL * s[0] and s[k] > 0.0:
            added += 1
    m = residual_cols.shape[0]
    n = residual_rows.shape[1]
    candidates = added
    added = 0
    for k in range(candidates):
        vector = rank + added
        inverse = 1.0 / s[k]
        u_norm2 = 0.0
        for r in range(m):
            total = 0.0
            for q in range(dc):
                total += residual_cols[r, q] * zh[k, q]
            ut[vector, r] = total * inverse
            u_norm2 += ut[vector, r] ** 2
        for c in range(n):
            vt[vector, c] = 0.0
        for p in range(d):
            coefficient = w[p, k]
            for c in range(n):
                vt[vector, c] += residual_rows[p, c] * coefficient
        v_norm2 = 0.0
        for c in range(n):
            v_norm2 += vt[vector, c] ** 2
        if k == 0 or u_norm2 * v_norm2 > threshold * threshold:
            added += 1
    # ||U_new V_new^T||_F^2 = sum_ab (U_new^T U_new)_ab (V_new^T V_new)_ab, and the
    # cross term with the old part uses (U_old^T U_new) and (V_old^T V_new): two BLAS
    # products (rank + added) x added.
    update_norm2 = 0.0
    cross = 0.0
    if added > 0:
        uu = np.dot(ut[:rank + added], ut[rank:rank + added].T)
        vv = np.dot(vt[:rank + added], vt[rank:rank + added].T)
        for a in range(rank + added):
            for b in range(added):
                if a >= rank:
                    update_norm2 += uu[a, b] * vv[a, b]
                else:
                    cross += uu[a, b] * vv[a, b]
                gram[a, rank + b] = uu[a, b]
                gram[rank + b, a] = uu[a, b]
    return added, update_norm2, 2.0 * cross


@njit(cache=True, nogil=True)
def _farthest_unvisited(visited):
    """Unvisited index farthest from every visited one (|i - j| in cluster-tree order,
    a proxy of the geometric distance); -1 when all are visited. O(len)."""
    count = visited.shape[0]
    left = np.empty(count, dtype=np.int64)
    last = -1
    for i in range(count):
        if visited[i]:
            last = i
        left[i] = i - last if last >= 0 else count
    best = -1
    best_distance = -1
    last = -1
    for i in range(count - 1, -1, -1):
        if visited[i]:
            last = i
            continue
        distance = left[i]
        if last >= 0 and last - i < distance:
            distance = last - i
        if distance > best_distance:
            best_distance = distance
            best = i
    return best


@njit(cache=True, nogil=True, fastmath=FAST)
def _squared_norm(array):
    total = 0.0
    for x in array.ravel():
        total += x * x
    return total
