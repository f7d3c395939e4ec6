import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(__file__))  # for kelvin_reference
# as the hmatddm command does (the library itself changes no environment variable):
# numba's OpenMP workers wait passively on this shared machine
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import hmatddm as hd  # noqa: E402

G, NU = 10e9, 0.25


@pytest.fixture(scope="session")
def material():
    return hd.Elastic(shear_modulus=G, poisson_ratio=NU)


def random_rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 2] *= -1
    return q


def rotation_2d(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])
