"""The event catalogue of a run as QuakeML, through ObsPy (issue 35; optional: ``pip install
".[seismology]"``): ``DIR/events.xml`` beside ``events.csv`` when ObsPy imports.

Each event has its located origin (the analyst's location of :mod:`hmatddm.app.catalogue`,
ref. Eqs 7.23-7.25; the true source position is in a comment), its moment magnitude ``Mw``
(ref. Eq. 7.2, from the true moment ``M0``) and its moment tensor (docs/conventions.md §4).

The run's frame is local Cartesian (x east, y north, z up, metres) and its clock starts at
0; QuakeML wants geographic origins and absolute times, so the frame is placed at a reference
point (``latitude``, ``longitude``, default 0, 0: a spherical Earth of radius 6371 km, exact
enough over a stage's hundreds of metres), the depth is ``-z`` (m below the reference level)
and the origin time is ``start`` (default 1970-01-01T00:00:00 UTC) plus the event's time. The
moment tensor goes from (x, y, z) = (east, north, up) to the (r, theta, phi) = (up, south,
east) of QuakeML: ``M_rr = M_zz``, ``M_tt = M_yy``, ``M_pp = M_xx``, ``M_rt = -M_yz``,
``M_rp = M_xz``, ``M_tp = -M_xy``.
"""
import math
from pathlib import Path

import numpy as np

from ..io import atomic_output

QUAKEML = "events.xml"
EARTH_RADIUS = 6371e3  # m


def obspy_available():
    """Whether ObsPy imports (the optional ``seismology`` extra)."""
    try:
        import obspy  # noqa: F401
    except ImportError:
        return False
    return True


def to_spherical(tensor):
    """``(M_rr, M_tt, M_pp, M_rt, M_rp, M_tp)`` of a Cartesian (east, north, up) tensor (3, 3)."""
    m = np.asarray(tensor, dtype=float)
    return m[2, 2], m[1, 1], m[0, 0], -m[1, 2], m[0, 2], -m[0, 1]


def geographic(position, latitude=0.0, longitude=0.0):
    """``(latitude, longitude, depth)`` (deg, deg, m) of a local (east, north, up) position."""
    x, y, z = (float(v) for v in position)
    lat = latitude + math.degrees(y / EARTH_RADIUS)
    lon = longitude + math.degrees(x / (EARTH_RADIUS * math.cos(math.radians(latitude))))
    return lat, lon, -z


def write_quakeml(path, catalogue, name="hmatddm", latitude=0.0, longitude=0.0, start=0.0):
    """``path``: the :class:`hmatddm.app.catalogue.Catalogue` as QuakeML (module docstring).
    Returns the path. Raises ImportError without ObsPy."""
    from obspy import UTCDateTime
    from obspy.core.event import (Catalog, Comment, Event, FocalMechanism, Magnitude, MomentTensor, Origin,
                                  ResourceIdentifier, Tensor)

    events = catalogue.events
    origin_time = UTCDateTime(start)
    result = Catalog(description=f"{name}: synthetic microseismic events of an hmatddm run")
    magnitude = events.moment_magnitude if len(events) else np.zeros(0)
    for k in range(len(events)):
        prefix = f"smi:local/hmatddm/{name}/event/{k}"
        lat, lon, depth = geographic(catalogue.located[k], latitude, longitude)
        origin = Origin(resource_id=ResourceIdentifier(f"{prefix}/origin"), time=origin_time + float(events.time[k]),
                        latitude=lat, longitude=lon, depth=depth, evaluation_mode="automatic",
                        comments=[Comment(text="true source (local east, north, up, m): "
                                               + ", ".join(f"{v:.3f}" for v in events.position[k]))])
        moment = float(events.seismic_moment[k])
        mag = Magnitude(resource_id=ResourceIdentifier(f"{prefix}/magnitude"), mag=float(magnitude[k]),
                        magnitude_type="Mw", origin_id=origin.resource_id)
        m_rr, m_tt, m_pp, m_rt, m_rp, m_tp = to_spherical(events.moment_tensor[k])
        tensor = MomentTensor(resource_id=ResourceIdentifier(f"{prefix}/moment-tensor"),
                              derived_origin_id=origin.resource_id, scalar_moment=moment,
                              tensor=Tensor(m_rr=m_rr, m_tt=m_tt, m_pp=m_pp, m_rt=m_rt, m_rp=m_rp, m_tp=m_tp))
        mechanism = FocalMechanism(resource_id=ResourceIdentifier(f"{prefix}/focal-mechanism"),
                                   triggering_origin_id=origin.resource_id, moment_tensor=tensor)
        event = Event(resource_id=ResourceIdentifier(prefix), event_type="induced or triggered event",
                      origins=[origin], magnitudes=[mag], focal_mechanisms=[mechanism])
        event.preferred_origin_id = origin.resource_id
        event.preferred_magnitude_id = mag.resource_id
        event.preferred_focal_mechanism_id = mechanism.resource_id
        result.append(event)
    path = Path(path)
    with atomic_output(path) as temporary:
        result.write(str(temporary), format="QUAKEML")
    return path


__all__ = ["QUAKEML", "obspy_available", "write_quakeml", "to_spherical", "geographic"]
