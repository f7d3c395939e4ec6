"""The remainder's rows per source and receiver height (issue 32,
:mod:`hmatddm.layered.remainder_rows3d`), with the near triples added at the same points
(:func:`hmatddm.layered.near_table3d.near_rectangle_stress`): a whole block, where every
source serves enough receivers to take the rows, against the same entries one receiver at a
time, where no source does (the table directly, each near group on its own)."""
import numpy as np
import pytest
from test_layered_fast3d import _random_mesh  # tests/layered on the path (pytest's prepend mode)

from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium
from hmatddm.layered import remainder_rows3d as rows3d
from hmatddm.layered.influence3d import influence_data

INTERFACES = [0.0, -1.5, -3.0]


@pytest.fixture(autouse=True)
def _tables_for_small_meshes(monkeypatch):
    from hmatddm.layered import influence3d

    monkeypatch.setattr(influence3d, "TABLE_MIN_ELEMENTS", 0)


def _one_receiver_at_a_time(data):
    every = np.arange(data.centers.shape[0], dtype=np.int64)
    out = np.empty((3 * every.size, 3 * every.size))
    row = np.empty((3, 3 * every.size))
    for i in every:
        drivers.traction_block(data, np.array([i]), every, row)
        out[3 * i:3 * i + 3] = row
    return out


@pytest.mark.parametrize("heights", ["shared", "distinct"])
def test_a_block_through_the_rows_equals_its_entries_one_receiver_at_a_time(heights):
    """Randomly oriented 0.3 m squares in all three layers under a free surface: receivers
    sharing nine heights (each entry of the rows reused), and every receiver at its own height
    (56, more than :data:`remainder_rows3d.ENTRIES`: entries taken over round-robin). The
    whole block (rows filled and reused, near triples and remainder at shared points) equals
    the entries computed one receiver at a time (no source takes the rows) to 1e-13."""
    rng = np.random.default_rng(4)
    x, y = np.meshgrid(0.45 * np.arange(7), 0.45 * np.arange(8))  # 0.45 m apart: no two squares meet
    n = x.size
    if heights == "distinct":
        z = rng.uniform(-3.9, -0.3, n)
    else:
        z = rng.choice([-0.3, -0.8, -1.2, -1.8, -2.2, -2.7, -3.3, -3.9], n)
    z = np.where(np.abs(z + 1.5) < 0.3, z - 0.6, z)
    z = np.where(np.abs(z + 3.0) < 0.3, z + 0.6, z)
    centers = np.column_stack([x.ravel(), y.ravel(), z])
    assert heights == "shared" or np.unique(z).size > rows3d.ENTRIES
    mesh = _random_mesh(9, centers, 0.15)
    medium = LayeredMedium(INTERFACES, [0.0, 1.0, 2.0, 1.0], [0.25, 0.25, 0.3, 0.2], images=3)
    data = influence_data(mesh, medium, 0.0, 0.0, 0.0, 3)
    assert data.table.near.ready[2, 2] and (data.table.pair_index >= 0).sum() > 0
    every = np.arange(n, dtype=np.int64)
    block = np.empty((3 * n, 3 * n))
    drivers.traction_block(data, every, every, block)
    reference = _one_receiver_at_a_time(data)
    assert np.abs(block - reference).max() <= 1e-13 * np.abs(reference).max()
