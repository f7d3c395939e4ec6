"""Time steps of a planar fracture whose front lies inside the tip elements
(``Propagation(front="asymptotic")``; implicit level set, Peirce and Detournay 2008).

Elements are *channel* (fully fractured, the plain fluid-loaded elasticity rows),
*tip* (crossed by the front: their opening is prescribed, the universal asymptote
averaged over the element, :func:`hmatddm.fracture.front.fill`) or *empty* (reached by
no front yet: opening 0). Every element keeps its flow row, so a tip element holds the
fluid volume of its partial opening and its pressure is the one its fluxes need. Per
time step, with the ribbon elements (channel elements next to the front) fixed:

1. from the trial distances ``s_r`` of the ribbon centres to the front, the front
   (:class:`~hmatddm.fracture.front.FrontField`), the tip elements and their openings;
   elements the front reaches for the first time join the mesh like the element switch's
   growth (:meth:`~hmatddm.simulation.state.State.joined`, :meth:`~hmatddm.simulation.state.StepStart.joined`;
   the operator grows by border blocks, :meth:`Simulation.operator`);
2. the coupled step (:func:`hmatddm.coupled.solve_step`, any scheme) with the tip rows
   ``DD_i = w_i n_i``;
3. the ribbon openings give new ``s_r`` by inverting the asymptote with ``V = (s_r -
   s_r^n) / dt`` (:meth:`~hmatddm.analytical.tip_asymptote.TipAsymptote.front_distance`);

until no ``s_r`` changes by more than ``front_tolerance`` element sizes (by default
:data:`FRONT_TOLERANCE`, :data:`LEAK_OFF_FRONT_TOLERANCE` with leak-off). The update of
``s_r`` is relaxed when it oscillates and, in 3D, accelerated by Anderson mixing of the
last iterates (:mod:`hmatddm.simulation.front_acceleration`). Each coupled solve starts at the
relaxation ``alpha`` the last one converged with, grown by ``relaxation_growth`` (up to
``relaxation``) when that one needed no restart: the alpha one trial front needed (a front far
ahead of the fluid took 1/128) is not kept for the next ones, where the coupled iteration
contracts ~0.5 per iteration at alpha = 1 but ``1 - alpha / 2`` at alpha (issue 33: kept, the
radial M~ run's full-tolerance solves failed at 1/128 and 1/256 one after another).

**Inexact front iteration** (issue 33: a step costs a few products, not a few full solves
per front iteration). Far from its fixed point the front iteration does not need the
coupled step solved to the scheme's tolerances (1e-6 of the change, GMRES to 1e-9): a ribbon
opening off by ``e`` (relative) moves its distance to the front by ~``2 e`` of it (``s ~ w^2``
at a toughness tip). After an iteration that moved the ribbon by ``c`` elements, more than
``inexact_from`` (10) front tolerances, the next solve asks ``inexact_forcing c`` (1%; at most
``inexact_ceiling``, 1e-3) of the nonlinear change and GMRES tolerances looser by the same
factor (:meth:`AsymptoticFront.inner_settings`, the forcing term of an inexact Newton
method); once within 10 front tolerances, the scheme's own. A step never ends on a loose
solve: one that meets the front tolerance is followed by one at full accuracy. 3D only, as
the acceleration: measured on the 0.5 m radial-k run, a third fewer products (15,540 ->
10,366) with the radius and opening the same to 4e-6 and 5e-8 (relative); a plane-strain
power-law run (kgd, n = 0.5, fully coupled) cycled by whole elements with it.

Both the inversion (3) and the tip openings (1) use the asymptote of a fracture of finite size
``L`` (:func:`~hmatddm.analytical.tip_asymptote.finite_fracture_factor`), with ``L`` the radius
``sqrt(A/pi)`` (3D) or the half-length (2D) at the start of the step plus the trial front's
mean advance (``AsymptoticFront.finite_fracture = False``: the bare semi-infinite asymptote).

**The ribbon stays away from the front.** In a plane-strain run an element the front
has crossed (*filled*) keeps its prescribed opening (the asymptote, fully inside the front)
and joins the channel only at the start of a step where its centre lies at least ``c h``
behind the front, ``c = max(ribbon_elements, ribbon_growth (L/h)^(1/2))``
(:meth:`AsymptoticFront.ribbon_distance`), so the ribbon's distance to the front is
``s_r >= c h``. Why, measured on a Griffith crack of constant elements under uniform pressure
whose elements within ``c h`` of the front hold the exact opening averaged over them
(benchmarks/bench_asymptotic_ribbon.py, an independent solve): the ribbon's opening is off
the exact one at its centre by +20% at ``s_r = 0.55 h``, +5% at 0.8 h, -1.4% at 1.3 h,
-0.2..-0.3% at 1.5-2.3 h, -0.1% at 3 h, whatever ``L/h``. The old rule (a filled element joined
the channel at once, the ribbon at ``s_r >= h/2``) read the ribbon 5-20% too wide after each
element the front crossed: the front ran ahead by an element, stalled while the fluid caught
up, and the 40-iteration cap cut the drift (the KGD half-length error +0.8, +0.8, +4.9, +1.0%
at 1, 0.5, 0.25, 0.125 m, a sawtooth in time). With ``s_r >= 1.5 h`` the error of the ribbon
is a fixed fraction of its opening at every ``h`` (a sqrt profile has no length scale), which
reads the toughness ~0.3% high at every mesh; growing ``c`` as ``(L/h)^(1/2)`` moves the
ribbon more elements from the front as the mesh is refined (its error falls) while its
distance ``c h = ribbon_growth (L h)^(1/2)`` still shrinks (kgd, K_m 8.7: every error falls
from h = 1 to 0.125 m, benchmarks/RESULTS.md, issue 39) at a toughness-dominated tip
(:meth:`AsymptoticFront.toughness_share` at least ``toughness_tip`` = 0.95; K_m >~ 4 in
KGD), where the asymptote holds far from the front (Griffith's opening). At any other tip
``c = ribbon_elements`` (1.5), and only once the half-length is ``resolved_tip`` (20)
elements or more: the ribbon next to a viscous front has the same scale-free error (the same
independent solve with the KGD M vertex's exact pressure and opening: +26% at ``s_r = 0.5 h``,
+7.7% at 0.8 h, +2.6% at h, 0 at 1.3 h; +7% averaged over ``[0.5, 1.5] h``, within +-0.25%
over ``[1.5, 2.5] h``), which made the tip's asymptote look ~7% narrower and the KGD M-vertex
run converge in h to a fracture 0.4% too long and 0.25% too thin (issue 39); with the ribbon
1.5 h away the errors fall to 0.03-0.05% at 0.125 m. On a coarse mesh (fewer than ~20
elements in the half-length) ``2.5 h`` is too far for the semi-infinite asymptote at a
viscous tip (the KGD M-vertex at 1 m, 24 s: half-length -1.5% with it, 0.0% without), so there
the ribbon stays next to the front. **3D**: the same rule (``c = 1.5``, the radius for ``L``) at
a tip that is not toughness-dominated, once the radius is ``resolved_tip`` elements
(``AsymptoticFront.far_ribbon_3d``). The ribbon next to a penny crack's front has the same
scale-free error (bench_asymptotic_ribbon.py ``--penny``, squares: at the radial M vertex +10%
at ``s_r`` in ``[0.5, 0.75) h``, +4% in ``[0.75, 1) h``, +1% in ``[1, 1.25) h``, +4-5% averaged
over the near ribbon, within +-0.1% from 1.5 h on; Sneddon's crack +8%, +2%, -0.4..-0.9%, +2-3%
averaged, -0.2..-0.4% from 1.5 h on), and the radial M-vertex run (K_m 0.005) converged with the
near ribbon to a fracture too long and thin (R +0.06 / +0.30%, w0 -0.12 / -0.33% at 0.5 / 0.25
m); with the far ribbon -0.36 / -0.10%, +0.35 / +0.05% (benchmarks/RESULTS.md, issue 39, "the far
ribbon in 3D"). At a toughness tip (by ``toughness_share``: radial-k and radial-km) 3D keeps
``s_r >= h/2``: there the far ribbon moved radial-k (K_m 4-6, 0.5 m) from R -0.23% / w0 +0.54%
to -0.37% / +1.10% against the K vertex (Dontsov's transition: -0.10% / +0.50%). Why, measured
(benchmarks/bench_ribbon_curvature.py; RESULTS.md, issue 39, "why the far ribbon fails at a 3D
toughness tip"): not the front's curvature in the asymptote (the finite-fracture factor inverts
Sneddon's opening exactly at any ``s``; without it the far band would read the front 0.10 h too
near at R = 20 h) but in the level set. First-order fast marching from ribbon centres ``s_r``
behind a convex front puts the front too near by ~0.25 ``s_r h / R`` (-0.015 h from the near
ribbon, -0.024 h from the far one at R = 20 h); the filled band's prescribed openings follow
it, so the far ribbon of Sneddon's crack reads 0.7 / 0.6 / 0.5% narrow (against its centre) at
R = 20 / 30 / 40 h, 0.3% with the exact openings in the band: a toughness read ~0.5% high, a
run shorter and wider by an error that falls only as ``h / R``. With the level set replaced by
the front interpolated in angle from the ribbons (an experiment, radial fronts only) the far
ribbon's radial-k gives R -0.19 / -0.15%, w0 +0.66 / +0.56% at 0.5 / 0.25 m, converging to
Dontsov's; the near ribbon reads ~1% wide, which cancels the level set's error in the default.
The general remedy is built as an option: ``AsymptoticFront.level_set_order = 2`` (3D only) takes
the front reconstructed from the ribbon to second order (:mod:`hmatddm.fracture.front_fit`; a
circle from exact ``s_r`` within 1e-3 h at R = 10 h, the march 0.04-0.09 h) and
``far_ribbon_3d_toughness = True`` the far ribbon at 3D toughness tips by the 2D rule. With both,
radial-k against Dontsov's transition: R -0.11 / -0.07%, w0 +0.18 / +0.12% at 0.5 / 0.25 m, RMS
over the second half 0.10 / 0.07% and 0.18 / 0.11% (the default: -0.13 / -0.03%, +0.03 /
-0.05%, RMS 0.28 / 0.06% and 0.41 / 0.20%). The build before ``front_fit.BAND``: radial-k 1 m
-0.15%, +0.35% (default -0.44%, +0.55%); radial-km 0.5 m R -0.38%, w0 -0.03% (default -0.40 /
-0.14%); radial-m 0.5 m R -0.60%, w0 +0.46% (default -0.75 / +0.60%). Not the default: the
0.25 m radial-m run took more than 4x the default's CPU (front iterations; not resolved), and
the default's final 0.5 m radial-k w0 is nearer Dontsov's, by the cancellation above
(benchmarks/RESULTS.md, issue 39, "a second-order level set").

**Carter leak-off** (a Newtonian fluid): the tip asymptote with leak-off, the elements the
front crosses leaking point by point, and the front iteration bracketed --
:mod:`hmatddm.simulation.front_leak_off`, where the measurements are.

Over 500 lines: one step's front iteration (fill, solve, inversion, relaxation, leak-off
brackets, far ribbons) reads best as one loop.
"""
import logging
import time
from dataclasses import replace

import numpy as np

from ..coupled import ElasticSolver, StepProblem, solve_step
from ..coupled.contact import ContactRows
from ..errors import ConvergenceError, InputError
from ..flow import fracture_compliance
from ..fracture.front import CHANNEL, EMPTY, FILLED, TIP, FrontField, PlanarGrid, fill, front_radii, level_set
from ..analytical.power_law_tip import tip_asymptote
from ..analytical.tip_asymptote import finite_fracture_factor
from ..analytical.tip_leak_off import LeakOffTipAsymptote
from . import proppant_step
from .front_acceleration import front_mixing
from .front_leak_off import MAX_RETREATS, crossing_times, starved, tip_leak_off_rate
from .records import StepTally, step_record
from .step_solve import mesh_topology
from .state import NewElements, StepStart

logger = logging.getLogger(__name__)
# sample points per element side for the filled fraction and mean opening of tip elements
# (2D: a segment, fine and cheap; 3D: 8 x 8, the fraction of the front's many tip elements
# averages out)
SUB_SAMPLES = {1: 256, 2: 8}

#: The front tolerance (element sizes) when the scene sets none: 1e-3 chased the fill's
#: discrete events for up to 30 solves a step without moving the answer (benchmarks/
#: RESULTS.md, issue 33, "the lattice"); with leak-off 1e-2 left the radial M~ run's centre
#: opening 6.7% from the vertex against 1.8% (tests/scene/test_leak_off_reference.py).
FRONT_TOLERANCE, LEAK_OFF_FRONT_TOLERANCE = 1e-2, 1e-3


class PrescribedOpening:
    """Elasticity rows ``k DD_i = k w_i n_i`` of the prescribed (tip, empty) elements, as
    block-diagonal rows (the ``contact`` interface of :class:`~hmatddm.coupled.StepProblem`,
    :class:`~hmatddm.coupled.contact.ContactRows`); ``k`` the element's own stiffness."""

    frozen = 0
    active_set = False  # fixed rows: no active-set update (and no residual matvec) per iterate

    def __init__(self, prescribed, width, normals, stiffness):
        n, d = normals.shape
        select = np.repeat(np.eye(d)[None], n, axis=0)
        select[prescribed] = 0.0
        direct = np.zeros((n, d, d))
        direct[prescribed] = stiffness[prescribed, None, None] * np.eye(d)
        rhs = np.zeros((n, d))
        rhs[prescribed] = (stiffness * width)[prescribed, None] * normals[prescribed]
        self._rows = ContactRows(select, direct, rhs, hash((n, np.asarray(prescribed, bool).tobytes())))

    def rows(self):
        return self._rows

    def reset(self):
        pass

    def update(self, dd, traction):
        return 0


class AsymptoticFront:
    """The asymptotic front of one :class:`~hmatddm.Simulation` (checks its setup)."""

    finite_fracture = True  # the asymptote of a fracture of the current size (module docstring)
    # a filled element joins the channel where its centre is >= c h behind the front,
    # c = max(ribbon_elements, ribbon_growth (L/h)^(1/2)) (module docstring)
    ribbon_elements = 1.5
    ribbon_growth = 0.5
    toughness_tip = 0.95  # ... where the toughness share of the ribbon (toughness_share) is at least this
    # ... and at any other tip c = ribbon_elements once the half-length is at least this many
    # elements (issue 39: the ribbon next to a viscous front reads +7% wide on average)
    resolved_tip = 20.0
    # ... and in 3D at such a (not toughness-dominated) tip once the radius is resolved_tip elements
    # (issue 39, "the far ribbon in 3D"); False: 3D keeps the ribbon next to the front everywhere
    far_ribbon_3d = True
    # ... and in 3D at a toughness-dominated tip too, by the 2D rule (c grows as (L/h)^(1/2));
    # False: 3D toughness tips keep the ribbon next to the front (module docstring)
    far_ribbon_3d_toughness = False
    # the level set of the 3D front (FrontField order): 1 first-order fast marching, bilinear
    # between cell centres; 2 the front reconstructed to second order (hmatddm.fracture.front_fit)
    level_set_order = 1
    # Anderson acceleration of the front iteration, 3D only (hmatddm.simulation.front_acceleration):
    # a 0.5 m radial K-vertex run takes half the front iterations with the same errors to 0.07
    # points; a plane-strain run's errors, 0.1-0.3 % and falling with h, moved by up to 0.08
    # points with it and no longer fell from 1 m to 0.5 m (RESULTS.md, issue 33)
    accelerate = True
    # inexact front iteration, 3D only (module docstring): a front iteration after one that moved the
    # ribbon by c > inexact_from front tolerances solves the coupled step to inexact_forcing c
    # (relative; at most inexact_ceiling) instead of the scheme's tolerances; 0: off
    inexact_forcing = 0.01
    inexact_from = 10.0
    inexact_ceiling = 1e-3

    def __init__(self, simulation):
        sim = simulation
        prop = sim.propagation
        unsupported = []
        if sim.network is not None:
            unsupported.append("natural fractures")
        if sim.leak_off.coefficient != 0.0 and sim.fluid.flow_index != 1.0:
            unsupported.append("leak-off (leak_off.coefficient > 0) with a power-law fluid")
        if prop.bounds is not None:
            unsupported.append("propagation.bounds")
        if sim.contact == "all":
            unsupported.append("contact = 'all'")
        if unsupported:
            raise InputError("propagation.front = 'asymptotic' supports one planar fracture without "
                             + ", ".join(unsupported) + "; use propagation.front = 'element'")
        self.grid = PlanarGrid(sim.mesh0)
        if sim.growing_fractures is not None and int(sim.mesh0.fracture_id[0]) not in sim.growing_fractures:
            raise InputError("propagation.front = 'asymptotic': the fracture is not among growing_fractures")
        # a power-law fluid (n < 1): its own k-m asymptote (hmatddm.analytical.power_law_tip)
        self.asymptote = tip_asymptote(sim.material.plane_strain_modulus, prop.toughness, sim.fluid.viscosity_prime,
                                       sim.fluid.flow_index)
        self.leak_off = sim.leak_off
        if sim.leak_off.coefficient != 0.0:  # Carter's leak-off in the tip (C' set per step, step())
            self.asymptote = LeakOffTipAsymptote(sim.material.plane_strain_modulus, prop.toughness,
                                                 sim.fluid.viscosity_prime)
        self._solver = None

    # -- the front at t = 0 -------------------------------------------------------------
    def initial(self, mesh):
        """``(front_distance, front_velocity, front_class)`` of the initial elements: every
        element is a circle reaching the boundary of the initial rectangle of cells."""
        grid = self.grid
        cells = grid.cells(mesh.centers)
        lo, hi = cells.min(axis=0) - 0.5, cells.max(axis=0) + 0.5
        if int(np.prod(hi - lo).round()) != mesh.n_elements or np.unique(grid.key(cells)).size != mesh.n_elements:
            raise InputError("propagation.front = 'asymptotic' needs an initial fracture that fills a rectangle "
                             "(3D) or a segment (2D) of elements")
        distance = grid.h * np.min(np.minimum(cells - lo, hi - cells), axis=1)
        velocity = np.zeros(mesh.n_elements)
        field = self.field(cells, distance, velocity, cells)
        fraction, _, full = fill(cells, field, self.asymptote, SUB_SAMPLES[self.grid.k])
        front_class = np.where(full, CHANNEL, np.where(fraction > 0.0, TIP, EMPTY)).astype(np.int64)
        return distance, velocity, front_class

    def field(self, cells, distance, velocity, channel):
        """The :class:`~hmatddm.fracture.front.FrontField` of ribbon ``cells`` at ``distance``."""
        margin = int(np.ceil(np.max(distance) / self.grid.h)) + 3
        return FrontField(cells, distance, velocity, channel, self.grid.h, margin,
                          order=self.level_set_order if self.grid.k == 2 else 1)

    # -- one step ------------------------------------------------------------------------
    def inner_settings(self, settings, change, front_tolerance):
        """The solver settings of a front iteration that follows one whose ribbon moved by
        ``change`` elements (inexact front iteration, module docstring): tolerances
        ``inexact_forcing`` times ``change`` (at most ``inexact_ceiling``), never tighter than
        ``settings``, and the GMRES tolerances looser by the same factor; ``settings`` itself
        once ``change`` is within ``inexact_from`` front tolerances (or with
        ``inexact_forcing = 0``)."""
        if not self.inexact_forcing > 0.0 or not change > self.inexact_from * front_tolerance:
            return settings
        base = max(settings.tolerance_pressure, settings.tolerance_opening)
        loose = min(self.inexact_forcing * change, self.inexact_ceiling)
        factor = loose / base
        if factor <= 1.0:
            return settings
        return replace(settings, tolerance_pressure=settings.tolerance_pressure * factor,
                       tolerance_opening=settings.tolerance_opening * factor,
                       linear_rtol=min(settings.linear_rtol * factor, self.inexact_ceiling),
                       first_linear_rtol=min(max(settings.first_linear_rtol, settings.linear_rtol) * factor,
                                             self.inexact_ceiling))

    def _solve(self, sim, trial, start, prescribed, width, t_old, t_new, relaxation, tip_leak_off=None,
               settings=None):
        """The coupled step from ``start`` (a :class:`~hmatddm.simulation.state.StepStart`) on
        the mesh of ``trial`` with the ``prescribed`` elements' openings held at ``width``:
        ``(trial with the solution, info, flow model)``. ``tip_leak_off``: ``(elements, rate)``
        replacing Carter's step rate of those elements (:func:`~.front_leak_off.tip_leak_off_rate`). The elastic solver (and its inverse
        of the modified rows) is kept across the front iterations of one operator."""
        mesh = trial.mesh
        _, faces = mesh_topology(mesh, sim.height)
        flow = sim.flow_model(mesh, faces, proppant_step.viscosity_factor(sim, trial, start.width),
                              well=sim.well_link(start, t_old, t_new))
        op = sim.operator(mesh)
        if self._solver is None or self._solver.operator is not op:
            self._solver = ElasticSolver(op, rtol=sim.settings.linear_rtol)
        rows = PrescribedOpening(prescribed, width, mesh.normals, self._solver.normal_stiffness(mesh.normals))
        flow.tip_leak_off = tip_leak_off  # also in the step's budget (hmatddm.simulation.records)
        leak_off_rate = flow.leak_off_rate(trial.creation_time, t_old, t_new)
        problem = StepProblem(elastic=self._solver, normals=mesh.normals, far_field=sim.far_field_traction(mesh),
                              flow=flow, compliance=fracture_compliance(mesh, sim.material), dt=t_new - t_old,
                              width_old=start.width, pressure_old=start.pressure,
                              leak_off_rate=leak_off_rate, contact=rows)
        guess = trial.dd.copy()
        guess[prescribed] = width[prescribed, None] * mesh.normals[prescribed]
        dd, p, info = solve_step(problem, settings or sim.settings, guess.ravel(), trial.pressure, relaxation)
        return replace(trial, dd=dd.reshape(mesh.n_elements, mesh.dim), pressure=p), info, flow

    def _candidates(self, cells, channel, field):
        """Cells the front may cross: cells of the field's box within half a diagonal of the
        front, not channel, plus every element of the mesh that is not channel (M, k)."""
        grid = self.grid
        k, h = grid.k, grid.h
        box = np.stack(np.meshgrid(*[np.arange(n) for n in field.phi.shape], indexing="ij"), axis=-1)
        box = box.reshape(-1, k) + field.low
        near = box[field.at_cells(box) < 0.5 * np.sqrt(k) * h + 1e-9 * h]
        own = cells[~channel]
        both = np.unique(np.concatenate([near, own]), axis=0)
        return both[~np.isin(grid.key(both), grid.key(cells[channel]))]

    def step(self, sim, end_time=None):
        clock = time.perf_counter()
        begin = sim.state
        prop = sim.propagation
        grid, h = self.grid, self.grid.h
        t_old, t_new = sim.step_times(end_time)
        dt = t_new - t_old
        start, trial = StepStart.of(begin), begin.copy()
        tally = StepTally()
        builds = sim.operator_builds

        # the front at t_old
        mesh = begin.mesh
        circle = np.isfinite(begin.front_distance)
        # the ribbon: channel elements with an edge neighbour that is not channel
        cells = grid.cells(mesh.centers)
        # (the field of the old ribbon: inward through the cells that were channel before it)
        old = self.field(cells[circle], begin.front_distance[circle], begin.front_velocity[circle],
                         cells[begin.front_class == CHANNEL])
        size = self.measures(begin, sim)
        size = size["radius"] if grid.k == 2 else size["half_length"]
        filled_old = begin.front_class == FILLED
        toughness_tip = self.toughness_share(begin, size) >= self.toughness_tip
        resolved = size >= self.resolved_tip * h
        # 3D: at a resolved tip that is not toughness-dominated (module docstring)
        far_ribbon = (toughness_tip or resolved) if grid.k == 1 else self.far_ribbon_3d and (
            (resolved and not toughness_tip) or (toughness_tip and self.far_ribbon_3d_toughness))
        if far_ribbon:  # a filled element joins the channel c h behind the front
            filled_old &= old.at_cells(cells) <= -self.ribbon_distance(size, toughness_tip) * h
        channel = (begin.front_class == CHANNEL) | filled_old
        channel_keys = grid.key(cells[channel])
        around = grid.key(grid.neighbours(cells[channel]).reshape(-1, grid.k)).reshape(int(channel.sum()), -1)
        ribbon = np.flatnonzero(channel)[~np.all(np.isin(around, channel_keys), axis=1)]
        distance_old = np.maximum(-old.at_cells(cells[ribbon]), 0.0)
        leaking = self.leak_off.coefficient != 0.0
        tolerance = prop.front_tolerance if prop.front_tolerance is not None else \
            (LEAK_OFF_FRONT_TOLERANCE if leaking else FRONT_TOLERANCE)
        if leaking:  # C' = c_l (p - p_r) at the ribbon's mean pressure at t_old
            self.asymptote.carter = self.leak_off.coefficient * max(
                float(np.mean(begin.pressure[ribbon])) - self.leak_off.pore_pressure, 0.0)
        velocity = old.velocity(cells[ribbon] * h)
        length_old = size if self.finite_fracture else np.inf
        distance = distance_old + velocity * dt
        length = length_old + float(np.mean(distance - distance_old))

        relaxation = starting = begin.relaxation  # the last solve's alpha; the next one's (module docstring)
        change, iterations, weight = np.inf, 0, 1.0
        last_update = np.zeros(len(ribbon))
        mixing = front_mixing()  # hmatddm.simulation.front_acceleration
        filled = np.zeros(mesh.n_elements, bool)  # filled once in this step: stays filled (no tip/filled cycling)
        retreats = 0  # failed coupled solves in a row (leak-off: the trial front's advance halved each time)
        ceiling = np.full(len(ribbon), np.inf)  # leak-off: the nearest trial front too far (solve failed or
        floor = distance_old.copy()  # the inversion asked for less), the farthest too near
        for iterations in range(1, prop.front_iterations + 1):
            filled_before = filled.copy()
            field = self.field(cells[ribbon], distance, velocity, cells[channel])
            candidates = self._candidates(cells, channel, field)
            fraction, mean_width, full = fill(candidates, field, self.asymptote, SUB_SAMPLES[self.grid.k], length,
                                              full_widths=far_ribbon)  # a full cell's opening is prescribed there only
            index = {key: i for i, key in enumerate(grid.key(cells).tolist())}
            where = np.array([index.get(key, -1) for key in grid.key(candidates).tolist()], np.int64)
            new = (where < 0) & (fraction > 0.0)
            if np.any(new):
                where[new] = mesh.n_elements + np.arange(np.count_nonzero(new))
                trial, start = self._joined(sim, trial, start, candidates[new], channel, tally, t_old, t_new)
                mesh = trial.mesh
                cells = np.concatenate([cells, candidates[new]])
                channel, filled = (np.concatenate([a, np.zeros(mesh.n_elements - len(a), bool)])
                                   for a in (channel, filled))
            kept = where >= 0
            state = np.full(mesh.n_elements, CHANNEL, np.int64)
            width = np.zeros(mesh.n_elements)
            state[where[kept]] = np.where(full[kept], FILLED, np.where(fraction[kept] > 0.0, TIP, EMPTY))
            filled |= state == FILLED
            state[filled] = FILLED
            state[channel] = CHANNEL
            width[where[kept]] = mean_width[kept]
            if leaking:  # an element leaks from when the front crosses its centre (module docstring)
                tau = crossing_times(trial.creation_time, cells, channel, old, field, t_old, t_new)
                # filled in an earlier iteration of the step (it stays filled) but behind this
                # trial front's centre line: it joins the channel next step, leaking from t_new
                tau[(state == FILLED) & ~np.isfinite(tau)] = t_new
                trial = replace(trial, creation_time=tau)
            tip_leak_off = None
            if leaking:  # the elements the front crosses leak point by point (front_leak_off)
                crossing = np.flatnonzero(~channel)
                tip_leak_off = (crossing, tip_leak_off_rate(self.grid, self.leak_off.coefficient, cells[crossing],
                                                              old, field, t_old, t_new))
            prescribed = (state == TIP) | (state == EMPTY)
            if far_ribbon:  # a filled element keeps the asymptote's opening (module docstring)
                prescribed |= state == FILLED
            last_try = iterations == prop.front_iterations  # the step may end on this solve: full accuracy
            settings = (self.inner_settings(sim.settings, change, tolerance)
                        if grid.k == 2 and not last_try else sim.settings)
            loose = settings is not sim.settings
            try:
                solved, info, flow = self._solve(sim, trial, start, prescribed, width, t_old, t_new, starting,
                                                 tip_leak_off, settings)
                if leaking and starved(solved, prescribed):
                    raise ConvergenceError("elements behind the trial front starved")
                trial = solved
            except ConvergenceError:
                # a trial front far ahead of the fluid can starve the elements behind it (at an M~
                # tip their leak-off takes more than the flow brings): halve its advance and retry
                retreats += 1
                if retreats > MAX_RETREATS or leaking is False:
                    raise
                logger.debug("front iteration %d: the coupled solve failed; the trial front's advance halved",
                             iterations)
                filled = np.concatenate([filled_before, np.zeros(len(filled) - len(filled_before), bool)])
                ceiling = np.minimum(ceiling, distance)  # no later trial front goes this far again
                distance = distance_old + 0.5 * (distance - distance_old)
                velocity = (distance - distance_old) / dt
                length = length_old + float(np.mean(distance - distance_old))
                last_update = np.zeros(len(ribbon))
                continue
            retreats = 0
            relaxation = starting = info["relaxation"]  # the step's alpha: that of its last solve
            if info["restarts"] == 0:  # an easy solve: the next trial front's starts at alpha grown back
                starting = min(sim.settings.relaxation, relaxation * sim.settings.relaxation_growth)
            tally.add_solve(info)
            ribbon_width = np.sum(trial.dd[ribbon] * mesh.normals[ribbon], axis=1)
            new_distance, _ = self.asymptote.front_distance(ribbon_width, distance_old, dt, length=length)
            # at most one element per iteration: far from the fixed point the ribbon takes the
            # volume the trial front leaves out, and the asymptote answers with a far front
            new_distance = np.maximum(np.clip(new_distance, distance - h, distance + h), distance_old)
            # below a trial front whose solve failed: halfway to it at most (bisection)
            new_distance = np.minimum(new_distance, np.where(np.isfinite(ceiling), 0.5 * (distance + ceiling), np.inf))
            update = new_distance - distance
            change = float(np.max(np.abs(update))) / h
            # relax an iteration that oscillates (the update turned back), speed up one
            # that creeps in one direction
            weight = max(0.5 * weight, 0.125) if np.dot(update, last_update) < 0.0 else min(1.5 * weight, 1.0)
            last_update = update
            accelerated = mixing.step(distance, update) if self.accelerate and grid.k == 2 else None
            if accelerated is None:
                proposal = distance + weight * update
            else:  # Anderson's step, held to an element and behind no old front like the plain one
                proposal = np.maximum(distance + np.clip(accelerated, -h, h), distance_old)
            if leaking:
                # bracket each ribbon's front (the inversion asks for more below it, less above):
                # at a leak-off-dominated tip the advance goes as a high power of the ribbon's
                # opening (w ~ V^(1/8) s^(5/8) at m~), the plain iteration cycled by whole elements
                floor = np.where(update > 0.0, np.maximum(floor, distance), floor)
                ceiling = np.where(update < 0.0, np.minimum(ceiling, distance), ceiling)
                outside = np.isfinite(ceiling) & ((proposal <= floor) | (proposal >= ceiling))
                proposal = np.where(outside, 0.5 * (floor + ceiling), proposal)
                if np.all(np.isfinite(ceiling)):  # located to the bracket's width
                    change = min(change, float(np.max(ceiling - floor)) / h)
            distance = proposal
            velocity = (distance - distance_old) / dt
            length = length_old + float(np.mean(distance - distance_old))  # the trial front's size
            logger.debug("front iteration %d: %d elements, %d ribbon, %d tip, %d empty, change %.3g elements",
                         iterations, mesh.n_elements, len(ribbon), np.count_nonzero(state == TIP),
                         np.count_nonzero(state == EMPTY), change)
            if change < tolerance and not loose:  # a loose solve: once more at full accuracy
                break
        if not np.isfinite(change) or change > 0.05:
            raise ConvergenceError(f"the asymptotic front did not converge in step {begin.step + 1} (t = {t_new:g} "
                                   f"s): the ribbon distances still moved by {change:.3g} elements after "
                                   f"{prop.front_iterations} iterations")

        front_distance = np.full(mesh.n_elements, np.nan)
        front_velocity = np.full(mesh.n_elements, np.nan)
        front_distance[ribbon], front_velocity[ribbon] = distance, velocity
        tally.growth_passes = iterations
        sim.state = replace(sim._finished(begin, trial, flow, t_old, t_new, relaxation, tally, start),
                            front_distance=front_distance, front_velocity=front_velocity, front_class=state)
        tally.operator_builds = sim.operator_builds - builds
        width = np.sum(trial.dd * mesh.normals, axis=1)
        record = step_record(sim, flow, width, tally, relaxation, time.perf_counter() - clock, start)
        record.update(self.measures(sim.state, sim))
        record["front_iterations"] = int(iterations)
        sim.records.append(record)
        return record

    def toughness_share(self, state, length):
        """``K^ = K' s^(1/2) (1 - s/(2L))^(1/2) / (E' w)`` averaged over the ribbon of ``state``
        (``s`` its distance to the front, ``w`` its opening, ``L`` = ``length``): the share of
        the ribbon's opening the toughness asymptote explains, 1 at a toughness-dominated tip,
        small at a viscosity-dominated one (module docstring)."""
        ribbon = np.isfinite(state.front_distance)
        if not np.any(ribbon):
            return 0.0
        s = state.front_distance[ribbon]
        w = np.sum(state.dd[ribbon] * state.mesh.normals[ribbon], axis=1)
        share = self.asymptote.toughness_width(s) * finite_fracture_factor(s, length) / np.maximum(w, 1e-300)
        return float(np.mean(np.minimum(share, 1.0)))

    def ribbon_distance(self, length, toughness_tip=True):
        """``c``, the fewest element sizes between a 2D ribbon's centre and the front, for a
        fracture of half-length ``length``: at a toughness tip ``max(ribbon_elements,
        ribbon_growth (L/h)^(1/2))``, at any other ``ribbon_elements`` (module docstring)."""
        if not toughness_tip:
            return self.ribbon_elements
        return max(self.ribbon_elements, self.ribbon_growth * float(np.sqrt(max(length, 0.0) / self.grid.h)))

    def _joined(self, sim, trial, start, new_cells, channel, tally, t_old, t_new):
        """``(trial, start)`` with elements at ``new_cells`` (reached by the trial front for
        the first time) appended, each taking the pressure of the nearest ``channel``
        element and starting closed. Raises SizeLimitError past ``max_elements``."""
        mesh = trial.mesh
        grown = self.grid.elements(new_cells, mesh)
        m = grown.n_elements
        sim.check_growth(mesh.n_elements + m, trial.step + 1, t_new)
        _, parent = level_set(self.grid.plane(grown.centers), self.grid.plane(mesh.centers[channel]),
                              np.zeros(int(channel.sum())))
        new = NewElements.hydraulic(grown, np.flatnonzero(channel)[parent])
        guess = np.zeros((m, mesh.dim))
        tally.elements_added += m
        return trial.joined(new, guess, t_old), start.joined(new, guess)

    def measures(self, state, sim):
        """Front measures of a state: the fractured area (channel elements plus the filled
        fractions of the tip elements), the radius sqrt(A/pi) (3D) or half-length (2D),
        and in 3D the smallest and largest front distance from the first injection point."""
        grid, h = self.grid, self.grid.h
        mesh = state.mesh
        circle = np.isfinite(state.front_distance)
        cells = grid.cells(mesh.centers)
        tip = state.front_class == TIP
        field = self.field(cells[circle], state.front_distance[circle], state.front_velocity[circle],
                           cells[state.front_class == CHANNEL])  # the ribbon's inside
        fraction, _, _ = fill(cells[tip], field, self.asymptote, SUB_SAMPLES[self.grid.k])
        filled = float(np.count_nonzero((state.front_class == CHANNEL) | (state.front_class == FILLED)))
        filled += float(np.sum(fraction))
        out = {}
        if grid.k == 2:
            area = filled * h * h
            well = grid.plane(mesh.centers[sim.injection_elements[0]])
            radii = front_radii(well, field)
            out.update(fracture_area=area, radius=float(np.sqrt(area / np.pi)), front_radius_min=float(radii.min()),
                       front_radius_max=float(radii.max()), front_circularity=float(radii.max() / radii.min()))
        else:
            out.update(fracture_area=filled * h * sim.height, half_length=0.5 * filled * h)
        return out
