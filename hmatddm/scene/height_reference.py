"""The closed form of height growth, ``[reference] kind = "three-layer-height"`` (ref. Ch.
3): for a 2D scene that is a symmetric three-layer stack (a pay zone between two bounding
layers of equal minimum horizontal stress, the injection point in the middle of the pay
zone), the equilibrium height for the stress contrast (:mod:`hmatddm.analytical.height_growth`,
Simonson et al. 1978) at each step's net pressure, next to the run's height: the rows of
summary.json's ``reference`` (:func:`hmatddm.scene.reference_values`), the equilibrium tips
dashed in the history plot and the plan view.
"""
import math

SOLUTION = "equilibrium height of a symmetric three-layer stack under a stress contrast"
_CENTRED = 0.01  # |well - middle of the pay zone| / pay thickness still "centred"
KIND = "three-layer-height"


def three_layer_stack(scene):
    """``(stress_contrast, pay_thickness, toughness, pay_stress)`` of a 2D scene that is a
    symmetric three-layer stack (module docstring), else None (:func:`stack_problem` says
    why)."""
    return None if stack_problem(scene) else _stack(scene)


def stack_problem(scene):
    """Why ``scene`` is not a symmetric three-layer stack (one line), or None when it is."""
    layers = scene.get("layer") or []
    if scene.get("dimension") != 2:
        return f"it is a 2D closed form; the scene has dimension = {scene.get('dimension')}"
    if len(layers) != 3:
        return f"it needs exactly three [[layer]] tables (bounding, pay, bounding), got {len(layers)}"
    if "propagation" not in scene:
        return "it compares a growing fracture: the scene needs a [propagation] section"
    top, pay, bottom = layers
    if "s_hmin" not in top or "s_hmin" not in bottom or top["s_hmin"] != bottom["s_hmin"] or "s_hmin" in pay:
        return ("the two bounding layers need the same layer s_hmin and the pay zone (the middle layer) the "
                "scene's [stress]")
    if len(scene["cluster"]) != 1:
        return f"it needs exactly one [[cluster]], got {len(scene['cluster'])}"
    upper, lower = top["bottom"], pay["bottom"]
    well = scene["cluster"][0]["position"][1]
    if abs(well - 0.5 * (upper + lower)) > _CENTRED * (upper - lower):
        return (f"the injection point (y = {well:g} m) must be in the middle of the pay zone (y = "
                f"{0.5 * (upper + lower):g} m)")
    fracture = (scene.get("initial_fracture") or [{}])[0]
    if "p0" not in fracture or "p1" not in fracture:
        return "it needs an [[initial_fracture]] line (p0, p1) through the injection point"
    contrast = _stack(scene)[0]
    if not contrast > 0.0:
        return f"the bounding layers' s_hmin must exceed the pay zone's closing stress (contrast {contrast:g} Pa)"
    return None


def _stack(scene):
    top, pay, _ = scene["layer"]
    pay_stress = _closing_stress(scene)
    toughness = top.get("toughness") or scene["propagation"]["toughness"]
    return top["s_hmin"] - pay_stress, top["bottom"] - pay["bottom"], toughness, pay_stress


def _closing_stress(scene):
    """The pay zone's compressive stress normal to the first initial fracture (a 2D line
    from ``p0`` to ``p1``), Pa: :func:`hmatddm.scene.confining_stress` without building its
    mesh (the schema checks a reference before anything is built)."""
    import numpy as np

    from .echo import far_field_stress

    fracture = scene["initial_fracture"][0]
    tangent = np.subtract(fracture["p1"], fracture["p0"], dtype=float)
    normal = np.array([-tangent[1], tangent[0]]) / np.hypot(*tangent)
    return float(-normal @ far_field_stress(scene) @ normal)


def height_reference(scene, steps):
    """One row per record of ``steps`` (summary.json's ``reference``): the equilibrium
    ``height`` (m; None where the net pressure exceeds the contrast: no equilibrium, the
    fracture grows through the barriers, ``contained`` False), the ``net_pressure`` it is
    computed for (the wellbore pressure minus the pay zone's closing stress), the
    ``relative_error`` of the run's height, and the ``solution`` (kind, name, formula,
    source, as :data:`hmatddm.analytical.regimes.SOLUTIONS` gives the others); None when the
    scene is not a symmetric three-layer stack."""
    from ..analytical.height_growth import FORMULA, SOURCE, equilibrium_height

    stack = three_layer_stack(scene)
    if stack is None:
        return None
    contrast, thickness, toughness, pay_stress = stack
    rows = []
    for step in steps:
        net = step["wellbore_pressure"][0] - pay_stress
        height = equilibrium_height(net, contrast, thickness, toughness) if step["time"] > 0.0 else float("nan")
        finite = math.isfinite(height)
        simulated = step.get("height")
        rows.append({"time": step["time"], "height": height if finite else None, "net_pressure": net,
                     "stress_contrast": contrast, "pay_thickness": thickness,
                     "contained": None if math.isnan(height) else bool(finite),
                     "relative_error": {"height": simulated / height - 1.0 if finite and simulated else None},
                     "solution": {"kind": KIND, "name": SOLUTION, "formula": FORMULA, "source": SOURCE}})
    return rows


def equilibrium_tips(scene, records):
    """The equilibrium tips ``middle +- height/2`` (m, the vertical coordinate) at the
    records where there is an equilibrium: ``{"time", "top", "bottom"}`` lists, or None
    when there is none."""
    rows = [row for row in (height_reference(scene, records) or []) if row["height"] is not None]
    if not rows:
        return None
    layers = scene["layer"]
    middle = 0.5 * (layers[0]["bottom"] + layers[1]["bottom"])
    return {"time": [row["time"] for row in rows], "top": [middle + 0.5 * row["height"] for row in rows],
            "bottom": [middle - 0.5 * row["height"] for row in rows]}


__all__ = ["KIND", "three_layer_stack", "stack_problem", "height_reference", "equilibrium_tips"]
