"""A Simulation's option groups (hmatddm.simulation.settings) given as objects or as the
flat keywords they replace."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.simulation.settings import (CheckpointSettings, OperatorSettings, RebuildSettings, group_options)


def _simulation(**kwargs):
    return hd.Simulation(hd.mesh.line([-1, 0], [1, 0], 2), hd.Elastic(1e9, 0.2), hd.Fluid(1e-3),
                         [hd.Cluster((0, 0), 1e-3)], np.zeros((2, 2)), 1.0, **kwargs)


def test_flat_keywords_fill_their_groups():
    grouped = group_options(dict(backend="dense", eps=1e-6, keep_checkpoints=5, rebuild_fraction=0.5))
    assert grouped["operator_settings"] == OperatorSettings(backend="dense", eps=1e-6)
    assert grouped["checkpoint_settings"] == CheckpointSettings(keep_checkpoints=5)
    assert grouped["rebuild_settings"] == RebuildSettings(rebuild_fraction=0.5)


def test_objects_and_keywords_define_the_same_run(tmp_path):
    flat = _simulation(backend="dense", eps=1e-6, alpha=1.0, checkpoint_dir=tmp_path, rebuild_fraction=0.5)
    grouped = _simulation(operator_settings=OperatorSettings(backend="dense", eps=1e-6, alpha=1.0),
                          checkpoint_settings=CheckpointSettings(checkpoint_dir=tmp_path),
                          rebuild_settings=RebuildSettings(rebuild_fraction=0.5))
    assert flat.fingerprint() == grouped.fingerprint()
    assert flat.checkpoint_dir == grouped.checkpoint_dir == tmp_path
    assert flat.rebuild_settings == grouped.rebuild_settings
    assert _simulation(backend="hmatrix").fingerprint() != flat.fingerprint()


def test_bad_groups_are_refused_by_name():
    with pytest.raises(InputError, match="backend"):
        _simulation(operator_settings=OperatorSettings(backend="dense"), backend="hmatrix")
    with pytest.raises(InputError, match="operator_settings"):
        _simulation(operator_settings=dict(backend="dense"))
    with pytest.raises(InputError, match="rebuild_fraction"):
        RebuildSettings(rebuild_fraction=11.0)
    with pytest.raises(InputError, match="keep_checkpoints"):
        CheckpointSettings(keep_checkpoints=0)
    with pytest.raises(TypeError, match="bakend"):
        _simulation(bakend="dense")


def test_border_blocks_fit_by_count_and_by_bytes():
    rebuild = RebuildSettings(rebuild_fraction=0.25, max_border_bytes=8.0 * 4 * (2 * 100 * 25 + 25 * 25))
    assert rebuild.border_fits(100, 25, dof=2)      # 25 <= 0.25 * 100, bytes exactly at the limit
    assert not rebuild.border_fits(100, 26, dof=2)  # too many
    assert not rebuild.border_fits(100, 25, dof=3)  # too many bytes
    assert rebuild.border_fits(100, 25, dof=3, entries_per_pair=4)  # a planar split border: fewer entries
