"""Solves with the elasticity block ``A`` of the coupled system, for any operator.

The operator (:class:`~hmatddm.elasticity.operator.ElasticityOperator` of either backend, or an
:class:`~hmatddm.elasticity.extended.ExtendedElasticityOperator` of a grown mesh) does the
solving: ``solve`` (dense: cached LU; otherwise GMRES preconditioned by its approximate
inverse, warm-started), ``approximate_inverse`` (what the Krylov-accelerated coupled
scheme uses inside its preconditioner: the exact LU solve for ``dense``, one
application of the near-field preconditioner otherwise, no inner iteration) and
``modified_inverse`` for contact rows; with an exact (dense LU) inverse also
``contact_update``, the solves with ``S A + D`` from a low-rank update of a factorised base
(:mod:`hmatddm.coupled.contact_factor`: the contact statuses of a large network change a few
at a time), which the preconditioner and the exact Schur complement of the ``"krylov"``
scheme use (:mod:`hmatddm.coupled.scaled_system`).

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
from .contact_factor import ContactFactor


class ElasticSolver:
    """Solver for ``A x = b`` (or ``(S A + D) x = b`` with contact rows) of one operator;
    ``contact_bases``: a :class:`~hmatddm.coupled.contact_factor.ContactBases` shared by the
    solves of one step, whose growth passes then border the last solve's contact base."""

    def __init__(self, operator, rtol=1e-9, restart=100, maxiter=20, contact_bases=None):
        self.operator = operator
        self.rtol = rtol
        self.restart, self.maxiter = restart, maxiter
        self.dof = operator.dof
        self.n_elements = operator.mesh.n_elements
        self._diagonal_blocks = None
        self._modified_key = None
        self._modified_inverse = None
        self._modified_factors = None  # (key, dense LU of S A + D) of exact operators, for solve
        self._update = None  # (key, UpdatedFactor) of exact operators (contact_update)
        self.contact_factor = None  # their ContactFactor (made on first use)
        self.contact_bases = contact_bases  # the step's ContactBases: the previous solve's factor, bordered

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
            exact = self.operator.inverse_is_exact
            inverse = self._exact_modified(rows) if exact else self._modified(rows)
            x, info = solve_with_inverse(self.modified_operator(rows), rhs, inverse, exact, **settings)
        return x, int(info["iterations"])

    def approximate_inverse(self, rhs, rows=None):
        if rows is None:
            return self.operator.approximate_inverse(rhs)
        return self._modified(rows)(rhs)

    def _modified(self, rows):
        """Approximate inverse of ``S A + D`` for ``rows`` (cached for the last key); for an
        exact operator the solve with :meth:`contact_update` (exact: a low-rank update of a
        factorised base, :mod:`hmatddm.coupled.contact_factor`)."""
        if self._modified_key != rows.key or self._modified_inverse is None:
            if self.operator.inverse_is_exact:
                inverse = self.contact_update(rows).solve
            else:
                inverse = self.operator.modified_inverse(rows)
            self._modified_key, self._modified_inverse = rows.key, inverse
        return self._modified_inverse

    def _exact_modified(self, rows):
        """The dense LU solve of ``S A + D`` (a fresh factorisation, cached for the last key):
        :meth:`solve`, which answers without an iteration, gets the factors' own accuracy."""
        if self._modified_factors is None or self._modified_factors[0] != rows.key:
            with single_threaded_blas():  # as the GMRES around it (hmatddm.hmatrix._threads)
                factors = scipy.linalg.lu_factor(rows.modify_dense(self.operator.to_dense()), check_finite=False)
            self._modified_factors = (rows.key, factors)
        factors = self._modified_factors[1]
        return lambda r: scipy.linalg.lu_solve(factors, np.asarray(r, dtype=np.float64).ravel(), check_finite=False)

    def contact_update(self, rows):
        """The :class:`~hmatddm.coupled.contact_factor.UpdatedFactor` of ``S A + D`` (``A``
        for ``rows`` None) of an exact (dense) operator, cached for the last key: exact
        solves and ``(S A + D)^-1 S B`` from the operator's factorised base."""
        key = None if rows is None else rows.key
        if self._update is None or self._update[0] != key:
            if self.contact_factor is None:
                bases = self.contact_bases
                read = getattr(self.operator, "dense_view", self.operator.to_dense)  # read only: no copy
                self.contact_factor = ContactFactor(read(), self.operator.dof,
                                                    previous=None if bases is None else bases.last)
                if bases is not None:
                    bases.last = self.contact_factor
            self._update = (key, self.contact_factor.update(rows))
        return self._update[1]

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
