"""Intersections of plan-view fracture segments and conforming splitting (ref. Sec. 6.2.3).

The reference meshes fractures without end-to-end connection at intersections and
patches the resulting singular influence coefficients (NaN averaging and the Eq. 6.11
scaling). We take the "exact" route it names instead: every fracture is split at its
intersection points (:func:`split_at_intersections`), so that element edges meet there
and no collocation point (element centre) lies on another element; then no correction
of the influence matrix is needed.

Tolerances
----------
All geometric decisions use one absolute distance ``eps = tol * D``, with ``D`` the
diagonal of the bounding box of all segments (``tol = 1e-9`` by default):

* two segments are *parallel* when ``|sin(angle)| <= tol``; parallel segments intersect
  only when *collinear* (both end points of one within ``eps`` of the other's line);
* an end point within ``eps`` (along the segment) of the other segment counts as
  touching it (T and L junctions), and is then reported exactly (snapped).
"""
import itertools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .._validation import finite_array, finite_scalar, positive_scalar
from ..errors import InputError
from .generation import Network


@dataclass(frozen=True, eq=False)
class Intersections:
    """Intersection records of pairs of segments, sorted by ``(i, j, t_i)``.

    Attributes
    ----------
    i, j : (K,) int, segment indices with ``i < j``
    points : (K, 2) intersection points
    t_i, t_j : (K,) parameters in ``[0, 1]`` along segment ``i`` and ``j``
        (``point = p0 + t (p1 - p0)`` up to round-off)
    collinear : (K,) bool, the pair is collinear (overlapping or touching end to end)

    A crossing (X), a T or an L junction gives one record. A collinear pair gives one
    record where the segments touch at a single point, and two records, at the start and
    the end of the shared part (in the order of ``t_i``), where they overlap.
    ``size`` is ``K``; the object unpacks as ``i, j, points, t_i, t_j, collinear``.
    """

    i: np.ndarray
    j: np.ndarray
    points: np.ndarray
    t_i: np.ndarray
    t_j: np.ndarray
    collinear: np.ndarray

    @property
    def size(self):
        """Number of records ``K``."""
        return len(self.i)

    def __iter__(self):
        return iter((self.i, self.j, self.points, self.t_i, self.t_j, self.collinear))


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _candidate_pairs(p0, p1, eps):
    """Pairs (a < b) of segments whose bounding circles (centre the midpoint, radius
    half the length) and bounding boxes, both widened by ``eps``, overlap.

    A k-d tree on midpoints finds them; each pair is searched from its longer segment
    (ball of radius ``2 r + eps``), so one long segment among many short ones costs one
    large query, not N of them.
    """
    n = len(p0)
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    centers = 0.5 * (p0 + p1)
    radii = 0.5 * np.hypot(*(p1 - p0).T)
    tree = cKDTree(centers)
    search = 2.0 * radii + eps
    counts = tree.query_ball_point(centers, search, return_length=True)
    lists = tree.query_ball_point(centers, search, return_sorted=False)
    b = np.fromiter(itertools.chain.from_iterable(lists), dtype=np.int64, count=int(counts.sum()))
    a = np.repeat(np.arange(n, dtype=np.int64), counts)
    keep = (radii[b] < radii[a]) | ((radii[b] == radii[a]) & (b > a))
    a, b = a[keep], b[keep]
    keep = np.hypot(*(centers[a] - centers[b]).T) <= radii[a] + radii[b] + eps
    a, b = a[keep], b[keep]
    low, high = np.minimum(p0, p1), np.maximum(p0, p1)
    keep = np.all((low[a] <= high[b] + eps) & (low[b] <= high[a] + eps), axis=1)
    a, b = a[keep], b[keep]
    return np.minimum(a, b), np.maximum(a, b)


def _project(point, start, end):
    """Parameter of the projection of ``point`` on segment ``start -> end``, clipped."""
    d = end - start
    t = np.einsum("...k,...k->...", point - start, d) / np.einsum("...k,...k->...", d, d)
    return np.clip(t, 0.0, 1.0)


def _crossing_records(a0, a1, b0, b1, eps):
    """Vectorised intersection of non-parallel pairs. Returns (hit, point, t, s)."""
    da, db = a1 - a0, b1 - b0
    la, lb = np.hypot(*da.T), np.hypot(*db.T)
    r = b0 - a0
    denom = _cross(da, db)
    t = _cross(r, db) / denom
    s = _cross(r, da) / denom
    ea, eb = eps / la, eps / lb
    hit = (t >= -ea) & (t <= 1.0 + ea) & (s >= -eb) & (s <= 1.0 + eb)
    t, s = np.clip(t, 0.0, 1.0), np.clip(s, 0.0, 1.0)
    point = (1.0 - t)[:, None] * a0 + t[:, None] * a1
    # Snap end points that touch the other segment (T and L junctions): the record is
    # then exactly that end point. Ends of segment a take precedence (deterministic).
    snap_a0, snap_a1 = t * la <= eps, (1.0 - t) * la <= eps
    snap_b0, snap_b1 = s * lb <= eps, (1.0 - s) * lb <= eps
    snap_b = (snap_b0 | snap_b1) & ~(snap_a0 | snap_a1)
    b_end = np.where(snap_b1[:, None], b1, b0)
    point = np.where(snap_b[:, None], b_end, point)
    t = np.where(snap_b, _project(point, a0, a1), t)
    s = np.where(snap_b, np.where(snap_b1, 1.0, 0.0), s)
    snap_a = snap_a0 | snap_a1
    a_end = np.where(snap_a1[:, None], a1, a0)
    point = np.where(snap_a[:, None], a_end, point)
    t = np.where(snap_a, np.where(snap_a1, 1.0, 0.0), t)
    s_projected = _project(point, b0, b1)
    s = np.where(snap_a & ~(snap_b0 | snap_b1), s_projected, s)
    s = np.where(snap_a & snap_b0, 0.0, np.where(snap_a & snap_b1, 1.0, s))
    return hit, point, t, s


def _collinear_records(a0, a1, b0, b1, eps):
    """Records of one collinear pair: a list of (point, t, s).

    The shared part runs, along ``a``, from its start to its end; each is an end point
    of ``a`` when ``b`` reaches past it (within ``eps``, ``a`` wins), else an end of ``b``.
    """
    da = a1 - a0
    la2 = float(da @ da)
    la = np.sqrt(la2)
    u0, u1 = float((b0 - a0) @ da) / la2, float((b1 - a0) @ da) / la2
    tol = eps / la
    if max(u0, u1) < -tol or min(u0, u1) > 1.0 + tol:
        return []
    # (point on b's end, its parameter along a, its parameter along b)
    b_lo, b_hi = ((b0, u0, 0.0), (b1, u1, 1.0)) if u0 <= u1 else ((b1, u1, 1.0), (b0, u0, 0.0))
    start = (a0, 0.0, float(_project(a0, b0, b1))) if b_lo[1] <= tol else b_lo
    end = (a1, 1.0, float(_project(a1, b0, b1))) if b_hi[1] >= 1.0 - tol else b_hi
    ends = [start] if (end[1] - start[1]) * la <= eps else [start, end]
    return [(np.array(point, dtype=float), float(np.clip(t, 0.0, 1.0)), s) for point, t, s in ends]


def _check_segments(p0, p1):
    p0 = finite_array("p0", p0, (None, 2))
    p1 = finite_array("p1", p1, (None, 2))
    if p0.shape != p1.shape:
        raise InputError(f"p0 and p1 must have the same shape, got {p0.shape} and {p1.shape}")
    lengths = np.hypot(*(p1 - p0).T) if len(p0) else np.zeros(0)
    bad = np.flatnonzero(lengths == 0.0)
    if bad.size:
        raise InputError(f"segment lengths must be > 0; segment {int(bad[0])} has zero length")
    return p0, p1, lengths


def _eps(p0, p1, tol):
    if len(p0) == 0:
        return tol
    points = np.concatenate([p0, p1])
    diagonal = float(np.hypot(*(points.max(axis=0) - points.min(axis=0))))
    return tol * diagonal


def find_intersections(p0, p1, tol=1e-9):
    """All pairs of plan-view segments ``p0[k] -> p1[k]`` (each (M, 2)) that meet.

    Candidate pairs come from a k-d tree on segment midpoints (bounding circles of
    radius ``length/2``), then an exact vectorised test; ~10^4 segments take well
    under a second. See the module docstring for ``tol`` and the treatment of parallel,
    collinear and touching segments.

    Returns
    -------
    :class:`Intersections` (unpacks as ``i, j, points, t_i, t_j, collinear``)
    """
    p0, p1, lengths = _check_segments(p0, p1)
    tol = positive_scalar("tol", tol)
    eps = _eps(p0, p1, tol)
    a, b = _candidate_pairs(p0, p1, eps)
    a0, a1, b0, b1 = p0[a], p1[a], p0[b], p1[b]
    sine = _cross(a1 - a0, b1 - b0) / (lengths[a] * lengths[b])
    parallel = np.abs(sine) <= tol
    crossing = np.flatnonzero(~parallel)
    hit, point, t, s = _crossing_records(a0[crossing], a1[crossing], b0[crossing], b1[crossing], eps)
    out_i, out_j = [a[crossing][hit]], [b[crossing][hit]]
    out_p, out_t, out_s = [point[hit]], [t[hit]], [s[hit]]
    out_c = [np.zeros(int(hit.sum()), dtype=bool)]
    # Parallel candidates: collinear when both ends of b lie within eps of a's line.
    par = np.flatnonzero(parallel)
    da = a1[par] - a0[par]
    offset = np.maximum(np.abs(_cross(b0[par] - a0[par], da)), np.abs(_cross(b1[par] - a0[par], da))) / lengths[a[par]]
    for k in par[offset <= eps]:
        for pt, ti, sj in _collinear_records(a0[k], a1[k], b0[k], b1[k], eps):
            out_i.append([a[k]])
            out_j.append([b[k]])
            out_p.append(pt[None, :])
            out_t.append([ti])
            out_s.append([sj])
            out_c.append([True])
    i = np.concatenate(out_i).astype(np.int64)
    j = np.concatenate(out_j).astype(np.int64)
    t_i = np.concatenate(out_t).astype(float)
    order = np.lexsort((t_i, j, i))
    return Intersections(i[order], j[order], np.concatenate(out_p).reshape(-1, 2)[order], t_i[order],
                         np.concatenate(out_s).astype(float)[order], np.concatenate(out_c).astype(bool)[order])


def check_network(network):
    if not isinstance(network, Network):
        raise InputError(f"network must be a hmatddm.network.Network, got {type(network).__name__}")
    return network


def split_at_intersections(network, min_stub=0.0, tol=1e-9):
    """The same fractures cut into segments that end at every intersection point.

    Every segment is split at all its intersection points (X, T, L junctions), so that
    meshing each piece end to end (:meth:`Network.to_mesh2d`, :meth:`Network.to_mesh3d`)
    puts element edges exactly on the intersections (the "end-to-end connection" of
    ref. Sec. 6.2.3) and no collocation point lies on another element: an element
    centre is strictly inside its piece, while another straight fracture meets that
    piece only at its end points. Both fractures at an intersection get the very same
    node coordinates.

    * Break points closer than ``eps`` (module docstring) along a segment are merged
      into one node (an intersection point wins over a segment end).
    * Collinear overlaps are kept once: the pieces of the higher-index segment that lie
      inside the shared part are dropped (the lower-index segment keeps them). A segment
      lying wholly on another one disappears.
    * ``min_stub`` (m, default 0 = off): a first or last piece shorter than this whose
      outer end is free (not an intersection) is trimmed, turning a near-miss X into a
      T junction; a segment always keeps at least one piece (of two stubs, the longer
      one). This avoids tiny elements next to intersections. Pieces between two close
      intersections are kept as they are, however short (they cannot be removed
      without moving an intersection).

    Returns a :class:`Network` with ``fracture_id`` and ``set_id`` of the parent segment,
    pieces ordered by parent segment and from ``p0`` to ``p1``.
    """
    network = check_network(network)
    min_stub = finite_scalar("min_stub", min_stub)
    if min_stub < 0.0:
        raise InputError(f"min_stub must be >= 0, got {min_stub}")
    m = len(network)
    if m == 0:
        return network
    found = find_intersections(network.p0, network.p1, tol)
    eps = _eps(network.p0, network.p1, positive_scalar("tol", tol))
    lengths = network.lengths
    # Break points: both segment ends, plus every intersection on either segment.
    segment = np.concatenate([np.arange(m), np.arange(m), found.i, found.j])
    t = np.concatenate([np.zeros(m), np.ones(m), found.t_i, found.t_j])
    points = np.concatenate([network.p0, network.p1, found.points, found.points])
    is_crossing = np.concatenate([np.zeros(2 * m, dtype=bool), np.ones(2 * found.size, dtype=bool)])
    order = np.lexsort((~is_crossing, t, segment))
    segment, t, points, is_crossing = segment[order], t[order], points[order], is_crossing[order]
    # Merge break points closer than eps along their segment.
    new_node = np.ones(len(t), dtype=bool)
    new_node[1:] = (segment[1:] != segment[:-1]) | ((t[1:] - t[:-1]) * lengths[segment[1:]] > eps)
    starts = np.flatnonzero(new_node)
    index = np.arange(len(t))
    key = np.minimum.reduceat(np.where(is_crossing, index, index + len(t)), starts)
    representative = np.where(key >= len(t), key - len(t), key)
    node_segment = segment[starts]
    node_t = t[representative]
    node_t[np.r_[node_segment[1:] != node_segment[:-1], True]] = 1.0  # keep exact ends
    node_t[np.r_[True, node_segment[1:] != node_segment[:-1]]] = 0.0
    node_point = points[representative]
    node_crossing = np.logical_or.reduceat(is_crossing, starts)
    # Pieces between consecutive nodes of one segment.
    first = np.flatnonzero(node_segment[:-1] == node_segment[1:])
    piece_segment = node_segment[first]
    piece_p0, piece_p1 = node_point[first], node_point[first + 1]
    piece_t = 0.5 * (node_t[first] + node_t[first + 1])
    keep = np.ones(len(first), dtype=bool)
    # Collinear overlaps: drop the higher-index segment's pieces inside the shared part.
    col = np.flatnonzero(found.collinear)
    if col.size:
        pair_start = np.r_[True, (found.i[col][1:] != found.i[col][:-1]) | (found.j[col][1:] != found.j[col][:-1])]
        for g in np.split(col, np.flatnonzero(pair_start)[1:]):
            if g.size < 2:
                continue  # touching at one point: nothing shared
            lo, hi = found.t_j[g].min(), found.t_j[g].max()
            keep &= ~((piece_segment == found.j[g[0]]) & (piece_t > lo) & (piece_t < hi))
    # Dangling stubs shorter than min_stub.
    if min_stub > 0.0:
        piece_length = np.hypot(*(piece_p1 - piece_p0).T)
        is_first = np.r_[True, piece_segment[1:] != piece_segment[:-1]]
        is_last = np.r_[piece_segment[1:] != piece_segment[:-1], True]
        stub_first = is_first & ~is_last & ~node_crossing[first] & (piece_length < min_stub)
        stub_last = is_last & ~is_first & ~node_crossing[first + 1] & (piece_length < min_stub)
        # A two-piece segment with two stubs keeps its longer piece (the first on a tie).
        nxt = np.r_[piece_segment[1:], -1]
        both = stub_first & np.r_[stub_last[1:], False] & (nxt == piece_segment)
        both_index = np.flatnonzero(both)
        first_shorter = piece_length[both_index] < piece_length[both_index + 1]
        stub_last[both_index[first_shorter] + 1] = False
        stub_first[both_index[~first_shorter]] = False
        keep &= ~(stub_first | stub_last)
    piece_segment = piece_segment[keep]
    return Network(piece_p0[keep], piece_p1[keep], network.fracture_id[piece_segment],
                   network.set_id[piece_segment], network.height, network.z_center, network.region)


__all__ = ["Intersections", "find_intersections", "split_at_intersections"]
