"""Pairs of points within a distance (hmatddm.mesh.neighbours), against scipy's KD-tree."""
import numpy as np
import pytest
from scipy.spatial import cKDTree

from hmatddm.mesh.neighbours import pairs_within


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("n", [1, 2, 60, 2000])
def test_pairs_within_finds_what_the_kd_tree_finds(dim, n):
    rng = np.random.default_rng(n + dim)
    points = rng.random((n, dim)) * np.array([50.0, 5.0, 2.0][:dim])
    points[n // 2:n // 2 + 3] = points[0]  # coincident points
    reach = rng.random(n) * 0.4
    sources, receivers = pairs_within(points, reach)
    found = cKDTree(points).query_ball_point(points, reach)
    expected = sorted((i, j) for i, near in enumerate(found) for j in near if i != j)
    assert list(zip(sources.tolist(), receivers.tolist())) == expected


def test_a_scalar_reach_and_points_far_apart():
    points = np.array([[0.0, 0.0], [1e9, 0.0], [1e9, 0.5]])
    sources, receivers = pairs_within(points, 1.0)
    assert sources.tolist() == [1, 2] and receivers.tolist() == [2, 1]
