"""What the nonlinear solve of one time step (:mod:`hmatddm.coupled.schemes`) takes: the
solver settings (:class:`SchemeSettings`, ref. Secs 4.4-4.5: the scheme, relaxation,
tolerances of ref. Eqs 4.43-4.44, the GMRES solves) and the problem (:class:`StepProblem`:
the blocks ``A``, ``B``, ``C``, ``D`` and right-hand sides ``f``, ``g`` of ref. Eq. 4.41,
with the contact rows of closed elements and the fixed pressure of drained ones).
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..hmatrix._threads import single_threaded_blas
from ..options import SCHEME_DEFAULTS, SCHEMES  # noqa: F401 (re-export: hmatddm.coupled.SCHEMES)
from ..settings import SCHEME  # (ranges and units of the fields)

COUPLED_SCHEMES = ("fully-coupled", "krylov")

#: The ``"krylov"`` preconditioner uses the exact Schur complement ``D - C A^-1 B`` (a dense
#: ``N x N`` LU, kept across iterates with refinement: :class:`.scaled_system.SchurFactor`;
#: :meth:`StepProblem.coupled_compliance`) when the elasticity solve is exact (the dense LU)
#: and the mesh has at most this many elements; the diagonal compliance ``C'`` of ref. Eq.
#: 4.49 otherwise. (dfn-3cluster, ~300 elements: 24-50 GMRES iterations per nonlinear
#: iteration with ``C'``; the exact complement's block LU solves with none.)
EXACT_SCHUR_MAX_ELEMENTS = 1500


@dataclass(frozen=True)
class SchemeSettings:
    """Nonlinear and linear solver settings of a time step.

    Parameters
    ----------
    scheme : one of ``SCHEMES``
    omega : float in [0, 1], weight of the compliance term (ref. Eq. 4.50)
    relaxation : float in (0, 1], initial relaxation factor alpha (ref. Eq. 4.47)
    min_relaxation : float, the smallest alpha tried before giving up
    tolerance_pressure, tolerance_opening : eps_p, eps_u of ref. Eqs 4.43-4.44
    max_iterations : nonlinear iterations per attempt
    linear_rtol : relative residual asked of every GMRES solve
    linear_maxiter : GMRES restart cycles (of ``linear_restart`` iterations)
    stopping : ``"contraction"`` or ``"change"`` (:mod:`hmatddm.coupled.schemes` docstring)
    first_linear_rtol : relative residual of the first GMRES solve of each attempt (coupled
        schemes; at least ``linear_rtol``)
    provisional_linear_rtol : relative residual at which the first GMRES solve of a
        provisional solve (``solve_step(provisional=True)``) first pauses (then at tenfold
        smaller ones above ``first_linear_rtol``, :mod:`hmatddm.coupled.paused`): a growth pass
        decides on such a cheaper iterate when no tip is near its threshold;
        ``PendingSolve.refine`` and ``finish`` continue the same GMRES solve, so the
        iterates that follow are a plain solve's, bit for bit.
    linear_forcing : float in [0, 1), the forcing term of the inexact (Picard) iteration
        (coupled schemes): an iterate after an attempt's first is solved to
        ``linear_forcing`` times the relative change of the iterate before it, clipped to
        ``[linear_rtol, first_linear_rtol]``, since a linear solve far below the change
        the next iterate makes is work thrown away; an iterate that would be accepted
        from such a loose solve is not: the next is solved to ``linear_rtol`` (so the
        solution a step ends on, and its fluid budget, are those of full-accuracy solves).
        0: every iterate to ``linear_rtol`` (before issue 33).
    growth_check : ``"first"`` or ``"converged"``: on which iterate a simulation with the
        element front (and no natural fractures) decides a growth pass. ``"first"``: on the
        first (loose) iterate of a coupled solve, converging it only when no element grows
        (then checked again on the converged solution, so a step still ends on a converged
        solve that admits no growth); the solves of the meshes a step leaves behind cost one
        loose iteration instead of two or three (``solve_step(provisional=True)``).
        ``"converged"``: every solve converges first (before issue 17).
    relaxation_growth : float >= 1, the factor by which a simulation raises alpha again
        (up to ``relaxation``) after a step that converged without a restart. ``None``:
        2 for the coupled schemes, whose iteration needs no relaxation (ref. Sec. 4.5.3)
        and only halves alpha to get through a hard step (e.g. a contact active set
        that settles slowly), and 1 for the segregated schemes, which keep the alpha
        they needed, as in ref. Fig. 4.10.
    """

    scheme: str = SCHEME_DEFAULTS["scheme"]
    omega: float = SCHEME_DEFAULTS["omega"]
    relaxation: float = SCHEME_DEFAULTS["relaxation"]
    min_relaxation: float = SCHEME_DEFAULTS["min_relaxation"]
    tolerance_pressure: float = SCHEME_DEFAULTS["tolerance_pressure"]
    tolerance_opening: float = SCHEME_DEFAULTS["tolerance_opening"]
    max_iterations: int = SCHEME_DEFAULTS["max_iterations"]
    linear_rtol: float = SCHEME_DEFAULTS["linear_rtol"]
    linear_restart: int = SCHEME_DEFAULTS["linear_restart"]
    linear_maxiter: int = SCHEME_DEFAULTS["linear_maxiter"]
    relaxation_growth: float = SCHEME_DEFAULTS["relaxation_growth"]
    stopping: str = SCHEME_DEFAULTS["stopping"]
    first_linear_rtol: float = SCHEME_DEFAULTS["first_linear_rtol"]
    growth_check: str = SCHEME_DEFAULTS["growth_check"]
    provisional_linear_rtol: float = SCHEME_DEFAULTS["provisional_linear_rtol"]
    linear_forcing: float = SCHEME_DEFAULTS["linear_forcing"]

    def __post_init__(self):
        object.__setattr__(self, "scheme", SCHEME["scheme"].value("scheme", self.scheme))
        if self.relaxation_growth is None:
            object.__setattr__(self, "relaxation_growth", 2.0 if self.scheme in COUPLED_SCHEMES else 1.0)
        for name in ("relaxation_growth", "omega", "relaxation", "min_relaxation", "tolerance_pressure",
                     "tolerance_opening", "linear_rtol", "max_iterations", "linear_restart", "linear_maxiter",
                     "stopping", "first_linear_rtol", "growth_check", "provisional_linear_rtol",
                     "linear_forcing"):
            object.__setattr__(self, name, SCHEME[name].value(name, getattr(self, name)))


@dataclass
class StepProblem:
    """Everything one time step needs: ``A`` (an ElasticSolver), the flow model and
    the old state (widths lag inside :meth:`flow_matrices`)."""

    elastic: object          # ElasticSolver
    normals: np.ndarray      # (N, d)
    far_field: np.ndarray    # (dN,) f = -sigma_0 . n (ref. Eq. 4.4)
    flow: object             # LubricationModel
    compliance: np.ndarray   # (N,) c_i (ref. Eq. 4.49)
    dt: float
    width_old: np.ndarray    # (N,) w^n
    pressure_old: np.ndarray  # (N,) p^n
    leak_off_rate: np.ndarray  # (N,) Lambda_i
    contact: object = None     # ContactModel or None
    fixed_pressure: np.ndarray = None  # (N,) pressure of drained elements, NaN where free

    def __post_init__(self):
        self.n, self.d = self.normals.shape
        self.coupling = self.flow.coupling_matrix(self.dt)
        self.compliance_term = self.flow.areas * self.compliance / self.dt  # diagonal of C'
        self.fixed = np.zeros(self.n, bool) if self.fixed_pressure is None else np.isfinite(self.fixed_pressure)
        if np.any(self.fixed):
            keep = sp.diags((~self.fixed).astype(np.float64))
            self.coupling = (keep @ self.coupling).tocsr()
            self.compliance_term = np.where(self.fixed, 0.0, self.compliance_term)
        self._last_product = (None, None)  # (dd, A dd) of the last elastic product
        self.flow_factor = None  # the last iterate's FlowFactor (hmatddm.coupled.scaled_system)
        self._coupled_compliance = (None, None)  # (rows key, C A^-1 B) of the last active set
        self._inverse_b = None  # (rows key, X_0, W, F): A^-1 B = X_0 + W F of that set (coupled_compliance)
        self._base_compliance = (None, None)  # (X_0, C X_0) of the contact factor's base
        # (rows key, operator, blocks, their inverses) of the coupled system's scaling, for the
        # last set of statuses (hmatddm.coupled.scaled_system)
        self._scaling_blocks = None
        self._schur_factor = None  # the kept LU of the exact Schur complement (scaled_system.SchurFactor)

    def elastic_matvec(self, dd):
        """``A dd``; the last product is kept: an iteration's first residual (and the
        active-set update) is the product of the DD the previous GMRES solve checked last."""
        last_dd, last_product = self._last_product
        if last_dd is not None and np.array_equal(dd, last_dd):
            return last_product.copy()
        product = self.elastic.matvec(dd)
        self._last_product = (np.array(dd, dtype=np.float64), product.copy())
        return product

    def rows(self):
        """Contact rows of the current active set (None: every element fluid-loaded)."""
        return None if self.contact is None else self.contact.rows()

    def elastic_apply(self, dd, p, rows):
        """Elasticity rows ``A dd + B p`` (with contact: ``S (A dd + B p) + D dd``)."""
        traction = self.elastic_matvec(dd) + self.b_times(p)
        return traction if rows is None else rows.apply(traction, dd)

    def elastic_rhs(self, rows, p=None):
        """Right-hand side ``f`` (``f - B p`` with ``p``), through the contact rows."""
        rhs = self.far_field if p is None else self.far_field - self.b_times(p)
        return rhs if rows is None else rows.rhs(rhs)

    def update_contact(self, dd, p):
        """Active-set update after an iterate; the number of elements that changed (none,
        without a matvec, for rows that have no active set: ``contact.active_set`` False)."""
        if self.contact is None or not getattr(self.contact, "active_set", True):
            return 0
        residual = self.elastic_matvec(dd) + self.b_times(p) - self.far_field
        return self.contact.update(dd, residual)

    def coupled_compliance(self, rows):
        """The dense ``(N, N)`` matrix ``C A^-1 B`` (``C (S A + D)^-1 S B`` with contact ``rows``):
        how the flow rows see the pressures through the elasticity, whose ``D - C A^-1 B`` is
        the exact Schur complement of the coupled matrix. Computed for an exact operator of
        at most :data:`EXACT_SCHUR_MAX_ELEMENTS` elements (else None) from the low-rank update
        of a factorised base (:meth:`ElasticSolver.contact_update`): ``C X_0`` once per base,
        then ``(C W) F`` per set of statuses; kept for the last active set."""
        if self.n > EXACT_SCHUR_MAX_ELEMENTS or not self.elastic.operator.inverse_is_exact:
            return None
        key = None if rows is None else rows.key
        cached_key, value = self._coupled_compliance
        if value is not None and cached_key == key:
            return value
        x0, w, f = self.elastic.contact_update(rows).inverse_times_b(self.normals)
        self._inverse_b = (key, x0, w, f)
        if self._base_compliance[0] is not x0:
            self._base_compliance = (x0, np.asarray(self.coupling @ x0))
        value = self._base_compliance[1]
        if w is not None:
            with single_threaded_blas():  # small dense blocks: threads cost more than they save (hmatrix._threads)
                value = value + np.asarray(self.coupling @ w) @ f
        self._coupled_compliance = (key, value)
        return value

    def inverse_b_times(self, p, rows):
        """``A^-1 B p`` (``(S A + D)^-1 S B p`` with contact ``rows``) from the ``X_0 + W F`` of
        :meth:`coupled_compliance` (called first for these rows): a product with the dense
        ``(dN, N)`` ``X_0``, a quarter of an elasticity solve's work."""
        key, x0, w, f = self._inverse_b
        if key != (None if rows is None else rows.key):
            raise RuntimeError("inverse_b_times before coupled_compliance for these contact rows")
        value = x0 @ p
        return value if w is None else value + w @ (f @ p)

    def width(self, dd):
        return np.sum(dd.reshape(self.n, self.d) * self.normals, axis=1)

    def b_times(self, p):
        return (self.normals * p[:, None]).ravel()

    def flow_matrices(self, dd, p=None):
        """``D`` and ``g`` at the iterate ``dd`` (widths lagged) and ``p`` (where a power-law
        flux is linearised, :mod:`hmatddm.flow.lubrication`; default the old pressure)."""
        matrix, rhs = self.flow.assemble(self.width(dd), self.width_old, self.pressure_old, self.dt,
                                         self.leak_off_rate, pressure_iterate=p)
        if np.any(self.fixed):  # drained elements: p_i = p_fixed, scaled like the other rows
            matrix = matrix.tocsr()
            diagonal = matrix.diagonal()
            scale = float(np.mean(np.abs(diagonal[~self.fixed]))) if np.any(~self.fixed) else 1.0
            row = np.repeat(np.arange(self.n), np.diff(matrix.indptr))
            on_diagonal = np.flatnonzero(matrix.indices == row)
            if on_diagonal.size == self.n:  # every diagonal stored: the rows rescaled in place
                matrix = matrix.copy()
                matrix.data[self.fixed[row]] = 0.0
                matrix.data[on_diagonal] += scale * self.fixed[row[on_diagonal]]
            else:
                free = (~self.fixed).astype(np.float64)
                matrix = (sp.diags(free) @ matrix + sp.diags(scale * self.fixed)).tocsr()
            rhs = np.where(self.fixed, scale * np.nan_to_num(self.fixed_pressure), rhs)
        return matrix, rhs
