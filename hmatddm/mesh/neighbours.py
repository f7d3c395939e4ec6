"""Pairs of points closer than a distance, with numpy alone (a uniform grid of cells).

The scene checks (:mod:`hmatddm.scene.preflight`) use it so that refusing a scene never
waits for scipy.spatial to load; the engine keeps its KD-trees.
"""
import itertools

import numpy as np

_HASH = np.array([73856093, 19349663, 83492791], dtype=np.int64)  # spatial hashing primes


def pairs_within(points, reach):
    """``(sources, receivers)``: every ordered pair ``s != r`` with
    ``|points[r] - points[s]| <= reach[s]`` (``reach``: one distance per point, or a
    scalar), sorted by source then receiver -- what ``cKDTree(points).query_ball_point(
    points, reach)`` finds, without the points themselves.

    Points are binned in cells of the largest reach; each point is compared with the
    points of its own and the neighbouring cells (cells are hashed, so a collision only
    adds candidates, which the distance test removes).
    """
    points = np.asarray(points, dtype=float)
    n, dim = points.shape
    reach = np.broadcast_to(np.asarray(reach, dtype=float), (n,))
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    size = float(np.max(reach))
    if not size > 0.0:
        size = 1.0
    cells = np.floor((points - points.min(axis=0)) / size).astype(np.int64)
    weights = _HASH[:dim]
    keys = (cells * weights).sum(axis=1)
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    sources, receivers = [], []
    for offset in itertools.product((-1, 0, 1), repeat=dim):
        wanted = keys + int(np.dot(offset, weights))
        low = np.searchsorted(sorted_keys, wanted, "left")
        counts = np.searchsorted(sorted_keys, wanted, "right") - low
        total = int(counts.sum())
        if total == 0:
            continue
        first = np.repeat(low - (np.cumsum(counts) - counts), counts)
        sources.append(np.repeat(np.arange(n, dtype=np.int64), counts))
        receivers.append(order[first + np.arange(total)])
    source, receiver = np.concatenate(sources), np.concatenate(receivers)
    keep = (source != receiver) & (np.linalg.norm(points[receiver] - points[source], axis=1) <= reach[source])
    pair = np.unique(source[keep] * n + receiver[keep])  # sorted; hash collisions may repeat a pair
    return pair // n, pair % n
