"""The completion stage of issue 35 (the embedded scene `stage`: five clusters on one pump, a
three-layer stack (stiffer, more stressed bounding layers), a natural-fracture network, microseismic monitoring): time, memory,
iterations and the rate split of the scene as embedded, its limited-entry and uniform-rock
variants, and a larger version (>= 5x the elements).

    python benchmarks/bench_stage.py              # the three variants of the scene (~8 min)
    python benchmarks/bench_stage.py --large      # the larger version only (1 m elements)
    python benchmarks/bench_stage.py --only large-stiff --end 90   # the larger version, stiff layers
    python benchmarks/bench_stage.py --dense      # open and limited with the dense operator (~15 min)
    python benchmarks/bench_stage.py --end 30     # a shorter pump time
    python benchmarks/bench_stage.py --only open,stress-only   # chosen variants

Each run is a fresh process (its own peak memory, a warm numba cache). Columns: CPU and wall
seconds, peak resident memory, steps, elements at the end (hydraulic and joined natural),
nonlinear and GMRES iterations summed over the steps, each cluster's share of the pump rate at
the end, the perforation friction's range, the middle (third) fracture's length and height,
the worst fluid-budget residual over the fluid moved (the error beside the time) and the
microseismic events.

Variants: `open` is the scene as embedded (24 perforations of 8 mm per cluster: kPa of
perforation friction; bounding layers stiffer and 3 MPa more stressed than the pay zone);
`limited` sets well.perforations = 1 (MPa: limited entry); `uniform` is `limited` with the
bounding layers' s_hmin and shear modulus equal to the pay zone's (uniform rock: the
containment check); `stress-only` and `limited-stress-only` give the bounding layers the pay
zone's modulus and keep their stress (the scene before its stiff layers); `large` is
`limited-stress-only` with 1 m elements for the initial fractures and the network (4x the
elements per area, twice the rows over the height; 983 s of CPU to 90 s); `large-stiff` is
`limited` with those 1 m elements and the scene's stiff bounding layers (the remote-failure
check keeps each element's layered stress at the ~8300 natural targets, 2.5 GB; 2063 elements
in 2159 s of CPU and 3.5 GB to 90 s at dgemm 49 GFLOP/s: benchmarks/RESULTS.md, issue 35);
`-dense` runs use the dense operator instead of the scene's H-matrix.
"""
import argparse
import json
import multiprocessing
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from _common import machine, peak_rss_bytes, print_table  # noqa: E402

LIMITED = ["well.perforations=1"]
#: uniform rock: the bounding layers with the pay zone's stress and moduli
UNIFORM = LIMITED + ["layer[0].s_hmin=35.85e6", "layer[2].s_hmin=35.85e6", "layer[0].shear_modulus=6.62e9",
                     "layer[2].shear_modulus=6.62e9"]
#: the bounding layers with the pay zone's moduli, their stress kept (the scene before issue 35's stiff layers)
STRESS_ONLY = ["layer[0].shear_modulus=6.62e9", "layer[2].shear_modulus=6.62e9"]
LARGE = LIMITED + STRESS_ONLY + [f"initial_fracture[{k}].element_size=1.0" for k in range(5)] + [
    "network.element_size=1.0"]
#: the larger version with the scene's stiff bounding layers
LARGE_STIFF = LIMITED + [f"initial_fracture[{k}].element_size=1.0" for k in range(5)] + ["network.element_size=1.0"]
DENSE = ["numerics.backend=dense"]
VARIANTS = {"open": [], "limited": LIMITED, "uniform": UNIFORM, "large": LARGE, "large-stiff": LARGE_STIFF,
            "open-dense": DENSE,
            "limited-dense": LIMITED + DENSE, "stress-only": STRESS_ONLY,
            "limited-stress-only": LIMITED + STRESS_ONLY}


def _run(name, overrides, end, queue):
    import hmatddm.scene as hs
    from hmatddm.app import runner
    from hmatddm.app.run_folder import latest_state
    from hmatddm.simulation.records import fluid_moved

    out = tempfile.mkdtemp(prefix=f"bench-stage-{name}-")
    scene = hs.load_scene("stage", overrides=overrides + [f"numerics.end_time={end}"])
    cpu, wall = time.process_time(), time.perf_counter()
    runner.run_scene(scene, out, quiet=True)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    steps = json.load(open(os.path.join(out, "summary.json")))["steps"]
    last = steps[-1]
    mesh, fields = latest_state(out)[:2]
    chosen = (mesh.fracture_id == 2) & (np.asarray(fields["state"]) == 0)
    corners = mesh.subset(np.flatnonzero(chosen)).corners()
    worst = max(abs(s["budget"]["residual"]) / fluid_moved(s["budget"]) for s in steps if "budget" in s
                and fluid_moved(s["budget"]) > 0)
    csv = os.path.join(out, "events.csv")  # (the catalogue reads the slip onset from the .vtu series)
    events = max(0, len(open(csv).read().splitlines()) - 1) if os.path.exists(csv) else 0
    queue.put(dict(name=name, cpu=cpu, wall=wall, rss=peak_rss_bytes(), steps=len(steps) - 1,
                   elements=last["n_elements"], nonlinear=sum(s["nonlinear_iterations"] for s in steps),
                   linear=sum(s["linear_iterations"] for s in steps),
                   share=[q / last["pump_rate"] for q in last["cluster_rates"]],
                   friction=(min(last["perforation_friction"]), max(last["perforation_friction"])),
                   length=float(np.ptp(corners[..., 1])), height=float(np.ptp(corners[..., 2])),
                   budget=worst, events=events, out=out))


def run(name, end):
    queue = multiprocessing.get_context("spawn").Queue()
    process = multiprocessing.get_context("spawn").Process(target=_run, args=(name, VARIANTS[name], end, queue))
    process.start()
    process.join()
    if process.exitcode != 0:
        raise RuntimeError(f"the {name} run failed (exit code {process.exitcode})")
    return queue.get()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--large", action="store_true", help="the larger version only")
    parser.add_argument("--dense", action="store_true", help="open and limited with the dense operator")
    parser.add_argument("--end", type=float, default=70.0, help="pump time, s (the scene's: 70)")
    parser.add_argument("--only", default=None, help="comma-separated variants (of: " + ", ".join(VARIANTS) + ")")
    args = parser.parse_args()
    print(f"Machine: {machine()}")
    names = ["large"] if args.large else ["open-dense", "limited-dense"] if args.dense else [
        "open", "limited", "uniform"]
    if args.only:
        names = args.only.split(",")
    rows = []
    for name in names:
        r = run(name, args.end)
        print(f"{name}: {json.dumps({k: v for k, v in r.items() if k != 'out'})}", flush=True)
        rows.append([name, f"{r['cpu']:.0f}", f"{r['wall']:.0f}", f"{r['rss'] / 2**20:.0f}", str(r["steps"]),
                     str(r["elements"]), str(r["nonlinear"]), str(r["linear"]),
                     " / ".join(f"{s:.2f}" for s in r["share"]),
                     f"{r['friction'][0] / 1e6:.3f}-{r['friction'][1] / 1e6:.3f}",
                     f"{r['length']:.0f} x {r['height']:.0f}", f"{r['budget']:.1e}", str(r["events"])])
    print_table(["run", "CPU s", "wall s", "peak MB", "steps", "elements", "nonlinear", "GMRES",
                 "share of the pump (clusters 0-4)", "perf. friction MPa", "middle L x H (m)", "budget", "events"],
                rows)


if __name__ == "__main__":
    main()
