"""Level-by-level factors of a growing matrix (hmatddm.elasticity.growing_lu) against
numpy's dense solve."""
import numpy as np
import pytest

from hmatddm.elasticity.growing_lu import GrowingBlockLU


def test_growing_block_lu_solves_like_a_dense_solve():
    """Levels added one block at a time (Schur complements) solve with the whole matrix,
    vectors and matrices of right-hand sides, as numpy's dense solve does."""
    rng = np.random.default_rng(3)
    n = 40
    matrix = rng.normal(size=(n, n)) + 2 * n * np.eye(n) * rng.choice([-1.0, 1.0], size=n)
    levels = None
    for size in (7, 8, 20, 33, 40):
        factors = GrowingBlockLU(matrix[:size, :size], levels)
        levels = factors.prefix(size)
        assert len(levels) == len(factors.levels)
        r = rng.normal(size=(size, 3))
        np.testing.assert_allclose(factors.solve(r), np.linalg.solve(matrix[:size, :size], r), rtol=0, atol=1e-12)
        np.testing.assert_allclose(factors.solve(r[:, 0]), np.linalg.solve(matrix[:size, :size], r[:, 0]), rtol=0,
                                   atol=1e-12)
    assert [(start, stop) for start, stop, *_ in factors.levels] == [(0, 7), (7, 8), (8, 20), (20, 33), (33, 40)]
    # a shared run that ends inside a level keeps the levels before it only
    assert [level[1] for level in factors.prefix(30)] == [7, 8, 20]
    partly = GrowingBlockLU(matrix, factors.prefix(30))
    assert [(start, stop) for start, stop, *_ in partly.levels] == [(0, 7), (7, 8), (8, 20), (20, 40)]
    r = rng.normal(size=n)
    np.testing.assert_allclose(partly.solve(r), np.linalg.solve(matrix, r), rtol=0, atol=1e-12)


def _needs_pivoting(n, rng):
    """A well-conditioned matrix whose leading pivot is tiny: elimination without row
    exchanges inside its first block would lose every digit."""
    matrix = rng.normal(size=(n, n)) + n * np.eye(n)
    matrix[0, 0] = 1e-14
    matrix[[0, 1]] = matrix[[1, 0]]
    return matrix


@pytest.mark.parametrize("pivoted", [False, True])
def test_a_first_level_that_needs_row_exchanges_as_an_lu_or_an_inverse(pivoted):
    """``pivoted_first``: the first level is kept as a partially pivoted LU (the contact base
    of a network: no explicit inverse of a large block), else as an explicit inverse; a
    first block that needs row exchanges, bordered once, solves like the dense matrix
    either way."""
    rng = np.random.default_rng(5)
    matrix = _needs_pivoting(30, rng)
    factors = GrowingBlockLU(matrix[:20, :20], pivoted_first=pivoted)
    assert isinstance(factors.levels[0][4], tuple) == pivoted
    grown = GrowingBlockLU(matrix, factors.prefix(20))
    assert grown.levels[-1][1] == 30 and len(grown.levels) == 2
    r = rng.normal(size=(30, 2))
    np.testing.assert_allclose(grown.solve(r), np.linalg.solve(matrix, r), rtol=0, atol=1e-10)


def test_continuing_a_solution_of_the_leading_block_equals_a_whole_solve():
    """``continue_solve`` from ``M[:s, :s]^-1 r[:s]`` runs only the levels after ``s``: the
    result is the whole solve's, bit for bit (the same operations in the same order)."""
    rng = np.random.default_rng(7)
    matrix = _needs_pivoting(50, rng)
    first = GrowingBlockLU(matrix[:36, :36], pivoted_first=True)
    grown = GrowingBlockLU(matrix[:44, :44], first.prefix(36))
    grown = GrowingBlockLU(matrix, grown.prefix(44))
    r = rng.normal(size=(50, 4))
    y = r.copy()
    y[:36] = first.solve(r[:36])
    np.testing.assert_array_equal(grown.continue_solve(y, 36), grown.solve(r))
    np.testing.assert_allclose(y, np.linalg.solve(matrix, r), rtol=0, atol=1e-10)
