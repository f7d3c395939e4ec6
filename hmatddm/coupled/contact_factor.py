"""Exact solves with the contact-modified dense elasticity matrix ``M = S A + D`` of an
active set that keeps changing (:mod:`hmatddm.coupled.contact`), by a low-rank update of
one factorised base instead of a fresh factorisation per set of statuses.

A set of rows that differs from the base's (``M_0 = S_0 A + D_0``, its LU kept) in the
rows of ``k`` elements is ``M = M_0 + U V^T`` with ``U`` the ``r = k d`` columns of the
identity at those elements' unknowns and ``V^T`` the difference of their rows,
``(S - S_0)_E A_E + (D - D_0)_E``. By the Sherman-Morrison-Woodbury identity::

    M^-1 = M_0^-1 - W K^-1 V^T M_0^-1,    W = M_0^-1 U,    K = I + V^T W  (r x r)

so a solve costs one solve with the base's LU and two ``(dN, r)`` products, and the
columns ``W`` of ``M_0^-1`` are solved once per base and element. The exact Schur
complement of the ``"krylov"`` preconditioner (:meth:`StepProblem.coupled_compliance`)
needs ``M^-1 S B`` (``B p = p_i n_i``); with ``X_0 = M_0^-1 S_0 B`` (once per base) and
``S B = S_0 B + U Q`` (``Q``: the changed rows of ``S B``, only in the changed elements'
columns)::

    M^-1 S B = X_0 + W K^-1 (Q - V^T X_0)

at ``O(r dN N)`` instead of a ``dN^3`` factorisation and a ``dN^2 N`` solve. On the
dfn-3cluster network at 4x its area (~550 elements, statuses changing at almost every
nonlinear iteration, a few elements at a time) the fresh factorisations took over half the
run's CPU (benchmarks/RESULTS.md, issue 33).

A base serves while the changed rows are at most :data:`MAX_RANK_FRACTION` of the unknowns
and ``K`` is well conditioned (:data:`MIN_RCOND`); otherwise the current rows become the
new base. The bases live with the solver of one step's solve (:class:`ElasticSolver`), not
with the operator: a run resumed from a checkpoint then makes the same bases, and the same
round-off, as the run it continues (the project's resumes are bit for bit).
"""
import itertools

import numpy as np
import scipy.linalg
from scipy.linalg import lapack

from ..hmatrix._threads import single_threaded_blas

#: A base serves rows that differ from it in at most this fraction of the unknowns (beyond
#: it the update costs about as much as a new factorisation, and solves cost more)
MAX_RANK_FRACTION = 0.2
#: ... and whose capacitance matrix ``K`` has at least this reciprocal condition number
#: (1-norm estimate; below it the update would lose digits that a new base keeps)
MIN_RCOND = 1e-8

_BASE_IDS = itertools.count()


def _element_dofs(elements, d):
    return (np.asarray(elements)[:, None] * d + np.arange(d)).ravel()


class _Base:
    """One factorised ``M_0 = S_0 A + D_0`` and what the updates from it reuse."""

    def __init__(self, matrix, select, direct, d):
        self.select, self.direct = select.copy(), direct.copy()
        self.d, self.size = d, matrix.shape[0]
        self.n = self.size // d
        modified = np.einsum("eij,ejc->eic", select, matrix.reshape(self.n, d, self.size)).reshape(matrix.shape)
        view = modified.reshape(self.n, d, self.n, d)
        index = np.arange(self.n)
        view[index, :, index, :] += direct
        self.lu = scipy.linalg.lu_factor(modified, check_finite=False, overwrite_a=True)
        self.id = next(_BASE_IDS)
        self._inverse = None                                 # (dN, dN): columns of M_0^-1, as solved
        self._solved = np.zeros(self.n, dtype=bool)          # ... for these elements
        self._x0 = None                                      # M_0^-1 S_0 B, (dN, N)
        self._ax0 = None                                     # rows of A X_0, (N, d, N)
        self._ax0_done = np.zeros(self.n, dtype=bool)

    def columns(self, elements):
        """``M_0^-1 U`` for the unknowns of ``elements``, (dN, k d)."""
        if self._inverse is None:
            self._inverse = np.empty((self.size, self.size))
        missing = elements[~self._solved[elements]]
        if missing.size:
            dofs = _element_dofs(missing, self.d)
            identity = np.zeros((self.size, dofs.size))
            identity[dofs, np.arange(dofs.size)] = 1.0
            self._inverse[:, dofs] = scipy.linalg.lu_solve(self.lu, identity, check_finite=False)
            self._solved[missing] = True
        return self._inverse[:, _element_dofs(elements, self.d)]

    def x0(self, normals):
        """``X_0 = M_0^-1 S_0 B``."""
        if self._x0 is None:
            n, d = self.n, self.d
            columns = np.zeros((n, d, n))
            columns[np.arange(n), :, np.arange(n)] = np.einsum("eij,ej->ei", self.select, normals)
            self._x0 = scipy.linalg.lu_solve(self.lu, columns.reshape(self.size, n), check_finite=False)
        return self._x0

    def ax0(self, matrix, normals, elements):
        """``(A X_0)`` rows of ``elements``, (k, d, N)."""
        x0 = self.x0(normals)
        if self._ax0 is None:
            self._ax0 = np.empty((self.n, self.d, self.n))
        missing = elements[~self._ax0_done[elements]]
        if missing.size:
            self._ax0[missing] = (matrix[_element_dofs(missing, self.d)] @ x0).reshape(missing.size, self.d, self.n)
            self._ax0_done[missing] = True
        return self._ax0[elements]


class UpdatedFactor:
    """``M = S A + D`` of one set of rows as its base plus a low-rank update (module
    docstring); ``rank`` 0 when the rows are the base's own."""

    def __init__(self, factor, base, select, direct, changed):
        self.factor, self.base = factor, base
        d, size = base.d, base.size
        self.changed = changed
        self.rank = changed.size * d
        self.d_select = select[changed] - base.select[changed]
        self.d_direct = direct[changed] - base.direct[changed]
        if not self.rank:
            return
        k = changed.size
        dofs = _element_dofs(changed, d)
        v_t = np.einsum("eij,ejc->eic", self.d_select, factor.matrix[dofs].reshape(k, d, size))
        view = v_t.reshape(k, d, base.n, d)
        view[np.arange(k), :, changed, :] += self.d_direct
        self.v_t = v_t.reshape(self.rank, size)
        self.w = base.columns(changed)
        capacitance = np.eye(self.rank) + self.v_t @ self.w
        self.k_lu = scipy.linalg.lu_factor(capacitance, check_finite=False)
        rcond, _ = lapack.dgecon(self.k_lu[0], np.linalg.norm(capacitance, 1), norm="1")
        self.rcond = float(rcond)

    def solve(self, r):
        """``M^-1 r`` (flat ``r``, or columns)."""
        with single_threaded_blas():  # small dense blocks (hmatddm.hmatrix._threads)
            y = scipy.linalg.lu_solve(self.base.lu, np.asarray(r, dtype=np.float64), check_finite=False)
            if self.rank:
                y = y - self.w @ scipy.linalg.lu_solve(self.k_lu, self.v_t @ y, check_finite=False)
        return y

    def inverse_times_b(self, normals):
        """``(X_0, W, F)`` with ``M^-1 S B = X_0 + W F`` (``W``, ``F`` None at rank 0):
        ``X_0`` is the base's, the same array for every set of rows it serves."""
        base, d = self.base, self.base.d
        with single_threaded_blas():
            x0 = base.x0(normals)
            if not self.rank:
                return x0, None, None
            k, n = self.changed.size, base.n
            q = np.zeros((k, d, n))
            q[np.arange(k), :, self.changed] = np.einsum("eij,ej->ei", self.d_select, normals[self.changed])
            v_x0 = (np.einsum("eij,ejc->eic", self.d_select, base.ax0(self.factor.matrix, normals, self.changed))
                    + np.einsum("eij,ejc->eic", self.d_direct, x0[_element_dofs(self.changed, d)].reshape(k, d, n)))
            f = scipy.linalg.lu_solve(self.k_lu, (q - v_x0).reshape(self.rank, n), check_finite=False)
        return x0, self.w, f


class ContactFactor:
    """The bases of one dense operator's matrix ``A`` and the updates of its rows."""

    def __init__(self, matrix, d):
        self.matrix = np.ascontiguousarray(matrix, dtype=np.float64)
        self.d = d
        self.n = self.matrix.shape[0] // d
        self.base = None
        self.bases_made = 0

    def _blocks(self, rows):
        if rows is None:
            return np.broadcast_to(np.eye(self.d), (self.n, self.d, self.d)), np.zeros((self.n, self.d, self.d))
        return rows.select, rows.direct

    def update(self, rows):
        """The :class:`UpdatedFactor` of ``rows`` (:class:`~hmatddm.coupled.contact.ContactRows`
        or None: ``A`` itself), from the current base or, past the limits (module
        docstring), from a new base at these rows."""
        select, direct = self._blocks(rows)
        base = self.base
        if base is not None:
            changed = np.flatnonzero(np.any((select != base.select) | (direct != base.direct), axis=(1, 2)))
            if changed.size * self.d <= MAX_RANK_FRACTION * self.matrix.shape[0]:
                with single_threaded_blas():
                    updated = UpdatedFactor(self, base, select, direct, changed)
                if not updated.rank or updated.rcond >= MIN_RCOND:
                    return updated
        with single_threaded_blas():
            self.base = _Base(self.matrix, select, direct, self.d)
        self.bases_made += 1
        return UpdatedFactor(self, self.base, select, direct, np.zeros(0, dtype=np.int64))
