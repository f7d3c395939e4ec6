"""One numba thread against two (or more), per operation and size, interleaved in the
same process.

    python benchmarks/bench_threads.py                  # sizes 100 .. 10 000 elements
    python benchmarks/bench_threads.py --sizes 10000,40000 --repeats 2 --modes raw   # issue 40
    python benchmarks/bench_threads.py --sizes 40000 --threads 1,4,16                 # a bigger machine
    python benchmarks/bench_threads.py --cache-check     # issue 40: serial code compiled first

For each planar 3D crack of N square elements: the H-matrix build, the H matvec, one
application of the default preconditioner (near-field block ILU, in nested-dissection
order from 5000 elements: hmatddm/hmatrix/dissection.py) and a preconditioned GMRES
solve (``hd.solve``, rtol 1e-8, preconditioner built beforehand), each timed with every
thread count in turn (1, 2, 1, 2, ...), so that all counts see the same background
load. The parallel efficiency is ``wall(1) / (threads * wall(threads))``; the outputs of
the product, the preconditioner and the solve are compared bit for bit across counts.

``--cache-check`` reproduces issue 40 in two child processes sharing an empty numba
cache: the first runs every product on the serial path (as a small problem does), the
second times the parallel product of 10 000 elements on 1 and 2 threads. Before the
serial twin had a cache of its own (``hmatddm.compiled.serial_twin``), the parallel
product then loaded the serial code: CPU time equal to wall time on 2 threads. "raw" runs the parallel code at every size (the
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


def measure(n, repeats, policy, thread_counts=(1, 2)):
    import hmatddm as hd
    from hmatddm.hmatrix import _threads

    saved = (_threads.SERIAL_MATVEC_ENTRIES, _threads.ADAPT_TO_LOAD)
    if not policy:
        _threads.SERIAL_MATVEC_ENTRIES, _threads.ADAPT_TO_LOAD = 0, False
    side = int(round(np.sqrt(n)))
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], float(side), float(side), side, side)
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    traction = -1e6 * mesh.normals
    holder = {}

    def build():
        holder["op"] = hd.ElasticityOperator(mesh, material, backend="hmatrix")
        holder["op"].preconditioner()

    build()  # compile
    x = np.random.default_rng(0).normal(size=holder["op"].shape[1])
    operations = ("build", "matvec", "preconditioner", "solve")
    results = {operation: {t: [] for t in thread_counts} for operation in operations}
    outputs = {operation: {} for operation in operations[1:]}
    calls = {"matvec": max(3, int(2e5 / n)), "preconditioner": max(3, int(2e5 / n)), "solve": 1}
    iterations = 0
    for _ in range(repeats):
        for threads in thread_counts:
            results["build"][threads].append(timed(build, threads, 1))  # noqa: B023
            op = holder["op"]
            preconditioner = op.preconditioner()
            work = {"matvec": lambda: op.matvec(x), "preconditioner": lambda: preconditioner @ x,  # noqa: B023
                    "solve": lambda: hd.solve(op, traction, rtol=1e-8, return_info=True)}  # noqa: B023
            for operation, function in work.items():
                results[operation][threads].append(timed(function, threads, calls[operation]))
                outputs[operation][threads] = function()
            iterations = outputs["solve"][threads][1]["iterations"]
    _threads.SERIAL_MATVEC_ENTRIES, _threads.ADAPT_TO_LOAD = saved
    import numba

    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    first = thread_counts[0]

    def same(operation):
        value = lambda t: outputs[operation][t][0] if operation == "solve" else outputs[operation][t]  # noqa: E731
        return all(np.array_equal(value(first), value(t)) for t in thread_counts)

    rows = []
    for operation, per_threads in results.items():
        best = {t: min(v, key=lambda r: r[0]) for t, v in per_threads.items()}
        for threads in thread_counts[1:]:
            rows.append(dict(n=mesh.n_elements, operation=operation, mode="policy" if policy else "raw",
                             threads=threads, wall_1=best[first][0], wall_t=best[threads][0],
                             cpu_1=best[first][1], cpu_t=best[threads][1],
                             load_1=float(np.mean([r[2] for r in per_threads[first]])),
                             load_t=float(np.mean([r[2] for r in per_threads[threads]])),
                             entries=int(holder["op"].hmatrix.storage.memory_bytes // 8),
                             identical=True if operation == "build" else same(operation),
                             iterations=iterations if operation == "solve" else None))
    return rows


_CACHE_CHECK = """
import sys, time, numba, numpy as np
import hmatddm as hd
from hmatddm.hmatrix import _threads
_threads.ADAPT_TO_LOAD = False
_threads.SERIAL_MATVEC_ENTRIES = 10**15 if sys.argv[1] == "serial-first" else 0
mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 100.0, 100.0, 100, 100)
op = hd.ElasticityOperator(mesh, hd.Elastic(10e9, 0.25), backend="hmatrix", eps=1e-4)
x = np.ones(op.shape[1])
op.matvec(x)
_threads.SERIAL_MATVEC_ENTRIES = 0
for threads in (1, 2):
    numba.set_num_threads(threads)
    op.matvec(x)
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(10):
        op.matvec(x)
    print(sys.argv[1], threads, 100 * (time.perf_counter() - wall), 100 * (time.process_time() - cpu))
"""


def cache_check():
    """Rows (process, threads, wall ms, CPU ms) of the two processes of ``--cache-check``."""
    import subprocess
    import tempfile

    rows = []
    with tempfile.TemporaryDirectory() as cache:
        environment = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=os.pathsep.join(
            [os.path.dirname(HERE), os.environ.get("PYTHONPATH", "")]))
        for process in ("serial-first", "after"):
            out = subprocess.run([sys.executable, "-c", _CACHE_CHECK, process], env=environment, check=True,
                                 capture_output=True, text=True).stdout
            rows += [line.split() for line in out.splitlines()]
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,400,1024,2025,4096,10000")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--modes", default="raw,policy")
    parser.add_argument("--threads", default="1,2", help="thread counts, the first the reference (default 1,2)")
    parser.add_argument("--cache-check", action="store_true", help="reproduce issue 40 (see the docstring)")
    args = parser.parse_args()
    sys.path.insert(0, HERE)
    from _common import machine, markdown_table, print_table

    print(f"Machine: {machine()}", flush=True)
    if args.cache_check:
        rows = cache_check()
        print(markdown_table(["process", "threads", "wall per product (ms)", "CPU per product (ms)"],
                             [[p, t, f"{float(w):.1f}", f"{float(c):.1f}"] for p, t, w, c in rows]))
        return
    thread_counts = tuple(int(t) for t in args.threads.split(","))
    rows = []
    for n in [int(s) for s in args.sizes.split(",")]:
        for mode in args.modes.split(","):
            new_rows = measure(n, args.repeats, mode == "policy", thread_counts)
            rows += new_rows
            print(new_rows, flush=True)
    header = ["N", "operation", "mode", "stored entries", "threads t", "wall 1 (ms)", "wall t (ms)", "efficiency",
              "CPU 1 (ms)", "CPU t (ms)", "background load 1 / t (cores)", "bit-identical"]
    body = [[r["n"], r["operation"] + (f" ({r['iterations']} its)" if r["iterations"] else ""), r["mode"],
             f"{r['entries']:.2e}", r["threads"], f"{1e3 * r['wall_1']:.2f}", f"{1e3 * r['wall_t']:.2f}",
             f"{r['wall_1'] / (r['threads'] * r['wall_t']):.2f}", f"{1e3 * r['cpu_1']:.2f}",
             f"{1e3 * r['cpu_t']:.2f}", f"{r['load_1']:.2f} / {r['load_t']:.2f}", "yes" if r["identical"] else "NO"]
            for r in rows]
    print_table(header, body)


if __name__ == "__main__":
    main()
