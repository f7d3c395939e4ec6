"""The pump schedule of a slurry (issue 34, hmatddm.flow.pump_schedule): stages as a step
function, its exact integral over any interval, and bad tables refused naming the stage."""
import pytest

from hmatddm.errors import InputError
from hmatddm.flow import PumpSchedule


def test_stages_hold_until_the_next_and_integrate_exactly():
    schedule = PumpSchedule.from_rows([[0.0, 0.0], [5.0, 0.1], [12.0, 0.25]], packing_limit=0.6)
    assert schedule.concentration(-1.0) == 0.0 and schedule.concentration(4.999) == 0.0
    assert schedule.concentration(5.0) == 0.1 and schedule.concentration(100.0) == 0.25
    # by hand: 0 on [3, 5), 0.1 on [5, 12), 0.25 on [12, 20]
    assert schedule.integral(3.0, 20.0) == pytest.approx(0.1 * 7.0 + 0.25 * 8.0, rel=1e-15)
    # the sum over any steps is the integral over their union (a run's injected mass does not
    # depend on its steps)
    edges = [0.0, 0.7, 4.9, 5.3, 11.99, 12.5, 20.0]
    assert sum(schedule.integral(a, b) for a, b in zip(edges[:-1], edges[1:])) == pytest.approx(
        schedule.integral(0.0, 20.0), rel=1e-14)
    late = PumpSchedule((2.0,), (0.3,))
    assert late.integral(0.0, 3.0) == pytest.approx(0.3)  # nothing before the first stage
    assert late.rows() == [[2.0, 0.3]]


@pytest.mark.parametrize("rows, message", [
    ([[0.0, 0.6]], r"proppant\.schedule\[0\] concentration must be in \[0, 0\.6\)"),
    ([[0.0, 0.1], [3.0, 0.7]], r"proppant\.schedule\[1\] concentration must be in \[0, 0\.6\)"),
    ([[0.0, -0.1]], r"proppant\.schedule\[0\] concentration"),
    ([[-1.0, 0.1]], r"proppant\.schedule\[0\] time must be a finite number >= 0"),
    ([[5.0, 0.1], [5.0, 0.2]], r"proppant\.schedule\[1\] time must be after"),
    ([[0.0, 0.1, 2.0]], r"proppant\.schedule\[0\] must be a pair"),
    ([], r"proppant\.schedule must hold at least one"),
])
def test_bad_schedules_are_refused_naming_the_stage(rows, message):
    with pytest.raises(InputError, match=message):
        PumpSchedule.from_rows(rows, packing_limit=0.6)
