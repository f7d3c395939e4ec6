"""The near image triples tabulated in one angle (issue 32, :mod:`hmatddm.layered.near_table3d`):
the homogeneity they rest on, the table against the image sum at random angles and
heights, its convergence as the grid of angles is refined, the entries against the
quadrature of the same triples at the same rules, and the media that build none."""
import math

import numpy as np
import pytest

from test_layered_fast3d import _matrix, _random_mesh  # tests/layered on the path (pytest's prepend mode)

from hmatddm.layered import LayeredMedium
from hmatddm.layered import near_table3d as nt
from hmatddm.layered.influence3d import influence_data
from hmatddm.layered.images3d import with_image_terms
from hmatddm.layered.remainder_table3d import layer_bounds

INTERFACES = np.array([0.0, -1.5, -3.0])
SHEAR = np.array([0.0, 1.0, 2.0, 1.0])
POISSON = np.array([0.25, 0.25, 0.3, 0.2])


@pytest.fixture(scope="module")
def near():
    return nt.build_near_table(INTERFACES, SHEAR, POISSON)[0]


def _groups():
    for ls in (1, 2, 3):
        for lr in (ls - 1, ls, ls + 1):
            if 1 <= lr <= 3:
                for side in range(2):
                    geometry = nt.group_geometry(ls, lr, side, INTERFACES)
                    if geometry is not None:
                        yield ls, lr, side, geometry


def _direct(ls, lr, geometry, theta, tau, radius):
    out = np.empty((1, 1, 20))
    nt.sample_group(ls, lr, *geometry, np.array([theta]), np.array([tau]), radius, INTERFACES, SHEAR, POISSON,
                    *layer_bounds(INTERFACES), out)
    return out[0, 0]


def test_every_group_of_a_free_surface_over_two_interfaces_is_tabulated(near):
    """Three solid layers under a void: reflections in the free surface and both interfaces,
    transmissions both ways across both interfaces (9 groups), every adjacent pair ready."""
    assert len(list(_groups())) == 9
    for ls, lr, side, _ in _groups():
        assert near.group[ls, lr, side] >= 0
        assert near.ready[ls, lr]
    assert not near.ready[1, 3] and not near.ready[3, 1]


def test_near_triples_are_homogeneous_about_their_interface():
    """What the table rests on: ``R^3 T`` of every group at a given angle and ``tau`` is the
    same at any radius (no length but the offset from the interface), to round-off."""
    rng = np.random.default_rng(3)
    for ls, lr, side, geometry in _groups():
        for _ in range(4):
            theta = rng.uniform(0.0, 0.5 * math.pi)
            tau = rng.uniform(0.05, 1.0) * math.cos(theta)
            small, large = _direct(ls, lr, geometry, theta, tau, 0.2), _direct(ls, lr, geometry, theta, tau, 0.7)
            assert np.abs(small - large).max() <= 1e-12 * np.abs(large).max()


def test_the_table_matches_the_image_sum_at_random_angles_and_heights(near):
    """Every group at random physical angles and heights (the ends of the range included)
    against the traced triples summed directly: within 1e-10 of the group's largest value."""
    rng = np.random.default_rng(11)
    thetas = np.concatenate([[0.0, 0.5 * math.pi - 1e-9], rng.uniform(0.0, 0.5 * math.pi, 30)])
    w = np.empty((1, nt.STENCIL))
    for ls, lr, side, geometry in _groups():
        anchor, reflected, source_side, receiver_sign = geometry
        q = near.group[ls, lr, side]
        worst, largest = 0.0, 0.0
        for theta in thetas:
            tau = rng.uniform(0.0, 1.0) * math.cos(theta)
            radius = rng.uniform(0.05, 1.2)
            t = anchor + source_side * tau * radius
            point = 2.0 * anchor - t if reflected else t
            got = np.zeros(20)
            nt._add_group(near, q, radius * math.sin(theta), t, point + receiver_sign * radius * math.cos(theta), got,
                          w)
            direct = _direct(ls, lr, geometry, theta, tau, 0.5)
            worst = max(worst, np.abs(got * radius ** 3 - direct).max())
            largest = max(largest, np.abs(direct).max())
        assert worst <= 1e-10 * largest


def test_the_error_falls_as_the_grid_of_angles_is_refined(monkeypatch):
    """The interpolation in the angle converges: halving the spacing from 8 to 16 to 32
    angles lowers the measured error by at least 8x each time (a degree-5 rule: ~64x)."""
    errors = []
    for nodes in (8, 16, 32):
        monkeypatch.setattr(nt, "FIRST_NODES", nodes)
        monkeypatch.setattr(nt, "NEAR_TABLE_TOL", 1.0)  # no refinement: the first grid's error
        errors.append(nt.build_near_table(INTERFACES, SHEAR, POISSON)[1]["near_error"])
    assert errors[0] > 8.0 * errors[1] > 64.0 * errors[2] > 0.0


def test_entries_equal_the_quadrature_of_the_near_triples_at_the_same_rules(monkeypatch):
    """Randomly oriented squares 0.1-0.6 m from the free surface and both interfaces, in all
    three layers (sub-squares and one-square rules, each mirror on its own rule): the entries
    with the near table equal those with the near triples integrated by their quadrature
    (the table left out), to 1e-10 of the largest entry."""
    from hmatddm.layered import influence3d

    monkeypatch.setattr(influence3d, "TABLE_MIN_ELEMENTS", 0)
    centers = [[x, 0.3 * x, z] for z in (-0.2, -0.7, -1.3, -1.75, -2.4, -2.8, -3.3, -3.9) for x in (0.0, 0.9)]
    mesh = _random_mesh(7, centers, 0.15)
    medium = LayeredMedium(list(INTERFACES), list(SHEAR), list(POISSON), images=3)
    data = influence_data(mesh, medium, 0.0, 0.0, 0.0, 3)
    assert data.table.near.ready[1, 2] and data.table.near.ready[2, 2]
    without = with_image_terms(data._replace(table=data.table._replace(near=nt.empty_near_table(4))))
    reference = _matrix(without)
    assert np.abs(_matrix(data) - reference).max() <= 1e-10 * np.abs(reference).max()


def test_media_without_far_triples_or_with_merged_images_build_no_near_table(monkeypatch):
    """A bi-material builds no remainder table, so no near table; where a deeper image merges
    with a near triple (remainder_build3d.near_images > 1) the near triples are no first
    reflections alone, and the table is left empty (the quadrature takes them)."""
    from hmatddm.layered import remainder_build3d as build

    mesh = _random_mesh(1, [[0.0, 0.0, -1.0], [1.0, 0.0, -2.0]], 0.2)
    medium = LayeredMedium([-1.5], [1.0, 3.0], [0.25, 0.25], images=1)
    data = influence_data(mesh, medium, 0.0, 0.0, 0.0, 1)
    assert not data.table.near.ready.any()
    monkeypatch.setattr(build, "near_images", lambda *args: 3)
    g = SHEAR
    table, stats = build.build_table(mesh, np.array([1, 2]), INTERFACES, g, POISSON, 3, 1e-6, 10.0)
    assert table.near_images == 3 and not table.near.ready.any() and "near_groups" not in stats
