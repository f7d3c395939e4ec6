"""Three clusters in a 3D discrete fracture network with full-height natural fractures
(ref. Sec. 6.3, Tables 6.1-6.2).

    python benchmarks/bench_dfn.py                          # full scene, 70 s, hmatrix
    python benchmarks/bench_dfn.py --density 0.1            # the denser network of Table 6.1
    python benchmarks/bench_dfn.py --elements-over-height 20 --dz 0.5   # twice the rows
    python benchmarks/bench_dfn.py --reduced                # dense vs hmatrix on a small scene
    python benchmarks/bench_dfn.py --profile --end-time 5   # cProfile of a short run

The scene: Table 6.2 rock, stress and fluid (S_hmin 35.85 MPa along x, S_Hmax 36.44 MPa
along y, S_v 45 MPa along z, G 6.62 GPa, nu 0.25, K_Ic 3 MPa m^1/2, mu 1 cP, c_f
4.4e-4 1/MPa, pore pressure 27.01 MPa, dt 1 s, 70 s), three perforation clusters at
x = -10, 0, 10 m (2e-3 m^3/s and a 5 m^3 wellbore each) feeding vertical hydraulic
fractures in the y-z plane, and a Table 6.1 network (a = 2, rho_NF 0.05 1/m^2, l in
[1, 30] m, mean strike 45 deg, kappa 5) in a 100 m x 200 m region. Unlike the reference
(one element over the height), every fracture is a FULL-HEIGHT vertical rectangle of
``height`` metres meshed with 1 m elements (``--elements-over-height`` rows); the
hydraulic fractures are confined to the same height (``Propagation(bounds=...)``), so
they grow in plan view only, as in the reference. Intact natural elements are stress
targets checked for remote Coulomb failure every step (Skempton B = 1). Every active
element, hydraulic or natural, closes with contact and Coulomb friction when the fluid
cannot hold it open (``contact="all"``, as in the ``dfn-3cluster`` scene).

What is recorded per step (printed as a table, saved as ``dfn_records.json`` in --out):
wall time of the step and its parts (coupled solve incl. operator builds, operator
builds alone, growth/encounter logic, the whole remote-failure check, checkpoint), CPU
time (``time.process_time``, all threads) of the step and of the remote-failure check,
the remote-failure checks and the targets whose stress they evaluated (the others are
cleared by the stress bound of :mod:`hmatddm.elasticity.field_bound`),
peak RSS (``resource.getrusage(...).ru_maxrss``), active elements (total, natural
activated), natural elements failed by remote failure, nonlinear and GMRES iterations,
and the memory a dense run would need: ``N_active^2 * 9 * 8`` bytes for the DDM matrix
plus ``N_targets * N_active * 18 * 8`` bytes for a dense influence matrix from the
active DDs (3 per element) to the stress tensor (6 components) at every intact natural
element. ``dfn_plan.png`` (next to this script unless --plot says otherwise) is the plan
view at the end of the run.

``--reduced`` runs a small version of the same scene (40 m x 60 m region, 4 m height
with 4 elements over it, 25 s) with the ``dense`` and ``hmatrix`` backends and compares
the fracture paths step by step: element counts, activated natural elements and the
element centres (every centre of one run within 1 mm of a centre of the other).

At the end of a run the remote-failure stress evaluation of the final state is timed
three ways (``remote_check``): the default of :func:`hmatddm.stress_at` (compressed far
field), the exact direct sum, and the per-DD-component kernel the engine used before; then
the screened check the run uses (``NaturalNetwork.remote_failure(screen=True)``), with no
memory and with the margins the run left, against the full check's failures.

``OMP_WAIT_POLICY=PASSIVE`` is set (unless already set) before numba loads; see below.

Importable: ``FULL``, ``REDUCED`` (:class:`Scene`), ``build_simulation``, ``run``,
``compare_paths``, ``remote_check``, ``plot_plan`` do nothing until called.
"""
import os

# numba's OpenMP threads spin between parallel regions by default; on a machine shared
# with other jobs every small parallel region (one H-matrix matvec of a few hundred
# elements) then waits for a scheduler time slice: measured 9.5 ms instead of 0.45 ms
# per matvec at load 7 on 2 cores. Sleep instead (must be set before numba loads).
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import cProfile  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import pstats  # noqa: E402
import resource  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import asdict, dataclass, replace  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.network import NetworkSpec, generate_network  # noqa: E402
from hmatddm.elasticity.operator import NEAR_SINGULAR_FRACTION  # noqa: E402
from hmatddm.simulation import checkpoint as checkpoint_module  # noqa: E402
from hmatddm.simulation import natural as natural_module  # noqa: E402
from hmatddm.simulation import growing_operator as growing_operator_module  # noqa: E402
from hmatddm.simulation import growth_pass as growth_pass_module  # noqa: E402
from hmatddm.simulation import simulation as simulation_module  # noqa: E402
from hmatddm.simulation import step_solve as step_solve_module  # noqa: E402
from hmatddm.simulation.natural import plan_segments  # noqa: E402


@dataclass(frozen=True)
class Scene:
    """Parameters of the DFN scene (ref. Tables 6.1-6.2); SI units, compression positive
    for the in-situ stresses."""

    region: tuple = (-50.0, 50.0, -100.0, 100.0)   # natural fractures, x_min, x_max, y_min, y_max (m)
    density: float = 0.05                           # rho_NF, 1/m^2 (Eq. 6.12)
    length_exponent: float = 2.0                    # a (Eq. 6.1)
    l_min: float = 1.0
    l_max: float = 30.0
    mean_azimuths_deg: tuple = (45.0,)              # mu of each orientation set
    kappas: tuple = (5.0,)                          # kappa of each set
    weights: tuple = None                           # mixing factors (None: equal)
    seed: int = 1
    height: float = 10.0                            # full height of every fracture, m
    elements_over_height: int = 10
    element_size: float = 1.0                       # along strike, m
    clusters_x: tuple = (-10.0, 0.0, 10.0)
    initial_length: float = 3.0                     # initial hydraulic fractures along y, m
    rate: float = 2e-3                              # m^3/s per cluster
    wellbore_volume: float = 5.0                    # m^3 per cluster
    s_hmin: float = 35.85e6                         # along x
    s_hmax: float = 36.44e6                         # along y
    s_v: float = 45.0e6                             # along z
    shear_modulus: float = 6.62e9
    poisson_ratio: float = 0.25
    toughness: float = 3e6
    viscosity: float = 1e-3
    compressibility: float = 4.4e-10
    pore_pressure: float = 27.01e6
    nf_friction: float = 0.25
    nf_cohesion: float = 0.0
    nf_toughness: float = 0.5e6
    critical_radius: float = 0.005
    skempton: float = 1.0
    time_step: float = 1.0
    end_time: float = 70.0
    initial_pressure: float = 36.5e6
    initial_opening: float = 1e-4
    remote_failure: bool = True
    contact: str = "all"   # hydraulic elements close too (with "natural", a hydraulic element in the
                           # stress shadow of another fracture went to -0.1 mm and the Picard
                           # iteration swung at t = 63 s with 20 elements over the height)
    eps: float = 1e-4

    @property
    def dz(self):
        return self.height / self.elements_over_height


FULL = Scene()
REDUCED = Scene(region=(-20.0, 20.0, -30.0, 30.0), height=4.0, elements_over_height=4, end_time=25.0)


def natural_mesh(scene):
    """The network of Table 6.1 as full-height vertical rectangles (Mesh3D)."""
    spec = NetworkSpec(region=scene.region, density=scene.density, length_exponent=scene.length_exponent,
                       l_min=scene.l_min, l_max=scene.l_max, mean_azimuths_deg=scene.mean_azimuths_deg,
                       kappas=scene.kappas, weights=scene.weights, height=scene.height, z_center=0.0,
                       seed=scene.seed)
    return generate_network(spec).to_mesh3d(scene.element_size, scene.elements_over_height)


def hydraulic_mesh(scene):
    """Initial hydraulic fractures: y-z rectangles (normal +x) at the clusters."""
    n_along = int(round(scene.initial_length / scene.element_size))
    parts = [hd.mesh.rectangle([x, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], scene.initial_length, scene.height,
                               n_along, scene.elements_over_height, fracture_id=k)
             for k, x in enumerate(scene.clusters_x)]
    return hd.mesh.concatenate(parts)


def build_simulation(scene, backend="hmatrix", checkpoint_dir=None):
    """The :class:`hmatddm.Simulation` of ``scene`` (nothing solved yet)."""
    mesh = hydraulic_mesh(scene)
    natural = natural_mesh(scene)
    half = 0.5 * scene.height
    propagation = hd.Propagation(toughness=scene.toughness, turning="plan",
                                 bounds=((-np.inf, np.inf), (-np.inf, np.inf), (-half, half)))
    properties = hd.NaturalFractureProperties(friction=scene.nf_friction, cohesion=scene.nf_cohesion,
                                              toughness=scene.nf_toughness, critical_radius=scene.critical_radius,
                                              crossing="mohr-coulomb", pore_pressure=scene.pore_pressure,
                                              skempton=scene.skempton)
    clusters = [hd.Cluster((x, 0.0, 0.0), rate=scene.rate, wellbore_volume=scene.wellbore_volume)
                for x in scene.clusters_x]
    stress = -np.diag([scene.s_hmin, scene.s_hmax, scene.s_v])
    return hd.Simulation(mesh, hd.Elastic(scene.shear_modulus, scene.poisson_ratio),
                         hd.Fluid(viscosity=scene.viscosity, compressibility=scene.compressibility), clusters,
                         stress, scene.time_step, propagation=propagation,
                         leak_off=hd.LeakOff(coefficient=0.0, pore_pressure=scene.pore_pressure),
                         initial_pressure=scene.initial_pressure, initial_opening=scene.initial_opening,
                         backend=backend, eps=scene.eps, singular_correction="average", alpha=1.0,
                         checkpoint_dir=checkpoint_dir, natural_fractures=natural, natural=properties,
                         remote_failure=scene.remote_failure, contact=scene.contact)


# ---------------------------------------------------------------------------------------
# Instrumentation: time the parts of a step by wrapping engine methods (no engine change)
# ---------------------------------------------------------------------------------------

class PartTimer:
    """Accumulates wall and CPU time (``time.process_time``: all threads of this process)
    per named part; ``wrap`` patches ``owner.name`` for a run."""

    def __init__(self):
        self.seconds = {}
        self.cpu = {}
        self.counts = {}
        self._patches = []

    def wrap(self, owner, name, part):
        original = getattr(owner, name)
        timer = self

        def timed(*args, **kwargs):
            start, start_cpu = time.perf_counter(), time.process_time()
            try:
                return original(*args, **kwargs)
            finally:
                timer.seconds[part] = timer.seconds.get(part, 0.0) + time.perf_counter() - start
                timer.cpu[part] = timer.cpu.get(part, 0.0) + time.process_time() - start_cpu

        self._patches.append((owner, name, original))
        setattr(owner, name, timed)

    def count(self, owner, name, what, amount):
        """Patch ``owner.name`` to add ``amount(args)`` to ``counts[what]`` at each call."""
        original = getattr(owner, name)
        timer = self

        def counted(*args, **kwargs):
            timer.counts[what] = timer.counts.get(what, 0) + int(amount(args))
            return original(*args, **kwargs)

        self._patches.append((owner, name, original))
        setattr(owner, name, counted)

    def restore(self):
        for owner, name, original in reversed(self._patches):
            setattr(owner, name, original)
        self._patches.clear()

    def take(self):
        """(wall, cpu) seconds per part and the counts since the last call."""
        seconds, self.seconds = self.seconds, {}
        cpu, self.cpu = self.cpu, {}
        counts, self.counts = self.counts, {}
        return seconds, cpu, counts


PARTS = ("solve", "operator", "grow", "remote_stress", "checkpoint")


@contextlib.contextmanager
def instrumented():
    timer = PartTimer()
    sim_class = simulation_module.Simulation
    timer.wrap(step_solve_module, "solve", "solve")     # coupled solve (includes operator)
    timer.wrap(growing_operator_module.GrowingOperator, "build", "operator")  # H-matrix / dense builds
    timer.wrap(growth_pass_module, "grow", "grow")       # tips, new elements, encounters
    timer.wrap(sim_class, "save_checkpoint", "checkpoint")
    # the whole remote-failure check (screening, stress at the targets kept, Coulomb test)
    timer.wrap(growth_pass_module, "remote_failures", "remote_stress")
    timer.count(natural_module.NaturalNetwork, "induced_stress", "targets_evaluated", lambda args: len(args[4]))
    timer.count(growth_pass_module, "remote_failures", "remote_checks", lambda args: 1)
    try:
        yield timer
    finally:
        timer.restore()


def _peak_rss():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _load():
    """Cores kept busy on this machine (1-minute load average)."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


def run(scene, backend="hmatrix", end_time=None, checkpoint_dir=None, keep_centres=False, verbose=True,
        max_wall=None):
    """Run ``scene`` to ``end_time``; returns ``(simulation, rows, error)``.

    ``rows``: one dict per step (see the module docstring); ``error``: the message of an
    engine error that stopped the run early (the rows up to it are kept), else None.
    ``keep_centres`` also stores the sorted active element centres of each step (for
    :func:`compare_paths`). ``max_wall`` stops after the step that passes it (s).
    """
    end_time = scene.end_time if end_time is None else end_time
    started = time.perf_counter()
    sim = build_simulation(scene, backend, checkpoint_dir)
    build_seconds = time.perf_counter() - started
    n_natural = sim.network.mesh.n_elements
    if checkpoint_dir is not None:
        checkpoint_module.check_writable(checkpoint_dir)
    rows, error = [], None
    if verbose:
        print(f"# {backend}: {n_natural} natural elements, {sim.mesh0.n_elements} initial hydraulic elements, "
              f"set-up {build_seconds:.2f} s", flush=True)
        print(_row_header(), flush=True)
    with instrumented() as timer:
        timer.take()
        while sim.state.time < end_time - 1e-9 * sim.time_step:
            step_start, step_cpu = time.perf_counter(), time.process_time()
            t_next = sim.state.time + sim.time_step
            try:
                record = sim.step(end_time)  # (front-following steps: the last one ends at end_time)
                if checkpoint_dir is not None:
                    sim.save_checkpoint()
            except hd.HmatddmError as exc:
                error = f"t = {t_next:g} s: {type(exc).__name__}: {exc}"
                if verbose:
                    print(f"# stopped: {error}", flush=True)
                break
            wall, cpu = time.perf_counter() - step_start, time.process_time() - step_cpu
            parts, parts_cpu, counts = timer.take()
            s = sim.state
            n_active = int(s.mesh.n_elements)
            n_targets = int(np.count_nonzero(s.intact))
            row = dict(
                time=float(record["time"]), wall_seconds=wall, cpu_seconds=cpu, n_active=n_active,
                n_hydraulic=int(np.count_nonzero(s.origin == 0)), natural_active=int(record["natural_active"]),
                natural_failed=int(record["natural_failed"]), natural_intact=n_targets,
                n_total=n_active + n_targets,
                natural_crossed=int(record["natural_crossed"]), natural_deflected=int(record["natural_deflected"]),
                elements_added=int(record["elements_added"]), growth_passes=int(record["growth_passes"]),
                operator_builds=int(record["operator_builds"]),
                nonlinear_iterations=int(record["nonlinear_iterations"]),
                linear_iterations=int(record["linear_iterations"]),
                max_opening=float(record["max_opening"]), wellbore_pressure=list(record["wellbore_pressure"]),
                peak_rss_bytes=_peak_rss(), load=_load(),
                dense_matrix_bytes=float(n_active) ** 2 * 9 * 8,
                dense_stress_bytes=float(n_targets) * n_active * 18 * 8,
                remote_checks=int(counts.get("remote_checks", 0)),
                targets_evaluated=int(counts.get("targets_evaluated", 0)),
                **{f"{part}_seconds": float(parts.get(part, 0.0)) for part in PARTS},
                **{f"{part}_cpu_seconds": float(parts_cpu.get(part, 0.0)) for part in PARTS})
            row["operator_stats"] = _operator_stats(sim)
            if keep_centres:
                row["centres"] = _sorted_centres(s.mesh)
                row["origin"] = s.origin.copy()
                row["failed"] = np.flatnonzero(s.failed)
            rows.append(row)
            if verbose:
                print(_row_line(row), flush=True)
            if max_wall is not None and time.perf_counter() - started > max_wall:
                error = f"stopped after {time.perf_counter() - started:.0f} s of wall time (--max-wall)"
                if verbose:
                    print(f"# {error}", flush=True)
                break
    return sim, rows, error


def _operator_stats(sim):
    base = sim.base_operator
    if base is None:
        return None
    stats = base.stats
    keep = ("memory_bytes", "dense_bytes", "compression", "build_seconds", "n_elements")
    return {k: (float(stats[k]) if k in stats else None) for k in keep}


def _sorted_centres(mesh):
    centres = np.array(mesh.centers)
    return centres[np.lexsort(centres.T[::-1])]


def _row_header():
    return (f"{'t':>4} {'wall':>7} {'cpu':>7} {'solve':>7} {'op':>6} {'grow':>6} {'remote':>7} {'rem cpu':>7} "
            f"{'checks':>6} {'evaluated':>9} {'ckpt':>5} "
            f"{'N_act':>6} {'nat_act':>7} {'nat_fail':>8} {'intact':>7} {'NL':>4} {'GMRES':>6} "
            f"{'RSS GB':>7} {'dense GB':>9} {'load':>5}")


def _row_line(r):
    return (f"{r['time']:4.0f} {r['wall_seconds']:7.2f} {r['cpu_seconds']:7.2f} {r['solve_seconds']:7.2f} "
            f"{r['operator_seconds']:6.2f} {r['grow_seconds']:6.2f} {r['remote_stress_seconds']:7.2f} "
            f"{r['remote_stress_cpu_seconds']:7.2f} {r['remote_checks']:6d} {r['targets_evaluated']:9d} "
            f"{r['checkpoint_seconds']:5.2f} {r['n_active']:6d} {r['natural_active']:7d} {r['natural_failed']:8d} "
            f"{r['natural_intact']:7d} {r['nonlinear_iterations']:4d} {r['linear_iterations']:6d} "
            f"{r['peak_rss_bytes'] / 1e9:7.2f} {(r['dense_matrix_bytes'] + r['dense_stress_bytes']) / 1e9:9.2f} "
            f"{r['load']:5.2f}")


def summary(rows, total_seconds, error=None):
    """Totals of a run: time per part, peaks and the largest counts."""
    if not rows:
        return dict(steps=0, total_seconds=total_seconds, error=error)
    last = rows[-1]
    out = dict(steps=len(rows), end_time_reached=last["time"], total_seconds=total_seconds,
               step_seconds=float(sum(r["wall_seconds"] for r in rows)),
               step_cpu_seconds=float(sum(r["cpu_seconds"] for r in rows)),
               peak_rss_bytes=max(r["peak_rss_bytes"] for r in rows),
               n_active_max=max(r["n_active"] for r in rows), n_total=last["n_total"],
               natural_active=last["natural_active"], natural_failed_max=max(r["natural_failed"] for r in rows),
               natural_failed_last=last["natural_failed"],
               nonlinear_iterations=sum(r["nonlinear_iterations"] for r in rows),
               linear_iterations=sum(r["linear_iterations"] for r in rows),
               dense_matrix_bytes_max=max(r["dense_matrix_bytes"] for r in rows),
               dense_stress_bytes_max=max(r["dense_stress_bytes"] for r in rows),
               mean_load=float(np.mean([r["load"] for r in rows])), error=error)
    for part in PARTS:
        out[f"{part}_seconds"] = float(sum(r[f"{part}_seconds"] for r in rows))
        out[f"{part}_cpu_seconds"] = float(sum(r[f"{part}_cpu_seconds"] for r in rows))
    return out


def remote_check(sim, original_kernel=True):
    """The remote-failure stress evaluation at the run's final state, three ways: the
    default of :func:`hmatddm.stress_at` (compressed far field when large), the exact
    direct sum, and (``original_kernel``) the per-DD-component kernel
    ``hmatddm.kernels.rectangle3d.stress_at_points`` the engine used before. Wall times,
    the largest error of the default against the exact sum relative to the largest
    induced stress component, and the evaluation details."""
    import importlib

    from hmatddm.kernels import element_data, rectangle3d

    fields_module = importlib.import_module("hmatddm.elasticity.fields")
    s = sim.state
    points = np.ascontiguousarray(sim.network.mesh.centers[s.intact])
    mesh, dd, mat = s.mesh, np.ascontiguousarray(s.dd), sim.material
    out = dict(n_active=int(mesh.n_elements), n_targets=int(len(points)))
    info = {}
    start = time.perf_counter()
    default = hd.stress_at(mesh, mat, dd, points, singular_correction="average", info=info,
                           near_fraction=NEAR_SINGULAR_FRACTION)
    out["default_seconds"] = time.perf_counter() - start
    out["default"] = {k: v for k, v in info.items() if k != "seconds"}
    start = time.perf_counter()
    exact = hd.stress_at(mesh, mat, dd, points, singular_correction="average", method="direct",
                         near_fraction=NEAR_SINGULAR_FRACTION)
    out["direct_seconds"] = time.perf_counter() - start
    out["default_error"] = float(np.max(np.abs(default - exact)) / max(np.max(np.abs(exact)), 1e-300))
    if original_kernel and hasattr(rectangle3d, "stress_at_points"):  # gone with the kernel drivers
        centers, frames, half_a, half_b, params, _ = element_data(mesh, mat, singular_shift=1e-3)
        reference = np.empty((len(points), 3, 3))
        rectangle3d.stress_at_points(points[:2], centers, frames, half_a, half_b, params, dd, reference[:2])
        start = time.perf_counter()
        rectangle3d.stress_at_points(points, centers, frames, half_a, half_b, params, dd, reference)
        # that engine evaluated the mean stress with the same kernel a second time (the
        # mean stress is now the trace of the one evaluation)
        out["original_seconds"] = 2.0 * (time.perf_counter() - start)
        out["direct_vs_original"] = float(np.max(np.abs(exact - reference)) / np.max(np.abs(reference)))
    out["stress_eps"] = fields_module.DEFAULT_STRESS_EPS
    # the screened check (the run's): with no memory, and with the margins the run left
    full = sim.network.remote_failure(mesh, dd, mat, sim.far_field_stress, s.intact, "average")
    for name, network in (("fresh", natural_module.NaturalNetwork(sim.network.mesh, sim.network.properties)),
                          ("memory", sim.network)):
        info = {}
        start, start_cpu = time.perf_counter(), time.process_time()
        failed = network.remote_failure(mesh, dd, mat, sim.far_field_stress, s.intact, "average", screen=True,
                                        info=info)[0]
        out[f"screened_{name}"] = dict(seconds=time.perf_counter() - start, cpu_seconds=time.process_time() - start_cpu,
                                       evaluated=info["evaluated"], targets=info["targets"],
                                       same_failures=bool(np.array_equal(failed, full[0])))
    return out


# ---------------------------------------------------------------------------------------
# Dense vs hmatrix paths
# ---------------------------------------------------------------------------------------

def compare_paths(rows_a, rows_b, tolerance=1e-3):
    """Step-by-step comparison of two runs of the same scene. Per step: the element
    counts, the activated and remote-failed natural elements, and the largest distance
    from an element centre of one run to the nearest centre of the other (both ways);
    a step has the same path when the counts agree and that distance is at most
    ``tolerance`` (m). Also lists the centres that differ at the first differing step."""
    from scipy.spatial import cKDTree

    steps = []
    first_difference, differing = None, None
    for a, b in zip(rows_a, rows_b):
        ca, cb = a["centres"], b["centres"]
        distance_ab = cKDTree(cb).query(ca)[0]
        distance_ba = cKDTree(ca).query(cb)[0]
        distance = float(max(distance_ab.max(), distance_ba.max()))
        same_count = a["n_active"] == b["n_active"] and a["natural_active"] == b["natural_active"]
        same = same_count and distance <= tolerance
        steps.append(dict(time=a["time"], n_active=(a["n_active"], b["n_active"]),
                          natural_active=(a["natural_active"], b["natural_active"]),
                          natural_failed=(a["natural_failed"], b["natural_failed"]), max_centre_distance=distance,
                          same_path=same, same_failed=bool(np.array_equal(a["failed"], b["failed"]))))
        if not same and first_difference is None:
            first_difference = a["time"]
            differing = dict(time=a["time"], only_first=ca[distance_ab > tolerance].tolist(),
                             only_second=cb[distance_ba > tolerance].tolist())
    return dict(steps=steps, n_compared=len(steps), same_length=len(rows_a) == len(rows_b), tolerance=tolerance,
                first_difference=first_difference, differing_centres=differing,
                all_same=first_difference is None and len(rows_a) == len(rows_b))


# ---------------------------------------------------------------------------------------
# Plot
# ---------------------------------------------------------------------------------------

def plot_plan(sim, path, title=""):
    """Plan view at the end of a run, whole region (left) and zoomed on the fractures
    (right): intact natural fractures grey, remotely failed ones orange, activated
    natural elements blue, hydraulic elements red; one line per element column (the
    traces of the vertical rectangles, :func:`hmatddm.simulation.natural.plan_segments`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    s = sim.state
    natural = sim.network.mesh

    def columns(mesh, mask):
        p0, p1, _ = plan_segments(mesh)
        keys = np.round(np.column_stack([p0, p1]), 4)
        index = np.flatnonzero(mask)
        if index.size == 0:
            return np.zeros((0, 2, 2))
        _, first = np.unique(keys[index], axis=0, return_index=True)
        index = index[first]
        return np.stack([p0[index], p1[index]], axis=1)

    layers = [(columns(natural, s.intact & ~s.failed), "0.6", 0.6, "natural, intact"),
              (columns(natural, s.failed), "tab:orange", 1.2, "natural, remote failure"),
              (columns(s.mesh, s.origin == 1), "tab:blue", 2.5, "natural, activated"),
              (columns(s.mesh, s.origin == 0), "tab:red", 2.0, "hydraulic")]
    active = np.concatenate([layers[2][0], layers[3][0]]).reshape(-1, 2)
    margin = 8.0
    zoom = (active[:, 0].min() - margin, active[:, 0].max() + margin,
            active[:, 1].min() - margin, active[:, 1].max() + margin)
    fig, axes = plt.subplots(1, 2, figsize=(13, 9), gridspec_kw=dict(width_ratios=[1, 1.3]))
    for ax, (x_min, x_max, y_min, y_max) in zip(axes, (sim_region(sim), zoom)):
        for segments, colour, width, label in layers:
            if len(segments):
                ax.add_collection(LineCollection(segments, colors=colour, linewidths=width, label=label))
        ax.set_xlim(x_min, x_max)
        ax.set_ylim(y_min, y_max)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m), S_hmin direction")
        ax.set_ylabel("y (m), S_Hmax direction")
    axes[0].add_patch(plt.Rectangle((zoom[0], zoom[2]), zoom[1] - zoom[0], zoom[3] - zoom[2], fill=False,
                                    edgecolor="k", linestyle="--", linewidth=0.8))
    axes[1].legend(loc="upper right", fontsize=8)
    axes[1].set_title("zoom")
    fig.suptitle(title or f"t = {s.time:g} s")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def sim_region(sim):
    p0, p1, _ = plan_segments(sim.network.mesh)
    points = np.concatenate([p0, p1])
    return (float(points[:, 0].min()) - 1, float(points[:, 0].max()) + 1,
            float(points[:, 1].min()) - 1, float(points[:, 1].max()) + 1)


# ---------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------

def _json_rows(rows):
    return [{k: v for k, v in r.items() if k not in ("centres", "origin", "failed")} for r in rows]


def _print_summary(name, s):
    gb = 1e9
    print(f"\n## {name}")
    if not s.get("steps"):
        print(f"no step completed ({s.get('error')})")
        return
    print(f"reached t = {s['end_time_reached']:g} s in {s['total_seconds']:.1f} s wall "
          f"(steps {s['step_seconds']:.1f} s wall, {s['step_cpu_seconds']:.1f} s CPU), peak RSS {s['peak_rss_bytes'] / gb:.2f} GB, "
          f"mean load {s['mean_load']:.2f}")
    print(f"elements: active max {s['n_active_max']}, total {s['n_total']}, natural activated "
          f"{s['natural_active']}, natural failed {s['natural_failed_last']} (max {s['natural_failed_max']})")
    print(f"iterations: nonlinear {s['nonlinear_iterations']}, GMRES {s['linear_iterations']}")
    print("time per part, wall / CPU (s): " + ", ".join(f"{p} {s[p + '_seconds']:.1f} / {s[p + '_cpu_seconds']:.1f}"
                                                       for p in PARTS))
    share = s["remote_stress_seconds"] / max(s["step_seconds"], 1e-300)
    share_cpu = s["remote_stress_cpu_seconds"] / max(s["step_cpu_seconds"], 1e-300)
    print(f"remote-failure share of the steps: {100 * share:.1f}% wall, {100 * share_cpu:.1f}% CPU")
    print(f"dense would need: matrix {s['dense_matrix_bytes_max'] / gb:.3f} GB + natural-target stress "
          f"{s['dense_stress_bytes_max'] / gb:.2f} GB")
    if s.get("error"):
        print(f"stopped early: {s['error']}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reduced", action="store_true", help="small scene, dense vs hmatrix path comparison")
    parser.add_argument("--end-time", type=float, default=None, help="s (default 70; 25 with --reduced)")
    parser.add_argument("--elements-over-height", type=int, default=None,
                        help="rows of 1 m... elements over the height (default 10; 4 with --reduced); "
                             "the height is this times --dz")
    parser.add_argument("--dz", type=float, default=1.0, help="element size over the height, m (default 1)")
    parser.add_argument("--region", type=float, nargs=4, default=None, metavar=("XMIN", "XMAX", "YMIN", "YMAX"),
                        help="region of the natural fractures, m")
    parser.add_argument("--backend", default="hmatrix", choices=("hmatrix", "dense"))
    parser.add_argument("--eps", type=float, default=None, help="H-matrix accuracy (default 1e-4)")
    parser.add_argument("--density", type=float, default=None,
                        help="areal density of natural fractures, 1/m^2 (default 0.05, ref. Table 6.1)")
    parser.add_argument("--seed", type=int, default=None, help="seed of the network (default 1)")
    parser.add_argument("--no-remote-failure", action="store_true")
    parser.add_argument("--checkpoints", action="store_true", help="write checkpoints to OUT/checkpoints-BACKEND")
    parser.add_argument("--no-remote-check", action="store_true",
                        help="skip the final timing of the remote-failure stress evaluation (default, exact, original)")
    parser.add_argument("--profile", action="store_true", help="cProfile the run; top functions to OUT/dfn_profile.txt")
    parser.add_argument("--max-wall", type=float, default=None, help="stop after this many seconds of wall time")
    parser.add_argument("--out", default=os.path.join(HERE, "out"), help="folder of the JSON (and profile)")
    parser.add_argument("--plot", default=None, help="plan-view PNG (default benchmarks/dfn_plan.png; "
                                                      "benchmarks/dfn_plan_reduced.png with --reduced)")
    args = parser.parse_args(argv)

    base = REDUCED if args.reduced else FULL
    changes = {}
    if args.end_time is not None:
        changes["end_time"] = args.end_time
    if args.elements_over_height is not None:
        changes["elements_over_height"] = args.elements_over_height
    if args.elements_over_height is not None or args.dz != 1.0:
        changes["height"] = args.dz * (args.elements_over_height or base.elements_over_height)
    if args.region is not None:
        changes["region"] = tuple(args.region)
    if args.eps is not None:
        changes["eps"] = args.eps
    if args.density is not None:
        changes["density"] = args.density
    if args.seed is not None:
        changes["seed"] = args.seed
    if args.no_remote_failure:
        changes["remote_failure"] = False
    scene = replace(base, **changes)
    os.makedirs(args.out, exist_ok=True)
    print(machine())
    print(f"numba threads: {__import__('numba').get_num_threads()} ({__import__('numba').threading_layer()} "
          f"layer, OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY')}), load at start {_load():.2f}")
    print("scene: " + json.dumps(asdict(scene)))

    results = dict(machine=machine(), scene=asdict(scene), runs={})
    backends = ("dense", "hmatrix") if args.reduced else (args.backend,)
    all_rows = {}
    last_sim = None
    profiler = cProfile.Profile() if args.profile else None
    for backend in backends:
        checkpoint_dir = os.path.join(args.out, f"checkpoints-{backend}") if args.checkpoints else None
        start = time.perf_counter()
        if profiler:
            profiler.enable()
        sim, rows, error = run(scene, backend, scene.end_time, checkpoint_dir=checkpoint_dir,
                               keep_centres=args.reduced, max_wall=args.max_wall)
        if profiler:
            profiler.disable()
        total = time.perf_counter() - start
        s = summary(rows, total, error)
        _print_summary(backend, s)
        results["runs"][backend] = dict(summary=s, records=_json_rows(rows))
        if rows and not args.no_remote_check:
            check = remote_check(sim)
            results["runs"][backend]["remote_check"] = check
            print(f"remote-failure stress on {check['n_targets']} targets from {check['n_active']} elements: "
                  f"default ({check['default'].get('method')}) {check['default_seconds']:.2f} s, exact direct "
                  f"{check['direct_seconds']:.2f} s, original kernel "
                  f"{check.get('original_seconds', float('nan')):.2f} s; "
                  f"default error {check['default_error']:.1e} of the largest stress (eps {check['stress_eps']:g})")
            for name in ("fresh", "memory"):
                c = check[f"screened_{name}"]
                print(f"screened check ({name}): {c['evaluated']} of {c['targets']} targets evaluated, "
                      f"{c['seconds']:.2f} s wall, {c['cpu_seconds']:.2f} s CPU, same failures as the full check: "
                      f"{c['same_failures']}")
        all_rows[backend] = rows
        last_sim = sim
    if args.reduced:
        comparison = compare_paths(all_rows["dense"], all_rows["hmatrix"])
        results["comparison"] = comparison
        print("\n## dense vs hmatrix paths")
        print(f"{'t':>4} {'N dense':>8} {'N hmat':>7} {'nat d':>6} {'nat h':>6} {'fail d':>6} {'fail h':>6} "
              f"{'max |dx|':>9} same")
        for st in comparison["steps"]:
            print(f"{st['time']:4.0f} {st['n_active'][0]:8d} {st['n_active'][1]:7d} {st['natural_active'][0]:6d} "
                  f"{st['natural_active'][1]:6d} {st['natural_failed'][0]:6d} {st['natural_failed'][1]:6d} "
                  f"{st['max_centre_distance']:9.2e} {'yes' if st['same_path'] else 'NO'}")
        print(f"same paths at every step (centres within {comparison['tolerance']:g} m): {comparison['all_same']} "
              f"(first difference: {comparison['first_difference']})")
        if comparison["differing_centres"]:
            d = comparison["differing_centres"]
            print(f"at t = {d['time']:g} s only in dense: {np.round(d['only_first'], 3).tolist()}; "
                  f"only in hmatrix: {np.round(d['only_second'], 3).tolist()}")
    if profiler:
        stream = io.StringIO()
        pstats.Stats(profiler, stream=stream).sort_stats("cumulative").print_stats(45)
        stream.write("\n\n")
        pstats.Stats(profiler, stream=stream).sort_stats("tottime").print_stats(30)
        path = os.path.join(args.out, "dfn_profile.txt")
        with open(path, "w") as f:
            f.write(stream.getvalue())
        print(f"\nprofile: {path}")
    name = "dfn_records_reduced.json" if args.reduced else "dfn_records.json"
    with open(os.path.join(args.out, name), "w") as f:
        json.dump(results, f, indent=1, default=float)
    plot = args.plot or os.path.join(HERE, "dfn_plan_reduced.png" if args.reduced else "dfn_plan.png")
    if last_sim is not None:
        plot_plan(last_sim, plot, title=f"{'reduced ' if args.reduced else ''}DFN, {backends[-1]}, "
                                         f"t = {last_sim.state.time:g} s")
        print(f"plan view: {plot}")
    print(f"records: {os.path.join(args.out, name)}")
    return results


if __name__ == "__main__":
    main()
