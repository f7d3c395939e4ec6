"""Convergence of the embedded closed-form scenes under mesh refinement (issue 39).

    python benchmarks/bench_convergence.py                          # h = 1, 0.5 m (0.25 m where it fits)
    python benchmarks/bench_convergence.py --cases kgd,radial-k --sizes 1,0.5,0.25
    python benchmarks/bench_convergence.py --max-elements 20000     # let h/4 of the 3D scenes run too
    python benchmarks/bench_convergence.py --cases radial-k --front level_set_order=2 \
        --front far_ribbon_3d_toughness=True                        # a variant of the asymptotic front

Cases, each against the closed form that applies to it (hmatddm.analytical.regimes):

* ``radial-m``: the M-vertex (K_m <= 0.6 over the run), 30 s;
* ``radial-k``: the K-vertex (K_m 4.1-6.3), 50 s;
* ``radial-km``: ref. Table 4.1's K column (K_m 1.8-2.9) against Dontsov's (2016) K-M
  transition, with the K-vertex beside it (its net pressure: the transition has none);
* ``kgd``: the plane-strain K-vertex, 100 s; ``kgd-element``: the same with the element
  front (the reference's switch), for comparison.

Each run (scene as embedded, ``initial_fracture[0].element_size = h`` and the initial
fracture cut into an odd number of elements, :func:`mesh_overrides`; the front of the
scene) is a child process; its CPU time is ``time.process_time`` around ``Simulation.run``
(every thread of the child, numba's cached kernels loaded before). Per run: the final size
(R or half-length), opening at the well ``w0``, net pressure (the opening-weighted mean
where the closed form's is uniform, and the injection element's beside it), their errors
against the closed form at the end, and the RMS error over the second half of the run
(the asymptotic front's error oscillates as the front crosses elements; the RMS over many
crossings says more than one instant), elements, CPU and wall time; then the observed order
``log2(e_h / e_(h/2))`` between consecutive sizes. A run whose closed-form size would need
more than ``--max-elements`` elements is skipped, and said so. Plot:
``benchmarks/convergence.png`` (|error| against h, log-log, one panel per case).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

CASES = ("radial-m", "radial-k", "radial-km", "kgd", "kgd-element")  # kgd-m (VARIANTS) on request
# a case that is an embedded scene with other settings: (scene, its --set assignments). kgd-m:
# the KGD M vertex (K_m 0.003) on the asymptotic front, incompressible and without the
# wellbore's storage (the vertex has neither; the kgd scene's put ~2% of the fluid in the
# wellbore at 25 s), 0.25 s steps (issue 39)
VARIANTS = {"kgd-element": ("kgd", ['propagation.front="element"']),
            "kgd-m": ("kgd", ["propagation.toughness=1e4", "fluid.viscosity=0.1", 'reference.kind="kgd-m"',
                              "fluid.compressibility=0", "cluster[0].wellbore_volume=0", "numerics.time_step=0.25",
                              'numerics.backend="dense"'])}

_CHILD = """
import json, os, sys, time
import hmatddm.scene as hs
from hmatddm.scene import apply_override

name, out, overrides = sys.argv[1], sys.argv[2], sys.argv[3:]
if os.environ.get("BENCH_FRONT"):  # --front: attributes of AsymptoticFront (variants of the front)
    import ast
    from hmatddm.simulation.asymptotic import AsymptoticFront
    for assignment in os.environ["BENCH_FRONT"].split(";"):
        key, value = assignment.split("=", 1)
        assert hasattr(AsymptoticFront, key), key
        setattr(AsymptoticFront, key, ast.literal_eval(value))
raw = hs.parse_scene(hs.embedded_text(name)).data
for assignment in overrides:
    apply_override(raw, assignment)
scene = hs.scene_from_dict(raw, name)
simulation = hs.build_simulation(scene.data)
cpu, wall = time.process_time(), time.perf_counter()
records = simulation.run(scene.data["numerics"]["end_time"])
cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
json.dump(dict(records=records, reference=hs.reference_values(scene.data, records), cpu=cpu, wall=wall,
               confining=hs.confining_stress(scene.data)), open(out, "w"))
"""

QUANTITIES = ("size", "max_opening", "net_pressure", "injection_net_pressure")


def expected_elements(name, h):
    """Elements the closed form's final size needs at element size h (to skip runs too big)."""
    sys.path.insert(0, ROOT)
    import hmatddm.scene as hs
    from hmatddm.scene.build import _closed_form

    data = hs.load_scene(VARIANTS.get(name, (name,))[0]).data
    curves = _closed_form(data, [data["numerics"]["end_time"]])
    if "radius" in curves:
        return int(math.pi * float(curves["radius"][0]) ** 2 / h**2)
    return int(2.0 * float(curves["half_length"][0]) / h)


def mesh_overrides(name, h):
    """``--set`` assignments of a run at element size ``h``: the initial fracture of the scene
    (3 m, centred on the well) cut into an odd number of elements, so that the well is at
    an element's centre at every h (3 m at h = 1 m; 3 m + h where 3 m / h is even: 3.5 m at
    0.5 m, 3.25 m at 0.25 m). With an even number the well lies on an element edge (2D) or
    corner (3D), the injection element is off-centre by h/2 and the two wings (the front)
    grow unevenly: measured on kgd at h = 0.5 m, 60 s, the RMS half-length error went from
    1.5% (6 elements, 3 m) to 0.6% (5 elements, 2.5 m)."""
    name, sets = VARIANTS.get(name, (name, []))
    length = 3.0 if round(3.0 / h) % 2 == 1 else 3.0 + h
    sets = sets + [f"initial_fracture[0].element_size={h}"]
    if name == "kgd":
        sets += [f"initial_fracture[0].p0=[{-length / 2},0.0]", f"initial_fracture[0].p1=[{length / 2},0.0]"]
    else:
        sets += [f"initial_fracture[0].length={length}", f"initial_fracture[0].height={length}"]
    return sets


def run(name, h, folder, extra=(), front=()):
    """One run in a child process: final values, errors, RMS errors over the second half
    (``extra``: more ``--set`` assignments, e.g. ``numerics.time_step=0.5``; ``front``:
    ``attribute=value`` of :class:`hmatddm.simulation.asymptotic.AsymptoticFront` set in the child)."""
    out = os.path.join(folder, f"{name}-{h}.json")
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]),
                       BENCH_FRONT=";".join(front))
    scene = VARIANTS.get(name, (name,))[0]
    subprocess.run([sys.executable, "-c", _CHILD, scene, out, *mesh_overrides(name, h), *extra], env=environment,
                   check=True)
    result = json.load(open(out))
    records, rows = result["records"], result["reference"]
    size_key = "radius" if "radius" in rows[-1] else "half_length"
    last, row = records[-1], rows[-1]
    end = last["time"]
    late = [r for r in rows if r["time"] >= 0.5 * end]

    def errors(row_of):
        """final and RMS (second half) errors of the three quantities, by ``row_of(row)``."""
        final, rms = {}, {}
        for quantity in QUANTITIES:
            key = size_key if quantity == "size" else quantity
            values = [row_of(r)["relative_error"].get(key) for r in late]
            if row_of(row) is None or row_of(row)["relative_error"].get(key) is None:
                final[quantity] = rms[quantity] = None
                continue
            final[quantity] = row_of(row)["relative_error"][key]
            rms[quantity] = math.sqrt(sum(v * v for v in values) / len(values))
        return final, rms

    final, rms = errors(lambda r: r)
    out_row = dict(case=name, h=h, elements=last["n_elements"], steps=len(records), cpu=result["cpu"],
                   wall=result["wall"], size=last[size_key], max_opening=last["max_opening"],
                   net_pressure=(last["mean_pressure"] if "mean_pressure" in last else last["wellbore_pressure"][0])
                   - result["confining"],
                   circularity=last.get("front_circularity"), regime=(rows[0]["regime"]["value"], row["regime"]["value"]),
                   error=final, rms=rms)
    if "k_vertex" in row:
        out_row["k_vertex_error"], out_row["k_vertex_rms"] = errors(lambda r: r.get("k_vertex"))
    return out_row


def order(coarse, fine):
    """log2(|e_h| / |e_(h/2)|) (None where an error is missing or zero)."""
    if coarse is None or fine is None or coarse == 0.0 or fine == 0.0:
        return None
    return math.log(abs(coarse) / abs(fine)) / math.log(2.0)


def percent(value):
    return "-" if value is None else f"{100.0 * value:+.2f}%"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--sizes", default="1,0.5,0.25", help="element sizes h (m), coarse to fine")
    parser.add_argument("--max-elements", type=int, default=5000,
                        help="skip a run whose closed-form size needs more elements than this")
    parser.add_argument("--plot", default=os.path.join(HERE, "convergence.png"))
    parser.add_argument("--json", default=None, help="also write the rows to this file")
    parser.add_argument("--set", action="append", default=[],
                        help="another scene assignment for every run (repeatable), e.g. numerics.time_step=0.5")
    parser.add_argument("--front", action="append", default=[],
                        help="an AsymptoticFront class attribute for every run (repeatable), e.g. level_set_order=2")
    parser.add_argument("--report", default=None,
                        help="no runs: print the tables and plot of earlier --json files (comma separated)")
    args = parser.parse_args()
    sys.path.insert(0, HERE)
    from _common import machine

    if args.report:
        rows, skipped = [], []
        for path in args.report.split(","):
            earlier = json.load(open(path))
            print(f"{path}: {earlier['machine']}")
            rows += earlier["rows"]
            skipped += earlier["skipped"]
        return report(rows, skipped, args.plot)
    print(f"Machine: {machine()}", flush=True)
    rows, skipped = [], []
    with tempfile.TemporaryDirectory() as folder:
        for name in args.cases.split(","):
            for h in [float(s) for s in args.sizes.split(",")]:
                needed = expected_elements(name, h)
                if needed > args.max_elements:
                    skipped.append(f"{name} at h = {h:g} m (~{needed} elements > --max-elements {args.max_elements})")
                    print(f"skipped {skipped[-1]}", flush=True)
                    continue
                rows.append(run(name, h, folder, args.set, args.front))
                print(json.dumps(rows[-1]), flush=True)
    if args.json:
        json.dump(dict(rows=rows, skipped=skipped, machine=machine()), open(args.json, "w"), indent=1)
    report(rows, skipped, args.plot)


def report(rows, skipped, plot_path):
    """The table of the runs, the observed orders, what was skipped, and the plot."""
    from _common import print_table

    header = ["case", "h (m)", "K_m (first, last)", "elements", "steps", "CPU (s)", "wall (s)", "R or l (m)",
              "w0 (mm)", "p net (MPa)", "R/l err", "w0 err", "p err", "p well err", "RMS R/l", "RMS w0", "RMS p",
              "RMS p well", "roundness"]
    table = []
    for r in rows:
        table.append([r["case"], f"{r['h']:g}", f"{r['regime'][0]:.2f}, {r['regime'][1]:.2f}", r["elements"],
                      r["steps"], f"{r['cpu']:.1f}", f"{r['wall']:.1f}", f"{r['size']:.3f}",
                      f"{1e3 * r['max_opening']:.4f}", f"{1e-6 * r['net_pressure']:.4f}",
                      *(percent(r["error"][q]) for q in QUANTITIES), *(percent(r["rms"][q]) for q in QUANTITIES),
                      "-" if r["circularity"] is None else f"{r['circularity']:.3f}"])
        if "k_vertex_error" in r:
            table.append([f"{r['case']} vs K-vertex", f"{r['h']:g}", "", "", "", "", "", "", "", "",
                          *(percent(r["k_vertex_error"][q]) for q in QUANTITIES),
                          *(percent(r["k_vertex_rms"][q]) for q in QUANTITIES), ""])
    print_table(header, table)
    orders = []
    for coarse, fine in zip(rows, rows[1:]):
        if coarse["case"] != fine["case"]:
            continue
        orders.append([coarse["case"], f"{coarse['h']:g} -> {fine['h']:g}",
                       *(_fmt(order(coarse["error"][q], fine["error"][q])) for q in QUANTITIES),
                       *(_fmt(order(coarse["rms"][q], fine["rms"][q])) for q in QUANTITIES)])
    print_table(["case", "h", "order R/l (end)", "order w0 (end)", "order p (end)", "order p well (end)",
                 "order R/l (RMS)", "order w0 (RMS)", "order p (RMS)", "order p well (RMS)"], orders)
    for line in skipped:
        print(f"skipped: {line}")
    plot(rows, plot_path)


def _fmt(value):
    return "-" if value is None else f"{value:.2f}"


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker  # noqa: F401  (matplotlib.ticker.NullLocator below)

    cases = list(dict.fromkeys(r["case"] for r in rows))
    figure, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 3.8), squeeze=False)
    labels = {"size": "R or l", "max_opening": "w0", "net_pressure": "p net (mean)",
              "injection_net_pressure": "p net (well)"}
    for axis, case in zip(axes[0], cases):
        mine = [r for r in rows if r["case"] == case]
        h = [r["h"] for r in mine]
        for quantity, colour in zip(QUANTITIES, ("C0", "C1", "C2", "C3")):
            for key, style, suffix in (("error", "o-", "end"), ("rms", "s--", "RMS 2nd half")):
                values = [r[key][quantity] for r in mine]
                if all(v is not None for v in values):
                    axis.loglog(h, [max(abs(v), 1e-5) for v in values], style, color=colour,
                                label=f"{labels[quantity]} ({suffix})")
        if len(h) > 1:  # first-order guide
            axis.loglog(h, [0.01 * x / h[0] for x in h], ":", color="grey", label="O(h)")
        axis.set_xticks(h, [f"{x:g}" for x in h])
        axis.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        axis.set_title(case)
        axis.set_xlabel("element size h (m)")
        axis.invert_xaxis()
        axis.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("|relative error|")
    axes[0][-1].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
