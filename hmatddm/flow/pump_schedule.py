"""The pump schedule of a slurry: the proppant volume fraction of the pumped fluid against time
(issue 34, beyond the reference, which names proppant as its next step: ref. Sec. 8.2 item 2).

A schedule is a table of stages ``(t_k, c_k)``: from ``t_k`` until the next stage's time the
clusters pump slurry of proppant volume fraction ``c_k`` (a step function, the way a treatment
schedule is written: a pad of clean fluid, then sand stages of rising concentration). Before
the first stage the concentration is 0. The proppant volume a cluster of slurry rate ``q`` pumps
over ``[t_0, t_1]`` is ``q`` times the exact integral :meth:`PumpSchedule.integral`, so the
injected mass of a run does not depend on its time steps.
"""
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..settings import show


def check_time_rows(name, times, values, value_ok, value_rule, rows="rows"):
    """Refuse a table of ``(time, value)`` rows (a pump schedule) naming the row: times
    finite, >= 0 and strictly increasing; each finite value ``value_ok`` (else the message
    says ``value_rule``)."""
    for k, (t, v) in enumerate(zip(times, values)):
        if not np.isfinite(t) or t < 0.0:
            raise InputError(f"{name}[{k}] time must be a finite number >= 0 s, got {show(float(t))}")
        if not np.isfinite(v) or not value_ok(v):
            raise InputError(f"{name}[{k}] {value_rule}, got {show(float(v))}")
        if k > 0 and not t > times[k - 1]:
            raise InputError(f"{name}[{k}] time must be after {name}[{k - 1}]'s {show(float(times[k - 1]))} s "
                             f"({rows} in increasing time), got {show(float(t))}")


@dataclass(frozen=True)
class PumpSchedule:
    """Stages ``(time, concentration)`` of the pumped slurry.

    Parameters
    ----------
    times : sequence of float
        Stage start times t_k, s, >= 0, strictly increasing.
    concentrations : sequence of float
        Proppant volume fraction c_k of each stage, in [0, packing_limit).
    packing_limit : float
        c_max of the proppant (:class:`hmatddm.flow.proppant.Proppant`): a pumped
        concentration at or above it would be a packed bed, not a slurry.
    name : str
        How errors name the table (the scene's ``proppant.schedule``).
    """

    times: tuple
    concentrations: tuple
    packing_limit: float = 0.6
    name: str = "proppant.schedule"

    def __post_init__(self):
        times = np.asarray(self.times, dtype=float).ravel()
        values = np.asarray(self.concentrations, dtype=float).ravel()
        name = self.name
        if times.size == 0 or times.size != values.size:
            raise InputError(f"{name} must hold at least one [time, concentration] stage, got {times.size} times "
                             f"and {values.size} concentrations")
        limit = self.packing_limit
        check_time_rows(name, times, values, lambda c: 0.0 <= c < limit,
                        f"concentration must be in [0, {limit:g}) (a volume fraction below proppant.packing_limit)",
                        "stages")
        object.__setattr__(self, "times", tuple(float(t) for t in times))
        object.__setattr__(self, "concentrations", tuple(float(c) for c in values))

    @classmethod
    def from_rows(cls, rows, packing_limit, name="proppant.schedule"):
        """The schedule of ``[[time, concentration], ...]`` (a scene's table)."""
        rows = [list(row) for row in rows]
        for k, row in enumerate(rows):
            if len(row) != 2:
                raise InputError(f"{name}[{k}] must be a pair [time (s), concentration], got {row!r}")
        return cls(tuple(r[0] for r in rows), tuple(r[1] for r in rows), packing_limit, name)

    def concentration(self, time):
        """c(t): the concentration of the stage that holds ``time`` (0 before the first)."""
        k = np.searchsorted(self.times, time, side="right") - 1
        return 0.0 if k < 0 else self.concentrations[k]

    def integral(self, time_old, time_new):
        """``int c(t) dt`` over ``[time_old, time_new]`` (s), exact for the step function."""
        edges = np.array(self.times + (np.inf,))
        values = np.array(self.concentrations)
        low = np.clip(edges[:-1], time_old, time_new)
        high = np.clip(edges[1:], time_old, time_new)
        return float(np.sum(values * (high - low)))

    def rows(self):
        """``[[time, concentration], ...]`` (a scene's table)."""
        return [[t, c] for t, c in zip(self.times, self.concentrations)]
