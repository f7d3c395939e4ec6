"""The stress at a point of one rectangular displacement discontinuity in a plane-layered
3D medium (ref. Secs 3.2-3.3): the closed form of the source layer's material plus the
image terms (:mod:`.images3d`), compiled once (issue 32: the cold compile of the layered
3D kernels).

The per-pair stress (:func:`_stress_traced`) is held by the kernel record
(``LayeredRectangles.point_stress``, :func:`.images3d.with_image_terms`) as a first-class
function and called through its address (:mod:`hmatddm.kernels.held_function`): numba links
every njit function a function calls into the caller's library and LLVM optimises it again
there, and the per-pair stress was compiled in full in the stress at points
(:func:`.stress3d.stress_points`), in the drivers' ``stress_block`` and in numba's own
compile of the per-kind ``element_stress`` the drivers inline (benchmarks/RESULTS.md, issue
32). The callers pass the record, the source state and the workspace as pointers
(:func:`hmatddm.kernels.held_function.address_of`), made once per block in
:mod:`.stress3d` (a copy of the record per pair costs as much as a half-space pair's
arithmetic), and the held image terms (``image_terms``, ``vertical_terms``) as arguments: a
held function takes the record without its function fields.
"""
import numpy as np
from numba import njit

from ..kernels import rectangle3d
from ..kernels.held_function import address_of, dereference, held_record, item
from . import okada3d
from .images2d import zero_in_void
from .okada_point3d import point_form_terms

__all__ = ["element_stress_traced"]


@njit(cache=True, no_cpython_wrapper=True)  # held: called through its C wrapper only
def _stress_traced(data_at, point, point_layer, j, state_at, work_at, image_terms, vertical_terms, out):
    """:func:`element_stress_traced` (held by the record), the record, the source's state
    and the workspace as pointers, ``image_terms`` and ``vertical_terms`` the record's held
    :func:`.images3d._complementary_stress` and :func:`.images3d._vertical_terms`."""
    data, state = dereference(data_at), dereference(state_at)
    local, image = item(work_at, 0), item(work_at, 1)  # the workspace's arrays one by one
    if zero_in_void(data.shear_modulus, point_layer, out):
        return
    g = data.shear_modulus
    nu = data.poisson_ratio
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    rectangle3d.stress_pair(point, center, frame, a, b, g[ls], nu[ls], data.singular_shift, out, local,
                            data.near_fraction * min(a, b))
    if data.closed_form[j]:
        okada3d.okada_stress(point, center, data.okada[j], data.okada_half[j, 0], data.okada_half[j, 1], data.surface,
                             g[ls], nu[ls], False, True, item(work_at, 8), item(work_at, 9), image)
        for q in range(3):
            for i in range(3):
                for k in range(3):
                    out[q, i, k] += image[q, i, k]
    elif data.interfaces.shape[0] > 0:
        if data.point_form[j]:
            point_form_terms(data, point, point_layer, j, state[4], item(work_at, 7), item(work_at, 8), 0.0, point, image, False)
        else:
            here = item(work_at, 12)
            for k in range(3):
                here[k] = point[k]
            image_terms(data_at, here, point_layer, j, state_at, work_at, np.float64(0.0), image, vertical_terms)
        for q in range(3):
            for i in range(3):
                for k in range(3):
                    out[q, i, k] += image[q, i, k]
        if data.surface_form[j] and point_layer == ls:
            okada3d.okada_stress(point, center, data.okada[j], data.okada_half[j, 0], data.okada_half[j, 1],
                                 data.surface, g[ls], nu[ls], False, True, item(work_at, 8), item(work_at, 9), image)
            for q in range(3):
                for i in range(3):
                    for k in range(3):
                        out[q, i, k] += image[q, i, k]


@njit(cache=True, inline="always")
def element_stress_traced(data, point, point_layer, j, state, work, out):
    """``out[q, i, k]``: stress at ``point`` (in ``point_layer``; zero in a void layer)
    for a unit global DD ``q`` of rectangle ``j`` of the :class:`.images3d.LayeredRectangles`
    ``data``, closed form plus images, with the source's ``state``
    (:func:`.images3d.source_state`: its triples traced once for every point; the sum over
    points of :mod:`.stress3d`) and ``work`` (:func:`.images3d.workspace`). A point within
    ``near_fraction`` smaller half sides of an edge counts as on it. The images as
    :func:`.images3d.element_traction`'s (:func:`.images3d._complementary_stress`) with the
    relative Gauss rule (no ``entry_tol``: a point's stress has no largest entry to be small
    against) and no table unless ``data`` has one; a ``closed_form`` source: the image and
    surface terms of :func:`.okada3d.okada_stress`; a ``point_form`` source: Okada's point
    source (:func:`.okada_point3d.point_form_terms`); a ``surface_form`` source: its
    reflection in the free surface in closed form, for points of its layer. Through the
    record's ``point_stress`` (:func:`_stress_traced`), the point copied to the workspace
    (any layout), the record, state and workspace copied to the stack for the call (a loop
    over pairs makes those pointers once: :mod:`.stress3d`): their arrays must outlive the
    call, held by the caller's variables (numba releases a temporary after its last use,
    here the copy, not the call)."""
    here = item(work[1], 12)
    for k in range(3):
        here[k] = point[k]
    data.point_stress(held_record(data), here, np.int64(point_layer), np.int64(j),
                      address_of(state), work[1], data.image_terms, data.vertical_terms, out)
