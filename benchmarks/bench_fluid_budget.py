"""The fluid budget of every embedded scene (issue 38): the worst residual of summary.json's
``budget`` against the fluid moved, on short runs (end times below, to keep each under a
few minutes on a loaded 2-core machine), with CPU and wall time.

    PYTHONPATH=. python benchmarks/bench_fluid_budget.py [SCENE ...]
"""
import sys
import time

from _common import machine, print_table

# end time (s) of each scene's short run; None: the scene's own
END_TIMES = {"crossing": 10.0, "default": 10.0, "dfn-3cluster": 10.0, "kgd": 20.0, "layered-3d": 1.0,
             "layered-height": 10.0, "radial-k": 10.0, "radial-km": 10.0, "radial-m": 10.0, "shallow-sill": 4.0,
             "three-clusters": 10.0}


def main(names):
    import hmatddm.scene as hs
    from hmatddm.simulation.records import initial_record, worst_budget_residual

    print(f"Machine at the start: {machine()}")
    rows = []
    for name in names or hs.embedded_names():
        end = END_TIMES.get(name)
        scene = hs.load_scene(name, overrides=[] if end is None else [f"numerics.end_time={end}"])
        end = scene.data["numerics"]["end_time"]
        cpu, wall = time.process_time(), time.perf_counter()
        simulation = hs.build_simulation(scene.data)
        steps = [initial_record(simulation)] + simulation.run(end)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        residual, moved, step = worst_budget_residual(steps)
        rows.append([name, f"{end:g}", len(steps) - 1, steps[-1]["n_elements"], f"{residual:+.2e}", f"{moved:.3g}",
                     f"{abs(residual) / moved:.1e}", step, f"{cpu:.1f}", f"{wall:.1f}"])
        print(" | ".join(str(c) for c in rows[-1]), flush=True)
    print_table(["scene", "end time (s)", "steps", "elements", "worst residual (m^3)", "fluid moved (m^3)",
                 "residual / moved", "at step", "CPU (s)", "wall (s)"], rows)


if __name__ == "__main__":
    main(sys.argv[1:])
