"""Preconditioners built from the exact near field stored in an HMatrix.

All return a ``scipy.sparse.linalg.LinearOperator`` approximating ``A^{-1}``, in the
original (element-major) ordering, ready to pass as ``M`` to :func:`gmres`.
"""

import logging

import numpy as np
import scipy.sparse.linalg as spla

from ..errors import InputError

from .block_ilu import block_ilu0, block_ilu_solve, block_ilu_solve_staged
from .dissection import dissection_depth, nested_dissection, permuted_pattern

logger = logging.getLogger(__name__)

# Settings of default_preconditioner: block ILU(0) (near_field_block_ilu) of the near
# field without the element blocks below `threshold` of their diagonal blocks
# (||A_ij||_F < threshold sqrt(||A_ii||_F ||A_jj||_F); the near field of a DDM kernel
# decays like 1/r^3, so this keeps the nearest neighbours; setup cost linear in N).
# Whole blocks are kept or dropped and factored, so the iterations do not depend on
# the frame of the unknowns: a penny of radius R needs 7 GMRES iterations aligned and
# tilted at h = R/8, 11 and 11 at R/16 (eps 1e-6, rtol 1e-10; the scalar spilu with
# entry-wise drop rules used before: 9 vs 13 and 13 vs 20).
# Measured on a planar 3D DDM crack, eps=1e-4, leaf_size=32, rtol 1e-8, 2 threads
# (block Jacobi -> this; the former spilu default, threshold 1e-2 entry-wise,
# drop_tol 1e-3, fill_factor 5, in brackets):
# N=10k: 43 -> 18 iterations (23), setup 0.35 s (1.2 s), factors 25 MB, setup + GMRES
# 1.4 s (2.4 s); N=40k: 61 -> 27 (31), setup 1.7 s (2.5 s), factors 100 MB (5% of the
# H-matrix), setup + GMRES 14.7 s (16.6 s). Cloud of vertical fractures, N=10k: 48 ->
# 19 (24). Threshold 1e-2: 24 / 33 iterations with a third of the memory; 1e-3: 16 at
# 10k with twice the memory and setup.
DEFAULT_ILU = {"threshold": 3e-3}

# Settings of the two-level preconditioner (two_level): aggregates of at most 256
# elements (a balanced tree gives 128-256), constant + 2 linear functions per aggregate
# and component; default_preconditioner uses it from TWO_LEVEL_MIN_ELEMENTS elements
# on. Measured (benchmarks/RESULTS.md, "Solver at scale"; CPU seconds, eps 1e-4, rtol
# 1e-8): planar crack 10k: 7 iterations instead of 18, but per solve 2.3 s + 1.0 s
# setup against 2.6 s; 40k: 7 instead of 27, 9.1 s per solve against 14.9 s (setup
# 6.9 s more, paid once per operator); cloud of tall fractures 10k: 13 instead of 19,
# 2.5 s against 1.9 s per solve (each iteration costs two H-matvecs). Hence only
# from 20 000 elements, where the near-field ILU's iterations keep growing.
TWO_LEVEL = {"aggregate_size": 256, "n_functions": 3}
TWO_LEVEL_MIN_ELEMENTS = 20_000


def _check_hmatrix(hmatrix):
    from .hmatrix import HMatrix

    if not isinstance(hmatrix, HMatrix):
        raise InputError(f"hmatrix must be an HMatrix, got {type(hmatrix).__name__}")


def block_jacobi(hmatrix):
    """Inverse of each element's d x d diagonal block (pseudo-inverse if singular).

    Setup O(N d^3), application O(N d^2).
    """
    _check_hmatrix(hmatrix)
    blocks = hmatrix.element_diagonal_blocks()
    try:
        inverse = np.linalg.inv(blocks)
    except np.linalg.LinAlgError:
        inverse = np.linalg.pinv(blocks)
    if not np.all(np.isfinite(inverse)):
        inverse = np.linalg.pinv(blocks)
    n, d = blocks.shape[0], hmatrix.dof

    def apply(x):
        x = np.asarray(x, dtype=np.float64).reshape(n, d, -1)
        return np.einsum("epq,eqk->epk", inverse, x).reshape(n * d, -1)

    return spla.LinearOperator(hmatrix.shape, matvec=apply, matmat=apply, dtype=np.float64)


def near_field_ilu(hmatrix, drop_tol=1e-4, fill_factor=10.0, part="near", threshold=0.0):
    """Incomplete LU (scipy ``spilu``, SuperLU) of the near-field matrix.

    ``part`` and ``threshold`` select the entries (see ``HMatrix.near_field_csr``:
    whole element blocks are kept or dropped); ``drop_tol`` and ``fill_factor`` are
    passed to spilu, whose drop rules are entry-wise, so its iterations depend on
    the frame of the unknowns (:func:`near_field_block_ilu` does not). Cost grows
    with the near field: about nnz * fill_factor memory.
    """
    _check_hmatrix(hmatrix)
    if not (isinstance(drop_tol, (int, float, np.floating)) and 0.0 <= drop_tol < 1.0):
        raise InputError(f"drop_tol must be in [0, 1), got {drop_tol!r}")
    if not (isinstance(fill_factor, (int, float, np.floating)) and fill_factor >= 1.0):
        raise InputError(f"fill_factor must be >= 1, got {fill_factor!r}")
    matrix = hmatrix.near_field_csr(part=part, threshold=threshold).tocsc()
    factor = spla.spilu(matrix, drop_tol=float(drop_tol), fill_factor=float(fill_factor))
    return spla.LinearOperator(hmatrix.shape, matvec=factor.solve, dtype=np.float64)


def near_field_lu(hmatrix, part="near"):
    """Sparse LU (scipy ``splu``) of the near-field matrix: exact inverse of the near field.

    Best for small and medium problems (fill-in grows fast with N for part="near");
    ``part="leaf_diagonal"`` factors only the leaf x leaf diagonal blocks, which is
    cheap at any N: O(N * (leaf_size * d)^2).
    """
    _check_hmatrix(hmatrix)
    matrix = hmatrix.near_field_csr(part=part).tocsc()
    factor = spla.splu(matrix)
    return spla.LinearOperator(hmatrix.shape, matvec=factor.solve, dtype=np.float64)


def near_field_block_ilu(hmatrix, threshold=0.0, part="near", depth=None):
    """Block ILU(0) (d x d element blocks) of the near-field matrix.

    The pattern is that of ``HMatrix.near_field_bsr(part, threshold)`` (element
    blocks below ``threshold`` of their diagonal blocks dropped, by Frobenius norm),
    factored without fill-in, with whole-block pivots: the preconditioner commutes with
    rotations of the element frames (see :mod:`hmatddm.hmatrix.block_ilu`). Setup
    O(kept blocks * neighbours * d^3), application O(kept blocks * d^2), memory one copy
    of the kept blocks.

    ``depth`` (default :func:`~hmatddm.hmatrix.dissection.dissection_depth`: 0 below
    5000 elements): with ``depth > 0`` the factors are in the nested-dissection order of
    the top ``depth`` cuts of the cluster tree (:mod:`hmatddm.hmatrix.dissection`), and
    an application runs on the threads the matvec would use, with the same result on
    any number of them; with 0, in the original element order, on one thread.

    Raises RuntimeError when a pivot block is missing or singular.
    """
    from ._threads import SERIAL_MATVEC_ENTRIES, threads_for

    _check_hmatrix(hmatrix)
    matrix = hmatrix.near_field_bsr(part=part, threshold=threshold)
    indptr = matrix.indptr.astype(np.int64)
    indices = matrix.indices.astype(np.int64)
    data = np.ascontiguousarray(matrix.data)
    n_elements, d = hmatrix.n_elements, hmatrix.dof
    depth = dissection_depth(n_elements) if depth is None else int(depth)
    dissection = None
    if depth > 0:
        dissection = nested_dissection(hmatrix.tree, indptr, indices, depth)
        indptr, indices, data = permuted_pattern(indptr, indices, data, dissection.order)
    values, inverse_diagonal, diagonal_position, failed = block_ilu0(indptr, indices, data)
    if failed >= 0:
        element = failed if dissection is None else int(dissection.order[failed])
        raise RuntimeError(f"block ILU: the pivot block of element {element} is missing or singular")
    n = hmatrix.shape[0]

    def solve_one(rhs):
        if dissection is None:
            return block_ilu_solve(indptr, indices, values, inverse_diagonal, diagonal_position, rhs)
        permuted = np.ascontiguousarray(rhs.reshape(n_elements, d)[dissection.order].reshape(-1))
        with threads_for(values.size, SERIAL_MATVEC_ENTRIES):
            solution = block_ilu_solve_staged(indptr, indices, values, inverse_diagonal, diagonal_position, permuted,
                                              dissection.stage_ptr, dissection.range_start, dissection.range_stop)
        out = np.empty_like(solution)
        out.reshape(n_elements, d)[dissection.order] = solution.reshape(n_elements, d)
        return out

    def apply(x):
        x = np.ascontiguousarray(x, dtype=np.float64)
        if x.ndim == 1:
            return solve_one(x)
        return np.column_stack([solve_one(np.ascontiguousarray(column)) for column in x.reshape(n, -1).T])

    operator = spla.LinearOperator(hmatrix.shape, matvec=apply, matmat=apply, dtype=np.float64)
    operator.nbytes = int(values.nbytes + inverse_diagonal.nbytes + indices.nbytes + indptr.nbytes)
    operator.dissection = dissection
    return operator


def two_level(hmatrix, smoother=None, aggregate_size=None, n_functions=None, multiplicative=True):
    """Near-field block ILU plus a Galerkin coarse correction built from the H-matrix
    (:mod:`hmatddm.hmatrix.coarse_space`): GMRES iterations that do not grow with N.

    ``smoother``: the fine-level preconditioner (default: the thresholded block ILU of
    :func:`default_preconditioner`'s near field). ``aggregate_size`` (default
    ``TWO_LEVEL["aggregate_size"]``): largest cluster forming one coarse aggregate;
    ``n_functions`` (1, 2 or 3; default ``TWO_LEVEL["n_functions"]``): constant, plus
    linear functions along the aggregate's principal axes. ``multiplicative=True``
    costs one extra H-matvec per application and halves the iterations against the
    additive form. Setup: one pass over the stored blocks and a dense LU of the coarse
    matrix (n_aggregates * n_functions * d square). The returned operator has a
    ``coarse`` attribute (sizes, bytes).
    """
    from .coarse_space import two_level_preconditioner

    _check_hmatrix(hmatrix)
    if smoother is None:
        smoother = near_field_block_ilu(hmatrix, **DEFAULT_ILU)
    return two_level_preconditioner(
        hmatrix, smoother,
        aggregate_size=TWO_LEVEL["aggregate_size"] if aggregate_size is None else aggregate_size,
        n_functions=TWO_LEVEL["n_functions"] if n_functions is None else n_functions,
        multiplicative=multiplicative)


def default_preconditioner(hmatrix):
    """The two-level preconditioner (:func:`two_level`) from ``TWO_LEVEL_MIN_ELEMENTS``
    elements on, else the thresholded near-field block ILU (``DEFAULT_ILU``); checked
    on one product.

    Falls back, with a logged warning, to :func:`block_jacobi` when the incomplete
    factorisation fails (singular pivot block) or gives non-finite values.
    """
    _check_hmatrix(hmatrix)
    try:
        preconditioner = near_field_block_ilu(hmatrix, **DEFAULT_ILU)
        probe_rhs = hmatrix @ np.ones(hmatrix.shape[0])
        if hmatrix.n_elements >= TWO_LEVEL_MIN_ELEMENTS:
            try:
                combined = two_level(hmatrix, smoother=preconditioner)
                if np.all(np.isfinite(combined @ probe_rhs)):
                    return combined
                reason = "non-finite values"
            except (np.linalg.LinAlgError, ValueError) as error:
                reason = str(error)
            logger.warning("two-level coarse correction failed (%s); using the near-field block ILU alone", reason)
        probe = preconditioner @ probe_rhs
        if np.all(np.isfinite(probe)):
            return preconditioner
        reason = "non-finite values"
    except RuntimeError as error:
        reason = str(error)
    logger.warning("near-field ILU failed (%s); using block Jacobi instead", reason)
    return block_jacobi(hmatrix)
