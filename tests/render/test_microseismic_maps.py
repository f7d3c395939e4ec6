"""hmatddm.render.microseismic_maps: the event map frames traces, wells and events, and is
written (not blank) with or without events."""
import matplotlib.image
import numpy as np
from matplotlib.figure import Figure

from hmatddm.render.microseismic_maps import draw_map, plot_event_map

TRACES = (np.array([[-10.0, 0.0], [0.0, -5.0]]), np.array([[10.0, 0.0], [0.0, 5.0]]), np.array([0, 2]))
WELLS = np.array([[0.0, 30.0]])


def test_the_map_frames_traces_wells_and_events_at_one_scale():
    axis = Figure().subplots()
    located = np.array([[1.0, 2.0, 0.0], [-4.0, 40.0, 1.0]])
    scatter = draw_map(axis, TRACES, WELLS, located, np.array([-2.5, -1.5]))
    (x_low, x_high), (y_low, y_high) = axis.get_xlim(), axis.get_ylim()
    assert x_low < -10.0 and x_high > 10.0 and y_low < -5.0 and y_high > 40.0
    assert scatter.get_clim() == (-2.5, -1.5) and axis.get_aspect() == 1.0
    assert len(axis.collections) == 3  # hydraulic traces, failed natural traces, events


def test_event_maps_are_written_with_and_without_events(tmp_path):
    for name, located, magnitude in (("none.png", np.zeros((0, 3)), np.zeros(0)),
                                     ("two.png", np.array([[1.0, 2.0, 0.0], [3.0, 1.0, 0.0]]), np.array([-2.0, -1.0]))):
        path = plot_event_map(tmp_path / name, TRACES, WELLS, located, magnitude, title=name)
        image = matplotlib.image.imread(path)
        assert image.shape[0] > 100 and np.ptp(image[..., :3]) > 0.5  # drawn, not blank
    assert sorted(p.name for p in tmp_path.iterdir()) == ["none.png", "two.png"]
