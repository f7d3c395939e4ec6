"""Cluster tree and block cluster tree of hmatddm.hmatrix (docs/conventions.md §7)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hmatddm.errors import InputError
from hmatddm.hmatrix.block_tree import block_tree, box_distance
from hmatddm.hmatrix.cluster_tree import cluster_tree


def tilted_plane(n, rng):
    """Points on the plane spanned by two tilted unit vectors (a planar fracture)."""
    e1 = np.array([1.0, 0.2, 0.4])
    e1 /= np.linalg.norm(e1)
    e2 = np.array([-0.3, 1.0, 0.5])
    e2 -= (e2 @ e1) * e1
    e2 /= np.linalg.norm(e2)
    uv = rng.random((n, 2))
    return uv[:, :1] * e1 + uv[:, 1:] * e2


def geometries():
    rng = np.random.default_rng(1)
    return {
        "cube": rng.random((700, 3)),
        "tilted_plane": tilted_plane(600, rng),
        "line2d": np.c_[np.linspace(0, 1, 333), np.zeros(333)],
        "disc2d": rng.standard_normal((500, 2)),
        "coincident": np.zeros((150, 3)),
        "single": np.array([[0.5, 0.5, 0.5]]),
    }


def check_tree_invariants(tree, points, radii):
    n = points.shape[0]
    assert np.array_equal(np.sort(tree.permutation), np.arange(n))
    assert tree.start[0] == 0 and tree.stop[0] == n
    leaves = tree.is_leaf
    assert np.all(tree.size[leaves] <= tree.leaf_size)
    assert np.all(tree.size >= 1)
    for c in np.flatnonzero(~leaves):
        left, right = tree.left[c], tree.right[c]
        # children partition the parent's range, in order
        assert tree.start[left] == tree.start[c] and tree.stop[left] == tree.start[right]
        assert tree.stop[right] == tree.stop[c]
        assert tree.parent[left] == c and tree.parent[right] == c
        assert tree.level[left] == tree.level[c] + 1
        # median split: sizes differ by at most one
        assert abs(tree.size[left] - tree.size[right]) <= 1
    # leaves partition [0, N) once sorted by start
    ordered = tree.leaves()
    assert tree.start[ordered[0]] == 0 and tree.stop[ordered[-1]] == n
    assert np.array_equal(tree.stop[ordered[:-1]], tree.start[ordered[1:]])
    # bounding boxes contain their elements' balls
    for c in range(tree.n_clusters):
        members = tree.permutation[tree.start[c]:tree.stop[c]]
        lower = points[members] - radii[members, None]
        upper = points[members] + radii[members, None]
        assert np.all(tree.bbox_min[c] <= lower.min(axis=0) + 1e-15)
        assert np.all(tree.bbox_max[c] >= upper.max(axis=0) - 1e-15)


@pytest.mark.parametrize("name", list(geometries()))
@pytest.mark.parametrize("leaf_size", [1, 16, 64])
def test_cluster_tree_invariants(name, leaf_size):
    points = geometries()[name]
    radii = np.full(points.shape[0], 0.01)
    tree = cluster_tree(points, radii, leaf_size)
    check_tree_invariants(tree, points, radii)


@settings(max_examples=30, deadline=None)
@given(
    n=st.integers(min_value=1, max_value=300),
    dim=st.sampled_from([2, 3]),
    leaf_size=st.integers(min_value=1, max_value=40),
    seed=st.integers(min_value=0, max_value=2**31),
)
def test_cluster_tree_invariants_random(n, dim, leaf_size, seed):
    rng = np.random.default_rng(seed)
    points = rng.standard_normal((n, dim)) * rng.random(dim) * 10
    radii = rng.random(n) * 0.1
    check_tree_invariants(cluster_tree(points, radii, leaf_size), points, radii)


def test_principal_axis_split_follows_a_tilted_strip():
    """The first bisection of a long tilted strip cuts across its long direction."""
    rng = np.random.default_rng(3)
    axis = np.array([1.0, 1.0, 1.0]) / np.sqrt(3)
    across = np.array([1.0, -1.0, 0.0]) / np.sqrt(2)
    points = rng.random((400, 1)) * 10 * axis + rng.random((400, 1)) * across
    tree = cluster_tree(points, np.zeros(400), 50)
    left = points[tree.permutation[tree.start[1]:tree.stop[1]]]
    right = points[tree.permutation[tree.start[2]:tree.stop[2]]]
    assert (left @ axis).max() <= (right @ axis).min() + 1e-12 or (right @ axis).max() <= (left @ axis).min() + 1e-12


def test_cluster_tree_refuses_bad_leaf_size():
    points = np.random.default_rng(0).random((10, 3))
    for bad in (0, -3, 2.5, True):
        with pytest.raises(InputError, match="leaf_size"):
            cluster_tree(points, np.zeros(10), bad)


def coverage(tree, blocks):
    n = tree.n_elements
    count = np.zeros((n, n), dtype=np.int64)
    for rows, cols in ((blocks.admissible_rows, blocks.admissible_cols), (blocks.near_rows, blocks.near_cols)):
        for r, c in zip(rows, cols):
            count[tree.start[r]:tree.stop[r], tree.start[c]:tree.stop[c]] += 1
    return count


@pytest.mark.parametrize("name", ["cube", "tilted_plane", "disc2d", "coincident", "single"])
@pytest.mark.parametrize("eta", [0.5, 3.0])
def test_block_tree_covers_matrix_exactly_once(name, eta):
    points = geometries()[name][:300]
    tree = cluster_tree(points, np.full(points.shape[0], 0.001), 8)
    blocks = block_tree(tree, eta)
    count = coverage(tree, blocks)
    assert np.all(count == 1)
    area = np.sum(tree.size[blocks.admissible_rows] * tree.size[blocks.admissible_cols]) + np.sum(
        tree.size[blocks.near_rows] * tree.size[blocks.near_cols])
    assert area == points.shape[0] ** 2


def test_block_tree_admissibility_and_near_leaves():
    points = geometries()["cube"]
    tree = cluster_tree(points, np.zeros(points.shape[0]), 16)
    eta = 2.0
    blocks = block_tree(tree, eta)
    assert blocks.admissible_rows.size > 0
    diameter = tree.diameter
    rows, cols = blocks.admissible_rows, blocks.admissible_cols
    distance = box_distance(tree, rows, cols)
    assert np.all(distance > 0)
    assert np.all(np.minimum(diameter[rows], diameter[cols]) <= eta * distance)
    # near blocks are leaf x leaf, and diagonal leaf blocks are all near
    assert np.all(tree.is_leaf[blocks.near_rows]) and np.all(tree.is_leaf[blocks.near_cols])
    diagonal = set(zip(blocks.near_rows[blocks.near_rows == blocks.near_cols].tolist(),
                       blocks.near_cols[blocks.near_rows == blocks.near_cols].tolist()))
    assert diagonal == {(c, c) for c in np.flatnonzero(tree.is_leaf).tolist()}


def test_block_tree_refuses_bad_eta():
    tree = cluster_tree(np.random.default_rng(0).random((50, 3)), np.zeros(50), 8)
    for bad in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(InputError, match="eta"):
            block_tree(tree, bad)


def test_group_split_keeps_each_group_whole_until_a_cluster_holds_one_group():
    """Three parallel strips (groups) close together: every cluster holds either whole
    groups or part of a single group, and the tree still partitions the elements."""
    rng = np.random.default_rng(0)
    strips = [np.column_stack([rng.uniform(0, 10, 300), np.full(300, 0.3 * k), rng.uniform(0, 1, 300)])
              for k in range(3)]
    points = np.concatenate(strips)
    groups = np.repeat(np.arange(3), 300)
    tree = cluster_tree(points, 0.01, leaf_size=32, groups=groups)
    assert np.array_equal(np.sort(tree.permutation), np.arange(900))
    counts = np.bincount(groups)
    for c in range(tree.n_clusters):
        members = groups[tree.permutation[tree.start[c]:tree.stop[c]]]
        present = np.unique(members)
        if present.size > 1:  # several groups: only whole ones
            assert all(np.count_nonzero(members == g) == counts[g] for g in present)
    with pytest.raises(InputError, match="groups"):
        cluster_tree(points, 0.01, leaf_size=32, groups=groups[:10])


def vertical_strips(n_strips, rng, length=30, height=10):
    """Element centres of vertical fractures (1 m elements) at random strikes: the tall
    thin fractures of the cloud benchmark, whose axis-aligned boxes are as wide as long."""
    parts, groups = [], []
    for k in range(n_strips):
        strike = rng.uniform(0.0, np.pi)
        e1 = np.array([np.cos(strike), np.sin(strike), 0.0])
        centre = np.r_[rng.uniform(-60.0, 60.0, 2), 0.0]
        u, w = np.meshgrid(np.arange(length) - 0.5 * (length - 1), np.arange(height) - 0.5 * (height - 1))
        parts.append(centre + u.reshape(-1, 1) * e1 + w.reshape(-1, 1) * np.array([0.0, 0.0, 1.0]))
        groups.append(np.full(u.size, k))
    return np.concatenate(parts), np.concatenate(groups)


def test_oriented_boxes_contain_their_elements_and_bound_the_distance():
    """Every element ball lies in its cluster's oriented box, the oriented gap never
    exceeds the true distance between two clusters' element balls, and on tall strips
    at random strikes it is larger than the axis-aligned box distance for many pairs."""
    from scipy.spatial.distance import cdist

    from hmatddm.hmatrix.block_tree import oriented_gap

    points, _ = vertical_strips(8, np.random.default_rng(3))
    radius = 0.5
    tree = cluster_tree(points, radius, 16)
    for c in range(tree.n_clusters):
        local = (points[tree.permutation[tree.start[c]:tree.stop[c]]] - tree.box_center[c]) @ tree.box_axes[c].T
        assert np.all(np.abs(local) + radius <= tree.box_half[c] + 1e-9)
    rows, cols = (a.ravel() for a in np.meshgrid(np.arange(tree.n_clusters), np.arange(tree.n_clusters)))
    gap = oriented_gap(tree, rows, cols)
    for r, c, g in zip(rows[::23], cols[::23], gap[::23]):
        p = points[tree.permutation[tree.start[r]:tree.stop[r]]]
        q = points[tree.permutation[tree.start[c]:tree.stop[c]]]
        assert g <= max(0.0, cdist(p, q).min() - 2 * radius) + 1e-9
    assert np.mean(gap > box_distance(tree, rows, cols) + 1.0) > 0.02  # 5% of all pairs here


def test_oriented_block_tree_covers_once_and_its_hmatrix_matches_dense():
    """boxes="oriented": an exact partition of the matrix, more admissible area than
    axis-aligned boxes on vertical strips, and an H-matrix within eps of dense."""
    from hmatddm.hmatrix import HMatrix
    from hmatddm.hmatrix.example_kernels import tensor_generator

    points, groups = vertical_strips(6, np.random.default_rng(4), length=20)
    tree = cluster_tree(points, 0.5, 16, groups=groups)
    areas = {}
    for boxes in ("axis", "oriented"):
        blocks = block_tree(tree, 3.0, boxes=boxes)
        assert np.all(coverage(tree, blocks) == 1)
        areas[boxes] = np.sum(tree.size[blocks.admissible_rows] * tree.size[blocks.admissible_cols])
    assert areas["oriented"] > areas["axis"]
    generator = tensor_generator(points)
    dense = generator.to_dense()
    h = HMatrix.build(generator, eps=1e-6, eta=3.0, leaf_size=16, groups=groups, boxes="oriented",
                      factor_dtype=np.float64)
    x = np.random.default_rng(0).normal(size=dense.shape[1])
    assert np.linalg.norm(h @ x - dense @ x) <= 1e-5 * np.linalg.norm(dense @ x)
    with pytest.raises(InputError, match="boxes"):
        block_tree(tree, 3.0, boxes="spheres")


def test_a_tree_without_oriented_boxes_is_the_same_tree_and_refused_where_they_are_needed():
    rng = np.random.default_rng(3)
    points = rng.uniform(-1.0, 1.0, (300, 3))
    full = cluster_tree(points, 0.01, 16)
    bare = cluster_tree(points, 0.01, 16, oriented=False)
    for name in ("permutation", "start", "stop", "left", "right", "parent", "level", "bbox_min", "bbox_max"):
        assert np.array_equal(getattr(bare, name), getattr(full, name))
    assert bare.box_center is None and bare.box_axes is None and bare.box_half is None
    a, b = block_tree(bare, 2.0), block_tree(full, 2.0)  # axis-aligned boxes: the same partition
    assert np.array_equal(a.admissible_rows, b.admissible_rows) and np.array_equal(a.admissible_cols, b.admissible_cols)
    with pytest.raises(InputError, match="oriented=True"):
        block_tree(bare, 2.0, boxes="oriented")
