"""A growing run's rebuilds in a LayeredMedium with images = "auto" keep the number of images
chosen on an earlier mesh while the mesh spans the same layers and stays within twice that
mesh's extent (hmatddm.simulation.growing_operator: the choice's sampling was 84% of the
layered-3d scene's run), choose again beyond, and a restored base uses the saved choice."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.layered import LayeredMedium
from hmatddm.layered import influence2d
from hmatddm.simulation.growing_operator import GrowingOperator
from hmatddm.simulation.settings import OperatorSettings, RebuildSettings

MEDIUM = LayeredMedium([3.0, -3.0], [2e10, 1e10, 2e10], [0.25] * 3, images="auto")


def _crack(size, n):
    return hd.mesh.rectangle([0.0, 0.0, 0.0], [0, 1, 0], [0, 0, 1], size, size, n, n)


@pytest.fixture
def counted(monkeypatch):
    calls = []
    choose = influence2d.choose_images

    def counting(mesh, medium, *args, **kwargs):
        chosen = choose(mesh, medium, *args, **kwargs)
        if medium.images == "auto":  # sampled
            calls.append(chosen)
        return chosen

    monkeypatch.setattr("hmatddm.layered.influence3d._choose_images", counting)
    return calls


def test_rebuilds_keep_the_choice_within_twice_the_extent_and_choose_again_beyond(counted):
    operators = GrowingOperator(MEDIUM, OperatorSettings(backend="dense"), RebuildSettings())
    first = operators.build(_crack(2.0, 2))
    assert len(counted) == 1 and operators.image_choice["n_images"] == first.stats["n_images"] == counted[0]
    assert operators.image_choice["layers"] == [1]
    kept = operators.build(_crack(2.4, 3))  # within 2x, same layer: no sampling
    assert len(counted) == 1 and kept.stats["n_images"] == first.stats["n_images"]
    operators.build(_crack(4.0, 4))  # 2x the first extent, still inside the middle layer
    assert len(counted) == 1
    across = operators.build(_crack(8.0, 8))  # into both bounding layers: chosen again
    assert len(counted) == 2 and across.stats["n_images"] == counted[1]
    assert operators.image_choice["layers"] == [0, 1, 2]


def test_restore_builds_the_base_with_the_saved_choice(counted):
    operators = GrowingOperator(MEDIUM, OperatorSettings(backend="dense"), RebuildSettings())
    mesh = _crack(2.4, 3)
    operators.build(_crack(2.0, 2))
    base = operators.build(mesh)
    saved = dict(operators.image_choice)
    fresh = GrowingOperator(MEDIUM, OperatorSettings(backend="dense"), RebuildSettings())
    fresh.restore(mesh, mesh.n_elements, saved)
    assert len(counted) == 1  # the saved choice holds for the restored base: no sampling
    assert np.array_equal(fresh.base.to_dense(), base.to_dense())
    assert fresh.image_choice == saved


def test_a_fixed_number_of_images_is_never_sampled_nor_remembered(counted):
    fixed = LayeredMedium([3.0, -3.0], [2e10, 1e10, 2e10], [0.25] * 3, images=1)
    operators = GrowingOperator(fixed, OperatorSettings(backend="dense"), RebuildSettings())
    assert operators.build(_crack(2.0, 2)).stats["n_images"] == 1
    assert not counted and operators.image_choice is None


def test_elasticity_operator_refuses_a_negative_number_of_images():
    with pytest.raises(hd.InputError, match="n_images"):
        hd.ElasticityOperator(_crack(2.0, 2), MEDIUM, n_images=-1)
    with pytest.raises(hd.InputError, match="n_images"):
        hd.ElasticityOperator(_crack(2.0, 2), MEDIUM, n_images=1.5)


def test_a_step_tried_again_from_an_earlier_base_starts_from_its_choice(counted):
    operators = GrowingOperator(MEDIUM, OperatorSettings(backend="dense"), RebuildSettings())
    first = operators.build(_crack(2.0, 2))
    chosen_first = dict(operators.image_choice)
    operators.build(_crack(8.0, 8))  # chosen again, across the interfaces
    assert operators.image_choice["layers"] == [0, 1, 2]
    operators.reset(first)
    assert operators.image_choice == chosen_first
    operators.reset(None)
    assert operators.image_choice is None


def test_2d_chooses_at_every_build():
    medium = LayeredMedium([1.0], [2e10, 1e10], [0.25, 0.25], images="auto")
    operators = GrowingOperator(medium, OperatorSettings(backend="dense"), RebuildSettings())
    operators.build(hd.mesh.line([0.0, -2.0], [0.0, 0.0], 8))
    assert operators.image_choice is None
