"""The solve of a large planar crack against its build (issue 33: a solve should cost a
few products, not a second build).

    python benchmarks/bench_solve_vs_build.py --sizes 10000,40000,100000
    python benchmarks/bench_solve_vs_build.py --operators lattice,hmatrix --sizes 10000,100000

For a square crack of N elements under 1 MPa (eps 1e-4, leaf 32, the default
preconditioner: near-field block ILU, two-level from 20 000 elements): the H-matrix build,
the preconditioner setup and the GMRES solve to rtol 1e-8 (``hd.solve``), each with its wall
and CPU time, the iterations, the solve / build ratio, and the opening at the centre
against Sneddon's penny of the same area (a check that the solve is the right one, not an
accuracy study: the crack is square). ``--operators lattice`` also (or only) times the FFT
operator of a lattice mesh (:mod:`hmatddm.elasticity.lattice`, which the simulation takes
for such a crack): its "build" is the kernel table, its products are exact.
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    value = function()
    return value, time.perf_counter() - wall, time.process_time() - cpu


def measure(n, kind="hmatrix"):
    import hmatddm as hd
    from hmatddm.elasticity.lattice import LatticePlanarOperator

    side = int(round(np.sqrt(n)))
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], float(side), float(side), side, side)
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    build = (lambda: LatticePlanarOperator(mesh, material)) if kind == "lattice" else \
        (lambda: hd.ElasticityOperator(mesh, material, backend="hmatrix"))
    operator, build_wall, build_cpu = timed(build)
    _, setup_wall, setup_cpu = timed(operator.preconditioner)
    (dd, info), solve_wall, solve_cpu = timed(lambda: hd.solve(operator, -1e6 * mesh.normals, rtol=1e-8,
                                                                 return_info=True))
    return dict(kind=kind, n=mesh.n_elements, build_wall=build_wall, build_cpu=build_cpu, setup_wall=setup_wall,
                setup_cpu=setup_cpu, solve_wall=solve_wall, solve_cpu=solve_cpu, iterations=info["iterations"],
                residual=info["residual"], max_opening=float(np.max(hd.opening(mesh, dd))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10000,40000,100000")
    parser.add_argument("--operators", default="hmatrix", help="hmatrix, lattice or both (comma-separated)")
    args = parser.parse_args()
    sys.path.insert(0, HERE)
    from _common import machine, print_table

    print(f"Machine: {machine()}", flush=True)
    rows = []
    for n in [int(s) for s in args.sizes.split(",")]:
        for kind in args.operators.split(","):
            rows.append(measure(n, kind))
            print(rows[-1], flush=True)
    header = ["operator", "N", "max opening (m)", "build wall / CPU (s)", "preconditioner setup wall / CPU (s)", "solve wall / CPU (s)",
              "GMRES its", "residual", "(setup + solve) / build, wall", "solve / build, wall"]
    body = [[r["kind"], r["n"], f"{r['max_opening']:.6e}", f"{r['build_wall']:.1f} / {r['build_cpu']:.1f}", f"{r['setup_wall']:.1f} / {r['setup_cpu']:.1f}",
             f"{r['solve_wall']:.1f} / {r['solve_cpu']:.1f}", r["iterations"], f"{r['residual']:.1e}",
             f"{(r['setup_wall'] + r['solve_wall']) / r['build_wall']:.2f}", f"{r['solve_wall'] / r['build_wall']:.2f}"]
            for r in rows]
    print_table(header, body)


if __name__ == "__main__":
    main()
