"""One numba thread against two, per operation and size, interleaved in the same process.

    python benchmarks/bench_threads.py                  # sizes 100 .. 10 000 elements
    python benchmarks/bench_threads.py --sizes 100,400,1600 --repeats 3

For each planar 3D crack of N square elements: the H-matrix build and the H matvec,
each timed with 1 and 2 threads alternately (1, 2, 1, 2, ...), so that both thread
counts see the same background load. "raw" runs the parallel code at every size (the
crossover search); "policy" runs what the library does now (one thread below
``SERIAL_MATVEC_ENTRIES`` and on the cores other processes leave free, see
:mod:`hmatddm.hmatrix._threads`). Each row gives the wall time (mean per call, best of the repeats), the
process CPU time (OpenMP threads spin a while after each region, so CPU time
can exceed the wall time) and the background load (cores kept busy by other processes during
the measurement: machine busy time minus this process's CPU time, over the wall time).
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def timed(function, threads, calls):
    """(mean wall, CPU per call, background cores) of ``calls`` calls on ``threads`` threads
    (the mean, not the median: a descheduled thread makes rare calls very slow)."""
    import numba

    from hmatddm.hmatrix._threads import machine_busy_seconds

    numba.set_num_threads(threads)
    walls = []
    busy0, cpu0 = machine_busy_seconds(), time.process_time()
    start = time.perf_counter()
    for _ in range(calls):
        t0 = time.perf_counter()
        function()
        walls.append(time.perf_counter() - t0)
    total = time.perf_counter() - start
    cpu = time.process_time() - cpu0
    background = max(0.0, (machine_busy_seconds() - busy0 - cpu) / total)
    return float(np.mean(walls)), cpu / calls, background


def measure(n, repeats, policy):
    import hmatddm as hd
    from hmatddm.hmatrix import _threads

    saved = (_threads.SERIAL_MATVEC_ENTRIES, _threads.ADAPT_TO_LOAD)
    if not policy:
        _threads.SERIAL_MATVEC_ENTRIES, _threads.ADAPT_TO_LOAD = 0, False
    side = int(round(np.sqrt(n)))
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], float(side), float(side), side, side)
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    holder = {}

    def build():
        holder["op"] = hd.ElasticityOperator(mesh, material, backend="hmatrix")

    build()  # compile
    x = np.random.default_rng(0).normal(size=holder["op"].shape[1])
    results = {"build": {1: [], 2: []}, "matvec": {1: [], 2: []}}
    outputs = {}
    calls = max(3, int(2e5 / n))
    for _ in range(repeats):
        for threads in (1, 2):
            results["build"][threads].append(timed(build, threads, 1))  # noqa: B023
            op = holder["op"]
            results["matvec"][threads].append(timed(lambda: op.matvec(x), threads, calls))
            outputs[threads] = op.matvec(x)
    _threads.SERIAL_MATVEC_ENTRIES, _threads.ADAPT_TO_LOAD = saved
    import numba

    numba.set_num_threads(2)
    identical = bool(np.array_equal(outputs[1], outputs[2]))
    rows = []
    for operation, per_threads in results.items():
        best = {t: min(v, key=lambda r: r[0]) for t, v in per_threads.items()}
        rows.append(dict(n=mesh.n_elements, operation=operation, mode="policy" if policy else "raw",
                         wall_1=best[1][0], wall_2=best[2][0], cpu_1=best[1][1], cpu_2=best[2][1],
                         load_1=float(np.mean([r[2] for r in per_threads[1]])),
                         load_2=float(np.mean([r[2] for r in per_threads[2]])),
                         entries=int(holder["op"].hmatrix.storage.memory_bytes // 8), identical=identical))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,400,1024,2025,4096,10000")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--modes", default="raw,policy")
    args = parser.parse_args()
    sys.path.insert(0, HERE)
    from _common import machine, markdown_table

    print(f"Machine: {machine()}", flush=True)
    rows = []
    for n in [int(s) for s in args.sizes.split(",")]:
        for mode in args.modes.split(","):
            rows += measure(n, args.repeats, mode == "policy")
            print(rows[-2:], flush=True)
    header = ["N", "operation", "mode", "stored entries", "wall 1 thread (ms)", "wall 2 threads (ms)",
              "2 / 1", "CPU 1 (ms)", "CPU 2 (ms)", "background load 1 / 2 (cores)", "bit-identical"]
    body = [[r["n"], r["operation"], r["mode"], f"{r['entries']:.2e}", f"{1e3 * r['wall_1']:.2f}",
             f"{1e3 * r['wall_2']:.2f}", f"{r['wall_2'] / r['wall_1']:.2f}", f"{1e3 * r['cpu_1']:.2f}",
             f"{1e3 * r['cpu_2']:.2f}", f"{r['load_1']:.2f} / {r['load_2']:.2f}", "yes" if r["identical"] else "NO"]
            for r in rows]
    print()
    print(markdown_table(header, body))


if __name__ == "__main__":
    main()
