"""One set of drivers for every element kernel: influence blocks, the dense matrix, the
singular-pair test and the stress at points (ref. Eqs 2.47, 2.57-2.59).

What differs between 2D and 3D, constant and higher-order elements, a homogeneous and a
layered medium is the influence of ONE source element at ONE receiver; that lives with
each kind of element (:mod:`.line2d`, :mod:`.rectangle3d`, :mod:`.line2d_higher_order`,
:mod:`hmatddm.layered.images2d`, :mod:`hmatddm.layered_higher_order`). The loops over
element pairs, the reference's scaling of blocks larger than the self-influence
(ref. Eq. 6.11) and the parallel assembly live here, once.

Kernel data are records (``typing.NamedTuple``, read by field name inside numba; flat:
numba's parallel loops take no nested tuples), one class per kind of element. Every
record has the fields

* ``centers`` (N, dim): element centres;
* ``singular_shift`` (float): 0 -- a collocation point on an element edge (a segment
  end in 2D) gives NaN (the operator refuses the mesh); > 0 -- the point is moved onto
  the edge and the influence is the mean at two points ``+- singular_shift`` half sizes
  across it (ref. Sec. 6.2.3);
* ``near_fraction`` (float): a point closer than this fraction of the smaller half size
  to an edge of another element counts as on it (a near-miss junction;
  :data:`hmatddm.operators.NEAR_SINGULAR_FRACTION`);
* ``alpha`` (float): > 0 -- blocks whose largest entry exceeds ``alpha`` times the
  largest entry of the source's self block are scaled down to it (ref. Eq. 6.11);
  0 -- no scaling;
* ``self_max`` (N,): the largest |entry| of each element's self block (zeros when
  ``alpha == 0``),

plus its own geometry and material. A kind of element registers six ``@njit`` functions,
each taking its record first (:class:`KernelKind`, :func:`register_kind`):

``unknowns(data) -> int``
    Unknowns per element ``d`` (``dim`` times the nodes per element); element ``e`` owns
    unknowns ``d e .. d e + d - 1`` (docs/conventions.md §2).
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

The drivers are compiled once per record type and cached on disk (``cache=True``). The
cache of a driver does not notice edits in a kind's module: delete
``hmatddm/**/__pycache__/*.nbi|*.nbc`` after changing a kernel.
"""
from dataclasses import dataclass
import numpy as np
from numba import njit, prange
from numba.extending import overload

from .correction import scale_to_self


@dataclass(frozen=True)
class KernelKind:
    """The six per-element functions of one kind of kernel data (see the module docstring)."""

    unknowns: object
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


# -- the per-kind hooks: plain Python for Python callers, resolved by type inside numba --
def element_unknowns(data):
    """Unknowns per element of ``data``'s kind."""
    return int(kind_of(data).unknowns(data))


def _workspace(data):
    return kind_of(data).workspace(data)


def _source_state(data, j, work):
    return kind_of(data).source_state(data, j, work)


def _element_traction(data, i, j, state, work, block):
    kind_of(data).element_traction(data, i, j, state, work, block)


def _element_stress(data, point, point_layer, j, work, out):
    kind_of(data).element_stress(data, point, point_layer, j, work, out)


def _edge_distance(data, i, j):
    return kind_of(data).edge_distance(data, i, j)


@overload(element_unknowns, inline="always")
def _overload_unknowns(data):
    function = kind_of(data).unknowns

    def impl(data):
        return function(data)
    return impl


@overload(_workspace, inline="always")
def _overload_workspace(data):
    function = kind_of(data).workspace

    def impl(data):
        return function(data)
    return impl


@overload(_source_state, inline="always")
def _overload_source_state(data, j, work):
    function = kind_of(data).source_state

    def impl(data, j, work):
        return function(data, j, work)
    return impl


@overload(_element_traction, inline="always")
def _overload_element_traction(data, i, j, state, work, block):
    function = kind_of(data).element_traction

    def impl(data, i, j, state, work, block):
        function(data, i, j, state, work, block)
    return impl


@overload(_element_stress, inline="always")
def _overload_element_stress(data, point, point_layer, j, work, out):
    function = kind_of(data).element_stress

    def impl(data, point, point_layer, j, work, out):
        function(data, point, point_layer, j, work, out)
    return impl


@overload(_edge_distance, inline="always")
def _overload_edge_distance(data, i, j):
    function = kind_of(data).edge_distance

    def impl(data, i, j):
        return function(data, i, j)
    return impl


# -- the drivers ---------------------------------------------------------------------------
@njit(cache=True)
def _fill_receiver(data, i, cols, out, row, work, block):
    """``out[row + p, d jb + q]``: the blocks of receiver ``i`` from the sources ``cols``,
    scaled by ref. Eq. 6.11 when ``alpha > 0`` (off the diagonal); for kinds whose
    receivers share nothing about a source (rows written contiguously)."""
    dof = element_unknowns(data)  # a constant of most kinds: the copy loops unroll
    alpha = data.alpha
    for jb in range(cols.shape[0]):
        j = cols[jb]
        _element_traction(data, i, j, 0, work, block)
        if alpha > 0.0 and i != j:
            scale_to_self(block, alpha * data.self_max[j])
        for p in range(dof):
            for q in range(dof):
                out[row + p, dof * jb + q] = block[p, q]


@njit(cache=True)
def _fill_source(data, j, rows, out, column, work, block):
    """``out[d ia + p, column + q]``: the blocks of source ``j`` at the receivers ``rows``
    (its ``source_state`` made once), scaled as :func:`_fill_receiver`."""
    state = _source_state(data, j, work)
    dof = element_unknowns(data)
    alpha = data.alpha
    for ia in range(rows.shape[0]):
        i = rows[ia]
        _element_traction(data, i, j, state, work, block)
        if alpha > 0.0 and i != j:
            scale_to_self(block, alpha * data.self_max[j])
        for p in range(dof):
            for q in range(dof):
                out[dof * ia + p, column + q] = block[p, q]


def _fill_block(data, rows, cols, out, work, block):
    """``rows`` x ``cols`` into ``out``: receiver by receiver, or source by source for
    kinds with a ``source_state`` (numba picks the loop by the record type)."""


def _fill_matrix_part(data, k, everything, out, work, block):
    """Part ``k`` of the dense matrix: the rows of receiver ``k``, or the columns of
    source ``k`` for kinds with a ``source_state``."""


def _shares_source_state(data):
    return kind_of(data).source_state is not no_source_state


@overload(_fill_block)
def _overload_fill_block(data, rows, cols, out, work, block):
    if _shares_source_state(data):
        def impl(data, rows, cols, out, work, block):
            dof = block.shape[0]
            for jb in range(cols.shape[0]):
                _fill_source(data, cols[jb], rows, out, dof * jb, work, block)
    else:
        def impl(data, rows, cols, out, work, block):
            dof = block.shape[0]
            for ia in range(rows.shape[0]):
                _fill_receiver(data, rows[ia], cols, out, dof * ia, work, block)
    return impl


@overload(_fill_matrix_part)
def _overload_fill_matrix_part(data, k, everything, out, work, block):
    if _shares_source_state(data):
        def impl(data, k, everything, out, work, block):
            _fill_source(data, k, everything, out, block.shape[0] * k, work, block)
    else:
        def impl(data, k, everything, out, work, block):
            _fill_receiver(data, k, everything, out, block.shape[0] * k, work, block)
    return impl


@njit(cache=True)
def traction_block(data, rows, cols, out):
    """Block generator kernel (see :class:`hmatddm.hmatrix.BlockGenerator`): ``out`` of
    shape ``(d len(rows), d len(cols))`` receives ``out[d a + p, d b + q]``, the traction
    component ``p`` at the collocation point(s) of element ``rows[a]`` for a unit global
    DD unknown ``q`` of element ``cols[b]``."""
    dof = element_unknowns(data)
    _fill_block(data, rows, cols, out, _workspace(data), np.empty((dof, dof)))


@njit(cache=True, parallel=True)
def traction_matrix(data, out):
    """Dense assembly of the whole traction matrix ``out`` (N d, N d), parallel over
    receivers (rows written contiguously), or over sources for kinds with a
    ``source_state`` (made once per source)."""
    n = data.centers.shape[0]
    dof = element_unknowns(data)
    everything = np.arange(n)
    for k in prange(n):
        _fill_matrix_part(data, k, everything, out, _workspace(data), np.empty((dof, dof)))


@njit(cache=True)
def singular_pairs(data, rows, cols, out):
    """``out[k]`` = True when the block of receiver ``rows[k]`` and source ``cols[k]``
    (as :func:`traction_block` fills it) is not finite: a singular pair."""
    dof = element_unknowns(data)
    work = _workspace(data)
    block = np.empty((dof, dof))
    pair = np.empty((dof, dof))
    for k in range(rows.shape[0]):
        _fill_source(data, cols[k], rows[k:k + 1], pair, 0, work, block)
        out[k] = not np.all(np.isfinite(pair))


@njit(cache=True)
def self_block_max(data, out):
    """``out[i]``: the largest |entry| of element ``i``'s self block (the ``self_max``
    of ref. Eq. 6.11)."""
    dof = element_unknowns(data)
    work = _workspace(data)
    block = np.empty((dof, dof))
    for i in range(data.centers.shape[0]):
        state = _source_state(data, i, work)
        _element_traction(data, i, i, state, work, block)
        out[i] = np.max(np.abs(block))


@njit(cache=True)
def edge_distance(data, i, j):
    """Distance from the collocation point(s) of element ``i`` to the nearest edge (end)
    of element ``j`` (for error messages)."""
    return _edge_distance(data, i, j)


@njit(cache=True, parallel=True)
def stress_at_points(data, points, point_layer, dd, out):
    """Global stress ``out`` (M, dim, dim) at ``points`` (M, dim), in layers
    ``point_layer`` (M,) (zeros in a homogeneous medium), induced by the DD unknowns
    ``dd`` (N, d) of every element (direct sum, parallel over points)."""
    n = data.centers.shape[0]
    dim = points.shape[1]
    dof = element_unknowns(data)
    for m in prange(points.shape[0]):
        work = _workspace(data)
        pair = np.empty((dof, dim, dim))
        acc = np.zeros((dim, dim))
        for j in range(n):
            _element_stress(data, points[m], point_layer[m], j, work, pair)
            for u in range(dof):
                du = dd[j, u]
                for a in range(dim):
                    for b in range(dim):
                        acc[a, b] += pair[u, a, b] * du
        out[m] = acc


def influence_matrix(data):
    """The dense traction matrix of kernel ``data`` (N d, N d)."""
    n = data.centers.shape[0] * element_unknowns(data)
    out = np.empty((n, n))
    traction_matrix(data, out)
    return out


def self_block_maxima(data):
    """(N,) :func:`self_block_max` as a new array."""
    out = np.empty(data.centers.shape[0])
    self_block_max(data, out)
    return out


def stress_sum(data, points, dd, point_layer=None):
    """(M, dim, dim): :func:`stress_at_points` of ``dd`` (N, d) at ``points`` (M, dim)
    (``point_layer`` None: zeros, a homogeneous medium)."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    if point_layer is None:
        point_layer = np.zeros(len(points), dtype=np.int64)
    dd = np.ascontiguousarray(np.asarray(dd, dtype=np.float64).reshape(data.centers.shape[0], -1))
    out = np.zeros((len(points), points.shape[1], points.shape[1]))
    if len(points):
        stress_at_points(data, points, np.ascontiguousarray(point_layer, dtype=np.int64), dd, out)
    return out


__all__ = ["KernelKind", "register_kind", "no_source_state", "kind_of", "element_unknowns",
           "traction_block", "traction_matrix", "singular_pairs", "self_block_max", "edge_distance",
           "stress_at_points", "influence_matrix", "self_block_maxima", "stress_sum"]
