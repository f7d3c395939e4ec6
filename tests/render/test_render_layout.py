"""hmatddm.render.layout: what a picture shows and where, checked without rendering
(the pictures themselves: tests/render/test_render.py)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.render.layout import FAILED_NATURAL, HYDRAULIC, INTACT_NATURAL, plan_traces
from test_render import vertical_scene


def test_plan_traces_merge_each_column_with_its_largest_opening():
    mesh, fields = vertical_scene()
    traces, opening, state, slip, column = plan_traces(mesh, **fields)
    assert isinstance(traces, hd.Mesh2D) and traces.n_elements == 8 + 4  # 8 + 4 columns of 4 elements
    assert column.shape == (mesh.n_elements,)
    for line in range(traces.n_elements):
        members = np.flatnonzero(column == line)
        assert members.size == 4 and np.unique(mesh.fracture_id[members]).size == 1
        assert opening[line] == np.max(fields["opening"][members])
        assert np.allclose(mesh.centers[members, :2], traces.centers[line])
        expected = FAILED_NATURAL if np.any(fields["state"][members] == FAILED_NATURAL) else fields["state"][members[0]]
        assert state[line] == expected
    assert np.allclose(slip[state == FAILED_NATURAL], [0.0, 1e-4])  # the horizontal part of the slip
    assert np.all(slip[state != FAILED_NATURAL] == 0.0)


def test_plan_frame_puts_the_fractures_left_of_the_colour_bar_and_above_the_legend():
    from hmatddm.render.layout import PLAN_BOX, plan_frame

    for extent, window in (((-50.0, 50.0, -1.0, 1.0), (1200, 900)), ((0.0, 1.0, -30.0, 10.0), (400, 300))):
        centre_x, centre_y, scale, box = plan_frame(extent, window)
        aspect = window[0] / window[1]
        fx = [0.5 + (x - centre_x) / (2 * scale * aspect) for x in extent[:2]]
        fy = [0.5 + (y - centre_y) / (2 * scale) for y in extent[2:]]
        assert box == PLAN_BOX
        assert PLAN_BOX[0] - 1e-9 <= fx[0] < fx[1] <= PLAN_BOX[1] + 1e-9
        assert PLAN_BOX[2] - 1e-9 <= fy[0] < fy[1] <= PLAN_BOX[3] + 1e-9
        assert max(fx[1] - fx[0] - (PLAN_BOX[1] - PLAN_BOX[0]), fy[1] - fy[0] - (PLAN_BOX[3] - PLAN_BOX[2])) > -1e-9


def test_legend_names_activated_natural_elements_and_the_slip_arrows():
    from hmatddm.render.layout import legend_labels

    state = np.array([HYDRAULIC, INTACT_NATURAL, FAILED_NATURAL])
    assert [text for text, _ in legend_labels(state, slip_shown=True)] == [
        "natural fracture, intact", "natural fracture, activated or failed", "slip (arrow length ~ slip)"]
    assert legend_labels(np.zeros(3, int)) == []


def test_the_scale_bar_of_a_vertical_section_follows_the_shown_width():
    """A vertical 2D section is ~0 wide in x; its bar is still a fifth of what the box shows."""
    from hmatddm.render.layout import plan_frame, plan_scale_bar

    extent, window = (-0.05, 0.05, -14.0, 14.0), (1200, 900)
    _, _, scale, box = plan_frame(extent, window)
    shown = 2.0 * scale * (window[0] / window[1]) * (box[1] - box[0])
    assert 0.1 * shown <= plan_scale_bar(extent, window) <= 0.2 * shown
    assert plan_scale_bar((-60.0, 60.0, -1.0, 1.0), window) == 20.0  # wide views: as before


def test_field_checks_name_the_field():
    from hmatddm.render.layout import check_fields, check_window_size

    mesh = hd.mesh.line([0.0, 0.0], [1.0, 0.0], 4)
    with pytest.raises(hd.InputError, match=r"state values must be 0 \(hydraulic\).*element 2 has 3"):
        check_fields(mesh, None, np.array([0, 1, 3, 0]), None)
    with pytest.raises(hd.InputError, match="opening must have shape"):
        check_fields(mesh, np.zeros(3), None, None)
    with pytest.raises(hd.InputError, match=r"window_size height must be an integer in \[16, 16384\], got 8"):
        check_window_size((400, 8))
    assert check_window_size((np.int64(400), 300)) == (400, 300)


def test_the_opening_band_of_a_2d_picture_is_each_opening_times_one_exaggeration():
    from hmatddm.render.layout import opening_ribbon

    mesh = hd.mesh.concatenate([hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 4),
                                hd.mesh.line([0.0, -1.0], [0.0, 1.0], 2, fracture_id=1)])
    opening = np.array([1e-3, 2e-3, 4e-3, -1e-3, 0.0, 2e-3])  # a closed element: no band
    points, quads, exaggeration = opening_ribbon(mesh, opening, diagonal=10.0, share=0.05)
    assert exaggeration == pytest.approx(0.05 * 10.0 / 4e-3)
    corners = points[quads]  # (6, 4, 2): start - n w/2, end - n w/2, end + n w/2, start + n w/2
    width = np.linalg.norm(corners[:, 3] - corners[:, 0], axis=1)
    assert np.allclose(width, exaggeration * np.clip(opening, 0.0, None))
    assert np.allclose(corners[2, 3, 1] - corners[2, 0, 1], 0.5)  # horizontal: the band spans y
    assert np.allclose(corners[5, 0, 0] - corners[5, 3, 0], 0.05 * 10.0 / 2.0)  # vertical: it spans x
    assert np.allclose(0.5 * (corners[:, 0] + corners[:, 3]), np.stack(mesh.endpoints, axis=1)[:, 0])
    assert opening_ribbon(mesh, np.zeros(6), 10.0) == (None, None, None)
    with pytest.raises(hd.InputError, match="Mesh2D"):
        opening_ribbon(hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 1, 1, 1, 1), [1e-3], 1.0)
