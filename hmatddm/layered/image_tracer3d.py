"""The image triples of a point force in a plane-layered 3D medium (ref. Sec. 3.2, Fig.
3.4, Eqs 3.25-3.28): the 3D use of the shared tracer :mod:`.image_tracer`, for source
points at given heights (:func:`trace`, :func:`trace_points`) and for the points of a
quadrature rule on a rectangle (:func:`_trace_range`, each distinct height traced once).

:mod:`.image_tracer` takes the source's coefficients and their parity under mirroring and
knows no dimension (2D traces through it from :mod:`.images2d`); this module supplies the
3D point-force potentials of ref. Eq. 3.24 (:func:`.potentials3d._original`), both
gauges. Mirroring a potential in a horizontal plane maps ``F, L`` of gauge ``sigma`` to
those of gauge ``-sigma`` (:mod:`.potentials3d`): the mirrored coefficient of ``D^n``
(``D = d/dy3``) only changes by ``(-1)^n``, so every parity is +1.

Reflection and transmission at an interface ``y3 = d`` (ref. Eqs 3.25-3.28, with
``h = z - d``, ``gamma = G_far / G_near``; derived and checked in ``_derive_images3d.py``):
the reflected triple emanates from ``2d - z`` and is ``R`` applied to the mirrored
incident triple, the transmitted one keeps ``z`` and is ``T`` applied to the incident one:

    R = [[2 d1 c1 h D, c2 - 4 d1^2 c1 h^2 D^2, 0],  T = [[c4, 2 (d1 c4 - d2 c5) h D, 0],
         [c1,          -2 d1 c1 h D,          0],       [0,  c5,                    0],
         [0,           0,                    c3]]       [0,  0,                    c6]]

(ref. Eq. 3.27 prints ``-2 (d1 c4 - d2 c5)``: the interface conditions need ``+``, as
in 2D.)
"""
import numpy as np
from numba import njit

from .image_tracer import trace_capacity, trace_potentials
from .potentials3d import _original


@njit(cache=True)
def trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, pair_layer, pair_z, pair_eps,
          pair_sigma, pair_coef, pair_dcoef):
    """Image triples of a unit point force at height ``t`` in ``source_layer``
    (:func:`.image_tracer.trace_potentials`): ``pair_sigma[k]`` is the triple's gauge (its
    direction of travel: +1 upward, receivers above ``z``), ``pair_coef[k, f, j, n]`` the
    coefficient of ``D^n`` of the base function of potential ``j`` for a force along
    ``f``. Returns the number of triples (the original excluded)."""
    delta_s = 1.0 / (3.0 - 4.0 * poisson_ratio[source_layer])
    original = np.zeros((2, 3, 3, 1))
    for e in range(2):
        _original(original[e], delta_s, shear_modulus[source_layer], 1.0 if e == 0 else -1.0, 1.0)
    n = trace_potentials(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images,
                         np.ascontiguousarray(original[:, :, :, 0]),
                         np.ones(3), pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef)
    return merge_coincident(n, pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef)


@njit(cache=True)
def copy_triple(k, into, pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef):
    """Copy traced triple ``k`` over triple ``into`` (element by element, not by slice
    assignment: docs/conventions.md, §5)."""
    pair_layer[into] = pair_layer[k]
    pair_z[into] = pair_z[k]
    pair_eps[into] = pair_eps[k]
    pair_sigma[into] = pair_sigma[k]
    for f in range(pair_coef.shape[1]):
        for j in range(pair_coef.shape[2]):
            for o in range(pair_coef.shape[3]):
                pair_coef[into, f, j, o] = pair_coef[k, f, j, o]
                pair_dcoef[into, f, j, o] = pair_dcoef[k, f, j, o]


@njit(cache=True)
def merge_coincident(n, pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef):
    """Merge the triples that differ only by their path through the interfaces: same
    layer, gauge ``sigma``, ``eps`` and point ``z`` (to round-off of the heights).
    The field of a triple is linear in its coefficients for a given point, gauge and
    ``eps`` (:func:`.potentials3d._pair_stress_gradient`, the vertical source derivative
    included), so the merged triple's coefficients are the sums: exact, and a third to a
    half fewer triples to evaluate with two or more interfaces. Returns the new count."""
    kept = np.int64(0)  # not a literal: one specialization of copy_triple
    for k in range(n):
        into = -1
        tol = 1e-12 * (1.0 + abs(pair_z[k]))
        for m in range(kept):
            if (pair_layer[m] == pair_layer[k] and pair_sigma[m] == pair_sigma[k] and pair_eps[m] == pair_eps[k]
                    and abs(pair_z[m] - pair_z[k]) <= tol):
                into = m
                break
        if into < 0:
            into = kept
            kept += 1
            copy_triple(k, into, pair_layer, pair_z, pair_eps, pair_sigma, pair_coef, pair_dcoef)
        else:
            for f in range(pair_coef.shape[1]):
                for j in range(pair_coef.shape[2]):
                    for o in range(pair_coef.shape[3]):
                        pair_coef[into, f, j, o] += pair_coef[k, f, j, o]
                        pair_dcoef[into, f, j, o] += pair_dcoef[k, f, j, o]
    return kept


@njit(cache=True)
def drop_surface_range(traced, lo, hi, center, frame, a, b, xi, eta, source_layer, surface):
    """Remove, from the triples traced at the points ``lo .. hi - 1`` of the rule ``(xi,
    eta)`` on a rectangle, the reflection of the source in the free surface ``z = surface``
    over its layer: the triple of the source's layer whose point is ``2 surface - t``
    (``eps = -1``), which :mod:`.okada3d` gives in closed form (it is the half-space's only
    triple, coefficient for coefficient: :func:`hmatddm.layered.influence3d.surface_reflection_alone`
    checks that no other path merged into it). The last triple takes its place."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(lo, hi):
        t = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
        target = 2.0 * surface - t
        tol = 1e-12 * (1.0 + abs(target))
        n = n_pairs[g]
        for k in range(n):
            if layer[g, k] == source_layer and eps[g, k] < 0.0 and abs(z[g, k] - target) <= tol:
                if k != n - 1:
                    copy_triple(n - 1, k, layer[g], z[g], eps[g], sigma[g], coef[g], dcoef[g])
                n_pairs[g] = n - 1
                break


@njit(cache=True)
def _traced_buffer(n_points, cap, n_orders):
    """Room for the triples of ``n_points`` source points (see :func:`trace_points`)."""
    return (np.zeros(n_points, dtype=np.int64), np.empty((n_points, cap), dtype=np.int64),
            np.empty((n_points, cap)), np.empty((n_points, cap)), np.empty((n_points, cap)),
            np.empty((n_points, cap, 3, 3, n_orders)), np.empty((n_points, cap, 3, 3, n_orders)))


@njit(cache=True)
def trace_points(heights, source_layer, interfaces, shear_modulus, poisson_ratio, n_images):
    """The image triples of source points at ``heights`` (P,): ``(n_pairs (P,), layer,
    z, eps, sigma (P, C), coef, dcoef (P, C, 3, 3, O))``."""
    cap, n_orders = trace_capacity(source_layer, shear_modulus, n_images)
    traced = _traced_buffer(heights.shape[0], cap, n_orders)
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(heights.shape[0]):
        n_pairs[g] = trace(heights[g], source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer[g],
                           z[g], eps[g], sigma[g], coef[g], dcoef[g])
    return traced


@njit(cache=True)
def _trace_range(center, frame, a, b, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, xi, eta, lo,
                 hi, traced):
    """Trace the points ``lo .. hi - 1`` of the rule ``(xi, eta)`` into ``traced``, once
    per distinct height (a horizontal rectangle is traced once, a vertical one once per
    row)."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    for g in range(lo, hi):
        t = center[2] + xi[g] * a * frame[0, 2] + eta[g] * b * frame[1, 2]
        same = -1
        for k in range(lo, g):
            if center[2] + xi[k] * a * frame[0, 2] + eta[k] * b * frame[1, 2] == t:
                same = k
                break
        if same < 0:
            n_pairs[g] = trace(t, source_layer, interfaces, shear_modulus, poisson_ratio, n_images, layer[g], z[g],
                               eps[g], sigma[g], coef[g], dcoef[g])
        else:
            n = n_pairs[same]
            n_pairs[g] = n
            # element by element, not by slice assignment (docs/conventions.md, §5)
            for k in range(n):
                layer[g, k] = layer[same, k]
                z[g, k] = z[same, k]
                eps[g, k] = eps[same, k]
                sigma[g, k] = sigma[same, k]
                for f in range(coef.shape[2]):
                    for j in range(coef.shape[3]):
                        for o in range(coef.shape[4]):
                            coef[g, k, f, j, o] = coef[same, k, f, j, o]
                            dcoef[g, k, f, j, o] = dcoef[same, k, f, j, o]
