"""The coupled solve of one pass of a time step (ref. Sec. 4.4): the elasticity and flow
of the trial state's mesh from the start of the step, with contact on the elements that
may close (:mod:`hmatddm.coupled.contact`) and the pressure of remotely failed elements
that no fluid reaches held at their failure pressure."""
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..mesh import topology
from ..coupled import ElasticSolver, StepProblem, solve_step
from ..coupled.contact import ContactLaw, ContactModel
from ..flow import fracture_compliance
from . import proppant_step
from .linking import with_links
from .state import Origin


class SolvedMesh(NamedTuple):
    """What a solve built of its mesh, which the growth pass and the record reuse."""

    edges: object  # hmatddm.mesh.topology.Edges
    faces: object  # flow faces, intersection links included
    flow: object   # the LubricationModel


def contact_law(simulation, origin):
    """The :class:`~hmatddm.coupled.contact.ContactLaw` of elements with ``origin``
    (``simulation.contact`` says which may close; natural elements with their friction
    and cohesion)."""
    natural = origin >= Origin.ACTIVATED
    enabled = {"natural": natural, "all": np.ones_like(natural), "none": np.zeros_like(natural)}[simulation.contact]
    friction = np.zeros(len(origin))
    cohesion = np.zeros(len(origin))
    if simulation.network is not None:
        friction[natural] = simulation.network.properties.friction
        cohesion[natural] = simulation.network.properties.cohesion
    return ContactLaw(enabled, friction, cohesion)


class _MeshTopology:
    """The edges and flow faces of the last mesh asked for: a step's first solve works on
    the mesh of the previous step's last one, and the asymptotic front's iterations on one
    mesh until it grows (the mesh is immutable; a new mesh is a new object)."""

    def __init__(self):
        self.entry = (None, None, None)  # (mesh, height, (edges, faces)), replaced at once (threads)

    def __call__(self, mesh, height):
        cached_mesh, cached_height, value = self.entry
        if cached_mesh is not mesh or cached_height != height:
            edges = topology.element_edges(mesh, height)
            value = (edges, topology.element_faces(mesh, edges))
            self.entry = (mesh, height, value)
        return value


mesh_topology = _MeshTopology()
"""``mesh_topology(mesh, height)``: ``(edges, faces)`` of ``mesh``
(:func:`hmatddm.mesh.topology.element_edges`, :func:`~hmatddm.mesh.topology.element_faces`), kept for
the last mesh."""


def drained(simulation, mesh, faces, origin):
    """Remotely failed elements that no fluid path connects to an injection point."""
    failed = origin == Origin.FAILED
    if not np.any(failed):
        return failed
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = mesh.n_elements
    graph = coo_matrix((np.ones(faces.n_faces), (faces.first, faces.second)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    fed = np.isin(label, label[simulation.injection_elements])
    return failed & ~fed


def solve(simulation, trial, start, t_old, t_new, relaxation, provisional=False):
    """The coupled step of ``simulation`` from ``start`` (a
    :class:`~hmatddm.simulation.state.StepStart`) to ``t_new`` on the mesh of ``trial``
    (a :class:`~hmatddm.simulation.state.State`), from its DD and pressure with
    relaxation ``relaxation``: ``(trial with the solution, info, SolvedMesh)``;
    ``info`` is :func:`hmatddm.coupled.solve_step`'s plus ``contact_frozen``, ``contact_violated`` and
    ``drained`` (the remotely failed elements no fluid reaches).

    ``provisional=True``: the solution may be the first (loose) iterate, with
    ``info["pending"]`` not None; :func:`finish` converges it. The growth pass decides on
    it whether the mesh grows; only the solve of the mesh a step keeps is converged
    (:class:`~hmatddm.coupled.SchemeSettings` ``growth_check``)."""
    sim, mesh = simulation, trial.mesh
    edges, faces = mesh_topology(mesh, sim.height)
    faces = with_links(faces, trial.extra_faces)
    flow = sim.flow_model(mesh, faces, proppant_step.viscosity_factor(sim, trial, start.width),
                          well=sim.well_link(start, t_old, t_new))
    elastic = ElasticSolver(sim.operator(mesh), rtol=sim.settings.linear_rtol, contact_bases=sim.contact_bases)
    contact, fixed_pressure, pressure_guess = None, None, trial.pressure
    law = contact_law(sim, trial.origin)
    if np.any(law.enabled):
        contact = ContactModel(law, mesh.normals, start.dd, trial.contact_status, trial.slip_direction,
                               elastic.normal_stiffness(mesh.normals),
                               propped_width=proppant_step.propped_width(sim, trial))
    no_fluid = drained(sim, mesh, faces, trial.origin)
    if np.any(no_fluid):
        fixed_pressure = np.where(no_fluid, trial.failure_pressure, np.nan)
        pressure_guess = np.where(no_fluid, trial.failure_pressure, pressure_guess)
    problem = StepProblem(elastic=elastic, normals=mesh.normals, far_field=sim.far_field_traction(mesh), flow=flow,
                          compliance=fracture_compliance(mesh, sim.elastic_constants(mesh)), dt=t_new - t_old,
                          width_old=start.width, pressure_old=start.pressure,
                          leak_off_rate=flow.leak_off_rate(trial.creation_time, t_old, t_new),
                          contact=contact, fixed_pressure=fixed_pressure)
    # a step that may still be split gives up a relaxation that does not help; accelerated
    # iterates while the active set stands still (solve_step)
    dd, p, info = solve_step(problem, sim.settings, trial.dd.ravel(), pressure_guess, relaxation,
                             provisional=provisional, splittable=sim.splittable(), accelerate=True)
    info["drained"] = no_fluid
    return _with_solution(trial, problem, dd, p, info), info, SolvedMesh(edges, faces, flow)


def refine(trial, info):
    """``(trial, info)`` with the provisional solve's first iterate redone at
    ``first_linear_rtol`` (:meth:`hmatddm.coupled.schemes.PendingSolve.refine`: the growth
    pass decided on a looser one), still pending."""
    pending = info["pending"]
    dd, p, more = pending.refine()
    more["drained"] = info["drained"]
    return _with_solution(trial, pending.problem, dd, p, more), more


def finish(trial, info):
    """``(trial, info)`` of the converged solve whose provisional result is ``trial`` and
    ``info`` (from :func:`solve` with ``info["pending"]``); the new ``info`` counts the
    iterations after the provisional return."""
    pending = info["pending"]
    dd, p, more = pending.finish()
    more["drained"] = info["drained"]
    return _with_solution(trial, pending.problem, dd, p, more), more


def _with_solution(trial, problem, dd, p, info):
    """``trial`` holding the solution ``dd``, ``p`` of ``problem`` (and its contact
    statuses); adds ``contact_frozen`` and ``contact_violated`` to ``info``."""
    contact = problem.contact
    solution = dict(dd=dd.reshape(trial.mesh.n_elements, trial.mesh.dim), pressure=p)
    if contact is not None:
        solution.update(contact_status=contact.status.copy(), slip_direction=contact.direction.copy())
    info["contact_frozen"] = 0 if contact is None else contact.frozen
    info["contact_violated"] = getattr(contact, "violated", 0)
    return replace(trial, **solution)
