import numpy as np
import pytest

import hmatddm as hd
from conftest import random_rotation


def test_rectangle_mesh_geometry():
    m = hd.mesh.rectangle([1, 2, 3], [1, 0, 0], [0, 0, 1], 40.0, 20.0, 8, 4)
    assert m.n_elements == 32
    assert np.allclose(m.areas, 25.0)
    assert np.allclose(m.normals, [0, -1, 0])  # e1 x e2 = x cross z = -y
    assert np.allclose(m.centers.mean(axis=0), [1, 2, 3])
    assert np.allclose(np.einsum("nij,nkj->nik", m.frames, m.frames), np.eye(3))


def test_penny_is_a_staircase_disc():
    m = hd.mesh.penny([0, 0, 0], [1, 1, 1], 1.0, 0.1)
    assert np.all(np.linalg.norm(m.centers, axis=1) < 1.0)
    assert np.allclose(m.normals, np.ones(3) / np.sqrt(3))
    # area close to the disc's, symmetric about the centre
    assert abs(m.areas.sum() - np.pi) / np.pi < 0.03
    assert np.allclose(m.centers.mean(axis=0), 0.0, atol=1e-12)


def test_line_mesh_normals_turn_left():
    m = hd.mesh.line([0, 0], [0, 2], 4)
    assert np.allclose(m.normals, [-1, 0])
    assert np.allclose(m.areas, 0.5)
    p0, p1 = m.endpoints
    assert np.allclose(p0[1:], p1[:-1])


def test_from_rectangles_any_orientation_and_size():
    rng = np.random.default_rng(3)
    rot = np.array([random_rotation(rng) for _ in range(5)])
    m = hd.Mesh3D.from_rectangles(rng.normal(size=(5, 3)), rot[:, :, 0], rot[:, :, 1],
                                  rng.uniform(0.1, 5, 5), rng.uniform(0.01, 2, 5))
    assert np.allclose(m.normals, rot[:, :, 2])
    assert m.corners().shape == (5, 4, 3)


@pytest.mark.parametrize("kwargs, message", [
    (dict(half_a=0.0), "half_a must be > 0"),
    (dict(half_b=-1.0), "half_b must be > 0"),
    (dict(e1=[1.0, 0.1, 0.0]), "e1 must be unit vectors"),
    (dict(e2=[0.6, 0.8, 0.0]), "e1 and e2 must be orthogonal"),
    (dict(centers=[[0, 0, np.nan]]), "centers must contain only finite numbers"),
    (dict(centers=[[0, 0]]), r"centers must have shape \(N, 3\)"),
])
def test_degenerate_rectangles_are_refused(kwargs, message):
    args = dict(centers=[[0, 0, 0]], e1=[1.0, 0, 0], e2=[0, 1.0, 0], half_a=1.0, half_b=1.0)
    args.update(kwargs)
    with pytest.raises(hd.InputError, match=message):
        hd.Mesh3D.from_rectangles(**args)


def test_degenerate_segments_are_refused():
    with pytest.raises(hd.InputError, match="zero length"):
        hd.Mesh2D.from_segments([[0, 0], [1, 0]], [[1, 0], [1, 0]])
    with pytest.raises(hd.InputError, match="finite"):
        hd.Mesh2D.from_segments([[0, np.inf]], [[1, 0]])
    with pytest.raises(hd.InputError, match="n must be an integer >= 1"):
        hd.mesh.line([0, 0], [1, 0], 0)
    with pytest.raises(hd.InputError, match="h must be > 0"):
        hd.mesh.penny([0, 0, 0], [0, 0, 1], 1.0, 0.0)


def test_concatenate_keeps_fracture_ids():
    a = hd.mesh.line([0, 0], [1, 0], 3, fracture_id=0)
    b = hd.mesh.line([0, 1], [1, 2], 2, fracture_id=7)
    m = hd.mesh.concatenate([a, b])
    assert m.n_elements == 5 and list(m.fracture_id) == [0, 0, 0, 7, 7]
