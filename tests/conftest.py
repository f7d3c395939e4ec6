import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))  # for kelvin_reference
# as the hmatddm command does (the library itself changes no environment variable):
# numba's OpenMP workers wait passively on this shared machine
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import hmatddm as hd  # noqa: E402

# a busy machine must not fail a property test: no per-example deadline and no "too slow"
# health check for every @given (tests may still set their own max_examples)
try:
    from hypothesis import HealthCheck, settings as _hypothesis_settings

    _hypothesis_settings.register_profile("hmatddm", deadline=None,
                                          suppress_health_check=[HealthCheck.too_slow])
    _hypothesis_settings.load_profile("hmatddm")
except ImportError:  # pragma: no cover - hypothesis is a test dependency
    pass

G, NU = 10e9, 0.25


@pytest.fixture(scope="session")
def material():
    return hd.Elastic(shear_modulus=G, poisson_ratio=NU)


def random_rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 2] *= -1
    return q


def rotation_2d(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


# -- parallel run (pytest-xdist: `-n 2 --dist loadscope --no-loadscope-reorder`, pyproject.toml)
# Most of a cold run's CPU time is numba compiling kernels on first use, on one thread,
# and each worker process compiles for itself what the on-disk cache does not yet hold.
# So the tests of a module run in one worker, and the modules that compile the same costly
# kernel family form one group. The two biggest families (layered media in 3D and in 2D,
# each also compiling the homogeneous kernels of its dimension) go out first, one to each
# worker, so that they compile at the same time on different cores and the other modules
# find most kernels in the cache; then the other modules, those with the most tests first.

_FAMILIES = {
    "layered-3d": ("test_layered_engine3d.py", "test_layered_halfspace3d.py",
                   "test_layered_images3d.py", "test_layered_influence3d.py"),
    "layered-2d": ("test_layered.py", "test_layered_engine.py", "test_layered_natural.py",
                   "test_higher_order_elements.py", "test_kernels_drivers.py"),
}
_FAMILY_OF_MODULE = {module: family for family, modules in _FAMILIES.items() for module in modules}


def _scope_of(nodeid):
    """A test's unit of work: its module's family, or its module."""
    module = nodeid.split("::", 1)[0]
    return _FAMILY_OF_MODULE.get(module.rsplit("/", 1)[-1], module)


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadscope`` with :func:`_scope_of` as the scope. (pytest-xdist's own
    ``loadgroup`` marks groups by appending ``@group`` to ``item._nodeid``, which pytest
    9.2 no longer reads: the groups were silently ignored and both workers compiled every
    kernel family, 1070 s of CPU instead of 750 s for the cold default set.)"""
    if config.getvalue("dist") != "loadscope":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class FamilyScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid):
            return _scope_of(nodeid)

    return FamilyScheduling(config, log)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    if hasattr(config, "workerinput"):  # a pytest-xdist worker: its order is the order sent out
        count = {}
        for item in items:
            count[item.path.name] = count.get(item.path.name, 0) + 1
        rank = {family: i for i, family in enumerate(_FAMILIES)}
        items.sort(key=lambda item: (rank.get(_FAMILY_OF_MODULE.get(item.path.name), len(rank)),
                                     -count[item.path.name]))


# -- CPU time per test (load-independent, unlike --durations' wall time) -------------------
# `python -m pytest --cpu-durations=30` lists the 30 tests that used the most CPU time
# (this process and its threads, plus waited-for child processes), and the session's total:
# on a shared machine this is what a test would cost on a quiet one. Under pytest-xdist each
# worker measures its tests and sends the figure with the teardown report; the summary adds
# the CPU time of each worker.

def pytest_addoption(parser):
    parser.addoption("--cpu-durations", type=int, default=None, metavar="N",
                     help="list the N tests with the most CPU time (setup + call + teardown)")


_CPU_SECONDS = {}  # nodeid -> (CPU seconds, worker)
_CPU_SECONDS_PER_WORKER = {}
_CPU_START = {}


def _cpu_now():
    import resource

    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if item.config.getoption("--cpu-durations") is not None:
        _CPU_START[item.nodeid] = _cpu_now()
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    if call.when == "teardown" and item.nodeid in _CPU_START:
        outcome.get_result().user_properties.append(("cpu_seconds", _cpu_now() - _CPU_START.pop(item.nodeid)))


def pytest_runtest_logreport(report):
    for name, value in report.user_properties:
        if name == "cpu_seconds":
            worker = getattr(getattr(report, "node", None), "gateway", None)
            worker = worker.id if worker is not None else "this process"
            _CPU_SECONDS[report.nodeid] = value, worker
            _CPU_SECONDS_PER_WORKER[worker] = _CPU_SECONDS_PER_WORKER.get(worker, 0.0) + value


_CPU_SECONDS_OF_WORKER_PROCESS = {}


def pytest_sessionfinish(session):
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None and session.config.getoption("--cpu-durations") is not None:
        workeroutput["cpu_seconds"] = _cpu_now()  # the whole worker, its collection included


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    if "cpu_seconds" in getattr(node, "workeroutput", {}):
        _CPU_SECONDS_OF_WORKER_PROCESS[node.gateway.id] = node.workeroutput["cpu_seconds"]


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    count = config.getoption("--cpu-durations")
    if count is None or not _CPU_SECONDS:
        return
    terminalreporter.section(f"most CPU time ({count} of {len(_CPU_SECONDS)} tests)")
    for nodeid, (seconds, worker) in sorted(_CPU_SECONDS.items(), key=lambda kv: -kv[1][0])[:count]:
        where = f"{worker}  " if len(_CPU_SECONDS_PER_WORKER) > 1 else ""
        terminalreporter.write_line(f"{seconds:8.2f}s cpu  {where}{nodeid}")
    for worker, seconds in sorted(_CPU_SECONDS_PER_WORKER.items()):
        whole = _CPU_SECONDS_OF_WORKER_PROCESS.get(worker)
        whole = f" ({whole:.2f}s cpu in the whole worker process)" if whole is not None else ""
        terminalreporter.write_line(f"{seconds:8.2f}s cpu  in the tests of {worker}{whole}")
    terminalreporter.write_line(f"{sum(_CPU_SECONDS_PER_WORKER.values()):8.2f}s cpu  in all tests")


# -- child processes import the hmatddm under test ------------------------------------------

def child_environment(**overrides):
    """``os.environ`` for a child ``python`` with the directory holding the ``hmatddm`` this
    process imported put first on ``PYTHONPATH`` (plus ``overrides``), so that the child
    runs the same copy and shares its numba cache. Without it a child started outside the
    repository (``.ci/run``: ``pip install .`` then pytest from the clone) imports the
    installed copy in ``site-packages``, tests that copy instead, and compiles its every
    kernel again into a second, empty cache (the 3D layered kill-and-resume child alone:
    ~100 s of CPU)."""
    package_parent = os.path.dirname(os.path.dirname(os.path.abspath(hd.__file__)))
    path = os.environ.get("PYTHONPATH")
    env = dict(os.environ, PYTHONPATH=package_parent + (os.pathsep + path if path else ""))
    env.update(overrides)
    return env


# -- a child process killed at a point it announces (event-driven, never sleep-driven) -----

def kill_when_announced(script):
    """Run ``python -c script``; wait for its first stdout line (the child prints it when
    it has reached the point to kill at, then waits), SIGKILL it and return that line
    ('' when the child died before announcing). No wall-clock limit: a busy machine only
    makes it slower (tests/simulation/test_simulation.py, tests/layered/test_layered_engine3d.py)."""
    import signal
    import subprocess

    process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                               env=child_environment())
    try:
        return process.stdout.readline()
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
        process.stdout.close()
