"""Anderson acceleration of the coupled schemes' nonlinear (Picard) iteration
(:mod:`hmatddm.coupled.schemes`), beyond the reference (its Sec. 4.5 relaxes, ref. Eq. 4.47).

The iteration of one attempt is the fixed point ``x = G(x)`` of the relaxed map
``G(x) = x + alpha (F(x) - x)``, ``x = (DD, p)`` and ``F`` one coupled linear solve with the
widths (and the contact rows) lagged at ``x``. Anderson acceleration (type II; Walker and
Ni 2011, SIAM J. Numer. Anal. 49:1715) takes the combination of the last ``memory`` iterates
whose residuals ``f = G(x) - x`` cancel best::

    gamma = argmin || f_k - dF gamma ||,    x_(k+1) = x_k + f_k - (dX + dF) gamma

with ``dX``, ``dF`` the differences of consecutive iterates and residuals, in units of the
tolerances of ref. Eqs 4.43-4.44 (DDs over ``tolerance_opening max|DD|``, pressures over
``tolerance_pressure max|p|``, the scales fixed when the history starts).

Why (issue 33, benchmarks/RESULTS.md): on the dfn-3cluster network at 4x its area the
iteration at ``alpha = 1`` falls into a period-2 cycle of constant amplitude (a Picard
eigenvalue at -1), the relaxation ladder halves alpha, and at ``alpha = 1/2`` every other
mode contracts by exactly 1/2 per iteration: ~18 of a solve's ~30 iterations, once the
contact active set has settled, were that contraction; other solves crept at a rate of
0.8-0.93 on one slow mode (an element that fills through a throttled face). Both are what
a least-squares combination of a few iterates removes.

The combination is used only while the active set stands still: the map ``G`` changes with
the contact rows, so the history restarts at every status change (and the plain relaxed
step is taken), and at every iterate whose residual does not fall (the safeguard of
:class:`AndersonMixing`, the history shared with the asymptotic front's iteration). The
convergence test of :mod:`hmatddm.coupled.schemes` is unchanged: an iterate is accepted on
its own relaxed change ``G(x_k) - x_k`` (below the tolerances, no status change), and the
accepted state is ``G(x_k)``, as without acceleration. "ref." is S. Hirose's 2019
dissertation (README); conventions: docs/conventions.md.
"""
import numpy as np

#: Iterates kept (the columns of dX and dF).
MEMORY = 5
#: Combinations start after this many iterates in a row without a status change
STILL = 1
#: ... where the changes fell slower than this per iterate (a fast contraction, e.g. the
#: radial K-vertex scene's ~1e-3 per iterate, keeps its plain iterates and the
#: "contraction" stopping rule, which an accelerated iterate gives up)
RATE = 0.3
#: An iterate after an accelerated one is accepted when its change is below this share of
#: the tolerances: the change of ``G(x)`` bounds its error only through the contraction
#: ``rho`` of the plain map (``rho / (1 - rho)`` times the change), unknown here; 0.1 keeps
#: the error within the tolerance up to rho = 0.9 (the slow fill mode of the dfn-3cluster
#: network at 4x its area: 0.8-0.93)
ACCEPT = 0.1
#: Singular values of dF below this share of the largest are dropped from the fit (nearly
#: parallel residual differences would amplify round-off into the combination).
RCOND = 1e-6


class AndersonMixing:
    """The history of a fixed-point iteration ``x = g(x)`` and its Anderson (type II)
    correction: the last ``memory + 1`` iterates and residuals ``f = g(x) - x``, restarted
    when a residual does not fall. Shared by the coupled iterates (:class:`IterateMixing`)
    and the asymptotic front's ribbon distances (:mod:`hmatddm.simulation.front_acceleration`)."""

    def __init__(self, memory=MEMORY, rcond=RCOND):
        self.memory, self.rcond = int(memory), float(rcond)
        self._points, self._residuals = [], []
        self.restarts = 0  # histories dropped by the safeguard

    def clear(self):
        """Forget the history (not counted as a restart)."""
        self._points, self._residuals = [], []

    def correction(self, point, residual, combine=True):
        """``(dX + dF) gamma``, the accelerated iterate being ``point + residual - correction``,
        or None when the caller takes its plain step: the first iterate of a history, one
        whose residual did not fall (the history then restarts from it) and, with ``combine``
        False, any (it only joins the history)."""
        point, residual = np.asarray(point, float), np.asarray(residual, float)
        if self._residuals and np.linalg.norm(residual) >= np.linalg.norm(self._residuals[-1]):
            self._points, self._residuals = [], []
            self.restarts += 1
        self._points.append(point.copy())
        self._residuals.append(residual.copy())
        if len(self._points) > self.memory + 1:
            self._points.pop(0)
            self._residuals.pop(0)
        if len(self._points) < 2 or not combine:
            return None
        points, residuals = np.array(self._points), np.array(self._residuals)
        d_points, d_residuals = np.diff(points, axis=0).T, np.diff(residuals, axis=0).T
        gamma = np.linalg.lstsq(d_residuals, residual, rcond=self.rcond)[0]
        return (d_points + d_residuals) @ gamma

    def step(self, point, residual):
        """The step to add to ``point`` (``residual - correction``), or None (see
        :meth:`correction`; also when it is not finite)."""
        correction = self.correction(point, residual)
        if correction is None:
            return None
        step = residual - correction
        return step if np.all(np.isfinite(step)) else None


class IterateMixing:
    """The accelerated iterates of one attempt of a coupled solve (:meth:`reset` at its start)."""

    def __init__(self, tolerance_opening, tolerance_pressure, memory=MEMORY):
        self.tolerance_opening, self.tolerance_pressure = float(tolerance_opening), float(tolerance_pressure)
        self.memory = int(memory)
        self.steps = 0     # accelerated iterates made (combinations returned)
        self._history = AndersonMixing(memory, RCOND)
        self.reset()

    @property
    def restarts(self):
        """Histories dropped by the safeguard (:class:`AndersonMixing`)."""
        return self._history.restarts

    def reset(self):
        """Forget the history (a new attempt, or a change of the active set)."""
        self._history.clear()
        self._scale = None
        self._still = 0  # iterates since the active set last changed

    def iterate(self, dd, p, dd_new, p_new, changed, history):
        """The iterate to continue from after ``x_k = (dd, p)`` whose relaxed map gave
        ``G(x_k) = (dd_new, p_new)`` and changed ``changed`` contact statuses, the attempt's
        changes (in tolerances) being ``history``: a combination (:meth:`next`) while the
        active set stood still for :data:`STILL` iterates and the changes fall slower than
        :data:`RATE`, else None (take ``G(x_k)``; a status change restarts the history)."""
        self._still = 0 if changed else self._still + 1
        if self._still < STILL:
            self._history.clear()
            self._scale = None
            return None
        slow = len(history) >= 2 and history[-2] > 0.0 and history[-1] > RATE * history[-2]
        return self.next(dd, p, dd_new, p_new, combine=slow)

    def _scaled(self, dd, p):
        scale_u, scale_p = self._scale
        return np.concatenate([dd / scale_u, p / scale_p])

    def next(self, dd, p, dd_new, p_new, combine=True):
        """The next iterate ``(dd, p)`` after ``x_k = (dd, p)`` whose relaxed map gave
        ``G(x_k) = (dd_new, p_new)``, or None: take ``G(x_k)`` (the first iterate of a
        history, any whose residual did not fall, which restarts it, and any with
        ``combine`` False, which only joins the history)."""
        if self._scale is None:
            self._scale = (self.tolerance_opening * max(float(np.max(np.abs(dd_new))), 1e-30),
                           self.tolerance_pressure * max(float(np.max(np.abs(p_new))), 1e-30))
        point = self._scaled(dd, p)
        residual = self._scaled(dd_new, p_new) - point
        correction = self._history.correction(point, residual, combine)
        if correction is None:
            return None
        mixed = point + residual - correction
        if not np.all(np.isfinite(mixed)):
            return None
        self.steps += 1
        nd = dd.size
        scale_u, scale_p = self._scale
        return mixed[:nd] * scale_u, mixed[nd:] * scale_p
