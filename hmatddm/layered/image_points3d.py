"""The complementary (image) field at a receiver of a point DD density in a plane-layered
3D medium (ref. Secs 3.2-3.3, Eq. 3.22): the traced triples of the source point
(:mod:`.image_tracer3d`) summed at the receiver through the field of one triple
(:mod:`.potentials3d`), for the stress (:func:`_complementary_gradient`, which the
quadrature over a rectangle integrates, :mod:`.rectangle_quadrature`) and the
displacement, and the whole-space (Kelvin) stress and displacement through the same
potentials (checks against :mod:`hmatddm.kernels.rectangle3d`).

The stress of a DD density is the moment-tensor contraction of the source derivative of
the point-force stress, exactly as in :mod:`.images2d`, and the bookkeeping is the same:
complementary = every image triple in the source's layer; transmitted minus the source
material's whole-space field elsewhere (the callers add the closed-form kernel of the
source's material at every receiver).
"""
import numpy as np
from numba import njit

from .image_tracer3d import trace_points
from .images2d import _lame, receiver_constants
from .potentials3d import (Workspace, _contract, _contract_vector, _original, _pair_displacement_gradient,
                           _pair_stress_gradient)


@njit(cache=True, inline="always")
def _complementary_gradient(y, receiver_layer, x, n_pairs, source_layer, pair_layer, pair_z, pair_eps, pair_sigma,
                            pair_coef, pair_dcoef, shear_modulus, poisson_ratio, gradient, work, work1, kelvin,
                            z_lo=-np.inf, z_hi=np.inf):
    """``gradient[f, q, i, k]`` of the complementary field at receiver ``y`` from the
    traced triples of the source point ``x`` (see :mod:`.images2d` for the bookkeeping);
    ``work``: a :func:`Workspace` of the triples' order, ``work1`` one of order 1,
    ``kelvin`` (2, 3, 3, 1) scratch; ``z_lo <= z < z_hi``: the triples' heights taken (a
    group of triples with its own rule, :func:`.images3d._complementary_stress`)."""
    gradient[:] = 0.0
    g_r, delta_r, lame_r = receiver_constants(shear_modulus, poisson_ratio, receiver_layer)
    for k in range(n_pairs):
        if pair_layer[k] == receiver_layer and z_lo <= pair_z[k] < z_hi:
            _pair_stress_gradient(y[0] - x[0], y[1] - x[1], y[2] - pair_z[k], pair_eps[k], pair_sigma[k],
                                  pair_coef[k], pair_dcoef[k], delta_r, g_r, lame_r, gradient, work)
    if receiver_layer != source_layer:
        # minus the whole-space field of the source's material (added in closed form)
        g_s = shear_modulus[source_layer]
        nu_s = poisson_ratio[source_layer]
        delta_s = 1.0 / (3.0 - 4.0 * nu_s)
        sigma = 1.0 if y[2] >= x[2] else -1.0
        kelvin[:] = 0.0
        _original(kelvin[0], delta_s, g_s, sigma, -1.0)
        _pair_stress_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, sigma, kelvin[0], kelvin[1], delta_s, g_s,
                              _lame(g_s, nu_s), gradient, work1)


@njit(cache=True)
def kelvin_point_stress(y, x, normal, shear_modulus, poisson_ratio, out):
    """``out[b, i, k]``: whole-space stress at ``y`` of a unit DD density along global
    ``b`` at the point ``x`` of a plane of ``normal``, through the Hansen-potential path
    of the images (a check of the machinery against :mod:`hmatddm.kernels.rectangle3d`)."""
    delta = 1.0 / (3.0 - 4.0 * poisson_ratio)
    sigma = 1.0 if y[2] >= x[2] else -1.0
    coef = np.zeros((3, 3, 1))
    _original(coef, delta, shear_modulus, sigma, 1.0)
    gradient = np.zeros((3, 3, 3, 3))
    lame = _lame(shear_modulus, poisson_ratio)
    _pair_stress_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, sigma, coef, np.zeros((3, 3, 1)), delta,
                          shear_modulus, lame, gradient, Workspace(1))
    out[:] = 0.0
    _contract(gradient, normal, shear_modulus, lame, 1.0, out)


@njit(cache=True)
def image_point_stress(y, receiver_layer, x, source_layer, normal, interfaces, shear_modulus, poisson_ratio,
                       n_images, out):
    """Complementary stress ``out[b, i, k]`` (3, 3, 3) at the receiver ``y`` (in
    ``receiver_layer``) of a unit DD density along global ``b`` at the source point
    ``x`` (in ``source_layer``) of a plane of ``normal``. The total stress is this plus
    the closed-form whole-space kernel of the source layer's material."""
    traced = trace_points(x[2:3], source_layer, interfaces, shear_modulus, poisson_ratio, n_images)
    n_pairs, layer, z, eps, sigma, coef, dcoef = traced
    gradient = np.empty((3, 3, 3, 3))
    _complementary_gradient(y, receiver_layer, x, n_pairs[0], source_layer, layer[0], z[0], eps[0], sigma[0],
                            coef[0], dcoef[0], shear_modulus, poisson_ratio, gradient, Workspace(coef.shape[-1]),
                            Workspace(1), np.zeros((2, 3, 3, 1)))
    out[:] = 0.0
    g_s = shear_modulus[source_layer]
    _contract(gradient, normal, g_s, _lame(g_s, poisson_ratio[source_layer]), 1.0, out)


@njit(cache=True)
def kelvin_point_displacement(y, x, normal, shear_modulus, poisson_ratio, out):
    """``out[b, i]``: whole-space displacement at ``y`` of a unit DD density along global
    ``b`` at the point ``x`` of a plane of ``normal`` (Hansen-potential path)."""
    delta = 1.0 / (3.0 - 4.0 * poisson_ratio)
    sigma = 1.0 if y[2] >= x[2] else -1.0
    coef = np.zeros((3, 3, 1))
    _original(coef, delta, shear_modulus, sigma, 1.0)
    gradient = np.zeros((3, 3, 3))
    _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, sigma, coef, np.zeros((3, 3, 1)), delta,
                                gradient, Workspace(1))
    _contract_vector(gradient, normal, shear_modulus, _lame(shear_modulus, poisson_ratio), out)


@njit(cache=True)
def image_point_displacement(y, receiver_layer, x, source_layer, normal, interfaces, shear_modulus, poisson_ratio,
                             n_images, out):
    """Complementary displacement ``out[b, i]`` (3, 3) at ``y`` of a unit DD density
    along global ``b`` at the source point ``x`` of a plane of ``normal`` (ref. Eq.
    3.22; the total is this plus the whole-space field of the source layer's material)."""
    n_pairs, layer, z, eps, sigma, coef, dcoef = trace_points(x[2:3], source_layer, interfaces, shear_modulus,
                                                              poisson_ratio, n_images)
    gradient = np.zeros((3, 3, 3))
    work = Workspace(coef.shape[-1])
    nu_r = poisson_ratio[receiver_layer]
    delta_r = 1.0 / (3.0 - 4.0 * nu_r)
    for k in range(n_pairs[0]):
        if layer[0, k] == receiver_layer:
            _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - z[0, k], eps[0, k], sigma[0, k], coef[0, k],
                                        dcoef[0, k], delta_r, gradient, work)
    g_s = shear_modulus[source_layer]
    nu_s = poisson_ratio[source_layer]
    if receiver_layer != source_layer:
        delta_s = 1.0 / (3.0 - 4.0 * nu_s)
        side = 1.0 if y[2] >= x[2] else -1.0
        kelvin = np.zeros((3, 3, 1))
        _original(kelvin, delta_s, g_s, side, -1.0)
        _pair_displacement_gradient(y[0] - x[0], y[1] - x[1], y[2] - x[2], 1.0, side, kelvin, np.zeros((3, 3, 1)),
                                    delta_s, gradient, Workspace(1))
    _contract_vector(gradient, normal, g_s, _lame(g_s, nu_s), out)
