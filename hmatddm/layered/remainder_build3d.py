"""Building the tables of :mod:`.remainder_table3d` (issue 32, item 2): what a table covers
(:func:`table_domain`, the mesh's extent rounded up by doubling), which layer pairs have far
triples and how far they stay (:func:`_far_pairs`), and the refinement of each pair's grids
until the error of the entries it carries is below the tolerance (:func:`build_table`), and
how many reflections the near triples need traced (:func:`near_images`).
Python driving a few compiled sampling calls per layer pair."""
import math

import numpy as np

from .image_tracer import trace_capacity
from .image_tracer3d import trace
from .near_table3d import build_near_table, empty_near_table
from .remainder_table3d import (COMPONENTS, ERROR_SAMPLES, MAX_TABLE_VALUES, PAD, STENCIL, RemainderTable,
                                interpolate, interpolation_scratch, is_far, keep_near, layer_bounds, layer_gap,
                                sample_remainder, triple_gap)


def empty_table(n_layers):
    """A table that tabulates nothing (every pair by quadrature, no near table)."""
    zeros = np.zeros(n_layers)
    return RemainderTable(-np.ones((n_layers, n_layers), dtype=np.int64), np.ones((1, 9)),
                          np.zeros(1, dtype=np.int64), np.zeros(1), np.zeros((n_layers, n_layers)), zeros - np.inf,
                          zeros + np.inf, 0, empty_near_table(n_layers))


def _far_pairs(interfaces, shear_modulus, poisson_ratio, n_images, ranges, bottoms, tops):
    """``clearance[ls, lr]`` of the far triples (and the whole-space term two or more layers
    away) of every pair of solid layers; ``inf`` where a pair has none."""
    from .image_tracer3d import trace_points

    n_layers = shear_modulus.shape[0]
    clearance = np.full((n_layers, n_layers), np.inf)
    for ls in range(n_layers):
        if shear_modulus[ls] <= 0.0:
            continue
        t = 0.5 * (ranges[ls][0] + ranges[ls][1])
        n_pairs, layer, z, eps, _, _, _ = trace_points(np.array([t]), ls, interfaces, shear_modulus, poisson_ratio,
                                                       n_images)
        for k in range(n_pairs[0]):
            gap = triple_gap(z[0, k], eps[0, k], t, ls, layer[0, k], bottoms, tops)
            if is_far(z[0, k], eps[0, k], t, ls, layer[0, k], bottoms, tops):
                clearance[ls, layer[0, k]] = min(clearance[ls, layer[0, k]], gap)
        for lr in range(n_layers):
            if shear_modulus[lr] > 0.0:
                gap = layer_gap(ls, lr, bottoms, tops)
                if gap > 0.0:
                    clearance[ls, lr] = min(clearance[ls, lr], gap)
    return clearance


def _doubling(length, unit):
    """The smallest ``unit 2^k >= length`` (``k >= 0``): table ranges grow by doubling, so a
    table is a function of the mesh's extent rounded up, not of the mesh's history."""
    return unit * 2.0 ** max(0, math.ceil(math.log2(max(length, unit) / unit) - 1e-12))


def table_domain(mesh, layers, interfaces, shear_modulus):
    """What a table of ``mesh`` covers, ``(ranges, horizontal, area)``: ``ranges[k]`` the
    heights of solid layer ``k`` (a finite layer whole; a half-space from its interface to
    twice the farthest element of the mesh in it, rounded up by :func:`_doubling` in units
    of the thinnest finite layer), the horizontal extent (rounded the same way) and the
    largest element area. Meshes with the same domain get the same table (a growing mesh
    and its resumed run alike)."""
    bottoms, tops = layer_bounds(interfaces)
    finite = [tops[k] - bottoms[k] for k in range(len(tops)) if np.isfinite(tops[k] - bottoms[k])]
    thin = min(finite) if finite else 1.0
    corners = mesh.corners()
    z_min, z_max = corners[:, :, 2].min(axis=1), corners[:, :, 2].max(axis=1)
    ranges = []
    for k in range(len(tops)):
        if shear_modulus[k] <= 0.0:
            ranges.append((0.0, 0.0))
            continue
        lo, hi = bottoms[k], tops[k]
        mine = layers == k
        if not np.isfinite(lo):
            depth = hi - float(np.min(z_min[mine])) if np.any(mine) else 0.0
            lo = hi - _doubling(2.0 * depth, thin)
        if not np.isfinite(hi):
            height = float(np.max(z_max[mine])) - lo if np.any(mine) else 0.0
            hi = lo + _doubling(2.0 * height, thin)
        ranges.append((float(lo), float(hi)))
    horizontal = _doubling(float(np.hypot(np.ptp(corners[:, :, 0]), np.ptp(corners[:, :, 1]))), thin)
    return tuple(ranges), horizontal, float(np.max(4.0 * mesh.half_a * mesh.half_b))


def _sample_height(rng, bounds, spacing):
    """A random height in ``bounds``; half of them within two grid spacings of an end,
    where the interpolation is one-sided and its error largest."""
    lo, hi = bounds
    if rng.uniform() < 0.5:
        return float(rng.uniform(lo, hi))
    width = min(2.0 * spacing, hi - lo)
    return float(rng.uniform(lo, lo + width) if rng.uniform() < 0.5 else rng.uniform(hi - width, hi))


def _pair_grid(d, rho_max, t_range, y_range, h):
    """``grid`` row of a layer pair (see :class:`RemainderTable`) at spacing ``h``, each grid
    padded by :data:`PAD` nodes beyond its range (``u`` below 0: the receiver on the other
    side of the source)."""
    h_u = h / d
    n_u = max(STENCIL, int(math.ceil(math.asinh(rho_max / d) / h_u)) + 1) + 2 * PAD
    row = [d, h_u, n_u]
    for lo, hi in (t_range, y_range):
        n = max(STENCIL, int(math.ceil((hi - lo) / h)) + 1)
        spacing = (hi - lo) / (n - 1)
        row += [lo - PAD * spacing, spacing, n + 2 * PAD]
    return np.array(row, dtype=np.float64)


def _sample_pair(ls, lr, grid, interfaces, g, nu, n_images, bottoms, tops):
    n_u, n_t, n_y = int(grid[2]), int(grid[5]), int(grid[8])
    values = np.zeros((n_u, n_t, n_y, len(COMPONENTS)))
    sample_remainder(ls, lr, grid[0] * np.sinh(grid[1] * (np.arange(n_u) - PAD)), grid[3] + grid[4] * np.arange(n_t),
                     grid[6] + grid[7] * np.arange(n_y), interfaces, g, nu, n_images, bottoms, tops, values)
    return values


#: Where in a source layer's range :func:`near_images` compares the two traces.
NEAR_CHECK_FRACTIONS = (0.13, 0.5, 0.91)


def near_images(interfaces, shear_modulus, poisson_ratio, n_images, ranges, bottoms, tops, source_layers):
    """The reflections to trace for the near triples of sources in ``source_layers`` when
    the far ones are tabulated: 1 or ``n_images``. A near triple is a first reflection in
    an interface of the source's layer or a transmission (:func:`.remainder_table3d.is_far`),
    all of which a trace with one reflection holds -- unless a deeper image coincides with
    one (layer thicknesses in special ratios) and the tracer merges them
    (:func:`.image_tracer3d.merge_coincident`). The near triples of both traces are compared
    at three heights of each source layer (a coincidence is a property of the stack, the
    same at every height): equal to round-off, 1; else ``n_images``. Tracing one reflection
    rather than four costs ~6x less (17 against 97 us a height for a source under a free
    surface and two interfaces), a fifth of a three-layer entry on the issue-32 lattice."""
    if n_images <= 1:
        return int(n_images)
    for ls in source_layers:
        cap, n_orders = trace_capacity(ls, shear_modulus, n_images)
        lo, hi = ranges[ls]
        for fraction in NEAR_CHECK_FRACTIONS:
            t = lo + fraction * (hi - lo)
            found = []
            for images in (n_images, 1):
                layer, z, eps, sigma = (np.zeros(cap, dtype=np.int64), np.zeros(cap), np.zeros(cap), np.zeros(cap))
                coef, dcoef = np.zeros((cap, 3, 3, n_orders)), np.zeros((cap, 3, 3, n_orders))
                n = trace(t, ls, interfaces, shear_modulus, poisson_ratio, images, layer, z, eps, sigma, coef, dcoef)
                n = keep_near(n, layer, z, eps, sigma, coef, dcoef, t, ls, bottoms, tops)
                found.append({(int(layer[k]), float(z[k]), float(sigma[k])): (coef[k], dcoef[k]) for k in range(n)})
            deep, one = found
            if deep.keys() != one.keys():
                return int(n_images)
            for key, (coef, dcoef) in deep.items():
                scale = max(float(np.max(np.abs(coef))), float(np.max(np.abs(dcoef))), 1e-300)
                if (np.max(np.abs(coef - one[key][0])) > 1e-12 * scale
                        or np.max(np.abs(dcoef - one[key][1])) > 1e-12 * scale):
                    return int(n_images)
    return 1


def build_table(mesh, layers, interfaces, shear_modulus, poisson_ratio, n_images, tolerance, entry_scale,
                seed=0):
    """The :class:`RemainderTable` of a medium for the :func:`table_domain` of ``mesh``: each pair of
    layers with far triples tabulated at the spacing (an eighth of its clearance, halved as
    needed) at which the error of an entry it carries, measured at :data:`ERROR_SAMPLES`
    random points against the image sum (``max |dT| (lambda + 2G) 4ab``, the largest
    element), is below ``tolerance * entry_scale`` (``entry_scale``: the largest entry,
    Pa/m). Returns ``(table, stats)``; no far triple: the empty table."""
    import time

    interfaces = np.asarray(interfaces, dtype=np.float64)
    g = np.asarray(shear_modulus, dtype=np.float64)
    nu = np.asarray(poisson_ratio, dtype=np.float64)
    n_layers = g.shape[0]
    stats = dict(table_pairs=0, table_values=0, table_error=0.0, table_build_cpu=0.0)
    if interfaces.shape[0] < 2 or n_images < 1:
        return empty_table(n_layers), stats
    cpu = time.process_time()
    bottoms, tops = layer_bounds(interfaces)
    ranges, horizontal, area = table_domain(mesh, layers, interfaces, g)
    clearance = _far_pairs(interfaces, g, nu, n_images, ranges, bottoms, tops)
    pairs = [(ls, lr) for ls in range(n_layers) for lr in range(n_layers) if np.isfinite(clearance[ls, lr])]
    if not pairs:
        return empty_table(n_layers), stats
    moment = np.where(g > 0.0, 2.0 * g + 2.0 * g * nu / np.maximum(1.0 - 2.0 * nu, 1e-300), 0.0)
    allowed = tolerance * entry_scale
    rng = np.random.default_rng(seed)
    pair_index = -np.ones((n_layers, n_layers), dtype=np.int64)
    grids, blocks, worst = [], [], 0.0
    response = np.empty(len(COMPONENTS))
    w = interpolation_scratch()
    direct = np.empty((1, 1, 1, len(COMPONENTS)))
    total = 0
    for k, (ls, lr) in enumerate(pairs):
        pair_index[ls, lr] = k
        d = float(clearance[ls, lr])
        rho_max = max(2.0 * horizontal, 4.0 * d)
        h = d / 8.0
        while True:
            grid = _pair_grid(d, rho_max, ranges[ls], ranges[lr], h)
            size = int(grid[2] * grid[5] * grid[8]) * len(COMPONENTS)
            if total + size > MAX_TABLE_VALUES:
                stats.update(table_refused=f"layer pair ({ls}, {lr}) needs more than {MAX_TABLE_VALUES} values")
                return empty_table(n_layers), stats
            values = _sample_pair(ls, lr, grid, interfaces, g, nu, n_images, bottoms, tops)
            one = RemainderTable(pair_index, grid[None, :], np.zeros(1, dtype=np.int64), values.ravel(), clearance,
                                 bottoms, tops, 0, empty_near_table(n_layers))
            saved = pair_index[ls, lr]
            pair_index[ls, lr] = 0
            error = 0.0
            for _ in range(ERROR_SAMPLES):
                rho = float(d * np.sinh(rng.uniform(0.0, grid[1] * (grid[2] - 1.0 - 2.0 * PAD))))
                t = _sample_height(rng, ranges[ls], grid[4])
                y3 = _sample_height(rng, ranges[lr], grid[7])
                sample_remainder(ls, lr, np.array([rho]), np.array([t]), np.array([y3]), interfaces, g, nu, n_images,
                                 bottoms, tops, direct)
                interpolate(one, ls, lr, rho, t, y3, response, w)
                error = max(error, float(np.max(np.abs(response - direct[0, 0, 0]))) * moment[ls] * area)
            pair_index[ls, lr] = saved
            if error <= allowed:
                break
            h /= 2.0
        worst = max(worst, error)
        grids.append(grid)
        blocks.append(values.ravel())
        total += size
    offset = np.cumsum([0] + [b.size for b in blocks[:-1]]).astype(np.int64)
    images = near_images(interfaces, g, nu, n_images, ranges, bottoms, tops, sorted({ls for ls, _ in pairs}))
    near, near_stats = build_near_table(interfaces, g, nu) if images == 1 else (empty_near_table(n_layers), {})
    table = RemainderTable(pair_index, np.array(grids), offset, np.concatenate(blocks), clearance, bottoms, tops,
                           images, near)
    stats.update(table_pairs=len(pairs), table_values=int(total), table_error=worst / entry_scale,
                 table_build_cpu=time.process_time() - cpu, **near_stats)
    return table, stats
