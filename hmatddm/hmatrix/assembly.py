"""Parallel assembly of the flat block storage of an H-matrix (:mod:`.storage`, layout
in its docstring): the compiled build driver (kernel fill of the inadmissible blocks,
whole-element ACA plus recompression of the admissible ones, :mod:`.aca`), its batches
on a pool of threads, and the offsets and segment lists of the stored blocks
(:func:`assemble`).
"""

import time
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
from numba import njit, types

from .aca import ACA_STEP_TYPES, _aca_compressed, aca_steps
from .factor_precision import FIXED_POINT_SHARE, split_factors
from .storage import KIND_DENSE, KIND_LOWRANK, KIND_ZERO, BlockStorage
from ..compiled import INDEX, compiled_for_data


def _build_blocks(kernel, data, row_permutation, col_permutation, row_dof, col_dof, eps, row_start, row_stop,
                  col_start, col_stop, admissible, dense_offset, dense_values, start, advance, recompress):
    """Assemble a batch of blocks (tree-position element ranges) sequentially.

    Compiled per kernel data type by :func:`build_driver` (the kernel and the ACA steps
    ``start``, ``advance``, ``recompress`` = aca_loop.aca_start, aca_loop.aca_advance,
    aca.recompress_state arrive as first-class functions, so the compiled driver is
    small and cached on disk).

    Inadmissible blocks are filled by the kernel straight into
    ``dense_values[dense_offset[b]:]`` (the final array). Admissible blocks get
    :func:`~hmatddm.hmatrix.aca.aca_compressed` (ACA plus recompression, the function
    the ACA tests call, here with its steps as arguments); their factors (or, when the rank does not pay or the ACA gave
    up on the block, rank -1, their exact dense values) are appended to batch-local
    buffers returned at the end.
    Returns (rank per block, stored-dense flag per block, U values, V values, dense
    values of the far blocks stored dense), factors in batch order.
    """
    count = row_start.shape[0]
    ranks = np.zeros(count, dtype=np.int64)
    stored_dense = np.zeros(count, dtype=np.bool_)
    u_buffer = np.empty(1024)
    v_buffer = np.empty(1024)
    far_dense = np.empty(0)
    u_used = 0
    v_used = 0
    far_used = 0
    for b in range(count):
        rows = row_permutation[row_start[b]:row_stop[b]]
        cols = col_permutation[col_start[b]:col_stop[b]]
        m = row_dof * rows.shape[0]
        n = col_dof * cols.shape[0]
        if not admissible[b]:
            target = dense_values[dense_offset[b]:dense_offset[b] + m * n].reshape((m, n))
            kernel(data, rows, cols, target)
            continue
        ut, vt, rank = _aca_compressed(kernel, data, rows, cols, row_dof, col_dof, eps, start, advance, recompress)
        ranks[b] = rank if rank >= 0 else min(m, n)
        if rank < 0 or rank * (m + n) >= m * n:
            stored_dense[b] = True
            far_dense = _reserve(far_dense, far_used, m * n)
            target = far_dense[far_used:far_used + m * n].reshape((m, n))
            kernel(data, rows, cols, target)
            far_used += m * n
        elif rank > 0:
            u_buffer = _reserve(u_buffer, u_used, m * rank)
            v_buffer = _reserve(v_buffer, v_used, n * rank)
            _append(u_buffer, u_used, ut)
            _append(v_buffer, v_used, vt)
            u_used += m * rank
            v_used += n * rank
    return ranks, stored_dense, _head(u_buffer, u_used), _head(v_buffer, v_used), _head(far_dense, far_used)


def build_driver(data):
    """The compiled :func:`_build_blocks` for kernel data of this type (cached on disk).

    The kernel argument is typed as a first-class function (:mod:`hmatddm.compiled`) rather
    than as its dispatcher, so numba caches the compiled driver: its compile is paid once
    per data type, not once per process. The ACA steps and the recompression are
    first-class function arguments too (:func:`.aca.aca_steps`; see aca_loop._aca_loop): called
    through pointers, their code is compiled once for all types instead of being linked
    into (and re-optimised with) every driver, which cuts the per-type compile from ~10 s
    to ~3 s of CPU. Call it with the kernel dispatcher as first argument and
    ``*aca_steps()`` last; numba compiles the kernel for its signature.
    """
    index = INDEX
    outputs = types.Tuple((index, types.boolean[::1], types.float64[::1], types.float64[::1], types.float64[::1]))
    return compiled_for_data(_build_blocks, data, (index, index, types.int64, types.int64, types.float64, index,
                                                   index, index, index, types.boolean[::1], index,
                                                   types.float64[::1]) + ACA_STEP_TYPES, outputs)


# Element-wise copies below avoid numba's slice assignment, whose shape-mismatch error
# message pulls string formatting into (and slows down) every kernel-specific compile.
@njit(cache=True, nogil=True)
def _reserve(buffer, used, extra):
    """``buffer`` or a larger copy with room for ``used + extra`` values."""
    if used + extra <= buffer.shape[0]:
        return buffer
    grown = np.empty(max(2 * buffer.shape[0], used + extra))
    for i in range(used):
        grown[i] = buffer[i]
    return grown


@njit(cache=True, nogil=True)
def _append(buffer, used, factor):
    """buffer[used:used + factor.size] = factor (row-major)."""
    rows, columns = factor.shape
    for k in range(rows):
        for i in range(columns):
            buffer[used + k * columns + i] = factor[k, i]


@njit(cache=True, nogil=True)
def _head(buffer, used):
    out = np.empty(used)
    for i in range(used):
        out[i] = buffer[i]
    return out


@njit(cache=True, nogil=True)
def _round_into(source, source_offset, target, target_offset):
    """target[target_offset[b]:+size_b] = source[source_offset[b]:source_offset[b + 1]]
    (cast to the target's dtype) for every block b of a batch."""
    for b in range(target_offset.shape[0]):
        start = target_offset[b]
        for i in range(source_offset[b + 1] - source_offset[b]):
            target[start + i] = source[source_offset[b] + i]


def _batches(cost, n_threads, per_thread=16):
    """Split blocks into batches of similar total cost, most expensive first.

    Returns a list of index arrays; with a dynamic thread pool this is longest-
    processing-time-first scheduling.
    """
    order = np.argsort(-cost, kind="stable")
    if order.size == 0:
        return []
    cumulative = np.cumsum(cost[order].astype(np.float64))
    target = max(cumulative[-1] / max(1, n_threads * per_thread), 1.0)
    label = np.minimum((cumulative - cost[order]) // target, order.size).astype(np.int64)
    cuts = np.flatnonzero(np.diff(label)) + 1
    return np.split(order, cuts)


def _run_parallel(function, batches, n_threads):
    """Yield ``function(batch)`` for each batch, in order, computed on a pool of threads
    (the numba drivers release the GIL).

    BLAS/LAPACK threading is limited to one thread meanwhile (the factorisations are
    small; nested threading would only oversubscribe the cores).
    """
    from ._threads import single_threaded_blas

    with single_threaded_blas():
        if n_threads <= 1 or len(batches) <= 1:
            for batch in batches:
                yield function(batch)
            return
        with ThreadPoolExecutor(max_workers=n_threads) as pool:
            yield from pool.map(function, batches)


class _GrowingArray:
    """A 1-D array appended to in place (values cast to its dtype).

    Grows by reallocation (``ndarray.resize``), which for large arrays remaps pages
    instead of copying, so the peak memory stays close to the final size.
    """

    def __init__(self, dtype=np.float64):
        self.values = np.empty(1 << 16, dtype=dtype)
        self.size = 0

    def append(self, part):
        needed = self.size + part.size
        if needed > self.values.size:
            self.values.resize(max(needed, int(1.25 * self.values.size)), refcheck=False)
        self.values[self.size:needed] = part
        self.size = needed

    def finish(self):
        self.values.resize(self.size, refcheck=False)
        return self.values


def assemble(generator, tree, blocks, eps, n_threads=None, factor_dtype=np.float64, col_tree=None,
             near_dtype=np.float64, fixed_point=False):
    """Compress and store all blocks of ``blocks`` (a BlockTree over ``tree`` x
    ``col_tree``; default ``tree`` x ``tree``).

    Far blocks: whole-element ACA + recompression, in batches on ``n_threads``
    threads (default: numba's thread count); factors stored as ``factor_dtype``
    (float64 or float32); with ``fixed_point`` the trailing columns of each block go to
    16-bit fixed point within FIXED_POINT_SHARE * eps of the block
    (:mod:`.factor_precision`). Dense blocks are stored as ``near_dtype`` (float64, or
    float32: filled in float64 per batch, then rounded into the store). Near blocks: exact kernel fill straight into the final
    (float64) dense array. Cost: the near-field kernel entries plus, per far block,
    O((m + n) k) kernel entries and O((m + n) k^2) flops.
    """
    d, dc = generator.dof, generator.column_dof
    col_tree = tree if col_tree is None else col_tree
    n_threads = numba.get_num_threads() if n_threads is None else int(n_threads)
    # the kernel's element indices (the generator's offsets); the stores are laid out by tree order
    permutation, col_permutation = generator.kernel_rows(tree.permutation), generator.kernel_cols(col_tree.permutation)
    kernel, data = generator.kernel, generator.data

    far_rows_start = tree.start[blocks.admissible_rows]
    far_rows_stop = tree.stop[blocks.admissible_rows]
    far_cols_start = col_tree.start[blocks.admissible_cols]
    far_cols_stop = col_tree.stop[blocks.admissible_cols]
    n_far = far_rows_start.size
    empty = np.empty(0)
    no_offsets = np.zeros(n_far, dtype=np.int64)
    driver = build_driver(data)

    share = FIXED_POINT_SHARE if fixed_point else 0.0

    def far_batch(ids):
        ranks, flags, ut, vt, far_dense = driver(
            kernel, data, permutation, col_permutation, d, dc, float(eps), far_rows_start[ids], far_rows_stop[ids],
            far_cols_start[ids], far_cols_stop[ids], np.ones(ids.size, dtype=np.bool_), no_offsets[ids], empty,
            *aca_steps())
        kept = (~flags) & (ranks > 0)
        rows = d * (far_rows_stop[ids][kept] - far_rows_start[ids][kept])
        cols = dc * (far_cols_stop[ids][kept] - far_cols_start[ids][kept])
        return (ranks, flags, far_dense) + split_factors(ranks[kept], rows, cols, ut, vt, float(eps), share)

    started = time.perf_counter()
    far_cost = (far_rows_stop - far_rows_start + far_cols_stop - far_cols_start).astype(np.float64)
    batches = _batches(far_cost, n_threads)
    u_values, v_values = _GrowingArray(factor_dtype), _GrowingArray(factor_dtype)
    u_fixed, v_fixed = _GrowingArray(np.int16), _GrowingArray(np.int16)
    u_scale, v_scale = _GrowingArray(), _GrowingArray()
    far_dense_values = _GrowingArray()
    rank_parts, flag_parts, head_parts = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=bool)], [
        np.zeros(0, dtype=np.int64)]
    for ranks_b, flags_b, dense_b, head_b, u_b, v_b, u_fixed_b, v_fixed_b, u_scale_b, v_scale_b in _run_parallel(
            far_batch, batches, n_threads):
        rank_parts.append(ranks_b)
        flag_parts.append(flags_b)
        head_parts.append(head_b)
        for store, part in ((u_values, u_b), (v_values, v_b), (u_fixed, u_fixed_b), (v_fixed, v_fixed_b),
                            (u_scale, u_scale_b), (v_scale, v_scale_b), (far_dense_values, dense_b)):
            store.append(part)
        del u_b, v_b, u_fixed_b, v_fixed_b, dense_b
    u_values, v_values = u_values.finish(), v_values.finish()
    u_fixed, v_fixed = u_fixed.finish(), v_fixed.finish()
    u_scale, v_scale = u_scale.finish(), v_scale.finish()
    lowrank_head = np.concatenate(head_parts)
    order = np.concatenate([np.zeros(0, dtype=np.int64)] + batches)
    ranks = np.concatenate(rank_parts)
    dense_flag = np.concatenate(flag_parts)
    far_seconds = time.perf_counter() - started

    admissible_kind = np.full(n_far, KIND_ZERO, dtype=np.int64)
    admissible_index = np.full(n_far, -1, dtype=np.int64)
    admissible_rank = np.zeros(n_far, dtype=np.int64)
    admissible_rank[order] = ranks

    lowrank = order[(~dense_flag) & (ranks > 0)]
    lowrank_rank = admissible_rank[lowrank]
    admissible_kind[lowrank] = KIND_LOWRANK
    admissible_index[lowrank] = np.arange(lowrank.size)
    far_dense = order[dense_flag]
    admissible_kind[far_dense] = KIND_DENSE
    admissible_index[far_dense] = np.arange(far_dense.size)

    # Dense storage: far blocks stored dense first, then the near field.
    near_rows_start = tree.start[blocks.near_rows]
    near_rows_stop = tree.stop[blocks.near_rows]
    near_cols_start = col_tree.start[blocks.near_cols]
    near_cols_stop = col_tree.stop[blocks.near_cols]
    dense_row_start = np.concatenate((far_rows_start[far_dense], near_rows_start))
    dense_row_stop = np.concatenate((far_rows_stop[far_dense], near_rows_stop))
    dense_col_start = np.concatenate((far_cols_start[far_dense], near_cols_start))
    dense_col_stop = np.concatenate((far_cols_stop[far_dense], near_cols_stop))
    dense_size = d * dc * (dense_row_stop - dense_row_start) * (dense_col_stop - dense_col_start)
    dense_offset = np.concatenate(([0], np.cumsum(dense_size))).astype(np.int64)
    dense_values = np.empty(dense_offset[-1], dtype=near_dtype)
    far_dense_values = far_dense_values.finish()
    assert far_dense_values.size == int(dense_size[: far_dense.size].sum())
    dense_values[: far_dense_values.size] = far_dense_values
    del far_dense_values

    near_offset = dense_offset[far_dense.size:-1]

    near_size = dense_size[far_dense.size:]

    def near_batch(ids):
        if dense_values.dtype == np.float64:
            return driver(kernel, data, permutation, col_permutation, d, dc, float(eps), near_rows_start[ids],
                          near_rows_stop[ids], near_cols_start[ids], near_cols_stop[ids],
                          np.zeros(ids.size, dtype=np.bool_), near_offset[ids], dense_values, *aca_steps())
        local = np.concatenate(([0], np.cumsum(near_size[ids]))).astype(np.int64)
        buffer = np.empty(local[-1])  # the kernel fills float64; the store holds the rounded values
        driver(kernel, data, permutation, col_permutation, d, dc, float(eps), near_rows_start[ids],
               near_rows_stop[ids], near_cols_start[ids], near_cols_stop[ids], np.zeros(ids.size, dtype=np.bool_),
               local[:-1], buffer, *aca_steps())
        _round_into(buffer, local, dense_values, near_offset[ids])
        return None

    started = time.perf_counter()
    near_cost = near_size.astype(np.float64)
    for _ in _run_parallel(near_batch, _batches(near_cost, n_threads), n_threads):
        pass
    near_seconds = time.perf_counter() - started

    rows_lr = far_rows_stop[lowrank] - far_rows_start[lowrank]
    cols_lr = far_cols_stop[lowrank] - far_cols_start[lowrank]
    tail = lowrank_rank - lowrank_head
    u_offset = np.concatenate(([0], np.cumsum(d * rows_lr * lowrank_head))).astype(np.int64)
    v_offset = np.concatenate(([0], np.cumsum(dc * cols_lr * lowrank_head))).astype(np.int64)
    u_fixed_offset = np.concatenate(([0], np.cumsum(d * rows_lr * tail))).astype(np.int64)
    v_fixed_offset = np.concatenate(([0], np.cumsum(dc * cols_lr * tail))).astype(np.int64)
    rank_offset = np.concatenate(([0], np.cumsum(lowrank_rank))).astype(np.int64)
    assert u_offset[-1] == u_values.size and v_offset[-1] == v_values.size
    assert u_fixed_offset[-1] == u_fixed.size and v_fixed_offset[-1] == v_fixed.size
    assert rank_offset[-1] == u_scale.size == v_scale.size

    leaves = tree.leaves()
    segment_start = np.concatenate((tree.start[leaves], [tree.n_elements])).astype(np.int64)
    dense_ptr, dense_ids = _segment_lists(segment_start, dense_row_start, dense_row_stop)
    lowrank_row_start = far_rows_start[lowrank]
    lowrank_row_stop = far_rows_stop[lowrank]
    lowrank_ptr, lowrank_ids = _segment_lists(segment_start, lowrank_row_start, lowrank_row_stop)

    dense_is_near = np.zeros(dense_row_start.size, dtype=bool)
    dense_is_near[far_dense.size:] = True
    return BlockStorage(
        dof=d,
        n_elements=tree.n_elements,
        col_dof=dc,
        n_col_elements=col_tree.n_elements,
        dense_row_start=dense_row_start,
        dense_row_stop=dense_row_stop,
        dense_col_start=dense_col_start,
        dense_col_stop=dense_col_stop,
        dense_offset=dense_offset,
        dense_values=dense_values,
        dense_is_near=dense_is_near,
        lowrank_row_start=lowrank_row_start,
        lowrank_row_stop=lowrank_row_stop,
        lowrank_col_start=far_cols_start[lowrank],
        lowrank_col_stop=far_cols_stop[lowrank],
        lowrank_rank=lowrank_rank,
        u_offset=u_offset,
        v_offset=v_offset,
        rank_offset=rank_offset,
        u_values=u_values,
        v_values=v_values,
        lowrank_head=lowrank_head,
        u_fixed_offset=u_fixed_offset,
        v_fixed_offset=v_fixed_offset,
        u_fixed=u_fixed,
        v_fixed=v_fixed,
        u_scale=u_scale,
        v_scale=v_scale,
        segment_start=segment_start,
        segment_dense_ptr=dense_ptr,
        segment_dense_ids=dense_ids,
        segment_lowrank_ptr=lowrank_ptr,
        segment_lowrank_ids=lowrank_ids,
        admissible_kind=admissible_kind,
        admissible_index=admissible_index,
        admissible_rank=admissible_rank,
        far_seconds=far_seconds,
        near_seconds=near_seconds,
    )


def _segment_lists(segment_start, block_row_start, block_row_stop):
    """CSR lists: for each segment (leaf row range), the blocks whose rows cover it.

    Block rows are cluster ranges, hence unions of consecutive leaves.
    """
    n_segments = segment_start.size - 1
    first = np.searchsorted(segment_start, block_row_start, side="left")
    last = np.searchsorted(segment_start, block_row_stop, side="left")
    counts = last - first
    block_ids = np.repeat(np.arange(block_row_start.size, dtype=np.int64), counts)
    # segment of each (block, segment) pair: first[b] + 0, 1, ..., counts[b]-1
    within = np.arange(block_ids.size, dtype=np.int64) - np.repeat(np.cumsum(counts) - counts, counts)
    segments = np.repeat(first, counts) + within
    order = np.argsort(segments, kind="stable")
    ptr = np.concatenate(([0], np.cumsum(np.bincount(segments, minlength=n_segments)))).astype(np.int64)
    return ptr, block_ids[order]
