"""One set of drivers for every element kernel: influence blocks, the dense matrix, the
singular-pair test and the stress at points (ref. Eqs 2.47, 2.57-2.59).

What differs between 2D and 3D, constant and higher-order elements, a homogeneous and a
layered medium is the influence of ONE source element at ONE receiver; that lives with
each kind of element (:mod:`.line2d`, :mod:`.rectangle3d`, :mod:`.line2d_higher_order`,
:mod:`hmatddm.layered.images2d`, :mod:`hmatddm.layered.higher_order2d`). The loops over
element pairs, the reference's scaling of blocks larger than the self-influence
(ref. Eq. 6.11) and the parallel assembly live here, once.

Kernel data are flat records (``typing.NamedTuple``, read by field name inside numba),
one class per kind of element. Every
record has the fields

* ``centers`` (N, dim): element centres;
* ``singular_shift`` (float): 0 -- a collocation point on an element edge (a segment
  end in 2D) gives NaN (the operator refuses the mesh); > 0 -- the point is moved onto
  the edge and the influence is the mean at two points ``+- singular_shift`` half sizes
  across it (ref. Sec. 6.2.3);
* ``near_fraction`` (float): a point closer than this fraction of the smaller half size
  to an edge of another element counts as on it (a near-miss junction;
  :data:`hmatddm.elasticity.operator.NEAR_SINGULAR_FRACTION`);
* ``alpha`` (float): > 0 -- blocks whose largest entry exceeds ``alpha`` times the
  largest entry of the source's self block are scaled down to it (ref. Eq. 6.11);
  0 -- no scaling;
* ``self_max`` (N,): the largest |entry| of each element's self block (zeros when
  ``alpha == 0``),

plus its own geometry and material (:func:`kernel_record` makes the classes). Element
``e`` owns unknowns ``d e .. d e + d - 1`` (docs/conventions.md §2), ``d`` =
:func:`element_unknowns`: the dimension (the frames' size) times the nodes per element
(the length of a ``nodes`` field; one without it). A kind of element registers five
``@njit`` functions, each taking its record first (:class:`KernelKind`,
:func:`register_kind`):

``workspace(data) -> tuple``
    Scratch arrays, allocated once per driver call (and per thread).
``source_state(data, j, work)``
    What the receivers of source ``j`` share (the layered kernels' traced image pairs);
    ``0`` when nothing.
``element_traction(data, i, j, state, work, block)``
    ``block`` (d, d): traction component ``p`` at the collocation point(s) of receiver
    ``i`` (with its normal) for a unit global DD unknown ``q`` of source ``j``, singular
    and near-singular points handled as the record says, without the Eq. 6.11 scaling.
``element_stress(data, point, point_layer, j, work, out)``
    ``out`` (d, dim, dim): global stress at ``point`` (in layer ``point_layer``; 0 in a
    homogeneous medium) for each unit DD unknown of source ``j``; a point within
    ``near_fraction`` half sizes of an edge of ``j`` counts as on it.
``edge_distance(data, i, j) -> float``
    Distance from the collocation point(s) of ``i`` to the nearest edge (end) of ``j``.

Compiled entry points are few on purpose, as each one compiles (and LLVM optimises) the
whole per-pair kernel it calls again: per record type only :func:`traction_block` (the
H-matrix's block generator, with exactly the signature the H-matrix build calls it with),
:func:`stress_block` and :func:`edge_distance`. The dense matrix, the stress at many
points and the singular-pair test call those two from Python (in parallel on numba's
thread count where it pays: the compiled drivers release the GIL); the self-block maxima
call :func:`traction_block` through a pointer from a small compiled loop (the kernel is not
compiled again). Inside an entry point the per-pair function is inlined into the one loop
nest (no njit helper level between them: each such level would optimise the kernel once
more); a kind whose per-pair function is large holds its heaviest parts in its record
as first-class functions (:mod:`.held_function`, the 3D layered kernel), so that they are
compiled once, not again in each entry point (nor in numba's own compile of each per-kind
function the drivers inline). The loops over pairs read :func:`borrowed` arrays: numba's
reference counts are atomic operations, and a pair's reads of the record would otherwise
pay a dozen.
The drivers are cached on disk (``cache=True``); the cache of a driver does not notice
edits in a kind's module: delete ``hmatddm/**/__pycache__/*.nbi|*.nbc`` after changing a
kernel.

Over 500 lines: the registry of element kinds and every driver over element
pairs (blocks, dense matrix, singular pairs, stress at points, serial and parallel) in
one place, so that each kind writes only its per-pair functions; about 110 lines are this
contract's documentation.
"""
import inspect
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic, overload
from numba.np.arrayobj import make_array

from . import compile_collector
from .correction import scale_to_self

compile_collector.install()  # the collector off the old heap while numba compiles (issue 32)

#: The fields every kernel record has, after its geometry and material: (name, type,
#: description) as :func:`kernel_record` takes them.
COMMON_FIELDS = (
    ("singular_shift", float, "see :mod:`hmatddm.kernels.drivers` (singular points)"),
    ("near_fraction", float, "near-miss distance, fraction of the smaller half size"),
    ("alpha", float, "ref. Eq. 6.11 scaling (0: none)"),
    ("self_max", np.ndarray, "(N,) largest |entry| of each self block (ref. Eq. 6.11)"),
)
#: The material fields of a homogeneous medium.
HOMOGENEOUS_FIELDS = (("shear_modulus", float, "G (Pa)"), ("poisson_ratio", float, "nu"))


def kernel_record(name, module, summary, fields, extra=()):
    """A kernel data record class (``typing.NamedTuple``) named ``name``, defined in
    ``module`` (pass ``__name__``; assign it there to the same name): its ``fields``
    (geometry and material), then :data:`COMMON_FIELDS`, then ``extra``, each a
    ``(name, type, description)``; the docstring is ``summary`` and the field list."""
    every = (*fields, *COMMON_FIELDS, *extra)
    record = NamedTuple(name, [(field, kind) for field, kind, _ in every])
    record.__module__ = module
    record.__doc__ = summary + "\n\nFields:\n\n" + "\n".join(f"* ``{field}``: {text}" for field, _, text in every)
    return record


@dataclass(frozen=True)
class KernelKind:
    """The five per-element functions of one kind of kernel data (see the module docstring)."""

    workspace: object
    source_state: object
    element_traction: object
    element_stress: object
    edge_distance: object


_KINDS = {}


def register_kind(record_class, kind):
    """Make the drivers serve kernel data of type ``record_class`` (a NamedTuple class)
    with the functions of ``kind`` (a :class:`KernelKind`)."""
    _KINDS[record_class] = kind


def kind_of(data):
    """The :class:`KernelKind` registered for ``data`` (a record instance or its numba type)."""
    record_class = getattr(data, "instance_class", type(data))
    kind = _KINDS.get(record_class)
    if kind is None:
        raise TypeError(f"no kernel kind is registered for {record_class.__name__} (see hmatddm.kernels.drivers)")
    return kind


@njit(cache=True)
def no_source_state(data, j, work):
    """The ``source_state`` of kinds whose receivers share nothing about a source."""
    return 0


def element_unknowns(data):
    """Unknowns per element of ``data``'s kind: the dimension (the frames' size) times
    the nodes per element (a ``nodes`` field's length; one without it)."""
    kind_of(data)
    return int(data.frames.shape[1]) * (len(data.nodes) if hasattr(data, "nodes") else 1)


@overload(element_unknowns, inline="always")
def _overload_unknowns(data):
    kind_of(data)
    if "nodes" in data.fields:
        return lambda data: data.frames.shape[1] * data.nodes.shape[0]
    return lambda data: data.frames.shape[1]


def _per_kind(stub):
    """The function of :class:`KernelKind` named as ``stub`` (less its underscore), called
    for ``data``'s kind: plain Python for Python callers; inside numba the kind's function
    is compiled in place (inlined), resolved by the record type. ``stub`` gives the
    signature (the kinds' functions use the same argument names) and the docstring."""
    name = stub.__name__.lstrip("_")

    def function(data, *args):
        return getattr(kind_of(data), name)(data, *args)

    def resolve(data, *args):
        return getattr(kind_of(data), name).py_func

    function.__signature__ = resolve.__signature__ = inspect.signature(stub)
    function.__name__, function.__qualname__, function.__doc__ = stub.__name__, stub.__qualname__, stub.__doc__
    # numba compiles the implementation on its own too before inlining it, only to type it:
    # never called, from Python or compiled code (no CPython or C wrapper, each of which
    # unboxes or passes every field of the record, a large part of a small function's
    # compile), so left unoptimised by LLVM (``optnone``; its callees are compiled as usual):
    # numba's reference counts of a large record made a layered kernel's per-pair function
    # 20-30k lines that LLVM optimised for nothing (benchmarks/RESULTS.md, issue 32)
    overload(function, inline="always",
             jit_options=dict(no_cpython_wrapper=True, no_cfunc_wrapper=True, _dbg_optnone=True))(resolve)
    return function


@_per_kind
def _workspace(data):
    """Scratch arrays of ``data``'s kind."""


@_per_kind
def _source_state(data, j, work):
    """What the receivers of source ``j`` share."""


@_per_kind
def _element_traction(data, i, j, state, work, block):
    """``block`` (d, d): the unscaled block of receiver ``i`` and source ``j``."""


@_per_kind
def _element_stress(data, point, point_layer, j, work, out):
    """``out`` (d, dim, dim): stress at ``point`` per unit DD unknown of source ``j``."""


@_per_kind
def _edge_distance(data, i, j):
    """Distance from the collocation point(s) of ``i`` to the nearest edge of ``j``."""


# -- the compiled drivers ------------------------------------------------------------------
def _without_reference_count(context, builder, kind, value):
    """``value`` of numba type ``kind`` with the meminfo of every array in it (through
    tuples and records) set to null."""
    if isinstance(kind, types.Array):
        array = make_array(kind)(context, builder, value=value)
        array.meminfo = cgutils.get_null_value(array.meminfo.type)
        return array._getvalue()
    if isinstance(kind, types.BaseTuple):
        for k, item in enumerate(kind.types):
            stripped = _without_reference_count(context, builder, item, builder.extract_value(value, k))
            value = builder.insert_value(value, stripped, k)
    return value


@intrinsic
def borrowed(typingctx, value):
    """``value`` (an array, or a tuple or record holding arrays) on the same data, without
    reference counting: numba counts references to an array with atomic instructions
    (~10 ns each here), and the per-pair code of a kind (record fields read, views such as
    ``centers[i]`` passed to a kernel function, the inlined function's arguments) made about
    twelve of them per element pair -- more time than the 2D kernel's arithmetic. numba's
    own parallel loops hand arrays to their bodies the same way (which is why the old
    ``prange`` dense assembly was faster than the same loop run serially). Only for values
    whose owner outlives every use -- a compiled function's own arguments (the caller holds
    them) -- and never returned or stored."""
    def codegen(context, builder, signature, args):
        return _without_reference_count(context, builder, signature.args[0], args[0])

    return value(value), codegen


@intrinsic
def _hold(typingctx, value):
    """Nothing, but a use of ``value``: numba releases a variable after its last use, so
    an owner of arrays that a loop reads :func:`borrowed` must be used after the loop."""
    def codegen(context, builder, signature, args):
        return context.get_dummy_value()

    return types.none(value), codegen


def _shares_source_state(data):
    """True for kinds with a ``source_state`` (blocks are filled source by source)."""
    return kind_of(data).source_state is not no_source_state


@overload(_shares_source_state, inline="always")
def _overload_shares_source_state(data):
    shares = _shares_source_state(data)
    return lambda data: shares


#: Sources whose blocks :func:`traction_block` stages (source by source): 3 cache lines a row.
STAGED_SOURCES = 8


@njit(cache=True, nogil=True)
def traction_block(data, rows, cols, out):
    """Block generator kernel (see :class:`hmatddm.hmatrix.BlockGenerator`): ``out`` of
    shape ``(d len(rows), d len(cols))`` receives ``out[d a + p, d b + q]``, the traction
    component ``p`` at the collocation point(s) of element ``rows[a]`` for a unit global
    DD unknown ``q`` of element ``cols[b]``, scaled by ref. Eq. 6.11 when ``alpha > 0``
    (off the diagonal). Called with int64 ``rows``, ``cols`` and a C-contiguous float64
    ``out`` everywhere (one compiled version per record type).

    Receiver by receiver, or source by source for kinds with a ``source_state`` (made
    once per source); the choice is a constant of the record type, so LLVM keeps one of
    the two loop orders. One loop nest with the per-pair function inlined once: the
    kernel is compiled (and optimised) here only, not again in helper levels. Source by
    source, :data:`STAGED_SOURCES` sources' columns are staged, then copied row by row: each
    pair's ``dof`` rows lie a row of ``out`` apart (0.05 us of a 0.45 us pair in a dense
    half-space matrix, benchmarks/RESULTS.md, issue 32)."""
    dof = element_unknowns(data)
    by_source = _shares_source_state(data)
    n_staged = min(STAGED_SOURCES, cols.shape[0]) if by_source else 1
    scratch = (_workspace(data), np.empty((dof, dof)), np.empty((dof * rows.shape[0] * by_source, dof * n_staged)))
    # every array borrowed (:func:`borrowed`): the caller holds the arguments, ``scratch``
    # lives until :func:`_hold` below; one by one, each copied once (numba takes and drops a
    # reference on every array of an aggregate it copies: a layered workspace's dozens)
    data_ = borrowed(data)
    rows_ = borrowed(rows)
    cols_ = borrowed(cols)
    out_ = borrowed(out)
    work, block, stage = borrowed(scratch)
    alpha = data_.alpha
    n_outer = cols_.shape[0] if by_source else rows_.shape[0]
    n_inner = rows_.shape[0] if by_source else cols_.shape[0]
    for outer in range(n_outer):
        if by_source:
            # the state's arrays borrowed in the pair loop (each pair counted references to
            # them: 10-15% of a half-space entry, benchmarks/RESULTS.md, issue 32), held below
            owner = _source_state(data_, cols_[outer], work)
            state = borrowed(owner)
        for inner in range(n_inner):
            ia = inner if by_source else outer
            jb = outer if by_source else inner
            i = rows_[ia]
            j = cols_[jb]
            if not by_source:
                state = _source_state(data_, j, work)
            _element_traction(data_, i, j, state, work, block)
            if alpha > 0.0 and i != j:
                scale_to_self(block, alpha * data_.self_max[j])
            target, column = (stage, dof * (outer % n_staged)) if by_source else (out_, dof * jb)
            for p in range(dof):
                for q in range(dof):
                    target[dof * ia + p, column + q] = block[p, q]
        if by_source:
            _hold(owner)
            if outer % n_staged == n_staged - 1 or outer == n_outer - 1:
                first = dof * (outer - outer % n_staged)
                width = dof * (outer % n_staged + 1)
                for r in range(dof * n_inner):
                    for c in range(width):
                        out_[r, first + c] = stage[r, c]
    _hold(scratch)


@njit(cache=True, nogil=True)
def stress_block(data, points, point_layer, dd, out):
    """Global stress ``out`` (M, dim, dim) at ``points`` (M, dim), in layers
    ``point_layer`` (M,) (zeros in a homogeneous medium), induced by the DD unknowns
    ``dd`` (N, d) of every element (direct sum)."""
    n = data.centers.shape[0]
    dim = points.shape[1]
    dof = element_unknowns(data)
    scratch = (_workspace(data), np.empty((dof, dim, dim)))
    # every array borrowed (:func:`borrowed`): the caller holds the arguments, ``scratch``
    # lives until :func:`_hold` below (one by one: as in traction_block)
    data_ = borrowed(data)
    points_ = borrowed(points)
    point_layer_ = borrowed(point_layer)
    dd_ = borrowed(dd)
    out_ = borrowed(out)
    work, pair = borrowed(scratch)
    for m in range(points_.shape[0]):
        acc = np.zeros((dim, dim))
        for j in range(n):
            _element_stress(data_, points_[m], point_layer_[m], j, work, pair)
            for u in range(dof):
                du = dd_[j, u]
                for a in range(dim):
                    for b in range(dim):
                        acc[a, b] += pair[u, a, b] * du
        for a in range(dim):
            for b in range(dim):
                out_[m, a, b] = acc[a, b]
    _hold(scratch)


@njit(cache=True)
def edge_distance(data, i, j):
    """Distance from the collocation point(s) of element ``i`` to the nearest edge (end)
    of element ``j`` (for error messages)."""
    return _edge_distance(data, i, j)


# -- what Python calls: the drivers above, in parallel where it pays -----------------------
def _in_parts(function, count, parts_per_thread=4):
    """``function(start, stop)`` over consecutive ranges covering ``range(count)``: on
    numba's thread count of threads (``parts_per_thread`` ranges each, for balance), or
    in one call on one thread."""
    threads = min(numba.get_num_threads(), count)
    if threads <= 1:
        if count:
            function(0, count)
        return
    bounds = np.linspace(0, count, min(count, threads * parts_per_thread) + 1).astype(np.int64)
    with ThreadPoolExecutor(max_workers=threads) as pool:
        list(pool.map(function, bounds[:-1], bounds[1:]))


def traction_matrix(data, out):
    """Dense assembly of the whole traction matrix into ``out`` (N d, N d), a C-contiguous
    float64 array: row bands of receivers on parallel threads, or column bands of sources
    for kinds with a ``source_state`` (made once per source)."""
    n = data.centers.shape[0]
    dof = element_unknowns(data)
    everything = np.arange(n, dtype=np.int64)
    if _shares_source_state(data):
        def part(start, stop):
            band = np.empty((n * dof, (stop - start) * dof))
            traction_block(data, everything, everything[start:stop], band)
            out[:, start * dof:stop * dof] = band
    else:
        def part(start, stop):
            traction_block(data, everything[start:stop], everything, out[start * dof:stop * dof])
    _in_parts(part, n)


def influence_matrix(data):
    """The dense traction matrix of kernel ``data`` (N d, N d)."""
    n = data.centers.shape[0] * element_unknowns(data)
    out = np.empty((n, n))
    traction_matrix(data, out)
    return out


def singular_pairs(data, rows, cols, out):
    """``out[k]`` = True when the block of receiver ``rows[k]`` and source ``cols[k]``
    (as :func:`traction_block` fills it) is not finite: a singular pair."""
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    dof = element_unknowns(data)
    for j in np.unique(cols):  # the pairs of one source in one call
        pairs = np.flatnonzero(cols == j)
        block = np.empty((dof * len(pairs), dof))
        traction_block(data, np.ascontiguousarray(rows[pairs]), np.array([j], dtype=np.int64), block)
        out[pairs] = ~np.all(np.isfinite(block.reshape(len(pairs), -1)), axis=1)


def _self_blocks(kernel, data, first, out):
    """:func:`self_blocks` with the block generator ``kernel`` (:func:`traction_block`)."""
    element = np.empty(1, dtype=np.int64)
    for k in range(out.shape[0]):
        element[0] = first + k
        kernel(data, element, element, out[k])


def self_blocks(data, start=0, stop=None):
    """(stop - start, d, d): the exact self block of elements ``start..stop-1`` (all by
    default), one kernel call per element.

    One compiled loop per record type that calls :func:`traction_block` as a first-class
    function (:mod:`hmatddm.compiled`, as the H-matrix build does): the kernel is
    not compiled again, and the loop is small and cached on disk."""
    from ..compiled import compiled_for_data

    stop = data.centers.shape[0] if stop is None else stop
    dof = element_unknowns(data)
    out = np.empty((stop - start, dof, dof))
    compiled_for_data(_self_blocks, data, (types.int64, types.float64[:, :, ::1]), types.none)(
        traction_block, data, start, out)
    return out


def self_block_max(data, out):
    """``out[i]`` (``out`` (N,) float64): the largest |entry| of element ``i``'s self block,
    NaN if it has one (the ``self_max`` of ref. Eq. 6.11; the Eq. 6.11 scaling never applies
    to a self block)."""
    out[:] = np.abs(self_blocks(data)).max(axis=(1, 2))


def with_self_max(data):
    """``data`` with its ``self_max`` filled in place when ``alpha > 0`` (ref. Eq. 6.11;
    records are built with zeros there)."""
    if data.alpha > 0.0:
        self_block_max(data, data.self_max)
    return data


def self_block_maxima(data):
    """(N,) :func:`self_block_max` as a new array."""
    out = np.empty(data.centers.shape[0])
    self_block_max(data, out)
    return out


def stress_at_points(data, points, point_layer, dd, out):
    """:func:`stress_block` with ``points`` (M, dim), ``point_layer`` (M,) int64, ``dd``
    (N, d) and ``out`` (M, dim, dim) C-contiguous float64 arrays, parallel over points."""
    def part(start, stop):
        stress_block(data, points[start:stop], point_layer[start:stop], dd, out[start:stop])
    _in_parts(part, len(points))


def stress_sum(data, points, dd, point_layer=None):
    """(M, dim, dim): :func:`stress_at_points` of ``dd`` (N, d) at ``points`` (M, dim)
    (``point_layer`` None: zeros, a homogeneous medium)."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    if point_layer is None:
        point_layer = np.zeros(len(points), dtype=np.int64)
    dd = np.ascontiguousarray(np.asarray(dd, dtype=np.float64).reshape(data.centers.shape[0], -1))
    out = np.zeros((len(points), points.shape[1], points.shape[1]))
    stress_at_points(data, points, np.ascontiguousarray(point_layer, dtype=np.int64), dd, out)
    return out


def finite_stress_sum(data, points, dd, point_layer, edge="element edge"):
    """:func:`stress_sum`, refusing a point where the stress is singular (on an ``edge``
    of an element: NaN without the reference's averaging) with an
    :class:`hmatddm.errors.InputError` naming it."""
    out = stress_sum(data, points, dd, point_layer)
    bad = np.flatnonzero(~np.all(np.isfinite(out.reshape(len(out), -1)), axis=1))
    if bad.size:
        from ..errors import InputError

        raise InputError(f"points[{int(bad[0])}] lies on an {edge}, where the stress is singular; move it or pass "
                         "singular_correction='average'")
    return out


__all__ = ["COMMON_FIELDS", "HOMOGENEOUS_FIELDS", "kernel_record", "KernelKind", "register_kind", "no_source_state",
           "kind_of", "element_unknowns", "borrowed", "traction_block", "stress_block", "edge_distance",
           "traction_matrix", "influence_matrix", "singular_pairs",
           "self_blocks", "self_block_max", "with_self_max", "self_block_maxima", "stress_at_points", "stress_sum",
           "finite_stress_sum"]
