"""Meshes of constant displacement-discontinuity elements, as structs of arrays.

Two element kinds (ref. Sec. 2.3, Appendix A.2):

* :class:`Mesh2D`: straight line segments in the plane (plane strain), unknowns
  ``[dd_x, dd_y]`` per element in the global frame.
* :class:`Mesh3D`: planar rectangles of any orientation and size, unknowns
  ``[dd_x, dd_y, dd_z]`` per element in the global frame.

The quality checks of a mesh (finite geometry, close parallel elements) are
:mod:`hmatddm.mesh.quality`'s, re-exported here.

Local frames are stored row-wise: ``frames[i]`` is the rotation whose rows are the
element's unit tangent(s) and unit normal, ``(t, n)`` in 2D and ``(e1, e2, n)`` in 3D,
with ``n = e1 x e2`` (right-handed). In 2D ``n`` is ``t`` turned by +90 degrees.
The normal points to the ``+`` face: a displacement discontinuity ``DD = u(+) - u(-)``
opens the crack when ``DD . n > 0`` (docs/conventions.md §1).
"""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array, finite_scalar, positive_int, positive_scalar
from ..errors import InputError
from .quality import (PARALLEL_MAX_ANGLE_DEG, PARALLEL_SPACING_FACTOR, CloseParallelPairs, check_mesh,
                      check_parallel_spacing, close_parallel_pairs, fracture_extents, largest_sides)

_ORTHONORMAL_TOL = 1e-6


def _fracture_ids(fracture_id, n):
    if fracture_id is None:
        return np.zeros(n, dtype=np.int64)
    ids = np.asarray(fracture_id)
    if ids.shape != (n,) or not np.issubdtype(ids.dtype, np.integer):
        raise InputError(f"fracture_id must be an integer array of shape ({n},), got {ids.dtype} {ids.shape}")
    return ids.astype(np.int64)


@dataclass(frozen=True, eq=False)
class Mesh2D:
    """Straight DD line elements (plane strain): constant by default, linear or
    quadratic with ``element_order`` 1 or 2 (ref. Sec. 3.5, App. B).

    Attributes
    ----------
    centers : (N, 2) segment midpoints (the collocation points of constant elements), m
    frames : (N, 2, 2) rows ``(tangent, normal)``
    half_length : (N,) half segment lengths, m
    fracture_id : (N,) integer label of the fracture each element belongs to
    element_order : 0, 1 or 2
        Order of the DD's variation along each element: ``element_order + 1`` nodes
        inside the element (:mod:`hmatddm.mesh.shape_functions`), which are also its
        collocation points (:attr:`collocation_points`); unknowns element-major, then
        node-major, then component (docs/conventions.md §2).
    """

    centers: np.ndarray
    frames: np.ndarray
    half_length: np.ndarray
    fracture_id: np.ndarray
    element_order: int = 0

    dim = 2

    def __post_init__(self):
        from .shape_functions import check_order

        object.__setattr__(self, "element_order", check_order(self.element_order))

    @classmethod
    def from_segments(cls, p0, p1, fracture_id=None, element_order=0):
        """Elements from segment end points ``p0`` and ``p1``, both (N, 2).

        The tangent points from ``p0`` to ``p1``; the normal is the tangent turned by
        +90 degrees (counter-clockwise). ``element_order``: see the class.
        """
        p0 = finite_array("p0", p0, (None, 2))
        p1 = finite_array("p1", p1, (None, 2))
        if p0.shape != p1.shape:
            raise InputError(f"p0 and p1 must have the same shape, got {p0.shape} and {p1.shape}")
        if len(p0) == 0:
            raise InputError("p0 must hold at least one segment, got 0")
        chord = p1 - p0
        length = np.hypot(chord[:, 0], chord[:, 1])
        scale = max(1.0, float(np.max(np.abs(np.concatenate([p0, p1])))))
        bad = np.flatnonzero(length <= 1e-12 * scale)
        if bad.size:
            raise InputError(f"segment lengths must be > 0; segment {int(bad[0])} has zero length")
        tangent = chord / length[:, None]
        normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
        frames = np.stack([tangent, normal], axis=1)
        return cls(0.5 * (p0 + p1), np.ascontiguousarray(frames), 0.5 * length,
                   _fracture_ids(fracture_id, len(p0)), element_order)

    @property
    def n_elements(self):
        return len(self.centers)

    @property
    def n_nodes(self):
        """Nodes (collocation points) per element: ``element_order + 1``."""
        return self.element_order + 1

    def with_element_order(self, element_order):
        """The same segments with elements of another order (0, 1 or 2)."""
        return Mesh2D(self.centers, self.frames, self.half_length, self.fracture_id, element_order)

    def points_at(self, xi):
        """(N, M, 2): the points at intrinsic coordinates ``xi`` (M,) in [-1, 1] of every element."""
        xi = finite_array("xi", np.atleast_1d(np.asarray(xi, dtype=float)), (None,))
        if np.any(np.abs(xi) > 1.0):
            raise InputError(f"xi must lie in [-1, 1] (intrinsic coordinate along an element), got {xi}")
        offset = self.half_length[:, None, None] * xi[None, :, None] * self.tangents[:, None, :]
        return self.centers[:, None, :] + offset

    @property
    def collocation_points(self):
        """(N * n_nodes, 2): the nodes where the traction is collocated, element-major
        then node-major (the centres for constant elements)."""
        from .shape_functions import nodes

        return self.points_at(nodes(self.element_order)).reshape(-1, 2)

    @property
    def normals(self):
        return self.frames[:, 1, :]

    @property
    def tangents(self):
        return self.frames[:, 0, :]

    @property
    def areas(self):
        """Segment lengths (the 2D 'area' of an element), m."""
        return 2.0 * self.half_length

    @property
    def radii(self):
        """Distance from the centre to the farthest point of each element."""
        return self.half_length.copy()

    @property
    def endpoints(self):
        """(p0, p1), each (N, 2)."""
        offset = self.half_length[:, None] * self.tangents
        return self.centers - offset, self.centers + offset

    def __len__(self):
        return self.n_elements

    def subset(self, index):
        index = np.asarray(index)
        return Mesh2D(self.centers[index], self.frames[index], self.half_length[index],
                      self.fracture_id[index], self.element_order)

    def transformed(self, rotation, translation=(0.0, 0.0)):
        """The same mesh moved rigidly: ``x -> rotation @ x + translation``."""
        rotation = np.asarray(rotation, dtype=float)
        return Mesh2D(self.centers @ rotation.T + np.asarray(translation, dtype=float),
                      np.ascontiguousarray(self.frames @ rotation.T), self.half_length.copy(),
                      self.fracture_id.copy(), self.element_order)


@dataclass(frozen=True, eq=False)
class Mesh3D:
    """Planar rectangular constant-DD elements of any orientation and size.

    Attributes
    ----------
    centers : (N, 3) collocation points (rectangle centres), m
    frames : (N, 3, 3) rows ``(e1, e2, n)``, orthonormal and right-handed
    half_a, half_b : (N,) half side lengths along ``e1`` and ``e2``, m
    fracture_id : (N,) integer label of the fracture each element belongs to
    """

    centers: np.ndarray
    frames: np.ndarray
    half_a: np.ndarray
    half_b: np.ndarray
    fracture_id: np.ndarray

    dim = 3
    #: Only constant elements exist in 3D (higher-order elements are 2D, :class:`Mesh2D`).
    element_order = 0
    n_nodes = 1

    def with_element_order(self, element_order):
        """This mesh for ``element_order`` 0; anything else is refused (3D elements are constant)."""
        from .shape_functions import check_order

        if check_order(element_order) != 0:
            raise InputError(f"element_order must be 0 for a Mesh3D (linear and quadratic DD elements exist "
                             f"for 2D meshes only, Mesh2D), got {element_order!r}")
        return self

    @classmethod
    def from_rectangles(cls, centers, e1, e2, half_a, half_b, fracture_id=None):
        """Elements from centres (N, 3), in-plane unit axes ``e1``, ``e2`` (N, 3)
        (or a single (3,) vector for all) and half sides ``half_a``, ``half_b`` (N,)
        (or scalars). ``e1`` and ``e2`` must be orthonormal; the normal is ``e1 x e2``.
        """
        centers = finite_array("centers", centers, (None, 3))
        n = len(centers)
        if n == 0:
            raise InputError("centers must hold at least one rectangle, got 0")
        e1 = np.broadcast_to(finite_array("e1", e1), (n, 3)) if np.ndim(e1) == 1 else finite_array("e1", e1, (n, 3))
        e2 = np.broadcast_to(finite_array("e2", e2), (n, 3)) if np.ndim(e2) == 1 else finite_array("e2", e2, (n, 3))
        half_a, half_b = (np.full(n, float(finite_scalar(name, h))) if np.ndim(h) == 0 else finite_array(name, h, (n,))
                          for name, h in (("half_a", half_a), ("half_b", half_b)))
        for name, h in (("half_a", half_a), ("half_b", half_b)):
            bad = np.flatnonzero(h <= 0.0)
            if bad.size:
                raise InputError(f"{name} must be > 0; element {int(bad[0])} has {h[bad[0]]}")
        for name, v in (("e1", e1), ("e2", e2)):
            norm = np.linalg.norm(v, axis=1)
            bad = np.flatnonzero(np.abs(norm - 1.0) > _ORTHONORMAL_TOL)
            if bad.size:
                raise InputError(f"{name} must be unit vectors; element {int(bad[0])} has length {norm[bad[0]]:.6g}")
        dot = np.einsum("ij,ij->i", e1, e2)
        bad = np.flatnonzero(np.abs(dot) > _ORTHONORMAL_TOL)
        if bad.size:
            raise InputError(f"e1 and e2 must be orthogonal; element {int(bad[0])} has e1.e2 = {dot[bad[0]]:.3g}")
        # Re-orthonormalise exactly (Gram-Schmidt) so frames are rotations to machine precision.
        u = e1 / np.linalg.norm(e1, axis=1)[:, None]
        v = e2 - np.einsum("ij,ij->i", e2, u)[:, None] * u
        v /= np.linalg.norm(v, axis=1)[:, None]
        frames = np.ascontiguousarray(np.stack([u, v, np.cross(u, v)], axis=1))
        return cls(centers.copy(), frames, half_a.copy(), half_b.copy(), _fracture_ids(fracture_id, n))

    @property
    def n_elements(self):
        return len(self.centers)

    @property
    def normals(self):
        return self.frames[:, 2, :]

    @property
    def areas(self):
        return 4.0 * self.half_a * self.half_b

    @property
    def radii(self):
        """Distance from the centre to a corner of each element."""
        return np.hypot(self.half_a, self.half_b)

    def corners(self):
        """(N, 4, 3) corner coordinates, counter-clockwise about the normal."""
        e1 = self.frames[:, 0, :] * self.half_a[:, None]
        e2 = self.frames[:, 1, :] * self.half_b[:, None]
        c = self.centers
        return np.stack([c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2], axis=1)

    def __len__(self):
        return self.n_elements

    def subset(self, index):
        index = np.asarray(index)
        return Mesh3D(self.centers[index], self.frames[index], self.half_a[index], self.half_b[index],
                      self.fracture_id[index])

    def transformed(self, rotation, translation=(0.0, 0.0, 0.0)):
        """The same mesh moved rigidly: ``x -> rotation @ x + translation``."""
        rotation = np.asarray(rotation, dtype=float)
        return Mesh3D(self.centers @ rotation.T + np.asarray(translation, dtype=float),
                      np.ascontiguousarray(self.frames @ rotation.T), self.half_a.copy(),
                      self.half_b.copy(), self.fracture_id.copy())


def nodal_array(name, array, mesh, uniform=False):
    """``array`` as (N, n, d) nodal values of ``mesh``: accepted as (N, n, d),
    (N * n, d) or flat (N * n * d,); with ``uniform``, an (N, d) array gives every node of
    an element its row (e.g. a pressure traction ``-p * mesh.normals``)."""
    n, k, d = mesh.n_elements, mesh.n_nodes, mesh.dim
    array = finite_array(name, array)
    if array.shape == (n, k, d):
        return array
    if array.shape in ((n * k, d), (n * k * d,)):
        return array.reshape(n, k, d)
    if uniform and array.shape == (n, d):
        return np.repeat(array[:, None, :], k, axis=1)
    shapes = f"({n}, {k}, {d}), ({n * k}, {d}) or ({n * k * d},)" + (f" or ({n}, {d})" if uniform else "")
    raise InputError(f"{name} must have shape {shapes} for {n} elements of element_order {mesh.element_order}, "
                     f"got {array.shape}")


def _unit(name, vector, dim):
    v = finite_array(name, vector, (dim,))
    norm = np.linalg.norm(v)
    if norm == 0.0:
        raise InputError(f"{name} must be a non-zero vector")
    return v / norm


def rectangle(center, e1, e2, length, height, nx, ny, fracture_id=0):
    """One planar rectangular fracture of ``length`` x ``height`` (along ``e1``, ``e2``)
    meshed into ``nx`` x ``ny`` equal rectangles. ``e1`` and ``e2`` are normalised and
    must be orthogonal."""
    center = finite_array("center", center, (3,))
    u = _unit("e1", e1, 3)
    v = _unit("e2", e2, 3)
    if abs(float(u @ v)) > _ORTHONORMAL_TOL:
        raise InputError(f"e1 and e2 must be orthogonal, got e1.e2 = {float(u @ v):.3g}")
    length = positive_scalar("length", length)
    height = positive_scalar("height", height)
    nx = positive_int("nx", nx)
    ny = positive_int("ny", ny)
    s = (np.arange(nx) + 0.5) / nx * length - 0.5 * length
    t = (np.arange(ny) + 0.5) / ny * height - 0.5 * height
    ss, tt = np.meshgrid(s, t, indexing="ij")
    centers = center + ss.reshape(-1, 1) * u + tt.reshape(-1, 1) * v
    n = len(centers)
    return Mesh3D.from_rectangles(centers, u, v, np.full(n, 0.5 * length / nx), np.full(n, 0.5 * height / ny),
                                  fracture_id=np.full(n, int(fracture_id)))


def in_plane_axes(normal):
    """A right-handed orthonormal pair ``(e1, e2)`` with ``e1 x e2 = normal``."""
    n = _unit("normal", normal, 3)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = helper - (helper @ n) * n
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(n, e1)


def penny(center, normal, radius, h, fracture_id=0):
    """Staircase disc: squares of side ``h`` on a grid symmetric about ``center``,
    kept when their centres lie inside the circle of ``radius``."""
    center = finite_array("center", center, (3,))
    radius = positive_scalar("radius", radius)
    h = positive_scalar("h", h)
    if h > 2.0 * radius:
        raise InputError(f"h must be <= 2*radius = {2 * radius}, got {h}")
    e1, e2 = in_plane_axes(normal)
    m = int(np.ceil(radius / h))
    s = (np.arange(-m, m) + 0.5) * h
    ss, tt = np.meshgrid(s, s, indexing="ij")
    inside = ss**2 + tt**2 < radius**2
    ss, tt = ss[inside], tt[inside]
    centers = center + ss[:, None] * e1 + tt[:, None] * e2
    n = len(centers)
    return Mesh3D.from_rectangles(centers, e1, e2, np.full(n, 0.5 * h), np.full(n, 0.5 * h),
                                  fracture_id=np.full(n, int(fracture_id)))


def line(p0, p1, n, fracture_id=0, element_order=0):
    """A straight 2D crack from ``p0`` to ``p1`` cut into ``n`` equal segments of
    ``element_order`` 0 (constant), 1 (linear) or 2 (quadratic)."""
    p0 = finite_array("p0", p0, (2,))
    p1 = finite_array("p1", p1, (2,))
    n = positive_int("n", n)
    if np.allclose(p0, p1):
        raise InputError("p0 and p1 must differ (a crack of zero length)")
    s = np.linspace(0.0, 1.0, n + 1)[:, None]
    nodes = p0 + s * (p1 - p0)
    return Mesh2D.from_segments(nodes[:-1], nodes[1:], fracture_id=np.full(n, int(fracture_id)),
                                element_order=element_order)


def concatenate(meshes):
    """Join meshes of the same dimension into one (fracture ids are kept)."""
    meshes = list(meshes)
    if not meshes:
        raise InputError("meshes must hold at least one mesh")
    kind = type(meshes[0])
    if any(type(m) is not kind for m in meshes):
        raise InputError("meshes must all be Mesh2D or all Mesh3D")
    if kind is Mesh2D:
        orders = sorted({m.element_order for m in meshes})
        if len(orders) > 1:
            raise InputError(f"meshes must all have the same element_order, got {orders}")
        return Mesh2D(*(np.concatenate([getattr(m, f) for m in meshes])
                        for f in ("centers", "frames", "half_length", "fracture_id")), orders[0])
    return Mesh3D(*(np.concatenate([getattr(m, f) for m in meshes])
                    for f in ("centers", "frames", "half_a", "half_b", "fracture_id")))


__all__ = ["Mesh2D", "Mesh3D", "rectangle", "penny", "line", "concatenate", "in_plane_axes", "nodal_array",
           "close_parallel_pairs", "check_parallel_spacing", "CloseParallelPairs", "largest_sides",
           "fracture_extents", "check_mesh", "PARALLEL_SPACING_FACTOR", "PARALLEL_MAX_ANGLE_DEG"]
