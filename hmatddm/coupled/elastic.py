"""Solves with the elasticity block ``A`` of the coupled system, for any operator.

The operator (:class:`~hmatddm.elasticity.operator.ElasticityOperator` of either backend, or an
:class:`~hmatddm.elasticity.extended.ExtendedElasticityOperator` of a grown mesh) does the
solving: ``solve`` (dense: cached LU; otherwise GMRES preconditioned by its approximate
inverse, warm-started), ``approximate_inverse`` (what the Krylov-accelerated coupled
scheme uses inside its preconditioner: the exact LU solve for ``dense``, one
application of the near-field preconditioner otherwise, no inner iteration) and
``modified_inverse`` for contact rows; with an exact (dense LU) inverse also
``exact_inverse_times``, the solve of a block of columns (the exact Schur complement of the
``"krylov"`` preconditioner, :mod:`hmatddm.coupled.scaled_system`).

Every method takes optional contact ``rows`` (:class:`~hmatddm.coupled.contact.ContactRows`):
the operator is then ``S A + D`` (closed elements, see :mod:`hmatddm.coupled.contact`),
and the factorisations are those of ``S A + D`` (dense LU), of ``S A_near + D``
(near-field ILU) or the block-triangular one with modified blocks (grown mesh); they
are cached here for the last set of statuses. Contact rows fall back to this scalar ILU
of ``S A_near + D``: the two-level correction is not built for modified rows.
"""
import numpy as np
import scipy.linalg
import scipy.sparse.linalg as spla

from ..elasticity.inverse import solve_with_inverse
from ..hmatrix._threads import single_threaded_blas


class ElasticSolver:
    """Solver for ``A x = b`` (or ``(S A + D) x = b`` with contact rows) of one operator."""

    def __init__(self, operator, rtol=1e-9, restart=100, maxiter=20):
        self.operator = operator
        self.rtol = rtol
        self.restart, self.maxiter = restart, maxiter
        self.dof = operator.dof
        self.n_elements = operator.mesh.n_elements
        self._diagonal_blocks = None
        self._modified_key = None
        self._modified_inverse = None
        self._modified_factors = None  # dense LU of S A + D (exact operators), for _modified_key

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
        settings = dict(x0=x0, rtol=self.rtol, restart=self.restart, maxiter=self.maxiter)
        if rows is None:
            x, info = self.operator.solve(rhs, **settings)
        else:
            x, info = solve_with_inverse(self.modified_operator(rows), rhs, self._modified(rows),
                                         self.operator.inverse_is_exact, **settings)
        return x, int(info["iterations"])

    def approximate_inverse(self, rhs, rows=None):
        if rows is None:
            return self.operator.approximate_inverse(rhs)
        return self._modified(rows)(rhs)

    def _modified(self, rows):
        """Approximate inverse of ``S A + D`` for ``rows`` (cached for the last key); for an
        exact operator the solve with the LU factors of :meth:`exact_inverse_times` (the
        factorisation of the operator's own ``modified_inverse``, made once for both)."""
        if self._modified_key != rows.key or self._modified_inverse is None:
            self._modified_factors = None
            if self.operator.inverse_is_exact:
                with single_threaded_blas():  # as the GMRES around it (hmatddm.hmatrix._threads)
                    factors = scipy.linalg.lu_factor(rows.modify_dense(self.operator.to_dense()), check_finite=False)
                self._modified_factors = factors
                inverse = lambda r: scipy.linalg.lu_solve(factors, np.asarray(r, dtype=np.float64).ravel(),  # noqa: E731
                                                          check_finite=False)
            else:
                inverse = self.operator.modified_inverse(rows)
            self._modified_key, self._modified_inverse = rows.key, inverse
        return self._modified_inverse

    def exact_inverse_times(self, columns, rows=None):
        """``A^-1 M`` (``(S A + D)^-1 M`` with ``rows``) for the dense ``(dN, k)`` columns
        ``M``, from the dense LU factors; None when the operator's inverse is not exact
        (:attr:`inverse_is_exact`: the ``hmatrix`` backend, a grown operator)."""
        if not self.operator.inverse_is_exact:
            return None
        if rows is None:
            factors = self.operator.lu()
        else:
            self._modified(rows)
            factors = self._modified_factors
        return scipy.linalg.lu_solve(factors, columns, check_finite=False)

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
