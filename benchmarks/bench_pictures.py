"""What a run's pictures and closed-form comparisons cost (issue 38): a whole run of each
scene through the runner (``hmatddm run``: summary.json after every step, a .vtu and a
profile picture beside every saved step, the snapshots and history at the end), once with
``output.snapshots`` on and once off, with CPU and wall time, the pictures written and the
CPU they took, and the error against the scene's closed form at the end.

Every run is a fresh child process (the same imports and cached compilations for every
row); ``--compare DIR`` adds a run of each scene with the hmatddm source tree in DIR (e.g. a
git worktree of the previous version), right after this version's, so both see the same
machine.

    PYTHONPATH=. python benchmarks/bench_pictures.py [SCENE ...] [--compare DIR]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import machine, print_table

SCENES = ("default", "kgd", "layered-height")


def run_once(name, snapshots):
    """One run of the embedded scene ``name`` into a temporary folder: a dict of its cost."""
    from hmatddm.app import runner
    from hmatddm.scene import load_scene

    scene = load_scene(name, overrides=[f"output.snapshots={'true' if snapshots else 'false'}"])
    with tempfile.TemporaryDirectory() as out:
        run = runner.SceneRun(scene, out, quiet=True)
        cpu, wall = time.process_time(), time.perf_counter()
        summary = run.execute()
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        pictures = len(list(Path(out, "snapshots").glob("*_profile.png")))
    reference = summary["reference"]
    errors = (reference[-1].get("relative_error") or {}) if reference else {}
    error = ", ".join(f"{key} {100 * value:+.2f}%" for key, value in errors.items() if value is not None)
    return {"scene": name, "snapshots": snapshots, "steps": len(summary["steps"]) - 1, "cpu": cpu, "wall": wall,
            "profiles": pictures, "profile_cpu": getattr(run, "profile_seconds", None), "error": error or "-"}


def in_child(name, snapshots, source):
    """:func:`run_once` in a fresh child process with the hmatddm source tree ``source``, so
    that every row pays the same imports and cached compilations."""
    # -P: not the script's folder first on sys.path, so that the package comes from ``source``
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(source).resolve()), str(Path(__file__).parent)]))
    arguments = [sys.executable, "-P", __file__, name, "--child"] + ([] if snapshots else ["--no-snapshots"])
    child = subprocess.run(arguments, env=env, capture_output=True, text=True, check=True, cwd=Path(__file__).parent)
    return json.loads(child.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=list(SCENES))
    parser.add_argument("--compare", help="source tree of another hmatddm version, run beside this one")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--no-snapshots", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:  # one scene, printed as JSON for the parent
        print(json.dumps(run_once(args.scenes[0], not args.no_snapshots)))
        return
    print(f"Machine at the start: {machine()}")
    this = Path(__file__).resolve().parent.parent
    rows = []
    for name in args.scenes:
        results = [in_child(name, True, this), in_child(name, False, this)]
        if args.compare:
            previous = in_child(name, True, args.compare)
            previous["scene"] = f"{name} (previous)"
            results.append(previous)
        for result in results:
            share = (f"{100 * result['profile_cpu'] / result['cpu']:.1f}%"
                     if result["profile_cpu"] is not None and result["snapshots"] else "-")
            rows.append([result["scene"], "on" if result["snapshots"] else "off", result["steps"],
                         f"{result['cpu']:.1f}", f"{result['wall']:.1f}", result["profiles"], share, result["error"]])
            print(" | ".join(str(c) for c in rows[-1]), flush=True)
    print_table(["scene", "snapshots", "steps", "CPU (s)", "wall (s)", "profile pictures",
                 "their CPU share", "error vs closed form (end)"], rows)
    print(f"Machine at the end: {machine()}")


if __name__ == "__main__":
    main()
