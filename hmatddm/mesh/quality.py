"""Checks of a mesh's quality for constant-DD elements: every element finite and of
positive size (:func:`check_mesh`), and close near-parallel elements of different
fractures that the elements cannot resolve (:func:`close_parallel_pairs`, warned about
by :func:`check_parallel_spacing`). :mod:`hmatddm.mesh` re-exports these names.
"""
import warnings
from typing import NamedTuple

import numpy as np

from .._validation import positive_scalar
from ..errors import InputError, MeshQualityWarning

#: Two near-parallel overlapping elements of different fractures are too close for
#: constant-DD elements when their spacing ``s < PARALLEL_SPACING_FACTOR * h * (L/h)**0.25``
#: (``h``: the larger element size, ``L``: the smaller fracture's extent); see
#: :func:`close_parallel_pairs` for the measurements.
PARALLEL_SPACING_FACTOR = 0.6
#: Elements whose normals differ by less than this angle (degrees) count as parallel.
PARALLEL_MAX_ANGLE_DEG = 20.0


class CloseParallelPairs(NamedTuple):
    """Element pairs found by :func:`close_parallel_pairs` (arrays of equal length)."""

    first: np.ndarray           # element index (the lower of the pair)
    second: np.ndarray          # element index, of another fracture
    spacing: np.ndarray         # distance between the two element planes, m
    limit: np.ndarray           # smallest spacing the pair's elements resolve, m
    element_size: np.ndarray    # h: the larger element size of the pair, m
    fracture_extent: np.ndarray  # L: the smaller of the two fractures' extents, m

    def refined_size(self):
        """Element size ``h`` at which every pair's spacing is resolved
        (``s = PARALLEL_SPACING_FACTOR * h**0.75 * L**0.25``), m."""
        needed = (self.spacing / (PARALLEL_SPACING_FACTOR * self.fracture_extent ** 0.25)) ** (4.0 / 3.0)
        return float(np.min(needed)) if len(needed) else float("inf")


def largest_sides(mesh):
    """(N,) the largest side of each element (the segment length in 2D), m."""
    if mesh.dim == 2:
        return 2.0 * mesh.half_length
    return 2.0 * np.maximum(mesh.half_a, mesh.half_b)


def fracture_extents(mesh):
    """(N,) for each element, the extent of its fracture: the largest side of the
    bounding box of the fracture's element centres plus its largest element size, m."""
    _, inverse = np.unique(mesh.fracture_id, return_inverse=True)
    count = inverse.max() + 1
    low = np.full((count, mesh.dim), np.inf)
    high = np.full((count, mesh.dim), -np.inf)
    size = np.zeros(count)
    np.minimum.at(low, inverse, mesh.centers)
    np.maximum.at(high, inverse, mesh.centers)
    np.maximum.at(size, inverse, largest_sides(mesh))
    return (np.max(high - low, axis=1) + size)[inverse]


def close_parallel_pairs(mesh, factor=PARALLEL_SPACING_FACTOR, max_angle_deg=PARALLEL_MAX_ANGLE_DEG):
    """Pairs of near-parallel, overlapping elements of different fractures that lie closer
    than constant-DD elements can resolve.

    Two parallel cracks a spacing ``s`` apart hold a thin bridge between them. With
    constant-DD elements of size ``h`` the antisymmetric mode of the pair (one crack
    opens where the other closes) is much softer than the collocation error of its
    opening-slip coupling once ``s`` is small, and the solution is finite but wrong:
    negative openings, -0.64 x the single crack at ``s = h/10``. A pair (i, j) is
    reported when

    * their normals differ by less than ``max_angle_deg`` (default 20),
    * each overlaps the other when projected on the other's plane,
    * ``s < factor * h * (L / h)**0.25``, with ``s`` the larger distance of each centre
      from the other element's plane, ``h`` the larger element size of the two (the
      segment length in 2D, the larger side in 3D) and ``L`` the smaller extent of the
      two fractures (:func:`fracture_extents`). ``factor`` defaults to 0.6.
    * ``L >= h / 2``: a fracture smaller than half the other's element lies within one
      of its constant-DD elements, which cannot hold the antisymmetric mode (a 0.25-0.5 m
      crack 0.05-0.5 m from a crack of 1 m elements: its openings within 2% of a refined
      solution; 10% at L = h, 20-40% at L = 2-4 h).

    Measured (pressurised parallel cracks of length or diameter L, dense solves): with
    element-to-element aligned meshes the openings stay positive down to ``s = 0.4-0.5 h``,
    but any misalignment (a shift of h/10-h/2, or n against n + 1 elements) gives
    negative openings up to ``s / h`` = 0.5 at L/h = 1-4, 0.7 at 6-12, 1.0 at 20,
    1.2-1.5 at 40, 1.5 at 80 and 160, 2.0 at 320 in 2D, and 0.5 at L/h = 8, about 1.0 at
    16 and 32 in 3D (staircase pennies); the coarser of two different meshes sets ``h``.
    The bound grows like ``(L/h)**0.25``; the default factor covers every measured
    failure (its limit is 0.6 h at L = h, 1.27 h at L/h = 20 and 2.5 h at 320). Cracks
    at 10-20 degrees fail like parallel ones near their closest point.

    Cost: a KD-tree per fracture and one on the fracture centres, O(N log N) plus the
    candidate pairs of different fractures within reach; pairs within one fracture are
    never enumerated, and a single-fracture mesh returns at once.

    Returns a :class:`CloseParallelPairs` sorted by ``spacing / limit`` (worst first).
    """
    factor = positive_scalar("factor", factor)
    max_angle_deg = positive_scalar("max_angle_deg", max_angle_deg)
    if max_angle_deg > 90.0:
        raise InputError(f"max_angle_deg must be in (0, 90], got {max_angle_deg}")
    empty = CloseParallelPairs(*(np.zeros(0, dtype=np.int64),) * 2, *(np.zeros(0),) * 4)
    ids = mesh.fracture_id
    if np.unique(ids).size < 2:
        return empty
    centers, normals = mesh.centers, mesh.normals
    size = largest_sides(mesh)
    extent = fracture_extents(mesh)
    # a reported pair has an in-plane offset below r_i + r_j + (sqrt 2 - 1) min(r_i, r_j)
    # (the overlap) and a normal one below its limit, which is at most the sum of the
    # per-element bounds factor size^0.75 extent^0.25
    i, j = _candidate_pairs(mesh, 1.21 * mesh.radii, factor * size**0.75 * extent**0.25)
    d = centers[j] - centers[i]
    ni, nj = normals[i], normals[j]
    parallel = np.abs(np.einsum("kd,kd->k", ni, nj)) >= np.cos(np.radians(max_angle_deg))
    spacing = np.maximum(np.abs(np.einsum("kd,kd->k", d, ni)), np.abs(np.einsum("kd,kd->k", d, nj)))
    overlap = _overlap(mesh, i, j) & _overlap(mesh, j, i)
    h = np.maximum(size[i], size[j])
    length = np.minimum(extent[i], extent[j])
    limit = factor * h * (length / h) ** 0.25
    close = parallel & overlap & (spacing < limit) & (length >= 0.5 * h)
    i, j = np.minimum(i[close], j[close]), np.maximum(i[close], j[close])
    spacing, limit, h, length = spacing[close], limit[close], h[close], length[close]
    order = np.lexsort((j, i, spacing / limit))
    return CloseParallelPairs(i[order], j[order], spacing[order], limit[order], h[order], length[order])


def _candidate_pairs(mesh, in_plane, normal):
    """Element pairs ``(i, j)`` of different fractures closer than
    ``hypot(in_plane_i + in_plane_j, normal_i + normal_j)`` (and maybe a few more), never
    enumerating pairs within one fracture: a KD-tree per fracture, queried only for
    fractures whose bounding spheres (inflated by the reach) meet, which a KD-tree on
    the fracture centres finds."""
    from scipy.spatial import cKDTree

    order = np.argsort(mesh.fracture_id, kind="stable")
    _, starts = np.unique(mesh.fracture_id[order], return_index=True)
    members = np.split(order, starts[1:])
    centre = np.array([0.5 * (mesh.centers[m].min(axis=0) + mesh.centers[m].max(axis=0)) for m in members])
    largest_in_plane = np.array([in_plane[m].max() for m in members])
    largest_normal = np.array([normal[m].max() for m in members])
    sphere = np.array([np.linalg.norm(mesh.centers[m] - c, axis=1).max() for m, c in zip(members, centre)])
    sphere += largest_in_plane + largest_normal
    trees = [cKDTree(mesh.centers[m]) for m in members]
    first, second = [], []
    # each fracture pair once, from the fracture with the larger sphere (lower index on ties)
    for f, near in enumerate(cKDTree(centre).query_ball_point(centre, 2.0 * sphere)):
        for g in near:
            if (sphere[g], g) >= (sphere[f], f):
                continue
            if np.linalg.norm(centre[f] - centre[g]) >= sphere[f] + sphere[g]:
                continue
            reach = np.hypot(largest_in_plane[f] + largest_in_plane[g], largest_normal[f] + largest_normal[g])
            pairs = trees[f].sparse_distance_matrix(trees[g], float(reach), output_type="ndarray")
            first.append(members[f][pairs["i"]])
            second.append(members[g][pairs["j"]])
    if not first:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(first), np.concatenate(second)


def _overlap(mesh, i, j):
    """(K,) True where element ``j`` overlaps element ``i`` projected on ``i``'s plane
    (elements that only touch end to end do not overlap)."""
    margin = 1.0 - 1e-9
    d = mesh.centers[j] - mesh.centers[i]
    if mesh.dim == 2:
        ti, tj = mesh.tangents[i], mesh.tangents[j]
        reach_j = mesh.half_length[j] * np.abs(np.einsum("kd,kd->k", tj, ti))
        return np.abs(np.einsum("kd,kd->k", d, ti)) < (mesh.half_length[i] + reach_j) * margin
    overlap = np.ones(len(i), dtype=bool)
    for axis, half in ((0, mesh.half_a), (1, mesh.half_b)):
        u = mesh.frames[i, axis]
        reach_j = (mesh.half_a[j] * np.abs(np.einsum("kd,kd->k", mesh.frames[j, 0], u))
                   + mesh.half_b[j] * np.abs(np.einsum("kd,kd->k", mesh.frames[j, 1], u)))
        overlap &= np.abs(np.einsum("kd,kd->k", d, u)) < (half[i] + reach_j) * margin
    return overlap


def check_mesh(mesh, name="mesh"):
    """InputError unless ``mesh`` holds at least one element with finite geometry and
    positive half sizes: arrays of a built mesh can be changed in place (NaN put into
    ``centers``), which would otherwise reach numpy or scipy errors far from the cause.
    The message names the array and the first bad element."""
    if mesh.n_elements == 0:
        raise InputError(f"{name} has no elements; build it with hd.mesh.rectangle, penny, line or "
                         "Mesh3D.from_rectangles / Mesh2D.from_segments")
    sizes = ("half_length",) if mesh.dim == 2 else ("half_a", "half_b")
    for field in ("centers", "frames", *sizes):
        values = np.asarray(getattr(mesh, field))
        finite = np.isfinite(values.reshape(len(values), -1)).all(axis=1)
        if not finite.all():
            index = int(np.flatnonzero(~finite)[0])
            raise InputError(f"{name}.{field}[{index}] must be finite, got {values[index].tolist()}")
    for field in sizes:
        values = getattr(mesh, field)
        if np.any(values <= 0.0):
            index = int(np.flatnonzero(values <= 0.0)[0])
            raise InputError(f"{name}.{field}[{index}] must be > 0 m, got {values[index]}")
    return mesh


def check_parallel_spacing(mesh, stacklevel=2):
    """Warn (:class:`~hmatddm.errors.MeshQualityWarning`) when
    :func:`close_parallel_pairs` finds any pair; the message names the worst pair and
    the element size that resolves every pair. Returns the pairs.

    A warning, not an error: the mesh is valid and refinement fixes it, element-aligned
    meshes are good below the bound, and a growing simulation may pass through such a
    state. Make it an error with ``warnings.simplefilter("error", MeshQualityWarning)``.
    """
    pairs = close_parallel_pairs(mesh)
    if len(pairs.first):
        i, j = int(pairs.first[0]), int(pairs.second[0])
        s, h = float(pairs.spacing[0]), float(pairs.element_size[0])
        fix = (f"refine both fractures to elements of h <= {pairs.refined_size():.3g} m there"
               if np.all(pairs.spacing > 0.0) else "merge the fractures (they overlap in one plane)")
        warnings.warn(MeshQualityWarning(
            f"{len(pairs.first)} pair(s) of near-parallel overlapping elements of different fractures lie closer "
            f"than constant-DD elements resolve, e.g. elements {i} (fracture {int(mesh.fracture_id[i])}) and {j} "
            f"(fracture {int(mesh.fracture_id[j])}): spacing {s:.3g} m with elements of h = {h:.3g} m (s/h = "
            f"{s / h:.2g}), below {PARALLEL_SPACING_FACTOR} h (L/h)^(1/4) = {float(pairs.limit[0]):.3g} m "
            f"(L = {float(pairs.fracture_extent[0]):.3g} m). The thin bridge between them is not resolved and "
            f"the openings can come out wrong (even negative); {fix}"), stacklevel=stacklevel + 1)
    return pairs
