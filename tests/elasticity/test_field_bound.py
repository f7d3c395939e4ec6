"""Upper bound of the induced stress (hmatddm.elasticity.field_bound): the point-DD constants against
the kernels' own response, and the bound against the exact sum of hmatddm.elasticity.fields at points
near and far, 2D and 3D."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.elasticity.field_bound import POINT_DD_CONSTANT_2D, POINT_DD_CONSTANT_3D, stress_bound
from hmatddm.kernels import line2d, rectangle3d


def _sphere(n, rng):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


@pytest.mark.parametrize("nu", [-0.9, 0.0, 0.25, 0.49])
def test_point_dd_constants_bound_the_kernels_far_response(nu):
    # a small element seen from unit distance: R^p |sigma(b)|_F / (G |b| A) times k pi (1 - nu)
    # is the point-DD constant; maximised over directions and over the DD direction (the
    # largest singular value of the components-by-DD matrix)
    g, h = 1.0, 1e-4
    rng = np.random.default_rng(1)
    out3 = np.empty((3, 3, 3))
    largest3 = 0.0
    for x in np.vstack([_sphere(3000, rng), [[0.0, 0.0, 1.0]]]):
        rectangle3d.local_stress(x[0], x[1], x[2], h, h, g, nu, out3)
        largest3 = max(largest3, np.linalg.svd(out3.reshape(3, 9).T, compute_uv=False)[0])
    c3 = largest3 / (4 * h * h) * 4 * np.pi * (1 - nu) / g
    out2 = np.empty((2, 2, 2))
    largest2 = 0.0
    for t in np.linspace(0.0, 2 * np.pi, 3001):
        line2d.local_stress(np.cos(t), np.sin(t), h, g, nu, out2)
        largest2 = max(largest2, np.linalg.svd(out2.reshape(2, 4).T, compute_uv=False)[0])
    c2 = largest2 / (2 * h) * 2 * np.pi * (1 - nu) / g
    assert 0.8 * POINT_DD_CONSTANT_3D < c3 <= POINT_DD_CONSTANT_3D
    assert 0.95 * POINT_DD_CONSTANT_2D < c2 <= POINT_DD_CONSTANT_2D


def _mesh3d(rng, n):
    centers = rng.uniform(-4, 4, (n, 3))
    e1 = _sphere(n, rng)
    e2 = np.cross(e1, rng.normal(size=(n, 3)))
    e2 /= np.linalg.norm(e2, axis=1)[:, None]
    return hd.Mesh3D.from_rectangles(centers, e1, e2, rng.uniform(0.2, 1.0, n), rng.uniform(0.2, 1.0, n))


def _points_near_and_far(rng, mesh, n):
    """Points at 0.05 - 30 element sizes from random elements, and a few far away."""
    j = rng.integers(0, mesh.n_elements, n)
    offset = rng.normal(size=(n, mesh.dim))
    offset /= np.linalg.norm(offset, axis=1)[:, None]
    distance = np.exp(rng.uniform(np.log(0.05), np.log(30.0), n)) * mesh.radii[j]
    return mesh.centers[j] + distance[:, None] * offset


@pytest.mark.parametrize("dim", [2, 3])
def test_bound_is_above_the_exact_stress_and_not_far_above(dim):
    rng = np.random.default_rng(7)
    mat = hd.Elastic(6.62e9, 0.25)
    if dim == 3:
        mesh = _mesh3d(rng, 60)
    else:
        start = rng.uniform(-4, 4, (60, 2))
        angle = rng.uniform(0, np.pi, 60)
        length = rng.uniform(0.3, 1.5, 60)
        mesh = hd.Mesh2D.from_segments(start, start + length[:, None] * np.column_stack([np.cos(angle),
                                                                                         np.sin(angle)]))
    dd = rng.normal(scale=1e-3, size=(mesh.n_elements, dim))
    points = _points_near_and_far(rng, mesh, 400)
    bound = stress_bound(mesh, mat, dd, points, near_fraction=0.5)
    finite = np.isfinite(bound)
    assert 100 < np.count_nonzero(finite) < len(points)  # the near points have no bound
    stress = hd.stress_at(mesh, mat, dd, points[finite], singular_correction="average", method="direct",
                          near_fraction=0.5)
    exact = np.linalg.norm(stress.reshape(len(stress), -1), axis=1)
    assert np.all(bound[finite] >= exact)
    # loose where the random DDs cancel (median 33x in 3D here), but not by orders of magnitude
    assert np.median(bound[finite] / exact) < 100.0
    # a limit stops a point's sum once passed: what is returned then still passes it
    limit = np.full(len(points), np.median(bound[finite]))
    limited = stress_bound(mesh, mat, dd, points, near_fraction=0.5, limit=limit)
    assert np.array_equal(limited >= limit, bound >= limit)
    assert np.array_equal(limited[bound < limit], bound[bound < limit])
    # leaves of a cluster tree of the points bounded whole first: still above the exact
    # stress wherever it is below the limit; -inf marks points not needed
    from hmatddm.hmatrix.cluster_tree import cluster_tree

    limit = np.where(np.arange(len(points)) % 5 == 0, -np.inf, 10.0 * np.median(bound[finite]))
    grouped = stress_bound(mesh, mat, dd, points, near_fraction=0.5, limit=limit,
                           point_tree=cluster_tree(points, 0.0, 16))
    below = (grouped < limit) & finite
    assert np.count_nonzero(below) > 50
    assert np.all(grouped[below] >= exact[below[finite]])
    needed = limit > -np.inf
    assert np.all((grouped < limit)[needed] <= (bound < limit)[needed])  # a leaf bound is never tighter


def test_points_on_or_near_an_element_have_no_bound():
    mat = hd.Elastic(1e9, 0.2)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 2, 2)
    dd = np.tile([0.0, 0.0, 1e-3], (mesh.n_elements, 1))
    points = np.array([[0.5, 0.5, 0.0], [1.0, 0.2, 0.0], [1.2, 0.5, 0.0], [1.6, 0.5, 0.0], [0.5, 0.5, 3.0]])
    bound = stress_bound(mesh, mat, dd, points, near_fraction=0.5)
    # on an element, on its edge, 0.2 m from an edge (half size 0.5: within 0.25); then free
    assert np.all(np.isinf(bound[:3])) and np.all(np.isfinite(bound[3:]))
    assert np.all(np.isfinite(stress_bound(mesh, mat, dd, points[2:3], near_fraction=0.0)))
