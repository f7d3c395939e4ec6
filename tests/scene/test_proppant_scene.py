"""Proppant in scenes (issue 34): the [proppant] section and its pump schedule, refused bad
input naming the field, and the embedded scene `proppant` run into a folder (summary masses
balanced every step, VTU fields, the concentration snapshot and the mass history)."""
import json

import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.app import runner
from hmatddm.errors import InputError
from hmatddm.io import read_vtu
from hmatddm.scene.build import proppant


def not_blank(path):
    from PIL import Image

    image = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    return image.std() > 5.0


def test_proppant_section_builds_the_particles_and_the_schedule():
    scene = hs.load_scene("proppant").data
    assert scene["proppant"]["schedule"][0] == [0.0, 0.0]  # a pad first
    built = proppant(scene)
    assert built["proppant"].diameter == scene["proppant"]["diameter"]
    assert built["pump_schedule"].rows() == scene["proppant"]["schedule"]
    assert proppant(hs.load_scene("radial-m").data) == {}
    assert hs.parse_scene(hs.Scene(scene).to_toml()).data == scene


@pytest.mark.parametrize("overrides, message", [
    (["proppant.diameter=-2e-4"], r"proppant\.diameter must be > 0"),
    (["proppant.packing_limit=1.2"], r"proppant\.packing_limit must be in \(0, 1\)"),
    (["proppant.schedule=[[0.0, 0.0], [5.0, 0.6]]"], r"proppant\.schedule\[1\] concentration must be in \[0, 0\.6\)"),
    (["proppant.packing_limit=0.25"], r"proppant\.schedule\[3\] concentration must be in \[0, 0\.25\)"),
    (["proppant.schedule=[[5.0, 0.1], [1.0, 0.2]]"], r"proppant\.schedule\[1\] time must be after"),
    (["proppant.schedule=[[0.0, 0.1, 3.0]]"], r"proppant\.schedule\[0\] must be a list of 2 numbers"),
    (["proppant.schedule=[]"], r"proppant\.schedule must hold at least one row"),
    (["proppant.bridging_factor=0.5"], r"proppant\.bridging_factor must be >= 1"),
    (["proppant.grain=1"], r"unknown key 'proppant\.grain'"),
])
def test_bad_proppant_sections_are_refused_naming_the_field(overrides, message):
    with pytest.raises(InputError, match=message):
        hs.load_scene("proppant", overrides=overrides)


def test_schedule_is_required():
    text = "\n".join(line for line in hs.embedded_text("proppant").splitlines() if not line.startswith("schedule"))
    with pytest.raises(InputError, match=r"proppant\.schedule is required"):
        hs.parse_scene(text)


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("proppant")
    scene = hs.load_scene("proppant", overrides=["numerics.end_time=8.0", "output.every=4"])
    return out, runner.run_scene(scene, out, quiet=True)


def test_proppant_scene_balances_its_mass_every_step(finished):
    out, _ = finished
    steps = json.loads((out / "summary.json").read_text())["steps"]
    assert [s["step"] for s in steps] == list(range(9))
    assert steps[0]["proppant_mass"] == 0.0 and steps[0]["proppant_injected_mass"] == 0.0
    for step in steps:
        injected = step["proppant_injected_mass"]
        assert abs(injected - step["proppant_mass"] - step["proppant_screened_mass"]) <= 1e-10 * max(injected, 1e-30)
        assert 0.0 <= step["max_proppant_fraction"] < 0.6
    # 3 s of 0.1 sand at 0.01 m^3/s of slurry: 2650 * 0.003 kg
    assert steps[-1]["proppant_injected_mass"] == pytest.approx(2650.0 * 0.01 * 0.1 * 3.0, rel=1e-12)


def test_proppant_scene_writes_fields_snapshot_and_history(finished):
    out, _ = finished
    _, _, data = read_vtu(out / "vtu/step-000008.vtu")
    fraction, propped = data["proppant_fraction"], data["propped_width"]
    assert np.all(fraction >= 0.0) and np.all(fraction < 0.6) and fraction.max() > 0.05
    np.testing.assert_allclose(propped, fraction * data["opening"].clip(1e-4) / 0.6, rtol=1e-9, atol=1e-15)
    assert np.count_nonzero(fraction == 0.0) > 0  # the bridged tip ring is clean
    assert not_blank(out / "snapshots" / "step-000008_proppant.png")
    assert not_blank(out / "proppant_history.png")


def test_render_draws_the_proppant_pictures_again(finished):
    out, _ = finished
    (out / "proppant_history.png").unlink()
    (out / "snapshots" / "step-000008_proppant.png").unlink()
    written = runner.render_folder(out)
    assert out / "proppant_history.png" in written and not_blank(out / "proppant_history.png")
    assert out / "snapshots" / "step-000008_proppant.png" in written
    assert not_blank(out / "snapshots" / "step-000008_proppant.png")
