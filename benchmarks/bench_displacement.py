"""Displacements at points (``hd.displacement_at``, ref. Eqs 2.43, 2.55-2.57): the exact
sum against the compressed build-free product.

    python benchmarks/bench_displacement.py            # uniform rock: direct against tree
    python benchmarks/bench_displacement.py --layered  # layered rock against uniform, error vs Okada

A horizontal 3D fracture (square, ``n x n`` elements of 1 m, 100 m deep, opening
``1 mm (1 - r^2/R^2)`` and a tenth of it in shear) seen from a square grid of ``m`` points
4 km wide on the plane z = 0 (an infinite medium: the free surface is not modelled).
Prints, per size, the CPU and wall time of ``method="direct"`` and ``"tree"`` (eps 1e-5 and
1e-7), the tree's largest error relative to the largest displacement, and the share of
point-element pairs in compressed blocks.

``--layered`` (:mod:`hmatddm.layered.displacement`, issue 36): a square sill 2 km wide,
1 km deep, meshed in ``n x n`` elements with a uniform opening of 1 mm (and, second
case, a 40-degree dipping fault 2 km x 1 km, 1.2 km deep at its lower edge, with
1 mm of strike and dip slip and 0.5 mm of opening), seen from 400 surface points
(a 20 x 20 grid 8 km wide). Prints the CPU and wall time per point-element pair of the
uniform rock's exact sum and of the layered one (a free surface; and the free surface
over two interfaces, 2G and 0.5G below 500 m and 1500 m, the sill in the third layer,
8 images),
and the largest error of the half-space against Okada's (1985) closed form for the whole
rectangle (``tests/okada_reference.py``: the sum of the elements' uniform DDs is the
rectangle's), relative to the largest displacement; beside it what uniform rock (no
free surface) misses. Then the same sill in 2D plane strain (a segment, ``n`` elements),
against the half-plane's closed form (``okada_reference.plane_strain_surface_displacement``).
"""
import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402

import hmatddm as hd  # noqa: E402


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    value = function()
    return value, time.process_time() - cpu, time.perf_counter() - wall


def layered():
    sys.path.insert(0, os.path.join(HERE, "..", "tests"))
    import okada_reference as okada

    print(f"Machine: {machine()}")
    g, nu = 10e9, 0.25
    uniform = hd.Elastic(g, nu)
    half_space = hd.LayeredMedium([0.0], [0.0, g], [nu, nu])
    three = hd.LayeredMedium([0.0, -500.0, -1500.0], [0.0, g, 2 * g, 0.5 * g], [nu, nu, 0.3, 0.2], images=8)
    side = 20
    x = np.linspace(-4000.0, 4000.0, side) + 1.0  # off the element edges' verticals
    points = np.column_stack([np.repeat(x, side), np.tile(x, side), np.zeros(side * side)])
    cases = (("sill", 0.0, 1000.0, 2000.0, 2000.0, (0.0, 0.0, 1e-3)),
             ("dipping fault", 40.0, 1200.0, 2000.0, 1000.0, (1e-3, 1e-3, 0.5e-3)))
    rows = []
    for name, dip_deg, depth, length, width, burgers in cases:
        dip = np.radians(dip_deg)
        center, frame, a, b = okada.rectangle(depth, dip, length, width)
        ref = np.array([okada.surface_displacement(px, py, depth, dip, length, width, *burgers, nu)
                        for px, py, _ in points])
        scale = np.max(np.abs(ref))
        for n in (4, 8, 16):
            mesh = hd.mesh.rectangle(center, frame[0], frame[1], 2 * a, 2 * b, n, max(int(n * width // length), 1))
            dd = np.tile(np.asarray(burgers) @ frame, (mesh.n_elements, 1))
            pairs = len(points) * mesh.n_elements
            hd.displacement_at(mesh, half_space, dd, points[:2])  # compile
            u_uniform, cpu_u, wall_u = timed(lambda: hd.displacement_at(mesh, uniform, dd, points, method="direct"))
            u_half, cpu_h, wall_h = timed(lambda: hd.displacement_at(mesh, half_space, dd, points))
            row = [name, mesh.n_elements, len(points), f"{1e6 * cpu_u / pairs:.3f} / {1e6 * wall_u / pairs:.3f}",
                   f"{1e6 * cpu_h / pairs:.2f} / {1e6 * wall_h / pairs:.2f}", f"{cpu_h / max(cpu_u, 1e-9):.0f}x"]
            if dip_deg == 0.0 and n <= 8:
                _, cpu_3, wall_3 = timed(lambda: hd.displacement_at(mesh, three, dd, points))
                row += [f"{1e6 * cpu_3 / pairs:.1f} / {1e6 * wall_3 / pairs:.1f}", f"{cpu_3 / max(cpu_u, 1e-9):.0f}x"]
            else:
                row += ["", ""]
            row += [f"{np.max(np.abs(u_half - ref)) / scale:.1e}", f"{np.max(np.abs(u_uniform - ref)) / scale:.2f}"]
            rows.append(row)
            print(" | ".join(str(c) for c in row), flush=True)
    print_table(["case", "elements", "points", "uniform CPU / wall per pair (us)",
                 "half-space CPU / wall per pair (us)",
                 "half-space / uniform CPU", "surface + 2 interfaces CPU / wall per pair (us)",
                 "3 layers / uniform CPU", "half-space max error vs Okada / max |u|",
                 "uniform rock vs Okada / max |u|"], rows)
    # 2D plane strain: the same sill as a segment, against the closed form of the half-plane
    plane = hd.LayeredMedium([0.0], [0.0, g], [nu, nu])
    three_2d = hd.LayeredMedium([0.0, -500.0, -1500.0], [0.0, g, 2 * g, 0.5 * g], [nu, nu, 0.3, 0.2], images=8)
    points2 = np.column_stack([np.linspace(-4000.0, 4000.0, 400) + 1.0, np.zeros(400)])
    ref = np.array([okada.plane_strain_surface_displacement(px, 1000.0, -1000.0, 1000.0, 0.0, 1e-3)
                    for px, _ in points2])
    rows = []
    for n in (8, 32, 128):
        mesh = hd.mesh.line([-1000.0, -1000.0], [1000.0, -1000.0], n)
        dd = np.tile([0.0, 1e-3], (n, 1))
        pairs = len(points2) * n
        hd.displacement_at(mesh, plane, dd, points2[:2])
        u_uniform, cpu_u, wall_u = timed(lambda: hd.displacement_at(mesh, uniform, dd, points2, method="direct"))
        u_half, cpu_h, wall_h = timed(lambda: hd.displacement_at(mesh, plane, dd, points2))
        _, cpu_3, wall_3 = timed(lambda: hd.displacement_at(mesh, three_2d, dd, points2))
        scale = np.max(np.abs(ref))
        rows.append(["2D sill", n, len(points2), f"{1e6 * cpu_u / pairs:.3f} / {1e6 * wall_u / pairs:.3f}",
                     f"{1e6 * cpu_h / pairs:.2f} / {1e6 * wall_h / pairs:.2f}", f"{cpu_h / max(cpu_u, 1e-9):.0f}x",
                     f"{1e6 * cpu_3 / pairs:.1f} / {1e6 * wall_3 / pairs:.1f}", f"{cpu_3 / max(cpu_u, 1e-9):.0f}x",
                     f"{np.max(np.abs(u_half - ref)) / scale:.1e}", f"{np.max(np.abs(u_uniform - ref)) / scale:.2f}"])
        print(" | ".join(str(c) for c in rows[-1]), flush=True)
    print_table(["case", "elements", "points", "uniform CPU / wall per pair (us)",
                 "half-plane CPU / wall per pair (us)",
                 "half-plane / uniform CPU", "surface + 2 interfaces CPU / wall per pair (us)",
                 "3 layers / uniform CPU", "half-plane max error vs closed form / max |u|",
                 "uniform rock vs closed form / max |u|"], rows)


def main():
    if "--layered" in sys.argv[1:]:
        layered()
        return
    print(f"Machine: {machine()}")
    material = hd.Elastic(10e9, 0.25)
    rows = []
    for n, m in ((20, 2500), (40, 10000), (60, 40000)):
        mesh = hd.mesh.rectangle([0.0, 0.0, -100.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], float(n), float(n), n, n)
        r2 = np.sum(mesh.centers[:, :2] ** 2, axis=1) / (0.5 * n) ** 2
        dd = np.zeros((mesh.n_elements, 3))
        dd[:, 2] = 1e-3 * np.maximum(1.0 - r2, 0.0)
        dd[:, 0] = 1e-4 * np.maximum(1.0 - r2, 0.0)
        side = int(round(np.sqrt(m)))
        x = np.linspace(-2000.0, 2000.0, side)
        points = np.column_stack([np.repeat(x, side), np.tile(x, side), np.zeros(side * side)])
        hd.displacement_at(mesh, material, dd, points[:10], method="direct")  # compile
        exact, cpu_d, wall_d = timed(lambda: hd.displacement_at(mesh, material, dd, points, method="direct"))
        scale = np.max(np.abs(exact))
        for eps in (1e-5, 1e-7):
            info = {}
            tree, cpu_t, wall_t = timed(lambda: hd.displacement_at(mesh, material, dd, points, method="tree",
                                                                   eps=eps, info=info))
            rows.append([mesh.n_elements, len(points), f"{eps:g}", f"{cpu_d:.2f} / {wall_d:.2f}",
                         f"{cpu_t:.2f} / {wall_t:.2f}", f"{np.max(np.abs(tree - exact)) / scale:.1e}",
                         f"{info.get('pairs_compressed', 0) / (len(points) * mesh.n_elements):.2f}"])
            print(" | ".join(str(c) for c in rows[-1]), flush=True)
    print_table(["elements", "points", "eps", "direct CPU / wall (s)", "tree CPU / wall (s)", "tree max error / max |u|",
                 "pairs compressed"], rows)


if __name__ == "__main__":
    main()
