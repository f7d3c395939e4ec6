"""The image quadrature along a 2D element (ref. Sec. 3.3, Table 3.2): Gauss-Legendre rules,
composite rules of equal sub-segments, and how many sub-segments a receiver needs (the
integrand of the image stress is singular at the element's mirror images).
"""
import math

import numpy as np
from numba import njit


@njit(cache=True)
def gauss_legendre(n):
    """Nodes and weights of the ``n``-point Gauss-Legendre rule on [-1, 1] (Newton on
    the Legendre recurrence)."""
    x = np.empty(n)
    w = np.empty(n)
    for i in range(n):
        z = math.cos(math.pi * (i + 0.75) / (n + 0.5))
        for _ in range(100):
            p0 = 1.0
            p1 = 0.0
            for k in range(1, n + 1):
                p2 = p1
                p1 = p0
                p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k
            dp = n * (z * p0 - p1) / (z * z - 1.0)
            dz = p0 / dp
            z -= dz
            if abs(dz) < 1e-15:
                break
        x[i] = z
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp)
    return x, w


@njit(cache=True)
def composite_rule(n_gauss, n_sub):
    """``n_gauss`` Gauss points on each of ``n_sub`` equal sub-segments of [-1, 1]."""
    x, w = gauss_legendre(n_gauss)
    xi = np.empty(n_gauss * n_sub)
    wt = np.empty(n_gauss * n_sub)
    for s in range(n_sub):
        lo = -1.0 + 2.0 * s / n_sub
        for g in range(n_gauss):
            xi[s * n_gauss + g] = lo + (x[g] + 1.0) / n_sub
            wt[s * n_gauss + g] = w[g] / n_sub
    return xi, wt


@njit(cache=True)
def subdivision_level(n_sub):
    """The smallest level with 2^level >= n_sub subdivisions (of a segment in 2D, of each
    side of a rectangle in 3D): composite rules are cached per level."""
    level = 0
    while 2 ** level < n_sub:
        level += 1
    return level


@njit(cache=True)
def _segment_distance(px, py, ax, ay, bx, by):
    ex = bx - ax
    ey = by - ay
    ll = ex * ex + ey * ey
    u = ((px - ax) * ex + (py - ay) * ey) / ll if ll > 0.0 else 0.0
    u = min(1.0, max(0.0, u))
    dx = px - ax - u * ex
    dy = py - ay - u * ey
    return math.sqrt(dx * dx + dy * dy)


@njit(cache=True)
def subdivisions(y1, y3, receiver_layer, p0, p1, source_layer, interfaces, max_sub):
    """Sub-segments so that each is at most half as long as the distance from the
    receiver to the nearest singular point of the integrand: the element's mirror
    images in the interfaces bounding the source's and the receiver's layers, and the
    element itself when the receiver is in another layer."""
    length = math.sqrt((p1[0] - p0[0]) ** 2 + (p1[1] - p0[1]) ** 2)
    dmin = np.inf
    if receiver_layer != source_layer:
        dmin = _segment_distance(y1, y3, p0[0], p0[1], p1[0], p1[1])
    n_if = interfaces.shape[0]
    for layer in (source_layer, receiver_layer):
        for k in (layer - 1, layer):
            if 0 <= k < n_if:
                d = interfaces[k]
                dmin = min(dmin, _segment_distance(y1, y3, p0[0], 2.0 * d - p0[1], p1[0], 2.0 * d - p1[1]))
    if dmin <= 0.0:
        return max_sub
    n = int(math.ceil(2.0 * length / dmin))
    return min(max(n, 1), max_sub)
