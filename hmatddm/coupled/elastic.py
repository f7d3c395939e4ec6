"""Solves with the elasticity block ``A`` of the coupled system, for either backend.

* ``dense``: LU factors, computed once per mesh and reused for every solve.
* ``hmatrix``: GMRES preconditioned by the near field (ILU), warm-started.
* an :class:`~hmatddm.extended_operator.ExtendedElasticityOperator` (a grown mesh):
  GMRES preconditioned by its block-triangular near-field solve.

:meth:`ElasticSolver.approximate_inverse` is what the Krylov-accelerated coupled
scheme uses inside its preconditioner: the exact LU solve for ``dense``, one
application of the near-field preconditioner otherwise (no inner iteration).
"""
import numpy as np
import scipy.linalg

from ..errors import ConvergenceError
from ..extended_operator import ExtendedElasticityOperator
from ..hmatrix import gmres


class ElasticSolver:
    """Solver for ``A x = b`` of one elasticity operator."""

    def __init__(self, operator, rtol=1e-9, restart=100, maxiter=20):
        self.operator = operator
        self.rtol = rtol
        self.restart, self.maxiter = restart, maxiter
        self.dof = operator.dof
        self.n_elements = operator.mesh.n_elements
        self._diagonal_blocks = None
        self.extended = isinstance(operator, ExtendedElasticityOperator)
        self.direct = operator.backend == "dense" and not self.extended

    @property
    def shape(self):
        return self.operator.shape

    def matvec(self, x):
        return self.operator.matvec(x)

    def solve(self, rhs, x0=None):
        """``(x, iterations)`` with ``x`` flat, element-major."""
        rhs = np.asarray(rhs, dtype=np.float64).ravel()
        if self.direct:
            return scipy.linalg.lu_solve(self.operator.lu(), rhs, check_finite=False), 0
        x, info = gmres(self.operator, rhs, M=self.operator.preconditioner(), rtol=self.rtol,
                        restart=self.restart, maxiter=self.maxiter, x0=x0)
        if not np.all(np.isfinite(x)):
            raise ConvergenceError("elastic solve gave non-finite DDs")
        return x, int(info["iterations"])

    def approximate_inverse(self, rhs):
        if self.direct:
            return scipy.linalg.lu_solve(self.operator.lu(), rhs, check_finite=False)
        if self.extended:
            return self.operator.approximate_inverse(rhs)
        return self.operator.preconditioner() @ rhs

    def diagonal_blocks(self):
        """(N, d, d) self-influence block of each element."""
        if self._diagonal_blocks is None:
            self._diagonal_blocks = self.operator.element_diagonal_blocks()
        return self._diagonal_blocks
