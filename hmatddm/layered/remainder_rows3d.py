"""The tabulated layered remainder (:mod:`.remainder_table3d`) of one source at the receivers
of one height, its contraction along the receiver's height done once (issue 32).

:func:`.remainder_table3d.remainder_rectangle_stress` contracts the table along the receiver
height ``y3`` for the box of ``(u, t)`` nodes that its points' stencils cover, then takes
``STENCIL^2`` nodes a point. With the near triples tabulated (:mod:`.near_table3d`) that
box was ~3/5 of a three-layer entry on the issue-32 lattice (3.6 of 5.9 us, one thread of
the 2-core Xeon at dgemm 75-87 GFLOP/s). But the drivers take the
receivers of one source after another (:func:`hmatddm.kernels.drivers.traction_block`), and
receivers share heights (the rows of a fracture's elements, the lattice's 9 depths): the
box's nodes along ``t`` are the source's (its rule's points keep their heights), its nodes
along ``u`` depend on the receiver's distance. So an *entry* ``(source, receiver layer,
receiver height, rule)`` keeps, for each node of ``u``, the table contracted along ``y3``
and along ``t`` with each of the rule's points' weights: a *row* of 20 components a point,
filled the first time a receiver of that height needs it; the next receivers of the height
take ``STENCIL`` rows a point (``STENCIL`` times 20 products, not ``STENCIL^2`` times 20
and the box's ``STENCIL`` times more), without touching the table. The sums are the box's,
in another order (round-off).

Where the near triples' rule is the remainder's, they are added at the same points
(:func:`.near_table3d.near_rectangle_stress` with :func:`rows_add`): one turn of the frame a
point. The entries (:data:`ENTRIES`, reused round-robin) live in the workspace. A source takes them
from its :data:`ROWS_AFTER`-th receiver on, so that an H-matrix's sampled entries (one
receiver a source) never fill rows they would not reuse."""
import math

import numpy as np
from numba import njit

from .rectangle_quadrature import one_square_order
from ..kernels.held_function import data_pointer
from .remainder_table3d import COMPONENTS, PAD, STENCIL, _lagrange, lagrange_at

#: Entries kept (source, receiver layer, receiver height, rule), reused round-robin.
ENTRIES = 48
#: Most ``t`` nodes of a source's box (its rule's points spread over ``BOX_T - STENCIL + 1``
#: nodes; a wider box takes the table directly).
BOX_T = STENCIL + 4
#: A source takes the rows from its receiver after this many (an H-matrix's sampled rows and
#: columns take one receiver a source).
ROWS_AFTER = 8
#: Most points of a rule that takes the rows (3 x 3: the remainder's singular points are a
#: layer away, its rules one square of 1 to 3 points per side).
MOST_POINTS = 9

#: The rows' place in the workspace's tuple (:func:`.workspace3d.workspace_arrays`).
ROWS_ITEM = 14

_N_C = COMPONENTS.shape[0]


@njit(cache=True)
def remainder_rows(table):
    """The workspace's room: ``(rows, filled, keys, heights, t_nodes, t_weights, y_weights,
    state, u_nodes, u_weights, box, response, weights)`` -- the rows of :data:`ENTRIES`
    entries for the largest grid's nodes of ``u`` (empty without a table), which rows hold
    values, each entry's ``(source, layer, rule's first point, first t node of its box, t
    nodes)``, its receiver height, its points' ``t`` stencils (first nodes, weights) and its
    ``y3`` stencil (first node, weights), ``(next entry, source served, receivers served)``,
    a pair's ``u`` stencils, the box's contraction along ``y3`` a fill, and a point's
    response and stencil weights for :func:`.near_table3d.near_rectangle_stress` (arrays it
    allocated a call)."""
    n_u = 0
    if table.pair_index.max() >= 0:
        for k in range(table.grid.shape[0]):
            n_u = max(n_u, int(table.grid[k, 2]))
    n_entries = ENTRIES if n_u > 0 else 0
    room = max(n_entries, 1)
    keys = np.full((room, 5), -1, dtype=np.int64)
    state = np.zeros(3, dtype=np.int64)
    state[1] = -1
    return (np.empty(n_entries * n_u * MOST_POINTS * _N_C), np.zeros((n_entries, n_u), dtype=np.bool_), keys,
            np.zeros(room), np.zeros((room, MOST_POINTS), dtype=np.int64), np.zeros((room, MOST_POINTS, STENCIL)),
            np.zeros((room, STENCIL + 1)), state, np.empty(MOST_POINTS, dtype=np.int64),
            np.empty((MOST_POINTS, STENCIL)), np.empty(BOX_T * _N_C), np.empty(_N_C), np.empty((1, STENCIL)))


@njit(cache=True, inline="always")
def takes_rows(rows, j, n_points):
    """Count a receiver of source ``j`` and say whether its remainder (a rule of ``n_points``)
    takes the rows."""
    state = rows[7]
    if state[1] != j:
        state[1] = j
        state[2] = 0
    state[2] += 1
    return state[2] > ROWS_AFTER and n_points <= MOST_POINTS and rows[1].shape[0] > 0


@njit(cache=True, inline="always")
def rows_entry(table, rows, j, y, layer, center, frame, a, b, source_layer, xi, eta, lo, hi):
    """The entry ``(j, layer, lo, y3)`` of the rows (:func:`remainder_rows`): found, or the next
    one taken over for it (its points' ``t`` stencils and its ``y3`` stencil set, no row
    filled); -1 where the source's box is wider than :data:`BOX_T` nodes along ``t``."""
    keys, heights, t_nodes, t_weights, y_weights, state, u_nodes, w = (rows[2], rows[3], rows[4], rows[5], rows[6],
                                                                       rows[7], rows[8], rows[9])
    for f in range(keys.shape[0]):
        if keys[f, 0] == j and keys[f, 1] == layer and keys[f, 2] == lo and heights[f] == y[2]:
            return f
    k = table.pair_index[source_layer, layer]
    grid = table.grid
    j_lo, j_hi = 1 << 62, 0
    for g in range(lo, hi):  # the points' t stencils (w and u_nodes: scratch here)
        x2 = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
        u_nodes[g - lo] = _lagrange(x2, grid[k, 3], grid[k, 4], int(grid[k, 5]), w, g - lo)
        j_lo, j_hi = min(j_lo, u_nodes[g - lo]), max(j_hi, u_nodes[g - lo])
    if j_hi - j_lo + STENCIL > BOX_T:
        return -1
    e = state[0]
    state[0] = (e + 1) % keys.shape[0]
    keys[e, 0], keys[e, 1], keys[e, 2], keys[e, 3], keys[e, 4] = j, layer, lo, j_lo, j_hi - j_lo + STENCIL
    heights[e] = y[2]
    for p in range(hi - lo):
        t_nodes[e, p] = u_nodes[p]
        for q in range(STENCIL):
            t_weights[e, p, q] = w[p, q]
    y_weights[e, 0] = _lagrange(y[2], grid[k, 6], grid[k, 7], int(grid[k, 8]), w, 0)
    for d in range(STENCIL):
        y_weights[e, 1 + d] = w[0, d]
    filled = rows[1]
    for u in range(filled.shape[1]):
        filled[e, u] = False
    return e


@njit(cache=True, inline="always")
def rows_view(table, rows, e, layer, source_layer):
    """Entry ``e``'s rows for :func:`rows_add`, taken once a rule: pointers to the rows, their
    flags and stencils, the table's values
    (:func:`hmatddm.kernels.held_function.data_pointer`: numba calls ``NRT_incref`` and
    ``NRT_decref``, functions it never inlines, for each array an inlined function takes, a
    dozen a point) and the constants of the entry and its layer pair."""
    k = max(table.pair_index[source_layer, layer], 0)  # (a pair without a table takes no rows)
    grid = table.grid
    keys, y_weights = rows[2], rows[6]
    return (data_pointer(rows[0]), data_pointer(rows[1]), data_pointer(rows[4]), data_pointer(rows[5]),
            data_pointer(y_weights), data_pointer(rows[9]), data_pointer(rows[10]), data_pointer(table.values),
            table.offset[k], int(grid[k, 5]), int(grid[k, 8]), rows[1].shape[1], int(y_weights[e, 0]), keys[e, 3],
            keys[e, 4], grid[k, 0], grid[k, 1], int(grid[k, 2]))


@njit(cache=True)
def _fill_row(values, base, u, n_t, n_y, k0, j_lo, n_j, e, n_points, row, y_weights, t_nodes, t_weights, box,
              values_rows):
    """Row ``u`` of entry ``e``: the box's ``n_j`` nodes of ``t`` from ``j_lo`` contracted
    along ``y3`` (the table's ``values`` from ``base``), then each point's ``t`` stencil, into
    ``values_rows`` from ``row`` (compiled once, not inlined: its callers run it once a row;
    the arrays as :func:`rows_view`'s pointers, indexed flat)."""
    for jj in range(n_j):
        at = base + ((u * n_t + j_lo + jj) * n_y + k0) * _N_C
        for c in range(_N_C):
            v = 0.0
            for d in range(STENCIL):
                v += y_weights[e * (STENCIL + 1) + 1 + d] * values[at + d * _N_C + c]
            box[jj * _N_C + c] = v
    for point in range(n_points):
        first = (t_nodes[e * MOST_POINTS + point] - j_lo) * _N_C
        for c in range(_N_C):
            v = 0.0
            for q in range(STENCIL):
                v += t_weights[(e * MOST_POINTS + point) * STENCIL + q] * box[first + q * _N_C + c]
            values_rows[row + point * _N_C + c] = v


@njit(cache=True, inline="always")
def rows_add(view, e, rho, p, n_points, response):
    """``response[c] +=`` the remainder at the rule's point ``p`` (of ``n_points``), ``rho``
    from the receiver, through the rows of entry ``e`` (``view``: :func:`rows_view`; each
    row filled on first use: the box's ``t`` nodes contracted along ``y3``, then each
    point's ``t`` stencil; ``response`` a pointer)."""
    (values_rows, filled, t_nodes, t_weights, y_weights, u_weights, box, values, base, n_t, n_y, n_u_room, k0, j_lo,
     n_j, scale, h_u, n_u) = view
    i0 = lagrange_at(math.asinh(rho / scale), -PAD * h_u, h_u, n_u, u_weights, 0)
    for s in range(STENCIL):
        u = i0 + s
        row = (e * n_u_room + u) * MOST_POINTS * _N_C
        if filled[e * n_u_room + u] == 0:  # (a boolean array's pointer is of uint8)
            _fill_row(values, base, u, n_t, n_y, k0, j_lo, n_j, e, n_points, row, y_weights, t_nodes, t_weights, box,
                      values_rows)
            filled[e * n_u_room + u] = 1
        w_u = u_weights[s]
        at = row + p * _N_C
        for c in range(_N_C):
            response[c] += w_u * values_rows[at + c]


@njit(cache=True)
def remainder_rule(table, rows, j, y, layer, center, frame, a, b, source_layer, gauss_points, far_tol, entry_tol,
                   xi, eta, start):
    """``(lo, hi, entry)``: the cached rule's points of the remainder of rectangle ``j`` at
    ``y`` (:func:`.rectangle_quadrature.one_square_order` at the distance of the far
    triples' points: at least the table's clearance below or above, beside by the horizontal
    distance) and its entry of the rows (:func:`takes_rows`, :func:`rows_entry`; -1: the
    table directly, :func:`.remainder_table3d.remainder_rectangle_stress`), for
    :func:`.near_table3d.near_rectangle_stress`, which adds it at a rule's points with the
    near triples or alone."""
    r1 = y[0] - center[0]
    r2 = y[1] - center[1]
    beside = max(0.0, math.sqrt(r1 * r1 + r2 * r2) - a - b)
    clearance = table.clearance[source_layer, layer]
    n = one_square_order(math.sqrt(clearance * clearance + beside * beside), a, b, gauss_points, far_tol, entry_tol)
    lo, hi = start[n - 1], start[n]
    entry = np.int64(-1)
    if takes_rows(rows, j, hi - lo):
        entry = rows_entry(table, rows, j, y, layer, center, frame, a, b, source_layer, xi, eta, lo, hi)
    return lo, hi, entry
