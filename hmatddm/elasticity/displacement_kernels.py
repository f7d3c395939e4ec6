"""Kernels of the displacement fields of :mod:`hmatddm.elasticity.fields` (ref. Eqs 2.43,
2.55-2.57): the points x elements matrix of displacements, block by block for the
H-matrix engine (:func:`field_block`: unit global DD components; :func:`contribution_block`:
each element with its given DD) and the exact sum (:func:`direct_sum`), with the same
:class:`~hmatddm.elasticity.field_kernels.FieldSources` and the same layout as the stress
kernels of :mod:`hmatddm.elasticity.field_kernels` (row ``d * t + i``: component ``i`` of
the displacement at point ``t``).

Entries come from :mod:`hmatddm.kernels.displacement` (the local ``A_ij`` of ref. Eq. 2.56),
contracted with a local DD and rotated to the global frame (ref. Eq. 2.57: a vector here,
``u = F^T u_local`` with the frame's rows the local axes). Points on an element edge (an
end in 2D) give NaN (the displacement is log-singular there); on an element's face, its
``+`` side.
"""
import numpy as np
from numba import njit, prange

from ..kernels.displacement import rectangle_local_displacement, segment_local_displacement

_DIRECT_CHUNKS = 64  # fixed split of the point range in the direct sum


@njit(cache=True, nogil=True, inline="always")
def _response3(sources, point, j, work):
    """``work[k, i]``: local displacement of rectangle ``j`` at ``point`` per unit local DD ``k``."""
    centers = sources.centers
    frame = sources.frames[j]
    dx = point[0] - centers[j, 0]
    dy = point[1] - centers[j, 1]
    dz = point[2] - centers[j, 2]
    rectangle_local_displacement(frame[0, 0] * dx + frame[0, 1] * dy + frame[0, 2] * dz,
                                 frame[1, 0] * dx + frame[1, 1] * dy + frame[1, 2] * dz,
                                 frame[2, 0] * dx + frame[2, 1] * dy + frame[2, 2] * dz,
                                 sources.half_a[j], sources.half_b[j], sources.poisson_ratio, work)


@njit(cache=True, nogil=True, inline="always")
def _response2(sources, point, j, work):
    """:func:`_response3` for segment ``j`` (2D plane strain)."""
    centers = sources.centers
    frame = sources.frames[j]
    dx = point[0] - centers[j, 0]
    dy = point[1] - centers[j, 1]
    segment_local_displacement(frame[0, 0] * dx + frame[0, 1] * dy, frame[1, 0] * dx + frame[1, 1] * dy,
                               sources.half_a[j], sources.poisson_ratio, work)


@njit(cache=True, nogil=True, inline="always")
def _global(work, dim, local_dd, frame, out):
    """``out[:dim]``: the global displacement of local DD ``local_dd`` from the local
    responses ``work[k, i]``: ``u_local = sum_k l_k work[k]``, then ``F^T u_local``."""
    for i in range(dim):
        out[i] = 0.0
    for p in range(dim):
        u = 0.0
        for k in range(dim):
            u += local_dd[k] * work[k, p]
        for i in range(dim):
            out[i] += frame[p, i] * u


@njit(cache=True, nogil=True, inline="always")
def _local_dd(frame, dd, dim, out):
    for k in range(dim):
        acc = 0.0
        for q in range(dim):
            acc += frame[k, q] * dd[q]
        out[k] = acc


@njit(cache=True, nogil=True, inline="always")
def _unit_dd_rows(data, rows, cols, out, response, work, dim):
    local = np.empty(3)
    value = np.empty(3)
    for a in range(rows.shape[0]):
        point = data.points[rows[a]]
        for b in range(cols.shape[0]):
            j = cols[b]
            frame = data.frames[j]
            response(data, point, j, work)
            for q in range(dim):
                for k in range(dim):
                    local[k] = frame[k, q]  # local components of the unit global DD q
                _global(work, dim, local, frame, value)
                for i in range(dim):
                    out[dim * a + i, dim * b + q] = value[i]


@njit(cache=True, nogil=True)
def field_block(data, rows, cols, out):
    """Block generator kernel (see :class:`hmatddm.hmatrix.BlockGenerator`):
    ``out[d * a + i, d * b + q]`` = displacement component ``i`` at point ``rows[a]`` from
    a unit global DD component ``q`` of element ``cols[b]``."""
    if data.centers.shape[1] == 3:
        _unit_dd_rows(data, rows, cols, out, _response3, np.empty((3, 3)), 3)
    else:
        _unit_dd_rows(data, rows, cols, out, _response2, np.empty((2, 2)), 2)


@njit(cache=True, nogil=True, inline="always")
def _contribution_rows(data, rows, cols, out, response, work, dim):
    local = np.empty(3)
    value = np.empty(3)
    for a in range(rows.shape[0]):
        point = data.points[rows[a]]
        for b in range(cols.shape[0]):
            j = cols[b]
            response(data, point, j, work)
            _local_dd(data.frames[j], data.dd[j], dim, local)
            _global(work, dim, local, data.frames[j], value)
            for i in range(dim):
                out[dim * a + i, b] = value[i]


@njit(cache=True, nogil=True)
def contribution_block(data, rows, cols, out):
    """Block generator kernel of given DDs, one column per element: ``out[d * a + i, b]``
    = displacement component ``i`` at point ``rows[a]`` of element ``cols[b]`` with its
    DD ``data.dd[cols[b]]``; the field is this matrix times a vector of ones."""
    if data.centers.shape[1] == 3:
        _contribution_rows(data, rows, cols, out, _response3, np.empty((3, 3)), 3)
    else:
        _contribution_rows(data, rows, cols, out, _response2, np.empty((2, 2)), 2)


@njit(cache=True, nogil=True, inline="always")
def _sum_points(sources, out, first, last, response, work, dim):
    local = np.empty(3)
    value = np.empty(3)
    for t in range(first, last):
        for i in range(dim):
            out[t, i] = 0.0
        for j in range(sources.frames.shape[0]):
            response(sources, sources.points[t], j, work)
            _local_dd(sources.frames[j], sources.dd[j], dim, local)
            _global(work, dim, local, sources.frames[j], value)
            for i in range(dim):
                out[t, i] += value[i]


@njit(cache=True, parallel=True)
def direct_sum(sources, out):
    """``out[t] = sum_j`` (displacement at point ``t`` of element ``j`` with its global DD
    ``sources.dd[j]``), exact; parallel over a fixed split of the points, the sum over
    ``j`` in element order (the result does not depend on the thread count)."""
    m = sources.points.shape[0]
    n_chunks = min(_DIRECT_CHUNKS, m)
    for chunk in prange(n_chunks):
        first = chunk * m // n_chunks
        last = (chunk + 1) * m // n_chunks
        if sources.centers.shape[1] == 3:
            _sum_points(sources, out, first, last, _response3, np.empty((3, 3)), 3)
        else:
            _sum_points(sources, out, first, last, _response2, np.empty((2, 2)), 2)


__all__ = ["field_block", "contribution_block", "direct_sum"]
