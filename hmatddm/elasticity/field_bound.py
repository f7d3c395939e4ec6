"""Upper bound of the stress that the DDs of a mesh induce at points, without summing the
kernels: which points a check can leave out (the remote-failure screen of
:mod:`hmatddm.simulation.natural`, ref. Sec. 5.3).

The stress of a constant DD ``b`` on a planar element in an infinite homogeneous medium
(ref. Eq. 2.59) is the integral over the element of the stress of a point DD (a
dislocation dipole), which decays as ``1/r^3`` in 3D and ``1/r^2`` in 2D plane strain.
Maximised over directions and over the direction of ``b`` (the kernels'
``local_stress`` on a small element seen from afar, tests/elasticity/test_field_bound.py), its
Frobenius norm is at most

* 3D: ``C3 G |b| dA / (4 pi (1 - nu) r^3)``, ``C3`` = 6 sqrt(2) = 8.49 at nu = 0, 8.28 at
  0.25, rising to 9.80 as nu -> -1 (the largest response is on the element's normal);
* 2D: ``C2 G |b| ds / (2 pi (1 - nu) r^2)``, ``C2`` = sqrt(10) for every nu.

So a point at distance at least ``d`` from an element feels at most ``C G |b| A /
(k pi (1 - nu) d^p)`` from it (``A`` area or length, ``p`` = 3 or 2), and summing over the
elements bounds the induced stress (triangle inequality). The bound uses ``C3 = 10`` and
``C2 = 3.2``. Clusters of elements (the cluster tree of :mod:`hmatddm.hmatrix`) far from a
point count together, at the distance to their bounding box (a Barnes-Hut descent: a
cluster is taken whole when that distance exceeds ``SEPARATION`` times its diameter).

Points closer to an element than the averaging distance of the singular-point correction
(``near_fraction`` of its smaller half size, or on it) get an infinite bound: the
corrected value there is not the integral above.
"""
import numpy as np
from numba import njit, prange

from ..kernels.rectangle3d import rectangle_distance

#: ``C3``, ``C2`` above, with a margin over the measured maxima (9.80 and sqrt(10)).
POINT_DD_CONSTANT_3D = 10.0
POINT_DD_CONSTANT_2D = 3.2
#: A cluster of elements counts whole at distances of at least this many diameters (its
#: bound then overestimates each element's term by at most (1 + 1/SEPARATION)^p).
SEPARATION = 3.0
_LEAF_SIZE = 8
_CHUNKS = 64


@njit(cache=True, inline="always")
def _element_distance(point, center, frame, a, b):
    """Distance from ``point`` to the rectangle (3D) or segment (2D, ``b`` unused)."""
    if point.shape[0] == 3:
        return rectangle_distance(point, center, frame, a, b)
    dx = point[0] - center[0]
    dy = point[1] - center[1]
    x = frame[0, 0] * dx + frame[0, 1] * dy
    y = frame[1, 0] * dx + frame[1, 1] * dy
    u = max(abs(x) - a, 0.0)
    return np.sqrt(u * u + y * y)


@njit(cache=True, parallel=True)
def _bound(query_min, query_max, exact, centers, frames, half_a, half_b, radii, weight, near, permutation, start, stop,
           left, right, box_min, box_max, cumulative, power, limit, out):
    """``out[t]``: sum over elements of ``weight / distance^power`` over the query box
    ``t`` (``query_min[t]`` to ``query_max[t]``; a point when ``exact``, and then the
    distance to each element is exact, else to its bounding box), clusters far enough
    counted whole; ``inf`` within ``near`` of an element. The descent of a query stops
    once its sum passes ``limit[t]`` (what is known then: the bound exceeds the limit)."""
    m = query_min.shape[0]
    dim = query_min.shape[1]
    n_chunks = min(_CHUNKS, m)
    separation2 = SEPARATION * SEPARATION
    for chunk in prange(n_chunks):
        stack = np.empty(2 * start.shape[0] + 2, np.int64)
        for t in range(chunk * m // n_chunks, (chunk + 1) * m // n_chunks):
            q_low = query_min[t]
            q_high = query_max[t]
            total = 0.0
            stack[0] = 0
            top = 1
            while top > 0 and total <= limit[t]:
                top -= 1
                c = stack[top]
                gap2 = 0.0
                diameter2 = 0.0
                for k in range(dim):
                    low = box_min[c, k]
                    high = box_max[c, k]
                    gap = max(low - q_high[k], q_low[k] - high, 0.0)
                    gap2 += gap * gap
                    diameter2 += (high - low) * (high - low)
                if gap2 > 0.0 and gap2 >= separation2 * diameter2:
                    total += (cumulative[stop[c]] - cumulative[start[c]]) / gap2 ** (0.5 * power)
                elif left[c] >= 0:
                    stack[top] = left[c]
                    stack[top + 1] = right[c]
                    top += 2
                else:
                    for k in range(start[c], stop[c]):
                        j = permutation[k]
                        if exact:
                            d = _element_distance(q_low, centers[j], frames[j], half_a[j], half_b[j])
                        else:
                            d2 = 0.0
                            for i in range(dim):
                                gap = max(centers[j, i] - radii[j] - q_high[i], q_low[i] - centers[j, i] - radii[j],
                                          0.0)
                                d2 += gap * gap
                            d = np.sqrt(d2)
                        if d <= near[j]:
                            total = np.inf
                            break
                        total += weight[j] / d ** power
            out[t] = total


def stress_bound(mesh, material, dd, points, near_fraction=0.0, limit=None, point_tree=None):
    """(M,) upper bounds of the Frobenius norm of the stress tensor that the global DDs
    ``dd`` (N, d) of the constant elements of ``mesh`` induce at ``points`` (M, d) in
    the homogeneous ``material`` (:class:`hmatddm.Elastic`); ``inf`` at points within
    ``near_fraction`` of an element's smaller half size of it (where
    ``singular_correction="average"`` averages) or on it.

    ``limit`` (M,) or None: a point's sum may stop as soon as it passes its limit (the
    result then only says that the bound exceeds the limit); points whose limit is
    ``-inf`` are not needed (their result is meaningless).
    ``point_tree`` (a :func:`hmatddm.hmatrix.cluster_tree.cluster_tree` of ``points``,
    e.g. kept across calls on the same points) with ``limit``: each leaf's box is bounded
    first, as a whole; where that stays below the smallest limit of its needed points,
    it is their bound, and only the other leaves' points are bounded one by one.
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    m = points.shape[0]
    out = np.empty(m)
    if m == 0:
        return out
    dim = mesh.dim
    if dim == 3:
        half_a, half_b = mesh.half_a, mesh.half_b
        size = 4.0 * half_a * half_b
        constant = POINT_DD_CONSTANT_3D / (4.0 * np.pi)
        smaller = np.minimum(half_a, half_b)
    else:
        half_a = half_b = mesh.half_length
        size = 2.0 * half_a
        constant = POINT_DD_CONSTANT_2D / (2.0 * np.pi)
        smaller = half_a
    g, nu = float(material.shear_modulus), float(material.poisson_ratio)
    dd = np.asarray(dd, dtype=np.float64).reshape(mesh.n_elements, dim)
    weight = constant * g / (1.0 - nu) * np.linalg.norm(dd, axis=1) * size
    # within the averaging distance, or (to round-off) on the element: no bound
    near = np.maximum(near_fraction * smaller, 1e-9 * (half_a + half_b))
    from ..hmatrix.cluster_tree import cluster_tree

    tree = cluster_tree(mesh.centers, mesh.radii, _LEAF_SIZE, oriented=False)  # its axis-aligned boxes only
    cumulative = np.concatenate(([0.0], np.cumsum(weight[tree.permutation])))
    limit = np.full(m, np.inf) if limit is None else np.ascontiguousarray(limit, dtype=np.float64)
    elements = tuple(np.ascontiguousarray(a, dtype=np.float64) for a in
                     (mesh.centers, mesh.frames, half_a, half_b, mesh.radii, weight, near))
    clusters = (tree.permutation, tree.start, tree.stop, tree.left, tree.right, np.ascontiguousarray(tree.bbox_min),
                np.ascontiguousarray(tree.bbox_max), cumulative, float(dim))
    alone = np.arange(m)
    if point_tree is not None:
        leaves = point_tree.leaves()
        sizes = point_tree.stop[leaves] - point_tree.start[leaves]
        members = point_tree.permutation[point_tree.start[leaves[0]]:point_tree.stop[leaves[-1]]]
        leaf_of = np.repeat(np.arange(leaves.size), sizes)
        leaf_limit = np.full(leaves.size, np.inf)
        needed = limit[members] > -np.inf
        np.minimum.at(leaf_limit, leaf_of[needed], limit[members][needed])
        kept = np.flatnonzero(np.bincount(leaf_of[needed], minlength=leaves.size) > 0)
        leaf_bound = np.full(leaves.size, np.inf)
        part = np.empty(kept.size)
        _bound(np.ascontiguousarray(point_tree.bbox_min[leaves[kept]]),
               np.ascontiguousarray(point_tree.bbox_max[leaves[kept]]), False, *elements, *clusters, leaf_limit[kept],
               part)
        leaf_bound[kept] = part
        cleared = leaf_bound < leaf_limit
        out[members] = np.where(cleared[leaf_of], leaf_bound[leaf_of], np.inf)
        alone = members[~cleared[leaf_of] & needed]
    if alone.size:
        values = np.empty(alone.size)
        _bound(points[alone], points[alone], True, *elements, *clusters, limit[alone], values)
        out[alone] = values
    return out


__all__ = ["stress_bound", "POINT_DD_CONSTANT_3D", "POINT_DD_CONSTANT_2D", "SEPARATION"]
