"""solve_with_inverse: a direct solve when the inverse is exact, preconditioned GMRES otherwise."""
import numpy as np
import pytest
import scipy.linalg

import hmatddm as hd
from hmatddm.elasticity.inverse import solve_with_inverse


@pytest.fixture(scope="module")
def system():
    rng = np.random.default_rng(3)
    a = np.eye(40) * 4.0 + 0.3 * rng.normal(size=(40, 40))
    return a, rng.normal(size=40)


def test_exact_inverse_is_applied_once(system):
    a, b = system
    factors = scipy.linalg.lu_factor(a)
    x, info = solve_with_inverse(a, b, lambda r: scipy.linalg.lu_solve(factors, r), True)
    assert info == {"iterations": 0}
    np.testing.assert_allclose(a @ x, b, rtol=0, atol=1e-12 * np.abs(b).max())


def test_approximate_inverse_preconditions_gmres(system):
    a, b = system
    diagonal = np.diag(a).copy()
    x, info = solve_with_inverse(a, b, lambda r: r / diagonal, False, rtol=1e-10)
    assert info["iterations"] > 1 and info["residual"] <= 1e-10
    np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=0, atol=1e-8 * np.abs(x).max())


def test_non_finite_solution_is_refused(system):
    a, b = system
    with pytest.raises(hd.ConvergenceError, match="NaN"):
        solve_with_inverse(a, b, lambda r: np.full_like(r, np.nan), True)
