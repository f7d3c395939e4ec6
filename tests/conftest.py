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


# -- CPU time per test (load-independent, unlike --durations' wall time) -------------------
# `python -m pytest --cpu-durations=30` lists the 30 tests that used the most CPU time
# (this process and its threads, plus waited-for child processes), and the session's total:
# on a shared machine this is what a test would cost on a quiet one.

def pytest_addoption(parser):
    parser.addoption("--cpu-durations", type=int, default=None, metavar="N",
                     help="list the N tests with the most CPU time (setup + call + teardown)")


_CPU_SECONDS = {}


def _cpu_now():
    import resource

    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if item.config.getoption("--cpu-durations") is None:
        yield
        return
    start = _cpu_now()
    yield
    _CPU_SECONDS[item.nodeid] = _cpu_now() - start


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    count = config.getoption("--cpu-durations")
    if count is None or not _CPU_SECONDS:
        return
    terminalreporter.section(f"most CPU time ({count} of {len(_CPU_SECONDS)} tests)")
    for nodeid, seconds in sorted(_CPU_SECONDS.items(), key=lambda kv: -kv[1])[:count]:
        terminalreporter.write_line(f"{seconds:8.2f}s cpu  {nodeid}")
    terminalreporter.write_line(f"{sum(_CPU_SECONDS.values()):8.2f}s cpu  in all tests")


# -- a child process killed at a point it announces (event-driven, never sleep-driven) -----

def kill_when_announced(script):
    """Run ``python -c script``; wait for its first stdout line (the child prints it when
    it has reached the point to kill at, then waits), SIGKILL it and return that line
    ('' when the child died before announcing). No wall-clock limit: a busy machine only
    makes it slower (tests/test_simulation.py, tests/test_layered_engine3d.py)."""
    import signal
    import subprocess

    process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        return process.stdout.readline()
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
        process.stdout.close()
