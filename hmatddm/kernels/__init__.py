"""Numba influence functions of constant displacement-discontinuity elements.

* :mod:`.line2d`: straight segments, plane strain (ref. App. A eqs 9-19).
* :mod:`.rectangle3d`: planar rectangles (ref. Eqs 2.50-2.59, App. A eqs 20-42).
* :mod:`.line2d_higher_order`: linear and quadratic 2D elements (ref. Sec. 3.5, App. B),
  the same block-generator functions with ``2 (order + 1)`` unknowns per element.

Each holds the influence of one element at one point (``local_stress``, ``traction_pair``,
``stress_pair``, ...) and registers its kernel data record with :mod:`.drivers`, the one
set of loops over element pairs: ``traction_block`` (the block generator of the
H-matrix), ``traction_matrix`` (dense assembly), ``singular_pairs``, ``edge_distance``
(for error messages) and ``stress_at_points``; :mod:`.held_function` lets a kind hold a
large per-pair function in its record, called through a pointer (compiled once for every
driver). Everything here is pure math on arrays.
"""
import importlib

import numpy as np


def __getattr__(name):
    """The kernel modules load (and numba loads) on first use."""
    if name in ("line2d", "rectangle3d", "line2d_higher_order", "drivers"):
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def element_data(mesh, material, singular_shift=0.0, alpha=0.0, self_max=None, near_fraction=0.0):
    """The kernel data record of ``mesh``'s kind of element in the homogeneous
    ``material``: :class:`.line2d.Segments`, :class:`.line2d_higher_order.NodalSegments`
    (``element_order`` 1 or 2) or :class:`.rectangle3d.Rectangles`, with
    the fields ``singular_shift``, ``near_fraction`` and ``alpha`` of :mod:`.drivers`.
    ``near_fraction`` (0 = exact hits only) widens the singular set to near-miss
    junctions (see :data:`hmatddm.elasticity.operator.NEAR_SINGULAR_FRACTION`); ``self_max`` (N,)
    is needed for ``alpha > 0`` (ref. Eq. 6.11; zeros when None).
    """
    options = dict(singular_shift=float(singular_shift), near_fraction=float(near_fraction), alpha=float(alpha))
    self_max = np.zeros(mesh.n_elements) if self_max is None else np.asarray(self_max, dtype=np.float64)
    g, nu = float(material.shear_modulus), float(material.poisson_ratio)
    if mesh.dim == 2 and mesh.element_order > 0:  # + shape functions (line2d_higher_order)
        from ..mesh.shape_functions import coefficients, nodes
        from .line2d_higher_order import NodalSegments

        return NodalSegments(mesh.centers, mesh.frames, mesh.half_length, g, nu, **options, self_max=self_max,
                             coefficients=coefficients(mesh.element_order), nodes=nodes(mesh.element_order))
    if mesh.dim == 2:
        from .line2d import Segments

        return Segments(mesh.centers, mesh.frames, mesh.half_length, g, nu, **options, self_max=self_max)
    from .rectangle3d import Rectangles

    return Rectangles(mesh.centers, mesh.frames, mesh.half_a, mesh.half_b, g, nu, **options, self_max=self_max)


__all__ = ["line2d", "rectangle3d", "line2d_higher_order", "drivers", "element_data"]
