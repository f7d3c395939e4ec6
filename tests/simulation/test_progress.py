"""hmatddm.simulation.progress: the lines a long computation prints (a run's own progress through
``hmatddm run``: tests/app/test_runner.py)."""
import io
import re

from hmatddm.simulation.progress import Progress, TaskProgress, _format_seconds


def test_seconds_read_as_seconds_minutes_or_hours():
    assert [_format_seconds(s) for s in (-3.0, 42.4, 59.6, 61.0, 3599.0, 3600.0, 7384.0)] == [
        "0s", "42s", "60s", "1m01s", "59m59s", "1h00m", "2h03m"]


def _record(step, time):
    return dict(step=step, time=time, n_elements=10 + step, nonlinear_iterations=3, linear_iterations=7,
                solve_seconds=0.25)


def test_a_log_gets_a_line_every_tenth_of_the_run_and_at_the_end():
    stream = io.StringIO()
    progress = Progress(end_time=25.0, time_step=1.0, stream=stream)  # 25 steps: a line every 3
    for step in range(1, 26):
        progress.update(_record(step, float(step)))
    lines = stream.getvalue().splitlines()
    assert [int(line.split()[1]) for line in lines] == [3, 6, 9, 12, 15, 18, 21, 24, 25]
    assert re.match(r"step   25  t 25/25 s \[#{20}\] 100%  elements 35  iterations 3 \(7 linear\)  "
                    r"0\.2 s/step  left ~0s$", lines[-1])


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_terminal_line_is_redrawn_in_place_and_closed_by_a_note():
    stream = _Terminal()
    progress = Progress(end_time=4.0, time_step=1.0, stream=stream)
    progress.update(_record(1, 1.0))
    progress.update(_record(2, 2.0))
    progress.note("checkpoint written")
    text = stream.getvalue()
    assert text.count("\r") == 2 and text.endswith("\ncheckpoint written\n")
    assert "[#####---------------]  25%" in text and "[##########----------]  50%" in text


def test_disabled_progress_prints_nothing():
    stream = io.StringIO()
    progress = Progress(end_time=4.0, time_step=1.0, stream=stream, enabled=False)
    progress.update(_record(4, 4.0))
    progress.note("x")
    tasks = TaskProgress(2, stream=stream, enabled=False)
    tasks.start("a")
    tasks.done("ok")
    tasks.finish()
    assert stream.getvalue() == ""


def test_tasks_print_one_line_each_and_a_closing_line_with_cpu_time():
    stream = io.StringIO()
    tasks = TaskProgress(2, stream=stream)
    for name in ("griffith", "sneddon"):
        tasks.start(name)
        tasks.done("error 1e-3")
    tasks.finish()
    lines = stream.getvalue().splitlines()
    assert re.fullmatch(r"\[1/2\] griffith \.\.\. error 1e-3 \(\d+\.\d s\)", lines[0])
    assert lines[1].startswith("[2/2] sneddon ... error 1e-3")
    assert re.fullmatch(r"2 task\(s\) in \d+\.\d s wall, \d+\.\d s CPU", lines[2])


def test_the_time_left_follows_the_recent_steps_not_the_first(monkeypatch):
    """Issue 38: the first step includes compiling and building the operator; the estimate
    of the time left uses the pace of the last steps, and says '?' until it has one."""
    import hmatddm.simulation.progress as progress_module

    clock = [0.0]
    monkeypatch.setattr(progress_module.time, "perf_counter", lambda: clock[0])
    stream = _Terminal()
    progress = Progress(end_time=100.0, time_step=1.0, stream=stream)
    clock[0] = 60.0  # the first step: a minute
    progress.update(_record(1, 1.0))
    assert stream.getvalue().rstrip().endswith("left ~?")
    for step in range(2, 11):  # then 2 s per step of 1 s: 90 s of simulated time left = 180 s
        clock[0] += 2.0
        progress.update(_record(step, float(step)))
    assert stream.getvalue().rstrip().endswith("left ~3m00s")
