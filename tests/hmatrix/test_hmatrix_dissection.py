"""Nested dissection of the near field and the block ILU sweeps it lets run on several
threads (hmatddm/hmatrix/dissection.py, block_ilu.block_ilu_solve_staged)."""
import numba
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.hmatrix import _threads
from hmatddm.hmatrix.block_ilu import block_ilu0, block_ilu_solve, block_ilu_solve_staged
from hmatddm.hmatrix.dissection import (DISSECTION_MIN_ELEMENTS, MAX_DEPTH, dissection_depth, nested_dissection,
                                        permuted_pattern)
from hmatddm.hmatrix.preconditioners import DEFAULT_ILU, near_field_block_ilu
from hmatddm.hmatrix.solvers import gmres

SIDE = 40


@pytest.fixture(scope="module")
def crack():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], float(SIDE), float(SIDE), SIDE, SIDE)
    operator = hd.ElasticityOperator(mesh, hd.Elastic(10e9, 0.25), backend="hmatrix", eps=1e-6, leaf_size=32)
    near = operator.hmatrix.near_field_bsr(threshold=DEFAULT_ILU["threshold"])
    return mesh, operator, near


@pytest.mark.parametrize("depth", [0, 1, 2, 3])
def test_ranges_of_a_stage_are_not_coupled(crack, depth):
    _, operator, near = crack
    indptr, indices = near.indptr.astype(np.int64), near.indices.astype(np.int64)
    dissection = nested_dissection(operator.hmatrix.tree, indptr, indices, depth)
    n = operator.hmatrix.n_elements
    assert np.array_equal(np.sort(dissection.order), np.arange(n))
    assert dissection.range_start[0] == 0 and dissection.range_stop[-1] == n
    assert np.array_equal(dissection.range_start[1:], dissection.range_stop[:-1])
    stage_of, range_of = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    for stage in range(dissection.n_stages):
        for r in range(dissection.stage_ptr[stage], dissection.stage_ptr[stage + 1]):
            stage_of[dissection.range_start[r]:dissection.range_stop[r]] = stage
            range_of[dissection.range_start[r]:dissection.range_stop[r]] = r
    position = dissection.position
    rows = position[np.repeat(np.arange(n), np.diff(indptr))]
    cols = position[indices]
    same_stage = stage_of[rows] == stage_of[cols]
    assert np.all(range_of[rows][same_stage] == range_of[cols][same_stage])
    if depth == 0:
        assert dissection.n_stages == 1 and dissection.separator_rows == 0
    else:
        assert dissection.stage_ptr[1] == 2 ** depth  # the domains of a balanced tree
        assert 0 < dissection.separator_rows < 0.3 * n


def test_staged_sweep_is_the_sequential_sweep_bit_for_bit_on_any_thread_count(crack, monkeypatch):
    _, operator, near = crack
    indptr, indices = near.indptr.astype(np.int64), near.indices.astype(np.int64)
    dissection = nested_dissection(operator.hmatrix.tree, indptr, indices, 2)
    indptr, indices, data = permuted_pattern(indptr, indices, np.ascontiguousarray(near.data), dissection.order)
    values, inverse_diagonal, diagonal_position, failed = block_ilu0(indptr, indices, data)
    assert failed < 0
    rhs = np.random.default_rng(1).normal(size=operator.shape[0])
    sequential = block_ilu_solve(indptr, indices, values, inverse_diagonal, diagonal_position, rhs)
    staged = {}
    for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
        numba.set_num_threads(threads)
        staged[threads] = block_ilu_solve_staged(indptr, indices, values, inverse_diagonal, diagonal_position, rhs,
                                                 dissection.stage_ptr, dissection.range_start, dissection.range_stop)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    for result in staged.values():
        assert np.array_equal(result, sequential)


def test_dissected_ilu_preconditions_gmres_to_the_dense_solution(crack, monkeypatch):
    mesh, operator, _ = crack
    monkeypatch.setattr(_threads, "ADAPT_TO_LOAD", False)
    monkeypatch.setattr(_threads, "SERIAL_MATVEC_ENTRIES", 0)
    traction = -1e6 * mesh.normals.ravel()
    dense = np.linalg.solve(operator.hmatrix.to_dense(), traction)
    iterations = {}
    for depth in (0, 2):
        preconditioner = near_field_block_ilu(operator.hmatrix, depth=depth, **DEFAULT_ILU)
        probe = np.random.default_rng(2).normal(size=operator.shape[0])
        assert np.all(np.isfinite(preconditioner @ probe))
        x, info = gmres(operator.hmatrix, traction, M=preconditioner, rtol=1e-10, restart=100)
        assert info["converged"]
        iterations[depth] = info["iterations"]
        assert np.linalg.norm(x - dense) <= 1e-5 * np.linalg.norm(dense)
    assert iterations[2] <= iterations[0] + 3  # the ordering costs at most a few iterations


def test_default_depth():
    assert dissection_depth(DISSECTION_MIN_ELEMENTS - 1) == 0
    assert dissection_depth(DISSECTION_MIN_ELEMENTS) == 1
    assert dissection_depth(10_000) == 2
    assert dissection_depth(40_000) == 4
    assert dissection_depth(10**7) == MAX_DEPTH


def test_depth_out_of_range_is_refused(crack):
    _, operator, near = crack
    with pytest.raises(ValueError, match="depth"):
        nested_dissection(operator.hmatrix.tree, near.indptr, near.indices, MAX_DEPTH + 1)
