"""Carter leak-off (ref. Eq. 4.25) against the leak-off-dominated and transition closed
forms of a plane-strain (KGD) fracture.

    python benchmarks/bench_leak_off.py              # the cases below, 2D, dense
    python benchmarks/bench_leak_off.py --quick      # shorter runs

Each case is a KGD fracture (element switch front, 0.1 m elements, a 0.4 m initial
fracture, G 1 GPa, nu 0.25, the fluid pressure ``sigma_0 + p_net`` leaking at ``c_l (p - p_r) / (t -
tau)^(1/2)`` with ``sigma_0 - p_r`` = 20 MPa, so the net pressure changes the leak-off rate by a few
percent only), compared at every step with:

* the K-K~ edge, :func:`hmatddm.analytical.kgd_toughness_leak_off_edge` (zero viscosity,
  Griffith's opening at uniform net pressure, Carter's leak-off with the net pressure in
  it, mass balance integrated in time): the toughness cases from the K vertex (storage)
  through the transition to the K~ vertex;
* the leak-off vertex size ``Q t^(1/2) / (pi C')`` with ``C' = c_l (sigma_0 - p_r + p_net)``
  (K~ and M~ alike), :func:`hmatddm.analytical.kgd_leak_off_half_length`: where leak-off
  dominates, whatever the viscosity -- the M~ case has a viscosity-dominated fracture
  (K_m below 1), compared with it alone.

And radial fractures (3D, 0.25 m elements, 20 s) against the radial K vertex and the
radial K-K~ edge (:func:`hmatddm.analytical.radial_toughness_leak_off_edge`).

``--viscous`` runs only the viscous leak-off rows (issue 36): a KGD fracture on the
asymptotic front with mu 1e-3 Pa s, K_Ic 1 kPa m^1/2 (K_m 0.011), c_l 1e-10 (C' = 2e-3 m/s^1/2 at
sigma_0 - p_r = 20 MPa), Q 1e-3 m^2/s, G 1 GPa, nu 0.25, 16 s (C_m 4.4 to 7.8: 1.7% of the fluid
stored at the end) at three element sizes, against the M~ vertex
(:func:`hmatddm.analytical.viscous_leak_off.kgd_m_leak_off_vertex`) and Dontsov's (2017)
solution at the run's K_m and C_m (:func:`~hmatddm.analytical.viscous_leak_off.kgd_leak_off_transition`),
and a transition case (mu 0.02 Pa s, C_m 2.7-4.8) against Dontsov's solution; the net pressure
as ``Pi = p / (E'^3 mu' C'^2 / (Q t))^(1/4)``, the M~ scaling, against the vertex's 0.7515 (its
similarity solution, :func:`~hmatddm.analytical.viscous_leak_off.kgd_m_leak_off_similarity`;
Dontsov's solution gives no pressure).

Then the radial rows (``RADIAL_VISCOUS_CASES``; ``--radial N`` runs row N alone, ``--h`` and
``--end-time`` set its element size and end): a fracture from M towards M~ (mu 1e-3 Pa s, C_m
2.4-6.9) and one deep in M~ (mu 2.5e-5 Pa s, c_l 2e-10, Q 2e-2 m^3/s: C_m 3.5 at the first
step to 25 at 8 s), each against Dontsov's (2016) solution with leak-off and the radial M~
vertex (``radial-m-leak-off``), with the reference block's warning where the vertex does not
apply over the run.

Also the leak-off coefficient from the reservoir (ref. Eq. 4.26,
:func:`hmatddm.flow.carter_coefficient`) for the reference's Table 5.2 / 6.2 rock (shown,
not run: with ``k_r = 0`` it is zero).

Prints a table per case (time, half-length, the closed form, the error, the share of the
injected volume that leaked off, wellbore net pressure), the CPU and wall time of each run,
and saves ``leak_off_kgd.png`` next to this script unless --plot says otherwise.
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
from hmatddm.analytical import (kgd_k_vertex, kgd_leak_off_half_length, kgd_regime,  # noqa: E402
                                kgd_toughness_leak_off_edge, radial_k_vertex, radial_leak_off_radius,
                                radial_toughness_leak_off_edge)
from hmatddm.errors import ConvergenceError  # noqa: E402
from hmatddm.flow import carter_coefficient  # noqa: E402

MATERIAL = hd.Elastic(1e9, 0.25)
S_HMIN, PORE = 20.0e6, 0.0
ELEMENT = 0.1
INITIAL = 0.4

#: name, injection rate per unit height (m^2/s), c_l (m/(s^1/2 Pa)), K_Ic (Pa m^1/2),
#: viscosity (Pa s), end time (s), time step (s), contact (hd.Simulation's: which elements
#: close). The M~ case needs closing tips (issue 36): with interpenetrating ones (the
#: default "natural") a fresh tip element leaks more than the viscous flow brings it, opens
#: negatively while still leaking, and the front stops for good (the last row shows it).
CASES = (
    ("K (no leak-off)", 1e-3, 0.0, 1e6, 1e-5, 40.0, 1.0, "natural"),
    ("K to K~ transition", 1e-3, 1e-11, 1e6, 1e-5, 40.0, 1.0, "natural"),
    ("K~ (leak-off dominated)", 4e-3, 5e-11, 1e6, 1e-5, 40.0, 1.0, "natural"),
    ("M~ (viscous, leak-off dominated), closing tips", 4e-3, 5e-11, 0.1e6, 0.02, 40.0, 1.0, "all"),
    ("M~, interpenetrating tips (stalls)", 4e-3, 5e-11, 0.1e6, 0.02, 40.0, 1.0, "natural"),
)


def run_case(name, rate, c_l, toughness, viscosity, end_time, dt, contact="natural"):
    mesh = hd.mesh.line([-0.5 * INITIAL, 0.0], [0.5 * INITIAL, 0.0], int(round(INITIAL / ELEMENT)))
    net = toughness / np.sqrt(np.pi * 0.5 * INITIAL)
    sim = hd.Simulation(mesh, MATERIAL, hd.Fluid(viscosity=viscosity, compressibility=0.0),
                        [hd.Cluster((0.0, 0.0), rate=rate)], -np.diag([2 * S_HMIN, S_HMIN]), dt,
                        propagation=hd.Propagation(toughness=toughness),
                        leak_off=hd.LeakOff(coefficient=c_l, pore_pressure=PORE),
                        initial_pressure=S_HMIN + 0.9 * net, initial_opening=1e-5, backend="dense", contact=contact)
    wall, cpu = time.perf_counter(), time.process_time()
    records = sim.run(end_time=end_time)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    t = np.array([r["time"] for r in records])
    length = np.array([r["half_length"] for r in records])
    pressure = np.array([r["wellbore_pressure"][0] for r in records]) - S_HMIN
    stored = np.array([r["fracture_volume"] for r in records])
    injected = np.array([r["injected_volume"] for r in records])
    e_prime = MATERIAL.plane_strain_modulus
    if c_l > 0.0:
        edge, edge_net = kgd_toughness_leak_off_edge(t, rate, c_l, S_HMIN - PORE, toughness, e_prime)
        # the leak-off vertex with the run's own net pressure in C'
        vertex = kgd_leak_off_half_length(t, rate, 1.0) * np.pi / (np.pi * c_l * (S_HMIN - PORE + pressure))
    else:
        edge, _, edge_net = kgd_k_vertex(t, rate, toughness, MATERIAL)
        vertex = np.full_like(t, np.nan)
    k_m = float(kgd_regime(rate, viscosity, toughness, MATERIAL))
    return {"name": name, "t": t, "length": length, "edge": edge, "edge_net": edge_net, "vertex": vertex,
            "net": pressure, "leaked": 1.0 - stored / injected, "wall": wall, "cpu": cpu, "k_m": k_m,
            "c_l": c_l, "rate": rate, "viscous": viscosity > 1e-2, "elements": records[-1]["n_elements"],
            "min_opening": min(r["min_opening"] for r in records), "contact": contact}


#: radial (3D, dense): name, injection rate (m^3/s), c_l; K_Ic 1 MPa m^1/2, mu 1e-5 Pa s, 20 s
RADIAL_CASES = (("radial K (no leak-off)", 1e-3, 0.0), ("radial K to K~", 1e-3, 7e-12),
                ("radial K~", 1e-3, 3e-11))


def run_radial(name, rate, c_l, end_time=20.0, toughness=1e6):
    """A horizontal radial fracture (0.25 m elements, 1 m x 1 m initial square, sigma_v = 20
    MPa above p_r = 0) against the radial K vertex or the radial K-K~ edge."""
    mesh = hd.mesh.rectangle([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, 1.0, 4, 4)
    sim = hd.Simulation(mesh, MATERIAL, hd.Fluid(viscosity=1e-5), [hd.Cluster((0.0, 0.0, 0.0), rate=rate)],
                        -np.diag([2 * S_HMIN, 2 * S_HMIN, S_HMIN]), 1.0, propagation=hd.Propagation(toughness=toughness),
                        leak_off=hd.LeakOff(coefficient=c_l, pore_pressure=PORE),
                        initial_pressure=S_HMIN + 0.9 * np.sqrt(np.pi) * toughness / (2 * np.sqrt(0.5)),
                        initial_opening=1e-5, backend="dense")
    wall, cpu = time.perf_counter(), time.process_time()
    records = sim.run(end_time=end_time)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    t = np.array([r["time"] for r in records])
    radius = np.array([r["radius"] for r in records])
    if c_l > 0.0:
        reference, _ = radial_toughness_leak_off_edge(t, rate, c_l, S_HMIN - PORE, toughness,
                                                      MATERIAL.plane_strain_modulus)
        vertex = radial_leak_off_radius(t, rate, c_l * (S_HMIN - PORE))
    else:
        reference, vertex = radial_k_vertex(t, rate, toughness, MATERIAL)[0], np.full_like(t, np.nan)
    leaked = 1.0 - np.array([r["fracture_volume"] / r["injected_volume"] for r in records])
    return {"name": name, "t": t, "radius": radius, "reference": reference, "vertex": vertex, "leaked": leaked,
            "cpu": cpu, "wall": wall, "elements": records[-1]["n_elements"], "c_l": c_l}


#: viscous leak-off (issue 36): name, viscosity (Pa s), element size (m), initial elements,
#: first step (s), longest step (s)
VISCOUS_CASES = (
    ("M~, 0.1 m", 1e-3, 0.1, 3, 2.0, 2.0),
    ("M~, 0.05 m", 1e-3, 0.05, 3, 0.5, 0.5),
    ("M~, 0.025 m", 1e-3, 0.025, 5, 0.5, 0.5),
    ("M to M~ (mu 0.02), 0.05 m", 0.02, 0.05, 3, 0.5, 0.5),
    ("deep M~ (mu 2.5e-5), 0.05 m", 2.5e-5, 0.05, 3, 0.5, 0.5),
)
VISCOUS = dict(rate=1e-3, c_l=1e-10, toughness=1e3, end_time=16.0)


def viscous_scene(viscosity, h, n_initial, first_step, max_step, end_time):
    """The scene of a viscous leak-off row (VISCOUS_CASES): KGD, the asymptotic front, steps
    that move the front 0.3 elements (the first long enough that the initial elements,
    leaking from t = 0, do not take all the fluid)."""
    import hmatddm.scene as hs

    half = 0.5 * n_initial * h
    text = f"""
dimension = 2
[material]
shear_modulus = 1e9
poisson_ratio = 0.25
[fluid]
viscosity = {viscosity}
compressibility = 0.0
[stress]
s_hmin = 20e6
s_hmax = 40e6
[[cluster]]
position = [0.0, 0.0]
rate = {VISCOUS['rate']}
[[initial_fracture]]
shape = "line"
p0 = [{-half}, 0.0]
p1 = [{half}, 0.0]
element_size = {h}
[propagation]
toughness = {VISCOUS['toughness']}
front = "asymptotic"
[leak_off]
coefficient = {VISCOUS['c_l']}
pore_pressure = 0.0
[numerics]
time_step = "auto"
first_time_step = {first_step}
max_time_step = {max_step}
step_advance = 0.3
end_time = {end_time}
backend = "dense"
initial_pressure = 20e6
initial_opening = 1e-6
[reference]
kind = "kgd-km-leak-off"
"""
    return hs.scene_from_dict(hs.parse_scene(text).data, "viscous-leak-off").data


def run_viscous(name, viscosity, h, n_initial, first_step, max_step, end_time):
    import hmatddm.scene as hs
    from hmatddm.analytical.viscous_leak_off import kgd_leak_off_transition, kgd_m_leak_off_vertex

    data = viscous_scene(viscosity, h, n_initial, first_step, max_step, end_time)
    simulation = hs.build_simulation(data)
    wall, cpu = time.perf_counter(), time.process_time()
    failure = None
    try:
        records = simulation.run(end_time)
    except ConvergenceError as error:  # shown in the table, not hidden
        records, failure = simulation.records, str(error)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    t = np.array([r["time"] for r in records])
    c_prime = VISCOUS["c_l"] * (S_HMIN - PORE)
    e_prime, mu_prime = MATERIAL.plane_strain_modulus, 12.0 * viscosity
    vertex_l, vertex_w = kgd_m_leak_off_vertex(t, VISCOUS["rate"], viscosity, c_prime, MATERIAL)
    dontsov_l, dontsov_w, efficiency = kgd_leak_off_transition(t, VISCOUS["rate"], viscosity, VISCOUS["toughness"],
                                                               c_prime, MATERIAL)
    scale = (e_prime**3 * mu_prime * c_prime**2 / (VISCOUS["rate"] * t)) ** 0.25
    return {"name": name, "t": t, "length": np.array([r["half_length"] for r in records]),
            "w0": np.array([r["max_opening"] for r in records]), "vertex_l": vertex_l, "vertex_w": vertex_w,
            "dontsov_l": dontsov_l, "dontsov_w": dontsov_w, "dontsov_stored": efficiency,
            "pi": (np.array([r["wellbore_pressure"][0] for r in records]) - S_HMIN) / scale,
            "stored": np.array([r["fracture_volume"] / r["injected_volume"] for r in records]),
            "c_m": (c_prime**6 * e_prime * t / (mu_prime * VISCOUS["rate"] ** 3)) ** (1.0 / 6.0),
            "residual": max(abs(r["budget"]["residual"]) / r["injected_volume"] for r in records),
            "cpu": cpu, "wall": wall, "elements": records[-1]["n_elements"] if records else 0, "failure": failure}


#: the radial rows: name, injection rate (m^3/s), viscosity (Pa s), c_l (m/(s^1/2 Pa)), first step (s)
RADIAL_VISCOUS_CASES = (
    ("radial M to M~", 1e-2, 1e-3, 1e-10, 0.05),
    ("radial M~ (mu 2.5e-5, C' 4e-3)", 2e-2, 2.5e-5, 2e-10, 0.05),
)


def radial_viscous_scene(end_time=8.0, h=0.2, rate=1e-2, viscosity=1e-3, c_l=1e-10, first_step=0.05,
                         kind="radial-km-leak-off"):
    """A radial fracture with viscous leak-off (K_Ic 10 kPa m^1/2, s_v - p_r = 20 MPa: C' = c_l
    20 MPa; 3 x 3 initial elements of ``h``; steps of 0.3 elements), the scene's data."""
    import hmatddm.scene as hs

    text = f"""
dimension = 3
[material]
shear_modulus = 1e9
poisson_ratio = 0.25
[fluid]
viscosity = {viscosity}
compressibility = 0.0
[stress]
s_hmin = 40e6
s_hmax = 40e6
s_v = 20e6
[[cluster]]
position = [0.0, 0.0, 0.0]
rate = {rate}
[[initial_fracture]]
shape = "rectangle"
center = [0.0, 0.0, 0.0]
e1 = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
length = {3 * h}
height = {3 * h}
element_size = {h}
[propagation]
toughness = 1e4
front = "asymptotic"
[leak_off]
coefficient = {c_l}
pore_pressure = 0.0
[numerics]
time_step = "auto"
first_time_step = {first_step}
max_time_step = 0.5
step_advance = 0.3
end_time = {end_time}
backend = "dense"
initial_pressure = 20e6
initial_opening = 1e-6
[reference]
kind = "{kind}"
"""
    return hs.scene_from_dict(hs.parse_scene(text).data, "radial-viscous-leak-off").data


def run_radial_viscous(name="radial M to M~", rate=1e-2, viscosity=1e-3, c_l=1e-10, first_step=0.05, end_time=8.0,
                       h=0.2):
    """A radial fracture towards (or at) M~ (:func:`radial_viscous_scene`) against Dontsov's (2016)
    solution with leak-off (``radial-km-leak-off``) and the radial M~ vertex
    (``radial-m-leak-off``), with the C_m of each row and the reference block's warning."""
    import hmatddm.scene as hs

    data = radial_viscous_scene(end_time, h, rate, viscosity, c_l, first_step)
    vertex_data = radial_viscous_scene(end_time, h, rate, viscosity, c_l, first_step, kind="radial-m-leak-off")
    simulation = hs.build_simulation(data)
    wall, cpu = time.perf_counter(), time.process_time()
    records = simulation.run(end_time)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    rows, vertex = hs.reference_values(data, records), hs.reference_values(vertex_data, records)
    t = np.array([r["time"] for r in records])
    pick = np.unique(np.clip(np.searchsorted(t, [0.5, 1, 2, 4, 8, 16]), 0, len(t) - 1))
    table = [[f"{t[i]:.3g}", f"{rows[i]['regime']['leak_off']['value']:.2f}",
              f"{100 * records[i]['fracture_volume'] / records[i]['injected_volume']:.1f}%",
              f"{records[i]['radius']:.3f}", f"{100 * rows[i]['relative_error']['radius']:+.1f}%",
              f"{100 * vertex[i]['relative_error']['radius']:+.1f}%", f"{1e3 * records[i]['max_opening']:.4f}",
              f"{100 * rows[i]['relative_error']['max_opening']:+.1f}%",
              f"{100 * vertex[i]['relative_error']['max_opening']:+.1f}%"] for i in pick]
    print(f"\n{name} (Q {rate:g}, mu {viscosity:g}, C' {c_l * S_HMIN:g}), {h} m: {records[-1]['n_elements']} elements "
          f"at the end; CPU {cpu:.1f} s, wall {wall:.1f} s; front circularity {records[-1]['front_circularity']:.3f}; "
          f"largest budget residual {max(abs(r['budget']['residual']) / r['injected_volume'] for r in records):.1e} "
          f"of the injected volume")
    print(f"radial-m-leak-off warning: {hs.reference_warning(vertex_data)}")
    print_table(["t (s)", "C_m", "stored", "R DDM (m)", "R vs Dontsov", "R vs M~", "w0 DDM (mm)", "w0 vs Dontsov",
                 "w0 vs M~"], table)


def print_viscous(results):
    from hmatddm.analytical.viscous_leak_off import KGD_M_LEAK_OFF_PRESSURE

    for r in results:
        pick = np.unique(np.clip(np.searchsorted(r["t"], [2, 4, 8, 16]), 0, len(r["t"]) - 1))
        rows = [[f"{r['t'][i]:.3g}", f"{r['c_m'][i]:.2f}", f"{100 * r['stored'][i]:.1f}% / "
                 f"{100 * r['dontsov_stored'][i]:.1f}%", f"{r['length'][i]:.4f}",
                 f"{100 * (r['length'][i] / r['vertex_l'][i] - 1):+.1f}%",
                 f"{100 * (r['length'][i] / r['dontsov_l'][i] - 1):+.1f}%", f"{1e3 * r['w0'][i]:.4f}",
                 f"{100 * (r['w0'][i] / r['vertex_w'][i] - 1):+.1f}%",
                 f"{100 * (r['w0'][i] / r['dontsov_w'][i] - 1):+.1f}%", f"{r['pi'][i]:.3f}",
                 f"{100 * (r['pi'][i] / KGD_M_LEAK_OFF_PRESSURE - 1):+.1f}%"] for i in pick]
        print(f"\n{r['name']}: {r['elements']} elements at the end; CPU {r['cpu']:.1f} s, wall {r['wall']:.1f} s; "
              f"largest budget residual {r['residual']:.1e} of the injected volume"
              + (f"; FAILED: {r['failure']}" if r["failure"] else ""))
        print_table(["t (s)", "C_m", "stored DDM / Dontsov", "l DDM (m)", "l vs M~", "l vs Dontsov",
                     "w0 DDM (mm)", "w0 vs M~", "w0 vs Dontsov", "Pi = p/P_m~", "p vs M~"], rows)


def plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for k, r in enumerate(results):
        color = f"C{k}"
        ax.loglog(r["t"], r["length"], "o", ms=3, color=color, label=f"{r['name']}: DDM")
        if not r["viscous"]:
            ax.loglog(r["t"], r["edge"], "-", color=color, lw=1,
                      label="K vertex" if r["c_l"] == 0 else "K-K~ edge (zero viscosity)")
        if r["c_l"] > 0:
            ax.loglog(r["t"], r["vertex"], "--", color=color, lw=1, label="leak-off vertex Q t^1/2/(pi C')")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("half-length (m)")
    ax.set_title("KGD with Carter leak-off")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="10 s runs")
    parser.add_argument("--plot", default=os.path.join(HERE, "leak_off_kgd.png"))
    parser.add_argument("--viscous", action="store_true", help="only the viscous leak-off (M~) rows")
    parser.add_argument("--radial", type=int, help="with --viscous: only this radial row (0, 1), no KGD rows")
    parser.add_argument("--h", type=float, default=0.2, help="element size of the radial viscous rows (m)")
    parser.add_argument("--end-time", type=float, help="end of the radial viscous rows (s; default 8)")
    args = parser.parse_args(argv)
    print(f"Machine: {machine()}")
    if args.viscous:
        if args.radial is None:
            print_viscous([run_viscous(*case, end_time=4.0 if args.quick else VISCOUS["end_time"])
                           for case in VISCOUS_CASES])
        for case in RADIAL_VISCOUS_CASES if args.radial is None else [RADIAL_VISCOUS_CASES[args.radial]]:
            run_radial_viscous(*case, end_time=args.end_time or (2.0 if args.quick else 8.0), h=args.h)
        return
    # ref. Eq. 4.26 for a shale and a tight sand (reservoir fluid: oil 1 cP; c_t 1e-9 1/Pa)
    md = 9.869233e-16
    for label, k_r in (("shale, 1e-4 mD", 1e-4), ("tight sand, 0.1 mD", 0.1)):
        both = carter_coefficient(k_r * md, 0.15, 1e-9, 1e-3)
        print(f"ref. Eq. 4.26, {label}, phi 0.15: c_l = {both:.3g} m/(s^1/2 Pa) for both faces "
              f"({0.5 * both:.3g} for one, the reference's reading); at 5 MPa C' = {5e6 * both:.3g} m/s^1/2")
    results = []
    for case in CASES:
        name, rate, c_l, toughness, viscosity, end_time, dt, contact = case
        results.append(run_case(name, rate, c_l, toughness, viscosity, 10.0 if args.quick else end_time, dt,
                                contact))
    for r in results:
        pick = np.unique(np.clip(np.searchsorted(r["t"], [1, 2, 5, 10, 20, 40]), 0, len(r["t"]) - 1))
        rows = []
        for i in pick:
            reference = r["vertex"][i] if r["viscous"] else r["edge"][i]
            rows.append([f"{r['t'][i]:g}", f"{r['length'][i]:.3f}", f"{r['edge'][i]:.3f}" if not r["viscous"] else "-",
                         f"{r['vertex'][i]:.3f}" if r["c_l"] > 0 else "-",
                         f"{100 * (r['length'][i] / reference - 1):+.1f}%", f"{100 * r['leaked'][i]:.0f}%",
                         f"{r['net'][i] / 1e6:.3f}", f"{r['edge_net'][i] / 1e6:.3f}" if not r["viscous"] else "-"])
        print(f"\n{r['name']}: Q = {r['rate']:g} m^2/s, c_l = {r['c_l']:g}, K_m = {r['k_m']:.2f}; "
              f"{r['elements']} elements at the end; contact {r['contact']!r}, smallest opening of the run "
              f"{1e3 * r['min_opening']:.3f} mm; CPU {r['cpu']:.1f} s, wall {r['wall']:.1f} s")
        print_table(["t (s)", "l DDM (m)", "l K-K~ edge (m)", "l leak-off vertex (m)", "error", "leaked",
                     "net p DDM (MPa)", "net p edge (MPa)"], rows)
    for r in [run_radial(*case, end_time=8.0 if args.quick else 20.0) for case in RADIAL_CASES]:
        pick = np.unique(np.clip(np.searchsorted(r["t"], [2, 5, 10, 15, 20]), 0, len(r["t"]) - 1))
        rows = [[f"{r['t'][i]:g}", f"{r['radius'][i]:.3f}", f"{r['reference'][i]:.3f}",
                 f"{r['vertex'][i]:.3f}" if r["c_l"] > 0 else "-", f"{100 * (r['radius'][i] / r['reference'][i] - 1):+.1f}%",
                 f"{100 * r['leaked'][i]:.0f}%"] for i in pick]
        print(f"\n{r['name']}: c_l = {r['c_l']:g}; {r['elements']} elements at the end; CPU {r['cpu']:.1f} s, "
              f"wall {r['wall']:.1f} s")
        print_table(["t (s)", "R DDM (m)", "R K vertex / K-K~ edge (m)", "R leak-off vertex (m)", "error", "leaked"],
                    rows)
    plot(results, args.plot)
    print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
