"""Faces and tip edges from element geometry (hmatddm.mesh.topology)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.mesh import topology


def test_structured_grid_faces_and_tips():
    nx, ny = 5, 3
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 5.0, 3.0, nx, ny)
    faces = topology.element_faces(mesh)
    assert faces.n_faces == (nx - 1) * ny + nx * (ny - 1)
    np.testing.assert_allclose(faces.length, 1.0)
    np.testing.assert_allclose(faces.first_distance, 0.5)
    element, edge = topology.tip_edges(mesh, faces)
    assert len(element) == 2 * (nx + ny)


def test_size_jump_gives_partial_faces():
    # one 2x2 element next to two 1x1 elements along its +e1 side
    centers = np.array([[0.0, 0, 0], [1.5, 0.5, 0], [1.5, -0.5, 0]])
    e1 = np.tile([1.0, 0, 0], (3, 1))
    e2 = np.tile([0.0, 1, 0], (3, 1))
    mesh = hd.Mesh3D.from_rectangles(centers, e1, e2, [1.0, 0.5, 0.5], [1.0, 0.5, 0.5])
    faces = topology.element_faces(mesh)
    pairs = sorted(zip(faces.first.tolist(), faces.second.tolist()))
    assert pairs == [(0, 1), (0, 2), (1, 2)]
    big = (faces.first == 0)
    np.testing.assert_allclose(faces.length[big], 1.0)
    np.testing.assert_allclose(faces.first_distance[big], 1.0)
    np.testing.assert_allclose(faces.second_distance[big], 0.5)
    element, edge = topology.tip_edges(mesh, faces)
    assert (0, 0) not in set(zip(element.tolist(), edge.tolist()))  # the big +e1 edge is fully covered


def test_kinked_segments_connect_and_separate_fractures_do_not():
    p0 = np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 5.0]])
    p1 = np.array([[1.0, 0.0], [1.0 + np.cos(0.5), np.sin(0.5)], [6.0, 5.0]])
    mesh = hd.Mesh2D.from_segments(p0, p1)
    faces = topology.element_faces(mesh)
    assert list(zip(faces.first, faces.second)) == [(0, 1)]
    element, _ = topology.tip_edges(mesh, faces)
    assert sorted(element.tolist()) == [0, 1, 2, 2]


def test_turned_rectangle_shares_the_hinge_edge():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 2.0, 1.0, 2, 1)
    # turn a copy of the +e1 element about the vertical edge at x = 1 by 20 degrees
    angle = np.deg2rad(20)
    e1 = np.array([np.cos(angle), np.sin(angle), 0.0])
    center = np.array([1.0, 0.0, 0.0]) + 0.5 * e1
    turned = hd.Mesh3D.from_rectangles(center[None], e1[None], np.array([[0.0, 0, 1]]), [0.5], [0.5])
    faces = topology.element_faces(hd.mesh.concatenate([mesh, turned]))
    assert sorted(zip(faces.first.tolist(), faces.second.tolist())) == [(0, 1), (1, 2)]


def test_extra_connections_are_appended():
    mesh = hd.mesh.line([0, 0], [2, 0], 2)
    faces = topology.element_faces(mesh).append([1], [0], [0.3], [0.1], [0.2])
    assert faces.n_faces == 2
    assert faces.first[-1] == 0 and faces.second[-1] == 1
    assert faces.first_distance[-1] == 0.2 and faces.second_distance[-1] == 0.1


def _candidate_pairs_by_lists(mesh):
    """The candidate pairs as they were found before (a neighbour list per element), the
    reference for the array version."""
    import itertools

    from scipy.spatial import cKDTree

    radii = mesh.radii
    reach = radii + radii.max() * (1.0 + 1e-9) + 1e-12
    neighbours = cKDTree(mesh.centers).query_ball_point(mesh.centers, reach, return_sorted=True)
    counts = np.fromiter(map(len, neighbours), np.int64, len(neighbours))
    second = np.fromiter(itertools.chain.from_iterable(neighbours), np.int64, int(counts.sum()))
    first = np.repeat(np.arange(len(neighbours), dtype=np.int64), counts)
    keep = second > first
    return first[keep], second[keep]


@pytest.mark.parametrize("case", ["grid", "mixed", "segments"])
def test_candidate_pairs_are_those_of_the_neighbour_lists(case):
    from hmatddm.mesh.topology import _candidate_pairs

    rng = np.random.default_rng(4)
    if case == "grid":
        mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 20.0, 20.0, 40, 40)
    elif case == "mixed":  # a fine crack beside coarse elements: reaches differ per element
        mesh = hd.mesh.concatenate([hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 4.0, 16, 16),
                                    hd.mesh.rectangle([3.0, 0, 0], [0, 1, 0], [0, 0, 1], 6.0, 6.0, 3, 3)])
    else:
        p0 = rng.uniform(-5, 5, (300, 2))
        mesh = hd.Mesh2D.from_segments(p0, p0 + rng.uniform(0.1, 0.8, (300, 1)) * [[1.0, 0.3]])
    first, second = _candidate_pairs(mesh)
    expected = _candidate_pairs_by_lists(mesh)
    assert np.array_equal(first, expected[0]) and np.array_equal(second, expected[1])
