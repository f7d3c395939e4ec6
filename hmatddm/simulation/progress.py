"""Progress lines of long computations: a run's time steps (:class:`Progress`, used by
``hmatddm run`` and ``Simulation.run(progress=True)``) and a list of tasks (:class:`TaskProgress`,
used by ``hmatddm validate`` and ``hmatddm bench``).

On a terminal a line is redrawn in place; otherwise (a log file, CI) plain lines are
printed at intervals, so that a long run is never silent.
"""
import math
import sys
import time


def _format_seconds(seconds):
    seconds = max(0.0, float(seconds))
    if seconds < 60:
        return f"{seconds:.0f}s"
    minutes, seconds = divmod(int(round(seconds)), 60)
    if minutes < 60:
        return f"{minutes}m{seconds:02d}s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h{minutes:02d}m"


class Progress:
    """A one-line progress display on ``stream`` (stderr by default).

    On a terminal the line is redrawn in place after every step: step, simulated time
    against the end time with a bar, elements, nonlinear (and linear) iterations,
    seconds of the last step and an estimate of the time left: the simulated time still
    to go at the pace of the last :data:`RECENT` steps, the first step of a session left
    out (it includes compiling and building the operator; ``left ~?`` until a second
    step gives a pace). When the stream is not
    a terminal (a log file, CI), a plain line is printed every ``ceil(steps / 10)``
    steps and at the end. ``enabled=False`` prints nothing.
    """

    BAR = 20
    RECENT = 5

    def __init__(self, end_time, time_step, stream=None, enabled=True, start_time=0.0):
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled
        self.end_time, self.time_step = float(end_time), float(time_step)
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        steps = max(1, math.ceil(self.end_time / self.time_step - 1e-9))
        self.every = max(1, math.ceil(steps / 10))
        self.started = time.perf_counter()
        self.start_time = float(start_time)
        self._drawn = False
        self._width = 0
        self._seen = []  # (wall clock, simulated time) after each step of this session

    def _left(self, record):
        """Seconds left at the pace of the recent steps (None before a pace is known)."""
        self._seen.append((time.perf_counter(), float(record["time"])))
        self._seen = self._seen[-(self.RECENT + 1):]
        if len(self._seen) < 2:
            return None
        (clock0, time0), (clock1, time1) = self._seen[0], self._seen[-1]
        if time1 <= time0:
            return None
        return (clock1 - clock0) / (time1 - time0) * max(self.end_time - time1, 0.0)

    def _line(self, record):
        fraction = min(1.0, max(0.0, record["time"] / self.end_time))
        filled = int(round(fraction * self.BAR))
        bar = "#" * filled + "-" * (self.BAR - filled)
        left = self._left(record)
        return (f"step {record['step']:>4}  t {record['time']:g}/{self.end_time:g} s [{bar}] {100 * fraction:3.0f}%"
                f"  elements {record['n_elements']}  iterations {record['nonlinear_iterations']}"
                f" ({record['linear_iterations']} linear)  {record['solve_seconds']:.1f} s/step"
                f"  left ~{'?' if left is None else _format_seconds(left)}")

    def update(self, record):
        if not self.enabled:
            return
        line = self._line(record)
        if self.tty:
            self.stream.write("\r" + line.ljust(self._width))
            self._width = len(line)
            self._drawn = True
        elif record["step"] % self.every == 0 or record["time"] >= self.end_time - 1e-9 * self.time_step:
            self.stream.write(line + "\n")
        self.stream.flush()

    def note(self, text):
        """Print a message on its own line (below the progress line)."""
        if not self.enabled:
            return
        self.close()
        self.stream.write(text + "\n")
        self.stream.flush()

    def close(self):
        if self.enabled and self.tty and self._drawn:
            self.stream.write("\n")
            self.stream.flush()
        self._drawn = False
        self._width = 0


class TaskProgress:
    """Progress through a known list of tasks (the checks of ``hmatddm validate``, the
    sizes of ``hmatddm bench``) on ``stream``: ``start(name)`` before a task and
    ``done(text)`` after it print ``[k/n] name ... text (seconds)``, one line per task
    whether or not the stream is a terminal. ``enabled=False`` prints nothing."""

    def __init__(self, total, stream=None, enabled=True):
        self.stream = sys.stderr if stream is None else stream
        self.total, self.enabled = int(total), enabled
        self.count = 0
        self._name, self._started = None, None
        self.began = time.perf_counter()
        self.cpu_began = time.process_time()

    def start(self, name):
        self.count += 1
        self._name, self._started = name, time.perf_counter()
        if self.enabled:
            self.stream.write(f"[{self.count}/{self.total}] {name} ...")
            self.stream.flush()

    def done(self, text=""):
        if self.enabled:
            seconds = time.perf_counter() - self._started
            self.stream.write(f" {text}{' ' if text else ''}({seconds:.1f} s)\n")
            self.stream.flush()

    def finish(self):
        """The closing line: wall and CPU time of all tasks."""
        if self.enabled:
            self.stream.write(f"{self.count} task(s) in {time.perf_counter() - self.began:.1f} s wall, "
                              f"{time.process_time() - self.cpu_began:.1f} s CPU\n")
            self.stream.flush()
