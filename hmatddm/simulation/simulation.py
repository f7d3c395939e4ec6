"""The time loop of a hydraulic-fracturing simulation (ref. Ch. 4, Fig. 4.1).

Each time step: solve the coupled system (:mod:`hmatddm.coupled`); check the
propagation criterion along the tip edges (:mod:`hmatddm.fracture`); if any edge
grows, add elements ahead of it and solve the same step again, until no edge grows
(or ``max_growth_passes``). The elasticity operator is rebuilt only when the mesh
has grown, never inside the nonlinear iterations.

After every accepted step a record is appended to :attr:`Simulation.records` and,
with a ``checkpoint_dir``, an atomic checkpoint is written; :meth:`Simulation.run`
with ``resume=True`` continues from the newest good checkpoint and gives the same
numbers as an uninterrupted run (everything the loop carries from one step to the
next is in the checkpoint).
"""
import hashlib
import json
import logging
import time
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from .. import topology
from .._validation import finite_array, finite_scalar, positive_int, positive_scalar
from ..coupled import ElasticSolver, SchemeSettings, StepProblem, solve_step
from ..coupled.contact import CONTACT_MODES, OPEN, SLIP, STICK, ContactLaw, ContactModel
from ..errors import InputError, MeshQualityWarning, NoInjectionWarning, SizeLimitError
from ..flow import Cluster, Fluid, LeakOff, LubricationModel, fracture_compliance
from ..fracture import Propagation, evaluate_tips, new_elements
from ..fracture.crossing import NaturalFractureProperties
from ..layered.medium import LayeredMedium
from ..material import Elastic
from ..mesh import Mesh2D, Mesh3D, check_mesh, concatenate
from ..extended_operator import ExtendedElasticityOperator
from ..operators import BACKENDS, DEFAULT_EPS, DEFAULT_ETA, DEFAULT_LEAF_SIZE, ElasticityOperator
from . import checkpoint
from .natural import NaturalNetwork

logger = logging.getLogger(__name__)

RECORD_KEYS = ("time", "n_elements", "injected_volume", "fracture_volume", "fracture_area", "max_opening",
               "wellbore_pressure", "nonlinear_iterations", "linear_iterations", "solve_seconds")


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
    origin: np.ndarray = None         # (N,) 0 hydraulic, 1 activated natural, 2 remotely failed natural
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

    def __post_init__(self):
        n, d = self.dd.shape
        if self.contact_status is None:
            self.contact_status = np.zeros(n, np.int64)
        if self.slip_direction is None:
            self.slip_direction = np.zeros((n, d))
        if self.failure_pressure is None:
            self.failure_pressure = np.full(n, np.nan)


def with_links(faces, links):
    """The flow faces plus the intersection links ``(K, 6)`` (i, j, length, d_i, d_j, edge
    of i), except links between elements that already share an edge: a tip linked to a
    natural element that another tip activated beside it in the same growth pass gets
    its face from the mesh topology, and a second face would double the conductance."""
    if len(links) == 0:
        return faces
    shared = set(zip(faces.first.tolist(), faces.second.tolist()))
    shared |= {(b, a) for a, b in shared}
    i, j, length, d_i, d_j, edge_i = np.asarray(links, dtype=np.float64).T
    i, j, edge_i = i.astype(np.int64), j.astype(np.int64), edge_i.astype(np.int64)
    keep = np.array([(a, b) not in shared for a, b in zip(i.tolist(), j.tolist())], dtype=bool)
    return faces.append(i[keep], j[keep], length[keep], d_i[keep], d_j[keep], edge_i[keep])


def _mesh_arrays(mesh):
    if isinstance(mesh, Mesh3D):
        return dict(centers=mesh.centers, frames=mesh.frames, half_a=mesh.half_a, half_b=mesh.half_b,
                    fracture_id=mesh.fracture_id)
    return dict(centers=mesh.centers, frames=mesh.frames, half_length=mesh.half_length,
                fracture_id=mesh.fracture_id)


def _mesh_from_arrays(arrays):
    if "half_a" in arrays:
        return Mesh3D(arrays["centers"], arrays["frames"], arrays["half_a"], arrays["half_b"],
                      arrays["fracture_id"].astype(np.int64))
    return Mesh2D(arrays["centers"], arrays["frames"], arrays["half_length"], arrays["fracture_id"].astype(np.int64))


class Simulation:
    """A hydraulic fracture (or several) driven by injection (ref. Ch. 4).

    Parameters
    ----------
    mesh : Mesh2D or Mesh3D
        The initial fracture(s).
    material : Elastic or LayeredMedium
        A :class:`hmatddm.LayeredMedium` (2D vertical cross-section or 3D, constant elements):
        the operator adds the layers' image terms (ref. Ch. 3), tips use their layer's
        moduli and toughness (if given), elements their layer's in-situ stress (if given,
        else ``far_field_stress``), and new tip elements are cut at the interfaces.
    fluid : Fluid
    clusters : list of Cluster
        Injection points; each feeds the element nearest its position.
    far_field_stress : (d, d) array
        In-situ stress tensor, tension positive (a 8 MPa minimum horizontal stress
        along x is ``-8e6`` in entry ``[0, 0]``), Pa.
    time_step : float
        dt, s.
    propagation : Propagation or None
        None: the mesh is fixed.
    leak_off : LeakOff
    initial_pressure : float
        Fluid pressure in the fractures and wellbores at t = 0, Pa.
    initial_opening : float
        Opening of the initial elements at t = 0, m (ref. Table 4.1).
    minimum_width : float or None
        Width floor of the flow model (default: ``initial_opening``), m.
    height : float
        2D only: the flow height of the plane-strain fracture, m (ref. Table 4.2).
    backend, eps, eta, leaf_size, singular_correction, alpha
        Passed to :class:`~hmatddm.ElasticityOperator`.
    scheme : str or SchemeSettings
        Coupling scheme (``"krylov"`` default; see :mod:`hmatddm.coupled.schemes`).
    growing_fractures : iterable of int or None
        Fracture ids allowed to grow (default: all).
    checkpoint_dir : path or None
        Where to write a checkpoint after every step.
    keep_checkpoints : int
    natural_fractures : Mesh2D or Mesh3D or None
        Natural-fracture elements (same dimension as ``mesh``). Intact ones are stress
        targets; they join the system when the fluid reaches them (ref. Ch. 5, see
        :mod:`hmatddm.simulation.natural`). Use ``singular_correction="average"`` and
        ``alpha=1.0`` (ref. Sec. 6.2.3) when elements meet at intersections.
    natural : NaturalFractureProperties or None
        Their strength and the crossing criterion (default properties if None).
    remote_failure : bool
        Check intact natural elements against Coulomb's criterion after every step
        (ref. Sec. 5.3). Failed elements join the system (closed, stick or Coulomb
        slip, at the undrained pore pressure of the moment they failed while no fluid
        reaches them) and the step is solved again; their slip is in ``dd`` and the
        records (``natural_failed``, ``natural_slipping``, ``max_slip``).
    contact : {"natural", "all", "none"}
        Which elements obey the contact condition (open / stick / Coulomb slip,
        :mod:`hmatddm.coupled.contact`): natural-fracture elements (activated or
        failed; the friction and cohesion of ``natural``), every element (hydraulic
        elements close without friction), or none (elements may interpenetrate).
    rebuild_fraction, max_border_bytes
        ``hmatrix`` backend: elements added by growth join the operator as exact
        border blocks (:class:`~hmatddm.extended_operator.ExtendedElasticityOperator`)
        until they exceed ``rebuild_fraction`` of the compressed elements or the
        border exceeds ``max_border_bytes``; then the H-matrix is rebuilt.
    """

    def __init__(self, mesh, material, fluid, clusters, far_field_stress, time_step, propagation=None,
                 leak_off=None, initial_pressure=0.0, initial_opening=1e-5, minimum_width=None, height=1.0,
                 backend="hmatrix", eps=DEFAULT_EPS, eta=DEFAULT_ETA, leaf_size=DEFAULT_LEAF_SIZE,
                 singular_correction="none", alpha=None, scheme="krylov", growing_fractures=None,
                 checkpoint_dir=None, keep_checkpoints=3, rebuild_fraction=0.25, max_border_bytes=2**28,
                 natural_fractures=None, natural=None, remote_failure=True, contact="natural", max_elements=None):
        if not isinstance(mesh, (Mesh2D, Mesh3D)):
            raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
        check_mesh(mesh)
        if mesh.element_order != 0:  # flow, tips and growth work on constant elements
            raise InputError(f"mesh.element_order must be 0 for a Simulation (linear and quadratic elements are "
                             f"for static solves: hd.ElasticityOperator, hd.solve), got {mesh.element_order}")
        self.medium = material if isinstance(material, LayeredMedium) else None  # layered rock, ref. Ch. 3
        if self.medium is not None:
            from ..layered import engine as layered_engine

            layered_engine.check_simulation(mesh, material, natural_fractures, propagation)
        elif not isinstance(material, Elastic):
            raise InputError(f"material must be an hmatddm.Elastic or hmatddm.LayeredMedium, got "
                             f"{type(material).__name__}")
        if not isinstance(fluid, Fluid):
            raise InputError(f"fluid must be an hmatddm.Fluid, got {type(fluid).__name__}")
        clusters = list(clusters)
        if not clusters or not all(isinstance(c, Cluster) for c in clusters):
            raise InputError("clusters must be a non-empty list of hmatddm.Cluster")
        if all(c.rate == 0.0 for c in clusters):
            warnings.warn("every cluster injects at rate 0 m^3/s: nothing drives the fractures, which only relax "
                          "from their initial pressure", NoInjectionWarning, stacklevel=2)
        if propagation is not None and not isinstance(propagation, Propagation):
            raise InputError(f"propagation must be an hmatddm.Propagation or None, got {type(propagation).__name__}")
        leak_off = LeakOff() if leak_off is None else leak_off
        if not isinstance(leak_off, LeakOff):
            raise InputError(f"leak_off must be an hmatddm.LeakOff, got {type(leak_off).__name__}")
        if backend not in BACKENDS:
            raise InputError(f"backend must be one of {BACKENDS}, got {backend!r}")
        d = mesh.dim
        self.far_field_stress = finite_array("far_field_stress", far_field_stress, (d, d))
        scale = 1.0 + np.abs(self.far_field_stress).max()
        if not np.allclose(self.far_field_stress, self.far_field_stress.T, rtol=0, atol=1e-9 * scale):
            raise InputError("far_field_stress must be a symmetric tensor")
        self.mesh0 = mesh
        self.material, self.fluid, self.clusters, self.leak_off = material, fluid, clusters, leak_off
        self.propagation = propagation
        self.time_step = positive_scalar("time_step", time_step)
        self.initial_pressure = finite_scalar("initial_pressure", initial_pressure)
        self.initial_opening = finite_scalar("initial_opening", initial_opening)
        if self.initial_opening < 0.0:
            raise InputError(f"initial_opening must be >= 0 m, got {self.initial_opening}")
        minimum_width = self.initial_opening if minimum_width is None else minimum_width
        self.minimum_width = positive_scalar("minimum_width", minimum_width)
        self.height = positive_scalar("height", height)
        self.operator_options = dict(backend=backend, eps=eps, eta=eta, leaf_size=leaf_size,
                                     singular_correction=singular_correction, alpha=alpha)
        self.settings = scheme if isinstance(scheme, SchemeSettings) else SchemeSettings(scheme=scheme)
        self.growing_fractures = None if growing_fractures is None else np.asarray(sorted(growing_fractures), np.int64)
        self.injection_elements = np.array([c.nearest_element(mesh) for c in clusters], dtype=np.int64)
        self.network = None
        self.remote_failure = bool(remote_failure)
        if contact not in CONTACT_MODES:
            raise InputError(f"contact must be one of {CONTACT_MODES}, got {contact!r}")
        self.contact = contact
        if natural_fractures is not None:
            if type(natural_fractures) is not type(mesh):
                raise InputError(f"natural_fractures must be a {type(mesh).__name__} like mesh, "
                                 f"got {type(natural_fractures).__name__}")
            check_mesh(natural_fractures, "natural_fractures")
            natural = NaturalFractureProperties() if natural is None else natural
            if not isinstance(natural, NaturalFractureProperties):
                raise InputError("natural must be an hmatddm.NaturalFractureProperties or None")
            # natural fracture ids follow the hydraulic ones so that they never collide
            offset = int(mesh.fracture_id.max()) + 1 - int(natural_fractures.fracture_id.min())
            shifted = natural_fractures.subset(np.arange(natural_fractures.n_elements))
            object.__setattr__(shifted, "fracture_id", natural_fractures.fracture_id + offset)
            self.network = NaturalNetwork(shifted, natural)
        self.checkpoint_dir = checkpoint_dir
        self.keep_checkpoints = keep_checkpoints
        # a resource limit, not part of the run's definition: left out of the fingerprint, so
        # that a run stopped by it resumes with a higher one
        self.max_elements = None if max_elements is None else positive_int("max_elements", max_elements)
        self.records = []
        self.front = None  # propagation.front == "asymptotic": its AsymptoticFront (raises for unsupported setups)
        if propagation is not None and propagation.front == "asymptotic":
            from .asymptotic import AsymptoticFront

            self.front = AsymptoticFront(self)
        self.state = self._initial_state()
        self.rebuild_fraction = finite_scalar("rebuild_fraction", rebuild_fraction)
        if not 0.0 <= self.rebuild_fraction <= 10.0:
            raise InputError(f"rebuild_fraction must be in [0, 10], got {self.rebuild_fraction}")
        self.max_border_bytes = finite_scalar("max_border_bytes", max_border_bytes)
        self._operator_mesh = None
        self._operator = None
        self._base = None
        self.operator_builds = 0
        self._mesh_quality_warned = False

    # -- setup ------------------------------------------------------------------------
    def _initial_state(self):
        mesh = self.mesh0
        dd = self.initial_opening * mesh.normals
        pressure = np.full(mesh.n_elements, self.initial_pressure)
        n_natural = 0 if self.network is None else self.network.mesh.n_elements
        front = {}
        if self.front is not None:
            front = dict(zip(("front_distance", "front_velocity", "front_class"), self.front.initial(mesh)))
        return State(mesh, dd, pressure, np.zeros(mesh.n_elements), 0.0, 0, self.settings.relaxation, 0.0, 0.0,
                     origin=np.zeros(mesh.n_elements, np.int64), natural_index=-np.ones(mesh.n_elements, np.int64),
                     intact=np.ones(n_natural, bool), failed=np.zeros(n_natural, bool),
                     extra_faces=np.zeros((0, 6)), **front)

    def fingerprint(self):
        """SHA-256 of everything that defines the run (a resume must match it)."""
        parts = dict(material=asdict(self.material), fluid=asdict(self.fluid),
                     clusters=[asdict(c) for c in self.clusters], leak_off=asdict(self.leak_off),
                     propagation=None if self.propagation is None else repr(self.propagation),
                     far_field_stress=self.far_field_stress.tolist(), time_step=self.time_step,
                     initial_pressure=self.initial_pressure, initial_opening=self.initial_opening,
                     minimum_width=self.minimum_width, height=self.height, operator=self.operator_options,
                     settings=repr(self.settings), contact=self.contact, remote_failure=self.remote_failure,
                     growing=None if self.growing_fractures is None else self.growing_fractures.tolist())
        digest = hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode())
        meshes = [self.mesh0] + ([] if self.network is None else [self.network.mesh])
        for value in [v for m in meshes for v in _mesh_arrays(m).values()]:
            digest.update(np.ascontiguousarray(value).tobytes())
        if self.network is not None:
            digest.update(repr(self.network.properties).encode())
        return digest.hexdigest()

    def operator(self, mesh):
        """The elasticity operator of ``mesh``: the last one if the mesh is unchanged, the
        compressed base plus exact borders if the mesh only grew a little, else a new build."""
        if self._operator_mesh is mesh:
            return self._operator
        base = self._base
        n = mesh.n_elements
        extends = (base is not None and n >= base.mesh.n_elements
                   and np.array_equal(mesh.centers[:base.mesh.n_elements], base.mesh.centers))
        if extends and n == base.mesh.n_elements:
            operator = base
        elif extends and self.operator_options["backend"] == "hmatrix" and self._border_fits(base, n):
            operator = ExtendedElasticityOperator(base, mesh)
        else:
            operator = self._build_base(mesh)
        self._operator, self._operator_mesh = operator, mesh
        return operator

    def _border_fits(self, base, n):
        n0, m, d = base.mesh.n_elements, n - base.mesh.n_elements, base.dof
        border_bytes = 8.0 * d * d * (2 * n0 * m + m * m)
        return m <= self.rebuild_fraction * n0 and border_bytes <= self.max_border_bytes

    def _build_base(self, mesh):
        # the mesh-quality check runs at every build of a growing mesh: warn once per run
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", MeshQualityWarning)
            self._base = ElasticityOperator(mesh, self.material, **self.operator_options)
        for warning in caught:
            if issubclass(warning.category, MeshQualityWarning):
                if not self._mesh_quality_warned:
                    self._mesh_quality_warned = True
                    warnings.warn(f"{warning.message} (warned once per simulation)", MeshQualityWarning,
                                  stacklevel=2)
            else:
                warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
        self.operator_builds += 1
        return self._base

    @property
    def compressed_elements(self):
        """Elements in the compressed base operator (0 before the first build)."""
        return 0 if self._base is None else self._base.mesh.n_elements

    def far_field_traction(self, mesh):
        """f = -sigma_0 . n at every element (ref. Eq. 4.4, our sign), flat."""
        if self.medium is not None:  # the in-situ stress of each element's layer, if given
            from ..layered import engine as layered_engine

            return layered_engine.far_field_traction(mesh, self.medium, self.far_field_stress)
        return -(mesh.normals @ self.far_field_stress.T).ravel()

    def elastic_constants(self, mesh, elements=None):
        """The material (an :class:`Elastic`), or in a layered medium the moduli of each
        element (of ``elements``, if given) as arrays with the same attribute names."""
        if self.medium is None:
            return self.material
        from ..layered import engine as layered_engine

        materials = layered_engine.element_materials(mesh, self.medium)
        if elements is None:
            return materials
        return layered_engine.ElementMaterials(materials.shear_modulus[elements], materials.poisson_ratio[elements])

    def flow_model(self, mesh, faces):
        areas = mesh.areas * (self.height if mesh.dim == 2 else 1.0)
        return LubricationModel(areas=areas, normals=mesh.normals, faces=faces, fluid=self.fluid,
                                leak_off=self.leak_off, injection_elements=self.injection_elements,
                                injection_rates=np.array([c.rate for c in self.clusters]),
                                wellbore_volumes=np.array([c.wellbore_volume for c in self.clusters]),
                                minimum_width=self.minimum_width)

    # -- one step -------------------------------------------------------------------------
    def contact_law(self, origin):
        """The :class:`~hmatddm.coupled.contact.ContactLaw` of elements with ``origin``."""
        natural = origin >= 1
        enabled = {"natural": natural, "all": np.ones_like(natural), "none": np.zeros_like(natural)}[self.contact]
        friction = np.zeros(len(origin))
        cohesion = np.zeros(len(origin))
        if self.network is not None:
            friction[natural] = self.network.properties.friction
            cohesion[natural] = self.network.properties.cohesion
        return ContactLaw(enabled, friction, cohesion)

    def drained(self, mesh, faces, origin):
        """Remotely failed elements that no fluid path connects to an injection point."""
        failed = origin == 2
        if not np.any(failed):
            return failed
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        n = mesh.n_elements
        graph = coo_matrix((np.ones(faces.n_faces), (faces.first, faces.second)), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        fed = np.isin(label, label[self.injection_elements])
        return failed & ~fed

    def _solve(self, mesh, dd_old_width, p_old, creation_time, dd_guess, p_guess, t_old, t_new, relaxation,
               extra_faces, origin=None, dd_start=None, contact_state=None, failure_pressure=None):
        edges = topology.element_edges(mesh, self.height)
        faces = with_links(topology.element_faces(mesh, edges), extra_faces)
        flow = self.flow_model(mesh, faces)
        op = self.operator(mesh)
        elastic = ElasticSolver(op, rtol=self.settings.linear_rtol)
        origin = np.zeros(mesh.n_elements, np.int64) if origin is None else origin
        contact, fixed_pressure = None, None
        law = self.contact_law(origin)
        if np.any(law.enabled):
            status, direction = contact_state
            contact = ContactModel(law, mesh.normals, dd_start, status, direction,
                                   elastic.normal_stiffness(mesh.normals))
        drained = self.drained(mesh, faces, origin)
        if np.any(drained):
            fixed_pressure = np.where(drained, failure_pressure, np.nan)
            p_guess = np.where(drained, failure_pressure, p_guess)
        problem = StepProblem(elastic=elastic, normals=mesh.normals,
                              far_field=self.far_field_traction(mesh), flow=flow,
                              compliance=fracture_compliance(mesh, self.elastic_constants(mesh)), dt=t_new - t_old,
                              width_old=dd_old_width, pressure_old=p_old,
                              leak_off_rate=flow.leak_off_rate(creation_time, t_old, t_new),
                              contact=contact, fixed_pressure=fixed_pressure)
        dd, p, info = solve_step(problem, self.settings, dd_guess.ravel(), p_guess, relaxation)
        if contact is not None:
            info["contact"] = (contact.status.copy(), contact.direction.copy())
            info["contact_frozen"] = contact.frozen
        else:
            info["contact"] = contact_state
            info["contact_frozen"] = 0
        info["drained"] = drained
        return dd.reshape(mesh.n_elements, mesh.dim), p, info, edges, faces, flow

    def step(self, end_time=None):
        """Advance one time step (with growth and remote-failure passes); returns the record.

        With ``end_time``, a step that would reach or pass it (within 1e-9 of a step) ends
        exactly at ``end_time``: the last step of a run is shortened, never longer.
        Raises :class:`~hmatddm.errors.SizeLimitError` (the state stays the last finished
        step) when growth would take the mesh past ``max_elements``.
        """
        if self.front is not None:  # propagation.front = "asymptotic" (hmatddm.simulation.asymptotic)
            return self.front.step(self, end_time)
        start = time.perf_counter()
        s = self.state
        t_old, t_new = self.step_times(end_time)
        dt = t_new - t_old
        mesh = s.mesh
        width_old = np.sum(s.dd * mesh.normals, axis=1)
        p_old = s.pressure.copy()
        creation = s.creation_time.copy()
        dd, p = s.dd.copy(), s.pressure.copy()
        dd_start = s.dd.copy()
        origin, natural_index = s.origin.copy(), s.natural_index.copy()
        intact, extra = s.intact.copy(), s.extra_faces.copy()
        contact_state = (s.contact_status.copy(), s.slip_direction.copy())
        failure_pressure = s.failure_pressure.copy()
        totals = dict(nonlinear_iterations=0, linear_iterations=0, restarts=0, contact_changes=0)
        self._events = dict(natural_crossed=0, natural_deflected=0, natural_newly_failed=0, contact_frozen=0,
                            junctions=0)
        added = 0
        passes = 0
        relaxation = s.relaxation
        builds = self.operator_builds
        max_passes = 50 if self.propagation is None else self.propagation.max_growth_passes
        while True:
            dd, p, info, edges, faces, flow = self._solve(mesh, width_old, p_old, creation, dd, p, t_old, t_new,
                                                          relaxation, extra, origin, dd_start, contact_state,
                                                          failure_pressure)
            relaxation = info["relaxation"]
            contact_state = info["contact"]
            self._events["contact_frozen"] = max(self._events["contact_frozen"], info["contact_frozen"])
            drained = info["drained"]
            for key in totals:
                totals[key] += info.get(key, 0)
            if passes >= max_passes:
                break
            grown = None
            if self.propagation is not None:
                grown = self._grow(mesh, edges, faces, dd, origin, natural_index, intact, drained)
            if grown is None:
                grown = self._remote_failures(mesh, dd, intact)
            if grown is None:
                break
            new_mesh, parent, new_natural, connections, new_origin, new_pressure = grown
            passes += 1
            first_new = mesh.n_elements
            for k, tip_element, length, d_tip, d_natural, tip_edge in connections:
                target = first_new + k if k >= 0 else -1 - k
                extra = np.vstack([extra, [tip_element, target, length, d_tip, d_natural, tip_edge]])
            if new_mesh is None:  # only new connections to elements already in the system
                continue
            added += new_mesh.n_elements
            m = new_mesh.n_elements
            mesh = concatenate([mesh, new_mesh])
            if self.max_elements is not None and mesh.n_elements > self.max_elements:
                raise SizeLimitError(
                    f"growth in step {s.step + 1} (t = {t_new:g} s) would take the mesh to {mesh.n_elements} "
                    f"elements, more than max_elements = {self.max_elements}", elements=mesh.n_elements,
                    limit=self.max_elements)
            width_old = np.concatenate([width_old, np.zeros(m)])
            has_parent = parent >= 0
            p_old = np.concatenate([p_old, np.where(has_parent, p_old[np.maximum(parent, 0)], new_pressure)])
            creation = np.concatenate([creation, np.full(m, t_old)])
            guess = np.where(has_parent[:, None], dd[np.maximum(parent, 0)], 0.0)
            activated = new_origin == 1
            guess[activated] = self.minimum_width * new_mesh.normals[activated]
            dd = np.concatenate([dd, guess])
            dd_start = np.concatenate([dd_start, guess])
            p = np.concatenate([p, np.where(has_parent, p[np.maximum(parent, 0)], new_pressure)])
            origin = np.concatenate([origin, new_origin])
            natural_index = np.concatenate([natural_index, new_natural])
            intact[new_natural[new_natural >= 0]] = False
            failure_pressure = np.concatenate([failure_pressure, np.where(new_origin == 2, new_pressure, np.nan)])
            status = np.where(new_origin == 2, STICK, OPEN).astype(np.int64)
            contact_state = (np.concatenate([contact_state[0], status]),
                             np.concatenate([contact_state[1], np.zeros((m, mesh.dim))]))

        width = np.sum(dd * mesh.normals, axis=1)
        leak = flow.leak_off_rate(creation, t_old, t_new) * flow.areas * (p - self.leak_off.pore_pressure)
        injected = s.injected_volume + dt * sum(c.rate for c in self.clusters)
        leaked = s.leaked_volume + float(np.sum(leak)) * dt
        failed = s.failed.copy()
        if self.network is not None:
            failed[natural_index[origin == 2]] = True
        next_relaxation = relaxation
        if totals["restarts"] == 0:  # an easy step: let alpha grow back (SchemeSettings.relaxation_growth)
            next_relaxation = min(self.settings.relaxation, relaxation * self.settings.relaxation_growth)
        self.state = State(mesh, dd, p, creation, t_new, s.step + 1, next_relaxation, injected, leaked,
                           origin=origin, natural_index=natural_index, intact=intact, failed=failed,
                           extra_faces=extra, contact_status=contact_state[0], slip_direction=contact_state[1],
                           failure_pressure=failure_pressure)
        record = self._record(flow, width, totals, added, passes, relaxation, time.perf_counter() - start,
                              self.operator_builds - builds)
        self.records.append(record)
        return record

    def step_times(self, end_time=None):
        """``(t_old, t_new)`` of the next step: one ``time_step``, shortened to end exactly at
        ``end_time`` when it would reach or pass it (within 1e-9 of a step)."""
        t_old = self.state.time
        t_new = t_old + self.time_step
        if end_time is not None and t_new >= end_time - 1e-9 * self.time_step:
            t_new = float(end_time)
        return t_old, t_new

    def _remote_failures(self, mesh, dd, intact):
        """Intact natural elements that fail (ref. Sec. 5.3) as new elements to join the
        system, or None: ``(mesh, parent=-1, natural_index, [], origin=2, pore_pressure)``."""
        if self.network is None or not self.remote_failure or not np.any(intact):
            return None
        failed, _, _, pore_change = self.network.remote_failure(mesh, dd, self.material, self.far_field_stress,
                                                                intact, self.operator_options["singular_correction"])
        index = np.flatnonzero(failed)
        if index.size == 0:
            return None
        self._events["natural_newly_failed"] += int(index.size)
        pressure = self.network.properties.pore_pressure + pore_change[index]
        m = index.size
        return (self.network.mesh.subset(index), -np.ones(m, np.int64), index.astype(np.int64), [],
                np.full(m, 2, np.int64), pressure)

    def _grow(self, mesh, edges, faces, dd, origin, natural_index, intact, drained=None):
        """Elements to add: ``(new_mesh, parent, natural_index_of_new, connections, origin_of_new,
        pressure_of_new)`` or None (the new pressures come from the parents; NaN here).

        Tips of drained elements (remotely failed, not reached by the fluid) do not grow.

        New elements come from :func:`new_elements`; with natural fractures each
        candidate is checked against the intact natural elements (see
        :mod:`hmatddm.simulation.natural`): it may activate one instead, or be kept
        when the crossing criterion says the tip crosses.
        """
        element, edge = topology.tip_edges(mesh, faces, edges)
        if self.growing_fractures is not None:
            keep = np.isin(mesh.fracture_id[element], self.growing_fractures)
            element, edge = element[keep], edge[keep]
        if drained is not None and np.any(drained):
            keep = ~drained[element]
            element, edge = element[keep], edge[keep]
        if element.size == 0:
            return None
        tips = evaluate_tips(mesh, edges, element, edge, dd, self.elastic_constants(mesh, element), self.propagation)
        if self.medium is not None:  # per-layer toughness; new elements end on interfaces
            from ..layered import engine as layered_engine

            tips = layered_engine.tip_criterion(tips, self.elastic_constants(mesh, element),
                                                layered_engine.layers_ahead(edges, element, edge, self.medium),
                                                self.medium, self.propagation)
        result = new_elements(mesh, edges, tips, self.propagation, return_tips=True)
        if result is None:
            return None
        grown, parent, rows = result
        if self.medium is not None and not layered_engine.uniform(self.medium):
            grown, parent, rows = layered_engine.split_new_elements(grown, parent, rows, self.medium)
        grown, parent, rows, junctions = self._junctions(mesh, edges, tips, grown, parent, rows, origin)
        if grown is None:
            return None, np.zeros(0, np.int64), np.zeros(0, np.int64), junctions, np.zeros(0, np.int64), np.zeros(0)
        if self.network is None:
            m = grown.n_elements
            return grown, parent, -np.ones(m, np.int64), junctions, np.zeros(m, np.int64), np.full(m, np.nan)
        network = self.network
        available = intact.copy()
        # natural elements already in the system (activated, or failed remotely): a tip
        # that reaches one connects to it instead of adding an element on top of it
        active_of = -np.ones(network.mesh.n_elements, np.int64)
        joined = natural_index >= 0
        active_of[natural_index[joined]] = np.flatnonzero(joined)
        reachable = available | (active_of >= 0)
        # pairs already connected (a tip never links to itself or to a neighbour twice)
        linked = {(int(a), int(b)) for a, b in zip(faces.first, faces.second)}
        linked |= {(b, a) for a, b in linked}
        kept, activated, activated_parent, connections = [], [], [], list(junctions)
        activated_at = {}  # natural element -> its place in `activated` (this pass)

        def activate(target, tip):
            available[target] = reachable[target] = False
            activated_at[int(target)] = len(activated)
            activated.append(target)
            activated_parent.append(tip)

        def connect(tip, row, target, point, size):
            """A flow face from ``tip`` to natural element ``target``, which is already in the
            system or was activated by another tip in this pass (two tips reaching the same
            element would otherwise put a hydraulic element on top of it, a singular pair:
            found by the 3D DFN benchmark); never to itself, never twice."""
            if active_of[target] >= 0:
                other, index = int(active_of[target]), -1 - int(active_of[target])
            else:
                place = activated_at[int(target)]
                other, index = ("new", place), place
                if activated_parent[place] == tip:
                    return
            if other == tip or (tip, other) in linked:
                return
            linked.add((tip, other))
            connections.append((index, tip, *self._link(mesh, edges, tip, tips.edge[row], target, point, size)))

        for k in range(grown.n_elements):
            row, tip = rows[k], int(parent[k])
            distance, nearest = network.tree.query(grown.centers[k])
            size = min(float(grown.radii[k]), float(network.mesh.radii[nearest]))
            if distance < 0.5 * size and (reachable[nearest] or int(nearest) in activated_at):
                if available[nearest]:
                    # the next element is an intact natural element: the fluid runs into it
                    activate(nearest, tip)
                else:
                    # it is in the system or was activated in this pass: connect the tip to it
                    connect(tip, row, nearest, grown.centers[k], size)
                continue
            hinge = edges.midpoints[tip, tips.edge[row]]
            hit = network.encounter(grown, k, hinge, available)  # intact elements only
            if hit is None:
                kept.append(k)
                continue
            target, point = hit
            if network.decide_crossing(tips.k_1[row], tips.k_2[row], tips.theta[row], edges.ahead[tip, tips.edge[row]],
                                       mesh.normals[tip], target, self.far_field_stress, self.propagation.toughness):
                self._events["natural_crossed"] += 1
                kept.append(k)
                continue
            self._events["natural_deflected"] += 1
            connections.append((len(activated), tip, *self._link(mesh, edges, tip, tips.edge[row], target, point,
                                                                 size)))
            activate(target, tip)
        pieces, parents = [], []
        if kept:
            pieces.append(grown.subset(np.asarray(kept)))
            parents.append(parent[np.asarray(kept)])
        if activated:
            pieces.append(network.mesh.subset(np.asarray(activated)))
            parents.append(np.asarray(activated_parent, dtype=np.int64))
        connections = [(len(kept) + k if k >= 0 else k, tip, length, d_tip, d_nat, edge)
                       for k, tip, length, d_tip, d_nat, edge in connections]
        if not pieces:
            if not connections:
                return None
            return None, np.zeros(0, np.int64), np.zeros(0, np.int64), connections, np.zeros(0, np.int64), np.zeros(0)
        new_mesh = concatenate(pieces)
        new_natural = np.concatenate([-np.ones(len(kept), np.int64), np.asarray(activated, dtype=np.int64)])
        m = new_mesh.n_elements
        return (new_mesh, np.concatenate(parents), new_natural, connections,
                (new_natural >= 0).astype(np.int64), np.full(m, np.nan))

    def _junctions(self, mesh, edges, tips, grown, parent, rows, origin):
        """Candidates that would cut a hydraulic element of another fracture: the tip
        stops there and a flow face connects it to that element (ref. Sec. 6.2.3, Figs
        6.5-6.7). Returns the remaining ``(grown, parent, rows)`` (``grown`` None when
        none remains) and the connections ``(-1 - element, tip, length, d_tip, d_other,
        edge)``."""
        hydraulic = origin == 0
        if np.unique(mesh.fracture_id[hydraulic]).size < 2:
            return grown, parent, rows, []
        active = NaturalNetwork(mesh, None)
        keep, connections, linked = [], [], set()
        for k in range(grown.n_elements):
            row, tip = rows[k], parent[k]
            others = hydraulic & (mesh.fracture_id != mesh.fracture_id[tip])
            hinge = edges.midpoints[tip, tips.edge[row]]
            hit = active.encounter(grown, k, hinge, others)
            if hit is not None:
                # touching only end to end or at the other's tip is not a cut: the element
                # is kept and ends on the other fracture (ref. Fig. 6.5b); the next pass connects
                reach = 2.0 * (grown.centers[k, :2] - hinge[:2])
                along = active.p1[hit[0]] - active.p0[hit[0]]
                t = float(np.dot(hit[1][:2] - active.p0[hit[0]], along)) / float(np.dot(along, along))
                if (float(np.dot(hit[1][:2] - hinge[:2], reach)) >= (1.0 - 1e-6) * float(np.dot(reach, reach))
                        or not 1e-6 < t < 1.0 - 1e-6):
                    hit = None
            if hit is None:
                keep.append(k)
                continue
            target, point = hit
            if (tip, target) not in linked:
                linked.add((tip, target))
                size = min(float(grown.radii[k]), float(mesh.radii[target]))
                connections.append((-1 - target, tip, *self._link(mesh, edges, tip, tips.edge[row], target, point,
                                                                  size, active)))
        if not connections:
            return grown, parent, rows, []
        self._events["junctions"] = self._events.get("junctions", 0) + len(connections)
        if not keep:
            return None, None, None, connections
        keep = np.asarray(keep)
        return grown.subset(keep), parent[keep], rows[keep], connections

    def _link(self, mesh, edges, tip, edge, target, point, size, network=None):
        """``(length, d_tip, d_natural, edge)`` of the flow face from a tip edge to the
        element ``target`` of ``network`` (default: the natural network) it reaches at
        ``point``."""
        network = self.network if network is None else network
        if mesh.dim == 3:
            length = min(float(edges.length[tip, edge]), 2.0 * float(network.vertical_half[target]))
            gap = np.linalg.norm(network.mesh.centers[target, :2] - point[:2])
        else:
            length = self.height
            gap = np.linalg.norm(network.mesh.centers[target] - point)
        return length, float(edges.half_width[tip, edge]), max(gap, 0.1 * size), int(edge)

    def _record(self, flow, width, totals, added, passes, relaxation, seconds, builds):
        s = self.state
        mesh = s.mesh
        area = float(np.sum(flow.areas))
        record = dict(
            step=s.step, time=s.time, n_elements=int(mesh.n_elements), injected_volume=s.injected_volume,
            fracture_volume=float(np.sum(flow.areas * width)), fracture_area=area,
            max_opening=float(np.max(width)),
            wellbore_pressure=[float(s.pressure[i]) for i in self.injection_elements],
            nonlinear_iterations=int(totals["nonlinear_iterations"]),
            linear_iterations=int(totals["linear_iterations"]), solve_seconds=float(seconds),
            leaked_volume=s.leaked_volume, relaxation=float(relaxation), restarts=int(totals["restarts"]),
            elements_added=int(added), growth_passes=int(passes), operator_builds=int(builds))
        record["junctions"] = int(self._events["junctions"])
        if self.network is not None:
            record["natural_active"] = int(np.count_nonzero(s.origin == 1))
            record["natural_failed"] = int(np.count_nonzero(s.origin == 2))
            record.update(self._events)
        record["contact_changes"] = int(totals["contact_changes"])
        if self.contact != "none":
            natural = s.origin >= 1 if self.contact == "natural" else np.ones(mesh.n_elements, bool)
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

    def view(self):
        """Every element of the run for output: ``(mesh, dd, pressure, state)`` with the
        active elements first, then the intact natural elements (zero DD, the pore
        pressure). ``state``: 0 hydraulic, 1 intact natural, 2 activated or failed natural."""
        s = self.state
        state = np.where(s.origin >= 1, 2, 0).astype(np.int64)
        if self.network is None or not np.any(s.intact):
            return s.mesh, s.dd, s.pressure, state
        intact = np.flatnonzero(s.intact)
        natural = self.network.mesh.subset(intact)
        mesh = concatenate([s.mesh, natural])
        dd = np.concatenate([s.dd, np.zeros((len(intact), s.mesh.dim))])
        pressure = np.concatenate([s.pressure, np.full(len(intact), self.network.properties.pore_pressure)])
        state = np.concatenate([state, np.where(s.failed[intact], 2, 1).astype(np.int64)])
        return mesh, dd, pressure, state

    # -- run, checkpoints, resume -------------------------------------------------------
    def run(self, end_time, resume=False, callback=None, progress=False):
        """Step until ``end_time`` (s); returns the list of records.

        The last step is shortened to end exactly at ``end_time`` when ``end_time`` is not a
        whole number of steps (no record is ever past it). ``resume=True`` first loads the
        newest good checkpoint of ``checkpoint_dir`` (CheckpointError when there is none or
        when it belongs to another run). ``callback(simulation, record)`` is called after
        every step. ``progress=True`` prints a progress line to stderr (redrawn on a
        terminal, one line every tenth of the run otherwise; a text stream instead of
        True prints there); every step is also logged at INFO level on the
        ``hmatddm.simulation.simulation`` logger.
        """
        end_time = positive_scalar("end_time", end_time)
        if self.checkpoint_dir is not None:
            checkpoint.check_writable(self.checkpoint_dir)
        if resume:
            if self.checkpoint_dir is None:
                raise InputError("resume=True needs a checkpoint_dir")
            self.load_checkpoint()
        shown = None
        if progress:
            from ..progress import Progress

            shown = Progress(end_time, self.time_step, stream=None if progress is True else progress,
                             start_time=self.state.time)
        try:
            while self.state.time < end_time - 1e-9 * self.time_step:
                record = self.step(end_time)
                if self.checkpoint_dir is not None:
                    self.save_checkpoint()
                logger.info("step %d: t = %g s of %g, %d elements, %d nonlinear iterations, %.2f s",
                            record["step"], record["time"], end_time, record["n_elements"],
                            record["nonlinear_iterations"], record["solve_seconds"])
                if shown is not None:
                    shown.update(record)
                if callback is not None:
                    callback(self, record)
        finally:
            if shown is not None:
                shown.close()
        return self.records

    def save_checkpoint(self):
        s = self.state
        arrays = dict(_mesh_arrays(s.mesh), dd=s.dd, pressure=s.pressure, creation_time=s.creation_time,
                      origin=s.origin, natural_index=s.natural_index, intact=s.intact, failed=s.failed,
                      extra_faces=s.extra_faces, contact_status=s.contact_status, slip_direction=s.slip_direction,
                      failure_pressure=s.failure_pressure)
        if s.front_class is not None:
            arrays.update(front_distance=s.front_distance, front_velocity=s.front_velocity, front_class=s.front_class)
        metadata = dict(time=s.time, step=s.step, relaxation=s.relaxation, injected_volume=s.injected_volume,
                        leaked_volume=s.leaked_volume, records=self.records, fingerprint=self.fingerprint(),
                        compressed_elements=self.compressed_elements)
        checkpoint.save(self.checkpoint_dir, s.step, arrays, metadata, keep=self.keep_checkpoints)

    def load_checkpoint(self):
        arrays, metadata = checkpoint.load_latest(self.checkpoint_dir)
        if metadata.get("fingerprint") != self.fingerprint():
            raise checkpoint.CheckpointError(
                f"the checkpoints in {str(self.checkpoint_dir)!r} belong to a different run "
                "(settings or initial mesh differ); use another checkpoint folder")
        mesh = _mesh_from_arrays(arrays)
        self.state = State(mesh, arrays["dd"], arrays["pressure"], arrays["creation_time"], float(metadata["time"]),
                           int(metadata["step"]), float(metadata["relaxation"]), float(metadata["injected_volume"]),
                           float(metadata["leaked_volume"]), origin=arrays["origin"],
                           natural_index=arrays["natural_index"], intact=arrays["intact"], failed=arrays["failed"],
                           extra_faces=arrays["extra_faces"], contact_status=arrays.get("contact_status"),
                           slip_direction=arrays.get("slip_direction"),
                           failure_pressure=arrays.get("failure_pressure"),
                           front_distance=arrays.get("front_distance"), front_velocity=arrays.get("front_velocity"),
                           front_class=arrays.get("front_class"))
        self.records = list(metadata["records"])
        # rebuild the compressed base exactly as the interrupted run had it, so the
        # resumed run applies the same operator (bit for bit)
        self._operator_mesh = self._operator = self._base = None
        n_base = int(metadata.get("compressed_elements", 0))
        if 0 < n_base <= mesh.n_elements:
            self._build_base(mesh.subset(np.arange(n_base)))
        return self.state
