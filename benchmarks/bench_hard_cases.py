"""Hard cases of the elasticity layer: the full table behind tests/test_hard_cases.py.

For each case: N (elements), the relative 2-norm difference of the DDs solved with the
``hmatrix`` backend (eps 1e-6 unless stated, GMRES with the default near-field ILU, rtol
1e-10) and with ``dense`` (LU), the error against a closed form or a refined reference,
the GMRES iterations and the wall times (build + solve) of both backends. Prints
markdown, writes ``benchmarks/out/hard_cases.md`` / ``.json`` and two plots
(``hard_cases_spacing.png``: opening vs spacing; ``hard_cases_mesh_quality.png``: error
vs element aspect ratio and size jump). Timings are indicative (a shared 2-core machine).

    python benchmarks/bench_hard_cases.py            # about 5 minutes
    python benchmarks/bench_hard_cases.py scales tilted   # some cases only (-> hard_cases_partial.md)

Cases: intersections, parallel, quality, edges, scales, tilted, coupled.
"""
import json
import os
import sys
import time

import numpy as np
import scipy.sparse.linalg as spla

sys.path.insert(0, os.path.dirname(__file__))

from _common import machine, markdown_table  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm import analytical as an  # noqa: E402
from hmatddm import network as nw  # noqa: E402
from hmatddm.mesh.hard_cases import graded_line, mixed_scales  # noqa: E402
from hmatddm.errors import ConvergenceError  # noqa: E402
from hmatddm.hmatrix import gmres  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out")
MAT = hd.Elastic(10e9, 0.25)
P = 1e6
EPS = 1e-6
ROWS = []
CURVES = {}


def run_both(mesh, eps=EPS, leaf_size=32, dense=True, **options):
    """Solve the pressurised mesh with both backends; returns a dict of results."""
    load = -P * mesh.normals
    out = dict(N=mesh.n_elements)
    start = time.perf_counter()
    op_h = hd.ElasticityOperator(mesh, MAT, backend="hmatrix", eps=eps, leaf_size=leaf_size, **options)
    try:
        dd_h, info = hd.solve(op_h, load, rtol=1e-10, return_info=True)
        out["its"] = info["iterations"]
        out["restart"] = info["restart"]
    except ConvergenceError as error:
        dd_h = None
        out["its"] = f"fail ({error.iterations} its, res {error.residual:.0e})"
    out["t_h"] = time.perf_counter() - start
    out["op_h"] = op_h
    out["dd_h"] = dd_h
    if dense:
        start = time.perf_counter()
        op_d = hd.ElasticityOperator(mesh, MAT, backend="dense", **options)
        dd = hd.solve(op_d, load)
        out["t_d"] = time.perf_counter() - start
        matrix = op_d.to_dense()
        out["finite"] = bool(np.all(np.isfinite(matrix)) and np.all(np.isfinite(dd)))
        out["matrix"] = matrix
        out["hd"] = np.linalg.norm(dd_h - dd) / np.linalg.norm(dd) if dd_h is not None else float("nan")
    else:
        dd = dd_h
        out["finite"] = bool(np.all(np.isfinite(dd)))
        out["hd"] = float("nan")
    out["dd"] = dd
    out["w"] = hd.opening(mesh, dd)
    out["volume"] = float(np.sum(out["w"] * mesh.areas))
    return out


def add(case, variant, result, reference_error, note=""):
    its = result.get("its", "-")
    row = dict(case=case, variant=variant, N=result["N"], hd=result.get("hd", float("nan")),
               error=reference_error, its=its, t_h=result.get("t_h", float("nan")),
               t_d=result.get("t_d", float("nan")), finite=result.get("finite", True), note=note)
    ROWS.append(row)
    print(f"  {case:<22} {variant:<40} N={row['N']:<6} hd={row['hd']:.1e} err={reference_error} its={its} "
          f"t_h={row['t_h']:.2f}s t_d={row['t_d']:.2f}s {note}", flush=True)


def fmt(value, digits=1):
    if isinstance(value, str):
        return value
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return "-"
    return f"{value:.{digits}e}"


# ------------------------------------------------------------------ 1. intersections
def case_intersections():
    print("1. intersections", flush=True)

    def non_conforming(dim, kind, n):
        if dim == 2:
            main = hd.mesh.line([-1, 0], [1, 0], n)
            branch = (hd.mesh.line([0, 0], [0, 1], (n + 1) // 2, fracture_id=1) if kind == "T"
                      else hd.mesh.line([0, -1], [0, 1], n + 1, fracture_id=1))
        else:
            h = 4.0 / n
            nz = int(round(2.0 / h))
            main = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 4.0, 2.0, n, nz)
            branch = (hd.mesh.rectangle([0, 1, 0], [0, 1, 0], [0, 0, 1], 2.0, 2.0, (n + 1) // 2, nz, fracture_id=1)
                      if kind == "T" else
                      hd.mesh.rectangle([0, 0, 0], [0, 1, 0], [0, 0, 1], 4.0, 2.0, n + 1, nz, fracture_id=1))
        return hd.mesh.concatenate([main, branch])

    def conforming(dim, kind, element_length):
        half = 1.0 if dim == 2 else 2.0
        start = 0.0 if kind == "T" else -half
        net = nw.Network.from_segments([[-half, 0], [0, start]], [[half, 0], [0, half]], height=2.0)
        split = nw.split_at_intersections(net)
        if dim == 2:
            return split.to_mesh2d(element_length)
        return split.to_mesh3d(element_length, int(round(2.0 / element_length)))

    for dim, levels, fine in ((2, (21, 81), 0.0125), (3, (9, 17), 4.0 / 36)):
        for kind in ("T", "X"):
            ref = run_both(conforming(dim, kind, fine), dense=dim == 2)
            v_ref = ref["volume"]
            add(f"1 junction {dim}D", f"{kind} conforming reference h={fine:.3g}", ref, "reference",
                note="the reference: finest conforming mesh")
            for n in levels:
                h = 2.0 / n if dim == 2 else 4.0 / n
                mesh = non_conforming(dim, kind, n)
                try:
                    hd.ElasticityOperator(mesh, MAT)
                    refused = "NOT refused"
                except hd.InputError:
                    refused = "refused with none"
                r = run_both(mesh, singular_correction="average", alpha=1.0)
                add(f"1 junction {dim}D", f"{kind} average+alpha=1, h={h:.3g}", r,
                    f"{r['volume'] / v_ref - 1:+.2%} vol", note=refused)
                r = run_both(conforming(dim, kind, h))
                add(f"1 junction {dim}D", f"{kind} conforming (split), h={h:.3g}", r,
                    f"{r['volume'] / v_ref - 1:+.2%} vol")
    # near-miss T: branch end `gap` element lengths above the main crack's centre
    n = 21
    h = 2.0 / n
    ref = run_both(conforming(2, "T", h))
    for gap in (1e-8, 1e-4, 1e-2, 1e-1, 0.3):  # 0.3 h = 0.6 half sizes: beyond NEAR_SINGULAR_FRACTION
        mesh = hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], n),
                                    hd.mesh.line([0, gap * h], [0, 1], 11, fracture_id=1)])
        for label, options in (("none", {}), ("none+alpha=1", dict(alpha=1.0)),
                               ("average+alpha=1", dict(singular_correction="average", alpha=1.0))):
            try:
                r = run_both(mesh, leaf_size=16, **options)
            except hd.InputError:
                add("1 near-miss T 2D", f"gap {gap:g} h, {label}", dict(N=mesh.n_elements), "refused",
                    note="InputError: near-miss junction")
                continue
            cond = np.linalg.cond(r["matrix"])
            ratio = np.abs(r["matrix"]).max() / np.abs(np.diag(r["matrix"])).max()
            add("1 near-miss T 2D", f"gap {gap:g} h, {label}", r, f"{r['volume'] / ref['volume'] - 1:+.1%} vol",
                note=f"vs touching conforming; max entry {ratio:.0e} x diag, cond {cond:.0e}")


# --------------------------------------------------------------- 2. parallel cracks
def case_parallel():
    print("2. parallel cracks", flush=True)
    n = 40
    h = 2.0 / n
    single = hd.mesh.line([-1, 0], [1, 0], n)
    rs = run_both(single, leaf_size=16)
    griffith = an.griffith_opening(single.centers[:, 0], 1.0, P, MAT)
    inner = np.abs(single.centers[:, 0]) < 0.5
    add("2 parallel 2D", "single crack vs Griffith", rs,
        f"{np.max(np.abs(rs['w'] - griffith)[inner]) / griffith.max():.1%} w(|x|<a/2)")
    spacings = [100.0 / h, 20, 10, 5, 2, 1, 0.5, 0.25, 0.1]
    curve = []
    for k in spacings:
        mesh = hd.mesh.concatenate([single, hd.mesh.line([-1, k * h], [1, k * h], n, fracture_id=1)])
        r = run_both(mesh, leaf_size=16)
        reduction = r["w"][:n].sum() / rs["w"].sum()
        cond = np.linalg.cond(r["matrix"])
        curve.append((k, reduction, r["its"] if isinstance(r["its"], int) else np.nan))
        add("2 parallel 2D", f"spacing {k:g} h (s/2a={k * h / 2:.3g})", r, f"w/w_single {reduction:.3f}",
            note=f"cond {cond:.1e}; min w/max w {r['w'].min() / r['w'].max():+.2f}")
    CURVES["2D"] = curve
    # fixed spacing 0.01 (0.5% of the length) under refinement
    for m in (20, 50, 100, 200):
        s = 0.01
        single_m = hd.mesh.line([-1, 0], [1, 0], m)
        w1 = hd.opening(single_m, hd.solve(hd.ElasticityOperator(single_m, MAT), -P * single_m.normals))
        mesh = hd.mesh.concatenate([single_m, hd.mesh.line([-1, s], [1, s], m, fracture_id=1)])
        r = run_both(mesh, leaf_size=16)
        note = f"cond {np.linalg.cond(r['matrix']):.1e}"
        if r.get("restart", 100) > 100:
            note += f"; restart grew 100 -> {r['restart']} on stagnation"
        # GMRES(20) kept plain (max_restart=20) against grown on stagnation (the default)
        op, b = r["op_h"], (-P * mesh.normals).ravel()
        for label, cap in (("plain", 20), ("grown", None)):
            try:
                _, info = gmres(op, b, M=op.preconditioner(), rtol=1e-10, restart=20, maxiter=20, max_restart=cap)
                note += f"; GMRES(20) {label}: {info['iterations']} its" + (
                    f" (restart {info['restart']})" if info["restart"] > 20 else "")
            except ConvergenceError as error:
                note += f"; GMRES(20) {label}: fails (res {error.residual:.0e} after {error.iterations})"
        add("2 parallel 2D", f"s=0.01 fixed, n={m} per crack (s/h={s * m / 2:g})", r,
            f"w/w_single {r['w'][:m].sum() / w1.sum():.3f}", note=note)
    # 3D: two pennies
    radius, hp = 1.0, 1.0 / 6
    penny = hd.mesh.penny([0, 0, 0], [0, 0, 1], radius, hp)
    rp = run_both(penny)
    add("2 parallel 3D", "single penny h=R/6 vs Sneddon", rp,
        f"{rp['volume'] / an.sneddon_volume(radius, P, MAT) - 1:+.1%} vol", note="staircase disc")
    curve = []
    for k in (100.0 / hp, 10, 4, 2, 1, 0.5, 0.25):
        mesh = hd.mesh.concatenate([penny, hd.mesh.penny([0, 0, k * hp], [0, 0, 1], radius, hp, fracture_id=1)])
        r = run_both(mesh)
        ratio = r["volume"] / (2 * rp["volume"])
        curve.append((k, ratio, r["its"] if isinstance(r["its"], int) else np.nan))
        add("2 parallel 3D", f"pennies, spacing {k:g} h", r, f"V/V_single {ratio:.3f}",
            note=f"min w/max w {r['w'].min() / r['w'].max():+.2f}")
    CURVES["3D"] = curve


# ------------------------------------------------------ 3. thin and graded elements
def case_mesh_quality():
    print("3. thin and graded elements", flush=True)
    griffith_area = np.pi * (1 - MAT.poisson_ratio) * P / MAT.shear_modulus
    graded = {}
    for layout in ("centre", "tips", "alternating"):
        for ratio in (1, 5, 10, 20, 50):
            mesh = graded_line(ratio, layout)
            r = run_both(mesh, leaf_size=16)
            x = mesh.centers[:, 0]
            g = an.griffith_opening(x, 1.0, P, MAT)
            inner = np.abs(x) < 0.5
            err = np.max(np.abs(r["w"] - g)[inner]) / g.max()
            graded.setdefault(layout, []).append((ratio, err))
            add("3 graded 2D", f"{layout}, size jump {ratio}", r,
                f"{err:.2%} w(|x|<a/2), {r['volume'] / griffith_area - 1:+.2%} vol")
    CURVES["graded"] = graded
    # reference volume of the 2 x 2 square crack: Richardson on uniform 16, 32, 64
    volumes = []
    for n in (16, 32, 64):
        mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, n, n)
        r = run_both(mesh, dense=n <= 32)
        volumes.append(r["volume"])
        add("3 square 3D", f"uniform {n}x{n}", r, "reference run")
    order = np.log2((volumes[1] - volumes[0]) / (volumes[2] - volumes[1]))
    v_ref = volumes[2] + (volumes[2] - volumes[1]) / (2**order - 1)
    print(f"  square crack: observed order {order:.2f}, extrapolated volume {v_ref:.6e}")
    thin = []
    for aspect in (1, 2, 5, 10, 20):
        mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 8, 8 * aspect)
        r = run_both(mesh)
        err = abs(r["volume"] / v_ref - 1)
        thin.append((aspect, err))
        add("3 thin elements 3D", f"8 x {8 * aspect} (aspect 1:{aspect})", r, f"{err:.2%} vol",
            note="vs Richardson extrapolation of uniform 16/32/64")
    CURVES["thin"] = thin
    # 9 x 9 crack with its centre element replaced by r x r elements
    n, L = 9, 2.0
    uniform = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], L, L, n, n)
    centre = np.flatnonzero(np.all(np.abs(uniform.centers) < 1e-12, axis=1))
    keep = np.setdiff1d(np.arange(uniform.n_elements), centre)
    ru = run_both(uniform)
    patch_curve = []
    for r_fine in (5, 10, 20, 50):
        patch = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], L / n, L / n, r_fine, r_fine)
        mesh = hd.mesh.concatenate([uniform.subset(keep), patch])
        r = run_both(mesh)
        moved = np.max(np.abs(r["w"][:len(keep)] - ru["w"][keep])) / ru["w"].max()
        patch_curve.append((r_fine, abs(r["volume"] / v_ref - 1)))
        add("3 refined patch 3D", f"9x9, centre -> {r_fine}x{r_fine} (jump {r_fine})", r,
            f"{abs(r['volume'] / v_ref - 1):.2%} vol", note=f"coarse openings moved {moved:.1e} of max")
    CURVES["patch"] = patch_curve


# ------------------------------------------------------------ 4. edge extensions
def case_edge_extensions():
    print("4. edge extension lines", flush=True)

    def offset(n, shift):
        h = 1.0 / n
        first = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 1.0, 1.0, n, n)
        second = hd.mesh.rectangle([1.5, 0.5 * h + shift * h, 0], [1, 0, 0], [0, 1, 0], 1.0, 1.0, n, n,
                                   fracture_id=1)
        return hd.mesh.concatenate([first, second])

    for n in (8, 16):
        r = run_both(offset(n, 0.0))
        changes = []
        for shift in (1e-9, 1e-7, 1e-5):
            moved = hd.solve(hd.ElasticityOperator(offset(n, shift), MAT), -P * offset(n, shift).normals)
            changes.append(np.abs(moved - r["dd"]).max() / np.abs(r["dd"]).max())
        add("4 edge extensions 3D", f"coplanar squares offset h/2, {n}x{n} each", r,
            "DD change for shift d: " + ", ".join(f"{c:.0e}" for c in changes),
            note="shifts 1e-9, 1e-7, 1e-5 h: change ~ shift (Lipschitz)")
    mesh = hd.mesh.concatenate([hd.mesh.line([-2.05, 0], [-0.05, 0], 40),
                                hd.mesh.line([0.05, 0], [2.05, 0], 40, fracture_id=1)])
    r = run_both(mesh, leaf_size=16)
    add("4 edge extensions 2D", "collinear cracks, gap h/5", r,
        f"symmetry {np.abs(r['w'][:40] - r['w'][40:][::-1]).max() / r['w'].max():.0e}")


# ------------------------------------------------------------- 5. scale separation
def case_scales():
    print("5. scale separation", flush=True)
    # 2D with 5 small fractures: a block then holds few small-fracture rows/columns,
    # where the ACA without its convergence check failed in 70-80% of the layouts
    for dim, small in ((2, 30), (2, 5), (3, 20)):
        for eps in (1e-4, 1e-6):
            worst_block, worst_fracture, failing, its, t_h, t_d, hd_err = 0.0, 0.0, 0, [], 0.0, 0.0, 0.0
            seeds = range(8)
            for seed in seeds:
                mesh = mixed_scales(dim, seed, small)
                r = run_both(mesh, eps=eps)
                op = r["op_h"]
                block = float(op.hmatrix.admissible_block_errors(n_samples=10**8).max())
                dd_h = r["dd_h"]
                per = max(np.linalg.norm(dd_h[mesh.fracture_id == f] - r["dd"][mesh.fracture_id == f])
                          / np.linalg.norm(r["dd"][mesh.fracture_id == f]) for f in np.unique(mesh.fracture_id))
                worst_block = max(worst_block, block)
                worst_fracture = max(worst_fracture, per)
                failing += block > 10 * eps
                its.append(r["its"])
                t_h += r["t_h"]
                t_d += r["t_d"]
                hd_err = max(hd_err, r["hd"])
            summary = dict(N=mesh.n_elements, hd=hd_err, its=f"{min(its)}-{max(its)}", t_h=t_h / len(seeds),
                           t_d=t_d / len(seeds), finite=True)
            add(f"5 0.1 m + 100 m {dim}D", f"{small} small fractures, eps {eps:g}, 8 seeds", summary,
                f"worst block {worst_block:.1e} ({worst_block / eps:.0f} eps)",
                note=f"blocks > 10 eps in {failing}/8 seeds; worst per-fracture DD error {worst_fracture:.1e}")


# ------------------------------------------------------- 6. tilted and curved cracks
def case_tilted_curved():
    print("6. tilted penny, arc crack", flush=True)
    tilted = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    centre = np.array([0.3, -0.2, 0.1])
    for h in (0.25, 0.125, 0.0625):
        results = {}
        for label, normal in (("aligned", [0, 0, 1]), ("tilted", tilted)):
            mesh = hd.mesh.penny(centre, normal, 1.0, h)
            results[label] = run_both(mesh)
        r = results["tilted"]
        same = np.abs(r["w"] - results["aligned"]["w"]).max() / r["w"].max()
        add("6 tilted penny 3D", f"normal (1,2,3)/sqrt14, h=R/{1 / h:g}", r,
            f"{r['volume'] / an.sneddon_volume(1.0, P, MAT) - 1:+.1%} vol",
            note=f"= aligned to {same:.0e}; aligned GMRES its {results['aligned']['its']}")
    for half_angle_deg in (5.0, 45.0, 90.0, 144.0):
        half_angle = np.radians(half_angle_deg)
        volumes, last = [], None
        for n in (32, 64, 128, 256, 512):
            t = np.linspace(-half_angle, half_angle, n + 1) + np.pi / 2
            nodes = np.column_stack([np.cos(t), np.sin(t)])
            mesh = hd.Mesh2D.from_segments(nodes[1:], nodes[:-1])
            last = run_both(mesh, leaf_size=16)
            volumes.append(last["volume"])
        steps = np.diff(volumes)
        order = np.log2(steps[-2] / steps[-1])
        extrapolated = volumes[-1] + steps[-1] / (2**order - 1)
        griffith = np.pi * half_angle**2 * (1 - MAT.poisson_ratio) * P / MAT.shear_modulus
        add("6 arc crack 2D", f"half angle {half_angle_deg:g} deg, n=512", last,
            f"{volumes[-1] / extrapolated - 1:+.2%} vol vs extrapolated",
            note=f"observed order {order:.2f}; V/V_Griffith(arc length) {extrapolated / griffith:.4f}")


# ------------------------------------------------------------- 7. coupled scaling
def case_coupled():
    print("7. coupled system scaling", flush=True)
    from hmatddm.mesh import topology
    from hmatddm.coupled import ElasticSolver, StepProblem
    from hmatddm.coupled.scaled_system import _CoupledLinearSystem
    from hmatddm.flow import LeakOff, LubricationModel, fracture_compliance

    rows = []
    for length in (3.0, 30.0, 300.0):
        for n in (10, 40):
            mesh = hd.mesh.line([-length / 2, 0], [length / 2, 0], n)
            flow = LubricationModel(areas=mesh.areas, normals=mesh.normals,
                                    faces=topology.element_faces(mesh, height=1.0),
                                    fluid=hd.Fluid(viscosity=1e-3, compressibility=4.5e-10),
                                    leak_off=LeakOff(coefficient=0.0, pore_pressure=0.5e6),
                                    injection_elements=np.array([n // 2]), injection_rates=np.array([5e-4]),
                                    wellbore_volumes=np.array([0.5]), minimum_width=1e-5)
            op = hd.ElasticityOperator(mesh, MAT, backend="dense")
            width_old = 1e-4 * (1 - (mesh.centers[:, 0] / (0.525 * length)) ** 2)
            problem = StepProblem(elastic=ElasticSolver(op, rtol=1e-11), normals=mesh.normals,
                                  far_field=np.tile([0.0, 0.5e6], n), flow=flow,
                                  compliance=fracture_compliance(mesh, MAT), dt=1.0, width_old=width_old,
                                  pressure_old=np.full(n, 1e6),
                                  leak_off_rate=flow.leak_off_rate(np.zeros(n), 0.0, 1.0))
            dd0 = (width_old[:, None] * mesh.normals).ravel()
            matrix, flow_rhs = problem.flow_matrices(dd0)
            system = _CoupledLinearSystem(problem, matrix, dd0, np.full(n, 1e6))
            b = np.zeros((2 * n, n))
            for i in range(n):
                b[2 * i:2 * i + 2, i] = mesh.normals[i]
            full = np.block([[op.to_dense(), b], [problem.coupling.toarray(), matrix.toarray()]])
            scaled = np.column_stack([system.operator @ e for e in np.eye(full.shape[0])])
            rhs = np.concatenate([problem.far_field, flow_rhs])
            direct = np.linalg.solve(full, rhs)
            counter = {"unscaled": 0, "scaled": 0, "krylov": 0}

            def callback_for(key):
                def callback(_):
                    counter[key] += 1
                return callback

            x, _ = spla.gmres(full, rhs, rtol=1e-9, atol=0.0, restart=100, maxiter=20,
                              callback=callback_for("unscaled"), callback_type="pr_norm")
            res_u = np.linalg.norm(full @ x - rhs) / np.linalg.norm(rhs)
            err_u = np.linalg.norm(x[2 * n:] - direct[2 * n:]) / np.linalg.norm(direct[2 * n:])
            y, _ = spla.gmres(system.operator, system.rhs(flow_rhs), rtol=1e-9, atol=0.0, restart=100, maxiter=20,
                              callback=callback_for("scaled"), callback_type="pr_norm")
            dd, p = system.split(y)
            err_s = np.linalg.norm(p - direct[2 * n:]) / np.linalg.norm(direct[2 * n:])
            spla.gmres(system.operator, system.rhs(flow_rhs), rtol=1e-9, atol=0.0, restart=100, maxiter=20,
                       M=system.compliance_preconditioner(1.0), callback=callback_for("krylov"),
                       callback_type="pr_norm")
            rows.append([f"{length:g}", n, 3 * n, f"{np.linalg.cond(full):.1e}", f"{np.linalg.cond(scaled):.1e}",
                         f"{counter['unscaled']} (res {res_u:.0e}, p error {err_u:.0e})",
                         f"{counter['scaled']} (p error {err_s:.0e})", counter["krylov"]])
            print("  ", rows[-1], flush=True)
    return markdown_table(["crack length (m)", "elements", "unknowns", "cond unscaled", "cond scaled (M1^-1 A M2)",
                           "GMRES its unscaled", "GMRES its scaled", "its scaled + compliance precond. (krylov)"],
                          rows)


def plots():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for key, marker in (("2D", "o"), ("3D", "s")):
        curve = [c for c in CURVES[key] if c[0] <= 50]
        k, ratio, its = (np.array(v, dtype=float) for v in zip(*curve))
        axes[0].semilogx(k, ratio, marker=marker, label=f"{key}: opening / single crack")
        axes[1].semilogx(k, its, marker=marker, label=key)
    axes[0].axhline(0.5, color="gray", ls=":", label="coalesced limit 1/2")
    axes[0].axhline(0.0, color="k", lw=0.5)
    axes[0].axvspan(0.05, 0.5, color="red", alpha=0.1, label="spacing < h/2: wrong")
    axes[0].set_xlabel("spacing / element size h")
    axes[0].set_ylabel("opening (volume) / single crack")
    axes[0].set_ylim(-1, 1.1)
    axes[0].legend(fontsize=8)
    axes[0].set_title("Two parallel pressurised cracks")
    axes[1].set_xlabel("spacing / element size h")
    axes[1].set_ylabel("GMRES iterations (eps 1e-6, rtol 1e-10)")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "hard_cases_spacing.png"), dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    aspect, err = zip(*CURVES["thin"])
    axes[0].loglog(aspect, err, "o-", label="3D square, 8 x 8k elements (aspect 1:k)")
    jump, err = zip(*CURVES["patch"])
    axes[0].loglog(jump, err, "s-", label="3D 9x9 with centre refined (size jump)")
    axes[0].set_xlabel("aspect ratio / size jump")
    axes[0].set_ylabel("|volume error| vs extrapolated")
    axes[0].legend(fontsize=8)
    for layout, curve in CURVES["graded"].items():
        ratio, err = zip(*curve)
        axes[1].semilogx(ratio, err, "o-", label=f"2D, fine block at {layout}")
    axes[1].set_xlabel("neighbouring size jump")
    axes[1].set_ylabel("max |w - Griffith| / w_max  (|x| < a/2)")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "hard_cases_mesh_quality.png"), dpi=110)
    plt.close(fig)


CASES = {"intersections": case_intersections, "parallel": case_parallel, "quality": case_mesh_quality,
         "edges": case_edge_extensions, "scales": case_scales, "tilted": case_tilted_curved}


def main(selected=()):
    unknown = sorted(set(selected) - set(CASES) - {"coupled"})
    if unknown:
        raise SystemExit(f"unknown case(s) {unknown}; choose from {sorted(CASES) + ['coupled']}")
    everything = not selected
    os.makedirs(OUT, exist_ok=True)
    start = time.perf_counter()
    print(machine(), flush=True)
    for name, case in CASES.items():
        if everything or name in selected:
            case()
    coupled = case_coupled() if everything or "coupled" in selected else "(not run)"
    if everything:
        plots()
    header = ["case", "variant", "N", "dense vs hmatrix (DD)", "closed-form / reference error", "GMRES its",
              "hmatrix build+solve (s)", "dense build+solve (s)", "notes"]
    table = markdown_table(header, [[r["case"], r["variant"], r["N"], fmt(r["hd"]), r["error"], r["its"],
                                     f"{r['t_h']:.2f}", "-" if np.isnan(r["t_d"]) else f"{r['t_d']:.2f}",
                                     r["note"] + ("" if r["finite"] else " NON-FINITE")] for r in ROWS])
    text = f"{machine()}\n\n{table}\n\n### Coupled system (7)\n\n{coupled}\n"
    print()
    print(text)
    print(f"total {time.perf_counter() - start:.0f} s")
    name = "hard_cases" if everything else "hard_cases_partial"
    with open(os.path.join(OUT, f"{name}.md"), "w") as f:
        f.write(text)
    with open(os.path.join(OUT, f"{name}.json"), "w") as f:
        json.dump([{k: (v if not isinstance(v, (np.floating, np.integer)) else v.item()) for k, v in r.items()}
                   for r in ROWS], f, indent=1, default=str)


if __name__ == "__main__":
    main(tuple(sys.argv[1:]))
