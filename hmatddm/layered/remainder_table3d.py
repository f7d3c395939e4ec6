"""The layered remainder of the 3D image method, tabulated once per medium (issue 32, item 2).

The image field of a point source in a plane-layered medium (ref. Secs 3.2-3.3) is the sum
of the traced Hansen triples (:mod:`.image_tracer3d`). With two or more interfaces (a free
surface counts as one) their number grows quickly with the number of reflections: 37
triples for a source below a free surface and two interfaces at ``images=4``, each costing
~2 us at every quadrature point. Only a few of them are singular where the receivers are:

* **near** triples: those whose point can come to the receiver's layer (a first reflection
  in an interface that bounds both the source's and the receiver's layer, the transmitted
  source for a receiver in the next layer) -- with the whole-space term of the source's
  material that :mod:`.image_points3d` subtracts in another layer, when that layer is the
  next one;
* **far** triples: every other one. Its point stays at least one layer thickness away
  from the receiver's layer for every source height in the source's layer
  (:func:`triple_gap`), so their sum -- the *layered remainder* -- is smooth there.

The near triples keep the quadrature's rules of :mod:`.rectangle_quadrature` (exact to its
tolerance next to the interfaces), their field at each point looked up in a table of one
angle (:mod:`.near_table3d`, built with this one: a near triple has no length but its
offset from its interface). The remainder depends only on the horizontal offset
``rho``, the source height ``t`` and the receiver height ``y3`` (the medium is
axisymmetric about the vertical through the source), and is tabulated on uniform grids in
the source frame rotated so that the receiver lies on its x axis (the approach of the
layered-media Green's function tables, e.g. Wang's EDGRN/EDCMP, applied to the image sum):
per pair of (source layer, receiver layer), the 20 components of the moment-to-stress
response ``T[m, s]`` that the mirror symmetry ``y -> -y`` of that frame leaves non-zero
(moment ``m`` and stress ``s`` components, each ``xx, yy, zz, xy, xz, yz``). A value is
interpolated by :data:`STENCIL`-point Lagrange polynomials in each of the three variables
(the grids padded past their ranges so every stencil is centred), then rotated back and
contracted with the element's moment tensor (Aki & Richards, Eq. 3.20).

The table is built (:mod:`.remainder_build3d`) from the image sum itself (so it is exact
at its nodes), and refined (the spacing halved) until its error at random points between
the nodes, converted to an influence entry (``max |dT| (lambda + 2G) 4ab``), is below
``table_tol`` times the scale of the largest entry (:func:`.rectangle_quadrature.entry_scale`).
A medium whose triples are all near (a half-space, a bi-material) builds no table, nor does
a mesh of fewer than :data:`.influence3d.TABLE_MIN_ELEMENTS` elements. A source or receiver
outside a table's range takes the quadrature of every triple, as without a table.
"""
import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ..kernels.held_function import data_pointer
from .image_tracer import trace_capacity
from .image_tracer3d import copy_triple, trace
from .images2d import _lame, receiver_constants
from .potentials3d import Workspace, _original, _pair_stress_gradient
from .turned_response3d import COMPONENTS, PAIRS as _PAIRS, rotated_stress

#: Largest number of values a table may hold (8 bytes each) before refinement stops.
MAX_TABLE_VALUES = 40_000_000
#: Random points between the nodes at which a table's error is measured, per layer pair
#: (half of them near the ends of the height ranges).
ERROR_SAMPLES = 128


class RemainderTable(NamedTuple):
    """The tabulated layered remainder of a medium (empty: ``pair_index`` all -1).

    Layer pair ``k = pair_index[ls, lr]`` has its own grids, ``grid[k]`` =
    ``(rho_scale, h_u, n_u, t0, h_t, n_t, y0, h_y, n_y)``: ``rho = rho_scale sinh(u)``,
    ``u = i h_u`` (nodes denser near the source, where the remainder varies on the scale
    of the layers, sparser far away, where it varies on the scale of ``rho``),
    ``t = t0 + i h_t`` (source height), ``y3 = y0 + i h_y`` (receiver height); its values
    ``values[offset[k] + ((i_u n_t + i_t) n_y + i_y) 20 + c]``. ``clearance[ls, lr]``: the
    smallest distance of a far triple's point to the receiver's layer; ``near_images``: the
    reflections a source's near triples are traced with (1 where no deeper image merges with
    a near one, :func:`.remainder_build3d.near_images`)."""

    pair_index: np.ndarray  #: (L, L) int64, -1: no table (all triples by quadrature)
    grid: np.ndarray  #: (P, 9)
    offset: np.ndarray  #: (P,) int64
    values: np.ndarray  #: (sum of the pairs' sizes,)
    clearance: np.ndarray  #: (L, L)
    bottoms: np.ndarray  #: (L,) layer bottoms (-inf for the lowest)
    tops: np.ndarray  #: (L,) layer tops (+inf for the highest)
    #: reflections to trace for a source's near triples (:func:`.remainder_build3d.near_images`;
    #: 0: the medium's own ``images``)
    near_images: int = 0
    #: the near triples tabulated in one angle (:class:`.near_table3d.NearTable`; every
    #: constructor passes one, :func:`.near_table3d.empty_near_table` for none;
    #: :func:`.remainder_build3d.empty_table`: a table of neither)
    near: tuple = None


def layer_bounds(interfaces):
    """``(bottoms, tops)`` of the layers (top down) between ``interfaces``."""
    d = np.asarray(interfaces, dtype=np.float64)
    tops = np.concatenate([[np.inf], d])
    bottoms = np.concatenate([d, [-np.inf]])
    return bottoms, tops


@njit(cache=True)
def triple_gap(z, eps, t, source_layer, layer, bottoms, tops):
    """Distance between the receiver layer ``layer`` and the points a triple emanates from
    (``z`` at the source height ``t``, moving as ``eps = dz/dt``) as the source sweeps its
    whole layer: 0 for a near triple, at least a layer thickness for a far one."""
    lo_t = bottoms[source_layer] - t
    hi_t = tops[source_layer] - t
    if eps > 0.0:
        lo = z + eps * lo_t
        hi = z + eps * hi_t
    else:
        lo = z + eps * hi_t
        hi = z + eps * lo_t
    if hi < bottoms[layer]:
        return bottoms[layer] - hi
    if lo > tops[layer]:
        return lo - tops[layer]
    return 0.0


@njit(cache=True)
def layer_gap(source_layer, layer, bottoms, tops):
    """Distance between two layers (0 for the same or adjacent layers)."""
    if layer == source_layer or abs(layer - source_layer) == 1:
        return 0.0
    if layer > source_layer:  # below
        return bottoms[source_layer] - tops[layer]
    return bottoms[layer] - tops[source_layer]


@njit(cache=True)
def is_far(z, eps, t, source_layer, layer, bottoms, tops):
    """True for a far triple: :func:`triple_gap` above round-off of the heights."""
    return triple_gap(z, eps, t, source_layer, layer, bottoms, tops) > 1e-9 * (1.0 + abs(z) + abs(t))


@njit(cache=True)
def keep_near(n, pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef, t, source_layer, bottoms, tops):
    """Drop the far triples (:func:`is_far`) of a traced source point at height ``t``, in
    place; returns the number kept."""
    kept = np.int64(0)  # not a literal: one specialization of copy_triple
    for k in range(n):
        if is_far(pair_z[k], pair_eps[k], t, source_layer, pair_layer[k], bottoms, tops):
            continue
        if kept != k:
            copy_triple(k, kept, pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef)
        kept += 1
    return kept


@njit(cache=True)
def keep_near_range(traced, lo, hi, center, frame, a, b, xi, eta, source_layer, bottoms, tops):
    """:func:`keep_near` on the traced points ``lo .. hi - 1`` of a rule on a rectangle."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(lo, hi):
        t = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
        n_pairs[g] = keep_near(n_pairs[g], layer[g], z[g], eps[g], sigma[g], coef[g], dcoef[g], t, source_layer,
                               bottoms, tops)


@njit(cache=True)
def _response(gradient, out):
    """``out[c] = T[m, s]`` of the :data:`COMPONENTS` from ``gradient[p, q, i, k]`` (force
    ``p``, source derivative ``q``): ``T[m, s] = G[p, q, i, k] (+ G[q, p, i, k] if p != q)``."""
    for c in range(COMPONENTS.shape[0]):
        m = COMPONENTS[c, 0]
        s = COMPONENTS[c, 1]
        p, q = _PAIRS[m, 0], _PAIRS[m, 1]
        i, k = _PAIRS[s, 0], _PAIRS[s, 1]
        v = gradient[p, q, i, k]
        if p != q:
            v += gradient[q, p, i, k]
        out[c] = v


@njit(cache=True)
def trace_room(cap, n_orders):
    """Room for the triples of one traced source point (:func:`.image_tracer3d.trace`): their
    layers, heights, ``eps``, gauges and coefficients (and their derivatives)."""
    return (np.empty(cap, dtype=np.int64), np.empty(cap), np.empty(cap), np.empty(cap),
            np.empty((cap, 3, 3, n_orders)), np.empty((cap, 3, 3, n_orders)))


@njit(cache=True, parallel=True)
def sample_remainder(source_layer, layer, rho, heights, receiver_heights, interfaces, shear_modulus, poisson_ratio,
                     n_images, bottoms, tops, out):
    """``out[i, j, k, c]``: the remainder's response at horizontal offset ``rho[i]`` (along
    x), source height ``heights[j]`` and receiver height ``receiver_heights[k]``: the far
    triples acting in ``layer`` and, two or more layers away, minus the whole-space field of
    the source's material (as :func:`.image_points3d._complementary_gradient` counts it)."""
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    g_r, delta_r, lame_r = receiver_constants(shear_modulus, poisson_ratio, layer)
    g_s = shear_modulus[source_layer]
    nu_s = poisson_ratio[source_layer]
    delta_s = 1.0 / (3.0 - 4.0 * nu_s)
    lame_s = _lame(g_s, nu_s)
    whole_space = layer_gap(source_layer, layer, bottoms, tops) > 0.0
    for j in prange(heights.shape[0]):
        t = heights[j]
        pair_layer, pair_z, pair_eps, pair_sigma, coef, dcoef = trace_room(cap, n_orders)
        n = trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, pair_layer, pair_z, pair_eps,
                  pair_sigma, coef, dcoef)
        work = Workspace(n_orders)
        work1 = Workspace(1)
        kelvin = np.zeros((2, 3, 3, 1))
        _original(kelvin[0], delta_s, g_s, 1.0, -1.0)
        kelvin_down = np.zeros((2, 3, 3, 1))
        _original(kelvin_down[0], delta_s, g_s, -1.0, -1.0)
        gradient = np.zeros((3, 3, 3, 3))
        for i in range(rho.shape[0]):
            for k in range(receiver_heights.shape[0]):
                y3 = receiver_heights[k]
                gradient[:] = 0.0
                for p in range(n):
                    if pair_layer[p] != layer:
                        continue
                    if not is_far(pair_z[p], pair_eps[p], t, source_layer, layer, bottoms, tops):
                        continue
                    _pair_stress_gradient(rho[i], 0.0, y3 - pair_z[p], pair_eps[p], pair_sigma[p], coef[p], dcoef[p],
                                          delta_r, g_r, lame_r, gradient, work)
                if whole_space:
                    up = y3 >= t
                    kc = kelvin if up else kelvin_down
                    _pair_stress_gradient(rho[i], 0.0, y3 - t, 1.0, 1.0 if up else -1.0, kc[0], kc[1], delta_s, g_s,
                                          lame_s, gradient, work1)
                _response(gradient, out[i, j, k])


#: Nodes per variable of the local Lagrange interpolation (degree ``STENCIL - 1``): the
#: error falls like ``(h / clearance)^STENCIL``.
STENCIL = 6
#: Nodes each grid carries beyond either end of its range, so that every stencil in the
#: range is centred. The remainder continues analytically past a layer's boundary; with
#: the source and the receiver both padded, its singular points stay at least
#: ``clearance - 2 PAD h >= clearance / 2`` away (``h <= clearance / 8``).
PAD = STENCIL // 2 - 1
#: ``1 / prod_{b != a} (a - b)`` of :func:`_lagrange`'s weights.
_INVERSE_DENOMINATORS = tuple(1.0 / math.prod(a - b for b in range(STENCIL) if b != a) for a in range(STENCIL))


@njit(cache=True, inline="always")
def _lagrange(x, x0, h, n, w, row):
    """First node and the :data:`STENCIL`-point Lagrange weights ``w[row]`` at ``x`` on the
    grid ``x0 + i h``, ``i < n`` (centred; one-sided at the ends; ``w`` C-contiguous, of
    :data:`STENCIL` columns)."""
    return lagrange_at(x, x0, h, n, data_pointer(w), row * STENCIL)


@njit(cache=True, inline="always")
def lagrange_at(x, x0, h, n, w, at):
    """:func:`_lagrange` with its weights at ``w[at:at + STENCIL]``, ``w`` a pointer
    (:func:`hmatddm.kernels.held_function.data_pointer`: no reference counts in a hot loop)."""
    u = (x - x0) / h
    i0 = int(math.floor(u)) - (STENCIL // 2 - 1)
    if i0 > n - STENCIL:
        i0 = n - STENCIL
    if i0 < 0:
        i0 = 0
    s = u - i0
    # the products of (s - b) over b < a and over b > a, times 1 / prod (a - b): 10
    # multiplications and no division (the 30 divisions of the textbook form were, with
    # asinh, most of the remainder's cost a point: benchmarks/RESULTS.md, thirteenth session)
    left = 1.0
    for a in range(STENCIL):
        w[at + a] = left
        left *= s - a
    right = 1.0
    for a in range(STENCIL - 1, -1, -1):
        w[at + a] *= right * _INVERSE_DENOMINATORS[a]
        right *= s - a
    return i0


@njit(cache=True, inline="always")
def covers(table, source_layer, layer, t, y3, rho):
    """True when the table holds the pair of layers and the point lies in its range (the
    grids less their :data:`PAD` nodes at either end). Inlined: a call took and dropped a
    reference on each of the table's arrays (0.4 us a pair of the issue-32 lattice with
    :func:`rectangle_covered`'s two calls, one thread of the 2-core Xeon)."""
    k = table.pair_index[source_layer, layer]
    if k < 0:
        return False
    grid = table.grid[k]
    t_lo = grid[3] + PAD * grid[4]
    t_hi = grid[3] + (grid[5] - 1.0 - PAD) * grid[4]
    y_lo = grid[6] + PAD * grid[7]
    y_hi = grid[6] + (grid[8] - 1.0 - PAD) * grid[7]
    tol = 1e-9 * (t_hi - t_lo + y_hi - y_lo + 1.0)
    u_hi = (grid[2] - 1.0 - 2.0 * PAD) * grid[1]
    return (math.asinh(rho / grid[0]) <= u_hi + 1e-12 and t_lo - tol <= t <= t_hi + tol
            and y_lo - tol <= y3 <= y_hi + tol)


@njit(cache=True, inline="always")
def interpolation_scratch():
    """The scratch ``w`` of :func:`interpolate`: the Lagrange weights of the three variables."""
    return np.empty((3, STENCIL))


@njit(cache=True, inline="always")
def interpolate(table, source_layer, layer, rho, t, y3, out, w):
    """``out[c]``: the tabulated response at ``(rho, t, y3)`` (``w``: :func:`interpolation_scratch`).
    The :data:`STENCIL` nodes along ``y3`` are one contiguous run of values: contracted
    there first, into a register, then added once to ``out`` (3x faster than adding every
    node's values to ``out``, whose stores LLVM could not keep in registers). Indexed
    through a slice of the run: ``values[at + ...]`` measured 2.3x slower (the index's
    sign is checked at every load, and the loop is no longer vectorised). Inlined: a call
    makes its callers take and drop a reference count on each array, atomic operations."""
    k = table.pair_index[source_layer, layer]
    grid = table.grid
    values = table.values
    n_t = int(grid[k, 5])
    n_y = int(grid[k, 8])
    i0 = _lagrange(math.asinh(rho / grid[k, 0]), -PAD * grid[k, 1], grid[k, 1], int(grid[k, 2]), w, 0)
    j0 = _lagrange(t, grid[k, 3], grid[k, 4], n_t, w, 1)
    k0 = _lagrange(y3, grid[k, 6], grid[k, 7], n_y, w, 2)
    base = table.offset[k]
    n_c = out.shape[0]
    for c in range(n_c):
        out[c] = 0.0
    for a in range(STENCIL):
        for b in range(STENCIL):
            wab = w[0, a] * w[1, b]
            at = base + (((i0 + a) * n_t + j0 + b) * n_y + k0) * n_c
            run = values[at:at + STENCIL * n_c]
            for c in range(n_c):
                v = 0.0
                for d in range(STENCIL):
                    v += w[2, d] * run[d * n_c + c]
                out[c] += wab * v


@njit(cache=True, inline="always")
def remainder_point_stress(table, y, layer, x, source_layer, normal, shear_modulus, lame, weight, out, response, w):
    """``out[b, i, k] += weight *`` the remainder's stress at ``y`` (in ``layer``) of a unit
    DD density along global ``b`` at ``x`` (in ``source_layer``) on a plane of ``normal``,
    the source layer's moduli (``response``, ``w`` (:func:`interpolation_scratch`):
    scratch): the table in the frame rotated about z towards the receiver, contracted with
    the rotated moment tensor and rotated back (:func:`.turned_response3d.rotated_stress`).
    No call and no array view: numba takes no reference counts (atomic operations) in the
    loop over the points of a rule."""
    r1 = y[0] - x[0]
    r2 = y[1] - x[1]
    rho = math.sqrt(r1 * r1 + r2 * r2)
    c = 1.0
    s = 0.0
    if rho > 0.0:
        c = r1 / rho
        s = r2 / rho
    interpolate(table, source_layer, layer, rho, x[2], y[2], response, w)
    rotated_stress(c, s, normal, shear_modulus, lame, weight, response, out)


@njit(cache=True, inline="always")
def rectangle_covered(table, y, layer, center, frame, a, b, source_layer):
    """True when the table covers every point of the rectangle against the receiver ``y``."""
    if table.pair_index[source_layer, layer] < 0:
        return False
    dz = a * abs(frame[0, 2]) + b * abs(frame[1, 2])
    r1 = y[0] - center[0]
    r2 = y[1] - center[1]
    reach = math.sqrt(r1 * r1 + r2 * r2) + a + b
    return (covers(table, source_layer, layer, center[2] - dz, y[2], reach)
            and covers(table, source_layer, layer, center[2] + dz, y[2], reach))


@njit(cache=True)
def remainder_rectangle_stress(table, y, layer, center, frame, a, b, source_layer, shear_modulus, lame, xi, eta, wt,
                               out):
    """``out[b, i, k] +=`` the remainder's stress at ``y`` of a unit global DD ``b`` on the
    rectangle, by the rule ``(xi, eta, wt)`` on [-1, 1]^2. The receiver's height, so its
    nodes and weights along ``y3``, is the same at every point of the rule, and the points'
    stencils along ``(u, t)`` overlap: the values are contracted along ``y3`` once per node
    of the box that the stencils cover, then each point takes its ``STENCIL^2`` nodes from
    there (the same sums, in the same order, as :func:`interpolate`'s), unless the box has
    as many nodes as the points' stencils together (:func:`remainder_point_stress` then)."""
    n = xi.shape[0]
    x = np.empty(3)
    response = np.empty(COMPONENTS.shape[0])
    w = interpolation_scratch()
    normal = frame[2]
    jac = a * b
    k = table.pair_index[source_layer, layer]
    grid = table.grid
    n_t = int(grid[k, 5])
    n_y = int(grid[k, 8])
    n_c = COMPONENTS.shape[0]
    nodes = np.empty((n, 2), dtype=np.int64)
    weights = np.empty((2 * n, STENCIL))
    i_lo, i_hi, j_lo, j_hi = 1 << 62, 0, 1 << 62, 0
    for g in range(n):
        for c in range(3):
            x[c] = center[c] + xi[g] * a * frame[0, c] + eta[g] * b * frame[1, c]
        r1 = y[0] - x[0]
        r2 = y[1] - x[1]
        rho = math.sqrt(r1 * r1 + r2 * r2)
        nodes[g, 0] = _lagrange(math.asinh(rho / grid[k, 0]), -PAD * grid[k, 1], grid[k, 1], int(grid[k, 2]),
                                weights, 2 * g)
        nodes[g, 1] = _lagrange(x[2], grid[k, 3], grid[k, 4], n_t, weights, 2 * g + 1)
        i_lo, i_hi = min(i_lo, nodes[g, 0]), max(i_hi, nodes[g, 0])
        j_lo, j_hi = min(j_lo, nodes[g, 1]), max(j_hi, nodes[g, 1])
    n_i = i_hi - i_lo + STENCIL
    n_j = j_hi - j_lo + STENCIL
    if n_i * n_j >= n * STENCIL * STENCIL:
        for g in range(n):
            for c in range(3):
                x[c] = center[c] + xi[g] * a * frame[0, c] + eta[g] * b * frame[1, c]
            remainder_point_stress(table, y, layer, x, source_layer, normal, shear_modulus, lame, wt[g] * jac, out,
                                   response, w)
        return
    k0 = _lagrange(y[2], grid[k, 6], grid[k, 7], n_y, w, 2)
    contracted = np.empty((n_i * n_j, n_c))
    values = table.values
    for i in range(n_i):
        for j in range(n_j):
            at = table.offset[k] + (((i_lo + i) * n_t + j_lo + j) * n_y + k0) * n_c
            run = values[at:at + STENCIL * n_c]
            for c in range(n_c):
                v = 0.0
                for d in range(STENCIL):
                    v += w[2, d] * run[d * n_c + c]
                contracted[i * n_j + j, c] = v
    for g in range(n):
        for c in range(n_c):
            response[c] = 0.0
        for p in range(STENCIL):
            for q in range(STENCIL):
                wpq = weights[2 * g, p] * weights[2 * g + 1, q]
                row = (nodes[g, 0] - i_lo + p) * n_j + nodes[g, 1] - j_lo + q
                for c in range(n_c):
                    response[c] += wpq * contracted[row, c]
        for c in range(3):
            x[c] = center[c] + xi[g] * a * frame[0, c] + eta[g] * b * frame[1, c]
        r1 = y[0] - x[0]
        r2 = y[1] - x[1]
        rho = math.sqrt(r1 * r1 + r2 * r2)
        cos, sin = (r1 / rho, r2 / rho) if rho > 0.0 else (1.0, 0.0)
        rotated_stress(cos, sin, normal, shear_modulus, lame, wt[g] * jac, response, out)
