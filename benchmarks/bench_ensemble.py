"""Intersection frequency of natural-fracture networks on Dask (ref. Fig. 6.9).

10 seeded realizations for each of a = 2, 3 and rho_NF = 0.05, 0.1 m^-2 on a 100 m x
100 m domain (mu = 45 deg, kappa = 5, l in [1, 30] m, ref. Table 6.1), run with
``hmatddm.app.ensemble.sweep`` on a local Dask cluster (or ``--scheduler ADDRESS``).
Prints a markdown table and saves ``benchmarks/ensemble_intersections.png``.
"""
import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))

from _common import machine  # noqa: E402

from hmatddm.app import ensemble  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--realizations", type=int, default=10)
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address (default: local cluster)")
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    grid = ensemble.parameter_grid(length_exponent=[2.0, 3.0], density=[0.05, 0.1])
    start = time.perf_counter()
    rows = ensemble.sweep(grid, realizations=args.realizations, scheduler=args.scheduler, n_workers=args.workers)
    seconds = time.perf_counter() - start
    table = ensemble.summarize(rows)
    print(machine())
    print(f"{len(rows)} realizations in {seconds:.1f} s on Dask\n")
    print(ensemble.format_table(table))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4))
    for exponent, marker in ((2.0, "o"), (3.0, "s")):
        rows_a = [t for t in table if t["length_exponent"] == exponent]
        x = [t["density"] for t in rows_a]
        mean = [t["mean"] for t in rows_a]
        low = [t["mean"] - t["min"] for t in rows_a]
        high = [t["max"] - t["mean"] for t in rows_a]
        ax.errorbar(x, mean, yerr=[low, high], marker=marker, capsize=4, label=f"a = {exponent:g}")
    ax.set_xlabel("areal density rho_NF (1/m^2)")
    ax.set_ylabel("intersections along the y axis (1/m)")
    ax.set_title(f"{args.realizations} realizations per point (min-max bars)")
    ax.legend()
    fig.tight_layout()
    path = os.path.join(os.path.dirname(__file__), "ensemble_intersections.png")
    fig.savefig(path, dpi=120)
    print(f"\nsaved {path}")


if __name__ == "__main__":
    main()
