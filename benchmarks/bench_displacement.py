"""Displacements at points (``hd.displacement_at``, ref. Eqs 2.43, 2.55-2.57): the exact
sum against the compressed build-free product.

    python benchmarks/bench_displacement.py

A horizontal 3D fracture (square, ``n x n`` elements of 1 m, 100 m deep, opening
``1 mm (1 - r^2/R^2)`` and a tenth of it in shear) seen from a square grid of ``m`` points
4 km wide on the plane z = 0 (an infinite medium: the free surface is not modelled).
Prints, per size, the CPU and wall time of ``method="direct"`` and ``"tree"`` (eps 1e-5 and
1e-7), the tree's largest error relative to the largest displacement, and the share of
point-element pairs in compressed blocks.
"""
import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402

import hmatddm as hd  # noqa: E402


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    value = function()
    return value, time.process_time() - cpu, time.perf_counter() - wall


def main():
    print(f"Machine: {machine()}")
    material = hd.Elastic(10e9, 0.25)
    rows = []
    for n, m in ((20, 2500), (40, 10000), (60, 40000)):
        mesh = hd.mesh.rectangle([0.0, 0.0, -100.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], float(n), float(n), n, n)
        r2 = np.sum(mesh.centers[:, :2] ** 2, axis=1) / (0.5 * n) ** 2
        dd = np.zeros((mesh.n_elements, 3))
        dd[:, 2] = 1e-3 * np.maximum(1.0 - r2, 0.0)
        dd[:, 0] = 1e-4 * np.maximum(1.0 - r2, 0.0)
        side = int(round(np.sqrt(m)))
        x = np.linspace(-2000.0, 2000.0, side)
        points = np.column_stack([np.repeat(x, side), np.tile(x, side), np.zeros(side * side)])
        hd.displacement_at(mesh, material, dd, points[:10], method="direct")  # compile
        exact, cpu_d, wall_d = timed(lambda: hd.displacement_at(mesh, material, dd, points, method="direct"))
        scale = np.max(np.abs(exact))
        for eps in (1e-5, 1e-7):
            info = {}
            tree, cpu_t, wall_t = timed(lambda: hd.displacement_at(mesh, material, dd, points, method="tree",
                                                                   eps=eps, info=info))
            rows.append([mesh.n_elements, len(points), f"{eps:g}", f"{cpu_d:.2f} / {wall_d:.2f}",
                         f"{cpu_t:.2f} / {wall_t:.2f}", f"{np.max(np.abs(tree - exact)) / scale:.1e}",
                         f"{info.get('pairs_compressed', 0) / (len(points) * mesh.n_elements):.2f}"])
            print(" | ".join(str(c) for c in rows[-1]), flush=True)
    print_table(["elements", "points", "eps", "direct CPU / wall (s)", "tree CPU / wall (s)", "tree max error / max |u|",
                 "pairs compressed"], rows)


if __name__ == "__main__":
    main()
