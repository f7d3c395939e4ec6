"""A provisional iterate whose GMRES solve is paused (issue 17).

A growing simulation decides each growth pass on the first iterate of a coupled solve
(:class:`hmatddm.coupled.step_problem.SchemeSettings` ``growth_check = "first"``), which GMRES
solves to ``first_linear_rtol`` (ref. Eq. 4.41 with the widths lagged). Most passes grow,
and their iterate is then only the next pass's guess. Here that GMRES solve pauses at
coarser relative residuals first (:func:`pause_levels`,
:class:`hmatddm.hmatrix.solvers.PausableGmres`): the pass decides on the paused iterate
when no tip is near its threshold (:func:`hmatddm.simulation.growth_pass.paused_margin`),
else the same solve continues in the same Krylov space, so that the iterate a pass decides
on last, and every later one, is the plain solve's, bit for bit.
"""
from ..errors import ConvergenceError


def pause_levels(settings):
    """The relative residuals at which a provisional first GMRES solve pauses:
    ``settings.provisional_linear_rtol`` and tenfold smaller ones while above
    ``first_linear_rtol`` (and ``linear_rtol``)."""
    final = max(settings.linear_rtol, settings.first_linear_rtol)
    levels, level = [], settings.provisional_linear_rtol
    while level > final * (1.0 + 1e-9):
        levels.append(level)
        level /= 10.0
    return levels


class PausedIterate:
    """A coupled iterate whose GMRES solve (``solver``, a
    :class:`~hmatddm.hmatrix.solvers.PausableGmres` of the scaled system whose ``split``
    gives ``(DD, p)``) may be paused: :meth:`advance` continues it to the next pause,
    :meth:`finish` to the end; each returns the iterate relaxed from ``(dd, p)`` with
    ``alpha`` (ref. Eq. 4.47) and adds the GMRES iterations to ``counters["linear"]``
    (also when the solve fails: ConvergenceError)."""

    def __init__(self, solver, split, dd, p, alpha, counters):
        self.solver, self.split, self.dd, self.p, self.alpha = solver, split, dd, p, alpha
        self.counters = counters
        self.iterations = 0

    @property
    def done(self):
        """Whether the GMRES solve has ended (converged)."""
        return self.solver.result is not None

    @property
    def level(self):
        """The relative residual reached: the last pause's, or the solve's rtol once done."""
        return self.solver.level

    def advance(self):
        return self._relaxed(self.solver.pause)

    def finish(self):
        return self._relaxed(self._finish)

    def _finish(self):
        x, info = self.solver.finish()
        return x, info["iterations"]

    def _relaxed(self, call):
        try:
            y, iterations = call()
        except ConvergenceError as error:
            self.counters["linear"] += (error.iterations or 0) - self.iterations
            self.iterations = error.iterations or 0
            raise
        self.counters["linear"] += iterations - self.iterations
        self.iterations = iterations
        dd_new, p_new = self.split(y)
        alpha = self.alpha
        return alpha * dd_new + (1.0 - alpha) * self.dd, alpha * p_new + (1.0 - alpha) * self.p
