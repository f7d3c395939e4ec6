"""Layered rock in 3D (ref. Ch. 3, issue 14): the layered rectangle operator on the
H-matrix, the shallow-sill scene against depth, and the layered-3d scene against the
modulus contrast.

1. ``operator``: a half-space (free surface z = 0) holding a horizontal and a vertical
   square fracture of 1 m squares (N/2 each, :func:`two_fractures`), on the H-matrix
   (eps 1e-4): build (wall and CPU), memory, compression, matvec (wall and CPU) and the
   relative error of the matvec of a smooth elliptical opening (docs/conventions.md §7)
   on 300 rows computed exactly by the kernel, next to the homogeneous operator on the
   same mesh. One reflection (images = 1) is the whole half-space solution. Every
   (N, medium) runs in a fresh process, so the peak RSS is its own.
2. ``sill``: the shallow-sill scene (hmatddm/scene/scenes/shallow-sill.toml) at depths
   3, 6.5 and 26 m below the free surface (~0.5, 1 and 4 radii at the end) and in a full space: radius and opening against
   time, with the full-space radial solution of hmatddm.analytical (K_m ~ 1: Dontsov's
   solution between the vertices, radial_transition).
3. ``layered3d``: the layered-3d scene with bounding layers gamma = 1, 2, 5 times as
   stiff as the middle layer: fracture height (z extent) and length (y extent) against
   time, one plot, and a snapshot of the gamma = 5 run.

    python benchmarks/bench_layered3d.py [operator|sill|layered3d ...] [--quick] [--n 10000 40000]
        [--rows 300] [--end-time 12]
"""
import argparse
import json
import os
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from _common import machine, markdown_table, peak_rss_bytes  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out")
G, NU = 10e9, 0.25


# -- 1. the operator --------------------------------------------------------------------
def two_fractures(n):
    """A half-space (free surface z = 0) holding a horizontal square fracture (a sill,
    side x side 1 m squares, centre at depth side / 4) and, beside it, a vertical one of
    the same size (plane x = side / 2 + 2 m, top 2 m below the surface): N ~ n squares."""
    import hmatddm as hd

    side = int(round(np.sqrt(n / 2.0)))
    sill = hd.mesh.rectangle([0.0, 0.0, -side / 4.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], float(side), float(side),
                             side, side)
    dyke = hd.mesh.rectangle([side / 2.0 + 2.0, 0.0, -2.0 - side / 2.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0],
                             float(side), float(side), side, side)
    return hd.mesh.concatenate([sill, dyke])


def smooth_field(mesh):
    """An elliptical opening over each planar fracture (docs/conventions.md §7; the
    fractures of :func:`two_fractures` differ by their normal)."""
    x = np.zeros((mesh.n_elements, 3))
    planes = np.unique(np.round(mesh.normals, 9), axis=0, return_inverse=True)[1].ravel()
    for f in np.unique(planes):
        member = planes == f
        c = mesh.centers[member]
        local = (c - c.mean(axis=0)) / (np.abs(c - c.mean(axis=0)).max(axis=0) + 0.5)
        w = np.sqrt(np.clip(1.0 - np.sum(local ** 2, axis=1), 0.0, None))
        x[member] = 1e-3 * w[:, None] * mesh.normals[member]
    return x.ravel()


def medium(layered, images):
    import hmatddm as hd
    from hmatddm.layered import LayeredMedium

    return LayeredMedium([0.0], [0.0, G], [NU, NU], images=images) if layered else hd.Elastic(G, NU)


def _clock():
    return time.perf_counter(), time.process_time()


def _since(start):
    return time.perf_counter() - start[0], time.process_time() - start[1]


def operator_case(n, layered, eps=1e-4, n_rows=300, images=1):
    """One measurement in this process (so that its peak RSS is its own); a dict."""
    import hmatddm as hd

    warm = two_fractures(128)  # numba loads or compiles its drivers outside the timing
    hd.ElasticityOperator(warm, medium(layered, images), backend="hmatrix", eps=eps).matvec(smooth_field(warm))
    mesh = two_fractures(n)
    row = dict(n=mesh.n_elements, layered=layered, eps=eps, images=images if layered else None)
    start = _clock()
    op = hd.ElasticityOperator(mesh, medium(layered, images), backend="hmatrix", eps=eps)
    row["build_s"], row["build_cpu_s"] = _since(start)
    stats = op.stats
    row.update(memory_mb=stats["memory_bytes"] / 2**20, dense_mb=stats["dense_bytes"] / 2**20,
               compression=stats["compression"], max_rank=stats.get("max_rank"))
    x = smooth_field(mesh)
    y = op.matvec(x)
    start, walls = _clock(), []
    for _ in range(5):
        one = time.perf_counter()
        op.matvec(x)
        walls.append(time.perf_counter() - one)
    row["matvec_s"], row["matvec_cpu_s"] = float(np.median(walls)), _since(start)[1] / 5
    rows = np.sort(np.random.default_rng(2).choice(mesh.n_elements, min(n_rows, mesh.n_elements), replace=False))
    start = _clock()
    exact = op.exact_block(rows, np.arange(mesh.n_elements)) @ x
    row["exact_rows"] = len(rows)
    row["exact_rows_s"], row["exact_rows_cpu_s"] = _since(start)
    row["pair_us"] = 1e6 * row["exact_rows_cpu_s"] / (len(rows) * mesh.n_elements)
    index = (3 * rows[:, None] + np.arange(3)).ravel()
    row["row_error"] = float(np.linalg.norm(y[index] - exact) / np.linalg.norm(exact))
    row["peak_rss_mb"] = peak_rss_bytes() / 2**20
    return row


def spawn_operator_case(n, layered, timeout, n_rows):
    script = ("import json, sys; sys.path.insert(0, %r)\nimport bench_layered3d as b\n"
              "print('RESULT', json.dumps(b.operator_case(%d, %r, n_rows=%d)))\n" % (HERE, n, layered, n_rows))
    try:
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return dict(n=n, layered=layered, failed=f"over {timeout:.0f} s")
    for line in done.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    return dict(n=n, layered=layered, failed=(done.stderr or "no output").strip().splitlines()[-1])


def operator_table(rows):
    def cell(row, key, spec):
        return "-" if row.get(key) is None else format(row[key], spec)

    body = []
    for r in rows:
        name = "half-space, images 1" if r["layered"] else "homogeneous"
        if "failed" in r:
            body.append([r["n"], name, r["failed"]] + ["-"] * 8)
            continue
        body.append([r["n"], name, f"{r['build_s']:.1f} / {r['build_cpu_s']:.1f}", cell(r, "memory_mb", ".0f"),
                     cell(r, "compression", ".1f"), cell(r, "max_rank", "d"),
                     f"{1e3 * r['matvec_s']:.0f} / {1e3 * r['matvec_cpu_s']:.0f}", cell(r, "row_error", ".1e"),
                     f"{r['exact_rows']} in {r['exact_rows_s']:.0f} / {r['exact_rows_cpu_s']:.0f}",
                     cell(r, "pair_us", ".1f"), cell(r, "peak_rss_mb", ".0f")])
    return markdown_table(["N", "medium", "build s (wall / CPU)", "H memory MB", "compression", "max rank",
                           "matvec ms (wall / CPU)", "matvec error vs exact rows", "exact rows s (wall / CPU)",
                           "CPU us per exact element pair", "peak RSS MB"], body)


# -- 2. shallow sill ----------------------------------------------------------------------
def sill_runs(depths, end_time, quick=False):
    import hmatddm as hd
    import hmatddm.scene as hs

    scene = hs.load_scene("shallow-sill").data
    results = {}
    for depth in list(depths) + [None]:
        data = json.loads(json.dumps(scene))
        if depth is None:  # the same fracture in a full space
            data.pop("layer")
            data["material"] = dict(shear_modulus=G, poisson_ratio=NU)
        else:
            data["initial_fracture"][0]["center"][2] = -depth
            data["cluster"][0]["position"][2] = -depth
        data["numerics"]["end_time"] = end_time
        sim = hs.build_simulation(hs.scene_from_dict(data).data)
        wall, cpu = time.perf_counter(), time.process_time()
        records = sim.run(end_time)
        key = "full space" if depth is None else f"{depth:g} m deep"
        results[key] = dict(time=[r["time"] for r in records], radius=[r["radius"] for r in records],
                            max_opening=[r["max_opening"] for r in records],
                            pressure=[r["wellbore_pressure"][0] for r in records],
                            elements=records[-1]["n_elements"], wall_s=time.perf_counter() - wall,
                            cpu_s=time.process_time() - cpu, depth=depth)
    cluster = scene["cluster"][0]
    material = hd.Elastic(G, NU)
    t = np.array(results["full space"]["time"])
    regime = float(hd.analytical.radial_regime(t[-1], cluster["rate"], scene["fluid"]["viscosity"],
                                               scene["propagation"]["toughness"], material))
    # K_m ~ 1: between the vertices, Dontsov's (2016) solution at any toughness
    radius, width = hd.analytical.radial_transition(t, cluster["rate"], scene["fluid"]["viscosity"],
                                                    scene["propagation"]["toughness"], material)
    vertex = "transition (Dontsov 2016)"
    results["analytical"] = dict(time=t.tolist(), radius=radius.tolist(), max_opening=width.tolist(),
                                 vertex=vertex, dimensionless_toughness=regime)
    return results


def sill_table(results):
    reference = results["analytical"]
    body = []
    for key, r in results.items():
        if key == "analytical":
            continue
        ratio = "-" if r["depth"] is None else f"{r['depth'] / r['radius'][-1]:.2f}"
        body.append([key, ratio, r["elements"], f"{r['radius'][-1]:.2f}",
                     f"{r['radius'][-1] / reference['radius'][-1]:.2f}", f"{1e3 * r['max_opening'][-1]:.3f}",
                     f"{r['max_opening'][-1] / reference['max_opening'][-1]:.2f}", f"{r['pressure'][-1] / 1e6:.2f}",
                     f"{r['wall_s']:.0f} / {r['cpu_s']:.0f}"])
    return markdown_table(["run", "depth / radius (end)", "elements", "radius m", "/ full-space solution",
                           "max opening mm", "/ full-space solution", "wellbore pressure MPa", "wall / CPU s"], body)


def sill_plot(results, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    reference = results["analytical"]
    for key, r in results.items():
        if key == "analytical":
            continue
        style = "k--" if key == "full space" else "-"
        label = key if r["depth"] is None else f"{key} (depth / radius {r['depth'] / r['radius'][-1]:.2f} at the end)"
        axes[0].plot(r["time"], r["radius"], style, marker="o", ms=3, label=label)
        axes[1].plot(r["time"], 1e3 * np.array(r["max_opening"]), style, marker="o", ms=3, label=label)
    axes[0].plot(reference["time"], reference["radius"], "k:", label=f"radial {reference['vertex']}, full space")
    axes[1].plot(reference["time"], 1e3 * np.array(reference["max_opening"]), "k:",
                 label=f"radial {reference['vertex']}, full space")
    axes[0].set(xlabel="time s", ylabel="radius sqrt(area / pi) m", title="shallow-sill: radius")
    axes[1].set(xlabel="time s", ylabel="max opening mm", title="shallow-sill: opening")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# -- 3. layered-3d --------------------------------------------------------------------------
def layered_runs(gammas, end_time, snapshot_path=None):
    import hmatddm.scene as hs
    from hmatddm.layered.engine import _vertical_extent

    scene = hs.load_scene("layered-3d").data
    results = {}
    for gamma in gammas:
        data = json.loads(json.dumps(scene))
        for k in (0, 2):
            data["layer"][k]["shear_modulus"] = gamma * data["layer"][1]["shear_modulus"]
        end_time = end_time or data["numerics"]["end_time"]
        data["numerics"]["end_time"] = end_time
        sim = hs.build_simulation(hs.scene_from_dict(data).data)
        history = dict(time=[], height=[], length=[])

        def record(simulation, rec):
            mesh = simulation.state.mesh
            low, high = _vertical_extent(mesh)
            along = mesh.centers[:, 1]
            reach = mesh.half_a * np.abs(mesh.frames[:, 0, 1]) + mesh.half_b * np.abs(mesh.frames[:, 1, 1])
            history["time"].append(rec["time"])
            history["height"].append(float(high.max() - low.min()))
            history["length"].append(float((along + reach).max() - (along - reach).min()))

        wall, cpu = time.perf_counter(), time.process_time()
        records = sim.run(end_time, callback=record)
        history.update(elements=records[-1]["n_elements"], wall_s=time.perf_counter() - wall,
                       cpu_s=time.process_time() - cpu, pressure=records[-1]["wellbore_pressure"][0],
                       max_opening=records[-1]["max_opening"])
        results[f"{gamma:g}"] = history
        if snapshot_path is not None and gamma == max(gammas):
            from hmatddm.render import snapshot

            mesh = sim.state.mesh
            opening = np.sum(sim.state.dd * mesh.normals, axis=1)
            snapshot(mesh, snapshot_path, opening=opening, view="oblique",
                     title=f"layered-3d, gamma = {gamma:g}, t = {records[-1]['time']:g} s (interfaces z = +-3 m)")
    return results


def layered_table(results):
    body = [[gamma, r["elements"], f"{r['height'][-1]:.1f}", f"{r['length'][-1]:.1f}",
             f"{1e3 * r['max_opening']:.3f}", f"{r['pressure'] / 1e6:.2f}", f"{r['wall_s']:.0f} / {r['cpu_s']:.0f}"]
            for gamma, r in results.items()]
    return markdown_table(["gamma (bounding / middle G)", "elements", "height m", "length m", "max opening mm",
                           "wellbore pressure MPa", "wall / CPU s"], body)


def layered_plot(results, path):
    """Height and length against time, one colour per gamma; line widths and markers
    differ so that coinciding histories stay visible."""
    fig, ax = plt.subplots(figsize=(8, 5))
    styles = zip(("C0", "C1", "C3", "C2"), (5.0, 3.0, 1.3, 1.0), ("o", "s", "^", "v"), (9, 6, 4, 3))
    for (gamma, r), (colour, width, marker, size) in zip(results.items(), styles):
        ax.plot(r["time"], r["height"], "-", marker=marker, color=colour, lw=width, ms=size, alpha=0.8,
                label=f"height, gamma = {gamma}")
        ax.plot(r["time"], r["length"], "--", marker=marker, color=colour, lw=width, ms=size, alpha=0.8,
                label=f"length, gamma = {gamma}")
    ax.axhline(6.0, color="grey", lw=0.8)
    ax.annotate("middle layer thickness (6 m)", (0.02, 6.0), xycoords=("axes fraction", "data"),
                xytext=(0, 3), textcoords="offset points", color="grey", fontsize=8)
    ax.set(xlabel="time s", ylabel="m", title="layered-3d: height (z extent) and length (y extent)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("parts", nargs="*", default=["operator", "sill", "layered3d"])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--n", type=int, nargs="*", default=None)
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds per operator case")
    parser.add_argument("--rows", type=int, default=300, help="exact rows for the operator error")
    parser.add_argument("--end-time", type=float, default=None, help="end time of the scene runs (s)")
    args = parser.parse_args()
    os.makedirs(OUT, exist_ok=True)
    print(f"machine: {machine()}")
    if "operator" in args.parts:
        sizes = args.n or ([1024] if args.quick else [10_000, 40_000])
        rows = []
        for n in sizes:
            for layered in (False, True):
                rows.append(spawn_operator_case(n, layered, args.timeout, args.rows))
                print(json.dumps(rows[-1]), flush=True)
        with open(os.path.join(OUT, "layered3d_operator%s.json" % ("_quick" if args.quick else "")), "w") as f:
            json.dump(rows, f, indent=1)
        print(operator_table(rows))
    if "sill" in args.parts:
        results = sill_runs((3.0, 6.5, 26.0), args.end_time or (6.0 if args.quick else 12.0))
        with open(os.path.join(OUT, "layered3d_sill.json"), "w") as f:
            json.dump(results, f, indent=1)
        sill_plot(results, os.path.join(HERE, "layered3d_sill.png"))
        print(sill_table(results))
    if "layered3d" in args.parts:
        results = layered_runs((1.0, 2.0, 5.0), args.end_time or (2.0 if args.quick else None),
                               snapshot_path=os.path.join(HERE, "layered3d_snapshot.png"))
        with open(os.path.join(OUT, "layered3d_scene.json"), "w") as f:
            json.dump(results, f, indent=1)
        layered_plot(results, os.path.join(HERE, "layered3d_height.png"))
        print(layered_table(results))


if __name__ == "__main__":
    main()
