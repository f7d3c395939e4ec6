"""A hydraulic fracture meets a natural fracture: crossing or deflection (ref. Sec. 5.2).

Runs the embedded ``crossing`` scene (ref. Table 5.1 rock, fluid and natural-fracture
strength, plane strain, Mohr-Coulomb criterion) twice: at S_Hmax = 13 MPa the tip
crosses the natural fracture at 90 degrees; at 6 MPa it is deflected into it (the
natural element is activated, connected for flow and the tip arrested). Prints the
decisions and writes snapshots to ``examples_out/crossing_*``.

Run: ``python examples/crossing.py`` (a few seconds).
"""
from pathlib import Path

import hmatddm.scene as hs
from hmatddm.app.runner import SceneRun


def main():
    for s_hmax in (13e6, 6e6):
        scene = hs.load_scene("crossing", overrides=[f"stress.s_hmax={s_hmax}"])
        out = Path(f"examples_out/crossing_{s_hmax / 1e6:.0f}MPa")
        summary = SceneRun(scene, out, overwrite=True, quiet=True).execute()
        crossed = sum(step["natural_crossed"] for step in summary["steps"])
        deflected = sum(step["natural_deflected"] for step in summary["steps"])
        last = summary["steps"][-1]
        print(f"S_Hmax {s_hmax / 1e6:4.0f} MPa: crossed {crossed}, deflected {deflected}, "
              f"{last['natural_active']} natural elements carry fluid, {last['n_elements']} active elements; "
              f"snapshots in {out / 'snapshots'}")


if __name__ == "__main__":
    main()
