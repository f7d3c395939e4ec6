"""Synthetic microseismic monitoring of three-cluster natural-fracture runs (ref. Ch. 7:
Figs 7.6-7.11, Tables 7.2-7.5).

    python benchmarks/bench_microseismic.py                # both runs, every study
    python benchmarks/bench_microseismic.py --runs 2d      # the plane-strain dfn-3cluster scene only
    python benchmarks/bench_microseismic.py --draws 50     # noise draws per level (default 50)
    python benchmarks/bench_microseismic.py --quick        # small sizes, a smoke test

Runs (their natural-fracture slip becomes the events):

* ``2d``: the embedded ``dfn-3cluster`` scene (plane strain in plan view, embedded at
  z = 0, 1 m flow height), written every step (``output.every = 1``) so that each event
  has the time of the step in which it first slips;
* ``3d``: the full-height 3D run of ``benchmarks/bench_dfn.py`` (10 rows of 1 m elements
  over a 10 m height, hmatrix backend), its onsets recorded after every step.

Studies, each with wall and CPU time:

1. forward model speed: 1e5 events x 100 receivers (``observe``), location and Brune;
2. event maps without noise, with small and large noise, one well (50, 50) and two
   wells (50, 50), (50, -50) (ref. Figs 7.6, 7.9, 7.10; noise levels of ref. Table 7.2
   read as small 10 deg / 2 ms, large 45 deg / 5 ms, see hmatddm/microseismic/noise.py);
3. Brune magnitudes with the RMS and the true radiation factors (ref. Figs 7.7-7.8);
4. location error (ref. Eq. 7.30) against noise level and well count over ``--draws``
   draws (ref. Fig. 7.11), and the strike error of traces fitted to the located events
   (DBSCAN with a data-driven radius + PCA) against the true traces;
5. source inversion (ref. Sec. 7.4.3) of the Table 7.3/7.4 source with one and two
   wells at the amplitude noise of ref. Table 7.5 (0, 5 %, 20 % of the largest
   amplitude), ``--draws`` draws each, general and double-couple sources.

PNGs go next to this script (``microseismic_*.png``; with ``--quick`` into ``--out``), numbers
to ``--out``/microseismic.json. ``--reuse`` reads the finished 2D run in ``--out`` and the
cached 3D state instead of running them again.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, markdown_table  # noqa: E402

from hmatddm import microseismic as ms  # noqa: E402
from hmatddm.app import catalogue  # noqa: E402
from hmatddm.microseismic.inversion import invert_source_draws  # noqa: E402

MEDIUM = ms.Medium(4000.0, 2350.0, 3000.0)  # ref. Table 7.1
WELLS = {1: [ms.Well(50.0, 50.0)], 2: [ms.Well(50.0, 50.0), ms.Well(50.0, -50.0)]}  # ref. Sec. 7.4.2
LOCATION_NOISE = {"none": ms.NO_NOISE, "small": ms.SMALL_LOCATION_NOISE, "large": ms.LARGE_LOCATION_NOISE}
AMPLITUDE_NOISE = {"none": ms.NO_NOISE, "5%": ms.SMALL_AMPLITUDE_NOISE, "20%": ms.LARGE_AMPLITUDE_NOISE}
TABLE_NORMAL = np.array([-1.0, 1.0, 0.0]) / np.sqrt(2)  # ref. Sec. 7.4.3
TABLE_SLIP = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
TABLE_POTENCY = 1e-3 * 4.0
TABLE_WELLS = {1: [ms.Well(50.0, 0.0)], 2: [ms.Well(50.0, 0.0), ms.Well(50.0, -20.0)]}


class Clock:
    """Wall and CPU seconds of a block."""

    def __enter__(self):
        self.wall, self.cpu = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.wall
        self.cpu = time.process_time() - self.cpu


def _load():
    return os.getloadavg()[0]


# ---------------------------------------------------------------------------------
# 1. forward speed
# ---------------------------------------------------------------------------------

def forward_speed(count, stations=100, seed=0):
    rng = np.random.default_rng(seed)
    normals = rng.normal(size=(count, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    slips = np.cross(normals, rng.normal(size=(count, 3)))
    dd = 1e-3 * slips / np.linalg.norm(slips, axis=1, keepdims=True)
    events = ms.point_sources(rng.uniform([-40, -80, -5], [40, 80, 5], size=(count, 3)), dd, normals, 1.0, MEDIUM)
    per_well = stations // 4
    wells = [ms.Well(x, y, 20.0, -20.0, 40.0 / (per_well - 1)) for x, y in ((60, 60), (60, -60), (-60, 60), (-60, -60))]
    receivers, well = ms.receivers_of(wells)
    with Clock() as forward:
        observations = ms.observe(events, receivers, MEDIUM, well)
    with Clock() as noise:
        noisy = ms.add_noise(observations, ms.SMALL_LOCATION_NOISE, seed)
    with Clock() as location:
        located = ms.locate(noisy, MEDIUM)
    with Clock() as brune:
        moment = ms.brune_moment(observations, MEDIUM, "s", factors="true")
    error = float(np.max(np.abs(moment / events.seismic_moment - 1.0)))
    exact = float(np.max(np.linalg.norm(ms.locate(observations, MEDIUM) - events.position, axis=1)))
    return dict(events=count, receivers=len(receivers), forward=(forward.wall, forward.cpu),
                noise=(noise.wall, noise.cpu), locate=(location.wall, location.cpu), brune=(brune.wall, brune.cpu),
                brune_true_error=error, location_noise_free_error=exact,
                location_error_small=ms.location_error(located, events.position))


# ---------------------------------------------------------------------------------
# the runs
# ---------------------------------------------------------------------------------

def run_2d(out, quick=False, reuse=False):
    """The dfn-3cluster run in ``out`` (``reuse``: a finished run there is read, not redone;
    its wall time is the one its summary.json recorded, its CPU time unknown: nan)."""
    from hmatddm.app.runner import SceneRun, read_summary
    from hmatddm.scene import load_scene

    overrides = ["output.every=1", "output.snapshots=false"] + (["numerics.end_time=30"] if quick else [])
    scene = load_scene("dfn-3cluster", overrides=overrides)
    summary = read_summary(out) if reuse and os.path.isdir(out) else None
    end = scene.numerics["end_time"]
    if summary and summary.get("steps") and summary["steps"][-1]["time"] >= end - 1e-9:
        clock = Clock()
        clock.wall, clock.cpu = float(summary["wall_seconds"]), float("nan")
        return catalogue.read_run(out), clock
    with Clock() as clock:
        SceneRun(scene, out, overwrite=True, quiet=True).execute()
    return catalogue.read_run(out), clock


def run_3d(quick=False, cache=None, reuse=False):
    """The bench_dfn run with onsets recorded every step; its last state and onsets are
    saved to ``cache`` (.npz), which ``reuse`` reads instead of running again."""
    import bench_dfn

    from hmatddm.mesh import Mesh3D

    if reuse and cache is not None and os.path.isfile(cache):
        data = np.load(cache)
        mesh = Mesh3D(data["centers"], data["frames"], data["half_a"], data["half_b"], data["fracture_id"])
        onset = ms.SlipOnset(float(data["tolerance"]))
        onset.centers, onset.time, onset.step = data["onset_centers"], data["onset_time"], data["onset_step"]
        clock = Clock()
        clock.wall, clock.cpu = float(data["wall"]), float(data["cpu"])
        return catalogue.RunState(mesh=mesh, dd=data["dd"], state=data["state"], time=float(data["time"]),
                                     step=int(data["step"]), onset=onset, height=1.0), clock
    scene = bench_dfn.FULL if not quick else bench_dfn.REDUCED
    simulation = bench_dfn.build_simulation(scene, "hmatrix")
    onset = ms.SlipOnset()
    with Clock() as clock:
        simulation.run(scene.end_time, callback=catalogue.onset_recorder(onset))
    run = catalogue.run_state_from_simulation(simulation, onset)
    if cache is not None:
        mesh = run.mesh
        np.savez(cache, centers=mesh.centers, frames=mesh.frames, half_a=mesh.half_a, half_b=mesh.half_b,
                 fracture_id=mesh.fracture_id, dd=run.dd, state=run.state, time=run.time, step=run.step,
                 tolerance=onset.tolerance, onset_centers=onset.centers, onset_time=onset.time,
                 onset_step=onset.step, wall=clock.wall, cpu=clock.cpu)
    return run, clock


# ---------------------------------------------------------------------------------
# 2-4. maps, Brune, location and strike errors
# ---------------------------------------------------------------------------------

def _true_azimuths(run):
    p0, p1, _ = run.plan_traces()
    return ms.true_trace_azimuths(p0, p1, run.mesh.fracture_id)


def location_study(run, events, draws, seed=1):
    """Location error and strike error of fitted traces per (wells, noise)."""
    truth = _true_azimuths(run)
    rows = []
    for count, wells in WELLS.items():
        receivers, well = ms.receivers_of(wells)
        clean = ms.observe(events, receivers, MEDIUM, well)
        for name, levels in LOCATION_NOISE.items():
            errors, strike, traces_found, seconds = [], [], [], [0.0, 0.0]
            for draw in range(1 if levels.is_zero else draws):
                with Clock() as clock:
                    noisy = ms.add_noise(clean, levels, seed + draw)
                    located = ms.locate(noisy, MEDIUM)
                seconds[0] += clock.wall
                seconds[1] += clock.cpu
                errors.append(ms.location_error(located, events.position))
                traces = ms.fit_traces(located, min_samples=3)
                if traces:
                    err, _ = ms.strike_errors(traces, events.fracture_id, truth)
                    strike.extend(err.tolist())
                traces_found.append(len(traces))
            rows.append(dict(wells=count, noise=name, draws=len(errors), error_mean=float(np.mean(errors)),
                             error_std=float(np.std(errors)),
                             strike_median=float(np.median(strike)) if strike else None,
                             strike_p90=float(np.percentile(strike, 90)) if strike else None,
                             traces=float(np.mean(traces_found)), wall=seconds[0] / len(errors),
                             cpu=seconds[1] / len(errors)))
    return rows


def plot_maps(run, events, path, title, seed=1):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from hmatddm.render.microseismic_maps import draw_map

    figure = Figure(figsize=(13.0, 10.5), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(2, 3)
    magnitude = events.moment_magnitude
    low, high = float(magnitude.min()), float(magnitude.max())
    traces = run.plan_traces()
    for row, (count, wells) in enumerate(WELLS.items()):
        receivers, well = ms.receivers_of(wells)
        clean = ms.observe(events, receivers, MEDIUM, well)
        for column, (name, levels) in enumerate(LOCATION_NOISE.items()):
            noisy = ms.add_noise(clean, levels, seed) if not levels.is_zero else clean
            located = ms.locate(noisy, MEDIUM)
            error = ms.location_error(located, events.position)
            scatter = draw_map(axes[row, column], traces, [[w.x, w.y] for w in wells], located, magnitude,
                               magnitude_range=(low, high),
                               title=f"{count} well(s), {'no' if levels.is_zero else name} noise: "
                                     f"location error {error:.2f} m")
            axes[row, column].set_xlim(-60, 60)
            axes[row, column].set_ylim(-110, 110)
    figure.colorbar(scatter, ax=axes, label="moment magnitude Mw", shrink=0.6)
    figure.suptitle(title)
    figure.savefig(path)
    return path


def plot_brune(events, path, title):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    receivers, well = ms.receivers_of(WELLS[1])
    observations = ms.observe(events, receivers, MEDIUM, well)
    truth = events.moment_magnitude
    figure = Figure(figsize=(10.0, 4.6), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(1, 2)
    stats = {}
    for axis, wave in zip(axes, ("p", "s")):
        rms = ms.moment_magnitude(ms.brune_moment(observations, MEDIUM, wave, "rms"))
        exact = ms.moment_magnitude(ms.brune_moment(observations, MEDIUM, wave, "true"))
        factor = ms.RMS_FACTOR_P if wave == "p" else ms.RMS_FACTOR_S
        axis.plot(truth, rms, "o", markersize=4, label=f"RMS factor {factor}")
        axis.plot(truth, exact, "x", markersize=5, label="true factors")
        line = [truth.min() - 0.2, truth.max() + 0.2]
        axis.plot(line, line, "k--", linewidth=1)
        axis.set_xlabel("Mw from Eq. 7.1")
        axis.set_ylabel(f"Mw from Brune's equation ({wave.upper()} wave)")
        axis.legend(fontsize=8)
        stats[wave] = dict(rms_mean=float(np.mean(rms - truth)), rms_max=float(np.max(np.abs(rms - truth))),
                           true_max=float(np.max(np.abs(exact - truth))))
        axis.set_title(f"{wave.upper()}: RMS factor off by {stats[wave]['rms_mean']:+.2f} on average "
                       f"(max {stats[wave]['rms_max']:.2f})", fontsize=9)
    figure.suptitle(title)
    figure.savefig(path)
    return stats


def plot_location_errors(studies, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.5, 4.5), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)
    axis = figure.subplots()
    names = list(LOCATION_NOISE)
    for label, rows in studies.items():
        for count in WELLS:
            chosen = [r for r in rows if r["wells"] == count]
            axis.errorbar(range(len(names)), [r["error_mean"] for r in chosen], yerr=[r["error_std"] for r in chosen],
                          marker="o", capsize=3, label=f"{label}, {count} well(s)")
    axis.set_xticks(range(len(names)), names)
    axis.set_xlabel("noise (ref. Table 7.2)")
    axis.set_ylabel("location error, Eq. 7.30 (m)")
    axis.legend(fontsize=8)
    axis.grid(alpha=0.3)
    figure.savefig(path)


# ---------------------------------------------------------------------------------
# 5. source inversion
# ---------------------------------------------------------------------------------

def inversion_study(draws, seed=10):
    events = ms.point_sources([0.0, 0.0, 0.0], 1e-3 * TABLE_SLIP, TABLE_NORMAL, 4.0, MEDIUM)
    rows, samples = [], {}
    for count, wells in TABLE_WELLS.items():
        receivers, well = ms.receivers_of(wells)
        clean = ms.observe(events, receivers, MEDIUM, well)
        for constraint in ("general", "double-couple"):
            for name, levels in AMPLITUDE_NOISE.items():
                with Clock() as clock:
                    spread = invert_source_draws(clean, MEDIUM, levels, 5 if levels.is_zero else draws, seed=seed,
                                                 constraint=constraint)
                angle = spread.orientation_errors(TABLE_NORMAL, TABLE_SLIP)
                ratio = spread.potency / TABLE_POTENCY
                samples[(count, constraint, name)] = (angle, ratio)
                rows.append(dict(wells=count, constraint=constraint, noise=name, draws=len(angle),
                                 angle_median=float(np.median(angle)), angle_p90=float(np.percentile(angle, 90)),
                                 within_5deg=float(np.mean(angle < 5.0)),
                                 potency_median=float(np.median(ratio)), potency_p5=float(np.percentile(ratio, 5)),
                                 potency_p95=float(np.percentile(ratio, 95)),
                                 misfit_median=float(np.median(spread.relative_misfit)),
                                 wall=clock.wall / len(angle), cpu=clock.cpu / len(angle)))
                print(f"  inversion {count} well(s) {constraint:13s} noise {name:4s}: median angle "
                      f"{rows[-1]['angle_median']:.2f} deg, potency {rows[-1]['potency_median']:.3f} "
                      f"[{rows[-1]['potency_p5']:.3f}, {rows[-1]['potency_p95']:.3f}], {rows[-1]['wall']:.2f} s each",
                      flush=True)
    return rows, samples


def plot_inversion(samples, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(12.0, 4.8), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(1, 2)
    keys = list(samples)
    labels = [f"{c}w {'gen' if k == 'general' else 'DC'} {n}" for c, k, n in keys]
    axes[0].boxplot([samples[k][0] for k in keys], showfliers=True)
    axes[0].set_ylabel("orientation error (deg, modulo the nodal-plane swap)")
    axes[1].boxplot([samples[k][1] for k in keys], showfliers=True)
    axes[1].axhline(1.0, color="k", linestyle="--", linewidth=1)
    axes[1].set_ylabel("fitted / true potency d A")
    for axis in axes:
        axis.set_xticks(range(1, len(keys) + 1), labels, rotation=70, fontsize=7)
        axis.grid(alpha=0.3)
    figure.suptitle("Source inversion of the ref. Table 7.3/7.4 source against amplitude noise (ref. Table 7.5)")
    figure.savefig(path)


# ---------------------------------------------------------------------------------

def _fmt(pair):
    return f"{pair[0]:.2f} / {pair[1]:.2f}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", choices=("2d", "3d", "both"), default="both")
    parser.add_argument("--draws", type=int, default=50)
    parser.add_argument("--quick", action="store_true", help="small sizes (smoke test)")
    parser.add_argument("--skip-inversion", action="store_true")
    parser.add_argument("--reuse", action="store_true",
                        help="read the 2D run in OUT and the cached 3D state instead of running them again")
    parser.add_argument("--out", default=os.path.join(HERE, "out"))
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    figures = args.out if args.quick else HERE  # a smoke test leaves the recorded pictures alone
    print(machine(), f"load at start {_load():.2f}", flush=True)
    results = dict(machine=machine(), load_start=_load())

    speed = forward_speed(2_000 if args.quick else 100_000)
    results["forward_speed"] = speed
    print(markdown_table(["events x receivers", "forward wall / CPU (s)", "noise (s)", "locate (s)", "Brune (s)",
                          "Brune true-factor error", "noise-free location error (m)"],
                         [[f"{speed['events']:,} x {speed['receivers']}", _fmt(speed["forward"]), _fmt(speed["noise"]),
                           _fmt(speed["locate"]), _fmt(speed["brune"]), f"{speed['brune_true_error']:.1e}",
                           f"{speed['location_noise_free_error']:.1e}"]]), flush=True)

    runs = {}
    if args.runs in ("2d", "both"):
        runs["2D dfn-3cluster"] = run_2d(os.path.join(args.out, "microseismic-dfn-3cluster"), args.quick,
                                         args.reuse)
    if args.runs in ("3d", "both"):
        cache = os.path.join(args.out, f"microseismic-3d-state{'-quick' if args.quick else ''}.npz")
        runs["3D bench_dfn"] = run_3d(args.quick, cache, args.reuse)
    studies, run_rows = {}, []
    for label, (run, clock) in runs.items():
        tag = "2d" if label.startswith("2D") else "3d"
        with Clock() as events_clock:
            events = catalogue.events_from_run(run, MEDIUM)
        failed = int(np.count_nonzero(run.state == 2))
        print(f"# {label}: run {clock.wall:.0f} s wall ({clock.cpu:.0f} s CPU); {failed} failed/activated natural "
              f"elements, {len(events)} shear events (Eq. 7.29) in {events_clock.wall:.2f} s", flush=True)
        if len(events) == 0:
            continue
        iso, dc, clvd = events.decomposition()
        run_rows.append([label, f"{clock.wall:.0f} / {clock.cpu:.0f}", failed, len(events),
                         f"{events.moment_magnitude.min():.2f} to {events.moment_magnitude.max():.2f}",
                         f"{np.median(dc):.2f}", f"{np.unique(events.time).size}"])
        plot_maps(run, events, os.path.join(figures, f"microseismic_maps_{tag}.png"),
                  f"{label}: {len(events)} events located from S-P time and direction (ref. Figs 7.6, 7.9, 7.10)")
        results[f"brune_{tag}"] = plot_brune(events, os.path.join(figures, f"microseismic_brune_{tag}.png"),
                                             f"{label}: Brune's equation, one well (ref. Figs 7.7-7.8)")
        studies[label] = location_study(run, events, 5 if args.quick else args.draws)
        results[f"location_{tag}"] = studies[label]
        print(markdown_table(["wells", "noise", "draws", "location error, Eq. 7.25 (m)",
                              "strike error median / p90 (deg)",
                              "traces found", "wall / CPU per draw (ms)"],
                             [[r["wells"], r["noise"], r["draws"], f"{r['error_mean']:.2f} ± {r['error_std']:.2f}",
                               "-" if r["strike_median"] is None
                               else f"{r['strike_median']:.1f} / {r['strike_p90']:.1f}",
                               f"{r['traces']:.1f}", f"{1e3 * r['wall']:.1f} / {1e3 * r['cpu']:.1f}"]
                              for r in studies[label]]), flush=True)
    if run_rows:
        print(markdown_table(["run", "wall / CPU (s)", "failed natural elements", "shear events", "Mw",
                              "median DC share", "distinct onset times"], run_rows))
    if studies:
        plot_location_errors(studies, os.path.join(figures, "microseismic_location_error.png"))

    if not args.skip_inversion:
        rows, samples = inversion_study(3 if args.quick else args.draws)
        results["inversion"] = rows
        print(markdown_table(["wells", "source", "amplitude noise", "draws", "orientation error median / p90 (deg)",
                              "within 5 deg", "potency / true: median [p5, p95]", "wall / CPU per inversion (s)"],
                             [[r["wells"], r["constraint"], r["noise"], r["draws"],
                               f"{r['angle_median']:.2f} / {r['angle_p90']:.2f}", f"{100 * r['within_5deg']:.0f}%",
                               f"{r['potency_median']:.3f} [{r['potency_p5']:.3f}, {r['potency_p95']:.3f}]",
                               f"{r['wall']:.2f} / {r['cpu']:.2f}"] for r in rows]))
        plot_inversion(samples, os.path.join(figures, "microseismic_source_inversion.png"))
    results["load_end"] = _load()
    path = os.path.join(args.out, "microseismic.json")
    if args.reuse and os.path.isfile(path):  # keep the parts this run did not redo
        with open(path) as handle:
            results = {**json.load(handle), **results}
    with open(path, "w") as handle:
        json.dump(results, handle, indent=1, default=float)
    print(f"load at end {_load():.2f}")


if __name__ == "__main__":
    main()
