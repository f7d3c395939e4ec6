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


@pytest.mark.parametrize("part", ["normal", "shear"])
def test_modified_block_ilu_preconditions_as_the_scalar_ilu_does(part):
    """The compiled block ILU(0) of S A_near + D (a planar crack's part, its outer ring's rows
    replaced by k DD = g): GMRES with it solves the modified system as the dense solve does,
    in about the iterations of SuperLU's ILU of the same entries; a singular pivot (a row
    replaced by nothing) falls back to the scalar path."""
    from hmatddm.coupled.contact import ContactRows
    from hmatddm.elasticity.inverse import modified_near_field_block_ilu, modified_near_field_inverse
    from hmatddm.elasticity.planar import PlanarElasticityOperator

    n_side = 24
    square = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 6.0, 6.0, n_side, n_side)
    disc = square.subset(np.flatnonzero(np.linalg.norm(square.centers[:, :2], axis=1) < 3.0))
    operator = PlanarElasticityOperator(disc, hd.Elastic(10e9, 0.25), eps=1e-8).part(part)
    n, d = disc.n_elements, operator.dof
    ring = np.linalg.norm(disc.centers[:, :2], axis=1) > 2.6
    select = np.repeat(np.eye(d)[None], n, axis=0)
    select[ring] = 0.0
    direct = np.zeros((n, d, d))
    direct[ring] = 1e10 * np.eye(d)
    rows = ContactRows(select, direct, np.zeros((n, d)), "ring")
    dense = rows.modify_dense(operator.hmatrix.to_dense())
    rhs = np.random.default_rng(4).normal(size=n * d)
    exact = np.linalg.solve(dense, rhs)
    iterations = {}
    for name, inverse in (("block", modified_near_field_block_ilu(operator, rows)),
                          ("scalar", modified_near_field_inverse(operator, rows))):
        x, info = solve_with_inverse(dense, rhs, lambda r: inverse @ r, False, rtol=1e-11)
        np.testing.assert_allclose(x, exact, rtol=0, atol=1e-8 * np.abs(exact).max())
        iterations[name] = info["iterations"]
    assert iterations["block"] <= 1.5 * iterations["scalar"] + 2, iterations
    assert iterations["block"] < 0.5 * solve_with_inverse(dense, rhs, lambda r: r / np.diag(dense), False,
                                                          rtol=1e-11)[1]["iterations"]
    singular = ContactRows(select, np.zeros((n, d, d)), np.zeros((n, d)), "nothing")
    fallback = modified_near_field_block_ilu(operator, singular)
    assert np.all(np.isfinite(fallback @ rhs))
