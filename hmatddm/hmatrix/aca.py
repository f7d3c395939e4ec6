"""Adaptive cross approximation (ACA) of d x d tensor blocks, with recompression: the
entry points (:func:`aca_tensor` for tests and explicit blocks, :func:`aca_compressed`
and its compiled form :func:`_aca_compressed` for the H-matrix build) and the ACA steps
the compiled drivers take as first-class functions (:data:`ACA_STEPS`,
:func:`aca_steps`).

The work is split by job:

* :mod:`.aca_pivoting`: whole-element pivots (the d rows of row element i and the d
  columns of column element j taken together, the d x d pivot block pseudo-inverted by
  SVD: a scalar partial ACA is wrong for tensor kernels whose components decouple), the
  residual updates and the choice of the next pivot;
* :mod:`.aca_loop`: the tensor cross loop, a resumable state machine with the stopping
  test, the convergence check of ACA+ (Grasedyck 2005; Bebendorf's "ACA with a check")
  and the give-up on blocks the ACA cannot compress (the callers store those dense);
* :mod:`.recompression`: truncation of the singular-value tail of U V^T at eps, which
  typically halves the ACA rank at no accuracy cost.

Conventions: a block is given by its row elements (m_e of them, d_r unknowns each)
and column elements (n_e, d_c unknowns each: a rectangular matrix, e.g. stress
components at points x DD components of elements, has d_r != d_c; a square operator
d_r = d_c = d); it has m = d_r*m_e rows and n = d_c*n_e columns and is approximated by
U V^T with U (m x k) and V (n x k). A pivot is a d_r x d_c block. The ACA and the recompression work on the transposed
factors (``ut`` k x m, ``vt`` k x n, one vector per contiguous row) so that every
inner loop is contiguous. The residual updates and the recompression's projections are
BLAS products; the build runs them on one BLAS thread (assembly._run_parallel), and so do
the Python entry points here, so that the factors never depend on the BLAS thread count.
"""

import numpy as np
from numba import njit, types

from ._threads import single_threaded_blas
from .aca_loop import (_RANK, ACA_ADVANCE_SIGNATURE, ACA_START_SIGNATURE, RECOMPRESS_STATE_SIGNATURE, _aca_loop,
                       _aca_run, aca_advance, aca_gave_up, aca_result, aca_start)
from .recompression import recompress_gram
from ..compiled import INDEX, compiled_for_data


# An ACA used as it is (no recompression: the one-shot product, hmatrix/product.py, and
# the field evaluation of hmatddm/elasticity/fields.py) runs at ACA_TOLERANCE_FACTOR * eps: the ACA
# stopping test (size of the last update) underestimates the error by up to ~10x on some
# blocks, and the tighter ACA removes that.
ACA_TOLERANCE_FACTOR = 0.1
# The H-matrix build (:func:`aca_compressed`) runs the ACA at RECOMPRESSED_ACA_FACTOR * eps
# and the recompression truncates at eps. A looser ACA costs less (at 0.1 eps its rank
# overshoots the stored one ~2x: 10k cloud, eps 1e-4, ACA rank 50.6 for 26.6 stored;
# planar crack 35.6 for 19.0), and at 0.3 eps the stored ranks were the same and the
# stored block errors against the exact blocks stayed within 1.11 eps (every 9th far
# block of both). But the error of the product with a smooth field grew: 10k planar
# crack 1.2e-6 -> 1.7e-6 (0.2 eps) and 2.1e-6 (0.3 eps), 40k 2.2e-6 -> 3.4e-6 (0.3 eps);
# the ACA leaves its error in the smooth directions that the truncation of the SVD tail
# spares. So the build keeps 0.1 (benchmarks/RESULTS.md, "Issue 17 item 2: the far-field
# ACA"; `bench_hmatrix.py --aca-study`).
RECOMPRESSED_ACA_FACTOR = 0.1


def aca_tensor(kernel, data, row_elements, col_elements, dof, eps, col_dof=0):
    """Partial ACA with whole-element pivots of the block rows x cols (original indices),
    ``dof`` unknowns per row element and ``col_dof`` per column element (0: ``dof``).

    Each step evaluates one row element (d rows) and one column element (d columns)
    of the residual: O((m + n) * d) kernel entries and O((m + n) * k * d) flops at
    rank k. The next row element is the one with the largest residual in the last
    pivot columns; a negligible residual row (a zero part of the block) is skipped
    by probing an unvisited column for a better row instead of stopping. Stops when
    the last update satisfies ||U_k V_k^T||_F <= eps ||S_k||_F (the norm of the
    approximation S_k is updated incrementally, cross terms included) and the
    convergence check passes (unvisited probe rows and columns with a residual
    below CHECK_FACTOR * eps ||S_k||_F, extrapolated to the block). When it gives up
    (every row or column element used before convergence, or rank min(m, n): see
    :mod:`.aca_loop`) the block is evaluated exactly and returned as an exact
    factorisation (U = block, V = identity, or U = identity, V = block^T; rank
    min(m, n)), as the build stores it dense.

    Returns (U, V, rank) with U (m x rank), V (n x rank); rank 0 for a zero block.
    Compiled once per data type (cached on disk, :func:`_for_data`).
    """
    col_dof = col_dof if col_dof > 0 else dof
    compiled = _for_data(_aca_tensor, data, 2)
    with single_threaded_blas():  # as in the build (see recompression.recompress)
        return compiled(kernel, data, _index(row_elements), _index(col_elements), int(dof), int(col_dof), float(eps),
                        *aca_steps()[:2])


def _aca_tensor(kernel, data, row_elements, col_elements, dof, col_dof, eps, start, advance):
    """:func:`aca_tensor` (njit source, compiled by :func:`_for_data`)."""
    ut, vt, ints = _aca_loop(kernel, data, row_elements, col_elements, dof, col_dof, eps, start, advance)
    if aca_gave_up(ints):
        m, n = dof * row_elements.shape[0], col_dof * col_elements.shape[0]
        block = np.empty((m, n))
        kernel(data, row_elements, col_elements, block)
        if m <= n:
            return np.eye(m), np.ascontiguousarray(block.T), m
        return block, np.eye(n), n
    return aca_result(ut, vt, ints)


def aca_compressed(kernel, data, row_elements, col_elements, row_dof, col_dof, eps):
    """What the H-matrix build stores for an admissible block: the ACA of
    :func:`aca_tensor` at ``RECOMPRESSED_ACA_FACTOR * eps``, recompressed at ``eps``.

    Returns the TRANSPOSED factors (U'^T, V'^T) with ``rank`` rows in use, and the rank;
    rank -1 (and empty factors) when the ACA gave up: the block is to be stored dense.
    The build driver (hmatrix/assembly.py) calls :func:`_aca_compressed`, this function
    with the steps given as first-class functions; so does this function, compiled once
    per data type (cached on disk, :func:`_for_data`).
    """
    compiled = _for_data(_aca_compressed.py_func, data, 3)
    with single_threaded_blas():  # as in the build (see recompression.recompress)
        return compiled(kernel, data, _index(row_elements), _index(col_elements), int(row_dof), int(col_dof),
                        float(eps), *aca_steps())


@njit(nogil=True)
def _aca_compressed(kernel, data, row_elements, col_elements, row_dof, col_dof, eps, start, advance, recompress):
    """:func:`aca_compressed` with the ACA steps (:func:`aca_start`, :func:`aca_advance`)
    and the recompression (:func:`recompress_state`) as arguments (see :func:`.aca_loop._aca_loop`)."""
    ut, vt, gram, ints = _aca_run(kernel, data, row_elements, col_elements, row_dof, col_dof,
                                  RECOMPRESSED_ACA_FACTOR * eps, start, advance)
    if aca_gave_up(ints):
        return np.zeros((0, ut.shape[1])), np.zeros((0, vt.shape[1])), -1
    return recompress(ut, vt, gram, ints, eps)


@njit(cache=True, nogil=True)
def recompress_state(ut, vt, gram, ints, eps):
    """The recompression of a finished ACA state, with the Gram matrix of U that the ACA
    kept (:func:`recompress_gram`): (U'^T, V'^T, rank')."""
    return recompress_gram(ut, vt, gram, ints[_RANK], eps)


# -- entry points for Python callers (tests, explicit blocks) ------------------------------
#: The ACA steps the compiled drivers take as first-class functions (see aca_loop._aca_loop), and
#: their types.
ACA_STEPS = (aca_start, aca_advance, recompress_state)
ACA_STEP_TYPES = (types.FunctionType(ACA_START_SIGNATURE), types.FunctionType(ACA_ADVANCE_SIGNATURE),
                  types.FunctionType(RECOMPRESS_STATE_SIGNATURE))


def aca_steps():
    """:data:`ACA_STEPS`, each compiled for its signature (:data:`ACA_STEP_TYPES`) on the
    first call (from the on-disk cache when it holds them): pass these, not the bare
    dispatchers, to the compiled drivers, and call this before calling a step from
    Python, so that the one compiled version has the declared signature."""
    for step, kind in zip(ACA_STEPS, ACA_STEP_TYPES):
        step.get_compile_result(kind.signature)  # a dictionary look-up once compiled
    return ACA_STEPS


def _index(elements):
    return np.ascontiguousarray(elements, dtype=np.int64)


def _for_data(function, data, n_steps):
    """``function`` (njit source taking ``(kernel, data, rows, cols, row_dof, col_dof, eps,
    *steps)``, the steps being the first ``n_steps`` of :data:`ACA_STEPS`) compiled for
    this data type by :func:`hmatddm.compiled.compiled_for_data`, like the build
    driver: cached on disk, ~3 s of cold compile per data type, instead of ~10 s per kernel
    in every process when the kernel dispatcher is an argument."""
    return compiled_for_data(function, data, (INDEX, INDEX, types.int64, types.int64, types.float64)
                             + ACA_STEP_TYPES[:n_steps])
