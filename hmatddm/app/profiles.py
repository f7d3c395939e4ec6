"""The profile picture of a saved step, ``snapshots/step-NNNNNN_profile.png``: the opening
and net pressure along the fractures (:func:`hmatddm.render.profiles.plot_profiles`), with
the closed form of the scene's ``[reference]`` at the step's time along each section.

The closed forms (ref. Sec. 4.5): the K-vertices (radial, ref. Eqs 4.65-4.67; KGD) have
Sneddon's elliptical opening ``w_max (1 - rho^2)^(1/2)`` under a uniform net pressure; the
M-vertices the profiles of Savitski and Detournay (2002, radial) and Adachi and Detournay
(2002, KGD), :func:`hmatddm.analytical.radial_m_vertex_profile` and
:func:`~hmatddm.analytical.kgd_m_vertex_profile`; the K-M transition the opening of
Dontsov (2016), :func:`~hmatddm.analytical.radial_transition_profile` (no pressure),
tabulated in time (:mod:`hmatddm.analytical.transition_table`) since a run draws one
picture per saved step.
"""
from pathlib import Path

import numpy as np

SAMPLES = 201
# rho = r / R of the sampled M-vertex profiles: the pressure is +inf at the well (radial)
# and -inf at the tip, so the samples stop short of both
_M_RHO = (0.01, 0.99)


def _symmetric(rho, width, pressure, radius):
    """Both sides of an axisymmetric profile sampled at ``rho`` in [0, 1): positions
    ``-R rho[::-1] ... R rho``."""
    position = np.concatenate([-radius * rho[::-1], radius * rho])
    out = {"position": position, "opening": np.concatenate([width[::-1], width])}
    if pressure is not None:
        out["net_pressure"] = np.concatenate([pressure[::-1], pressure])
    return out


def closed_form_profile(scene, time_value):
    """The closed-form profile of ``scene``'s ``[reference]`` at ``time_value`` (s, > 0):
    a dict with ``position`` (m, from the well), ``opening`` (m), ``net_pressure`` (Pa,
    where the solution has one) and ``label``; None without a [reference] (or for a
    reference kind this module does not draw)."""
    from .. import analytical
    from ..scene.build import material

    reference = scene.get("reference")
    if reference is None or not time_value > 0.0:
        return None
    kind = reference["kind"]
    rock = material(scene)
    rate = scene["cluster"][0]["rate"]
    fluid = scene["fluid"]
    viscosity = fluid.get("viscosity")
    toughness = scene.get("propagation", {}).get("toughness")
    t = float(time_value)
    if fluid.get("rheology") == "power-law" and kind in ("kgd-m", "radial-m"):  # hmatddm.analytical.power_law
        from ..analytical import power_law

        fluid_args = (fluid["consistency"], fluid["flow_index"])
        if kind == "kgd-m":
            size = power_law.kgd_power_law_vertex(t, rate / scene["height"], *fluid_args, rock)[0]
            rho = np.linspace(0.0, _M_RHO[1], SAMPLES)
            width, pressure = power_law.kgd_power_law_profile(rho, t, rate / scene["height"], *fluid_args, rock)
        else:
            size = power_law.radial_power_law_vertex(t, rate, *fluid_args, rock)[0]
            rho = np.linspace(*_M_RHO, SAMPLES)
            width, pressure = power_law.radial_power_law_profile(rho, t, rate, *fluid_args, rock)
        profile = _symmetric(rho, np.ravel(width), np.ravel(pressure), float(np.ravel(size)[0]))
        profile["label"] = f"power-law {kind[-1].upper()}-vertex (n = {fluid['flow_index']:g})"
        return profile
    if kind in ("kgd-k", "radial-k"):
        if kind == "kgd-k":
            size, width, pressure = analytical.kgd_k_vertex(t, rate / scene["height"], toughness, rock)
        else:
            size, width, pressure = analytical.radial_k_vertex(t, rate, toughness, rock)
        rho = np.linspace(0.0, 1.0, SAMPLES)
        profile = _symmetric(rho, float(width) * np.sqrt(1.0 - rho ** 2), np.full(SAMPLES, float(pressure)),
                             float(size))
        profile["label"] = f"{kind} vertex"
        return profile
    if kind in ("kgd-k-leak-off", "radial-k-leak-off"):  # the K-K~ edge: Griffith's / Sneddon's opening
        from ..scene.build import _closed_form

        curves = _closed_form(scene, [t])
        size = float(curves["radius" if kind.startswith("radial") else "half_length"][0])
        rho = np.linspace(0.0, 1.0, SAMPLES)
        profile = _symmetric(rho, float(curves["max_opening"][0]) * np.sqrt(1.0 - rho ** 2),
                             np.full(SAMPLES, float(curves["net_pressure"][0])), size)
        profile["label"] = f"{kind.split('-')[0]} K-K~ edge (leak-off)"
        return profile
    if kind in ("kgd-m-leak-off", "kgd-km-leak-off", "radial-km-leak-off", "radial-m-leak-off"):  # no net pressure
        from ..analytical import viscous_leak_off
        from ..scene.build import _closed_form, confining_stress, leak_off

        rho = np.linspace(0.0, 1.0, SAMPLES)
        c_prime = leak_off(scene).coefficient * (confining_stress(scene) - scene["leak_off"]["pore_pressure"])
        if kind == "kgd-m-leak-off":
            size, width = viscous_leak_off.kgd_m_leak_off_profile(rho, t, rate / scene["height"], viscosity,
                                                                  c_prime, rock)
            profile = _symmetric(rho, width, None, size)
            profile["label"] = "kgd M~ vertex (Dontsov 2017)"
        elif kind == "radial-m-leak-off":
            size, width = viscous_leak_off.radial_m_leak_off_profile(rho, t, rate, viscosity, c_prime, rock)
            profile = _symmetric(rho, width, None, size)
            profile["label"] = "radial M~ vertex (Dontsov 2016)"
        elif kind == "kgd-km-leak-off":
            size, width = viscous_leak_off.kgd_leak_off_transition(t, rate / scene["height"], viscosity, toughness,
                                                                   c_prime, rock, profile=rho)
            profile = _symmetric(rho, width, None, float(size[0]))
            profile["label"] = "kgd with leak-off (Dontsov 2017)"
        else:
            size, width = viscous_leak_off.radial_leak_off_profile(rho, t, rate, viscosity, toughness, c_prime, rock)
            profile = _symmetric(rho, width, None, size)
            profile["label"] = "radial with leak-off (Dontsov 2016)"
        return profile
    if kind == "kgd-m":
        size, _, _ = analytical.kgd_m_vertex(t, rate / scene["height"], viscosity, rock)
        rho = np.linspace(0.0, _M_RHO[1], SAMPLES)
        width, pressure = analytical.kgd_m_vertex_profile(rho, t, rate / scene["height"], viscosity, rock)
        profile = _symmetric(rho, width, pressure, float(size))
    elif kind == "radial-m":
        radius, _ = analytical.radial_m_vertex(t, rate, viscosity, rock)  # the profile's own radius
        rho = np.linspace(*_M_RHO, SAMPLES)
        width, pressure = analytical.radial_m_vertex_profile(rho, t, rate, viscosity, rock)
        profile = _symmetric(rho, width, pressure, float(radius))
    elif kind == "radial-km":
        rho = np.linspace(0.0, 1.0, SAMPLES)
        table = analytical.radial_transition_table(rate, viscosity, toughness, rock)  # tabulated in time
        radius, width = table.profile(rho, t)
        profile = _symmetric(rho, width, None, float(radius))
    else:
        return None
    profile["label"] = f"{kind} vertex" if kind != "radial-km" else "radial K-M (Dontsov 2016)"
    return profile


def wells(scene):
    """The injection points of a scene (m)."""
    return np.array([cluster["position"] for cluster in scene.get("cluster", [])], dtype=float)


def write_profile(folder, mesh, fields, step, time_value, scene, title, plotter=None):
    """``folder/step-NNNNNN_profile.png`` (a run's ``snapshots`` folder) of one state
    (``fields``: :func:`hmatddm.app.run_folder.cell_fields`;
    ``plotter``: a :class:`hmatddm.render.profiles.ProfilePlotter` to reuse); returns its
    path, or None when the state has no hydraulic element to draw."""
    from ..render.profiles import fracture_sections, plot_profiles

    points = wells(scene) if scene is not None else np.zeros((0, mesh.dim))
    sections = fracture_sections(mesh, fields["opening"], fields["net_pressure"], fields.get("state"), points)
    if not sections:
        return None
    reference = None
    curve = closed_form_profile(scene, time_value) if scene is not None else None
    if curve is not None:
        reference = [curve] * len(sections)
    label = "distance from the injection point along the section (m)"
    if mesh.dim == 2:
        label = "arc length along the fracture from the injection point (m)"
    marks = interface_crossings(mesh, sections, scene)
    return plot_profiles(sections, Path(folder) / f"step-{step:06d}_profile.png", reference=reference,
                         title=title, position_label=label, plotter=plotter, marks=marks)


def interface_crossings(mesh, sections, scene):
    """Positions along the sections where they cross a layer interface of ``scene`` (the
    vertical coordinate through the element centres, linear between them)."""
    interfaces = [float(layer["bottom"]) for layer in ((scene or {}).get("layer") or [])[:-1]]
    axis = mesh.dim - 1
    marks = []
    for section in sections:
        height = mesh.centers[section.elements, axis]
        for level in interfaces:
            crossing = np.flatnonzero((height[:-1] - level) * (height[1:] - level) < 0.0)
            for i in crossing:
                fraction = (level - height[i]) / (height[i + 1] - height[i])
                marks.append(section.position[i] + fraction * (section.position[i + 1] - section.position[i]))
    return marks


__all__ = ["closed_form_profile", "wells", "write_profile"]
