"""Near-field preconditioners and the checked GMRES wrapper of hmatddm.hmatrix."""

import logging

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from hmatddm.errors import ConvergenceError, InputError
from hmatddm.hmatrix import (HMatrix, block_jacobi, default_preconditioner, gmres, near_field_block_ilu,
                             near_field_ilu, near_field_lu)
from hmatddm.hmatrix.example_kernels import matrix_generator, tensor_generator


@pytest.fixture(scope="module")
def spd_problem():
    """A well-conditioned symmetric positive definite kernel system, exp(-r / 0.05) + 0.5 I
    on 1500 points, whose near field dominates (as in DDM, where near-field
    preconditioners are meant to work)."""
    rng = np.random.default_rng(0)
    points = rng.random((1500, 3))
    r = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=2)
    dense = np.exp(-r / 0.05) + 0.5 * np.eye(1500)
    h = HMatrix.build(matrix_generator(dense, points), eps=1e-8, leaf_size=32)
    b = rng.standard_normal(1500)
    return h, dense, b


def test_preconditioned_gmres_agrees_with_dense_solve(spd_problem):
    h, dense, b = spd_problem
    assert h.stats["n_lowrank_blocks"] > 0
    x, info = gmres(h, b, M=default_preconditioner(h), rtol=1e-10, restart=50, maxiter=10)
    exact = np.linalg.solve(dense, b)
    assert np.linalg.norm(x - exact) / np.linalg.norm(exact) < 1e-6
    assert info["converged"] and info["residual"] <= 1e-10
    assert info["residual"] == pytest.approx(np.linalg.norm(b - h @ x) / np.linalg.norm(b))
    assert 0 < info["iterations"] < 20


@pytest.mark.parametrize("make", [
    lambda h: None,
    block_jacobi,
    near_field_ilu,
    near_field_lu,
    lambda h: near_field_lu(h, part="leaf_diagonal"),
    lambda h: near_field_ilu(h, part="leaf_diagonal", drop_tol=1e-3, fill_factor=5),
    lambda h: near_field_block_ilu(h, threshold=1e-2),
])
def test_every_preconditioner_converges(spd_problem, make):
    h, dense, b = spd_problem
    M = make(h)
    if M is not None:
        assert isinstance(M, spla.LinearOperator) and M.shape == h.shape
    x, info = gmres(h, b, M=M, rtol=1e-9, restart=60, maxiter=10)
    assert np.linalg.norm(dense @ x - b) / np.linalg.norm(b) < 1e-7


def test_near_field_preconditioners_cut_iterations(spd_problem):
    h, _, b = spd_problem
    _, plain = gmres(h, b, rtol=1e-9, restart=100, maxiter=10)
    _, lu = gmres(h, b, M=near_field_lu(h), rtol=1e-9, restart=100, maxiter=10)
    _, ilu = gmres(h, b, M=near_field_ilu(h), rtol=1e-9, restart=100, maxiter=10)
    assert lu["iterations"] < plain["iterations"]
    assert ilu["iterations"] < plain["iterations"]


def test_block_jacobi_inverts_the_element_diagonal_blocks():
    rng = np.random.default_rng(1)
    points = rng.random((200, 3))
    blocks = rng.standard_normal((200, 3, 3)) + 4 * np.eye(3)
    dense = np.zeros((600, 600))
    for e in range(200):
        dense[3 * e:3 * e + 3, 3 * e:3 * e + 3] = blocks[e]
    h = HMatrix.build(matrix_generator(dense, points, dof=3), eps=1e-6, leaf_size=16)
    M = block_jacobi(h)
    x = rng.standard_normal(600)
    assert np.allclose(M @ (dense @ x), x)
    X = rng.standard_normal((600, 2))
    assert np.allclose(M @ (dense @ X), X)


def test_gmres_raises_convergence_error_with_the_residual(spd_problem):
    h, _, b = spd_problem
    with pytest.raises(ConvergenceError, match="residual") as caught:
        gmres(h, b, rtol=1e-12, restart=2, maxiter=1)
    error = caught.value
    assert error.residual > 1e-12 and error.iterations == 2
    assert f"{error.residual:.3e}" in str(error)


def test_gmres_zero_rhs_and_plain_arrays():
    A = np.diag(np.arange(1.0, 11.0))
    x, info = gmres(A, np.zeros(10))
    assert np.all(x == 0) and info["iterations"] == 0 and info["residual"] == 0.0
    b = np.ones(10)
    x, info = gmres(A, b, rtol=1e-12)
    assert np.allclose(x, 1.0 / np.arange(1.0, 11.0))
    x, _ = gmres(A, b[:, None], rtol=1e-12, x0=np.ones(10))
    assert x.shape == (10,)


def test_gmres_refuses_bad_input():
    A = np.eye(4)
    for b in (np.array([1.0, np.nan, 0.0, 0.0]), np.array([np.inf, 0.0, 0.0, 0.0])):
        with pytest.raises(InputError, match="finite"):
            gmres(A, b)
    with pytest.raises(InputError, match="shape"):
        gmres(A, np.ones(3))
    for rtol in (0.0, 1.0, -1e-8, np.nan):
        with pytest.raises(InputError, match="rtol"):
            gmres(A, np.ones(4), rtol=rtol)
    with pytest.raises(InputError, match="restart"):
        gmres(A, np.ones(4), restart=0)
    with pytest.raises(InputError, match="maxiter"):
        gmres(A, np.ones(4), maxiter=1.5)
    with pytest.raises(InputError, match="x0"):
        gmres(A, np.ones(4), x0=np.ones(3))


def test_preconditioners_refuse_bad_input(spd_problem):
    h, _, _ = spd_problem
    with pytest.raises(InputError, match="hmatrix"):
        block_jacobi(np.eye(3))
    with pytest.raises(InputError, match="drop_tol"):
        near_field_ilu(h, drop_tol=2.0)
    with pytest.raises(InputError, match="fill_factor"):
        near_field_ilu(h, fill_factor=0.5)
    with pytest.raises(InputError, match="part"):
        near_field_lu(h, part="everything")


def test_default_preconditioner_falls_back_on_a_singular_near_field(caplog):
    rng = np.random.default_rng(2)
    points = rng.random((100, 3))
    dense = np.zeros((100, 100))
    dense[np.arange(50), np.arange(50)] = 1.0  # half the diagonal is zero: singular
    h = HMatrix.build(matrix_generator(dense, points), eps=1e-6, leaf_size=16)
    with caplog.at_level(logging.WARNING):
        M = default_preconditioner(h)
    assert "block Jacobi" in caplog.text
    assert np.all(np.isfinite(M @ np.ones(100)))


# ----------------------------------------------------------------------------- GMRES restarts


def cyclic_shift(n):
    """A e_i = e_(i+1 mod n): with b = e_0 every Krylov space of dimension k < n
    leaves the residual at ||b||, so any restarted GMRES(m < n) stagnates forever."""
    return np.roll(np.eye(n), 1, axis=0)


def test_gmres_grows_the_restart_of_a_stagnating_cycle_and_matches_the_dense_solve():
    n = 40
    A, b = cyclic_shift(n), np.eye(n)[0]
    x, info = gmres(A, b, rtol=1e-10, restart=10, maxiter=10)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), atol=1e-12)
    # the stagnating cycle was continued (10 -> 20 -> 40), not restarted: no lost work
    assert info["iterations"] == n and info["cycles"] == 1 and info["restart"] == n


def test_gmres_growth_is_capped_and_the_budget_bounded():
    n = 40
    A, b = cyclic_shift(n), np.eye(n)[0]
    for max_restart, grown in ((10, ""), (20, "grown on stagnation to 20")):
        with pytest.raises(ConvergenceError, match="did not converge") as caught:
            gmres(A, b, rtol=1e-10, restart=10, maxiter=5, max_restart=max_restart)
        assert caught.value.iterations == 50  # restart * maxiter, whatever the restart grew to
        assert caught.value.residual == pytest.approx(1.0)
        assert grown in str(caught.value) and "budget" in str(caught.value)
    with pytest.raises(InputError, match="max_restart"):
        gmres(A, b, restart=10, max_restart=5)


def test_gmres_takes_scipys_iterations_while_the_restart_does_not_grow(spd_problem):
    h, _, b = spd_problem
    M = near_field_ilu(h, part="leaf_diagonal", drop_tol=1e-3, fill_factor=5)
    count = [0]

    def callback(_):
        count[0] += 1

    reference, _ = spla.gmres(h, b, M=M, rtol=1e-9, atol=0.0, restart=100, maxiter=10, callback=callback,
                              callback_type="pr_norm")
    x, info = gmres(h, b, M=M, rtol=1e-9, restart=100, maxiter=10)
    assert info["iterations"] == count[0] and info["restart"] == 100
    np.testing.assert_allclose(x, reference, rtol=1e-12, atol=0)


def test_gmres_restarts_without_growth_while_cycles_converge_fast(spd_problem):
    h, dense, b = spd_problem
    x, info = gmres(h, b, rtol=1e-10, restart=5, maxiter=40)
    assert info["restart"] == 5 and info["cycles"] > 1  # plain restarts: every cycle gains > 10x
    assert np.linalg.norm(dense @ x - b) / np.linalg.norm(b) < 1e-9


def test_gmres_refuses_a_non_finite_preconditioner():
    A = np.diag(np.arange(1.0, 11.0))
    M = spla.LinearOperator(A.shape, matvec=lambda x: np.full(10, np.nan), dtype=np.float64)
    with pytest.raises(ConvergenceError, match="non-finite"):
        gmres(A, np.ones(10), M=M)


# ----------------------------------------------------------------------------- block ILU


def test_block_ilu_is_exact_on_a_block_tridiagonal_matrix():
    """ILU(0) of a block tridiagonal matrix makes no fill: it is the exact block LU."""
    rng = np.random.default_rng(3)
    n, d = 300, 3
    points = np.column_stack([np.linspace(0, 1, n), np.zeros(n), np.zeros(n)])
    dense = np.zeros((n * d, n * d))
    for e in range(n):
        dense[d * e:d * e + d, d * e:d * e + d] = rng.standard_normal((d, d)) + 6 * np.eye(d)
        if e + 1 < n:
            dense[d * e:d * e + d, d * e + d:d * e + 2 * d] = rng.standard_normal((d, d))
            dense[d * e + d:d * e + 2 * d, d * e:d * e + d] = rng.standard_normal((d, d))
    h = HMatrix.build(matrix_generator(dense, points, dof=d), eps=1e-8, leaf_size=16)
    M = near_field_block_ilu(h, threshold=0.0)
    x = rng.standard_normal(n * d)
    np.testing.assert_allclose(M @ (dense @ x), x, rtol=0, atol=1e-10 * np.abs(x).max())
    X = rng.standard_normal((n * d, 2))
    np.testing.assert_allclose(M @ (dense @ X), X, rtol=0, atol=1e-10 * np.abs(X).max())


def test_default_preconditioner_does_not_depend_on_the_element_frames():
    """Rotating every element's unknowns (Q A Q^T, Q block diagonal orthogonal) rotates
    the block ILU exactly, so GMRES takes the same iterations and gives the rotated
    solution; both agree with the dense solve."""
    side = 28
    n, h = side * side, 1.0 / side
    rng = np.random.default_rng(4)
    u, v = np.meshgrid((np.arange(side) + 0.5) * h, (np.arange(side) + 0.5) * h)
    uv = np.column_stack([u.ravel(), v.ravel()]) + rng.uniform(-0.2, 0.2, (n, 2)) * h
    points = np.column_stack([uv, 0.2 * uv[:, 0] + 0.5 * uv[:, 1]])  # a tilted plane
    scales = np.array([1.0, 0.6, 3.0])
    # 1/r^3, shear and normal uncoupled, self term ~ 1/h^3: a planar-crack-like DDM kernel
    generator = tensor_generator(points, scales=scales, coupling=0.0, exponent=3.0, self_value=4.0 * scales / h**3)
    dense = generator.to_dense()
    rotations, _ = np.linalg.qr(rng.standard_normal((n, 3, 3)))
    Q = np.zeros((3 * n, 3 * n))
    for e in range(n):
        Q[3 * e:3 * e + 3, 3 * e:3 * e + 3] = rotations[e]
    rotated = np.einsum("iab,ibjc,jdc->iajd", rotations, dense.reshape(n, 3, n, 3), rotations).reshape(dense.shape)
    h = HMatrix.build(matrix_generator(dense, generator.points, dof=3), eps=1e-8, leaf_size=32)
    h_rotated = HMatrix.build(matrix_generator(rotated, generator.points, dof=3), eps=1e-8, leaf_size=32)
    M, M_rotated = default_preconditioner(h), default_preconditioner(h_rotated)
    v = rng.standard_normal(3 * n)
    np.testing.assert_allclose(M_rotated @ (Q @ v), Q @ (M @ v), rtol=1e-9, atol=1e-12 * np.abs(M @ v).max())
    b = rng.standard_normal(3 * n)
    x, info = gmres(h, b, M=M, rtol=1e-10)
    x_rotated, info_rotated = gmres(h_rotated, Q @ b, M=M_rotated, rtol=1e-10)
    assert info["iterations"] == info_rotated["iterations"]
    exact = np.linalg.solve(dense, b)
    assert np.linalg.norm(x - exact) < 1e-8 * np.linalg.norm(exact)
    assert np.linalg.norm(x_rotated - Q @ exact) < 1e-8 * np.linalg.norm(exact)


def test_a_paused_gmres_finishes_bit_for_bit_as_an_unpaused_one(spd_problem):
    # PausableGmres: pause() stops at pause_rtol (preconditioned estimate) with an iterate of
    # about that residual, finish() continues the same Krylov cycle: the result and the
    # iteration count of gmres without a pause, bit for bit.
    from hmatddm.hmatrix.solvers import PausableGmres

    h, dense, b = spd_problem
    precond = default_preconditioner(h)
    x_ref, info_ref = gmres(h, b, M=precond, rtol=1e-10, restart=50, maxiter=10, x0=0.1 * b)
    solver = PausableGmres(h, b, M=precond, rtol=1e-10, restart=50, maxiter=10, x0=0.1 * b, pause_rtol=1e-4)
    x_pause, iterations = solver.pause()
    assert solver.result is None and 0 < iterations < info_ref["iterations"]
    assert np.linalg.norm(b - dense @ x_pause) < 1e-2 * np.linalg.norm(b)
    assert np.linalg.norm(b - dense @ x_pause) > 1e-10 * np.linalg.norm(b)
    x, info = solver.finish()
    np.testing.assert_array_equal(x, x_ref)
    assert info == info_ref
    assert solver.finish()[0] is x
    # no pause, or a solve that ends before it: pause() returns the result
    solver = PausableGmres(h, b, M=precond, rtol=1e-10, restart=50, maxiter=10)
    x, iterations = solver.pause()
    assert solver.result is not None and iterations == solver.result[1]["iterations"]
    with pytest.raises(InputError, match="pause_rtol"):
        PausableGmres(h, b, rtol=1e-6, pause_rtol=1e-8).pause()


def test_an_exact_preconditioner_solves_at_once_and_an_inexact_one_falls_back_to_gmres(spd_problem):
    # ExactPreconditionerSolve: M = A^-1 (dense LU) gives M b, checked by its residual, with no
    # iteration; an M that is not exact (block Jacobi) leaves the check failing and GMRES
    # continues from M b to the same tolerance as a plain solve.
    import scipy.linalg

    from hmatddm.hmatrix.solvers import ExactPreconditionerSolve

    h, dense, b = spd_problem
    lu = scipy.linalg.lu_factor(dense)
    exact = spla.LinearOperator(dense.shape, matvec=lambda v: scipy.linalg.lu_solve(lu, v), dtype=np.float64)
    solver = ExactPreconditionerSolve(h, b, exact, rtol=1e-8, pause_rtol=1e-4)
    x, iterations = solver.pause()
    assert iterations == 0 and solver.result is not None and solver.level == 1e-8
    x_dense = np.linalg.solve(dense, b)
    assert np.linalg.norm(x - x_dense) <= 1e-7 * np.linalg.norm(x_dense)
    assert solver.finish()[1]["residual"] <= 1e-8
    inexact = default_preconditioner(h)
    solver = ExactPreconditionerSolve(h, b, inexact, rtol=1e-10, restart=50, maxiter=10)
    x, info = solver.finish()
    assert info["iterations"] > 0 and np.linalg.norm(b - dense @ x) <= 1e-9 * np.linalg.norm(b)
    zero = ExactPreconditionerSolve(h, np.zeros_like(b), exact)
    assert not zero.finish()[0].any()
