"""Profile pictures (issue 38): sections through the fractures, the relative error against a
closed form, the picture itself; the fronts, axes and budget panel of the other pictures."""
import matplotlib.image
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.render import plot_history, snapshot
from hmatddm.render.layout import HYDRAULIC, INTACT_NATURAL, Curve, dashes, plan_ticks
from hmatddm.render.profiles import ProfilePlotter, fracture_sections, plot_profiles, relative_error


def _picture(path):
    image = matplotlib.image.imread(path)[..., :3]
    assert np.var(image) > 1e-3, "the image is blank"
    return image


def test_a_2d_section_runs_along_the_fracture_from_the_well():
    # a crack along x from -2 to 3 m on 10 elements, shuffled, and an intact natural one
    mesh = hd.mesh.concatenate([hd.mesh.line([3.0, 0.0], [-2.0, 0.0], 10),
                                hd.mesh.line([0.25, -1.0], [0.25, 1.0], 4, fracture_id=1)])
    order = np.r_[np.random.default_rng(0).permutation(10), np.arange(10, 14)]
    mesh = mesh.subset(order)
    opening = 1e-3 + 1e-4 * mesh.centers[:, 0]
    state = np.where(mesh.fracture_id == 1, INTACT_NATURAL, HYDRAULIC)
    sections = fracture_sections(mesh, opening, -opening * 1e9, state, wells=[[0.25, 0.0]])
    assert len(sections) == 1  # the intact natural fracture is no section
    section = sections[0]
    # centres at -1.75, -1.25, ..., 2.75; the well's element (0.25) at arc length 0
    assert np.allclose(section.position, np.arange(-1.75, 2.8, 0.5) - 0.25)
    assert np.allclose(section.opening, 1e-3 + 1e-4 * (section.position + 0.25))
    assert np.allclose(section.net_pressure, -1e9 * section.opening)
    assert "along x" in section.label


def test_3d_sections_cross_the_injection_point_along_both_axes():
    mesh = hd.mesh.rectangle([1.0, 2.0, -3.0], [1, 0, 0], [0, 1, 0], 5.0, 3.0, 5, 3)  # 5 x 3 elements of 1 m
    opening = np.arange(mesh.n_elements, dtype=float)
    along_x, along_y = fracture_sections(mesh, opening, opening, wells=[[1.2, 2.1, -3.0]])
    # distances from the well along the line through it
    assert np.allclose(along_x.position, [-2.2, -1.2, -0.2, 0.8, 1.8])
    assert np.allclose(along_y.position, [-1.1, -0.1, 0.9])
    assert np.allclose(mesh.centers[along_x.elements, 1], 2.0) and np.allclose(mesh.centers[along_y.elements, 0], 1.0)
    assert along_x.label == "along x" and along_y.label == "along y"


def test_the_relative_error_is_the_2_norm_inside_the_closed_form():
    position = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    reference = np.linspace(-1.5, 1.5, 31), np.full(31, 2.0)  # extends over the three middle points only
    assert relative_error(position, [9.0, 2.0, 2.0, 2.0, 9.0], *reference) == pytest.approx(0.0)
    assert relative_error(position, [0.0, 2.2, 2.2, 1.8, 0.0], *reference) == pytest.approx(
        np.sqrt(3 * 0.2 ** 2) / np.sqrt(3 * 4.0))
    assert relative_error(position, np.ones(5), [5.0, 6.0], [1.0, 1.0]) is None


def test_plot_profiles_draws_the_sections_and_the_closed_form(tmp_path):
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8, 8, 8, 8)
    r = np.linalg.norm(mesh.centers, axis=1)
    opening = 1e-3 * np.sqrt(np.clip(1 - (r / 4) ** 2, 0, None))
    sections = fracture_sections(mesh, opening, np.full(mesh.n_elements, 1e6), wells=[[0.1, 0.1, 0.0]])
    rho = np.linspace(-1, 1, 101)
    reference = dict(position=4 * rho, opening=1e-3 * np.sqrt(1 - rho ** 2), net_pressure=np.full(101, 1e6),
                     label="Sneddon")
    plotter = ProfilePlotter()
    for name in ("a.png", "b.png"):  # one plotter reused, as a run does
        path = plot_profiles(sections, tmp_path / name, reference=[reference, reference], title="t = 1 s",
                             plotter=plotter)
        image = _picture(path)
    assert image.shape[1] == 700
    with pytest.raises(InputError, match="one entry"):
        plot_profiles(sections, tmp_path / "c.png", reference=[reference])
    with pytest.raises(InputError, match="at least one section"):
        plot_profiles([], tmp_path / "d.png")


def test_dashes_and_ticks():
    line = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    pieces = dashes(line, 1.0)
    assert len(pieces) == 5 and all(np.isclose(np.ptp(piece[:, 0]), 1.0) for piece in pieces)
    assert np.allclose(plan_ticks(-7.3, 12.0), [-5, 0, 5, 10])
    assert np.allclose(plan_ticks(0.0, 1.0), [0.0, 0.2, 0.4, 0.6, 0.8, 1.0])


def test_a_plan_view_draws_curves_over_the_fractures(tmp_path):
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 6, 6, 6, 6)
    angle = np.linspace(0, 2 * np.pi, 91)
    circle = np.column_stack([2.5 * np.cos(angle), 2.5 * np.sin(angle), np.zeros(91)])
    plain = snapshot(mesh, tmp_path / "plain.png", opening=np.full(36, 1e-3), view="plan", window_size=(600, 450))
    drawn = snapshot(mesh, tmp_path / "front.png", opening=np.full(36, 1e-3), view="plan", window_size=(600, 450),
                     curves=[Curve(circle, "red", False, "front"), Curve(1.1 * circle, "black", True, "closed form")])
    red = [int(np.sum((im[..., 0] > 0.8) & (im[..., 1] < 0.25) & (im[..., 2] < 0.25)))
           for im in (_picture(plain), _picture(drawn))]
    assert red[1] > red[0] + 200
    with pytest.raises(InputError, match="curves\\[0\\].points must have shape"):
        snapshot(mesh, tmp_path / "bad.png", view="plan", curves=[Curve(circle[:, :2])])


def test_the_history_plot_gets_a_budget_panel(tmp_path):
    records = []
    for k in range(5):
        budget = dict(injected=1e-3 * k, initial=0.5003, fractures=3e-4 + 0.9e-3 * k, wellbore=0.5 + 0.1e-3 * k,
                      leaked=0.0, residual=0.0, compression=0.0)
        records.append(dict(time=float(k), fracture_area=3.0, max_opening=1e-4, wellbore_pressure=[1e6],
                            half_length=1.5, budget=budget))
    with_budget = matplotlib.image.imread(plot_history(records, tmp_path / "with.png"))
    without = matplotlib.image.imread(plot_history([{k: v for k, v in r.items() if k != "budget"} for r in records],
                                                   tmp_path / "without.png"))
    assert with_budget.shape[0] > 1.25 * without.shape[0]  # a fourth panel


def test_a_3d_side_view_draws_the_layer_interfaces(tmp_path):
    mesh = hd.mesh.rectangle([0, 0, 0], [0, 1, 0], [0, 0, 1], 6, 6, 6, 6)  # vertical, across z = +-2
    plain = _picture(snapshot(mesh, tmp_path / "plain.png", opening=np.full(36, 1e-3), window_size=(600, 450)))
    layered = _picture(snapshot(mesh, tmp_path / "layers.png", opening=np.full(36, 1e-3), window_size=(600, 450),
                                interfaces=[2.0, -2.0]))
    changed = np.mean(np.any(np.abs(layered - plain) > 0.05, axis=2))
    assert changed > 0.02  # two translucent planes and their caption


def test_every_embedded_reference_scene_has_a_closed_form_profile():
    """Each embedded scene with a [reference] (power-law fluids included) gets a finite
    closed-form profile to overlay; but the equilibrium height, which follows the run's
    net pressure and has no profile of its own in time."""
    import hmatddm.scene as scenes
    from hmatddm.app.profiles import closed_form_profile

    for name in scenes.embedded_names():
        data = scenes.load_scene(name).data
        if "reference" not in data or data["reference"]["kind"] == "three-layer-height":
            continue
        profile = closed_form_profile(data, data["numerics"]["end_time"])
        assert profile is not None and profile["label"], name
        assert np.all(np.isfinite(profile["opening"])) and np.all(profile["opening"] >= 0.0), name
