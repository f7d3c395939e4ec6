"""Tip growth: which tip edges propagate and the elements added ahead of them
(ref. Sec. 4.4, Fig. 4.1: new elements of the owner's size, in the direction of the
maximum circumferential stress).

A new element hinges on its parent's tip edge: the parent frame is rotated by
``theta_0`` about the edge axis (from ``ahead`` towards the normal), so the new
element shares the tip edge exactly and the flow faces and tip edges of
:mod:`hmatddm.mesh.topology` find it. In 3D, ``turning="plan"`` lets only edges parallel
to the vertical axis turn (fractures turn in plan view and stay vertical); the
others grow straight.
"""
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .._validation import finite_scalar
from ..errors import InputError
from ..mesh import Mesh2D, Mesh3D
from .criteria import (OLSON_CORRECTION, circumferential_stress_direction, energy_release_rate,
                       equivalent_mode_one, stress_intensity_factors)

from ..options import CRITERIA, FRONTS, TURNING  # noqa: E402,F401
from ..settings import PROPAGATION  # noqa: E402  (ranges, units and defaults of the fields)


@dataclass(frozen=True)
class Propagation:
    """Propagation settings (ref. Sec. 4.2.2).

    Parameters
    ----------
    toughness : float
        K_Ic in Pa m^1/2, > 0.
    criterion : {"mcs", "energy"}
        ``"mcs"``: K-bar_I >= K_Ic (ref. Eq. 4.9). ``"energy"``: G >= G_c (ref. Eqs
        4.14-4.15, with the mode-III term of Eq. 4.13), ``G_c = K_Ic^2 / E'`` unless
        ``critical_energy_release_rate`` is given.
    critical_energy_release_rate : float or None
        G_c in J/m^2.
    correction : float
        C_cor of Olson's SIF estimate (ref. Eqs 4.18-4.19), default 0.806.
    turning : {"none", "plan", "any"}
        Which tip edges may turn by theta_0: none, those along the z axis (3D; all in
        2D), or any.
    min_turn_angle : float
        Directions with ``|theta_0|`` below this (radians) grow straight, so planar
        fractures stay exactly planar under round-off.
    max_growth_passes : int
        Re-solves of one time step after adding elements, >= 0 (0 disables growth).
    bounds : ((lo, hi), ...) or None
        Per-axis limits for new element centres (e.g. barrier layers bounding z).
    front : {"element", "asymptotic"}
        ``"element"``: the reference's switch, whole elements added where the criterion
        holds (ref. Sec. 4.2.2, growth direction from ref. Eqs 4.10-4.11, so fractures
        may turn). ``"asymptotic"``: the front is located inside the tip elements by
        inverting the universal tip asymptote (:mod:`hmatddm.analytical.tip_asymptote`,
        :mod:`hmatddm.fracture.front`); partially filled tip elements carry the
        asymptote's opening. Planar fractures only (one fracture, square elements on one
        grid in 3D, equal segments on a line in 2D), without natural fractures, contact
        or bounds, and leak-off only with a Newtonian fluid (the tip asymptote with
        leak-off): :class:`~hmatddm.Simulation` raises InputError otherwise. ``criterion`` and ``turning`` are not used by it.
    front_iterations : int
        Asymptotic front: fixed-point iterations of the front per time step, >= 1.
    front_tolerance : float
        Asymptotic front: converged when no ribbon distance changes by more than this
        fraction of the element size, in (0, 1). None (the default): 1e-2 without
        leak-off, 1e-3 with it (:data:`hmatddm.simulation.asymptotic.FRONT_TOLERANCE`).
    """

    toughness: float
    criterion: str = "mcs"
    critical_energy_release_rate: float | None = None
    correction: float = OLSON_CORRECTION
    turning: str = "plan"
    min_turn_angle: float = np.deg2rad(1.0)
    max_growth_passes: int = 50
    bounds: tuple | None = None
    front: str = "element"
    front_iterations: int = 40
    front_tolerance: float | None = None

    def __post_init__(self):
        for name in ("toughness", "criterion", "front", "front_iterations", "front_tolerance", "turning",
                     "critical_energy_release_rate", "correction", "max_growth_passes"):
            object.__setattr__(self, name, PROPAGATION[name].value(f"propagation.{name}", getattr(self, name)))
        angle = finite_scalar("propagation.min_turn_angle", self.min_turn_angle)  # radians here, degrees in a scene
        if not 0.0 <= angle < np.pi / 2:
            raise InputError(f"propagation.min_turn_angle must be in [0, pi/2) rad, got {angle}")
        object.__setattr__(self, "min_turn_angle", angle)
        if self.bounds is not None:
            try:
                bounds = tuple((float(lo), float(hi)) for lo, hi in self.bounds)
            except (TypeError, ValueError):
                raise InputError("propagation.bounds must be a list of (low, high) pairs, one per axis") from None
            if any(not (np.isfinite(lo) or np.isinf(lo)) or lo >= hi for lo, hi in bounds):
                raise InputError(f"propagation.bounds must have low < high on every axis, got {bounds}")
            object.__setattr__(self, "bounds", bounds)


@dataclass(frozen=True)
class TipState:
    """Criterion at every tip edge (arrays of the same length)."""

    element: np.ndarray
    edge: np.ndarray
    k_1: np.ndarray
    k_2: np.ndarray
    k_3: np.ndarray
    theta: np.ndarray
    k_bar: np.ndarray
    energy_release_rate: np.ndarray
    grows: np.ndarray


def evaluate_tips(mesh, edges, tip_element, tip_edge, dd, material, propagation):
    """SIFs, theta_0 and the criterion at the given tip edges (ref. Eqs 4.9-4.19)."""
    dd = np.asarray(dd).reshape(mesh.n_elements, mesh.dim)
    tip_dd = dd[tip_element]
    ahead = edges.ahead[tip_element, tip_edge]
    normal = mesh.normals[tip_element]
    opening = np.sum(tip_dd * normal, axis=1)
    slip_ahead = np.sum(tip_dd * ahead, axis=1)
    if mesh.dim == 3:
        slip_along = np.sum(tip_dd * edges.axis[tip_element, tip_edge], axis=1)
    else:
        slip_along = np.zeros(len(tip_element))
    half_width = edges.half_width[tip_element, tip_edge]
    k_1, k_2, k_3 = stress_intensity_factors(opening, slip_ahead, slip_along, half_width, material,
                                             propagation.correction)
    theta = circumferential_stress_direction(k_1, k_2)
    k_bar = equivalent_mode_one(k_1, k_2, theta)
    g = energy_release_rate(k_bar, k_3, material)
    if propagation.criterion == "mcs":
        grows = k_bar >= propagation.toughness
    else:
        g_c = propagation.critical_energy_release_rate
        if g_c is None:
            g_c = propagation.toughness**2 / material.plane_strain_modulus
        grows = g >= g_c
    return TipState(tip_element, tip_edge, k_1, k_2, k_3, theta, k_bar, g, grows)


def _rotation(axis, angle):
    """Rotation matrices (M, 3, 3) about unit ``axis`` (M, 3) by ``angle`` (M,) (Rodrigues)."""
    k = axis
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    cross = np.zeros((len(k), 3, 3))
    cross[:, 0, 1], cross[:, 0, 2] = -k[:, 2], k[:, 1]
    cross[:, 1, 0], cross[:, 1, 2] = k[:, 2], -k[:, 0]
    cross[:, 2, 0], cross[:, 2, 1] = -k[:, 1], k[:, 0]
    outer = k[:, :, None] * k[:, None, :]
    return c * np.eye(3) + s * cross + (1.0 - c) * outer


def _turn_angles(mesh, edges, tips, propagation):
    theta = np.where(np.abs(tips.theta) < propagation.min_turn_angle, 0.0, tips.theta)
    if propagation.turning == "none":
        return np.zeros_like(theta)
    if propagation.turning == "plan" and mesh.dim == 3:
        vertical = np.abs(edges.axis[tips.element, tips.edge][:, 2]) > 0.999
        theta = np.where(vertical, theta, 0.0)
    return theta


def new_elements(mesh, edges, tips, propagation, return_tips=False):
    """Elements ahead of the growing tip edges, or ``None``.

    Returns ``(mesh_of_new_elements, parent_element)`` (plus the row of ``tips`` each
    came from when ``return_tips``). Candidates closer than half an
    element to an existing centre or to an earlier candidate are dropped (two tips of
    a staircase front may reach the same cell); candidates outside ``bounds`` too.
    """
    index = np.flatnonzero(tips.grows)
    if index.size == 0:
        return None
    parent = tips.element[index]
    edge = tips.edge[index]
    theta = _turn_angles(mesh, edges, tips, propagation)[index]
    midpoint = edges.midpoints[parent, edge]
    ahead = edges.ahead[parent, edge]
    normal = mesh.normals[parent]
    half = edges.half_width[parent, edge]
    direction = np.cos(theta)[:, None] * ahead + np.sin(theta)[:, None] * normal
    centers = midpoint + half[:, None] * direction

    keep = np.ones(len(index), dtype=bool)
    if propagation.bounds is not None:
        for axis_index, (lo, hi) in enumerate(propagation.bounds[:mesh.dim]):
            keep &= (centers[:, axis_index] >= lo) & (centers[:, axis_index] <= hi)
    size = np.minimum(mesh.radii[parent], half)
    tree = cKDTree(mesh.centers)
    distance, _ = tree.query(centers)
    keep &= distance > 0.5 * size
    chosen = []
    for m in np.flatnonzero(keep):
        if all(np.linalg.norm(centers[m] - centers[q]) > 0.5 * size[m] for q in chosen):
            chosen.append(m)
    if not chosen:
        return None
    chosen = np.asarray(chosen, dtype=np.int64)
    tip_rows = index[chosen]
    parent, edge, theta, centers = parent[chosen], edge[chosen], theta[chosen], centers[chosen]
    fracture_id = mesh.fracture_id[parent]

    if isinstance(mesh, Mesh3D):
        axis = np.cross(edges.ahead[parent, edge], mesh.normals[parent])
        rotation = _rotation(axis, theta)
        frames = np.einsum("mij,mkj->mki", rotation, mesh.frames[parent])
        grown = Mesh3D(centers, np.ascontiguousarray(frames), mesh.half_a[parent].copy(),
                       mesh.half_b[parent].copy(), fracture_id.copy())
    else:
        tangent = mesh.tangents[parent]
        normal = mesh.normals[parent]
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        sense = np.where(edge == 0, 1.0, -1.0)[:, None]  # +t end or -t end: keep the tangent's sense
        new_tangent = c * tangent + sense * s * normal
        new_normal = c * normal - sense * s * tangent
        grown = Mesh2D(centers, np.ascontiguousarray(np.stack([new_tangent, new_normal], axis=1)),
                       mesh.half_length[parent].copy(), fracture_id.copy())
    return (grown, parent, tip_rows) if return_tips else (grown, parent)
