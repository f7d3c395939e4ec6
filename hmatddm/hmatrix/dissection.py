"""Nested dissection of a block sparsity pattern along the cluster tree, so that the
triangular sweeps of a block ILU run on several threads.

A block ILU(0) sweep is sequential in its ordering: row ``i`` needs every earlier row it
is coupled to. Ordered by dissection, most rows are not coupled to most others: the
top ``depth`` levels of the cluster tree cut the elements into ``2**depth`` domains;
at each cut, the elements of the first half that are coupled (in the pattern) to an
element of the second half form the cut's *separator*. The ordering is: the domains'
remaining elements, domain by domain, then the separators, deepest cuts first, the
root's last. Then

* a domain's rows are coupled only to its own rows and to the separators of the cuts
  above it;
* a separator's rows only to rows of its own subtree (earlier) and to the separators
  above it (later);

so the rows of one *stage* (stage 0: all domains; stage ``k``: the separators of the
cuts ``k`` levels above the domains) are independent of each other, and a sweep runs
stage by stage, the ranges of a stage in parallel, each range in order. Every row's
arithmetic is the one a sequential sweep in the same ordering does, so the result is
the same bit for bit on any number of threads. The ordering depends on the pattern
and the tree only, never on the thread count.

The separators of a surface mesh are thin (one near-field radius wide, on one side of
each cut): at 10 000 planar elements and depth 2, 6% of the rows (benchmarks/RESULTS.md,
issue 40).
"""
import math

import numpy as np

#: Below this many elements the ILU keeps the original element order (no dissection):
#: a sweep costs under a millisecond there, less than two parallel launches per stage.
DISSECTION_MIN_ELEMENTS = 5000
#: Elements per domain the depth aims at, and the deepest dissection (32 domains).
DOMAIN_ELEMENTS = 2500
MAX_DEPTH = 5


def dissection_depth(n_elements):
    """The default depth for ``n_elements``: 0 below ``DISSECTION_MIN_ELEMENTS``, else
    ``log2(n_elements / DOMAIN_ELEMENTS)`` rounded down, in [1, MAX_DEPTH]."""
    if n_elements < DISSECTION_MIN_ELEMENTS:
        return 0
    return int(min(MAX_DEPTH, max(1, math.floor(math.log2(n_elements / DOMAIN_ELEMENTS)))))


class Dissection:
    """A nested-dissection ordering of ``n`` elements.

    Attributes
    ----------
    order : (n,) int64
        ``order[k]`` is the element at position ``k`` of the dissected ordering.
    stage_ptr : (n_stages + 1,) int64
        The ranges of stage ``s`` are ``stage_ptr[s] <= r < stage_ptr[s + 1]``.
    range_start, range_stop : (n_ranges,) int64
        Range ``r`` holds the positions ``range_start[r] <= k < range_stop[r]``.
    separator_rows : int
        Positions in separators (the rows a sweep cannot spread over the domains).
    """

    def __init__(self, order, stage_ptr, range_start, range_stop, separator_rows):
        self.order = order
        self.stage_ptr = stage_ptr
        self.range_start = range_start
        self.range_stop = range_stop
        self.separator_rows = separator_rows

    @property
    def n_stages(self):
        return self.stage_ptr.shape[0] - 1

    @property
    def position(self):
        """``position[e]``: where element ``e`` stands in the dissected ordering."""
        position = np.empty_like(self.order)
        position[self.order] = np.arange(self.order.shape[0], dtype=np.int64)
        return position


def nested_dissection(tree, indptr, indices, depth):
    """The :class:`Dissection` of the block pattern ``indptr``, ``indices`` (CSR of
    element couplings, original element indices, structurally symmetric) along the
    cluster tree ``tree`` (a :class:`~hmatddm.hmatrix.cluster_tree.ClusterTree`), cut at
    its top ``depth`` levels (fewer where the tree is shallower)."""
    n = tree.n_elements
    if not 0 <= depth <= MAX_DEPTH:
        raise ValueError(f"depth must be in [0, {MAX_DEPTH}], got {depth}")
    tree_position = tree.inverse_permutation()
    counts = np.diff(indptr)
    block_row = np.repeat(np.arange(n, dtype=np.int64), counts)
    row_position = tree_position[block_row]
    col_position = tree_position[np.asarray(indices, dtype=np.int64)]
    by_row = np.argsort(row_position, kind="stable")  # a cluster's blocks: one slice of these
    row_position, col_position = row_position[by_row], col_position[by_row]
    in_separator = np.zeros(n, dtype=bool)  # by tree position
    # cuts[k]: (cluster, separator positions) of the cuts at depth k
    cuts = [[] for _ in range(depth)]
    domains = []

    def visit(cluster, level):
        first, second = tree.left[cluster], tree.right[cluster]
        if level == depth or first < 0:
            domains.append(cluster)
            return
        # the first half's elements coupled to the second half, neither in a separator yet
        a0, a1 = tree.start[first], tree.stop[first]
        b0, b1 = tree.start[second], tree.stop[second]
        blocks = slice(*np.searchsorted(row_position, [a0, a1]))  # the rows of the first half
        rows, cols = row_position[blocks], col_position[blocks]
        across = (cols >= b0) & (cols < b1) & ~in_separator[rows] & ~in_separator[cols]
        separator = np.unique(rows[across])
        in_separator[separator] = True
        cuts[level].append(separator)
        visit(first, level + 1)
        visit(second, level + 1)

    visit(0, 0)
    pieces = []
    for cluster in domains:  # stage 0, in tree order
        positions = np.arange(tree.start[cluster], tree.stop[cluster], dtype=np.int64)
        pieces.append(positions[~in_separator[positions]])
    stage_sizes = [len(domains)]
    for level in range(depth - 1, -1, -1):  # deepest cuts first
        pieces.extend(cuts[level])
        stage_sizes.append(len(cuts[level]))
    stage_sizes = [size for size in stage_sizes if size > 0]
    lengths = np.array([piece.shape[0] for piece in pieces], dtype=np.int64)
    range_stop = np.cumsum(lengths)
    range_start = range_stop - lengths
    order = tree.permutation[np.concatenate(pieces)] if pieces else np.empty(0, dtype=np.int64)
    stage_ptr = np.concatenate([[0], np.cumsum(stage_sizes)]).astype(np.int64)
    if order.shape[0] != n:
        raise AssertionError("nested dissection lost or repeated elements")
    return Dissection(np.ascontiguousarray(order, dtype=np.int64), stage_ptr, range_start.astype(np.int64),
                      range_stop.astype(np.int64), int(in_separator.sum()))


def permuted_pattern(indptr, indices, data, order):
    """The block CSR ``(indptr, indices, data)`` with rows and columns renumbered so that
    element ``order[k]`` becomes ``k``; columns sorted within each row."""
    n = indptr.shape[0] - 1
    position = np.empty(n, dtype=np.int64)
    position[order] = np.arange(n, dtype=np.int64)
    counts = np.diff(indptr)
    rows = position[np.repeat(np.arange(n, dtype=np.int64), counts)]
    cols = position[np.asarray(indices, dtype=np.int64)]
    sort = np.lexsort((cols, rows))
    new_indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows, minlength=n), out=new_indptr[1:])
    return new_indptr, np.ascontiguousarray(cols[sort]), np.ascontiguousarray(data[sort])
