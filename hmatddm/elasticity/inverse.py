"""Solving with any elasticity operator through its approximate inverse.

Every operator (:class:`~hmatddm.elasticity.operator.ElasticityOperator` of either backend,
:class:`~hmatddm.elasticity.extended.ExtendedElasticityOperator`) offers ``solve``,
``approximate_inverse``, ``modified_inverse(rows)`` and ``inverse_is_exact``; this module
holds what they share: the direct-or-GMRES solve given an approximate inverse, and the
ILU of a contact-modified near field (``S A_near + D``, see :mod:`hmatddm.coupled.contact`).
"""
import numpy as np
import scipy.sparse.linalg as spla
from scipy.sparse.linalg import LinearOperator

from ..errors import ConvergenceError


def solve_with_inverse(operator, rhs, inverse, exact, x0=None, rtol=1e-9, restart=100, maxiter=20):
    """``(x, info)`` solving ``operator x = rhs`` given an approximate inverse (a callable).

    ``exact``: the inverse is exact (a direct factorisation): ``x = inverse(rhs)``, ``info``
    ``{"iterations": 0}`` (no residual: it would cost a product). Otherwise GMRES
    (:func:`hmatddm.hmatrix.gmres`, from ``x0``) preconditioned by ``inverse``; ``info`` is
    its dict (``iterations``, ``residual``, ...). Raises ConvergenceError when GMRES stops
    above ``rtol`` or ``x`` is not finite.
    """
    rhs = np.asarray(rhs, dtype=np.float64).ravel()
    if exact:
        x, info = inverse(rhs), {"iterations": 0}
    else:
        from ..hmatrix import gmres

        preconditioner = LinearOperator(operator.shape, matvec=inverse, dtype=np.float64)
        x, info = gmres(operator, rhs, M=preconditioner, rtol=rtol, restart=restart, maxiter=maxiter, x0=x0)
    if not np.all(np.isfinite(x)):
        raise ConvergenceError("the solution contains NaN or inf", residual=float("nan"))
    return x, info


# scalar ILU of the contact-modified near field (its rows mix element frames, so the
# block ILU of the default preconditioner does not apply); the entries kept are those of
# the default preconditioner's block threshold
_CONTACT_ILU = {"drop_tol": 1e-3, "fill_factor": 5.0}


def modified_near_field_inverse(operator, rows):
    """ILU of ``S A_near + D`` (the default preconditioner's near field with contact rows),
    falling back to block Jacobi of the modified diagonal blocks."""
    from ..hmatrix.preconditioners import DEFAULT_ILU

    hmatrix = operator.hmatrix
    matrix = rows.modify_sparse(hmatrix.near_field_csr(part="near", threshold=DEFAULT_ILU["threshold"]))
    try:
        factor = spla.spilu(matrix, drop_tol=_CONTACT_ILU["drop_tol"], fill_factor=_CONTACT_ILU["fill_factor"])
        inverse = LinearOperator(operator.shape, matvec=factor.solve, dtype=np.float64)
        if np.all(np.isfinite(inverse @ np.ones(operator.shape[0]))):
            return inverse
    except RuntimeError:
        pass
    blocks = np.linalg.pinv(rows.modify_blocks(operator.element_diagonal_blocks()))
    n, d = blocks.shape[0], blocks.shape[1]
    return LinearOperator(operator.shape, dtype=np.float64,
                          matvec=lambda x: np.einsum("eij,ej->ei", blocks, np.reshape(x, (n, d))).ravel())


def near_field_blocks(hmatrix):
    """``(indptr, indices, block_row, blocks)`` (int64 arrays, blocks (nnz, d, d)) of the
    near-field element blocks the default preconditioner keeps
    (:meth:`~hmatddm.hmatrix.HMatrix.near_field_bsr`), the input of
    :func:`modified_near_field_block_ilu`."""
    from ..hmatrix.preconditioners import DEFAULT_ILU

    near = hmatrix.near_field_bsr(part="near", threshold=DEFAULT_ILU["threshold"])
    indptr = near.indptr.astype(np.int64)
    block_row = np.repeat(np.arange(indptr.size - 1), np.diff(indptr))
    return indptr, near.indices.astype(np.int64), block_row, near.data


def modified_near_field_block_ilu(operator, rows):
    """Block ILU(0) (:mod:`hmatddm.hmatrix.block_ilu`, compiled, no fill-in) of ``S A_near + D``
    on the element blocks the default preconditioner keeps, as a LinearOperator; the scalar
    ILU of :func:`modified_near_field_inverse` when a pivot block is missing or singular.

    For the parts of a planar crack (:class:`~hmatddm.elasticity.planar.OperatorPart`), whose
    rows change at every front iteration of the asymptotic front: on a 8.5k-element disc with
    its outer ring prescribed, 0.01 s against SuperLU's 0.20 s (drop 1e-3, fill 5), for 21
    GMRES iterations against 19 (benchmarks/RESULTS.md, issue 33)."""
    from ..hmatrix.block_ilu import block_ilu0, block_ilu_solve

    near_field = getattr(operator, "near_field_blocks", None)
    if near_field is not None:  # kept by the operator: the rows change, the near field does not
        indptr, indices, block_row, near_data = near_field()
    else:
        indptr, indices, block_row, near_data = near_field_blocks(operator.hmatrix)
    select = rows.select[block_row]
    data = select * near_data if rows.d == 1 else np.einsum("bij,bjk->bik", select, near_data)
    diagonal = indices == block_row
    data[diagonal] += rows.direct[block_row[diagonal]]
    values, inverse_diagonal, diagonal_position, failed = block_ilu0(indptr, indices, np.ascontiguousarray(data))
    if failed >= 0:
        return modified_near_field_inverse(operator, rows)
    return LinearOperator(operator.shape, dtype=np.float64, matvec=lambda x: block_ilu_solve(
        indptr, indices, values, inverse_diagonal, diagonal_position, np.ascontiguousarray(x, dtype=np.float64).ravel()))
