"""How fast the command answers: `hmatddm --help`, `hmatddm scenes` and refused scenes.

Each case runs ``python -m hmatddm.app.cli ...`` in a fresh process ``--repeats`` times and
reports the median wall time and the median CPU time of the child (user + system), with
the exit code and the first line of the answer: the check that the answer is the right
one. ``--source DIR`` runs the package found in DIR instead of this checkout, e.g. an
export of an older commit (``git archive <commit> | tar -x -C DIR``) for the before/after
table of benchmarks/RESULTS.md.

    python benchmarks/bench_startup.py [--repeats 5] [--source DIR]
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import machine, markdown_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

_KGD = """dimension = 2
[material]
shear_modulus = 10e9
poisson_ratio = 0.25
[fluid]
viscosity = {viscosity}
[stress]
s_hmin = 0.5e6
s_hmax = 1e6
[[cluster]]
position = [0.0, 0.0]
rate = 5e-4
[[initial_fracture]]
shape = "line"
p0 = [-1.5, 0.0]
p1 = [1.5, 0.0]
element_size = {size}
[propagation]
toughness = 5e6
[numerics]
end_time = 10.0
backend = "dense"
"""
# a T junction: the second fracture ends on the centre of the first's middle element
_T_JUNCTION = _KGD.format(viscosity=1e-3, size=1.0) + """[[initial_fracture]]
shape = "line"
p0 = [0.0, 0.0]
p1 = [0.0, 2.0]
element_size = 1.0
"""
_HUGE_3D = """[material]
shear_modulus = 24e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-3
[stress]
s_hmin = 10e6
s_hmax = 12e6
s_v = 8e6
[[cluster]]
position = [0.0, 0.0, 0.0]
rate = 0.01
[[initial_fracture]]
e2 = [0.0, 1.0, 0.0]
length = 100.0
height = 100.0
element_size = 1e-4
[numerics]
end_time = 10.0
"""


def cases(folder):
    """(name, argv, expected exit code) of every case; scene files go to ``folder``."""
    scenes = {"negative-viscosity": _KGD.format(viscosity=-1e-3, size=1.0), "t-junction": _T_JUNCTION,
              "huge-3d": _HUGE_3D, "huge-2d": _KGD.format(viscosity=1e-3, size=3e-6)}
    paths = {}
    for name, text in scenes.items():
        paths[name] = folder / f"{name}.toml"
        paths[name].write_text(text)
    out = "{out}"  # a fresh folder for every process (an older version claimed it on a refusal)
    return [("hmatddm --help", ["--help"], 0),
            ("hmatddm scenes", ["scenes"], 0),
            ("run: viscosity < 0", ["run", str(paths["negative-viscosity"]), "--out", out], 2),
            ("run: T junction (centre on an edge)", ["run", str(paths["t-junction"]), "--out", out], 2),
            ("run: 100 m square of 0.1 mm elements (1e12)", ["run", str(paths["huge-3d"]), "--out", out], 2),
            ("run: 2D, 1e6 elements", ["run", str(paths["huge-2d"]), "--out", out], 2)]


def run_case(argv, source, repeats, timeout):
    env = dict(os.environ, PYTHONPATH=str(source))
    walls, cpus, result = [], [], None
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        with tempfile.TemporaryDirectory() as out:
            command = [sys.executable, "-m", "hmatddm.app.cli", *(a.replace("{out}", out + "/run") for a in argv)]
            try:
                result = subprocess.run(command, capture_output=True, text=True, env=env, cwd=tempfile.gettempdir(),
                                        timeout=timeout)
            except subprocess.TimeoutExpired as expired:
                result = subprocess.CompletedProcess(command, f"killed after {timeout:g} s", "",
                                                     (expired.stderr or b"").decode(errors="replace")
                                                     + f"\nstill running after {timeout:g} s: killed")
        walls.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    answer = (result.stderr.strip() or result.stdout.strip()).splitlines()
    first = (answer[0] if result.returncode == 0 else answer[-1]) if answer else ""  # a traceback's last line
    for line in answer:  # the refusal, when there is one
        if line.startswith("hmatddm: error"):
            first = line
            break
    return statistics.median(walls), statistics.median(cpus), result.returncode, first


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--source", default=str(ROOT), help="folder holding the hmatddm package to time")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds before a case is killed")
    parser.add_argument("--width", type=int, default=110, help="answers are cut to this many characters")
    args = parser.parse_args(argv)
    print(f"machine: {machine()}; load average at start {os.getloadavg()[0]:.2f}; source {args.source}; "
          f"median of {args.repeats} fresh processes")
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, command, expected in cases(Path(folder)):
            wall, cpu, code, first = run_case(command, args.source, args.repeats, args.timeout)
            answer = first if len(first) <= args.width else first[:args.width - 3] + "..."
            rows.append([name, f"{wall:.2f}", f"{cpu:.2f}", f"{code}{'' if code == expected else ' (!)'}",
                         answer.replace("|", "\\|")])
    print(markdown_table(["case", "wall (s)", "CPU (s)", "exit", "answer"], rows))
    print(f"load average at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
