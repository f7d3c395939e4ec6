"""From a validated scene to the engine's objects: mesh, material, fluid, clusters,
stress, propagation, leak-off, solver settings and the :class:`~hmatddm.Simulation`;
and the closed-form reference values a scene asks for.
"""
import math

import numpy as np

from ..flow import Cluster, Fluid, LeakOff
from ..material import Elastic
from ..settings import NATURAL_FRACTURE
from .meshes import check_clusters, fracture_mesh, initial_mesh, natural_mesh
from .preflight import estimate, refuse_too_many_elements
from .schema import SCHEME_KEYS, far_field_stress, has_natural_fractures
from .sections import LEAK_OFF_REFERENCE_KINDS

_CROSSING_NAMES = {"mohr-coulomb": "mohr-coulomb", "energy-release-rate": "energy", "stress-intensity": "sif"}


def material(scene):
    """The :class:`Elastic` of ``[material]``, or a :class:`LayeredMedium` of the
    ``[[layer]]`` tables (2D, y up; per-layer s_hmin and toughness where given)."""
    if "layer" in scene:
        return layered_medium(scene)
    rock = undrained_rock(scene)
    return Elastic(shear_modulus=scene["material"]["shear_modulus"],
                   poisson_ratio=scene["material"]["poisson_ratio"] if rock is None else rock.undrained_poisson_ratio)


def undrained_rock(scene):
    """The :class:`hmatddm.fracture.poroelastic.UndrainedRock` of ``[poroelastic]`` (the
    drained constants of ``[material]``), or None: with it the DDM runs with the undrained
    Poisson's ratio and the remote-failure check with its Skempton B (ref. Sec. 5.3.1)."""
    if "poroelastic" not in scene:
        return None
    from ..fracture.poroelastic import UndrainedRock

    poro, rock = scene["poroelastic"], scene["material"]
    return UndrainedRock.from_poisson_ratio(rock["shear_modulus"], rock["poisson_ratio"], poro["biot"],
                                            poro["fluid_bulk_modulus"], poro["porosity"])


def layered_medium(scene):
    from ..layered import LayeredMedium

    layers = scene["layer"]
    stress = None
    if any("s_hmin" in layer for layer in layers):
        base = far_field_stress(scene)
        stress = np.repeat(base[None], len(layers), axis=0)
        for k, layer in enumerate(layers):
            if "s_hmin" in layer:
                stress[k, 0, 0] = -layer["s_hmin"]
    toughness = None
    if any("toughness" in layer for layer in layers):
        toughness = [layer.get("toughness", scene["propagation"]["toughness"]) for layer in layers]
    return LayeredMedium([layer["bottom"] for layer in layers[:-1]], [layer["shear_modulus"] for layer in layers],
                         [layer["poisson_ratio"] for layer in layers], in_situ_stress=stress, toughness=toughness)


def fluid(scene):
    return Fluid(**scene["fluid"])  # the echo's keys are the fields (hmatddm.settings.FLUID)


def clusters(scene):
    """The :class:`Cluster` of each ``[[cluster]]`` (with a [well], its perforations or the well's)."""
    from .well_section import perforations

    return [Cluster(tuple(c["position"]), rate=c.get("rate"), wellbore_volume=c["wellbore_volume"],
                    **perforations(scene, i)) for i, c in enumerate(scene["cluster"])]


def well(scene):
    """The :class:`hmatddm.flow.Well` of ``[well]`` (issue 35), or None."""
    section = scene.get("well")
    if section is None:
        return None
    from ..flow.well import PumpRate, Well

    return Well(PumpRate.from_rows(section["schedule"], section["interpolation"]), tuple(section["heel"]),
                tuple(section["direction"]), volume=section["volume"], diameter=section.get("diameter"),
                friction_factor=section["friction_factor"])


def propagation(scene):
    settings = scene.get("propagation")
    if settings is None:
        return None
    bounds = settings.get("bounds")
    from ..fracture import Propagation  # scipy.spatial: loaded when a run is built

    return Propagation(toughness=settings["toughness"], criterion=settings["criterion"],
                       critical_energy_release_rate=settings.get("critical_energy_release_rate"),
                       correction=settings["correction"], turning=settings["turning"],
                       min_turn_angle=math.radians(settings["min_turn_angle_deg"]),
                       max_growth_passes=settings["max_growth_passes"],
                       bounds=None if bounds is None else tuple(tuple(pair) for pair in bounds),
                       front=settings["front"], front_iterations=settings["front_iterations"],
                       front_tolerance=settings.get("front_tolerance"))


def leak_off(scene):
    """The :class:`LeakOff` of ``[leak_off]``: its coefficient, or the one the reservoir keys
    give (ref. Eq. 4.26, both faces, :func:`hmatddm.flow.carter_coefficient`)."""
    section = scene["leak_off"]
    coefficient = section["coefficient"]
    if "permeability" in section:
        from ..flow import carter_coefficient

        coefficient = carter_coefficient(section["permeability"], section["porosity"],
                                         section["reservoir_compressibility"], section["reservoir_viscosity"])
    return LeakOff(coefficient=coefficient, pore_pressure=section["pore_pressure"])


def scheme_settings(scene):
    from ..coupled import SchemeSettings  # scipy.sparse.linalg: loaded when a run is built

    numerics = scene["numerics"]
    return SchemeSettings(**{key: numerics[key] for key in SCHEME_KEYS if numerics.get(key) is not None})


def build_simulation(scene, checkpoint_dir=None):
    """A :class:`~hmatddm.Simulation` of a validated scene (nothing is solved yet).

    Raises InputError for more elements than ``numerics.max_elements`` (counted before
    any mesh is allocated), a cluster off the initial fractures or overlapping initial
    fractures.
    """
    from ..simulation import Simulation  # the engine loads here, not when a scene is validated

    refuse_too_many_elements(scene, estimate(scene))
    mesh = initial_mesh(scene)
    check_clusters(scene, mesh)
    rock = material(scene)
    if "layer" in scene:  # initial elements end on the interfaces
        from ..layered import split_at_interfaces

        mesh = split_at_interfaces(mesh, rock)[0]
    numerics = scene["numerics"]
    growing = scene.get("propagation", {}).get("growing_fractures")
    return Simulation(
        mesh, rock, fluid(scene), clusters(scene), far_field_stress(scene), numerics["time_step"],
        propagation=propagation(scene), leak_off=leak_off(scene), initial_pressure=numerics["initial_pressure"],
        initial_opening=numerics["initial_opening"], minimum_width=numerics.get("minimum_width"),
        height=scene.get("height", 1.0), backend=numerics["backend"], eps=numerics["eps"], eta=numerics["eta"],
        leaf_size=numerics["leaf_size"], singular_correction=numerics["singular_correction"],
        alpha=numerics.get("alpha"), scheme=scheme_settings(scene), growing_fractures=growing,
        checkpoint_dir=checkpoint_dir, keep_checkpoints=numerics["keep_checkpoints"],
        natural_fractures=natural_mesh(scene), natural=natural_properties(scene),
        remote_failure=scene.get("network", {}).get("remote_failure", True), contact=numerics["contact"],
        max_elements=numerics.get("max_elements"), step_control=step_control(numerics), well=well(scene),
        **proppant(scene))


def proppant(scene):
    """``{proppant, pump_schedule}`` of ``[proppant]`` (:class:`hmatddm.flow.Proppant`,
    :class:`hmatddm.flow.PumpSchedule`), or {} without the section."""
    section = scene.get("proppant")
    if section is None:
        return {}
    from ..flow import Proppant, PumpSchedule

    particles = Proppant(**{key: value for key, value in section.items() if key != "schedule"})
    return {"proppant": particles,
            "pump_schedule": PumpSchedule.from_rows(section["schedule"], particles.packing_limit)}


def step_control(numerics):
    """The :class:`~hmatddm.simulation.step_control.StepControl` of ``[numerics]`` with
    ``time_step = "auto"``, else None."""
    if numerics["time_step"] != "auto":
        return None
    from ..simulation.step_control import StepControl

    return StepControl(advance=numerics["step_advance"], first=numerics["first_time_step"],
                       minimum=numerics["min_time_step"], maximum=numerics.get("max_time_step"))


def first_time_step(numerics):
    """The first step of ``[numerics]`` (s): ``time_step``, or ``first_time_step`` with "auto"."""
    return numerics["first_time_step"] if numerics["time_step"] == "auto" else numerics["time_step"]


def natural_properties(scene):
    """:class:`hmatddm.NaturalFractureProperties` of the scene, or None."""
    from ..fracture import NaturalFractureProperties

    if not has_natural_fractures(scene):
        return None
    settings = scene.get("network", {})
    value = {key: settings.get(key, setting.default) for key, setting in NATURAL_FRACTURE.items()}
    rock = undrained_rock(scene)
    return NaturalFractureProperties(
        friction=value["friction_coefficient"], cohesion=value["cohesion"],
        tensile_strength=value["tensile_strength"], toughness=value["toughness"],
        critical_radius=value["critical_radius"], shear_toughness=value["shear_toughness"],
        rock_shear_toughness=value["rock_shear_toughness"],
        crossing=_CROSSING_NAMES[settings.get("crossing", "mohr-coulomb")],
        pore_pressure=scene["leak_off"]["pore_pressure"], skempton=0.0 if rock is None else rock.skempton)


def confining_stress(scene, normal=None):
    """Compressive normal stress on the first initial fracture (Pa, positive), the
    ``S_hmin`` that the net pressure of the closed forms is measured from."""
    if normal is None:
        mesh = fracture_mesh(scene["initial_fracture"][0], 0)
        normal = mesh.normals[0]
    normal = np.asarray(normal, dtype=float)
    return float(-normal @ far_field_stress(scene) @ normal)


# ---------------------------------------------------------------------------------
# Closed-form reference (ref. Sec. 4.5)
# ---------------------------------------------------------------------------------

def _closed_form(scene, times, kind=None):
    """Closed-form curves at ``times`` (> 0): dict of arrays with ``time``, ``radius`` or
    ``half_length``, ``max_opening``, optionally ``net_pressure``, and
    ``dimensionless_toughness``; of the scene's ``[reference] kind`` or of ``kind``."""
    from .. import analytical  # scipy.special: loaded only for a [reference]

    kind = scene["reference"]["kind"] if kind is None else kind
    mat = material(scene)
    rate = scene["cluster"][0]["rate"]
    toughness = scene["propagation"]["toughness"]
    times = np.asarray(times, dtype=float)
    curves = {"time": times}
    if kind in LEAK_OFF_REFERENCE_KINDS:
        return _leak_off_closed_form(scene, times, kind, curves)
    if scene["fluid"]["rheology"] == "power-law":  # the power-law vertices (hmatddm.analytical.power_law)
        from ..analytical import power_law

        args = (scene["fluid"]["consistency"], scene["fluid"]["flow_index"])
        if kind.startswith("radial"):  # radial-m or radial-k (radial-km is refused by the schema)
            if kind == "radial-k":
                curves["radius"], curves["max_opening"], curves["net_pressure"] = analytical.radial_k_vertex(
                    times, rate, toughness, mat)
            else:
                curves["radius"], curves["max_opening"] = power_law.radial_power_law_vertex(times, rate, *args, mat)
            curves["dimensionless_toughness"] = power_law.radial_power_law_regime(times, rate, *args, toughness, mat)
            return curves
        rate = rate / scene["height"]
        if kind == "kgd-k":
            values = analytical.kgd_k_vertex(times, rate, toughness, mat)
        else:
            values = power_law.kgd_power_law_vertex(times, rate, *args, mat)
        curves["half_length"], curves["max_opening"], curves["net_pressure"] = values
        curves["dimensionless_toughness"] = power_law.kgd_power_law_regime(times, rate, *args, toughness, mat)
        return curves
    viscosity = scene["fluid"]["viscosity"]
    if kind.startswith("radial"):
        if kind == "radial-k":
            curves["radius"], curves["max_opening"], curves["net_pressure"] = analytical.radial_k_vertex(
                times, rate, toughness, mat)
        elif kind == "radial-km":  # Dontsov (2016) between the vertices: no net pressure; tabulated in
            from ..analytical.transition_table import radial_transition_table  # time (one solve a decade)

            table = radial_transition_table(rate, viscosity, toughness, mat)
            curves["radius"], curves["max_opening"] = table.radius_and_width(times)
        else:
            curves["radius"], curves["max_opening"] = analytical.radial_m_vertex(times, rate, viscosity, mat)
        curves["dimensionless_toughness"] = analytical.radial_regime(times, rate, viscosity, toughness, mat)
    else:
        rate = rate / scene["height"]  # per unit height
        if kind == "kgd-k":
            values = analytical.kgd_k_vertex(times, rate, toughness, mat)
        else:
            values = analytical.kgd_m_vertex(times, rate, viscosity, mat)
        curves["half_length"], curves["max_opening"], curves["net_pressure"] = values
        curves["dimensionless_toughness"] = np.full(times.shape, analytical.kgd_regime(rate, viscosity,
                                                                                         toughness, mat))
    return curves


def _leak_off_closed_form(scene, times, kind, curves):
    """The K-K~ edge of a scene with Carter leak-off (``kind`` in
    :data:`~hmatddm.scene.sections.LEAK_OFF_REFERENCE_KINDS`; zero viscosity, the leak-off
    ``c_l (sigma_0 + p_net - p_r) / (t - t_0)^(1/2)`` with ``sigma_0`` the confining stress):
    size and net pressure from :mod:`hmatddm.analytical.leak_off`, the opening at the well
    Griffith's ``4 p l / E'`` or Sneddon's ``8 p R / (pi E')``; ``dimensionless_toughness`` as
    for the K vertex, and ``leak_off_number`` ``C_m`` with ``C' = c_l (sigma_0 - p_r)``
    (:func:`hmatddm.analytical.regimes.carter_prime`)."""
    from .. import analytical
    from ..analytical import regimes

    mat = material(scene)
    e_prime = mat.plane_strain_modulus
    rate = scene["cluster"][0]["rate"]
    toughness = scene["propagation"]["toughness"]
    viscosity = scene["fluid"]["viscosity"]
    c_l = leak_off(scene).coefficient
    excess = confining_stress(scene) - scene["leak_off"]["pore_pressure"]
    c_prime = regimes.carter_prime(c_l, excess)
    if kind in ("kgd-m-leak-off", "kgd-km-leak-off", "radial-km-leak-off", "radial-m-leak-off"):  # viscous:
        from ..analytical import viscous_leak_off  # Dontsov's solutions have no net pressure

        if kind.startswith("radial"):
            if kind == "radial-m-leak-off":
                curves["radius"], curves["max_opening"] = viscous_leak_off.radial_m_leak_off_vertex(
                    times, rate, viscosity, c_prime, mat)
            else:
                curves["radius"], curves["max_opening"], _ = viscous_leak_off.radial_leak_off_transition(
                    times, rate, viscosity, toughness, c_prime, mat)
            curves["dimensionless_toughness"] = analytical.radial_regime(times, rate, viscosity, toughness, mat)
            curves["leak_off_number"] = regimes.radial_leak_off_number(times, rate, viscosity, c_prime, mat)
        else:
            rate = rate / scene["height"]
            if kind == "kgd-m-leak-off":  # with the inlet net pressure of the similarity solution
                curves["half_length"], curves["max_opening"], curves["net_pressure"] = \
                    viscous_leak_off.kgd_m_leak_off_vertex(times, rate, viscosity, c_prime, mat, pressure=True)
            else:
                curves["half_length"], curves["max_opening"], _ = viscous_leak_off.kgd_leak_off_transition(
                    times, rate, viscosity, toughness, c_prime, mat)
            curves["dimensionless_toughness"] = np.full(times.shape, analytical.kgd_regime(rate, viscosity,
                                                                                            toughness, mat))
            curves["leak_off_number"] = regimes.kgd_leak_off_number(times, rate, viscosity, c_prime, mat)
        return curves
    if kind == "radial-k-leak-off":
        radius, net = analytical.radial_toughness_leak_off_edge(times, rate, c_l, excess, toughness, e_prime)
        curves.update(radius=radius, max_opening=8.0 * net * radius / (np.pi * e_prime), net_pressure=net)
        curves["dimensionless_toughness"] = analytical.radial_regime(times, rate, viscosity, toughness, mat)
        curves["leak_off_number"] = regimes.radial_leak_off_number(times, rate, viscosity, c_prime, mat)
    else:
        rate = rate / scene["height"]  # per unit height
        half_length, net = analytical.kgd_toughness_leak_off_edge(times, rate, c_l, excess, toughness, e_prime)
        curves.update(half_length=half_length, max_opening=4.0 * net * half_length / e_prime, net_pressure=net)
        curves["dimensionless_toughness"] = np.full(times.shape, analytical.kgd_regime(rate, viscosity, toughness,
                                                                                        mat))
        curves["leak_off_number"] = regimes.kgd_leak_off_number(times, rate, viscosity, c_prime, mat)
    return curves


def reference_regime(scene, times):
    """The regime of a scene with a ``[reference]`` at ``times`` (s, > 0): a dict with
    ``number`` (``"K_m"``), ``values`` (array like ``times``), ``vertex`` (``"M"``, ``"K"``
    or ``"transition"`` at each time, :func:`hmatddm.analytical.regimes.vertex`), ``applies``
    (whether the reference's closed form applies at every time) and ``instead`` (the
    solution that applies where it does not, else None)."""
    from ..analytical import regimes

    kind = scene["reference"]["kind"]
    curves = _closed_form(scene, times)
    values, leak_off_numbers = curves["dimensionless_toughness"], curves.get("leak_off_number")
    geometry = "radial" if kind.startswith("radial") else "kgd"
    applies, instead = regimes.applicable_solution(kind, values, leak_off_numbers)
    return {"number": "K_m", "values": values, "vertex": [regimes.vertex(float(k), geometry) for k in values],
            "applies": applies, "instead": instead, "leak_off_numbers": leak_off_numbers}


def run_times(scene):
    """First and last time of a run of ``scene`` (s): the first step and ``numerics.end_time``."""
    numerics = scene["numerics"]
    return np.array([min(first_time_step(numerics), numerics["end_time"]), numerics["end_time"]])


def reference_warning(scene):
    """One line when the scene's ``[reference]`` closed form does not apply over the run
    (its dimensionless toughness at the first step and at the end, :func:`reference_regime`),
    naming the solution that does; None when it applies, there is no ``[reference]`` or its
    closed form has no regime (``three-layer-height``)."""
    if "reference" not in scene or scene["reference"]["kind"] == "three-layer-height":
        return None
    times = run_times(scene)
    regime = reference_regime(scene, times)
    if regime["applies"]:
        return None
    from ..analytical.regimes import KGD_LIMITS, M_LEAK_OFF_LIMITS, M_LEAK_OFF_TOUGHNESS, RADIAL_LIMITS, SOLUTIONS

    kind = scene["reference"]["kind"]
    geometry = "radial" if kind.startswith("radial") else "kgd"
    low, high = RADIAL_LIMITS if geometry == "radial" else KGD_LIMITS

    def over(name, first, last):
        return f"{name} = {first:.2f}" if abs(last - first) < 5e-3 else f"{name} = {first:.2f} to {last:.2f}"

    numbers = over("K_m", *regime["values"])
    limits = f"M-vertex at K_m <= {low:g}, K-vertex at K_m >= {high:g}"
    if kind.endswith("-m-leak-off"):  # an M~ vertex: the leak-off number and the M~ toughness number
        numbers += ", " + over("C_m", *regime["leak_off_numbers"])
        limits = (f"the M~ vertex at C_m >= {M_LEAK_OFF_LIMITS[geometry]:g} and "
                  f"{'K_m' if geometry == 'kgd' else 'K_m C_m^(-1/8)'} <= {M_LEAK_OFF_TOUGHNESS:g}")
    return (f"reference.kind = {kind!r} ({SOLUTIONS[kind].name}) does not apply over this run: {numbers} between "
            f"t = {times[0]:g} and {times[1]:g} s ({limits}); the solution that applies is {regime['instead']}")


def reference_curves(scene, end_time=None, samples=200):
    """Closed-form curves for a history plot (``time`` from a small fraction of the
    first step to ``end_time``), in the format of :func:`hmatddm.render.plot_history`;
    None when the scene has no ``[reference]``. ``three-layer-height``: its equilibrium
    tips need the run's net pressures, :func:`hmatddm.scene.height_reference.equilibrium_tips`
    (None here)."""
    if "reference" not in scene or scene["reference"]["kind"] == "three-layer-height":
        return None
    end_time = scene["numerics"]["end_time"] if end_time is None else end_time
    start = min(0.25 * first_time_step(scene["numerics"]), 0.5 * end_time)
    curves = _closed_form(scene, np.linspace(start, end_time, samples))
    curves.pop("dimensionless_toughness")
    return curves


def reference_values(scene, records):
    """One dict per record with the closed-form values at its time, the relative
    differences of the simulation (``relative_error``: simulation / closed form - 1),
    the regime there (``dimensionless_toughness``; ``regime``: its number, value, the
    vertex it is at, whether the closed form applies from the first step to the last
    record) and the ``solution`` compared with (kind, name, formula, source,
    :data:`hmatddm.analytical.regimes.SOLUTIONS`); with ``reference.kind = "radial-km"``
    also the K-vertex beside it (``k_vertex``: its values and the simulation's relative
    differences, net pressure included). None when the scene has no ``[reference]``.

    The net pressure is compared where the closed form defines it (:func:`_simulated`): a
    K-vertex's is uniform, compared with the fracture's opening-weighted mean pressure minus
    the confining stress (``net_pressure``) and with the injection element's
    (``injection_net_pressure``, which adds the viscous drop near the well); the KGD
    M-vertex's ``p(0)`` with the injection element's. The radial M-vertex and the transition
    solution give none (log-singular at the well, resp. not approximated).

    ``three-layer-height``: the equilibrium height at each record's net pressure
    (:func:`hmatddm.scene.height_reference.height_reference`)."""
    if "reference" not in scene:
        return None
    if not records:
        return []
    if scene["reference"]["kind"] == "three-layer-height":
        from .height_reference import height_reference

        return height_reference(scene, records)
    from ..analytical.regimes import SOLUTIONS

    times = [record["time"] for record in records]
    kind = scene["reference"]["kind"]
    curves = _closed_form(scene, times)
    beside = _closed_form(scene, times, kind="radial-k") if kind == "radial-km" else None
    regime = reference_regime(scene, np.concatenate([run_times(scene)[:1], times]))
    solution = SOLUTIONS[kind].as_dict()
    confining = confining_stress(scene)
    size_key = "radius" if "radius" in curves else "half_length"
    rows = []
    for index, record in enumerate(records):
        row = {key: float(values[index]) for key, values in curves.items()}
        uniform = kind.endswith("-k") or kind.endswith("-k-leak-off")  # a K vertex or a K-K~ edge
        simulated = _simulated(record, size_key, confining, uniform_pressure=uniform)
        row["relative_error"] = _relative(simulated, row)
        row["regime"] = {"number": regime["number"], "value": row["dimensionless_toughness"],
                         "vertex": regime["vertex"][index + 1], "applies_over_run": regime["applies"],
                         "solution_that_applies": regime["instead"]}
        if "leak_off_number" in row:  # a closed form with leak-off: its number C_m beside K_m
            row["regime"]["leak_off"] = {"number": "C_m", "value": row.pop("leak_off_number"),
                                         "carter_prime": "C' = c_l (sigma_0 - p_r)"}
        row["solution"] = solution
        if beside is not None:
            vertex = {key: float(beside[key][index]) for key in (size_key, "max_opening", "net_pressure")}
            vertex["relative_error"] = _relative(_simulated(record, size_key, confining, uniform_pressure=True),
                                                 vertex)
            vertex["solution"] = SOLUTIONS["radial-k"].as_dict()
            row["k_vertex"] = vertex
        rows.append(row)
    return rows


def _simulated(record, size_key, confining, uniform_pressure):
    """The simulated values a closed form is compared with. ``net_pressure``: where the closed
    form's net pressure is uniform (K-vertex), the opening-weighted mean pressure of the
    fracture (``mean_pressure`` of the record, :func:`hmatddm.simulation.records.step_record`)
    minus the confining stress, and the injection element's beside it
    (``injection_net_pressure``); otherwise (the KGD M-vertex's ``p(0)``) the injection
    element's."""
    injection = record["wellbore_pressure"][0] - confining
    simulated = {size_key: record.get(size_key), "max_opening": record.get("max_opening"), "net_pressure": injection}
    if uniform_pressure and record.get("mean_pressure") is not None:
        simulated["net_pressure"] = record["mean_pressure"] - confining
        simulated["injection_net_pressure"] = injection
    return simulated


def _relative(simulated, closed_form):
    """``simulated / closed form - 1`` for the keys the closed form has (None where the
    simulation has no value or the closed form is 0); ``injection_net_pressure`` against the
    closed form's (uniform) ``net_pressure``."""
    closed_form = dict(closed_form)
    if "net_pressure" in closed_form:
        closed_form.setdefault("injection_net_pressure", closed_form["net_pressure"])
    return {key: (None if value is None or closed_form[key] == 0.0 else float(value / closed_form[key] - 1.0))
            for key, value in simulated.items() if key in closed_form}
