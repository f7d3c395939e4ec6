"""The scaled linear system of one iterate of the coupled schemes (``"fully-coupled"``,
``"krylov"``; ref. Eqs 4.52-4.61): ``M_1^-1 A M_2`` for the flow matrix ``D`` of the
lagged widths, with ``M_1`` the element diagonal blocks of ``A`` and the diagonal of ``D``
times the scales ``s_u``, ``s_p`` (powers of two), and the fracture-compliance split
preconditioner of the ``"krylov"`` scheme. The iteration that solves it is
:mod:`hmatddm.coupled.schemes`.
"""
import math

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..element_blocks import apply_blocks
from ..hmatrix._threads import single_threaded_blas


#: The flow block of the split is symmetric with a positive diagonal (finite-volume
#: transmissibilities plus the compliance diagonal): an ordering of ``A + A^T`` and
#: diagonal pivots halve the factors' fill against scipy's default (COLAMD, partial
#: pivoting). On a 12.9k-cell disc: 2.0x faster factorisation, 2.3x faster solves.
SYMMETRIC_LU = dict(permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.1, options=dict(SymmetricMode=True))


def _power_of_two(x):
    """The power of two nearest ``x`` > 0 (within a factor sqrt(2))."""
    return 2.0 ** round(math.log2(x))


class _CoupledLinearSystem:
    """The scaled coupled matrix ``M_1^-1 A M_2`` of ref. Eqs 4.53-4.61 for fixed D."""

    def __init__(self, problem, matrix, dd, p):
        self.problem = problem
        self.flow_matrix = matrix.tocsr()
        # powers of two: the scaled guess scales back to exactly the DD and pressure of the
        # last iterate (StepProblem.elastic_matvec finds its product)
        self.s_u = _power_of_two(max(float(np.max(np.abs(dd))), 1e-12))
        self.s_p = _power_of_two(max(float(np.max(np.abs(p))), 1.0))
        self.rows = problem.rows()
        # (N, d, d) blocks and M_u^-1 without s_u: the same for every iterate of one set of
        # contact statuses, kept with the problem for the last one
        key = None if self.rows is None else self.rows.key
        kept = problem._scaling_blocks
        if kept is None or kept[0] != key or kept[1] is not problem.elastic.operator:
            blocks = problem.elastic.diagonal_blocks(self.rows)
            kept = problem._scaling_blocks = (key, problem.elastic.operator, blocks, np.linalg.inv(blocks))
        self.blocks, self.block_inverse = kept[2], kept[3]
        self.flow_diagonal = self.flow_matrix.diagonal()
        #: whether :meth:`compliance_preconditioner` inverts the system to round-off (the
        #: exact Schur complement with an exact elasticity solve)
        self.exact_preconditioner = False

    @property
    def operator(self):
        """The scaled matrix as a LinearOperator (made on demand, not kept: a kept one would
        tie the system into a reference cycle, which a paused GMRES solve keeps out of the
        reach of reference counting, with the problem's operator and border blocks)."""
        size = self.problem.n * self.problem.d + self.problem.n
        return spla.LinearOperator((size, size), matvec=self._matvec, dtype=np.float64)

    def left_scale(self, residual_u, residual_p):
        u = apply_blocks(self.block_inverse, residual_u) / self.s_u
        return np.concatenate([u, residual_p / (self.s_p * self.flow_diagonal)])

    def unscale_left(self, z):
        """Inverse of :meth:`left_scale`."""
        n, d = self.problem.n, self.problem.d
        u = apply_blocks(self.blocks, z[:n * d]) * self.s_u
        return u, z[n * d:] * self.s_p * self.flow_diagonal

    def split(self, y):
        nd = self.problem.n * self.problem.d
        return y[:nd] * self.s_u, y[nd:] * self.s_p

    def _matvec(self, y):
        dd, p = self.split(np.asarray(y).ravel())
        problem = self.problem
        u = problem.elastic_apply(dd, p, self.rows)
        q = problem.coupling @ dd + self.flow_matrix @ p
        return self.left_scale(u, q)

    def rhs(self, flow_rhs):
        return self.left_scale(self.problem.elastic_rhs(self.rows), flow_rhs)

    def compliance_preconditioner(self, omega, previous=None, rtol=None):
        """Inverse of the scaled fracture-compliance split, as a LinearOperator, and the
        :class:`FlowFactor` it uses. The flow block is ``D + omega C'`` (ref. Eq. 4.50), its
        factor ``previous``'s when it may serve again (:meth:`FlowFactor.reusable`), else a
        new factorisation of this iterate's flow block; or, with an exact elasticity solve,
        the exact Schur complement ``S = D - C A^-1 B`` (:meth:`StepProblem.coupled_compliance`;
        no factor is kept: None) and the whole block LU, ``p = S^-1 (r_p - C A^-1 r_u)``,
        ``dd = A^-1 r_u - (A^-1 B) p`` (:meth:`StepProblem.inverse_b_times`): the inverse of
        the system to round-off
        (``exact_preconditioner``), which :class:`hmatddm.hmatrix.solvers.ExactPreconditionerSolve`
        applies once and checks, with no Krylov cycle. (The block-triangular factor alone, one
        elasticity solve fewer, left GMRES ~1.3 iterations, three products with ``A`` and
        three applications a solve: 11% more CPU on the dfn-3cluster network at 4x its area.)
        ``rtol``: the relative residual the solve asks for (the kept Schur LU refines its
        solves to :data:`SchurFactor.ACCURACY` of it; None: to round-off)."""
        problem = self.problem
        coupled = problem.coupled_compliance(self.rows)
        if coupled is not None:
            schur = self.flow_matrix.toarray() - coupled
            kept = problem._schur_factor
            if kept is None or not kept.serves(coupled):
                kept = problem._schur_factor = SchurFactor(coupled)
            kept.use(schur, SchurFactor.REFINED if rtol is None else max(SchurFactor.REFINED,
                                                                        SchurFactor.ACCURACY * rtol))
            flow_solve = kept.solve
            factor = None
            self.exact_preconditioner = True
        else:
            leaking = bool(np.any(problem.leak_off_rate))  # see FlowFactor: not kept with leak-off
            if previous is not None and not leaking and previous.reusable(omega, problem.n):
                factor = previous
                factor.uses += 1
            else:
                schur = (self.flow_matrix + sp.diags(omega * problem.compliance_term)).tocsc()
                factor = FlowFactor(spla.splu(schur, **SYMMETRIC_LU), omega, problem.n)
            flow_solve = factor.lu.solve
        nd = problem.n * problem.d

        def apply(z):
            r_u, r_p = self.unscale_left(np.asarray(z).ravel())
            if self.exact_preconditioner:  # the whole block LU, A^-1 B p from C A^-1 B's terms
                y = problem.elastic.approximate_inverse(r_u, self.rows)
                p = flow_solve(r_p - problem.coupling @ y)
                return np.concatenate([(y - problem.inverse_b_times(p, self.rows)) / self.s_u, p / self.s_p])
            p = flow_solve(r_p)
            b_p = problem.b_times(p)
            dd = problem.elastic.approximate_inverse(r_u - (b_p if self.rows is None else self.rows.select_rows(b_p)),
                                                     self.rows)
            return np.concatenate([dd / self.s_u, p / self.s_p])

        return spla.LinearOperator((nd + problem.n,) * 2, matvec=apply, dtype=np.float64), factor


class FlowFactor:
    """The LU of one iterate's flow block ``D + omega C'`` (the split preconditioner's
    expensive part), kept for the next iterates of the same step problem (same mesh): a
    preconditioner may lag the widths (the Krylov solve still meets its tolerance), and on
    a 55k-cell disc a factorisation costs 0.23 s against 5.6 ms for a solve. It serves
    again while the GMRES iterations of the iterates that reused it stay within
    :data:`REUSE_ITERATIONS` times (plus 2) those of the iterate that made it, at most
    :data:`REUSE_LIMIT` times. Not with leak-off: on the radial M~ test run
    (tests/scene/test_leak_off_reference.py) the fluid budget's residual grew from 3.0e-7
    to 3.6e-6 of the injected volume with a kept factor (without leak-off it stays at
    1e-10 either way); why was not found, so a leaking step factors every iterate."""

    REUSE_ITERATIONS = 1.5
    REUSE_LIMIT = 4

    def __init__(self, lu, omega, n):
        self.lu, self.omega, self.n = lu, omega, n
        self.uses = 0
        self.fresh_iterations = None  # GMRES iterations of the iterate that made it
        self.last_iterations = None   # ... of the last iterate that used it

    def record(self, iterations):
        """The GMRES iterations of an iterate that used this factor."""
        if self.fresh_iterations is None:
            self.fresh_iterations = iterations
        self.last_iterations = iterations

    def reusable(self, omega, n):
        if omega != self.omega or n != self.n or self.uses >= self.REUSE_LIMIT or self.fresh_iterations is None:
            return False
        return self.last_iterations <= self.REUSE_ITERATIONS * self.fresh_iterations + 2


class SchurFactor:
    """The LU of the exact Schur complement ``S = D - C A^-1 B`` of one set of contact
    statuses (one ``C A^-1 B``, :meth:`StepProblem.coupled_compliance`), kept for the next
    iterates: theirs differ only in the flow block ``D`` of the lagged widths. A solve takes
    the kept LU with iterative refinement against the iterate's own ``S`` (a product with
    the dense ``N x N`` complement and an LU solve a sweep) to the iterate's target (at
    least :data:`REFINED`, :data:`ACCURACY` of the solve's tolerance) within
    :data:`MAX_SWEEPS` sweeps, and factorises ``S`` anew as soon as the sweeps' contraction
    says they will not get there. A factorisation costs ``~N / 5`` sweeps: on the
    dfn-3cluster network at 4x its area (~470 cells) the new complement of every iterate
    took 17% of the run, profiled (benchmarks/RESULTS.md, issue 33)."""

    #: Relative residual of a refined solve that needs no better (round-off of a fresh LU's)
    REFINED = 1e-13
    #: ... and the fraction of the coupled solve's tolerance a refined flow solve reaches
    ACCURACY = 1e-2
    #: Refinement sweeps at most before the complement is factorised anew
    MAX_SWEEPS = 8

    def __init__(self, coupled):
        self.coupled = coupled  # the C A^-1 B of its statuses (identity: the cache's array)
        self.schur = self.factored = self.lu = None
        self.target = self.REFINED
        self.factorisations = 0

    def serves(self, coupled):
        """Whether the complement of ``coupled`` may take this LU."""
        return self.coupled is coupled

    def use(self, schur, target=REFINED):
        """The complement ``S`` of the current iterate (dense ``(N, N)``) and the relative
        residual its solves reach."""
        self.schur, self.target = schur, target
        if self.lu is None:
            self._factorise()

    def _factorise(self):
        with single_threaded_blas():  # an N x N block of a small mesh (hmatddm.hmatrix._threads)
            self.lu = scipy.linalg.lu_factor(self.schur, check_finite=False)
        self.factored = self.schur
        self.factorisations += 1

    def solve(self, r):
        """``S^-1 r`` to the target (see the class docstring)."""
        p = scipy.linalg.lu_solve(self.lu, r, check_finite=False)
        if self.schur is self.factored:
            return p
        target = self.target * float(np.linalg.norm(r))
        previous = None
        for sweep in range(self.MAX_SWEEPS + 1):
            residual = r - self.schur @ p
            size = float(np.linalg.norm(residual))
            if size <= target:
                return p
            if not math.isfinite(size) or sweep == self.MAX_SWEEPS:
                break
            if previous is not None:  # the contraction so far: give up early when it cannot reach the target
                rate = size / previous
                if rate >= 1.0 or size * rate ** (self.MAX_SWEEPS - sweep) > target:
                    break
            previous = size
            p = p + scipy.linalg.lu_solve(self.lu, residual, check_finite=False)
        self._factorise()
        return scipy.linalg.lu_solve(self.lu, r, check_finite=False)
