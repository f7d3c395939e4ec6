"""Plane-layered elastic media (ref. Ch. 3): the medium and its image-method kernels.

* :class:`LayeredMedium`: interfaces, per-layer moduli (a void layer is a free surface),
  optional per-layer in-situ stress and toughness.
* :mod:`.images2d`: complementary (image) stress of DDs in 2D plane strain by the general
  image method (ref. Secs 3.2-3.3), numba; loaded on first use. Its parts: :mod:`.image_tracer`
  (images through the interfaces, shared with 3D), :mod:`.segment_quadrature` (the image
  quadrature along a segment), :mod:`.segments2d` (kernel data of constant 2D elements).
* :mod:`.images3d`: the same for constant rectangles in 3D (any orientation), with the
  3D Hansen potentials (ref. Eq. 3.24); :mod:`.influence3d` builds their kernel data. Its
  parts: :mod:`.potentials3d` (the potentials and the field of one image triple),
  :mod:`.image_tracer3d` (the triples through the interfaces), :mod:`.image_points3d` (the
  field of a point source), :mod:`.rectangle_quadrature` (the quadrature over a rectangle),
  :mod:`.okada3d` and :mod:`.vertical3d` (image terms in closed form), :mod:`.stress3d`
  (the stress at points behind :func:`hmatddm.stress_at`, each source traced once).
* :mod:`.displacement`: the displacement at points (ref. Eqs 2.43, 2.55-2.57 with the
  images' displacement of ref. Eq. 3.22), behind :func:`hmatddm.displacement_at`; its
  kernels :mod:`.displacement3d` (rectangles) and :mod:`.displacement2d` (segments).
* :func:`split_at_interfaces`: cut a mesh's elements where they cross interfaces (2D
  segments; 3D rectangles with a horizontal edge).
"""
import importlib

from .medium import LayeredMedium


def __getattr__(name):
    if name in ("images2d", "influence2d", "images3d", "influence3d", "image_tracer", "segment_quadrature",
                "segments2d", "potentials3d", "image_tracer3d", "image_points3d", "rectangle_quadrature",
                "displacement", "displacement2d", "displacement3d", "okada3d", "vertical3d", "stress3d"):
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def split_at_interfaces(mesh, medium):
    """See :func:`hmatddm.layered.influence2d.split_at_interfaces` (2D) and
    :func:`hmatddm.layered.engine.split_rectangles` (3D)."""
    if mesh.dim == 3:
        from .engine import split_rectangles as split
    else:
        from .influence2d import split_at_interfaces as split

    return split(mesh, medium)


__all__ = ["LayeredMedium", "split_at_interfaces", "images2d"]
