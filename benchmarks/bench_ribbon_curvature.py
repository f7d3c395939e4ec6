"""Where a radial fracture's front lands when the asymptotic front reads an exact opening
(issue 39: why the far ribbon makes a 3D toughness tip shorter and wider).

    python benchmarks/bench_ribbon_curvature.py            # tables 1 and 2 (seconds)
    python benchmarks/bench_ribbon_curvature.py --penny    # and table 3 (dense solves, ~1 min)

1. **The inversion alone.** The exact opening of a radial fracture at a distance ``s`` from its
   front, inverted for ``s`` with the package's asymptote
   (:meth:`hmatddm.analytical.tip_asymptote.TipAsymptote.front_distance`, as
   :mod:`hmatddm.simulation.asymptotic` calls it: ``V = (s - s_old)/dt``, ``length`` the
   radius), against the bare semi-infinite asymptote (``length = inf``), averaged over ``s``
   uniform in a near band ``[0.5, 1.5] h`` and a far band ``[1.5, 2.5] h`` (where the near and
   the far ribbon sit), at ``R / h`` = 10, 20, 40, 80. Toughness: Sneddon's penny, ``w = (8 p
   R / (pi E')) (1 - rho^2)^(1/2) = (K'/E') s^(1/2) (1 - s/(2R))^(1/2)`` (K-vertex; zero
   viscosity in the asymptote); viscosity: the computed radial M vertex
   (:func:`hmatddm.analytical.radial_m_vertex_profile`, ``V = (4/9) R / t``, steps of 1% of
   ``t``). The front error is ``s_true - s_read`` (positive: the front read too near, a
   shorter fracture), in ``h`` and in % of ``R``.
2. **The level set.** The front the package rebuilds
   (:class:`hmatddm.fracture.front.FrontField`: first-order fast marching from the ribbon
   centres, bilinear between centres; :func:`hmatddm.fracture.front.front_radii`, 720 rays)
   from the *exact* distances of the ribbon centres to a circle of radius ``R`` (four
   positions of the circle's centre in its cell), with the simulator's two ribbons: near (the
   channel is every cell fully inside the front, ``s_r`` ~ 0.5-1.5 h) and far (the channel is
   the cells whose centre is ``c h`` behind the front, ``c = 1.5`` and the 2D rule ``c =
   max(1.5, 0.5 (R/h)^(1/2))``).
3. ``--penny``: **the whole static chain** on Sneddon's crack (uniform ``p``): square
   constant-DD elements (the independent solve of ``bench_asymptotic_ribbon.py --penny``,
   :func:`bench_asymptotic_ribbon.square_stiffness`); every cell not in the channel holds the
   asymptote's opening as :func:`hmatddm.fracture.front.fill` prescribes it in the simulator
   (the level set of the exact ribbon distances, 8 x 8 samples, the finite-fracture factor of
   ``R``), or, for comparison, the exact opening averaged over it; the channel is solved under
   ``p``; its ribbon openings are inverted (with ``length = R``), and the level set of those
   distances gives the front. Reported: the ribbon's opening against the exact one at its
   centre (``e``), the centre square's (``g``), and the front's mean radius error. At a
   toughness tip a ribbon that reads ``e`` against an interior that reads ``g`` acts as a
   toughness ``(1 + e - g)^(-1)`` times the true one for the run (the elastic part of the
   error ``g``, a modulus, does not move the K-vertex's ``R`` and ``w0``): ``R`` off by ``0.4
   (e - g)`` and ``w0`` by ``-0.8 (e - g)`` (``R ~ K'^(-2/5)``, ``w0 ~ K'^(4/5)``).
"""
import os
import sys
import time
from types import SimpleNamespace

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402

RATIOS = (10.0, 20.0, 40.0, 80.0)
BANDS = {"near [0.5, 1.5] h": (0.5, 1.5), "far [1.5, 2.5] h": (1.5, 2.5)}
OFFSETS = ((0.0, 0.0), (0.3, 0.1), (0.5, 0.5), (0.17, 0.41))  # the circle's centre in its cell (h)


def inversion_errors(kind, ratio, band, finite, n=201):
    """Mean ``s_true - s_read`` over ``s`` uniform in ``band`` (units of h = 1), table 1."""
    from hmatddm.analytical import radial_m_vertex, radial_m_vertex_profile
    from hmatddm.analytical.tip_asymptote import TipAsymptote, toughness_prime

    radius = ratio
    s = np.linspace(band[0], band[1], n)
    length = radius if finite else np.inf
    if kind == "K":
        asymptote = TipAsymptote(1.0, 1.0, 0.0)  # E' = 1, K_Ic = 1, zero viscosity
        w = toughness_prime(1.0) * np.sqrt(s * (1.0 - s / (2.0 * radius)))
        read, _ = asymptote.front_distance(w, np.zeros_like(s), 1.0, length=length)
    else:  # the radial M vertex scaled to R = ratio (E' = 1, mu = 1, Q chosen)
        material = SimpleNamespace(plane_strain_modulus=1.0)
        t, mu = 1.0, 1.0
        q = (radius / float(radial_m_vertex(t, 1.0, mu, material)[0])) ** 3.0  # R ~ Q^(1/3)
        velocity = 4.0 / 9.0 * radius / t
        w, _ = radial_m_vertex_profile(1.0 - s / radius, t, q, mu, material)
        dt = 0.01 * t
        asymptote = TipAsymptote(1.0, 1e-9, 12.0 * mu)  # (K^ ~ 1e-9: the bracket [s_old, s_k] is
        # ~1e18 h wide, so 200 halvings, not the simulator's 64)
        read, _ = asymptote.front_distance(w, s - velocity * dt, dt, iterations=200, length=length)
    return float(np.mean(s - read))


def ribbon_cells(radius, c, offset):
    """Cells (M, 2), the channel mask and the exact ``s`` of each cell centre for a circle of
    ``radius`` centred at ``offset`` (h = 1); ``c = None``: the near ribbon (channel = cells
    fully inside), else channel = cells fully inside whose centre is ``c`` behind the front."""
    n = int(np.ceil(radius)) + 4
    g = np.arange(-n, n + 1)
    x, y = np.meshgrid(g, g, indexing="ij")
    cells = np.column_stack([x.ravel(), y.ravel()])
    rel = cells - np.asarray(offset)[None]
    s = radius - np.hypot(rel[:, 0], rel[:, 1])
    corners = np.max([np.hypot(rel[:, 0] + a, rel[:, 1] + b) for a in (-0.5, 0.5) for b in (-0.5, 0.5)], axis=0)
    channel = corners < radius
    if c is not None:
        channel &= s >= c
    return cells, channel, s


def ribbon_of(cells, channel):
    keys = set(map(tuple, cells[channel].tolist()))
    return np.array([bool(ch) and not all((a + da, b + db) in keys for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1)))
                     for (a, b), ch in zip(cells.tolist(), channel)])


def field_front(cells, channel, ribbon, distances, offset):
    """Mean radius of the front the package rebuilds from ribbon ``distances`` (table 2)."""
    from hmatddm.fracture.front import FrontField, front_radii

    field = FrontField(cells[ribbon], distances, np.zeros(int(ribbon.sum())), cells[channel], 1.0,
                       int(np.ceil(np.max(distances))) + 3)
    return float(np.mean(front_radii(np.asarray(offset, float), field, n_rays=720))), field


def far_c(ratio):
    return max(1.5, 0.5 * np.sqrt(ratio))


def level_set_errors(ratio, rule):
    """Mean front radius error (h) of the level set of the exact ribbon distances (table 2)."""
    errors, depth = [], []
    for offset in OFFSETS:
        c = None if rule == "near" else (1.5 if rule == "far 1.5" else far_c(ratio))
        cells, channel, s = ribbon_cells(ratio, c, offset)
        ribbon = ribbon_of(cells, channel)
        front, _ = field_front(cells, channel, ribbon, s[ribbon], offset)
        errors.append(front - ratio)
        depth.append(np.mean(s[ribbon]))
    return float(np.mean(errors)), float(np.mean(depth))


def static_chain(ratio, rule, band, offset=(0.17, 0.41), n_sub=8):
    """Table 3: ``(e, g, front error in h, mean s_r)`` of Sneddon's crack of radius ``ratio``
    (h = 1, E' = 1, p = 1) with the band of non-channel cells holding ``band`` ("fill": the
    simulator's prescribed opening; "exact": the exact cell average)."""
    from bench_asymptotic_ribbon import square_stiffness
    from hmatddm.analytical.tip_asymptote import TipAsymptote, toughness_prime
    from hmatddm.fracture.front import fill

    radius = ratio
    c = None if rule == "near" else (1.5 if rule == "far 1.5" else far_c(ratio))
    cells, channel, s = ribbon_cells(radius, c, offset)
    rel = cells - np.asarray(offset)[None]
    corner = np.hypot(np.abs(rel[:, 0]) - 0.5, np.abs(rel[:, 1]) - 0.5)
    keep = channel | (corner < radius + 1.0)  # the crack's cells and a margin of empty ones
    cells, channel, s, rel = cells[keep], channel[keep], s[keep], rel[keep]
    ribbon = ribbon_of(cells, channel)
    k_ic = 2.0 * np.sqrt(radius / np.pi)  # K_I = 2 p (R/pi)^(1/2) with p = 1
    asymptote = TipAsymptote(1.0, k_ic, 0.0)

    def exact(r):
        rho = np.minimum(np.asarray(r, float) / radius, 1.0)
        return 8.0 * radius / np.pi * np.sqrt(np.maximum(1.0 - rho * rho, 0.0))

    _, field = field_front(cells, channel, ribbon, s[ribbon], offset)
    prescribed = ~channel
    if band == "fill":
        _, width, _ = fill(cells[prescribed], field, asymptote, n_sub, radius)
    else:
        u = ((np.arange(24) + 0.5) / 24 - 0.5)
        sub = np.column_stack([np.repeat(u, 24), np.tile(u, 24)])
        width = np.array([exact(np.hypot(*(p + sub).T)).mean() for p in rel[prescribed]])
    matrix = square_stiffness(cells.astype(float), 1.0)
    rhs = np.ones(len(cells))
    index = np.flatnonzero(prescribed)
    matrix[index] = 0.0
    matrix[index, index] = 1.0
    rhs[index] = width
    opening = np.linalg.solve(matrix, rhs)
    e = float(np.mean(opening[ribbon] / exact(radius - s[ribbon]) - 1.0))
    centre = int(np.argmax(s))
    g = float(opening[centre] / exact(radius - s[centre]) - 1.0)
    read, _ = asymptote.front_distance(opening[ribbon], np.zeros(int(ribbon.sum())), 1.0, length=radius)
    assert abs(toughness_prime(k_ic) * np.pi / (8.0 * np.sqrt(2.0 * radius)) - 1.0) < 1e-12
    front, _ = field_front(cells, channel, ribbon, read, offset)
    return e, g, front - radius, float(np.mean(s[ribbon]))


def main():
    print(f"Machine: {machine()}")
    cpu = time.process_time()
    rows = []
    for kind, label in (("K", "K vertex (Sneddon)"), ("M", "M vertex (computed)")):
        for finite in (False, True):
            for name, band in BANDS.items():
                cells = []
                for ratio in RATIOS:
                    err = inversion_errors(kind, ratio, band, finite)
                    cells.append(f"{err:+.4f} h ({100 * err / ratio:+.3f}%)")
                rows.append([label, "finite (code)" if finite else "bare", name, *cells])
    print("1. front error s_true - s_read of the exact opening inverted (positive: front read too near)")
    print_table(["profile", "asymptote", "band", *(f"R = {r:g} h" for r in RATIOS)], rows)
    rows = []
    for rule in ("near", "far 1.5", "far c(R)"):
        cells = []
        for ratio in RATIOS:
            err, depth = level_set_errors(ratio + 0.3, rule)
            cells.append(f"{err:+.4f} h ({100 * err / (ratio + 0.3):+.3f}%), s_r {depth:.2f} h")
        rows.append([rule, *cells])
    print("2. front radius error of the level set of the exact ribbon distances (negative: too near)")
    print_table(["ribbon", *(f"R = {r + 0.3:g} h" for r in RATIOS)], rows)
    print(f"CPU {time.process_time() - cpu:.1f} s")
    if "--penny" in sys.argv[1:]:
        rows = []
        for ratio in (10.3, 20.3, 30.3, 40.3):
            for rule in ("near", "far 1.5", "far c(R)"):
                for band in ("fill", "exact"):
                    t0 = time.process_time()
                    e, g, front, depth = static_chain(ratio, rule, band)
                    rows.append([f"{ratio:g}", rule, band, f"{depth:.2f}", f"{100 * e:+.2f}%", f"{100 * g:+.2f}%",
                                 f"{front:+.4f} h ({100 * front / ratio:+.3f}%)",
                                 f"{40 * (e - g):+.2f}% / {-80 * (e - g):+.2f}%", f"{time.process_time() - t0:.1f}"])
        print("3. the static chain on Sneddon's crack (one pass: exact ribbon distances -> band -> solve -> "
              "inversion -> level set)")
        print_table(["R / h", "ribbon", "band holds", "mean s_r / h", "ribbon e", "centre g", "front error",
                     "as a toughness: R / w0", "CPU (s)"], rows)
        print(f"CPU {time.process_time() - cpu:.1f} s")


if __name__ == "__main__":
    main()
