"""How far from the front the asymptotic front may read its ribbon (issue 39).

    python benchmarks/bench_asymptotic_ribbon.py

An independent solve, written apart from the package: a Griffith crack of half-length ``L``
under uniform net pressure ``p`` on a row of equal constant-displacement-discontinuity
segments of size ``h`` (plane strain; the normal traction at ``x`` of a unit opening on
``[a, b]`` is ``E'/(4 pi) (1/(x - b) - 1/(x - a))``, Crouch and Starfield 1983). The segments
whose centre lies within ``c h`` of the front hold the exact opening ``(4 p / E') (L^2 -
x^2)^(1/2)`` averaged over them (as the asymptotic front prescribes its tip segments: the
K-vertex asymptote with the finite-fracture factor is Griffith's opening); the others are
solved under ``p``. The *ribbon* is the free segment nearest the front, at ``s_r`` from it;
the table gives its opening against the exact one at its centre, for the front at several
places in its segment (``s_r / h``) and three ``L / h``. The asymptotic front inverts that
opening for ``s_r``, so a ribbon ``e`` too wide puts the front ``2 e s_r`` too far
(toughness: ``w ~ s^(1/2)``) -- and, the opening of a square-root tip having no length scale,
the same ``e`` at every ``h``: an apparent toughness ``1 + e`` that refinement alone does not
remove.

    python benchmarks/bench_asymptotic_ribbon.py --viscous

does the same at a viscous tip (issue 39): the crack is the KGD M vertex (zero toughness,
:func:`hmatddm.analytical.m_vertex_numeric.kgd_m_vertex_numeric`, in units ``E' = 1``,
half-length ``gamma``, ``w = Omega(x / gamma)``), the free segments loaded with its net
pressure ``Pi`` at their centres, the segments within ``c h`` of the front holding its opening
averaged over them; ``c`` = 0.5 (a ribbon next to the front, ``s_r`` in ``[0.5, 1.5] h``) and
1.5 (``[1.5, 2.5] h``), at L = 25, 50 and 100 h.

    python benchmarks/bench_asymptotic_ribbon.py --penny [--viscous]

the same in 3D (issue 39, the far ribbon in 3D): a penny-shaped crack of radius ``a`` on a
square grid of equal constant-displacement-discontinuity squares of side ``h`` (the normal
traction at ``(x, y)`` of a unit opening on ``[x_1, x_2] x [y_1, y_2]`` is ``E'/(8 pi)``
times the corner sum of ``sqrt(u^2 + v^2) / (u v)``, ``u = x_i - x``, ``v = y_j - y``, signs
``(-1)^(i+j)``: the finite-part integral of ``1/r^3``, the point-source traction ``E' dA /
(8 pi r^3)`` of a planar crack). Squares whose centre lies within ``c h`` of the front hold the
exact opening averaged over them (zero outside the front); the others are solved under the
load. Toughness: Sneddon's crack under uniform ``p``, ``w = (8 p a / (pi E')) (1 -
r^2/a^2)^(1/2)``; ``--viscous``: the radial M vertex
(:func:`hmatddm.analytical.m_vertex_numeric.radial_m_vertex_numeric`, ``E' = 1``, ``w =
Omega(r/a) a / gamma``, ``p = Pi(r/a)``). The ribbon is every free square with an edge
neighbour that is not free; on a square grid a circle's ribbon squares sit at every
``s_r / h`` from ``c`` to ``c + 1`` and beyond (the staircase), so one crack gives the whole
curve: the error of each ribbon square's opening against the exact one at its centre,
binned by ``s_r / h``, at ``a`` = 12.3, 24.3 and 36.3 h.
"""
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402

E_PRIME, PRESSURE = 1.0, 1.0


def ribbon_error(half_length, h, c, n_sub=2000, vertex=None):
    """(ribbon opening / exact - 1, s_r / h, opening at the centre / exact - 1); ``vertex``: the
    KGD M vertex (:func:`hmatddm.analytical.m_vertex_numeric.kgd_m_vertex_numeric`) of
    half-length ``half_length`` instead of Griffith's crack (E' = 1, ``w = Omega(x/l)``, ``p =
    Pi(x/l)`` in its scaling with ``L = l / gamma``)."""
    n = int(np.ceil(half_length / h + 0.5)) + 1
    centres = np.arange(-n, n + 1) * h
    distance = half_length - np.abs(centres)
    free = distance >= c * h
    x = centres[:, None]
    stiffness = E_PRIME / (4.0 * np.pi) * (1.0 / (x - (centres - h / 2)[None]) - 1.0 / (x - (centres + h / 2)[None]))

    def exact(points):
        if vertex is not None:
            xi = np.abs(np.asarray(points, float)) / half_length
            out = np.zeros(xi.shape)
            inside = xi < 1.0
            out[inside] = vertex.opening(xi[inside]) * half_length / vertex.gamma
            return out
        return 4.0 * PRESSURE / E_PRIME * np.sqrt(np.maximum(half_length**2 - points**2, 0.0))

    if vertex is None:
        load = np.full(len(centres), PRESSURE)
    else:
        load = np.zeros(len(centres))
        load[free] = vertex.pressure(np.minimum(np.abs(centres[free]) / half_length, 1.0 - 1e-12))
    matrix, rhs = stiffness.copy(), load
    for i in np.flatnonzero(~free):
        matrix[i] = 0.0
        matrix[i, i] = 1.0
        rhs[i] = exact(centres[i] + h * ((np.arange(n_sub) + 0.5) / n_sub - 0.5)).mean()
    opening = np.linalg.solve(matrix, rhs)
    ribbon = np.flatnonzero(free)[-1]
    return (opening[ribbon] / exact(centres[ribbon]) - 1.0, distance[ribbon] / h,
            opening[n] / exact(0.0) - 1.0)


def viscous():
    """The ribbon's error at the KGD M vertex's tip (module docstring, ``--viscous``)."""
    from hmatddm.analytical.m_vertex_numeric import kgd_m_vertex_numeric

    vertex = kgd_m_vertex_numeric()
    rows = []
    cpu = time.process_time()
    for c in (0.5, 1.5):
        for offset in np.arange(10) / 10.0:
            errors = [ribbon_error(length + (offset + 0.5 - c) % 1.0, 1.0, c, n_sub=400, vertex=vertex)
                      for length in (25.0, 50.0, 100.0)]
            rows.append([f"{c:g}", f"{errors[0][1]:.2f}", *(f"{100 * e[0]:+.2f}%" for e in errors)])
    rows.sort(key=lambda row: (float(row[0]), float(row[1])))
    print_table(["c (s_r >= c h)", "s_r / h", "ribbon error, L = 25 h", "L = 50 h", "L = 100 h"], rows)
    print(f"CPU {time.process_time() - cpu:.1f} s")


def square_stiffness(points, h):
    """Normal traction (E' = 1) at in-plane ``points`` (M, 2) of a unit opening on the squares
    of side ``h`` centred at the same points (module docstring, ``--penny``)."""
    out = np.zeros((len(points), len(points)))
    for i0 in range(0, len(points), 512):  # rows in blocks (memory)
        x = points[i0:i0 + 512, None, :]
        total = 0.0
        for sx in (-1.0, 1.0):
            for sy in (-1.0, 1.0):
                u = points[None, :, 0] + 0.5 * sx * h - x[..., 0]
                v = points[None, :, 1] + 0.5 * sy * h - x[..., 1]
                total = total + sx * sy * np.sqrt(u * u + v * v) / (u * v)
        out[i0:i0 + 512] = total / (8.0 * np.pi)
    return out


def penny_ribbon(radius, h, c, n_sub=24, vertex=None):
    """``(s_r / h, ribbon error)`` arrays of a penny-shaped crack of ``radius`` (module
    docstring, ``--penny``; ``vertex``: the radial M vertex instead of Sneddon's crack), and
    the centre square's opening / exact - 1."""
    n = int(np.ceil(radius / h)) + 1
    grid = np.arange(-n, n + 1) * h
    x, y = np.meshgrid(grid, grid, indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel()])
    corner = np.hypot(np.abs(points[:, 0]) - 0.5 * h, np.abs(points[:, 1]) - 0.5 * h)
    points = points[corner < radius]  # squares the crack reaches (their nearest corner inside)
    distance = radius - np.hypot(points[:, 0], points[:, 1])
    free = distance >= c * h

    def exact(r):
        rho = np.minimum(np.asarray(r, float) / radius, 1.0)
        out = np.zeros(rho.shape)
        inside = rho < 1.0
        if vertex is not None:
            out[inside] = vertex.opening(rho[inside]) * radius / vertex.gamma
        else:
            out[inside] = 8.0 * PRESSURE * radius / (np.pi * E_PRIME) * np.sqrt(1.0 - rho[inside] ** 2)
        return out

    if vertex is None:
        load = np.full(len(points), PRESSURE)
    else:  # the vertex's net pressure at the free squares' centres (log-singular at the source:
        # interpolated in r from 400 points, the source square at a quarter of its side)
        rho = np.linspace(0.25 * h / radius, 1.0 - 1e-9, 400)
        table = vertex.pressure(rho)
        r = np.maximum(np.hypot(points[:, 0], points[:, 1]), 0.25 * h) / radius
        load = np.interp(r, rho, table)
    matrix = E_PRIME * square_stiffness(points, h)
    rhs = load.copy()
    u = ((np.arange(n_sub) + 0.5) / n_sub - 0.5) * h
    sub = np.column_stack([np.repeat(u, n_sub), np.tile(u, n_sub)])
    for i in np.flatnonzero(~free):
        matrix[i] = 0.0
        matrix[i, i] = 1.0
        rhs[i] = exact(np.hypot(*(points[i] + sub).T)).mean()
    opening = np.linalg.solve(matrix, rhs)
    keys = {tuple(k): i for i, k in enumerate(np.round(points / h).astype(int).tolist())}
    ribbon = [i for i in np.flatnonzero(free) if not all(
        keys.get((a + da, b + db), -1) >= 0 and free[keys[(a + da, b + db)]]
        for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1)) for a, b in [tuple(np.round(points[i] / h).astype(int))])]
    ribbon = np.array(ribbon)
    error = opening[ribbon] / exact(np.hypot(*points[ribbon].T)) - 1.0
    centre = keys[(0, 0)]
    return distance[ribbon] / h, error, opening[centre] / exact(0.0) - 1.0


def penny(viscous_tip):
    """The 3D ribbon's error binned by ``s_r / h`` (module docstring, ``--penny``)."""
    vertex = None
    if viscous_tip:
        from hmatddm.analytical.m_vertex_numeric import radial_m_vertex_numeric
        vertex = radial_m_vertex_numeric()
    cpu = time.process_time()
    radii = (12.3, 24.3, 36.3)
    edges = np.round(np.arange(0.5, 3.01, 0.25), 2)
    rows, means, centres = [], {}, {}
    curves = {}
    for c in (0.5, 1.0, 1.5, 2.0):
        for radius in radii:
            curves[c, radius] = penny_ribbon(radius, 1.0, c, vertex=vertex)
            s, e, centre = curves[c, radius]
            means[c, radius], centres[c, radius] = float(np.mean(e)), centre
    for lo, hi in zip(edges, edges[1:]):
        cells = []
        for radius in radii:
            values = [e for c in (0.5, 1.0, 1.5, 2.0) for s, e in zip(*curves[c, radius][:2]) if lo <= s < hi]
            cells.append(f"{100 * np.mean(values):+.2f}% ({len(values)})" if values else "-")
        rows.append([f"[{lo:g}, {hi:g})", *cells])
    print_table(["s_r / h", *(f"ribbon error, a = {r:g} h (squares)" for r in radii)], rows)
    rows = [[f"{c:g}", *(f"{100 * means[c, r]:+.2f}%" for r in radii), *(f"{100 * centres[c, r]:+.3f}%" for r in radii)]
            for c in (0.5, 1.0, 1.5, 2.0)]
    print_table(["c (s_r >= c h)", *(f"mean ribbon error, a = {r:g} h" for r in radii),
                 *(f"centre error, a = {r:g} h" for r in radii)], rows)
    print(f"CPU {time.process_time() - cpu:.1f} s")


def main():
    print(f"Machine: {machine()}")
    if "--penny" in sys.argv[1:]:
        return penny("--viscous" in sys.argv[1:])
    if "--viscous" in sys.argv[1:]:
        return viscous()
    rows = []
    cpu = time.process_time()
    for c in (0.5, 1.0, 1.5, 2.0, 3.0):
        for offset in sorted((0.05, 0.3, 0.55, 0.8), key=lambda o: (o - c) % 1.0):
            errors = [ribbon_error(length + offset, 1.0, c) for length in (18.0, 36.0, 72.0)]
            rows.append([f"{c:g}", f"{errors[0][1]:.2f}", *(f"{100 * e[0]:+.3f}%" for e in errors),
                         f"{100 * errors[0][2]:+.3f}%"])
    print_table(["c (s_r >= c h)", "s_r / h", "ribbon error, L = 18 h", "L = 36 h", "L = 72 h",
                 "centre error, L = 18 h"], rows)
    print(f"CPU {time.process_time() - cpu:.1f} s")


if __name__ == "__main__":
    main()
