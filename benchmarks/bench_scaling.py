"""The whole simulation at growing sizes: cost against elements, with the error beside it.

    python benchmarks/bench_scaling.py                           # radial-k at h = 1, 0.5, 0.25 m
    python benchmarks/bench_scaling.py --scenes radial-k,radial-m --sizes 1,0.5,0.25,0.125
    python benchmarks/bench_scaling.py --steps fixed,auto        # both step rules, side by side
    python benchmarks/bench_scaling.py --compare ../previous     # and another source tree, run by run
    python benchmarks/bench_scaling.py --sizes "" --steps fixed --dfn-areas 1,4   # the network at 1x, 4x area
    python benchmarks/bench_scaling.py --sizes "" --steps fixed --dfn-areas 1,4 --schur-accuracy 1e-3  # both families

Each row is one ``hmatddm run SCENE --set initial_fracture[0].element_size=h`` in a child
process (its own CPU time and peak memory), with fixed 1 s steps or front-following steps
(``numerics.time_step = "auto"``, hmatddm/simulation/step_control.py). It prints the final
elements, steps, growth passes, nonlinear and GMRES iterations, elasticity products
(matvecs, all and per step), operator builds, wall and
CPU time, peak memory and the errors against the scene's closed form at the end, then the
cost exponent between consecutive sizes (log CPU ratio over log elements ratio), and saves
a plot of CPU time against elements (``benchmarks/scaling.png``).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

_RUN = """
import os
import sys
if os.environ.get("BENCH_SCHUR_ACCURACY"):  # --schur-accuracy: the kept Schur LU's refinement target
    from hmatddm.coupled.scaled_system import SchurFactor
    SchurFactor.ACCURACY = float(os.environ["BENCH_SCHUR_ACCURACY"])
from hmatddm.app.cli import main
sys.exit(main(sys.argv[1:]))
"""


def run(scene, h, steps, folder, source=ROOT, label="this", extra=(), schur_accuracy=None):
    """One run in a child process (the package of the source tree ``source``): its
    summary totals, wall and CPU time, peak memory."""
    out = os.path.join(folder, f"{label}-{os.path.basename(scene)}-{h}-{steps}-{len(os.listdir(folder))}")
    arguments = ["run", scene, "--out", out, "--quiet"]
    if h is not None:
        arguments += ["--set", f"initial_fracture[0].element_size={h}"]
    if steps == "auto":
        arguments += ["--set", "numerics.time_step=auto"]
    for setting in extra:
        arguments += ["--set", setting]
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join([source, os.environ.get("PYTHONPATH", "")]),
                       BENCH_SCHUR_ACCURACY=schur_accuracy or "")
    start = time.perf_counter()
    # -P: not the working directory first on sys.path, so that PYTHONPATH picks the source tree
    child = subprocess.Popen([sys.executable, "-P", "-c", _RUN] + arguments, env=environment)
    _, status, usage = os.wait4(child.pid, 0)  # this child's own CPU time and peak memory
    child.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - start
    # exit 3: did not converge; its summary.json holds the steps up to the last converged one,
    # reported as a failed row (the run's CPU is still its cost so far)
    if child.returncode != 0 and not (child.returncode == 3 and os.path.exists(os.path.join(out, "summary.json"))):
        raise RuntimeError(f"hmatddm {' '.join(arguments)} exited {child.returncode}")
    summary = json.load(open(os.path.join(out, "summary.json")))
    records = [record for record in summary["steps"] if record["step"] > 0]  # step 0: the initial state

    def total(key):
        return sum(record.get(key) or 0 for record in records)

    error = summary["reference"][-1]["relative_error"] if summary.get("reference") else {}
    return dict(version=label, scene=scene, h=h, steps=steps, elements=records[-1]["n_elements"], n_steps=len(records),
                passes=total("growth_passes"), nonlinear=total("nonlinear_iterations"),
                gmres=total("linear_iterations"), matvecs=total("matvecs"), builds=total("operator_builds"), wall=wall,
                cpu=usage.ru_utime + usage.ru_stime, peak_mb=usage.ru_maxrss / 1024.0, error=error,
                failed=None if child.returncode == 0 else f"no convergence after t = {records[-1]['time']:g} s")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="radial-k")
    parser.add_argument("--sizes", default="1,0.5,0.25", help="element sizes h (m)")
    parser.add_argument("--steps", default="fixed,auto", help="step rules: fixed, auto or both")
    parser.add_argument("--plot", default=os.path.join(HERE, "scaling.png"))
    parser.add_argument("--dfn-areas", default="", metavar="A,B,...",
                        help="also run dfn-3cluster with its network region scaled to these multiples of its area "
                             "and its injection lengthened so that the fractures span the same share of it "
                             "(end time x area^0.75: plane-strain length ~ t^(2/3))")
    parser.add_argument("--schur-accuracy", default="", metavar="A,B,...",
                        help="also run the network with the kept Schur LU refined to these fractions of the solve's "
                             "tolerance (SchurFactor.ACCURACY, default 1e-2): a round-off-level change that moves the "
                             "4x run between its two families of answers (benchmarks/RESULTS.md, issue 33)")
    parser.add_argument("--compare", default=None, metavar="DIR",
                        help="also run the package of another source tree (e.g. a git worktree of the previous "
                             "version) in the same session, row by row")
    args = parser.parse_args()
    sources = [("this", ROOT)] + ([("previous", os.path.abspath(args.compare))] if args.compare else [])
    sys.path.insert(0, HERE)
    from _common import machine, print_table

    print(f"Machine: {machine()}", flush=True)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for label, source in sources:  # compile (or load the numba cache) before anything is timed
            run(args.scenes.split(",")[0], 1.0, "fixed", folder, source, f"warm-{label}", ["numerics.end_time=2"])
        for scene in args.scenes.split(","):
            for h in [float(s) for s in args.sizes.split(",") if s]:
                for steps in args.steps.split(","):
                    for label, source in sources:
                        rows.append(run(scene, h, steps, folder, source, label))
                        print(rows[-1], flush=True)
        for area in [float(a) for a in args.dfn_areas.split(",") if a]:
            side = math.sqrt(area)
            extra = [f"network.region=[{-50 * side}, {50 * side}, {-100 * side}, {100 * side}]",
                     f"numerics.end_time={70.0 * area ** 0.75:.6g}"]
            for steps in args.steps.split(","):
                for accuracy in [None] + [a for a in args.schur_accuracy.split(",") if a]:
                    for label, source in sources:
                        version = label if accuracy is None else f"{label} (Schur {accuracy})"
                        rows.append(dict(run("dfn-3cluster", None, steps, folder, source, version, extra, accuracy),
                                         area=area))
                        print(rows[-1], flush=True)
    header = ["version", "scene", "h (m)", "steps rule", "elements", "steps", "growth passes", "nonlinear its", "GMRES its",
              "matvecs", "matvecs/step", "builds", "wall (s)", "CPU (s)", "peak RSS (MB)", "R error", "w0 error", "p error",
              "CPU exponent vs previous h"]
    body = []
    for row in rows:
        previous = [r for r in rows if r["version"] == row["version"] and r["scene"] == row["scene"]
                    and r["steps"] == row["steps"] and r["elements"] < row["elements"]]
        if "area" in row:  # the network runs: cost against area, the first area the baseline
            first = [r for r in rows if r.get("area") and r["version"] == row["version"] and r["steps"] == row["steps"]]
            previous = [first[0]] if first[0] is not row else []
        exponent = ""
        if previous:
            p = max(previous, key=lambda r: r["elements"])
            exponent = f"{math.log(row['cpu'] / p['cpu']) / math.log(row['elements'] / p['elements']):.2f}"
            if "area" in row:
                exponent += f" ({row['cpu'] / p['cpu']:.1f}x CPU for {row['area'] / p['area']:g}x area)"
        error = row["error"]
        size = f"{row['h']:g}" if row["h"] is not None else f"area x{row['area']:g}"
        if row["failed"]:
            size += f" (FAILED: {row['failed']})"
        body.append([row["version"], row["scene"], size, row["steps"], row["elements"], row["n_steps"], row["passes"],
                     row["nonlinear"], row["gmres"], row["matvecs"], f"{row['matvecs'] / row['n_steps']:.0f}",
                     row["builds"], f"{row['wall']:.1f}", f"{row['cpu']:.1f}",
                     f"{row['peak_mb']:.0f}"] + [f"{100 * error[k]:+.2f}%" if k in error else "-"
                                                for k in ("radius", "max_opening", "net_pressure")] + [exponent])
    print_table(header, body)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    figure, axes = plt.subplots(figsize=(6, 4))
    for scene in args.scenes.split(","):
        for steps in args.steps.split(","):
            for label, _ in sources:
                chosen = [r for r in rows if r["scene"] == scene and r["steps"] == steps and r["version"] == label
                          and "area" not in r]
                axes.loglog([r["elements"] for r in chosen], [r["cpu"] for r in chosen], "o-",
                            label=f"{scene}, {steps}" + (f" ({label})" if len(sources) > 1 else ""))
    axes.set_xlabel("elements at the end")
    axes.set_ylabel("CPU time of the whole run (s)")
    axes.legend()
    axes.grid(True, which="both", alpha=0.3)
    figure.tight_layout()
    figure.savefig(args.plot, dpi=120)
    print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
