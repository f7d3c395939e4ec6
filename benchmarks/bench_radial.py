"""Growing radial hydraulic fractures against closed forms (ref. Sec. 4.5.1, Table 4.1), and
the cost of accuracy as the elements shrink.

    python benchmarks/bench_radial.py              # full study (about 30 min, one thread)
    python benchmarks/bench_radial.py --quick      # h = 2 and 1.5 m only, to 20 s (under a minute)
    python benchmarks/bench_radial.py --report     # tables and plots again from the saved JSON
    python benchmarks/bench_radial.py --case '{"case": "K", "h": 1.0, "backend": "hmatrix"}'   # one run, JSON
    # issue 17: the h = 0.5 m K-vertex run with its CPU split, and with the plain iteration of before
    python benchmarks/bench_radial.py --case '{"case": "K-vertex", "h": 0.5, "backend": "hmatrix", "parts": true}'
    python benchmarks/bench_radial.py --case '{"case": "K-vertex", "h": 0.5, "backend": "hmatrix",
        "scheme_options": {"stopping": "change", "first_linear_rtol": 1e-9}}'
    # ... and with every growth pass decided on a converged solve (before the growth_check)
    python benchmarks/bench_radial.py --case '{"case": "K-vertex", "h": 0.5, "backend": "hmatrix", "parts": true,
        "scheme_options": {"growth_check": "converged"}}'

Two studies, printed as markdown tables and saved (JSON in benchmarks/out/, PNG in benchmarks/):

1. table41: the M- and K-vertex cases of ref. Table 4.1 (G 24 GPa, nu 0.25, S_hmin 8 MPa,
   Q 0.01 m^3/s, wellbore 0.005 m^3, mu 1 cP, c_f 4.4e-4 1/MPa, p_0 10 MPa, dt 1 s; K_Ic 1
   and 5 MPa m^1/2, initial widths 4e-3 and 1e-2 mm) to 50 s with 1 m elements (the
   reference's 0.1 m would be about 100k elements at 50 s), initial fracture 3 x 3
   elements, on both backends ("hmatrix" and "dense"). Per step: radius sqrt(A/pi) (ref.
   Eq. 4.69), maximum opening and net pressure (wellbore minus S_hmin) against the closed
   forms: K case with the K-vertex (ref. Eqs 4.65-4.67, exact at zero viscosity); M case
   with the M-vertex radius and opening (ref. Eqs 4.62-4.63) and, for the pressure, the
   Savitski-Detournay M-vertex net pressure at rho = r_eq / R, with r_eq = exp(-pi/2) h
   Peaceman's equivalent radius of a finite-volume source cell
   (hmatddm.analytical.well_element_radius; the M-vertex pressure is log-singular at the
   source: it has no single "wellbore" value without a radius). The dense twin: same number of elements
   at every step, and the largest relative difference of R, w_max and p over the run.
   Plot: radial_history.png.
2. cost: the K-vertex at several element sizes h (initial 3 x 3 elements of side h). With
   mu = 1e-5 Pa s the fracture IS toughness dominated (K_m ~ 8-10 over the run); the
   Table 4.1 K case (mu = 1e-3, K_m ~ 2-3, in the K-M transition) is run at the same sizes
   for comparison. Wall time of the whole run (operator builds included), peak RSS,
   elements, and the errors at t_end = 50 s of the radius and of the opening at the
   injection (centre) element and the maximum opening. Dense where its matrix is below
   --dense-limit elements. Plot: radial_accuracy_cost.png (error against wall time).

3. threads: the K-vertex at h = 1 m with 1 and 2 numba threads, alternating.

4. front: the two front models (``Propagation(front="element" | "asymptotic")``, issue 16)
   on the M case (h = 2 and 1 m to 50 s, h = 0.5 m to 12 s; dense twin of the asymptotic
   front at h = 2 m), the K-vertex and the Table 4.1 K case against Dontsov's (2016)
   solution of the K-M transition ("K-M", K_m 1.8-2.9; hmatddm.analytical.radial_transition)
   and the same with K_Ic 3 MPa m^1/2 ("K-M 1-2", K_m 1.1-1.7: mid-transition) (h = 1 m): errors at t_end, RMS over 10 s
   to t_end, the worst front circularity (largest / smallest front distance from the well,
   minus 1) over the same times, wall and process CPU time. Plot:
   radial_front_accuracy_cost.png (M-vertex errors against wall time, with the planar-3D
   level-set simulator's 1.1% / 0.7% in ~121 s). ``--skip table41,cost,kgd,threads`` runs it alone;
   ``--front-rows 4,9`` runs rows of FRONT_RUNS again and merges them into the saved study.

5. kgd: the 2D plane-strain fracture of ref. Table 4.2 with K_Ic 5 and 0.2 MPa m^1/2 (K_m
   4.9 and 0.2) at h = 1 and 0.5 m, both front models, against the KGD K- and M-vertex at
   100 s (in this process: 2D runs are small).

Every run is a separate process (clean timings and peak RSS), with one numba/BLAS thread
unless --threads says otherwise; each row records the background load (cores kept busy by
other processes during the run), because other jobs share the machine.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out")

SHEAR_MODULUS, POISSON = 24e9, 0.25
S_HMIN = 8e6
RATE, WELLBORE = 0.01, 0.005
COMPRESSIBILITY = 4.4e-10
INITIAL_PRESSURE = 10e6
# ref. Table 4.1; "K-vertex" is the same K case with a 100 times thinner fluid, so that it is
# toughness dominated (K_m > 3.5) over the whole run
CASES = {
    "M": dict(toughness=1e6, initial_opening=4e-6, viscosity=1e-3),
    "K": dict(toughness=5e6, initial_opening=1e-5, viscosity=1e-3),
    "K-vertex": dict(toughness=5e6, initial_opening=1e-5, viscosity=1e-5),
    # the K case again, compared with Dontsov's (2016) solution of the K-M transition (K_m 1.8-2.9)
    "K-M": dict(toughness=5e6, initial_opening=1e-5, viscosity=1e-3),
    # mid-transition (issue 16: K_m ~ 1-2): K_Ic 3 MPa m^1/2, K_m 1.1 (1 s) - 1.7 (50 s)
    "K-M 1-2": dict(toughness=3e6, initial_opening=1e-5, viscosity=1e-3),
}


def closed_form(case, t, h):
    """(radius, max width, net pressure, name of the solution) at times ``t``."""
    import hmatddm as hd

    params = CASES[case]
    material = hd.Elastic(SHEAR_MODULUS, POISSON)
    t = np.asarray(t, dtype=float)
    if case == "M":
        radius, width = hd.analytical.radial_m_vertex(t, RATE, params["viscosity"], material)
        # the injection element's pressure is the log-singular M-vertex pressure at Peaceman's
        # equivalent radius exp(-pi/2) h of a finite-volume source cell (not at the radius
        # h/sqrt(pi) of a disc of its area: that read the M-vertex ~10% low)
        rho = hd.analytical.well_element_radius(h) / radius
        pressure = np.array([hd.analytical.radial_m_vertex_pressure(min(r, 0.99), ti, RATE, params["viscosity"],
                                                                    material) for r, ti in zip(np.atleast_1d(rho),
                                                                                               np.atleast_1d(t))])
        return radius, width, pressure.reshape(t.shape), "M-vertex"
    if case.startswith("K-M"):  # no net pressure in this approximation
        radius, width = hd.analytical.radial_transition(t, RATE, params["viscosity"], params["toughness"], material)
        return radius, width, np.full(t.shape, np.nan), "K-M transition (Dontsov 2016)"
    radius, width, pressure = hd.analytical.radial_k_vertex(t, RATE, params["toughness"], material)
    return radius, width, pressure, "K-vertex"


def cpu_parts():
    """Process CPU seconds spent in the main costs of a run, by name (a dict filled while
    the run goes): wrappers around the H build, the border blocks and products of the grown
    mesh, the coupled GMRES and its parts, the flow LU and the mesh topology. Nested: "coupled
    GMRES" includes the matvecs and the preconditioner, "grown-mesh matvec" the H matvec."""
    import functools

    import hmatddm.coupled.scaled_system as scaled_system
    import hmatddm.elasticity.extended as extended
    import hmatddm.hmatrix.hmatrix as hmatrix
    import hmatddm.hmatrix.solvers as solvers
    import hmatddm.simulation.growing_operator as growing
    import hmatddm.mesh.topology as topology

    parts = {}

    def wrap(owner, name, key):
        function = getattr(owner, name)

        @functools.wraps(function)
        def timed(*args, **kwargs):
            begin = time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                parts[key] = parts.get(key, 0.0) + time.process_time() - begin

        setattr(owner, name, timed)

    wrap(growing.GrowingOperator, "build", "H builds")
    wrap(extended.ExtendedElasticityOperator, "_border_blocks", "border blocks")
    # every GMRES solve (the coupled ones only, in these runs), paused or not
    wrap(solvers.PausableGmres, "pause", "coupled GMRES")
    wrap(solvers.PausableGmres, "finish", "coupled GMRES")
    wrap(hmatrix.HMatrix, "_matvec", "H matvec")
    wrap(extended.ExtendedElasticityOperator, "_matvec", "grown-mesh matvec")
    wrap(extended.ExtendedElasticityOperator, "approximate_inverse", "block-triangular preconditioner")
    wrap(scaled_system._CoupledLinearSystem, "compliance_preconditioner", "flow LU")
    wrap(topology, "element_edges", "topology")
    wrap(topology, "element_faces", "topology")
    return parts


def run_case(case, h, backend, t_end, scheme="krylov", front="element", scheme_options=None, parts=False,
             rebuild=None):
    """One simulation; returns a dict with the per-step history and the final errors.
    ``scheme_options``: further :class:`hmatddm.coupled.SchemeSettings` fields (e.g.
    ``{"stopping": "change", "first_linear_rtol": 1e-9}``, the plain iteration of before
    issue 17; ``{"growth_check": "converged"}``, every growth pass on a converged solve, as
    before the third issue-17 session); ``parts``: add ``cpu_parts`` (:func:`cpu_parts`);
    ``rebuild``: :class:`hmatddm.simulation.settings.RebuildSettings` fields (when the
    grown operator is rebuilt), e.g. ``{"rebuild_fraction": 0.5}``."""
    import hmatddm as hd
    from _common import peak_rss_bytes

    params = CASES[case]
    costs = cpu_parts() if parts else None
    cpu = time.process_time()
    start = time.perf_counter()
    settings = scheme
    if scheme_options:
        from hmatddm.coupled import SchemeSettings

        settings = SchemeSettings(scheme=scheme, **scheme_options)
    material = hd.Elastic(SHEAR_MODULUS, POISSON)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3 * h, 3 * h, 3, 3)
    sim = hd.Simulation(mesh, material, hd.Fluid(params["viscosity"], COMPRESSIBILITY),
                        [hd.Cluster((0, 0, 0), RATE, WELLBORE)], far_field_stress=np.diag([0, 0, -S_HMIN]),
                        time_step=1.0, propagation=hd.Propagation(toughness=params["toughness"], front=front),
                        initial_pressure=INITIAL_PRESSURE, initial_opening=params["initial_opening"],
                        backend=backend, scheme=settings, **(rebuild or {}))
    failure = None
    try:
        records = sim.run(t_end)
    except hd.HmatddmError as error:  # ConvergenceError and friends: report, do not hide
        records, failure = sim.records, f"{type(error).__name__}: {error}"
    wall = time.perf_counter() - start
    cpu = time.process_time() - cpu
    state = sim.state
    width = np.sum(state.dd * state.mesh.normals, axis=1)
    injection = int(sim.injection_elements[0])
    keys = ("time", "n_elements", "radius", "max_opening", "nonlinear_iterations", "linear_iterations",
            "solve_seconds", "operator_builds", "growth_passes")
    history = {k: [r[k] for r in records] for k in keys}
    history["front_circularity"] = [r.get("front_circularity") for r in records]
    history["net_pressure"] = [r["wellbore_pressure"][0] - S_HMIN for r in records]
    row = dict(case=case, h=h, backend=backend, scheme=scheme, front=front, t_end=t_end, wall_s=wall, cpu_s=cpu,
               peak_rss_mb=peak_rss_bytes() / 2**20, history=history, failure=failure,
               centre_width=float(width[injection]), final_elements=int(state.mesh.n_elements),
               operator_builds=int(sim.operator_builds))
    if scheme_options:
        row["scheme_options"] = dict(scheme_options)
    if rebuild:
        row["rebuild"] = dict(rebuild)
    if costs is not None:
        row["cpu_parts"] = dict(costs)
    if records:
        add_reference(row)
        t = np.array(history["time"])
        row["K_m"] = [float(hd.analytical.radial_regime(t[0], RATE, params["viscosity"], params["toughness"],
                                                        material)),
                      float(hd.analytical.radial_regime(t[-1], RATE, params["viscosity"], params["toughness"],
                                                        material))]
    return row


def add_reference(row):
    """The closed form of ``row``'s case at its steps and the errors at t_end (in place; also
    used by --report, so saved runs are compared with the current closed forms)."""
    history = row["history"]
    radius, w_max, p_net, name = closed_form(row["case"], np.array(history["time"]), row["h"])
    row["reference_name"] = name
    row["reference"] = dict(radius=np.atleast_1d(radius).tolist(), max_width=np.atleast_1d(w_max).tolist(),
                            net_pressure=np.atleast_1d(p_net).tolist())
    row["error"] = dict(radius=history["radius"][-1] / float(np.atleast_1d(radius)[-1]) - 1,
                        max_width=history["max_opening"][-1] / float(np.atleast_1d(w_max)[-1]) - 1,
                        centre_width=row["centre_width"] / float(np.atleast_1d(w_max)[-1]) - 1,
                        net_pressure=history["net_pressure"][-1] / float(np.atleast_1d(p_net)[-1]) - 1)


def _cpu_busy_seconds():
    """Busy CPU seconds of the whole machine so far (all processes, all cores)."""
    with open("/proc/stat") as f:
        fields = [int(v) for v in f.readline().split()[1:]]
    return (sum(fields) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")


def measured_run(cmd, threads=None, timeout=1800):
    """Run ``cmd`` (prints a JSON row last) in a fresh process; adds ``threads`` and
    ``background_cores``: the average number of cores that OTHER processes kept busy
    during the run (machine busy time minus the child's CPU time, over the wall time), so
    a table can say how disturbed each timing was."""
    import resource

    env = dict(os.environ)
    if threads:
        for name in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            env[name] = str(threads)
    busy0, child0 = _cpu_busy_seconds(), resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    try:
        result = subprocess.run(cmd, capture_output=True, text=True, cwd=HERE, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return dict(failure=f"killed after {timeout} s")
    wall = time.perf_counter() - start
    child1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = (child1.ru_utime - child0.ru_utime) + (child1.ru_stime - child0.ru_stime)
    background = max(0.0, (_cpu_busy_seconds() - busy0 - own) / wall)
    if result.returncode != 0:
        print(result.stdout[-2000:], result.stderr[-4000:], file=sys.stderr)
        return dict(failure=(result.stderr.strip().splitlines() or ["?"])[-1])
    row = json.loads(result.stdout.strip().splitlines()[-1])
    row.update(threads=threads or int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count())),
               background_cores=background, process_cpu_s=own)
    return row


def spawn(case, h, backend, t_end, scheme="krylov", threads=None, timeout=1800, front="element"):
    spec = dict(case=case, h=h, backend=backend, t_end=t_end, scheme=scheme, front=front)
    print(f"  running {spec}" + (f", {threads} thread(s)" if threads else ""), flush=True)
    row = measured_run([sys.executable, os.path.abspath(__file__), "--case", json.dumps(spec)], threads, timeout)
    if "history" not in row:
        return dict(spec, **row)
    print(f"    {row['wall_s']:.1f} s, {row['final_elements']} elements, background load "
          f"{row['background_cores']:.2f} cores" + (f", FAILED {row['failure']}" if row.get("failure") else ""),
          flush=True)
    return row


def rms_errors(row, t_from=10.0):
    """RMS over t >= t_from of the relative errors of R, w_max and p_net per step: the error
    at one instant jumps with each ring of new elements (the staircase front)."""
    h, ref = row["history"], row["reference"]
    t = np.array(h["time"])
    keep = t >= t_from
    out = {}
    for key, ref_key in (("radius", "radius"), ("max_opening", "max_width"), ("net_pressure", "net_pressure")):
        e = np.array(h[key])[keep] / np.array(ref[ref_key], dtype=float)[keep] - 1.0
        out[key] = float(np.sqrt(np.mean(e * e))) if e.size and np.all(np.isfinite(e)) else None
    return out


def pct(value):
    return "-" if value is None or not np.isfinite(value) else f"{100 * value:+.1f}%"


def dense_twin(rows):
    """Per case: same n_elements at every step?, max relative differences of R, w, p."""
    out = {}
    for case in sorted({r["case"] for r in rows}):
        pair = {r["backend"]: r for r in rows if r["case"] == case and "history" in r}
        if set(pair) != {"hmatrix", "dense"}:
            continue
        a, b = pair["hmatrix"]["history"], pair["dense"]["history"]
        m = min(len(a["time"]), len(b["time"]))
        same = a["n_elements"][:m] == b["n_elements"][:m] and len(a["time"]) == len(b["time"])
        first = next((i for i in range(m) if a["n_elements"][i] != b["n_elements"][i]), None)
        diff = {}
        for key in ("radius", "max_opening", "net_pressure"):
            x, y = np.array(a[key][:m]), np.array(b[key][:m])
            diff[key] = float(np.max(np.abs(x - y) / np.abs(y)))
        out[case] = dict(same_elements=bool(same), first_difference_step=first, **diff,
                         wall_hmatrix=pair["hmatrix"]["wall_s"], wall_dense=pair["dense"]["wall_s"])
    return out


def table41_table(rows):
    from _common import markdown_table

    header = ["case", "backend", "K_m (1 s - 50 s)", "elements at 50 s", "wall (s)", "background load (cores)",
              "peak RSS (MB)", "nonlinear its / step", "R error", "w_max error", "centre w error", "p_net error",
              "RMS error 10-50 s (R / w_max / p_net)"]
    body = []
    for r in rows:
        if "history" not in r:
            body.append([r["case"], r["backend"], "failed: " + str(r.get("failure"))] + [""] * (len(header) - 3))
            continue
        e = r.get("error", {})
        its = np.mean(r["history"]["nonlinear_iterations"]) if r["history"]["time"] else float("nan")
        body.append([r["case"] + (" (FAILED: " + r["failure"] + ")" if r.get("failure") else ""), r["backend"],
                     f"{r['K_m'][0]:.1f} - {r['K_m'][1]:.1f}", r["final_elements"], f"{r['wall_s']:.1f}",
                     f"{r.get('background_cores', float('nan')):.2f}",
                     f"{r['peak_rss_mb']:.0f}", f"{its:.1f}", pct(e.get("radius")), pct(e.get("max_width")),
                     pct(e.get("centre_width")), pct(e.get("net_pressure")),
                     " / ".join(f"{100 * v:.1f}%" for v in rms_errors(r).values())])
    return markdown_table(header, body)


def cost_table(rows):
    from _common import markdown_table

    header = ["case", "h (m)", "backend", "elements at t_end", "wall (s)", "background load (cores)",
              "peak RSS (MB)", "R error",
              "centre w error", "w_max error", "p_net error", "RMS error 10-50 s (R / w_max / p_net)",
              "target (R <= 2%, w <= 4%, <= ~100 s)"]
    body = []
    for r in rows:
        if "history" not in r:
            body.append([r["case"], r["h"], r["backend"], "skipped/failed: " + str(r.get("failure"))]
                        + [""] * (len(header) - 4))
            continue
        e = r["error"]
        met = (abs(e["radius"]) <= 0.02 and abs(e["centre_width"]) <= 0.04 and r["wall_s"] <= 100
               and not r.get("failure"))
        accurate = abs(e["radius"]) <= 0.02 and abs(e["centre_width"]) <= 0.04
        rms = rms_errors(r)
        rms_ok = rms["radius"] <= 0.02 and rms["max_opening"] <= 0.04
        if met:
            verdict = "yes, also on RMS" if rms_ok else "at 50 s only (RMS misses)"
        else:
            verdict = "accuracy only (time > 100 s)" if accurate else "no"
        if r["case"] != "K-vertex":
            verdict = "n/a (K_m 2-3: transition, K-vertex not exact)"
        body.append([r["case"] + (" (FAILED)" if r.get("failure") else ""), f"{r['h']:g}", r["backend"],
                     r["final_elements"], f"{r['wall_s']:.1f}", f"{r.get('background_cores', float('nan')):.2f}",
                     f"{r['peak_rss_mb']:.0f}", pct(e["radius"]),
                     pct(e["centre_width"]), pct(e["max_width"]), pct(e["net_pressure"]),
                     " / ".join(f"{100 * v:.1f}%" for v in rms_errors(r).values()), verdict])
    return markdown_table(header, body)


def plot_history(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    colors = {"M": "C0", "K": "C3"}
    for case in ("M", "K"):
        sel = [r for r in rows if r["case"] == case and "history" in r]
        if not sel:
            continue
        for r in sel:
            t = np.array(r["history"]["time"])
            style = "-" if r["backend"] == "hmatrix" else "--"
            marker = "" if r["backend"] == "hmatrix" else "."
            label = f"{case}, {r['backend']} (h = {r['h']:g} m)"
            axes[0].plot(t, r["history"]["radius"], style, marker=marker, markevery=5, color=colors[case],
                         label=label)
            axes[1].plot(t, 1e3 * np.array(r["history"]["max_opening"]), style, marker=marker, markevery=5,
                         color=colors[case], label=label)
            axes[2].plot(t, 1e-6 * np.array(r["history"]["net_pressure"]), style, marker=marker, markevery=5,
                         color=colors[case], label=label)
        r = sel[0]
        t = np.array(r["history"]["time"])
        ref = r["reference"]
        name = r["reference_name"]
        axes[0].plot(t, ref["radius"], "k:" if case == "K" else "k-.", label=f"{name}")
        axes[1].plot(t, 1e3 * np.array(ref["max_width"]), "k:" if case == "K" else "k-.", label=name)
        plabel = name if case == "K" else f"{name} at r = h/sqrt(pi)"
        axes[2].plot(t, 1e-6 * np.array(ref["net_pressure"]), "k:" if case == "K" else "k-.", label=plabel)
    axes[0].set(xlabel="t (s)", ylabel="radius sqrt(A/pi) (m)", title="radius")
    axes[1].set(xlabel="t (s)", ylabel="max opening (mm)", title="maximum width")
    axes[2].set(xlabel="t (s)", ylabel="net pressure (MPa)", title="wellbore minus S_hmin", ylim=(0, None))
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    sizes = ", ".join(sorted({f"{r['h']:g}" for r in rows if "history" in r}))
    fig.suptitle(f"Radial fractures of ref. Table 4.1 (M: K_Ic 1 MPa m^0.5; K: 5 MPa m^0.5), h = {sizes} m elements; "
                 "solid hmatrix, dashed dense")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_cost(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    keys = (("radius", "radius", "radius"), ("centre width", "centre_width", "max_opening"))
    for case, color in (("K-vertex", "C0"), ("K", "C3")):
        for backend, style in (("hmatrix", "o-"), ("dense", "s--")):
            sel = sorted([r for r in rows if r["case"] == case and r["backend"] == backend and "history" in r
                          and not r.get("failure")], key=lambda r: r["wall_s"])
            if not sel:
                continue
            wall = [r["wall_s"] for r in sel]
            name = case if case == "K-vertex" else "K of Table 4.1 (transition: vs K-vertex)"
            for ax, (_, end_key, rms_key) in zip(axes, keys):
                # the centre is the widest element: its RMS is that of w_max
                ax.loglog(wall, [max(rms_errors(r)[rms_key], 1e-4) for r in sel], style, color=color,
                          label=f"{name}, {backend}: RMS 10-50 s")
                ax.loglog(wall, [max(abs(r["error"][end_key]), 1e-4) for r in sel], style[0], color=color,
                          mfc="none", alpha=0.6, label=f"{name}, {backend}: at 50 s")
                if backend == "hmatrix":
                    for r in sel:
                        ax.annotate(f"h={r['h']:g}", (r["wall_s"], max(rms_errors(r)[rms_key], 1e-4)), fontsize=7,
                                    textcoords="offset points", xytext=(3, 3))
    for ax, (label, _, _), target in zip(axes, keys, (0.02, 0.04)):
        ax.axhline(target, color="k", ls=":", lw=1)
        ax.axvline(100, color="k", ls=":", lw=1)
        ax.set(xlabel="wall time of the 50 s run (s), 1 thread", ylabel=f"|relative {label} error|",
               title=f"{label}: target <= {100 * target:.0f}% in <= 100 s")
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=7, loc="lower right")
    fig.suptitle("Radial fracture, K_Ic 5 MPa m^0.5, mu 1e-5 Pa s (K-vertex) and 1e-3 Pa s (Table 4.1 K); "
                 "filled: RMS error over 10-50 s, hollow: at 50 s")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


FRONT_RUNS = [  # (case, h, backend, front, t_end), cheapest first
    ("M", 2.0, "hmatrix", "element", 50.0), ("M", 2.0, "hmatrix", "asymptotic", 50.0),
    ("M", 2.0, "dense", "asymptotic", 50.0), ("M", 1.0, "hmatrix", "element", 50.0),
    ("M", 1.0, "hmatrix", "asymptotic", 50.0), ("M", 0.5, "hmatrix", "asymptotic", 12.0),
    ("K-vertex", 1.0, "hmatrix", "element", 50.0), ("K-vertex", 1.0, "hmatrix", "asymptotic", 50.0),
    ("K-M", 1.0, "hmatrix", "element", 50.0), ("K-M", 1.0, "hmatrix", "asymptotic", 50.0),
    ("K-M 1-2", 1.0, "hmatrix", "element", 50.0), ("K-M 1-2", 1.0, "hmatrix", "asymptotic", 50.0),
]


def run_front_rows(spec, threads):
    """Only the FRONT_RUNS rows whose index is in ``spec`` (comma-separated), merged into the
    saved study (a row of the same case, h, backend and front is replaced), e.g. to resume."""
    keep = [int(i) for i in spec.split(",")]
    path = os.path.join(OUT, "radial_front.json")
    rows = []
    if os.path.exists(path):
        with open(path) as f:
            rows = json.load(f)
    for k, (case, h, backend, front, t_end) in enumerate(FRONT_RUNS):
        if k not in keep:
            continue
        row = spawn(case, h, backend, t_end, threads=threads, front=front, timeout=3600)
        same = [i for i, r in enumerate(rows) if (r.get("case"), r.get("h"), r.get("backend"), r.get("front"))
                == (case, h, backend, front)]
        if same:
            rows[same[0]] = row
        else:
            rows.append(row)
        with open(path, "w") as f:
            json.dump(rows, f)
    order = {(c, h, b, f): i for i, (c, h, b, f, _) in enumerate(FRONT_RUNS)}
    return sorted(rows, key=lambda r: order.get((r.get("case"), r.get("h"), r.get("backend"), r.get("front")), 99))


KGD_CASES = {"K": 5e6, "M": 0.2e6}  # K_Ic of the ref. Table 4.2 setup: K_m = 4.9 and 0.2


def run_kgd(case, h, front, t_end=100.0):
    """Plane-strain (KGD) fracture of ref. Table 4.2 (G 10 GPa, nu 0.25, Q 5e-4 m^2/s, height
    1 m, mu 1 cP, initial 3 elements of h) against the KGD K- or M-vertex at t_end."""
    import hmatddm as hd

    material = hd.Elastic(10e9, 0.25)
    start = time.perf_counter()
    cpu = time.process_time()
    sim = hd.Simulation(hd.mesh.line([-1.5 * h, 0.0], [1.5 * h, 0.0], 3), material, hd.Fluid(1e-3, 4.5e-10),
                        [hd.Cluster((0.0, 0.0), 5e-4, 0.5)], far_field_stress=np.diag([-1e6, -0.5e6]), time_step=1.0,
                        propagation=hd.Propagation(toughness=KGD_CASES[case], front=front), initial_pressure=1e6,
                        initial_opening=1e-4)
    record = sim.run(t_end)[-1]
    if case == "K":
        length, width, _ = hd.analytical.kgd_k_vertex(t_end, 5e-4, KGD_CASES[case], material)
    else:
        length, width, _ = hd.analytical.kgd_m_vertex(t_end, 5e-4, 1e-3, material)
    i = sim.injection_elements[0]
    centre = float(sim.state.dd[i] @ sim.state.mesh.normals[i])
    return dict(case=case, h=h, front=front, t_end=t_end, wall_s=time.perf_counter() - start,
                cpu_s=time.process_time() - cpu, K_m=float(hd.analytical.kgd_regime(5e-4, 1e-3, KGD_CASES[case],
                                                                                   material)),
                length_error=record["half_length"] / float(length) - 1.0, width_error=centre / float(width) - 1.0)


def run_front_study(threads):
    """Every FRONT_RUNS row in its own process; the JSON is rewritten after each row."""
    rows = []
    for case, h, backend, front, t_end in FRONT_RUNS:
        rows.append(spawn(case, h, backend, t_end, threads=threads, front=front, timeout=3600))
        with open(os.path.join(OUT, "radial_front_partial.json"), "w") as f:
            json.dump(rows, f)
    return rows


def front_table(rows):
    from _common import markdown_table

    out = []
    for r in rows:
        if "error" not in r:
            out.append([r.get("case"), "", r.get("front"), r.get("h"), r.get("backend"), r.get("t_end"),
                        f"failed: {r.get('failure')}"] + [""] * 9)
            continue
        rms = rms_errors(r)
        circ = [c for c, t in zip(r["history"]["front_circularity"], r["history"]["time"]) if c and t >= 10.0]
        out.append([r["case"], r.get("reference_name", ""), r["front"], f"{r['h']:g}", r["backend"], f"{r['t_end']:g}",
                    r["final_elements"],
                    f"{r['wall_s']:.0f}", f"{r.get('process_cpu_s', float('nan')):.0f}",
                    f"{r.get('background_cores', float('nan')):.2f}", pct(r["error"]["radius"]),
                    pct(r["error"]["centre_width"]), pct(r["error"]["net_pressure"]),
                    " / ".join("-" if v is None else f"{100 * v:.1f}%" for v in rms.values()),
                    f"{100 * (max(circ) - 1):.1f}%" if circ else "-",
                    r.get("failure") or ""])
    return markdown_table(["case", "reference", "front", "h (m)", "backend", "t_end (s)", "elements", "wall (s)",
                           "CPU (s)",
                           "background (cores)", "R error", "centre w error", "p_net error",
                           "RMS 10 s-t_end (R / w_max / p_net)", "worst circularity 10 s-t_end", "note"], out)


def plot_front(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 6.2))
    for r in rows:
        if ("history" not in r or r["case"] not in ("M", "K-vertex", "K-M", "K-M 1-2") or r["backend"] != "hmatrix"
                or r["t_end"] < 50):
            continue
        marker = {"M": "o", "K-vertex": "^", "K-M": "D", "K-M 1-2": "s"}[r["case"]]
        label = f"{r['case']} ({r['reference_name'].split(' (')[0]}), {r['front']}, h = {r['h']:g} m"
        cpu = r.get("process_cpu_s", r["wall_s"])  # the machine was shared: CPU time, not wall
        style = dict(ms=8, mfc="none" if r["front"] == "element" else None,
                     color={"M": "C0", "K-vertex": "C3", "K-M": "C2", "K-M 1-2": "C4"}[r["case"]])
        axes[0].loglog(cpu, abs(r["error"]["radius"]) * 100, marker, label=label, **style)
        axes[1].loglog(cpu, abs(r["error"]["centre_width"]) * 100, marker, label=label, **style)
    for ax, name in zip(axes, ("radius", "centre opening")):
        ax.loglog([121.0], [1.1 if name == "radius" else 0.7], "k*", ms=12,
                   label="planar-3D level-set peer (~121 s wall)")
        ax.set_xlabel("process CPU time (s), one thread")
        ax.set_ylabel(f"|{name} error| at 50 s (%)")
        ax.set_title(f"radial (ref. Table 4.1 setup): {name}")
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, title="case (reference), front model "
               "(hollow: element switch), element size")
    fig.tight_layout(rect=(0, 0.22, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="h = 2, 1.5 m to 20 s (about 1-2 min)")
    parser.add_argument("--case", help="one run, JSON spec: case, h, backend, t_end")
    parser.add_argument("--t-end", type=float, default=None, help="end time (default 50 s; 20 s with --quick)")
    parser.add_argument("--sizes", default=None, help="comma-separated element sizes of the cost study "
                                                      "(default 2,1.5,1,0.75,0.5)")
    parser.add_argument("--dense-limit", type=int, default=2500,
                        help="dense backend only for meshes expected below this many elements at t_end")
    parser.add_argument("--front-rows", default=None,
                        help="comma-separated indices of FRONT_RUNS to run again, merged into the saved front study")
    parser.add_argument("--skip", default="", help="comma-separated studies to skip: table41, cost, front, kgd, threads")
    parser.add_argument("--report", action="store_true",
                        help="print the tables and redraw the plots from the JSON of the last run (no runs)")
    parser.add_argument("--threads", type=int, default=1,
                        help="NUMBA/BLAS threads of every run (default 1: see RESULTS.md, 2 threads lose badly "
                             "to background load at these sizes)")
    args = parser.parse_args()
    sys.path.insert(0, HERE)
    if args.case:
        spec = json.loads(args.case)
        if "two_level_from" in spec:  # elements from which the H-matrix runs use the two-level preconditioner
            import hmatddm.hmatrix.preconditioners as preconditioners

            preconditioners.TWO_LEVEL_MIN_ELEMENTS = int(spec["two_level_from"])
        print(json.dumps(run_case(spec["case"], float(spec["h"]), spec["backend"], float(spec.get("t_end", 50.0)),
                                  spec.get("scheme", "krylov"), spec.get("front", "element"),
                                  spec.get("scheme_options"), bool(spec.get("parts", False)),
                                  spec.get("rebuild"))))
        return
    from _common import machine, markdown_table

    os.makedirs(OUT, exist_ok=True)
    t_end = args.t_end or (20.0 if args.quick else 50.0)
    skip = set(filter(None, args.skip.split(",")))
    print(f"Machine: {machine()}")
    suffix = "_quick" if args.quick else ""
    plots = OUT if args.quick else HERE

    def study(name, run):
        """Rows of a study: run and save them, or (--report) load the saved ones."""
        path = os.path.join(OUT, f"radial_{name}{suffix}.json")
        if args.report:
            with open(path) as f:
                rows = json.load(f)
            for row in rows:
                if row.get("history", {}).get("time") and "case" in row and row["case"] in CASES:
                    add_reference(row)
            return rows
        rows = run()
        with open(path, "w") as f:
            json.dump(rows, f)
        return rows

    if "table41" not in skip:
        h41 = 2.0 if args.quick else 1.0
        rows41 = study("table41", lambda: [spawn(case, h41, backend, t_end, threads=args.threads)
                                           for case in ("M", "K") for backend in ("hmatrix", "dense")])
        print(f"\n## Ref. Table 4.1 radial cases, h = {rows41[0]['h']:g} m, t_end = {t_end:g} s\n")
        print(table41_table(rows41))
        print("\n### Dense twin (hmatrix against dense, every step)\n")
        twin = dense_twin(rows41)
        print(markdown_table(["case", "same elements every step", "max rel. diff R", "max rel. diff w_max",
                              "max rel. diff p_net", "wall hmatrix (s)", "wall dense (s)"],
                             [[c, "yes" if d["same_elements"] else f"no (first at step {d['first_difference_step']})",
                               f"{d['radius']:.1e}", f"{d['max_opening']:.1e}", f"{d['net_pressure']:.1e}",
                               f"{d['wall_hmatrix']:.1f}", f"{d['wall_dense']:.1f}"] for c, d in twin.items()]))
        plot_history(rows41, os.path.join(plots, "radial_history.png"))

    if "cost" not in skip:
        sizes = [2.0, 1.5] if args.quick else [2.0, 1.5, 1.0, 0.75, 0.5]
        if args.sizes:
            sizes = [float(s) for s in args.sizes.split(",")]

        def run_cost():
            import hmatddm as hd

            rows = []
            for case in ("K-vertex", "K"):
                for h in sizes:
                    # the K-vertex area at t_end in elements, to decide whether dense fits
                    radius = hd.analytical.radial_k_vertex(t_end, RATE, CASES[case]["toughness"],
                                                           hd.Elastic(SHEAR_MODULUS, POISSON))[0]
                    expected = np.pi * float(radius) ** 2 / h**2
                    rows.append(spawn(case, h, "hmatrix", t_end, threads=args.threads))
                    if expected <= args.dense_limit:
                        rows.append(spawn(case, h, "dense", t_end, threads=args.threads))
                    else:
                        rows.append(dict(case=case, h=h, backend="dense", failure=f"not run: ~{expected:.0f} "
                                                                                   f"elements > --dense-limit "
                                                                                   f"{args.dense_limit}"))
            return rows

        rows = study("cost", run_cost)
        print(f"\n## Accuracy against cost (radial K, t_end = {t_end:g} s)\n")
        for case in ("K-vertex", "K"):
            ok = [r for r in rows if r["case"] == case and "K_m" in r]
            if ok:
                print(f"- {case}: viscosity {CASES[case]['viscosity']:g} Pa s, K_m from {ok[0]['K_m'][0]:.2f} "
                      f"(1 s) to {ok[0]['K_m'][1]:.2f} ({t_end:g} s)")
        print()
        print(cost_table(rows))
        plot_cost(rows, os.path.join(plots, "radial_accuracy_cost.png"))

    if "front" not in skip:
        if args.front_rows:
            rows_f = run_front_rows(args.front_rows, args.threads)
            for row in rows_f:
                if row.get("history", {}).get("time"):
                    add_reference(row)  # rows kept from an earlier run: today's closed forms
        else:
            rows_f = study("front", lambda: run_front_study(args.threads))
        print("\n## Front models: element switch against the asymptotic front (radial, hmatrix unless said)\n")
        print(front_table(rows_f))
        plot_front(rows_f, os.path.join(plots, "radial_front_accuracy_cost.png"))

    if "kgd" not in skip:
        rows_k = study("kgd", lambda: [run_kgd(case, h, front) for case in ("M", "K") for h in (1.0, 0.5)
                                       for front in ("element", "asymptotic")])
        print("\n## KGD (2D, ref. Table 4.2 setup) at 100 s: both front models\n")
        print(markdown_table(["case", "K_m", "h (m)", "front", "wall (s)", "CPU (s)", "half-length error",
                              "centre opening error"],
                             [[r["case"], f"{r['K_m']:.2f}", f"{r['h']:g}", r["front"], f"{r['wall_s']:.0f}",
                               f"{r['cpu_s']:.0f}", pct(r["length_error"]), pct(r["width_error"])] for r in rows_k]))

    if "threads" not in skip:
        h_threads = 2.0 if args.quick else 1.0
        rows_t = study("threads", lambda: [spawn("K-vertex", h_threads, "hmatrix", t_end, threads=n)
                                           for n in (1, 2, 1, 2)])
        print(f"\n## Threads (K-vertex, h = {h_threads:g} m, hmatrix, alternating runs)\n")
        print(markdown_table(["threads", "wall (s)", "process CPU (s)", "background load (cores)", "R error"],
                             [[r.get("threads"), f"{r['wall_s']:.1f}", f"{r['process_cpu_s']:.1f}",
                               f"{r['background_cores']:.2f}", pct(r["error"]["radius"])]
                              for r in rows_t if "history" in r]))


if __name__ == "__main__":
    main()
