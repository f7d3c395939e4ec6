"""The compiled fast marching and nearest-circle kernels against plain-Python versions of
the same algorithm (the loops they replaced, kept here as the reference): same fields to
the bit, on random boxes in 1D and 2D."""
import heapq

import numpy as np
import pytest

from hmatddm.fracture.fast_marching import march, nearest_circle
from hmatddm.fracture.front import level_set


def python_march(phi, known, allowed, h):
    """First-order fast marching with Python's heap of ``(value, index tuple)``."""
    shape, k = phi.shape, phi.ndim
    done = known.copy()
    heap = []

    def update(index):
        values = []
        for axis in range(k):
            best = np.inf
            for sign in (-1, 1):
                j = list(index)
                j[axis] += sign
                if 0 <= j[axis] < shape[axis] and done[tuple(j)]:
                    best = min(best, phi[tuple(j)])
            if np.isfinite(best):
                values.append(best)
        values.sort()
        value = values[0] + h
        for m in range(2, len(values) + 1):
            a = np.array(values[:m])
            b = a.sum()
            disc = b * b - m * (np.sum(a * a) - h * h)
            if disc < 0.0:
                break
            candidate = (b + np.sqrt(disc)) / m
            if candidate < values[m - 1]:
                break
            value = candidate
        return value

    def push_neighbours(index):
        for axis in range(k):
            for sign in (-1, 1):
                j = list(index)
                j[axis] += sign
                j = tuple(j)
                if 0 <= j[axis] < shape[axis] and allowed[j] and not done[j]:
                    value = update(j)
                    if value < phi[j]:
                        phi[j] = value
                        heapq.heappush(heap, (value, j))

    for index in zip(*np.nonzero(known)):
        push_neighbours(tuple(int(i) for i in index))
    while heap:
        value, index = heapq.heappop(heap)
        if done[index] or value > phi[index]:
            continue
        done[index] = True
        push_neighbours(index)


@pytest.mark.parametrize("shape", [(57,), (23, 31), (40, 40)])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_march_equals_the_python_march_to_the_bit(shape, seed):
    rng = np.random.default_rng(seed)
    h = 0.37
    known = rng.random(shape) < 0.08
    allowed = rng.random(shape) < 0.85
    phi = np.where(known, -rng.random(shape) * h, np.inf)
    # ties: some known values equal, so the heap's order of equal values matters
    phi[known] = np.round(phi[known], 1)
    expected = phi.copy()
    python_march(expected, known, allowed, h)
    march(phi, known, allowed, h)
    assert np.array_equal(phi, expected)
    assert np.all(np.isfinite(phi[known]))


def test_nearest_circle_equals_numpy():
    rng = np.random.default_rng(5)
    points, centers = rng.random((500, 2)) * 10, rng.random((40, 2)) * 10
    distances = rng.random(40)
    value = np.linalg.norm(points[:, None] - centers[None], axis=2) - distances[None]
    phi, nearest = nearest_circle(points, centers, distances)
    assert np.array_equal(nearest, np.argmin(value, axis=1))
    assert np.array_equal(phi, value[np.arange(500), np.argmin(value, axis=1)])
    phi1, nearest1 = level_set(points[:, :1], centers[:, :1], distances)
    value1 = np.abs(points[:, :1] - centers[None, :, 0]) - distances[None]
    assert np.array_equal(nearest1, np.argmin(value1, axis=1))


def test_march_refuses_a_strided_array():
    phi = np.zeros((8, 8))[:, ::2]
    with pytest.raises(ValueError, match="C-contiguous"):
        march(phi, np.zeros((8, 4), bool), np.ones((8, 4), bool), 1.0)


def _numpy_interpolation(field, points):
    """The numpy bilinear interpolation that FrontField.__call__ was (the reference)."""
    points = np.asarray(points, float).reshape(-1, field.k)
    u = points / field.h - field.low
    base = np.floor(u).astype(np.int64)
    frac = u - base
    out = np.zeros(len(points))
    corners = np.array(np.meshgrid(*([[0, 1]] * field.k), indexing="ij")).reshape(field.k, -1).T
    for corner in corners:
        weight = np.prod(np.where(corner == 1, frac, 1.0 - frac), axis=1)
        value = field.at_cells(base + corner + field.low)
        value = np.where(weight > 0.0, value, 0.0)
        with np.errstate(invalid="ignore"):
            out = out + np.where(weight > 0.0, weight * value, 0.0)
    return np.where(np.isnan(out), np.inf, out)


@pytest.mark.parametrize("k", [1, 2])
def test_compiled_interpolation_is_the_numpy_one_to_the_bit(k):
    from hmatddm.fracture.front import FrontField

    rng = np.random.default_rng(7)
    h = 0.37
    if k == 2:
        channel = np.array([(i, j) for i in range(-6, 7) for j in range(-6, 7) if i * i + j * j <= 30])
        ribbon = np.array([(i, j) for i, j in channel if 20 <= i * i + j * j <= 30])
    else:
        channel = np.arange(-8, 9)[:, None]
        ribbon = np.array([[-8], [8]])
    field = FrontField(ribbon, rng.uniform(0.1, 0.4, len(ribbon)) * h, np.ones(len(ribbon)), channel, h, margin=3)
    field.phi[tuple(np.argwhere(np.isfinite(field.phi))[:3].T)] = -np.inf  # unreached cells inside
    extent = (np.max(np.abs(channel)) + 6) * h
    points = np.concatenate([rng.uniform(-extent, extent, (3000, k)),  # some outside the box
                             channel * h, (channel + 0.5) * h])  # on centres and on cell edges
    compiled = field(points)
    reference = _numpy_interpolation(field, points)
    assert np.isinf(compiled).any() and np.isfinite(compiled).any()
    np.testing.assert_array_equal(compiled, reference)


def test_the_nearest_ribbon_by_k_d_tree_is_the_brute_force_one_on_a_lattice():
    """FrontField.velocity's k-d tree candidates and exact choice give the brute-force
    search's ribbon for every sample point of the fill, cell corners (4-way ties) included."""
    from hmatddm.fracture import front

    cells = np.array([(i, j) for i in range(-30, 31) for j in range(-30, 31) if 24 ** 2 <= i * i + j * j < 27 ** 2])
    h = 0.25
    field = front.FrontField(cells, np.full(len(cells), 0.1), np.arange(len(cells), dtype=float), cells, h, 4)
    inner, corners = front.sample_offsets(2, 8)
    offsets = np.concatenate([inner, corners])
    points = ((cells[::3, None, :] + offsets[None]) * h).reshape(-1, 2)
    points = np.concatenate([points, np.random.default_rng(0).uniform(-8.0, 8.0, (4000, 2))])
    assert len(points) * len(cells) > front.BRUTE_FORCE_PAIRS  # the k-d tree path
    _, brute = level_set(points, cells * h, np.zeros(len(cells)))
    np.testing.assert_array_equal(field.velocity(points), field.velocities[brute])
