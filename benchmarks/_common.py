"""Shared helpers of the benchmark scripts: machine description and markdown tables."""
import functools
import os
import platform
import time


def machine():
    """A one-line description: CPU model, cores, RAM and the :func:`calibration`."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    ram = "?"
    try:
        with open("/proc/meminfo") as f:
            kb = int(f.readline().split()[1])
        ram = f"{kb / 2**20:.0f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    return f"{model}, {os.cpu_count()} cores, {ram} RAM; calibration: {calibration()}"


@functools.lru_cache(maxsize=None)
def calibration():
    """Speed of this machine now, to set every table's times against (machines of one
    kind differ 5-10x, and a shared machine varies by the minute): 1-thread dgemm
    GFLOP/s (n = 1000, best of 3) and numpy log / atan throughput (Melem/s, 1e6
    elements, best of 3). About 1 s; measured once per process."""
    import numpy as np
    from threadpoolctl import threadpool_limits

    rng = np.random.default_rng(0)
    a, b = rng.random((1000, 1000)), rng.random((1000, 1000))
    x = rng.random(1_000_000) + 0.5

    def best(function, repeats=3):
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            function()
            times.append(time.perf_counter() - start)
        return min(times)

    with threadpool_limits(limits=1, user_api="blas"):
        a @ b  # warm up
        gflops = 2e-9 * 1000**3 / best(lambda: a @ b)
    log_rate = 1e-6 * x.size / best(lambda: np.log(x))
    atan_rate = 1e-6 * x.size / best(lambda: np.arctan(x))
    return f"dgemm {gflops:.1f} GFLOP/s (1 thread), log {log_rate:.0f} Melem/s, atan {atan_rate:.0f} Melem/s"


def markdown_table(header, rows):
    """Rows of already formatted cells -> a markdown table string."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def print_table(header, rows):
    """Print a blank line, the markdown table and the machine's calibration now (the
    closing lines of a benchmark: its calibration at the start and at the end)."""
    print()
    print(markdown_table(header, rows))
    print(f"Calibration at the end: {machine()}")


def peak_rss_bytes():
    """Peak resident memory of this process so far."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
