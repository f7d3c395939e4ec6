"""Offscreen snapshots and history plots: files exist, have the asked size, show something."""
import matplotlib.image
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.render import plot_history, snapshot, snapshots
from hmatddm.render.layout import FAILED_NATURAL, HYDRAULIC, INTACT_NATURAL

WINDOW = (400, 300)


@pytest.fixture(scope="module")
def scene3d():
    return vertical_scene()


def vertical_scene():
    """A vertical hydraulic fracture (8 x 4) crossed by a natural one (4 x 4), part of
    which has failed and slips."""
    hydraulic = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 4, 2, 8, 4)
    natural = hd.mesh.rectangle([1, 0.5, 0], [0, 1, 0], [0, 0, 1], 2, 2, 4, 4, fracture_id=1)
    mesh = hd.mesh.concatenate([hydraulic, natural])
    x = mesh.centers
    is_natural = mesh.fracture_id == 1
    opening = np.where(is_natural, 1e-5, 1e-3 * np.sqrt(np.clip(1 - (x[:, 0] / 2) ** 2 - x[:, 2] ** 2, 0.01, None)))
    state = np.where(is_natural, INTACT_NATURAL, HYDRAULIC)
    state[is_natural & (np.abs(x[:, 1]) < 0.6)] = FAILED_NATURAL
    slip = np.zeros((mesh.n_elements, 3))
    slip[state == FAILED_NATURAL] = [0.0, 1e-4, 3e-5]
    return mesh, dict(opening=opening, state=state, slip=slip)


@pytest.fixture(scope="module")
def scene2d():
    crossing = hd.mesh.line([0.5, -0.5], [0.5, 0.5], 5, fracture_id=1)
    mesh = hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], 10), crossing])
    n = mesh.n_elements
    opening = np.r_[1e-3 * np.sqrt(1 - np.linspace(-0.9, 0.9, 10) ** 2), np.zeros(5)]
    state = np.r_[np.full(10, HYDRAULIC), np.full(5, INTACT_NATURAL)]
    state[12] = FAILED_NATURAL
    slip = np.zeros((n, 2))
    slip[12] = [0.0, 1e-4]
    return mesh, dict(opening=opening, state=state, slip=slip)


def _image(path):
    return matplotlib.image.imread(path)[..., :3]


def _assert_picture(path, window_size):
    assert path.is_file()
    image = _image(path)
    width, height = window_size
    assert image.shape[:2] == (height, width)
    assert np.var(image) > 1e-3, "the image is blank"


def _red_pixels(image):
    return int(np.sum((image[..., 0] > 0.8) & (image[..., 1] < 0.25) & (image[..., 2] < 0.25)))


def test_snapshots_3d_write_plan_and_oblique_views(tmp_path, scene3d):
    mesh, fields = scene3d
    paths = snapshots(mesh, tmp_path / "png", "step_0001", title="t = 1 s", window_size=WINDOW, **fields)
    assert [p.name for p in paths] == ["step_0001_plan.png", "step_0001_oblique.png"]
    for path in paths:
        _assert_picture(path, WINDOW)
    plan, oblique = (_image(p) for p in paths)
    assert not np.array_equal(plan, oblique)
    assert _red_pixels(oblique) > 20, "failed natural-fracture elements are not outlined in red"
    assert sorted(p.name for p in (tmp_path / "png").iterdir()) == sorted(p.name for p in paths)


def test_plan_view_of_a_horizontal_fracture_fills_the_frame(tmp_path):
    mesh = hd.mesh.penny([5.0, -3.0, 100.0], [0, 0, 1], 1.0, 0.2)
    opening = 1e-3 * np.sqrt(np.clip(1 - np.sum((mesh.centers[:, :2] - [5, -3]) ** 2, axis=1), 0, None))
    path = snapshot(mesh, tmp_path / "plan.png", opening=opening, view="plan", window_size=WINDOW)
    _assert_picture(path, WINDOW)
    image = _image(path)
    coloured = np.ptp(image, axis=2) > 0.15  # viridis is far from grey; the white background is not
    rows, columns = np.nonzero(coloured)
    assert np.ptp(rows) > 0.5 * WINDOW[1], "the disc should span most of the picture height"


def test_snapshot_without_fields_and_with_opening_only(tmp_path, scene3d):
    mesh, fields = scene3d
    _assert_picture(snapshot(mesh, tmp_path / "plain.png", window_size=WINDOW), WINDOW)
    _assert_picture(snapshot(mesh, tmp_path / "opening.png", opening=fields["opening"], window_size=WINDOW), WINDOW)


def test_snapshots_2d_draw_one_plan_view(tmp_path, scene2d):
    mesh, fields = scene2d
    paths = snapshots(mesh, tmp_path, "crack", window_size=WINDOW, **fields)
    assert [p.name for p in paths] == ["crack_plan.png"]
    _assert_picture(paths[0], WINDOW)
    assert _red_pixels(_image(paths[0])[:int(0.8 * WINDOW[1])]) > 5  # above the legend


def _coloured_pixels(image):
    return np.ptp(image, axis=2) > 0.15  # viridis and red are far from grey; white and grey are not


def test_plan_view_of_vertical_fractures_draws_their_traces(tmp_path, scene3d):
    """Seen from above, vertical fractures are edge on: the plan view draws each column
    of elements as its horizontal trace, coloured by its largest opening."""
    mesh, fields = scene3d
    assert np.all(np.abs(mesh.normals[:, 2]) < 1e-12)
    traces = snapshot(mesh, tmp_path / "traces.png", view="plan", window_size=WINDOW, **fields)
    edge_on = snapshot(mesh, tmp_path / "edge_on.png", view="plan", plan_style="surfaces", window_size=WINDOW,
                       **fields)
    _assert_picture(traces, WINDOW)
    image = _image(traces)
    rows, columns = np.nonzero(_coloured_pixels(image[:, :int(0.8 * WINDOW[0])]))  # left of the scalar bar
    assert np.ptp(columns) > 0.4 * WINDOW[0], "the 4 m hydraulic trace should span much of the width"
    assert np.ptp(rows) > 0.15 * WINDOW[1], "the natural trace (along y) should show"
    above_legend = image[:int(0.8 * WINDOW[1])]  # the legend's red square does not count
    assert _red_pixels(above_legend) > 10, "the failed natural trace has no red border"
    grey = (np.ptp(image, axis=2) < 0.05) & (image[..., 0] > 0.5) & (image[..., 0] < 0.8)
    assert np.sum(grey) > 10, "the intact natural trace is not grey"
    assert np.sum(_coloured_pixels(image)) > 3 * np.sum(_coloured_pixels(_image(edge_on))[:, :int(0.8 * WINDOW[0])])


def test_plan_view_of_a_mostly_vertical_mesh_keeps_its_other_elements(tmp_path, scene3d):
    from hmatddm.render.layout import is_mostly_vertical

    mesh, fields = scene3d
    horizontal = hd.mesh.rectangle([3.0, -1.5, 0.5], [1, 0, 0], [0, 1, 0], 1.0, 1.0, 2, 2, fracture_id=3)
    mixed = hd.mesh.concatenate([mesh, horizontal])
    assert is_mostly_vertical(mixed) and not is_mostly_vertical(horizontal)
    opening = np.r_[fields["opening"], np.full(4, 5e-4)]
    state = np.r_[fields["state"], np.zeros(4, dtype=int)]
    with_patch = _image(snapshot(mixed, tmp_path / "mixed.png", view="plan", opening=opening, state=state,
                                 window_size=WINDOW))
    without = _image(snapshot(mesh, tmp_path / "vertical.png", view="plan", window_size=WINDOW, **fields))
    assert np.sum(_coloured_pixels(with_patch)) > np.sum(_coloured_pixels(without)) + 500  # the 1 m x 1 m patch


@pytest.mark.parametrize("change, message", [
    (dict(view="side"), "view"),
    (dict(view="plan", plan_style="map"), "plan_style"),
    (dict(state=np.full(48, 5)), "state values"),
    (dict(state=np.zeros(48)), "state must be an integer array"),
    (dict(opening=np.zeros(47)), "opening"),
    (dict(opening=np.full(48, np.nan)), "opening"),
    (dict(slip=np.zeros((48, 2))), "slip"),
    (dict(window_size=(0, 300)), "window_size"),
])
def test_snapshot_bad_inputs_raise_input_error(tmp_path, scene3d, change, message):
    mesh, fields = scene3d
    assert mesh.n_elements == 48
    with pytest.raises(hd.InputError, match=message):
        snapshot(mesh, tmp_path / "bad.png", **{**fields, **change})
    assert not list(tmp_path.iterdir())


def test_traces_of_a_mesh_without_vertical_elements_are_refused(tmp_path):
    disc = hd.mesh.penny([0.0, 0.0, 0.0], [0, 0, 1], 1.0, 0.5)
    with pytest.raises(hd.InputError, match="plan_style='traces' needs vertical elements"):
        snapshot(disc, tmp_path / "bad.png", view="plan", plan_style="traces")
    assert not list(tmp_path.iterdir())


def test_missing_render_context_is_a_clear_error(tmp_path, scene2d, monkeypatch):
    import pyvista

    def no_context(*args, **kwargs):
        raise RuntimeError("failed to create an OpenGL context")

    monkeypatch.setattr(pyvista, "Plotter", no_context)
    mesh, fields = scene2d
    with pytest.raises(hd.HmatddmError, match="offscreen render context"):
        snapshot(mesh, tmp_path / "none.png", **fields)
    assert not list(tmp_path.iterdir())


def _history(n_clusters=2):
    records = []
    for time in np.linspace(0.5, 10.0, 12):
        radius = 0.7 * time ** 0.4
        records.append(dict(time=time, fracture_area=np.pi * radius**2, max_opening=1e-3 * time ** 0.2,
                            wellbore_pressure=[20e6 + 1e6 * time ** -0.2 + 1e4 * k for k in range(n_clusters)]))
    return records


def test_plot_history_with_closed_form_overlay(tmp_path):
    time = np.linspace(0.5, 10.0, 50)
    reference = dict(time=time, radius=0.7 * time ** 0.4, max_opening=1e-3 * time ** 0.2,
                     net_pressure=1e6 * time ** -0.2)
    path = plot_history(_history(), tmp_path / "plots" / "history.png", reference=reference, confining_stress=20e6)
    assert path.is_file()
    image = _image(path)
    assert image.shape[0] > 300 and image.shape[1] > 300
    assert np.var(image) > 1e-3


def test_plot_history_prefers_radius_or_half_length_keys(tmp_path):
    records = [dict(record, half_length=2.0 * record["time"] ** 0.5, wellbore_pressure=1e6)
               for record in _history(n_clusters=1)]
    path = plot_history(records, tmp_path / "kgd.png", reference=dict(time=[1.0, 5.0], half_length=[2.0, 4.5]))
    assert np.var(_image(path)) > 1e-3


@pytest.mark.parametrize("records, reference, message", [
    ([], None, "non-empty"),
    ([dict(time=0.0, fracture_area=1.0, max_opening=1e-3)], None, "wellbore_pressure"),
    ([dict(time=0.0, fracture_area=1.0, max_opening=np.nan, wellbore_pressure=[1e6])], None, "max_opening"),
    ([dict(time=0.0, fracture_area=1.0, max_opening=0.0, wellbore_pressure=[1e6]),
      dict(time=1.0, fracture_area=1.0, max_opening=0.0, wellbore_pressure=[1e6, 2e6])], None, "one per cluster"),
    (_history(), dict(radius=[1.0, 2.0]), "time"),
    (_history(), dict(time=[0.0, 1.0], radius=[1.0]), "radius"),
    (_history(), dict(time=[0.0, 1.0], pressure=[1.0, 2.0]), "keys"),
])
def test_plot_history_bad_inputs_raise_input_error(tmp_path, records, reference, message):
    with pytest.raises(hd.InputError, match=message):
        plot_history(records, tmp_path / "history.png", reference=reference)
    assert not list(tmp_path.iterdir())


# -- pictures that tell the truth (issue 19 item 7) -------------------------------------


def test_a_long_2d_crack_ends_left_of_the_colour_bar(tmp_path):
    """The kgd picture: the right tip was hidden under the colour bar."""
    from hmatddm.render.layout import BAR_LEFT

    mesh = hd.mesh.line([-60.0, 0.0], [60.0, 0.0], 120)
    opening = 1e-3 * np.sqrt(np.clip(1 - (mesh.centers[:, 0] / 60.0) ** 2, 1e-4, None))
    path = snapshot(mesh, tmp_path / "kgd.png", opening=opening, title="kgd", window_size=WINDOW)
    coloured = _coloured_pixels(_image(path))
    _, columns = np.nonzero(coloured[:, :int(BAR_LEFT * WINDOW[0]) - 1])
    assert columns.max() < 0.84 * WINDOW[0] and columns.max() > 0.75 * WINDOW[0]
    assert columns.min() < 0.1 * WINDOW[0]
    gap = coloured[:, int(0.835 * WINDOW[0]):int(BAR_LEFT * WINDOW[0]) - 1]
    assert not gap.any(), "something coloured between the crack and the colour bar"


def test_a_2d_crack_is_drawn_as_a_band_as_wide_as_its_opening(tmp_path):
    """A KGD-like crack from x = -10 to 10 m: the coloured band is thickest at the middle
    (the widest opening drawn as 4 % of the diagonal, about 0.8 m), and a line where the
    opening is zero."""
    mesh = hd.mesh.line([-10.0, 0.0], [10.0, 0.0], 40)
    opening = 1e-3 * np.sqrt(np.clip(1 - (mesh.centers[:, 0] / 10.0) ** 2, 0.0, None))
    path = snapshot(mesh, tmp_path / "band.png", opening=opening, window_size=WINDOW)
    coloured = _coloured_pixels(_image(path)[:, :int(0.84 * WINDOW[0])])
    rows_per_column = coloured.sum(axis=0)
    columns = np.flatnonzero(rows_per_column)
    middle, near_tip = columns[columns.size // 2], columns[2]
    pixels_per_metre = columns.size / 20.0
    assert rows_per_column[middle] == pytest.approx(0.04 * 20.0 * pixels_per_metre, rel=0.35)
    assert rows_per_column[middle] > 3 * rows_per_column[near_tip]


def test_negative_openings_are_drawn_as_zero_and_said_so(tmp_path, scene2d):
    from hmatddm.render.layout import opening_colour_range

    clim, title = opening_colour_range(np.array([-1.4e-2, 0.0, 0.5]))
    assert clim == [0.0, 0.5] and "< 0 drawn as 0" in title and "-0.014" in title
    clim, title = opening_colour_range(np.array([0.1, 0.5]))
    assert clim == [0.0, 0.5] and title == "opening (mm)"
    mesh, fields = scene2d
    closed = dict(fields, opening=fields["opening"] - 2e-5)  # some elements pressed shut
    _assert_picture(snapshot(mesh, tmp_path / "closed.png", window_size=WINDOW, **closed), WINDOW)


def test_plan_views_carry_a_round_length_scale(tmp_path, scene3d):
    from hmatddm.render.layout import scale_bar_length

    assert [scale_bar_length(span) for span in (120.0, 3.0, 0.75, 40.0)] == [20.0, 0.5, 0.1, 5.0]

    mesh, fields = scene3d
    path = snapshot(mesh, tmp_path / "plan.png", view="plan", window_size=WINDOW, **fields)
    image = _image(path)
    black = (image.max(axis=2) < 0.15)[int(0.88 * WINDOW[1]):, :int(0.3 * WINDOW[0])]  # lower left corner
    assert black.sum() > 10, "no length scale in the lower left corner"


def test_a_layered_section_draws_its_interfaces_across_the_picture(tmp_path):
    """A vertical 2D crack from y = -3 to 3 m with interfaces at +-1 m: two grey rows
    that span most of the picture's width; none without interfaces."""
    mesh = hd.mesh.line([0.0, -3.0], [0.0, 3.0], 12)
    opening = 1e-3 * np.sqrt(1 - np.linspace(-0.95, 0.95, 12) ** 2)

    def grey_rows(path):
        image = _image(path)
        grey = (np.ptp(image, axis=2) < 0.05) & (image.mean(axis=2) > 0.3) & (image.mean(axis=2) < 0.7)
        return np.flatnonzero(grey.sum(axis=1) > 0.5 * WINDOW[0])

    plain = snapshot(mesh, tmp_path / "plain.png", opening=opening, window_size=WINDOW)
    layered = snapshot(mesh, tmp_path / "layered.png", opening=opening, window_size=WINDOW, interfaces=(1.0, -1.0))
    assert grey_rows(plain).size == 0
    rows = grey_rows(layered)
    assert rows.size >= 2 and np.ptp(rows) > 0.1 * WINDOW[1]  # two separate lines
    with pytest.raises(hd.InputError, match="interfaces"):
        snapshot(mesh, tmp_path / "bad.png", opening=opening, interfaces=(np.nan,))
