"""Block cluster tree: splits the matrix into admissible (far) and near blocks.

A block (row cluster tau, column cluster sigma) is admissible when

    min(diam tau, diam sigma) <= eta * dist(tau, sigma)

on the axis-aligned bounding boxes (dist = 0 when the boxes touch or overlap, so
such blocks are never admissible); with ``boxes="oriented"`` also on the oriented
(principal-axis) boxes of the clusters: dist is then the larger of the axis-aligned
box distance and the largest gap between the two oriented boxes along one of their
six face normals (both are lower bounds of the true distance; separating-axis test),
diam the smaller of the two box diagonals (both upper bounds of the true diameter).
Tall thin fractures at random strikes have axis-aligned boxes as wide as they are
long, which overlap where the fractures are metres apart. Inadmissible blocks are split into the children
pairs until both clusters are leaves; those leaf pairs form the near field.

A square operator has one tree for rows and columns and both sides are split at once
(blocks stay square, the diagonal blocks hold the self terms). A rectangular matrix
has a row tree and a column tree of different points (targets and sources) whose
clusters may differ in size by orders of magnitude: there only the cluster with the
larger diameter is split (the other when it is a leaf), so that every block pairs
clusters of similar size.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class BlockTree:
    """Leaves of the block cluster tree as flat (row cluster, column cluster) lists.

    ``admissible_rows[b], admissible_cols[b]`` is the b-th far block;
    ``near_rows[b], near_cols[b]`` the b-th near (dense) leaf block (row clusters of
    the row tree, column clusters of the column tree). Together they cover every
    (row element, column element) pair exactly once.
    """

    admissible_rows: np.ndarray
    admissible_cols: np.ndarray
    near_rows: np.ndarray
    near_cols: np.ndarray
    eta: float


def box_distance(tree, rows, cols, col_tree=None):
    """Euclidean distance between the bounding boxes of clusters rows[k] (of ``tree``)
    and cols[k] (of ``col_tree``, default ``tree``)."""
    col_tree = tree if col_tree is None else col_tree
    gap = np.maximum(
        0.0,
        np.maximum(col_tree.bbox_min[cols] - tree.bbox_max[rows], tree.bbox_min[rows] - col_tree.bbox_max[cols]),
    )
    return np.sqrt(np.einsum("ij,ij->i", gap, gap))


def oriented_gap(tree, rows, cols, col_tree=None):
    """Largest gap between the oriented boxes of clusters rows[k] and cols[k] along one
    of their face normals (0 when they overlap on every such axis): a lower bound of
    the distance between the clusters."""
    col_tree = tree if col_tree is None else col_tree
    a_axes, b_axes = tree.box_axes[rows], col_tree.box_axes[cols]
    a_half, b_half = tree.box_half[rows], col_tree.box_half[cols]
    t = col_tree.box_center[cols] - tree.box_center[rows]
    cosines = np.abs(np.einsum("kij,klj->kil", a_axes, b_axes))  # |a_i . b_l|
    gap_a = np.abs(np.einsum("kij,kj->ki", a_axes, t)) - a_half - np.einsum("kil,kl->ki", cosines, b_half)
    gap_b = np.abs(np.einsum("klj,kj->kl", b_axes, t)) - b_half - np.einsum("kil,ki->kl", cosines, a_half)
    return np.maximum(0.0, np.maximum(gap_a.max(axis=1), gap_b.max(axis=1)))


def is_admissible(tree, rows, cols, eta, col_tree=None, boxes="axis"):
    """Admissibility ``min(diam) <= eta * dist`` of cluster pairs (vectorised), on
    axis-aligned boxes or (``boxes="oriented"``) also on oriented ones."""
    col_tree = tree if col_tree is None else col_tree
    distance = box_distance(tree, rows, cols, col_tree)
    row_diameter, col_diameter = tree.diameter[rows], col_tree.diameter[cols]
    if boxes == "oriented":
        distance = np.maximum(distance, oriented_gap(tree, rows, cols, col_tree))
        row_diameter = np.minimum(row_diameter, 2.0 * np.linalg.norm(tree.box_half[rows], axis=1))
        col_diameter = np.minimum(col_diameter, 2.0 * np.linalg.norm(col_tree.box_half[cols], axis=1))
    return (distance > 0.0) & (np.minimum(row_diameter, col_diameter) <= eta * distance)


def block_tree(tree, eta=3.0, col_tree=None, boxes="axis"):
    """Partition ``tree x col_tree`` (default ``tree x tree``) into admissible and near blocks.

    Traverses the block tree level by level with vectorised numpy: an inadmissible
    pair is replaced by the pairs of children (a leaf stands for itself; with a
    separate ``col_tree`` only the larger cluster is split, see the module docstring)
    until both sides are leaves. Cost O(number of visited pairs) = O(N/leaf_size *
    log N) for an eta-admissible partition of a quasi-uniform cloud. ``boxes``:
    "axis" (axis-aligned bounding boxes) or "oriented" (also the principal-axis
    boxes, see the module docstring).
    """
    if not np.isfinite(eta) or eta <= 0:
        raise InputError(f"eta must be > 0, got {eta!r}")
    if boxes not in ("axis", "oriented"):
        raise InputError(f"boxes must be 'axis' or 'oriented', got {boxes!r}")
    if boxes == "oriented" and (tree.box_axes is None or (col_tree is not None and col_tree.box_axes is None)):
        raise InputError("boxes='oriented' needs cluster trees with their oriented boxes (cluster_tree(..., "
                         "oriented=True), the default)")
    split = _split_both if col_tree is None or col_tree is tree else _split_larger
    col_tree = tree if col_tree is None else col_tree
    rows = np.zeros(1, dtype=np.int64)
    cols = np.zeros(1, dtype=np.int64)
    far_rows, far_cols, near_rows, near_cols = [], [], [], []
    while rows.size:
        admissible = is_admissible(tree, rows, cols, eta, col_tree, boxes)
        far_rows.append(rows[admissible])
        far_cols.append(cols[admissible])
        rows, cols = rows[~admissible], cols[~admissible]
        row_leaf = tree.left[rows] < 0
        col_leaf = col_tree.left[cols] < 0
        both = row_leaf & col_leaf
        near_rows.append(rows[both])
        near_cols.append(cols[both])
        rows, cols = split(tree, col_tree, rows[~both], cols[~both], row_leaf[~both], col_leaf[~both])
    return BlockTree(
        admissible_rows=np.concatenate(far_rows),
        admissible_cols=np.concatenate(far_cols),
        near_rows=np.concatenate(near_rows),
        near_cols=np.concatenate(near_cols),
        eta=float(eta),
    )


def _split_both(tree, col_tree, rows, cols, row_leaf, col_leaf):
    """Pairs of children of both sides (a leaf stands in for itself)."""
    row_first = np.where(row_leaf, rows, tree.left[rows])
    row_second = np.where(row_leaf, -1, tree.right[rows])  # -1: no second child
    col_first = np.where(col_leaf, cols, col_tree.left[cols])
    col_second = np.where(col_leaf, -1, col_tree.right[cols])
    new_rows = np.concatenate((row_first, row_first, row_second, row_second))
    new_cols = np.concatenate((col_first, col_second, col_first, col_second))
    keep = (new_rows >= 0) & (new_cols >= 0)
    return new_rows[keep], new_cols[keep]


def _split_larger(tree, col_tree, rows, cols, row_leaf, col_leaf):
    """Children of the cluster with the larger diameter (of the other one when that is a
    leaf), paired with the other cluster."""
    split_row = ~row_leaf & (col_leaf | (tree.diameter[rows] >= col_tree.diameter[cols]))
    return (np.concatenate((np.where(split_row, tree.left[rows], rows), np.where(split_row, tree.right[rows], rows))),
            np.concatenate((np.where(split_row, cols, col_tree.left[cols]),
                            np.where(split_row, cols, col_tree.right[cols]))))
