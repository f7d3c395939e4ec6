"""Cost of natural fractures in a layered medium (issue 14 item 4): the same small 2D runs
in uniform rock, in equal layers and in layers with a free surface and a stiffness and
stress contrast.

Scenes (2D, dense operator):

* ``crossing``: the crossing scene of tests/fracture/test_crossing.py (a fracture along x meets a
  natural fracture across its path), 20 s;
* ``network``: a 40-element fracture along x injected for 4 s next to 300 random natural
  segments (the remote-failure scene of tests/simulation/test_simulation_natural.py), so that the
  remote-failure checks dominate: in uniform rock and equal layers they are screened by the
  stress bound; with images every intact element is evaluated by the layered direct sum.

Every run is done twice; the second is timed (the first compiles). The error column of the
equal layers is ``max |dd - dd_uniform| / max |dd_uniform|`` (the images vanish there).

Usage: ``python benchmarks/bench_layered_natural.py``
"""
import time

import numpy as np

import hmatddm as hd
from hmatddm.layered import LayeredMedium

try:
    from benchmarks._common import machine, markdown_table
except ImportError:  # run as a script from benchmarks/
    from _common import machine, markdown_table

G, NU = 10e9, 0.25


def crossing(material):
    hf = hd.mesh.line([-0.075, 0], [0.075, 0], 3)
    nf = hd.mesh.line([0.2, -0.15], [0.2, 0.15], 6)
    props = hd.NaturalFractureProperties(friction=0.38, cohesion=3.2e6, tensile_strength=5e6, toughness=0.5e6,
                                         critical_radius=0.005)
    sim = hd.Simulation(hf, material, hd.Fluid(0.135, 4.545e-10), [hd.Cluster((0, 0), 4e-6, 1e-5)],
                        far_field_stress=np.diag([-13e6, -3e6]), time_step=1.0,
                        propagation=hd.Propagation(toughness=2e6), initial_pressure=3.5e6, initial_opening=1e-5,
                        backend="dense", natural_fractures=nf, natural=props, singular_correction="average",
                        alpha=1.0)
    return sim, 20.0


def network(material):
    rng = np.random.default_rng(3)
    hf = hd.mesh.line([-5, 0], [5, 0], 40)
    centers = np.column_stack([rng.uniform(-25, 25, 300), rng.uniform(-12, 12, 300)])
    angle = rng.uniform(0, np.pi, 300)
    tangent = np.column_stack([np.cos(angle), np.sin(angle)])
    nf = hd.Mesh2D.from_segments(centers - 0.25 * tangent, centers + 0.25 * tangent)
    props = hd.NaturalFractureProperties(friction=0.25, cohesion=0.0, pore_pressure=30.2e6 * 0.9, skempton=0.5)
    sim = hd.Simulation(hf, material, hd.Fluid(1e-3, 4.4e-10), [hd.Cluster((0, 0), 2e-3, 0.0)],
                        far_field_stress=np.diag([-39.44e6, -35.85e6]), time_step=1.0, initial_pressure=37.5e6,
                        initial_opening=1e-4, backend="dense", natural_fractures=nf, natural=props,
                        singular_correction="average", alpha=1.0)
    return sim, 4.0


def _media(scene):
    """The media of a scene (the stress layers match its far field)."""
    far = np.diag([-13e6, -3e6]) if scene is crossing else np.diag([-39.44e6, -35.85e6])
    upper = far + np.diag([2e6, 0.0])
    return {
        "uniform (Elastic)": hd.Elastic(G, NU),
        "equal layers": LayeredMedium([0.1, -0.1] if scene is crossing else [6.0, -6.0], [G] * 3, [NU] * 3),
        "free surface, 2x stiffer layer, -2 MPa s_xx": LayeredMedium(
            [0.3, 0.05] if scene is crossing else [13.0, 1.0], [0.0, 2 * G, G], [NU] * 3, images=4,
            in_situ_stress=[np.zeros((2, 2)), upper, far]),
    }


def timed(scene, material):
    for attempt in range(2):
        sim, end = scene(material)
        cpu, wall = time.process_time(), time.perf_counter()
        records = sim.run(end)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    events = (sum(r["natural_crossed"] for r in records), sum(r["natural_deflected"] for r in records),
              records[-1]["natural_failed"])
    return sim, cpu, wall, events


def main():
    import os

    print(machine())
    print("load (1, 5, 15 min):", " ".join(f"{x:.1f}" for x in os.getloadavg()))
    rows = []
    for scene in (crossing, network):
        reference = None
        for name, material in _media(scene).items():
            sim, cpu, wall, events = timed(scene, material)
            dd = sim.state.dd
            if reference is None:
                reference, error = dd, "-"
            elif name == "equal layers" and dd.shape == reference.shape:
                error = f"{np.abs(dd - reference).max() / np.abs(reference).max():.1e}"
            else:
                error = "-"
            rows.append([scene.__name__, name, sim.network.mesh.n_elements, sim.state.mesh.n_elements,
                         "%d / %d / %d" % events, f"{cpu:.2f}", f"{wall:.2f}", error])
            print(rows[-1], flush=True)
    print("load (1, 5, 15 min):", " ".join(f"{x:.1f}" for x in os.getloadavg()))
    print(markdown_table(["scene", "medium", "natural elements", "active elements (end)",
                          "crossed / deflected / failed", "CPU s", "wall s", "error vs uniform"], rows))


if __name__ == "__main__":
    main()
