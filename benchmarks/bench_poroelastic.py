"""Poroelastic effects on the remote failure of natural fractures (ref. Sec. 5.3.3,
Table 5.2, Figs 5.16-5.18): the three cases of the study, at the reference's set-up.

    python benchmarks/bench_poroelastic.py                 # the three cases, 25 s
    python benchmarks/bench_poroelastic.py --end-time 5    # a quick look

The set-up of ref. Sec. 5.3.3 and Table 5.2: a planar hydraulic fracture grows from the
origin in the y-z plane (S_hmin 35.85 MPa along x, S_Hmax 39.44 MPa along y, S_v 45 MPa
along z), confined to a formation 22 m high, with 2 m elements; 0.01 m^3/s for 25 s
through a 5 m^3 wellbore; G 6.62 GPa, drained K 11.03 GPa (nu 0.24994), K_Ic
1.5 MPa m^1/2, mu 1 cP, c_f 4.545e-4 1/MPa, no leak-off, pore pressure 30.20 MPa. Natural
fractures at 45 deg from the y axis, placed at random in a 50 m (x) x 100 m (y) region
on the z = 0 plane only, one element (2 m) high, friction 0.25, no cohesion: near the
critical state (ratio of shear stress to frictional strength 0.964 in the far field).
The three cases: no poroelasticity (drained nu, B = 0); an oil reservoir (K_f 2.2 GPa)
and a gas reservoir (K_f 30 MPa), with Biot 0.8 and porosity 0.15, whose undrained nu_u
and Skempton B come from :class:`hmatddm.UndrainedRock` (ref. Eqs 5.19-5.21): the whole
DDM runs with nu_u and the remote-failure check adds ``-B sigma_m`` to the pore pressure.

What the reference does not give, chosen here and stated: the number and lengths of the
natural fractures (here a power-law network of :mod:`hmatddm.network`, a = 2, lengths
2-10 m, 0.04 fractures per m^2, i.e. about 200, one fixed seed, the azimuth fixed by
kappa = 1e6), the initial fracture (6 m x 6 m at the origin, 3 x 3 elements) and its
initial pressure (36.2 MPa), the time step (1 s). Every natural element keeps the
initial pore pressure 30.2 MPa plus the undrained change; the reference's Figs 5.16-5.18
show the failed natural fractures, not their count, so the comparison is qualitative:
failures near the fracture only, more with oil than with gas.

Prints a table (failed natural elements, activated ones, hydraulic elements, the
fracture's extent, CPU and wall time per case) and saves ``poroelastic_plan.png`` (plan
view at z = 0 of the three cases) next to this script unless --plot says otherwise.
"""
import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.network import NetworkSpec, generate_network  # noqa: E402
from hmatddm.simulation.natural import NaturalNetwork, plan_segments  # noqa: E402
from hmatddm.simulation.state import Origin  # noqa: E402

G, K = 6.62e9, 11.03e9                      # ref. Table 5.2
DRAINED_NU = (3 * K - 2 * G) / (2 * (3 * K + G))
BIOT, POROSITY = 0.8, 0.15
CASES = (("1: no poroelasticity", None), ("2: oil", 2.2e9), ("3: gas", 30.0e6))
#: a check of ours, not the reference's: the oil case's B with the drained nu, so that the
#: hydraulic fracture is case 1's and only the pore-pressure change differs
B_ONLY = ("2b: oil B, drained nu", 2.2e9)
S_HMIN, S_HMAX, S_V = 35.85e6, 39.44e6, 45.0e6
FAR_FIELD = -np.diag([S_HMIN, S_HMAX, S_V])  # tension positive
PORE_PRESSURE = 30.20e6
HEIGHT, ELEMENT = 22.0, 2.0


def natural_mesh(seed):
    """The natural fractures at z = 0 (one 2 m element high), less those that cross the
    hydraulic fracture's plane x = 0 (the reference keeps them off it: "the distance
    between hydraulic and natural fractures is 25 m at a maximum")."""
    spec = NetworkSpec(region=(-25.0, 25.0, -50.0, 50.0), density=0.04, length_exponent=2.0, l_min=2.0, l_max=10.0,
                       mean_azimuths_deg=(45.0,), kappas=(1e6,), height=ELEMENT, z_center=0.0, seed=seed)
    network = generate_network(spec)
    p0, p1 = np.asarray(network.p0), np.asarray(network.p1)
    keep = np.sign(p0[:, 0]) * np.sign(p1[:, 0]) > 0
    return network.subset(np.flatnonzero(keep)).to_mesh3d(ELEMENT, 1)


def constants(fluid_bulk_modulus, b_only=False):
    """(nu the DDM runs with, Skempton B) of a case."""
    if fluid_bulk_modulus is None:
        return DRAINED_NU, 0.0
    rock = hd.UndrainedRock(G, K, BIOT, fluid_bulk_modulus, POROSITY)
    return (DRAINED_NU if b_only else rock.undrained_poisson_ratio), rock.skempton


def properties(skempton):
    return hd.NaturalFractureProperties(friction=0.25, cohesion=0.0, crossing="mohr-coulomb",
                                        pore_pressure=PORE_PRESSURE, skempton=skempton)


def build(fluid_bulk_modulus, seed, coupled=False, b_only=False):
    """The :class:`hmatddm.Simulation` of a case: a planar hydraulic fracture alone
    (``coupled=False``; the natural fractures are checked apart, see :func:`run_case`),
    or with the natural fractures in the run (remotely failed elements join it and slip,
    the fracture may turn and be deflected)."""
    nu, skempton = constants(fluid_bulk_modulus, b_only)
    mesh = hd.mesh.rectangle([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 6.0, 6.0, 3, 3)
    half = 0.5 * HEIGHT
    propagation = hd.Propagation(toughness=1.5e6, turning="plan" if coupled else "none",
                                 bounds=((-np.inf, np.inf), (-np.inf, np.inf), (-half, half)))
    return hd.Simulation(mesh, hd.Elastic(G, nu), hd.Fluid(viscosity=1e-3, compressibility=4.545e-10),
                         [hd.Cluster((0.0, 0.0, 0.0), rate=0.01, wellbore_volume=5.0)],
                         FAR_FIELD, 1.0, propagation=propagation,
                         leak_off=hd.LeakOff(coefficient=0.0, pore_pressure=PORE_PRESSURE),
                         initial_pressure=36.2e6, initial_opening=1e-4, backend="dense",
                         singular_correction="average", natural_fractures=natural_mesh(seed) if coupled else None,
                         natural=properties(skempton) if coupled else None, remote_failure=coupled,
                         contact="all" if coupled else "natural")


def run_case(name, fluid_bulk_modulus, end_time, seed, coupled=False, b_only=False):
    """One case. Planar (``coupled=False``): after every step the Coulomb check with the
    undrained pore-pressure change (:meth:`NaturalNetwork.remote_failure`, ref. Eqs
    5.18, 5.23-5.28) on every natural element, with the hydraulic fracture's DDs; an
    element that failed once counts as failed (the reference's figures show the failed
    natural fractures at the end)."""
    nu, skempton = constants(fluid_bulk_modulus, b_only)
    sim = build(fluid_bulk_modulus, seed, coupled, b_only)
    network = NaturalNetwork(natural_mesh(seed), properties(skempton))
    ever = np.zeros(network.mesh.n_elements, bool)
    pore = np.zeros(network.mesh.n_elements)
    check = [0.0, 0.0]

    def after_step(simulation, record):
        if coupled:
            return
        wall, cpu = time.perf_counter(), time.process_time()
        s = simulation.state
        failed, _, _, change = network.remote_failure(s.mesh, s.dd, simulation.material, FAR_FIELD,
                                                      np.ones(network.mesh.n_elements, bool))
        ever[:] |= failed
        np.maximum(pore, change, out=pore)
        check[0] += time.perf_counter() - wall
        check[1] += time.process_time() - cpu

    wall, cpu = time.perf_counter(), time.process_time()
    records = sim.run(end_time=end_time, callback=after_step)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    s = sim.state
    hydraulic = s.origin == Origin.HYDRAULIC
    y = s.mesh.centers[hydraulic, 1]
    if coupled:
        failed_centers = s.mesh.centers[s.origin == Origin.FAILED]
        n_failed = len(failed_centers)
    else:
        failed_centers = network.mesh.centers[ever]
        n_failed = int(ever.sum())
    return {"case": name, "nu": nu, "B": skempton, "failed": n_failed, "failed_mask": ever.copy(),
            "activated": int(np.count_nonzero(s.origin == Origin.ACTIVATED)), "hydraulic": int(hydraulic.sum()),
            "half_length": 0.5 * (y.max() - y.min()) + ELEMENT / 2, "targets": network.mesh.n_elements,
            "max_distance": float(np.abs(failed_centers[:, 0]).max(initial=0.0)),
            "max_pore_change": float(pore.max()), "pressure": float(records[-1]["wellbore_pressure"][0]),
            "wall": wall, "cpu": cpu, "check_wall": check[0], "check_cpu": check[1], "sim": sim, "coupled": coupled}


def plot(results, path, seed):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    network = natural_mesh(seed)
    p0, p1, _ = plan_segments(network)
    fig, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 7), sharey=True)
    for ax, result in zip(np.atleast_1d(axes), results):
        s = result["sim"].state
        for k, (a, b) in enumerate(zip(p0, p1)):
            failed = not result["coupled"] and result["failed_mask"][k]
            ax.plot([a[0], b[0]], [a[1], b[1]], color="tab:red" if failed else "0.75", lw=2.2 if failed else 0.8)
        at_mid = np.abs(s.mesh.centers[:, 2]) < ELEMENT  # the row at z = 0
        q0, q1, _ = plan_segments(s.mesh)
        for origin, color, label in ((Origin.HYDRAULIC, "tab:blue", "hydraulic"),
                                     (Origin.ACTIVATED, "tab:green", "activated"),
                                     (Origin.FAILED, "tab:red", "failed remotely")):
            chosen = np.flatnonzero((s.origin == origin) & at_mid)
            for k, i in enumerate(chosen):
                ax.plot([q0[i, 0], q1[i, 0]], [q0[i, 1], q1[i, 1]], color=color, lw=2.2,
                        label=label if k == 0 else None)
        ax.set_title(f"Case {result['case']}\nnu = {result['nu']:.4f}, B = {result['B']:.4g}: "
                     f"{result['failed']} failed")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.legend(loc="lower right", fontsize=8)
    np.atleast_1d(axes)[0].set_ylabel("y (m)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--end-time", type=float, default=25.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--seeds", type=int, default=5, help="networks drawn for the table of failed counts")
    parser.add_argument("--plot", default=os.path.join(HERE, "poroelastic_plan.png"))
    parser.add_argument("--coupled", action="store_true",
                        help="natural fractures in the run: failed elements join and slip, the fracture may turn")
    args = parser.parse_args(argv)
    print(f"Machine: {machine()}")
    results = [run_case(name, k_f, args.end_time, args.seed, args.coupled) for name, k_f in CASES]
    if not args.coupled:
        results.append(run_case(*B_ONLY, args.end_time, args.seed, b_only=True))
    rows = [[r["case"], f"{r['nu']:.4f}", f"{r['B']:.4g}", r["failed"], r["activated"], r["hydraulic"],
             f"{r['half_length']:.1f}", f"{r['max_distance']:.1f}", f"{r['max_pore_change'] / 1e6:.3f}",
             f"{r['pressure'] / 1e6:.3f}", f"{r['cpu']:.1f}", f"{r['wall']:.1f}",
             f"{r['check_cpu']:.2f} / {r['check_wall']:.2f}"] for r in results]
    mode = "coupled (failed elements slip, turning)" if args.coupled else "planar fracture, natural fractures checked"
    print(f"\n{natural_mesh(args.seed).n_elements} natural elements at z = 0 (seed {args.seed}); "
          f"t = {args.end_time:g} s; {mode}")
    print_table(["case", "nu (DDM)", "B", "failed NF elements", "activated NF elements", "HF elements",
                 "HF half-length (m)", "farthest failure from HF (m)", "largest dp (MPa)", "wellbore p (MPa)",
                 "run CPU (s)", "run wall (s)", "checks CPU / wall (s)"], rows)
    if args.seeds > 1 and not args.coupled:
        seeds = range(args.seed, args.seed + args.seeds)
        cases = [(name, k_f, False) for name, k_f in CASES] + [(*B_ONLY, True)]
        table = [[name] + [run_case(name, k_f, args.end_time, seed, b_only=b_only)["failed"] for seed in seeds]
                 for name, k_f, b_only in cases]
        print_table(["case"] + [f"failed, seed {seed}" for seed in seeds], table)
    results = results[:3]
    plot(results, args.plot, args.seed)
    print(f"plan view: {args.plot}")


if __name__ == "__main__":
    main()
