"""The near image triples of the 3D image method tabulated in one angle (issue 32, items 1
and 2): their field at a point is exact up to an interpolation in the angle alone.

With two or more interfaces the image field of a point source (ref. Secs 3.2-3.3) is split
into the tabulated *layered remainder* (:mod:`.remainder_table3d`) and the *near* triples:
the source's first reflections in the interfaces of its layer and its transmissions into
the next layers (with the whole-space field of the source's material that the next layer
subtracts, :mod:`.image_points3d`). Those were integrated by Gauss quadrature over the source
rectangle, each point costing a Hansen triple evaluated to derivative order 5 (~1 us a
triple, three to four triples a point, ~2/3 of a three-layer entry on the issue-32 lattice;
one thread of the 2-core Xeon at dgemm 86 GFLOP/s).

A near triple involves one interface ``z = d`` and the two materials beside it, and no other
length: its coefficients of ``D^n`` are ``a_n (t - d)^n`` (``t`` the source height), its
point is the source point or the source's mirror ``2 d - t``, and every term of its stress
gradient is homogeneous of degree -3 in the receiver's offset ``r`` from that point and in
``t - d`` together (measured to 1e-14 for every near triple of a free surface over two
interfaces). So, in the frame turned about the vertical towards the receiver (as the
remainder's table, :data:`.remainder_table3d.COMPONENTS`), the response of a *group* (the
near triples of a pair of layers that share one interface) is

    T(r, t) = R^-3 sum_k tau^k h_k(theta),   R = |r|,  tau = (t - d) / R,
    theta = the angle of r from the vertical (0 .. pi / 2: the receivers' side),

a polynomial of degree < :data:`DEGREES` in ``tau`` (the ``D`` orders of a near triple: 0 to
2) whose coefficients are functions of the angle alone, analytic on ``[0, pi / 2]`` (the
singular half-line of the triple's gauge lies at ``theta = pi``). They are tabulated once per
medium (:func:`build_near_table`) from the image sum itself (:func:`sample_group`: the
polynomial fitted through three heights, a fourth checks it) on a uniform grid of
``v = tan(theta / 2) = rho / (R + |r3|)`` over ``[0, 1]`` (analytic in ``v`` too: a division
where ``theta`` took an ``atan2``, a fifth of a point's cost),
interpolated by the remainder's :data:`.remainder_table3d.STENCIL`-point Lagrange rule, the
grid halved until the interpolation's error, at random angles and heights against the image
sum, is below :data:`NEAR_TABLE_TOL` of the group's largest value. The quadrature's rules stay
the same (the integrand is the same function), a point costs a table lookup instead of a
triple evaluation, and the moment contraction and the rotation back are done once per point
for every group (:func:`near_rectangle_stress`).

Built with the remainder's table (the near triples of a medium whose far triples are
tabulated, traced with one reflection: :func:`.remainder_build3d.near_images` = 1); the
quadrature of the triples stays the cross-check (``LayeredMedium(method="quadrature")``, or
this table left out: :func:`empty_near_table`)."""
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .image_tracer import trace_capacity
from .image_tracer3d import trace
from .images2d import receiver_constants
from .potentials3d import Workspace, _original, _pair_stress_gradient
from ..kernels.held_function import data_pointer, dereference, item
from .remainder_rows3d import ROWS_ITEM, rows_add, rows_view
from .remainder_table3d import (COMPONENTS, PAD, STENCIL, _response, keep_near, lagrange_at,
                                layer_bounds, trace_room)
from .turned_response3d import rotated_stress

#: Powers of ``tau`` of a group's response (the ``D`` orders of a first reflection: 0 to 2).
DEGREES = 3
#: Error of the interpolation in the angle allowed relative to the group's largest value of
#: ``R^3 T`` (the entries' image parts are at most the largest entry: a few 1e-11 of it).
NEAR_TABLE_TOL = 1e-11
#: Intervals of the first grid over ``v`` in ``[0, 1]`` (``theta`` in ``[0, pi / 2]``); halved until
#: :data:`NEAR_TABLE_TOL` holds.
FIRST_NODES = 64
#: Most angles of a grid (the refinement stops there; the group then stays on the quadrature).
MAX_NODES = 8192
#: Random (angle, height) pairs at which a group's interpolation error is measured.
NEAR_ERROR_SAMPLES = 200
#: The three heights (in units of the sampling radius) the polynomial in ``tau`` is fitted
#: through, and the fourth that checks it.
FIT_TAUS = (0.25, 0.5, 0.75, 0.9)

_N_C = COMPONENTS.shape[0]


class NearTable(NamedTuple):
    """The tabulated near triples of a medium (none: ``group`` all -1).

    ``group[ls, lr, side]``: the group of the near triples of a source in layer ``ls`` at a
    receiver in layer ``lr`` whose interface is the top (``side`` 0) or the bottom (1) of the
    source's layer, -1 where there is none or it is not tabulated; ``ready[ls, lr]``: every
    group of the pair tabulated (the quadrature takes the pair otherwise). Group ``q``:
    ``anchor[q]`` the interface's height, ``reflected[q]`` 1 when the triples' point is the
    source's mirror ``2 d - t`` (0: the source point); its values
    ``values[((q n + i) DEGREES + k) 20 + c]`` at ``v_i = tan(theta_i / 2) = (i - PAD) step``."""

    group: np.ndarray  #: (L, L, 2) int64
    ready: np.ndarray  #: (L, L) bool
    anchor: np.ndarray  #: (G,)
    reflected: np.ndarray  #: (G,)
    values: np.ndarray  #: (G n DEGREES 20,)
    step: float  #: spacing of the nodes in ``v = tan(theta / 2)``
    n_nodes: int  #: nodes of every group's grid (the pads included)


def empty_near_table(n_layers):
    """A near table that tabulates nothing (every near triple by quadrature)."""
    return NearTable(-np.ones((n_layers, n_layers, 2), dtype=np.int64), np.zeros((n_layers, n_layers), dtype=np.bool_),
                     np.zeros(1), np.zeros(1), np.zeros(DEGREES * _N_C * STENCIL), 1.0, STENCIL)


def group_geometry(ls, lr, side, interfaces):
    """``(anchor, reflected, source_side, receiver_sign)`` of the group ``(ls, lr, side)``, or
    ``None`` where it has no triples: the interface's height; 1.0 for reflections (the
    receiver in the source's layer), 0.0 for transmissions (the next layer, across
    ``side``'s interface); the sign of ``t - d`` of sources in ``ls``; the sign of the
    receiver's vertical offset from the triples' point."""
    k = ls - 1 if side == 0 else ls  # the interface above (side 0) or below (1) the layer
    if k < 0 or k >= len(interfaces):
        return None
    source_side = -1.0 if side == 0 else 1.0  # sources lie below their top, above their bottom
    if lr == ls:
        return float(interfaces[k]), 1.0, source_side, source_side
    if lr == ls + (-1 if side == 0 else 1):
        return float(interfaces[k]), 0.0, source_side, -source_side
    return None


@njit(cache=True)
def sample_group(ls, lr, anchor, reflected, source_side, receiver_sign, thetas, taus, radius, interfaces,
                 shear_modulus, poisson_ratio, bottoms, tops, out):
    """``out[i, j, c] = R^3 T`` of the group at the angle ``thetas[i]``, ``tau = taus[j]``
    (``t = anchor + source_side tau radius``, ``R = radius``): the near triples of a source at
    height ``t`` traced with one reflection (:func:`.remainder_table3d.keep_near`) whose
    point is the group's, at the receiver ``R (sin theta, 0, receiver_sign cos theta)`` from
    it, with the whole-space field of the source's material subtracted in another layer (as
    :func:`.image_points3d._complementary_gradient` counts it); ``bottoms``, ``tops``: the
    layers' (:func:`.remainder_table3d.layer_bounds`)."""
    cap, n_orders = trace_capacity(ls, shear_modulus, 1)
    g_r, delta_r, lame_r = receiver_constants(shear_modulus, poisson_ratio, lr)
    g_s, delta_s, lame_s = receiver_constants(shear_modulus, poisson_ratio, ls)  # the source layer's
    pair_layer, pair_z, pair_eps, pair_sigma, coef, dcoef = trace_room(cap, n_orders)
    work = Workspace(n_orders)
    work1 = Workspace(1)
    gradient = np.zeros((3, 3, 3, 3))
    scale = radius ** 3
    for j in range(taus.shape[0]):
        t = anchor + source_side * taus[j] * radius
        n = trace(t, ls, interfaces, shear_modulus, poisson_ratio, 1, pair_layer, pair_z, pair_eps, pair_sigma, coef,
                  dcoef)
        n = keep_near(n, pair_layer, pair_z, pair_eps, pair_sigma, coef, dcoef, t, ls, bottoms, tops)
        point = 2.0 * anchor - t if reflected > 0.0 else t
        kelvin = np.zeros((2, 3, 3, 1))
        sigma = receiver_sign
        _original(kelvin[0], delta_s, g_s, sigma, -1.0)
        for i in range(thetas.shape[0]):
            rho = radius * math.sin(thetas[i])
            r3 = receiver_sign * radius * math.cos(thetas[i])
            gradient[:] = 0.0
            for p in range(n):
                if pair_layer[p] == lr and abs(pair_z[p] - point) <= 1e-9 * (1.0 + abs(point)):
                    _pair_stress_gradient(rho, 0.0, r3, pair_eps[p], pair_sigma[p], coef[p], dcoef[p], delta_r, g_r,
                                          lame_r, gradient, work)
            if reflected <= 0.0:
                _pair_stress_gradient(rho, 0.0, r3, 1.0, sigma, kelvin[0], kelvin[1], delta_s, g_s, lame_s, gradient,
                                      work1)
            _response(gradient, out[i, j])
            for c in range(out.shape[2]):
                out[i, j, c] *= scale


@njit(cache=True, inline="always")
def _add_group(near, q, rho, t, y3, response, w):
    """``response[c] +=`` group ``q``'s tabulated response at the horizontal offset ``rho``
    from a source point at height ``t``, the receiver at height ``y3`` (``w``: (1, STENCIL)
    scratch)."""
    _add_group_at(data_pointer(near.anchor), data_pointer(near.reflected), data_pointer(near.values), near.step,
                  near.n_nodes, q, rho, t, y3, data_pointer(response), data_pointer(w))


@njit(cache=True, inline="always")
def _add_group_at(anchor, reflected, values, step, n, q, rho, t, y3, response, w):
    """:func:`_add_group` on pointers to the table's arrays, the response and the scratch
    (:func:`hmatddm.kernels.held_function.data_pointer`, taken once a rule): indexed
    without reference counts (~10 calls of numba's ``NRT_incref``/``NRT_decref`` a lookup
    with arrays) or checks for a negative index (LLVM gathered a stencil's loads one by
    one: half a lookup's cost)."""
    d = anchor[q]
    point = 2.0 * d - t if reflected[q] > 0.0 else t
    r3 = y3 - point
    r2 = rho * rho + r3 * r3
    if r2 <= 0.0:
        return
    radius = math.sqrt(r2)
    inv3 = 1.0 / (r2 * radius)
    tau = abs(t - d) / radius
    i0 = lagrange_at(rho / (radius + abs(r3)), -PAD * step, step, n, w, 0)  # tan(theta / 2)
    at = (q * n + i0) * DEGREES * _N_C
    # each power of tau (DEGREES = 3 of them) summed over the stencil in a register, then
    # once into the response (its stores were a tenth of a group's cost)
    for c in range(_N_C):
        v0 = 0.0
        v1 = 0.0
        v2 = 0.0
        for s in range(STENCIL):
            k = at + s * DEGREES * _N_C + c
            ws = w[s]
            v0 += ws * values[k]
            v1 += ws * values[k + _N_C]
            v2 += ws * values[k + 2 * _N_C]
        response[c] += inv3 * (v0 + tau * (v1 + tau * v2))


@njit(cache=True)
def near_rectangle_stress(near, y, lr, center, frame, a, b, ls, shear_modulus, lame, xi, eta, wt, lo, hi, side_lo,
                          side_hi, table, rows, entry, out):
    """``out[b, i, k] +=`` the near triples' stress at ``y`` (in ``lr``) of a unit global DD
    ``b`` on the rectangle (in ``ls``, its moduli ``shear_modulus``, ``lame``) by the points
    ``lo .. hi - 1`` of the rule ``(xi, eta, wt)`` on [-1, 1]^2 (whole arrays and a range,
    not slices: one compiled signature for the cached rules and the sub-squares'), the
    groups of sides ``side_lo <= side < side_hi`` (the top interface's 0, the bottom's 1):
    at each point the groups' tabulated responses summed in the frame turned towards the
    receiver, contracted with the moment and turned back once
    (:func:`.turned_response3d.rotated_stress`); with the remainder's table at the same
    points too, through the rows' ``entry`` of ``rows`` (:func:`.remainder_rows3d.rows_add`;
    -1: not here)."""
    _rule_stress(near, y, lr, center, frame, a, b, ls, shear_modulus, lame, xi, eta, wt, lo, hi, side_lo, side_hi,
                 table, rows, entry, out)


@njit(cache=True, no_cpython_wrapper=True)  # compiled callers only
def near_rule_stress(data_at, work_at, y, lr, center, frame, a, b, ls, shear_modulus, lame, xi, eta, wt, lo, hi,
                     side_lo, side_hi, entry, out):
    """:func:`near_rectangle_stress` of the record's table, the rows those of the workspace
    (:mod:`.workspace3d`), both by pointer (:mod:`hmatddm.kernels.held_function`): what
    :func:`.images3d._complementary_stress` calls, two pointers where the near table, the
    remainder's and the rows are 35 arrays, each split into its fields for a call by value
    (no measurable difference on the issue-32 lattice alone; the arrays the loop reads are
    taken as pointers once a rule, :func:`_rule_stress`: RESULTS.md, fourteenth session)."""
    table = dereference(data_at).table
    _rule_stress(table.near, y, lr, center, frame, a, b, ls, shear_modulus, lame, xi, eta, wt, lo, hi, side_lo,
                 side_hi, table, item(work_at, ROWS_ITEM), entry, out)


@njit(cache=True, inline="always")
def _rule_stress(near, y, lr, center, frame, a, b, ls, shear_modulus, lame, xi, eta, wt, lo, hi, side_lo, side_hi,
                 table, rows, entry, out):
    """:func:`near_rectangle_stress` (inlined into it and into :func:`near_rule_stress`)."""
    normal = frame[2]
    jac = a * b
    response, w = rows[11], rows[12]  # the workspace's scratch, not allocated a call
    # the lookups' arrays as pointers, taken once (_add_group_at)
    anchor, reflected, values = data_pointer(near.anchor), data_pointer(near.reflected), data_pointer(near.values)
    response_at, w_at, step, n_nodes = data_pointer(response), data_pointer(w), near.step, near.n_nodes
    view = rows_view(table, rows, max(entry, 0), lr, ls)  # the rows' pointers, taken once (entry >= 0)
    q0 = near.group[ls, lr, 0] if side_lo <= 0 < side_hi else -1
    q1 = near.group[ls, lr, 1] if side_lo <= 1 < side_hi else -1
    for g in range(lo, hi):
        x0 = center[0] + xi[g] * a * frame[0, 0] + eta[g] * b * frame[1, 0]
        x1 = center[1] + xi[g] * a * frame[0, 1] + eta[g] * b * frame[1, 1]
        x2 = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
        r1 = y[0] - x0
        r2 = y[1] - x1
        rho = math.sqrt(r1 * r1 + r2 * r2)
        for c in range(_N_C):
            response[c] = 0.0
        if q0 >= 0:
            _add_group_at(anchor, reflected, values, step, n_nodes, q0, rho, x2, y[2], response_at, w_at)
        if q1 >= 0:
            _add_group_at(anchor, reflected, values, step, n_nodes, q1, rho, x2, y[2], response_at, w_at)
        if entry >= 0:
            rows_add(view, entry, rho, g - lo, hi - lo, response_at)
        cos, sin = (r1 / rho, r2 / rho) if rho > 0.0 else (1.0, 0.0)
        rotated_stress(cos, sin, normal, shear_modulus, lame, wt[g] * jac, response, out)


def _fit(samples):
    """The coefficients of ``tau^k`` (``k < DEGREES``) through the first ``DEGREES`` samples
    along axis 1 (at :data:`FIT_TAUS`), and the largest misfit at the last, relative."""
    taus = np.asarray(FIT_TAUS)
    vander = np.vander(taus[:DEGREES], DEGREES, increasing=True)
    coefficients = np.einsum("kj,ijc->ikc", np.linalg.inv(vander), samples[:, :DEGREES])
    check = np.einsum("k,ikc->ic", taus[DEGREES] ** np.arange(DEGREES), coefficients)
    scale = max(float(np.max(np.abs(samples))), 1e-300)
    return coefficients, float(np.max(np.abs(check - samples[:, DEGREES]))) / scale


def _group_error(near, q, geometry, ls, lr, radius, interfaces, g, nu, rng):
    """Largest error of group ``q``'s interpolation at random angles and physical heights
    (``tau <= cos theta``) against the image sum, relative to its largest sampled value."""
    anchor, reflected, source_side, receiver_sign = geometry
    thetas = rng.uniform(0.0, 0.5 * math.pi, NEAR_ERROR_SAMPLES)
    taus = rng.uniform(0.02, 1.0, NEAR_ERROR_SAMPLES) * np.cos(thetas)
    worst, largest = 0.0, 1e-300
    direct = np.empty((1, 1, _N_C))
    w = np.empty((1, STENCIL))
    response = np.empty(_N_C)
    for theta, tau in zip(thetas, taus):
        sample_group(ls, lr, anchor, reflected, source_side, receiver_sign, np.array([theta]), np.array([tau]),
                     radius, interfaces, g, nu, *layer_bounds(interfaces), direct)
        t = anchor + source_side * tau * radius
        point = 2.0 * anchor - t if reflected > 0.0 else t
        response[:] = 0.0
        _add_group(near, q, radius * math.sin(theta), t, point + receiver_sign * radius * math.cos(theta), response,
                   w)
        worst = max(worst, float(np.max(np.abs(response * radius ** 3 - direct[0, 0]))))
        largest = max(largest, float(np.max(np.abs(direct))))
    return worst / largest


def build_near_table(interfaces, shear_modulus, poisson_ratio, seed=0):
    """The :class:`NearTable` of every pair of solid layers that share an interface (and of
    each layer with itself), each group sampled by :func:`sample_group` and its grid of angles
    halved from :data:`FIRST_NODES` until its error (:func:`_group_error`) is below
    :data:`NEAR_TABLE_TOL`; a group whose polynomial in ``tau`` does not fit (a misfit above
    1e-10) or whose grid would pass :data:`MAX_NODES` is left to the quadrature, as is its
    pair. Returns ``(table, stats)``."""
    interfaces = np.asarray(interfaces, dtype=np.float64)
    g = np.asarray(shear_modulus, dtype=np.float64)
    nu = np.asarray(poisson_ratio, dtype=np.float64)
    n_layers = g.shape[0]
    rng = np.random.default_rng(seed)
    thickness = np.diff(interfaces[::-1]) if interfaces.shape[0] > 1 else np.array([1.0])
    radius = 0.5 * min(1.0, float(np.min(thickness)))  # every sampled height inside its layer
    specs = []
    for ls in range(n_layers):
        for lr in range(max(ls - 1, 0), min(ls + 2, n_layers)):
            if g[ls] <= 0.0 or g[lr] <= 0.0:
                continue
            for side in range(2):
                geometry = group_geometry(ls, lr, side, interfaces)
                if geometry is not None:
                    specs.append((ls, lr, side, geometry))
    stats = dict(near_groups=0, near_nodes=0, near_error=0.0)
    if not specs:
        return empty_near_table(n_layers), stats
    nodes = FIRST_NODES
    while True:
        step = 1.0 / nodes
        n_nodes = nodes + 1 + 2 * PAD
        thetas = 2.0 * np.arctan((np.arange(n_nodes) - PAD) * step)
        blocks, kept, worst = [], [], 0.0
        for ls, lr, side, geometry in specs:
            samples = np.empty((n_nodes, len(FIT_TAUS), _N_C))
            sample_group(ls, lr, geometry[0], geometry[1], geometry[2], geometry[3], thetas, np.asarray(FIT_TAUS),
                         radius, interfaces, g, nu, *layer_bounds(interfaces), samples)
            coefficients, misfit = _fit(samples)
            if misfit > 1e-10:
                continue
            kept.append((ls, lr, side, geometry))
            blocks.append(coefficients)
        group = -np.ones((n_layers, n_layers, 2), dtype=np.int64)
        for q, (ls, lr, side, _) in enumerate(kept):
            group[ls, lr, side] = q
        near = NearTable(group, np.zeros((n_layers, n_layers), dtype=np.bool_),
                         np.array([s[3][0] for s in kept] or [0.0]), np.array([s[3][1] for s in kept] or [0.0]),
                         np.concatenate([b.ravel() for b in blocks]) if blocks else np.zeros(1), step, n_nodes)
        for q, (ls, lr, side, geometry) in enumerate(kept):
            worst = max(worst, _group_error(near, q, geometry, ls, lr, radius, interfaces, g, nu, rng))
        if worst <= NEAR_TABLE_TOL or 2 * nodes > MAX_NODES:
            break
        nodes *= 2
    if worst > NEAR_TABLE_TOL:
        return empty_near_table(n_layers), dict(stats, near_refused=f"error {worst:.1e} at {nodes} angles")
    ready = np.zeros((n_layers, n_layers), dtype=np.bool_)
    for ls, lr, side, geometry in specs:
        ready[ls, lr] = True
    for ls, lr, side, geometry in specs:
        if group[ls, lr, side] < 0:
            ready[ls, lr] = False
    stats.update(near_groups=len(kept), near_nodes=n_nodes, near_error=worst)
    return near._replace(ready=ready), stats
