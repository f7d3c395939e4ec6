"""Cost and accuracy of one influence entry (a 3 x 3 element pair) of the 3D layered
kernel (issue 14): a 108 x 108 element block of a 216-rectangle mesh (a horizontal sill
1 m below the free surface and a vertical fracture beside it), one thread, for a
half-space, a bi-material and three layers, next to the homogeneous kernel. The error of
each block is measured against the same block with 8 Gauss points per side on every
(sub-)square (``far_tol = 0``; ``--quick``: the half-space only).

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_kernel.py``."""
import argparse
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
    """(block, best CPU s, its wall s) of ``traction_block`` (compiled first)."""
    out = np.empty((3 * len(rows), 3 * len(cols)))
    drivers.traction_block(data, rows[:2], cols[:2], out[:6, :6])
    best = (np.inf, np.inf)
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        drivers.traction_block(data, rows, cols, out)
        best = min(best, (time.process_time() - c0, time.perf_counter() - t0))
    return out, best[0], best[1]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
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
