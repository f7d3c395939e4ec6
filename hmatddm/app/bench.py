"""``hmatddm bench``: the H-matrix against the dense operator on a planar crack.

For square planar cracks of growing size, both backends are built and compared:
build time, memory, matvec time (median of a few products) and the relative error of
the H-matrix matvec against the dense one on a SMOOTH field, an elliptical opening
``w = sqrt(1 - (x/a)^2 - (y/b)^2)`` (docs/conventions.md §7: the hypersingular operator
cancels its near field on smooth inputs, so this is where far-field ACA error shows).
The full benchmarks (to N = 100k, eps sweeps) are in ``benchmarks/``.
"""
import time

import numpy as np

from .. import mesh as meshes
from ..material import Elastic
from ..elasticity.operator import DEFAULT_EPS, ElasticityOperator

QUICK_SIDES = (16, 32, 48)     # 256, 1024 and 2304 elements
FULL_SIDES = (32, 64, 80)      # 1024, 4096 and 6400 elements (dense 2.9 GB at 6400)
MATVEC_REPEATS = 5


def planar_crack(side):
    """A square crack of ``side`` x ``side`` unit elements in the x-y plane."""
    return meshes.rectangle([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], float(side), float(side),
                            side, side)


def smooth_field(mesh):
    """DD of an elliptical opening over the crack (flat, element-major)."""
    half = 0.5 * np.ptp(mesh.centers, axis=0)[:2] + np.max(mesh.radii)
    x, y = mesh.centers[:, 0] / half[0], mesh.centers[:, 1] / half[1]
    width = np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, None))
    return (width[:, None] * mesh.normals).ravel()


def _matvec_seconds(op, x):
    op.matvec(x)
    times = []
    for _ in range(MATVEC_REPEATS):
        start = time.perf_counter()
        op.matvec(x)
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def _row(side, backend, op, seconds, error):
    stats = op.stats
    return {"elements": int(side * side), "backend": backend, "build_seconds": float(stats["build_seconds"]),
            "memory_mb": stats["memory_bytes"] / 2**20, "compression": float(stats["compression"]),
            "matvec_ms": 1e3 * seconds, "relative_error": error,
            "eps": float(stats["eps"]) if backend == "hmatrix" else None,
            "max_rank": int(stats["max_rank"]) if backend == "hmatrix" else None}


def run_bench(quick=False, eps=DEFAULT_EPS, stream=None):
    """Rows (dicts) of the comparison, two per size (dense then hmatrix).

    ``relative_error`` is ``||H x - D x|| / ||D x||`` on the smooth field (None for
    the dense rows). ``stream``: where to print one progress line per operator.
    """
    from ..simulation.progress import TaskProgress

    material = Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    sides = QUICK_SIDES if quick else FULL_SIDES
    progress = TaskProgress(1 + 2 * len(sides), stream=stream, enabled=stream is not None)
    progress.start("compiling the numba kernels (cached after the first run)")
    warm = planar_crack(4)  # compile the numba kernels before timing anything
    for backend in ("dense", "hmatrix"):
        ElasticityOperator(warm, material, backend=backend, eps=eps).matvec(smooth_field(warm))
    progress.done()
    rows = []
    for side in sides:
        mesh = planar_crack(side)
        x = smooth_field(mesh)
        progress.start(f"{side * side} elements, dense")
        dense = ElasticityOperator(mesh, material, backend="dense")
        reference = dense.matvec(x)
        rows.append(_row(side, "dense", dense, _matvec_seconds(dense, x), None))
        del dense
        progress.done(f"build {rows[-1]['build_seconds']:.2f} s")
        progress.start(f"{side * side} elements, hmatrix (eps {eps:g})")
        hmatrix = ElasticityOperator(mesh, material, backend="hmatrix", eps=eps)
        error = float(np.linalg.norm(hmatrix.matvec(x) - reference) / np.linalg.norm(reference))
        rows.append(_row(side, "hmatrix", hmatrix, _matvec_seconds(hmatrix, x), error))
        progress.done(f"build {rows[-1]['build_seconds']:.2f} s, error {error:.1e}")
    progress.finish()
    return rows


def format_table(rows):
    header = (f"{'elements':>8}  {'backend':<8}  {'build (s)':>9}  {'memory (MB)':>11}  {'compression':>11}  "
              f"{'matvec (ms)':>11}  {'error (smooth)':>14}")
    lines = [header, "-" * len(header)]
    for r in rows:
        error = "-" if r["relative_error"] is None else f"{r['relative_error']:.2e}"
        lines.append(f"{r['elements']:>8}  {r['backend']:<8}  {r['build_seconds']:9.2f}  {r['memory_mb']:11.1f}  "
                     f"{r['compression']:11.1f}  {r['matvec_ms']:11.2f}  {error:>14}")
    lines.append("error: ||H x - D x|| / ||D x|| for an elliptical opening x; planar square crack, "
                 "G = 10 GPa, nu = 0.25")
    return "\n".join(lines)
