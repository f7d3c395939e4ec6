"""Kernels of the stress fields of :mod:`hmatddm.elasticity.fields` (ref. Eq. 2.59): what a points x
elements matrix reads (:class:`FieldSources`), its entries block by block for the
H-matrix engine (:func:`field_block`: unit global DD components; :func:`contribution_block`:
each element with its given DD) and the exact sum (:func:`direct_sum`).

Entries come from the per-pair kernels of :mod:`hmatddm.kernels`
(``local_stress_corrected`` of :mod:`~hmatddm.kernels.rectangle3d` and
:mod:`~hmatddm.kernels.line2d`), contracted with a local DD and rotated to the global frame
(ref. Eq. 2.57). Each driver branches on the dimension once, outside its loops, and runs a
loop nest that calls only that dimension's kernel (:func:`_response3`, :func:`_response2`,
passed to the inlined loop helpers): with both kernel calls in the hot loop, the unused one
cost ~50 ns per pair in 3D (0.16 -> 0.11 us per pair with numba's default pipeline, as fast as
its parallel pipeline made the combined loop, which these serial drivers no longer need).
"""
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ..kernels.line2d import local_stress_corrected as _segment_local_stress
from ..kernels.rectangle3d import local_stress_corrected as _rectangle_local_stress

_DIRECT_CHUNKS = 64  # fixed split of the point range in the direct sum


class FieldSources(NamedTuple):
    """What the field kernels read (numba reads the fields by name): the target
    ``points`` (M, dim), the elements (``centers``, ``frames`` with the local axes as
    rows, half sizes ``half_a``, ``half_b``; in 2D both are the half length), the
    material, the singular-point treatment: ``singular_shift`` (0: NaN at singular
    points, else the averaging offset of ref. Sec. 6.2.3) and ``near_fraction``, and the
    global DDs ``dd`` (N, dim) that :func:`contribution_block` folds into its columns."""

    points: np.ndarray
    centers: np.ndarray
    frames: np.ndarray
    half_a: np.ndarray
    half_b: np.ndarray
    shear_modulus: float
    poisson_ratio: float
    singular_shift: float
    near_fraction: float
    dd: np.ndarray


def field_sources(mesh, material, points, singular_correction="none", near_fraction=0.0, dd=None):
    """The :class:`FieldSources` of ``mesh`` seen from ``points`` (contiguous float64
    arrays: one compiled specialisation of each kernel, whatever slicing or
    concatenation produced the mesh)."""
    half_a, half_b = (mesh.half_length, mesh.half_length) if mesh.dim == 2 else (mesh.half_a, mesh.half_b)
    arrays = (np.ascontiguousarray(a, dtype=np.float64) for a in (points, mesh.centers, mesh.frames, half_a, half_b))
    dd = np.zeros((mesh.n_elements, mesh.dim)) if dd is None else dd
    return FieldSources(*arrays, float(material.shear_modulus), float(material.poisson_ratio),
                        1e-3 if singular_correction == "average" else 0.0, float(near_fraction),
                        np.ascontiguousarray(dd, dtype=np.float64))


@njit(cache=True, inline="always")
def _may_touch_boundary(x1, x2, x3, a, b, distance):
    """False when the local point is certainly farther than ``distance`` from the
    rectangle's boundary (a bounding test, so that the far pairs skip the nearest
    boundary point search of ``local_stress_corrected``)."""
    if abs(x3) > distance:
        return False
    u = abs(x1)
    v = abs(x2)
    if u > a + distance or v > b + distance:
        return False
    return abs(u - a) <= distance or abs(v - b) <= distance


@njit(cache=True, nogil=True, inline="always")
def _response3(sources, point, j, work):
    """Local stress of rectangle ``j`` at ``point`` per unit local DD component
    (``work[k]``): the kernels' ``local_stress_corrected`` (points on an edge, or within
    ``near_fraction`` of the element's smaller half size of one, are averaged across it
    when ``singular_shift > 0``, else NaN)."""
    centers = sources.centers
    frame = sources.frames[j]
    dx = point[0] - centers[j, 0]
    dy = point[1] - centers[j, 1]
    dz = point[2] - centers[j, 2]
    x1 = frame[0, 0] * dx + frame[0, 1] * dy + frame[0, 2] * dz
    x2 = frame[1, 0] * dx + frame[1, 1] * dy + frame[1, 2] * dz
    x3 = frame[2, 0] * dx + frame[2, 1] * dy + frame[2, 2] * dz
    a = sources.half_a[j]
    b = sources.half_b[j]
    near = sources.near_fraction * min(a, b)
    if near > 0.0 and not _may_touch_boundary(x1, x2, x3, a, b, near):
        near = 0.0
    _rectangle_local_stress(x1, x2, x3, a, b, sources.shear_modulus, sources.poisson_ratio, sources.singular_shift,
                            work, near)


@njit(cache=True, nogil=True, inline="always")
def _response2(sources, point, j, work):
    """:func:`_response3` for segment ``j`` (2D plane strain; ``near_fraction`` of its
    half length from an end)."""
    centers = sources.centers
    frame = sources.frames[j]
    dx = point[0] - centers[j, 0]
    dy = point[1] - centers[j, 1]
    a = sources.half_a[j]
    _segment_local_stress(frame[0, 0] * dx + frame[0, 1] * dy, frame[1, 0] * dx + frame[1, 1] * dy, a,
                          sources.shear_modulus, sources.poisson_ratio, sources.singular_shift, work,
                          sources.near_fraction * a)


@njit(cache=True, nogil=True, inline="always")
def _components(work3, work2, dim, l0, l1, l2, frame, n_out, nu, out):
    """``out[:n_out]``: the global components of the stress of local DD ``(l0, l1, l2)``
    (``l2`` unused in 2D) from the local responses: ``s = sum_k l_k work[k]``, rotated
    ``F^T s F`` (``frame`` rows are the local axes, ref. Eq. 2.57), or the mean stress
    ``tr(s)/3`` (2D plane strain: ``(1 + nu) tr(s) / 3``, since ``s_zz = nu tr(s)``)."""
    if dim == 3:
        s00 = l0 * work3[0, 0, 0] + l1 * work3[1, 0, 0] + l2 * work3[2, 0, 0]
        s11 = l0 * work3[0, 1, 1] + l1 * work3[1, 1, 1] + l2 * work3[2, 1, 1]
        s22 = l0 * work3[0, 2, 2] + l1 * work3[1, 2, 2] + l2 * work3[2, 2, 2]
        if n_out == 1:
            out[0] = (s00 + s11 + s22) / 3.0
            return
        s01 = l0 * work3[0, 0, 1] + l1 * work3[1, 0, 1] + l2 * work3[2, 0, 1]
        s02 = l0 * work3[0, 0, 2] + l1 * work3[1, 0, 2] + l2 * work3[2, 0, 2]
        s12 = l0 * work3[0, 1, 2] + l1 * work3[1, 1, 2] + l2 * work3[2, 1, 2]
        t00 = s00 * frame[0, 0] + s01 * frame[1, 0] + s02 * frame[2, 0]
        t01 = s00 * frame[0, 1] + s01 * frame[1, 1] + s02 * frame[2, 1]
        t02 = s00 * frame[0, 2] + s01 * frame[1, 2] + s02 * frame[2, 2]
        t10 = s01 * frame[0, 0] + s11 * frame[1, 0] + s12 * frame[2, 0]
        t11 = s01 * frame[0, 1] + s11 * frame[1, 1] + s12 * frame[2, 1]
        t12 = s01 * frame[0, 2] + s11 * frame[1, 2] + s12 * frame[2, 2]
        t20 = s02 * frame[0, 0] + s12 * frame[1, 0] + s22 * frame[2, 0]
        t21 = s02 * frame[0, 1] + s12 * frame[1, 1] + s22 * frame[2, 1]
        t22 = s02 * frame[0, 2] + s12 * frame[1, 2] + s22 * frame[2, 2]
        out[0] = frame[0, 0] * t00 + frame[1, 0] * t10 + frame[2, 0] * t20
        out[1] = frame[0, 1] * t01 + frame[1, 1] * t11 + frame[2, 1] * t21
        out[2] = frame[0, 2] * t02 + frame[1, 2] * t12 + frame[2, 2] * t22
        out[3] = frame[0, 0] * t01 + frame[1, 0] * t11 + frame[2, 0] * t21
        out[4] = frame[0, 0] * t02 + frame[1, 0] * t12 + frame[2, 0] * t22
        out[5] = frame[0, 1] * t02 + frame[1, 1] * t12 + frame[2, 1] * t22
        return
    s00 = l0 * work2[0, 0, 0] + l1 * work2[1, 0, 0]
    s11 = l0 * work2[0, 1, 1] + l1 * work2[1, 1, 1]
    if n_out == 1:
        out[0] = (1.0 + nu) * (s00 + s11) / 3.0
        return
    s01 = l0 * work2[0, 0, 1] + l1 * work2[1, 0, 1]
    t00 = s00 * frame[0, 0] + s01 * frame[1, 0]
    t01 = s00 * frame[0, 1] + s01 * frame[1, 1]
    t10 = s01 * frame[0, 0] + s11 * frame[1, 0]
    t11 = s01 * frame[0, 1] + s11 * frame[1, 1]
    out[0] = frame[0, 0] * t00 + frame[1, 0] * t10
    out[1] = frame[0, 1] * t01 + frame[1, 1] * t11
    out[2] = frame[0, 0] * t01 + frame[1, 0] * t11


@njit(cache=True, nogil=True, inline="always")
def _contribution(sources, j, n_out, work, dim, value):
    """``value[:n_out]``: the components of element ``j`` with its global DD
    ``sources.dd[j]`` from its local responses ``work`` at a point, contracted in the
    local frame before the one rotation."""
    frame = sources.frames[j]
    dd = sources.dd[j]
    l0 = frame[0, 0] * dd[0] + frame[0, 1] * dd[1]
    l1 = frame[1, 0] * dd[0] + frame[1, 1] * dd[1]
    l2 = 0.0
    if dim == 3:
        l0 += frame[0, 2] * dd[2]
        l1 += frame[1, 2] * dd[2]
        l2 = frame[2, 0] * dd[0] + frame[2, 1] * dd[1] + frame[2, 2] * dd[2]
    _components(work, work, dim, l0, l1, l2, frame, n_out, sources.poisson_ratio, value)


@njit(cache=True, nogil=True, inline="always")
def _unit_dd_rows(data, rows, cols, out, response, work, dim):
    """The loops of :func:`field_block` for one dimension's kernel ``response``."""
    n_out = out.shape[0] // rows.shape[0]
    nu = data.poisson_ratio
    value = np.empty(6)
    for a in range(rows.shape[0]):
        point = data.points[rows[a]]
        for b in range(cols.shape[0]):
            j = cols[b]
            frame = data.frames[j]
            response(data, point, j, work)
            for q in range(dim):
                # local components of the unit global DD q: column q of the frame
                _components(work, work, dim, frame[0, q], frame[1, q], frame[dim - 1, q], frame, n_out, nu, value)
                for c in range(n_out):
                    out[n_out * a + c, dim * b + q] = value[c]


@njit(cache=True, nogil=True)
def field_block(data, rows, cols, out):
    """Block generator kernel of the points x elements matrix (see
    :class:`hmatddm.hmatrix.BlockGenerator`): ``out[n_out * a + c, d * b + q]`` =
    component ``c`` at point ``rows[a]`` from a unit global DD component ``q`` of
    element ``cols[b]``. ``data``: :class:`FieldSources`; ``n_out`` (6, 3 or 1) is read
    from the shape of ``out``."""
    if data.centers.shape[1] == 3:
        _unit_dd_rows(data, rows, cols, out, _response3, np.empty((3, 3, 3)), 3)
    else:
        _unit_dd_rows(data, rows, cols, out, _response2, np.empty((2, 2, 2)), 2)


@njit(cache=True, nogil=True, inline="always")
def _contribution_rows(data, rows, cols, out, response, work, dim):
    """The loops of :func:`contribution_block` for one dimension's kernel ``response``."""
    n_out = out.shape[0] // rows.shape[0]
    value = np.empty(6)
    for a in range(rows.shape[0]):
        point = data.points[rows[a]]
        for b in range(cols.shape[0]):
            response(data, point, cols[b], work)
            _contribution(data, cols[b], n_out, work, dim, value)
            for c in range(n_out):
                out[n_out * a + c, b] = value[c]


@njit(cache=True, nogil=True)
def contribution_block(data, rows, cols, out):
    """Block generator kernel of the points x elements matrix of given DDs, one column
    per element: ``out[n_out * a + c, b]`` = component ``c`` at point ``rows[a]`` of
    element ``cols[b]`` with its DD ``data.dd[cols[b]]``; the field is this matrix
    times a vector of ones."""
    if data.centers.shape[1] == 3:
        _contribution_rows(data, rows, cols, out, _response3, np.empty((3, 3, 3)), 3)
    else:
        _contribution_rows(data, rows, cols, out, _response2, np.empty((2, 2, 2)), 2)


@njit(cache=True, nogil=True, inline="always")
def _sum_points(sources, out, first, last, response, work, dim):
    """``out[first:last]`` of :func:`direct_sum` for one dimension's kernel."""
    points = sources.points
    n_out = out.shape[1]
    value = np.empty(6)
    for t in range(first, last):
        for c in range(n_out):
            out[t, c] = 0.0
        for j in range(sources.frames.shape[0]):
            response(sources, points[t], j, work)
            _contribution(sources, j, n_out, work, dim, value)
            for c in range(n_out):
                out[t, c] += value[c]


@njit(cache=True, parallel=True)
def direct_sum(sources, out):
    """``out[t] = sum_j`` (stress at point ``t`` of element ``j`` with its global DD
    ``sources.dd[j]``), exact, ``n_out = out.shape[1]``. Each pair contracts its DD
    before the one rotation; parallel over a fixed split of the points, the sum over
    ``j`` in element order (the result does not depend on the thread count)."""
    m = sources.points.shape[0]
    n_chunks = min(_DIRECT_CHUNKS, m)
    for chunk in prange(n_chunks):
        first = chunk * m // n_chunks
        last = (chunk + 1) * m // n_chunks
        if sources.centers.shape[1] == 3:
            _sum_points(sources, out, first, last, _response3, np.empty((3, 3, 3)), 3)
        else:
            _sum_points(sources, out, first, last, _response2, np.empty((2, 2, 2)), 2)


__all__ = ["FieldSources", "field_sources", "field_block", "contribution_block", "direct_sum"]
