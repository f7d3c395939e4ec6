"""The time loop of a hydraulic-fracturing simulation (ref. Ch. 4, Fig. 4.1).

Each time step: solve the coupled system (:mod:`hmatddm.coupled`); check the
propagation criterion along the tip edges and add elements ahead of the edges that
grow (:mod:`~hmatddm.simulation.growth_pass`), then solve the same step again, until no
edge grows (or ``max_growth_passes``); record the step. The elasticity operator is
rebuilt only when the mesh has grown, never inside the nonlinear iterations
(:mod:`~hmatddm.simulation.growing_operator`).

After every accepted step a record is appended to :attr:`Simulation.records` and,
with a ``checkpoint_dir``, an atomic checkpoint is written; :meth:`Simulation.run`
with ``resume=True`` continues from the newest good checkpoint and gives the same
numbers as an uninterrupted run (everything the loop carries from one step to the
next, the :class:`~hmatddm.simulation.state.State`, is in the checkpoint).

Over 500 lines: about 80 lines are the parameter documentation of the public
:class:`Simulation`; the logic is split into ``state``, ``growth_pass``, ``step_solve``,
``records``, ``growing_operator``, ``junctions``, ``linking`` and ``encounters``.
"""
import hashlib
import json
import logging
import time
import warnings
from dataclasses import asdict, replace

import numpy as np

from .._validation import finite_array, positive_scalar
from ..coupled import SchemeSettings
from ..coupled.contact_factor import ContactBases
from ..errors import ConvergenceError, InputError, NoInjectionWarning, SizeLimitError
from ..flow import Cluster, Fluid, LeakOff, LubricationModel
from ..fracture import Propagation
from ..layered.medium import LayeredMedium
from ..material import Elastic
from ..mesh import Mesh2D, Mesh3D, check_mesh
from ..settings import NUMERICS
from . import checkpoint, growth_pass, proppant_step, step_solve
from .growing_operator import GrowingOperator
from .natural import natural_network
from .records import RECORD_KEYS, StepTally, output_view, step_record
from .settings import group_options
from .state import Origin, State, StepStart, mesh_arrays
from .step_control import StepControl, advance_of_step, front_elements
from .linking import with_links
from .step_solve import mesh_topology

__all__ = ["RECORD_KEYS", "Simulation", "State"]

logger = logging.getLogger(__name__)

#: A fixed step that does not converge is split in halves at most this deep (:meth:`Simulation.step`).
MAX_FIXED_STEP_SPLITS = 6


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
    time_step : float or "auto"
        dt, s; ``"auto"``: each step chosen so that the front crosses about
        ``step_control.advance`` element rows (:mod:`~hmatddm.simulation.step_control`).
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
    scheme : str or SchemeSettings
        Coupling scheme (``"krylov"`` default; see :mod:`hmatddm.coupled.schemes`).
    growing_fractures : iterable of int or None
        Fracture ids allowed to grow (default: all).
    natural_fractures : Mesh2D or Mesh3D or None
        Natural-fracture elements (same dimension as ``mesh``). Intact ones are stress
        targets; they join the system when the fluid reaches them (ref. Ch. 5, see
        :mod:`hmatddm.simulation.natural`). Use ``singular_correction="average"`` and
        ``alpha=1.0`` (ref. Sec. 6.2.3) when elements meet at intersections. With a
        LayeredMedium they are cut at the interfaces (3D; 2D where the layers differ) and
        feel the layers (:mod:`hmatddm.layered.engine`).
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
        Strong leak-off with a viscous fluid needs ``"all"``: a fresh tip element
        loses ``2 c_l (p - p_r) dt^(1/2)`` of width in its first step (mm), more than
        the flow brings it; without contact its opening goes negative (to -5 mm in the
        M~ case of ``benchmarks/bench_leak_off.py``) while it still leaks, the tip
        overlaps, its K_I is negative and the front stops for good; closed, its
        pressure falls to the pore pressure, it stops leaking and the front goes on.
        (Not the default with leak-off: a coarse radial start that closes whole in its
        first step, the radial K~ case there, does not converge with it.)
    max_elements : int or None
        A step whose growth would take the mesh past it raises SizeLimitError (a
        resource limit: a run stopped by it resumes with a higher one).
    step_control : StepControl or None
        With ``time_step="auto"``: the target advance and the bounds of the steps
        (:class:`hmatddm.simulation.StepControl`; default: one element row per step,
        first step 0.1 s, steps of at least 1 ms).
    operator_settings : OperatorSettings or None
        Or its keywords ``backend, eps, eta, leaf_size, singular_correction, alpha``; passed to
        :class:`~hmatddm.ElasticityOperator`.
    rebuild_settings : RebuildSettings or None
        Or its keywords ``rebuild_fraction, max_border_bytes``: when a grown ``hmatrix``
        operator is rebuilt instead of extended by border blocks.
    checkpoint_settings : CheckpointSettings or None
        Or its keywords ``checkpoint_dir, keep_checkpoints``: where to write a
        checkpoint after every step, and how many to keep.
    proppant : Proppant or None
        Proppant carried by the slurry (issue 34, :mod:`hmatddm.simulation.proppant_step`:
        transport after each step's coupled solve, slurry viscosity, bridging, the packed bed
        a closing element keeps); needs ``pump_schedule``.
    pump_schedule : PumpSchedule or None
        The proppant volume fraction the clusters pump against time
        (:class:`hmatddm.flow.pump_schedule.PumpSchedule`).
    well : Well or None
        One pump shared by the clusters through their perforations (issue 35,
        :mod:`hmatddm.flow.well`): the clusters take no ``rate`` (the split of the pump's
        schedule follows from the perforation and wellbore friction, solved inside every
        step's coupled system) and no ``wellbore_volume`` (the well's ``volume`` stores fluid at
        the heel pressure). The records add ``heel_pressure``, ``pump_rate``,
        ``cluster_rates``, ``cluster_pressures``, ``perforation_friction`` and
        ``wellbore_friction``. Without a well every cluster needs its ``rate``.

    (The settings classes are in :mod:`hmatddm.simulation.settings`.)
    """

    def __init__(self, mesh, material, fluid, clusters, far_field_stress, time_step, propagation=None,
                 leak_off=None, initial_pressure=0.0, initial_opening=1e-5, minimum_width=None, height=1.0, *,
                 scheme="krylov", growing_fractures=None, natural_fractures=None, natural=None, remote_failure=True,
                 contact="natural", max_elements=None, step_control=None, operator_settings=None,
                 rebuild_settings=None, checkpoint_settings=None, proppant=None, pump_schedule=None, well=None,
                 **options):
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
            if natural_fractures is not None:  # cut at the interfaces (hmatddm.layered.engine)
                natural_fractures = layered_engine.natural_fracture_mesh(mesh, natural_fractures, material)
        elif not isinstance(material, Elastic):
            raise InputError(f"material must be an hmatddm.Elastic or hmatddm.LayeredMedium, got "
                             f"{type(material).__name__}")
        if not isinstance(fluid, Fluid):
            raise InputError(f"fluid must be an hmatddm.Fluid, got {type(fluid).__name__}")
        clusters = list(clusters)
        if not clusters or not all(isinstance(c, Cluster) for c in clusters):
            raise InputError("clusters must be a non-empty list of hmatddm.Cluster")
        self.well, self.well_system = _checked_well(well, clusters, fluid)
        if (self.well is None and all(c.rate == 0.0 for c in clusters)) or (
                self.well is not None and self.well.schedule.peak == 0.0):
            warnings.warn("every cluster injects at rate 0 m^3/s: nothing drives the fractures, which only relax "
                          "from their initial pressure", NoInjectionWarning, stacklevel=2)
        if propagation is not None and not isinstance(propagation, Propagation):
            raise InputError(f"propagation must be an hmatddm.Propagation or None, got {type(propagation).__name__}")
        leak_off = LeakOff() if leak_off is None else leak_off
        if not isinstance(leak_off, LeakOff):
            raise InputError(f"leak_off must be an hmatddm.LeakOff, got {type(leak_off).__name__}")
        grouped = group_options(options, operator_settings=operator_settings, rebuild_settings=rebuild_settings,
                                checkpoint_settings=checkpoint_settings)
        self.operator_settings = grouped["operator_settings"]
        self.rebuild_settings = grouped["rebuild_settings"]
        self.checkpoint_settings = grouped["checkpoint_settings"]
        d = mesh.dim
        self.far_field_stress = finite_array("far_field_stress", far_field_stress, (d, d))
        scale = 1.0 + np.abs(self.far_field_stress).max()
        if not np.allclose(self.far_field_stress, self.far_field_stress.T, rtol=0, atol=1e-9 * scale):
            raise InputError("far_field_stress must be a symmetric tensor")
        self.mesh0 = mesh
        self.material, self.fluid, self.clusters, self.leak_off = material, fluid, clusters, leak_off
        self.propagation = propagation
        # the ranges a scene's [numerics] declares (hmatddm.settings.NUMERICS)
        time_step = NUMERICS["time_step"].value("time_step", time_step)
        if time_step == "auto":  # steps that follow the front (hmatddm.simulation.step_control)
            self.step_control = StepControl() if step_control is None else step_control
            if not isinstance(self.step_control, StepControl):
                raise InputError(f"step_control must be an hmatddm.simulation.StepControl, got "
                                 f"{type(self.step_control).__name__}")
            time_step = self.step_control.first
        elif step_control is not None:
            raise InputError('step_control is for time_step = "auto"; a fixed time_step takes none')
        else:
            self.step_control = None
        self.time_step = time_step  # the first step (each step, unless "auto")
        self.initial_pressure = NUMERICS["initial_pressure"].value("initial_pressure", initial_pressure)
        self.initial_opening = NUMERICS["initial_opening"].value("initial_opening", initial_opening)
        minimum_width = self.initial_opening if minimum_width is None else minimum_width
        self.minimum_width = NUMERICS["minimum_width"].value("minimum_width", minimum_width)
        self.height = positive_scalar("height", height)
        self.settings = scheme if isinstance(scheme, SchemeSettings) else SchemeSettings(scheme=scheme)
        self.growing_fractures = None if growing_fractures is None else np.asarray(sorted(growing_fractures), np.int64)
        self.injection_elements = np.array([c.nearest_element(mesh) for c in clusters], dtype=np.int64)
        self.remote_failure = bool(remote_failure)
        self.contact = NUMERICS["contact"].value("contact", contact)
        self.network = None if natural_fractures is None else natural_network(mesh, natural_fractures, natural)
        # a resource limit, not part of the run's definition: left out of the fingerprint, so
        # that a run stopped by it resumes with a higher one
        self.max_elements = None if max_elements is None else NUMERICS["max_elements"].value("max_elements",
                                                                                             max_elements)
        self.proppant, self.pump_schedule = _checked_proppant(proppant, pump_schedule)
        self.records = []
        self._encoded_records = {}  # the records' checkpoint text, encoded once (checkpoint.metadata_text)
        # the contact factor of the step's last solve, which a growth pass's solve borders
        # (hmatddm.coupled.contact_factor); made anew at each step, so resumes stay bit for bit
        self.contact_bases = ContactBases()
        self.front = None  # propagation.front == "asymptotic": its AsymptoticFront (raises for unsupported setups)
        if propagation is not None and propagation.front == "asymptotic":
            from .asymptotic import AsymptoticFront

            self.front = AsymptoticFront(self)
        self.state = self._initial_state()
        self.operators = GrowingOperator(material, self.operator_settings, self.rebuild_settings)

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
                     time_step=self.time_step, origin=np.full(mesh.n_elements, Origin.HYDRAULIC, np.int64),
                     natural_index=-np.ones(mesh.n_elements, np.int64), intact=np.ones(n_natural, bool),
                     failed=np.zeros(n_natural, bool), extra_faces=np.zeros((0, 6)),
                     proppant_volume=None if self.proppant is None else np.zeros(mesh.n_elements),
                     heel_pressure=None if self.well is None else self.initial_pressure, **front)

    def fingerprint(self):
        """SHA-256 of everything that defines the run (a resume must match it)."""
        fluid = asdict(self.fluid)
        if self.well is None:  # (fields of issue 35 left out without a well: the fingerprints of other runs stay)
            fluid.pop("density")
        clusters = [{k: v for k, v in asdict(c).items() if v is not None} for c in self.clusters]
        parts = dict(material=asdict(self.material), fluid=fluid, clusters=clusters, leak_off=asdict(self.leak_off),
                     propagation=None if self.propagation is None else repr(self.propagation),
                     far_field_stress=self.far_field_stress.tolist(), time_step=self.time_step,
                     step_control=None if self.step_control is None else asdict(self.step_control),
                     initial_pressure=self.initial_pressure, initial_opening=self.initial_opening,
                     minimum_width=self.minimum_width, height=self.height, operator=asdict(self.operator_settings),
                     settings=repr(self.settings), contact=self.contact, remote_failure=self.remote_failure,
                     growing=None if self.growing_fractures is None else self.growing_fractures.tolist())
        if self.proppant is not None:  # (absent without proppant: the fingerprints of other runs stay)
            parts.update(proppant=asdict(self.proppant), pump_schedule=self.pump_schedule.rows())
        if self.well is not None:
            parts.update(well=asdict(self.well))
        digest = hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode())
        meshes = [self.mesh0] + ([] if self.network is None else [self.network.mesh])
        for value in [v for m in meshes for v in mesh_arrays(m).values()]:
            digest.update(np.ascontiguousarray(value).tobytes())
        if self.network is not None:
            digest.update(repr(self.network.properties).encode())
        return digest.hexdigest()

    # -- the operator and the physics of a mesh -------------------------------------------
    def operator(self, mesh):
        """The elasticity operator of ``mesh`` (:class:`~hmatddm.simulation.growing_operator.GrowingOperator`)."""
        return self.operators(mesh)

    @property
    def operator_builds(self):
        """Full operator builds so far."""
        return self.operators.builds

    @property
    def base_operator(self):
        """The last full operator build (None before the first; growth adds exact borders to it)."""
        return self.operators.base

    @property
    def compressed_elements(self):
        """Elements in the compressed base operator (0 before the first build)."""
        return self.operators.compressed_elements

    @property
    def checkpoint_dir(self):
        return self.checkpoint_settings.checkpoint_dir

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

    def flow_model(self, mesh, faces, viscosity_factor=None, well=None):
        """The :class:`LubricationModel` of ``mesh`` with flow ``faces``; ``viscosity_factor``:
        the slurry's per element (:func:`hmatddm.simulation.proppant_step.viscosity_factor`);
        ``well``: the shared well over the step (:meth:`well_link`)."""
        areas = mesh.areas * (self.height if mesh.dim == 2 else 1.0)
        if self.well is None:
            rates = np.array([c.rate for c in self.clusters])
            volumes = np.array([c.wellbore_volume for c in self.clusters])
        else:  # the well's injection is its own block (hmatddm.flow.well), but a direct well's
            direct = self.well_system.direct
            rates = np.array([well.pump_rate if direct and well is not None else 0.0] * len(self.clusters))
            volumes = np.array([self.well.volume if direct else 0.0] * len(self.clusters))
        return LubricationModel(areas=areas, normals=mesh.normals, faces=faces, fluid=self.fluid,
                                leak_off=self.leak_off, injection_elements=self.injection_elements,
                                injection_rates=rates, wellbore_volumes=volumes,
                                minimum_width=self.minimum_width, viscosity_factor=viscosity_factor, well=well)

    def well_link(self, start, t_old, t_new):
        """The shared well over the step from ``t_old`` to ``t_new`` from ``start`` (a
        :class:`StepStart`): :class:`hmatddm.flow.well.WellLink` (None without a well)."""
        if self.well is None:
            return None
        from ..flow.well import WellLink

        dt = t_new - t_old
        n = len(self.clusters)
        # the slope of an orifice is floored at this rate (only the iteration's path depends on it)
        floor = 1e-3 * max(self.well.schedule.peak, 1e-12) / n
        return WellLink(self.well_system, self.injection_elements, self.well.schedule.mean(t_old, t_new),
                        self.fluid.compressibility * self.well.volume / dt, start.heel_pressure, floor)

    # -- one step -------------------------------------------------------------------------
    def step(self, end_time=None):
        """Advance one time step (with growth and remote-failure passes); returns the record.

        With ``end_time``, a step that would reach or pass it (within 1e-9 of a step) ends
        exactly at ``end_time``: the last step of a run is shortened, never longer.
        Raises :class:`~hmatddm.errors.SizeLimitError` (the state stays the last finished
        step) when growth would take the mesh past ``max_elements``. With front-following
        steps (``step_control``), a step whose solve does not converge is tried again at
        half its length, down to ``min_time_step`` (the record's ``step_retries`` counts the
        tries). A fixed step that does not converge is tried again in halves (down to
        ``1 / 2**MAX_FIXED_STEP_SPLITS`` of it), the steps after it the rest of the fixed
        step, so that the run stays on the grid of its fixed steps; then
        :class:`~hmatddm.errors.ConvergenceError` is raised. (A step over which an element fed
        through a throttled face fills from below the minimum width, its conductance
        ``~ w^3``, may have no solution that the iteration from the step's start reaches: the
        dfn-3cluster scene at 4x its area, t = 27 s; its halves converge.)
        """
        # a step that does not converge is tried again at half its length, from the same
        # state and the same base operator: front-following steps down to min_time_step,
        # fixed steps down to 1 / 2**MAX_FIXED_STEP_SPLITS of theirs (then back on their grid);
        # the same for the element front and the asymptotic front (propagation.front =
        # "asymptotic", hmatddm.simulation.asymptotic: a first step of 0.1 s from a 3 x 3
        # start with one ribbon element cycled with period two at 1 m elements, its halves converge)
        base, clock, retries = self.operators.base, time.perf_counter(), 0
        while True:
            try:
                record = self._step(end_time) if self.front is None else self.front.step(self, end_time)
            except ConvergenceError:
                # half the step that was tried: one cut to end at end_time is shorter than
                # time_step, and half of time_step could be that same step again
                t_old, t_new = self.step_times(end_time)
                shorter = self._shorter_step(min(self.state.time_step, t_new - t_old))
                if shorter is None:
                    raise
                self.state = replace(self.state, time_step=shorter)
                self.operators.reset(base)
                retries += 1
                continue
            if self.step_control is None and self.state.time_step != self.time_step:
                self.state = replace(self.state, time_step=self._rest_of_fixed_step())
            record.update(solve_seconds=float(time.perf_counter() - clock), step_retries=retries)
            return record

    def splittable(self):
        """Whether the step being solved may still be redone in shorter steps (:meth:`step`),
        so that its coupled solve may give up early on a hopeless relaxation ladder. Element
        front only: the asymptotic front's steps are split too, but its solves keep the whole
        ladder (a trial front's solve that fails changes the front iteration's course)."""
        return self.front is None and self._shorter_step() is not None

    def _shorter_step(self, step=None):
        """Half the step ``step`` (default ``state.time_step``) that did not converge, or None
        when it may not be shorter (see :meth:`step`)."""
        step = self.state.time_step if step is None else step
        if self.step_control is not None:
            shorter = max(0.5 * step, self.step_control.minimum)
            return shorter if shorter < step else None
        shortest = self.time_step / 2.0**MAX_FIXED_STEP_SPLITS
        return 0.5 * step if 0.5 * step >= shortest * (1.0 - 1e-9) else None

    def _rest_of_fixed_step(self):
        """After a split fixed step ends at ``t``: the step to the next point of the fixed
        grid ``k * time_step`` (a whole step when ``t`` is on it)."""
        dt, t = self.time_step, self.state.time
        grid = np.ceil(t / dt - 1e-9) * dt
        rest = grid - t
        return rest if rest > 1e-9 * dt else dt

    def _step(self, end_time):
        """One step of the element front (see :meth:`step`)."""
        clock = time.perf_counter()
        t_old, t_new = self.step_times(end_time)
        begin = self.state
        start, trial = StepStart.of(begin), begin.copy()
        tally = StepTally()
        builds = self.operator_builds
        relaxation = begin.relaxation
        self.contact_bases = ContactBases()
        max_passes = 50 if self.propagation is None else self.propagation.max_growth_passes
        # growth decided on a solve's first iterate, converged only on the mesh the step keeps
        provisional = (self.propagation is not None and self.network is None
                       and self.settings.growth_check == "first")
        while True:
            trial, info, solved = step_solve.solve(self, trial, start, t_old, t_new, relaxation, provisional)
            growth = None if tally.growth_passes >= max_passes else self._growth(
                trial, solved, info, tally, margin=_paused_margin(info))
            while ((growth is None or growth is growth_pass.UNCERTAIN) and _paused_margin(info) is not None
                   and tally.growth_passes < max_passes):
                # no growth, or a tip too close to its threshold, on a paused iterate: continue
                # its GMRES solve (to the next pause, at last to the plain first iterate)
                tally.add_solve(info)
                trial, info = step_solve.refine(trial, info)
                growth = self._growth(trial, solved, info, tally, margin=_paused_margin(info))
            if growth is None and info.get("pending") is not None:  # converge, then check again
                tally.add_solve(info)
                trial, info = step_solve.finish(trial, info)
                growth = None if tally.growth_passes >= max_passes else self._growth(trial, solved, info, tally)
            relaxation = info["relaxation"]
            tally.add_solve(info)
            if growth is None:
                break
            tally.growth_passes += 1
            trial, start = self._joined(begin, trial, start, growth, t_old, t_new, tally)
        self.state = self._finished(begin, trial, solved.flow, t_old, t_new, relaxation, tally, start)
        tally.operator_builds = self.operator_builds - builds
        width = np.sum(trial.dd * trial.mesh.normals, axis=1)
        record = step_record(self, solved.flow, width, tally, relaxation, time.perf_counter() - clock, start)
        self.records.append(record)
        return record

    def step_times(self, end_time=None):
        """``(t_old, t_new)`` of the next step: one ``time_step`` (with ``"auto"``, the step
        the last one chose: :mod:`~hmatddm.simulation.step_control`), shortened to end
        exactly at ``end_time`` when it would reach or pass it (within 1e-9 of a step)."""
        t_old = self.state.time
        step = self.state.time_step
        t_new = t_old + step
        if end_time is not None and t_new >= end_time - 1e-9 * step:
            t_new = float(end_time)
        return t_old, t_new

    def _growth(self, trial, solved, info, tally, margin=None):
        """What the growth pass after a solve adds: the tips' growth (ref. Sec. 4.2.2), else
        the remote failures of intact natural elements (ref. Sec. 5.3), else None;
        ``growth_pass.UNCERTAIN`` when a tip is within ``margin`` of its threshold."""
        growth = None
        if self.propagation is not None:
            growth = growth_pass.grow(self, trial, solved.edges, solved.faces, info["drained"], tally.events, margin)
            if growth is growth_pass.UNCERTAIN:
                return growth
        if growth is None:
            growth = growth_pass.remote_failures(self, trial, tally.events)
        return growth

    def _joined(self, begin, trial, start, growth, t_old, t_new, tally):
        """``(trial, start)`` with the connections and new elements of ``growth``. Raises
        SizeLimitError when the mesh would pass ``max_elements``."""
        trial = trial.connected(growth.connections, trial.mesh.n_elements)
        new = growth.elements
        if new is None:  # only new connections to elements already in the system
            return trial, start
        self.check_growth(trial.mesh.n_elements + new.mesh.n_elements, begin.step + 1, t_new)
        tally.elements_added += new.mesh.n_elements
        guess = new.first_guess(trial.dd, self.minimum_width)
        return trial.joined(new, guess, t_old), start.joined(new, guess)

    def check_growth(self, n_elements, step, t_new):
        """Raise SizeLimitError when growth in ``step`` (ending at ``t_new``) would take the
        mesh to ``n_elements``, more than ``max_elements``."""
        if self.max_elements is not None and n_elements > self.max_elements:
            raise SizeLimitError(
                f"growth in step {step} (t = {t_new:g} s) would take the mesh to {n_elements} "
                f"elements, more than max_elements = {self.max_elements}", elements=n_elements,
                limit=self.max_elements)

    def _finished(self, begin, trial, flow, t_old, t_new, relaxation, tally, start):
        """The state at the end of the step from ``begin`` (whose start is ``start``, a
        :class:`StepStart`) whose last solve is ``trial``: volumes injected and leaked,
        natural elements failed, the next relaxation, the proppant moved over the step
        (:func:`hmatddm.simulation.proppant_step.advance`)."""
        dt = t_new - t_old
        leak = (flow.leak_off_rate(trial.creation_time, t_old, t_new) * flow.areas
                * (trial.pressure - self.leak_off.pore_pressure))
        failed = begin.failed.copy()
        if self.network is not None:
            failed[trial.natural_index[trial.origin == Origin.FAILED]] = True
        next_relaxation = relaxation
        if tally.restarts == 0:  # an easy step: let alpha grow back (SchemeSettings.relaxation_growth)
            next_relaxation = min(self.settings.relaxation, relaxation * self.settings.relaxation_growth)
        next_step = begin.time_step
        if self.step_control is not None:
            # the front at the step's end: the topology of the last solve's mesh, already computed
            faces = with_links(mesh_topology(trial.mesh, self.height)[1], trial.extra_faces)
            front = front_elements(faces, trial.mesh.n_elements, 4 if trial.mesh.dim == 3 else 2)
            advance = advance_of_step(tally.elements_added, front)
            planned = begin.time_step
            if dt < planned:  # shortened to end at a run's end time: the front's pace over the planned step
                advance *= planned / dt
            next_step = self.step_control.next_step(max(dt, planned), advance)
        pumped, heel = None, None
        if self.well is None:
            pumped = dt * sum(c.rate for c in self.clusters)
        else:  # the schedule's exact volume; the heel pressure of the converged solve
            pumped = self.well.schedule.volume(t_old, t_new)
            heel = float(flow.well.state(trial.pressure)[0])
        return replace(trial, time=t_new, step=begin.step + 1, relaxation=next_relaxation, time_step=next_step,
                       injected_volume=begin.injected_volume + pumped, heel_pressure=heel,
                       leaked_volume=begin.leaked_volume + float(np.sum(leak)) * dt, failed=failed,
                       **proppant_step.advance(self, begin, trial, start, flow, t_old, t_new))

    def view(self):
        """Every element of the run for output: ``(mesh, dd, pressure, state)`` with the
        active elements first, then the intact natural elements (zero DD, the pore
        pressure). ``state``: 0 hydraulic, 1 intact natural, 2 activated or failed natural."""
        return output_view(self)

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
            from .progress import Progress

            shown = Progress(end_time, self.time_step, stream=None if progress is True else progress,
                             start_time=self.state.time)
        try:
            while self.state.time < end_time - 1e-9 * self.state.time_step:
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
        metadata = dict(s.scalars(), records=self.records, fingerprint=self.fingerprint(),
                        compressed_elements=self.compressed_elements, image_choice=self.operators.image_choice)
        checkpoint.save(self.checkpoint_dir, s.step, s.arrays(), metadata,
                        keep=self.checkpoint_settings.keep_checkpoints, encoded=self._encoded_records)

    def load_checkpoint(self):
        arrays, metadata = checkpoint.load_latest(self.checkpoint_dir)
        if metadata.get("fingerprint") != self.fingerprint():
            raise checkpoint.CheckpointError(
                f"the checkpoints in {str(self.checkpoint_dir)!r} belong to a different run "
                "(settings or initial mesh differ); use another checkpoint folder")
        self.state = State.from_checkpoint(arrays, metadata)
        if self.state.time_step is None:  # a checkpoint written before steps were recorded in it
            self.state.time_step = self.time_step
        self.records = list(metadata["records"])
        # rebuild the compressed base exactly as the interrupted run had it, so the
        # resumed run applies the same operator (bit for bit)
        self.operators.restore(self.state.mesh, int(metadata.get("compressed_elements", 0)),
                               metadata.get("image_choice"))
        return self.state


def _checked_proppant(proppant, schedule):
    """``(proppant, schedule)``, both None or both given, the schedule below the packing limit."""
    from ..flow.proppant import Proppant
    from ..flow.pump_schedule import PumpSchedule

    if proppant is None and schedule is None:
        return None, None
    if not isinstance(proppant, Proppant):
        raise InputError(f"proppant must be an hmatddm.flow.Proppant when a pump_schedule is given, got "
                         f"{type(proppant).__name__}")
    if not isinstance(schedule, PumpSchedule):
        raise InputError(f"pump_schedule must be an hmatddm.flow.PumpSchedule when proppant is given, got "
                         f"{type(schedule).__name__}")
    highest = max(schedule.concentrations)
    if highest >= proppant.packing_limit:
        raise InputError(f"pump_schedule concentrations must be below proppant.packing_limit = "
                         f"{proppant.packing_limit:g}, got {highest:g}")
    return proppant, schedule


def _checked_well(well, clusters, fluid):
    """``(well, its WellSystem)`` (both None without a well); without a well every cluster
    needs its ``rate``."""
    from ..flow.well import Well

    if well is None:
        for i, c in enumerate(clusters):
            if c.rate is None:
                raise InputError(f"cluster[{i}].rate is required (m^3/s, >= 0) when the clusters do not share a well "
                                 f"(a [well] with a pump schedule)")
        return None, None
    if not isinstance(well, Well):
        raise InputError(f"well must be an hmatddm.flow.Well or None, got {type(well).__name__}")
    return well, well.system(clusters, fluid.density)


def _paused_margin(info):
    """The growth-pass margin of a solve whose provisional iterate is paused
    (:func:`hmatddm.simulation.growth_pass.paused_margin`), None otherwise."""
    pending = info.get("pending")
    if pending is None or not pending.refinable:
        return None
    return growth_pass.paused_margin(pending.paused_level)
