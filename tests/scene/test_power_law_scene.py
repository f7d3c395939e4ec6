"""Power-law fluids in scenes (issue 34): the [fluid] keys, `--set fluid.rheology=power-law`
on a Newtonian scene, the refused combinations and the power-law reference curves."""
import pytest

import hmatddm.scene as hs
from hmatddm.errors import InputError
from hmatddm.scene.build import fluid, reference_curves


def test_set_turns_a_newtonian_scene_into_a_power_law_one():
    scene = hs.load_scene("kgd", overrides=["fluid.rheology=power-law", "fluid.consistency=0.1",
                                            "fluid.flow_index=0.5"]).data
    assert scene["fluid"] == {"compressibility": 4.5e-10, "rheology": "power-law", "consistency": 0.1,
                              "flow_index": 0.5, "minimum_shear_rate": 1e-3}  # the viscosity is dropped
    built = fluid(scene)
    assert built.power_law and built.consistency == 0.1 and built.flow_index == 0.5
    again = hs.parse_scene(hs.Scene(scene).to_toml())
    assert again.data == scene
    # rheology alone: K = mu, n = 1 (the Newtonian fluid as a power-law one)
    only = hs.load_scene("kgd", overrides=["fluid.rheology=power-law"]).data["fluid"]
    viscosity = hs.load_scene("kgd").data["fluid"]["viscosity"]
    assert only["consistency"] == viscosity and only["flow_index"] == 1.0


@pytest.mark.parametrize("overrides, message", [
    (["fluid.rheology=power-law", "fluid.flow_index=1.5"], r"fluid\.flow_index must be in \(0, 1\]"),
    (["fluid.rheology=power-law", "fluid.flow_index=0"], r"fluid\.flow_index must be in \(0, 1\]"),
    (["fluid.rheology=power-law", "fluid.consistency=0"], r"fluid\.consistency must be > 0"),
    (["fluid.rheology=power-law", "fluid.consistency=-2"], r"fluid\.consistency must be > 0"),
    (["fluid.flow_index=0.5"], r"fluid\.consistency and fluid\.flow_index describe a power-law fluid"),
    (["fluid.rheology=bingham"], r"fluid\.rheology must be one of 'newtonian', 'power-law'"),
])
def test_bad_power_law_scenes_are_refused_naming_the_field(overrides, message):
    with pytest.raises(InputError, match=message):
        hs.load_scene("kgd", overrides=overrides)


def test_power_law_scene_without_consistency_or_viscosity_is_refused():
    text = hs.embedded_text("kgd-power-law").replace("consistency = 0.1", "")
    with pytest.raises(InputError, match=r"fluid\.consistency \(Pa s\^n\) is required"):
        hs.parse_scene(text)
    newtonian = "\n".join(line for line in hs.embedded_text("kgd").splitlines()
                          if not line.strip().startswith("viscosity"))
    with pytest.raises(InputError, match=r"fluid\.viscosity \(Pa s\) is required"):
        hs.parse_scene(newtonian)


def test_radial_km_reference_is_refused_for_a_power_law_fluid():
    with pytest.raises(InputError, match=r"reference.kind = 'radial-km' is a Newtonian closed form"):
        hs.load_scene("default", overrides=["fluid.rheology=power-law", "fluid.flow_index=0.5"])


def test_power_law_scene_references_adachi_detournay():
    from hmatddm.analytical import power_law

    scene = hs.load_scene("kgd-power-law").data
    curves = reference_curves(scene, 60.0, samples=5)
    import hmatddm as hd

    material = hd.Elastic(scene["material"]["shear_modulus"], scene["material"]["poisson_ratio"])
    length, width, _ = power_law.kgd_power_law_vertex(curves["time"], 5e-4, 0.1, 0.5, material)
    assert curves["half_length"] == pytest.approx(length, rel=1e-12)
    assert curves["max_opening"] == pytest.approx(width, rel=1e-12)
