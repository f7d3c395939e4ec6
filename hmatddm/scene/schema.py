"""The scene schema: checking a scene against what a scene file may hold (its sections,
keys, defaults and ranges are declared in :mod:`hmatddm.scene.sections`).

A scene is a TOML document (read with the standard library's ``tomllib``). Every
quantity is in SI units (Pa, m, s, Pa s, m^3/s, 1/Pa); angles are in degrees and the
keys that hold them end in ``_deg``. Stresses in the file are COMPRESSIVE POSITIVE,
as engineers write them (``s_hmin = 8e6`` is 8 MPa of compression); the engine counts
tension positive, so the tensor handed to :class:`hmatddm.Simulation` is the negative
of the one in the file (:func:`far_field_stress`).

Validation (:func:`validate`) returns a new dict with every default filled in and every
number converted to float (the "echo" of the scene). Every problem raises
:class:`~hmatddm.errors.InputError` naming the key (``section.key`` or
``section[i].key``), the value and the allowed range; unknown keys are errors with a
"did you mean" suggestion. Validating an echo gives the same echo back.

The full format, annotated, is in ``hmatddm/scene/__init__.py``.
"""
import difflib
import math

import numpy as np

from ..errors import InputError
from ..settings import ABSENT, REQUIRED, show  # noqa: F401  (show: re-exported for scene.build and preflight)
from .echo import far_field_stress, has_natural_fractures, to_toml  # noqa: F401  (the scene's public names)
from .sections import (FILLED_WHEN_ABSENT, INITIAL_FRACTURE, NETWORK_GENERATOR, SCHEME_KEYS, SECTIONS,
                       SHAPE_KEYS, SHAPES, TOP)
from .sections import LEAK_OFF_REFERENCE_KINDS
from .well_section import check_clusters_and_well


# ---------------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------------

def _unknown(path, key, allowed, where=""):
    """InputError for an unknown key, with the closest allowed key as a suggestion."""
    full = f"{path}.{key}" if path else key
    close = difflib.get_close_matches(key, list(allowed), n=1, cutoff=0.6)
    if close:
        suggestion = f"{path}.{close[0]}" if path else close[0]
        return InputError(f"unknown key {full!r}{where}; did you mean {suggestion!r}?")
    if path and key in TOP:
        return InputError(f"unknown key {full!r}; {key!r} is a top-level key: put it above the first "
                          "[section] header of the file")
    return InputError(f"unknown key {full!r}{where}; allowed keys: {', '.join(sorted(allowed))}")


def _check_table(path, table, keys, dim, defaults=None, required=()):
    """Check the keys of one table against ``keys``; returns the echo (defaults filled).

    ``defaults`` overrides the defaults of ``keys`` (and restricts the allowed keys to
    its own, for shape-dependent tables)."""
    if not isinstance(table, dict):
        raise InputError(f"{path} must be a table, got {show(table)}")
    allowed = keys if defaults is None else {k: keys[k] for k in defaults}
    for key in table:
        if key not in allowed:
            raise _unknown(path, key, allowed)
    echo = {}
    for key, spec in allowed.items():
        default = spec.default if defaults is None else defaults[key]
        if key in table:
            echo[key] = spec.check(f"{path}.{key}", table[key], dim)
        elif default is REQUIRED or key in required:
            unit = f" ({spec.unit})" if spec.unit else ""
            raise InputError(f"{path}.{key}{unit} is required")
        elif default is not ABSENT:
            echo[key] = list(default) if isinstance(default, list) else default
    return echo


def _as_tables(name, value):
    """An array-of-tables section as a list (a single ``[name]`` table counts as one)."""
    if isinstance(value, dict):
        return [value]
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise InputError(f"{name} must be one or more tables [[{name}]], got {show(value)}")
    if not value:
        raise InputError(f"{name} must hold at least one [[{name}]] table")
    return value


def _norm(vector):
    return math.sqrt(sum(v * v for v in vector))


def _unit_vector(path, vector):
    norm = _norm(vector)
    if norm == 0.0:
        raise InputError(f"{path} must be a non-zero vector, got {show(vector)}")
    return [v / norm for v in vector]


def _whole_multiple(path, size_path, extent, size):
    count = extent / size
    if abs(count - round(count)) > 1e-6 * max(1.0, count) or round(count) < 1:
        raise InputError(f"{path} = {show(extent)} m must be a whole multiple (>= 1) of {size_path} = "
                         f"{show(size)} m, got {count:.6g} elements")
    return int(round(count))


# ---------------------------------------------------------------------------------
# Cross-key checks
# ---------------------------------------------------------------------------------

def _check_initial_fracture(path, table, dim):
    if not isinstance(table, dict):
        raise InputError(f"{path} must be a table, got {show(table)}")
    shape = table.get("shape", SHAPES[dim][0])
    shape = INITIAL_FRACTURE["shape"].check(f"{path}.shape", shape, dim)
    if shape not in SHAPES[dim]:
        raise InputError(f"{path}.shape = {shape!r} needs dimension = {2 if dim == 3 else 3}; with "
                         f"dimension = {dim} use {' or '.join(map(repr, SHAPES[dim]))}")
    rest = {k: v for k, v in table.items() if k != "shape"}
    for key in rest:
        if key not in SHAPE_KEYS[shape]:
            if key in INITIAL_FRACTURE:
                raise InputError(f"{path}.{key} is not used by shape {shape!r}; its keys are "
                                 f"{', '.join(['shape', *SHAPE_KEYS[shape]])}")
            raise _unknown(path, key, INITIAL_FRACTURE)
    echo = {"shape": shape, **_check_table(path, rest, INITIAL_FRACTURE, dim, defaults=SHAPE_KEYS[shape])}
    size = echo["element_size"]
    if shape == "rectangle":
        e1 = _unit_vector(f"{path}.e1", echo["e1"])
        e2 = _unit_vector(f"{path}.e2", echo["e2"])
        dot = sum(a * b for a, b in zip(e1, e2))
        if abs(dot) > 1e-6:
            raise InputError(f"{path}.e1 and {path}.e2 must be orthogonal, got e1.e2 = {dot:.3g} "
                             f"(unit vectors of {show(echo['e1'])} and {show(echo['e2'])})")
        _whole_multiple(f"{path}.length", f"{path}.element_size", echo["length"], size)
        _whole_multiple(f"{path}.height", f"{path}.element_size", echo["height"], size)
    elif shape == "penny":
        _unit_vector(f"{path}.normal", echo["normal"])
        if size > 2.0 * echo["radius"]:
            raise InputError(f"{path}.element_size must be <= 2 * radius = {show(2 * echo['radius'])} m, "
                             f"got {show(size)}")
    else:
        length = _norm([b - a for a, b in zip(echo["p0"], echo["p1"])])
        if length == 0.0:
            raise InputError(f"{path}.p0 and {path}.p1 must differ (a crack of zero length), got {show(echo['p0'])}")
        _whole_multiple(f"{path} length |p1 - p0|", f"{path}.element_size", length, size)
    return echo


def _check_stress(echo, dim):
    has_tensor = "tensor" in echo
    principal = [k for k in ("s_hmin", "s_hmax", "s_v", "azimuth_deg") if k in echo]
    if has_tensor and principal:
        raise InputError(f"stress: give either stress.tensor or the principal values (s_hmin, s_hmax"
                         f"{', s_v' if dim == 3 else ''}, azimuth_deg), not both; got tensor and "
                         f"{', '.join('stress.' + k for k in principal)}")
    if has_tensor:
        tensor = np.array(echo["tensor"])
        scale = 1.0 + float(np.max(np.abs(tensor)))
        if not np.allclose(tensor, tensor.T, rtol=0.0, atol=1e-9 * scale):
            i, j = np.unravel_index(np.argmax(np.abs(tensor - tensor.T)), tensor.shape)
            raise InputError(f"stress.tensor must be symmetric, got [{i}][{j}] = {show(tensor[i, j])} but "
                             f"[{j}][{i}] = {show(tensor[j, i])}")
        return echo
    needed = ["s_hmin", "s_hmax"] + (["s_v"] if dim == 3 else [])
    missing = [k for k in needed if k not in echo]
    if missing:
        raise InputError(f"stress needs either stress.tensor or the principal values "
                         f"{', '.join('stress.' + k for k in needed)} (Pa, compressive positive); "
                         f"missing {', '.join('stress.' + k for k in missing)}")
    if dim == 2 and "s_v" in echo:
        raise InputError("stress.s_v is not used in a 2D scene (dimension = 2: plane strain in the x-y "
                         "plane, only s_hmin, s_hmax and azimuth_deg act); remove it")
    if echo["s_hmin"] > echo["s_hmax"]:
        raise InputError(f"stress.s_hmin must be <= stress.s_hmax = {show(echo['s_hmax'])} Pa, "
                         f"got {show(echo['s_hmin'])}")
    echo.setdefault("azimuth_deg", 0.0)
    return echo


def _check_network(echo, given):
    generator = [k for k in NETWORK_GENERATOR if k in given]
    if generator and "density" not in given:
        raise InputError(f"network.density (1/m^2) is required to generate a network (given: "
                         f"{', '.join('network.' + k for k in generator)})")
    if "density" not in given:
        for key in NETWORK_GENERATOR:
            echo.pop(key, None)
        return echo
    if "region" not in given:
        raise InputError("network.region = [x_min, x_max, y_min, y_max] (m) is required with network.density")
    from ..network.generation import check_spec

    check_spec(echo, "network.")
    modes = len(echo["mean_azimuths_deg"])
    echo.setdefault("weights", [1.0 / modes] * modes)  # the echo keeps the weights as given
    return echo


def _check_fluid(echo):
    """The keys a rheology takes (issue 34; :class:`hmatddm.flow.Fluid`): a Newtonian fluid its
    viscosity; a power-law fluid its consistency K and flow index n. A power-law fluid without
    a consistency takes K = viscosity (n = 1, K = mu is the Newtonian fluid), and a viscosity
    beside a consistency is dropped from the echo, so that ``--set fluid.rheology=power-law
    --set fluid.consistency=... --set fluid.flow_index=...`` turns a Newtonian scene into a
    power-law one. Returns the echo."""
    if echo["rheology"] == "newtonian":
        if "viscosity" not in echo:
            raise InputError("fluid.viscosity (Pa s) is required for fluid.rheology = 'newtonian'")
        if "consistency" in echo or echo["flow_index"] != 1.0:
            raise InputError("fluid.consistency and fluid.flow_index describe a power-law fluid: set "
                             "fluid.rheology = 'power-law' (a Newtonian fluid takes fluid.viscosity)")
        return echo
    viscosity = echo.pop("viscosity", None)
    if "consistency" not in echo:
        if viscosity is None:
            raise InputError("fluid.consistency (Pa s^n) is required for fluid.rheology = 'power-law'")
        echo["consistency"] = viscosity
    return {key: echo[key] for key in ("compressibility", "rheology", "consistency", "flow_index",
                                       "minimum_shear_rate")}


def _check_reference(scene):
    kind = scene["reference"]["kind"]
    dim = scene["dimension"]
    want = 3 if kind.startswith("radial") else 2
    where = f"reference.kind = {kind!r}"
    if kind == "three-layer-height":  # Simonson et al. 1978 (hmatddm.scene.height_reference)
        from .height_reference import stack_problem

        problem = stack_problem(scene)
        if problem:
            raise InputError(f"{where} is the equilibrium height of a symmetric three-layer stack: {problem}")
        return
    if dim != want:
        raise InputError(f"{where} is a {want}D closed form; the scene has dimension = {dim}")
    if "well" in scene:
        raise InputError(f"{where} compares one cluster of a fixed rate: a scene with a [well] has no closed form "
                         "here (remove [reference] or [well])")
    if len(scene["cluster"]) != 1 or scene["cluster"][0].get("rate", 0.0) <= 0.0:
        raise InputError(f"{where} needs exactly one [[cluster]] with rate > 0, got {len(scene['cluster'])} "
                         "cluster(s)")
    if "propagation" not in scene:
        raise InputError(f"{where} compares a growing fracture: the scene needs a [propagation] section")
    if scene["fluid"]["rheology"] == "power-law" and kind == "radial-km":
        raise InputError(f"{where} is a Newtonian closed form (Dontsov 2016); a power-law fluid "
                         "(fluid.rheology = 'power-law') is compared with kind = 'radial-m', 'radial-k', 'kgd-m' "
                         "or 'kgd-k'")
    if kind in LEAK_OFF_REFERENCE_KINDS:  # a K-K~ edge: Carter leak-off, a Newtonian fluid
        if scene["leak_off"]["coefficient"] <= 0.0 and "permeability" not in scene["leak_off"]:
            raise InputError(f"{where} is a closed form with Carter leak-off: leak_off.coefficient must be > 0 "
                             f"(or the reservoir keys), got {show(scene['leak_off']['coefficient'])}; without "
                             f"leak-off use kind = {kind.removesuffix('-leak-off')!r}")
        if scene["fluid"]["rheology"] == "power-law":
            raise InputError(f"{where}: its regime numbers are a Newtonian fluid's; a power-law fluid "
                             "(fluid.rheology = 'power-law') is compared with kind = 'radial-m', 'radial-k', 'kgd-m' "
                             "or 'kgd-k'")
    elif scene["leak_off"]["coefficient"] != 0.0:
        raise InputError(f"{where} assumes no leak-off: leak_off.coefficient must be 0, got "
                         f"{show(scene['leak_off']['coefficient'])}; with leak-off use kind = "
                         f"{kind.split('-')[0] + '-k-leak-off'!r} (the K-K~ edge) or "
                         f"{kind.split('-')[0] + '-km-leak-off'!r} (viscous)")


# ---------------------------------------------------------------------------------
# Entry point
# ---------------------------------------------------------------------------------

def validate(raw, name=None):
    """Validate a scene given as a dict (e.g. from ``tomllib``); returns its echo.

    The echo has every section and key in a fixed order, defaults filled in, numbers as
    floats, and ``name`` set (``name`` argument, else the scene's own, else "scene").
    Raises InputError on the first problem found.
    """
    if not isinstance(raw, dict):
        raise InputError(f"a scene must be a table of sections, got {show(raw)}")
    for key, value in raw.items():
        if key not in TOP and key not in SECTIONS:
            if isinstance(value, dict) or (isinstance(value, list) and value
                                           and all(isinstance(v, dict) for v in value)):
                close = difflib.get_close_matches(key, list(SECTIONS), n=1, cutoff=0.6)
                hint = f"; did you mean {close[0]!r}?" if close else f"; sections: {', '.join(SECTIONS)}"
                raise InputError(f"unknown section {key!r}{hint}")
            raise _unknown("", key, {**TOP, **SECTIONS})
    scene = {}
    for key, spec in TOP.items():
        if key in raw:
            scene[key] = spec.check(key, raw[key], None)
        elif spec.default is not ABSENT:
            scene[key] = spec.default
    if name is not None:
        scene["name"] = name
    scene.setdefault("name", "scene")
    dim = scene["dimension"]
    if dim == 3 and "height" in raw:
        raise InputError("height is the flow height of a 2D (plane-strain) scene; a 3D scene "
                         "(dimension = 3) takes its heights from the fractures: remove it")
    if dim == 3:
        scene.pop("height")

    for section, (keys, is_array, required) in SECTIONS.items():
        if section not in raw:
            if required and not (section == "material" and "layer" in raw):  # layers give the moduli
                header = f"[[{section}]]" if is_array else f"[{section}]"
                raise InputError(f"the scene needs a {header} section")
            if section in FILLED_WHEN_ABSENT:
                scene[section] = _check_table(section, {}, keys, dim)
            continue
        value = raw[section]
        if is_array:
            tables = _as_tables(section, value)
            if section == "initial_fracture":
                scene[section] = [_check_initial_fracture(f"{section}[{i}]", t, dim) for i, t in enumerate(tables)]
            else:
                scene[section] = [_check_table(f"{section}[{i}]", t, keys, dim) for i, t in enumerate(tables)]
            continue
        if isinstance(value, list):
            raise InputError(f"{section} must be one table [{section}], not an array of tables [[{section}]]")
        if not isinstance(value, dict):
            raise InputError(f"{section} must be a table [{section}], got {show(value)}")
        echo = _check_table(section, value, keys, dim)
        if section == "stress":
            echo = _check_stress(echo, dim)
        elif section == "fluid":
            echo = _check_fluid(echo)
        elif section == "network":
            echo = _check_network(echo, set(value))
        elif section == "proppant":
            _check_proppant(echo)
        elif section == "microseismic":
            from ..microseismic.monitoring import check_section

            echo = check_section(echo)
        scene[section] = echo

    numerics = scene["numerics"]
    if numerics["min_relaxation"] > numerics["relaxation"]:
        raise InputError(f"numerics.min_relaxation must be <= numerics.relaxation = {show(numerics['relaxation'])}, "
                         f"got {show(numerics['min_relaxation'])}")
    if numerics["time_step"] == "auto":  # the bounds of front-following steps (hmatddm.simulation.step_control)
        longest = numerics.get("max_time_step", math.inf)
        if numerics["min_time_step"] > longest:
            raise InputError(f"numerics.min_time_step must be <= numerics.max_time_step = {show(longest)} s, "
                             f"got {show(numerics['min_time_step'])}")
        if not numerics["min_time_step"] <= numerics["first_time_step"] <= longest:
            raise InputError(f"numerics.first_time_step must lie in [numerics.min_time_step, numerics.max_time_step] "
                             f"= [{show(numerics['min_time_step'])}, {show(longest)}] s, "
                             f"got {show(numerics['first_time_step'])}")
    propagation = scene.get("propagation")
    if propagation is not None:
        if "bounds" in propagation and len(propagation["bounds"]) > dim:
            raise InputError(f"propagation.bounds must hold at most {dim} [low, high] pairs (one per axis), "
                             f"got {len(propagation['bounds'])}")
        count = len(scene["initial_fracture"])
        for index in propagation.get("growing_fractures", []):
            if index >= count:
                raise InputError(f"propagation.growing_fractures holds {index}, but the scene has {count} "
                                 f"initial fracture(s), numbered 0 to {count - 1}")
    for i, fracture in enumerate(scene.get("natural_fracture", [])):
        if fracture["p0"] == fracture["p1"]:
            raise InputError(f"natural_fracture[{i}].p0 and natural_fracture[{i}].p1 must differ, "
                             f"got {show(fracture['p0'])}")
    check_clusters_and_well(scene)
    if "layer" in scene:
        _check_layers(scene)
    if "reference" in scene:
        _check_reference(scene)
    if "poroelastic" in scene:
        _check_poroelastic(scene)
    _check_leak_off_reservoir(scene)
    if "monitor" in scene and "layer" in scene:
        _check_monitors_in_rock(scene)
    if has_natural_fractures(scene) and "contact" not in raw["numerics"]:
        # a hydraulic element squeezed between natural fractures can open negatively and stall
        # the Picard iteration with contact = "natural": in a network every element closes
        numerics["contact"] = "all"
    return scene


def _check_proppant(echo):
    """[proppant] (issue 34): the particles and a schedule of stages in increasing time whose
    concentrations lie in [0, packing_limit) (:class:`hmatddm.flow.pump_schedule.PumpSchedule`
    names ``proppant.schedule[k]``)."""
    from ..flow.pump_schedule import PumpSchedule

    PumpSchedule.from_rows(echo["schedule"], echo["packing_limit"])


RESERVOIR_KEYS = ("permeability", "porosity", "reservoir_compressibility", "reservoir_viscosity")


def _check_leak_off_reservoir(scene):
    """[leak_off] takes the coefficient, or the four reservoir keys it comes from (ref.
    Eq. 4.26, :func:`hmatddm.flow.carter_coefficient`), not both."""
    section = scene["leak_off"]
    given = [key for key in RESERVOIR_KEYS if key in section]
    if not given:
        return
    missing = [key for key in RESERVOIR_KEYS if key not in section]
    if missing:
        raise InputError(f"leak_off.{missing[0]} is required with leak_off.{given[0]}: the coefficient from the "
                         f"reservoir (ref. Eq. 4.26) needs {', '.join('leak_off.' + k for k in RESERVOIR_KEYS)}")
    if section["coefficient"] != 0.0:
        raise InputError("leak_off.coefficient must be left out when the reservoir gives it (leak_off."
                         f"{given[0]} ...), got {show(section['coefficient'])}")


def _check_poroelastic(scene):
    """[poroelastic] turns [material]'s drained constants undrained (ref. Eqs 5.19-5.21):
    one uniform rock, so no [[layer]] tables; biot >= porosity is checked here."""
    if "layer" in scene:
        raise InputError("[poroelastic] derives the undrained constants of the uniform [material]; a scene with "
                         "[[layer]] tables cannot take it: remove one of them")
    from ..fracture.poroelastic import UndrainedRock

    poro, rock = scene["poroelastic"], scene["material"]
    UndrainedRock.from_poisson_ratio(rock["shear_modulus"], rock["poisson_ratio"], poro["biot"],
                                     poro["fluid_bulk_modulus"], poro["porosity"])


def _check_monitors_in_rock(scene):
    """A ``[[monitor]]`` above a void top layer's bottom (the free surface) or below a void
    bottom layer's top has no rock to displace (a position on the surface is in the rock)."""
    layers = scene["layer"]
    axis = scene["dimension"] - 1
    for k, monitor in enumerate(scene["monitor"]):
        height = monitor["position"][axis] if len(monitor["position"]) > axis else None
        if height is None:
            continue
        if layers[0]["shear_modulus"] == 0.0 and height > layers[0]["bottom"]:
            raise InputError(f"monitor[{k}].position[{axis}] must be at most {show(layers[0]['bottom'])} (the free "
                             f"surface, layer[0] is void), got {show(height)}")
        if len(layers) > 1 and layers[-1]["shear_modulus"] == 0.0 and height < layers[-2]["bottom"]:
            raise InputError(f"monitor[{k}].position[{axis}] must be at least {show(layers[-2]['bottom'])} (the "
                             f"void bottom layer's top), got {show(height)}")


def _check_layers(scene):
    layers = scene["layer"]
    if scene["dimension"] not in (2, 3):  # 2D: a vertical cross-section, y up; 3D: z up
        raise InputError("[[layer]] tables need dimension = 2 (a vertical cross-section, y up) or 3 (z up)")
    for i, layer in enumerate(layers):
        last = i == len(layers) - 1
        if not last and "bottom" not in layer:
            raise InputError(f"layer[{i}].bottom is required (the height of the interface below it); only the last "
                             "layer extends downwards without one")
        if last and "bottom" in layer:
            raise InputError(f"layer[{i}].bottom must be omitted: the last layer extends downwards to infinity")
        if i > 0 and not last and layer["bottom"] >= layers[i - 1]["bottom"]:
            raise InputError(f"layer[{i}].bottom must be below layer[{i - 1}].bottom = {show(layers[i - 1]['bottom'])} "
                             f"(layers are listed top down), got {show(layer['bottom'])}")
        if layer["shear_modulus"] == 0.0 and 0 < i < len(layers) - 1:
            raise InputError(f"layer[{i}].shear_modulus = 0 (void) is allowed only for the top or bottom layer")
    if "toughness" in [k for layer in layers for k in layer] and "propagation" not in scene:
        raise InputError("layer toughness needs a [propagation] section")
