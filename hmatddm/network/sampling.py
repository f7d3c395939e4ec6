"""Sampling laws of a synthetic natural-fracture network (ref. Sec. 6.2): truncated
power-law lengths (Eqs 6.1-6.7) and von Mises strikes of undirected lines, one set or a
mixture of sets (Eqs 6.8-6.10). The network itself (:class:`NetworkSpec`, positions,
clipping) is :mod:`hmatddm.network.generation`'s.

Conventions
-----------
* **Azimuth** ``theta`` is the strike direction measured from the +x axis,
  counter-clockwise, as in the reference ("45 deg and 135 deg from the x axis",
  Fig. 6.14). Strikes are undirected lines (axial data), so azimuths live in
  ``[0, pi)``. These functions take and return radians.
* **Concentration** ``kappa`` is the von Mises concentration of the *doubled* angle
  ``2 theta`` (the reference's ``kappa'``; ref. Sec. 6.2.2): the reference generates
  ``theta' ~ VM(mu', kappa')`` and uses ``theta = theta'/2``, so its Table 6.1 pair
  ``mu = 45 deg, kappa = 5`` means ``mu' = 90 deg, kappa' = 5``.
"""
import numpy as np

from .._validation import finite_array, finite_scalar, positive_int
from ..errors import InputError
from ..settings import NETWORK_GENERATOR, integer


def _rng(rng):
    """A numpy Generator from a Generator, an integer seed or None (fresh entropy)."""
    if isinstance(rng, np.random.Generator):
        return rng
    return np.random.default_rng(None if rng is None else integer("rng", rng, minimum=0))


def _check_lengths(exponent, l_min, l_max, exponent_name="exponent"):
    exponent = NETWORK_GENERATOR["length_exponent"].value(exponent_name, exponent)
    l_min = NETWORK_GENERATOR["l_min"].value("l_min", l_min)
    try:
        l_max = float(l_max)
    except (TypeError, ValueError):
        raise InputError(f"l_max must be a number >= l_min = {l_min}, got {l_max!r}") from None
    if np.isnan(l_max) or l_max < l_min:
        raise InputError(f"l_max must be >= l_min = {l_min}, got {l_max}")
    if np.isinf(l_max) and exponent <= 1.0:
        raise InputError(f"l_max must be finite when {exponent_name} = 1 "
                         "(1/l is not normalisable on [l_min, inf)), got inf")
    return exponent, l_min, l_max


def power_law_lengths(n, exponent, l_min, l_max, rng=None):
    """``n`` fracture lengths from the truncated power law of ref. Eqs. 6.1-6.7.

    The density is ``f(l) = b l^-a / (l_min^-b - l_max^-b)`` on ``[l_min, l_max]``
    with ``a = exponent`` and ``b = a - 1`` (Eq. 6.4), sampled by inverting the
    cumulative distribution Eq. 6.5 at uniform ``u``::

        l = l_min * (1 - u (1 - (l_max/l_min)^-b))^(-1/b)

    evaluated with ``log1p``/``expm1`` so that it stays accurate as ``a -> 1``.
    ``a == 1`` is handled exactly as its limit, the log-uniform law
    ``F(l) = ln(l/l_min) / ln(l_max/l_min)``. ``l_max = inf`` gives Eqs. 6.6-6.7
    (needs ``a > 1``); ``l_max == l_min`` gives constant lengths.

    Parameters
    ----------
    n : int >= 0
    exponent : float >= 1, the ``a`` of ``n(l) ~ l^-a``
    l_min, l_max : lower and upper length limits ``l_0``, ``l_1``, m
    rng : numpy Generator, integer seed or None
    """
    n = positive_int("n", n, minimum=0)
    a, l_min, l_max = _check_lengths(exponent, l_min, l_max)
    rng = _rng(rng)
    u = rng.random(n)
    if l_max == l_min:
        return np.full(n, l_min)
    b = a - 1.0
    if b == 0.0:
        lengths = l_min * np.exp(u * np.log(l_max / l_min))
    else:
        q = 1.0 if np.isinf(l_max) else -np.expm1(-b * np.log(l_max / l_min))  # 1 - (l_max/l_min)^-b
        lengths = l_min * np.exp(-np.log1p(-u * q) / b)
    return np.clip(lengths, l_min, l_max)


def von_mises_directions(n, mean_azimuth, kappa, rng=None):
    """``n`` axial directions (undirected strikes) in ``[0, pi)``, radians.

    Angle doubling of ref. Sec. 6.2.2: ``theta' = 2 theta`` follows the von Mises law
    Eq. 6.8 with mean ``mu' = 2 * mean_azimuth`` and concentration ``kappa``; it is
    drawn with numpy's ``Generator.vonmises`` (the Best & Fisher 1979 algorithm the
    reference uses) and halved, ``theta = theta'/2 mod pi``.

    Parameters
    ----------
    mean_azimuth : mean strike ``mu`` in radians from the +x axis, counter-clockwise
        (any value; only ``mu mod pi`` matters)
    kappa : concentration >= 0 of the doubled angle (the reference's ``kappa'``);
        0 gives uniformly random strikes
    """
    n = positive_int("n", n, minimum=0)
    mean_azimuth = finite_scalar("mean_azimuth", mean_azimuth)
    kappa = finite_scalar("kappa", kappa)
    if kappa < 0.0:
        raise InputError(f"kappa must be >= 0, got {kappa}")
    rng = _rng(rng)
    doubled = rng.vonmises(2.0 * mean_azimuth, kappa, n)
    return np.mod(0.5 * doubled, np.pi)


def _check_modes(means, kappas, weights, names=("means", "kappas", "weights")):
    means = np.atleast_1d(finite_array(names[0], means))
    kappas = np.atleast_1d(finite_array(names[1], kappas))
    if means.ndim != 1 or means.size == 0:
        raise InputError(f"{names[0]} must be a non-empty 1D sequence, got shape {means.shape}")
    if weights is None:
        weights = np.full(means.size, 1.0 / means.size)
    weights = np.atleast_1d(finite_array(names[2], weights))
    if kappas.shape != means.shape or weights.shape != means.shape:
        raise InputError(f"{', '.join(names)} must have the same length, got "
                         f"{means.size}, {kappas.size}, {weights.size}")
    if np.any(kappas < 0.0):
        raise InputError(f"{names[1]} must be >= 0, got {kappas.tolist()}")
    if np.any(weights < 0.0) or abs(weights.sum() - 1.0) > 1e-9:
        raise InputError(f"{names[2]} must be >= 0 and sum to 1, got {weights.tolist()}")
    return means, kappas, weights / weights.sum()


def bimodal_directions(n, means, kappas, weights, rng=None, return_modes=False):
    """``n`` axial directions from a mixture of von Mises modes (ref. Eq. 6.10).

    The reference's procedure, for any number of modes: draw ``x ~ U(0, 1)`` for every
    fracture; it belongs to mode ``k`` when ``x`` falls in the ``k``-th interval of the
    cumulative weights (two modes: mode 1 when ``x < w``); then each mode's strikes are
    drawn with :func:`von_mises_directions`.

    Parameters
    ----------
    means : mean strikes (radians, from +x counter-clockwise), one per mode
    kappas : concentrations >= 0 of the doubled angle, one per mode
    weights : mixing factors >= 0 summing to 1 (``(w, 1 - w)`` in Eq. 6.10)
    return_modes : also return the (n,) mode index of each direction

    Returns
    -------
    azimuths : (n,) in ``[0, pi)``, and ``modes`` (n,) int when ``return_modes``
    """
    n = positive_int("n", n, minimum=0)
    means, kappas, weights = _check_modes(means, kappas, weights)
    rng = _rng(rng)
    x = rng.random(n)
    cumulative = np.cumsum(weights)
    modes = np.minimum(np.searchsorted(cumulative, x, side="right"), len(weights) - 1)
    azimuths = np.empty(n)
    for k in range(len(weights)):
        index = np.flatnonzero(modes == k)
        azimuths[index] = von_mises_directions(index.size, means[k], kappas[k], rng)
    if return_modes:
        return azimuths, modes.astype(np.int64)
    return azimuths
