"""Intersections of plan-view fracture segments, conforming splitting, clusters, P10."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm import network as nw


def _random_segments(n, rng, box=20.0):
    """Segments in general position, lengths spread over two decades."""
    centers = rng.uniform(0.0, box, (n, 2))
    theta = rng.uniform(0.0, np.pi, n)
    lengths = nw.power_law_lengths(n, 2.0, 0.2, 12.0, rng)
    half = 0.5 * lengths[:, None] * np.column_stack([np.cos(theta), np.sin(theta)])
    return centers - half, centers + half


def _brute_force(p0, p1):
    """O(M^2) reference: every pair, its 2x2 system solved by Cramer's rule."""
    i, j = np.triu_indices(len(p0), k=1)
    d = p1 - p0
    rhs = p0[j] - p0[i]
    det = -d[i, 0] * d[j, 1] + d[i, 1] * d[j, 0]
    ok = np.abs(det) > 1e-14
    t = (-rhs[:, 0] * d[j, 1] + rhs[:, 1] * d[j, 0]) / np.where(ok, det, 1.0)
    s = (d[i, 0] * rhs[:, 1] - d[i, 1] * rhs[:, 0]) / np.where(ok, det, 1.0)
    hit = ok & (t >= 0) & (t <= 1) & (s >= 0) & (s <= 1)
    return {(int(a), int(b)): (p0[a] + ta * d[a], ta, sb)
            for a, b, ta, sb in zip(i[hit], j[hit], t[hit], s[hit])}


def _as_dict(found):
    return {(int(i), int(j)): (p, t, s) for i, j, p, t, s in zip(found.i, found.j, found.points, found.t_i,
                                                                  found.t_j)}


def _point_segment_distance(points, a, b):
    """(P, S) distances from points to segments a -> b (any dimension)."""
    d = b - a
    t = np.einsum("psk,sk->ps", points[:, None, :] - a[None], d) / np.einsum("sk,sk->s", d, d)
    closest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * d[None]
    return np.linalg.norm(points[:, None, :] - closest, axis=-1)


def _min_relative_distance_2d(mesh):
    """min over elements k of dist(centre_k, any other element) / half_length_k."""
    p0, p1 = mesh.endpoints
    distance = _point_segment_distance(mesh.centers, p0, p1)
    np.fill_diagonal(distance, np.inf)
    return float(np.min(distance.min(axis=1) / mesh.half_length))


def _min_relative_distance_3d(mesh):
    """min over elements k of dist(centre_k, any edge of any other element) / size_k."""
    corners = mesh.corners()
    a = corners.reshape(-1, 3)
    b = np.roll(corners, -1, axis=1).reshape(-1, 3)
    owner = np.repeat(np.arange(mesh.n_elements), 4)
    distance = _point_segment_distance(mesh.centers, a, b)
    distance[owner[None, :] == np.arange(mesh.n_elements)[:, None]] = np.inf
    return float(np.min(distance.min(axis=1) / np.minimum(mesh.half_a, mesh.half_b)))


# ----------------------------------------------------------------------------- find_intersections

@pytest.mark.parametrize("seed", [0, 1, 2])
def test_find_intersections_matches_brute_force(seed):
    p0, p1 = _random_segments(1500, np.random.default_rng(seed), box=40.0)
    found = nw.find_intersections(p0, p1)
    reference = _brute_force(p0, p1)
    assert len(reference) > 200
    assert set(_as_dict(found)) == set(reference)
    for key, (point, t, s) in _as_dict(found).items():
        assert np.allclose(point, reference[key][0], atol=1e-10)
        assert np.isclose(t, reference[key][1], atol=1e-10) and np.isclose(s, reference[key][2], atol=1e-10)
    assert np.all(found.i < found.j) and not np.any(found.collinear)
    # t_i, t_j locate the point on both segments
    assert np.allclose(p0[found.i] + found.t_i[:, None] * (p1 - p0)[found.i], found.points, atol=1e-10)
    assert np.allclose(p0[found.j] + found.t_j[:, None] * (p1 - p0)[found.j], found.points, atol=1e-10)


def test_find_intersections_is_deterministic_and_order_independent():
    p0, p1 = _random_segments(3000, np.random.default_rng(5), box=60.0)
    first, second = nw.find_intersections(p0, p1), nw.find_intersections(p0, p1)
    for a, b in zip(first, second):
        assert np.array_equal(a, b)
    assert np.all(np.diff(first.i) >= 0)
    permutation = np.random.default_rng(6).permutation(len(p0))
    shuffled = nw.find_intersections(p0[permutation], p1[permutation])
    pairs = {tuple(sorted((int(permutation[i]), int(permutation[j])))) for i, j in zip(shuffled.i, shuffled.j)}
    assert pairs == set(zip(first.i.tolist(), first.j.tolist()))


def test_one_long_segment_among_many_short_ones():
    p0, p1 = _random_segments(2000, np.random.default_rng(8), box=50.0)
    p0 = np.vstack([p0, [[-5.0, 25.3]]])
    p1 = np.vstack([p1, [[55.0, 24.1]]])
    found = nw.find_intersections(p0, p1)
    on_long = np.flatnonzero(found.j == 2000)
    d = p1 - p0
    # brute force against the long segment only
    expected = []
    for i in range(2000):
        matrix = np.column_stack([d[i], -d[2000]])
        t, s = np.linalg.solve(matrix, p0[2000] - p0[i])
        if 0 <= t <= 1 and 0 <= s <= 1:
            expected.append(i)
    assert found.i[on_long].tolist() == expected and len(expected) > 5


def test_x_intersection():
    found = nw.find_intersections([[0, 0], [0, 2]], [[2, 2], [2, 0]])
    assert found.i.tolist() == [0] and found.j.tolist() == [1]
    assert np.allclose(found.points, [[1, 1]]) and np.allclose(found.t_i, 0.5) and np.allclose(found.t_j, 0.5)
    assert not found.collinear[0]


def test_t_and_l_intersections_are_exact():
    # T: the stem ends on the bar; L: two segments share an end point
    p0 = np.array([[0.0, 0.0], [1.0 / 3.0, 0.0], [5.0, 0.0], [6.0, 0.0]])
    p1 = np.array([[2.0, 0.0], [0.7, 1.3], [6.0, 0.0], [6.3, 2.1]])
    found = nw.find_intersections(p0, p1)
    records = _as_dict(found)
    assert set(records) == {(0, 1), (2, 3)}
    point, t, s = records[(0, 1)]
    assert np.array_equal(point, p0[1]) and s == 0.0 and np.isclose(t, 1.0 / 6.0)
    point, t, s = records[(2, 3)]
    assert np.array_equal(point, p1[2]) and t == 1.0 and s == 0.0
    # a stem that stops just short of the bar (well beyond tol) does not touch it
    assert nw.find_intersections([[0, 0], [1, 1e-6]], [[2, 0], [1, 1]]).size == 0
    # ... one within tol * (bounding-box diagonal) does, snapped to its end point
    near = nw.find_intersections([[0, 0], [1, 1e-12]], [[2, 0], [1, 1]])
    assert near.size == 1 and near.t_j[0] == 0.0 and np.array_equal(near.points[0], [1, 1e-12])


def test_parallel_and_collinear_cases():
    # parallel, apart: nothing
    assert nw.find_intersections([[0, 0], [0, 1]], [[2, 0], [2, 1]]).size == 0
    # collinear, disjoint: nothing
    assert nw.find_intersections([[0, 0], [3, 0]], [[2, 0], [5, 0]]).size == 0
    # collinear overlap: two records, at the start and end of the shared part (along i)
    found = nw.find_intersections([[0, 0], [1, 0]], [[2, 0], [3, 0]])
    assert found.collinear.tolist() == [True, True]
    assert np.allclose(found.points, [[1, 0], [2, 0]])
    assert np.allclose(found.t_i, [0.5, 1.0]) and np.allclose(found.t_j, [0.0, 0.5])
    # containment, opposite directions
    found = nw.find_intersections([[0, 0], [3, 0]], [[4, 0], [1, 0]])
    assert np.allclose(found.points, [[1, 0], [3, 0]])
    assert np.allclose(found.t_i, [0.25, 0.75]) and np.allclose(found.t_j, [1.0, 0.0])
    # collinear, touching end to end: one record
    found = nw.find_intersections([[0, 0], [1, 0]], [[1, 0], [2, 0]])
    assert found.size == 1 and found.collinear[0] and found.t_i[0] == 1.0 and found.t_j[0] == 0.0
    # identical segments: the whole of both
    found = nw.find_intersections([[0, 0], [0, 0]], [[1, 1], [1, 1]])
    assert found.size == 2 and np.allclose(found.t_i, [0, 1]) and np.allclose(found.t_j, [0, 1])


def test_near_parallel_is_classified_by_the_sine_threshold():
    # |sin| = 1e-12 <= tol: treated as parallel; their lines are within eps -> collinear overlap
    a = nw.find_intersections([[0, 0], [0, -5e-13]], [[1, 0], [1, 5e-13]])
    assert a.size == 2 and np.all(a.collinear)
    # |sin| = 1e-12, lines far apart: parallel, no intersection (although they would cross far away)
    assert nw.find_intersections([[0, 0], [0, 1]], [[1, 0], [1, 1 + 1e-12]]).size == 0
    # |sin| = 1e-6 > tol: an ordinary crossing, computed accurately
    b = nw.find_intersections([[0, 0], [0, -5e-7]], [[1, 0], [1, 5e-7]])
    assert b.size == 1 and not b.collinear[0] and np.allclose(b.points, [[0.5, 0]], atol=1e-12)
    # deterministic: the same answer every time
    again = nw.find_intersections([[0, 0], [0, -5e-13]], [[1, 0], [1, 5e-13]])
    assert all(np.array_equal(x, y) for x, y in zip(a, again))


def test_find_intersections_input_checks():
    assert nw.find_intersections(np.zeros((0, 2)), np.zeros((0, 2))).size == 0
    assert nw.find_intersections([[0, 0]], [[1, 1]]).size == 0
    with pytest.raises(hd.InputError, match="p1"):
        nw.find_intersections([[0, 0]], [[1, 1, 1]])
    with pytest.raises(hd.InputError, match="zero length"):
        nw.find_intersections([[0, 0], [1, 1]], [[1, 0], [1, 1]])
    with pytest.raises(hd.InputError, match="tol"):
        nw.find_intersections([[0, 0]], [[1, 1]], tol=-1.0)


# ----------------------------------------------------------------------------- splitting

def test_reference_fig_6_5_crossing_on_an_element_centre():
    """Ref. Fig. 6.5: one fracture reaches another exactly at an element centre. The
    plain mesh puts an element edge on that collocation point; the split mesh does not."""
    network = nw.Network.from_segments([[0.0, 0.0], [1.5, -1.0]], [[5.0, 0.0], [3.5, 1.0]])
    plain = network.to_mesh2d(1.0)
    assert _min_relative_distance_2d(plain) < 1e-12  # centre (2.5, 0) lies on the other fracture
    split = nw.split_at_intersections(network)
    assert len(split) == 4 and split.fracture_id.tolist() == [0, 0, 1, 1]
    mesh = split.to_mesh2d(1.0)
    assert _min_relative_distance_2d(mesh) > 0.1
    # the intersection is a node of both fractures
    p0, p1 = mesh.endpoints
    for fracture in (0, 1):
        nodes = np.concatenate([p0[mesh.fracture_id == fracture], p1[mesh.fracture_id == fracture]])
        assert np.min(np.linalg.norm(nodes - [2.5, 0.0], axis=1)) < 1e-12


def _random_network(seed, **kwargs):
    args = dict(region=(-15, 15, -15, 15), density=0.15, length_exponent=2.0, l_min=1.0, l_max=12.0,
                mean_azimuths_deg=(45.0, 135.0), kappas=(3.0, 3.0), seed=seed) | kwargs
    return nw.generate_network(nw.NetworkSpec(**args))


@pytest.mark.parametrize("seed", [0, 1])
def test_split_mesh_2d_has_no_collocation_point_on_another_element(seed):
    network = _random_network(seed)
    found = nw.find_intersections(network.p0, network.p1)
    assert found.size > 20
    split = nw.split_at_intersections(network)
    assert len(split) == len(network) + 2 * found.size
    # same fractures, same total length
    assert np.allclose(np.bincount(split.fracture_id, split.lengths), network.lengths)
    mesh = split.to_mesh2d(0.5)
    assert _min_relative_distance_2d(mesh) > 1e-9
    # every intersection point is an element end of both fractures
    p0, p1 = mesh.endpoints
    nodes = np.concatenate([p0, p1])
    node_fracture = np.concatenate([mesh.fracture_id, mesh.fracture_id])
    for point, i, j in zip(found.points, found.i, found.j):
        near = np.linalg.norm(nodes - point, axis=1) < 1e-9
        assert set(node_fracture[near].tolist()) == {int(network.fracture_id[i]), int(network.fracture_id[j])}


def test_split_mesh_3d_has_no_collocation_point_on_another_edge():
    network = _random_network(3, region=(-8, 8, -8, 8), l_max=8.0, height=2.0)
    assert nw.find_intersections(network.p0, network.p1).size > 3
    mesh = nw.split_at_intersections(network).to_mesh3d(1.0, 2)
    assert np.all(mesh.areas > 0)
    assert _min_relative_distance_3d(mesh) > 1e-9
    assert np.allclose(np.bincount(mesh.fracture_id, mesh.areas), network.lengths * 2.0)


def test_split_is_idempotent():
    split = nw.split_at_intersections(_random_network(4))
    again = nw.split_at_intersections(split)
    assert np.array_equal(split.p0, again.p0) and np.array_equal(split.p1, again.p1)
    assert np.array_equal(split.fracture_id, again.fracture_id)


def test_split_t_junction_and_collinear_overlap():
    # a T: the bar is split, the stem is not
    t_net = nw.Network.from_segments([[0, 0], [1, 0]], [[4, 0], [1, 2]])
    split = nw.split_at_intersections(t_net)
    assert split.fracture_id.tolist() == [0, 0, 1]
    assert np.allclose(split.p1[0], [1, 0]) and np.allclose(split.p0[1], [1, 0])
    # a collinear overlap is kept once, by the lower-index fracture
    overlap = nw.Network.from_segments([[0, 0], [1, 0]], [[2, 0], [3, 0]])
    split = nw.split_at_intersections(overlap)
    assert split.fracture_id.tolist() == [0, 0, 1]
    assert np.allclose(split.lengths, [1, 1, 1])
    mesh = split.to_mesh2d(0.25)
    assert _min_relative_distance_2d(mesh) > 0.5
    # a fracture lying wholly on another one disappears
    inside = nw.Network.from_segments([[0, 0], [1, 0]], [[3, 0], [2, 0]])
    assert nw.split_at_intersections(inside).fracture_id.tolist() == [0, 0, 0]


def test_split_min_stub_trims_dangling_ends():
    network = nw.Network.from_segments([[0, 0], [5, -0.1], [2, -0.1]], [[10, 0], [5, 3], [2, 0.15]])
    plain = nw.split_at_intersections(network)
    assert plain.fracture_id.tolist() == [0, 0, 0, 1, 1, 2, 2]
    trimmed = nw.split_at_intersections(network, min_stub=0.25)
    assert trimmed.fracture_id.tolist() == [0, 0, 0, 1, 2]
    assert np.allclose(trimmed.p0[3], [5, 0]) and np.allclose(trimmed.p1[3], [5, 3])
    assert np.allclose(trimmed.p0[4], [2, 0]) and np.allclose(trimmed.p1[4], [2, 0.15])  # longer stub kept
    # the bar keeps its ends (they are free but longer than min_stub) and its nodes
    assert np.allclose(trimmed.lengths[:3], [2, 3, 5])
    with pytest.raises(hd.InputError, match="min_stub"):
        nw.split_at_intersections(network, min_stub=-1.0)
    with pytest.raises(hd.InputError, match="network"):
        nw.split_at_intersections([[0, 0], [1, 1]])
