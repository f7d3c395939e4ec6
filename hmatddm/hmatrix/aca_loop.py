"""The tensor cross loop of the whole-element ACA: a resumable state machine
(:func:`aca_start`, :func:`aca_advance`, cached and kernel-independent) with its
stopping test, convergence check and give-up, and the small loop that drives it with a
kernel (:func:`_aca_run`, :func:`_aca_loop`).

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

The pivots and the cross they add are :mod:`.aca_pivoting`'s; the conventions (block
sizes, transposed factors) are those of :mod:`.aca`.
"""

import numpy as np
from numba import njit, types

from .aca_pivoting import (_add_cross, _best_element, _best_row_element, _coprime_hop, _farthest_unvisited,
                           _grow, _grow_gram, _max_abs, _next_pivot_row, _next_unvisited, _squared_norm,
                           _subtract_cols, _subtract_rows)


# A residual row/column whose largest entry is below NEGLIGIBLE * (largest entry seen
# in the block) is treated as zero.
NEGLIGIBLE = 1e-14
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


# The ACA is a resumable state machine (cached, kernel-independent): each call of
# aca_advance consumes the rows or columns just evaluated and says what to evaluate
# next. Only the small loop _aca_loop calls the kernel (aca.aca_tensor for tests and
# explicit blocks, aca.aca_compressed for the H-matrix build); the build driver
# (assembly.build_driver) receives the kernel and these steps as first-class functions
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


# Signatures of the state-machine steps: compiled for these (:func:`.aca.aca_steps`), the
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
def _pivot_row_or_stop(row, ints, row_visited, col_visited):
    """Request row element ``row`` as the next pivot row (marked visited), or, when
    ``row < 0`` (none found), :func:`_stop`."""
    if row < 0:
        return _stop(ints, row_visited, col_visited)
    row_visited[row] = True
    ints[_ROW] = row
    ints[_PHASE] = _PHASE_PIVOT_ROW
    return REQUEST_ROW, row


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
        request, index = _pivot_row_or_stop(row, ints, row_visited, col_visited)
        return ut, vt, gram, request, index
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
        request, index = _pivot_row_or_stop(row, ints, row_visited, col_visited)
        return ut, vt, gram, request, index
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
    request, index = _pivot_row_or_stop(row, ints, row_visited, col_visited)
    return ut, vt, gram, request, index


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
    (hmatrix/assembly.py, hmatrix/product.py) can pass them as first-class functions:
    called through pointers, their code is compiled once and cached instead of being
    linked and re-optimised into every kernel-specific driver (~10 s of compile per
    kernel data type before, ~3 s now). Python callers (:func:`.aca.aca_tensor`,
    :func:`.aca.aca_compressed`) pass the dispatchers themselves. A call through a pointer
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
