"""The meshes of a validated scene: its initial fractures and its natural-fracture network
(numpy and scipy.spatial, no engine), shared by the preflight checks
(:mod:`hmatddm.scene.preflight`) and the builder of a run (:mod:`hmatddm.scene.build`).
"""
import numpy as np

from .. import mesh as meshes
from ..errors import InputError
from .schema import has_natural_fractures, show


def fracture_mesh(fracture, fracture_id):
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
            parts.append(fracture_mesh(fracture, index))
        except InputError as error:
            raise InputError(f"initial_fracture[{index}]: {error}") from None
    mesh = meshes.concatenate(parts)
    _check_overlaps(scene, mesh)
    return mesh


def _check_overlaps(scene, mesh):
    """Two initial fractures must not put collocation points on top of each other."""
    if len(scene["initial_fracture"]) < 2:
        return
    from ..mesh.neighbours import pairs_within  # numpy only: refusing a scene does not wait for scipy.spatial

    sources, receivers = pairs_within(mesh.centers, 1e-6 * float(np.max(mesh.radii)))
    if len(sources):
        first, second = int(sources[0]), int(receivers[0])
        a, b = int(mesh.fracture_id[first]), int(mesh.fracture_id[second])
        raise InputError(f"initial_fracture[{a}] and initial_fracture[{b}] overlap: elements {first} and {second} "
                         f"share the centre {show(mesh.centers[first].tolist())}")


def check_clusters(scene, mesh):
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


__all__ = ["fracture_mesh", "initial_mesh", "check_clusters", "natural_network", "natural_mesh"]
