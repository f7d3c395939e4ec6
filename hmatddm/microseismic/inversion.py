"""Inversion of microseismic observations (ref. Sec. 7.3, 7.4.3): event location, Brune
moment, location error and the source parameters, with what the data cannot tell apart.

* :func:`locate`: distance from the S-P time and direction from the direction cosines,
  averaged over every receiver of every well (ref. Eqs 7.23-7.25).
* :func:`brune_moment`: ref. Eq. 7.26, with the RMS radiation factors 0.52 / 0.63 or the
  true ones (ref. Figs 7.7-7.8).
* :func:`location_error`: ref. Eq. 7.30.
* :func:`invert_source`: the fit of ref. Eq. 7.31 over normal and slip direction (ref.
  Eqs 7.32-7.33) with scipy's differential evolution (seeded), then a least-squares
  polish.

What the amplitudes determine (beyond ref. Table 7.3). The low-frequency amplitudes
are ``|R gamma M| / (4 pi rho v^3 r)`` with ``M = d A [lambda (nu.n) I + mu (nu n + n nu)]``:

1. only the product ``d A`` (the potency; the moment ``mu d A``) enters, so slip and area
   can never be separated: the reference's six-parameter objective is constant along
   ``(d s, A / s)`` (:func:`reference_objective`);
2. ``M`` is symmetric in ``n`` and ``nu``: the fault plane and the auxiliary plane (the
   two nodal planes) swap without changing any amplitude, and amplitudes have no sign,
   so ``M`` and ``-M`` look the same;
3. with one vertical well the source and every receiver lie in one vertical plane; its
   horizontal normal ``t`` never appears (``gamma.t = 0``), so ``M_tt`` is invisible
   (:func:`unresolved_direction`). A source with a tensile part can then trade ``M_tt``
   for a different orientation and potency with exactly the same amplitudes
   (:func:`dislocation_twins`): one well leaves this ambiguity, two wells remove it.

So :func:`invert_source` solves for the orientation pair and the potency (the potency in
closed form for each orientation: the amplitudes are linear in it) and reports both
nodal planes; :func:`orientation_error` compares orientations modulo these symmetries.
"""
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, differential_evolution, least_squares

from ..errors import InputError
from ..settings import integer

RMS_FACTOR_P = 0.52  # ref. Sec. 7.3.2: RMS of F_P over the focal sphere (sqrt(4/15) = 0.516)
RMS_FACTOR_S = 0.63  # ref. Sec. 7.3.2: RMS of F_S over the focal sphere (sqrt(2/5) = 0.632)
CONSTRAINTS = ("general", "double-couple")


# ---------------------------------------------------------------------------------
# Location and moment (ref. Secs 7.3.1-7.3.2)
# ---------------------------------------------------------------------------------

def s_minus_p_distance(observations, medium):
    """Distance r (E, R) from the S-P time of each receiver, ref. Eq. 7.23."""
    return medium.distance_per_s_minus_p * observations.s_minus_p


def locate(observations, medium):
    """Event locations (E, 3): ``mean_j (x_r^j - r^j gamma^j)`` over all receivers of all
    wells, ref. Eqs 7.24-7.25."""
    distance = s_minus_p_distance(observations, medium)
    estimates = observations.receivers[None, :, :] - distance[:, :, None] * observations.direction
    return estimates.mean(axis=1)


def location_error(located, true):
    """RMS distance between located and true events (m), ref. Eq. 7.30."""
    located, true = np.asarray(located, dtype=float), np.asarray(true, dtype=float)
    if located.shape != true.shape or len(true) == 0:
        raise InputError(f"located and true must be non-empty arrays of the same shape, got {located.shape} "
                         f"and {true.shape}")
    return float(np.sqrt(np.mean(np.sum((located - true) ** 2, axis=1))))


def brune_moment(observations, medium, wave="s", factors="rms", distance=None):
    """Seismic moment (E,) from Brune's equation ``M0 = 4 pi rho c^3 r Omega_0 / F``
    (ref. Eq. 7.26), combined over the receivers.

    ``factors="rms"``: F is the RMS factor (0.52 for P, 0.63 for S) and M0 the mean of
    the receivers' estimates; ``"true"``: F is each receiver's true factor (ref. Eqs
    7.19-7.20) and M0 the least-squares fit ``sum F y / sum F^2`` of ``y = M0 F`` (exact
    without noise, and no division by a nodal receiver's F = 0). ``distance`` (E, R):
    default the S-P distance (what an analyst has, ref. Eq. 7.23).
    """
    if wave not in ("p", "s"):
        raise InputError(f"wave must be 'p' or 's', got {wave!r}")
    speed = medium.p_wave_speed if wave == "p" else medium.s_wave_speed
    amplitude = observations.amplitude_p if wave == "p" else observations.amplitude_s
    r = s_minus_p_distance(observations, medium) if distance is None else np.asarray(distance, dtype=float)
    scaled = 4.0 * np.pi * medium.density * speed ** 3 * r * amplitude
    if factors == "rms":
        return scaled.mean(axis=1) / (RMS_FACTOR_P if wave == "p" else RMS_FACTOR_S)
    if factors == "true":
        factor = observations.factor_p if wave == "p" else observations.factor_s
        norm = np.sum(factor ** 2, axis=1)
        if np.any(norm <= 0.0):
            raise InputError(f"every receiver lies on a nodal direction of the {wave.upper()} wave for some event: "
                             "Brune's equation with the true factors has no answer there")
        return np.sum(factor * scaled, axis=1) / norm
    raise InputError(f"factors must be 'rms' or 'true', got {factors!r}")


# ---------------------------------------------------------------------------------
# Source parameters (ref. Sec. 7.4.3)
# ---------------------------------------------------------------------------------

def unit_vector(theta, phi):
    """``[sin theta cos phi, sin theta sin phi, cos theta]`` (ref. Eqs 7.32-7.33), radians;
    array arguments give (..., 3)."""
    theta, phi = np.asarray(theta, dtype=float), np.asarray(phi, dtype=float)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)


def spherical_angles(vector):
    """``(theta, phi)`` in radians of unit vectors (..., 3), the inverse of :func:`unit_vector`."""
    vector = np.asarray(vector, dtype=float)
    return np.arccos(np.clip(vector[..., 2], -1.0, 1.0)), np.mod(np.arctan2(vector[..., 1], vector[..., 0]),
                                                                    2.0 * np.pi)


def unit_moment_tensor(normal, slip_direction, medium):
    """``lambda (nu.n) I + mu (nu n + n nu)`` (..., 3, 3): the moment tensor per unit potency."""
    n, nu = np.asarray(normal, dtype=float), np.asarray(slip_direction, dtype=float)
    cos = np.sum(n * nu, axis=-1)
    tensor = medium.shear_modulus * (nu[..., :, None] * n[..., None, :] + n[..., :, None] * nu[..., None, :])
    return tensor + (medium.lame_lambda * cos)[..., None, None] * np.eye(3)


def _amplitudes_per_potency(tensors, position, receivers, medium):
    """Predicted (P, S) amplitudes per unit potency, (S, R) each, for unit tensors (S, 3, 3)."""
    offset = receivers - position
    distance = np.linalg.norm(offset, axis=1)
    gamma = np.broadcast_to(offset / distance[:, None], (len(tensors),) + offset.shape)
    projected = np.einsum("sij,srj->sri", tensors, gamma)
    p_part = np.einsum("sri,sri->sr", projected, gamma)
    s_vector = projected - p_part[:, :, None] * gamma
    s_part = np.sqrt(np.einsum("sri,sri->sr", s_vector, s_vector))
    rho4pi = 4.0 * np.pi * medium.density
    return (np.abs(p_part) / (rho4pi * medium.p_wave_speed ** 3 * distance),
            s_part / (rho4pi * medium.s_wave_speed ** 3 * distance))


def _orientation(parameters, constraint):
    """Normal and slip direction (S, 3) each from parameters (k, S)."""
    normal = unit_vector(parameters[0], parameters[1])
    if constraint == "double-couple":  # slip in the plane: angle psi from a horizontal in-plane axis
        horizontal = np.cross(np.array([0.0, 0.0, 1.0]), normal)
        size = np.linalg.norm(horizontal, axis=-1, keepdims=True)
        horizontal = np.where(size > 1e-12, horizontal / np.maximum(size, 1e-300), np.array([1.0, 0.0, 0.0]))
        other = np.cross(normal, horizontal)
        psi = parameters[2][..., None]
        return normal, np.cos(psi) * horizontal + np.sin(psi) * other
    return normal, unit_vector(parameters[2], parameters[3])


def _best_potency(predicted_p, predicted_s, observed_p, observed_s):
    """Least-squares potency for each candidate (the amplitudes are linear in it) and the
    misfit of ref. Eq. 7.31 at it."""
    numerator = predicted_p @ observed_p + predicted_s @ observed_s
    denominator = np.sum(predicted_p ** 2, axis=1) + np.sum(predicted_s ** 2, axis=1)
    potency = np.maximum(np.divide(numerator, denominator, out=np.zeros_like(numerator),
                                   where=denominator > 0.0), 0.0)
    misfit = (np.sum((observed_p - potency[:, None] * predicted_p) ** 2, axis=1)
              + np.sum((observed_s - potency[:, None] * predicted_s) ** 2, axis=1))
    return potency, misfit


def reference_objective(parameters, position, receivers, amplitude_p, amplitude_s, medium):
    """Ref. Eq. 7.31 as the reference wrote it: ``f(theta_f, phi_f, theta_s, phi_s, d, A)``
    (radians, m, m^2). It depends on ``d`` and ``A`` only through ``d A``."""
    theta_f, phi_f, theta_s, phi_s, slip, area = (float(v) for v in parameters)
    tensor = unit_moment_tensor(unit_vector(theta_f, phi_f), unit_vector(theta_s, phi_s), medium)[None]
    predicted_p, predicted_s = _amplitudes_per_potency(tensor, np.asarray(position, float),
                                                       np.asarray(receivers, float), medium)
    potency = slip * area
    return float(np.sum((amplitude_p - potency * predicted_p[0]) ** 2)
                 + np.sum((amplitude_s - potency * predicted_s[0]) ** 2))


@dataclass
class SourceSolution:
    """Result of :func:`invert_source`.

    ``normal`` and ``slip_direction`` (3,) are the fitted pair; ``nodal_planes`` (2, 3)
    the normals of the two planes the data cannot tell apart (``normal`` and
    ``slip_direction`` swapped); ``potency`` ``d A`` (m^3) and ``seismic_moment``
    ``mu d A`` (N m) are what the amplitudes fix (not ``d`` or ``A`` alone);
    ``relative_misfit`` is ``sqrt(f / sum Omega*^2)`` (ref. Eq. 7.31); ``evaluations``
    the objective evaluations.
    """

    normal: np.ndarray
    slip_direction: np.ndarray
    potency: float
    seismic_moment: float
    relative_misfit: float
    evaluations: int
    constraint: str

    @property
    def nodal_planes(self):
        return np.stack([self.normal, self.slip_direction])

    def moment_tensor(self, medium):
        return self.potency * unit_moment_tensor(self.normal, self.slip_direction, medium)


def invert_source(position, receivers, amplitude_p, amplitude_s, medium, seed=0, constraint="general",
                  popsize=20, maxiter=300, tol=1e-10, restarts=3):
    """Fit the orientation and potency of a point source at ``position`` (3,) to the
    low-frequency amplitudes (R,) at ``receivers`` (R, 3) (ref. Eqs 7.31-7.33).

    ``constraint="general"``: normal and slip direction free (the reference's four
    angles; a tensile part is allowed); ``"double-couple"``: slip in the plane (three
    angles). The potency is solved in closed form for each orientation, the angles by
    :func:`scipy.optimize.differential_evolution` (``restarts`` independent starts drawn
    from ``seed``; the best is kept) and a least-squares polish.
    """
    if constraint not in CONSTRAINTS:
        raise InputError(f"constraint must be one of {', '.join(CONSTRAINTS)}, got {constraint!r}")
    position = np.asarray(position, dtype=float)
    receivers = np.atleast_2d(np.asarray(receivers, dtype=float))
    observed_p, observed_s = np.asarray(amplitude_p, float), np.asarray(amplitude_s, float)
    if observed_p.shape != (len(receivers),) or observed_s.shape != (len(receivers),):
        raise InputError(f"amplitude_p and amplitude_s must hold one value per receiver ({len(receivers)})")
    if np.min(np.linalg.norm(receivers - position, axis=1)) <= 0.0:
        raise InputError("wells: a receiver lies on the source")
    total = float(observed_p @ observed_p + observed_s @ observed_s)
    if total <= 0.0:
        raise InputError("amplitude_p and amplitude_s are all zero: nothing to invert")
    counter = [0]

    def predicted(parameters):
        normal, slip_direction = _orientation(parameters, constraint)
        return _amplitudes_per_potency(unit_moment_tensor(normal, slip_direction, medium), position, receivers,
                                       medium)

    def objective(parameters):
        parameters = np.asarray(parameters, dtype=float)
        single = parameters.ndim == 1
        parameters = parameters.reshape(len(parameters), -1)
        counter[0] += parameters.shape[1]
        _, misfit = _best_potency(*predicted(parameters), observed_p, observed_s)
        misfit = misfit / total
        return float(misfit[0]) if single else misfit

    angles = [(0.0, np.pi), (0.0, 2.0 * np.pi)]
    bounds = angles + ([(0.0, 2.0 * np.pi)] if constraint == "double-couple" else angles)
    result = None
    for child in np.random.SeedSequence(seed).spawn(restarts):  # independent starts: the objective has local minima
        trial = differential_evolution(objective, bounds, seed=np.random.default_rng(child), popsize=popsize,
                                       maxiter=maxiter, tol=tol, vectorized=True, updating="deferred", polish=False)
        if result is None or trial.fun < result.fun:
            result = trial
        if result.fun < 1e-12:  # an exact fit: further starts cannot do better
            break

    scale = np.sqrt(total)

    def residuals(parameters):
        predicted_p, predicted_s = predicted(parameters[:-1, None])
        potency = parameters[-1]
        counter[0] += 1
        return np.concatenate([observed_p - potency * predicted_p[0], observed_s - potency * predicted_s[0]]) / scale

    potency0, _ = _best_potency(*predicted(result.x[:, None]), observed_p, observed_s)
    polished = least_squares(residuals, np.append(result.x, potency0[0]), x_scale="jac", xtol=1e-15, ftol=1e-15,
                             gtol=1e-15, max_nfev=2000)
    parameters = polished.x if 2.0 * polished.cost <= result.fun else np.append(result.x, potency0[0])
    normal, slip_direction = _orientation(parameters[:-1, None], constraint)
    potency = abs(float(parameters[-1]))
    misfit = float(np.sum(residuals(parameters) ** 2))
    return SourceSolution(normal=normal[0], slip_direction=slip_direction[0], potency=potency,
                          seismic_moment=medium.shear_modulus * potency, relative_misfit=float(np.sqrt(misfit)),
                          evaluations=counter[0], constraint=constraint)


@dataclass
class SourceSpread:
    """Solutions of :func:`invert_source_draws`, one row per noise draw: ``normal`` and
    ``slip_direction`` (D, 3), ``potency`` (D,) m^3, ``relative_misfit`` (D,)."""

    normal: np.ndarray
    slip_direction: np.ndarray
    potency: np.ndarray
    relative_misfit: np.ndarray

    def orientation_errors(self, true_normal, true_slip_direction):
        """:func:`orientation_error` of every draw (deg)."""
        return np.array([orientation_error(n, s, true_normal, true_slip_direction)
                         for n, s in zip(self.normal, self.slip_direction)])

    def potency_percentiles(self, percentiles=(5, 50, 95)):
        return np.percentile(self.potency, percentiles)


def invert_source_draws(observations, medium, levels, draws, seed=0, constraint="general", event=0, **options):
    """The source of event ``event`` of ``observations`` inverted for ``draws`` noise
    draws of ``levels`` (:class:`~hmatddm.microseismic.noise.NoiseLevels`), the draws and
    the optimiser seeded from ``seed``: the spread of the answers, not one answer."""
    from .noise import add_noise

    draws = integer("draws", draws)
    single = observations if len(observations.distance) == 1 else _one_event(observations, event)
    position = single.receivers[0] - single.distance[0, 0] * single.direction[0, 0]
    rows = []
    for draw in range(int(draws)):
        noisy = single if levels.is_zero else add_noise(single, levels, [seed, draw])
        rows.append(invert_source(position, single.receivers, noisy.amplitude_p[0], noisy.amplitude_s[0], medium,
                                  seed=[seed, draw], constraint=constraint, **options))
    return SourceSpread(normal=np.array([r.normal for r in rows]),
                        slip_direction=np.array([r.slip_direction for r in rows]),
                        potency=np.array([r.potency for r in rows]),
                        relative_misfit=np.array([r.relative_misfit for r in rows]))


def _one_event(observations, event):
    from dataclasses import replace

    fields = ("distance", "direction", "travel_time_p", "travel_time_s", "amplitude_p", "amplitude_s", "factor_p",
              "factor_s")
    return replace(observations, **{name: getattr(observations, name)[event:event + 1] for name in fields})


def _line_angle(a, b):
    """Angle (deg) between the lines along unit vectors a and b (sign-free)."""
    return np.degrees(np.arccos(np.clip(abs(float(np.dot(a, b))), 0.0, 1.0)))


def orientation_error(normal, slip_direction, true_normal, true_slip_direction):
    """Largest angle (deg) between fitted and true normal and slip direction, minimised
    over the symmetries the amplitudes cannot see: normal and slip swapped, and signs."""
    straight = max(_line_angle(normal, true_normal), _line_angle(slip_direction, true_slip_direction))
    swapped = max(_line_angle(normal, true_slip_direction), _line_angle(slip_direction, true_normal))
    return min(straight, swapped)


def unresolved_direction(position, receivers, tolerance=1e-9):
    """The unit normal ``t`` of the plane holding the source and every receiver, or None.

    When there is one (one vertical well), ``gamma . t = 0`` at every receiver and the
    component ``M_tt`` of the moment tensor never enters the amplitudes."""
    offsets = np.atleast_2d(np.asarray(receivers, dtype=float)) - np.asarray(position, dtype=float)
    _, singular, vectors = np.linalg.svd(offsets, full_matrices=True)
    if len(singular) < 3 or singular[-1] <= tolerance * singular[0]:
        return vectors[-1]
    return None


def dislocation_from_moment_tensor(tensor, medium, tolerance=1e-9):
    """``(normal, slip_direction, potency)`` with ``potency * unit_moment_tensor(...) =
    tensor``, or None when no displacement discontinuity has this moment tensor.

    The eigenvalues of ``P [lambda c I + mu (nu n + n nu)]`` (``c = nu.n``) are
    ``P (lambda c + mu (c + 1)) >= P lambda c >= P (lambda c + mu (c - 1))``, so a tensor
    with eigenvalues ``e1 >= e2 >= e3`` is one when ``2 (lambda + mu) e2 = lambda (e1 + e3)``
    and ``|c| <= 1``; then ``P = (e1 - e3) / (2 mu)``, ``nu + n`` lies along the first
    eigenvector and ``nu - n`` along the third.
    """
    values, vectors = np.linalg.eigh(np.asarray(tensor, dtype=float))
    e3, e2, e1 = values
    lam, mu = medium.lame_lambda, medium.shear_modulus
    scale = max(abs(e1), abs(e3), 1e-300)
    if abs(2.0 * (lam + mu) * e2 - lam * (e1 + e3)) > tolerance * (lam + mu) * scale or e1 - e3 <= 0.0:
        return None
    potency = (e1 - e3) / (2.0 * mu)
    cos = (e1 + e3 - 2.0 * e2) / (2.0 * mu * potency)
    if abs(cos) > 1.0 + tolerance:
        return None
    cos = float(np.clip(cos, -1.0, 1.0))
    plus, minus = np.sqrt(2.0 * (1.0 + cos)) * vectors[:, 2], np.sqrt(2.0 * (1.0 - cos)) * vectors[:, 0]
    return 0.5 * (plus - minus), 0.5 * (plus + minus), float(potency)


def dislocation_twins(tensor, direction, medium, span=20.0, samples=4001):
    """Sources ``(normal, slip_direction, potency)`` whose moment tensor differs from
    ``tensor`` (or from ``-tensor``) only by ``alpha t t`` with ``t = direction``, alpha != 0:
    with one well (``t`` from :func:`unresolved_direction`) they give exactly the same
    amplitudes as the source of ``tensor``. ``alpha`` is searched in ``+-span |M|``.
    """
    tensor = np.asarray(tensor, dtype=float)
    t = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    outer = np.outer(t, t)
    norm = float(np.max(np.abs(np.linalg.eigvalsh(tensor))))
    lam, mu = medium.lame_lambda, medium.shear_modulus

    def condition(alpha, sign):
        e3, e2, e1 = np.linalg.eigvalsh(sign * tensor + alpha * outer)
        return (2.0 * (lam + mu) * e2 - lam * (e1 + e3)) / ((lam + mu) * norm)

    twins = []
    grid = np.linspace(-span * norm, span * norm, samples)
    for sign in (1.0, -1.0):
        values = np.array([condition(alpha, sign) for alpha in grid])
        for k in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0):
            alpha = brentq(condition, grid[k], grid[k + 1], args=(sign,), xtol=1e-14 * norm)
            if abs(alpha) <= 1e-8 * norm:
                continue
            source = dislocation_from_moment_tensor(sign * tensor + alpha * outer, medium, tolerance=1e-7)
            if source is not None:
                twins.append(source)
    return twins
