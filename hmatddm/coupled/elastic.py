"""Solves with the elasticity block ``A`` of the coupled system, for either backend.

* ``dense``: LU factors, computed once per mesh and reused for every solve.
* ``hmatrix``: GMRES preconditioned by the near field (ILU), warm-started.

:meth:`ElasticSolver.approximate_inverse` is what the Krylov-accelerated coupled
scheme uses inside its preconditioner: the exact LU solve for ``dense``, the
near-field ILU (one application, no inner iteration) for ``hmatrix``.
"""
import numpy as np
import scipy.linalg

from ..solve import solve as solve_elastic


class ElasticSolver:
    """Solver for ``A x = b`` of one :class:`~hmatddm.ElasticityOperator`."""

    def __init__(self, operator, rtol=1e-9):
        self.operator = operator
        self.rtol = rtol
        self.dof = operator.dof
        self.n_elements = operator.mesh.n_elements
        self._diagonal_blocks = None

    @property
    def shape(self):
        return self.operator.shape

    def matvec(self, x):
        return self.operator.matvec(x)

    def solve(self, rhs, x0=None):
        """``(x, iterations)`` with ``x`` flat, element-major."""
        dd, info = solve_elastic(self.operator, rhs, rtol=self.rtol, x0=x0, return_info=True)
        return dd.reshape(-1), int(info["iterations"])

    def approximate_inverse(self, rhs):
        if self.operator.backend == "dense":
            return scipy.linalg.lu_solve(self.operator.lu(), rhs, check_finite=False)
        return self.operator.preconditioner() @ rhs

    def diagonal_blocks(self):
        """(N, d, d) self-influence block of each element."""
        if self._diagonal_blocks is None:
            d, n = self.dof, self.n_elements
            if self.operator.backend == "dense":
                matrix = self.operator._matrix.reshape(n, d, n, d)
                index = np.arange(n)
                self._diagonal_blocks = np.ascontiguousarray(matrix[index, :, index, :])
            else:
                self._diagonal_blocks = self.operator.hmatrix.element_diagonal_blocks()
        return self._diagonal_blocks
