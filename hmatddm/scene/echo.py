"""A validated scene (the echo of :func:`hmatddm.scene.schema.validate`) read and
written: the far-field tensor the engine wants, whether natural fractures are declared,
and the echo as TOML text (written next to a run, read back by ``tomllib``).
"""
import json
import math

import numpy as np

from .sections import SECTIONS, TOP


def has_natural_fractures(scene):
    """Whether a validated scene declares natural fractures (a network or explicit ones)."""
    return "network" in scene or bool(scene.get("natural_fracture"))


def far_field_stress(scene):
    """The (d, d) far-field stress tensor the engine wants (tension positive, Pa).

    The file's stresses are compressive positive: ``tensor`` is negated; the principal
    form puts ``s_hmax`` along the azimuth (degrees from +x, counter-clockwise),
    ``s_hmin`` perpendicular to it in the x-y plane and ``s_v`` along z.
    """
    stress = scene["stress"]
    dim = scene["dimension"]
    if "tensor" in stress:
        return -np.array(stress["tensor"], dtype=float) + 0.0
    angle = math.radians(stress["azimuth_deg"])
    along = np.array([math.cos(angle), math.sin(angle)])
    across = np.array([-math.sin(angle), math.cos(angle)])
    horizontal = stress["s_hmax"] * np.outer(along, along) + stress["s_hmin"] * np.outer(across, across)
    if dim == 2:
        return -horizontal + 0.0
    tensor = np.zeros((3, 3))
    tensor[:2, :2] = horizontal
    tensor[2, 2] = stress["s_v"]
    return -tensor + 0.0


# ---------------------------------------------------------------------------------
# TOML output (the echo written next to a run, readable by tomllib)
# ---------------------------------------------------------------------------------

def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} as TOML")  # pragma: no cover


def to_toml(scene, header=None):
    """A validated scene as TOML text (``tomllib`` reads it back to the same echo)."""
    lines = [f"# {line}" for line in (header or "").splitlines()]
    for key in TOP:
        if key in scene:
            lines.append(f"{key} = {_toml_value(scene[key])}")
    for section, (_, is_array, _) in SECTIONS.items():
        if section not in scene:
            continue
        tables = scene[section] if is_array else [scene[section]]
        for table in tables:
            lines += ["", f"[[{section}]]" if is_array else f"[{section}]"]
            lines += [f"{key} = {_toml_value(value)}" for key, value in table.items()]
    return "\n".join(lines) + "\n"
