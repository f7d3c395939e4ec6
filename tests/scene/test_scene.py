"""Scene files: embedded scenes, validation messages (key, value, range), unknown keys
with suggestions, stress conventions, overrides and the closed-form reference."""
import copy
import tomllib

import numpy as np
import pytest

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.errors import InputError
from hmatddm.scene.schema import far_field_stress, to_toml, validate
from scene_texts import RADIAL_3D_BODY

TINY_3D = 'description = "tiny radial fracture"\n' + RADIAL_3D_BODY

TINY_2D = """
dimension = 2
height = 1.0
[material]
shear_modulus = 10e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-3
[stress]
s_hmin = 0.5e6
s_hmax = 1e6
[[cluster]]
position = [0.0, 0.0]
rate = 5e-4
[[initial_fracture]]
shape = "line"
p0 = [-1.5, 0.0]
p1 = [1.5, 0.0]
element_size = 1.0
[propagation]
toughness = 5e6
[numerics]
time_step = 1.0
end_time = 3.0
"""


def raw(text=TINY_3D):
    return tomllib.loads(text)


def set_key(scene, path, value):
    """Set ``section.key`` (or ``section[i].key``, or ``key``) in a raw scene; DELETE removes it."""
    *sections, key = path.split(".")
    table = scene
    for section in sections:
        if section.endswith("]"):
            name, index = section[:-1].split("[")
            table = table[name][int(index)]
        else:
            table = table.setdefault(section, {})
    if value is DELETE:
        del table[key]
    else:
        table[key] = value
    return scene


class _Delete:
    """The marker DELETE; its repr is the test id, the same in every pytest-xdist worker."""

    def __repr__(self):
        return "DELETE"


DELETE = _Delete()

BAD_SCENES = [
    ("material.poisson_ratio", 0.5, "material.poisson_ratio must be in [0, 0.5), got 0.5"),
    ("material.shear_modulus", -1.0, "material.shear_modulus must be > 0 Pa, got -1"),
    ("fluid.viscosity", "1 cP", "fluid.viscosity must be a number (> 0 Pa s), got '1 cP'"),
    ("fluid.compressibility", -1e-10, "fluid.compressibility must be >= 0 1/Pa, got -1e-10"),
    ("numerics.backend", "hmatirx", "numerics.backend must be one of 'dense', 'hmatrix', got 'hmatirx'; "
                                    "did you mean 'hmatrix'?"),
    ("numerics.eps", 0.0, "numerics.eps must be in (0, 1), got 0"),
    ("numerics.end_time", DELETE, "numerics.end_time (s) is required"),
    ("numerics.time_step", -1.0, "numerics.time_step must be > 0 s, got -1"),
    ("numerics.max_iterations", 1.5, "numerics.max_iterations must be an integer (>= 1), got 1.5"),
    ("numerics.relaxation", 0.001, "numerics.min_relaxation must be <= numerics.relaxation = 0.001, "
                                   "got 0.00390625"),
    ("numerics.min_relaxation", 1.0, None),  # fine: no halving of the relaxation
    ("numerics.relaxation_growth", 0.5, "numerics.relaxation_growth must be >= 1, got 0.5"),
    ("numerics.relaxation_growth", 1.0, None),  # fine: keep the alpha a step needed (ref. Fig. 4.10)
    ("output.snapshots", "yes", "output.snapshots must be true or false, got 'yes'"),
    ("output.every", 0, "output.every must be an integer >= 1, got 0"),
    ("cluster[0].position", [0.0, 0.0], "cluster[0].position must be a list of 3 coordinates (m), got 2"),
    ("cluster[0].rate", -0.01, "cluster[0].rate must be >= 0 m^3/s, got -0.01"),
    ("stress.s_hmin", 20e6, "stress.s_hmin must be <= stress.s_hmax = 12000000 Pa, got 20000000"),
    ("stress.tensor", [[1e6, 0, 0], [0, 1e6, 0], [0, 0, 1e6]], "give either stress.tensor or the principal values"),
    ("stress.s_v", DELETE, "missing stress.s_v"),
    ("stress.azimuth_deg", 400.0, "stress.azimuth_deg must be in [-360, 360] deg, got 400"),
    ("initial_fracture[0].length", 3.5, "initial_fracture[0].length = 3.5 m must be a whole multiple (>= 1) "
                                        "of initial_fracture[0].element_size = 1 m"),
    ("initial_fracture[0].e2", [1.0, 1.0, 0.0], "initial_fracture[0].e1 and initial_fracture[0].e2 must be orthogonal"),
    ("initial_fracture[0].shape", "line", "initial_fracture[0].shape = 'line' needs dimension = 2"),
    ("initial_fracture[0].radius", 2.0, "initial_fracture[0].radius is not used by shape 'rectangle'"),
    ("initial_fracture[0].element_size", DELETE, "initial_fracture[0].element_size (m) is required"),
    ("propagation.toughness", 0, "propagation.toughness must be > 0 Pa m^0.5, got 0"),
    ("propagation.criterion", "MCS", "propagation.criterion must be one of 'mcs', 'energy', got 'MCS'"),
    ("propagation.growing_fractures", [3], "propagation.growing_fractures holds 3, but the scene has 1"),
    ("propagation.bounds", [[1.0, -1.0]], "propagation.bounds[0] must be numbers [low, high] with low < high"),
    ("reference.kind", "kgd-k", "reference.kind = 'kgd-k' is a 2D closed form; the scene has dimension = 3"),
    ("reference.kind", "radial", "reference.kind must be one of 'radial-k', 'radial-m', 'radial-km', 'kgd-k', 'kgd-m', "
                                 "'three-layer-height', 'kgd-k-leak-off', 'radial-k-leak-off', 'kgd-m-leak-off', "
                                 "'kgd-km-leak-off', 'radial-km-leak-off', 'radial-m-leak-off', got 'radial'"),
    ("leak_off.coefficient", 1e-12, "reference.kind = 'radial-k' assumes no leak-off"),
    ("dimension", 4, "dimension must be one of [2, 3], got 4"),
    ("height", 2.0, "height is the flow height of a 2D (plane-strain) scene"),
    ("network.density", 0.05, "network.region = [x_min, x_max, y_min, y_max] (m) is required with network.density"),
    ("network.friction_coefficient", -0.1, "network.friction_coefficient must be >= 0, got -0.1"),
    ("network.crossing", "mc", "network.crossing must be one of"),
    ("natural_fracture", [{"p0": [0.0, 0.0], "p1": [0.0, 0.0]}], "natural_fracture[0].p0 and natural_fracture[0].p1 "
                                                                   "must differ"),
]


@pytest.mark.parametrize("path, value, fragment", BAD_SCENES, ids=[f"{p}={v!r}"[:60] for p, v, _ in BAD_SCENES])
def test_bad_values_name_the_key_the_value_and_the_range(path, value, fragment):
    scene = set_key(raw(), path, value)
    if fragment is None:
        validate(scene)
        return
    with pytest.raises(InputError) as error:
        validate(scene)
    assert fragment in str(error.value)


@pytest.mark.parametrize("path, suggestion", [
    ("numerics.tme_step", "unknown key 'numerics.tme_step'; did you mean 'numerics.time_step'?"),
    ("material.shear_modulous", "unknown key 'material.shear_modulous'; did you mean 'material.shear_modulus'?"),
    ("cluster[0].wellbore_volum",
     "unknown key 'cluster[0].wellbore_volum'; did you mean 'cluster[0].wellbore_volume'?"),
    ("stress.azimuth", "unknown key 'stress.azimuth'; did you mean 'stress.azimuth_deg'?"),
    ("descripton", "unknown key 'descripton'; did you mean 'description'?"),
    ("numerics.dimension", "'dimension' is a top-level key: put it above the first [section] header"),
    ("numerics.zzz", "unknown key 'numerics.zzz'; allowed keys: alpha, backend,"),
])
def test_unknown_keys_are_errors_with_a_suggestion(path, suggestion):
    scene = set_key(raw(), path, 1.0)
    with pytest.raises(InputError) as error:
        validate(scene)
    assert suggestion in str(error.value)


def test_unknown_sections_and_section_shapes():
    scene = raw()
    scene["numerix"] = {"end_time": 1.0}
    with pytest.raises(InputError, match=r"unknown section 'numerix'; did you mean 'numerics'\?"):
        validate(scene)
    scene = raw()
    scene["material"] = [scene["material"]]
    with pytest.raises(InputError, match=r"material must be one table \[material\], not an array of tables"):
        validate(scene)
    scene = raw()
    del scene["fluid"]
    with pytest.raises(InputError, match=r"the scene needs a \[fluid\] section"):
        validate(scene)
    scene = raw()
    scene["cluster"] = scene["cluster"][0]  # a single [cluster] table counts as one
    assert len(validate(scene)["cluster"]) == 1


def test_invalid_toml_and_unknown_scene_names():
    with pytest.raises(InputError, match="is not valid TOML"):
        hs.parse_scene("[material\nshear_modulus = 1")
    with pytest.raises(InputError, match=r"unknown scene 'radial_k': did you mean 'radial-k'\?"):
        hs.load_scene("radial_k")
    with pytest.raises(InputError, match="does not exist"):
        hs.load_scene("no/such/scene.toml")


def test_embedded_scenes_validate_build_and_round_trip():
    names = hs.embedded_names()
    assert names[0] == "default"
    assert {"default", "radial-k", "radial-m", "kgd", "crossing", "dfn-3cluster"} <= set(names)
    for name in names:
        scene = hs.load_scene(name)
        assert scene.name == name and scene.description
        assert scene.has_natural_fractures == (name in ("crossing", "dfn-3cluster", "stage"))
        sim = hs.build_simulation(scene.data)
        assert isinstance(sim, hd.Simulation) and sim.mesh0.dim == scene.dimension
        again = hs.parse_scene(scene.to_toml())  # the echo reads back to itself
        assert again.data == scene.data
        assert validate(copy.deepcopy(scene.data)) == scene.data


def test_kgd_scene_is_toughness_dominated():
    scene = hs.load_scene("kgd").data
    mat = hd.Elastic(scene["material"]["shear_modulus"], scene["material"]["poisson_ratio"])
    k_m = hd.analytical.kgd_regime(scene["cluster"][0]["rate"] / scene["height"], scene["fluid"]["viscosity"],
                                   scene["propagation"]["toughness"], mat)
    assert k_m > 4.0


def test_defaults_are_filled_and_numbers_are_floats():
    data = raw()
    del data["numerics"]["time_step"]  # a scene without time_step follows the front
    scene = validate(data)
    assert scene["dimension"] == 3 and "height" not in scene
    assert scene["numerics"]["time_step"] == "auto" and scene["numerics"]["scheme"] == "krylov"
    assert scene["leak_off"] == {"coefficient": 0.0, "pore_pressure": 0.0}
    assert scene["output"]["every"] == 1 and scene["output"]["snapshots"] is True
    assert scene["initial_fracture"][0]["shape"] == "rectangle"
    assert isinstance(scene["material"]["shear_modulus"], float)
    two = validate(raw(TINY_2D))
    assert two["height"] == 1.0 and two["initial_fracture"][0]["shape"] == "line"


def test_stress_file_convention_is_compressive_positive():
    scene = validate(raw())
    assert np.allclose(far_field_stress(scene), -np.diag([12e6, 10e6, 8e6]))  # s_hmax along x (azimuth 0)
    rotated = set_key(raw(), "stress.azimuth_deg", 90.0)
    assert np.allclose(far_field_stress(validate(rotated)), -np.diag([10e6, 12e6, 8e6]), atol=1e-6)
    tensor = raw()
    tensor["stress"] = {"tensor": [[1e6, 2e5, 0], [2e5, 3e6, 0], [0, 0, 5e6]]}
    assert np.allclose(far_field_stress(validate(tensor)), -np.array([[1e6, 2e5, 0], [2e5, 3e6, 0], [0, 0, 5e6]]))
    tensor["stress"]["tensor"][0][1] = 0.0
    with pytest.raises(InputError, match=r"stress.tensor must be symmetric"):
        validate(tensor)
    two = validate(raw(TINY_2D))
    assert np.allclose(far_field_stress(two), -np.diag([1e6, 0.5e6]))
    with pytest.raises(InputError, match="stress.s_v is not used in a 2D scene"):
        validate(set_key(raw(TINY_2D), "stress.s_v", 1e6))
    # the built simulation opens the crack with the stress normal to it
    sim = hs.build_simulation(validate(raw()))
    assert np.allclose(sim.far_field_traction(sim.mesh0).reshape(-1, 3), [0.0, 0.0, 8e6])


def test_clusters_must_lie_on_a_fracture_and_fractures_must_not_overlap():
    scene = validate(set_key(raw(), "cluster[0].position", [10.0, 0.0, 0.0]))
    with pytest.raises(InputError, match=r"cluster\[0\].position = \[10, 0, 0\] m is .* from the nearest"):
        hs.build_simulation(scene)
    twice = raw()
    twice["initial_fracture"] = twice["initial_fracture"] * 2
    with pytest.raises(InputError, match=r"initial_fracture\[0\] and initial_fracture\[1\] overlap"):
        hs.build_simulation(validate(twice))


def test_penny_and_multiple_fractures_build():
    scene = raw()
    scene["initial_fracture"] = [
        {"shape": "penny", "center": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "radius": 2.0, "element_size": 1.0},
        {"center": [0.0, 10.0, 0.0], "length": 2.0, "height": 2.0, "element_size": 1.0}]
    del scene["reference"]
    scene["propagation"]["growing_fractures"] = [0]
    sim = hs.build_simulation(validate(scene))
    assert set(sim.mesh0.fracture_id.tolist()) == {0, 1}
    assert sim.growing_fractures.tolist() == [0]


def test_natural_fractures_validate_and_build():
    scene = raw()
    scene["network"] = {"friction_coefficient": 0.3, "region": [-50.0, 50.0, -100.0, 100.0], "density": 0.05,
                        "mean_azimuths_deg": [45.0, 135.0], "kappas": [5.0, 5.0], "weights": [0.5, 0.5]}
    scene["natural_fracture"] = [{"p0": [5.0, -10.0], "p1": [5.0, 10.0]}]
    checked = validate(scene)
    assert checked["network"]["l_max"] == 30.0 and checked["network"]["crossing"] == "mohr-coulomb"
    assert hs.has_natural_fractures(checked)
    assert validate(copy.deepcopy(checked)) == checked
    simulation = hs.build_simulation(checked)
    assert simulation.network.mesh.n_elements > 20 and simulation.network.properties.friction == 0.3
    bad = copy.deepcopy(scene)
    bad["network"]["weights"] = [0.5, 0.6]
    with pytest.raises(InputError, match=r"network.weights must sum to 1"):
        validate(bad)
    bad["network"]["weights"] = [1.0]
    with pytest.raises(InputError, match=r"must have the same length"):
        validate(bad)
    bad = copy.deepcopy(scene)
    bad["network"]["l_min"] = 40.0
    with pytest.raises(InputError, match=r"network.l_max must be >= network.l_min = 40 m, got 30"):
        validate(bad)
    only = raw()
    only["network"] = {"l_min": 2.0}
    with pytest.raises(InputError, match=r"network.density \(1/m\^2\) is required to generate a network"):
        validate(only)


def test_natural_fracture_defaults_are_those_of_the_properties_class():
    # one default per field (hmatddm.settings.NATURAL_FRACTURE): a scene that sets no strength
    # builds what NaturalFractureProperties() holds, the values of ref. Table 6.2
    scene = raw()
    scene["natural_fracture"] = [{"p0": [5.0, -10.0], "p1": [5.0, 10.0]}]
    built = hs.build.natural_properties(validate(scene))
    assert built == hd.NaturalFractureProperties(pore_pressure=built.pore_pressure)
    assert (built.friction, built.cohesion, built.toughness, built.critical_radius) == (0.25, 0.0, 0.5e6, 0.005)


def test_overrides_apply_before_validation():
    scene = hs.load_scene("kgd", overrides=["numerics.end_time=5", 'numerics.backend="dense"',
                                            "cluster[0].rate=1e-3", "output.snapshots=false"])
    assert scene.numerics["end_time"] == 5.0 and scene.numerics["backend"] == "dense"
    assert scene.data["cluster"][0]["rate"] == 1e-3 and scene.data["output"]["snapshots"] is False
    assert hs.load_scene("kgd", overrides=["numerics.scheme=fully-coupled"]).numerics["scheme"] == "fully-coupled"
    with pytest.raises(InputError, match="unknown key 'numerics.end_tme'"):
        hs.load_scene("kgd", overrides=["numerics.end_tme=5"])
    with pytest.raises(InputError, match="expects KEY=VALUE"):
        hs.load_scene("kgd", overrides=["numerics.end_time"])


def test_scene_files_and_names(tmp_path):
    path = tmp_path / "my-crack.toml"
    path.write_text(TINY_3D)
    scene = hs.load_scene(str(path))
    assert scene.name == "my-crack" and scene.source == str(path)
    path.write_text('name = "named"\n' + TINY_3D)
    assert hs.load_scene(str(path)).name == "named"
    assert "[[cluster]]" in to_toml(scene.data)


def test_reference_values_follow_the_closed_forms():
    scene = validate(raw())
    mat = hd.Elastic(24e9, 0.25)
    radius, width, pressure = hd.analytical.radial_k_vertex(2.0, 0.01, 5e6, mat)
    record = dict(time=2.0, radius=1.1 * radius, max_opening=width, wellbore_pressure=[8e6 + pressure])
    (row,) = hs.reference_values(scene, [record])
    assert row["radius"] == pytest.approx(radius) and row["net_pressure"] == pytest.approx(pressure)
    assert row["relative_error"]["radius"] == pytest.approx(0.1)
    assert row["relative_error"]["net_pressure"] == pytest.approx(0.0, abs=1e-12)
    assert row["dimensionless_toughness"] > 1.0
    two = set_key(raw(TINY_2D), "reference.kind", "kgd-m")
    length, width, pressure = hd.analytical.kgd_m_vertex(3.0, 5e-4, 1e-3, hd.Elastic(10e9, 0.25))
    (row,) = hs.reference_values(validate(two), [dict(time=3.0, half_length=length, max_opening=width,
                                                      wellbore_pressure=[0.5e6 + pressure])])
    assert row["half_length"] == pytest.approx(length)
    assert max(abs(v) for v in row["relative_error"].values()) < 1e-9
    assert hs.reference_values(validate(raw(TINY_2D)), [record]) is None
    curves = hs.reference_curves(scene)
    assert set(curves) == {"time", "radius", "max_opening", "net_pressure"} and curves["time"][-1] == 2.0


def test_relaxation_growth_reaches_the_scheme_settings():
    from hmatddm.scene.build import scheme_settings

    default = scheme_settings(validate(raw()))
    assert default.relaxation_growth == (2.0 if default.scheme in ("krylov", "fully-coupled") else 1.0)
    assert scheme_settings(validate(set_key(raw(), "numerics.relaxation_growth", 1.5))).relaxation_growth == 1.5


def test_scenes_with_natural_fractures_close_every_element_by_default():
    """issue 19 item 5: numerics.contact defaults to "all" with natural fractures (a hydraulic
    element squeezed in a network otherwise opens negatively), "natural" without; a scene
    that says otherwise keeps its choice, and the echo validates to itself."""
    from scene_texts import KGD_2D_HEAD

    plain = KGD_2D_HEAD + "end_time = 1.0\n"
    natural = plain + "[[natural_fracture]]\np0 = [2.0, -1.0]\np1 = [2.0, 1.0]\n"
    assert hs.parse_scene(plain).numerics["contact"] == "natural"
    echo = hs.parse_scene(natural).data
    assert echo["numerics"]["contact"] == "all" and validate(copy.deepcopy(echo)) == echo
    assert hs.parse_scene(natural, overrides=['numerics.contact="natural"']).numerics["contact"] == "natural"
    assert hs.load_scene("crossing").numerics["contact"] == "all"
