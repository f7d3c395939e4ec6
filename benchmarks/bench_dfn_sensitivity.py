"""The sensitivities of ref. Ch. 6 (Figs 6.10-6.14) at the reference's discretisation: the
three-cluster DFN scene of ``bench_dfn.py`` (Tables 6.1-6.2, 70 s) with its fractures one
1 m square element tall, as the reference meshed them ("elements are square, and their edge
length is 1 m"; "fractures have only one element height", ref. Sec. 6.3), and each case
changing one thing against the a = 2, rho_NF = 0.05 run:

* ``a=3``: length exponent 3 (fewer long fractures; ref. Sec. 6.4);
* ``no-remote``: natural fractures not connected to a hydraulic fracture may not fail
  (ref. Fig. 6.11 against 6.10);
* ``shmax-39.44``: S_Hmax = 39.44 MPa (ref. Fig. 6.12);
* ``rho-0.1``: the denser network (ref. Fig. 6.13);
* ``bimodal``: two sets at 45 and 135 degrees, kappa 5 each, weights 0.5 (ref. Fig. 6.14).

Per case: elements, natural elements activated (fluid-filled), remotely failed at the end
and at most, crossings and deflections over the run, branches (natural fractures that hold
fluid, each counted once), fluid volume in the hydraulic and in the natural elements, the
wellbore pressures at the end, CPU and wall time, and
``benchmarks/dfn_sensitivity_CASE.png`` (plan view as in ``bench_dfn.py``; CASE without its
``=``).

    PYTHONPATH=. python benchmarks/bench_dfn_sensitivity.py [CASE ...] [--end-time 70]
"""
import argparse
import json
import os
import sys
import time
from dataclasses import replace

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402
import bench_dfn  # noqa: E402  (sets OMP_WAIT_POLICY before numba loads)

REFERENCE_MESH = dict(elements_over_height=1, height=1.0)  # one 1 m square over the height (ref. Sec. 6.3)
CASES = {
    "a=2": {},
    "a=3": dict(length_exponent=3.0),
    "no-remote": dict(remote_failure=False),
    "shmax-39.44": dict(s_hmax=39.44e6),
    "rho-0.1": dict(density=0.1),
    "bimodal": dict(mean_azimuths_deg=(45.0, 135.0), kappas=(5.0, 5.0), weights=(0.5, 0.5)),
}


def volumes(sim):
    """Fluid volume (m^3) in the hydraulic and in the natural elements (opening x area,
    closed elements counted as zero)."""
    state = sim.state
    opening = np.clip(np.einsum("ij,ij->i", state.dd, state.mesh.normals), 0.0, None) * state.mesh.areas
    natural = state.origin != 0
    return float(opening[~natural].sum()), float(opening[natural].sum())


def branches(sim):
    """Natural fractures (of the generated network) with at least one fluid-filled element."""
    state = sim.state
    filled = state.natural_index[(state.origin == 1) & (state.natural_index >= 0)]
    return int(np.unique(sim.network.mesh.fracture_id[filled]).size)


def run_case(name, end_time):
    """One case with Table 6.2's fixed 1 s steps; where that stops without converging, the
    case again with front-following steps (``time_step = "auto"``: a step that does not
    converge is retried at half its length), and the first stop named in ``error``."""
    scene = replace(bench_dfn.FULL, **REFERENCE_MESH, **CASES[name])
    cpu, wall = time.process_time(), time.perf_counter()
    sim, rows, error = bench_dfn.run(scene, end_time=end_time, verbose=False)
    steps = "1 s"
    if error is not None:
        sim, rows, second = bench_dfn.run(replace(scene, time_step="auto"), end_time=end_time, verbose=False)
        error, steps = f"1 s steps stopped at {error}" + (f"; auto: {second}" if second else ""), "auto"
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    hydraulic, natural = volumes(sim)
    bench_dfn.plot_plan(sim, os.path.join(HERE, f"dfn_sensitivity_{name.replace('=', '')}.png"), title=f"{name}, t = "
                        f"{sim.state.time:g} s, one 1 m element over the height")
    last = rows[-1] if rows else {}
    return dict(case=name, steps=steps, time=float(sim.state.time), elements=int(sim.state.mesh.n_elements),
                natural_elements=int(sim.network.mesh.n_elements), activated=last.get("natural_active", 0),
                failed_end=last.get("natural_failed", 0), failed_max=max((r["natural_failed"] for r in rows), default=0),
                crossed=sum(r["natural_crossed"] for r in rows), deflected=sum(r["natural_deflected"] for r in rows),
                branches=branches(sim), volume_hydraulic=hydraulic, volume_natural=natural,
                wellbore_pressure=last.get("wellbore_pressure"), nonlinear=sum(r["nonlinear_iterations"] for r in rows),
                gmres=sum(r["linear_iterations"] for r in rows), cpu=cpu, wall=wall, error=error)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", default=list(CASES), help=f"some of {', '.join(CASES)} (default all)")
    parser.add_argument("--end-time", type=float, default=70.0)
    parser.add_argument("--json", default=os.path.join(HERE, "out", "dfn_sensitivity.json"))
    args = parser.parse_args()
    unknown = [name for name in args.cases if name not in CASES]
    if unknown:
        parser.error(f"unknown case {unknown[0]!r}; cases: {', '.join(CASES)}")
    print(f"Machine at the start: {machine()}", flush=True)
    results = []
    for name in args.cases:
        result = run_case(name, args.end_time)
        results.append(result)
        print(json.dumps(result), flush=True)
        os.makedirs(os.path.dirname(args.json), exist_ok=True)
        with open(args.json, "w") as handle:
            json.dump(results, handle, indent=1)
    rows = [[r["case"], r["steps"], f"{r['time']:g}", r["elements"], r["natural_elements"], r["activated"], r["failed_end"],
             r["failed_max"], r["crossed"], r["deflected"], r["branches"], f"{r['volume_hydraulic']:.3f}",
             f"{r['volume_natural']:.3f}", r["nonlinear"], r["gmres"], f"{r['cpu']:.0f}", f"{r['wall']:.0f}",
             r["error"] or ""] for r in results]
    print_table(["case", "time steps", "t (s)", "active elements", "natural elements", "activated", "failed (end)",
                 "failed (max)", "crossed", "deflected", "branches", "V hydraulic (m^3)", "V natural (m^3)",
                 "nonlinear its", "GMRES its", "CPU (s)", "wall (s)", "stopped"], rows)
    print(f"Machine at the end: {machine()}")


if __name__ == "__main__":
    main()
