"""A growing run's operator builds warn of unresolved near-parallel pairs once
(:class:`hmatddm.errors.MeshQualityWarning`, "warned once per simulation") and, having
warned, skip the pair check at later builds (``ElasticityOperator(check_spacing=False)``):
the same operators, without its cost at every growth pass."""
import warnings

import numpy as np
import pytest

import hmatddm as hd
from hmatddm.mesh import quality
from hmatddm.simulation.growing_operator import GrowingOperator
from hmatddm.simulation.settings import OperatorSettings, RebuildSettings


def _parallel(n):
    """Two near-parallel cracks 0.05 apart, elements of 2/n: unresolved for small n."""
    return hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], n),
                                hd.mesh.line([-1, 0.05], [1, 0.05], n + 1, fracture_id=1)])


@pytest.fixture
def checks(monkeypatch):
    calls = []
    pairs = quality.close_parallel_pairs

    def counting(mesh, *args, **kwargs):
        calls.append(mesh.n_elements)
        return pairs(mesh, *args, **kwargs)

    monkeypatch.setattr(quality, "close_parallel_pairs", counting)
    return calls


def test_a_growing_run_warns_once_then_skips_the_check(checks):
    operators = GrowingOperator(hd.Elastic(1e10, 0.25), OperatorSettings(backend="dense"), RebuildSettings())
    with pytest.warns(hd.errors.MeshQualityWarning, match="warned once per simulation"):
        first = operators.build(_parallel(10))
    assert checks == [21]
    with warnings.catch_warnings():
        warnings.simplefilter("error", hd.errors.MeshQualityWarning)
        second = operators.build(_parallel(12))  # still unresolved: no second warning, no check
    assert checks == [21]
    assert np.array_equal(second.to_dense(), hd.ElasticityOperator(_parallel(12), hd.Elastic(1e10, 0.25),
                                                                     check_spacing=False).to_dense())
    assert first.mesh.n_elements == 21


def test_a_run_that_has_not_warned_keeps_checking(checks):
    operators = GrowingOperator(hd.Elastic(1e10, 0.25), OperatorSettings(backend="dense"), RebuildSettings())
    with warnings.catch_warnings():
        warnings.simplefilter("error", hd.errors.MeshQualityWarning)
        operators.build(hd.mesh.line([-1, 0], [1, 0], 8))
        operators.build(hd.mesh.line([-1, 0], [1, 0], 10))
    assert checks == [8, 10]
    with pytest.warns(hd.errors.MeshQualityWarning):
        operators.build(_parallel(10))
    assert checks == [8, 10, 21]
