"""Numbers of one source tree, to check that a restructuring changed none of them.

    PYTHONPATH=OLD_TREE python benchmarks/bit_identity.py snapshot old.npz --scenes old-runs
    PYTHONPATH=NEW_TREE python benchmarks/bit_identity.py snapshot new.npz --scenes new-runs
    python benchmarks/bit_identity.py compare old.npz new.npz old-runs new-runs

``snapshot`` saves, through the public API only (so any version of the package can
write one): dense operators of random 2D segments (constant, linear and quadratic
elements), of a three-layer 2D medium, of 3D rectangles in uniform rock and in a
two-layer medium; an H-matrix product, a solve and stresses at points on a penny crack;
an H-matrix product on a cloud of tilted rectangles. With ``--scenes DIR`` it also runs
every embedded scene for its first few steps (``hmatddm run NAME --set
numerics.end_time=T``) into ``DIR/NAME``. ``compare`` reports, per array, whether the two
snapshots are equal bit for bit, and per scene whether every value of the two
``summary.json`` (times, versions and paths aside) is.

Run each snapshot with an empty ``NUMBA_CACHE_DIR``: numba does not invalidate a cached
function when a function it calls changed in another file.
"""
import argparse
import importlib
import json
import pathlib
import re
import sys

import numpy as np

#: Embedded scenes and the end time (s) each runs to: a few steps, growth included.
SCENES = {"default": 5, "kgd": 10, "three-clusters": 5, "crossing": 10, "dfn-3cluster": 5, "layered-height": 5,
          "shallow-sill": 2, "layered-3d": 1, "radial-k": 5, "radial-m": 5}
#: summary.json keys that are not numbers of the method (timings, versions, paths).
NOT_COMPARED = re.compile(r"(seconds|versions|output)")


def _frames(rng, n):
    e1 = rng.normal(size=(n, 3))
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(e1, rng.normal(size=(n, 3)))
    e2 /= np.linalg.norm(e2, axis=1)[:, None]
    return e1, e2


def snapshot():
    """``{name: array}`` of the numbers listed in the module docstring."""
    import hmatddm as hd

    rng = np.random.default_rng(7)
    out = {}
    rock = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    grid = np.stack(np.meshgrid(np.arange(8.0), np.arange(5.0)), -1).reshape(-1, 2)
    p0 = grid + rng.uniform(-0.1, 0.1, grid.shape)
    angle = rng.uniform(0, np.pi, len(grid))
    p1 = p0 + rng.uniform(0.2, 0.6, len(grid))[:, None] * np.c_[np.cos(angle), np.sin(angle)]
    segments = hd.Mesh2D.from_segments(p0, p1)
    out["dense_2d"] = hd.ElasticityOperator(segments, rock).to_dense()
    for order in (1, 2):
        out[f"dense_2d_order{order}"] = hd.ElasticityOperator(segments.with_element_order(order), rock).to_dense()
    layers_2d = hd.LayeredMedium([0.0, -3.0], [10e9, 20e9, 5e9], [0.25, 0.3, 0.2])
    small = hd.Mesh2D.from_segments(p0[:16] * 0.3 + [0, -1.5], p0[:16] * 0.3 + [0, -1.5] + 0.1 * (p1[:16] - p0[:16]))
    out["dense_2d_layered"] = hd.ElasticityOperator(small, layers_2d).to_dense()
    centers = np.stack(np.meshgrid(np.arange(5.0), np.arange(4.0), np.arange(3.0)), -1).reshape(-1, 3) * 1.2
    centers[:, 2] -= 10
    e1, e2 = _frames(rng, len(centers))
    rectangles = hd.Mesh3D.from_rectangles(centers, e1, e2, np.full(len(centers), 0.25), np.full(len(centers), 0.3))
    out["dense_3d"] = hd.ElasticityOperator(rectangles, rock).to_dense()
    two_layers = hd.LayeredMedium([-7.0], [10e9, 20e9], [0.25, 0.3], images=1)
    out["dense_3d_layered"] = hd.ElasticityOperator(rectangles.subset(np.arange(12)), two_layers).to_dense()
    penny = hd.mesh.penny([0, 0, 0], [0, 0, 1], radius=1.0, h=0.05)
    operator = hd.ElasticityOperator(penny, rock, backend="hmatrix", eps=1e-4)
    out["hmatrix_product"] = operator @ rng.normal(size=operator.shape[1])
    dd = hd.solve(operator, -1e6 * penny.normals)
    out["hmatrix_solve"] = dd
    points = rng.uniform(-2, 2, (50, 3))
    points[:, 2] = np.abs(points[:, 2]) + 0.3
    out["stress_at"] = hd.stress_at(penny, rock, dd, points)
    cloud_centers = np.stack(np.meshgrid(*[np.arange(12.0)] * 2, np.arange(10.0)), -1).reshape(-1, 3)
    f1, f2 = _frames(rng, len(cloud_centers))
    cloud = hd.Mesh3D.from_rectangles(cloud_centers, f1, f2, np.full(len(f1), 0.3), np.full(len(f1), 0.3))
    cloud_operator = hd.ElasticityOperator(cloud, rock, backend="hmatrix", eps=1e-5)
    out["cloud_product"] = cloud_operator @ rng.normal(size=cloud_operator.shape[1])
    return out


def run_scenes(folder):
    """Run each of :data:`SCENES` into ``folder/NAME`` with the tree's own command line."""
    import hmatddm

    cli = None
    for name in ("hmatddm.app.cli", "hmatddm.cli"):  # after and before the rooms of issue 31
        try:
            cli = importlib.import_module(name)
            break
        except ImportError:
            continue
    folder = pathlib.Path(folder)
    for scene, end_time in SCENES.items():
        code = cli.main(["run", scene, "--out", str(folder / scene), "--quiet",
                         "--set", f"numerics.end_time={end_time}"])
        print(f"{scene}: exit {code} ({hmatddm.__file__})")


def _leaves(x, y, where, differences, counted):
    if isinstance(x, dict) and isinstance(y, dict):
        for key in sorted(set(x) | set(y)):
            if NOT_COMPARED.search(key):
                continue
            if key not in x or key not in y:
                differences.append(f"{where}.{key}: in one summary only")
            else:
                _leaves(x[key], y[key], f"{where}.{key}", differences, counted)
    elif isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        for i, (u, v) in enumerate(zip(x, y)):
            _leaves(u, v, f"{where}[{i}]", differences, counted)
    else:
        counted.append(1)
        if x != y and not (x != x and y != y):  # NaN equals NaN here
            differences.append(f"{where}: {x!r} != {y!r}")


def compare(old, new, old_runs=None, new_runs=None):
    """Print the comparison; returns the number of differing arrays and scenes."""
    a, b = np.load(old), np.load(new)
    failures = 0
    for name in a.files:
        same = name in b.files and a[name].shape == b[name].shape and np.array_equal(a[name], b[name], equal_nan=True)
        failures += not same
        print(f"{name:20s} {str(a[name].shape):12s} {'bit-identical' if same else 'DIFFERENT'}")
    if old_runs is not None:
        for scene in SCENES:
            summaries = [pathlib.Path(folder) / scene / "summary.json" for folder in (old_runs, new_runs)]
            x, y = (json.loads(path.read_text()) for path in summaries)
            differences, counted = [], []
            _leaves(x, y, scene, differences, counted)
            failures += bool(differences)
            print(f"{scene:20s} {len(x['steps'])} steps, {len(counted)} values, "
                  f"{'bit-identical' if not differences else f'{len(differences)} differ: ' + differences[0]}")
    return failures


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    save = sub.add_parser("snapshot")
    save.add_argument("out")
    save.add_argument("--scenes", metavar="DIR")
    check = sub.add_parser("compare")
    check.add_argument("old")
    check.add_argument("new")
    check.add_argument("runs", nargs="*", metavar="RUNS", help="the two --scenes folders")
    args = parser.parse_args(argv)
    if args.command == "snapshot":
        np.savez(args.out, **snapshot())
        if args.scenes:
            run_scenes(args.scenes)
        return 0
    return 1 if compare(args.old, args.new, *(args.runs or [None, None])) else 0


if __name__ == "__main__":
    sys.exit(main())
