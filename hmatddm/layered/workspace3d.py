"""The scratch of the 3D layered kernel's per-pair functions (:mod:`.images3d`), made once
a block: :func:`workspace` stashes its 80 arrays in one buffer
(:func:`hmatddm.kernels.held_function.stash`), so that the drivers, which copy the
workspace and pass it to inlined functions, take and drop one reference where they took
80 -- code that LLVM optimised in every caller (the cold compile of the layered kernels,
issue 32: benchmarks/RESULTS.md, twelfth session). The held functions take ``work[1]``,
the pointer to the tuple, and read its arrays one by one
(:func:`hmatddm.kernels.held_function.item`). The record holds the function that makes it
(``LayeredRectangles.workspace_maker``, :func:`_make_workspace`, a held function as
:func:`.images3d.with_image_terms` makes them): its code (the arrays' constructors, the
cached rules) compiled once, not linked into the drivers, the stress at points and the
per-kind workspace of each (RESULTS.md, twelfth session)."""
import numpy as np
from numba import njit

from ..kernels.held_function import dereference, held_record, stash
from .image_tracer import trace_capacity
from .image_tracer3d import _traced_buffer
from .okada_point3d import POINT_SETUP
from .potentials3d import Workspace
from .remainder_rows3d import remainder_rows
from .rectangle_quadrature import _cached_rules
from .vertical3d import vertical_workspace

__all__ = ["workspace", "workspace_arrays"]


@njit(cache=True, inline="always")
def workspace(data):
    """:func:`workspace_arrays` stashed (:func:`hmatddm.kernels.held_function.stash`):
    ``(buffer, pointer)``, the tuple of 80 arrays behind ``pointer`` (``work[1]``, what the
    held functions take), so that a copy of the workspace takes one reference, not 80
    (benchmarks/RESULTS.md, issue 32, twelfth session). Made by the record's held
    :func:`_make_workspace`."""
    return data.workspace_maker(held_record(data))


@njit(cache=True, no_cpython_wrapper=True)  # held: called through its C wrapper only
def _make_workspace(data_at):
    """:func:`workspace` (held by the record), the record as a pointer."""
    return stash(workspace_arrays(dereference(data_at)))


@njit(cache=True, inline="always")
def workspace_arrays(data):
    """Scratch: local stress (3, 3, 3), image stress (3, 3, 3), gradient (3, 3, 3, 3), the
    Kelvin scratch (2, 3, 3, 1), the :func:`Workspace` of order 1 and of the largest order
    of any source layer's triples, the tracer's room per layer ``(cap, n_orders)``, the
    :func:`.rectangle_quadrature._cached_rules`, the scratch of :func:`.okada3d.okada_stress` and of
    :func:`.vertical3d.vertical_image_stress`, the whole-space stress and the receiver point
    of :func:`.images3d._complementary_stress`, the arrays of the state of a source that traces
    nothing (:func:`_untraced_state`: made once a block, not once a source) and the rows of the
    remainder's table a source keeps per receiver height (:func:`.remainder_rows3d.remainder_rows`)."""
    n_layers = data.shear_modulus.shape[0]
    room = np.zeros((n_layers, 2), dtype=np.int64)
    n_orders = np.int64(1)  # not a literal: one specialization of vertical_workspace
    if data.interfaces.shape[0] > 0:
        for layer in range(n_layers):
            if data.shear_modulus[layer] > 0.0:
                room[layer, 0], room[layer, 1] = trace_capacity(layer, data.shear_modulus, data.n_images)
                n_orders = max(n_orders, room[layer, 1])
    return (np.empty((3, 3, 3)), np.zeros((3, 3, 3)), np.empty((3, 3, 3, 3)), np.zeros((2, 3, 3, 1)), Workspace(1),
            Workspace(n_orders), room, _cached_rules(data.gauss_points), np.empty((5, 3, 3, 3)), np.empty((30, 4)),
            vertical_workspace(n_orders), np.empty((3, 3, 3)), np.empty(3), _untraced_state(data.gauss_points),
            remainder_rows(data.table))


@njit(cache=True)
def _untraced_state(gauss_points):
    """The arrays of :func:`.images3d.source_state` for a source that traces nothing (closed form or
    point source): one empty point, no rule traced, three empty heights (a point-form
    source's :func:`.okada_point3d.point_setup` in their room: one source's state at a time
    per workspace)."""
    one = np.int64(1)
    return (_traced_buffer(one, one, one), np.zeros(gauss_points + 1, dtype=np.bool_),
            _traced_buffer(np.int64(3), one, one), np.zeros(max(3, POINT_SETUP)))
