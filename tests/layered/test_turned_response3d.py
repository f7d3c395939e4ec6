"""The written-out turn of a tabulated response (:mod:`hmatddm.layered.turned_response3d`)
against the tensors turned by matrices, written apart from it."""
import numpy as np
import pytest

from hmatddm.layered.turned_response3d import COMPONENTS, PAIRS, rotated_stress


def _by_matrices(c, s, normal, shear_modulus, lame, weight, response):
    """``out[b]``: the moment of a unit DD along global ``b`` turned into the frame by ``R``,
    mapped to a stress by the response as a 6 x 6 matrix, and turned back: ``R^T S R``."""
    turn = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    table = np.zeros((6, 6))
    for (m, k), value in zip(COMPONENTS, response):
        table[m, k] = value
    out = np.zeros((3, 3, 3))
    for b in range(3):
        dd = np.eye(3)[b]
        moment = shear_modulus * (np.outer(dd, normal) + np.outer(normal, dd)) + lame * (dd @ normal) * np.eye(3)
        turned = turn @ moment @ turn.T
        stress6 = np.array([turned[p, q] for p, q in PAIRS]) @ table
        local = np.zeros((3, 3))
        for k, (p, q) in enumerate(PAIRS):
            local[p, q] = local[q, p] = stress6[k]
        out[b] = weight * turn.T @ local @ turn
    return out


@pytest.mark.parametrize("seed", range(4))
def test_rotated_stress_equals_the_matrices(seed):
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0.0, 2.0 * np.pi)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    response = rng.normal(size=len(COMPONENTS))
    got = np.full((3, 3, 3), 0.5)  # added to, not overwritten
    rotated_stress(np.cos(angle), np.sin(angle), normal, 1.7, 0.9, 0.3, response, got)
    want = 0.5 + _by_matrices(np.cos(angle), np.sin(angle), normal, 1.7, 0.9, 0.3, response)
    assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max()


def test_components_are_the_mirror_even_pairs():
    """A component survives the mirror ``y -> -y`` when the moment and the stress hold an
    even number of ``y`` indices together: 20 of 36, the order the turn is written for."""
    y_count = [int(p == 1) + int(q == 1) for p, q in PAIRS]
    even = [[m, k] for m in range(6) for k in range(6) if (y_count[m] + y_count[k]) % 2 == 0]
    assert COMPONENTS.tolist() == even and len(even) == 20
