"""GMRES with checked convergence and a restart length that grows on stagnation.

Restarted GMRES(m) forgets its Krylov space at every restart; when the preconditioned
operator has a few eigenvalues near zero that m iterations cannot resolve (two cracks
a fraction of their length apart: a thin bridge whose stiffness the local near-field
preconditioner cannot see), every later cycle stalls at about the same residual. Here
a cycle that ran its full length without reducing the true residual by
``1 / STAGNATION_RATIO`` (or whose rate would not reach ``rtol`` within the remaining
budget) is not restarted but continued: its Krylov basis grows to twice the length
(up to ``max_restart``, capped by the memory of the basis), so no work is lost and
the space that resolves the slow modes is kept; later cycles use the grown length.
The total number of inner iterations stays bounded by ``restart * maxiter``.

Each cycle is scipy's left-preconditioned GMRES (modified Gram-Schmidt Arnoldi,
Givens rotations, inner test on the preconditioned residual, outer test on the
true residual, the same inner-tolerance control between cycles), so a solve that
converges within its first cycle takes the same iterations as
``scipy.sparse.linalg.gmres``.
"""

import math

import numpy as np
import scipy.sparse.linalg as spla
from scipy.linalg import get_lapack_funcs

from ..errors import ConvergenceError, InputError

from ._threads import single_threaded_blas

# A full cycle that reduces the true residual by less than 1/STAGNATION_RATIO stagnates.
STAGNATION_RATIO = 0.1
# Restart length multiplier of a stagnating cycle.
RESTART_GROWTH = 2
# Default cap of the grown restart length: at most this many times the given restart
# and a Krylov basis of at most MAX_BASIS_BYTES (never below the given restart).
MAX_RESTART_FACTOR = 8
MAX_BASIS_BYTES = 1 << 30


def _positive_integer(name, value):
    """``value`` as an int >= 1 (Python or numpy integer; bools refused), with the message
    of the package's settings (the compressor imports no settings, docs/architecture.md)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        shown = "true" if value is True else "false" if value is False else repr(value)
        raise InputError(f"{name} must be an integer (>= 1), got {shown}")
    if value < 1:
        raise InputError(f"{name} must be an integer >= 1, got {value}")
    return int(value)


def _default_max_restart(restart, n):
    by_memory = MAX_BASIS_BYTES // (8 * max(n, 1)) - 1
    return max(restart, min(MAX_RESTART_FACTOR * restart, by_memory))


class _Arnoldi:
    """State of one GMRES cycle: orthonormal basis V, Hessenberg matrix (stored by
    columns, as scipy does), Givens rotations and the rotated right-hand side.

    ``size`` iterations done; ``grow`` enlarges the arrays without losing them.
    """

    def __init__(self, n, length):
        self.basis = np.empty((length + 1, n))
        self.hessenberg = np.zeros((length, length + 1))
        self.givens = np.zeros((length, 2))
        self.rhs = np.zeros(length + 1)
        self.size = 0
        self.breakdown = False

    @property
    def length(self):
        return self.hessenberg.shape[0]

    def grow(self, length):
        """Room for ``length`` iterations, keeping the current cycle."""
        if length <= self.length:
            return
        size = self.size
        basis = np.empty((length + 1, self.basis.shape[1]))
        basis[:size + 1] = self.basis[:size + 1]
        hessenberg = np.zeros((length, length + 1))
        hessenberg[:self.length, :self.length + 1] = self.hessenberg
        givens = np.zeros((length, 2))
        givens[:self.length] = self.givens
        rhs = np.zeros(length + 1)
        rhs[:self.rhs.size] = self.rhs
        self.basis, self.hessenberg, self.givens, self.rhs = basis, hessenberg, givens, rhs

    def start(self, v0):
        """New cycle from the preconditioned residual v0; returns its norm."""
        self.hessenberg[:] = 0.0
        self.givens[:] = 0.0
        self.rhs[:] = 0.0
        self.size = 0
        self.breakdown = False
        beta = float(np.linalg.norm(v0))
        if beta > 0.0 and math.isfinite(beta):
            self.basis[0] = v0 / beta
        self.rhs[0] = beta
        return beta

    def step(self, matvec, psolve, lartg):
        """One Arnoldi iteration; returns the preconditioned residual norm."""
        col = self.size
        basis, h = self.basis, self.hessenberg
        w = psolve(matvec(basis[col]))
        h0 = np.linalg.norm(w)
        for k in range(col + 1):  # modified Gram-Schmidt
            coefficient = np.dot(basis[k], w)
            h[col, k] = coefficient
            w -= coefficient * basis[k]
        h1 = np.linalg.norm(w)
        h[col, col + 1] = h1
        basis[col + 1] = w
        if h1 <= np.finfo(np.float64).eps * h0:  # the Krylov space is invariant
            h[col, col + 1] = 0.0
            self.breakdown = True
        else:
            basis[col + 1] *= 1.0 / h1
        for k in range(col):
            c, s = self.givens[k]
            n0, n1 = h[col, k], h[col, k + 1]
            h[col, k], h[col, k + 1] = c * n0 + s * n1, -s * n0 + c * n1
        c, s, magnitude = lartg(h[col, col], h[col, col + 1])
        self.givens[col] = c, s
        h[col, col], h[col, col + 1] = magnitude, 0.0
        self.rhs[col], self.rhs[col + 1] = c * self.rhs[col], -s * self.rhs[col]
        self.size = col + 1
        return abs(self.rhs[col + 1])

    def correction(self):
        """V y minimising the preconditioned residual over the current space."""
        used = self.size
        if used == 0:
            return 0.0
        h = self.hessenberg
        col = used - 1
        y = self.rhs[:used].copy()
        if h[col, col] == 0.0:
            y[col] = 0.0
        for k in range(col, 0, -1):  # back substitution (h holds the triangle transposed)
            if y[k] != 0.0:
                y[k] /= h[k, k]
                y[:k] -= y[k] * h[k, :k]
        if y[0] != 0.0:
            y[0] /= h[0, 0]
        return y @ self.basis[:used]


def gmres(A, b, M=None, rtol=1e-8, restart=50, maxiter=20, x0=None, max_restart=None):
    """Solve ``A x = b`` (:class:`PausableGmres` without a pause: see its parameters)."""
    return PausableGmres(A, b, M=M, rtol=rtol, restart=restart, maxiter=maxiter, x0=x0,
                         max_restart=max_restart).finish()


class PausableGmres:
    """Solve ``A x = b`` with restarted, (left-)preconditioned GMRES.

    Parameters
    ----------
    A : LinearOperator, ndarray or sparse matrix, shape (n, n)
    b : (n,) array, finite
    M : LinearOperator, optional
        Approximate inverse of A (e.g. :func:`default_preconditioner`).
    rtol : float in (0, 1)
        Asked relative residual ``||b - A x|| / ||b||`` (true, unpreconditioned).
    restart : int >= 1
        Krylov dimension between restarts (at first; see ``max_restart``).
    maxiter : int >= 1
        Restart cycles of length ``restart``, as in scipy: the budget is at most
        ``restart * maxiter`` inner iterations, whatever the restart grows to.
    x0 : (n,) array, optional
        Initial guess.
    max_restart : int >= restart, optional
        Largest restart length. A cycle that ran its full length without reducing
        the true residual 10x (or at a rate that would not reach ``rtol`` within the
        budget) is continued with twice the length, up to this cap, instead of being
        restarted. Default: the smaller of 8 * restart and the length whose Krylov
        basis takes 1 GiB (at least ``restart``); ``max_restart=restart`` gives plain
        GMRES(restart).
    pause_rtol : float >= rtol, or a decreasing sequence of them, optional
        :meth:`pause` stops the iteration as soon as the preconditioned residual
        estimate falls below the next ``pause_rtol`` times that of ``b`` (the inner test,
        as ``rtol`` does, without the true residual's product) and returns that iterate
        (``level``: the smallest pause it passed); the next :meth:`pause` or
        :meth:`finish` continues the same Krylov cycle: the result is bit for bit the one
        without pauses (loose iterates to decide on, the accurate one for the cost of
        solving for it alone).

    :meth:`finish` returns ``(x, info)`` (``gmres(...)`` is ``PausableGmres(...).finish()``):

    x : (n,) array
    info : dict
        ``iterations`` (inner iterations = matvecs with A, not counting residual
        checks), ``residual`` (final true relative residual), ``converged`` (True),
        ``restart`` (the restart length reached), ``cycles`` (restarts + 1).

    Raises ConvergenceError (with ``residual`` and ``iterations``) when the tolerance
    is not reached within the budget or the iterate is not finite; a zero ``b``
    returns zeros at once. Cost per iteration: one product with A, one with M and
    O(n * current restart); memory O(n * current restart).
    """
    def __init__(self, A, b, M=None, rtol=1e-8, restart=50, maxiter=20, x0=None, max_restart=None, pause_rtol=None):
        pauses = [] if pause_rtol is None else list(np.atleast_1d(np.asarray(pause_rtol, dtype=np.float64)))
        if any(not (rtol <= level < 1.0) for level in pauses) or any(np.diff(pauses) >= 0.0):
            raise InputError(f"pause_rtol must be decreasing values in [rtol, 1), got {pause_rtol!r}")
        self._steps = _gmres_steps(A, b, M, rtol, restart, maxiter, x0, max_restart, pauses)
        self.result = None
        self.level = None  # the smallest pause_rtol the last pause passed (rtol once finished)
        self._rtol = rtol

    def pause(self):
        """``(x, iterations)``: the iterate at the next pause and the inner iterations so
        far; the converged ``x`` if the solve ended first (a guess already good enough, or
        no pause left), ``result`` then set. Raises ConvergenceError as :func:`gmres`."""
        if self.result is None:
            with single_threaded_blas():
                try:
                    x, iterations, self.level = next(self._steps)
                    return x, iterations
                except StopIteration as stop:
                    self.result = stop.value
        self.level = self._rtol
        return self.result[0], self.result[1]["iterations"]

    def finish(self):
        """``(x, info)`` of the whole solve (see the class docstring)."""
        if self.result is None:
            with single_threaded_blas():
                try:
                    while True:
                        next(self._steps)
                except StopIteration as stop:
                    self.result = stop.value
        self.level = self._rtol
        return self.result


class ExactPreconditionerSolve:
    """A solve with a preconditioner ``M`` that inverts ``A`` to round-off (e.g. the exact
    Schur complement of a small coupled system, :mod:`hmatddm.coupled.scaled_system`):
    ``x = M b``, accepted when its true residual meets ``rtol``; otherwise a
    :class:`PausableGmres` continues from it (the same arguments, ``x0`` replaced by ``M b``).
    One product with ``M`` and one with ``A``, where GMRES with such an ``M`` makes three of
    each (the initial and final residuals, ``M b`` for its inner test, one iteration). The
    interface of :class:`PausableGmres`: :meth:`pause` and :meth:`finish` return the solution
    at once (``iterations`` 0) when the check passed."""

    def __init__(self, A, b, M, rtol=1e-8, restart=50, maxiter=20, x0=None, max_restart=None, pause_rtol=None):
        self.result = None
        self.level = None
        self._rtol = rtol
        self._gmres = None
        b = np.asarray(b, dtype=np.float64).reshape(-1)
        with single_threaded_blas():
            x = np.asarray(spla.aslinearoperator(M).matvec(b), dtype=np.float64).reshape(-1)
            b_norm = float(np.linalg.norm(b))
            residual = math.inf
            if np.all(np.isfinite(x)) and b_norm > 0.0:
                residual = float(np.linalg.norm(b - np.asarray(spla.aslinearoperator(A).matvec(x)).reshape(-1)))
                residual /= b_norm
        if b_norm == 0.0 or residual <= rtol:
            self.result = (x if b_norm > 0.0 else np.zeros_like(b),
                           {"iterations": 0, "residual": 0.0 if b_norm == 0.0 else residual, "converged": True,
                            "restart": 0, "cycles": 0})
        else:  # not exact after all (round-off of an ill-conditioned M): iterate from M b
            start = x if np.all(np.isfinite(x)) else x0
            self._gmres = PausableGmres(A, b, M, rtol, restart, maxiter, start, max_restart, pause_rtol)

    def pause(self):
        """As :meth:`PausableGmres.pause`."""
        if self._gmres is None:
            self.level = self._rtol
            return self.result[0], self.result[1]["iterations"]
        x, iterations = self._gmres.pause()
        self.result, self.level = self._gmres.result, self._gmres.level
        return x, iterations

    def finish(self):
        """As :meth:`PausableGmres.finish`."""
        if self._gmres is not None:
            self.result = self._gmres.finish()
        self.level = self._rtol
        return self.result


def _gmres_steps(A, b, M, rtol, restart, maxiter, x0, max_restart, pauses):
    """The iteration of :class:`PausableGmres` as a generator: yields ``(x, iterations,
    level)`` at the pauses (``pauses``: decreasing relative residuals), returns ``(x, info)``. The caller limits BLAS to one thread
    around each step (the Krylov vector operations are memory-bound, and idle spinning
    BLAS threads would steal the cores from the parallel H-matrix matvec: measured,
    matvec twice slower inside GMRES otherwise); not while paused."""
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float, np.floating)) or not (0.0 < rtol < 1.0):
        raise InputError(f"rtol must be in (0, 1), got {rtol!r}")
    restart = _positive_integer("restart", restart)
    maxiter = _positive_integer("maxiter", maxiter)
    n = A.shape[0]
    if len(A.shape) != 2 or A.shape[1] != n:
        raise InputError(f"A must be square, got shape {A.shape}")
    if max_restart is None:
        max_restart = _default_max_restart(restart, n)
    else:
        max_restart = _positive_integer("max_restart", max_restart)
        if max_restart < restart:
            raise InputError(f"max_restart must be >= restart ({restart}), got {max_restart}")
    b = np.asarray(b, dtype=np.float64)
    if b.ndim == 2 and b.shape[1] == 1:
        b = b[:, 0]
    if b.shape != (n,):
        raise InputError(f"b must have shape ({n},), got {b.shape}")
    if not np.all(np.isfinite(b)):
        raise InputError("b must be finite (it contains NaN or inf)")
    if x0 is not None:
        x0 = np.asarray(x0, dtype=np.float64).reshape(-1)
        if x0.shape != (n,) or not np.all(np.isfinite(x0)):
            raise InputError(f"x0 must be a finite array of shape ({n},)")
    b_norm = float(np.linalg.norm(b))
    if b_norm == 0.0:
        return np.zeros(n), {"iterations": 0, "residual": 0.0, "converged": True, "restart": restart, "cycles": 0}

    operator = spla.aslinearoperator(A)
    preconditioner = None if M is None else spla.aslinearoperator(M)

    def matvec(v):
        return np.asarray(operator.matvec(v), dtype=np.float64).reshape(-1)

    def psolve(v):
        if preconditioner is None:
            return np.array(v, dtype=np.float64)
        return np.asarray(preconditioner.matvec(v), dtype=np.float64).reshape(-1)

    atol = float(rtol) * b_norm
    budget = restart * maxiter
    iterations = cycles = 0
    length = min(restart, n)
    history = [length]
    lartg = get_lapack_funcs("lartg", dtype=np.float64)
    x = np.zeros(n) if x0 is None else x0.copy()
    r = b - matvec(x) if x.any() else b.copy()
    residual_norm = float(np.linalg.norm(r))
    # inner tolerance on the preconditioned residual, adapted between cycles as in scipy
    ptol_factor = 1.0
    b_precond = float(np.linalg.norm(psolve(b)))
    ptol = b_precond * min(1.0, float(rtol))
    pauses = [(b_precond * level, level) for level in pauses]
    krylov = _Arnoldi(n, length)
    while residual_norm > atol and iterations < budget:
        cycles += 1
        start_norm = residual_norm
        presid = krylov.start(psolve(r))
        if not math.isfinite(presid):
            raise ConvergenceError(f"GMRES: the preconditioner returned non-finite values after {iterations} "
                                   "iterations", residual=residual_norm / b_norm, iterations=iterations)
        if presid == 0.0:
            break  # M r = 0 with r != 0: M is singular, nothing to iterate on
        while True:
            while krylov.size < length and iterations < budget:
                presid = krylov.step(matvec, psolve, lartg)
                iterations += 1
                if pauses and presid <= pauses[0][0] and math.isfinite(presid):
                    while pauses and presid <= pauses[0][0]:
                        level = pauses.pop(0)[1]
                    yield x + krylov.correction(), iterations, level
                if presid <= ptol or krylov.breakdown or not math.isfinite(presid):
                    break
            candidate = x + krylov.correction()
            if not np.all(np.isfinite(candidate)):
                raise ConvergenceError(f"GMRES produced a non-finite iterate after {iterations} iterations",
                                       residual=math.nan, iterations=iterations)
            r = b - matvec(candidate)
            residual_norm = float(np.linalg.norm(r))
            full = krylov.size == length and presid > ptol and not krylov.breakdown
            remaining = budget - iterations
            if residual_norm <= atol or not full or remaining == 0 or length >= min(max_restart, n):
                break
            # Stagnation: continue this cycle in a larger space instead of restarting.
            ratio = residual_norm / start_norm
            rate = min(1.0, ratio) ** (1.0 / krylov.size)
            if ratio <= STAGNATION_RATIO and residual_norm * rate**remaining <= atol:
                break
            length = min(max_restart, RESTART_GROWTH * length, n)
            history.append(length)
            krylov.grow(length)
        x = candidate
        if residual_norm <= atol or krylov.breakdown or not math.isfinite(presid):
            break
        if presid <= ptol:  # inner test passed, outer did not: tighten the inner one
            ptol_factor = max(np.finfo(np.float64).eps, 0.25 * ptol_factor)
        else:
            ptol_factor = min(1.0, 1.5 * ptol_factor)
        ptol = presid * min(ptol_factor, atol / residual_norm)
    residual = residual_norm / b_norm
    if not residual <= rtol:
        grown = "" if len(history) == 1 else f", grown on stagnation to {'->'.join(map(str, history[1:]))}"
        raise ConvergenceError(
            f"GMRES did not converge: relative residual {residual:.3e} > rtol {rtol:.1e} after "
            f"{iterations} iterations in {cycles} cycle(s) (restart={restart}{grown}, max_restart={max_restart}; "
            f"budget restart*maxiter = {budget} iterations)",
            residual=residual, iterations=iterations)
    return x, {"iterations": iterations, "residual": residual, "converged": True, "restart": length,
               "cycles": cycles}
