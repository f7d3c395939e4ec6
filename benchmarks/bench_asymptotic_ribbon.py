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


def main():
    print(f"Machine: {machine()}")
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
