"""Anderson acceleration of the asymptotic front's fixed point (:mod:`hmatddm.simulation.asymptotic`).

Within a time step the ribbon distances ``s`` solve ``s = g(s)``: a coupled solve with the
front at ``s``, then the universal asymptote inverted at the ribbon's openings. The plain
iteration ``s <- s + w (g(s) - s)`` converges linearly, and slowly where the front's
elements interact: 10-25 iterations a step on a 0.5 m radial K-vertex run, each a coupled
solve. Anderson acceleration (type II; Walker and Ni 2011, SIAM J. Numer. Anal. 49:1715)
takes the combination of the last ``memory`` iterates whose residuals ``f = g(s) - s``
cancel best,

    gamma = argmin || f_k - dF gamma ||,   s_(k+1) = s_k + f_k - (dS + dF) gamma,

with ``dS``, ``dF`` the differences of consecutive iterates and residuals. Safeguard: when
a residual is not smaller than the last one (a new element joined, a clip bit, or the
combination overshot), the history restarts and the caller takes its own relaxed step.
"""
import numpy as np

#: Iterates kept (the columns of dS and dF).
MEMORY = 4
#: Singular values of dF below this share of the largest are dropped from the least-squares
#: fit: nearly parallel residual differences would otherwise amplify round-off (and an
#: H-matrix's eps) into the combination.
RCOND = 1e-3


class AndersonMixing:
    """The accelerated steps of one time step's front iteration (a new one each step)."""

    def __init__(self, memory=MEMORY):
        self.memory = int(memory)
        self._points, self._residuals = [], []
        self.restarts = 0

    def step(self, point, residual):
        """The step to add to ``point`` given its residual ``g(point) - point``, or None
        when the caller should take its plain (relaxed) step: the first iterate, and any
        whose residual did not fall (the history then restarts from it)."""
        point, residual = np.asarray(point, float), np.asarray(residual, float)
        if self._residuals and np.linalg.norm(residual) >= np.linalg.norm(self._residuals[-1]):
            self._points, self._residuals = [], []
            self.restarts += 1
        self._points.append(point.copy())
        self._residuals.append(residual.copy())
        if len(self._points) > self.memory + 1:
            self._points.pop(0)
            self._residuals.pop(0)
        if len(self._points) < 2:
            return None
        points, residuals = np.array(self._points), np.array(self._residuals)
        d_points, d_residuals = np.diff(points, axis=0).T, np.diff(residuals, axis=0).T
        gamma = np.linalg.lstsq(d_residuals, residual, rcond=RCOND)[0]
        step = residual - (d_points + d_residuals) @ gamma
        return step if np.all(np.isfinite(step)) else None


__all__ = ["AndersonMixing", "MEMORY", "RCOND"]
