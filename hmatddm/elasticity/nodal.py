"""Nodal DDs of 2D meshes with linear or quadratic elements (ref. Sec. 3.5, App. B).

A mesh of ``element_order`` p carries ``n = p + 1`` nodal DDs per element, stored
``(N, n, 2)`` in the global frame (flat: element-major, node-major, component;
docs/conventions.md §2). :func:`hmatddm.solve`, :func:`hmatddm.opening`,
:func:`hmatddm.slip`, :func:`hmatddm.stress_at` and :func:`hmatddm.mean_stress_at`
delegate here for such meshes; :func:`dd_at` and :func:`opening_at` interpolate the DD
anywhere along the elements with the shape functions (any order, constant included).
"""
import time

import numpy as np

from .._validation import finite_array, finite_scalar
from ..errors import InputError
from ..material import Elastic
from ..mesh import nodal_array
from ..mesh.shape_functions import values


def opening(mesh, dd):
    """Nodal openings ``w = DD . n`` (N, n)."""
    return np.einsum("ekd,ed->ek", nodal_array("dd", dd, mesh), mesh.normals)


def slip(mesh, dd):
    """Nodal tangential DDs ``DD - w n`` (N, n, 2), global frame."""
    dd = nodal_array("dd", dd, mesh)
    return dd - opening(mesh, dd)[:, :, None] * mesh.normals[:, None, :]


def dd_at(mesh, dd, xi):
    """(N, M, d): the DD of every element at intrinsic coordinates ``xi`` (M,) in [-1, 1]
    (points :meth:`hmatddm.Mesh2D.points_at`), interpolated by the shape functions. For
    constant elements (and 3D meshes) the element's DD at every ``xi``."""
    xi = finite_array("xi", np.atleast_1d(np.asarray(xi, dtype=float)), (None,))
    if np.any(np.abs(xi) > 1.0):
        raise InputError(f"xi must lie in [-1, 1] (intrinsic coordinate along an element), got {xi}")
    if mesh.n_nodes == 1:
        dd = finite_array("dd", dd).reshape(mesh.n_elements, 1, mesh.dim)
    else:
        dd = nodal_array("dd", dd, mesh)
    return np.einsum("mk,ekd->emd", values(mesh.element_order, xi), dd)


def opening_at(mesh, dd, xi):
    """(N, M): the opening ``DD . n`` of every element at intrinsic coordinates ``xi``
    (M,) in [-1, 1] (points :meth:`hmatddm.Mesh2D.points_at`)."""
    return np.einsum("emd,ed->em", dd_at(mesh, dd, xi), mesh.normals)


def stress_at(mesh, material, dd, points, singular_correction="none", method="auto", info=None,
              near_fraction=0.0):
    """(M, 2, 2) stress induced at ``points`` by the nodal DDs of a linear or quadratic
    mesh, summed directly over all elements (the arguments of :func:`hmatddm.stress_at`;
    ``method`` may be ``"auto"`` or ``"direct"``; the compressed sum exists for
    constant elements only)."""
    from ..kernels import element_data
    from ..kernels.drivers import stress_sum
    from ..layered.medium import LayeredMedium

    if not isinstance(material, (Elastic, LayeredMedium)):
        raise InputError(f"material must be an hmatddm.Elastic or LayeredMedium, got {type(material).__name__}")
    if singular_correction not in ("none", "average"):
        raise InputError(f"singular_correction must be one of ('none', 'average'), got {singular_correction!r}")
    if method not in ("auto", "direct"):
        raise InputError(f"method must be 'auto' or 'direct' for element_order {mesh.element_order} (the "
                         f"compressed 'tree' sum exists for constant elements only), got {method!r}")
    near_fraction = finite_scalar("near_fraction", near_fraction)
    if not 0.0 <= near_fraction < 1.0:
        raise InputError(f"near_fraction must be in [0, 1), got {near_fraction}")
    if isinstance(material, LayeredMedium):  # closed form + image terms (ref. Ch. 3)
        from ..layered.higher_order2d import stress_at as layered_stress_at

        return layered_stress_at(mesh, material, dd, points, singular_correction, near_fraction)
    dd = np.ascontiguousarray(nodal_array("dd", dd, mesh))
    points = np.ascontiguousarray(finite_array("points", points, (None, 2)))
    data = element_data(mesh, material, singular_shift=1e-3 if singular_correction == "average" else 0.0,
                        near_fraction=near_fraction)
    started = time.perf_counter()
    out = stress_sum(data, points, dd)
    bad = np.flatnonzero(~np.all(np.isfinite(out.reshape(len(points), -1)), axis=1))
    if bad.size:
        where = "on an element end" if near_fraction == 0.0 else \
            f"on an element end or within near_fraction = {near_fraction:g} half lengths of one"
        raise InputError(f"points[{int(bad[0])}] lies {where}, where the stress is singular; "
                         "move it or pass singular_correction='average'")
    if info is not None:
        info.update(method="direct", n_far=0, n_near=1, pairs_exact=len(points) * mesh.n_elements,
                    seconds=time.perf_counter() - started, points=len(points), elements=mesh.n_elements)
    return out


__all__ = ["nodal_array", "opening", "slip", "dd_at", "opening_at", "stress_at"]
