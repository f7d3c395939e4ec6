"""Carter leak-off on the asymptotic front (:mod:`hmatddm.simulation.asymptotic`; a Newtonian
fluid, ref. Eq. 4.25).

* The tip asymptote is the one with leak-off
  (:class:`~hmatddm.analytical.tip_leak_off.LeakOffTipAsymptote`, ``C' = c_l (p - p_r)`` at
  the ribbon's mean pressure at the start of the step).
* A channel element leaks from the time the front crossed its centre (Carter's ``tau_i``, the
  state's ``creation_time``; :func:`crossing_times`), linear between the front at the start
  of the step and the trial front -- not from when it joined the mesh. Leaking the whole
  element from the first touch made the solve fail or the front stall (issue 36).
* An element the front crosses (tip, filled) leaks point by point, each sample point from
  its own arrival time (:func:`tip_leak_off_rate`): an element switched on at its centre's
  crossing leaks at once with an infinite slope in the front position, and at a
  leak-off-dominated (M~) tip -- where that leak-off is most of the fluid the element takes --
  the front iterations cycled and did not converge (issue 36).
* The front iteration is bracketed (:meth:`AsymptoticFront.step`): at an m~ tip the opening
  goes as ``V^(1/8) s^(5/8)``, so the advance of a step goes as a high power of the ribbon's
  opening and the plain fixed point cycled by whole elements; each ribbon's front is kept
  between the farthest trial front the inversion asked to pass and the nearest it asked to
  pull back from (or whose coupled solve failed: a trial front far ahead of the fluid starves
  the elements behind it, whose leak-off then takes more than the flow brings), and bisected
  when the iteration leaves that bracket; a failed solve -- or one that starved an element
  (:func:`starved`) -- halves the trial advance, at most :data:`MAX_RETREATS` times in a row.

Measured against the K-K~ edge (benchmarks/RESULTS.md, issue 39): KGD from K to K~ (0.1 m
elements, 1 s steps, 52% leaked by 20 s) within 0.15% in half-length and 0.6% in net pressure
from 5 s on; K~ (85% leaked by 40 s) within 0.5% with 0.25 s steps; radial K to K~ -1.1% in
radius. Against the viscous leak-off vertex (M~; benchmarks/RESULTS.md, issue 36: KGD, C_m 4.4
to 7.8, 1.7% of the fluid stored at 16 s, 0.1 / 0.05 / 0.025 m): half-length -1.8 / -2.0 / -2.2%
from the M~ vertex at 16 s and -0.3 / -0.5 / -0.7% from Dontsov's (2017) solution at the run's
C_m, inlet opening -0.7 / -1.0 / -2.2% and 0.0 / -0.2 / -1.4%; the stored share as Dontsov's.
"""
import numpy as np

from ..fracture.front import sample_offsets

# failed coupled solves in a row after which a step with leak-off gives up (each halves the
# trial front's advance)
MAX_RETREATS = 6
# an element open by less than -STARVED times the largest opening is starved (natural contact
# lets it overlap while Carter's term goes on leaking)
STARVED = 0.01
# sample points per element side of the point-by-point leak-off (2D segments; 3D 8 x 8), as
# the asymptotic front's fill
SUB_SAMPLES = {1: 256, 2: 8}


def starved(state, prescribed):
    """Whether a coupled solution ``state`` (its ``dd`` and mesh) starved an element that is
    not ``prescribed``: its opening below ``-STARVED`` times the largest. Such a solution of a
    trial front far ahead of the fluid (the elements behind it leak more than the viscous flow
    brings; the coupled solve converges, to overlapping faces) is treated as a failed solve: at
    0.1 m the KGD M~ run of benchmarks/bench_leak_off.py accepted one at 16 s and ran away
    (half-length +12%, openings -0.7 mm)."""
    width = np.sum(state.dd * state.mesh.normals, axis=1)
    free = ~np.asarray(prescribed, bool)
    return bool(np.any(width[free] < -STARVED * max(float(np.max(width)), 0.0)))


def crossing_times(creation_time, cells, channel, old, field, t_old, t_new):
    """Carter's ``tau`` of the elements that are not channel: the time the front crosses the
    element's centre, linear between the front at ``t_old`` (``old``, a
    :class:`~hmatddm.fracture.front.FrontField`) and the trial front at ``t_new`` (``field``);
    +inf (no leak-off yet) while the centre is outside. Elements whose centre was inside at
    ``t_old`` keep theirs."""
    tau = creation_time.copy()
    open_ = ~channel
    phi_old = old.at_cells(cells[open_])
    phi_new = field.at_cells(cells[open_])
    crossed = (phi_old > 0.0) & (phi_new <= 0.0)
    far = crossed & ~np.isfinite(phi_old)  # beyond the old front's box: crossed mid-step
    ratio = np.where(crossed & ~far, phi_old / np.where(crossed & ~far, phi_old - phi_new, 1.0), 0.5)
    fraction = np.clip(ratio, 0.0, 1.0)
    new = np.where(phi_new > 0.0, np.inf, np.where(crossed, t_old + fraction * (t_new - t_old), tau[open_]))
    new = np.where((phi_old <= 0.0) & ~np.isfinite(tau[open_]), t_old, new)  # inside before, never timed
    tau[open_] = new
    return tau


def tip_leak_off_rate(grid, coefficient, cells, old, field, t_old, t_new):
    """Carter's step rate ``2 c_l (<(t_new - t_0)^(1/2)> - <(t_old - t_0)^(1/2)>) / dt`` (per
    Pa of ``p - p_r``) of elements at ``cells`` of ``grid`` (a
    :class:`~hmatddm.fracture.front.PlanarGrid`) that the front crosses, averaged over sample
    points of each with each point's own arrival time ``t_0``: linear in time between the front
    at ``t_old`` (``old``) and the trial front (``field``); a point inside the old front reached
    at the step's speed before ``t_old`` (clipped at 0; at ``t_old`` where the front did not
    move, mid-step beyond the old front's box); a point outside the trial front not yet."""
    k, h = grid.k, grid.h
    if len(cells) == 0:
        return np.zeros(0)
    inner, _ = sample_offsets(k, SUB_SAMPLES[k])
    points = (cells[:, None, :] * h + h * inner[None]).reshape(-1, k)
    phi_old, phi_new = old(points), field(points)
    dt = t_new - t_old
    known = np.isfinite(phi_old) & np.isfinite(phi_new)
    speed = np.where(known, phi_old - phi_new, 0.0) / dt
    moving = speed > 0.0
    arrival = np.where(moving, t_old + np.where(known, phi_old, 0.0) / np.where(moving, speed, 1.0), t_old)
    arrival = np.where(known, arrival, t_old + 0.5 * dt)  # beyond the old front's box: mid-step
    arrival = np.where(np.isfinite(phi_new) & (phi_new <= 0.0), np.maximum(arrival, 0.0), np.inf)
    new = np.sqrt(np.maximum(t_new - arrival, 0.0))
    before = np.sqrt(np.maximum(t_old - arrival, 0.0))
    rate = 2.0 * coefficient * (new - before) / dt
    return rate.reshape(len(cells), -1).mean(axis=1)


__all__ = ["crossing_times", "tip_leak_off_rate", "starved", "MAX_RETREATS", "STARVED"]
