"""Proppant transport in the fracture elements (beyond the reference, which names it as its
next step, ref. Sec. 8.2 item 2): the slurry's proppant volume fraction advected with the
fluid, hindered gravitational settling, bridging in narrow openings, the packing limit and the
packed bed a closing element keeps.

The unknown is the proppant (solid) volume ``V_i = c_i S_i w_i`` of each element (``c`` the
volume fraction of the slurry, ``S_i`` the element's area, ``w_i`` its opening). Over a flow
step the faces carry the slurry fluxes ``F_e`` (m^3/s, first element to second, e.g.
:meth:`hmatddm.flow.LubricationModel.face_flux` of the converged step) and the proppant moves
by an explicit, conservative finite-volume scheme (:func:`transport`):

* advection, upwind: ``c_up F_e``;
* settling along the vertical axis (``z`` in 3D, the second coordinate of a 2D vertical
  cross-section: docs/conventions.md §3) at the hindered Stokes velocity
  ``v(c) = v_St (1 - c)^m``, ``v_St = (rho_p - rho_f) g d^2 / (18 mu)`` (Richardson and Zaki 1954,
  ``m`` = ``hindrance_exponent``), through the face area ``l_e w_e`` times the vertical part of
  the face's direction: ``c_up v(c_up) (-z . t_e) l_e w_e``, ``c_up`` the upper element's;
* bridging: a face whose narrower element is narrower than ``bridging_factor`` particle
  diameters (``min(w_i, w_j) < b d``) carries the fluid but no proppant;
* the packing limit ``c_max``: the proppant flux into an element never fills it past
  ``c_max S w`` (its incoming fluxes are scaled down, the proppant stays upstream), so
  concentrations stay in ``[0, c_max]``; an element that closes on more proppant than
  ``c_max S w`` holds it as a packed bed of propped width ``V / (c_max S)`` (:func:`propped_width`).

Every flux leaves one element and enters another, so the proppant volume is conserved to
round-off (injection and nothing else changes the total). The step is split into sub-steps
that keep the outflow of each element within its content (CFL number ``courant``, at most 1),
with the openings interpolated linearly over the step: with non-negative contents and
upwind fluxes the scheme is monotone (a uniform concentration stays uniform, no new extrema).

Slurry viscosity (:func:`slurry_viscosity_factor`): Maron and Pierce (1956),
``mu_s / mu = (1 - c / c_max)^-2``, which diverges at the packing limit.

This module is the transport engine and its physics, checked in ``tests/flow/test_proppant.py``;
:mod:`hmatddm.simulation.proppant_step` runs it after every time step of a
:class:`hmatddm.Simulation` (operator splitting) with the pump schedule of
:mod:`hmatddm.flow.pump_schedule`.
"""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..settings import PROPPANT

GRAVITY = 9.81  # m/s^2


@dataclass(frozen=True)
class Proppant:
    """Proppant particles in the slurry (declarations: ``hmatddm.settings.PROPPANT``).

    Parameters
    ----------
    diameter : float
        Particle diameter d, m, > 0.
    density : float
        Particle density rho_p, kg/m^3, > 0 (quartz sand 2650).
    fluid_density : float
        Carrier fluid density rho_f, kg/m^3, > 0.
    packing_limit : float
        c_max in (0, 1): the volume fraction of a packed bed.
    bridging_factor : float
        b >= 1: faces narrower than b d carry no proppant.
    hindrance_exponent : float
        m >= 0 of the hindered settling ``(1 - c)^m`` (Richardson and Zaki: 4.65 at low
        Reynolds numbers).
    """

    diameter: float
    density: float = 2650.0
    fluid_density: float = 1000.0
    packing_limit: float = 0.6
    bridging_factor: float = 3.0
    hindrance_exponent: float = 4.65

    def __post_init__(self):
        for name in ("diameter", "density", "fluid_density", "packing_limit", "bridging_factor",
                     "hindrance_exponent"):
            object.__setattr__(self, name, PROPPANT[name].value(f"proppant.{name}", getattr(self, name)))

    def stokes_velocity(self, viscosity):
        """``v_St = (rho_p - rho_f) g d^2 / (18 mu)``, m/s (downward when positive)."""
        if not viscosity > 0.0:
            raise InputError(f"viscosity must be > 0 Pa s, got {viscosity}")
        return (self.density - self.fluid_density) * GRAVITY * self.diameter**2 / (18.0 * viscosity)

    def settling_velocity(self, concentration, viscosity):
        """Hindered settling velocity ``v_St (1 - c)^m`` at volume fractions ``c``, m/s."""
        c = np.clip(np.asarray(concentration, float), 0.0, 1.0)
        return self.stokes_velocity(viscosity) * (1.0 - c) ** self.hindrance_exponent

    def check_concentration(self, name, concentration):
        """``concentration`` as an array in [0, c_max); an InputError naming ``name`` otherwise."""
        c = finite_array(name, concentration)
        if np.any(c < 0.0) or np.any(c >= self.packing_limit):
            bad = c[(c < 0.0) | (c >= self.packing_limit)].ravel()[0]
            raise InputError(f"{name} must be in [0, {self.packing_limit:g}) (below proppant.packing_limit), "
                             f"got {bad:g}")
        return c


def slurry_viscosity_factor(concentration, packing_limit):
    """Maron-Pierce ``mu_slurry / mu = (1 - c / c_max)^-2`` (inf at and above the limit)."""
    ratio = np.asarray(concentration, float) / packing_limit
    with np.errstate(divide="ignore"):
        return np.where(ratio < 1.0, (1.0 - np.minimum(ratio, 1.0)) ** -2.0, np.inf)


#: The largest slurry viscosity factor the flow sees (Maron-Pierce at c = 0.9 c_max): a packed
#: bed still conducts the carrier fluid through its pores, where the suspension law diverges.
MAX_VISCOSITY_FACTOR = 100.0


def flow_viscosity_factor(concentration, packing_limit):
    """:func:`slurry_viscosity_factor` capped at :data:`MAX_VISCOSITY_FACTOR` (what the
    lubrication flow of a time step takes, :mod:`hmatddm.flow.lubrication`)."""
    return np.minimum(slurry_viscosity_factor(concentration, packing_limit), MAX_VISCOSITY_FACTOR)


def propped_width(volume, areas, packing_limit):
    """Width ``V / (c_max S)`` of the packed bed that proppant volume ``V`` forms (m): the width an
    element closing on it keeps."""
    return np.asarray(volume, float) / (packing_limit * np.asarray(areas, float))


@dataclass
class TransportGeometry:
    """What the transport needs of a mesh: element areas ``S`` (N,), face topology (``first``,
    ``second``, ``length``: :class:`hmatddm.mesh.topology.Faces`), element centres (N, d) and the
    unit vertical (d,) (``None``: no settling, e.g. a 2D plan view)."""

    areas: np.ndarray
    first: np.ndarray
    second: np.ndarray
    length: np.ndarray
    centers: np.ndarray
    vertical: np.ndarray = None

    @classmethod
    def of(cls, areas, faces, centers, vertical=None):
        return cls(np.asarray(areas, float), np.asarray(faces.first, np.int64), np.asarray(faces.second, np.int64),
                   np.asarray(faces.length, float), np.asarray(centers, float),
                   None if vertical is None else np.asarray(vertical, float))

    def face_slope(self):
        """``z . t_e`` of every face: the vertical part of the unit direction first -> second."""
        if self.vertical is None:
            return np.zeros(len(self.first))
        direction = self.centers[self.second] - self.centers[self.first]
        direction /= np.linalg.norm(direction, axis=1)[:, None]
        return direction @ self.vertical


def transport(geometry, proppant, volume, width_old, width_new, face_flux, dt, viscosity,
              injection=None, courant=0.9):
    """Advance the proppant volumes ``volume`` (N,) over a flow step of length ``dt``.

    ``width_old``/``width_new``: element openings at the start and end of the step (m),
    ``face_flux``: slurry flux of every face, first -> second (m^3/s), ``viscosity``: carrier
    fluid viscosity for settling (Pa s), ``injection``: proppant volume rate into each element
    (m^3/s, e.g. ``c_pumped q_w`` at the clusters). Returns ``(volume, substeps, screened_out)``:
    the total changes by ``dt * sum(injection) - screened_out``, the injected proppant that found
    no room (an injection element packed to ``c_max``: a screen-out; it stays in the wellbore).
    Elements never exceed ``c_max S w_new`` unless they held more at the start (a closing
    packed bed, :func:`propped_width`)."""
    volume = np.array(volume, dtype=np.float64)
    areas = geometry.areas
    n = len(areas)
    first, second = geometry.first, geometry.second
    face_flux = np.asarray(face_flux, float)
    injection = np.zeros(n) if injection is None else np.asarray(injection, float)
    if np.any(volume < 0.0) or np.any(injection < 0.0):
        raise InputError("proppant volumes and injection rates must be >= 0")
    slope = geometry.face_slope()
    c_max = proppant.packing_limit
    w_old, w_new = (np.maximum(np.asarray(w, float), 0.0) for w in (width_old, width_new))

    def face_width(w):
        return 0.5 * (w[first] + w[second])

    def rates(w, v):
        """Proppant volume flux of every face (first -> second) at openings ``w``, volumes ``v``."""
        slurry = np.maximum(areas * w, 1e-300)
        c = np.clip(v / slurry, 0.0, c_max)
        open_face = np.minimum(w[first], w[second]) >= proppant.bridging_factor * proppant.diameter
        up = np.where(face_flux >= 0.0, c[first], c[second])
        advection = up * face_flux
        # settling: downward velocity; the upper element of the face is upwind
        upper = np.where(slope < 0.0, c[first], c[second])  # slope < 0: second lies below first
        speed = proppant.settling_velocity(upper, viscosity) * geometry.length * face_width(w)
        settling = -slope * upper * speed
        return np.where(open_face, advection + settling, 0.0)

    def outflow_rate(flux):
        out = np.zeros(n)
        np.add.at(out, first, np.maximum(flux, 0.0))
        np.add.at(out, second, np.maximum(-flux, 0.0))
        return out

    # sub-steps (CFL): the slurry leaving an element per sub-step is at most `courant` of its
    # volume (the fluid fluxes, and the settling through the faces below it), counted on the
    # faces that may carry proppant in the step (both sides at least b d wide at one end of
    # it; a bridged face carries none), whose elements then hold at least S b d of slurry
    bridge = proppant.bridging_factor * proppant.diameter
    widest = np.maximum(w_old, w_new)
    may_carry = np.minimum(widest[first], widest[second]) >= bridge
    slurry_volume = areas * np.maximum(np.minimum(w_old, w_new), bridge)
    settling_rate = proppant.settling_velocity(0.0, viscosity) * geometry.length * np.maximum(
        face_width(w_old), face_width(w_new)) * np.abs(slope)
    leaving = np.zeros(n)
    np.add.at(leaving, first, np.where(may_carry, np.maximum(face_flux, 0.0)
                                       + np.where(slope < 0.0, settling_rate, 0.0), 0.0))
    np.add.at(leaving, second, np.where(may_carry, np.maximum(-face_flux, 0.0)
                                        + np.where(slope > 0.0, settling_rate, 0.0), 0.0))
    rate_scale = float(np.max(leaving / slurry_volume, initial=0.0))
    substeps = max(1, int(np.ceil(dt * rate_scale / courant)))
    tau = dt / substeps
    rejected = 0.0
    for k in range(substeps):
        s = (k + 0.5) / substeps
        w = (1.0 - s) * w_old + s * w_new
        w_end = (1.0 - (k + 1.0) / substeps) * w_old + (k + 1.0) / substeps * w_new
        flux = rates(w, volume)
        # never send more than an element holds (the CFL bound above, held exactly)
        out = outflow_rate(flux) * tau
        keep = np.where(out > volume, volume / np.maximum(out, 1e-300), 1.0)
        flux = flux * np.where(flux >= 0.0, keep[first], keep[second])
        # the packing limit: scale the incoming fluxes of an element that would overfill (the
        # proppant stays upstream; passes repeat while a held-back flux overfills its sender)
        capacity = c_max * areas * w_end
        receiving = np.where(flux >= 0.0, second, first)
        for _ in range(n + 1):
            inflow = np.zeros(n)
            np.add.at(inflow, receiving, np.abs(flux) * tau)
            room = np.maximum(capacity - (volume - outflow_rate(flux) * tau), 0.0)
            full = inflow > room * (1.0 + 1e-12)
            if not np.any(full):
                break
            scale = np.where(full, room / np.maximum(inflow, 1e-300), 1.0)
            flux = flux * scale[receiving]
        # injection fills what room is left; the rest screens out (stays in the wellbore)
        inflow = np.zeros(n)
        np.add.at(inflow, receiving, np.abs(flux) * tau)
        room = np.maximum(capacity - (volume - outflow_rate(flux) * tau) - inflow, 0.0)
        placed = np.minimum(injection * tau, room)
        rejected += float(np.sum(injection * tau - placed))
        volume = np.maximum(volume + placed - outflow_rate(flux) * tau + inflow, 0.0)
    return volume, substeps, rejected
