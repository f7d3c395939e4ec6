"""Fracture traces from located event clouds (beyond ref. Sec. 7.4.2, which reads
orientations off consecutive events): cluster the events with DBSCAN and fit each
cluster's trace with a principal-component analysis (scikit-learn), then compare the
fitted traces with the true ones.

The fractures of a run are vertical, so traces are fitted in plan view (x, y): the
trace azimuth is the direction of the first principal axis, in degrees from +x
counter-clockwise, modulo 180 (the scene's azimuth convention); the strike error is
the angle between a fitted and a true trace (0 to 90 deg).
"""
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..settings import integer


@dataclass
class Trace:
    """A fitted trace: ``azimuth_deg`` in [0, 180), ``centroid`` (2,), ``members`` (event
    indices), ``linearity`` = 1 - (second / first principal standard deviation), ``length``
    (m, the extent along the trace)."""

    azimuth_deg: float
    centroid: np.ndarray
    members: np.ndarray
    linearity: float
    length: float


def trace_azimuth(direction):
    """Azimuth (deg, [0, 180)) of plan directions (..., 2)."""
    direction = np.asarray(direction, dtype=float)
    return np.mod(np.degrees(np.arctan2(direction[..., 1], direction[..., 0])), 180.0)


def azimuth_difference(a, b):
    """Angle (deg, [0, 90]) between traces of azimuths a and b (deg)."""
    difference = np.mod(np.asarray(a, dtype=float) - np.asarray(b, dtype=float), 180.0)
    return np.minimum(difference, 180.0 - difference)


def neighbour_distance(plan, min_samples):
    """Data-driven DBSCAN radius: twice the median distance of an event to its
    ``min_samples - 1``-th nearest neighbour (the knee heuristic of Ester et al. 1996, in
    its simplest form), so that the radius follows the scatter the noise adds; 1% more,
    so that events on a regular element grid (distances that tie with the radius) fall
    inside it whatever the round-off."""
    from scipy.spatial import cKDTree

    distance, _ = cKDTree(plan).query(plan, k=int(min_samples))
    return 2.02 * float(np.median(distance[:, -1]))


def fit_traces(positions, eps=None, min_samples=3):
    """Cluster located events (E, 2 or 3) in plan view with DBSCAN (radius ``eps`` m,
    default :func:`neighbour_distance`; ``min_samples``) and fit one trace per cluster by
    PCA; noise points are left out, and so are clusters at a single plan position (the
    events of one vertical column of elements), whose azimuth would be round-off."""
    from sklearn.cluster import DBSCAN
    from sklearn.decomposition import PCA

    min_samples = integer("min_samples", min_samples, minimum=2)
    plan = np.atleast_2d(np.asarray(positions, dtype=float))[:, :2]
    if len(plan) < min_samples:
        return []
    if eps is None:
        eps = max(neighbour_distance(plan, min_samples), 1e-12)
    if not np.isfinite(eps) or eps <= 0.0:
        raise InputError(f"eps must be > 0 m, got {eps!r}")
    labels = DBSCAN(eps=eps, min_samples=int(min_samples)).fit_predict(plan)
    traces = []
    for label in np.unique(labels[labels >= 0]):
        members = np.flatnonzero(labels == label)
        points = plan[members]
        pca = PCA(n_components=2).fit(points)
        spread = np.sqrt(np.maximum(pca.explained_variance_, 0.0))
        if spread[0] <= 1e-9 * max(1.0, float(np.max(np.abs(points)))):
            continue  # one plan position (a vertical column of events): no trace to fit
        along = (points - pca.mean_) @ pca.components_[0]
        traces.append(Trace(azimuth_deg=float(trace_azimuth(pca.components_[0])), centroid=pca.mean_.copy(),
                            members=members, linearity=float(1.0 - spread[1] / max(spread[0], 1e-300)),
                            length=float(np.ptp(along))))
    return traces


def true_trace_azimuths(p0, p1, fracture_id):
    """``{fracture id: azimuth (deg)}`` of the plan segments (M, 2) of a run's elements,
    the length-weighted mean direction of each fracture (doubled angles)."""
    vector = np.asarray(p1, dtype=float) - np.asarray(p0, dtype=float)
    length = np.linalg.norm(vector, axis=1)
    angle = 2.0 * np.arctan2(vector[:, 1], vector[:, 0])
    result = {}
    for fid in np.unique(fracture_id):
        mask = np.asarray(fracture_id) == fid
        mean = np.arctan2(np.sum(length[mask] * np.sin(angle[mask])), np.sum(length[mask] * np.cos(angle[mask])))
        result[int(fid)] = float(np.mod(np.degrees(0.5 * mean), 180.0))
    return result


def strike_errors(traces, event_fracture_id, true_azimuths):
    """Strike error (deg) of each fitted trace against the true trace of the fracture most
    of its events belong to; returns ``(errors (T,), fracture ids (T,))``."""
    errors, fractures = [], []
    event_fracture_id = np.asarray(event_fracture_id)
    for trace in traces:
        ids, counts = np.unique(event_fracture_id[trace.members], return_counts=True)
        fid = int(ids[np.argmax(counts)])
        fractures.append(fid)
        errors.append(float(azimuth_difference(trace.azimuth_deg, true_azimuths[fid])))
    return np.array(errors), np.array(fractures, dtype=np.int64)
