"""Numba influence functions of constant displacement-discontinuity elements.

* :mod:`.line2d`: straight segments, plane strain (ref. App. A eqs 9-19).
* :mod:`.rectangle3d`: planar rectangles (ref. Eqs 2.50-2.59, App. A eqs 20-42).
* :mod:`.line2d_higher_order`: linear and quadratic 2D elements (ref. Sec. 3.5, App. B),
  the same block-generator functions with ``2 (order + 1)`` unknowns per element.

Both expose the same functions: ``local_stress``, ``traction_pair``, ``stress_pair``,
``traction_block`` (the block generator of the H-matrix), ``traction_matrix`` (dense
assembly), ``stress_at_points`` and ``edge_distance`` (from a collocation point to an
element's edges, for error messages). Everything here is pure math on arrays.
"""
import importlib

import numpy as np


def __getattr__(name):
    """``line2d`` and ``rectangle3d`` load (and numba loads) on first use."""
    if name in ("line2d", "rectangle3d", "line2d_higher_order"):
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def element_data(mesh, material, singular_shift=0.0, alpha=0.0, self_max=None, near_fraction=0.0):
    """The tuple of arrays the kernels of ``mesh``'s dimension take.

    ``(centers, frames, half_a, half_b, params, self_max)`` with ``params =
    [G, nu, singular_shift, alpha, near_fraction]``; in 2D ``half_a = half_b =
    half_length``. ``near_fraction`` (0 = exact hits only) widens the singular set of
    the block generator ``traction_block`` to near-miss junctions (see
    :data:`hmatddm.operators.NEAR_SINGULAR_FRACTION`).
    """
    params = np.array([material.shear_modulus, material.poisson_ratio, float(singular_shift), float(alpha),
                       float(near_fraction)])
    if self_max is None:
        self_max = np.zeros(mesh.n_elements)
    if mesh.dim == 2 and mesh.element_order > 0:  # + shape functions (line2d_higher_order)
        from ..shape_functions import coefficients, nodes

        return (mesh.centers, mesh.frames, mesh.half_length, mesh.half_length, params, self_max,
                coefficients(mesh.element_order), nodes(mesh.element_order))
    if mesh.dim == 2:
        return (mesh.centers, mesh.frames, mesh.half_length, mesh.half_length, params, self_max)
    return (mesh.centers, mesh.frames, mesh.half_a, mesh.half_b, params, self_max)


def kernel_module(mesh):
    """:mod:`.line2d` for 2D meshes (:mod:`.line2d_higher_order` for ``element_order``
    1 or 2), :mod:`.rectangle3d` for 3D ones."""
    if mesh.dim == 2 and mesh.element_order > 0:
        return importlib.import_module(f"{__name__}.line2d_higher_order")
    return importlib.import_module(f"{__name__}.{'line2d' if mesh.dim == 2 else 'rectangle3d'}")


__all__ = ["line2d", "rectangle3d", "element_data", "kernel_module"]
