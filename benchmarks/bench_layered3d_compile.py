"""Cold compile time of the 3D layered kernel (issues 14, 18 and 32): each compiled entry
point for :class:`hmatddm.layered.images3d.LayeredRectangles` (the operator's
``traction_block``; ``stress_points`` of :mod:`hmatddm.layered.stress3d`, the stress at
points of ``hd.stress_at``; the drivers' generic ``stress_block``, which only tests and
benchmarks call with layered 3D data; ``edge_distance``) first called, in that order, in a
fresh process with an empty numba cache (``NUMBA_CACHE_DIR`` set to a new folder: everything it uses is
compiled, the homogeneous rectangle kernel included), then again with that cache warm.
CPU time beside wall time; the functions taking the most compile CPU (exclusive of the
njit functions they call, from numba's ``numba:compile`` events; ``llvm`` is the part
spent in LLVM: optimisation and machine code) and their number of compiled type
signatures. ``--2d``: the same for the 2D layered kernel (:mod:`hmatddm.layered.images2d`).

Run: ``python benchmarks/bench_layered3d_compile.py [--2d] [--top 25]``."""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

try:
    from _common import machine, markdown_table
    from compile_profile import CompileRecorder
except ImportError:  # run from the repository root
    from benchmarks._common import machine, markdown_table
    from benchmarks.compile_profile import CompileRecorder


def _child(two_d):
    """In the measured process: the compile events and each entry point's first call."""
    from collections import defaultdict

    recorder = CompileRecorder()

    import numpy as np

    timings = []

    def timed(label, function):
        c0, t0 = time.process_time(), time.perf_counter()
        function()
        timings.append((label, time.process_time() - c0, time.perf_counter() - t0))

    with recorder.listening():
        modules = {}
        timed("import hmatddm", lambda: modules.update(hd=__import__("hmatddm")))
        from hmatddm.elasticity import operator as operators
        from hmatddm.kernels import drivers
        from hmatddm.layered import LayeredMedium
        from hmatddm.mesh import concatenate, line, rectangle

        if two_d:
            grid = concatenate([line([-1.0, -1.0], [1.0, -1.0], 8, fracture_id=0),
                                line([2.0, -2.0], [2.0, -1.0], 4, fracture_id=1)])
            medium = LayeredMedium([-0.5, -2.2], [3.0, 1.0, 2.0], [0.25, 0.25, 0.3], images=2)
        else:
            grid = concatenate([rectangle([0, 0, -1.0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 3, 3, fracture_id=0),
                                rectangle([3, 0, -1.5], [0, 1, 0], [0, 0, 1], 2.0, 1.0, 3, 2, fracture_id=1)])
            medium = LayeredMedium([-0.5, -2.2], [3.0, 1.0, 2.0], [0.25, 0.25, 0.3], images=2)
        data = operators.influence_data(grid, medium)
        dim = grid.dim
        n = grid.n_elements
        every = np.arange(n, dtype=np.int64)
        out = np.empty((dim * n, dim * n))
        timed("traction_block", lambda: drivers.traction_block(data, every, every, out))
        points = np.ascontiguousarray(grid.centers[:2] + 0.1)
        layers = medium.layer_of(points[:, -1]).astype(np.int64)
        if not two_d:  # the stress at points of hd.stress_at: sources outside (layered/stress3d.py)
            from hmatddm.layered import stress3d

            timed("stress_points", lambda: stress3d.stress_sum(data, points, np.ones((n, dim)), layers))
        timed("stress_block", lambda: drivers.stress_sum(data, points, np.ones((n, dim)), layers))
        timed("edge_distance", lambda: drivers.edge_distance(data, 0, 1))
    exclusive = defaultdict(lambda: [0.0, 0.0, 0])  # name -> [CPU s, LLVM CPU s, signatures]
    for record in recorder.records:
        entry = exclusive[f"{record['module'].split('.')[-1]}.{record['name'].split('.')[-1]}"]
        entry[0] += record["exclusive"]
        entry[1] += record["llvm"]
        entry[2] += 1
    print("RESULT " + json.dumps({"timings": timings, "functions": dict(exclusive),
                                  "checksum": float(np.abs(out).sum())}))


def measure(cache_dir, two_d):
    """Run :func:`_child` in a fresh process using ``cache_dir``; its result and CPU time."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    command = [sys.executable, __file__, "--child"] + (["--2d"] if two_d else [])
    before = os.times()
    t0 = time.perf_counter()
    run = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    after = os.times()
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    line = [text for text in run.stdout.splitlines() if text.startswith("RESULT ")][-1]
    return json.loads(line[7:]), cpu, wall


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--2d", dest="two_d", action="store_true", help="the 2D layered kernel instead")
    parser.add_argument("--top", type=int, default=25, help="functions listed")
    args = parser.parse_args()
    if args.child:
        _child(args.two_d)
        return
    print(machine())
    print(f"load (1, 5, 15 min): {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as cache:
        cold, cold_cpu, cold_wall = measure(cache, args.two_d)
        warm, warm_cpu, warm_wall = measure(cache, args.two_d)
    print(f"load after: {os.getloadavg()}")
    rows = [[label, f"{c:.1f}", f"{w:.1f}", f"{wc:.2f}", f"{ww:.2f}"]
            for (label, c, w), (_, wc, ww) in zip(cold["timings"], warm["timings"])]
    rows.append(["whole process", f"{cold_cpu:.1f}", f"{cold_wall:.1f}", f"{warm_cpu:.2f}", f"{warm_wall:.2f}"])
    kind = "2D" if args.two_d else "3D"
    print(f"\nFirst calls, layered {kind} kernel (3 layers, 2 images), empty cache then warm cache:")
    print(markdown_table(["call", "cold CPU s", "cold wall s", "warm CPU s", "warm wall s"], rows))
    functions = sorted(cold["functions"].items(), key=lambda item: -item[1][0])
    total = sum(v[0] for _, v in functions)
    print(f"\nCompile CPU by function (exclusive), cold; {len(functions)} functions, {total:.1f} s in all:")
    print(markdown_table(["function", "CPU s", "of which LLVM s", "signatures"],
                         [[name, f"{v[0]:.2f}", f"{v[1]:.2f}", v[2]] for name, v in functions[:args.top]]))
    print(f"\nchecksum of the traction block: {cold['checksum']!r} (warm: {warm['checksum']!r})")


if __name__ == "__main__":
    main()
