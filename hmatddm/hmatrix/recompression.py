"""Recompression of a low-rank approximation U V^T: truncation of the singular-value
tail at eps.

Every ACA approximation of the H-matrix build is recompressed, which typically halves
the ACA rank at no accuracy cost: at eps >= EIGEN_MIN_EPS from the QR of V and the Gram
matrix U^T U the ACA keeps, through a symmetric eigenproblem of the size of the rank
(:func:`recompress_gram`), below it by the QR of both factors and the SVD of the small
core (:func:`recompress_transposed`). The QRs are block Gram-Schmidt twice
(:func:`_orthonormalize`).

The factors are given transposed (``ut`` k x m, ``vt`` k x n, one vector per
contiguous row, as the ACA of :mod:`.aca_loop` keeps them; conventions in :mod:`.aca`).
The projections are BLAS products; the build runs them on one BLAS thread
(assembly._run_parallel), and so does :func:`recompress`, so that the factors never
depend on the BLAS thread count.
"""

import numpy as np
from numba import njit

from ..compiled import FAST
from ._threads import single_threaded_blas


# Vectors per panel of the blocked Gram-Schmidt (:func:`_orthonormalize`): the
# projections on the previous panels are BLAS products (rank x m) @ (m x PANEL).
PANEL = 16


@njit(cache=True, nogil=True, fastmath=FAST)
def _orthonormalize_panel(q, r, first, last, original):
    """Classical Gram-Schmidt twice of rows first..last-1 of ``q`` against each other
    (they are already orthogonal to the rows before ``first``), in place; adds the
    coefficients to ``r``. A row whose remaining squared norm is below 1e-28 times
    ``original`` (its squared norm before any projection) lies in the span of the
    previous ones and becomes zero."""
    m = q.shape[1]
    coefficients = np.empty(last - first)
    for k in range(first, last):
        w = q[k]
        for _ in range(2):
            for j in range(first, k):
                total = 0.0
                qj = q[j]
                for i in range(m):
                    total += qj[i] * w[i]
                coefficients[j - first] = total
            for j in range(first, k):
                c = coefficients[j - first]
                r[j, k] += c
                qj = q[j]
                for i in range(m):
                    w[i] -= c * qj[i]
        norm2 = 0.0
        for i in range(m):
            norm2 += w[i] * w[i]
        if norm2 > 1e-28 * original[k] and norm2 > 0.0:
            norm = np.sqrt(norm2)
            r[k, k] = norm
            inverse = 1.0 / norm
            for i in range(m):
                w[i] *= inverse
        else:
            for i in range(m):
                w[i] = 0.0


@njit(cache=True, nogil=True, fastmath=FAST)
def _orthonormalize(vectors, count):
    """Thin QR of the first ``count`` rows of ``vectors`` (k x m, one vector per row).

    Block classical Gram-Schmidt applied twice ("twice is enough"; BCGS2): panels of
    PANEL vectors are projected on the previous panels twice with BLAS products
    (most of the O(4 m k^2) flops), then orthonormalised among themselves by
    classical Gram-Schmidt twice on contiguous rows (:func:`_orthonormalize_panel`).
    About 2x faster than the vector-by-vector loop (and than LAPACK's Householder QR)
    on the skinny ACA factors of the build.
    Returns (q, r) with q (k x m) orthonormal rows (a zero row where a vector lies in
    the span of the previous ones) and r (k x k) upper triangular, vectors = r^T q.
    """
    m = vectors.shape[1]
    q = np.empty((count, m))
    r = np.zeros((count, count))
    original = np.empty(count)
    for k in range(count):
        total = 0.0
        for i in range(m):
            q[k, i] = vectors[k, i]
            total += q[k, i] * q[k, i]
        original[k] = total
    for first in range(0, count, PANEL):
        last = min(count, first + PANEL)
        if first > 0:
            previous = q[:first]
            panel = q[first:last]
            for _ in range(2):
                coefficients = np.dot(previous, panel.T)  # first x (last - first)
                panel -= np.dot(coefficients.T, previous)
                # element by element, not by slice assignment (docs/conventions.md, §5)
                for a in range(first):
                    for b in range(first, last):
                        r[a, b] += coefficients[a, b - first]
        _orthonormalize_panel(q, r, first, last, original)
    return q, r


@njit(cache=True, nogil=True, fastmath=FAST)
def _kept_rank(tail_squares, total, eps):
    """The truncation rule of both recompressions: the smallest rank whose discarded
    squared singular values, ``tail_squares`` (all of them, the smallest first), sum to
    at most ``eps^2 * total``."""
    tail = 0.0
    kept = tail_squares.shape[0]
    for square in tail_squares:
        if tail + square > eps * eps * total:
            break
        tail += square
        kept -= 1
    return kept


@njit(cache=True, nogil=True, fastmath=FAST)
def recompress_transposed(ut, vt, rank, eps):
    """Truncate U V^T (given as the first ``rank`` rows of U^T and V^T) to the smallest
    rank with relative Frobenius error <= eps.

    QR of both factors, SVD of the small core R_u R_v^T, truncation of the singular
    value tail: O((m + n) k^2 + k^3). Returns (U'^T, V'^T, rank') with U' = Q_u W S
    and V' = Q_v Z (singular values folded into U'). Rank 0 for a zero product.
    """
    m = ut.shape[1]
    n = vt.shape[1]
    if rank == 0:
        return np.zeros((0, m)), np.zeros((0, n)), 0
    qu, ru = _orthonormalize(ut, rank)
    qv, rv = _orthonormalize(vt, rank)
    # U = qu^T ru and V = qv^T rv (rows of qu, qv orthonormal): U V^T = qu^T (ru rv^T) qv
    core = np.dot(ru, rv.T)
    w, s, zh = np.linalg.svd(core, False)
    total = 0.0
    for x in s:
        total += x * x
    if total == 0.0 or not np.isfinite(total):
        return np.zeros((0, m)), np.zeros((0, n)), 0
    new_rank = _kept_rank(s[::-1] ** 2, total, eps)
    if new_rank == 0:
        return np.zeros((0, m)), np.zeros((0, n)), 0
    # U'^T = (W S)^T qu and V'^T = Z^T qv over the kept columns: two BLAS products
    left = np.empty((new_rank, rank))
    right = np.empty((new_rank, rank))
    for k in range(new_rank):
        for j in range(rank):
            left[k, j] = w[j, k] * s[k]
            right[k, j] = zh[k, j]
    u_out = np.dot(left, qu)
    v_out = np.dot(right, qv)
    return u_out, v_out, new_rank


# At eps >= EIGEN_MIN_EPS the recompression finds the singular values and vectors of the
# product from a symmetric eigenproblem (:func:`recompress_gram`) instead of an SVD of the
# core: its eigenvalues are the squared singular values, known to an absolute ~k u
# sigma_1^2 (u: unit round-off, k the ACA rank), against a truncated tail of eps^2
# sigma_1^2 or more: a relative ~1e-4 of it at eps = 1e-5 (k ~ 100), ~1e-6 at the usual
# 1e-4. Below it the SVD path (:func:`recompress_transposed`), whose singular values are
# accurate to ~u sigma_1.
EIGEN_MIN_EPS = 1e-5


@njit(cache=True, nogil=True, fastmath=FAST)
def recompress_gram(ut, vt, gram_u, rank, eps):
    """:func:`recompress_transposed` with one QR and an eigenproblem, given the Gram
    matrix G_u = U^T U (``rank`` x ``rank``, e.g. kept by the ACA); at eps <
    EIGEN_MIN_EPS it is :func:`recompress_transposed`.

    V = Q_v R_v (block Gram-Schmidt, :func:`_orthonormalize`), so U V^T = (U R_v^T) Q_v^T
    and (U V^T)^T (U V^T) = Q_v M Q_v^T with M = R_v G_u R_v^T (k x k, symmetric).
    With M = Z diag(s^2) Z^T: U' = U R_v^T Z and V' = Q_v Z over the kept eigenvalues
    (the singular values folded into U', V' orthonormal, as from the SVD path). The
    truncation is the orthogonal projection of the rows of U V^T on V' (error^2 = the
    dropped eigenvalues, to ~k u sigma_1^2). Compared with the SVD path it saves the QR
    of U (O(m k^2), replaced by the Gram matrix the ACA has anyway) and replaces the
    SVD of the k x k core by a symmetric eigenproblem (~4x cheaper at k ~ 50).
    U itself is never inverted: its conditioning does not matter.
    """
    m = ut.shape[1]
    n = vt.shape[1]
    if eps < EIGEN_MIN_EPS:
        return recompress_transposed(ut, vt, rank, eps)
    if rank == 0:
        return np.zeros((0, m)), np.zeros((0, n)), 0
    qv, rv = _orthonormalize(vt, rank)
    gram = np.empty((rank, rank))  # a contiguous copy of the leading block for BLAS
    for i in range(rank):
        for j in range(rank):
            gram[i, j] = gram_u[i, j]
    product = np.dot(rv, gram)
    reduced = np.dot(product, rv.T)
    for i in range(rank):  # exactly symmetric for the eigensolver
        for j in range(i):
            mean = 0.5 * (reduced[i, j] + reduced[j, i])
            reduced[i, j] = mean
            reduced[j, i] = mean
    values, vectors = np.linalg.eigh(reduced)  # ascending
    total = 0.0
    for x in values:
        if x > 0.0:
            total += x
    if total == 0.0 or not np.isfinite(total):
        return np.zeros((0, m)), np.zeros((0, n)), 0
    new_rank = _kept_rank(np.maximum(values, 0.0), total, eps)  # eigenvalues: squared singular values
    if new_rank == 0:
        return np.zeros((0, m)), np.zeros((0, n)), 0
    # kept eigenvectors, largest first: Z_k^T (k' x k)
    kept = np.empty((new_rank, rank))
    for k in range(new_rank):
        for j in range(rank):
            kept[k, j] = vectors[j, rank - 1 - k]
    # U'^T = Z_k^T R_v U^T and V'^T = Z_k^T Q_v
    left = np.dot(kept, rv)
    u_out = np.dot(left, ut[:rank])
    v_out = np.dot(kept, qv)
    return u_out, v_out, new_rank


@njit(cache=True, nogil=True)
def recompress_transposed_gram(ut, vt, rank, eps):
    """:func:`recompress_gram` with the Gram matrix of U computed here (one BLAS product)."""
    gram_u = np.dot(ut[:rank], ut[:rank].T)
    return recompress_gram(ut, vt, gram_u, rank, eps)


def recompress(u, v, eps):
    """The build's recompression (:func:`recompress_gram`, the Gram matrices computed
    here) for factors U (m x k), V (n x k); returns (U', V', rank').

    On one BLAS thread, as in the build: the rounding of the BLAS products (and so the
    factors, to round-off) would otherwise depend on the BLAS thread count."""
    with single_threaded_blas():
        return _recompress(u, v, eps)


@njit(cache=True, nogil=True)
def _recompress(u, v, eps):
    """:func:`recompress` (compiled)."""
    ut, vt, rank = recompress_transposed_gram(np.ascontiguousarray(u.T), np.ascontiguousarray(v.T), u.shape[1], eps)
    return np.ascontiguousarray(ut.T), np.ascontiguousarray(vt.T), rank
