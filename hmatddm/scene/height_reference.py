"""The closed form of height growth for a layered 2D scene (ref. Ch. 3): when the scene is a
symmetric three-layer stack (a pay zone between two bounding layers of equal minimum
horizontal stress, the injection point in the middle of the pay zone), the equilibrium
height for the stress contrast (:mod:`hmatddm.analytical.height_growth`, Simonson et al.
1978) at each step's net pressure, next to the run's height: summary.json's ``reference``
of such a scene (which has no ``[reference]`` section of its own).
"""
import math

SOLUTION = "equilibrium height of a symmetric three-layer stack under a stress contrast"
_CENTRED = 0.01  # |well - middle of the pay zone| / pay thickness still "centred"


def three_layer_stack(scene):
    """``(stress_contrast, pay_thickness, toughness, pay_stress)`` of a 2D scene that is a
    symmetric three-layer stack (module docstring), else None."""
    from ..scene import confining_stress

    layers = scene.get("layer") or []
    if scene.get("dimension") != 2 or len(layers) != 3 or "propagation" not in scene:
        return None
    top, pay, bottom = layers
    if "s_hmin" not in top or "s_hmin" not in bottom or top["s_hmin"] != bottom["s_hmin"] or "s_hmin" in pay:
        return None
    upper, lower = top["bottom"], pay["bottom"]
    thickness = upper - lower
    well = scene["cluster"][0]["position"][1]
    if len(scene["cluster"]) != 1 or abs(well - 0.5 * (upper + lower)) > _CENTRED * thickness:
        return None
    pay_stress = confining_stress(scene)
    contrast = top["s_hmin"] - pay_stress
    if not contrast > 0.0:
        return None
    toughness = top.get("toughness") or scene["propagation"]["toughness"]
    return contrast, thickness, toughness, pay_stress


def height_reference(scene, steps):
    """One row per record of ``steps`` (summary.json's ``reference``): the equilibrium
    ``height`` (m; None where the net pressure exceeds the contrast: no equilibrium, the
    fracture grows through the barriers, ``contained`` False), the ``net_pressure`` it is
    computed for (the wellbore pressure minus the pay zone's closing stress), the
    ``relative_error`` of the run's height, and the solution, formula and source; None
    when the scene is not a symmetric three-layer stack."""
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
                     "solution": SOLUTION, "formula": FORMULA, "source": SOURCE})
    return rows


__all__ = ["three_layer_stack", "height_reference"]
