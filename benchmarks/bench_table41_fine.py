"""Ref. Table 4.1 at the reference's own mesh: 0.1 m elements and a 0.3 m x 0.3 m start, to 50 s
(issue 36 item 5), with the 50 s opening and pressure profiles against the closed forms (ref.
Figs 4.4, 4.5, 4.8, 4.9).

    python benchmarks/bench_table41_fine.py                  # both columns at 0.1 m (hours of CPU, one thread)
    python benchmarks/bench_table41_fine.py --h 0.5          # the same study at 0.5 m (a minute)
    python benchmarks/bench_table41_fine.py --report DIR [DIR ...]   # tables and plot from run folders

The two columns of ref. Table 4.1 are the embedded scenes ``radial-m`` (K_Ic 1 MPa m^1/2, K_m
0.37-0.6: the M vertex applies) and ``radial-km`` (K_Ic 5 MPa m^1/2, K_m 1.8-2.9: the K-M
transition, compared with Dontsov 2016, the K vertex beside it; the reference called it the
K-vertex column), each run as ``hmatddm run SCENE --set initial_fracture[0].element_size=H
--set initial_fracture[0].length=3H --set initial_fracture[0].height=3H --set
numerics.end_time=50 --set numerics.time_step=auto`` in a child process (its CPU time and
peak memory). The reference stepped 1 s at a time; at 0.1 m elements the front then crosses
up to ~20 element rows a step, so the runs follow the front (``time_step = "auto"``,
issue 33). The operator is the lattice FFT operator of a planar crack in uniform rock
(hmatddm/elasticity/lattice.py).

At 50 s it prints elements, steps, growth passes, nonlinear and GMRES iterations, CPU, wall
and peak memory, the radius sqrt(A/pi) (ref. Eq. 4.69), the opening at the well and the net
pressure at the well against the closed forms, and the profiles' errors: the opening averaged
over rings of one element width around the well against the closed form at the ring's
radius, RMS over r < 0.9 R relative to the closed form's opening at the well; for the M
column the net pressure likewise over 0.1 R < r < 0.9 R (the M vertex's pressure is
log-singular at the well and at the tip) relative to its value at r = R/2. Plot:
``benchmarks/table41_fine_profiles.png`` (ring means and every 50th element against the
closed forms).

``--report`` reads run folders (each named by its scene); when a folder holds ``time.log``,
the output of ``/usr/bin/time -v`` for its run, its CPU time and peak memory are reported.
"""
import argparse
import json
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))

from _common import machine, print_table  # noqa: E402
from bench_scaling import run  # noqa: E402

CASES = ("radial-m", "radial-km")
END_TIME = 50.0


def settings(h):
    """The ``--set`` values of one run at element size ``h`` (m)."""
    return [f"initial_fracture[0].length={3 * h}", f"initial_fracture[0].height={3 * h}",
            f"numerics.end_time={END_TIME}", "output.every=100000"]


def time_log(folder):
    """``(cpu_seconds, peak_mb)`` from ``folder/time.log`` (GNU time -v), or None."""
    path = os.path.join(folder, "time.log")
    if not os.path.isfile(path):
        return None
    text = open(path).read()
    user = float(re.search(r"User time \(seconds\): ([\d.]+)", text).group(1))
    system = float(re.search(r"System time \(seconds\): ([\d.]+)", text).group(1))
    peak = float(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1)) / 1024.0
    return user + system, peak


def ring_means(radius, values, width, limit):
    """Means of ``values`` over rings ``[k width, (k+1) width)`` of ``radius`` below ``limit``:
    ``(ring centres, means)`` of the rings that hold elements."""
    ring = np.floor(radius / width).astype(np.int64)
    keep = radius < limit
    count = np.bincount(ring[keep])
    total = np.bincount(ring[keep], weights=values[keep])
    filled = count > 0
    return (np.arange(len(count))[filled] + 0.5) * width, total[filled] / count[filled]


def profiles(folder, size):
    """The last saved state of a run folder (a fracture of radius ``size``, m) against its
    scene's closed form: a dict of the element radii, openings, net pressures, the
    closed-form curves and the profile errors."""
    from hmatddm.app.profiles import closed_form_profile
    from hmatddm.app.run_folder import saved_states
    from hmatddm.scene import load_scene

    scene = load_scene(os.path.join(folder, "scene.toml")).data
    mesh, fields, step, time_value = list(saved_states(folder))[-1]
    if not abs(time_value - END_TIME) < 1e-6 * END_TIME:
        raise RuntimeError(f"{folder}: the last saved step is at {time_value} s, not {END_TIME} s")
    well = np.asarray(scene["cluster"][0]["position"], dtype=float)
    radius = np.linalg.norm(mesh.centers - well, axis=1)
    h = float(scene["initial_fracture"][0]["element_size"])
    curve = closed_form_profile(scene, time_value)
    half = curve["position"] >= 0.0
    r_curve, w_curve = curve["position"][half], curve["opening"][half]
    out = dict(step=step, time=time_value, r=radius, opening=fields["opening"], net_pressure=fields["net_pressure"],
               curve=curve, label=curve["label"], h=h)
    rings, w_mean = ring_means(radius, fields["opening"], h, 0.9 * size)
    w_exact = np.interp(rings, r_curve, w_curve)
    out["opening_rms"] = float(np.sqrt(np.mean((w_mean - w_exact) ** 2)) / np.interp(0.0, r_curve, w_curve))
    if "net_pressure" in curve:
        p_curve = curve["net_pressure"][half]
        rings_p, p_mean = ring_means(radius, fields["net_pressure"], h, 0.9 * size)
        inner = rings_p > 0.1 * size
        p_exact = np.interp(rings_p[inner], r_curve, p_curve)
        scale = float(np.interp(0.5 * size, r_curve, p_curve))
        out["pressure_rms"] = float(np.sqrt(np.mean((p_mean[inner] - p_exact) ** 2)) / abs(scale))
    out["rings"], out["ring_opening"] = rings, w_mean
    out["rings_pressure"], out["ring_pressure"] = ring_means(radius, fields["net_pressure"], h, size)
    if scene["reference"]["kind"] == "radial-km":  # the K vertex beside the transition (ref. Eqs 4.65-4.67)
        out["vertex"] = closed_form_profile(dict(scene, reference=dict(scene["reference"], kind="radial-k")),
                                            time_value)
    return out


def summary_row(folder, case, measured=None):
    """The table row of one run folder (``measured``: the child's cpu, wall, peak_mb)."""
    summary = json.load(open(os.path.join(folder, "summary.json")))
    records = [record for record in summary["steps"] if record["step"] > 0]
    reference = summary["reference"][-1]
    error = reference["relative_error"]
    total = lambda key: sum(record.get(key) or 0 for record in records)  # noqa: E731
    if measured is None:
        logged = time_log(folder)
        measured = dict(cpu=logged[0], peak_mb=logged[1]) if logged else {}
        measured["wall"] = summary.get("wall_seconds")
    shape = profiles(folder, reference["radius"])
    k_vertex = reference.get("k_vertex", {}).get("relative_error", {})
    return dict(case=case, h=shape["h"], elements=records[-1]["n_elements"], steps=len(records),
                passes=total("growth_passes"), nonlinear=total("nonlinear_iterations"),
                gmres=total("linear_iterations"), matvecs=total("matvecs"), cpu=measured.get("cpu"),
                wall=measured.get("wall"), peak_mb=measured.get("peak_mb"), radius=reference["radius"],
                radius_error=error.get("radius"), opening_error=error.get("max_opening"),
                opening_rms=shape["opening_rms"], pressure_rms=shape.get("pressure_rms"),
                k_vertex_radius=k_vertex.get("radius"), k_vertex_opening=k_vertex.get("max_opening"),
                k_m=reference.get("dimensionless_toughness"), reference=reference["solution"]["name"]), shape


def plot(shapes, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(2, len(shapes), figsize=(6 * len(shapes), 8), squeeze=False)
    for column, (case, shape) in enumerate(shapes):
        curve, every = shape["curve"], slice(None, None, 50)
        half = curve["position"] >= 0.0
        top, bottom = axes[0, column], axes[1, column]
        top.plot(shape["r"][every], 1e3 * shape["opening"][every], ".", ms=1, color="0.7", label="elements (every 50th)")
        top.plot(shape["rings"], 1e3 * shape["ring_opening"], "o", ms=3, label=f"ring means ({shape['h']:g} m)")
        top.plot(curve["position"][half], 1e3 * curve["opening"][half], "k-", label=curve["label"])
        vertex = shape.get("vertex")
        if vertex is not None:
            inside = vertex["position"] >= 0.0
            top.plot(vertex["position"][inside], 1e3 * vertex["opening"][inside], "k--", label=vertex["label"])
            bottom.plot(vertex["position"][inside], 1e-6 * vertex["net_pressure"][inside], "k--", label=vertex["label"])
        top.set(xlabel="distance from the well (m)", ylabel="opening (mm)", title=f"{case}, t = {shape['time']:g} s")
        top.legend(fontsize=8)
        bottom.plot(shape["r"][every], 1e-6 * shape["net_pressure"][every], ".", ms=1, color="0.7")
        bottom.plot(shape["rings_pressure"], 1e-6 * shape["ring_pressure"], "o", ms=3, label="ring means")
        if "net_pressure" in curve:
            bottom.plot(curve["position"][half], 1e-6 * curve["net_pressure"][half], "k-", label=curve["label"])
        bottom.legend(fontsize=8)
        bottom.set(xlabel="distance from the well (m)", ylabel="net pressure (MPa)")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    print(f"saved {path}")


def report(rows, shapes, plot_path):
    print(machine())
    header = ["case", "h (m)", "elements", "steps", "passes", "nonlinear", "GMRES", "matvecs", "CPU (s)", "wall (s)",
              "peak (MB)", "R (m)", "R err", "w0 err", "w RMS", "p RMS", "K_m", "vs K vertex R / w0"]
    percent = lambda x: "-" if x is None else f"{100 * x:+.2f}%"  # noqa: E731
    number = lambda x, f: "-" if x is None else format(x, f)  # noqa: E731
    print_table(header, [[row["case"], f"{row['h']:g}", row["elements"], row["steps"], row["passes"], row["nonlinear"],
                          row["gmres"], row["matvecs"], number(row["cpu"], ".0f"), number(row["wall"], ".0f"),
                          number(row["peak_mb"], ".0f"), f"{row['radius']:.3f}", percent(row["radius_error"]),
                          percent(row["opening_error"]), f"{100 * row['opening_rms']:.2f}%",
                          "-" if row["pressure_rms"] is None else f"{100 * row['pressure_rms']:.2f}%",
                          number(row["k_m"], ".2f"),
                          "-" if row["k_vertex_radius"] is None else
                          f"{percent(row['k_vertex_radius'])} / {percent(row['k_vertex_opening'])}"] for row in rows])
    for row in rows:
        print(f"{row['case']}: compared with {row['reference']}")
    plot(shapes, plot_path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=0.1, help="element size (m); the reference's is 0.1")
    parser.add_argument("--out", default=os.path.join(HERE, "out", "table41_fine"))
    parser.add_argument("--plot", default=os.path.join(HERE, "table41_fine_profiles.png"))
    parser.add_argument("--report", nargs="+", metavar="DIR", default=None,
                        help="report run folders (of radial-m, radial-km) instead of running")
    args = parser.parse_args()
    rows, shapes = [], []
    if args.report:
        for folder in args.report:
            case = json.load(open(os.path.join(folder, "summary.json")))["scene"]["name"]
            row, shape = summary_row(folder, case)
            rows.append(row)
            shapes.append((case, shape))
    else:
        os.makedirs(args.out, exist_ok=True)
        for case in CASES:
            folder = os.path.join(args.out, f"this-{case}-{args.h}-auto-{len(os.listdir(args.out))}")  # run()'s name
            measured = run(case, args.h, "auto", args.out, extra=settings(args.h))
            row, shape = summary_row(folder, case, measured)
            rows.append(row)
            shapes.append((case, shape))
    report(rows, shapes, args.plot)


if __name__ == "__main__":
    main()
