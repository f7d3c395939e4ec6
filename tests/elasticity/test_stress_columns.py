"""StressColumns (hmatddm.elasticity.stress_columns): the stress of a growing 3D mesh at
fixed points in a layered medium, element terms kept across calls, is the direct layered
sum (hd.stress_at) to rounding; only appended elements are computed; anything else starts
again; 2D meshes and an unknown number of images are left to the direct sum."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.elasticity.stress_columns import StressColumns
from hmatddm.layered import LayeredMedium

G, NU = 10e9, 0.25
#: stiffer bounding layers (the stage's contrast, issue 35), one image, few Gauss points
MEDIUM = LayeredMedium([1.0, -1.0], [1.5 * G, G, 1.5 * G], [NU] * 3, images=1, gauss_points=3)


def _mesh():
    """A vertical fracture of the middle layer and a row into each bounding layer, and
    targets around it (some in the bounding layers, two at near misses)."""
    mid = hd.mesh.rectangle([0.0, 0.0, 0.0], [0, 1, 0], [0, 0, 1], 2.0, 2.0, 2, 2)
    top = hd.mesh.rectangle([0.0, 0.0, 1.5], [0, 1, 0], [0, 0, 1], 2.0, 1.0, 2, 1)
    bottom = hd.mesh.rectangle([0.0, 0.0, -1.5], [0, 1, 0], [0, 0, 1], 2.0, 1.0, 2, 1)
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(0.3, 3.0, 12), rng.uniform(-2, 2, 12), rng.uniform(-2.5, 2.5, 12)])
    points = np.vstack([points, [[0.0, 1.0 + 1e-3, 0.5], [0.0, 0.5, 1.0 + 1e-3]]])
    return hd.mesh.concatenate([mid, top, bottom]), points


def _direct(mesh, dd, points):
    return hd.stress_at(mesh, MEDIUM, dd, points, singular_correction="average", near_fraction=0.5)


@pytest.mark.slow  # the 3D layered stress kernel compiles cold in a minute or two
def test_kept_terms_are_the_direct_sum_and_only_new_elements_are_computed():
    mesh, points = _mesh()
    rng = np.random.default_rng(0)
    rows = np.arange(len(points))
    first = mesh.subset(np.arange(4))
    columns = StressColumns.reuse(None, first, MEDIUM, points, rows, 1, "average", 0.5)
    dd = rng.normal(size=(4, 3)) * 1e-3
    ref = _direct(first, dd, points)
    np.testing.assert_allclose(columns.stress(first, dd, rows), ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert columns.computed == 4
    # the same mesh, other DDs: nothing computed
    dd = rng.normal(size=(4, 3)) * 1e-3
    ref = _direct(first, dd, points)
    again = StressColumns.reuse(columns, first, MEDIUM, points, rows, 1, "average", 0.5)
    assert again is columns
    np.testing.assert_allclose(again.stress(first, dd, rows), ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert columns.computed == 4
    # grown (appended elements), at fewer targets: only the new elements computed
    dd = rng.normal(size=(mesh.n_elements, 3)) * 1e-3
    fewer = rows[::2]
    ref = _direct(mesh, dd, points[fewer])
    grown = StressColumns.reuse(columns, mesh, MEDIUM, points, fewer, 1, "average", 0.5)
    assert grown is columns
    np.testing.assert_allclose(grown.stress(mesh, dd, fewer), ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    assert columns.computed == mesh.n_elements
    # the terms differ from the homogeneous rock's (the images are in them)
    homogeneous = hd.stress_at(mesh, hd.Elastic(G, NU), dd, points[fewer], singular_correction="average",
                               near_fraction=0.5)
    assert np.abs(ref - homogeneous).max() > 1e-3 * np.abs(ref).max()


def test_anything_but_an_extension_starts_again_and_2d_is_left_to_the_direct_sum():
    mesh, points = _mesh()
    rows = np.arange(len(points))
    columns = StressColumns(points, rows, MEDIUM, 1, "average", 0.5)
    columns.geometry = (mesh.centers, mesh.frames, mesh.half_a, mesh.half_b)  # as if it had seen ``mesh``
    assert columns.serves(mesh, MEDIUM, points, rows, 1, "average", 0.5)
    moved = mesh.subset(np.arange(mesh.n_elements)[::-1])  # the same elements in another order
    assert not columns.serves(moved, MEDIUM, points, rows, 1, "average", 0.5)
    assert not columns.serves(mesh, MEDIUM, points, rows, 2, "average", 0.5)  # other images
    assert not columns.serves(mesh, MEDIUM, points, rows, 1, "none", 0.5)
    other = LayeredMedium([1.0, -1.0], [1.5 * G, G, 1.5 * G], [NU] * 3, images=1, gauss_points=3)
    assert not columns.serves(mesh, other, points, rows, 1, "average", 0.5)
    assert not columns.serves(mesh.subset(np.arange(3)), MEDIUM, points, rows, 1, "average", 0.5)  # fewer
    assert not columns.serves(mesh, MEDIUM, points, np.array([len(points)]), 1, "average", 0.5)  # a new target
    assert StressColumns.reuse(columns, moved, MEDIUM, points, rows, 1, "average", 0.5) is not columns
    assert StressColumns.reuse(None, mesh, MEDIUM, points, rows, None, "average", 0.5) is None
    line = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 4)
    assert StressColumns.reuse(None, line, MEDIUM, points[:, :2], rows, 1, "average", 0.5) is None
