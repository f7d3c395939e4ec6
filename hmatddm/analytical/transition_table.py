"""Dontsov's (2016) radial K-M transition solution tabulated in time, for runs that
need it at every step.

:func:`hmatddm.analytical.radial_transition` solves, at each time, for the radius that
holds the injected volume (secant iterations on the universal tip asymptote, with the
growth exponent ``alpha = d ln R / d ln t`` by a fixed point). One call costs about
0.18 s of CPU whether it is asked for one time or a hundred (the iterations are
vectorised over the times), so a run that compares with it after every step
(``summary.json``'s ``reference``, the profile picture of every saved step) paid that
for every step: about 25 s of a 46 s default run (Intel Xeon, dgemm 70 GFLOP/s).

:class:`RadialTransitionTable` solves once on a grid of times uniform in ``log10 t``
(:data:`NODES_PER_DECADE` nodes a decade, extended a decade or more at a time when asked
beyond it) and interpolates ``ln R``, ``ln w_a``, ``delta`` and ``lambda`` of the
solution (:func:`hmatddm.analytical.radial_transition_profile`) by cubic splines in
``ln t``. The solution is smooth in ``ln t`` (it depends on ``t`` through the
dimensionless toughness ``K_m ~ t^(1/18)``), so the interpolation agrees with the
direct solution to better than 1e-7 relative (``tests/analytical/test_transition_table.py``),
five orders below the approximation's own ~1% (Dontsov 2016).
:func:`radial_transition_table` keeps one table per set of parameters.
"""
import math
from collections import OrderedDict

import numpy as np
from scipy.interpolate import CubicSpline

from .._validation import finite_array, positive_scalar
from ..errors import InputError

NODES_PER_DECADE = 16
_MARGIN = 2  # nodes kept beyond the asked range on each side (the splines' ends)
_TABLES = OrderedDict()
_MAX_TABLES = 16


class RadialTransitionTable:
    """The radial K-M transition solution (Dontsov 2016) of one fracture's parameters,
    tabulated in time (see the module). Same parameters as
    :func:`hmatddm.analytical.radial_transition`; ``nodes_per_decade`` the grid's density."""

    def __init__(self, injection_rate, viscosity, fracture_toughness, material, nodes_per_decade=NODES_PER_DECADE):
        self.injection_rate = positive_scalar("injection_rate", injection_rate)
        self.viscosity = positive_scalar("viscosity", viscosity)
        self.fracture_toughness = positive_scalar("fracture_toughness", fracture_toughness)
        self.material = material
        if int(nodes_per_decade) != nodes_per_decade or nodes_per_decade < 4:
            raise InputError(f"nodes_per_decade must be an integer >= 4, got {nodes_per_decade!r}")
        self.nodes_per_decade = int(nodes_per_decade)
        self._first = self._last = None  # node indices k of the grid t_k = 10^(k / nodes_per_decade)
        self._values = np.empty((0, 4))  # ln R, ln w_a, delta, lambda at the nodes
        self._splines = None
        self.solves = 0  # calls of the direct solution (each one vectorised over new nodes)

    def _node_times(self, first, last):
        return 10.0 ** (np.arange(first, last + 1) / self.nodes_per_decade)

    def _solve(self, first, last):
        from .solutions import _radial_transition

        self.solves += 1
        radius, w_a, delta, lam = _radial_transition(self._node_times(first, last), self.injection_rate,
                                                     self.viscosity, self.fracture_toughness, self.material)
        return np.column_stack([np.log(radius), np.log(w_a), delta, lam])

    def _cover(self, times):
        """Extend the grid over ``times`` (grown a decade or more at a time, so that a run
        asking one step later each time solves about once a decade)."""
        low = math.floor(math.log10(float(np.min(times))) * self.nodes_per_decade) - _MARGIN
        high = math.ceil(math.log10(float(np.max(times))) * self.nodes_per_decade) + _MARGIN
        if self._first is not None and low >= self._first and high <= self._last:
            return
        if self._first is None:
            self._first, self._last = low, max(high, low + self.nodes_per_decade)
            self._values = self._solve(self._first, self._last)
        else:
            if low < self._first:
                start = min(low, self._first - self.nodes_per_decade)
                self._values = np.vstack([self._solve(start, self._first - 1), self._values])
                self._first = start
            if high > self._last:
                end = max(high, self._last + self.nodes_per_decade)
                self._values = np.vstack([self._values, self._solve(self._last + 1, end)])
                self._last = end
        log_times = np.log(self._node_times(self._first, self._last))
        self._splines = CubicSpline(log_times, self._values, axis=0)

    def state(self, t):
        """``(radius, w_a, delta, lambda)`` at times ``t`` (s, > 0; arrays like ``t``):
        the quantities of :func:`hmatddm.analytical.radial_transition_profile`."""
        t = finite_array("t", t)
        if t.size == 0:
            raise InputError("t must hold at least one time")
        if np.any(t <= 0.0):
            raise InputError(f"t must be > 0 s, got {t[t <= 0.0].ravel()[0]}")
        self._cover(t)
        values = self._splines(np.log(t))
        return np.exp(values[..., 0]), np.exp(values[..., 1]), values[..., 2], values[..., 3]

    def radius_and_width(self, t):
        """Radius and opening at the well (m), arrays like ``t``: as
        :func:`hmatddm.analytical.radial_transition`."""
        radius, w_a, _, lam = self.state(t)
        return radius, w_a * 0.5 ** lam

    def profile(self, rho, t):
        """``(radius, width)`` at one time ``t``, ``width`` at ``rho = r / R`` in [0, 1]:
        as :func:`hmatddm.analytical.radial_transition_profile`."""
        rho = finite_array("rho", rho)
        if np.any((rho < 0.0) | (rho > 1.0)):
            raise InputError(f"rho must be in [0, 1] (r / R), got {rho[(rho < 0.0) | (rho > 1.0)].ravel()[0]}")
        if np.size(t) != 1:
            raise InputError("t must be a scalar > 0 for RadialTransitionTable.profile")
        radius, w_a, delta, lam = (float(np.ravel(v)[0]) for v in self.state(np.ravel(t)))
        return radius, w_a * (1.0 - rho) ** delta * (0.5 * (1.0 + rho)) ** lam


def radial_transition_table(injection_rate, viscosity, fracture_toughness, material):
    """The :class:`RadialTransitionTable` of these parameters, kept between calls (the
    last :data:`_MAX_TABLES` sets of parameters)."""
    key = (float(injection_rate), float(viscosity), float(fracture_toughness), float(material.shear_modulus),
           float(material.poisson_ratio))
    table = _TABLES.pop(key, None)
    if table is None:
        table = RadialTransitionTable(injection_rate, viscosity, fracture_toughness, material)
    _TABLES[key] = table
    while len(_TABLES) > _MAX_TABLES:
        _TABLES.popitem(last=False)
    return table


__all__ = ["RadialTransitionTable", "radial_transition_table", "NODES_PER_DECADE"]
