"""Accuracy against unknowns and time of constant, linear and quadratic 2D DD elements
on the Griffith crack (ref. Sec. 3.5; Crawford & Curran 1982).

    python benchmarks/bench_element_order.py             # table + plot (~1 min)
    python benchmarks/bench_element_order.py --quick     # up to 384 nodes

A crack of half length a = 1 under a net pressure p = 1e-3 G (nu = 0.25), meshed with
equal elements so that each order has the same number of nodes (unknowns = 2 x nodes).
Errors at the nodes against the closed form (hmatddm.analytical.griffith_opening):
largest relative error with |x| < a/2 and |x| < 0.8 a ("away from the tips"), and the
relative error of the crack volume (the nodal openings integrated with the shape
functions, exactly). Times: operator build + solve, wall and CPU (process time) of this
process, after a warm-up that compiles every kernel; dense backend, and the H-matrix
(eps 1e-8, GMRES to 1e-12) from 1536 nodes on.
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import machine, markdown_table  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.mesh import shape_functions  # noqa: E402
from hmatddm.analytical import griffith_opening  # noqa: E402

MATERIAL = hd.Elastic(shear_modulus=1.0, poisson_ratio=0.25)
PRESSURE = 1e-3
HERE = os.path.dirname(os.path.abspath(__file__))


def calibration():
    """Seconds of a fixed workload (LU of a 1500 x 1500 dense matrix, best of 3), to
    compare machines: scale the times below by it."""
    rng = np.random.default_rng(0)
    matrix = rng.normal(size=(1500, 1500))
    import scipy.linalg

    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        scipy.linalg.lu_factor(matrix)
        best = min(best, time.perf_counter() - start)
    return best


def crack_volume(mesh, dd):
    """Integral of the opening along the crack from the nodal openings (Gauss rule exact
    for the shape functions)."""
    xi, weight = np.polynomial.legendre.leggauss(3)
    openings = hd.opening(mesh, dd).reshape(mesh.n_elements, mesh.n_nodes)
    values = openings @ shape_functions.values(mesh.element_order, xi).T  # (N, 3)
    return float(np.sum(values * weight[None, :] * mesh.half_length[:, None]))


def run(order, nodes, backend):
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], nodes // (order + 1), element_order=order)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    options = dict(eps=1e-8) if backend == "hmatrix" else {}
    operator = hd.ElasticityOperator(mesh, MATERIAL, backend=backend, **options)
    dd = hd.solve(operator, -PRESSURE * mesh.normals, rtol=1e-12)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    x = mesh.collocation_points[:, 0]
    exact = griffith_opening(x, 1.0, PRESSURE, MATERIAL)
    error = np.abs(hd.opening(mesh, dd).reshape(-1) - exact) / exact
    volume_exact = np.pi * 2.0 * (1.0 - MATERIAL.poisson_ratio) * PRESSURE / MATERIAL.shear_modulus / 2.0
    compression = operator.stats["compression"]
    return dict(order=order, nodes=nodes, elements=mesh.n_elements, backend=backend, compression=compression,
                half=float(error[np.abs(x) < 0.5].max()), inner=float(error[np.abs(x) < 0.8].max()),
                volume=abs(crack_volume(mesh, dd) / volume_exact - 1.0), wall=wall, cpu=cpu)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--plot", default=os.path.join(HERE, "element_order_accuracy.png"))
    args = parser.parse_args()
    sizes = [24, 48, 96, 192, 384] + ([] if args.quick else [768, 1536, 3072])
    for order in (0, 1, 2):  # warm-up: compile every kernel and driver
        run(order, 12, "dense")
        run(order, 600, "hmatrix")
    calib = calibration()
    rows = []
    for nodes in sizes:
        for order in (0, 1, 2):
            backends = ["dense"] + (["hmatrix"] if nodes >= 1536 else [])
            if nodes > 1536:
                backends = ["hmatrix"]
            for backend in backends:
                rows.append(run(order, nodes, backend))
                r = rows[-1]
                print(f"order {order} nodes {nodes} {backend}: {r['half']:.2e} {r['wall']:.3f}s", flush=True)
    names = {0: "constant", 1: "linear", 2: "quadratic"}
    constant = {(r["nodes"], r["backend"]): r for r in rows if r["order"] == 0}
    table = []
    for r in rows:
        ref = constant[(r["nodes"], r["backend"])]
        table.append([r["nodes"], 2 * r["nodes"], names[r["order"]], r["elements"], r["backend"], f"{r['half']:.2e}",
                      f"{ref['half'] / r['half']:.1f}", f"{r['inner']:.2e}", f"{r['volume']:.1e}",
                      f"{r['wall']:.3f}", f"{r['cpu']:.3f}", f"{r['compression']:.2f}"])
    print(f"\nMachine: {machine()}; calibration (LU of a 1500x1500 matrix, best of 3): {calib:.3f} s")
    print(markdown_table(["nodes", "unknowns", "element type", "elements", "backend", "max rel. error \\|x\\|<a/2",
                          "gain vs constant", "max rel. error \\|x\\|<0.8a", "volume error", "wall s", "CPU s",
                          "compression (dense bytes / stored)"],
                         table))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        for order in (0, 1, 2):
            mine = [r for r in rows if r["order"] == order]
            dense = [r for r in mine if r["backend"] == "dense"]
            axes[0].loglog([2 * r["nodes"] for r in mine], [r["half"] for r in mine], "o-", label=names[order])
            axes[1].loglog([r["wall"] for r in dense], [r["half"] for r in dense], "o-", label=names[order])
        axes[0].set_xlabel("unknowns")
        axes[1].set_xlabel("build + solve wall time, dense (s)")
        for ax in axes:
            ax.set_ylabel("max relative opening error, |x| < a/2")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend()
        fig.suptitle("Griffith crack: constant, linear and quadratic DD elements")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
