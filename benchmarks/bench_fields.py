"""Stress at many points from many elements (hmatddm.elasticity.fields behind hd.stress_at): time and
error of the exact sum and of the points x elements H-matrix, before and after field
evaluation moved onto the generic H-matrix engine.

    python benchmarks/bench_fields.py                      # the new code only
    python benchmarks/bench_fields.py --before /tmp/old    # + the code at /tmp/old (a tree
                                                           #   of the repository, e.g.
                                                           #   `git archive <commit> | tar -x -C /tmp/old`)

Scenes (remote failure of ref. Sec. 5.3 is the use): the intact natural-fracture elements of
the ``bench_dfn.py`` network (full-height 10 m rectangles, ~35,500 centres) as targets, and
three vertical hydraulic fractures at x = -10, 0, 10 m as sources (1 m elements, 10 rows),
``length`` long (18 m: ~540 elements, the size of the default ``bench_dfn.py`` run at its
end; 80 m: 2,400), with an elliptical opening plus some slip; and a 2D plan view (three
segments crossing a grid of 40,000 points). Targets are evaluated as the remote-failure
check does (``singular_correction="average"``, ``near_fraction=0.5``).

Columns: wall and CPU time (all threads) of one evaluation, and the largest error of any
component relative to the largest induced component, against the exact direct sum of the
new code. The "before" rows run in a subprocess on the old tree, on the same scenes.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

NEAR_FRACTION = 0.5  # hmatddm.elasticity.operator.NEAR_SINGULAR_FRACTION, what remote failure uses


def scenes(quick=False):
    """name -> (mesh, dd, points); built with functions present before and after."""
    import hmatddm as hd
    from hmatddm.network import NetworkSpec, generate_network

    out = {}
    spec = NetworkSpec(region=(-50.0, 50.0, -100.0, 100.0), density=0.05, length_exponent=2.0, l_min=1.0,
                       l_max=30.0, mean_azimuths_deg=(45.0,), kappas=(5.0,), height=10.0, z_center=0.0, seed=1)
    targets = generate_network(spec).to_mesh3d(1.0, 10).centers
    if quick:
        targets = targets[::8]
    for length in ((18,) if quick else (18, 80)):
        parts = [hd.mesh.rectangle([x, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], float(length), 10.0, length,
                                   10, fracture_id=k) for k, x in enumerate((-10.0, 0.0, 10.0))]
        mesh = hd.mesh.concatenate(parts)
        y, z = mesh.centers[:, 1], mesh.centers[:, 2]
        opening = 1e-3 * np.sqrt(np.clip(1 - (y / (length / 2)) ** 2, 0.01, 1)) * np.sqrt(
            np.clip(1 - (z / 5.0) ** 2, 0.01, 1))
        dd = opening[:, None] * mesh.normals + 0.2 * opening[:, None] * np.array([0.0, 1.0, 0.3])
        out[f"3D DFN, {mesh.n_elements} elements"] = (mesh, dd, np.ascontiguousarray(targets))
    segments = [hd.mesh.line([x, -40.0], [x + 8.0, 40.0], 400) for x in (-30.0, 0.0, 30.0)]
    mesh2 = hd.mesh.concatenate(segments)
    x, y = np.meshgrid(np.linspace(-100.0, 100.0, 100 if quick else 200), np.linspace(-100.0, 100.0, 200) + 0.01)
    dd2 = 1e-3 * mesh2.normals * np.sqrt(np.clip(1 - (mesh2.centers[:, 1] / 40.0) ** 2, 0.01, 1))[:, None]
    out[f"2D plan view, {mesh2.n_elements} elements"] = (mesh2, dd2, np.column_stack([x.ravel(), y.ravel()]))
    return out


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    value = function()
    return value, time.perf_counter() - wall, time.process_time() - cpu


def evaluate(scene_list):
    """Rows of (scene, method, values, wall, cpu, extra) for the code importable now."""
    import hmatddm as hd

    material = hd.Elastic(6.62e9, 0.25)
    rows = []
    for name, (mesh, dd, points) in scene_list.items():
        kwargs = dict(singular_correction="average", near_fraction=NEAR_FRACTION)
        small = points[:200]  # compile outside the timings
        hd.stress_at(mesh, material, dd, small, method="direct", **kwargs)
        hd.stress_at(mesh, material, dd, small[:100], method="tree", **kwargs)
        for method in ("direct", "tree"):
            info = {}
            values, wall, cpu = timed(lambda: hd.stress_at(mesh, material, dd, points, method=method, info=info,
                                                           **kwargs))
            print(f"#   {name}: {method} {wall:.2f} s", flush=True)
            rows.append((name, method, values, wall, cpu, {k: v for k, v in info.items()
                                                            if isinstance(v, (int, float, str))}))
    return rows


def worker(path, quick):
    """Evaluate with the code found first on sys.path; save to ``path`` (npz + json)."""
    rows = evaluate(scenes(quick))
    arrays = {f"v{k}": row[2] for k, row in enumerate(rows)}
    np.savez(path, **arrays)
    with open(path + ".json", "w") as f:
        json.dump([[r[0], r[1], r[3], r[4], r[5]] for r in rows], f)


def run_before(before, quick):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "before.npz")
        env = dict(os.environ, PYTHONPATH=os.path.abspath(before))
        code = (f"import sys; sys.path.insert(0, {os.path.abspath(before)!r}); sys.path.insert(1, {HERE!r}); "
                f"import bench_fields; bench_fields.worker({path!r}, {quick!r})")
        subprocess.run([sys.executable, "-c", code], check=True, env=env, cwd=tmp)
        values = np.load(path)
        with open(path + ".json") as f:
            meta = json.load(f)
    return [(m[0], m[1], values[f"v{k}"], m[2], m[3], m[4]) for k, m in enumerate(meta)]


def main(argv=None):
    from _common import machine, markdown_table

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--before", help="a tree of the code before the change, run in a subprocess")
    parser.add_argument("--quick", action="store_true", help="an eighth of the 3D targets, one 3D scene")
    args = parser.parse_args(argv)
    import numba

    print(f"# machine: {machine()}; numba threads {numba.get_num_threads()}; load {os.getloadavg()[0]:.1f}",
          flush=True)
    before = run_before(args.before, args.quick) if args.before else []
    after = evaluate(scenes(args.quick))
    exact = {r[0]: r[2] for r in after if r[1] == "direct"}
    table = []
    for label, rows in (("before", before), ("after", after)):
        for name, method, values, wall, cpu, extra in rows:
            reference = exact[name]
            error = float(np.max(np.abs(values - reference)) / np.max(np.abs(reference)))
            detail = ""
            if extra.get("method") == "tree":
                detail = f"max rank {extra.get('max_rank', '?')}"
            table.append([name, label, method, reference.shape[0], f"{wall:.3f}", f"{cpu:.3f}", f"{error:.1e}",
                          detail])
    print(markdown_table(["scene", "code", "method", "points", "wall s", "CPU s", "max error / max stress",
                          "notes"], table))


if __name__ == "__main__":
    main()
