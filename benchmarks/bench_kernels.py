"""Kernel throughput and operator builds through the kernel drivers.

Table 1 (``--throughput``): element pairs per second of the full traction block through
:mod:`hmatddm.kernels.drivers` -- 3D: the 3x3 block of a rectangle pair; 2D: the 2x2 block
of a segment pair. Single thread (the serial block kernel the H-matrix calls) and all
threads (the parallel dense assembly).

Table 2 (``--builds``): the public path (:class:`hmatddm.ElasticityOperator`, dense and
hmatrix backends) for each kind of kernel data the drivers serve: 3D rectangles, 2D
constant segments, 2D quadratic segments, 2D constant segments in a layered medium. Wall
and CPU time (best of ``--repeats`` after a warm-up build that compiles), with the sha1
of the dense matrix and of the H-matrix's product with a fixed vector, so that two
versions of the kernels can be compared bit for bit.

    python benchmarks/bench_kernels.py [--throughput] [--builds] [--repeats 2] [--scale 1.0]
"""
import argparse
import hashlib
import time

import numba
import numpy as np

import hmatddm as hd
from _common import machine, markdown_table

MATERIAL = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)


def square_crack(n_side):
    """``n_side^2`` unit squares of one planar crack tilted 30 degrees about x."""
    h = 1.0 / n_side
    grid = (np.arange(n_side) + 0.5) * h - 0.5
    x, y = np.meshgrid(grid, grid, indexing="ij")
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    e1 = np.tile([1.0, 0.0, 0.0], (x.size, 1))
    e2 = np.tile([0.0, c, s], (x.size, 1))
    centers = x.reshape(-1, 1) * e1 + y.reshape(-1, 1) * e2
    half = np.full(x.size, 0.5 * h)
    return hd.Mesh3D.from_rectangles(centers, e1, e2, half, half)


def parallel_segments(n, n_cracks=4, element_order=0):
    """``n`` segments on ``n_cracks`` parallel, slightly inclined cracks."""
    per = n // n_cracks
    p0, p1 = [], []
    for k in range(n_cracks):
        s = np.linspace(-1.0, 1.0, per + 1)
        y = 0.3 * k + 0.05 * s
        p0.append(np.stack([s[:-1] + 0.1 * k, y[:-1]], axis=1))
        p1.append(np.stack([s[1:] + 0.1 * k, y[1:]], axis=1))
    return hd.Mesh2D.from_segments(np.concatenate(p0), np.concatenate(p1), element_order=element_order)


def digest(array):
    return hashlib.sha1(np.ascontiguousarray(array).tobytes()).hexdigest()[:12]


def timed(build, repeats):
    best_wall, best_cpu, result = np.inf, np.inf, None
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        result = build()
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        if wall < best_wall:
            best_wall, best_cpu = wall, cpu
    return best_wall, best_cpu, result


def best_of(function, repeats=3):
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - t0)
    return best


def throughput():
    """Table 1: M pairs/s of the block kernel (1 thread) and the dense assembly."""
    from hmatddm.kernels import drivers, element_data  # here: bench_dense_assembly runs older trees too

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
    for label, mesh in (("3D rectangle, 3x3 block", cloud), ("2D segment, 2x2 block", segments)):
        d = mesh.dim
        data = element_data(mesh, MATERIAL)
        block = np.empty((len(rows) * d, len(cols) * d))
        drivers.traction_block(data, rows, cols, block)  # compile
        serial = len(rows) * len(cols) / best_of(lambda: drivers.traction_block(data, rows, cols, block))
        dense = np.empty((n * d, n * d))
        drivers.traction_matrix(data, dense)
        speeds = {}
        for t in sorted({1, threads}):
            numba.set_num_threads(t)
            speeds[t] = n * n / best_of(lambda: drivers.traction_matrix(data, dense))
        numba.set_num_threads(threads)
        table.append([label, f"{serial / 1e6:.2f}", f"{speeds[1] / 1e6:.2f}", f"{speeds[threads] / 1e6:.2f}",
                      f"{1e9 / serial:.0f}"])
    print(markdown_table(["kernel", "block kernel, 1 thread (M pairs/s)", "dense assembly, 1 thread (M pairs/s)",
                          f"dense assembly, {threads} threads (M pairs/s)", "ns per pair (1 thread)"], table))


def builds(repeats, s):
    """Table 2: dense and H-matrix operator builds of every kind of kernel data."""
    layered = hd.LayeredMedium(interfaces=[0.45, 0.15], shear_modulus=[10e9, 4e9, 12e9],
                               poisson_ratio=[0.25, 0.3, 0.2], images=2)
    cases = [("3D rectangles", square_crack(int(45 * s ** 0.5)), MATERIAL),
             ("2D constant", parallel_segments(int(2000 * s)), MATERIAL),
             ("2D quadratic", parallel_segments(int(700 * s), element_order=2), MATERIAL),
             ("2D layered, constant", parallel_segments(int(600 * s)), layered)]
    rng = np.random.default_rng(1)
    table = []
    for label, mesh, material in cases:
        for backend in ("dense", "hmatrix"):
            hd.ElasticityOperator(mesh.subset(np.arange(8)), material, backend=backend)  # compile
            wall, cpu, op = timed(lambda: hd.ElasticityOperator(mesh, material, backend=backend), repeats)
            x = rng.standard_normal(op.shape[1])
            check = digest(op.to_dense()) if backend == "dense" else digest(op @ x)
            table.append([label, backend, str(mesh.n_elements), str(op.shape[0]), f"{wall:.2f}", f"{cpu:.2f}",
                          check])
            print(" | ".join(table[-1]), flush=True)
    print(markdown_table(["kernel", "backend", "elements", "unknowns", "build wall (s)", "build CPU (s)",
                          "sha1 (dense matrix / H-matrix @ x)"], table))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--throughput", action="store_true", help="table 1 only (default: both tables)")
    parser.add_argument("--builds", action="store_true", help="table 2 only (default: both tables)")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--scale", type=float, default=1.0, help="multiplies every element count of table 2")
    args = parser.parse_args()
    both = not (args.throughput or args.builds)
    print(f"Machine: {machine()}; numba threads: {numba.config.NUMBA_NUM_THREADS}")
    if both or args.throughput:
        throughput()
    if both or args.builds:
        builds(args.repeats, args.scale)


if __name__ == "__main__":
    main()
