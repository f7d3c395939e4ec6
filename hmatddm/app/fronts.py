"""The fronts drawn over a plan snapshot (:class:`hmatddm.render.Curve`): the front the solver
tracks and the closed form's.

* The tracked front: with ``propagation.front = "asymptotic"``, the zero level of the
  signed distance ``phi`` that the ribbon elements' front distances define
  (:class:`hmatddm.fracture.front.FrontField` of the solver's order, drawn through its cell
  centres; Peirce and Detournay 2008), as a curve in the fracture's plane; with the element front (the
  reference's switch, ref. Sec. 4.2.2), the outer edges of the hydraulic elements.
* The closed form's front (the scene's ``[reference]``): the circle of radius ``R(t)``
  round the injection point (radial solutions) or the tips ``+-l(t)`` of a plane-strain
  fracture, dashed.
"""
import numpy as np

from ..mesh import Mesh3D

FRONT_COLOUR = "red"
REFERENCE_COLOUR = "black"


def _contour(phi, low, h):
    """The zero level of ``phi`` on the cell grid with corner cell ``low`` and spacing ``h``:
    a list of (n, 2) polylines in the plane's coordinates (m)."""
    import contourpy  # a dependency of matplotlib

    bound = 4.0 * h
    values = np.clip(np.where(np.isfinite(phi), phi, np.sign(phi) * bound), -bound, bound)
    x = (low[0] + np.arange(phi.shape[0])) * h
    y = (low[1] + np.arange(phi.shape[1])) * h
    generator = contourpy.contour_generator(x, y, values.T, line_type="Separate")
    return [np.asarray(line) for line in generator.lines(0.0)]


def asymptotic_front(mesh, front_distance, front_velocity, front_class):
    """The front of a state with the asymptotic front's arrays: a list of (n, 3) polylines
    (3D; [] for a 2D mesh, whose front is two points)."""
    from ..fracture.front import CHANNEL, FrontField, PlanarGrid
    from ..simulation.asymptotic import AsymptoticFront

    if not isinstance(mesh, Mesh3D):
        return []
    grid = PlanarGrid(mesh)
    ribbon = np.isfinite(front_distance)
    if not np.any(ribbon):
        return []
    cells = grid.cells(mesh.centers)
    distance = np.asarray(front_distance, float)[ribbon]
    margin = int(np.ceil(np.max(distance) / grid.h)) + 3  # as AsymptoticFront.field
    field = FrontField(cells[ribbon], distance, np.asarray(front_velocity, float)[ribbon],
                       cells[np.asarray(front_class) == CHANNEL], grid.h, margin,
                       order=AsymptoticFront.level_set_order)  # the solver's level set
    return [grid.origin + line @ grid.axes for line in _contour(field.phi, field.low, grid.h) if len(line) >= 2]


def element_front(mesh, state=None):
    """The outer edges of the hydraulic elements of a Mesh3D as (2m, 3) points, one pair per
    edge (the edges that belong to one hydraulic element only); None for a Mesh2D."""
    if not isinstance(mesh, Mesh3D):
        return None
    kept = np.ones(mesh.n_elements, bool) if state is None else np.asarray(state) == 0
    corners = mesh.corners()[kept]                                   # (n, 4, 3)
    starts = corners.reshape(-1, 3)
    ends = np.roll(corners, -1, axis=1).reshape(-1, 3)
    scale = 1e-6 * float(np.max(mesh.radii))
    key = np.round(0.5 * (starts + ends) / scale).astype(np.int64)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    outer = counts[inverse.reshape(-1)] == 1
    return np.stack([starts[outer], ends[outer]], axis=1).reshape(-1, 3)


def reference_front(scene, time_value, mesh):
    """The closed form's front at ``time_value`` (s): a list of (n, d) polylines, or [] when
    the scene has no [reference] (or at t = 0) or one without a front of its own in time
    (``three-layer-height``: its tips follow the run's pressure, drawn in the history plot)."""
    from ..scene import reference_curves

    if scene is None or "reference" not in scene or not time_value > 0.0:
        return []
    curves = reference_curves(scene, end_time=float(time_value), samples=2)
    if curves is None:
        return []
    well = np.asarray(scene["cluster"][0]["position"], dtype=float)
    home = int(np.argmin(np.sum((mesh.centers - well) ** 2, axis=1)))
    if "radius" in curves:
        radius = float(curves["radius"][-1])
        e1, e2 = mesh.frames[home][0], mesh.frames[home][1]
        angle = np.linspace(0.0, 2.0 * np.pi, 181)
        return [well + radius * (np.cos(angle)[:, None] * e1 + np.sin(angle)[:, None] * e2)]
    half_length = float(curves["half_length"][-1])
    along, across = mesh.frames[home][0], mesh.frames[home][1]
    bar = 0.15 * half_length
    return [np.array([well + side * half_length * along - bar * across, well + side * half_length * along
                      + bar * across]) for side in (-1.0, 1.0)]


def front_curves(mesh, state, scene, time_value, front_arrays=None):
    """The :class:`hmatddm.render.Curve` s of a plan snapshot: the tracked front (asymptotic,
    from ``front_arrays`` = (front_distance, front_velocity, front_class), else the element
    front in 3D) and the closed form's front, dashed."""
    from ..render.layout import Curve

    curves = []
    if front_arrays is not None and front_arrays[0] is not None:
        lines = asymptotic_front(mesh, *front_arrays)
        for index, line in enumerate(lines):
            curves.append(Curve(line, FRONT_COLOUR, False, "tracked front (asymptote)" if index == 0 else ""))
    else:
        pairs = element_front(mesh, state)
        if pairs is not None and len(pairs):
            curves.append(Curve(pairs, FRONT_COLOUR, False, "front (element edges)", width=2.0, pairs=True))
    kind = (scene or {}).get("reference", {}).get("kind", "")
    for index, line in enumerate(reference_front(scene, time_value, mesh)):
        curves.append(Curve(line, REFERENCE_COLOUR, True, f"closed-form front ({kind})" if index == 0 else ""))
    return curves


def tip_regime(mesh, opening, front_distance, well, toughness, plane_strain_modulus):
    """The regime of the universal tip asymptote at each ribbon element of an asymptotic front
    (Dontsov and Peirce 2015; no leak-off, as the asymptotic front has none): ``K^ = K'
    s^(1/2) / (E' w)`` with ``s`` the element's distance to the front, ``w`` its opening and
    ``K' = 4 (2/pi)^(1/2) K_Ic`` (ref. Eq. 4.68): 1 at the toughness limit, falling to 0 as
    viscosity takes over. Returns ``(angle, k_hat)`` sorted by the angle (degrees, from the
    in-plane axis e1 about the normal) of each ribbon centre round ``well``; None without a
    ribbon or for a Mesh2D."""
    from ..analytical import toughness_scale

    ribbon = np.flatnonzero(np.isfinite(front_distance))
    if not isinstance(mesh, Mesh3D) or ribbon.size == 0:
        return None
    e1, e2, _ = mesh.frames[ribbon[0]]
    offset = mesh.centers[ribbon] - np.asarray(well, dtype=float)
    angle = np.degrees(np.arctan2(offset @ e2, offset @ e1)) % 360.0
    width = np.maximum(np.asarray(opening, dtype=float)[ribbon], 1e-300)
    k_hat = toughness_scale(toughness) * np.sqrt(np.asarray(front_distance)[ribbon]) / (plane_strain_modulus * width)
    order = np.argsort(angle)
    return angle[order], np.clip(k_hat[order], 0.0, None)


def write_tip_regime(folder, mesh, fields, front, scene, step, time_value, title):
    """``folder/step-NNNNNN_front.png``: the tip regime along an asymptotic front
    (:func:`tip_regime`); None when there is no asymptotic front to draw."""
    from pathlib import Path

    from ..render.profiles import plot_tip_regime
    from ..scene.build import material

    if front is None or front[0] is None or scene is None or "material" not in scene:
        return None
    well = scene["cluster"][0]["position"]
    regime = tip_regime(mesh, fields["opening"], front[0], well, scene["propagation"]["toughness"],
                        material(scene).plane_strain_modulus)
    if regime is None:
        return None
    return plot_tip_regime(*regime, Path(folder) / f"step-{step:06d}_front.png", title=title)


__all__ = ["asymptotic_front", "element_front", "reference_front", "front_curves", "tip_regime", "write_tip_regime"]
