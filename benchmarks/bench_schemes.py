"""Coupling schemes of the flow-elasticity system (ref. Sec. 4.4, 4.6; Table 4.2, Figs 4.10-4.16).

    python benchmarks/bench_schemes.py            # full study (about 7 min, one thread)
    python benchmarks/bench_schemes.py --quick    # 2D to 12 s, fewer runs, no 3D runs (about a minute)
    python benchmarks/bench_schemes.py --case '{"scheme": "krylov", "omega": 1, "backend": "dense", "t_end": 30}'

Studies, printed as markdown tables and saved (JSON in benchmarks/out/, PNG in benchmarks/):

1. 2D (plane strain) propagation of ref. Table 4.2: initial crack 3 m of 1 m elements along
   x, flow height 1 m, G 10 GPa, nu 0.25, S_hmin 0.5 MPa (far_field_stress diag(0, -0.5e6)),
   mu 1 cP, c_f 4.5e-4 1/MPa, Q 5e-4 m^3/s, wellbore 0.5 m^3, p_0 1 MPa, w_0 0.1 mm,
   dt 1 s. K_Ic is not given in the reference: 1 MPa m^1/2 here. Every scheme ("fixed-width",
   "fracture-compliance" with omega 0, 0.5, 1, "fully-coupled", "krylov") on both backends,
   with max_iterations 3000 and min_relaxation 1/1024: per step the relaxation factor the
   step converged with (the engine carries it to the next step, as ref. Fig. 4.10), the
   nonlinear and linear (GMRES) iterations, and the wall time of the whole run. A scheme
   that raises ConvergenceError is recorded with its step, time and last relaxation.
   The segregated schemes are also run with the engine's early-abort test ("the changes
   grew for 5 iterations in a row") switched off in that process only (marked
   "no early abort"): this shows whether a failure is the scheme or that test.
2. Condition numbers (ref. Fig. 4.13) of the coupled matrix [[A, B], [C, D]] unscaled, right
   scaled (A M_2) and scaled (M_1^-1 A M_2, ref. Eqs 4.53-4.61), and of the scaled matrix
   preconditioned by the compliance split of the "krylov" scheme, for the initial 2D state,
   the 2D crack at t_end, and a 3D radial crack.
3. 3D radial K case of ref. Table 4.1 (hmatrix; h = 1.5 m to 30 s, 1 m and 0.75 m to 50 s):
   "fully-coupled" against "krylov" (iterations and time at larger N).

Plot: schemes_relaxation.png (relaxation, nonlinear and linear iterations per step, time
ratios as in ref. Fig. 4.16).
"""
import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out")
sys.path.insert(0, HERE)

MIN_RELAXATION = 1.0 / 1024.0
MAX_ITERATIONS = 3000
# (label, scheme, omega)
SCHEMES_2D = [("fixed-width", "fixed-width", 0.0), ("compliance, omega 0", "fracture-compliance", 0.0),
              ("compliance, omega 0.5", "fracture-compliance", 0.5),
              ("compliance, omega 1", "fracture-compliance", 1.0), ("fully-coupled", "fully-coupled", 1.0),
              ("krylov", "krylov", 1.0)]
SEGREGATED = ("fixed-width", "fracture-compliance")


def simulation_2d(scheme, omega, backend):
    import hmatddm as hd

    settings = hd.SchemeSettings(scheme=scheme, omega=omega, max_iterations=MAX_ITERATIONS,
                                 min_relaxation=MIN_RELAXATION)
    mesh = hd.mesh.line([-1.5, 0.0], [1.5, 0.0], 3)
    return hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(viscosity=1e-3, compressibility=4.5e-10),
                         [hd.Cluster((0.0, 0.0), rate=5e-4, wellbore_volume=0.5)],
                         far_field_stress=np.diag([0.0, -0.5e6]), time_step=1.0,
                         propagation=hd.Propagation(toughness=1e6), initial_pressure=1e6, initial_opening=1e-4,
                         height=1.0, backend=backend, scheme=settings)


def run_2d(scheme, omega, backend, t_end, early_abort=True):
    """One 2D run; returns the per-step history, the wall time and any failure."""
    import hmatddm as hd
    import hmatddm.coupled.schemes as schemes

    if not early_abort:
        # the only use of the builtin all() in schemes.py is the "changes grew for 5
        # iterations" test of solve_step; shadowing it there switches that test off
        schemes.all = lambda iterable: False
    start = time.perf_counter()
    sim = simulation_2d(scheme, omega, backend)
    failure = None
    try:
        sim.run(t_end)
    except hd.ConvergenceError as error:
        failure = dict(step=len(sim.records) + 1, time=sim.state.time + sim.time_step,
                       relaxation=float(str(error).split("down to relaxation ")[1].split(":")[0])
                       if "down to relaxation" in str(error) else None,
                       iterations_in_failed_step=error.iterations, message=str(error))
    wall = time.perf_counter() - start
    keys = ("time", "n_elements", "relaxation", "nonlinear_iterations", "linear_iterations", "solve_seconds",
            "half_length", "max_opening", "restarts")
    history = {k: [r[k] for r in sim.records] for k in keys}
    history["wellbore_pressure"] = [r["wellbore_pressure"][0] for r in sim.records]
    return dict(scheme=scheme, omega=omega, backend=backend, t_end=t_end, early_abort=early_abort, wall_s=wall,
                history=history, failure=failure)


# -- condition numbers (ref. Fig. 4.13) ------------------------------------------------------
def _step_problem(sim):
    """The StepProblem and flow matrix the next step's first iteration sees (dense A)."""
    import hmatddm as hd
    from hmatddm.mesh import topology
    from hmatddm.coupled import ElasticSolver, StepProblem
    from hmatddm.flow import fracture_compliance

    s = sim.state
    mesh = s.mesh
    edges = topology.element_edges(mesh, sim.height)
    faces = topology.element_faces(mesh, edges)
    flow = sim.flow_model(mesh, faces)
    op = hd.ElasticityOperator(mesh, sim.material, backend="dense")
    width = np.sum(s.dd * mesh.normals, axis=1)
    problem = StepProblem(elastic=ElasticSolver(op), normals=mesh.normals, far_field=sim.far_field_traction(mesh),
                          flow=flow, compliance=fracture_compliance(mesh, sim.material), dt=sim.time_step,
                          width_old=width, pressure_old=s.pressure,
                          leak_off_rate=flow.leak_off_rate(s.creation_time, s.time, s.time + sim.time_step))
    return problem, s.dd.ravel().copy(), s.pressure.copy()


def condition_numbers(sim, label):
    """cond of A, A M_2, M_1^-1 A M_2 and P^-1 M_1^-1 A M_2 (P: the krylov compliance split)."""
    from hmatddm.coupled.scaled_system import _CoupledLinearSystem

    problem, dd, p = _step_problem(sim)
    matrix, _ = problem.flow_matrices(dd)
    system = _CoupledLinearSystem(problem, matrix, dd, p)
    n, d = problem.n, problem.d
    a = problem.elastic.operator.to_dense()
    b = np.zeros((n * d, n))
    for i in range(n):
        b[d * i:d * i + d, i] = problem.normals[i]
    full = np.block([[a, b], [problem.coupling.toarray(), matrix.toarray()]])
    m2 = np.concatenate([np.full(n * d, system.s_u), np.full(n, system.s_p)])
    eye = np.eye(full.shape[0])
    scaled = np.column_stack([system.operator @ e for e in eye])
    precond = system.compliance_preconditioner(1.0)
    preconditioned = np.column_stack([precond @ (system.operator @ e) for e in eye])
    return dict(label=label, n_elements=n, unknowns=full.shape[0], s_u=system.s_u, s_p=system.s_p,
                cond_a=float(np.linalg.cond(full)), cond_right=float(np.linalg.cond(full * m2[None, :])),
                cond_scaled=float(np.linalg.cond(scaled)), cond_krylov=float(np.linalg.cond(preconditioned)))


def conditioning_study(t_end_2d, radial_h, radial_t):
    import hmatddm as hd

    rows = []
    sim = simulation_2d("krylov", 1.0, "dense")
    rows.append(condition_numbers(sim, "2D, initial state (ref. Fig. 4.13)"))
    sim.run(t_end_2d)
    rows.append(condition_numbers(sim, f"2D, t = {t_end_2d:g} s"))
    import bench_radial as br

    params = br.CASES["K"]
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3 * radial_h, 3 * radial_h, 3, 3)
    sim = hd.Simulation(mesh, hd.Elastic(br.SHEAR_MODULUS, br.POISSON), hd.Fluid(params["viscosity"],
                                                                                 br.COMPRESSIBILITY),
                        [hd.Cluster((0, 0, 0), br.RATE, br.WELLBORE)], far_field_stress=np.diag([0, 0, -br.S_HMIN]),
                        time_step=1.0, propagation=hd.Propagation(toughness=params["toughness"]),
                        initial_pressure=br.INITIAL_PRESSURE, initial_opening=params["initial_opening"],
                        backend="hmatrix")
    rows.append(condition_numbers(sim, f"3D radial K, initial (h = {radial_h:g} m)"))
    sim.run(radial_t)
    rows.append(condition_numbers(sim, f"3D radial K, t = {radial_t:g} s"))
    return rows


# -- driver ---------------------------------------------------------------------------------
def spawn_2d(scheme, omega, backend, t_end, early_abort=True, threads=None):
    from bench_radial import measured_run

    spec = dict(scheme=scheme, omega=omega, backend=backend, t_end=t_end, early_abort=early_abort)
    print(f"  running {spec}", flush=True)
    row = measured_run([sys.executable, os.path.abspath(__file__), "--case", json.dumps(spec)], threads, 1800)
    if "history" not in row:
        return dict(spec, **row)
    f = row["failure"]
    print(f"    {row['wall_s']:.1f} s" + (f", FAILED at step {f['step']} (t = {f['time']:g} s)" if f else ""),
          flush=True)
    return row


def label_of(row):
    name = row["scheme"] if row["scheme"] != "fracture-compliance" else f"compliance, omega {row['omega']:g}"
    return name + ("" if row["early_abort"] else " (no early abort)")


def schemes_table(rows, reference_wall):
    from _common import markdown_table

    header = ["scheme", "backend", "outcome", "steps", "final elements", "relaxation (min)", "nonlinear its / step",
              "max nonlinear its", "linear its / step", "wall (s)", "time / fully-coupled",
              "max rel. p difference vs krylov"]
    body = []
    for r in rows:
        h = r.get("history")
        if not h or not h["time"]:
            body.append([label_of(r), r["backend"], "failed at step 1" if r.get("failure") else "error"]
                        + [""] * (len(header) - 3))
            continue
        f = r["failure"]
        outcome = "completed" if not f else f"ConvergenceError at step {f['step']} (t = {f['time']:g} s), " \
                                            f"down to relaxation {f['relaxation']:g}"
        its = np.array(h["nonlinear_iterations"])
        ref = reference_wall.get(r["backend"])
        ratio = "-" if (f or not ref) else f"{r['wall_s'] / ref:.2f}"
        body.append([label_of(r), r["backend"], outcome, len(h["time"]), h["n_elements"][-1],
                     f"{min(h['relaxation']):g}", f"{its.mean():.0f}", int(its.max()),
                     f"{np.mean(h['linear_iterations']):.0f}", f"{r['wall_s']:.2f}", ratio,
                     "-" if r.get("dp") is None else f"{r['dp']:.1e}"])
    return markdown_table(header, body)


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(15, 8))
    sel = [r for r in rows if r["backend"] == "dense" and r.get("history") and r["history"]["time"]]
    for i, r in enumerate(sel):
        h = r["history"]
        style = "-" if r["early_abort"] else "--"
        label = label_of(r) + (" [failed]" if r["failure"] else "")
        color = f"C{i % 10}"
        axes[0, 0].semilogy(h["time"], h["relaxation"], style, drawstyle="steps-post", color=color, label=label,
                            lw=2.5 if r["scheme"] == "fixed-width" else 1.5)
        axes[0, 1].semilogy(h["time"], h["nonlinear_iterations"], style, marker=".", color=color, label=label)
        if r["failure"]:
            f = r["failure"]
            axes[0, 0].plot([f["time"]], [f["relaxation"]], "x", color=color, ms=10, mew=2)
            if f.get("iterations_in_failed_step"):
                axes[0, 1].plot([f["time"]], [f["iterations_in_failed_step"]], "x", color=color, ms=10, mew=2)
        if r["scheme"] in ("fully-coupled", "krylov"):
            axes[1, 0].semilogy(h["time"], h["linear_iterations"], style, marker=".", color=color, label=label)
    axes[0, 0].set(xlabel="t (s)", ylabel="relaxation factor alpha", title="relaxation (ref. Figs 4.11, 4.14)")
    axes[0, 1].set(xlabel="t (s)", ylabel="nonlinear iterations per step",
                   title="iterations (ref. Figs 4.12, 4.15)")
    axes[1, 0].set(xlabel="t (s)", ylabel="GMRES iterations per step", title="linear iterations, coupled schemes")
    # time ratios (ref. Fig. 4.16), completed runs only
    done = [r for r in sel if not r["failure"]]
    ref = next((r["wall_s"] for r in done if r["scheme"] == "fully-coupled"), None)
    if ref:
        labels = [label_of(r).replace(" (no early abort)", "*") for r in done]
        axes[1, 1].bar(range(len(done)), [r["wall_s"] / ref for r in done], color="C0")
        axes[1, 1].set_xticks(range(len(done)), labels, rotation=30, ha="right", fontsize=8)
        axes[1, 1].axhline(1.0, color="k", lw=0.8)
        axes[1, 1].set(ylabel="wall time / fully-coupled", title="simulation time ratio (ref. Fig. 4.16), dense\n"
                                                                   "* = engine's early-abort test off")
    for ax in axes.flat[:3]:
        ax.grid(True, which="both", alpha=0.3)
    axes[1, 0].legend(fontsize=8)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="center right", fontsize=8, title="x: ConvergenceError (relaxation\n"
                                                                       "tried last, iterations spent)")
    fig.suptitle("Ref. Table 4.2 plane-strain propagation, dense backend")
    fig.tight_layout(rect=(0, 0, 0.78, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--case", help="one 2D run, JSON spec: scheme, omega, backend, t_end, early_abort")
    parser.add_argument("--t-end", type=float, default=None, help="2D end time (default 30 s, 12 s with --quick)")
    parser.add_argument("--threads", type=int, default=1,
                        help="NUMBA/BLAS threads of the child processes (default 1, see RESULTS.md)")
    parser.add_argument("--skip", default="", help="comma-separated: 2d, cond, 3d")
    args = parser.parse_args()
    if args.case:
        spec = json.loads(args.case)
        print(json.dumps(run_2d(spec["scheme"], float(spec["omega"]), spec["backend"], float(spec["t_end"]),
                                bool(spec.get("early_abort", True)))))
        return
    from _common import machine, markdown_table

    os.makedirs(OUT, exist_ok=True)
    skip = set(filter(None, args.skip.split(",")))
    t_end = args.t_end or (12.0 if args.quick else 30.0)
    suffix = "_quick" if args.quick else ""
    print(f"Machine: {machine()}")

    if "2d" not in skip:
        rows = []
        for backend in ("dense", "hmatrix"):
            for _, scheme, omega in SCHEMES_2D:
                if args.quick and backend == "hmatrix" and scheme in SEGREGATED and omega < 1.0:
                    continue  # slow (GMRES per segregated iteration) and failing anyway
                rows.append(spawn_2d(scheme, omega, backend, t_end, threads=args.threads))
        for _, scheme, omega in SCHEMES_2D:  # the segregated schemes without the early abort
            if scheme in SEGREGATED and not (scheme == "fracture-compliance" and omega == 0.0):
                if args.quick and scheme != "fixed-width":
                    continue
                rows.append(spawn_2d(scheme, omega, "dense", t_end, early_abort=False, threads=args.threads))
        # pressure agreement with krylov over the common steps (all schemes solve the same equations)
        for r in rows:
            ref = next((k for k in rows if k["scheme"] == "krylov" and k["backend"] == r["backend"]
                        and k.get("history")), None)
            if ref and r.get("history") and r["history"]["time"]:
                m = min(len(ref["history"]["time"]), len(r["history"]["time"]))
                a = np.array(r["history"]["wellbore_pressure"][:m])
                b = np.array(ref["history"]["wellbore_pressure"][:m])
                r["dp"] = float(np.max(np.abs(a - b) / b))
        with open(os.path.join(OUT, f"schemes_2d{suffix}.json"), "w") as f:
            json.dump(rows, f)
        reference_wall = {r["backend"]: r["wall_s"] for r in rows
                          if r["scheme"] == "fully-coupled" and r.get("history") and not r["failure"]}
        print(f"\n## Ref. Table 4.2 plane-strain propagation to {t_end:g} s (K_Ic 1 MPa m^1/2)\n")
        print(schemes_table(rows, reference_wall))
        plot(rows, os.path.join(HERE if not args.quick else OUT, "schemes_relaxation.png"))

    if "cond" not in skip:
        cond = conditioning_study(t_end, 1.5 if not args.quick else 2.0, 30.0 if not args.quick else 4.0)
        with open(os.path.join(OUT, f"schemes_cond{suffix}.json"), "w") as f:
            json.dump(cond, f)
        print("\n## Condition numbers of the coupled matrix (ref. Fig. 4.13)\n")
        print(markdown_table(["state", "elements", "unknowns", "s_u (m)", "s_p (Pa)", "cond A", "cond A M_2",
                              "cond M_1^-1 A M_2", "cond with compliance-split precond. (krylov)"],
                             [[c["label"], c["n_elements"], c["unknowns"], f"{c['s_u']:.1e}", f"{c['s_p']:.1e}",
                               f"{c['cond_a']:.1e}", f"{c['cond_right']:.1e}", f"{c['cond_scaled']:.1e}",
                               f"{c['cond_krylov']:.1e}"] for c in cond]))

    if "3d" not in skip and not args.quick:
        import bench_radial as br

        rows3 = [br.spawn("K", h, "hmatrix", t3, scheme=s, threads=args.threads)
                 for h, t3 in ((1.5, 30.0), (1.0, 50.0), (0.75, 50.0)) for s in ("fully-coupled", "krylov")]
        with open(os.path.join(OUT, "schemes_3d.json"), "w") as f:
            json.dump(rows3, f)
        print("\n## 3D radial K case (ref. Table 4.1), hmatrix: fully-coupled against krylov\n")
        body = []
        for r in rows3:
            if "history" not in r:
                body.append([r.get("scheme"), r.get("h"), "failed: " + str(r.get("failure"))] + [""] * 9)
                continue
            h = r["history"]
            body.append([r["scheme"] + (" (FAILED)" if r.get("failure") else ""), f"{r['h']:g}", f"{r['t_end']:g}",
                         r["final_elements"], f"{np.mean(h['nonlinear_iterations']):.1f}",
                         f"{np.sum(h['nonlinear_iterations'])}", f"{np.sum(h['linear_iterations'])}",
                         f"{np.sum(h['linear_iterations']) / np.sum(h['nonlinear_iterations']):.1f}",
                         f"{r['wall_s']:.1f}", f"{100 * r['error']['radius']:+.1f}%",
                         f"{100 * r['error']['net_pressure']:+.1f}%", f"{r['background_cores']:.2f}"])
        print(markdown_table(["scheme", "h (m)", "t_end (s)", "elements at t_end", "nonlinear its / step",
                              "nonlinear its total", "GMRES its total", "GMRES its / nonlinear it", "wall (s)",
                              "R error", "p_net error", "background load (cores)"], body))


if __name__ == "__main__":
    main()
