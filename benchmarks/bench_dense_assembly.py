"""Dense assembly and the block kernel per element pair, this tree against another (issue 18).

For each kind of kernel data -- 2D constant segments (homogeneous), 3D rectangles
(homogeneous), 2D constant segments in a layered medium -- the whole dense traction
matrix is assembled on 1 thread and on all of numba's threads, and the serial block
kernel (what the H-matrix build calls) fills half the rows; CPU and wall time per element
pair (best of ``--repeats`` after a compiling warm-up) and the sha1 of the dense matrix.
With ``--before TREE`` (a checkout of an older commit, e.g. ``git worktree add --detach
/tmp/before 6ea7e49``) the same measurements run on that tree's ``hmatddm`` too, in
alternating child processes (``--rounds`` rounds), so both columns see the same machine
load; the table gives the best of every round. Works with the drivers before the merge
into :mod:`hmatddm.kernels.drivers` (per-dimension ``traction_matrix``) and after.

    python benchmarks/bench_dense_assembly.py [--before TREE] [--rounds 2] [--repeats 3] [--scale 1.0]
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def cases(scale):
    """(label, mesh, material) of the three kinds of kernel data."""
    import hmatddm as hd

    sys.path.insert(0, HERE)
    from bench_kernels import parallel_segments, square_crack

    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    layered = hd.LayeredMedium(interfaces=[0.45, 0.15], shear_modulus=[10e9, 4e9, 12e9],
                               poisson_ratio=[0.25, 0.3, 0.2], images=2)
    return [("2D line, homogeneous", parallel_segments(int(2000 * scale)), material),
            ("3D rectangle, homogeneous", square_crack(int(40 * scale ** 0.5)), material),
            ("2D line, layered (2 images)", parallel_segments(int(160 * scale)), layered)]


def kernel(mesh, material):
    """(data, dense assembly, block kernel) of this tree's hmatddm."""
    import hmatddm as hd
    from hmatddm import kernels

    if isinstance(material, hd.LayeredMedium):
        from hmatddm.layered import images2d, influence2d

        data = influence2d.influence_data(mesh, material, 0.0, 0.0, 0.0, material.images)
        module = images2d
    else:
        data = kernels.element_data(mesh, material)
        module = kernels.kernel_module(mesh) if hasattr(kernels, "kernel_module") else None
    try:
        from hmatddm.kernels import drivers  # after the merge (29610e6)
    except ImportError:
        return data, module.traction_matrix, module.traction_block
    return data, drivers.traction_matrix, drivers.traction_block


def best(function, repeats):
    """Best (CPU s, wall s) of ``repeats`` calls."""
    cpu, wall = np.inf, np.inf
    for _ in range(repeats):
        c, w = time.process_time(), time.perf_counter()
        function()
        c, w = time.process_time() - c, time.perf_counter() - w
        if w < wall:
            cpu, wall = c, w
    return cpu, wall


def worker(scale, repeats):
    """One tree's measurements, as JSON on stdout."""
    import numba

    threads = numba.config.NUMBA_NUM_THREADS
    rows = []
    for label, mesh, material in cases(scale):
        data, dense, block_kernel = kernel(mesh, material)
        n = mesh.n_elements
        d = mesh.dim
        out = np.empty((n * d, n * d))
        dense(data, out)  # compile
        numba.set_num_threads(1)
        cpu1, wall1 = best(lambda: dense(data, out), repeats)
        numba.set_num_threads(threads)
        cpu_all, wall_all = best(lambda: dense(data, out), repeats)
        sha = hashlib.sha1(out.tobytes()).hexdigest()[:12]
        half = np.arange(n // 2, dtype=np.int64)
        every = np.arange(n, dtype=np.int64)
        block = np.empty((len(half) * d, n * d))
        block_kernel(data, half, every, block)
        cpu_block, wall_block = best(lambda: block_kernel(data, half, every, block), repeats)
        if not np.array_equal(block, out[:len(half) * d], equal_nan=True):
            raise AssertionError(f"{label}: the block kernel and the dense matrix differ")
        pairs = float(n * n)
        rows.append(dict(label=label, n=n, sha=sha, threads=threads,
                         dense1=(cpu1 / pairs * 1e9, wall1 / pairs * 1e9),
                         dense_all=(cpu_all / pairs * 1e9, wall_all / pairs * 1e9),
                         block=(cpu_block / (pairs / 2) * 1e9, wall_block / (pairs / 2) * 1e9)))
    print(json.dumps(rows))


def run_tree(tree, scale, repeats):
    env = dict(os.environ, PYTHONPATH=tree)
    result = subprocess.run([sys.executable, os.path.abspath(__file__), "--worker", "--scale", str(scale),
                             "--repeats", str(repeats)], env=env, cwd=tree, check=True, capture_output=True, text=True)
    return json.loads(result.stdout.strip().splitlines()[-1])


def merge(old, new):
    """Element-wise minimum of two rounds' rows (best of every round)."""
    if old is None:
        return new
    for a, b in zip(old, new):
        for key in ("dense1", "dense_all", "block"):
            a[key] = min(a[key], b[key], key=lambda t: t[1])
    return old


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", help="a checkout of the older tree (its root directory)")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--scale", type=float, default=1.0, help="multiplies every element count")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.scale, args.repeats)
        return
    sys.path.insert(0, HERE)
    from _common import calibration, machine, markdown_table

    here = os.path.dirname(HERE)
    trees = {"after": here} if args.before is None else {"before": os.path.abspath(args.before), "after": here}
    print(f"Machine: {machine()}; load (uptime): {os.getloadavg()}", flush=True)
    results = {name: None for name in trees}
    for round_ in range(args.rounds):
        for name, tree in trees.items():
            results[name] = merge(results[name], run_tree(tree, args.scale, args.repeats))
            print(f"round {round_ + 1} {name} done, load {os.getloadavg()}", flush=True)
    calibration.cache_clear()
    print(f"Machine after: {machine()}; load (uptime): {os.getloadavg()}")
    fmt = "{:.0f} / {:.0f}".format
    table = []
    for k, row in enumerate(results["after"]):
        for name in trees:
            r = results[name][k]
            table.append([r["label"], str(r["n"]), name, fmt(*r["dense1"]), fmt(*r["dense_all"]), fmt(*r["block"]),
                          r["sha"]])
    threads = results["after"][0]["threads"]
    print(markdown_table(["kernel", "elements", "tree", "dense, 1 thread: CPU / wall (ns per pair)",
                          f"dense, {threads} threads: CPU / wall (ns per pair)",
                          "block kernel (serial): CPU / wall (ns per pair)", "sha1 of the dense matrix"], table))


if __name__ == "__main__":
    main()
