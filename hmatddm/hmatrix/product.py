"""One-shot H-matrix product without storage ("build-free apply"): ``y = A x`` for a
matrix given by its :class:`~hmatddm.hmatrix.BlockGenerator`, when the matrix is applied
once (a stress field from given DDs, :mod:`hmatddm.elasticity.fields`).

The same cluster trees and block tree as :meth:`HMatrix.build <hmatddm.hmatrix.HMatrix.build>`;
each near block is filled by the kernel and multiplied at once; each admissible block
runs the production whole-element ACA (:func:`hmatddm.hmatrix.aca_loop._aca_loop`, the loop the
build calls) to ``eps`` and adds ``U (V^T x)`` to the result. No recompression (it would
only shrink factors that are used once) and nothing is stored, so the cost is the ACA's
kernel entries plus O((m + n) k) flops per far block.
"""
import numba
import numpy as np
from numba import types

from ..errors import InputError
from .aca import ACA_STEP_TYPES, aca_steps
from .aca_loop import _RANK, _aca_loop, aca_gave_up
from .block_tree import block_tree
from .cluster_tree import cluster_tree
from .generator import BlockGenerator
from ..compiled import INDEX, compiled_for_data
from .assembly import _batches, _run_parallel


def _apply_blocks(kernel, data, row_permutation, col_permutation, row_dof, col_dof, eps, row_start, row_stop,
                  col_start, col_stop, admissible, x, n_rows, start, advance):
    """Apply a batch of blocks (tree-position element ranges) to ``x`` (original column
    order); returns the batch's part of ``A x`` (``n_rows`` values, original row order).

    Compiled per kernel data type by :func:`product_driver` (the kernel arrives as a
    first-class function, as in the build driver of hmatrix/assembly.py, so the compiled
    driver is cached on disk; the ACA steps ``start``, ``advance`` = aca_loop.aca_start,
    aca_loop.aca_advance arrive as first-class functions too, see assembly.build_driver).
    Admissible blocks: ``_aca_loop`` at ``eps``, then
    ``y += U (V^T x)``; the others, those the ACA gave up on, and those whose ACA rank does not pay
    (``rank (m + n) >= m n``, which the build stores dense too): kernel fill of the
    block, then ``y += B x``.
    """
    y = np.zeros(n_rows)
    dense = np.empty(0)
    for b in range(row_start.shape[0]):
        rows = row_permutation[row_start[b]:row_stop[b]]
        cols = col_permutation[col_start[b]:col_stop[b]]
        m = row_dof * rows.shape[0]
        n = col_dof * cols.shape[0]
        xb = np.empty(n)
        for c in range(cols.shape[0]):
            for q in range(col_dof):
                xb[col_dof * c + q] = x[col_dof * cols[c] + q]
        if admissible[b]:
            ut, vt, ints = _aca_loop(kernel, data, rows, cols, row_dof, col_dof, eps, start, advance)
        if admissible[b] and not aca_gave_up(ints) and ints[_RANK] * (m + n) < m * n:
            for k in range(ints[_RANK]):
                s = 0.0
                for c in range(n):
                    s += vt[k, c] * xb[c]
                if s != 0.0:
                    for r in range(rows.shape[0]):
                        for p in range(row_dof):
                            y[row_dof * rows[r] + p] += s * ut[k, row_dof * r + p]
            continue
        if dense.shape[0] < m * n:
            dense = np.empty(m * n)
        block = dense[:m * n].reshape((m, n))
        kernel(data, rows, cols, block)
        for r in range(rows.shape[0]):
            for p in range(row_dof):
                s = 0.0
                for c in range(n):
                    s += block[row_dof * r + p, c] * xb[c]
                y[row_dof * rows[r] + p] += s
    return y


_BATCHES = 64  # fixed number of batches of blocks (load balance on up to ~16 threads)


def product_driver(data):
    """The compiled :func:`_apply_blocks` for kernel data of this type (cached on disk;
    the kernel is a first-class function, :mod:`.first_class`)."""
    return compiled_for_data(_apply_blocks, data, (INDEX, INDEX, types.int64, types.int64, types.float64, INDEX,
                                                   INDEX, INDEX, INDEX, types.boolean[::1], types.float64[::1],
                                                   types.int64) + ACA_STEP_TYPES[:2], types.float64[::1])


def build_free_product(generator, x, eps, eta=3.0, leaf_size=64, col_leaf_size=None, n_threads=None,
                       min_aca_elements=1):
    """``A x`` for the matrix of ``generator`` (square or rectangular), evaluated block by
    block over the block tree of :meth:`HMatrix.build <hmatddm.hmatrix.HMatrix.build>`
    (same ``eta``, ``leaf_size``, ``col_leaf_size``) without storing anything.

    Admissible blocks are approximated by the whole-element ACA at ``eps`` (relative
    Frobenius accuracy of each block, no recompression), the others are exact. Blocks
    are split in a fixed number of batches run on ``n_threads`` threads (default numba's);
    the batches' partial results are summed in a fixed order, so the result does not
    depend on the thread count.
    Admissible blocks with fewer than ``min_aca_elements`` row or column elements are
    evaluated exactly (the ACA's rank would not pay on them).
    Returns (y, info) with ``y`` of length ``dof * n_rows`` and ``info`` the numbers of
    ACA and exact blocks (``n_far``, ``n_near``) and of element pairs in each
    (``pairs_compressed``, ``pairs_exact``).
    """
    if not isinstance(generator, BlockGenerator):
        raise InputError(f"generator must be a BlockGenerator, got {type(generator).__name__}")
    from .hmatrix import _check_parameters

    col_leaf_size = leaf_size if col_leaf_size is None else col_leaf_size
    _check_parameters(eps, eta, leaf_size)
    _check_parameters(eps, eta, col_leaf_size)
    if generator.row_offset or generator.col_offset:  # the driver indexes x and y by the kernel's indices
        raise InputError("build_free_product takes a generator without row_offset or col_offset")
    d, dc = generator.dof, generator.column_dof
    tree = cluster_tree(generator.points, generator.radii, int(leaf_size))
    col_tree = tree
    if generator.rectangular:
        col_tree = cluster_tree(generator.col_points, generator.col_radii, int(col_leaf_size))
    n_cols = dc * col_tree.n_elements
    x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1)
    if x.size != n_cols:
        raise InputError(f"x must have {n_cols} values, got {x.size}")
    blocks = block_tree(tree, float(eta), col_tree=col_tree)
    n_far, n_near = blocks.admissible_rows.size, blocks.near_rows.size
    row_start = np.concatenate((tree.start[blocks.admissible_rows], tree.start[blocks.near_rows])).astype(np.int64)
    row_stop = np.concatenate((tree.stop[blocks.admissible_rows], tree.stop[blocks.near_rows])).astype(np.int64)
    col_start = np.concatenate((col_tree.start[blocks.admissible_cols],
                                col_tree.start[blocks.near_cols])).astype(np.int64)
    col_stop = np.concatenate((col_tree.stop[blocks.admissible_cols],
                               col_tree.stop[blocks.near_cols])).astype(np.int64)
    admissible = np.zeros(n_far + n_near, dtype=np.bool_)
    rows_n, cols_n = row_stop - row_start, col_stop - col_start
    admissible[:n_far] = np.minimum(rows_n[:n_far], cols_n[:n_far]) >= int(min_aca_elements)
    # cost: far blocks ~ (m + n) * rank, near blocks m * n kernel entries (a rank ~ 20 guess)
    cost = np.where(admissible, 20.0 * (rows_n + cols_n), rows_n * cols_n.astype(np.float64))
    n_threads = numba.get_num_threads() if n_threads is None else int(n_threads)
    # a split that does not depend on the thread count (and partial results summed in the
    # order of each batch's first block): the same result on any number of threads
    batches = _batches(cost, 1, per_thread=_BATCHES)
    batches = [np.sort(batch) for batch in batches]
    batches.sort(key=lambda batch: int(batch[0]))
    driver = product_driver(generator.data)
    kernel, data = generator.kernel, generator.data
    n_rows = d * tree.n_elements

    def run(ids):
        return driver(kernel, data, tree.permutation, col_tree.permutation, d, dc, float(eps), row_start[ids],
                      row_stop[ids], col_start[ids], col_stop[ids], admissible[ids], x, n_rows, *aca_steps()[:2])

    y = np.zeros(n_rows)
    try:
        for part in _run_parallel(run, batches, n_threads):
            y += part
    except np.linalg.LinAlgError as error:  # the SVD of a pivot refuses NaN/inf
        raise InputError(f"the kernel returned NaN or inf entries (in a far-field block): {error}") from None
    n_aca = int(np.count_nonzero(admissible))
    pairs = rows_n * cols_n
    compressed = int(pairs[admissible].sum())
    return y, {"n_far": n_aca, "n_near": int(n_far + n_near - n_aca), "pairs_compressed": compressed,
               "pairs_exact": int(pairs.sum()) - compressed}


__all__ = ["build_free_product", "product_driver"]
