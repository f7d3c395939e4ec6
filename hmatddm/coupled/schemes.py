"""Nonlinear solution of one time step of the coupled system (ref. Sec. 4.4, Eq. 4.41)::

    [ A  B ] [DD]   [f]        A: elasticity (dense or H-matrix), B p = p_i n_i,
    [ C  D ] [p ] = [g]        C, D, g: lubrication (hmatddm.flow.lubrication)

``D`` and ``g`` depend on the widths, so the system is iterated (Picard, widths lagged)
until the changes of ``p`` and ``DD`` fall below the tolerances of ref. Eqs 4.43-4.44. For a
power-law fluid they depend on the pressure too: every scheme assembles them at the iterate
``(DD, p)``, the flux linearised in the pressure (Newton, :mod:`hmatddm.flow.lubrication`).
Four schemes:

* ``"fixed-width"`` (ref. Eq. 4.46): ``p = D^-1 (g - C DD^k)``, then ``DD = A^-1 (f - B p)``.
* ``"fracture-compliance"`` (ref. Eqs 4.48-4.51): the flow solve carries ``omega C'``,
  ``C' = diag(S_i c_i)/dt`` with the self compliance ``c_i`` of ref. Eq. 4.49.
* ``"fully-coupled"`` (ref. Eqs 4.52-4.61): the whole system at once, scaled by
  ``M_1`` (element diagonal blocks of A and the diagonal of D times ``s_u``, ``s_p``)
  and ``M_2`` (``s_u``, ``s_p``), solved by GMRES (the reference used BiCGSTAB).
* ``"krylov"`` (beyond the reference): the same scaled system, GMRES preconditioned by
  the fracture-compliance split ``P = [[A~, B], [0, D + C']]`` with ``A~^-1`` the
  LU solve (dense) or the near-field ILU (H-matrix). One application costs one
  sparse flow solve and one near-field solve; no inner iteration.

Stopping (``SchemeSettings.stopping``): ``"change"`` stops when the change between two
iterates is below the tolerances (ref. Eqs 4.43-4.44); ``"contraction"`` (default) also
stops when the change the next iterations would make, extrapolated from the last ones
(``c_k rho / (1 - rho)`` with ``rho`` the slower of the rates ``c_k / c_{k-1}`` and
``c_{k-1} / c_{k-2}``, at most 1/2: the error estimate of a contracting fixed point), times
``CONTRACTION_SAFETY``, is below them. On a growing radial fracture the coupled schemes
contract ~200-1000x per iteration: the accepted iterate differs from the one ``"change"``
accepts an iteration later by less than the tolerance, and a solve takes two iterations
instead of three. The first
iteration of a solve starts far from the fixed point and only feeds the next one, whose
change is checked: its GMRES asks ``first_linear_rtol`` (at least ``linear_rtol``), and
its iterate is never accepted (a guess whose residual is already below that tolerance
comes back unchanged: the next iteration checks it at ``linear_rtol``).

Segregated schemes relax (ref. Eq. 4.47) with ``alpha``; when an iteration diverges
or does not converge, ``alpha`` is halved and the step restarted (ref. Fig. 4.10). The
coupled schemes' iterates may be Anderson-accelerated while the contact active set stands
still and the changes fall slowly (``solve_step(accelerate=True)``, the element front's
steps; :mod:`hmatddm.coupled.acceleration`).

Closed elements (:mod:`hmatddm.coupled.contact`): with a ``contact`` model the
elasticity rows of closed elements become ``S (A DD + B p - f) + D DD = g`` (stick or
Coulomb slip) in every scheme, the active set is updated after every nonlinear
iteration, and a step converges only when the active set no longer changes.
Elements with a ``fixed_pressure`` (natural elements that failed remotely and are not
connected to an injection point) keep that pressure: their flow row is ``p_i = p_fixed``.

A provisional solve's first GMRES solve may pause at coarser residuals
(``provisional_linear_rtol``) and be continued in the same Krylov space
(:mod:`hmatddm.coupled.paused`): a growth pass decides on the cheapest iterate that can
decide it, and the iterates after it are a plain solve's, bit for bit.

The settings and the problem of a step are :mod:`hmatddm.coupled.step_problem`, the scaled
linear system of the coupled schemes :mod:`hmatddm.coupled.scaled_system`; here are the
iterations of the four schemes and the loop that drives them (stopping, divergence,
relaxation restarts, the provisional solve).
"""
import math
import time
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import ConvergenceError
from ..hmatrix.solvers import ExactPreconditionerSolve, PausableGmres
from .acceleration import ACCEPT, IterateMixing
from .paused import PausedIterate, pause_levels
from .scaled_system import _CoupledLinearSystem
from .step_problem import COUPLED_SCHEMES


def _relative_change(new, old):
    scale = max(np.max(np.abs(old)), np.max(np.abs(new)))
    change = np.max(np.abs(new - old))
    if scale == 0.0:
        return 0.0 if change == 0.0 else math.inf
    return change / scale


class _Diverged(Exception):
    pass


def _segregated_iteration(problem, settings, dd, p, alpha, counters, first=False):
    matrix, rhs = problem.flow_matrices(dd, p)
    rhs = rhs - problem.coupling @ dd
    if settings.scheme == "fracture-compliance" and settings.omega > 0.0:
        correction = settings.omega * problem.compliance_term
        matrix = matrix + sp.diags(correction)
        rhs = rhs + correction * p
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spla.MatrixRankWarning)
        p_new = spla.spsolve(matrix.tocsc(), rhs)
    if not np.all(np.isfinite(p_new)):
        raise _Diverged("the flow solve gave non-finite pressures")
    rows = problem.rows()
    try:
        dd_new, iterations = problem.elastic.solve(problem.elastic_rhs(rows, p_new), x0=dd, rows=rows)
    except ConvergenceError as error:
        counters["linear"] += error.iterations or 0
        raise _Diverged(str(error)) from None
    counters["linear"] += iterations
    return alpha * dd_new + (1.0 - alpha) * dd, alpha * p_new + (1.0 - alpha) * p


def _coupled_iteration(problem, settings, dd, p, alpha, counters, first=False, pause=None, rtol=None):
    """One coupled iterate from ``(dd, p)`` (the widths lagged there); ``first``: its GMRES at
    ``first_linear_rtol``. ``pause`` (a list, with ``first``): the GMRES solve pauses at
    :func:`~hmatddm.coupled.paused.pause_levels` (:class:`hmatddm.hmatrix.solvers.PausableGmres`),
    the iterate returned is the first paused one, and a
    :class:`~hmatddm.coupled.paused.PausedIterate` appended to ``pause``
    continues the same solve (nothing appended when it ended before a pause). ``rtol``: the
    GMRES tolerance of a later iterate (default ``linear_rtol``; :meth:`PendingSolve.linear_rtol`)."""
    matrix, flow_rhs = problem.flow_matrices(dd, p)
    if not (np.all(np.isfinite(matrix.data)) and np.all(np.isfinite(flow_rhs))):
        raise _Diverged("non-finite flow matrix")
    if first:
        rtol = max(settings.linear_rtol, settings.first_linear_rtol)
    elif rtol is None:
        rtol = settings.linear_rtol
    try:
        system = _CoupledLinearSystem(problem, matrix, dd, p)
        preconditioner = factor = None
        if settings.scheme == "krylov":
            preconditioner, factor = system.compliance_preconditioner(settings.omega, problem.flow_factor, rtol)
            problem.flow_factor = factor
    except (RuntimeError, np.linalg.LinAlgError) as error:  # singular flow or diagonal blocks
        raise _Diverged(f"singular coupled system: {error}") from None
    guess = np.concatenate([dd / system.s_u, p / system.s_p])
    levels = pause_levels(settings) if pause is not None else None
    # an exact preconditioner solves the system: checked by its residual, no Krylov cycle
    method = ExactPreconditionerSolve if system.exact_preconditioner else PausableGmres
    solver = method(system.operator, system.rhs(flow_rhs), M=preconditioner, rtol=rtol,
                    restart=settings.linear_restart, maxiter=settings.linear_maxiter, x0=guess,
                    pause_rtol=levels or None)
    paused = PausedIterate(solver, system.split, dd, p, alpha, counters)
    linear = counters["linear"]
    iterate = _continued(paused.advance)
    if factor is not None:
        factor.record(counters["linear"] - linear)
    if pause is not None and not paused.done:
        pause.append(paused)
    return iterate


def _continued(call):
    """``call()`` (a :class:`~hmatddm.coupled.paused.PausedIterate` step), its GMRES failure
    a divergence of the attempt."""
    try:
        return call()
    except ConvergenceError as error:
        raise _Diverged(str(error)) from None


# "contraction" stopping: the extrapolated next change times this must be below the
# tolerance (the rate of the first iterations varies; measured on the radial K-vertex run
# at h = 1 m, the change after an accepted iterate was at most 0.9 tolerance)
CONTRACTION_SAFETY = 3.0
#: The contraction rate assumed for the second iterate of an attempt, whose rate is unknown
#: (PendingSolve.linear_rtol: an iterate expected to pass the test is solved to linear_rtol)
FIRST_RATE = 0.1
#: ... and an iterate whose change is expected within this many tolerances is solved to
#: linear_rtol (measured on the radial K-vertex at 0.5 m: the changes of a solve's iterates
#: run ~1200, ~57, <1 tolerances; forcing the second-to-last iterate cost one more iterate)
FORCING_FROM = 10.0


def _converged(stopping, change, history):
    """Whether an iterate whose ``change`` (in units of the tolerances) follows the changes
    ``history`` of the attempt is accepted (module docstring, ``stopping``): the rate is
    the slower of the last two."""
    if change < 1.0:
        return True
    if stopping != "contraction" or not history or min(history[-2:]) <= 0.0:
        return False
    rho = change / history[-1]
    if len(history) >= 2:
        rho = max(rho, history[-1] / history[-2])
    return rho <= 0.5 and CONTRACTION_SAFETY * change * rho / (1.0 - rho) < 1.0


#: Iterations over which :func:`_stagnated` measures the rate of an attempt (twice this
#: many before it judges)
STAGNATION_WINDOW = 10


def _stagnated(history, left):
    """Whether an attempt whose changes (in units of the tolerances) are ``history`` cannot
    converge in the ``left`` iterations it has: the smallest change of its last
    :data:`STAGNATION_WINDOW` iterations against that of the window before gives the rate
    per iteration, which must bring it below 1 in ``left`` iterations. A relaxed iteration
    stuck on an oscillation (the dfn-3cluster scene, t = 24 s: changes 4.5e-2 for 380
    iterations until ``max_iterations``, where half the relaxation converged in 20) or
    drifting on a slow mode is given up after ``2 * STAGNATION_WINDOW`` iterations."""
    window = STAGNATION_WINDOW
    if len(history) < 2 * window:
        return False
    recent, before = min(history[-window:]), min(history[-2 * window:-window])
    if recent <= 1.0 or before <= 0.0:
        return False
    if recent >= before:
        return True
    rate = (recent / before) ** (1.0 / window)
    return math.log(recent) / -math.log(rate) > left


#: A solve that may be redone in shorter steps (``solve_step(splittable=True)``) is given up
#: when two attempts in a row stagnate (:func:`_stagnated`) and halving the relaxation cut
#: the stagnated change by less than this factor (it cuts any change by 2: a mode that the
#: relaxation does not damp, e.g. a drift or a cycle of the active set whose size follows
#: alpha). On the dfn-3cluster network at 4x its area, 154-158 s: six steps went down the
#: whole ladder from alpha 1/2 or 1/4 to 1/256 (~20 iterations an attempt, 800 of 1485
#: iterations) before their halves converged; no attempt converged below alpha 1/4, and
#: none after two stagnated attempts.
RELAXATION_HELPS = 0.25

#: Iterates combined by the Anderson acceleration of a coupled attempt
#: (:mod:`hmatddm.coupled.acceleration`, ``solve_step(accelerate=True)``); 0: the plain iteration
ANDERSON_MEMORY = 5


def _products(problem):
    """Products the step problem's elasticity operator has made so far
    (:class:`hmatddm.elasticity.operator.ProductCounter`; 0 for an operator that does not
    count them)."""
    return int(getattr(getattr(problem.elastic, "operator", None), "products", 0))


def solve_step(problem, settings, dd_guess, p_guess, relaxation, provisional=False, splittable=False,
               accelerate=False):
    """Iterate one time step to convergence (ref. Eqs 4.43-4.44).

    Returns ``(dd, p, info)``; ``info`` has ``nonlinear_iterations`` (all attempts),
    ``linear_iterations`` (GMRES iterations), ``elastic_products`` (products with the
    elasticity operator: GMRES iterations, residuals, segregated solves), ``relaxation`` (the alpha that
    converged), ``restarts``, ``solve_seconds``, ``contact_changes`` (active-set
    changes over the step) and ``pending``. Raises ConvergenceError when even
    ``min_relaxation`` fails.

    ``provisional=True`` (coupled schemes with a loose first iteration, ``first_linear_rtol
    > linear_rtol``): return the first iterate of the attempt, which is never accepted
    (module docstring), with ``info["pending"]`` a :class:`PendingSolve` whose ``finish()``
    continues the very same iteration to convergence (the same iterates as without
    ``provisional``, so the converged result is identical). A growing simulation decides on
    this iterate whether the mesh grows (:mod:`hmatddm.simulation.step_solve`) and pays the
    rest of the iteration only for the mesh it keeps. Otherwise ``pending`` is None and the
    result converged.

    ``splittable=True`` (the caller redoes a step that does not converge in shorter steps):
    a relaxation that does not help is not pursued (:data:`RELAXATION_HELPS`; coupled schemes
    only: the segregated ones converge slowly at small alpha, ref. Fig. 4.10).

    ``accelerate=True`` (coupled schemes): Anderson-accelerated iterates while the contact
    active set stands still (:mod:`hmatddm.coupled.acceleration`; the element front's steps,
    :mod:`hmatddm.simulation.step_solve`). Not the asymptotic front's solves: its front
    iteration converges to ``front_tolerance`` around them, and an accelerated inner path
    moved its answer within that tolerance but by more than its tests' 2e-6.
    """
    pending = PendingSolve(problem, settings, dd_guess, p_guess, relaxation, splittable=splittable,
                           accelerate=accelerate)
    return pending.run(provisional)


class PendingSolve:
    """The nonlinear iteration of one :func:`solve_step`, which may stop after the first
    (loose) iterate of an attempt and be continued by :meth:`finish`."""

    def __init__(self, problem, settings, dd_guess, p_guess, relaxation, splittable=False, accelerate=False):
        self.problem, self.settings = problem, settings
        self.splittable = splittable and settings.scheme in COUPLED_SCHEMES  # segregated ones need the ladder
        self._stalled = None       # the stagnated change of this attempt (None: it did not stagnate)
        self._last_stalled = None  # ... of the attempt before it
        self.dd_guess, self.p_guess = dd_guess, p_guess
        self.coupled = settings.scheme in COUPLED_SCHEMES
        self.iterate = _coupled_iteration if self.coupled else _segregated_iteration
        self.counters = {"nonlinear": 0, "linear": 0}
        self._products_before = _products(problem)  # elasticity products, counted by the operator
        self.reported = {}  # the counts already reported by a provisional return
        self.alpha = relaxation
        self.restarts = 0
        self.contact_changes = 0
        self.mixing = (IterateMixing(settings.tolerance_opening, settings.tolerance_pressure, ANDERSON_MEMORY)
                       if accelerate and self.coupled and ANDERSON_MEMORY > 0 else None)
        self._start_attempt()

    @property
    def loose_first(self):
        """Whether an attempt's first iterate comes from the loose GMRES (never accepted)."""
        return self.coupled and self.settings.first_linear_rtol > self.settings.linear_rtol

    def _start_attempt(self):
        self.dd, self.p = self.dd_guess.copy(), self.p_guess.copy()
        self._paused = None    # the attempt's first iterate, paused (a PausedIterate)
        self._continue = None  # "advance" or "finish": the next first iteration continues it
        if self.problem.contact is not None:
            self.problem.contact.reset()
        self.history = []
        self._stalled = None
        self._mixed = False  # the current iterate is an accelerated one (hmatddm.coupled.acceleration)
        if self.mixing is not None:
            self.mixing.reset()
        self.iteration = 0
        self.last_change = math.nan
        self.accurate_next = False  # an iterate solved loosely passed the test: the next at linear_rtol
        self.last_rtol = None       # GMRES tolerance of the last iterate (None: linear_rtol)

    def linear_rtol(self, iteration):
        """The GMRES tolerance of iterate ``iteration`` after the first of an attempt
        (``SchemeSettings.linear_forcing``): ``linear_forcing`` times the last relative
        change, within ``[linear_rtol, first_linear_rtol]``; ``linear_rtol`` once a loosely
        solved iterate passed the convergence test. None: ``linear_rtol`` (segregated
        schemes, the first iterate, forcing off)."""
        settings, history = self.settings, self.history
        if iteration == 0 or not self.coupled or not settings.linear_forcing > 0.0 or self.accurate_next:
            return None
        if not (math.isfinite(self.last_change) and history):
            return None
        # the next change extrapolated from the last two (an unknown rate: FIRST_RATE); where
        # it is within FORCING_FROM tolerances the iterate may well be the accepted one: solved
        # to linear_rtol at once (a loose one would cost an extra accurate iterate)
        rate = history[-1] / history[-2] if len(history) >= 2 and history[-2] > 0.0 else FIRST_RATE
        if rate * history[-1] < FORCING_FROM:
            return None
        ceiling = max(settings.first_linear_rtol, settings.linear_rtol)
        return max(settings.linear_rtol, min(ceiling, settings.linear_forcing * self.last_change))

    @property
    def looser_provisional(self):
        """Whether a provisional first iterate comes from a GMRES solve paused above
        ``first_linear_rtol`` (``provisional_linear_rtol`` larger)."""
        settings = self.settings
        return self.loose_first and settings.provisional_linear_rtol > max(settings.first_linear_rtol,
                                                                           settings.linear_rtol)

    @property
    def refinable(self):
        """Whether the provisional iterate is a paused one that :meth:`refine` continues."""
        return self._paused is not None

    @property
    def paused_level(self):
        """The relative residual of the paused GMRES solve of the provisional iterate (one of
        :func:`~hmatddm.coupled.paused.pause_levels`), None when it is not paused."""
        return None if self._paused is None else self._paused.level

    def _rewind(self, mode):
        """Back to the attempt's start, its first iteration to be the paused GMRES solve
        continued (``mode``: to its next pause or to its end; the same linear system,
        nothing else is recomputed)."""
        paused = self._paused
        self._start_attempt()
        self._paused, self._continue = paused, mode

    def refine(self):
        """``(dd, p, info)``, still pending: the first iterate with its GMRES solve continued
        to the next of :func:`~hmatddm.coupled.paused.pause_levels` or, after the last, to ``first_linear_rtol``
        (the same Krylov space: then bit for bit the first iterate of a plain solve, for
        the GMRES iterations a plain solve makes beyond the pauses). A growth pass that
        cannot decide on a paused iterate decides on the refined one."""
        if not self.refinable:
            raise RuntimeError("refine() needs a paused provisional iterate (refinable)")
        self._rewind("advance")
        return self._run(True)

    def finish(self):
        """``(dd, p, info)`` of the converged solve (``info`` counts the work since the
        provisional return only, so that the two infos add up to the whole solve): the
        iterates of a plain solve, bit for bit (a paused first GMRES solve is continued)."""
        if self.refinable:
            self._rewind("finish")
        return self.run(False)

    def run(self, provisional=False):
        """Iterate (see :func:`solve_step`): ``(dd, p, info)``."""
        return self._run(provisional and self.loose_first)

    def _run(self, provisional):
        settings, problem = self.settings, self.problem
        self._begin = time.perf_counter()
        while True:
            try:
                while self.iteration < settings.max_iterations:
                    iteration = self.iteration
                    self.iteration += 1
                    if not (iteration == 0 and self._continue):  # a paused one is counted already
                        self.counters["nonlinear"] += 1
                    dd_new, p_new = self._iterate(iteration, provisional)
                    if not (np.all(np.isfinite(dd_new)) and np.all(np.isfinite(p_new))):
                        raise _Diverged("non-finite iterate")
                    change_p = _relative_change(p_new, self.p)
                    change_u = _relative_change(dd_new, self.dd)
                    dd_old, p_old, mixed = self.dd, self.p, self._mixed
                    self.dd, self.p = dd_new, p_new
                    self.last_change = max(change_p, change_u)
                    changed = problem.update_contact(self.dd, self.p)
                    self.contact_changes += changed
                    # the change in units of the tolerances
                    change = max(change_p / settings.tolerance_pressure, change_u / settings.tolerance_opening)
                    # a loosely solved first iteration may return its guess (its residual already
                    # below first_linear_rtol): only a full-accuracy iterate can be accepted
                    loose = iteration == 0 and self.loose_first
                    forced = self.last_rtol is not None and self.last_rtol > settings.linear_rtol
                    # after an accelerated iterate the rate of the changes is not the map's: no
                    # extrapolation, and a change within acceleration.ACCEPT of the tolerances
                    accepted = change < ACCEPT if mixed else _converged(settings.stopping, change, self.history)
                    if accepted and changed == 0:
                        if not (loose or forced):
                            return self.dd, self.p, self._finished(pending=False)
                        self.accurate_next = True  # the next at linear_rtol (SchemeSettings.linear_forcing)
                    history = self.history
                    history.append(change)
                    # divergence: the change grew for 5 iterations in a row AND doubled over its
                    # recent minimum (a relaxed iteration creeps up ~1% per iteration on a
                    # plateau, which is not divergence; measured on ref. Table 4.2)
                    if (len(history) > 6 and all(history[-i] > history[-i - 1] for i in range(1, 6))
                            and history[-1] > 2.0 * min(history[-10:])):
                        raise _Diverged("changes grew for 5 iterations and doubled")
                    if max(change_p, change_u) > 1e6:
                        raise _Diverged(f"relative change {max(change_p, change_u):.2e}")
                    if _stagnated(history, settings.max_iterations - self.iteration):
                        self._stalled = min(history[-STAGNATION_WINDOW:])
                        raise _Diverged(f"changes stagnated at {self.last_change:.2e} (no convergence within "
                                        f"{settings.max_iterations} iterations at their rate)")
                    self._accelerate(dd_old, p_old, changed)  # (never on a first iterate)
                    if provisional and loose:
                        return self.dd.copy(), self.p.copy(), self._finished(pending=True)
                raise _Diverged(f"no convergence in {settings.max_iterations} iterations "
                                f"(last relative change {self.last_change:.2e})")
            except _Diverged as reason:
                stalled, last = self._stalled, self._last_stalled
                self._last_stalled = stalled
                if (self.splittable and stalled is not None and last is not None
                        and stalled > RELAXATION_HELPS * last):
                    raise ConvergenceError(
                        f"time step did not converge with scheme {settings.scheme!r}: two attempts stagnated, at "
                        f"relaxation {2.0 * self.alpha:g} and {self.alpha:g}, with changes {last:.3g} and {stalled:.3g} "
                        "tolerances (a smaller relaxation does not help)", iterations=self.counters["nonlinear"])
                if self.alpha / 2.0 < settings.min_relaxation:
                    raise ConvergenceError(
                        f"time step did not converge with scheme {settings.scheme!r} down to relaxation "
                        f"{self.alpha:g}: {reason}", iterations=self.counters["nonlinear"]) from None
                self.alpha /= 2.0
                self.restarts += 1
                self._start_attempt()

    def _accelerate(self, dd, p, changed):
        """Continue from the Anderson combination (:meth:`IterateMixing.iterate`) instead of the
        relaxed iterate ``G(x_k)`` (``self.dd``, ``self.p``) after ``x_k = (dd, p)``, if any."""
        mixed = None if self.mixing is None else self.mixing.iterate(dd, p, self.dd, self.p, changed, self.history)
        self._mixed = mixed is not None
        if self._mixed:
            self.dd, self.p = mixed

    def _iterate(self, iteration, provisional):
        """The next iterate from ``(self.dd, self.p)``: the paused first GMRES solve
        continued, or ``self.iterate``, its first GMRES solve paused at
        ``provisional_linear_rtol`` for a provisional return."""
        first = iteration == 0
        self.last_rtol = None
        if first and self._continue:
            paused, mode, self._continue = self._paused, self._continue, None
            out = _continued(paused.advance if mode == "advance" else paused.finish)
            if paused.done:
                self._paused = None
            return out
        if not self.coupled:
            return self.iterate(self.problem, self.settings, self.dd, self.p, self.alpha, self.counters, first=first)
        pause = [] if first and provisional and self.looser_provisional else None
        self.last_rtol = None if first else self.linear_rtol(iteration)
        out = self.iterate(self.problem, self.settings, self.dd, self.p, self.alpha, self.counters, first=first,
                           pause=pause, rtol=self.last_rtol)
        self._paused = pause[0] if pause else None
        return out

    def _finished(self, pending):
        counts = dict(nonlinear_iterations=self.counters["nonlinear"], linear_iterations=self.counters["linear"],
                      restarts=self.restarts, contact_changes=self.contact_changes,
                      elastic_products=_products(self.problem) - self._products_before)
        info = {key: value - self.reported.get(key, 0) for key, value in counts.items()}
        self.reported.update(counts)
        seconds = time.perf_counter() - self._begin
        return dict(info, relaxation=self.alpha, solve_seconds=seconds, pending=self if pending else None)
