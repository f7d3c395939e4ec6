"""What the time loop carries from one step to the next (ref. Ch. 4, Fig. 4.1), and how
it grows when a growth pass adds elements or connections.

:class:`State` is everything a checkpoint holds; :class:`StepStart` the start-of-step
values the coupled step compares with; a growth pass (:mod:`hmatddm.simulation.growth_pass`)
returns a :class:`Growth` (:class:`NewElements` and :class:`Connection`\\ s) that both
extend themselves with (:meth:`State.joined`, :meth:`StepStart.joined`).
"""
from dataclasses import dataclass, field, fields, replace
from enum import IntEnum

import numpy as np

from ..coupled.contact import OPEN, STICK
from ..fracture.front import EMPTY
from ..mesh import Mesh2D, Mesh3D, concatenate


class Origin(IntEnum):
    """How an element joined the system (:attr:`State.origin`)."""

    HYDRAULIC = 0  # initial or grown hydraulic-fracture element
    ACTIVATED = 1  # natural-fracture element the fluid reached (ref. Ch. 5)
    FAILED = 2     # natural-fracture element that failed remotely (ref. Sec. 5.3)


@dataclass(frozen=True)
class Connection:
    """A flow face between a tip element and an element it reached at an intersection
    (ref. Sec. 6.2.3): a natural element (activated or already in the system) or an
    element of another hydraulic fracture (a junction)."""

    tip: int                # the tip element (an index of the mesh before the pass)
    target: int             # the element reached: a mesh index, or with ``target_is_new``
    target_is_new: bool     # an index among the new elements of the same pass
    length: float           # face length, m (2D: the flow height)
    tip_distance: float     # d_i: from the tip centre to the face, m
    target_distance: float  # d_j: from the target centre to the face, m
    tip_edge: int           # the tip edge the face leaves from

    def face(self, first_new):
        """The :attr:`State.extra_faces` row ``(i, j, length, d_i, d_j, edge of i)``; new
        elements are numbered from ``first_new``."""
        target = first_new + self.target if self.target_is_new else self.target
        return [self.tip, target, self.length, self.tip_distance, self.target_distance, self.tip_edge]

    def shifted(self, offset):
        """The connection with a new target numbered ``offset`` places later."""
        return replace(self, target=self.target + offset) if self.target_is_new else self


@dataclass
class NewElements:
    """Elements that join the system in one growth pass."""

    mesh: object               # their geometry (Mesh2D or Mesh3D)
    parent: np.ndarray         # (m,) the element each grew from; -1: none (remote failure)
    origin: np.ndarray         # (m,) Origin codes
    natural_index: np.ndarray  # (m,) index in the natural mesh, -1 for hydraulic elements
    pressure: np.ndarray       # (m,) pressure of elements without a parent (NaN for the others)

    @classmethod
    def hydraulic(cls, mesh, parent):
        """New hydraulic elements grown from ``parent``."""
        m = mesh.n_elements
        return cls(mesh, parent, np.zeros(m, np.int64), -np.ones(m, np.int64), np.full(m, np.nan))

    @property
    def has_parent(self):
        return self.parent >= 0

    def from_parent(self, values, otherwise):
        """Per new element: ``values`` of its parent, or ``otherwise`` where it has none."""
        return np.where(self.has_parent, values[np.maximum(self.parent, 0)], otherwise)

    def first_guess(self, dd, minimum_width):
        """The DD a new element starts the iterations from: its parent's, an open
        ``minimum_width`` for an activated natural element, zero for a failed one."""
        guess = np.where(self.has_parent[:, None], dd[np.maximum(self.parent, 0)], 0.0)
        activated = self.origin == Origin.ACTIVATED
        guess[activated] = minimum_width * self.mesh.normals[activated]
        return guess


@dataclass
class Growth:
    """What one growth pass adds: new elements (None when the pass only connects tips
    to elements already in the system) and flow connections."""

    elements: NewElements = None
    connections: list = field(default_factory=list)


@dataclass
class StepEvents:
    """What happened in one step besides the solves (counted into its record)."""

    natural_crossed: int = 0       # tips that crossed an intact natural element
    natural_deflected: int = 0     # tips deflected into (activating) a natural element
    natural_newly_failed: int = 0  # intact natural elements that failed remotely
    contact_frozen: int = 0        # contact elements frozen by the contact iterations (largest)
    contact_violated: int = 0      # ... of them violating their contact conditions at convergence (largest)
    junctions: int = 0             # tips stopped at another hydraulic fracture


def mesh_arrays(mesh):
    """The arrays that define ``mesh`` (checkpoints, fingerprints)."""
    if isinstance(mesh, Mesh3D):
        return dict(centers=mesh.centers, frames=mesh.frames, half_a=mesh.half_a, half_b=mesh.half_b,
                    fracture_id=mesh.fracture_id)
    return dict(centers=mesh.centers, frames=mesh.frames, half_length=mesh.half_length,
                fracture_id=mesh.fracture_id)


def mesh_from_arrays(arrays):
    """The mesh :func:`mesh_arrays` wrote."""
    if "half_a" in arrays:
        return Mesh3D(arrays["centers"], arrays["frames"], arrays["half_a"], arrays["half_b"],
                      arrays["fracture_id"].astype(np.int64))
    return Mesh2D(arrays["centers"], arrays["frames"], arrays["half_length"], arrays["fracture_id"].astype(np.int64))


_SCALARS = ("time", "step", "relaxation", "injected_volume", "leaked_volume", "time_step")
_ALWAYS = ("dd", "pressure", "creation_time", "origin", "natural_index", "intact", "failed", "extra_faces",
           "contact_status", "slip_direction", "failure_pressure")
_FRONT = ("front_distance", "front_velocity", "front_class")
_PROPPANT = ("proppant_injected_volume", "proppant_screened_volume", "proppant_substeps")


@dataclass
class State:
    """What the loop carries between steps (all of it goes into a checkpoint)."""

    mesh: object
    dd: np.ndarray             # (N, d)
    pressure: np.ndarray       # (N,)
    creation_time: np.ndarray  # (N,) tau_i of Carter's leak-off
    time: float
    step: int
    relaxation: float
    injected_volume: float
    leaked_volume: float
    origin: np.ndarray = None         # (N,) Origin codes
    natural_index: np.ndarray = None  # (N,) index in the natural mesh, -1 for hydraulic elements
    intact: np.ndarray = None         # (M,) natural elements still intact (stress targets)
    failed: np.ndarray = None         # (M,) intact natural elements failing Coulomb's criterion
    extra_faces: np.ndarray = None    # (K, 6) flow connections (i, j, length, d_i, d_j, edge of i) at intersections
    contact_status: np.ndarray = None  # (N,) OPEN / STICK / SLIP (hmatddm.coupled.contact)
    slip_direction: np.ndarray = None  # (N, d) unit slip direction of slipping elements
    failure_pressure: np.ndarray = None  # (N,) pore pressure of remotely failed elements (NaN otherwise)
    front_distance: np.ndarray = None  # (N,) asymptotic front: ribbon distance to the front (NaN elsewhere)
    front_velocity: np.ndarray = None  # (N,) asymptotic front: ribbon front velocity (NaN elsewhere)
    front_class: np.ndarray = None     # (N,) asymptotic front: channel, tip, empty, filled (hmatddm.fracture.front)
    time_step: float = None            # the next step's length, s (hmatddm.simulation.step_control)
    # proppant (issue 34, hmatddm.simulation.proppant_step): None / 0 without proppant
    proppant_volume: np.ndarray = None   # (N,) proppant (solid) volume in each element, m^3
    proppant_injected_volume: float = 0.0  # pumped by the clusters so far, m^3
    proppant_screened_volume: float = 0.0  # found a packed injection element: stays in the wellbore, m^3
    proppant_substeps: int = 0           # transport sub-steps of the last step
    heel_pressure: float = None          # a shared well's heel pressure (issue 35); None without a well

    def __post_init__(self):
        n, d = self.dd.shape
        if self.contact_status is None:
            self.contact_status = np.zeros(n, np.int64)
        if self.slip_direction is None:
            self.slip_direction = np.zeros((n, d))
        if self.failure_pressure is None:
            self.failure_pressure = np.full(n, np.nan)

    def copy(self):
        """A state with copies of every array (the trial state of a step)."""
        return replace(self, **{f.name: getattr(self, f.name).copy() for f in fields(self)
                                if isinstance(getattr(self, f.name), np.ndarray)})

    def connected(self, connections, first_new):
        """The state with ``connections`` (:class:`Connection`) added to its flow faces."""
        if not connections:
            return self
        return replace(self, extra_faces=np.vstack([self.extra_faces] + [c.face(first_new) for c in connections]))

    def joined(self, new, guess, creation_time):
        """The state with :class:`NewElements` ``new`` appended: DD ``guess``, pressure of
        the parent (or the new elements' own), created at ``creation_time``; failed
        elements start stuck at their failure pressure, the others open, and without proppant. The asymptotic
        front's arrays, where carried, mark the new elements off the ribbon (no front
        distance) and EMPTY until its front iteration classifies them."""
        m = new.mesh.n_elements
        failed = new.origin == Origin.FAILED
        intact = self.intact.copy()
        intact[new.natural_index[new.natural_index >= 0]] = False
        front = {}
        if self.front_class is not None:
            front = dict(front_distance=np.concatenate([self.front_distance, np.full(m, np.nan)]),
                         front_velocity=np.concatenate([self.front_velocity, np.full(m, np.nan)]),
                         front_class=np.concatenate([self.front_class, np.full(m, EMPTY, np.int64)]))
        return replace(
            self, **front, mesh=concatenate([self.mesh, new.mesh]), dd=np.concatenate([self.dd, guess]),
            pressure=np.concatenate([self.pressure, new.from_parent(self.pressure, new.pressure)]),
            creation_time=np.concatenate([self.creation_time, np.full(m, creation_time)]),
            origin=np.concatenate([self.origin, new.origin]),
            natural_index=np.concatenate([self.natural_index, new.natural_index]), intact=intact,
            failure_pressure=np.concatenate([self.failure_pressure, np.where(failed, new.pressure, np.nan)]),
            contact_status=np.concatenate([self.contact_status, np.where(failed, STICK, OPEN).astype(np.int64)]),
            slip_direction=np.concatenate([self.slip_direction, np.zeros((m, self.mesh.dim))]),
            proppant_volume=None if self.proppant_volume is None else np.concatenate([self.proppant_volume,
                                                                                      np.zeros(m)]))

    # -- checkpoints ------------------------------------------------------------------
    def arrays(self):
        """The state's arrays, the mesh's included (a checkpoint's ``.npz``)."""
        arrays = dict(mesh_arrays(self.mesh), **{name: getattr(self, name) for name in _ALWAYS})
        if self.front_class is not None:
            arrays.update({name: getattr(self, name) for name in _FRONT})
        if self.proppant_volume is not None:
            arrays["proppant_volume"] = self.proppant_volume
        return arrays

    def scalars(self):
        """The state's numbers (in a checkpoint's metadata)."""
        scalars = {name: getattr(self, name) for name in _SCALARS}
        if self.proppant_volume is not None:
            scalars.update({name: getattr(self, name) for name in _PROPPANT})
        if self.heel_pressure is not None:
            scalars["heel_pressure"] = self.heel_pressure
        return scalars

    @classmethod
    def from_checkpoint(cls, arrays, metadata):
        """The state that :meth:`arrays` and :meth:`scalars` wrote."""
        return cls(mesh_from_arrays(arrays), arrays["dd"], arrays["pressure"], arrays["creation_time"],
                   float(metadata["time"]), int(metadata["step"]), float(metadata["relaxation"]),
                   float(metadata["injected_volume"]), float(metadata["leaked_volume"]),
                   time_step=None if metadata.get("time_step") is None else float(metadata["time_step"]),
                   proppant_volume=arrays.get("proppant_volume"),
                   heel_pressure=None if metadata.get("heel_pressure") is None else float(metadata["heel_pressure"]),
                   **{name: type(getattr(cls, name))(metadata.get(name, 0)) for name in _PROPPANT},
                   **{name: arrays.get(name) for name in _ALWAYS[3:] + _FRONT})


@dataclass
class StepStart:
    """Per element, the start of the step the coupled step compares with: the opening
    ``w^n`` and pressure ``p^n`` (ref. Eq. 4.36) and the DD from which contact slip is
    measured. New elements start with zero opening, their parent's pressure and the
    DD they start the iterations from. A shared well's heel pressure at the step's start
    (:mod:`hmatddm.flow.well`) too."""

    width: np.ndarray     # (N,)
    pressure: np.ndarray  # (N,)
    dd: np.ndarray        # (N, d)
    heel_pressure: float = None  # a shared well's heel pressure p_h^n (issue 35)

    @classmethod
    def of(cls, state):
        return cls(np.sum(state.dd * state.mesh.normals, axis=1), state.pressure.copy(), state.dd.copy(),
                   state.heel_pressure)

    def joined(self, new, guess):
        """The start with :class:`NewElements` ``new`` (starting from DD ``guess``) appended."""
        return StepStart(np.concatenate([self.width, np.zeros(new.mesh.n_elements)]),
                         np.concatenate([self.pressure, new.from_parent(self.pressure, new.pressure)]),
                         np.concatenate([self.dd, guess]), self.heel_pressure)
