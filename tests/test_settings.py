"""hmatddm.settings: one declaration per setting, read by the scene schema and by the
dataclasses the scene builds, so that both refuse a value with the same words."""
import copy

import numpy as np
import pytest

from hmatddm import settings
from hmatddm.errors import InputError
from hmatddm.scene import schema, sections
from hmatddm.settings import Setting, integer


def test_range_text_and_bounds_open_and_closed():
    half_open = Setting("number", low=0.0, high=0.5, high_open=True)
    assert half_open.range_text() == "in [0, 0.5)"
    assert half_open.in_range(0.0) and not half_open.in_range(0.5)
    assert Setting("number", low=0.0, low_open=True, unit="Pa").range_text() == "> 0 Pa"
    assert Setting("number", high=1.0).range_text() == "<= 1"
    assert Setting("number").range_text() == "a finite number"


@pytest.mark.parametrize("value, message", [
    (True, "n must be an integer (in [1, 3]), got true"),
    (2.0, "n must be an integer (in [1, 3]), got 2"),
    (0, "n must be an integer in [1, 3], got 0"),
    (4, "n must be an integer in [1, 3], got 4"),
])
def test_integer_refuses_by_name_and_range(value, message):
    with pytest.raises(InputError) as error:
        integer("n", value, 1, 3)
    assert str(error.value) == message


def test_integer_takes_numpy_integers():
    value = integer("n", np.int64(7))
    assert value == 7 and type(value) is int


def test_value_outside_a_scene_takes_numeric_strings_and_refuses_nan():
    toughness = settings.PROPAGATION["toughness"]
    assert toughness.value("K", "2e6") == 2e6
    with pytest.raises(InputError, match=r"K must be a finite number \(> 0 Pa m\^0.5\), got nan"):
        toughness.value("K", float("nan"))
    assert settings.NUMERICS["alpha"].value("alpha", None) is None  # optional without a default


def test_scene_sections_are_the_declarations():
    """The scene's sections hold the very objects the dataclasses check against."""
    assert sections.NUMERICS is settings.NUMERICS and sections.LAYER is settings.LAYER
    assert sections.MICROSEISMIC is settings.MICROSEISMIC
    assert sections.NETWORK_GENERATOR is settings.NETWORK_GENERATOR
    for key, setting in settings.SCHEME.items():
        assert sections.NUMERICS[key] is setting
    for key in ("eps", "eta", "leaf_size", "singular_correction", "alpha"):
        assert sections.NUMERICS[key] is settings.OPERATOR[key]
    for key in ("friction_coefficient", "cohesion", "tensile_strength", "toughness", "critical_radius"):
        assert sections.NETWORK[key] is settings.NATURAL_FRACTURE[key]


def test_dataclass_defaults_come_from_the_declarations():
    from hmatddm.layered import LayeredMedium
    from hmatddm.microseismic.forward import Well
    from hmatddm.microseismic.sources import Medium
    from hmatddm.network import NetworkSpec

    ms = settings.MICROSEISMIC
    assert Medium() == Medium(ms["p_wave_speed"].default, ms["s_wave_speed"].default, ms["density"].default)
    well = Well(0.0, 0.0)
    assert (well.top, well.bottom, well.spacing) == tuple(ms[k].default for k in
                                                           ("receiver_top", "receiver_bottom", "receiver_spacing"))
    spec = NetworkSpec(region=(-50, 50, -50, 50), density=0.05)
    for key in ("length_exponent", "l_min", "l_max", "seed", "boundary"):
        assert getattr(spec, key) == settings.NETWORK_GENERATOR[key].default
    assert list(spec.kappas) == settings.NETWORK_GENERATOR["kappas"].default
    medium = LayeredMedium((), (1e9,), (0.25,))
    assert medium.image_tol == settings.LAYERED_MEDIUM["image_tol"].default
    assert medium.gauss_points == settings.LAYERED_MEDIUM["gauss_points"].default


def _scene_with(section, key, value):
    raw = {"dimension": 2, "height": 1.0, "material": {"shear_modulus": 1e10, "poisson_ratio": 0.25},
           "fluid": {"viscosity": 1e-3}, "stress": {"s_hmin": 1e6, "s_hmax": 2e6},
           "cluster": [{"position": [0.0, 0.0], "rate": 1e-3}],
           "initial_fracture": [{"p0": [-1.0, 0.0], "p1": [1.0, 0.0], "element_size": 0.5}],
           "numerics": {"end_time": 1.0},
           "microseismic": {"wells": [[0.0, 30.0]]},
           "network": {"region": [-20.0, 20.0, -20.0, 20.0], "density": 0.05}}
    raw = copy.deepcopy(raw)
    raw[section][key] = value
    return raw


def _message(call):
    with pytest.raises(InputError) as error:
        call()
    return str(error.value)


@pytest.mark.parametrize("section, key, value, build", [
    ("microseismic", "p_wave_speed", 0.0, lambda: __import__("hmatddm.microseismic.sources", fromlist=["Medium"])
     .Medium(p_wave_speed=0.0)),
    ("microseismic", "receiver_spacing", -1.0, lambda: __import__("hmatddm.microseismic.forward", fromlist=["x"])
     .wells_from_positions([[0.0, 30.0]], spacing=-1.0)),
    ("network", "l_min", 0.0, lambda: __import__("hmatddm.network", fromlist=["NetworkSpec"])
     .NetworkSpec(region=(-20, 20, -20, 20), density=0.05, l_min=0.0)),
    ("network", "length_exponent", 0.5, lambda: __import__("hmatddm.network", fromlist=["NetworkSpec"])
     .NetworkSpec(region=(-20, 20, -20, 20), density=0.05, length_exponent=0.5)),
    ("network", "l_max", 10.0, lambda: __import__("hmatddm.network", fromlist=["NetworkSpec"])
     .NetworkSpec(region=(-20, 20, -20, 20), density=0.05, l_min=12.0, l_max=10.0)),
])
def test_scene_and_dataclass_refuse_with_the_same_words(section, key, value, build):
    """``section.key must be ...`` from the scene reads ``key must be ...`` from the
    class: the range (and for cross-field checks the rule) is written once."""
    raw = _scene_with(section, key, value)
    if key == "l_max":
        raw["network"]["l_min"] = 12.0
    scene_message = _message(lambda: schema.validate(raw))
    class_message = _message(build)
    assert scene_message.startswith(f"{section}.{key} must be")
    assert scene_message.replace(f"{section}.", "") == class_message


def test_check_fields_converts_in_place_and_names_the_field():
    from dataclasses import dataclass

    @dataclass(frozen=True)
    class Options:
        image_tol: float = 1e-4
        gauss_points: int = 4

    options = Options(gauss_points=np.int32(5))
    settings.check_fields(options, settings.LAYERED_MEDIUM)
    assert type(options.gauss_points) is int
    with pytest.raises(InputError, match=r"medium.image_tol must be in \(0, 1\), got 2"):
        settings.check_fields(Options(image_tol=2), settings.LAYERED_MEDIUM, prefix="medium.")
