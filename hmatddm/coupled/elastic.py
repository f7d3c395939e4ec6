"""Solves with the elasticity block ``A`` of the coupled system, for either backend.

* ``dense``: LU factors, computed once per mesh and reused for every solve.
* ``hmatrix``: GMRES preconditioned by the operator's default preconditioner (near-field
  block ILU; from 20 000 elements plus the two-level coarse correction of
  :mod:`hmatddm.hmatrix.coarse_space`), built once per operator, warm-started.
* an :class:`~hmatddm.extended_operator.ExtendedElasticityOperator` (a grown mesh):
  GMRES preconditioned by its block-triangular near-field solve.

:meth:`ElasticSolver.approximate_inverse` is what the Krylov-accelerated coupled
scheme uses inside its preconditioner: the exact LU solve for ``dense``, one
application of the near-field preconditioner otherwise (no inner iteration).

Every method takes optional contact ``rows`` (:class:`~hmatddm.coupled.contact.ContactRows`):
the operator is then ``S A + D`` (closed elements, see :mod:`hmatddm.coupled.contact`),
and the factorisations are those of ``S A + D`` (dense LU), of ``S A_near + D``
(near-field ILU) or the block-triangular one with modified blocks (grown mesh); they
are cached for the last set of statuses. Contact rows fall back to this scalar ILU of
``S A_near + D``: the two-level correction is not built for modified rows.
"""
import numpy as np
import scipy.linalg
import scipy.sparse.linalg as spla

from ..errors import ConvergenceError
from ..extended_operator import ExtendedElasticityOperator
from ..hmatrix import gmres
from ..hmatrix.preconditioners import DEFAULT_ILU


class ElasticSolver:
    """Solver for ``A x = b`` (or ``(S A + D) x = b`` with contact rows) of one operator."""

    def __init__(self, operator, rtol=1e-9, restart=100, maxiter=20):
        self.operator = operator
        self.rtol = rtol
        self.restart, self.maxiter = restart, maxiter
        self.dof = operator.dof
        self.n_elements = operator.mesh.n_elements
        self._diagonal_blocks = None
        self.extended = isinstance(operator, ExtendedElasticityOperator)
        self.direct = operator.backend == "dense" and not self.extended
        self._modified_key = None
        self._modified_inverse = None

    @property
    def shape(self):
        return self.operator.shape

    def matvec(self, x):
        return self.operator.matvec(x)

    def modified_operator(self, rows):
        """``S A + D`` as a LinearOperator."""
        return spla.LinearOperator(self.shape, matvec=lambda x: rows.apply(self.operator.matvec(x), x),
                                   dtype=np.float64)

    def solve(self, rhs, x0=None, rows=None):
        """``(x, iterations)`` with ``x`` flat, element-major."""
        rhs = np.asarray(rhs, dtype=np.float64).ravel()
        if self.direct:
            factors = self.operator.lu() if rows is None else self._modified(rows)[1]
            return scipy.linalg.lu_solve(factors, rhs, check_finite=False), 0
        if rows is None:
            operator, preconditioner = self.operator, self._plain_preconditioner()
        else:
            operator = self.modified_operator(rows)
            preconditioner = spla.LinearOperator(self.shape, matvec=lambda r: self.approximate_inverse(r, rows),
                                                 dtype=np.float64)
        x, info = gmres(operator, rhs, M=preconditioner, rtol=self.rtol, restart=self.restart,
                        maxiter=self.maxiter, x0=x0)
        if not np.all(np.isfinite(x)):
            raise ConvergenceError("elastic solve gave non-finite DDs")
        return x, int(info["iterations"])

    def _plain_preconditioner(self):
        if self.extended:
            return spla.LinearOperator(self.shape, matvec=self.operator.approximate_inverse, dtype=np.float64)
        return self.operator.preconditioner()

    def approximate_inverse(self, rhs, rows=None):
        if rows is None:
            if self.direct:
                return scipy.linalg.lu_solve(self.operator.lu(), rhs, check_finite=False)
            if self.extended:
                return self.operator.approximate_inverse(rhs)
            return self.operator.preconditioner() @ rhs
        kind, factors = self._modified(rows)
        rhs = np.asarray(rhs, dtype=np.float64).ravel()
        if kind == "lu":
            return scipy.linalg.lu_solve(factors, rhs, check_finite=False)
        if kind == "operator":
            return factors @ rhs
        base_inverse, no_rows, nn_lu, k = factors  # block lower-triangular (grown mesh)
        x_old = base_inverse(rhs[:k])
        x_new = scipy.linalg.lu_solve(nn_lu, rhs[k:] - no_rows @ x_old, check_finite=False)
        return np.concatenate([x_old, x_new])

    def _modified(self, rows):
        """Factorisation of ``S A + D`` for ``rows`` (cached for the last key)."""
        if self._modified_key == rows.key and self._modified_inverse is not None:
            return self._modified_inverse
        if self.extended:
            op = self.operator
            n0 = op.n_base
            base_rows = rows.subset(0, n0)
            base_inverse = self._base_modified_inverse(op.base, base_rows)
            no_rows = rows.modify_rows(op.no, n0)
            nn = rows.subset(n0, rows.n).modify_dense(op.nn)
            result = ("block", (base_inverse, no_rows, scipy.linalg.lu_factor(nn, check_finite=False), n0 * self.dof))
        elif self.direct:
            result = ("lu", scipy.linalg.lu_factor(rows.modify_dense(self.operator.to_dense()), check_finite=False))
        else:
            result = ("operator", _modified_near_field_inverse(self.operator, rows))
        self._modified_key, self._modified_inverse = rows.key, result
        return result

    @staticmethod
    def _base_modified_inverse(base, rows):
        if base.backend == "dense":
            factors = scipy.linalg.lu_factor(rows.modify_dense(base.to_dense()), check_finite=False)
            return lambda r: scipy.linalg.lu_solve(factors, r, check_finite=False)
        inverse = _modified_near_field_inverse(base, rows)
        return lambda r: inverse @ r

    def diagonal_blocks(self, rows=None):
        """(N, d, d) self-influence block of each element (``S_i A_ii + D_i`` with rows)."""
        if self._diagonal_blocks is None:
            self._diagonal_blocks = self.operator.element_diagonal_blocks()
        if rows is None:
            return self._diagonal_blocks
        return rows.modify_blocks(self._diagonal_blocks)

    def normal_stiffness(self, normals):
        """``|n_i . A_ii . n_i|`` per element, Pa/m (the scale of a contact row)."""
        blocks = self.diagonal_blocks()
        return np.abs(np.einsum("ei,eij,ej->e", normals, blocks, normals))


# scalar ILU of the contact-modified near field (its rows mix element frames, so the
# block ILU of the default preconditioner does not apply); the entries kept are those of
# the default preconditioner's block threshold
_CONTACT_ILU = {"drop_tol": 1e-3, "fill_factor": 5.0}


def _modified_near_field_inverse(operator, rows):
    """ILU of ``S A_near + D`` (the default preconditioner's near field with contact rows),
    falling back to block Jacobi of the modified diagonal blocks."""
    hmatrix = operator.hmatrix
    matrix = rows.modify_sparse(hmatrix.near_field_csr(part="near", threshold=DEFAULT_ILU["threshold"]))
    try:
        factor = spla.spilu(matrix, drop_tol=_CONTACT_ILU["drop_tol"], fill_factor=_CONTACT_ILU["fill_factor"])
        inverse = spla.LinearOperator(operator.shape, matvec=factor.solve, dtype=np.float64)
        if np.all(np.isfinite(inverse @ np.ones(operator.shape[0]))):
            return inverse
    except RuntimeError:
        pass
    blocks = np.linalg.pinv(rows.modify_blocks(operator.element_diagonal_blocks()))
    n, d = blocks.shape[0], blocks.shape[1]
    return spla.LinearOperator(operator.shape, dtype=np.float64,
                               matvec=lambda x: np.einsum("eij,ej->ei", blocks, np.reshape(x, (n, d))).ravel())
