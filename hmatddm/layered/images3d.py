"""Complementary (image) stress of rectangular displacement discontinuities in a
plane-layered 3D medium by the general image method (ref. Secs 3.2-3.3): the kernel
record of constant rectangles (:class:`LayeredRectangles`) and the per-pair functions that
:mod:`hmatddm.kernels.drivers` call for it. The entry of the 3D image method; its parts,
whose public functions are re-exported here:

* :mod:`.potentials3d`: the Hansen potentials of a point force (ref. Eqs 3.14-3.17, 3.22,
  3.24), the derivatives of their base functions and the field of one image triple;
* :mod:`.image_tracer3d`: the triples traced through the interfaces (ref. Fig. 3.4,
  Eqs 3.25-3.28), on the shared :mod:`.image_tracer`;
* :mod:`.image_points3d`: the complementary field of a point source (the sum over its
  triples) and the whole-space field through the same potentials;
* :mod:`.rectangle_quadrature`: the quadrature over a source rectangle, subdivided near
  its images, with fewer points far from them.

Cost (issue 32). The tracer merges the triples that reach the same point by different
paths (:func:`.image_tracer3d.merge_coincident`: exact, 1.6-1.9x fewer triples with two
or more interfaces), and an operator's entries take the fewest Gauss points that keep
their image error below :data:`.rectangle_quadrature.ENTRY_TOL` of the largest entry
(:func:`.rectangle_quadrature.entry_order`; ``entry_tol = 0``: the relative rule of
:func:`far_order` alone, the cross-check). With two or more interfaces, only the *near*
triples (those that can reach the receiver's layer) are integrated by quadrature; the far
ones, the smooth layered remainder, come from a table built once per medium and mesh
extent (:mod:`.remainder_table3d`, ``LayeredMedium(method="table")``, the default;
``method="quadrature"`` integrates every triple, the cross-check). With that table, the
near triples' field at a quadrature point is itself a lookup: a first reflection or a
transmission is homogeneous of degree -3 about its interface, so it is tabulated in one
angle, exactly to 1e-11 (:mod:`.near_table3d`), and the remainder is contracted once per
source and receiver height (:mod:`.remainder_rows3d`): three layers on the issue-32 lattice
25 -> 3.3 us a pair (27x uniform rock), one thread of the 2-core Xeon at dgemm 74 GFLOP/s
(benchmarks/RESULTS.md, thirteenth and fourteenth sessions). In a half-space (one
solid layer under a void) the image and surface terms of a rectangle with a horizontal side
are in closed form (:mod:`.okada3d`, Okada 1992; ``LayeredRectangles.closed_form``). With
two or more solid layers under a void, a source of the top solid layer with a horizontal
side takes its reflection in the free surface in closed form too (that triple is the
half-space's image triple, coefficient for coefficient:
:func:`.influence3d.surface_reflection_alone`; ``LayeredRectangles.surface_form``,
:func:`.image_tracer3d.drop_surface_range`), and the quadrature neither integrates it nor
refines for its singular point. In a half-space, a rectangle without a horizontal side
takes Okada's point source at the quadrature's points (:mod:`.okada_point3d`;
``LayeredRectangles.point_form``): the half-space's image triple, ~30x cheaper a point than
the Hansen potentials; elsewhere it keeps the quadrature.
The stress at points takes the same per-pair terms (:func:`element_stress_traced`) with
sources outside and points inside (:mod:`.stress3d`: each source traced once).

What is not in closed form, and why (measured in ``_derive_closed_form3d.py``): every other
near triple, i.e. the reflections in an interface between two solids and the
transmissions. Each triple is a point-source field built from the Hansen base functions
``F = r - sigma r3 log(r + sigma r3)``, ``L = log(r + sigma r3)`` and ``1/r`` (ref. Eqs
3.14-3.17, 3.22, 3.24) whose coefficients of ``D^n`` are polynomials of degree <= min(n, 2)
in the source height (ref. Eqs 3.25-3.28; measured up to ``images=4``, the ``D`` order
growing to 5), so its integral over a rectangle with a horizontal side is elementary, as
Okada's is, though not from the uniform-rock kernel's primitives of ``1/r`` alone.
But it is not Okada's closed form reweighted: his image terms split into their seven
coefficient groups (parts A, B, C) fit the reflection at a bi-material interface only to
0.3-1.2 % (separate weights per dislocation component; 4e-15 for a free surface): his
grouped expressions fix combinations of the terms that the free surface's reflection
coefficients make, and ``c1, c2, c3`` of an interface between solids (ref. Eq. 3.27) make
others. A closed form
needs the primitives of each term, the integral of ``P(t) d1^a d2^b d3^c B`` over the
rectangle (``deg P <= 3`` with the ``s`` factor, ``B`` in ``F, L`` of either gauge). For a
*vertical* rectangle they are derived and checked (``_derive_closed_form3d.py``, item 4):
along the dip ``d3 = -eps d/dt``, so the height integral is exact by parts (``deg P`` never
exceeds the number of ``d3``), needing only ``d3^-1 F = K = 3/4 r3 r + (rho^2/4 - r3^2/2) L
- rho^2/8`` and ``d3^-1 L = -sigma F``; along the strike ``d1^-1`` is a difference of the
derivative tables at the corners, and for the terms without ``d1`` (after the Laplace
equation) a derivative of ``log(r + r1)``, the ``L`` of :mod:`.potentials3d` with the axes
turned. Compiled in :mod:`.vertical3d` (``LayeredRectangles.vertical_form``): a vertical
source takes its near triples in closed form where the quadrature would need sub-squares
or :data:`VERTICAL_FROM` points per side; whole image entries of every triple, reflections
in interfaces between solids and transmissions, agree with the quadrature to ~1e-14.
Dipping rectangles (and horizontal ones, beyond the free surface's reflection) keep the
quadrature: along a dip that is not the vertical, ``d3`` is no total derivative and the
weights ``P(t)`` need primitives of their own, not derived.

Coordinates: ``(x, y, z)`` with ``z`` vertical (the reference's ``x3``); interfaces are
the planes ``z = d_k`` (see :class:`LayeredMedium`, docs/conventions.md §3).

Compile cost (issue 18: a cold numba cache). numba links every njit function a function
calls into its compiled library and LLVM optimises and generates machine code for all of
it again there, so each njit function above the per-pair stress
(:func:`.potentials3d._pair_stress_gradient`) costs one more compile of everything below
it: the chain is kept short (``_complementary_gradient``, ``image_rectangle_stress`` and
``Workspace`` are inlined by numba, not compiled on their own); loops LLVM would unroll
into thousands of instructions (``_base_table``) run to array sizes; and no njit function
takes a literal int argument where another call passes a variable (numba compiles one
specialization per literal: ``first = np.int64(0)``).
Issue 32: the image terms (:func:`_complementary_stress` and all below it: the quadrature,
the table, the closed forms of :mod:`.vertical3d`) and the tracing of a source's triples
(:func:`_source_state`) are held by the record as first-class functions (``image_terms``,
``source_tracer``: :func:`with_image_terms`, :mod:`hmatddm.kernels.held_function`) and
called through their addresses, so that each is compiled once, not again in each compiled
caller: the operator's ``traction_block``, the stress at points (:mod:`.stress3d`,
:func:`element_stress_traced`), the drivers' generic ``stress_block`` and numba's own
compiles of the per-kind functions that the drivers inline (they were six copies of the
image terms; the cold compile of the layered 3D entry points 126 -> 96 s of CPU, RESULTS.md).
Then the stress at a point (:mod:`.stress_terms3d`, ``point_stress``) and the vertical
closed forms (:func:`_vertical_terms`, ``vertical_terms``) are held the same way, the
functions only compiled code calls have no CPython or C wrapper, and the record (29
arrays), the workspace (69) and a source's state (16) are passed to inlined functions as
seldom as possible: numba takes and drops a reference on every array of such an aggregate
each time it is copied or passed to an inlined function, code that LLVM optimises in every
caller (``traction_block`` was 77k lines of IR for 3900 reference counts; the cold compile
0.73-0.85x of the CPU before, RESULTS.md, issue 32 continued). The workspace is stashed
in one buffer (:mod:`.workspace3d`: one reference a copy, not 69; RESULTS.md, twelfth session).
A record built otherwise than by :func:`.influence3d.influence_data` needs
:func:`with_image_terms` before a compiled function takes it.
``benchmarks/bench_layered3d_compile.py`` measures it.
"""
import math
from typing import NamedTuple

import numpy as np
from numba import njit, typeof, types

from ..kernels import rectangle3d
from ..kernels.drivers import KernelKind, _hold, register_kind
from ..kernels.held_function import HeldFunction, address_of, dereference, held_record, held_signature, item
from . import okada3d
from .okada_point3d import point_form_terms, point_setup
from .image_points3d import image_point_displacement, image_point_stress, kelvin_point_displacement, kelvin_point_stress
from .images2d import _lame
from .image_tracer3d import _traced_buffer, trace, trace_points
from .source_traces3d import three_heights, traced_slot
from .workspace3d import _make_workspace, workspace, workspace_arrays
from .stress_terms3d import _stress_traced, element_stress_traced
from .near_table3d import near_rule_stress
from .remainder_rows3d import remainder_rule
from .remainder_table3d import rectangle_covered, remainder_rectangle_stress
from .potentials3d import Workspace, base_derivatives, inverse_distance_derivatives, inverse_distance_scratch
from .vertical3d import _vertical_stress
from .rectangle_quadrature import (FAR_TOL, _image_order, _integrate, far_order, image_rectangle_stress,
                                   image_rectangle_stress_without, mirror_distance, one_square_order,
                                   nearest_singularity, square_rule, subdivisions)

__all__ = ["LayeredRectangles", "with_image_terms", "workspace", "source_state", "element_traction", "element_stress", "element_stress_traced",
           # re-exported from the parts (module docstring)
           "base_derivatives", "inverse_distance_derivatives", "inverse_distance_scratch", "Workspace", "trace", "trace_points",
           "kelvin_point_stress", "image_point_stress", "kelvin_point_displacement", "image_point_displacement",
           "square_rule", "nearest_singularity", "subdivisions", "FAR_TOL", "far_order", "image_rectangle_stress"]


#: Gauss points per side from which a vertical source's near triples are taken in closed
#: form (:mod:`.vertical3d`) rather than by the one-square rule (sub-squares: always).
VERTICAL_FROM = 4


class LayeredRectangles(NamedTuple):
    """Kernel data of constant rectangles in a layered medium (the record
    :mod:`hmatddm.kernels.drivers` take; built by
    :func:`hmatddm.layered.influence3d.influence_data`). No translation invariance is
    assumed anywhere: every entry is computed from both elements' absolute positions."""

    centers: np.ndarray  #: (N, 3) element centres
    frames: np.ndarray  #: (N, 3, 3) rows: e1, e2, normal e1 x e2
    half_a: np.ndarray  #: (N,) half sides along e1
    half_b: np.ndarray  #: (N,) half sides along e2
    layer: np.ndarray  #: (N,) int64 layer of each element
    interfaces: np.ndarray  #: (L - 1,) interface heights (z), top down
    shear_modulus: np.ndarray  #: (L,) per layer (0: void)
    poisson_ratio: np.ndarray  #: (L,) per layer
    n_images: int  #: reflections per interface (ref. Fig. 3.4)
    gauss_points: int  #: Gauss-Legendre points per side of a sub-square near images (fewer far away: :func:`far_order`)
    max_subdivisions: int  #: largest number of sub-squares per side (:func:`subdivisions`)
    singular_shift: float  #: see :mod:`hmatddm.kernels.drivers` (singular points)
    near_fraction: float  #: near-miss distance, fraction of the smaller half size
    alpha: float  #: ref. Eq. 6.11 scaling (0: none)
    self_max: np.ndarray  #: (N,) largest |entry| of each self block (ref. Eq. 6.11)
    far_tol: float = FAR_TOL  #: error allowed to :func:`far_order` (0: ``gauss_points`` everywhere)
    entry_tol: float = 0.0  #: image error allowed relative to the largest entry (:func:`entry_order`; 0: off)
    entry_scale: float = 0.0  #: the largest entry's scale (:func:`entry_scale`) over the largest shear modulus
    table: object = None  #: the :class:`.remainder_table3d.RemainderTable` (never None once built by influence_data)
    closed_form: np.ndarray = None  #: (N,) bool: the source's images in closed form (a half-space, :mod:`.okada3d`)
    okada: np.ndarray = None  #: (N, 3, 3) rows strike, up-dip, normal of each closed-form element (:mod:`.okada3d`)
    okada_half: np.ndarray = None  #: (N, 2) half sides along the strike and the dip
    surface: float = 0.0  #: height of the free surface (closed-form elements, ``surface_form`` elements)
    #: (N,) bool: the source's reflection in the free surface in closed form (two or more
    #: solid layers, :func:`.influence3d.surface_form`)
    surface_form: np.ndarray = None
    #: (N,) bool: a vertical source whose near triples are in closed form next to it (:mod:`.vertical3d`)
    vertical_form: np.ndarray = None
    #: (N,) bool: a half-space source with no horizontal side, whose image and surface terms
    #: are Okada's point source at the quadrature's points (:mod:`.okada_point3d`; ``okada``
    #: holds its :func:`.okada_point3d.point_frame`)
    point_form: np.ndarray = None
    #: :func:`_complementary_stress` held as a first-class function (:func:`with_image_terms`;
    #: compiled once for every caller, not linked into each)
    image_terms: object = None
    #: :func:`_source_state` held the same way (the tracer it calls compiled once)
    source_tracer: object = None
    #: :func:`.stress_terms3d._stress_traced`, the stress at a point, held the same way
    #: (:func:`element_stress_traced`)
    point_stress: object = None
    #: :func:`_vertical_terms`, the closed forms of a vertical source, held the same way
    #: (an argument of ``image_terms``)
    vertical_terms: object = None
    #: :func:`.workspace3d._make_workspace` (:func:`workspace`) held the same way
    workspace_maker: object = None


def with_image_terms(data):
    """``data`` with its ``image_terms``, ``source_tracer``, ``point_stress``,
    ``vertical_terms`` and ``workspace_maker``: :func:`_complementary_stress`,
    :func:`_source_state`, :func:`.stress_terms3d._stress_traced`, :func:`_vertical_terms`
    and :func:`.workspace3d._make_workspace` held as first-class
    functions (:class:`hmatddm.kernels.held_function.HeldFunction`), so that each is compiled
    once, not again in every compiled caller (module docstring, compile cost)."""
    core = data._replace(image_terms=None, source_tracer=None, point_stress=None, vertical_terms=None,
                         workspace_maker=None)
    return data._replace(image_terms=HeldFunction(_complementary_stress, core, _image_term_types),
                         source_tracer=HeldFunction(_source_state, core, _source_state_types),
                         point_stress=HeldFunction(_stress_traced, core, _point_stress_types),
                         vertical_terms=HeldFunction(_vertical_terms, core, _vertical_term_types),
                         workspace_maker=HeldFunction(_make_workspace, core, _workspace_types))


def _state_type():
    """The numba type of :func:`source_state`'s tuple."""
    traced = typeof(_traced_buffer.py_func(1, 1, 1))
    return types.Tuple((traced, types.Array(types.boolean, 1, "C"), types.boolean, traced,
                        types.Array(types.float64, 1, "C")))


def _source_state_types(data):
    """The numba types of :func:`_source_state`'s result and arguments after the record."""
    return _state_type(), (types.int64, types.CPointer(typeof(workspace_arrays.py_func(data))))


def _vertical_term_types(data):
    """The numba types of :func:`_vertical_terms`'s result and arguments after the record:
    the point, its layer, the source, :func:`source_state`'s tuple, :func:`workspace`'s
    tuple, the entry tolerance and the stress."""
    return types.boolean, (types.Array(types.float64, 1, "C"), types.int64, types.int64,
                           types.CPointer(_state_type()), types.CPointer(typeof(workspace_arrays.py_func(data))),
                           types.float64, types.Array(types.float64, 3, "C"))


def _workspace_types(data):
    """The numba types of :func:`.workspace3d._make_workspace`'s result (the stashed
    :func:`workspace`) and arguments after the record (none)."""
    return types.Tuple((types.Array(types.uint8, 1, "C"), types.CPointer(typeof(workspace_arrays.py_func(data))))), ()


def _held_type(data, types_of):
    """The numba type of a record's held function whose :class:`HeldFunction` takes
    ``types_of`` (``data``: the record without its function fields)."""
    return types.FunctionType(held_signature(types_of, data))


def _image_term_types(data):
    """The numba types of :func:`_complementary_stress`'s result and arguments after the
    record: those of :func:`_vertical_terms` and the held :func:`_vertical_terms`."""
    return types.none, _vertical_term_types(data)[1] + (_held_type(data, _vertical_term_types),)


def _point_stress_types(data):
    """The numba types of :func:`.stress_terms3d._stress_traced`'s result and arguments
    after the record: the point, its layer, the source, :func:`source_state`'s tuple,
    :func:`workspace`'s tuple, the held image terms (``image_terms``) and the stress."""
    return types.none, (types.Array(types.float64, 1, "C"), types.int64, types.int64, types.CPointer(_state_type()),
                        types.CPointer(typeof(workspace_arrays.py_func(data))), _held_type(data, _image_term_types),
                        _held_type(data, _vertical_term_types), types.Array(types.float64, 3, "C"))


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)  # compiled callers only
def source_state(data, j, work):
    """What the receivers of source ``j`` share: room for the image triples at the points
    of the cached rules, traced when a receiver first needs a rule, and whether they are
    the near triples only (the source's layer has a tabulated remainder), and, for a
    ``vertical_form`` source, those triples traced at its bottom, middle and top heights
    (:func:`.vertical3d.vertical_image_stress`). A source whose images are in closed form
    (``closed_form``) or by Okada's point source (``point_form``) traces nothing: its state
    is the workspace's (:func:`_untraced_state`). :func:`_source_state` through
    ``data.source_tracer`` (:func:`with_image_terms`)."""
    return data.source_tracer(held_record(data), np.int64(j), work[1])


@njit(cache=True, no_cpython_wrapper=True)  # held: called through its C wrapper only
def _source_state(data_at, j, work_at):
    """:func:`source_state` (held by the record: the tracer compiled once), the record and
    the workspace as pointers."""
    data = dereference(data_at)
    room = item(work_at, 6)
    start = item(work_at, 7)[3]
    ls = data.layer[j]
    near_only = data.table.pair_index[ls].max() >= 0
    if data.closed_form[j] or data.point_form[j]:
        # the workspace's arrays: nothing allocated a source (16 arrays a source made the
        # half-space's H-matrix rows cost as much again as their entries)
        traced, is_traced, three, heights = item(work_at, 13)
        if data.point_form[j]:
            point_setup(data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], data.okada[j], data.surface,
                        data.shear_modulus[ls], data.poisson_ratio[ls], heights)
        return traced, is_traced, near_only, three, heights
    cap, n_orders = max(room[ls, 0], 1), max(room[ls, 1], 1)
    three, heights = three_heights(data, j, near_only, cap, n_orders)
    return (_traced_buffer(start[-1], cap, n_orders), np.zeros(start.shape[0] - 1, dtype=np.bool_), near_only,
            three, heights)


@njit(cache=True)
def element_traction(data, i, j, state, work, block):
    """``block`` (3, 3): traction at the centre of element ``i`` (its normal) for a unit
    global DD of rectangle ``j``: closed form of the source layer's material (with the
    closed-form kernel's singular and near-miss handling) plus images
    (:func:`_complementary_stress`, the source's traced triples reused across receivers, the
    Gauss order of an entry: :func:`_image_order` with ``entry_tol``). In a half-space, a
    source with a horizontal side (``closed_form``) takes its image and surface terms in
    closed form instead (:func:`.okada3d.okada_traction`, Okada 1992), whatever the number
    of images (the closed form is the exact half-space). With two or more solid layers, a
    ``surface_form`` source adds its reflection in the free surface the same way for
    receivers of its layer (and the quadrature leaves it out)."""
    work_at = work[1]  # the stashed arrays (workspace), one by one
    local, image, okada_work, corners = item(work_at, 0), item(work_at, 1), item(work_at, 8), item(work_at, 9)
    g = data.shear_modulus
    nu = data.poisson_ratio
    ls = data.layer[j]
    center = data.centers[j]
    frame = data.frames[j]
    a = data.half_a[j]
    b = data.half_b[j]
    point = data.centers[i]
    normal = data.frames[i, 2]
    near = 0.0
    if i != j:
        near = data.near_fraction * min(data.half_a[i], data.half_b[i], a, b)
    rectangle3d.traction_pair(point, normal, center, frame, a, b, g[ls], nu[ls], data.singular_shift, block, local,
                              near)
    if data.closed_form[j]:
        okada3d.okada_traction(point, normal, center, data.okada[j], data.okada_half[j, 0], data.okada_half[j, 1],
                               data.surface, g[ls], nu[ls], False, True, okada_work, corners, block)
    elif data.point_form[j]:
        point_form_terms(data, point, data.layer[i], j, state[4], item(work_at, 7), okada_work,
                         data.entry_tol * data.entry_scale, normal, block, True)
    elif data.interfaces.shape[0] > 0:
        lr = data.layer[i]
        if data.surface_form[j] and lr == ls:
            okada3d.okada_traction(point, normal, center, data.okada[j], data.okada_half[j, 0], data.okada_half[j, 1],
                                   data.surface, g[ls], nu[ls], False, True, okada_work, corners, block)
        # the held image terms (with_image_terms), the point copied to the workspace (any
        # layout): called here, not through an inlined helper taking the record, the state
        # and the workspace (numba takes and drops a reference to each of their arrays per
        # inlined function they are passed to: code that LLVM optimises in every caller)
        here = item(work_at, 12)
        for k in range(3):
            here[k] = point[k]
        data.image_terms(held_record(data), here, np.int64(lr), np.int64(j), address_of(state), work_at,
                         np.float64(data.entry_tol * data.entry_scale), image, data.vertical_terms)
        for p in range(3):
            for q in range(3):
                block[p, q] += image[q, p, 0] * normal[0] + image[q, p, 1] * normal[1] + image[q, p, 2] * normal[2]


@njit(cache=True, no_cpython_wrapper=True)  # held: called through its C wrapper only
def _complementary_stress(data_at, point, lr, j, state_at, work_at, entry_tol, image, vertical_terms):
    """``image[q, i, k]``: the complementary (image) stress at ``point`` (in layer ``lr``)
    of a unit global DD ``q`` of rectangle ``j`` (interfaces present, not ``closed_form``),
    what :func:`element_traction` and :func:`element_stress_traced` share: the quadrature
    of the source's triples (``state``: traced once per source, reused across receivers;
    :func:`_image_order`, ``entry_tol``: the error allowed relative to the largest entry,
    0 for the relative rule of :func:`far_order` alone). With a tabulated remainder
    (:mod:`.remainder_table3d`) the quadrature takes the near triples only and the table
    the rest; a receiver outside the table's range takes every triple by quadrature. A
    ``surface_form`` source's reflection in the free surface is left out for receivers of
    its layer (the caller adds it in closed form), and the quadrature does not refine for
    it. A ``vertical_form`` source (a vertical rectangle, interfaces between solids) takes
    its triples in closed form (:func:`.vertical3d.vertical_image_stress`) where the
    quadrature would need sub-squares or :data:`VERTICAL_FROM` points per side, the
    quadrature elsewhere (``vertical_terms``: the record's held :func:`_vertical_terms`). The
    record, the state and the workspace come as pointers
    (:func:`hmatddm.kernels.held_function.address_of`)."""
    data, state = dereference(data_at), dereference(state_at)
    traced, is_traced, near_only, three, heights = state
    # the workspace's arrays one by one (held_function.item: not all 69 loaded and released)
    local, gradient, kelvin = item(work_at, 0), item(work_at, 2), item(work_at, 3)
    ws1, ws, rules, uniform = item(work_at, 4), item(work_at, 5), item(work_at, 7), item(work_at, 11)
    xi, eta, wt, start = rules
    g = data.shear_modulus
    nu = data.poisson_ratio
    interfaces = data.interfaces
    table = data.table
    ls = data.layer[j]
    g_s, lame_s = g[ls], _lame(g[ls], nu[ls])
    center, frame, a, b = data.centers[j], data.frames[j], data.half_a[j], data.half_b[j]
    image[:] = 0.0
    tabulated = near_only and rectangle_covered(table, point, lr, center, frame, a, b, ls)
    rows, fused = item(work_at, 14), False  # the remainder's rule and rows (.remainder_rows3d)
    lo_r, hi_r, entry = (remainder_rule(table, rows, j, point, lr, center, frame, a, b, ls, data.gauss_points,
                                        data.far_tol, entry_tol, xi, eta, start) if tabulated else (0, 0, -1))
    # the reflection in the free surface in closed form: the quadrature neither takes it
    # nor refines for its singular point (the receiver's mirror in the surface)
    surface_form = data.surface_form[j]
    skip = ls - 1 if surface_form and lr == ls else -1
    if near_only and not tabulated and table.pair_index[ls, lr] >= 0:
        # outside the table's range: every triple by quadrature
        n_gauss, n_sub = _image_order(point, lr, center, frame, a, b, ls, interfaces, data.gauss_points,
                                      data.max_subdivisions, data.far_tol, entry_tol, skip)
        image_rectangle_stress_without(point, lr, center, frame, a, b, ls, interfaces, g, nu, data.n_images, n_gauss,
                                       n_sub, image, False, table.bottoms, table.tops, surface_form, data.surface)
    elif not (tabulated and abs(lr - ls) >= 2):  # two layers apart, every triple is far
        n_gauss, n_sub = _image_order(point, lr, center, frame, a, b, ls, interfaces, data.gauss_points,
                                      data.max_subdivisions, data.far_tol, entry_tol, skip)
        closed = False
        if data.vertical_form[j] and (n_sub > 1 or n_gauss >= VERTICAL_FROM):
            # next to the images: every triple traced at three heights, in closed form
            closed = vertical_terms(data_at, point, lr, j, state_at, work_at, entry_tol, image)
            if closed and lr != ls:  # minus the whole space of the source's material
                rectangle3d.stress_pair(point, center, frame, a, b, g[ls], nu[ls], 0.0, uniform, local, 0.0)
                for q in range(3):
                    for p in range(3):
                        for kk in range(3):
                            image[q, p, kk] -= uniform[q, p, kk]
        near = table.near
        if not closed and tabulated and near.ready[ls, lr]:
            # the near triples tabulated in one angle (.near_table3d), the surface's group left out when skipped
            first, every = np.int64(1 if 0 <= skip == ls - 1 else 0), np.int64(2)  # no literals: one signature
            if n_sub == 1 and lr == ls:
                for side in range(first, 2):
                    k = ls - 1 if side == 0 else ls
                    if near.group[ls, lr, side] < 0:
                        continue
                    n = one_square_order(mirror_distance(point, interfaces[k], center, frame, a, b), a, b,
                                         data.gauss_points, data.far_tol, entry_tol)
                    # the remainder added at the same points when its rule is this one (one turn a point)
                    with_rows = entry if not fused and start[n - 1] == lo_r and start[n] == hi_r else -1
                    fused = fused or with_rows >= 0
                    near_rule_stress(data_at, work_at, point, lr, center, frame, a, b, ls, g_s, lame_s, xi, eta, wt,
                                     start[n - 1], start[n], side, side + 1, with_rows, image)
            elif n_sub <= 2:
                slot = n_gauss - 1 if n_sub == 1 else data.gauss_points
                with_rows = entry if start[slot] == lo_r and start[slot + 1] == hi_r else -1
                fused = with_rows >= 0
                near_rule_stress(data_at, work_at, point, lr, center, frame, a, b, ls, g_s, lame_s, xi, eta, wt,
                                 start[slot], start[slot + 1], first, every, with_rows, image)
            else:
                sub_xi, sub_eta, sub_wt = square_rule(n_gauss, n_sub)
                near_rule_stress(data_at, work_at, point, lr, center, frame, a, b, ls, g_s, lame_s, sub_xi, sub_eta,
                                 sub_wt, np.int64(0), np.int64(sub_xi.shape[0]), first, every, np.int64(-1), image)
        elif not closed and n_sub == 1 and tabulated and lr == ls:
            # with the rest tabulated, the near triples of the receiver's own layer are its
            # first reflections in the layer's top (above it) and bottom (below it): each
            # takes the rule of its own mirror, not both the nearer one's
            bottom, top = table.bottoms[ls], table.tops[ls]
            split = 0.5 * (bottom + top) if math.isfinite(bottom + top) else (top if math.isfinite(top) else bottom)
            for side in range(2):
                k = ls - 1 if side == 0 else ls
                if k < 0 or k >= interfaces.shape[0] or k == skip:
                    continue
                n = one_square_order(mirror_distance(point, interfaces[k], center, frame, a, b), a, b,
                                     data.gauss_points, data.far_tol, entry_tol)
                lo, hi = traced_slot(data, j, n - 1, state, rules)
                _integrate(point, lr, center, frame, a, b, ls, g, nu, xi[lo:hi], eta[lo:hi], wt[lo:hi], traced, lo,
                           image, gradient, ws, ws1, kelvin, split if side == 0 else -np.inf,
                           np.inf if side == 0 else split)
        elif not closed and n_sub <= 2:
            slot = n_gauss - 1 if n_sub == 1 else data.gauss_points
            lo, hi = traced_slot(data, j, slot, state, rules)
            _integrate(point, lr, center, frame, a, b, ls, g, nu, xi[lo:hi], eta[lo:hi], wt[lo:hi], traced, lo,
                       image, gradient, ws, ws1, kelvin, -np.inf, np.inf)
        elif not closed:
            image_rectangle_stress_without(point, lr, center, frame, a, b, ls, interfaces, g, nu, data.n_images,
                                           n_gauss, n_sub, image, near_only, table.bottoms, table.tops, surface_form,
                                           data.surface)
    if tabulated and not fused and entry >= 0:  # the remainder alone at its points, through the rows
        near_rule_stress(data_at, work_at, point, lr, center, frame, a, b, ls, g_s, lame_s, xi, eta, wt, lo_r, hi_r,
                         np.int64(0), np.int64(0), entry, image)
    elif tabulated and not fused:
        remainder_rectangle_stress(table, point, lr, center, frame, a, b, ls, g_s, lame_s, xi[lo_r:hi_r],
                                   eta[lo_r:hi_r], wt[lo_r:hi_r], image)


@njit(cache=True, no_cpython_wrapper=True)  # held: called through its C wrapper only
def _vertical_terms(data_at, point, lr, j, state_at, work_at, entry_tol, image):
    """:func:`.vertical3d.vertical_image_stress` of the ``vertical_form`` source ``j`` at
    ``point`` (layer ``lr``), its triples traced at three heights in the source's state
    (held by the record, ``vertical_terms``, and called by :func:`_complementary_stress`:
    the closed forms compiled once, not again in the image terms' library). The record, the
    state and the workspace as pointers."""
    data, state = dereference(data_at), dereference(state_at)
    return _vertical_stress(point, lr, data.centers[j], data.okada[j, 0], data.okada_half[j, 0], data.okada_half[j, 1],
                            state[4], state[3], data.shear_modulus, data.poisson_ratio, data.layer[j], data.far_tol,
                            entry_tol, item(work_at, 10), image)


@njit(cache=True)
def element_stress(data, point, point_layer, j, work, out):
    """:func:`element_stress_traced` for one point (the registered per-pair function of
    :func:`hmatddm.kernels.drivers.stress_block`, which has no source state: the source's
    triples are traced for this point alone; :mod:`.stress3d` traces them once per source).
    The state is held to the end: the inlined :func:`element_stress_traced` passes it by
    pointer, and numba would release a temporary after its last use, before the call."""
    owner = data.source_tracer(held_record(data), np.int64(j), work[1])
    element_stress_traced(data, point, point_layer, j, owner, work, out)
    _hold(owner)


register_kind(LayeredRectangles, KernelKind(workspace, source_state, element_traction, element_stress,
                                            rectangle3d.edge_distance))
