"""Layered rock (ref. Ch. 3): cost and accuracy of the image-method operator, and the
layered-height scene's height against time.

1. Operator cost: a vertical crack through three layers plus a horizontal one, dense
   layered build against the homogeneous one (time per entry, wall and CPU), images
   chosen ("auto"), and the H-matrix compression and its error against the dense matrix.
2. Error against images and Gauss points: the horizontal and vertical cracks of ref.
   Figs 3.10-3.17 (crack length = middle-layer height h, gamma = G_outer/G_middle = 2
   and 5, nu = 0.2, 40 constant elements): crack volume against a converged reference
   (16 images, 8 Gauss points with adaptive sub-segments).
3. The layered-height scene (hmatddm/scene/scenes/layered-height.toml) with bounding
   layers gamma = 0.5, 1, 2, 5 times as stiff (no stress contrast), and gamma = 1 with
   the scene's +0.5 MPa stress contrast and with +1.5 MPa: fracture height against time,
   one plot (benchmarks/layered_height.png).

    python benchmarks/bench_layered.py [--quick]
"""
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hmatddm as hd  # noqa: E402
import hmatddm.scene as hs  # noqa: E402
from hmatddm.layered import LayeredMedium, split_at_interfaces  # noqa: E402

from _common import machine, markdown_table  # noqa: E402


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    result = function()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def operator_cost(sizes):
    rows = []
    g, nu = 10e9, 0.25
    medium = LayeredMedium([2.0, -2.0], [2 * g, g, 2 * g], [nu, nu, nu])
    homogeneous = hd.Elastic(g, nu)
    warm = split_at_interfaces(hd.mesh.line([0.0, -3.0], [0.0, 3.0], 8), medium)[0]  # numba compiles here
    for backend in ("dense", "hmatrix"):
        hd.ElasticityOperator(warm, medium, backend=backend)
        hd.ElasticityOperator(warm, homogeneous, backend=backend)
    for n in sizes:
        mesh = hd.mesh.concatenate([hd.mesh.line([0.0, -5.0], [0.0, 5.0], n // 2, fracture_id=0),
                                    hd.mesh.line([-5.5, 0.5], [4.5, 0.5], n - n // 2, fracture_id=1)])
        mesh = split_at_interfaces(mesh, medium)[0]
        entries = (2 * mesh.n_elements) ** 2
        _, wall_h, cpu_h = timed(lambda: hd.ElasticityOperator(mesh, homogeneous, backend="dense"))
        lay, wall_l, cpu_l = timed(lambda: hd.ElasticityOperator(mesh, medium, backend="dense"))
        hmat, wall_m, cpu_m = timed(lambda: hd.ElasticityOperator(mesh, medium, backend="hmatrix", eps=1e-4))
        dense = lay.to_dense()
        error = np.linalg.norm(hmat.to_dense() - dense) / np.linalg.norm(dense)
        rows.append([mesh.n_elements, f"{1e6 * wall_h / entries:.2f} / {1e6 * cpu_h / entries:.2f}",
                     f"{1e6 * wall_l / entries:.1f} / {1e6 * cpu_l / entries:.1f}", lay.stats["n_images"],
                     f"{wall_m:.1f} / {cpu_m:.1f}", f"{hmat.stats['compression']:.2f}", f"{error:.1e}"])
    return markdown_table(["N", "homogeneous dense us/entry (wall / CPU)", "layered dense us/entry (wall / CPU)",
                           "images (auto)", "layered hmatrix build s (wall / CPU)", "compression (dense / H bytes)",
                           "H vs dense (Frobenius)"], rows)


def crack_volume(mesh, medium):
    op = hd.ElasticityOperator(mesh, medium)
    dd = hd.solve(op, -1e-3 * medium.shear_modulus[1] * mesh.normals)
    return float(np.sum(hd.opening(mesh, dd) * mesh.areas))


def images_and_gauss(n_elements=40):
    """Ref. Table 3.2 setting with constant elements; relative volume error and build time."""
    h = 1.0
    rows = []
    for gamma in (2.0, 5.0):
        for name, mesh in (("horizontal", hd.mesh.line([-h / 2, 0.0], [h / 2, 0.0], n_elements)),
                           ("vertical", hd.mesh.line([0.0, -h / 2], [0.0, h / 2], n_elements))):
            def medium(**options):
                return LayeredMedium([h / 2, -h / 2], [gamma, 1.0, gamma], [0.2, 0.2, 0.2], **options)

            reference = crack_volume(mesh, medium(images=16, gauss_points=8))
            for images in (0, 1, 2, 3, 8):
                volume, wall, cpu = timed(lambda: crack_volume(mesh, medium(images=images, gauss_points=3)))
                rows.append([gamma, name, f"images {images}, 3 Gauss", f"{volume / reference - 1:+.2e}",
                             f"{wall:.2f} / {cpu:.2f}"])
            for gauss in (1, 2, 3, 4):
                volume, wall, cpu = timed(lambda: crack_volume(mesh, medium(images=8, gauss_points=gauss)))
                rows.append([gamma, name, f"images 8, {gauss} Gauss", f"{volume / reference - 1:+.2e}",
                             f"{wall:.2f} / {cpu:.2f}"])
            auto = medium()
            op = hd.ElasticityOperator(mesh, auto)
            volume = crack_volume(mesh, auto)
            rows.append([gamma, name, f"auto ({op.stats['n_images']} images, tol 1e-4), 4 Gauss",
                         f"{volume / reference - 1:+.2e}", ""])
    return markdown_table(["gamma", "crack", "setting", "volume error", "solve s (wall / CPU)"], rows)


def height_runs(end_time):
    base = hs.load_scene("layered-height").data
    cases = [(f"gamma = {gamma:g}", gamma, 0.5e6) for gamma in (0.5, 1.0, 2.0, 5.0)]
    cases += [("gamma = 1, +0.5 MPa stress", 1.0, 1.0e6), ("gamma = 1, +1.5 MPa stress", 1.0, 2.0e6)]
    curves, rows = [], []
    for label, gamma, s_outer in cases:
        raw = {k: v for k, v in base.items()}
        layers = [dict(layer) for layer in base["layer"]]
        for k in (0, 2):
            layers[k]["shear_modulus"] = gamma * layers[1]["shear_modulus"]
            layers[k]["s_hmin"] = s_outer
        raw["layer"] = layers
        raw["numerics"] = dict(base["numerics"], end_time=end_time)
        scene = hs.scene_from_dict(raw)
        sim = hs.build_simulation(scene.data)
        heights, times = [], []
        wall, cpu = time.perf_counter(), time.process_time()
        step = 0.0
        while step < end_time:
            step += sim.time_step
            sim.run(end_time=step)
            p0, p1 = sim.state.mesh.endpoints
            heights.append(float(max(p0[:, 1].max(), p1[:, 1].max()) - min(p0[:, 1].min(), p1[:, 1].min())))
            times.append(step)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        curves.append((label, times, heights))
        images = sim.base_operator.stats.get("n_images")  # the last full build (growth adds exact borders)
        rows.append([label, f"{heights[-1]:.2f}", sim.state.mesh.n_elements, images, f"{wall:.0f} / {cpu:.0f}"])
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for label, times, heights in curves:
        ax.plot(times, heights, label=label)
    ax.axhline(6.0, color="0.6", lw=0.8, ls="--")
    ax.text(0.5, 6.1, "middle layer (6 m)", color="0.4", fontsize=8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("fracture height (m)")
    ax.set_title("layered-height: bounding layers gamma x stiffer, or more stressed")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(os.path.dirname(os.path.abspath(__file__)), "layered_height.png"), dpi=110)
    return markdown_table(["case", "height at end (m)", "elements", "images", "run s (wall / CPU)"], rows)


def main():
    quick = "--quick" in sys.argv
    print(f"machine: {machine()}\n")
    print("## Operator cost (vertical crack through 3 layers + a horizontal one; gamma = 2)\n")
    print(operator_cost([100, 200] if quick else [100, 200, 400, 800]))
    print("\n## Volume error against images and Gauss points (ref. Table 3.2 cracks, 40 constant elements)\n")
    print(images_and_gauss())
    print("\n## layered-height scene: height against time\n")
    print(height_runs(10.0 if quick else 40.0))


if __name__ == "__main__":
    main()
