"""Adaptive cross approximation (ACA) of d x d tensor blocks, with recompression.

A scalar partial ACA is wrong for tensor kernels whose components decouple (a DDM
kernel of a planar crack couples shear only to shear and normal only to normal):
started on a shear row it never visits normal rows and stops with a large error
whatever the tolerance. Here every pivot is a whole element: the d rows of row
element i and the d columns of column element j are taken together and the d x d
pivot block is pseudo-inverted (SVD), adding its numerical rank (at most d) to the
approximation at once.

Every approximation is then recompressed (truncation of the singular-value tail of
U V^T at eps), which typically halves the ACA rank at no accuracy cost: at eps >=
EIGEN_MIN_EPS from the QR of V and the Gram matrix U^T U the ACA keeps, through a
symmetric eigenproblem of the size of the rank (:func:`recompress_gram`), below it by
the QR of both factors and the SVD of the small core (:func:`recompress_transposed`).

The stopping test ``||u|| ||v|| <= eps ||S_k||`` only looks at the last cross, and the
pivots are chosen from the last residual rows and columns: on a block that mixes
scales (rows and columns of a large fracture plus several small ones) every pivot
lands in the large part, whose rows and columns do not see the interaction of the
small parts with each other, and the ACA stops at 2-3e-2 error whatever eps. So,
as in ACA+ (Grasedyck 2005; Bebendorf's "ACA with a check"), convergence is only
accepted after a check: the exact residual of a few row and column elements that no
pivot has visited (the unvisited ones farthest, in cluster-tree order, from every
visited one) must be small; a probe that fails becomes the next pivot and the
iteration goes on.

Blocks the ACA cannot compress: once every row element (or every column element) has
been a pivot, the ACA has evaluated as many entries as the block holds, and pivoting
on elements again is where its accuracy broke down: a d_r x d_c pivot with d_r > d_c,
or a weak direction left in the residual, leaves a part of the visited rows that the
re-pivots (chosen from the last residual columns) stopped finding, and the loop ended
on "no residual left where I look" (rectangular 3D field blocks of 28 x 32 elements
stopped at rank 58-62 of 64 with a block error of 1e-6 - 1e-2 whatever eps). So the
ACA only ends normally through a passed stopping test and convergence check (or on a
zero block); an end without them after every row or every column element was a pivot
makes it GIVE UP by design: it stops and flags the block (:func:`aca_gave_up`), and the
callers store and apply the block exactly (dense); the kernel fill costs no more
entries than the ACA already spent. It also gives up on reaching rank min(m, n), which
is exact in exact arithmetic but not in floating point, where the check can only probe
unvisited elements (on an AMD EPYC the 28 x 32-element block above reached rank 64 of 64
with "converged" factors 17x eps off at eps 1e-6); stored dense, such a block is smaller
too, as min(m, n) (m + n) > m n. (Giving up on a converged block with no unvisited
element left to check was tried and not kept: those blocks were within eps after
recompression, and storing them dense cost memory.)

Conventions: a block is given by its row elements (m_e of them, d_r unknowns each)
and column elements (n_e, d_c unknowns each: a rectangular matrix, e.g. stress
components at points x DD components of elements, has d_r != d_c; a square operator
d_r = d_c = d); it has m = d_r*m_e rows and n = d_c*n_e columns and is approximated by
U V^T with U (m x k) and V (n x k). A pivot is a d_r x d_c block. The ACA and the recompression work on the transposed
factors (``ut`` k x m, ``vt`` k x n, one vector per contiguous row) so that every
inner loop is contiguous. The residual updates and the recompression's projections are
BLAS products; the build runs them on one BLAS thread (storage._run_parallel), and so do
the Python entry points here, so that the factors never depend on the BLAS thread count.

Length (over ~400 lines): the one ACA loop used in production and its numba helpers
(pivoting on tensor blocks, re-pivoting, recompression), which must compile together.
"""

import numpy as np
from numba import njit, types

from ._threads import single_threaded_blas
from .first_class import INDEX, compiled_for_data

# Floating-point flags that let LLVM vectorise dot products (reassociation) while
# keeping NaN/inf semantics, so finiteness checks stay meaningful.
FAST = {"reassoc", "contract", "nsz", "arcp"}

# Pivot singular values below PIVOT_RTOL * largest are dropped (numerical rank).
PIVOT_RTOL = 1e-12
# A residual row/column whose largest entry is below NEGLIGIBLE * (largest entry seen
# in the block) is treated as zero.
NEGLIGIBLE = 1e-14
# An ACA used as it is (no recompression: the one-shot product, hmatrix/product.py, and
# the field evaluation of hmatddm/fields.py) runs at ACA_TOLERANCE_FACTOR * eps: the ACA
# stopping test (size of the last update) underestimates the error by up to ~10x on some
# blocks, and the tighter ACA removes that.
ACA_TOLERANCE_FACTOR = 0.1
# The H-matrix build (:func:`aca_compressed`) runs the ACA at RECOMPRESSED_ACA_FACTOR * eps
# and the recompression truncates at eps. A looser ACA costs less (at 0.1 eps its rank
# overshoots the stored one ~2x: 10k cloud, eps 1e-4, ACA rank 50.6 for 26.6 stored;
# planar crack 35.6 for 19.0), and at 0.3 eps the stored ranks were the same and the
# stored block errors against the exact blocks stayed within 1.11 eps (every 9th far
# block of both). But the error of the product with a smooth field grew: 10k planar
# crack 1.2e-6 -> 1.7e-6 (0.2 eps) and 2.1e-6 (0.3 eps), 40k 2.2e-6 -> 3.4e-6 (0.3 eps);
# the ACA leaves its error in the smooth directions that the truncation of the SVD tail
# spares. So the build keeps 0.1 (benchmarks/RESULTS.md, "Issue 17 item 2: the far-field
# ACA"; `bench_hmatrix.py --aca-study`).
RECOMPRESSED_ACA_FACTOR = 0.1
# Consecutive negligible pivots tolerated before the block is declared converged.
MAX_FAILED_PIVOTS = 4
# Convergence check (ACA+-like): when the stopping test passes, CHECK_PROBES row
# elements and CHECK_PROBES column elements not yet visited are evaluated exactly
# (alternately, each the unvisited element farthest in cluster-tree order from the
# visited ones). A probe fails when its residual, extrapolated to the whole block
# (times sqrt of the element count), exceeds CHECK_FACTOR * eps * ||S_k||_F (eps of
# the ACA, i.e. ACA_TOLERANCE_FACTOR or RECOMPRESSED_ACA_FACTOR times the block's eps); it is then used as the next
# pivot. Cost on ordinary blocks: 2 * CHECK_PROBES extra row/column evaluations.
CHECK_PROBES = 2
CHECK_FACTOR = 3.0


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
    recompression (:func:`recompress_gram`).
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


# The ACA is a resumable state machine (cached, kernel-independent): each call of
# aca_advance consumes the rows or columns just evaluated and says what to evaluate
# next. Only the small loop _aca_loop calls the kernel (aca_tensor for tests and
# explicit blocks, aca_compressed for the H-matrix build); the build driver
# (storage.build_driver) receives the kernel and these steps as first-class functions
# of fixed signatures, so the driver with this loop in it is small and cached on disk
# per data type.
REQUEST_DONE = 0
REQUEST_ROW = 1  # evaluate the d_r rows of row element `index` into `rows` (d_r x n)
REQUEST_COL = 2  # evaluate the d_c columns of column element `index` into `cols` (m x d_c)

# Slots of the integer state array.
_PHASE, _RANK, _FAILURES, _PROBE, _ROW, _COL, _ROW_HOP, _COL_HOP, _CHECKS, _CHECK_INDEX, _GAVE_UP = range(11)
_PHASE_PIVOT_ROW, _PHASE_PIVOT_COL, _PHASE_PROBE_COL, _PHASE_CHECK_ROW, _PHASE_CHECK_COL = 0, 1, 2, 3, 4
# Slots of the float state array.
_SCALE, _NORM2, _EPS = range(3)

@njit(cache=True, nogil=True)
def _next_check(row_visited, col_visited, ints):
    """Request of the next convergence-check probe, or REQUEST_DONE when all passed.

    Probes alternate row, column, row, ... (2 * CHECK_PROBES in all); a side with no
    unvisited element left is skipped.
    """
    while ints[_CHECKS] < 2 * CHECK_PROBES:
        k = ints[_CHECKS]
        ints[_CHECKS] = k + 1
        if k % 2 == 0:
            row = _farthest_unvisited(row_visited)
            if row >= 0:
                ints[_CHECK_INDEX] = row
                ints[_PHASE] = _PHASE_CHECK_ROW
                return REQUEST_ROW, row
        else:
            col = _farthest_unvisited(col_visited)
            if col >= 0:
                ints[_CHECK_INDEX] = col
                ints[_PHASE] = _PHASE_CHECK_COL
                return REQUEST_COL, col
    return REQUEST_DONE, 0


# Why the ACA gave up (ints[_GAVE_UP]; 0: it did not).
GAVE_UP_NO_PIVOT = 1  # ended unconverged after every row or column element was a pivot
GAVE_UP_FULL_RANK = 2  # the rank reached min(m, n)


@njit(cache=True, nogil=True)
def _give_up(ints, reason):
    """Stop and flag the block for exact (dense) storage (see the module docstring);
    ``reason`` (> 0, kept in the state for diagnostics): GAVE_UP_* below."""
    ints[_GAVE_UP] = reason
    return REQUEST_DONE, 0


@njit(cache=True, nogil=True)
def _stop(ints, row_visited, col_visited):
    """End of the ACA other than through a passed convergence check: it gives up when
    some pivots were found and every row or every column element was a pivot (the
    block was not converged where it had been sampled whole); otherwise (zero block,
    zero rows left) it is done."""
    if ints[_RANK] > 0 and (_all(row_visited) or _all(col_visited)):
        return _give_up(ints, GAVE_UP_NO_PIVOT)
    return REQUEST_DONE, 0


@njit(cache=True, nogil=True)
def _all(flags):
    for flag in flags:
        if not flag:
            return False
    return True


@njit(cache=True, nogil=True)
def aca_gave_up(ints):
    """True when the ACA of this state gave up on its block: every row or column
    element was a pivot before convergence, or the rank reached min(m, n). The factors
    are then NOT an approximation of the block: evaluate it exactly instead."""
    return ints[_GAVE_UP] != 0


# Signatures of the state-machine steps: compiled for these (:func:`aca_steps`), the
# kernel-specific build and product drivers take them as first-class function arguments
# and call them through pointers instead of linking (and re-optimising) their code,
# which cuts the cold compile per kernel data type from ~10 s to ~3 s of CPU. They are
# compiled on first use, not at import: ~28 s of CPU with a cold cache (AMD EPYC),
# which each test process and every dense-only run used to pay on importing this module.
_MATRIX = types.float64[:, ::1]
_FLAGS = types.boolean[::1]
_INTS = types.int64[::1]
_FLOATS = types.float64[::1]
_GRAM = _MATRIX
ACA_START_SIGNATURE = types.Tuple(
    (_MATRIX, _MATRIX, _GRAM, _MATRIX, _MATRIX, _FLAGS, _FLAGS, _INTS, _FLOATS, types.int64, types.int64)
)(types.int64, types.int64, types.int64, types.int64, types.float64)
ACA_ADVANCE_SIGNATURE = types.Tuple((_MATRIX, _MATRIX, _GRAM, types.int64, types.int64))(
    _MATRIX, _MATRIX, _GRAM, _MATRIX, _MATRIX, _FLAGS, _FLAGS, _INTS, _FLOATS
)
RECOMPRESS_STATE_SIGNATURE = types.Tuple((_MATRIX, _MATRIX, types.int64))(_MATRIX, _MATRIX, _GRAM, _INTS,
                                                                         types.float64)


@njit(cache=True, nogil=True)
def aca_start(n_row_elements, n_col_elements, row_dof, col_dof, eps):
    """Allocate the ACA state of an (m_e x n_e)-element block with ``row_dof`` unknowns
    per row element and ``col_dof`` per column element; first request: row element 0.

    Returns (ut, vt, gram, rows, cols, row_visited, col_visited, ints, floats, request,
    index) with the transposed factors ut (capacity x m), vt (capacity x n) and the Gram
    matrix gram = U^T U (capacity x capacity).
    """
    m = n_row_elements * row_dof
    n = n_col_elements * col_dof
    d = max(row_dof, col_dof)
    capacity = min(min(m, n) + d, 4 * d)
    ints = np.zeros(11, dtype=np.int64)
    ints[_ROW_HOP] = _coprime_hop(n_row_elements)
    ints[_COL_HOP] = _coprime_hop(n_col_elements)
    ints[_PHASE] = _PHASE_PIVOT_ROW
    floats = np.zeros(3)
    floats[_EPS] = eps
    row_visited = np.zeros(n_row_elements, dtype=np.bool_)
    row_visited[0] = True
    return (np.zeros((capacity, m)), np.zeros((capacity, n)), np.zeros((capacity, capacity)), np.empty((row_dof, n)),
            np.empty((m, col_dof)), row_visited, np.zeros(n_col_elements, dtype=np.bool_), ints, floats, REQUEST_ROW, 0)


@njit(cache=True, nogil=True)
def aca_advance(ut, vt, gram, rows, cols, row_visited, col_visited, ints, floats):
    """One step of the whole-element ACA after the requested entries were evaluated.

    Phases: after a pivot row element (``rows`` holds its d raw rows) pick the
    column element with the largest residual entry and request it; after that
    column element (``cols`` holds its raw columns) add the cross C P^+ R and request
    the row element with the largest residual in C; a negligible residual row is
    skipped by probing an unvisited column element for a row with a residual. When
    the stopping test passes, the convergence check requests its probes (see
    CHECK_PROBES): a probe row with a large residual becomes the next pivot row, a
    probe column with a large residual gives the next pivot row (its largest residual).
    When the ACA ends without a passed stopping test and check after every row or
    every column element was a pivot (the pivots ran out, or only zero residuals were
    left where pivots were), it gives up (REQUEST_DONE with :func:`aca_gave_up` true;
    module docstring). It also gives up on reaching rank min(m, n).
    Returns (ut, vt, gram, request, index); ut, vt, gram may have been reallocated to grow.
    """
    d = rows.shape[0]  # unknowns per row element
    dc = cols.shape[1]  # unknowns per column element
    m = cols.shape[0]
    n = rows.shape[1]
    max_rank = min(m, n)
    rank = ints[_RANK]
    phase = ints[_PHASE]
    if phase == _PHASE_PIVOT_ROW or phase == _PHASE_CHECK_ROW:
        row = ints[_ROW] if phase == _PHASE_PIVOT_ROW else ints[_CHECK_INDEX]
        floats[_SCALE] = max(floats[_SCALE], _max_abs(rows))
        _subtract_rows(rows, ut, vt, rank, row * d)
        if phase == _PHASE_CHECK_ROW:
            row_visited[row] = True
            limit = CHECK_FACTOR * floats[_EPS]
            if row_visited.shape[0] * _squared_norm(rows) <= limit * limit * floats[_NORM2]:
                request, index = _next_check(row_visited, col_visited, ints)
                return ut, vt, gram, request, index
            ints[_CHECKS] = 0  # the check failed: this row is the next pivot
            ints[_ROW] = row
        col, largest = _best_element(rows, col_visited, dc)
        if col < 0 and rank < max_rank:
            # every column element was a pivot once, but a weak direction of a pivot
            # (see _add_cross) may have stayed in the residual: pivot on the largest
            # residual entry again (blocks with few column elements, e.g. 18 x 2 DDs)
            col, largest = _best_element(rows, np.zeros(col_visited.shape[0], dtype=np.bool_), dc)
        if col < 0:
            request, index = _stop(ints, row_visited, col_visited)
            return ut, vt, gram, request, index
        if largest > NEGLIGIBLE * floats[_SCALE]:
            col_visited[col] = True
            ints[_COL] = col
            ints[_PHASE] = _PHASE_PIVOT_COL
            return ut, vt, gram, REQUEST_COL, col
        # Zero residual row: probe an unvisited column for a row that has a residual.
        ints[_FAILURES] += 1
        probe = _next_unvisited(col_visited, ints[_PROBE], ints[_COL_HOP])
        if ints[_FAILURES] >= MAX_FAILED_PIVOTS or probe < 0:
            request, index = _stop(ints, row_visited, col_visited)
            return ut, vt, gram, request, index
        ints[_PROBE] = probe
        ints[_PHASE] = _PHASE_PROBE_COL
        return ut, vt, gram, REQUEST_COL, probe
    floats[_SCALE] = max(floats[_SCALE], _max_abs(cols))
    if phase == _PHASE_CHECK_COL:
        probe = ints[_CHECK_INDEX]
        _subtract_cols(cols, ut, vt, rank, probe * dc)
        limit = CHECK_FACTOR * floats[_EPS]
        if col_visited.shape[0] * _squared_norm(cols) <= limit * limit * floats[_NORM2]:
            col_visited[probe] = True
            request, index = _next_check(row_visited, col_visited, ints)
            return ut, vt, gram, request, index
        ints[_CHECKS] = 0  # the check failed: pivot on this column's largest residual row
        row = _next_pivot_row(cols, row_visited, d, rank < max_rank, NEGLIGIBLE * floats[_SCALE])
        if row < 0:
            request, index = _stop(ints, row_visited, col_visited)
            return ut, vt, gram, request, index
        row_visited[row] = True
        ints[_ROW] = row
        ints[_PHASE] = _PHASE_PIVOT_ROW
        return ut, vt, gram, REQUEST_ROW, row
    if phase == _PHASE_PROBE_COL:
        probe = ints[_PROBE]
        _subtract_cols(cols, ut, vt, rank, probe * dc)
        candidate, norm2 = _best_row_element(cols, row_visited, d)
        if candidate >= 0 and np.sqrt(norm2) > NEGLIGIBLE * floats[_SCALE]:
            row = candidate
        else:
            col_visited[probe] = True  # its residual column is zero and stays zero
            row = _next_unvisited(row_visited, ints[_ROW], ints[_ROW_HOP])
            if row < 0 and rank < max_rank:
                row = _next_pivot_row(cols, row_visited, d, True, NEGLIGIBLE * floats[_SCALE])
        if row < 0:
            request, index = _stop(ints, row_visited, col_visited)
            return ut, vt, gram, request, index
        row_visited[row] = True
        ints[_ROW] = row
        ints[_PHASE] = _PHASE_PIVOT_ROW
        return ut, vt, gram, REQUEST_ROW, row
    # phase == _PHASE_PIVOT_COL: add the cross of pivot (row, col).
    col = ints[_COL]
    _subtract_cols(cols, ut, vt, rank, col * dc)
    if rank + min(d, dc) > ut.shape[0]:
        capacity = min(max_rank + max(d, dc), 2 * ut.shape[0])
        ut = _grow(ut, capacity)
        vt = _grow(vt, capacity)
        gram = _grow_gram(gram, rank, capacity)
    threshold = floats[_EPS] * np.sqrt(floats[_NORM2])
    added, update_norm2, cross = _add_cross(ut, vt, gram, rank, rows, cols, col * dc, threshold)
    rank += added
    ints[_RANK] = rank
    floats[_NORM2] = max(floats[_NORM2] + update_norm2 + cross, 0.0)
    ints[_FAILURES] = 0
    if rank >= max_rank:
        # Full rank: exact in exact arithmetic, but not always in floating point (the
        # weak directions of rectangular pivots), and the check can only probe unvisited
        # elements: the exact block is both safe and no larger (min(m, n) (m + n) > m n).
        request, index = _give_up(ints, GAVE_UP_FULL_RANK)
        return ut, vt, gram, request, index
    if update_norm2 <= floats[_EPS] ** 2 * floats[_NORM2]:
        request, index = _next_check(row_visited, col_visited, ints)
        return ut, vt, gram, request, index
    row = _next_pivot_row(cols, row_visited, d, True, NEGLIGIBLE * floats[_SCALE])
    if row < 0:
        request, index = _stop(ints, row_visited, col_visited)
        return ut, vt, gram, request, index
    row_visited[row] = True
    ints[_ROW] = row
    ints[_PHASE] = _PHASE_PIVOT_ROW
    return ut, vt, gram, REQUEST_ROW, row


@njit(cache=True, nogil=True)
def aca_result(ut, vt, ints):
    """(U, V, rank) of a finished ACA, factors trimmed to the rank (contiguous copies)."""
    rank = ints[_RANK]
    u_out = np.empty((ut.shape[1], rank))
    v_out = np.empty((vt.shape[1], rank))
    for k in range(rank):
        for i in range(ut.shape[1]):
            u_out[i, k] = ut[k, i]
        for i in range(vt.shape[1]):
            v_out[i, k] = vt[k, i]
    return u_out, v_out, rank


def aca_tensor(kernel, data, row_elements, col_elements, dof, eps, col_dof=0):
    """Partial ACA with whole-element pivots of the block rows x cols (original indices),
    ``dof`` unknowns per row element and ``col_dof`` per column element (0: ``dof``).

    Each step evaluates one row element (d rows) and one column element (d columns)
    of the residual: O((m + n) * d) kernel entries and O((m + n) * k * d) flops at
    rank k. The next row element is the one with the largest residual in the last
    pivot columns; a negligible residual row (a zero part of the block) is skipped
    by probing an unvisited column for a better row instead of stopping. Stops when
    the last update satisfies ||U_k V_k^T||_F <= eps ||S_k||_F (the norm of the
    approximation S_k is updated incrementally, cross terms included) and the
    convergence check passes (unvisited probe rows and columns with a residual
    below CHECK_FACTOR * eps ||S_k||_F, extrapolated to the block). When it gives up
    (every row or column element used before convergence, or rank min(m, n): see
    the module docstring) the block is evaluated exactly and returned as an exact
    factorisation (U = block, V = identity, or U = identity, V = block^T; rank
    min(m, n)), as the build stores it dense.

    Returns (U, V, rank) with U (m x rank), V (n x rank); rank 0 for a zero block.
    Compiled once per data type (cached on disk, :func:`_for_data`).
    """
    col_dof = col_dof if col_dof > 0 else dof
    compiled = _for_data(_aca_tensor, data, 2)
    with single_threaded_blas():  # as in the build (see recompress)
        return compiled(kernel, data, _index(row_elements), _index(col_elements), int(dof), int(col_dof), float(eps),
                        *aca_steps()[:2])


def _aca_tensor(kernel, data, row_elements, col_elements, dof, col_dof, eps, start, advance):
    """:func:`aca_tensor` (njit source, compiled by :func:`_for_data`)."""
    ut, vt, ints = _aca_loop(kernel, data, row_elements, col_elements, dof, col_dof, eps, start, advance)
    if aca_gave_up(ints):
        m, n = dof * row_elements.shape[0], col_dof * col_elements.shape[0]
        block = np.empty((m, n))
        kernel(data, row_elements, col_elements, block)
        if m <= n:
            return np.eye(m), np.ascontiguousarray(block.T), m
        return block, np.eye(n), n
    return aca_result(ut, vt, ints)


@njit(cache=True, nogil=True)
def _all_finite(array):
    for x in array.ravel():
        if not np.isfinite(x):
            return False
    return True


@njit(nogil=True)
def _aca_loop(kernel, data, row_elements, col_elements, row_dof, col_dof, eps, start, advance):
    """Drive the ACA state machine (``start`` = :func:`aca_start`, ``advance`` =
    :func:`aca_advance`) to the end, evaluating the requested row and column elements
    with ``kernel``; returns (ut, vt, ints). When ``aca_gave_up(ints)`` the factors are
    no approximation: use the exact block. (:func:`_aca_run`, less the Gram matrices.)"""
    ut, vt, _, ints = _aca_run(kernel, data, row_elements, col_elements, row_dof, col_dof, eps, start, advance)
    return ut, vt, ints


@njit(nogil=True)
def _aca_run(kernel, data, row_elements, col_elements, row_dof, col_dof, eps, start, advance):
    """Drive the ACA state machine (``start`` = :func:`aca_start`, ``advance`` =
    :func:`aca_advance`) to the end, evaluating the requested row and column elements
    with ``kernel``; returns (ut, vt, gram, ints). When ``aca_gave_up(ints)`` the
    factors are no approximation: use the exact block.

    The steps are arguments so that the compiled build and product drivers
    (hmatrix/storage.py, hmatrix/product.py) can pass them as first-class functions:
    called through pointers, their code is compiled once and cached instead of being
    linked and re-optimised into every kernel-specific driver (~10 s of compile per
    kernel data type before, ~3 s now). Python callers (:func:`aca_tensor`,
    :func:`aca_compressed`) pass the dispatchers themselves. A call through a pointer
    cannot raise, so NaN/inf kernel entries are refused here, before the pivot SVD
    would (the same LinAlgError as that SVD raises).
    """
    ut, vt, gram, rows, cols, row_visited, col_visited, ints, floats, request, index = start(
        row_elements.shape[0], col_elements.shape[0], row_dof, col_dof, eps)
    while request != REQUEST_DONE:
        if request == REQUEST_ROW:
            kernel(data, row_elements[index:index + 1], col_elements, rows)
            finite = _all_finite(rows)
        else:
            kernel(data, row_elements, col_elements[index:index + 1], cols)
            finite = _all_finite(cols)
        if not finite:
            raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")
        ut, vt, gram, request, index = advance(ut, vt, gram, rows, cols, row_visited, col_visited, ints, floats)
    return ut, vt, gram, ints


def aca_compressed(kernel, data, row_elements, col_elements, row_dof, col_dof, eps):
    """What the H-matrix build stores for an admissible block: the ACA of
    :func:`aca_tensor` at ``RECOMPRESSED_ACA_FACTOR * eps``, recompressed at ``eps``.

    Returns the TRANSPOSED factors (U'^T, V'^T) with ``rank`` rows in use, and the rank;
    rank -1 (and empty factors) when the ACA gave up: the block is to be stored dense.
    The build driver (hmatrix/storage.py) calls :func:`_aca_compressed`, this function
    with the steps given as first-class functions; so does this function, compiled once
    per data type (cached on disk, :func:`_for_data`).
    """
    compiled = _for_data(_aca_compressed.py_func, data, 3)
    with single_threaded_blas():  # as in the build (see recompress)
        return compiled(kernel, data, _index(row_elements), _index(col_elements), int(row_dof), int(col_dof),
                        float(eps), *aca_steps())


@njit(nogil=True)
def _aca_compressed(kernel, data, row_elements, col_elements, row_dof, col_dof, eps, start, advance, recompress):
    """:func:`aca_compressed` with the ACA steps (:func:`aca_start`, :func:`aca_advance`)
    and the recompression (:func:`recompress_state`) as arguments (see :func:`_aca_loop`)."""
    ut, vt, gram, ints = _aca_run(kernel, data, row_elements, col_elements, row_dof, col_dof,
                                  RECOMPRESSED_ACA_FACTOR * eps, start, advance)
    if aca_gave_up(ints):
        return np.zeros((0, ut.shape[1])), np.zeros((0, vt.shape[1])), -1
    return recompress(ut, vt, gram, ints, eps)


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


@njit(cache=True, nogil=True)
def recompress_state(ut, vt, gram, ints, eps):
    """The recompression of a finished ACA state, with the Gram matrix of U that the ACA
    kept (:func:`recompress_gram`): (U'^T, V'^T, rank')."""
    return recompress_gram(ut, vt, gram, ints[_RANK], eps)


# -- entry points for Python callers (tests, explicit blocks) ------------------------------
#: The ACA steps the compiled drivers take as first-class functions (see aca._aca_loop), and
#: their types.
ACA_STEPS = (aca_start, aca_advance, recompress_state)
ACA_STEP_TYPES = (types.FunctionType(ACA_START_SIGNATURE), types.FunctionType(ACA_ADVANCE_SIGNATURE),
                  types.FunctionType(RECOMPRESS_STATE_SIGNATURE))


def aca_steps():
    """:data:`ACA_STEPS`, each compiled for its signature (:data:`ACA_STEP_TYPES`) on the
    first call (from the on-disk cache when it holds them): pass these, not the bare
    dispatchers, to the compiled drivers, and call this before calling a step from
    Python, so that the one compiled version has the declared signature."""
    for step, kind in zip(ACA_STEPS, ACA_STEP_TYPES):
        step.get_compile_result(kind.signature)  # a dictionary look-up once compiled
    return ACA_STEPS


def _index(elements):
    return np.ascontiguousarray(elements, dtype=np.int64)


def _for_data(function, data, n_steps):
    """``function`` (njit source taking ``(kernel, data, rows, cols, row_dof, col_dof, eps,
    *steps)``, the steps being the first ``n_steps`` of :data:`ACA_STEPS`) compiled for
    this data type by :func:`hmatddm.hmatrix.first_class.compiled_for_data`, like the build
    driver: cached on disk, ~3 s of cold compile per data type, instead of ~10 s per kernel
    in every process when the kernel dispatcher is an argument."""
    return compiled_for_data(function, data, (INDEX, INDEX, types.int64, types.int64, types.float64)
                             + ACA_STEP_TYPES[:n_steps])

