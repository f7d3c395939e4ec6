"""Power-law fracturing fluids (issue 34): accuracy of the viscosity-dominated KGD fracture
against Adachi and Detournay (2002) and the cost of power-law radial runs against the
Newtonian one (CPU time, nonlinear and GMRES iterations).

    python benchmarks/bench_power_law.py            # both parts (a few minutes, one thread)
    python benchmarks/bench_power_law.py --kgd      # the KGD part only
    python benchmarks/bench_power_law.py --radial   # the radial part only

KGD: ref. Table 4.2's plane-strain setup (3 initial segments of 1 m, Q = 5e-4 m^3/s into 1 m
of height, E = 25 GPa), K_Ic = 0.05 MPa m^1/2, asymptotic front, dense operator, 3 s steps to
60 s; errors of the half-length and of the opening at the injection point against
:func:`hmatddm.analytical.power_law.kgd_power_law_vertex`, and the exponent of the
half-length fitted from 21 s on. Plot: power_law_kgd.png.

Radial: ref. Table 4.1's radial setup (3 x 3 initial elements of h = 1 m, Q = 0.01 m^3/s,
G = 24 GPa, K_Ic = 0.3 MPa m^1/2, asymptotic front, H-matrix operator, 1 s steps) to 12 s with
water (1 cP) and power-law fluids whose M-vertex radius at 12 s is the water's (the same
mesh: a cost per element); radius and opening at the injection point against
:func:`hmatddm.analytical.power_law.radial_power_law_vertex` (at n = 1 too).
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from _common import machine, print_table  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.analytical import power_law  # noqa: E402

OUT = os.path.dirname(os.path.abspath(__file__))


def fluid(n, consistency):
    if n is None:
        return hd.Fluid(consistency, 4.5e-10)
    return hd.Fluid(compressibility=4.5e-10, rheology="power-law", consistency=consistency, flow_index=n)


def run(sim, end):
    cpu, wall = time.process_time(), time.perf_counter()
    records = sim.run(end)
    return records, time.process_time() - cpu, time.perf_counter() - wall


def totals(records):
    return (sum(r["nonlinear_iterations"] for r in records), sum(r["linear_iterations"] for r in records),
            sum(r.get("front_iterations", 0) for r in records))


def kgd_part():
    material = hd.Elastic(10e9, 0.25)
    rows, curves = [], {}
    for n, consistency in ((None, 1e-3), (0.8, 0.01), (0.5, 0.1)):
        sim = hd.Simulation(hd.mesh.line([-1.5, 0.0], [1.5, 0.0], 3), material, fluid(n, consistency),
                            [hd.Cluster((0.0, 0.0), 5e-4, 0.5)], far_field_stress=np.diag([-1e6, -0.5e6]),
                            time_step=3.0, propagation=hd.Propagation(toughness=0.05e6, front="asymptotic"),
                            initial_pressure=1e6, initial_opening=1e-4, backend="dense")
        records, cpu, wall = run(sim, 60.0)
        t = np.array([r["time"] for r in records])
        length = np.array([r["half_length"] for r in records])
        opening = np.array([r["max_opening"] for r in records])
        index = 1.0 if n is None else n
        exact_length, exact_opening, _ = power_law.kgd_power_law_vertex(t, 5e-4, consistency, index, material)
        late = t >= 21.0
        length_error = length[late] / exact_length[late] - 1.0
        opening_error = opening[late] / exact_opening[late] - 1.0
        exponent = np.polyfit(np.log(t[late]), np.log(length[late]), 1)[0]
        nonlinear, linear, front = totals(records)
        name = "Newtonian 1 cP" if n is None else f"n = {n}, K = {consistency}"
        rows.append([name, len(records), records[-1]["n_elements"], nonlinear, linear, front, f"{cpu:.2f}",
                     f"{wall:.2f}", f"{length_error.min() * 100:+.2f}..{length_error.max() * 100:+.2f}",
                     f"{length_error[-1] * 100:+.2f} / {opening_error[-1] * 100:+.2f}",
                     f"{opening_error.min() * 100:+.2f}..{opening_error.max() * 100:+.2f}",
                     f"{exponent:.4f} ({(index + 1) / (index + 2):.4f})"])
        curves[name] = (t, length, exact_length)
    print_table(["fluid", "steps", "elements", "nonlinear its", "GMRES its", "front its", "CPU (s)", "wall (s)",
                 "length error from 21 s (%)", "length / opening error at 60 s (%)", "opening error from 21 s (%)",
                 "exponent (exact)"], rows)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for name, (t, length, exact) in curves.items():
        line, = ax.plot(t, length, "o", ms=3, label=f"{name} (simulation)")
        ax.plot(t, exact, "-", color=line.get_color(), lw=1, label=f"{name} (Adachi & Detournay)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("half-length (m)")
    ax.set_title("KGD, viscosity dominated: power-law fluids")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "power_law_kgd.png"), dpi=120)


def matched_consistency(n, end, material):
    """K of the power-law fluid whose radial M-vertex reaches the radius of the 1 cP one at
    ``end`` (the same mesh sizes: the cost comparison is per element)."""
    target = power_law.radial_power_law_vertex(end, RADIAL_RATE, 1e-3, 1.0, material)[0]
    gamma = power_law.solve_radial(n).gamma
    m_prime = (material.plane_strain_modulus * RADIAL_RATE ** (n + 2.0) * end ** (2.0 * n + 2.0)
               / (target / gamma) ** (3.0 * n + 6.0))
    return m_prime / (2.0 ** (n + 1.0) * (2.0 * n + 1.0) ** n / n**n)


RADIAL_RATE = 0.01


def radial_part(end=12.0):
    material = hd.Elastic(24e9, 0.25)
    rows = []
    for n in (None, 0.8, 0.5):
        consistency = 1e-3 if n is None else matched_consistency(n, end, material)
        mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 3)
        sim = hd.Simulation(mesh, material, fluid(n, consistency), [hd.Cluster((0, 0, 0), RADIAL_RATE, 0.005)],
                            far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                            propagation=hd.Propagation(toughness=0.3e6, front="asymptotic"),
                            initial_pressure=10e6, initial_opening=4e-6, backend="hmatrix")
        records, cpu, wall = run(sim, end)
        index = 1.0 if n is None else n
        radius, opening = power_law.radial_power_law_vertex(end, RADIAL_RATE, consistency, index, material)
        injection = sim.injection_elements[0]
        centre = float(sim.state.dd[injection] @ sim.state.mesh.normals[injection])
        nonlinear, linear, front = totals(records)
        k_m = power_law.radial_power_law_regime(end, RADIAL_RATE, consistency, index, 0.3e6, material)
        rows.append(["Newtonian 1 cP" if n is None else f"n = {n}, K = {consistency:.3g}", f"{k_m:.2f}",
                     len(records), records[-1]["n_elements"], nonlinear, linear, front, f"{cpu:.1f}", f"{wall:.1f}",
                     f"{(records[-1]['radius'] / radius - 1) * 100:+.2f} / {(centre / opening - 1) * 100:+.2f}"])
    print_table(["fluid", "K_m", "steps", "elements", "nonlinear its", "GMRES its", "front its", "CPU (s)",
                 "wall (s)", "radius / opening error at 12 s (%)"], rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kgd", action="store_true")
    parser.add_argument("--radial", action="store_true")
    args = parser.parse_args()
    print(f"Calibration at the start: {machine()}")
    warm = hd.Simulation(hd.mesh.line([-1.5, 0.0], [1.5, 0.0], 3), hd.Elastic(10e9, 0.25), fluid(0.5, 0.1),
                         [hd.Cluster((0.0, 0.0), 5e-4, 0.5)], far_field_stress=np.diag([-1e6, -0.5e6]), time_step=3.0,
                         propagation=hd.Propagation(toughness=0.05e6, front="asymptotic"), initial_pressure=1e6,
                         initial_opening=1e-4, backend="dense")
    warm.run(6.0)  # compiled code warm before the first timed run
    both = not (args.kgd or args.radial)
    if args.kgd or both:
        kgd_part()
    if args.radial or both:
        radial_part()


if __name__ == "__main__":
    main()
