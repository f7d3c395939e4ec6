"""The record of one time step (:attr:`hmatddm.Simulation.records`), and the view of a
run's elements that output reads (:meth:`hmatddm.Simulation.view`)."""
from dataclasses import asdict, dataclass, field
from enum import IntEnum

import numpy as np

from ..coupled.contact import OPEN, SLIP
from ..mesh import concatenate
from .state import Origin, StepEvents

RECORD_KEYS = ("time", "n_elements", "injected_volume", "fracture_volume", "fracture_area", "max_opening",
               "wellbore_pressure", "nonlinear_iterations", "linear_iterations", "solve_seconds")
_SOLVE_COUNTS = ("nonlinear_iterations", "linear_iterations", "restarts", "contact_changes")


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


def step_record(simulation, flow, width, tally, relaxation, seconds):
    """The record of the step that led to ``simulation.state`` (its last solve's ``flow``
    model, ``width`` and relaxation ``relaxation``; ``seconds`` of wall time)."""
    sim, s = simulation, simulation.state
    mesh = s.mesh
    area = float(np.sum(flow.areas))
    record = dict(
        step=s.step, time=s.time, time_step=float(s.time - (sim.records[-1]["time"] if sim.records else 0.0)),
        n_elements=int(mesh.n_elements), injected_volume=s.injected_volume,
        fracture_volume=float(np.sum(flow.areas * width)), fracture_area=area, max_opening=float(np.max(width)),
        wellbore_pressure=[float(s.pressure[i]) for i in sim.injection_elements],
        nonlinear_iterations=int(tally.nonlinear_iterations), linear_iterations=int(tally.linear_iterations),
        solve_seconds=float(seconds), leaked_volume=s.leaked_volume, relaxation=float(relaxation),
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
    return record


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
