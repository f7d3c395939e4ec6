"""What a run shows its user (issue 38): profile pictures of the saved steps, the fronts of the
plan view, the movie, the height of a layered run, a folder given as the scene."""
import json

import numpy as np
import pytest
from PIL import Image

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.app import cli, runner
from hmatddm.app.fronts import asymptotic_front, element_front, reference_front, tip_regime
from hmatddm.scene.height_reference import height_reference, stack_problem, three_layer_stack
from hmatddm.app.profiles import closed_form_profile
from hmatddm.render.profiles import plot_tip_regime
from scene_texts import KGD_2D_HEAD

TINY_2D = 'name = "tiny-kgd"\n' + KGD_2D_HEAD + """end_time = 3.0
backend = "dense"
initial_pressure = 0.6e6
[reference]
kind = "kgd-k"
"""


def not_blank(path):
    image = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    return image.std() > 5.0


def test_a_run_draws_profiles_and_render_draws_every_saved_step_and_a_movie(tmp_path, capsys):
    out = tmp_path / "out"
    runner.run_scene(hs.parse_scene(TINY_2D, overrides=["numerics.end_time=2"]), out, quiet=True)
    snapshots = out / "snapshots"
    for step in (0, 1, 2):  # the run itself draws a profile beside every saved step
        assert not_blank(snapshots / f"step-{step:06d}_profile.png")
    assert cli.main(["render", str(out), "--movie"]) == cli.EXIT_OK
    written = capsys.readouterr().out
    for step in (0, 1, 2):  # output.every = 1: every step is saved
        assert f"step-{step:06d}_profile.png" in written
    movie = Image.open(out / "movie.gif")
    assert movie.n_frames == 3 and movie.size == Image.open(snapshots / "step-000002_profile.png").size


def test_the_closed_form_profile_is_the_vertex_solution():
    scene = hs.parse_scene(TINY_2D).data
    profile = closed_form_profile(scene, 2.0)
    material = hd.Elastic(scene["material"]["shear_modulus"], scene["material"]["poisson_ratio"])
    half_length, width, pressure = hd.analytical.kgd_k_vertex(2.0, 5e-4, 5e6, material)
    assert profile["position"].min() == pytest.approx(-half_length) and profile["position"].max() == pytest.approx(
        half_length)
    assert np.max(profile["opening"]) == pytest.approx(width) and np.allclose(profile["net_pressure"], pressure)
    middle = np.argmin(np.abs(profile["position"] - 0.5 * half_length))  # Sneddon's ellipse
    assert profile["opening"][middle] == pytest.approx(
        width * np.sqrt(1 - (profile["position"][middle] / half_length) ** 2))
    assert closed_form_profile(scene, 0.0) is None and closed_form_profile({"cluster": []}, 1.0) is None


def test_the_fronts_of_a_plan_view():
    # the element front of a 3 x 3 square: its 12 outer edges
    square = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3, 3, 3, 3)
    pairs = element_front(square)
    assert pairs.shape == (24, 3) and np.allclose(np.max(np.abs(pairs[:, :2]), axis=1), 1.5)
    # the closed form's circle round the well, of the reference radius
    scene = hs.load_scene("radial-m").data
    circle = reference_front(scene, 10.0, square)[0]
    radius = hs.reference_curves(scene, end_time=10.0, samples=2)["radius"][-1]
    assert np.allclose(np.linalg.norm(circle, axis=1), radius) and np.allclose(circle[:, 2], 0.0)


def test_the_tracked_asymptotic_front_is_the_run_s_radius(tmp_path):
    simulation = hs.build_simulation(hs.load_scene("radial-m", overrides=["numerics.end_time=2"]).data)
    simulation.run(2.0)
    state = simulation.state
    lines = asymptotic_front(state.mesh, state.front_distance, state.front_velocity, state.front_class)
    points = np.concatenate(lines)
    radius = np.linalg.norm(points[:, :2], axis=1)
    record = simulation.records[-1]
    assert record["front_radius_min"] - 0.05 <= radius.min() and radius.max() <= record["front_radius_max"] + 0.05
    assert np.mean(radius) == pytest.approx(record["radius"], rel=0.03)
    # the tip regime at the ribbon elements: K^ = K' s^(1/2) / (E' w), K' = sqrt(32/pi) K_Ic
    opening = np.sum(state.dd * state.mesh.normals, axis=1)
    angle, k_hat = tip_regime(state.mesh, opening, state.front_distance, [0.0, 0.0, 0.0], 1e6,
                              simulation.material.plane_strain_modulus)
    ribbon = np.flatnonzero(np.isfinite(state.front_distance))
    assert len(k_hat) == ribbon.size and np.all(np.diff(angle) >= 0) and np.all((0 < k_hat) & (k_hat < 1))
    first = ribbon[np.argmin(np.degrees(np.arctan2(state.mesh.centers[ribbon, 1], state.mesh.centers[ribbon, 0]))
                             % 360.0)]
    expected = np.sqrt(32.0 / np.pi) * 1e6 * np.sqrt(state.front_distance[first]) / (
        simulation.material.plane_strain_modulus * opening[first])
    assert k_hat[0] == pytest.approx(expected, rel=1e-12)
    assert not_blank(plot_tip_regime(angle, k_hat, tmp_path / "front.png", title="radial-m"))


def test_layered_height_reports_its_height_tips_and_the_closed_form(tmp_path):
    summary = runner.run_scene(hs.load_scene("layered-height", overrides=["numerics.end_time=3"]), tmp_path,
                               quiet=True)
    steps = summary["steps"]
    scene = summary["scene"]
    interfaces = [layer["bottom"] for layer in scene["layer"][:-1]]
    first = steps[0]
    assert (first["height"], first["top"], first["bottom"]) == (2.0, 1.0, -1.0)
    assert first["top_layer"] == first["bottom_layer"] == 1 and first["interfaces_crossed"] == 0
    for step in steps:
        assert step["height"] == pytest.approx(step["top"] - step["bottom"])
        for tip, layer in (("top", "top_layer"), ("bottom", "bottom_layer")):
            inside = step[tip] - 0.25 if tip == "top" else step[tip] + 0.25  # the tip element's centre
            assert step[layer] == sum(inside < d for d in interfaces)
        assert step["interfaces_crossed"] == sum(step["bottom"] < d < step["top"] for d in interfaces)
    assert steps[-1]["height"] > 2.0  # it grew
    # the equilibrium height of the three-layer stack, for each step's net pressure
    assert three_layer_stack(scene) == (0.5e6, 6.0, 5e6, 0.5e6)
    rows = summary["reference"]
    assert len(rows) == len(steps) and rows[0]["height"] is None
    for row, step in zip(rows[1:], steps[1:]):
        assert row["net_pressure"] == pytest.approx(step["wellbore_pressure"][0] - 0.5e6)
        assert "Simonson" in row["solution"]["source"] and row["solution"]["formula"].startswith("K_Ic = sqrt(pi a)")
        assert row["solution"]["kind"] == "three-layer-height"
        if row["net_pressure"] >= 0.5e6:  # above the contrast: no equilibrium
            assert row["height"] is None and row["contained"] is False
    assert not_blank(tmp_path / "history.png")


def test_height_reference_of_a_contained_stack():
    scene = hs.load_scene("layered-height", overrides=["propagation.toughness=0.5e6"]).data
    steps = [dict(time=1.0, wellbore_pressure=[0.5e6 + 0.45e6], height=10.0)]
    row = height_reference(scene, steps)[0]
    from hmatddm.analytical.height_growth import equilibrium_height

    assert row["height"] == pytest.approx(equilibrium_height(0.45e6, 0.5e6, 6.0, 0.5e6)) and row["height"] > 6.0
    assert row["contained"] is True and row["relative_error"]["height"] == pytest.approx(10.0 / row["height"] - 1)
    assert height_reference(hs.load_scene("kgd").data, steps) is None


@pytest.mark.parametrize("overrides, message", [
    (["cluster[0].position=[0.0, 1.0]"], "the injection point (y = 1 m) must be in the middle of the pay zone"),
    (["layer[2].s_hmin=2e6"], "the two bounding layers need the same layer s_hmin"),
    (["layer[0].s_hmin=0.2e6", "layer[2].s_hmin=0.2e6"], "must exceed the pay zone's closing stress"),
])
def test_the_three_layer_height_reference_is_refused_where_it_does_not_apply(overrides, message):
    import re

    with pytest.raises(hd.InputError) as refused:
        hs.load_scene("layered-height", overrides=overrides)
    assert str(refused.value).startswith("reference.kind = 'three-layer-height' is the equilibrium height of a "
                                         "symmetric three-layer stack: ")
    assert message in str(refused.value)
    with pytest.raises(hd.InputError, match=re.escape("is a 2D closed form; the scene has dimension = 3")):
        hs.load_scene("radial-k", overrides=['reference.kind="three-layer-height"'])
    assert stack_problem(hs.load_scene("layered-height").data) is None


def test_a_folder_given_as_the_scene(tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert cli.main(["run", str(empty)]) == cli.EXIT_BAD_INPUT
    assert f"SCENE '{empty}' is a folder, not a scene: it holds no .toml file" in capsys.readouterr().err
    many = tmp_path / "many"
    many.mkdir()
    for name in ("a.toml", "b.toml"):
        (many / name).write_text(TINY_2D)
    assert cli.main(["run", str(many)]) == cli.EXIT_BAD_INPUT
    assert "it holds 2 .toml files: a.toml, b.toml; give one of them" in capsys.readouterr().err
    one = tmp_path / "one"
    one.mkdir()
    (one / "mine.toml").write_text(TINY_2D)
    assert cli.main(["run", str(one), "--check"]) == cli.EXIT_OK
    captured = capsys.readouterr()
    assert f"is a folder: running its scene file {one / 'mine.toml'}" in captured.err
    assert json.loads(captured.out)["name"] == "tiny-kgd"


def test_resume_prints_this_session_s_time_and_the_total(tmp_path, capsys, monkeypatch):
    from test_runner import interrupt_after

    path = tmp_path / "tiny.toml"
    path.write_text(TINY_2D)
    out = tmp_path / "out"
    monkeypatch.setattr(runner.Progress, "update", interrupt_after(2))
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == cli.EXIT_INTERRUPTED
    monkeypatch.undo()
    capsys.readouterr()
    assert cli.main(["run", "--out", str(out), "--resume"]) == cli.EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    assert "s in all, with the earlier sessions)" in lines[0]
    assert lines[1].startswith("hmatddm: fluid budget (volume at the reference density): worst residual")


def test_the_profile_of_a_layered_section_marks_its_interfaces():
    from hmatddm.app.profiles import interface_crossings
    from hmatddm.render.profiles import fracture_sections

    mesh = hd.mesh.line([0.0, -5.0], [0.0, 5.0], 20)  # a vertical fracture, 0.5 m elements
    sections = fracture_sections(mesh, np.ones(20), np.ones(20), wells=[[0.0, 0.1]])
    assert sections[0].position[10] == pytest.approx(0.25 - 0.1)  # arc length from the well itself
    scene = {"layer": [{"bottom": 3.0}, {"bottom": -3.0}, {}]}
    assert np.allclose(sorted(interface_crossings(mesh, sections, scene)), [-3.1, 2.9])
