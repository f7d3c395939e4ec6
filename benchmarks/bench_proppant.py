"""Proppant transport in the time loop (issue 34): the cost of proppant-laden runs against the
clean (Newtonian) ones, and the embedded scene `proppant`'s mass pumped and in place.

    python benchmarks/bench_proppant.py            # both parts (about a minute, one thread)
    python benchmarks/bench_proppant.py --cost     # the cost table only
    python benchmarks/bench_proppant.py --scene    # the scene part only

Cost: two set-ups, each run clean and with the slurry of the `proppant` scene's schedule
(pad 5 s, then 0.1 / 0.2 / 0.3 volume fraction of 200 um sand, bridging at 2 grain diameters):

* the `proppant` scene: vertical fracture, 20 cP, element front, dense operator, 1 s steps to 30 s;
* ref. Table 4.1's radial set-up of bench_power_law.py (horizontal fracture, 1 cP, K_Ic 0.3
  MPa m^1/2, asymptotic front, H-matrix operator, 1 s steps to 12 s); 1 cP gives openings of
  ~0.4 mm, so this one uses 100 um sand (bridging below 0.2 mm).

Columns: CPU and wall time of the run, of it in the proppant transport (the operator split
after each step's solve), nonlinear and GMRES iterations, transport sub-steps, the final size
and the mass balance's worst relative residual |pumped - in place - screened| / pumped (the
error beside the time). Scene: the masses every 5 s; snapshots copied to
proppant_scene_mass.png and proppant_scene_fraction.png.
"""
import argparse
import json
import os
import shutil
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from _common import machine, print_table  # noqa: E402

import hmatddm as hd  # noqa: E402
import hmatddm.scene as hs  # noqa: E402
from hmatddm.flow import Proppant, PumpSchedule  # noqa: E402
from hmatddm.simulation import proppant_step  # noqa: E402

OUT = os.path.dirname(os.path.abspath(__file__))
SCHEDULE = PumpSchedule((0.0, 5.0, 15.0, 22.0), (0.0, 0.1, 0.2, 0.3))


class TransportClock:
    """CPU and wall seconds spent in proppant_step.advance (wrapped while a run lasts)."""

    def __init__(self):
        self.cpu = self.wall = 0.0
        self.original = proppant_step.advance

    def __enter__(self):
        def timed(*args, **kwargs):
            cpu, wall = time.process_time(), time.perf_counter()
            try:
                return self.original(*args, **kwargs)
            finally:
                self.cpu += time.process_time() - cpu
                self.wall += time.perf_counter() - wall

        proppant_step.advance = timed
        return self

    def __exit__(self, *exc):
        proppant_step.advance = self.original


def scene_simulation(slurry):
    scene = hs.load_scene("proppant").data
    if not slurry:
        scene.pop("proppant")
    return hs.build_simulation(scene), scene["numerics"]["end_time"]


def radial_simulation(slurry):
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 3)
    extra = dict(proppant=Proppant(diameter=1e-4, bridging_factor=2.0), pump_schedule=SCHEDULE) if slurry else {}
    sim = hd.Simulation(mesh, hd.Elastic(24e9, 0.25), hd.Fluid(1e-3, 4.4e-10), [hd.Cluster((0, 0, 0), 0.01, 0.005)],
                        far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                        propagation=hd.Propagation(toughness=0.3e6, front="asymptotic"),
                        initial_pressure=10e6, initial_opening=4e-6, backend="hmatrix", **extra)
    return sim, 12.0


def cost_part():
    rows = []
    for name, build in (("proppant scene (vertical, element front, dense, 30 s)", scene_simulation),
                        ("radial Table 4.1 (asymptotic front, H-matrix, 12 s)", radial_simulation)):
        for slurry in (False, True):
            sim, end = build(slurry)
            with TransportClock() as clock:
                cpu, wall = time.process_time(), time.perf_counter()
                records = sim.run(end)
                cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
            last = records[-1]
            size = last.get("radius")
            balance, substeps = "-", "-"
            if slurry:
                worst = max(abs(r["proppant_residual"]) / r["proppant_injected_mass"] for r in records
                            if r["proppant_injected_mass"] > 0.0)
                balance = f"{worst:.1e}"
                substeps = sum(r["proppant_substeps"] for r in records)
            rows.append([name, "slurry" if slurry else "clean", len(records), last["n_elements"],
                         sum(r["nonlinear_iterations"] for r in records), sum(r["linear_iterations"] for r in records),
                         f"{cpu:.2f}", f"{wall:.2f}", f"{clock.cpu:.2f}" if slurry else "-", substeps,
                         f"{size:.2f}", f"{last['max_opening'] * 1e3:.3f}",
                         f"{last.get('proppant_mass', 0.0):.1f}" if slurry else "-", balance])
    print_table(["set-up", "fluid", "steps", "elements", "nonlinear its", "GMRES its", "CPU (s)", "wall (s)",
                 "transport CPU (s)", "transport sub-steps", "radius (m)", "max opening (mm)", "proppant in place (kg)",
                 "worst mass residual / pumped"], rows)


def scene_part():
    folder = tempfile.mkdtemp(prefix="bench-proppant-")
    try:
        cpu, wall = time.process_time(), time.perf_counter()
        from hmatddm.app import runner

        runner.run_scene(hs.load_scene("proppant"), folder, quiet=True)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        steps = json.load(open(os.path.join(folder, "summary.json")))["steps"]
        rows = []
        for step in steps:
            if step["step"] % 5 == 0:
                pumped = step["proppant_injected_mass"]
                rows.append([f"{step['time']:g}", step["n_elements"], f"{step['radius']:.2f}", f"{pumped:.3f}",
                             f"{step['proppant_mass']:.3f}", f"{step['proppant_screened_mass']:.3f}",
                             f"{step['max_proppant_fraction']:.3f}", step["propped_elements"],
                             f"{abs(step['proppant_residual']) / pumped:.1e}" if pumped > 0 else "-"])
        print(f"\nscene `proppant` into a folder (every output, pictures included): CPU {cpu:.2f} s, wall {wall:.2f} s")
        print_table(["t (s)", "elements", "radius (m)", "pumped (kg)", "in place (kg)", "screened (kg)",
                     "max fraction", "elements with proppant", "|residual| / pumped"], rows)
        last = steps[-1]["step"]
        shutil.copy(os.path.join(folder, "proppant_history.png"), os.path.join(OUT, "proppant_scene_mass.png"))
        shutil.copy(os.path.join(folder, "snapshots", f"step-{last:06d}_proppant.png"),
                    os.path.join(OUT, "proppant_scene_fraction.png"))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cost", action="store_true")
    parser.add_argument("--scene", action="store_true")
    args = parser.parse_args()
    print(f"Calibration at the start: {machine()}")
    warm, _ = scene_simulation(True)
    warm.run(7.0)  # compiled code warm before the first timed run
    both = not (args.cost or args.scene)
    if args.cost or both:
        cost_part()
    if args.scene or both:
        scene_part()


if __name__ == "__main__":
    main()
