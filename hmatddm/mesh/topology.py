"""Element edges, faces between neighbouring elements, and tip edges.

The flow (ref. Sec. 4.3.1, Eqs 4.31-4.33) needs the faces across which fluid moves
between two elements; propagation (ref. Sec. 4.2.2) needs the tip edges, those
with no neighbour. Both come from one geometric test, so they work across
elements of different sizes and across kinks of a turning fracture.

Local edges of an element (``k``):

* 3D rectangle: ``0: +e1``, ``1: -e1``, ``2: +e2``, ``3: -e2`` (the side whose
  outward in-plane direction is that axis).
* 2D segment: ``0: +t`` end, ``1: -t`` end.

For every edge: its midpoint, the outward in-plane direction ``ahead``, the unit
axis along the edge (3D; 2D uses the out-of-plane z axis), its length (2D: the
``height`` given to the flow model) and the element half size perpendicular to it.

Two edges form a face when they lie on one line (3D) or at one point (2D), overlap
over a positive length and each element lies ahead of the other's edge. The
overlap length and the half sizes perpendicular to the edges give the two-point
flux of the face.
"""
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.spatial import cKDTree

from .elements import Mesh2D, Mesh3D

_TOLERANCE = 1e-6  # relative to the smaller element size


@dataclass(frozen=True)
class Edges:
    """Edge geometry of every element, shape (N, K, ...) with K = 4 (3D) or 2 (2D)."""

    midpoints: np.ndarray   # (N, K, d)
    ahead: np.ndarray       # (N, K, d) outward in-plane unit directions
    axis: np.ndarray        # (N, K, 3) unit edge directions (2D: +z)
    length: np.ndarray      # (N, K) edge lengths (2D: the flow height)
    half_width: np.ndarray  # (N, K) element half size perpendicular to the edge


@dataclass(frozen=True)
class Faces:
    """Faces between neighbouring elements (one row per face, ``first < second``)."""

    first: np.ndarray         # (F,) element index
    second: np.ndarray        # (F,) element index
    first_edge: np.ndarray    # (F,) local edge of ``first`` (-1 for extra connections)
    second_edge: np.ndarray   # (F,) local edge of ``second`` (-1 for extra connections)
    length: np.ndarray        # (F,) face length (overlap of the two edges), m
    first_distance: np.ndarray   # (F,) centre-to-face distance on the ``first`` side, m
    second_distance: np.ndarray  # (F,) centre-to-face distance on the ``second`` side, m

    @property
    def n_faces(self):
        return len(self.first)

    def append(self, first, second, length, first_distance, second_distance, first_edge=None):
        """These faces plus extra connections (e.g. fracture intersections).

        ``first_edge`` (optional, -1 for none) is the local edge of ``first`` the
        connection covers (a tip arrested on a natural fracture is no tip any more);
        the other side gets edge ``-1``.
        """
        first = np.asarray(first, dtype=np.int64)
        second = np.asarray(second, dtype=np.int64)
        first_edge = -np.ones(len(first), np.int64) if first_edge is None else np.asarray(first_edge, np.int64)
        low, high = np.minimum(first, second), np.maximum(first, second)
        swap = first > second
        d_first = np.where(swap, second_distance, first_distance)
        d_second = np.where(swap, first_distance, second_distance)
        minus = -np.ones(len(low), dtype=np.int64)
        edge_low = np.where(swap, minus, first_edge)
        edge_high = np.where(swap, first_edge, minus)
        return Faces(np.concatenate([self.first, low]), np.concatenate([self.second, high]),
                     np.concatenate([self.first_edge, edge_low]), np.concatenate([self.second_edge, edge_high]),
                     np.concatenate([self.length, np.asarray(length, float)]),
                     np.concatenate([self.first_distance, np.asarray(d_first, float)]),
                     np.concatenate([self.second_distance, np.asarray(d_second, float)]))


def element_edges(mesh, height=1.0):
    """:class:`Edges` of a mesh (``height``: the edge length of 2D elements)."""
    n = mesh.n_elements
    if isinstance(mesh, Mesh3D):
        e1, e2 = mesh.frames[:, 0, :], mesh.frames[:, 1, :]
        a, b = mesh.half_a, mesh.half_b
        ahead = np.stack([e1, -e1, e2, -e2], axis=1)
        half_width = np.stack([a, a, b, b], axis=1)
        axis = np.stack([e2, e2, e1, e1], axis=1)
        length = np.stack([2 * b, 2 * b, 2 * a, 2 * a], axis=1)
        midpoints = mesh.centers[:, None, :] + ahead * half_width[:, :, None]
        return Edges(midpoints, ahead, axis, length, half_width)
    if isinstance(mesh, Mesh2D):
        t = mesh.tangents
        ahead = np.stack([t, -t], axis=1)
        half_width = np.stack([mesh.half_length, mesh.half_length], axis=1)
        midpoints = mesh.centers[:, None, :] + ahead * half_width[:, :, None]
        axis = np.zeros((n, 2, 3))
        axis[:, :, 2] = 1.0
        length = np.full((n, 2), float(height))
        return Edges(midpoints, ahead, axis, length, half_width)
    raise TypeError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")


def _candidate_pairs(mesh):
    """Element pairs close enough to share an edge (i < j), by ``i`` then ``j``: ``j``
    within ``radius_i + max radius`` of ``i``.

    All pairs within twice the largest radius come from the tree at once as an array
    (a growth pass recomputes the faces of the whole mesh: a list per element cost 19 ms
    at 16 000 elements), then each is held to its first element's reach."""
    radii = mesh.radii
    centers = mesh.centers
    largest = radii.max()
    reach = radii + largest * (1.0 + 1e-9) + 1e-12
    pairs = cKDTree(centers).query_pairs(2.0 * largest * (1.0 + 1e-9) + 2e-12, output_type="ndarray")
    first, second = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
    distance = np.sqrt(np.sum((centers[first] - centers[second]) ** 2, axis=1))
    keep = distance <= reach[first]
    first, second = first[keep], second[keep]
    order = np.lexsort((second, first))
    return first[order], second[order]


@njit(cache=True)
def _match_edges(first, second, centers, midpoints, ahead, axis, length, half_width, is_3d, tolerance):
    n_pairs = len(first)
    k_edges = midpoints.shape[1]
    out_i = np.empty(n_pairs * 2, np.int64)
    out_j = np.empty(n_pairs * 2, np.int64)
    out_ki = np.empty(n_pairs * 2, np.int64)
    out_kj = np.empty(n_pairs * 2, np.int64)
    out_len = np.empty(n_pairs * 2)
    count = 0
    dim = midpoints.shape[2]
    for p in range(n_pairs):
        i = first[p]
        j = second[p]
        size = min(half_width[i, 0], half_width[i, k_edges - 1], half_width[j, 0], half_width[j, k_edges - 1])
        tol = tolerance * size
        for ki in range(k_edges):
            for kj in range(k_edges):
                # each element lies ahead of the other's edge
                side_i = 0.0
                side_j = 0.0
                for c in range(dim):
                    side_i += ahead[i, ki, c] * (centers[j, c] - midpoints[i, ki, c])
                    side_j += ahead[j, kj, c] * (centers[i, c] - midpoints[j, kj, c])
                if side_i <= tol or side_j <= tol:
                    continue
                overlap = 0.0
                if not is_3d:
                    gap = 0.0
                    for c in range(dim):
                        gap += (midpoints[i, ki, c] - midpoints[j, kj, c]) ** 2
                    if np.sqrt(gap) > tol:
                        continue
                    overlap = length[i, ki]
                else:
                    # parallel axes
                    cross = 0.0
                    ax = axis[i, ki]
                    bx = axis[j, kj]
                    cross += (ax[1] * bx[2] - ax[2] * bx[1]) ** 2
                    cross += (ax[2] * bx[0] - ax[0] * bx[2]) ** 2
                    cross += (ax[0] * bx[1] - ax[1] * bx[0]) ** 2
                    if np.sqrt(cross) > 1e-6:
                        continue
                    # j's midpoint on i's edge line
                    s = 0.0
                    for c in range(3):
                        s += (midpoints[j, kj, c] - midpoints[i, ki, c]) * ax[c]
                    off = 0.0
                    for c in range(3):
                        r = midpoints[j, kj, c] - midpoints[i, ki, c] - s * ax[c]
                        off += r * r
                    if np.sqrt(off) > tol:
                        continue
                    lo = max(-0.5 * length[i, ki], s - 0.5 * length[j, kj])
                    hi = min(0.5 * length[i, ki], s + 0.5 * length[j, kj])
                    overlap = hi - lo
                    if overlap <= tol:
                        continue
                if count == len(out_i):
                    break
                out_i[count] = i
                out_j[count] = j
                out_ki[count] = ki
                out_kj[count] = kj
                out_len[count] = overlap
                count += 1
    return out_i[:count], out_j[:count], out_ki[:count], out_kj[:count], out_len[:count]


def element_faces(mesh, edges=None, height=1.0):
    """:class:`Faces` between elements that share (part of) an edge."""
    if edges is None:
        edges = element_edges(mesh, height)
    first, second = _candidate_pairs(mesh)
    i, j, ki, kj, length = _match_edges(first, second, np.ascontiguousarray(mesh.centers),
                                        np.ascontiguousarray(edges.midpoints), np.ascontiguousarray(edges.ahead),
                                        np.ascontiguousarray(edges.axis), np.ascontiguousarray(edges.length),
                                        np.ascontiguousarray(edges.half_width), mesh.dim == 3, _TOLERANCE)
    return Faces(i, j, ki, kj, length, edges.half_width[i, ki], edges.half_width[j, kj])


def tip_edges(mesh, faces, edges=None, height=1.0, covered_fraction=0.5):
    """Edges ``(element, local edge)`` not covered by faces: the fracture front.

    An edge counts as a tip when less than ``covered_fraction`` of its length is
    shared with neighbours (a long edge next to one short neighbour stays a tip).
    Returns two arrays ``(element, edge)`` in element order.
    """
    if edges is None:
        edges = element_edges(mesh, height)
    covered = np.zeros(edges.length.shape)
    np.add.at(covered, (faces.first[faces.first_edge >= 0], faces.first_edge[faces.first_edge >= 0]),
              faces.length[faces.first_edge >= 0])
    np.add.at(covered, (faces.second[faces.second_edge >= 0], faces.second_edge[faces.second_edge >= 0]),
              faces.length[faces.second_edge >= 0])
    element, edge = np.nonzero(covered < covered_fraction * edges.length)
    return element.astype(np.int64), edge.astype(np.int64)
