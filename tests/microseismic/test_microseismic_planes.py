"""Fracture traces from event clouds: DBSCAN + PCA recover synthetic traces."""
import numpy as np
import pytest

from hmatddm.errors import InputError
from hmatddm.microseismic.planes import azimuth_difference, fit_traces, strike_errors, true_trace_azimuths


def test_two_noisy_lines_give_their_azimuths():
    rng = np.random.default_rng(0)
    lines = []
    for azimuth, center in ((30.0, (0.0, 0.0)), (120.0, (40.0, 10.0))):
        direction = np.array([np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))])
        s = np.linspace(-10, 10, 41)
        lines.append(np.asarray(center) + s[:, None] * direction + rng.normal(scale=0.05, size=(41, 2)))
    points = np.vstack(lines)
    ids = np.repeat([5, 9], 41)
    traces = fit_traces(points, eps=2.0, min_samples=3)
    assert len(traces) == 2
    truth = true_trace_azimuths(np.array([[0, 0], [40, 10]]),
                                np.array([[np.cos(np.radians(30)), np.sin(np.radians(30))],
                                          [40 + np.cos(np.radians(120)), 10 + np.sin(np.radians(120))]]), [5, 9])
    assert truth[5] == pytest.approx(30.0) and truth[9] == pytest.approx(120.0)
    errors, fractures = strike_errors(traces, ids, truth)
    assert sorted(fractures) == [5, 9] and np.all(errors < 0.5)
    assert all(t.linearity > 0.9 and t.length == pytest.approx(20.0, abs=0.5) for t in traces)
    # the data-driven radius finds the same two traces
    assert sorted(round(t.azimuth_deg) for t in fit_traces(points)) == [30, 120]


def test_azimuth_difference_is_modulo_180():
    assert azimuth_difference(179.0, 1.0) == pytest.approx(2.0)
    assert azimuth_difference(10.0, 100.0) == pytest.approx(90.0)


def test_bad_settings_are_refused():
    with pytest.raises(InputError, match="eps"):
        fit_traces(np.ones((5, 2)), eps=0.0)
    with pytest.raises(InputError, match="min_samples"):
        fit_traces(np.zeros((5, 2)), min_samples=1)
    assert fit_traces(np.zeros((2, 2)), min_samples=3) == []
    column = np.array([[3.0, 4.0, z] for z in range(6)]) + 1e-15 * np.arange(18).reshape(6, 3)
    assert fit_traces(column, eps=1.0) == []  # events stacked in one vertical column: no trace
