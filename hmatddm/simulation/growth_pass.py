"""One growth pass of a time step (ref. Fig. 4.1): the elements and flow connections to
add after a solve, or None when nothing grows.

Tips that grow (ref. Sec. 4.2.2) add elements ahead of them
(:func:`hmatddm.fracture.new_elements`); in a layered medium they are cut at the
interfaces; a candidate that would cut another hydraulic fracture stops there
(:mod:`~hmatddm.simulation.junctions`); with natural fractures, each candidate is checked
against them (:mod:`~hmatddm.simulation.encounters`). When no tip grows, intact natural
elements that fail remotely (ref. Sec. 5.3) join instead.
"""
import numpy as np

from ..mesh import topology
from ..fracture import evaluate_tips, new_elements
from .encounters import meet_natural_fractures
from .junctions import stop_at_other_fractures
from .state import Growth, NewElements, Origin

#: What :func:`grow` returns with a ``margin`` when a tip's criterion is that close to its
#: threshold: the iterate is not accurate enough to decide.
UNCERTAIN = "uncertain"

#: A growth pass decided on a paused iterate (GMRES at relative residual ``level``,
#: :func:`hmatddm.coupled.schemes.pause_levels`) refuses to decide when a tip is within
#: ``PAUSED_MARGIN_PER_RTOL * level`` of its threshold: over the h = 0.5 m radial K-vertex
#: run the tips' ``K / K_Ic`` of such iterates differed from the plain first iterate's by
#: at most 2.6e-2 at level 1e-4 and 1.5e-3 at 1e-5 (RESULTS.md, issue 17, fifth pass).
PAUSED_MARGIN_PER_RTOL = 500.0


def paused_margin(level):
    """The margin of :func:`grow` for an iterate paused at relative residual ``level``."""
    return PAUSED_MARGIN_PER_RTOL * level


def grow(simulation, state, edges, faces, drained, events, margin=None):
    """The :class:`~hmatddm.simulation.state.Growth` of the tips of ``state`` (``edges``,
    ``faces``: its mesh's, as solved) or None. Tips of ``drained`` elements (remotely
    failed, not reached by the fluid) do not grow; ``events`` counts what happened.
    ``margin``: :data:`UNCERTAIN` when a tip's criterion (``K / K_Ic`` or ``G / G_c``,
    ref. Eqs 4.18-4.19; in a layered medium against the layer ahead's toughness) is within
    ``margin`` of 1."""
    sim, mesh = simulation, state.mesh
    element, edge = topology.tip_edges(mesh, faces, edges)
    if sim.growing_fractures is not None:
        keep = np.isin(mesh.fracture_id[element], sim.growing_fractures)
        element, edge = element[keep], edge[keep]
    if drained is not None and np.any(drained):
        keep = ~drained[element]
        element, edge = element[keep], edge[keep]
    if element.size == 0:
        return None
    materials = sim.elastic_constants(mesh, element)
    tips = evaluate_tips(mesh, edges, element, edge, state.dd, materials, sim.propagation)
    toughness = None  # the propagation's
    if sim.medium is not None:  # per-layer toughness; new elements end on interfaces
        from ..layered import engine as layered_engine

        layers = layered_engine.layers_ahead(edges, element, edge, sim.medium)
        tips = layered_engine.tip_criterion(tips, materials, layers, sim.medium, sim.propagation)
        if sim.medium.toughness is not None:
            toughness = np.asarray(sim.medium.toughness)[layers]
    if margin is not None and _closest_call(tips, sim.propagation, materials, toughness) < margin:
        return UNCERTAIN
    candidates = new_elements(mesh, edges, tips, sim.propagation, return_tips=True)
    if candidates is None:
        return None
    grown, parent, rows = candidates
    # cut at interfaces (3D: also between equal layers, the 3D kernels refuse straddling rectangles)
    if sim.medium is not None and (mesh.dim == 3 or not layered_engine.uniform(sim.medium)):
        grown, parent, rows = layered_engine.split_new_elements(grown, parent, rows, sim.medium, mesh)
        if grown is None:
            return None
    grown, parent, rows, junctions = stop_at_other_fractures(mesh, edges, tips, grown, parent, rows, state.origin,
                                                             events)
    if grown is None:
        return Growth(None, junctions)
    if sim.network is None:
        return Growth(NewElements.hydraulic(grown, parent), junctions)
    elements, connections = meet_natural_fractures(sim, state, edges, faces, tips, grown, parent, rows, events)
    connections = junctions + connections
    if elements is None and not connections:
        return None
    return Growth(elements, connections)


def _closest_call(tips, propagation, material, toughness=None):
    """The smallest ``|criterion / threshold - 1|`` over ``tips`` (ref. Eqs 4.18-4.19), the
    thresholds those the tips were judged by: ``toughness`` per tip (the layer ahead's,
    :func:`hmatddm.layered.engine.tip_criterion`) or, when None, the propagation's."""
    if propagation.criterion == "mcs":
        ratio = tips.k_bar / (propagation.toughness if toughness is None else toughness)
    else:
        g_c = propagation.critical_energy_release_rate if toughness is None else None
        if g_c is None:
            g_c = (propagation.toughness if toughness is None else toughness)**2 / material.plane_strain_modulus
        ratio = tips.energy_release_rate / g_c
    return float(np.min(np.abs(ratio - 1.0)))


def remote_failures(simulation, state, events):
    """Intact natural elements of ``state`` that fail (ref. Sec. 5.3) as the
    :class:`~hmatddm.simulation.state.Growth` that adds them (no parent, at the pore
    pressure plus the undrained change, ref. Eq. 5.18), or None."""
    sim = simulation
    if sim.network is None or not sim.remote_failure or not np.any(state.intact):
        return None
    material, far_field, layered = sim.material, sim.far_field_stress, {}
    if sim.medium is not None:  # images, and each natural element's layer (hmatddm.layered.engine)
        from ..layered import engine as layered_engine

        material, far_field, nu = layered_engine.remote_failure_setting(sim.network.mesh, sim.medium, far_field)
        layered = dict(poisson_ratio=nu, n_images=sim.base_operator.stats.get("n_images"))
    # screened: only the targets that the stress bound leaves able to fail are evaluated
    failed, _, _, pore_change = sim.network.remote_failure(state.mesh, state.dd, material, far_field, state.intact,
                                                           sim.operator_settings.singular_correction, screen=True,
                                                           **layered)
    index = np.flatnonzero(failed)
    if index.size == 0:
        return None
    events.natural_newly_failed += int(index.size)
    m = index.size
    pressure = sim.network.properties.pore_pressure + pore_change[index]
    return Growth(NewElements(sim.network.mesh.subset(index), -np.ones(m, np.int64), np.full(m, Origin.FAILED, np.int64),
                              index.astype(np.int64), pressure))
