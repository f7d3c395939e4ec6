"""The stress at points of constant rectangles in a plane-layered 3D medium (ref. Secs
3.2-3.3; the direct sum behind :func:`hmatddm.stress_at`, the remote-failure check of
natural fractures, the microseismic forward model and the monitors in layered rock).

Sources outside, points inside (:func:`stress_points`): each source's image triples are
traced once for all the points (:func:`.images3d.source_state`: the points of its Gauss
rules, and for a vertical rectangle its three heights), and each point-source pair takes
the per-pair image terms of the operator (:func:`.stress_terms3d.element_stress_traced`:
the closed forms of :mod:`.okada3d` and :mod:`.vertical3d`, the quadrature elsewhere),
called through the record's held functions (``source_tracer``, ``point_stress``) with the
record, the workspace and the source's state as pointers made once (issue 32: compiled
once, not again here; no per-pair copies of them). The
generic driver :func:`hmatddm.kernels.drivers.stress_block` loops over points outside and
has no source state, so it traces every source's triples again at every point (issue 32,
a free surface over two interfaces, ``images=4``: 857 us a pair against 643 us with sources
outside, both by quadrature; ``benchmarks/bench_layered3d_stress.py``, benchmarks/RESULTS.md).
"""
import numpy as np
from numba import njit

from ..kernels.drivers import _hold, _in_parts, borrowed
from ..kernels.held_function import address_of, held_record
from .images3d import workspace

__all__ = ["stress_points", "stress_sum", "stress_columns_points", "stress_columns"]


@njit(cache=True, nogil=True)
def stress_points(data, points, point_layer, dd, out):
    """``out`` (M, 3, 3): the stress at ``points`` (M, 3) in layers ``point_layer`` (M,)
    of the global DDs ``dd`` (N, 3) of every rectangle of the
    :class:`.images3d.LayeredRectangles` ``data`` (each point's sum in element order)."""
    work = workspace(data)
    pair = np.empty((3, 3, 3))
    for m in range(points.shape[0]):
        for i in range(3):
            for k in range(3):
                out[m, i, k] = 0.0
    # the record and the workspace on the stack once, for every call of the held per-pair
    # stress (.stress_terms3d): live while ``data`` and ``work`` are (``_hold`` below)
    data_at, work_at = held_record(data), work[1]
    for j in range(data.centers.shape[0]):
        owner = data.source_tracer(data_at, np.int64(j), work_at)  # source_state through the pointers
        state = borrowed(owner)  # no reference counts per point (kernels.drivers.traction_block)
        state_at = address_of(state)
        for m in range(points.shape[0]):
            data.point_stress(data_at, points[m], point_layer[m], np.int64(j), state_at, work_at, data.image_terms,
                              data.vertical_terms, pair)
            for i in range(3):
                for k in range(3):
                    acc = 0.0
                    for q in range(3):
                        acc += pair[q, i, k] * dd[j, q]
                    out[m, i, k] += acc
        _hold(owner)
    _hold(work)


def stress_sum(data, points, dd, point_layer):
    """(M, 3, 3): :func:`stress_points` of ``dd`` ((N, 3) or (3N,)) at ``points`` (M, 3),
    one range of points per thread (each range traces every source once: fewer, longer
    ranges trace less)."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    point_layer = np.ascontiguousarray(point_layer, dtype=np.int64)
    dd = np.ascontiguousarray(np.asarray(dd, dtype=np.float64).reshape(data.centers.shape[0], 3))
    out = np.zeros((len(points), 3, 3))

    def part(start, stop):
        stress_points(data, points[start:stop], point_layer[start:stop], dd, out[start:stop])

    _in_parts(part, len(points), parts_per_thread=1)
    return out


@njit(cache=True, nogil=True)
def stress_columns_points(data, points, point_layer, out):
    """``out[m, j, q]`` (M, N, 3, 3, 3): the stress at ``points[m]`` of a unit DD component
    ``q`` of rectangle ``j``, each source traced once -- the terms :func:`stress_points` sums
    (the same function per pair, so a sum of these terms is its sum up to the order of the
    additions)."""
    work = workspace(data)
    pair = np.empty((3, 3, 3))
    data_at, work_at = held_record(data), work[1]  # as in stress_points
    for j in range(data.centers.shape[0]):
        owner = data.source_tracer(data_at, np.int64(j), work_at)  # as in stress_points
        state = borrowed(owner)
        state_at = address_of(state)
        for m in range(points.shape[0]):
            data.point_stress(data_at, points[m], point_layer[m], np.int64(j), state_at, work_at, data.image_terms,
                              data.vertical_terms, pair)
            out[m, j] = pair
        _hold(owner)
    _hold(work)


def stress_columns(data, points, point_layer):
    """(M, N, 3, 3, 3): :func:`stress_columns_points`, one range of points per thread."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    point_layer = np.ascontiguousarray(point_layer, dtype=np.int64)
    out = np.empty((len(points), data.centers.shape[0], 3, 3, 3))

    def part(start, stop):
        stress_columns_points(data, points[start:stop], point_layer[start:stop], out[start:stop])

    _in_parts(part, len(points), parts_per_thread=1)
    return out
