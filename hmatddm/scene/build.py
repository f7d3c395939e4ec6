"""From a validated scene to the engine's objects: mesh, material, fluid, clusters,
stress, propagation, leak-off, solver settings and the :class:`~hmatddm.Simulation`;
and the closed-form reference values a scene asks for.
"""
import math

import numpy as np

from .. import mesh as meshes
from ..errors import InputError
from ..flow import Cluster, Fluid, LeakOff
from ..material import Elastic
from ..settings import NATURAL_FRACTURE
from .schema import SCHEME_KEYS, far_field_stress, has_natural_fractures, show

_CROSSING_NAMES = {"mohr-coulomb": "mohr-coulomb", "energy-release-rate": "energy", "stress-intensity": "sif"}


def material(scene):
    """The :class:`Elastic` of ``[material]``, or a :class:`LayeredMedium` of the
    ``[[layer]]`` tables (2D, y up; per-layer s_hmin and toughness where given)."""
    if "layer" in scene:
        return layered_medium(scene)
    return Elastic(shear_modulus=scene["material"]["shear_modulus"],
                   poisson_ratio=scene["material"]["poisson_ratio"])


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
    return Fluid(viscosity=scene["fluid"]["viscosity"], compressibility=scene["fluid"]["compressibility"])


def clusters(scene):
    return [Cluster(tuple(c["position"]), rate=c["rate"], wellbore_volume=c["wellbore_volume"])
            for c in scene["cluster"]]


def _fracture_mesh(fracture, fracture_id):
    shape, size = fracture["shape"], fracture["element_size"]
    if shape == "rectangle":
        nx = int(round(fracture["length"] / size))
        ny = int(round(fracture["height"] / size))
        return meshes.rectangle(fracture["center"], fracture["e1"], fracture["e2"], fracture["length"],
                                fracture["height"], nx, ny, fracture_id=fracture_id)
    if shape == "penny":
        return meshes.penny(fracture["center"], fracture["normal"], fracture["radius"], size,
                            fracture_id=fracture_id)
    p0, p1 = np.array(fracture["p0"]), np.array(fracture["p1"])
    n = int(round(np.linalg.norm(p1 - p0) / size))
    return meshes.line(p0, p1, n, fracture_id=fracture_id)


def initial_mesh(scene):
    """The initial fractures as one mesh; fracture ``i`` of the scene has fracture id ``i``."""
    parts = []
    for index, fracture in enumerate(scene["initial_fracture"]):
        try:
            parts.append(_fracture_mesh(fracture, index))
        except InputError as error:
            raise InputError(f"initial_fracture[{index}]: {error}") from None
    mesh = meshes.concatenate(parts)
    _check_overlaps(scene, mesh)
    return mesh


def _check_overlaps(scene, mesh):
    """Two initial fractures must not put collocation points on top of each other."""
    if len(scene["initial_fracture"]) < 2:
        return
    from ..neighbours import pairs_within  # numpy only: refusing a scene does not wait for scipy.spatial

    sources, receivers = pairs_within(mesh.centers, 1e-6 * float(np.max(mesh.radii)))
    if len(sources):
        first, second = int(sources[0]), int(receivers[0])
        a, b = int(mesh.fracture_id[first]), int(mesh.fracture_id[second])
        raise InputError(f"initial_fracture[{a}] and initial_fracture[{b}] overlap: elements {first} and {second} "
                         f"share the centre {show(mesh.centers[first].tolist())}")


def _check_clusters(scene, mesh):
    """Every cluster must lie on an initial fracture (it feeds the nearest element)."""
    for index, cluster in enumerate(scene["cluster"]):
        position = np.asarray(cluster["position"])
        distance = np.linalg.norm(mesh.centers - position, axis=1)
        nearest = int(np.argmin(distance))
        reach = 1.0001 * float(mesh.radii[nearest])
        if distance[nearest] > reach:
            raise InputError(f"cluster[{index}].position = {show(cluster['position'])} m is "
                             f"{distance[nearest]:.6g} m from the nearest initial-fracture element "
                             f"(centre {show(mesh.centers[nearest].tolist())}); a cluster must lie on an "
                             f"initial fracture (within {reach:.6g} m of an element centre)")


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
                       front_tolerance=settings["front_tolerance"])


def leak_off(scene):
    return LeakOff(coefficient=scene["leak_off"]["coefficient"], pore_pressure=scene["leak_off"]["pore_pressure"])


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
    from .preflight import estimate, refuse_too_many_elements

    refuse_too_many_elements(scene, estimate(scene))
    mesh = initial_mesh(scene)
    _check_clusters(scene, mesh)
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
        max_elements=numerics.get("max_elements"))


def natural_network(scene):
    """The scene's natural fractures as an :class:`hmatddm.network.Network` (generated
    when ``network.density`` is given, plus the explicit ``[[natural_fracture]]``), or None."""
    from ..network import Network, NetworkSpec, generate_network

    if not has_natural_fractures(scene):
        return None
    settings = scene.get("network", {})
    height, z_center = settings.get("height", 1.0), settings.get("z_center", 0.0)
    p0 = [np.asarray(f["p0"], float) for f in scene.get("natural_fracture", [])]
    p1 = [np.asarray(f["p1"], float) for f in scene.get("natural_fracture", [])]
    if "density" in settings:
        keys = ("region", "density", "length_exponent", "l_min", "l_max", "mean_azimuths_deg", "kappas",
                "weights", "seed", "boundary")
        spec = NetworkSpec(height=height, z_center=z_center,
                           **{k: (tuple(settings[k]) if isinstance(settings[k], list) else settings[k])
                              for k in keys if k in settings and settings[k] is not None})
        generated = generate_network(spec)
        p0.extend(generated.p0)
        p1.extend(generated.p1)
    return Network.from_segments(np.array(p0), np.array(p1), height=height, z_center=z_center)


def natural_mesh(scene):
    """Elements of the natural fractures (2D segments or 3D vertical rectangles), or None."""
    network = natural_network(scene)
    if network is None:
        return None
    size = scene.get("network", {}).get("element_size", 1.0)
    if scene["dimension"] == 2:
        return network.to_mesh2d(size)
    return network.to_mesh3d(size, max(1, int(round(network.height / size))))


def natural_properties(scene):
    """:class:`hmatddm.NaturalFractureProperties` of the scene, or None."""
    from ..fracture import NaturalFractureProperties

    if not has_natural_fractures(scene):
        return None
    settings = scene.get("network", {})
    value = {key: settings.get(key, setting.default) for key, setting in NATURAL_FRACTURE.items()}
    return NaturalFractureProperties(
        friction=value["friction_coefficient"], cohesion=value["cohesion"],
        tensile_strength=value["tensile_strength"], toughness=value["toughness"],
        critical_radius=value["critical_radius"],
        crossing=_CROSSING_NAMES[settings.get("crossing", "mohr-coulomb")],
        pore_pressure=scene["leak_off"]["pore_pressure"])


def confining_stress(scene, normal=None):
    """Compressive normal stress on the first initial fracture (Pa, positive), the
    ``S_hmin`` that the net pressure of the closed forms is measured from."""
    if normal is None:
        mesh = _fracture_mesh(scene["initial_fracture"][0], 0)
        normal = mesh.normals[0]
    normal = np.asarray(normal, dtype=float)
    return float(-normal @ far_field_stress(scene) @ normal)


# ---------------------------------------------------------------------------------
# Closed-form reference (ref. Sec. 4.5)
# ---------------------------------------------------------------------------------

def _closed_form(scene, times):
    """Closed-form curves at ``times`` (> 0): dict of arrays with ``time``, ``radius`` or
    ``half_length``, ``max_opening``, optionally ``net_pressure``, and
    ``dimensionless_toughness``."""
    from .. import analytical  # scipy.special: loaded only for a [reference]

    kind = scene["reference"]["kind"]
    mat = material(scene)
    rate = scene["cluster"][0]["rate"]
    viscosity = scene["fluid"]["viscosity"]
    toughness = scene["propagation"]["toughness"]
    times = np.asarray(times, dtype=float)
    curves = {"time": times}
    if kind.startswith("radial"):
        if kind == "radial-k":
            curves["radius"], curves["max_opening"], curves["net_pressure"] = analytical.radial_k_vertex(
                times, rate, toughness, mat)
        elif kind == "radial-km":  # Dontsov (2016) between the vertices: no net pressure
            curves["radius"], curves["max_opening"] = analytical.radial_transition(times, rate, viscosity,
                                                                                   toughness, mat)
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


def reference_curves(scene, end_time=None, samples=200):
    """Closed-form curves for a history plot (``time`` from a small fraction of the
    first step to ``end_time``), in the format of :func:`hmatddm.render.plot_history`;
    None when the scene has no ``[reference]``."""
    if "reference" not in scene:
        return None
    end_time = scene["numerics"]["end_time"] if end_time is None else end_time
    start = min(0.25 * scene["numerics"]["time_step"], 0.5 * end_time)
    curves = _closed_form(scene, np.linspace(start, end_time, samples))
    curves.pop("dimensionless_toughness")
    return curves


def reference_values(scene, records):
    """One dict per record with the closed-form values at its time and the relative
    differences of the simulation (``relative_error``: simulation / closed form - 1);
    None when the scene has no ``[reference]``."""
    if "reference" not in scene:
        return None
    if not records:
        return []
    curves = _closed_form(scene, [record["time"] for record in records])
    confining = confining_stress(scene)
    size_key = "radius" if "radius" in curves else "half_length"
    rows = []
    for index, record in enumerate(records):
        row = {key: float(values[index]) for key, values in curves.items()}
        simulated = {size_key: record.get(size_key), "max_opening": record.get("max_opening")}
        if "net_pressure" in curves:
            simulated["net_pressure"] = record["wellbore_pressure"][0] - confining
        row["relative_error"] = {key: (None if value is None or row[key] == 0.0 else float(value / row[key] - 1.0))
                                 for key, value in simulated.items()}
        rows.append(row)
    return rows
