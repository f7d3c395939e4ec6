"""Thread control: one threadpoolctl controller for the process, and the serial path
for small operations and busy machines.

Building a controller (or calling ``threadpool_limits``) scans the loaded native
libraries, about 0.7 ms each time: a third of a small 2D run when it happened on every
GMRES call (measured on ref. Table 4.2). The controller is built once and reused.

Small parallel regions lose: numba's OpenMP threads synchronise at the end of every
``prange``, which costs more than the work below a few hundred thousand stored
entries, and when another process holds the second core the barrier waits for a
descheduled thread (an H matvec at N = 1024 took 14 ms on 2 threads under load
against 1 ms on one; 2-20x slower at every N up to 4096 with 1.8 cores of background
load, benchmarks/RESULTS.md). :func:`threads_for` runs an operation on one thread below
a measured size, and on no more threads than the cores other processes leave free.
"""
import os
import time
from contextlib import contextmanager

import numba
from threadpoolctl import ThreadpoolController

_CONTROLLER = []
_BLAS = []

# Measured by benchmarks/bench_threads.py (benchmarks/RESULTS.md, "Threads that never
# lose"): an H matvec with fewer stored entries x right-hand sides than this runs on one
# thread (quiet machine: two threads pay from N ~ 1000 planar elements, 3e6 entries).
SERIAL_MATVEC_ENTRIES = 1_000_000
# Background load (cores busy with other processes) is sampled at most this often.
LOAD_WINDOW_SECONDS = 0.5
# Whether threads_to_use leaves the cores busy with other processes alone.
ADAPT_TO_LOAD = True
_LOAD = {"time": None, "busy": None, "cpu": None, "others": 0.0}


def _blas_libraries():
    """threadpoolctl's controllers of the loaded BLAS libraries (found once)."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
        _BLAS.extend(_CONTROLLER[0].select(user_api="blas").lib_controllers)
    return _BLAS


class _OneBlasThread:
    """BLAS/LAPACK on one thread inside the ``with`` block, their thread counts restored
    after. Only the libraries' own get/set calls: threadpoolctl's ``limit`` reads every
    library's state again at each use, 12 us against 1.2 us (BLAS already on one thread) or
    4.1 us (two threads set and restored), measured on an Intel Xeon; dfn-3cluster at 4x its
    area uses it 18,490 times (0.2 s). Nested blocks find one thread and change nothing."""

    __slots__ = ("saved",)

    def __enter__(self):
        self.saved = []
        for library in _blas_libraries():
            threads = library.get_num_threads()
            if threads is not None and threads != 1:
                library.set_num_threads(1)
                self.saved.append((library, threads))
        return self

    def __exit__(self, *exception):
        for library, threads in self.saved:
            library.set_num_threads(threads)
        return False


def single_threaded_blas():
    """Context manager limiting BLAS/LAPACK to one thread."""
    return _OneBlasThread()


def machine_busy_seconds():
    """Busy CPU seconds of the whole machine (Linux /proc/stat), None elsewhere."""
    try:
        with open("/proc/stat") as f:
            fields = [int(v) for v in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    return (sum(fields) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")


def background_cores():
    """Cores kept busy by OTHER processes since the previous sample (machine busy time
    minus this process's CPU time, over the wall time); 0 where unknown. Sampled at most
    every LOAD_WINDOW_SECONDS (reading /proc/stat costs ~30 us)."""
    now = time.monotonic()
    state = _LOAD
    if state["time"] is not None and now - state["time"] < LOAD_WINDOW_SECONDS:
        return state["others"]
    busy, cpu = machine_busy_seconds(), time.process_time()
    if busy is not None and state["busy"] is not None and now > state["time"]:
        state["others"] = max(0.0, (busy - state["busy"] - (cpu - state["cpu"])) / (now - state["time"]))
    state.update(time=now, busy=busy, cpu=cpu)
    return state["others"]


def threads_to_use(size, serial_below):
    """Threads for a numba parallel region of ``size``: one below ``serial_below``,
    else numba's count reduced to the cores other processes leave free (at least 1)."""
    threads = numba.get_num_threads()
    if threads <= 1 or size < serial_below:
        return 1
    if not ADAPT_TO_LOAD:
        return threads
    free = int((os.cpu_count() or 1) - background_cores() + 0.5)
    return max(1, min(threads, free))


@contextmanager
def threads_for(size, serial_below):
    """Run the enclosed numba code on :func:`threads_to_use` threads
    (``numba.set_num_threads`` is per calling thread and costs ~1 us); yields the
    thread count in force. The same compiled code runs, so results are bit-identical
    whatever the count (where they were before)."""
    threads = numba.get_num_threads()
    chosen = threads_to_use(size, serial_below)
    if chosen == threads:
        yield threads
        return
    numba.set_num_threads(chosen)
    try:
        yield chosen
    finally:
        numba.set_num_threads(threads)
