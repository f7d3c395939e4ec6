"""Profiles of one state with matplotlib (Agg canvas, no window, no pyplot): the opening
and the net pressure along lines through the fractures, with the closed form overlaid.

* :func:`fracture_sections`: in 2D, each hydraulic fracture against its arc length
  (from the injection point on it, else from its middle); in 3D, the sections of the
  fracture through an injection point along both in-plane axes of the element there.
  Constant elements: one value per element, at its centre on the line.
* :func:`plot_profiles`: two panels (opening in mm, net pressure in MPa) against the
  position along the section (m), the closed form dashed with the relative error of
  each section in the legend (:func:`relative_error`).
"""
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..io import atomic_output
from ..mesh import Mesh2D, Mesh3D
from .layout import HYDRAULIC, check_fields, check_mesh_type

MAX_SECTIONS = 8  # more hydraulic fractures than this in 2D: the first ones (by fracture id)
_IN_PLANE = 1e-6  # |distance from the section's plane| / element size still on the section
_AXIS_NAMES = ("x", "y", "z")


@dataclass
class Section:
    """Values along one line through the fractures, ordered by ``position``."""

    label: str
    position: np.ndarray      # (n,) m, along the line from its origin
    opening: np.ndarray       # (n,) m
    net_pressure: np.ndarray  # (n,) Pa
    elements: np.ndarray      # (n,) element indices


def _axis_name(direction):
    """``"x"`` for a direction along an axis (either sign: ``"-x"``), else the components."""
    direction = np.asarray(direction, dtype=float)
    largest = int(np.argmax(np.abs(direction)))
    if abs(direction[largest]) > 1.0 - 1e-9:
        return ("-" if direction[largest] < 0 else "") + _AXIS_NAMES[largest]
    return "(" + ", ".join(f"{v:.2f}" for v in direction) + ")"


def sections_2d(mesh, opening, net_pressure, state=None, wells=()):
    """One :class:`Section` per hydraulic fracture of a Mesh2D (at most
    :data:`MAX_SECTIONS`): its elements ordered along the fracture's principal direction,
    ``position`` the arc length through their centres, 0 at a well on it (``wells``:
    points, m; projected on the element nearest it), else at its middle."""
    wells = np.asarray(wells, dtype=float).reshape(-1, 2)
    kept = np.ones(mesh.n_elements, bool) if state is None else state == HYDRAULIC
    sections = []
    for fracture in np.unique(mesh.fracture_id[kept])[:MAX_SECTIONS]:
        members = np.flatnonzero(kept & (mesh.fracture_id == fracture))
        centres = mesh.centers[members]
        if len(members) == 1:
            direction = mesh.frames[members[0], 0]
        else:
            _, _, rows = np.linalg.svd(centres - centres.mean(axis=0), full_matrices=False)
            direction = rows[0]
        if direction[np.argmax(np.abs(direction))] < 0.0:  # along +x (+y for a vertical fracture)
            direction = -direction
        order = np.argsort(centres @ direction)
        members, centres = members[order], centres[order]
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(centres, axis=0), axis=1))])
        origin = 0.5 * (arc[0] + arc[-1])
        if len(wells):
            distance = np.linalg.norm(centres[:, None, :] - wells[None, :, :], axis=2)
            nearest = np.unravel_index(np.argmin(distance), distance.shape)
            if distance[nearest] <= 1.01 * float(np.max(mesh.half_length[members])):  # the well's projection
                origin = arc[nearest[0]] + float((wells[nearest[1]] - centres[nearest[0]]) @ direction)
        sections.append(Section(f"fracture {int(fracture)} (along {_axis_name(direction)})", arc - origin,
                                opening[members], net_pressure[members], members))
    return sections


def sections_3d(mesh, opening, net_pressure, point, state=None):
    """The two :class:`Section` s of a Mesh3D through ``point`` (m) along the in-plane axes
    ``e1``, ``e2`` of the element nearest it: the elements in that element's plane that the
    line crosses, ``position`` the distance of their centres along the line from ``point``."""
    point = finite_array("point", point, (3,))
    kept = np.ones(mesh.n_elements, bool) if state is None else state == HYDRAULIC
    candidates = np.flatnonzero(kept)
    if candidates.size == 0:
        return []
    home = candidates[np.argmin(np.sum((mesh.centers[candidates] - point) ** 2, axis=1))]
    e1, e2, normal = mesh.frames[home]
    size = float(np.max(mesh.radii))
    offset = mesh.centers - mesh.centers[home]
    in_plane = kept & (np.abs(offset @ normal) <= _IN_PLANE * size) & (np.abs(mesh.normals @ normal) > 1.0 - 1e-9)
    sections = []
    for along, across in ((e1, e2), (e2, e1)):
        # the half extent of each element across the line (its rectangle projected)
        reach = (mesh.half_a * np.abs(mesh.frames[:, 0] @ across) + mesh.half_b * np.abs(mesh.frames[:, 1] @ across))
        crossed = np.flatnonzero(in_plane & (np.abs((mesh.centers - point) @ across) < reach * (1.0 + 1e-9)))
        position = (mesh.centers[crossed] - point) @ along
        order = np.argsort(position)
        crossed, position = crossed[order], position[order]
        sections.append(Section(f"along {_axis_name(along)}", position, opening[crossed], net_pressure[crossed],
                                crossed))
    return sections


def fracture_sections(mesh, opening, net_pressure, state=None, wells=()):
    """The :class:`Section` s of a state: :func:`sections_2d` of a Mesh2D (``wells``: the
    injection points), :func:`sections_3d` through the first well of a Mesh3D."""
    check_mesh_type(mesh)
    opening, state, _ = check_fields(mesh, opening, state, None)
    net_pressure = finite_array("net_pressure", net_pressure, (mesh.n_elements,))
    if isinstance(mesh, Mesh2D):
        return sections_2d(mesh, opening, net_pressure, state, wells)
    wells = np.asarray(wells, dtype=float).reshape(-1, 3)
    point = wells[0] if len(wells) else mesh.centers[int(np.argmax(opening))]
    return sections_3d(mesh, opening, net_pressure, point, state)


def relative_error(position, values, reference_position, reference_values):
    """``||v - v_ref|| / ||v_ref||`` (2-norm) over the section's points inside the closed
    form's extent, the closed form interpolated linearly at them; None when no point is
    inside or the closed form is zero there."""
    position = np.asarray(position, dtype=float)
    reference_position = np.asarray(reference_position, dtype=float)
    inside = (position >= reference_position.min()) & (position <= reference_position.max())
    if not np.any(inside):
        return None
    exact = np.interp(position[inside], reference_position, np.asarray(reference_values, dtype=float))
    norm = float(np.linalg.norm(exact))
    if norm == 0.0 or not np.isfinite(norm):
        return None
    return float(np.linalg.norm(np.asarray(values, dtype=float)[inside] - exact) / norm)


def _check_reference(reference, n_sections):
    if reference is None:
        return [None] * n_sections
    reference = list(reference)
    if len(reference) != n_sections:
        raise InputError(f"reference must hold one entry (a dict or None) per section, {n_sections}; "
                         f"got {len(reference)}")
    checked = []
    for index, curve in enumerate(reference):
        if curve is None:
            checked.append(None)
            continue
        position = finite_array(f"reference[{index}]['position']", curve["position"])
        entry = {"position": position, "label": str(curve.get("label", "closed form"))}
        for key in ("opening", "net_pressure"):
            if curve.get(key) is not None:
                entry[key] = finite_array(f"reference[{index}][{key!r}]", curve[key], position.shape)
        checked.append(entry)
    return checked


class ProfilePlotter:
    """Draws :func:`plot_profiles` pictures on one reused matplotlib figure (a run draws one
    per saved step: a new figure and its layout cost more than the drawing)."""

    def __init__(self):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.figure = Figure(figsize=(7.0, 6.4), dpi=100)
        FigureCanvasAgg(self.figure)
        self.figure.subplots_adjust(left=0.1, right=0.97, top=0.94, bottom=0.08, hspace=0.06)
        self.axes = self.figure.subplots(2, 1, sharex=True)

    def draw(self, sections, path, reference=None, title=None, position_label=None, marks=()):
        """See :func:`plot_profiles`."""
        sections = list(sections)
        if not sections:
            raise InputError("plot_profiles needs at least one section (no hydraulic fracture element?)")
        references = _check_reference(reference, len(sections))
        opening_axis, pressure_axis = self.axes
        for axis in self.axes:
            axis.cla()
        for index, (section, curve) in enumerate(zip(sections, references)):
            colour = f"C{index % 10}"
            for axis, key, scale in ((opening_axis, "opening", 1e3), (pressure_axis, "net_pressure", 1e-6)):
                values = getattr(section, key)
                label = section.label
                if curve is not None and key in curve:
                    error = relative_error(section.position, values, curve["position"], curve[key])
                    if error is not None:
                        label += f" (error {100 * error:.1f}% vs {curve['label']})"
                    axis.plot(curve["position"], scale * curve[key], color=colour, linestyle="--", linewidth=1.2)
                axis.plot(section.position, scale * values, color=colour, marker="o", markersize=3,
                          linewidth=1.2, label=label)
        if any(curve is not None for curve in references):
            opening_axis.plot([], [], color="black", linestyle="--", linewidth=1.2, label="closed form (dashed)")
        for index, position in enumerate(finite_array("marks", marks).ravel() if len(marks) else ()):
            for axis in self.axes:
                axis.axvline(position, color="grey", linestyle=":", linewidth=1.5,
                             label="layer interfaces" if index == 0 and axis is opening_axis else None)
        for axis, label in ((opening_axis, "opening (mm)"), (pressure_axis, "net pressure (MPa)")):
            axis.set_ylabel(label)
            axis.grid(True, alpha=0.3)
            axis.legend(loc="lower center", fontsize="small")
        opening_axis.set_ylim(bottom=0.0)
        opening_axis.tick_params(labelbottom=False)
        pressure_axis.set_xlabel(position_label or "position along the section (m)")
        self.figure.suptitle("" if title is None else str(title), fontsize="medium")
        path = Path(path)
        with atomic_output(path) as temporary:
            self.figure.savefig(temporary, format="png")
        return path


def plot_profiles(sections, path, reference=None, title=None, position_label=None, plotter=None, marks=()):
    """Two panels against the position along each :class:`Section` (m): the opening (mm)
    and the net pressure (MPa, the fluid pressure minus the compressive normal in-situ
    stress); ``reference``: per section None or a dict with ``position`` (m), ``opening``
    (m) and/or ``net_pressure`` (Pa) arrays and a ``label``, drawn dashed with the
    section's :func:`relative_error` in the legend; ``marks``: positions (m) along the
    sections drawn as dotted vertical lines (layer interfaces). ``plotter``: a
    :class:`ProfilePlotter` to draw on (a new one by default). Returns the path of the PNG
    (written atomically)."""
    return (plotter or ProfilePlotter()).draw(sections, path, reference, title, position_label, marks)


def plot_tip_regime(angle, k_hat, path, title=None):
    """The regime of the tip asymptote along a front: ``K^`` (1 toughness, 0 viscosity)
    against the angle round the injection point (degrees), one dot per ribbon element.
    Returns the path of the PNG (written atomically)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    angle = finite_array("angle", angle)
    k_hat = finite_array("k_hat", k_hat, angle.shape)
    figure = Figure(figsize=(7.0, 3.2), dpi=100)
    FigureCanvasAgg(figure)
    figure.subplots_adjust(left=0.1, right=0.97, top=0.86, bottom=0.16)
    axis = figure.subplots()
    axis.scatter(angle, k_hat, c=k_hat, cmap="coolwarm", vmin=0.0, vmax=1.0, s=14)
    axis.set_xlim(0.0, 360.0)
    axis.set_ylim(-0.02, 1.05)
    axis.set_xticks(np.arange(0.0, 361.0, 45.0))
    axis.set_xlabel("angle round the injection point, from x (degrees)")
    axis.set_ylabel("K^ = K' s^(1/2) / (E' w)")
    axis.axhline(1.0, color="grey", linewidth=0.8)
    axis.text(2.0, 0.97, "toughness", va="top", fontsize="small", color="tab:red")
    axis.text(2.0, 0.03, "viscosity", va="bottom", fontsize="small", color="tab:blue")
    axis.grid(True, alpha=0.3)
    figure.suptitle(("" if title is None else f"{title}: ") + "tip regime along the front (ribbon elements)",
                    fontsize="medium")
    path = Path(path)
    with atomic_output(path) as temporary:
        figure.savefig(temporary, format="png")
    return path


__all__ = ["plot_tip_regime", "Section", "ProfilePlotter", "fracture_sections", "sections_2d", "sections_3d", "relative_error",
           "plot_profiles"]
