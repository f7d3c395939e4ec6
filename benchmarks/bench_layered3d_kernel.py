"""Cost and accuracy of one influence entry (a 3 x 3 element pair) of the 3D layered
kernel (issue 14): a 108 x 108 element block of a 216-rectangle mesh (a horizontal sill
1 m below the free surface and a vertical fracture beside it), one thread, for a
half-space, a bi-material and three layers, next to the homogeneous kernel. The error of
each block is measured against the same block with 8 Gauss points per side on every
(sub-)square (``far_tol = 0``; ``--quick``: the half-space only).

``--issue32``: the mesh of issue 32 (576 randomly oriented 0.5 m squares on an 8 x 8 x 9
lattice of 3 m, centres at 3-27 m depth), uniform rock, a half-space (``images=1``) and a
free surface with interfaces at z = -10, -20 m (G, 2G, G, ``images=4``) side by side:
per-pair CPU of the default path (merged image triples, Gauss order from the error
allowed relative to the largest entry) and of the relative-error rule of issue 14
(``entry_tol = 0``), each with its error against 8 points per side everywhere (on
``--error-rows`` receivers), for ``gauss_points`` 4 (the default) and 6; the three-layer
timings on ``--rows3`` receivers (all 576 sources).

``--whole``: the same mesh, the *whole* 576 x 576 matrix of each medium after a warm-up (so a
source's tracing is shared by all 576 receivers, as in a real assembly), uniform rock the best
of five, the three-layer error on ``--error-rows`` receivers against 8 points per side
everywhere; ``--compare TREE`` runs the same in a child process on another source tree (e.g.
a worktree of the previous commit) and prints both, one after the other.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_kernel.py [--issue32 | --whole [--compare TREE]]``."""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

import hmatddm as hd
from hmatddm.elasticity import operator as operators
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium
from hmatddm.mesh import concatenate, rectangle

try:
    from _common import machine, markdown_table
except ImportError:  # run from the repository root
    from benchmarks._common import machine, markdown_table

CASES = {"homogeneous": hd.Elastic(1.0, 0.25),
         "half-space (1 image)": LayeredMedium([0.0], [0.0, 1.0], [0.25, 0.25], images=1),
         "bi-material (1 image)": LayeredMedium([0.0], [2.0, 1.0], [0.25, 0.25], images=1),
         "3 layers (4 images)": LayeredMedium([-0.5, -2.2], [3.0, 1.0, 2.0], [0.25, 0.25, 0.3], images=4)}


def mesh():
    return concatenate([rectangle([0, 0, -1.0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 12, 12, fracture_id=0),
                        rectangle([3, 0, -1.5], [0, 1, 0], [0, 0, 1], 2.0, 1.0, 12, 6, fracture_id=1)])


def block(data, rows, cols, repeats=2):
    """(block, best CPU s, its wall s) of ``traction_block`` (compiled first; with ``repeats > 1``
    one whole untimed pass first: the first one or two after another kernel's run slower)."""
    out = np.empty((3 * len(rows), 3 * len(cols)))
    drivers.traction_block(data, rows[:2], cols[:2], out[:6, :6])
    if repeats > 1:
        drivers.traction_block(data, rows, cols, out)
    best = (np.inf, np.inf)
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        drivers.traction_block(data, rows, cols, out)
        best = min(best, (time.process_time() - c0, time.perf_counter() - t0))
    return out, best[0], best[1]


def issue32_mesh(n_side=8, levels=9, seed=0):
    """576 randomly oriented 0.5 m squares on a lattice of 3 m, centres at 3-27 m depth."""
    rng = np.random.default_rng(seed)
    xs = np.arange(n_side) * 3.0
    centers = np.array([[x, y, -3.0 - 3.0 * k] for k in range(levels) for x in xs for y in xs])
    frames = np.linalg.qr(rng.normal(size=(len(centers), 3, 3)))[0]
    half = np.full(len(centers), 0.25)
    return hd.Mesh3D.from_rectangles(centers, frames[:, :, 0], frames[:, :, 1], half, half)


def _timed(data, rows, cols):
    out = np.empty((3 * len(rows), 3 * len(cols)))
    drivers.traction_block(data, rows[:2], cols[:2], np.empty((6, 6)))
    t0, c0 = time.perf_counter(), time.process_time()
    drivers.traction_block(data, rows, cols, out)
    return out, time.process_time() - c0, time.perf_counter() - t0


def issue32(args):
    grid = issue32_mesh()
    every = np.arange(grid.n_elements, dtype=np.int64)
    g = 1.0
    media = {"uniform": hd.Elastic(g, 0.25),
             "half-space, images=1": lambda n: LayeredMedium([0.0], [0.0, g], [0.25, 0.25], images=1,
                                                             gauss_points=n),
             "surface + 2 interfaces, images=4": lambda n: LayeredMedium(
                 [0.0, -10.0, -20.0], [0.0, g, 2 * g, g], [0.25] * 4, images=4, gauss_points=n)}
    print(f"issue 32 mesh: {grid.n_elements} squares; 1 thread")
    print(machine())
    table = []
    base = None
    for name, medium in media.items():
        layered = callable(medium)
        for n_gauss in ((4, 6) if layered else (None,)):
            data = operators.influence_data(grid, medium(n_gauss) if layered else medium)
            rows = every if not name.startswith("surface") else every[::len(every) // args.rows3][:args.rows3]
            err_rows = every[::len(every) // args.error_rows][:args.error_rows]
            paths = [("default", data)]
            if layered:
                paths.append(("relative rule (issue 14)", data._replace(entry_tol=0.0)))
            reference = None
            if layered:
                reference, *_ = _timed(data._replace(gauss_points=8, far_tol=0.0, entry_tol=0.0), err_rows, every)
            for label, d in paths:
                _, cpu, wall = _timed(d, rows, every)
                per = cpu / (len(rows) * len(every)) * 1e6
                base = base or per
                error = "-"
                if reference is not None:
                    got, *_ = _timed(d, err_rows, every)
                    error = f"{np.abs(got - reference).max() / np.abs(reference).max():.1e}"
                table.append([name, n_gauss or "-", label, f"{len(rows)} x {len(every)}", f"{cpu:.3f}", f"{wall:.3f}",
                              f"{per:.2f}", f"{per / base:.0f}", error])
                print(table[-1], flush=True)
    print(markdown_table(["medium", "gauss_points", "path", "pairs", "CPU s", "wall s", "CPU us / pair",
                          "x uniform", "max error / max entry (vs 8 points)"], table))
    print(machine())


def whole(error_rows, repeats=5, media=None):
    """``{medium: (CPU s, wall s, CPU us / pair, error)}`` of the whole issue-32 matrix, each
    medium the best of ``repeats`` after a whole untimed one (the first one or two after
    another kernel's ran up to 1.5x slower; the three layers were timed once while a matrix
    took minutes, up to the thirteenth session); ``media``: the names of the media to run
    (None: all)."""
    grid = issue32_mesh()
    every = np.arange(grid.n_elements, dtype=np.int64)
    g = 1.0
    all_media = {"uniform": hd.Elastic(g, 0.25),
                 "half-space, images=1": LayeredMedium([0.0], [0.0, g], [0.25, 0.25], images=1),
                 "surface + 2 interfaces, images=4": LayeredMedium([0.0, -10.0, -20.0], [0.0, g, 2 * g, g],
                                                                   [0.25] * 4, images=4)}
    found = {}
    for name, medium in all_media.items():
        if media is not None and name.split(",")[0].split(" ")[0] not in media:
            continue
        data = operators.influence_data(grid, medium)  # the three layers' table is built here
        _timed(data, every, every)  # a whole warm-up: the first runs after another kernel's are slower
        runs = [_timed(data, every, every) for _ in range(repeats)]
        out, cpu, wall = min(runs, key=lambda run: run[1])
        error = "-"
        if name.startswith("surface"):
            rows = every[::len(every) // error_rows][:error_rows]
            reference, *_ = _timed(data._replace(gauss_points=8, far_tol=0.0, entry_tol=0.0), rows, every)
            error = f"{np.abs(out[_dof(rows)] - reference).max() / np.abs(reference).max():.1e}"
        found[name] = (cpu, wall, cpu / len(every) ** 2 * 1e6, error)
    return found


def _dof(rows):
    return (3 * rows[:, None] + np.arange(3)).ravel()


def print_whole(label, found):
    base = found["uniform"][2]
    print(markdown_table(["tree", "medium", "CPU s (576 x 576)", "wall s", "CPU us / pair", "x uniform",
                          "max error / max entry (vs 8 points)"],
                         [[label, name, f"{cpu:.2f}", f"{wall:.2f}", f"{per:.2f}", f"{per / base:.1f}", error]
                          for name, (cpu, wall, per, error) in found.items()]))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--whole", action="store_true")
    parser.add_argument("--compare", default=None, help="another source tree, run in a child process (--whole)")
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--issue32", action="store_true")
    parser.add_argument("--rows3", type=int, default=48)
    parser.add_argument("--error-rows", type=int, default=12)
    parser.add_argument("--repeats", type=int, default=5, help="--whole: best of this many (uniform, half-space)")
    parser.add_argument("--media", default=None,
                        help="--whole: media to run, comma-separated first words (uniform,half-space,surface)")
    args = parser.parse_args()
    media = None if args.media is None else args.media.split(",")
    if args.whole:
        if args.json:
            print(json.dumps(whole(args.error_rows, args.repeats, media)))
            return
        print(machine(), flush=True)
        found = whole(args.error_rows, args.repeats, media)
        print_whole("this", found)
        if args.compare:
            env = dict(os.environ, PYTHONPATH=os.path.abspath(args.compare))
            child = subprocess.run([sys.executable, os.path.abspath(__file__), "--whole", "--json",
                                    "--error-rows", str(args.error_rows), "--repeats", str(args.repeats)]
                                   + ([] if media is None else ["--media", args.media]), env=env, capture_output=True,
                                   text=True, check=True, cwd=os.path.abspath(args.compare))
            print_whole(args.compare, json.loads(child.stdout.strip().splitlines()[-1]))
        print(machine())
        return
    if args.issue32:
        issue32(args)
        return
    grid = mesh()
    rows = np.arange(0, grid.n_elements, 2, dtype=np.int64)
    cols = np.arange(1, grid.n_elements, 2, dtype=np.int64)
    print(f"mesh {grid.n_elements} rectangles; block {len(rows)} x {len(cols)} element pairs; 1 thread")
    print(machine())
    table = []
    base = None
    for name, material in CASES.items():
        if args.quick and name.startswith(("bi", "3")):
            continue
        data = operators.influence_data(grid, material)
        out, cpu, wall = block(data, rows, cols)
        per = cpu / (len(rows) * len(cols)) * 1e6
        base = base or per
        error = "-"
        if hasattr(data, "gauss_points"):
            fine = data._replace(gauss_points=8, far_tol=0.0)
            reference, *_ = block(fine, rows, cols, repeats=1)
            error = f"{np.abs(out - reference).max() / np.abs(reference).max():.1e}"
        table.append([name, f"{cpu:.3f}", f"{wall:.3f}", f"{per:.2f}", f"{per / base:.0f}", error])
        print(table[-1], flush=True)
    print(markdown_table(["medium", "CPU s", "wall s", "CPU us / pair", "x homogeneous",
                          "max error / max entry (vs 8 points)"], table))


if __name__ == "__main__":
    main()
