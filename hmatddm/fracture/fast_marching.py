"""Compiled kernels of the implicit front (:mod:`.front`): first-order fast marching of the
eikonal equation ``|grad phi| = 1`` on the cells of a 1D or 2D box, and the distance to a
union of circles with its nearest circle.

They were Python loops (a heap of tuples, one ``update`` call per neighbour); on the radial
K scene at 0.5 m elements the front's level sets took more CPU than the coupled solves
(issue 33: every O(N) step of the loop as fast as the solve). The arithmetic is the one of
the loops they replace, operation for operation, and the heap orders its entries by
``(value, flat index)`` as Python's tuples did, so the fields are the same to the bit
(``tests/fracture/test_fast_marching.py`` compares them with a plain-Python march).
"""
import math

import numpy as np
from numba import njit


@njit(cache=True)
def _before(value_a, index_a, value_b, index_b):
    """Heap order: by value, ties by flat index (the order of ``(value, index tuple)``)."""
    return value_a < value_b or (value_a == value_b and index_a < index_b)


@njit(cache=True)
def _push(values, indices, size, value, index):
    """Push ``(value, index)`` on the binary heap of ``size`` entries; returns the new size
    (the arrays have room for every push of a march: see :func:`march`)."""
    i = size
    values[i] = value
    indices[i] = index
    while i > 0:
        parent = (i - 1) // 2
        if _before(values[i], indices[i], values[parent], indices[parent]):
            values[i], values[parent] = values[parent], values[i]
            indices[i], indices[parent] = indices[parent], indices[i]
            i = parent
        else:
            break
    return size + 1


@njit(cache=True)
def _pop(values, indices, size):
    """Remove the first entry of the heap; returns ``(value, index, new size)``."""
    value, index = values[0], indices[0]
    size -= 1
    values[0], indices[0] = values[size], indices[size]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= size:
            break
        child = left
        if left + 1 < size and _before(values[left + 1], indices[left + 1], values[left], indices[left]):
            child = left + 1
        if _before(values[child], indices[child], values[i], indices[i]):
            values[i], values[child] = values[child], values[i]
            indices[i], indices[child] = indices[child], indices[i]
            i = child
        else:
            break
    return value, index, size


@njit(cache=True)
def _update(phi, done, flat, shape, strides, h):
    """The upwind value at cell ``flat`` from its done neighbours: the smallest neighbour per
    axis, sorted; ``min + h``, improved by the quadratic of the m smallest while it stays
    above the m-th (first-order fast marching, Sethian 1996)."""
    k = shape.shape[0]
    values = np.empty(k)
    n = 0
    for axis in range(k):
        position = (flat // strides[axis]) % shape[axis]
        best = np.inf
        for sign in (-1, 1):
            j = position + sign
            if 0 <= j < shape[axis]:
                neighbour = flat + sign * strides[axis]
                if done[neighbour]:
                    best = min(best, phi[neighbour])
        if math.isfinite(best):
            values[n] = best
            n += 1
    values[:n] = np.sort(values[:n])
    value = values[0] + h
    for m in range(2, n + 1):
        b = 0.0
        squares = 0.0
        for i in range(m):
            b += values[i]
            squares += values[i] * values[i]
        disc = b * b - m * (squares - h * h)
        if disc < 0.0:
            break
        candidate = (b + math.sqrt(disc)) / m
        if candidate < values[m - 1]:
            break
        value = candidate
    return value


@njit(cache=True)
def _push_neighbours(phi, done, allowed, flat, shape, strides, h, values, indices, size):
    k = shape.shape[0]
    for axis in range(k):
        position = (flat // strides[axis]) % shape[axis]
        for sign in (-1, 1):
            j = position + sign
            if 0 <= j < shape[axis]:
                neighbour = flat + sign * strides[axis]
                if allowed[neighbour] and not done[neighbour]:
                    value = _update(phi, done, neighbour, shape, strides, h)
                    if value < phi[neighbour]:
                        phi[neighbour] = value
                        size = _push(values, indices, size, value, neighbour)
    return size


@njit(cache=True)
def _march_flat(phi, known, allowed, shape, h):
    """:func:`march` on C-ordered flat arrays."""
    k = shape.shape[0]
    strides = np.ones(k, np.int64)
    for axis in range(k - 2, -1, -1):
        strides[axis] = strides[axis + 1] * shape[axis + 1]
    n = phi.shape[0]
    done = known.copy()
    # each push lowers phi of a cell that is not done; a cell is pushed at most once per
    # neighbour that becomes done, so 2k pushes per cell bound the heap
    capacity = 2 * k * n + 1
    values = np.empty(capacity)
    indices = np.empty(capacity, np.int64)
    size = 0
    for flat in range(n):
        if known[flat]:
            size = _push_neighbours(phi, done, allowed, flat, shape, strides, h, values, indices, size)
    while size > 0:
        value, flat, size = _pop(values, indices, size)
        if done[flat] or value > phi[flat]:
            continue
        done[flat] = True
        size = _push_neighbours(phi, done, allowed, flat, shape, strides, h, values, indices, size)


def march(phi, known, allowed, h):
    """First-order fast marching of ``|grad phi| = 1`` (increasing ``phi``) from the
    ``known`` cells through the ``allowed`` cells of a 1D or 2D array, in place."""
    if not (phi.flags.c_contiguous and known.flags.c_contiguous and allowed.flags.c_contiguous):
        raise ValueError("march needs C-contiguous arrays")
    shape = np.array(phi.shape, np.int64)
    _march_flat(phi.reshape(-1), known.reshape(-1), allowed.reshape(-1), shape, float(h))


@njit(cache=True)
def nearest_circle(points, centers, distances):
    """``min_r (|x - x_r| - s_r)`` and its first arg-min ``r`` for in-plane points (M, k)."""
    m, k = points.shape
    phi = np.empty(m)
    nearest = np.empty(m, np.int64)
    for i in range(m):
        best = np.inf
        where = 0
        for r in range(centers.shape[0]):
            square = 0.0
            for axis in range(k):
                d = points[i, axis] - centers[r, axis]
                square += d * d
            value = math.sqrt(square) - distances[r]
            if value < best:
                best = value
                where = r
        phi[i] = best
        nearest[i] = where
    return phi, nearest


@njit(cache=True)
def first_nearest(points, centers, candidates):
    """For each point, the first of the centres nearest it among its ``candidates`` (M, c)
    (the distance as :func:`nearest_circle` computes it, ties to the lowest index)."""
    m, k = points.shape
    nearest = np.empty(m, np.int64)
    for i in range(m):
        best = np.inf
        where = -1
        for c in range(candidates.shape[1]):
            r = candidates[i, c]
            square = 0.0
            for axis in range(k):
                d = points[i, axis] - centers[r, axis]
                square += d * d
            value = math.sqrt(square)
            if value < best or (value == best and r < where):
                best = value
                where = r
        nearest[i] = where
    return nearest


@njit(cache=True)
def interpolate(phi, low, h, points, out):
    """``out[i]``: ``phi`` (cell centres of a 2D box whose first cell is ``low``, spacing
    ``h``; a 1D box as ``(n, 1)`` with its points' second coordinate 0) bilinear at
    ``points[i]`` (in plane), +inf outside the box, as :meth:`.front.FrontField.__call__`
    did it in numpy: corners in the order (0, 0), (0, 1), (1, 0), (1, 1), a corner of zero
    weight skipped, an infinite corner value kept (``inf - inf``: NaN, read as +inf)."""
    n0, n1 = phi.shape
    for i in range(points.shape[0]):
        u0 = points[i, 0] / h - low[0]
        u1 = points[i, 1] / h - low[1]
        b0 = math.floor(u0)
        b1 = math.floor(u1)
        f0 = u0 - b0
        f1 = u1 - b1
        total = 0.0
        for c0 in range(2):
            w0 = f0 if c0 == 1 else 1.0 - f0
            for c1 in range(2):
                weight = w0 * (f1 if c1 == 1 else 1.0 - f1)
                if weight > 0.0:
                    j0 = int(b0) + c0
                    j1 = int(b1) + c1
                    value = phi[j0, j1] if 0 <= j0 < n0 and 0 <= j1 < n1 else np.inf
                    total = total + weight * value
                else:
                    total = total + 0.0
        out[i] = np.inf if math.isnan(total) else total
