"""The M-vertex similarity solutions computed to 1e-7 (issue 39,
hmatddm/analytical/m_vertex_numeric.py): convergence with the number of Chebyshev points,
independence of the stretching map, and the differences of the published constants.

    python benchmarks/bench_m_vertex.py        # a few seconds, one thread

Columns: gamma (half length or radius over L), Omega(0) (opening at the source over eps L),
Pi(0) (KGD) or B (radial, Pi ~ -B ln rho), Pi at 0.5 and 0.9, the tip coefficient over its
exact value beta_m (V t / L)^(1/3) gamma^(2/3) minus one, wall and CPU time of a solve
(operators built and cached on the first call of each size). Last table: the openings of the
closed forms of hmatddm/analytical/solutions.py against the computed one at the same distance
from the source (each closed form on its own radius, so the tip errors include the radius's).
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
from _common import machine, print_table  # noqa: E402

from hmatddm.analytical import m_vertex_numeric as mv  # noqa: E402
from hmatddm.analytical import solutions  # noqa: E402

BETA_M = 2.0 ** (1.0 / 3.0) * 3.0 ** (5.0 / 6.0)


def solve(radial, n):
    wall, cpu = time.perf_counter(), time.process_time()
    solution = mv.MVertexSolution(radial, n)
    return solution, time.perf_counter() - wall, time.process_time() - cpu


def row(label, n, solution, wall=None, cpu=None):
    velocity = 4.0 / 9.0 if solution.radial else 2.0 / 3.0
    exact_tip = BETA_M * velocity ** (1.0 / 3.0) * solution.gamma
    third = solution.log_coefficient if solution.radial else solution.pressure_at_source
    cells = [label, n, f"{solution.gamma:.9f}", f"{solution.opening_at_source:.9f}", f"{third:.9f}",
             f"{float(solution.pressure(0.5)):.8f}", f"{float(solution.pressure(0.9)):.8f}",
             f"{solution.tip_coefficient / exact_tip - 1.0:.1e}"]
    if wall is not None:
        cells += [f"{wall:.3f}", f"{cpu:.3f}"]
    return cells


def main():
    print(f"Calibration at the start: {machine()}")
    header = ["case", "points", "gamma", "Omega(0)", "Pi(0) or B", "Pi(0.5)", "Pi(0.9)", "tip / exact - 1",
              "wall s", "CPU s"]
    rows = []
    for radial in (False, True):
        for n in (8, 12, 16, 24, 32, 48, 64):
            rows.append(row("radial" if radial else "KGD", n, *solve(radial, n)))
    print_table(header, rows)

    # the same at 32 points with other maps x = 1 - (1 - tau^2)^m, the tip graded to 2^-30
    rows = []
    levels, power = mv._FAR_LEVELS, mv._MAP_POWER
    try:
        mv._FAR_LEVELS = 30
        for m in (5, 6, 7, 8):
            mv._MAP_POWER = m
            mv._operators.cache_clear()
            for radial in (False, True):
                rows.append(row(("radial" if radial else "KGD") + f", map m = {m}", 32, mv.MVertexSolution(radial, 32)))
    finally:
        mv._FAR_LEVELS, mv._MAP_POWER = levels, power
        mv._operators.cache_clear()
    print_table(header[:-2], rows)

    kgd, radial = mv.MVertexSolution(False, 32), mv.MVertexSolution(True, 32)
    published = [
        ("KGD gamma", "Adachi and Detournay 2002 (7 terms)", 0.61524, kgd.gamma),
        ("KGD Omega(0)", "Adachi and Detournay 2002 (7 terms)", 1.1233, kgd.opening_at_source),
        ("KGD Pi(0)", "Adachi and Detournay 2002 (7 terms)", 0.5443, kgd.pressure_at_source),
        ("radial gamma", "Savitski and Detournay 2002 (zero order)", 0.6955, radial.gamma),
        ("radial Omega(0)", "Savitski and Detournay 2002 (zero order)", 1.1977, radial.opening_at_source),
        ("radial B", "Savitski and Detournay 2002 (zero order)", 0.09269, radial.log_coefficient),
        ("radial gamma", "Dontsov 2016 (ref. Eq. 4.62)", 0.6944, radial.gamma),
        ("radial Omega(0)", "Dontsov 2016 (ref. Eq. 4.63)", 1.1901, radial.opening_at_source),
    ]
    print_table(["constant", "source", "published", "computed", "published / computed - 1"],
                [[name, source, f"{value:g}", f"{computed:.7f}", f"{value / computed - 1.0:+.3%}"]
                 for name, source, value, computed in published])

    # openings of the closed forms at the same distance r / L (each on its own radius)
    fractions = (0.0, 0.25, 0.5, 0.75, 0.9, 0.97)
    rows = []
    for name, exact, own_gamma, shape in (
            ("KGD, Adachi and Detournay", kgd, solutions._KGD_M_GAMMA,
             lambda x: solutions._KGD_M_GAMMA * solutions._kgd_m_width_bar(x)),
            ("radial, Savitski and Detournay", radial, solutions._RADIAL_M_GAMMA, solutions._radial_m_width_scaled),
            ("radial, Dontsov", radial, 0.6944, lambda x: 1.1901 * (1.0 + x) ** 0.487 * (1.0 - x) ** (2.0 / 3.0))):
        cells = [name]
        for f in fractions:
            own = f * exact.gamma / own_gamma
            cells.append(f"{float(shape(own)) / float(exact.opening(f)) - 1.0:+.2%}" if own < 1.0 else "closed")
        rows.append(cells)
    print_table(["opening / computed - 1 at r = f gamma L, f ="] + [f"{f:g}" for f in fractions], rows)


if __name__ == "__main__":
    main()
