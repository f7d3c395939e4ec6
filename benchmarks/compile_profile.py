"""Where a cold test run spends its numba compile time: a pytest plugin and its report.

Most of a cold default test set is numba compiling (issue 18). This plugin listens to
numba's ``numba:compile`` events and records, for every compiled function and signature,
its inclusive CPU time and its exclusive time (inclusive less the compiles nested in it),
with the test that triggered it. Exclusive times add up to the run's compile CPU; a
function's exclusive time includes LLVM's re-optimisation of everything it links (numba
links each callee's module into its caller and optimises the whole module again).

Run the default set cold (an empty cache directory) with the plugin, then the report::

    rm -rf /tmp/cold && NUMBA_CACHE_DIR=/tmp/cold PYTHONPATH=benchmarks \\
        python -m pytest -p compile_profile
    python benchmarks/compile_profile.py compile-profile-*.json

Each pytest process that compiled something (each xdist worker) writes ``compile-profile-<worker>.json`` in the
directory named by ``COMPILE_PROFILE_DIR`` (default: the current one).
"""
import argparse
import collections
import json
import os
import time

_stack = []  # [start CPU time, CPU time of nested compiles] per open compile
_records = []
_test = ["<collection>"]


def _register():
    from numba.core import event

    class CompileListener(event.Listener):
        def on_start(self, ev):
            _stack.append([time.process_time(), 0.0])

        def on_end(self, ev):
            start, nested = _stack.pop()
            inclusive = time.process_time() - start
            if _stack:
                _stack[-1][1] += inclusive
            function = getattr(ev.data.get("dispatcher"), "py_func", None)
            name = f"{function.__module__}.{function.__qualname__}" if function else "?"
            _records.append(dict(test=_test[0], function=name, signature=str(ev.data.get("args")),
                                 inclusive=inclusive, exclusive=inclusive - nested, depth=len(_stack)))

    event.register("numba:compile", CompileListener())


def pytest_configure(config):
    _register()


def pytest_runtest_setup(item):
    _test[0] = item.nodeid


def pytest_sessionfinish(session):
    if not _records:  # e.g. the controller of xdist workers
        return
    worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
    path = os.path.join(os.environ.get("COMPILE_PROFILE_DIR", "."), f"compile-profile-{worker}.json")
    from _common import machine  # benchmarks/ is on the path (-p compile_profile)

    with open(path, "w") as f:
        json.dump(dict(machine=machine(), records=_records), f)


def report(paths, top=30):
    """Compile CPU per worker, per function (all its signatures) and per module."""
    records = []
    for path in paths:
        with open(path) as f:
            run = json.load(f)
        print(f"{os.path.basename(path)}: {run['machine']}")
        for record in run["records"]:
            record["worker"] = os.path.basename(path)
            records.append(record)
    total = sum(r["exclusive"] for r in records)
    print(f"compile CPU: {total:.1f} s in {len(records)} compiles")
    per_worker = collections.Counter()
    for r in records:
        per_worker[r["worker"]] += r["exclusive"]
    for worker, seconds in sorted(per_worker.items()):
        print(f"  {worker}: {seconds:.1f} s")
    for title, key in (("function", lambda r: r["function"]),
                       ("module", lambda r: r["function"].split(".<locals>")[0].rsplit(".", 1)[0])):
        seconds, count = collections.Counter(), collections.Counter()
        for r in records:
            seconds[key(r)] += r["exclusive"]
            count[key(r)] += 1
        print(f"\n| {title} | exclusive CPU (s) | compiles |\n|---|---|---|")
        for name, value in seconds.most_common(top):
            print(f"| `{name}` | {value:.1f} | {count[name]} |")
    per_test = collections.Counter()
    for r in records:
        if r["depth"] == 0:
            per_test[r["test"]] += r["inclusive"]
    print("\n| test (first to need the code) | compile CPU (s) |\n|---|---|")
    for test, value in per_test.most_common(top // 2):
        print(f"| `{test}` | {value:.1f} |")
    return records


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("paths", nargs="+", help="compile-profile-*.json files of one run")
    parser.add_argument("--top", type=int, default=30)
    args = parser.parse_args()
    report(args.paths, args.top)


if __name__ == "__main__":
    main()
