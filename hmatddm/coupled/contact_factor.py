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

**Growth passes border the last base.** A growth pass appends elements to the mesh of the
step's previous solve, whose matrix is then the leading block of the new one. Its first base
keeps the previous base's rows for the old elements, so its leading block ``M_0[:s, :s]`` is
the previous base's matrix, factorised already: the base is bordered by the new elements'
rows and columns (:class:`~hmatddm.elasticity.growing_lu.GrowingBlockLU`, O(s^2 b) for ``b``
new unknowns instead of a new O(s^3) LU), and the columns of ``M_0^-1`` and ``X_0`` solved
for the previous base are bordered the same way (their right-hand sides vanish in the new
rows) instead of solved again. Statuses that changed since become the update's rows, as
always. The previous solve's factor is handed on by :class:`ContactBases`, made anew at
every step, so that a resumed run still starts each step as the run it continues did. On
dfn-3cluster at 4x its area 336 of the 546 bases were made after a growth pass
(benchmarks/RESULTS.md, issue 33).
"""
import itertools

import numpy as np
import scipy.linalg
from scipy.linalg import lapack

from ..elasticity.growing_lu import GrowingBlockLU
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


def _contact_rows(rows, select, direct, d, first, start):
    """Columns ``start:`` of ``S A + D`` in the rows ``rows`` of ``A`` (whole elements from
    element ``first`` on)."""
    k = rows.shape[0] // d
    modified = np.einsum("eij,ejc->eic", select, rows[:, start:].reshape(k, d, -1)).reshape(k * d, -1)
    diagonal = np.arange(first, first + k)
    inside = diagonal * d >= start
    view = modified.reshape(k, d, -1, d)
    view[np.flatnonzero(inside), :, diagonal[inside] - start // d, :] += direct[inside]
    return modified


class _Base:
    """One factorised ``M_0 = S_0 A + D_0`` and what the updates from it reuse; with
    ``previous`` (a base whose matrix is ``M_0[:shared, :shared]``, ``shared`` a level's
    end) its levels are kept and bordered by the rest (module docstring)."""

    def __init__(self, matrix, select, direct, d, previous=None, shared=0):
        self.select, self.direct = select.copy(), direct.copy()
        self.d, self.size = d, matrix.shape[0]
        self.n = self.size // d
        if previous is None:
            modified, kept = _contact_rows(matrix, select, direct, d, 0, 0), None
        else:  # only the border is read: the old rows' new columns and the new rows
            modified, k = np.empty_like(matrix), shared // d
            if shared < self.size:
                modified[:shared, shared:] = _contact_rows(matrix[:shared], select[:k], direct[:k], d, 0, shared)
                modified[shared:] = _contact_rows(matrix[shared:], select[k:], direct[k:], d, k, 0)
            kept = previous.levels.prefix(shared)
        self.levels = GrowingBlockLU(modified, kept, pivoted_first=True)
        self.id = next(_BASE_IDS)
        self._inverse = None                                 # (dN, dN): columns of M_0^-1, as solved
        self._solved = np.zeros(self.n, dtype=bool)          # ... for these elements
        self._x0 = None                                      # M_0^-1 S_0 B, (dN, N)
        self._x0_normals = None                              # ... of these normals
        self._ax0 = None                                     # rows of A X_0, (N, d, N)
        self._ax0_done = np.zeros(self.n, dtype=bool)
        self._x0_bordered = None                             # (X_0, normals) of the previous base
        if previous is not None and shared == previous.size:
            self._border_solved(previous)

    def _border_solved(self, previous):
        """The columns of ``M_0^-1`` and ``X_0`` that ``previous`` (this base's leading block)
        solved, bordered by the new rows: their right-hand sides vanish there, so only the
        levels after it run."""
        s, n_old = previous.size, previous.n
        if previous._inverse is not None and previous._solved.any():
            self._inverse = np.empty((self.size, self.size))
            dofs = _element_dofs(np.flatnonzero(previous._solved), self.d)
            columns = np.zeros((self.size, dofs.size))
            columns[:s] = previous._inverse[:, dofs]
            self._inverse[:, dofs] = self.levels.continue_solve(columns, s)
            self._solved[:n_old] = previous._solved
        if previous._x0 is not None:
            self._x0_bordered = (previous._x0, previous._x0_normals)  # bordered on first use (x0)

    def columns(self, elements):
        """``M_0^-1 U`` for the unknowns of ``elements``, (dN, k d)."""
        if self._inverse is None:
            self._inverse = np.empty((self.size, self.size))
        missing = elements[~self._solved[elements]]
        if missing.size:
            dofs = _element_dofs(missing, self.d)
            identity = np.zeros((self.size, dofs.size))
            identity[dofs, np.arange(dofs.size)] = 1.0
            self._inverse[:, dofs] = self.levels.solve(identity)
            self._solved[missing] = True
        return self._inverse[:, _element_dofs(elements, self.d)]

    def _b_columns(self, normals, elements):
        """The columns of ``S_0 B`` of ``elements``, (dN, k)."""
        columns = np.zeros((self.n, self.d, elements.size))
        columns[elements, :, np.arange(elements.size)] = np.einsum("eij,ej->ei", self.select[elements],
                                                                   normals[elements])
        return columns.reshape(self.size, elements.size)

    def x0(self, normals):
        """``X_0 = M_0^-1 S_0 B``; a bordered base's from the previous base's (module
        docstring) when the old elements' normals are the same."""
        if self._x0 is None and self._x0_bordered is not None:
            previous, previous_normals = self._x0_bordered
            self._x0_bordered = None
            s, n_old = previous.shape
            if np.array_equal(previous_normals, normals[:n_old]):
                x0 = np.zeros((self.size, self.n))
                x0[:s, :n_old] = previous
                x0[:, n_old:] = self._b_columns(normals, np.arange(n_old, self.n))
                self._x0, self._x0_normals = self.levels.continue_solve(x0, s), normals.copy()
        if self._x0 is None:
            self._x0 = self.levels.solve(self._b_columns(normals, np.arange(self.n)))
            self._x0_normals = normals.copy()
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
            y = self.base.levels.solve(r)
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


class ContactBases:
    """The contact factor of the last solve of one step (:class:`ContactFactor`), from
    which the next solve's factor borders its first base after a growth pass (module
    docstring). Made anew at every step."""

    def __init__(self):
        self.last = None


class ContactFactor:
    """The bases of one dense operator's matrix ``A`` and the updates of its rows;
    ``previous``: the factor of the step's previous solve (:class:`ContactBases`), whose
    last base the first base borders where its matrix leads this one."""

    def __init__(self, matrix, d, previous=None):
        self.matrix = np.ascontiguousarray(matrix, dtype=np.float64)
        self.d = d
        self.n = self.matrix.shape[0] // d
        self.base = None
        self.bases_made = 0       # new factorisations
        self.bases_bordered = 0   # bases bordered from the previous solve's
        self._previous = previous

    def _blocks(self, rows):
        if rows is None:
            return np.broadcast_to(np.eye(self.d), (self.n, self.d, self.d)), np.zeros((self.n, self.d, self.d))
        return rows.select, rows.direct

    def _bordered(self, select, direct):
        """The first base, bordered from the previous solve's last base (its rows for the
        old elements, ``select``/``direct`` for the new), or None when that base's matrix
        (to a level's end) does not lead this one."""
        previous, self._previous = self._previous, None
        if previous is None or previous.base is None or previous.d != self.d:
            return None
        base, limit = previous.base, min(previous.matrix.shape[0], self.matrix.shape[0])
        ends = [level[1] for level in base.levels.levels if level[1] <= limit]
        if not ends or not np.array_equal(self.matrix[:ends[-1], :ends[-1]], previous.matrix[:ends[-1], :ends[-1]]):
            return None
        shared, k = ends[-1], ends[-1] // self.d
        select, direct = np.array(select), np.array(direct)
        select[:k], direct[:k] = base.select[:k], base.direct[:k]
        try:
            with single_threaded_blas():
                bordered = _Base(self.matrix, select, direct, self.d, previous=base, shared=shared)
        except np.linalg.LinAlgError:  # a singular border: the new rows' own factorisation decides
            return None
        self.bases_bordered += 1
        return bordered

    def update(self, rows):
        """The :class:`UpdatedFactor` of ``rows`` (:class:`~hmatddm.coupled.contact.ContactRows`
        or None: ``A`` itself), from the current base or, past the limits (module
        docstring), from a new base at these rows."""
        select, direct = self._blocks(rows)
        if self.base is None:
            self.base = self._bordered(select, direct)
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
