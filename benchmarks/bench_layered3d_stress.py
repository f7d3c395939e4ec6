"""The stress at points of vertical fractures in layered rock (issue 32, the stress at
points, ``hd.stress_at``): per point-source pair CPU of the direct sum with the vertical
rectangles' image triples in closed form (:mod:`hmatddm.layered.vertical3d`, the default)
against the quadrature of every triple (the path before), beside uniform rock.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_stress.py

Medium: a free surface over interfaces at z = -10, -20 m (G, 2G, G, ``images=4``), as the
issue's benchmarks. Meshes: a vertical fracture of 0.5 m squares across the whole stack (z
from -22 to -8 m, 8 m long: edges on both interfaces) and one whose top edge is 0.25 m under
the free surface. Points: where a natural fracture's centre would be (0.3 to 4 m from the
fracture's plane, along and above and below it), a fifth of them 0.02-0.1 m from an interface
or the free surface. One thread, after a warm-up, CPU beside wall; the error of a subset of
points against the quadrature with 8 points per side on every (sub-)square and no lowered
far order (``method="quadrature"``, ``far_tol=0``), relative to the largest stress there.
"""
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, markdown_table  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.elasticity import operator as operators  # noqa: E402
from hmatddm.kernels import drivers  # noqa: E402
from hmatddm.layered import LayeredMedium  # noqa: E402
from hmatddm.layered import stress3d  # noqa: E402
from hmatddm.layered.influence3d import influence_data  # noqa: E402
from hmatddm.mesh import rectangle  # noqa: E402

G, NU = 1.0, 0.25
THREE = dict(interfaces=[0.0, -10.0, -20.0], shear_modulus=[0.0, G, 2 * G, G], poisson_ratio=[NU] * 4, images=4)


def meshes():
    across = rectangle([0.0, 0.0, -15.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 8.0, 14.0, 16, 28)
    shallow = rectangle([0.0, 0.0, -2.25], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 8.0, 4.0, 16, 8)
    return (("vertical fracture across both interfaces (448)", across, (-22.0, -8.0)),
            ("vertical fracture 0.25 m under the surface (128)", shallow, (-4.25, -0.25)))


def points_near(z_range, count, seed=0):
    rng = np.random.default_rng(seed)
    lo, hi = z_range
    x = rng.uniform(-6.0, 6.0, count)
    y = rng.choice([-1.0, 1.0], count) * rng.uniform(0.3, 4.0, count)
    z = rng.uniform(lo - 2.0, min(hi + 2.0, -0.05), count)
    near = np.arange(count) % 5 == 0
    planes = np.array([0.0, -10.0, -20.0])
    plane = planes[rng.integers(0, 3, count)]
    side = np.where(plane == 0.0, -1.0, rng.choice([-1.0, 1.0], count))
    z[near] = (plane + side * rng.uniform(0.02, 0.1, count))[near]
    return np.column_stack([x, y, z])


def stress_data(mesh, medium, vertical=True, surface=True):
    data = influence_data(mesh, medium, 0.0, 0.0, 0.0, medium.images, with_table=False)
    none = np.zeros(mesh.n_elements, dtype=bool)
    if not vertical:
        data = data._replace(vertical_form=none)
    if not surface:
        data = data._replace(surface_form=none)
    return data


def timed(data, points, layers, dd, by_source=True):
    total = stress3d.stress_sum if by_source else drivers.stress_sum
    total(data, points[:1], dd, layers[:1])
    c0, t0 = time.process_time(), time.perf_counter()
    out = total(data, points, dd, layers)
    return out, time.process_time() - c0, time.perf_counter() - t0


def main():
    count = int(sys.argv[sys.argv.index("--points") + 1]) if "--points" in sys.argv else 60
    check = int(sys.argv[sys.argv.index("--check") + 1]) if "--check" in sys.argv else 10
    print(machine(), flush=True)
    medium = LayeredMedium(**THREE)
    reference_medium = LayeredMedium(**{**THREE, "gauss_points": 8}, method="quadrature")
    rows = []
    for name, mesh, z_range in meshes():
        points = points_near(z_range, count)
        layers = medium.layer_of(points[:, 2]).astype(np.int64)
        dd = np.random.default_rng(1).normal(size=(mesh.n_elements, 3))
        uniform = operators.influence_data(mesh, hd.Elastic(G, NU))
        _, cpu, wall = timed(uniform, points, np.zeros(count, dtype=np.int64), dd, by_source=False)
        base = cpu / (count * mesh.n_elements) * 1e6
        rows.append([name, "uniform rock", "-", f"{cpu:.2f}", f"{wall:.2f}", f"{base:.2f}", "1", "-"])
        print(rows[-1], flush=True)
        sub = slice(0, check)
        reference = stress_data(mesh, reference_medium)._replace(far_tol=0.0)
        want, *_ = timed(reference, points[sub], layers[sub], dd)
        for path, vertical, by_source in (
                ("sources outside, vertical triples in closed form (default)", True, True),
                ("sources outside, quadrature of every triple", False, True),
                ("points outside, quadrature of every triple, no surface form (before)", False, False)):
            data = stress_data(mesh, medium, vertical, surface=by_source)
            got, cpu, wall = timed(data, points, layers, dd, by_source)
            per = cpu / (count * mesh.n_elements) * 1e6
            error = np.abs(got[sub] - want).max() / np.abs(want).max()
            rows.append([name, "surface + 2 interfaces, images=4", path, f"{cpu:.2f}", f"{wall:.2f}", f"{per:.2f}",
                         f"{per / base:.0f}", f"{error:.1e}"])
            print(rows[-1], flush=True)
    print(markdown_table(["mesh", "medium", "path", "CPU s", "wall s", "CPU us / point-source pair", "x uniform",
                          f"max error / max stress ({check} points, vs 8-point quadrature)"], rows))
    print(machine())


if __name__ == "__main__":
    main()
