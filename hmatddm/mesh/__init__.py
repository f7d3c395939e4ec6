"""Meshes and what is computed from them alone (the bottom of the house, docs/architecture.md).

* :mod:`.elements`: :class:`Mesh2D` (segments) and :class:`Mesh3D` (rectangles) as structs of
  arrays, and the builders :func:`rectangle`, :func:`penny`, :func:`line`, :func:`concatenate`;
  re-exported here, so ``hd.mesh.penny(...)`` and ``from hmatddm.mesh import Mesh3D`` work.
* :mod:`.quality`: finite geometry and close near-parallel elements (re-exported).
* :mod:`.shape_functions`: the shape functions of higher-order 2D elements (ref. App. B).
* :mod:`.topology`: faces between neighbouring elements and tip edges (ref. Sec. 4.3.1).
* :mod:`.neighbours`: pairs of points closer than a distance (numpy only).
* :mod:`.hard_cases`: the geometries of the hard-case suite (tests and benchmarks).

Importing this package loads numpy only: no numba, scipy or kernels.
"""
from .elements import (PARALLEL_MAX_ANGLE_DEG, PARALLEL_SPACING_FACTOR, CloseParallelPairs, Mesh2D, Mesh3D,
                       check_mesh, check_parallel_spacing, close_parallel_pairs, concatenate, fracture_extents,
                       in_plane_axes, largest_sides, line, nodal_array, penny, rectangle)

__all__ = ["Mesh2D", "Mesh3D", "rectangle", "penny", "line", "concatenate", "in_plane_axes", "nodal_array",
           "close_parallel_pairs", "check_mesh", "check_parallel_spacing", "CloseParallelPairs", "largest_sides",
           "fracture_extents", "PARALLEL_SPACING_FACTOR", "PARALLEL_MAX_ANGLE_DEG"]
