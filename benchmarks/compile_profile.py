"""Where a cold test run spends its numba compile time: a pytest plugin and its report.

Most of a cold default test set is numba compiling (issue 18). This plugin listens to
numba's ``numba:compile`` events (:class:`CompileRecorder`, also used by
``bench_layered3d_compile.py``) and records, for every compiled function and signature,
its inclusive CPU time, its exclusive time (inclusive less the compiles nested in it) and
the LLVM part of that, with the test that triggered it. Exclusive times add up to the run's compile CPU; a
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
import contextlib
import json
import os
import time

class CompileRecorder:
    """Listens to numba's compile events while :meth:`listening`: one record per compile
    (``module``, ``name`` (qualified), ``signature``, ``inclusive`` / ``exclusive`` /
    ``llvm`` CPU seconds, ``depth`` of nesting, ``label``: what :attr:`label` was then) in
    :attr:`records`. ``exclusive`` is ``inclusive`` less the compiles nested in it;
    ``llvm`` is the exclusive part spent holding numba's LLVM lock (optimisation and
    machine code)."""

    def __init__(self):
        self.records = []
        self.label = "<none>"
        self._open = []  # per open compile: [start CPU, nested compiles' CPU, LLVM CPU, LLVM start or None]

    def _listeners(self):
        from numba.core import event

        recorder = self

        class Compiles(event.Listener):
            def on_start(self, ev):
                recorder._open.append([time.process_time(), 0.0, 0.0, None])

            def on_end(self, ev):
                start, nested, llvm, _ = recorder._open.pop()
                inclusive = time.process_time() - start
                if recorder._open:
                    recorder._open[-1][1] += inclusive
                function = getattr(ev.data.get("dispatcher"), "py_func", None)
                recorder.records.append(dict(
                    label=recorder.label, module=getattr(function, "__module__", "?"),
                    name=getattr(function, "__qualname__", "?"), signature=str(ev.data.get("args")),
                    inclusive=inclusive, exclusive=inclusive - nested, llvm=llvm, depth=len(recorder._open)))

        class Llvm(event.Listener):
            def on_start(self, ev):
                if recorder._open:
                    recorder._open[-1][3] = time.process_time()

            def on_end(self, ev):
                if recorder._open and recorder._open[-1][3] is not None:
                    recorder._open[-1][2] += time.process_time() - recorder._open[-1][3]
                    recorder._open[-1][3] = None

        return {"numba:compile": Compiles(), "numba:llvm_lock": Llvm()}

    def register(self):
        """Listen from now on (for a whole process)."""
        from numba.core import event

        for kind, listener in self._listeners().items():
            event.register(kind, listener)

    @contextlib.contextmanager
    def listening(self):
        """Listen inside a ``with`` block."""
        from numba.core import event

        with contextlib.ExitStack() as stack:
            for kind, listener in self._listeners().items():
                stack.enter_context(event.install_listener(kind, listener))
            yield self


_recorder = CompileRecorder()
_recorder.label = "<collection>"


def pytest_configure(config):
    _recorder.register()


def pytest_runtest_setup(item):
    _recorder.label = item.nodeid


def pytest_sessionfinish(session):
    if not _recorder.records:  # e.g. the controller of xdist workers
        return
    worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
    path = os.path.join(os.environ.get("COMPILE_PROFILE_DIR", "."), f"compile-profile-{worker}.json")
    from _common import machine  # benchmarks/ is on the path (-p compile_profile)

    with open(path, "w") as f:
        json.dump(dict(machine=machine(), records=_recorder.records), f)


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
    for title, key in (("function", lambda r: f"{r['module']}.{r['name']}"), ("module", lambda r: r["module"])):
        seconds, llvm, count = collections.Counter(), collections.Counter(), collections.Counter()
        for r in records:
            seconds[key(r)] += r["exclusive"]
            llvm[key(r)] += r["llvm"]
            count[key(r)] += 1
        print(f"\n| {title} | exclusive CPU (s) | of which LLVM (s) | compiles |\n|---|---|---|---|")
        for name, value in seconds.most_common(top):
            print(f"| `{name}` | {value:.1f} | {llvm[name]:.1f} | {count[name]} |")
    per_test = collections.Counter()
    for r in records:
        if r["depth"] == 0:
            per_test[r["label"]] += r["inclusive"]
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
