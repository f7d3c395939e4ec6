"""Issue 32: the half-space in closed form (Okada 1992: the finite rectangle of
:mod:`hmatddm.layered.okada3d`, the point source of :mod:`hmatddm.layered.okada_point3d`)
against uniform rock and the image quadrature they replace.

1. Per pair: the influence entries (``traction_block``) of the issue's lattice (576 0.5 m
   squares on an 8 x 8 x 9 lattice of 3 m, centres at 3-27 m depth) under uniform rock, in
   the half-space by default (a square with a horizontal side: the finite rectangle; one
   without: the point source at the quadrature's points) and by the image quadrature
   (``method="quadrature"``, the old path), CPU per pair and the error of each against the
   converged quadrature (12 points per side on up to 64 x 64 sub-squares, ``far_tol =
   entry_tol = 0``). The issue's squares are randomly oriented, so none has a horizontal
   side; the lattice is taken three times: with the issue's orientations, with random
   strike and dip (every square has a horizontal side), and with the issue's orientations
   raised so that the top squares' centres are 0.45 m under the free surface.
2. H-matrix build (eps 1e-4): uniform rock against the half-space (closed form) on a
   vertical square crack of 0.5 m squares (a horizontal side on every element) whose top is
   1 m under the free surface, at a few sizes; CPU and wall time, memory (drivers compiled
   before the timing).

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_halfspace_okada.py [--sizes 2500,10000,40000]``."""
import argparse
import time

import numpy as np

import hmatddm as hd
from hmatddm.elasticity import operator as operators
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium

try:
    from _common import machine, markdown_table
    from bench_layered3d_kernel import block, issue32_mesh
except ImportError:  # run from the repository root
    from benchmarks._common import machine, markdown_table
    from benchmarks.bench_layered3d_kernel import block, issue32_mesh

G, NU = 1.0, 0.25


def half_space(**options):
    return LayeredMedium([0.0], [0.0, G], [NU, NU], images=1, **options)


def strike_dip_mesh(seed=0):
    """The lattice of :func:`issue32_mesh` with random strike and dip (a horizontal side)."""
    grid = issue32_mesh(seed=seed)
    rng = np.random.default_rng(seed)
    n = grid.n_elements
    strike = rng.uniform(0.0, 2.0 * np.pi, n)
    dip = rng.uniform(0.0, np.pi, n)
    e1 = np.stack([np.cos(strike), np.sin(strike), np.zeros(n)], axis=1)
    up = np.cos(dip)[:, None] * np.stack([-e1[:, 1], e1[:, 0], np.zeros(n)], axis=1)
    up[:, 2] = np.sin(dip)
    return hd.Mesh3D.from_rectangles(grid.centers, e1, up, grid.half_a, grid.half_b)


def shallow_mesh():
    """The issue's lattice raised: its top squares' centres 0.45 m under the free surface."""
    grid = issue32_mesh()
    return hd.Mesh3D.from_rectangles(grid.centers + np.array([0.0, 0.0, 2.55]), grid.frames[:, 0], grid.frames[:, 1],
                                     grid.half_a, grid.half_b)


def per_pair(args):
    table = []
    for mesh_name, grid in (("strike and dip", strike_dip_mesh()), ("issue 32 (random frames)", issue32_mesh()),
                            ("issue 32, top 0.45 m under the surface", shallow_mesh())):
        every = np.arange(grid.n_elements, dtype=np.int64)
        some = every[::len(every) // args.rows][:args.rows]
        err_rows = every[::len(every) // args.error_rows][:args.error_rows]
        reference = block(operators.influence_data(grid, half_space(method="quadrature"))._replace(
            gauss_points=12, max_subdivisions=64, far_tol=0.0, entry_tol=0.0), err_rows, every, repeats=1)[0]
        base = None
        for name, medium, rows in (("uniform rock", hd.Elastic(G, NU), every),
                                   ("half-space, Okada's forms (default)", half_space(), every),
                                   ("half-space, image quadrature (old path)", half_space(method="quadrature"), some)):
            data = operators.influence_data(grid, medium)
            forms = (f"{int(data.closed_form.sum())} / {int(data.point_form.sum())}"
                     if hasattr(data, "closed_form") else "-")
            _, cpu, wall = block(data, rows, every, repeats=3)
            per = cpu / (len(rows) * len(every)) * 1e6
            base = base or per
            error = "-"
            if isinstance(medium, LayeredMedium):
                got = block(data, err_rows, every, repeats=1)[0]
                error = f"{np.abs(got - reference).max() / np.abs(reference).max():.1e}"
            table.append([mesh_name, name, forms, f"{len(rows)} x {len(every)}", f"{cpu:.3f}", f"{wall:.3f}",
                          f"{per:.2f}", f"{per / base:.1f}", error])
            print(table[-1], flush=True)
    print(markdown_table(["mesh", "medium", "finite / point-source forms", "pairs", "CPU s", "wall s",
                          "CPU us / pair", "x uniform", "max error / max entry (vs converged quadrature)"], table))


def crack(n, depth_top=1.0):
    side = int(round(np.sqrt(n)))
    size = float(side) * 0.5
    return hd.mesh.rectangle([0.0, 0.0, -depth_top - 0.5 * size], [1, 0, 0], [0, 0, 1], size, size, side, side)


def builds(args):
    table = []
    for medium in (hd.Elastic(G, NU), half_space()):  # compile (or load) the drivers outside the timing
        hd.ElasticityOperator(crack(400), medium, backend="hmatrix", eps=1e-4)
    for n in args.sizes:
        grid = crack(n)
        row = {}
        for name, medium in (("uniform rock", hd.Elastic(G, NU)), ("half-space, closed form", half_space())):
            t0, c0 = time.perf_counter(), time.process_time()
            op = hd.ElasticityOperator(grid, medium, backend="hmatrix", eps=1e-4)
            cpu, wall = time.process_time() - c0, time.perf_counter() - t0
            row[name] = cpu
            table.append([grid.n_elements, name, f"{cpu:.1f}", f"{wall:.1f}", f"{op.stats['memory_bytes'] / 2**20:.0f}",
                          f"{op.stats['compression']:.3f}", op.stats["max_rank"],
                          f"{cpu / row['uniform rock']:.2f}"])
            print(table[-1], flush=True)
            del op
    print(markdown_table(["N", "medium", "build CPU s", "build wall s", "memory MiB", "compression", "max rank",
                          "x uniform (CPU)"], table))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--rows", type=int, default=48, help="receiver rows of the old (quadrature) path")
    parser.add_argument("--error-rows", type=int, default=12)
    parser.add_argument("--sizes", type=lambda s: [int(v) for v in s.split(",")], default=[2500, 10000])
    parser.add_argument("--skip-pairs", action="store_true")
    parser.add_argument("--skip-builds", action="store_true")
    args = parser.parse_args()
    print(machine())
    if not args.skip_pairs:
        per_pair(args)
    if not args.skip_builds:
        builds(args)
    print(machine())


if __name__ == "__main__":
    main()
