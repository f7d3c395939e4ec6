"""Connectivity of a natural-fracture network (ref. Sec. 6.2.3, Fig. 6.9): the graph of
fractures joined by intersections, its clusters, and the number of intersections per
metre along a scanline. The intersections themselves are found by
:func:`hmatddm.network.intersections.find_intersections` (its tolerances apply here).
"""
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .._validation import finite_array, finite_scalar
from ..errors import InputError
from .intersections import check_network, find_intersections


@dataclass(frozen=True, eq=False)
class IntersectionGraph:
    """Fractures as nodes, intersecting pairs as edges.

    Attributes
    ----------
    fracture_ids : (F,) the distinct fracture ids of the network (sorted); node ``k``
        is fracture ``fracture_ids[k]``
    pairs : (E, 2) fracture ids ``(f, g)``, ``f < g``, of every intersecting pair of
        distinct fractures (counted once however many segments they consist of)
    points : (E, 2) an intersection point of each pair (the first one found)
    labels : (F,) connected-component (cluster) label of each fracture, 0..C-1, with
        clusters numbered by decreasing size (ties: by smallest fracture id)
    sizes : (C,) number of fractures in each cluster
    """

    fracture_ids: np.ndarray
    pairs: np.ndarray
    points: np.ndarray
    labels: np.ndarray
    sizes: np.ndarray

    @property
    def n_fractures(self):
        return len(self.fracture_ids)

    @property
    def n_intersections(self):
        """Number of intersecting fracture pairs."""
        return len(self.pairs)

    @property
    def n_clusters(self):
        return len(self.sizes)

    @property
    def intersections_per_fracture(self):
        """Mean number of other fractures each fracture meets, ``2 E / F``."""
        return 2.0 * self.n_intersections / max(1, self.n_fractures)

    def clusters(self):
        """Fracture ids of every cluster, largest first."""
        return [self.fracture_ids[self.labels == c] for c in range(self.n_clusters)]

    def cluster_of(self, fracture):
        """Fracture ids of the cluster that holds ``fracture``."""
        k = np.searchsorted(self.fracture_ids, fracture)
        if k >= self.n_fractures or self.fracture_ids[k] != fracture:
            raise InputError(f"fracture must be one of the network's fracture ids, got {fracture!r}")
        return self.fracture_ids[self.labels == self.labels[k]]


def intersection_graph(network, tol=1e-9):
    """Connected clusters of intersecting fractures (an :class:`IntersectionGraph`).

    Segments of the same fracture (``fracture_id``) are one node; X, T, L junctions
    and collinear contacts all connect.
    """
    network = check_network(network)
    fracture_ids = np.unique(network.fracture_id)
    found = find_intersections(network.p0, network.p1, tol)
    f = network.fracture_id[found.i]
    g = network.fracture_id[found.j]
    distinct = f != g
    f, g, points = np.minimum(f, g)[distinct], np.maximum(f, g)[distinct], found.points[distinct]
    pairs, first = np.unique(np.column_stack([f, g]).reshape(-1, 2), axis=0, return_index=True)
    points = points[first].reshape(-1, 2)
    n = len(fracture_ids)
    u, v = np.searchsorted(fracture_ids, pairs[:, 0]), np.searchsorted(fracture_ids, pairs[:, 1])
    adjacency = coo_matrix((np.ones(len(u)), (u, v)), shape=(n, n))
    _, raw = connected_components(adjacency, directed=False)
    raw_sizes = np.bincount(raw)
    first_member = np.full(len(raw_sizes), n)
    np.minimum.at(first_member, raw, np.arange(n))
    rank = np.lexsort((first_member, -raw_sizes))  # by size descending, then first member
    relabel = np.empty_like(rank)
    relabel[rank] = np.arange(len(rank))
    return IntersectionGraph(fracture_ids, pairs.astype(np.int64), points, relabel[raw].astype(np.int64),
                             raw_sizes[rank].astype(np.int64))


def scanline_frequency(network, start, end, tol=1e-9):
    """Fractures crossed per metre of the scan line ``start -> end`` (its ``P10``).

    Counts the distinct fractures (``fracture_id``) that meet the line segment, divided
    by its length, 1/m.
    """
    network = check_network(network)
    start = finite_array("start", start, (2,))
    end = finite_array("end", end, (2,))
    length = float(np.hypot(*(end - start)))
    if length == 0.0:
        raise InputError("end must differ from start (a scan line of zero length)")
    if len(network) == 0:
        return 0.0
    found = find_intersections(np.vstack([network.p0, start]), np.vstack([network.p1, end]), tol)
    scan = len(network)
    on_line = np.concatenate([found.i[found.j == scan], found.j[found.i == scan]])
    return np.unique(network.fracture_id[on_line]).size / length


def intersection_frequency(network, x=None, tol=1e-9):
    """Frequency of intersections along the y axis per length (ref. Fig. 6.9), 1/m.

    The reference counts, per metre, the natural fractures met by a line along the
    y direction (the direction in which its hydraulic fractures grow, ``S_hmax || y``),
    over a domain centred on the origin. Here: :func:`scanline_frequency` of the line
    ``x = x`` from ``y_min`` to ``y_max`` of the network's region (or bounding box);
    ``x`` defaults to the middle of the region, which is the y axis for a region
    centred on the origin as in the reference.
    """
    network = check_network(network)
    if len(network) == 0:
        return 0.0
    x_min, x_max, y_min, y_max = network.bounds
    x = 0.5 * (x_min + x_max) if x is None else finite_scalar("x", x)
    return scanline_frequency(network, (x, y_min), (x, y_max), tol)


__all__ = ["IntersectionGraph", "intersection_graph", "scanline_frequency", "intersection_frequency"]
