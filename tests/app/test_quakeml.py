"""The QuakeML export of an event catalogue (issue 35, hmatddm.app.quakeml): read back by
obspy.read_events with each event's origin, Mw and moment tensor (skipped without ObsPy)."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from hmatddm.app.catalogue import Catalogue
from hmatddm.app.quakeml import EARTH_RADIUS, geographic, to_spherical, write_quakeml

obspy = pytest.importorskip("obspy")


class Events(SimpleNamespace):
    def __len__(self):
        return len(self.time)


def catalogue():
    rng = np.random.default_rng(4)
    tensors = rng.normal(size=(3, 3, 3)) * 1e9
    tensors = tensors + np.transpose(tensors, (0, 2, 1))
    moment = np.array([1e9, 3e10, 2e8])
    events = Events(time=np.array([3.0, 12.5, 40.0]), position=np.array([[1.0, 2.0, -3.0], [10.0, -5.0, 0.5],
                                                                         [-20.0, 30.0, 2.0]]),
                    seismic_moment=moment, moment_magnitude=2.0 / 3.0 * (np.log10(moment) - 9.1),
                    moment_tensor=tensors)
    located = events.position + np.array([0.5, -0.25, 1.0])
    return Catalogue(events, None, located, moment, moment)


def test_the_catalogue_reads_back_with_origins_magnitudes_and_moment_tensors(tmp_path):
    source = catalogue()
    path = write_quakeml(tmp_path / "events.xml", source, name="test", latitude=30.0, longitude=-100.0)
    read = obspy.read_events(str(path))
    assert len(read) == 3
    for k, event in enumerate(read):
        origin = event.preferred_origin()
        x, y, z = source.located[k]
        assert origin.latitude == pytest.approx(30.0 + math.degrees(y / EARTH_RADIUS), abs=1e-9)
        assert origin.longitude == pytest.approx(-100.0 + math.degrees(x / (EARTH_RADIUS * math.cos(math.radians(30)))),
                                                 abs=1e-9)
        assert origin.depth == pytest.approx(-z, abs=1e-6)
        assert origin.time - obspy.UTCDateTime(0) == pytest.approx(source.events.time[k], abs=1e-6)
        magnitude = event.preferred_magnitude()
        assert magnitude.magnitude_type == "Mw"
        assert magnitude.mag == pytest.approx(source.events.moment_magnitude[k], abs=1e-9)
        tensor = event.preferred_focal_mechanism().moment_tensor
        assert tensor.scalar_moment == pytest.approx(source.events.seismic_moment[k], rel=1e-9)
        t = tensor.tensor
        m = source.events.moment_tensor[k]
        # back from (r, theta, phi) = (up, south, east) to (east, north, up), written apart
        back = np.array([[t.m_pp, -t.m_tp, t.m_rp], [-t.m_tp, t.m_tt, -t.m_rt], [t.m_rp, -t.m_rt, t.m_rr]])
        np.testing.assert_allclose(back, m, rtol=1e-9)


def test_the_spherical_components_keep_the_trace_and_the_norm():
    m = np.array([[1.0, 2.0, 3.0], [2.0, -4.0, 5.0], [3.0, 5.0, 6.0]])
    rr, tt, pp, rt, rp, tp = to_spherical(m)
    assert rr + tt + pp == pytest.approx(np.trace(m))
    assert rr**2 + tt**2 + pp**2 + 2 * (rt**2 + rp**2 + tp**2) == pytest.approx(np.sum(m * m))
    assert geographic((0.0, 0.0, -250.0)) == (0.0, 0.0, 250.0)


def test_an_empty_catalogue_is_an_empty_quakeml(tmp_path):
    empty = Catalogue(Events(time=np.zeros(0), position=np.zeros((0, 3)), seismic_moment=np.zeros(0),
                             moment_magnitude=np.zeros(0), moment_tensor=np.zeros((0, 3, 3))), None,
                      np.zeros((0, 3)), np.zeros(0), np.zeros(0))
    assert len(obspy.read_events(str(write_quakeml(tmp_path / "e.xml", empty)))) == 0
