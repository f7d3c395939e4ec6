"""GMRES with checked convergence: a thin wrapper of scipy.sparse.linalg.gmres."""

import math

import numpy as np
import scipy.sparse.linalg as spla

from hmatddm.errors import ConvergenceError, InputError

from ._threads import single_threaded_blas


def _positive_integer(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def gmres(A, b, M=None, rtol=1e-8, restart=50, maxiter=20, x0=None):
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
        Krylov dimension between restarts.
    maxiter : int >= 1
        Restart cycles, as in scipy: at most ``restart * maxiter`` iterations.
    x0 : (n,) array, optional
        Initial guess.

    Returns
    -------
    x : (n,) array
    info : dict
        ``iterations`` (inner iterations = matvecs with A, not counting residual
        checks), ``residual`` (final true relative residual), ``converged`` (True).

    Raises ConvergenceError (with ``residual`` and ``iterations``) when the tolerance
    is not reached or the iterate is not finite; a zero ``b`` returns zeros at once.
    Cost per iteration: one product with A, one with M and O(n * restart).
    """
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float, np.floating)) or not (0.0 < rtol < 1.0):
        raise InputError(f"rtol must be in (0, 1), got {rtol!r}")
    restart = _positive_integer("restart", restart)
    maxiter = _positive_integer("maxiter", maxiter)
    n = A.shape[0]
    if len(A.shape) != 2 or A.shape[1] != n:
        raise InputError(f"A must be square, got shape {A.shape}")
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
        return np.zeros(n), {"iterations": 0, "residual": 0.0, "converged": True}

    iterations = [0]

    def count(_):
        iterations[0] += 1

    # One BLAS thread: the Krylov vector operations are memory-bound, and idle
    # spinning BLAS threads would steal the cores from the parallel H-matrix matvec
    # (measured: matvec twice slower inside GMRES otherwise).
    with single_threaded_blas():
        x, _ = spla.gmres(A, b, x0=x0, rtol=float(rtol), atol=0.0, restart=restart, maxiter=maxiter, M=M,
                          callback=count, callback_type="pr_norm")
    if not np.all(np.isfinite(x)):
        raise ConvergenceError(f"GMRES produced a non-finite iterate after {iterations[0]} iterations",
                               residual=math.nan, iterations=iterations[0])
    residual = float(np.linalg.norm(b - A @ x)) / b_norm
    if not residual <= rtol:
        raise ConvergenceError(
            f"GMRES did not converge: relative residual {residual:.3e} > rtol {rtol:.1e} after "
            f"{iterations[0]} iterations (restart={restart}, maxiter={maxiter} cycles)",
            residual=residual, iterations=iterations[0])
    return x, {"iterations": iterations[0], "residual": residual, "converged": True}
