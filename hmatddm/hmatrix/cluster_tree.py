"""Cluster tree over elements: recursive principal-axis bisection.

Elements (never single unknowns) are clustered, so an element's d unknowns always
stay together. The tree is stored as flat arrays; cluster ``c`` is the contiguous
range ``permutation[start[c]:stop[c]]`` of original element indices.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class ClusterTree:
    """Binary cluster tree in flat-array form (clusters numbered level by level).

    Attributes
    ----------
    permutation : (N,) int64
        ``permutation[k]`` is the original element at tree position k.
    start, stop : (C,) int64
        Cluster c holds tree positions ``start[c] <= k < stop[c]``.
    left, right : (C,) int64
        Children of cluster c, ``-1`` for leaves.
    parent : (C,) int64
        Parent cluster, ``-1`` for the root (cluster 0).
    level : (C,) int64
        Depth (root = 0).
    bbox_min, bbox_max : (C, dim) float64
        Axis-aligned bounding box of the cluster's elements, inflated by their radii.
    leaf_size : int
        Largest number of elements in a leaf.
    box_center, box_axes, box_half : (C, dim), (C, dim, dim), (C, dim) float64
        Oriented bounding box of each cluster: rows of ``box_axes[c]`` are the
        principal axes of its element centres, ``box_half[c]`` the half extents along
        them (inflated by the radii) around ``box_center[c]``. A tilted or vertical
        fracture at any strike has a thin oriented box, where its axis-aligned box is
        as wide as it is long (used by ``block_tree(..., boxes="oriented")``).
    """

    permutation: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    left: np.ndarray
    right: np.ndarray
    parent: np.ndarray
    level: np.ndarray
    bbox_min: np.ndarray
    bbox_max: np.ndarray
    leaf_size: int
    box_center: np.ndarray = None
    box_axes: np.ndarray = None
    box_half: np.ndarray = None

    @property
    def n_clusters(self):
        return self.start.shape[0]

    @property
    def n_elements(self):
        return self.permutation.shape[0]

    @property
    def is_leaf(self):
        """(C,) bool mask of leaf clusters."""
        return self.left < 0

    @property
    def size(self):
        """(C,) number of elements in each cluster."""
        return self.stop - self.start

    @property
    def diameter(self):
        """(C,) diagonal length of each bounding box."""
        return np.linalg.norm(self.bbox_max - self.bbox_min, axis=1)

    def leaves(self):
        """Indices of the leaf clusters sorted by start: they partition [0, N)."""
        leaves = np.flatnonzero(self.is_leaf)
        return leaves[np.argsort(self.start[leaves], kind="stable")]

    def inverse_permutation(self):
        """``inverse[i]`` is the tree position of original element i."""
        inverse = np.empty_like(self.permutation)
        inverse[self.permutation] = np.arange(self.permutation.size, dtype=np.int64)
        return inverse


def _principal_split(points):
    """Order of ``points`` by projection on their principal axis; split at the median."""
    centred = points - points.mean(axis=0)
    covariance = centred.T @ centred
    _, vectors = np.linalg.eigh(covariance)
    projection = centred @ vectors[:, -1]
    half = points.shape[0] // 2
    order = np.argpartition(projection, half)
    return order[:half], order[half:]


def _group_split(points, groups):
    """Split whole groups (e.g. fractures): order the groups by the projection of
    their centroids on the principal axis of the points and cut where the element
    count is closest to half (at least one group on each side). None when all
    points are in one group."""
    labels, inverse, counts = np.unique(groups, return_inverse=True, return_counts=True)
    if labels.size < 2:
        return None
    centred = points - points.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    projection = centred @ vectors[:, -1]
    centroid = np.bincount(inverse, weights=projection, minlength=labels.size) / counts
    order = np.argsort(centroid, kind="stable")
    cumulative = np.cumsum(counts[order])
    cut = int(np.clip(np.argmin(np.abs(cumulative - 0.5 * points.shape[0])) + 1, 1, labels.size - 1))
    left = np.zeros(labels.size, dtype=bool)
    left[order[:cut]] = True
    first = np.flatnonzero(left[inverse])
    second = np.flatnonzero(~left[inverse])
    return first, second


def cluster_tree(points, radii, leaf_size=64, groups=None, oriented=True):
    """Build the cluster tree of element centres ``points`` (N, dim).

    Each cluster with more than ``leaf_size`` elements is bisected at the median of
    the projections of its centres on their principal axis (largest eigenvector of
    the covariance), which follows tilted planar fractures. Balanced by
    construction: depth ceil(log2(N / leaf_size)). Cost O(N log N).

    ``groups`` (N,) int, optional (e.g. the fracture of each element): a cluster that
    holds several groups is split between whole groups (:func:`_group_split`), so
    that every cluster below the group level lies on one fracture, whose blocks have
    the low ranks of a planar crack; the tree is then only roughly balanced.

    ``oriented=False`` leaves out the oriented boxes (``box_center``, ``box_axes``,
    ``box_half`` None: an eigenproblem per cluster, over half the tree's cost), for a
    tree whose axis-aligned boxes are all its user reads (the stress bound of
    :mod:`hmatddm.elasticity.field_bound`, built at every remote-failure check).
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[0] < 1:
        raise InputError(f"points must have shape (N, dim) with N >= 1, got {points.shape}")
    n, dim = points.shape
    radii = np.broadcast_to(np.asarray(radii, dtype=np.float64), (n,))
    if isinstance(leaf_size, bool) or not isinstance(leaf_size, (int, np.integer)) or leaf_size < 1:
        raise InputError(f"leaf_size must be an integer >= 1, got {leaf_size!r}")
    if groups is not None:
        groups = np.asarray(groups)
        if groups.shape != (n,) or not np.issubdtype(groups.dtype, np.integer):
            raise InputError(f"groups must be an integer array of shape ({n},), got {groups.dtype} {groups.shape}")

    permutation = np.arange(n, dtype=np.int64)
    # Clusters are appended breadth-first, so numbering goes level by level.
    start, stop, left, right, parent, level = [0], [n], [], [], [-1], [0]
    current = 0
    while current < len(start):
        lo, hi = start[current], stop[current]
        if hi - lo > leaf_size:
            members = permutation[lo:hi]
            split = None if groups is None else _group_split(points[members], groups[members])
            first, second = _principal_split(points[members]) if split is None else split
            mid = lo + first.size
            permutation[lo:hi] = np.concatenate((members[first], members[second]))
            left.append(len(start))
            right.append(len(start) + 1)
            for a, b in ((lo, mid), (mid, hi)):
                start.append(a)
                stop.append(b)
                parent.append(current)
                level.append(level[current] + 1)
        else:
            left.append(-1)
            right.append(-1)
        current += 1

    start = np.array(start, dtype=np.int64)
    stop = np.array(stop, dtype=np.int64)
    lower = points[permutation] - radii[permutation, None]
    upper = points[permutation] + radii[permutation, None]
    # Boxes of the leaves first, then children -> parents (children have larger numbers).
    n_clusters = start.size
    bbox_min = np.empty((n_clusters, dim))
    bbox_max = np.empty((n_clusters, dim))
    left = np.array(left, dtype=np.int64)
    right = np.array(right, dtype=np.int64)
    for c in range(n_clusters - 1, -1, -1):
        if left[c] < 0:
            bbox_min[c] = lower[start[c]:stop[c]].min(axis=0)
            bbox_max[c] = upper[start[c]:stop[c]].max(axis=0)
        else:
            bbox_min[c] = np.minimum(bbox_min[left[c]], bbox_min[right[c]])
            bbox_max[c] = np.maximum(bbox_max[left[c]], bbox_max[right[c]])
    box_center = box_axes = box_half = None
    if oriented:
        box_center, box_axes, box_half = _oriented_boxes(points[permutation], radii[permutation], start, stop)
    return ClusterTree(
        permutation=permutation,
        start=start,
        stop=stop,
        left=left,
        right=right,
        parent=np.array(parent, dtype=np.int64),
        level=np.array(level, dtype=np.int64),
        bbox_min=bbox_min,
        bbox_max=bbox_max,
        leaf_size=int(leaf_size),
        box_center=box_center,
        box_axes=box_axes,
        box_half=box_half,
    )


def _oriented_boxes(points, radii, start, stop):
    """Oriented bounding box of every cluster (``points``, ``radii`` in tree order):
    principal axes of its centres (eigenvectors of their covariance), extents of the
    projections on them inflated by the radii. O(N log N) over the tree."""
    n_clusters, dim = start.size, points.shape[1]
    center = np.empty((n_clusters, dim))
    axes = np.empty((n_clusters, dim, dim))
    half = np.empty((n_clusters, dim))
    for c in range(n_clusters):
        members = points[start[c]:stop[c]]
        r = radii[start[c]:stop[c]]
        mean = members.mean(axis=0)
        centred = members - mean
        _, vectors = np.linalg.eigh(centred.T @ centred)
        local = centred @ vectors
        low = (local - r[:, None]).min(axis=0)
        high = (local + r[:, None]).max(axis=0)
        axes[c] = vectors.T
        half[c] = 0.5 * (high - low)
        center[c] = mean + vectors @ (0.5 * (high + low))
    return center, axes, half
