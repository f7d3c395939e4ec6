"""The record of one time step (:attr:`hmatddm.Simulation.records`), the record of the
initial state (:func:`initial_record`), the fluid budget of every record
(:func:`fluid_budget`), and the view of a run's elements that output reads
(:meth:`hmatddm.Simulation.view`)."""
from dataclasses import asdict, dataclass, field
from enum import IntEnum

import numpy as np

from ..coupled.contact import OPEN, SLIP
from ..mesh import concatenate
from .state import Origin, StepEvents

RECORD_KEYS = ("time", "n_elements", "injected_volume", "fracture_volume", "fracture_area", "max_opening",
               "wellbore_pressure", "nonlinear_iterations", "linear_iterations", "solve_seconds")
_SOLVE_COUNTS = ("nonlinear_iterations", "linear_iterations", "elastic_products", "restarts", "contact_changes")


class ViewState(IntEnum):
    """What an element of :func:`output_view` is (the ``state`` of .vtu files)."""

    HYDRAULIC = 0       # a hydraulic-fracture element
    INTACT_NATURAL = 1  # an intact natural element (a stress target, not in the system)
    JOINED_NATURAL = 2  # a natural element in the system (activated, or failed remotely)


@dataclass
class StepTally:
    """What one step counted: its solves' iterations, the growth passes and what they
    added, the operator builds, and the :class:`~hmatddm.simulation.state.StepEvents`."""

    nonlinear_iterations: int = 0
    linear_iterations: int = 0
    elastic_products: int = 0
    restarts: int = 0
    contact_changes: int = 0
    elements_added: int = 0
    growth_passes: int = 0
    operator_builds: int = 0
    events: StepEvents = field(default_factory=StepEvents)

    def add_solve(self, info):
        """Count the solve whose :func:`hmatddm.coupled.solve_step` info is ``info``."""
        for key in _SOLVE_COUNTS:
            setattr(self, key, getattr(self, key) + info.get(key, 0))
        self.events.contact_frozen = max(self.events.contact_frozen, info.get("contact_frozen", 0))
        self.events.contact_violated = max(self.events.contact_violated, info.get("contact_violated", 0))


def step_record(simulation, flow, width, tally, relaxation, seconds, start=None):
    """The record of the step that led to ``simulation.state`` (its last solve's ``flow``
    model, ``width`` and relaxation ``relaxation``; ``seconds`` of wall time). With the
    step's ``start`` (a :class:`~hmatddm.simulation.state.StepStart`), the record has its
    fluid ``budget`` (:func:`fluid_budget`)."""
    sim = simulation
    previous = sim.records[-1] if sim.records else None
    record = _state_record(sim, sim.state, flow, width, tally, relaxation, seconds,
                           previous["time"] if previous else 0.0)
    if start is not None:
        before = previous.get("budget") if previous is not None else initial_budget(sim)
        if before is not None:  # (a record of a run checkpointed before budgets were recorded has none)
            record["budget"] = fluid_budget(sim, before, start, flow, record["time"] - record["time_step"])
    return record


def _state_record(sim, s, flow, width, tally, relaxation, seconds, previous_time):
    """The record's numbers of state ``s`` (see :func:`step_record`)."""
    mesh = s.mesh
    area = float(np.sum(flow.areas))
    record = dict(
        step=s.step, time=s.time, time_step=float(s.time - previous_time),
        n_elements=int(mesh.n_elements), injected_volume=s.injected_volume,
        fracture_volume=float(np.sum(flow.areas * width)), fracture_area=area, max_opening=float(np.max(width)),
        wellbore_pressure=[float(s.pressure[i]) for i in sim.injection_elements],
        nonlinear_iterations=int(tally.nonlinear_iterations), linear_iterations=int(tally.linear_iterations),
        matvecs=int(tally.elastic_products), solve_seconds=float(seconds), leaked_volume=s.leaked_volume,
        relaxation=float(relaxation),
        restarts=int(tally.restarts), elements_added=int(tally.elements_added),
        growth_passes=int(tally.growth_passes), operator_builds=int(tally.operator_builds))
    # fluid pressure weighted by the opening (issue 39): by Betti's reciprocity a crack's volume
    # is its pressure weighted by the opening under a unit uniform pressure, the opening's
    # shape near a K-vertex; so this is the pressure a uniform-pressure closed form (radial,
    # KGD K-vertex) predicts. The injection element's pressure adds the viscous drop of a
    # point source (log-singular in 3D: it grows as the element shrinks).
    held = flow.areas * np.maximum(width, 0.0)
    record["mean_pressure"] = float(np.sum(held * s.pressure) / np.sum(held)) if np.sum(held) > 0.0 else None
    record["junctions"] = int(tally.events.junctions)
    if sim.network is not None:
        record["natural_active"] = int(np.count_nonzero(s.origin == Origin.ACTIVATED))
        record["natural_failed"] = int(np.count_nonzero(s.origin == Origin.FAILED))
        record.update(asdict(tally.events))
    record["contact_changes"] = int(tally.contact_changes)
    if sim.contact != "none":
        natural = s.origin >= Origin.ACTIVATED if sim.contact == "natural" else np.ones(mesh.n_elements, bool)
        opening = np.sum(s.dd * mesh.normals, axis=1)
        slip = np.linalg.norm(s.dd - opening[:, None] * mesh.normals, axis=1)
        record["closed_elements"] = int(np.count_nonzero(natural & (s.contact_status != OPEN)))
        record["slipping_elements"] = int(np.count_nonzero(natural & (s.contact_status == SLIP)))
        record["max_slip"] = float(np.max(slip[natural], initial=0.0))
        record["min_opening"] = float(np.min(opening))
    if mesh.dim == 3:
        record["radius"] = float(np.sqrt(area / np.pi))
    else:
        record["half_length"] = float(np.sum(mesh.areas) / 2.0)
    if sim.medium is not None:
        record.update(height_growth(mesh, s.origin, sim.medium))
    if sim.proppant is not None:  # masses pumped, in place, screened out (hmatddm.simulation.proppant_step)
        from .proppant_step import record as proppant_record

        record.update(proppant_record(sim, s, flow, width))
    if sim.well is not None:
        record.update(well_record(sim, s, flow))
    return record


def well_record(simulation, state, flow):
    """A shared well's numbers (issue 35, :mod:`hmatddm.flow.well`) at ``state``, of its last
    solve's ``flow`` model: ``heel_pressure`` (Pa), ``pump_rate`` (the schedule's mean over the
    step, m^3/s), ``cluster_rates`` (into each cluster, m^3/s; they sum to the pump rate less
    the well's storage rate ``c_f V dp_h/dt``), ``cluster_pressures`` (the wellbore pressure at
    each cluster, the heel pressure less the wellbore friction, Pa), ``perforation_friction``
    (``a_c q_c |q_c|``, Pa) and ``wellbore_friction`` (heel to cluster, Pa); the fracture
    pressure at a cluster is ``wellbore_pressure`` (its element's)."""
    sim, link = simulation, flow.well
    system = sim.well_system
    if link is None:  # the initial state: the pump's rate at t = 0, nothing flowing yet
        n = len(sim.clusters)
        return dict(heel_pressure=float(state.heel_pressure), pump_rate=sim.well.schedule.rate(state.time),
                    cluster_rates=[0.0] * n, cluster_pressures=[float(state.heel_pressure)] * n,
                    perforation_friction=[0.0] * n, wellbore_friction=[0.0] * n)
    heel, rates = link.state(state.pressure)
    friction = np.zeros(len(rates)) if link.direct or link.last is None else link.last.friction
    return dict(heel_pressure=float(heel), pump_rate=float(link.pump_rate),
                cluster_rates=[float(q) for q in rates], cluster_pressures=[float(heel - w) for w in friction],
                perforation_friction=[float(v) for v in system.perforation_friction(rates)],
                wellbore_friction=[float(w) for w in friction])


def height_growth(mesh, origin, medium):
    """How far the hydraulic fractures reach up and down in a layered medium (ref. Ch. 3),
    along the vertical axis (z in 3D, the second coordinate in 2D, docs/conventions.md §3):
    ``top`` and ``bottom`` (m, the highest and lowest point of a hydraulic element),
    ``height = top - bottom``, the layer of the element at each (``top_layer``,
    ``bottom_layer``: 0 the top layer; :meth:`~hmatddm.layered.LayeredMedium.layer_of` of its
    centre) and ``interfaces_crossed`` (interfaces strictly between bottom and top)."""
    hydraulic = np.flatnonzero(origin == Origin.HYDRAULIC)
    if hydraulic.size == 0:
        return {}
    axis = mesh.dim - 1
    if mesh.dim == 3:
        points = mesh.subset(hydraulic).corners()[..., axis]          # (n, 4)
    else:
        ends = mesh.subset(hydraulic).endpoints
        points = np.stack([ends[0][:, axis], ends[1][:, axis]], axis=1)  # (n, 2)
    highest, lowest = np.max(points, axis=1), np.min(points, axis=1)
    top_element, bottom_element = hydraulic[np.argmax(highest)], hydraulic[np.argmin(lowest)]
    top, bottom = float(np.max(highest)), float(np.min(lowest))
    layers = medium.layer_of(mesh.centers[[top_element, bottom_element], axis])
    interfaces = np.asarray(medium.interfaces, dtype=float)
    return dict(height=top - bottom, top=top, bottom=bottom, top_layer=int(layers[0]), bottom_layer=int(layers[1]),
                interfaces_crossed=int(np.count_nonzero((interfaces < top) & (interfaces > bottom))))


# ---------------------------------------------------------------------------------
# The initial state and the fluid budget
# ---------------------------------------------------------------------------------

BUDGET_KEYS = ("injected", "initial", "fractures", "wellbore", "leaked", "residual")


def initial_record(simulation):
    """The record of the initial state (step 0, time 0): the initial fractures at
    ``initial_opening``, the pressure ``initial_pressure`` everywhere (the wellbores
    too), no iteration, and the initial fluid ``budget``. It has every key of a step's
    record, so that a table of the records starts at t = 0."""
    from .step_solve import mesh_topology

    sim = simulation
    state = sim._initial_state()
    _, faces = mesh_topology(state.mesh, sim.height)
    flow = sim.flow_model(state.mesh, faces)
    width = np.sum(state.dd * state.mesh.normals, axis=1)
    record = _state_record(sim, state, flow, width, StepTally(), state.relaxation, 0.0, 0.0)
    if sim.front is not None:  # the asymptotic front's measures of the initial elements
        record.update(sim.front.measures(state, sim))
        record["front_iterations"] = 0
    record["budget"] = initial_budget(sim)
    return record


def initial_budget(simulation):
    """The fluid budget at t = 0 (:func:`fluid_budget`): the initial fractures (their
    area times ``initial_opening``) and the wellbores, at the initial pressure."""
    sim = simulation
    mesh = sim.mesh0
    areas = mesh.areas * (sim.height if mesh.dim == 2 else 1.0)
    fractures = float(np.sum(areas) * sim.initial_opening)
    wellbore = float(sum(c.wellbore_volume for c in sim.clusters)) if sim.well is None else sim.well.volume
    budget = dict(injected=0.0, initial=fractures + wellbore, fractures=fractures, wellbore=wellbore, leaked=0.0,
                  residual=0.0, compression=0.0)
    if sim.network is not None:
        budget["natural"] = 0.0
    return budget


def fluid_budget(simulation, before, start, flow, time_old):
    """The fluid budget at the end of the step from ``time_old`` to ``simulation.state``:
    where the fluid pumped (``injected``) and present at t = 0 (``initial``) is, as
    volume at the reference density (the density at ``initial_pressure``, ref. Eq. 4.22):

    * ``fractures``: the volume of the openings plus the fluid stored in them by
      compression (``compression``, accumulated step by step as the storage term of
      ref. Eq. 4.36, ``c_f S_i w_i (p_i - p_i^n)``);
    * ``wellbore``: ``V_w (1 + c_f (p_w - p_0))`` of each cluster (of a shared well: its
      volume at the heel pressure, :mod:`hmatddm.flow.well`);
    * ``leaked``: Carter leak-off into the rock, ``S_i Lambda_i (p_i - p_r) dt`` per step
      (ref. Eqs 4.25-4.26);
    * ``natural`` (runs with natural fractures): the pore fluid that remotely failed
      natural elements held when a fluid path first joined them to a wellbore
      (drained failed elements are held at their failure pressure without a flow
      equation, ref. Sec. 5.3, so their fluid is the rock's, not the pump's);
    * ``residual = injected + initial (+ natural) - fractures - wellbore - leaked``.

    Summed over the elements, the fluxes of ref. Eq. 4.36 cancel, so ``residual``
    measures how well the step's solve satisfied the flow equations (the linear and
    nonlinear tolerances of the coupled solve) plus the difference between the width of
    the last iterate, which the storage term lags, and the final one.
    ``before`` is the budget at ``time_old``; ``start`` the step's
    :class:`~hmatddm.simulation.state.StepStart` (``w^n``, ``p^n``; new elements 0 and
    their parent's pressure); ``flow`` its last solve's :class:`~hmatddm.flow.LubricationModel`.
    """
    from .step_solve import drained

    sim, s = simulation, simulation.state
    mesh = s.mesh
    fed = np.ones(mesh.n_elements, bool)
    if sim.network is not None:  # drained failed elements: no flow equation (the pore fluid's)
        fed = ~drained(sim, mesh, flow.faces, s.origin)
    areas, c_f = flow.areas[fed], sim.fluid.compressibility
    width = np.sum(s.dd * mesh.normals, axis=1)[fed]
    pressure = s.pressure[fed]
    compression = before["compression"] + c_f * float(np.sum(areas * flow.effective_width(width)
                                                             * (pressure - start.pressure[fed])))
    volume = float(np.sum(areas * width))
    rate = flow.leak_off_rate(s.creation_time, time_old, s.time)[fed]
    leaked = before["leaked"] + (s.time - time_old) * float(
        np.sum(areas * rate * (pressure - sim.leak_off.pore_pressure)))
    if sim.well is None:
        wellbore = float(sum(c.wellbore_volume * (1.0 + c_f * (s.pressure[i] - sim.initial_pressure))
                             for c, i in zip(sim.clusters, sim.injection_elements)))
    else:  # a shared well stores at its heel pressure (hmatddm.flow.well)
        wellbore = sim.well.volume * (1.0 + c_f * (s.heel_pressure - sim.initial_pressure))
    budget = dict(injected=float(s.injected_volume), initial=before["initial"], fractures=volume + compression,
                  wellbore=wellbore, leaked=leaked, residual=0.0, compression=compression)
    sources = budget["injected"] + budget["initial"]
    if sim.network is not None:  # fluid the joined elements held before the step, not counted before
        budget["natural"] = before["natural"] + float(np.sum(areas * start.width[fed])) - (
            before["fractures"] - before["compression"])
        sources += budget["natural"]
    budget["residual"] = sources - budget["fractures"] - wellbore - leaked
    return budget


def worst_budget_residual(records):
    """``(residual, fluid moved, step)`` of the record whose budget closes worst relative to
    the fluid moved (:func:`fluid_moved`); None when no record has a budget."""
    worst = None
    for record in records:
        budget = record.get("budget")
        if not budget:
            continue
        moved = fluid_moved(budget)
        ratio = abs(budget["residual"]) / moved if moved > 0.0 else 0.0
        if worst is None or ratio > worst[0]:
            worst = (ratio, budget["residual"], moved, record["step"])
    return None if worst is None else worst[1:]


def fluid_moved(budget):
    """The fluid a budget moved, what its residual is measured against: the larger of the
    volume injected and the fluid in the fractures (a run without injection moves only
    the fluid it started with)."""
    return max(budget["injected"], budget["fractures"])


def output_view(simulation):
    """Every element of ``simulation`` for output: ``(mesh, dd, pressure, state)`` with the
    active elements first, then the intact natural elements (zero DD, the pore
    pressure); ``state``: :class:`ViewState` codes."""
    s, network = simulation.state, simulation.network
    state = np.where(s.origin >= Origin.ACTIVATED, ViewState.JOINED_NATURAL, ViewState.HYDRAULIC).astype(np.int64)
    if network is None or not np.any(s.intact):
        return s.mesh, s.dd, s.pressure, state
    intact = np.flatnonzero(s.intact)
    mesh = concatenate([s.mesh, network.mesh.subset(intact)])
    dd = np.concatenate([s.dd, np.zeros((len(intact), s.mesh.dim))])
    pressure = np.concatenate([s.pressure, np.full(len(intact), network.properties.pore_pressure)])
    natural = np.where(s.failed[intact], ViewState.JOINED_NATURAL, ViewState.INTACT_NATURAL).astype(np.int64)
    return mesh, dd, pressure, np.concatenate([state, natural])
