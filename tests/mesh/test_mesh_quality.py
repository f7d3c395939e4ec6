"""hmatddm.mesh.quality: close near-parallel elements of different fractures (against a
brute-force search written apart), the warning that names the refined size, and the
check of a mesh's own arrays."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.mesh.quality import check_mesh


# ------------------------------------------------------------ close parallel pairs
def overlaps(mesh, i, j):
    """Element j overlaps element i projected on i's plane (strictly, not end to end)."""
    d = mesh.centers[j] - mesh.centers[i]
    if mesh.dim == 2:
        ti, tj = mesh.tangents[i], mesh.tangents[j]
        return abs(d @ ti) < (mesh.half_length[i] + mesh.half_length[j] * abs(tj @ ti)) * (1 - 1e-9)
    return all(abs(d @ mesh.frames[i, k]) < (half[i] + mesh.half_a[j] * abs(mesh.frames[j, 0] @ mesh.frames[i, k])
                                              + mesh.half_b[j] * abs(mesh.frames[j, 1] @ mesh.frames[i, k]))
               * (1 - 1e-9) for k, half in ((0, mesh.half_a), (1, mesh.half_b)))


def brute_force_parallel_pairs(mesh, factor=0.6, max_angle_deg=20.0):
    """The criteria of hd.mesh.close_parallel_pairs on every pair, in plain Python."""
    size = 2 * (mesh.half_length if mesh.dim == 2 else np.maximum(mesh.half_a, mesh.half_b))
    extent = {}
    for f in np.unique(mesh.fracture_id):
        members = mesh.fracture_id == f
        c = mesh.centers[members]
        extent[f] = (c.max(axis=0) - c.min(axis=0)).max() + size[members].max()
    found = set()
    for i in range(mesh.n_elements):
        for j in range(i + 1, mesh.n_elements):
            if mesh.fracture_id[i] == mesh.fracture_id[j]:
                continue
            ni, nj, d = mesh.normals[i], mesh.normals[j], mesh.centers[j] - mesh.centers[i]
            if abs(ni @ nj) < np.cos(np.radians(max_angle_deg)):
                continue
            if not (overlaps(mesh, i, j) and overlaps(mesh, j, i)):
                continue
            spacing = max(abs(d @ ni), abs(d @ nj))
            h = max(size[i], size[j])
            length = min(extent[mesh.fracture_id[i]], extent[mesh.fracture_id[j]])
            if length >= 0.5 * h and spacing < factor * h * (length / h) ** 0.25:
                found.add((i, j))
    return found


def random_fractures(dim, seed, count=6):
    """Small fractures of random size, element size and orientation, packed close."""
    rng = np.random.default_rng(seed)
    parts = []
    for k in range(count):
        centre = rng.uniform(-0.4, 0.4, size=dim)
        length = rng.uniform(0.3, 2.0)
        if dim == 2:
            angle = rng.choice([0.0, rng.uniform(-0.5, 0.5)])
            t = np.array([np.cos(angle), np.sin(angle)])
            parts.append(hd.mesh.line(centre - 0.5 * length * t, centre + 0.5 * length * t,
                                      int(rng.integers(2, 30)), fracture_id=k))
        else:
            normal = np.array([0.0, 0.0, 1.0]) + rng.choice([0.0, 0.4]) * rng.normal(size=3)
            e1, e2 = hd.mesh.in_plane_axes(normal)
            parts.append(hd.mesh.rectangle(centre, e1, e2, length, rng.uniform(0.3, 1.0),
                                           int(rng.integers(1, 8)), int(rng.integers(1, 8)), fracture_id=k))
    return hd.mesh.concatenate(parts)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", range(6))
def test_close_parallel_pairs_match_a_brute_force_search(dim, seed):
    """The KD-tree search (per fracture, pruned by fracture) finds exactly the pairs that
    the criteria select among all N^2 pairs; element sizes differ up to ~50x."""
    mesh = random_fractures(dim, seed)
    pairs = hd.mesh.close_parallel_pairs(mesh)
    found = set(zip(pairs.first.tolist(), pairs.second.tolist()))
    assert found == brute_force_parallel_pairs(mesh)
    assert len(found) == len(pairs.first)  # each pair once
    ratio = pairs.spacing / pairs.limit
    assert np.all(ratio < 1) and np.all(np.diff(ratio) >= 0)  # worst first


def test_close_parallel_pairs_geometry():
    """Two parallel 2 m cracks of 0.1 m elements: bound 0.6 h (L/h)^(1/4) = 0.1269 m."""
    lower = hd.mesh.line([-1, 0], [1, 0], 20)

    def pairs(upper):
        return hd.mesh.close_parallel_pairs(hd.mesh.concatenate([lower, upper]))

    limit = 0.6 * 0.1 * 20**0.25
    below = pairs(hd.mesh.line([-1, 0.99 * limit], [1, 0.99 * limit], 20, fracture_id=1))
    assert len(below.first) == 20 and np.allclose(below.limit, limit) and np.allclose(below.spacing, 0.99 * limit)
    assert np.all(below.second == below.first + 20) and np.allclose(below.fracture_extent, 2.0)
    assert len(pairs(hd.mesh.line([-1, 1.01 * limit], [1, 1.01 * limit], 20, fracture_id=1)).first) == 0
    # the same crack split in two fractures end to end, or a collinear one beyond the tip
    assert len(hd.mesh.close_parallel_pairs(hd.mesh.concatenate([
        hd.mesh.line([-1, 0], [0, 0], 10), hd.mesh.line([0, 0], [1, 0], 10, fracture_id=1)])).first) == 0
    assert len(pairs(hd.mesh.line([1.05, 0], [2, 0], 10, fracture_id=1)).first) == 0
    # within the same fracture, or crossing at right angles: nothing
    same_fracture = hd.mesh.concatenate([lower, hd.mesh.line([-1, 0.01], [1, 0.01], 20)])
    assert len(hd.mesh.close_parallel_pairs(same_fracture).first) == 0
    assert len(pairs(hd.mesh.line([0.05, -1], [0.05, 1], 20, fracture_id=1)).first) == 0
    # tilted by 15 degrees (near-parallel) and by 30 (not)
    for degrees, expected in ((15.0, True), (30.0, False)):
        t = np.array([np.cos(np.radians(degrees)), np.sin(np.radians(degrees))])
        found = pairs(hd.mesh.line(-t + [0, 0.05], t + [0, 0.05], 20, fracture_id=1))
        assert (len(found.first) > 0) == expected
    # a fracture smaller than half an element of the other: its constant DD cannot hold the mode
    coarse = hd.mesh.line([-5, 0], [5, 0], 10)  # h = 1
    small = hd.mesh.line([-0.2, 0.05], [0.2, 0.05], 10, fracture_id=1)  # L = 0.4
    assert len(hd.mesh.close_parallel_pairs(hd.mesh.concatenate([coarse, small])).first) == 0
    larger = hd.mesh.line([-0.3, 0.05], [0.3, 0.05], 10, fracture_id=1)  # L = 0.6
    assert len(hd.mesh.close_parallel_pairs(hd.mesh.concatenate([coarse, larger])).first) > 0


def test_close_parallel_pennies_3d():
    lower = hd.mesh.penny([0, 0, 0], [0, 0, 1], 1.0, 0.25)
    upper = hd.mesh.penny([0.06, 0.06, 0.2], [0, 0, 1], 1.0, 0.25, fracture_id=1)
    pairs = hd.mesh.close_parallel_pairs(hd.mesh.concatenate([lower, upper]))
    assert len(pairs.first) > 0 and np.allclose(pairs.spacing, 0.2)
    assert np.allclose(pairs.limit, 0.6 * 0.25 * 8**0.25) and np.allclose(pairs.fracture_extent, 2.0)
    far = hd.mesh.penny([0.06, 0.06, 0.3], [0, 0, 1], 1.0, 0.25, fracture_id=1)
    assert len(hd.mesh.close_parallel_pairs(hd.mesh.concatenate([lower, far])).first) == 0


def test_check_parallel_spacing_warns_with_the_refined_size():
    import warnings

    def parallel(spacing, n):
        return hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], n),
                                    hd.mesh.line([-1, spacing], [1, spacing], n + 1, fracture_id=1)])

    with pytest.warns(hd.errors.MeshQualityWarning, match=r"h <= ([0-9.e-]+) m") as record:
        pairs = hd.mesh.check_parallel_spacing(parallel(0.05, 20))
    size = pairs.refined_size()
    assert f"h <= {size:.3g} m" in str(record[0].message)
    assert 0.6 * size**0.75 * 2.0**0.25 == pytest.approx(0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error", hd.errors.MeshQualityWarning)
        assert len(hd.mesh.check_parallel_spacing(parallel(0.05, int(np.ceil(2.0 / size)))).first) == 0
        assert len(hd.mesh.check_parallel_spacing(hd.mesh.line([-1, 0], [1, 0], 20)).first) == 0
    coplanar = hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], 20), hd.mesh.line([-0.5, 0], [1.5, 0], 20,
                                                                                      fracture_id=1)])
    with pytest.warns(hd.errors.MeshQualityWarning, match="merge the fractures"):
        hd.mesh.check_parallel_spacing(coplanar)


@pytest.mark.parametrize("kwargs, message", [(dict(factor=0.0), "factor must be > 0"),
                                             (dict(max_angle_deg=95.0), r"max_angle_deg must be in \(0, 90\]")])
def test_close_parallel_pairs_bad_arguments(kwargs, message):
    with pytest.raises(hd.InputError, match=message):
        hd.mesh.close_parallel_pairs(hd.mesh.line([0, 0], [1, 0], 2), **kwargs)



def test_check_mesh_names_the_first_bad_array_entry():
    mesh = hd.mesh.line([0.0, 0.0], [1.0, 0.0], 4)
    assert check_mesh(mesh) is mesh
    mesh.half_length[2] = 0.0  # arrays of a built mesh can be changed in place
    with pytest.raises(hd.InputError, match=r"mesh.half_length\[2\] must be > 0 m, got 0.0"):
        check_mesh(mesh)
    empty = hd.mesh.line([0.0, 0.0], [1.0, 0.0], 1).subset(np.zeros(0, dtype=np.int64))
    with pytest.raises(hd.InputError, match="has no elements"):
        check_mesh(empty, "natural_fractures")
