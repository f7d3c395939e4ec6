"""Numba influence functions of constant displacement-discontinuity elements.

* :mod:`.line2d`: straight segments, plane strain (ref. App. A eqs 9-19).
* :mod:`.rectangle3d`: planar rectangles (ref. Eqs 2.50-2.59, App. A eqs 20-42).

Both expose the same functions: ``local_stress``, ``traction_pair``, ``stress_pair``,
``traction_block`` (the block generator of the H-matrix), ``traction_matrix`` (dense
assembly), ``stress_at_points`` and ``edge_distance`` (from a collocation point to an
element's edges, for error messages). Everything here is pure math on arrays.
"""
import numpy as np

from . import line2d, rectangle3d


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
    if mesh.dim == 2:
        return (mesh.centers, mesh.frames, mesh.half_length, mesh.half_length, params, self_max)
    return (mesh.centers, mesh.frames, mesh.half_a, mesh.half_b, params, self_max)


def kernel_module(mesh):
    """:mod:`.line2d` for 2D meshes, :mod:`.rectangle3d` for 3D ones."""
    return line2d if mesh.dim == 2 else rectangle3d


__all__ = ["line2d", "rectangle3d", "element_data", "kernel_module"]
