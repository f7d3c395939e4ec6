"""Near-field preconditioners and the checked GMRES wrapper of hmatddm.hmatrix."""

import logging

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from hmatddm.errors import ConvergenceError, InputError
from hmatddm.hmatrix import (
    HMatrix,
    block_jacobi,
    default_preconditioner,
    gmres,
    near_field_ilu,
    near_field_lu,
)
from hmatddm.hmatrix.example_kernels import matrix_generator


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
