"""Proppant in the time loop of a :class:`hmatddm.Simulation` (issue 34, beyond the reference,
which names proppant transport as its next step: ref. Sec. 8.2 item 2).

The state carries the proppant (solid) volume ``V_i`` of every element
(:attr:`~hmatddm.simulation.state.State.proppant_volume`; an element a growth pass adds starts
empty) and the proppant pumped and screened out so far. Each time step is split into two
operators:

1. the coupled solve (ref. Sec. 4.4, :mod:`hmatddm.simulation.step_solve`) with the slurry
   viscosity of the concentrations at the start of the step, ``c_i = V_i / (S_i w_i^n)``
   (Maron-Pierce, capped at :data:`hmatddm.flow.proppant.MAX_VISCOSITY_FACTOR`:
   :func:`viscosity_factor`), and, where elements may close (``contact``), the packed bed's
   width ``V_i / (c_max S_i)`` as the opening a closed element keeps (:func:`propped_width`,
   :class:`hmatddm.coupled.contact.ContactModel`);
2. then the proppant transport (:func:`hmatddm.flow.proppant.transport`) over the step with the
   face fluxes of the converged flow (ref. Eq. 4.36's ``K_e (p_i - p_j)``, or the power-law flux:
   :meth:`hmatddm.flow.LubricationModel.face_flux`), the openings interpolated between the step's
   start and end (effective widths of the flow, the ``minimum_width`` floor included), hindered
   settling along the vertical axis of docs/conventions.md §3 (z in 3D; the second coordinate of
   a 2D vertical cross-section, i.e. a layered 2D run; none in a 2D plan view), bridging and the
   packing limit; the clusters inject ``q c(t)`` of the pump schedule
   (:class:`hmatddm.flow.pump_schedule.PumpSchedule`, integrated exactly over the step).

The splitting lags the slurry viscosity by one step (first order in time, as the widths of
ref. Eq. 4.36 are lagged within a step). The proppant is not in the wellbore's storage: the
slurry enters the fractures as it is pumped. Proppant that finds an injection element packed
(a screen-out) stays in the wellbore and is counted apart, so the balance
``injected = in fractures + screened out`` holds to round-off every step.
"""
import numpy as np

from ..flow.proppant import TransportGeometry, flow_viscosity_factor, propped_width as bed_width, transport


def vertical_axis(simulation, dim):
    """The unit vertical of docs/conventions.md §3, or None for a 2D plan view (no settling)."""
    if dim == 3:
        return np.array([0.0, 0.0, 1.0])
    if simulation.medium is not None:  # a 2D vertical cross-section (layers declared)
        return np.array([0.0, 1.0])
    return None


def carrier_viscosity(fluid):
    """The viscosity the particles settle through, Pa s: a Newtonian fluid's; a power-law fluid's
    apparent viscosity ``K gamma_0^(n-1)`` at its ``minimum_shear_rate`` (the Newtonian plateau of
    the truncated power law, :mod:`hmatddm.flow.lubrication`: a settling particle shears the
    fluid far less than the fracture flow does)."""
    if not fluid.power_law:
        return fluid.viscosity
    return fluid.consistency * fluid.minimum_shear_rate ** (fluid.flow_index - 1.0)


def flow_areas(simulation, mesh):
    """Element areas of the flow (2D: length times the flow height), m^2."""
    return mesh.areas * (simulation.height if mesh.dim == 2 else 1.0)


def concentration(simulation, volume, width, areas):
    """Proppant volume fractions ``V / (S max(w, w_min))`` in [0, c_max] of ``simulation``'s
    elements (:func:`volume_fraction`)."""
    return volume_fraction(volume, width, areas, simulation.minimum_width, simulation.proppant.packing_limit)


def volume_fraction(volume, width, areas, minimum_width, packing_limit):
    """Proppant volume fractions ``V / (S max(w, w_min))`` clipped to [0, c_max]: proppant
    volumes ``V`` (m^3) in elements of flow areas ``S`` (m^2) and openings ``w`` (m), the flow's
    width floor ``w_min``."""
    slurry = np.asarray(areas, float) * np.maximum(width, minimum_width)
    return np.clip(np.asarray(volume, float) / slurry, 0.0, packing_limit)


def viscosity_factor(simulation, state, start_width):
    """Per element of ``state``'s mesh, the slurry viscosity factor the coupled solve of a step
    takes (the concentrations at its start, ``start_width`` the openings ``w^n``); None
    without proppant."""
    if simulation.proppant is None:
        return None
    areas = flow_areas(simulation, state.mesh)
    c = concentration(simulation, state.proppant_volume, start_width, areas)
    return flow_viscosity_factor(c, simulation.proppant.packing_limit)


def propped_width(simulation, state):
    """Per element, the width of the packed bed its proppant forms, ``V / (c_max S)`` (m): the
    opening a closing element keeps; None without proppant."""
    if simulation.proppant is None:
        return None
    return bed_width(state.proppant_volume, flow_areas(simulation, state.mesh), simulation.proppant.packing_limit)


def advance(simulation, begin, trial, start, flow, t_old, t_new):
    """The proppant of ``trial`` (the converged solve of the step from ``begin``) moved over the
    step: the :class:`~hmatddm.simulation.state.State` fields ``proppant_volume``,
    ``proppant_injected_volume``, ``proppant_screened_volume`` and ``proppant_substeps``
    (a dict; empty without proppant). ``start`` is the step's
    :class:`~hmatddm.simulation.state.StepStart` (new elements at zero opening), ``flow`` its
    last solve's :class:`~hmatddm.flow.LubricationModel`."""
    sim = simulation
    if sim.proppant is None:
        return {}
    mesh = trial.mesh
    dt = t_new - t_old
    width_new = np.sum(trial.dd * mesh.normals, axis=1)
    geometry = TransportGeometry.of(flow.areas, flow.faces, mesh.centers, vertical_axis(sim, mesh.dim))
    # the pumped proppant: q c(t) of every cluster, its exact mean over the step
    pumped = sim.pump_schedule.integral(t_old, t_new)
    injection = np.zeros(mesh.n_elements)
    rates = np.maximum(flow.cluster_rates(trial.pressure), 0.0)  # (a shared well's: the step's; no backflow of sand)
    np.add.at(injection, sim.injection_elements, rates * pumped / dt)
    face_flux = flow.face_flux(width_new, trial.pressure)
    volume, substeps, screened = transport(geometry, sim.proppant, trial.proppant_volume,
                                           flow.effective_width(start.width), flow.effective_width(width_new),
                                           face_flux, dt, carrier_viscosity(sim.fluid), injection=injection)
    return dict(proppant_volume=volume,
                proppant_injected_volume=begin.proppant_injected_volume + float(np.sum(rates)) * pumped,
                proppant_screened_volume=begin.proppant_screened_volume + screened,
                proppant_substeps=int(substeps))


def record(simulation, state, flow, width):
    """The proppant numbers of a step's record: masses (kg) pumped
    (``proppant_injected_mass``), in the fractures (``proppant_mass``), screened out
    (``proppant_screened_mass``), the balance ``proppant_residual = injected - in fractures -
    screened out`` (kg), the largest volume fraction (``max_proppant_fraction``), the
    elements holding proppant, the transport's sub-steps of the step."""
    sim = simulation
    density = sim.proppant.density
    volume = state.proppant_volume
    injected = density * state.proppant_injected_volume
    in_place = density * float(np.sum(volume))
    screened = density * state.proppant_screened_volume
    c = concentration(sim, volume, width, flow.areas)
    return dict(proppant_injected_mass=injected, proppant_mass=in_place, proppant_screened_mass=screened,
                proppant_residual=injected - in_place - screened,
                max_proppant_fraction=float(np.max(c, initial=0.0)),
                propped_elements=int(np.count_nonzero(volume > 0.0)),
                proppant_substeps=int(state.proppant_substeps or 0))


def cell_fields(simulation):
    """``proppant_fraction`` and ``propped_width`` of every element of
    :meth:`hmatddm.Simulation.view` (the intact natural elements after the active ones hold
    none); {} without proppant."""
    sim = simulation
    if sim.proppant is None:
        return {}
    s = sim.state
    areas = flow_areas(sim, s.mesh)
    width = np.sum(s.dd * s.mesh.normals, axis=1)
    fraction = concentration(sim, s.proppant_volume, width, areas)
    propped = bed_width(s.proppant_volume, areas, sim.proppant.packing_limit)
    n_view = sim.view()[0].n_elements
    extra = n_view - s.mesh.n_elements
    return {"proppant_fraction": np.concatenate([fraction, np.zeros(extra)]),
            "propped_width": np.concatenate([propped, np.zeros(extra)])}


__all__ = ["advance", "record", "cell_fields", "viscosity_factor", "propped_width", "vertical_axis",
           "carrier_viscosity", "concentration", "volume_fraction"]
