"""The tabulated layered remainder of the 3D image method (issue 32, item 2) against the
quadrature of every image triple (the cross-check, ``LayeredMedium(method="quadrature")``).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_table.py            # operator + scenes
    NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_table.py --skip-scenes

Operator: the mesh of issue 32 (576 randomly oriented 0.5 m squares on an 8 x 8 x 9 lattice
of 3 m, centres at 3-27 m depth), the whole dense traction matrix (576 x 576 pairs) after a
warm-up, one thread: uniform rock, a half-space (``images=1``: no far triple, so no table)
and a free surface with interfaces at z = -10, -20 m (G, 2G, G, ``images=4``) on both paths,
side by side in one process. Per path: CPU and wall time, CPU per pair and against uniform
rock, the table's build CPU and size, and the error of 6 rows (all 576 sources) against the
quadrature of every triple with 8 Gauss points per side on every (sub-)square.

Scenes: ``layered-3d`` (two interfaces: a table) and ``shallow-sill`` (a half-space: none)
end to end, each method in a fresh child process after a warm-up run of the same scene (so
the numba cache is warm and the table is built inside the timed run), CPU of the whole
``Simulation.run`` and the final maximum opening.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

from _common import machine, markdown_table  # noqa: E402
from bench_layered3d_kernel import _timed, issue32_mesh  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.elasticity import operator as operators  # noqa: E402
from hmatddm.layered import LayeredMedium  # noqa: E402
from hmatddm.layered import influence3d  # noqa: E402


def operator_table(error_rows=6):
    grid = issue32_mesh()
    every = np.arange(grid.n_elements, dtype=np.int64)
    err_rows = every[::len(every) // error_rows][:error_rows]
    g = 1.0
    three = dict(interfaces=[0.0, -10.0, -20.0], shear_modulus=[0.0, g, 2 * g, g], poisson_ratio=[0.25] * 4,
                 images=4)
    half = dict(interfaces=[0.0], shear_modulus=[0.0, g], poisson_ratio=[0.25, 0.25], images=1)
    cases = [("uniform", None, hd.Elastic(g, 0.25)),
             ("half-space, images=1", "table (no far triple: no table)", LayeredMedium(**half)),
             ("surface + 2 interfaces, images=4", "table", LayeredMedium(**three)),
             ("surface + 2 interfaces, images=4", "quadrature", LayeredMedium(**three, method="quadrature"))]
    rows, base = [], None
    for name, path, medium in cases:
        influence3d._TABLES.clear()
        c0 = time.process_time()
        data = operators.influence_data(grid, medium)
        setup = time.process_time() - c0
        _, cpu, wall = _timed(data, every, every)
        per = cpu / len(every) ** 2 * 1e6
        base = base or per
        error, table = "-", "-"
        if path is not None:
            reference_medium = LayeredMedium(**(half if name.startswith("half") else three), method="quadrature",
                                             gauss_points=8)
            reference = operators.influence_data(grid, reference_medium)._replace(far_tol=0.0, entry_tol=0.0)
            want, *_ = _timed(reference, err_rows, every)
            got, *_ = _timed(data, err_rows, every)
            error = f"{np.abs(got - want).max() / np.abs(want).max():.1e}"
            if data.table.values.size > 1:
                table = f"{setup:.1f} s, {data.table.values.nbytes / 1e6:.0f} MB"
        rows.append([name, path or "closed form", f"{cpu:.2f}", f"{wall:.2f}", f"{per:.2f}", f"{per / base:.0f}",
                     table, error])
        print(rows[-1], flush=True)
    return markdown_table(["medium", "path", "CPU s (576 x 576)", "wall s", "CPU us / pair", "x uniform",
                           "table build CPU, size", "max error / max entry (vs 8 points, every triple)"], rows)


_CHILD = """
import json, sys, time
import hmatddm.scene as hs
import hmatddm.layered as layered
name, method, out = sys.argv[1:4]
plain = layered.LayeredMedium  # the scene builds its medium through this name (hmatddm.scene.build)
layered.LayeredMedium = lambda *args, **options: plain(*args, method=method, **options)
scene = hs.scene_from_dict(hs.parse_scene(hs.embedded_text(name)).data, name)
simulation = hs.build_simulation(scene.data)
cpu, wall = time.process_time(), time.perf_counter()
records = simulation.run(scene.data["numerics"]["end_time"])
cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
json.dump(dict(cpu=cpu, wall=wall, elements=records[-1]["n_elements"], opening=records[-1]["max_opening"]),
          open(out, "w"))
"""


def scene_rows(names=("layered-3d", "shallow-sill")):
    import tempfile

    environment = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "run.json")
        for name in names:
            results = {}
            for method in ("table", "quadrature"):
                for _ in range(2):  # a warm-up (numba cache), then the timed run
                    subprocess.run([sys.executable, "-c", _CHILD, name, method, out], env=environment, check=True)
                results[method] = json.load(open(out))
            for method, r in results.items():
                rows.append([name, method, r["elements"], f"{r['cpu']:.1f}", f"{r['wall']:.1f}",
                             f"{results['quadrature']['cpu'] / r['cpu']:.2f}", f"{r['opening']:.9e}"])
                print(rows[-1], flush=True)
    return markdown_table(["scene", "method", "elements at the end", "CPU s (run)", "wall s",
                           "speed-up vs quadrature", "final max opening (m)"], rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-scenes", action="store_true")
    parser.add_argument("--skip-operator", action="store_true")
    args = parser.parse_args()
    print(machine(), flush=True)
    if not args.skip_operator:
        print(operator_table())
    if not args.skip_scenes:
        print(scene_rows())
    print(machine())


if __name__ == "__main__":
    main()
