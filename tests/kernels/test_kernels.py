"""The closed-form kernels against an independent computation (Gauss quadrature of
the Kelvin solution, tests/kelvin_reference.py) and their behaviour at awkward points."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import G, NU, random_rotation
from kelvin_reference import rectangle_quadrature, segment_quadrature, stress_from_dd
from hmatddm.kernels import line2d, rectangle3d


def rect_stress(x, center, frame, a, b, shift=0.0):
    out, work = np.empty((3, 3, 3)), np.empty((3, 3, 3))
    rectangle3d.stress_pair(np.asarray(x, float), center, frame, a, b, G, NU, shift, out, work)
    return out


def line_stress(x, center, frame, a, shift=0.0):
    out, work = np.empty((2, 2, 2)), np.empty((2, 2, 2))
    line2d.stress_pair(np.asarray(x, float), center, frame, a, G, NU, shift, out, work)
    return out


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), a=st.floats(0.05, 2.0), b=st.floats(0.05, 2.0),
       distance=st.floats(3.0, 20.0))
def test_rectangle_matches_kelvin_quadrature(seed, a, b, distance):
    rng = np.random.default_rng(seed)
    frame = random_rotation(rng).T.copy()
    center = rng.normal(size=3)
    direction = rng.normal(size=3)
    x = center + direction / np.linalg.norm(direction) * distance * np.hypot(a, b)
    pts, w = rectangle_quadrature(center, frame[0], frame[1], a, b, order=20)
    exact = stress_from_dd(x, pts, w, frame[2], NU, G)
    got = rect_stress(x, center, frame, a, b)
    assert np.max(np.abs(got - exact)) <= 1e-9 * np.max(np.abs(exact))


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(0, 2 * np.pi), a=st.floats(0.05, 2.0), distance=st.floats(3.0, 20.0),
       direction=st.floats(0, 2 * np.pi))
def test_line_matches_kelvin_quadrature(angle, a, distance, direction):
    t = np.array([np.cos(angle), np.sin(angle)])
    frame = np.array([t, [-t[1], t[0]]])
    center = np.array([0.3, -0.7])
    x = center + distance * a * np.array([np.cos(direction), np.sin(direction)])
    pts, w = segment_quadrature(center, t, a, order=40)
    exact = stress_from_dd(x, pts, w, frame[1], NU, G)
    got = line_stress(x, center, frame, a)
    assert np.max(np.abs(got - exact)) <= 1e-9 * np.max(np.abs(exact))


def test_rectangle_near_field_matches_refined_quadrature():
    """Closer than the well-separated regime: split the element into sub-rectangles."""
    frame = np.eye(3)
    center = np.zeros(3)
    x = np.array([0.7, 0.4, 0.3])  # one element size away, off-plane
    exact = np.zeros((3, 3, 3))
    n = 16
    for i in range(n):
        for j in range(n):
            c = np.array([-1 + (2 * i + 1) / n, -0.5 + (2 * j + 1) / (2 * n), 0.0])
            pts, w = rectangle_quadrature(c, frame[0], frame[1], 1.0 / n, 0.5 / n, order=8)
            exact += stress_from_dd(x, pts, w, frame[2], NU, G)
    got = rect_stress(x, center, frame, 1.0, 0.5)
    assert np.max(np.abs(got - exact)) <= 1e-6 * np.max(np.abs(exact))


def test_opening_compresses_its_own_element_and_shear_loads_shear():
    out = rect_stress([0.0, 0.0, 0.0], np.zeros(3), np.eye(3), 1.0, 1.0)
    assert out[2, 2, 2] < 0  # opening -> compressive normal traction on itself
    assert out[0, 0, 2] < 0 and out[1, 1, 2] < 0  # slip -> opposing shear traction
    assert abs(out[2, 0, 2]) < 1e-6 * abs(out[2, 2, 2])  # no normal/shear coupling on a planar element
    out2 = line_stress([0.0, 0.0], np.zeros(2), np.eye(2), 1.0)
    assert out2[1, 1, 1] < 0 and out2[0, 0, 1] < 0


@pytest.mark.parametrize("point", [[3.0, 1.0, 0.0], [1.0, -4.0, 0.0], [-1.0, 2.5, 0.0], [1.0, 1.0 + 1e-3, 0.0]])
def test_rectangle_is_regular_on_edge_extensions(point):
    """Points on the extension of an edge line (x1 = +-a or x2 = +-b, in plane) are regular:
    finite and continuous with their neighbourhood."""
    frame, center = np.eye(3), np.zeros(3)
    at = rect_stress(point, center, frame, 1.0, 1.0)
    assert np.all(np.isfinite(at))
    for offset in ([1e-9, 0, 0], [0, 1e-9, 0], [0, 0, 1e-9], [0, 0, -1e-9]):
        near = rect_stress(np.add(point, offset), center, frame, 1.0, 1.0)
        assert np.max(np.abs(near - at)) <= 1e-5 * np.max(np.abs(at))


def test_line_is_regular_on_its_extension():
    at = line_stress([3.0, 0.0], np.zeros(2), np.eye(2), 1.0)
    near = line_stress([3.0, 1e-8], np.zeros(2), np.eye(2), 1.0)
    assert np.all(np.isfinite(at)) and np.max(np.abs(near - at)) <= 1e-6 * np.max(np.abs(at))


def test_points_on_an_edge_are_nan_unless_averaged():
    frame, center = np.eye(3), np.zeros(3)
    for point in ([1.0, 0.2, 0.0], [0.3, -1.0, 0.0], [1.0, 1.0, 0.0]):
        assert np.all(np.isnan(rect_stress(point, center, frame, 1.0, 1.0)))
        averaged = rect_stress(point, center, frame, 1.0, 1.0, shift=1e-3)
        assert np.all(np.isfinite(averaged))
    assert np.all(np.isnan(line_stress([1.0, 0.0], np.zeros(2), np.eye(2), 1.0)))
    assert np.all(np.isfinite(line_stress([1.0, 0.0], np.zeros(2), np.eye(2), 1.0, shift=1e-3)))


def test_traction_is_stress_times_receiver_normal():
    rng = np.random.default_rng(5)
    frame = random_rotation(rng).T.copy()
    x, n = rng.normal(size=3) * 3, random_rotation(rng)[:, 2]
    stress = rect_stress(x, np.zeros(3), frame, 0.4, 0.9)
    out, work = np.empty((3, 3)), np.empty((3, 3, 3))
    rectangle3d.traction_pair(x, n, np.zeros(3), frame, 0.4, 0.9, G, NU, 0.0, out, work)
    assert np.allclose(out, np.einsum("qij,j->iq", stress, n), rtol=1e-12, atol=0)


def test_mean_stress_influence_is_trace_of_stress():
    """ref. Eqs 5.25-5.29 against the trace of the full stress (ref. Eq. 2.59)."""
    rng = np.random.default_rng(6)
    frame = random_rotation(rng).T.copy()
    x = rng.normal(size=3) * 2
    out = np.empty(3)
    rectangle3d.mean_stress_pair(x, np.zeros(3), frame, 0.5, 0.3, G, NU, out)
    assert np.allclose(out, np.trace(rect_stress(x, np.zeros(3), frame, 0.5, 0.3), axis1=1, axis2=2) / 3)
    t = np.array([np.cos(0.4), np.sin(0.4)])
    frame2 = np.array([t, [-t[1], t[0]]])
    out2 = np.empty(2)
    line2d.mean_stress_pair(x[:2], np.zeros(2), frame2, 0.5, G, NU, out2)
    assert np.allclose(out2, np.trace(line_stress(x[:2], np.zeros(2), frame2, 0.5), axis1=1, axis2=2) / 2)


# ------------------------------------------------------ near-miss points (near > 0)
def test_line_point_near_a_tip_is_treated_as_on_it():
    """Within ``near`` of an end point (beyond it, on the element or off its line) the
    point is singular: NaN without averaging, else exactly the averaged value at the tip;
    beyond ``near`` the plain kernel (~1/gap) is used."""
    frame, center, a = np.eye(2), np.zeros(2), 1.0
    out, work = np.empty((2, 2, 2)), np.empty((2, 2, 2))
    at_tip = line_stress([a, 0.0], center, frame, a, shift=1e-3)
    for gap in (1e-9, 1e-4, 0.3):
        for point in ([a + gap, 0.0], [a - gap, 0.0], [a, gap], [a + 0.6 * gap, -0.8 * gap]):
            line2d.stress_pair(np.array(point), center, frame, a, G, NU, 0.0, out, work, 0.4)
            assert np.all(np.isnan(out))
            line2d.stress_pair(np.array(point), center, frame, a, G, NU, 1e-3, out, work, 0.4)
            np.testing.assert_allclose(out, at_tip, rtol=1e-12, atol=0)
        # without near (the default) the entry is finite and of order 1/gap
        raw = line_stress([a, gap], center, frame, a)
        assert np.all(np.isfinite(raw)) and np.abs(raw).max() > 0.05 * G / gap
    line2d.stress_pair(np.array([a, 0.41]), center, frame, a, G, NU, 0.0, out, work, 0.4)
    np.testing.assert_array_equal(out, line_stress([a, 0.41], center, frame, a))


def test_rectangle_point_near_an_edge_is_treated_as_on_it():
    frame, center, a, b = np.eye(3), np.zeros(3), 1.0, 0.5
    out, work = np.empty((3, 3, 3)), np.empty((3, 3, 3))
    cases = [([a, 0.2, 0.0], [(1e-7, 0, 0), (-1e-7, 0, 0), (0, 0, 1e-7), (0.03, 0, -0.035)]),  # x1 = a edge
             ([-0.3, -b, 0.0], [(0, -1e-7, 0), (0, 0.02, 0), (0, 0, -0.01)]),                    # x2 = -b edge
             ([a, b, 0.0], [(1e-7, 1e-7, 0), (0.01, 0.02, 0.03), (0.02, 0.01, -0.01)]),         # corner
             ([0.99, b, 0.0], [(0, 0.03, 0), (0, -0.005, 0.02)])]  # near the corner, but nearest to an edge
    for on_edge, offsets in cases:
        at_edge = rect_stress(on_edge, center, frame, a, b, shift=1e-3)
        assert np.all(np.isfinite(at_edge))
        for offset in offsets:
            point = np.add(on_edge, offset)
            rectangle3d.stress_pair(point, center, frame, a, b, G, NU, 0.0, out, work, 0.05)
            assert np.all(np.isnan(out))
            rectangle3d.stress_pair(point, center, frame, a, b, G, NU, 1e-3, out, work, 0.05)
            np.testing.assert_allclose(out, at_edge, rtol=1e-12, atol=1e-12 * np.abs(at_edge).max())
    far = np.array([a + 0.06, 0.2, 0.0])  # 0.06 > near = 0.05: the plain kernel
    rectangle3d.stress_pair(far, center, frame, a, b, G, NU, 0.0, out, work, 0.05)
    np.testing.assert_array_equal(out, rect_stress(far, center, frame, a, b))


@settings(max_examples=60, deadline=None)
@given(x=st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(-1, 1)),
       a=st.floats(0.1, 2.0), b=st.floats(0.1, 2.0))
def test_nearest_boundary_point_against_brute_force(x, a, b):
    """The distance to the rectangle's edges against a dense sampling of the edges."""
    distance, p1, p2, u1, u2 = rectangle3d.nearest_boundary_point(*x, a, b)
    t = np.linspace(-1.0, 1.0, 20001)
    edges = np.concatenate([np.column_stack([np.full_like(t, s * a), t * b]) for s in (-1, 1)]
                           + [np.column_stack([t * a, np.full_like(t, s * b)]) for s in (-1, 1)])
    sampled = np.sqrt(((edges - np.array(x[:2])) ** 2).sum(axis=1) + x[2] ** 2)
    step = 2.0 * max(a, b) / 20000
    assert sampled.min() - step <= distance <= sampled.min() + 1e-12
    assert np.hypot(p1 - x[0], p2 - x[1]) ** 2 + x[2] ** 2 == pytest.approx(distance**2, rel=1e-9, abs=1e-18)
    assert abs(abs(p1) - a) < 1e-12 or abs(abs(p2) - b) < 1e-12  # on the boundary
    assert np.hypot(u1, u2) == pytest.approx(1.0)


def test_line_tip_distance():
    assert line2d.tip_distance(1.3, 0.4, 1.0) == pytest.approx(0.5)
    assert line2d.tip_distance(-0.6, -0.3, 1.0) == pytest.approx(0.5)
    assert line2d.tip_distance(0.0, 0.0, 1.0) == pytest.approx(1.0)
