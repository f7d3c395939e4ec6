"""Kernel throughput: element pairs per second for the full traction block.

3D: the 3x3 block (3 DD components x 3 traction components) of a rectangle pair;
2D: the 2x2 block of a segment pair. Single thread (the serial block kernel the H-matrix
calls) and all threads (the parallel dense assembly). Prints a markdown table.

    python benchmarks/bench_kernels.py
"""
import time

import numba
import numpy as np

import hmatddm as hd
from hmatddm.kernels import element_data, line2d, rectangle3d

from _common import machine, markdown_table


def best_of(function, repeats=3):
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - t0)
    return best


def main():
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    rng = np.random.default_rng(0)
    n = 2000
    # a cloud of randomly oriented rectangles (every pair in general position)
    q = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    cloud = hd.Mesh3D.from_rectangles(rng.uniform(-20, 20, (n, 3)), q[:, :, 0], q[:, :, 1],
                                      rng.uniform(0.2, 1, n), rng.uniform(0.2, 1, n))
    segments = hd.Mesh2D.from_segments(rng.uniform(-20, 20, (n, 2)), rng.uniform(-20, 20, (n, 2)))
    rows, cols = np.arange(n // 2), np.arange(n)
    threads = numba.config.NUMBA_NUM_THREADS
    table = []
    for label, mesh, module in (("3D rectangle, 3x3 block", cloud, rectangle3d),
                                ("2D segment, 2x2 block", segments, line2d)):
        d = mesh.dim
        data = element_data(mesh, material)
        block = np.empty((len(rows) * d, len(cols) * d))
        module.traction_block(data, rows, cols, block)  # compile
        serial = len(rows) * len(cols) / best_of(lambda: module.traction_block(data, rows, cols, block))
        dense = np.empty((n * d, n * d))
        module.traction_matrix(data, dense)
        speeds = {}
        for t in sorted({1, threads}):
            numba.set_num_threads(t)
            speeds[t] = n * n / best_of(lambda: module.traction_matrix(data, dense))
        numba.set_num_threads(threads)
        table.append([label, f"{serial / 1e6:.2f}", f"{speeds[1] / 1e6:.2f}", f"{speeds[threads] / 1e6:.2f}",
                      f"{1e9 / serial:.0f}"])
    print(f"Machine: {machine()}; numba threads: {threads}")
    print(markdown_table(["kernel", "block kernel, 1 thread (M pairs/s)", "dense assembly, 1 thread (M pairs/s)",
                          f"dense assembly, {threads} threads (M pairs/s)", "ns per pair (1 thread)"], table))


if __name__ == "__main__":
    main()
