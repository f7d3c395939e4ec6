"""A wellbore shared by perforation clusters (issue 35, beyond the reference, whose clusters
each take a fixed rate and lose no pressure at the perforations, ref. Eqs 4.34-4.35).

One pump feeds the well at the heel with the rate of a schedule (:class:`PumpRate`); the
clusters along the well share it. Cluster ``c`` (its perforations: count ``n``, diameter
``d``, discharge coefficient ``C_d``) takes the rate ``q_c`` that the pressure drop across
its perforations drives (the orifice law of a perforation, Crump and Conway 1988;
Lecampion and Desroches 2015, their Eq. 7)::

    Delta_c = p_h - w_c - p_c = a_c q_c |q_c|,     a_c = 8 rho / (pi^2 C_d^2 n^2 d^4)

with ``p_h`` the wellbore pressure at the heel, ``p_c`` the fluid pressure of the fracture
element the cluster feeds, and ``w_c`` the wellbore friction from the heel to the cluster:
the Darcy-Weisbach loss of each pipe segment between the heel and the cluster (length
``L``, inner diameter ``D``, Darcy friction factor ``f_D``, the rate ``Q`` of the clusters
beyond the segment's start)::

    dp = f_D (L / D) rho v |v| / 2,  v = Q / (pi D^2 / 4)   =>   dp = 8 f_D rho L Q |Q| / (pi^2 D^5)

The well stores fluid through the compressibility (its volume ``V``, ``S = c_f V / dt`` per
step), at the heel pressure, and the pumped volume over a step is the schedule's exact
integral (``Qbar dt``, :meth:`PumpRate.volume`)::

    sum_c q_c + S (p_h - p_h^n) = Qbar

Inside the coupled step (:meth:`hmatddm.flow.LubricationModel.assemble`) the well is solved
with the fracture pressures, not lagged: at every nonlinear iterate ``p^k``
:meth:`WellSystem.solve` solves the well exactly for the cluster pressures ``p_c^k`` (one
monotone scalar equation in ``p_h``; with wellbore friction the rates at each ``p_h`` are
the minimum of a strictly convex function, :meth:`WellSystem.rates_at`), then
:class:`WellLinearisation` linearises each orifice there (the tangent
``q_c ~ k_c Delta_c + r_c`` through the exact point) and eliminates ``p_h``, so that the
rate into each cluster element is a linear function of the cluster pressures. Its matrix
(:meth:`WellLinearisation.matrix_terms`) is symmetric: ``+k_c`` on the diagonal of the
element of ``c`` and ``-k_c k_j / (K + S)`` between the elements of ``c`` and ``j``
(``K = sum k``). At the fixed point ``p = p^k`` the rates and the heel pressure are the
exact ones of the well, whatever the tangent's slope: ``k_c = 1 / (2 a_c max(|q_c|, q_0))``,
floored at a small rate ``q_0`` so that a stopped cluster keeps a finite slope. (The wellbore
friction enters each linearisation as the constant of its iterate: it converges with the
step's iteration.) The rates and heel pressure a step records are the last linearisation's at
the converged pressures (:class:`WellLink`), so the fluid budget (pumped volume = fractures +
leak-off + the well's storage) closes to the flow solve's tolerance.

A single cluster without perforation friction (no perforation data) is the reference's
injection point (ref. Eqs 4.34-4.35): the pump rate goes straight into its element, which
stores the well's fluid (:attr:`WellSystem.direct`).
"""
import math
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import ConvergenceError, InputError
from ..settings import FLUID, WELL, show
from .pump_schedule import check_time_rows

#: how far a cluster may lie from the well's line, m
ON_WELL_TOLERANCE = 1e-3


def perforation_coefficient(density, count, diameter, discharge_coefficient):
    """``a = 8 rho / (pi^2 C_d^2 n^2 d^4)`` (Pa s^2 / m^6) of the orifice law
    ``dp = a q |q|`` (SI; Crump and Conway 1988, Lecampion and Desroches 2015)."""
    return 8.0 * density / (math.pi**2 * discharge_coefficient**2 * count**2 * diameter**4)


def pipe_friction_coefficient(density, diameter, friction_factor):
    """``b`` (Pa s^2 / m^7) of the Darcy-Weisbach loss ``dp = b L Q |Q|`` of a pipe of inner
    ``diameter`` D (m) and Darcy ``friction_factor`` f_D: ``b = 8 f_D rho / (pi^2 D^5)``."""
    return 8.0 * friction_factor * density / (math.pi**2 * diameter**5)


@dataclass(frozen=True)
class PumpRate:
    """The pump's rate against time: rows ``(t_k, q_k)`` (s, m^3/s).

    ``interpolation="constant"``: the rate ``q_k`` from ``t_k`` until the next row's time;
    ``"linear"``: linear between the rows. Both keep the last rate after the last row; before
    the first row the pump is off (rate 0). :meth:`volume` is the exact integral, so the
    pumped volume does not depend on the time steps.
    """

    times: tuple
    rates: tuple
    interpolation: str = "constant"
    name: str = "well.schedule"

    def __post_init__(self):
        times = np.asarray(self.times, dtype=float).ravel()
        rates = np.asarray(self.rates, dtype=float).ravel()
        name = self.name
        object.__setattr__(self, "interpolation",
                           WELL["interpolation"].value("well.interpolation", self.interpolation))
        if times.size == 0 or times.size != rates.size:
            raise InputError(f"{name} must hold at least one [time, rate] row, got {times.size} times and "
                             f"{rates.size} rates")
        check_time_rows(name, times, rates, lambda q: q >= 0.0, "rate must be a finite number >= 0 m^3/s")
        object.__setattr__(self, "times", tuple(float(t) for t in times))
        object.__setattr__(self, "rates", tuple(float(q) for q in rates))

    @classmethod
    def from_rows(cls, rows, interpolation="constant", name="well.schedule"):
        """The schedule of ``[[time, rate], ...]`` (a scene's table)."""
        rows = [list(row) for row in rows]
        for k, row in enumerate(rows):
            if len(row) != 2:
                raise InputError(f"{name}[{k}] must be a pair [time (s), rate (m^3/s)], got {row!r}")
        return cls(tuple(r[0] for r in rows), tuple(r[1] for r in rows), interpolation, name)

    def rows(self):
        return [[t, q] for t, q in zip(self.times, self.rates)]

    @property
    def peak(self):
        """The largest rate of the schedule, m^3/s."""
        return max(self.rates)

    def rate(self, time):
        """q(t), m^3/s."""
        times, rates = self.times, self.rates
        k = int(np.searchsorted(times, time, side="right")) - 1
        if k < 0:
            return 0.0
        if self.interpolation == "constant" or k == len(times) - 1:
            return rates[k]
        fraction = (time - times[k]) / (times[k + 1] - times[k])
        return rates[k] + fraction * (rates[k + 1] - rates[k])

    def volume(self, time_old, time_new):
        """``int q(t) dt`` over ``[time_old, time_new]`` (m^3), exact for both interpolations."""
        edges = list(self.times) + [math.inf]
        total = 0.0
        for k in range(len(self.times)):
            low, high = max(edges[k], time_old), min(edges[k + 1], time_new)
            if high <= low:
                continue
            if self.interpolation == "constant" or k == len(self.times) - 1:
                total += self.rates[k] * (high - low)
            else:  # the trapezoid of a linear piece is exact
                total += 0.5 * (self.rate(low) + self._left_limit(k, high)) * (high - low)
        return total

    def _left_limit(self, k, time):
        """The rate of piece ``k`` at ``time`` (its end included)."""
        times, rates = self.times, self.rates
        fraction = (time - times[k]) / (times[k + 1] - times[k])
        return rates[k] + fraction * (rates[k + 1] - rates[k])

    def mean(self, time_old, time_new):
        """The mean rate over the step, ``volume / dt``, m^3/s."""
        return self.volume(time_old, time_new) / (time_new - time_old)


@dataclass(frozen=True)
class Well:
    """A straight well from its heel along ``direction``, pumped with ``schedule``.

    Parameters
    ----------
    schedule : PumpRate
    heel : (d,) point, m: where the pump's pressure is (the heel pressure p_h).
    direction : (d,) vector from the heel towards the toe (normalised here).
    volume : float, m^3 >= 0: the wellbore volume that stores fluid (c_f V).
    diameter : float, m > 0, or None: inner diameter for the friction between clusters.
    friction_factor : float >= 0: Darcy friction factor f_D (0: no wellbore friction).

    The fluid's density (:attr:`hmatddm.flow.Fluid.density`) enters the orifice law and the
    pipe friction (:meth:`system`).
    """

    schedule: PumpRate
    heel: tuple
    direction: tuple
    volume: float = 0.0
    diameter: float = None
    friction_factor: float = 0.0

    def __post_init__(self):
        if not isinstance(self.schedule, PumpRate):
            raise InputError(f"well.schedule must be an hmatddm.flow.PumpRate, got {type(self.schedule).__name__}")
        heel = finite_array("well.heel", self.heel)
        direction = finite_array("well.direction", self.direction)
        if heel.ndim != 1 or heel.size not in (2, 3) or direction.shape != heel.shape:
            raise InputError(f"well.heel and well.direction must be points of 2 or 3 coordinates, got shapes "
                             f"{heel.shape} and {direction.shape}")
        norm = float(np.linalg.norm(direction))
        if norm == 0.0:
            raise InputError("well.direction must be a non-zero vector (from the heel towards the toe)")
        object.__setattr__(self, "heel", tuple(float(v) for v in heel))
        object.__setattr__(self, "direction", tuple(float(v) / norm for v in direction))
        for name in ("volume", "diameter", "friction_factor"):
            object.__setattr__(self, name, WELL[name].value(f"well.{name}", getattr(self, name)))
        if self.friction_factor > 0.0 and self.diameter is None:
            raise InputError("well.diameter (m, > 0) is required with well.friction_factor > 0 (the Darcy-Weisbach "
                             "loss between clusters)")

    def measured_depths(self, positions):
        """Distance along the well from the heel to each of ``positions`` (m); InputError naming
        ``cluster[i].position`` when a cluster is off the well's line (more than
        ``ON_WELL_TOLERANCE``) or behind the heel."""
        heel, direction = np.asarray(self.heel), np.asarray(self.direction)
        depths = []
        for i, position in enumerate(positions):
            position = np.asarray(position, dtype=float)
            if position.shape != heel.shape:
                raise InputError(f"cluster[{i}].position must have {heel.size} coordinates like well.heel, got "
                                 f"{position.size}")
            offset = position - heel
            along = float(offset @ direction)
            off = float(np.linalg.norm(offset - along * direction))
            if off > ON_WELL_TOLERANCE:
                raise InputError(f"cluster[{i}].position must lie on the well (the line from well.heel along "
                                 f"well.direction, within {ON_WELL_TOLERANCE:g} m), got {show(position.tolist())}, "
                                 f"{off:.6g} m off it")
            if along < -ON_WELL_TOLERANCE:
                raise InputError(f"cluster[{i}].position must lie beyond well.heel along well.direction, got "
                                 f"{show(position.tolist())}, {-along:.6g} m behind the heel")
            depths.append(max(along, 0.0))
        return np.array(depths)

    def system(self, clusters, density=FLUID["density"].default):
        """The :class:`WellSystem` of ``clusters`` (:class:`hmatddm.flow.Cluster` with their
        perforations) on this well, for a fluid of ``density`` (kg/m^3)."""
        density = FLUID["density"].value("fluid.density", density)
        clusters = list(clusters)
        depths = self.measured_depths([c.position for c in clusters])
        coefficients = []
        for i, c in enumerate(clusters):
            if c.rate is not None:
                raise InputError(f"cluster[{i}].rate must be left out when the clusters share a [well]: the pump "
                                 f"schedule well.schedule sets the rates, which the perforations split")
            if c.wellbore_volume != 0.0:
                raise InputError(f"cluster[{i}].wellbore_volume must be 0 (left out) with a [well]: well.volume is "
                                 f"the wellbore's storage, got {show(c.wellbore_volume)}")
            if c.perforations is None:
                if len(clusters) > 1:
                    raise InputError(f"cluster[{i}].perforations is required (an integer >= 1) when several clusters "
                                     f"share the [well]: the perforation friction splits the rate")
                coefficients.append(0.0)
                continue
            coefficients.append(perforation_coefficient(density, c.perforations, c.perforation_diameter,
                                                        c.discharge_coefficient))
        friction = 0.0
        if self.friction_factor > 0.0:
            friction = pipe_friction_coefficient(density, self.diameter, self.friction_factor)
        return WellSystem(np.array(coefficients), depths, friction, self.volume)


class WellSystem:
    """The well's equations for fixed clusters: perforation coefficients ``a`` (C,), the
    clusters' measured depths (C,, m), the pipe friction coefficient ``b`` (Pa s^2/m^7, 0:
    none) and the storage volume ``V`` (m^3). Module docstring for the equations."""

    def __init__(self, coefficients, depths, friction, volume):
        self.coefficients = np.asarray(coefficients, dtype=float)
        self.depths = np.asarray(depths, dtype=float)
        self.friction = float(friction)
        self.volume = float(volume)
        self.order = np.argsort(self.depths, kind="stable")  # heel to toe
        sorted_depths = self.depths[self.order]
        self.segment_lengths = np.diff(np.concatenate([[0.0], sorted_depths]))

    @property
    def n_clusters(self):
        return len(self.coefficients)

    @property
    def direct(self):
        """One cluster without perforation friction: the reference's injection point."""
        return self.n_clusters == 1 and self.coefficients[0] == 0.0

    def wellbore_friction(self, rates):
        """``w_c`` (Pa): the Darcy-Weisbach loss from the heel to each cluster for cluster
        ``rates`` (module docstring; each segment carries the rates of the clusters beyond it)."""
        if self.friction == 0.0:
            return np.zeros(self.n_clusters)
        q = np.asarray(rates, dtype=float)[self.order]
        carried = np.cumsum(q[::-1])[::-1]  # segment k (ending at the k-th cluster) carries clusters k..C-1
        loss = np.cumsum(self.friction * self.segment_lengths * carried * np.abs(carried))
        friction = np.empty(self.n_clusters)
        friction[self.order] = loss
        return friction

    def perforation_rates(self, drop):
        """``q_c = sign(Delta) sqrt(|Delta| / a_c)`` for drops ``drop`` = Delta_c (Pa)."""
        return np.sign(drop) * np.sqrt(np.abs(drop) / self.coefficients)

    def perforation_friction(self, rates):
        """``a_c q_c |q_c|`` (Pa)."""
        rates = np.asarray(rates, dtype=float)
        return self.coefficients * rates * np.abs(rates)

    def rates_at(self, heel_pressure, cluster_pressure, guess=None, max_iterations=200):
        """The rates ``q`` (C,) of the clusters at the heel pressure ``heel_pressure`` and the
        cluster pressures ``cluster_pressure``: ``a_c q_c |q_c| + w_c(q) = p_h - p_c`` for every
        cluster. Without wellbore friction each is its orifice's; with it the system is the
        gradient of the strictly convex
        ``E(q) = sum_c a_c |q_c|^3 / 3 + sum_m b L_m |Q_m|^3 / 3 - sum_c (p_h - p_c) q_c``
        (``Q_m`` the rate of segment ``m``), solved by Newton's method with a line search on
        ``E`` from ``guess``; ConvergenceError if it does not converge."""
        drive = heel_pressure - np.asarray(cluster_pressure, dtype=float)
        alone = self.perforation_rates(drive)
        if self.friction == 0.0:
            return alone
        a = self.coefficients
        q = alone.copy() if guess is None else np.array(guess, dtype=float)
        tolerance = 1e-13 * max(1.0, float(np.max(np.abs(drive))))
        floor = 1e-9 * max(float(np.max(np.abs(alone))), 1e-300)
        order = self.order
        segment = self.friction * self.segment_lengths

        def energy(rates):
            carried = np.cumsum(rates[order][::-1])[::-1]
            return (float(np.sum(a * np.abs(rates) ** 3)) + float(np.sum(segment * np.abs(carried) ** 3))) / 3.0 \
                - float(drive @ rates)

        for _ in range(max_iterations):
            residual = a * q * np.abs(q) + self.wellbore_friction(q) - drive
            if float(np.max(np.abs(residual))) <= tolerance:
                return q
            carried = np.cumsum(q[order][::-1])[::-1]
            # d w_c / d q_j = sum over the segments m up to c that carry j of 2 b L_m |Q_m|
            weights = 2.0 * segment * np.abs(carried)  # (C,) by segment, heel to toe
            rank = np.empty(self.n_clusters, np.int64)
            rank[order] = np.arange(self.n_clusters)
            shared = np.minimum.outer(rank, rank)       # the last segment both clusters lie beyond
            hessian = np.cumsum(weights)[shared] + np.diag(2.0 * a * np.maximum(np.abs(q), floor))
            step = np.linalg.solve(hessian, -residual)
            before, norm = energy(q), float(np.max(np.abs(residual)))
            length = 1.0
            while length > 1e-3:
                trial = q + length * step
                trial_residual = a * trial * np.abs(trial) + self.wellbore_friction(trial) - drive
                if energy(trial) < before or float(np.max(np.abs(trial_residual))) < norm:
                    break
                length *= 0.5
            q = q + length * step
        raise ConvergenceError(f"the rates of the clusters with wellbore friction did not converge in "
                               f"{max_iterations} Newton iterations")

    def heel_pressure(self, cluster_pressure, pump_rate, storage, heel_pressure_old):
        """``(p_h, q)``: the heel pressure solving ``sum_c q_c(p_h) + S (p_h - p_h^n) = Qbar``, a
        monotone scalar equation (bracketed, then Brent's method to round-off), and the rates
        there (:meth:`rates_at`)."""
        from scipy.optimize import brentq

        cluster_pressure = np.asarray(cluster_pressure, dtype=float)
        last = [None]

        def balance(p_h):
            last[0] = self.rates_at(p_h, cluster_pressure, last[0])
            return float(np.sum(last[0]) + storage * (p_h - heel_pressure_old) - pump_rate)

        low, high = float(np.min(cluster_pressure)), float(np.max(cluster_pressure))
        scale = max(float(np.max(np.abs(cluster_pressure))), abs(heel_pressure_old), 1.0)
        width = max(high - low, float(np.max(self.coefficients)) * pump_rate**2, 1e-6 * scale)
        step = width
        while balance(low) > 0.0:
            low -= step
            step *= 2.0
        step = width
        while balance(high) < 0.0:
            high += step
            step *= 2.0
        if balance(low) == 0.0:
            p_h = low
        elif balance(high) == 0.0:
            p_h = high
        else:
            p_h = brentq(balance, low, high, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=500)
        return p_h, self.rates_at(p_h, cluster_pressure, last[0])

    def solve(self, cluster_pressure, pump_rate, storage, heel_pressure_old):
        """The well's exact state for the cluster pressures ``cluster_pressure`` (C,):
        ``(p_h, q (C,), w (C,))`` (:meth:`heel_pressure`, :meth:`rates_at`)."""
        if self.direct:
            raise ValueError("a direct well (one cluster, no perforation friction) has no orifice to solve")
        p_h, rates = self.heel_pressure(cluster_pressure, pump_rate, storage, heel_pressure_old)
        return p_h, rates, self.wellbore_friction(rates)

    def linearise(self, cluster_pressure, pump_rate, storage, heel_pressure_old, rate_floor):
        """The :class:`WellLinearisation` at the cluster pressures ``cluster_pressure``."""
        p_h, rates, friction = self.solve(cluster_pressure, pump_rate, storage, heel_pressure_old)
        drop = p_h - cluster_pressure - friction
        slope = 1.0 / (2.0 * self.coefficients * np.maximum(np.abs(rates), rate_floor))
        return WellLinearisation(slope, rates - slope * drop, friction, pump_rate, storage, heel_pressure_old)


@dataclass(frozen=True)
class WellLinearisation:
    """The orifices linearised at one iterate: ``q_c = k_c (p_h - w_c - p_c) + r_c`` with the
    heel pressure eliminated by ``sum q_c + S (p_h - p_h^n) = Qbar`` (module docstring)."""

    slope: np.ndarray        # k_c, m^3/(s Pa)
    offset: np.ndarray       # r_c, m^3/s
    friction: np.ndarray     # w_c, Pa
    pump_rate: float         # Qbar, m^3/s
    storage: float           # S = c_f V / dt, m^3/(s Pa)
    heel_pressure_old: float  # p_h^n, Pa

    def _constant(self):
        k = self.slope
        return (self.pump_rate + self.storage * self.heel_pressure_old + float(np.sum(k * self.friction))
                - float(np.sum(self.offset)))

    def heel_pressure(self, cluster_pressure):
        """p_h of the linearised well at the cluster pressures, Pa."""
        k = self.slope
        return (self._constant() + float(np.sum(k * cluster_pressure))) / (float(np.sum(k)) + self.storage)

    def rates(self, cluster_pressure):
        """q_c of the linearised well at the cluster pressures, m^3/s."""
        p_h = self.heel_pressure(cluster_pressure)
        return self.slope * (p_h - self.friction - cluster_pressure) + self.offset

    def matrix_terms(self, elements, n):
        """``(M, g)``: the injection ``q = g - M p`` into the ``n`` elements (the clusters feed
        ``elements``) as a symmetric sparse ``M`` (n x n) and a vector ``g`` (n,)."""
        import scipy.sparse as sp

        k = self.slope
        total = float(np.sum(k)) + self.storage
        rows = np.concatenate([elements, np.repeat(elements, len(elements))])
        cols = np.concatenate([elements, np.tile(elements, len(elements))])
        values = np.concatenate([k, -np.outer(k, k).ravel() / total])
        matrix = sp.csr_matrix((values, (rows, cols)), shape=(n, n))
        rhs = np.zeros(n)
        np.add.at(rhs, elements, k * self._constant() / total - k * self.friction + self.offset)
        return matrix, rhs


@dataclass
class WellLink:
    """The well over one time step, as the flow model of the step uses it: the
    :class:`WellSystem`, the clusters' elements, the pump's mean rate ``Qbar`` over the step,
    the storage ``S = c_f V / dt`` and the heel pressure at the step's start. Each
    :meth:`linearise` keeps its result (:attr:`last`): the rates and heel pressure of the
    converged step are those of the linearisation the last flow matrix was built from, at the
    converged pressures, so the fluid budget closes to the flow solve's tolerance."""

    system: WellSystem
    elements: np.ndarray
    pump_rate: float
    storage: float
    heel_pressure_old: float
    rate_floor: float
    last: WellLinearisation = None

    @property
    def direct(self):
        return self.system.direct

    def linearise(self, pressure):
        """Linearise the well at the element pressures ``pressure`` (N,) and keep it."""
        self.last = self.system.linearise(np.asarray(pressure, dtype=float)[self.elements], self.pump_rate,
                                          self.storage, self.heel_pressure_old, self.rate_floor)
        return self.last

    def state(self, pressure):
        """``(heel pressure, cluster rates)`` at the element pressures ``pressure`` (N,): the last
        linearisation's (linearised there first if there is none); a direct well's heel is its
        element, its rate the pump's less the storage."""
        p_c = np.asarray(pressure, dtype=float)[self.elements]
        if self.direct:
            p_h = float(p_c[0])
            return p_h, np.array([self.pump_rate - self.storage * (p_h - self.heel_pressure_old)])
        if self.last is None:
            self.linearise(pressure)
        return self.last.heel_pressure(p_c), self.last.rates(p_c)


__all__ = ["PumpRate", "Well", "WellSystem", "WellLinearisation", "WellLink", "perforation_coefficient",
           "pipe_friction_coefficient", "ON_WELL_TOLERANCE"]
