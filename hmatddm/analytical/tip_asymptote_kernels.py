"""Compiled point-by-point inversions of the universal tip asymptote (issue 33).

:class:`~hmatddm.analytical.tip_asymptote.TipAsymptote` (and its leak-off form,
:class:`~hmatddm.analytical.tip_leak_off.LeakOffTipAsymptote`) inverts Dontsov and Peirce's
(2015) ``s^ = g_delta(K^, C^)`` by bisection, once for the opening of every sample point
of the tip elements (``width``, 64 points a cell) and once for the distance of every
ribbon element to the front (``front_distance``). Vectorised in numpy, each of the 36-64
halvings evaluated ``g_delta`` (two logarithms, two tangents, a dozen temporaries) over
all points: the fill of the tip elements took more time than the coupled solves of a
1 m radial run. Here each point is bisected on its own in one compiled loop, with the
same formulas (:mod:`hmatddm.analytical.tip_asymptote`'s module docstring; the series
of ``f`` for ``C > 10``) and the same brackets: ``width`` by the Illinois variant of
regula falsi in ``log w`` (~10 evaluations to 1e-13 instead of 36 halvings to 1e-11),
``front_distance`` by the same 64 halvings. The results are the numpy bisection's to
its precision (~1e-11 relative).
tests/analytical/test_tip_asymptote_kernels.py compares them.
"""
import math

import numpy as np
from numba import njit

from .tip_asymptote_constants import _C1_M as C1_M
from .tip_asymptote_constants import BETA_C, BETA_M, SERIES_FROM, SERIES_TERMS


@njit(cache=True, nogil=True)
def _f(k_hat, c, c_1):
    """Dontsov and Peirce's ``f(K, C, C_1)`` at one point (``tip_asymptote._f``: its
    series beyond ``C = SERIES_FROM``)."""
    k = min(k_hat, 1.0)
    if c > SERIES_FROM:
        inverse = 1.0 / c
        series = 0.0
        for j in range(4 + SERIES_TERMS - 1, 3, -1):  # smallest terms first
            series += (-1.0) ** j * (1.0 - k**j) / j * inverse ** (j - 3)
        return series / c_1
    log_term = c**3 * math.log((c + 1.0) / (c + k)) if c > 0.0 else 0.0
    return (1.0 - k**3 - 1.5 * c * (1.0 - k * k) + 3.0 * c * c * (1.0 - k) - 3.0 * log_term) / (3.0 * c_1)


@njit(cache=True, nogil=True)
def g_delta_point(k_hat, c_hat):
    """``g_delta(K^, C^)`` at one point (``tip_asymptote.g_delta``)."""
    g_0 = _f(k_hat, BETA_C * c_hat, C1_M)
    delta = min(max(C1_M * (1.0 + BETA_C * c_hat) * g_0, 1e-9), 1.0 / 3.0)
    c_1 = 4.0 * (1.0 - 2.0 * delta) / (delta * (1.0 - delta)) * math.tan(math.pi * delta)
    c_2 = 16.0 * (1.0 - 3.0 * delta) / (3.0 * delta * (2.0 - 3.0 * delta)) * math.tan(1.5 * math.pi * delta)
    return _f(k_hat, c_hat * c_2 / c_1, c_1)


@njit(cache=True, nogil=True)
def residual_point(k_prime, e_prime, mu_prime, carter, s, velocity, w):
    """``s^ - g_delta(K^, C^)`` at one point: negative when ``w`` is wider than the
    asymptote at ``(s, V)``; a front at rest (``V <= 0``) has ``s^ = C^ = 0``."""
    v = max(velocity, 0.0)
    k_hat = k_prime * math.sqrt(s) / (e_prime * w)
    if v > 0.0:
        s_hat = mu_prime * v * s * s / (e_prime * w**3)
        c_hat = 2.0 * carter * math.sqrt(s) / (math.sqrt(v) * w)
    else:
        s_hat, c_hat = 0.0, 0.0
    return s_hat - g_delta_point(k_hat, c_hat)


@njit(cache=True, nogil=True)
def finite_fracture_point(s, length):
    """``tip_asymptote.finite_fracture_factor`` at one point (1 for ``length = inf``)."""
    return math.sqrt(1.0 - 0.5 * min(s, 0.5 * length) / length)


@njit(cache=True, nogil=True)
def _log_width_root(k_prime, e_prime, mu_prime, carter, s, v, lo, hi, tolerance, max_evaluations):
    """The root in ``x = log w`` of ``residual(s, v, e^x)`` (decreasing in ``x``) on
    ``[log lo, log hi]``, ``residual(lo) > 0 >= residual(hi)``: the Illinois variant of regula
    falsi (the end that stays is halved in value, so both ends close in; superlinear, ~10
    evaluations to ``tolerance``), a bisection step whenever the bracket shrank by less
    than half in two steps. Returns ``w``."""
    a, b = math.log(lo), math.log(hi)
    f_a = residual_point(k_prime, e_prime, mu_prime, carter, s, v, lo)
    f_b = residual_point(k_prime, e_prime, mu_prime, carter, s, v, hi)
    side = 0
    width_before = 2.0 * (b - a)
    for evaluation in range(max_evaluations):
        if b - a <= tolerance:
            break
        if evaluation % 2 == 0:
            if b - a > 0.5 * width_before:  # slow: bisect
                x = 0.5 * (a + b)
                width_before = 2.0 * (b - a)
            else:
                width_before = b - a
                x = (a * f_b - b * f_a) / (f_b - f_a)
        else:
            x = (a * f_b - b * f_a) / (f_b - f_a)
        if not (a < x < b):
            x = 0.5 * (a + b)
        f_x = residual_point(k_prime, e_prime, mu_prime, carter, s, v, math.exp(x))
        if f_x > 0.0:  # narrow: the root is wider
            a, f_a = x, f_x
            if side == 1:
                f_b *= 0.5
            side = 1
        else:
            b, f_b = x, f_x
            if f_x == 0.0:
                a = b
                break
            if side == -1:
                f_a *= 0.5
            side = -1
    return math.exp(0.5 * (a + b))


#: relative precision (in ``log w``) of the compiled ``width``: 36 halvings of the bisection's
#: ratio <= 2 (``TipAsymptote.width``) leave ~1e-11
WIDTH_TOLERANCE = 1e-13


@njit(cache=True, nogil=True)
def width_points(s, velocity, k_prime, e_prime, mu_prime, carter, iterations, length, out):
    """``out[i] = w(s[i], V[i])`` (times the finite-fracture factor of ``length``): the root
    of the residual in ``log w`` between ``max(w_k, w_m)`` and ``w_k + w_m`` (the bracket of
    ``TipAsymptote.width``) by :func:`_log_width_root`, to :data:`WIDTH_TOLERANCE` or within
    ``iterations`` + 64 evaluations; with leak-off (``carter > 0``) the upper end doubles
    first until the asymptote is narrower."""
    for i in range(s.size):
        si = max(s[i], 0.0)
        if not si > 0.0:
            out[i] = 0.0
            continue
        v = max(velocity[i], 0.0)
        w_k = k_prime * math.sqrt(si) / e_prime
        w_m = BETA_M * (mu_prime * v / e_prime) ** (1.0 / 3.0) * si ** (2.0 / 3.0)
        lo = max(max(w_k, w_m), 1e-300)
        hi = (w_k + w_m) * (1.0 + 1e-12) + 1e-300
        if carter > 0.0:
            for _ in range(200):
                if not residual_point(k_prime, e_prime, mu_prime, carter, si, v, hi) > 0.0:
                    break
                lo, hi = hi, 2.0 * hi
        if not residual_point(k_prime, e_prime, mu_prime, carter, si, v, lo) > 0.0:
            w = lo  # the asymptote is at (or, by round-off, below) the lower end: a vertex
        elif residual_point(k_prime, e_prime, mu_prime, carter, si, v, hi) > 0.0:
            w = hi
        else:
            w = _log_width_root(k_prime, e_prime, mu_prime, carter, si, v, lo, hi, WIDTH_TOLERANCE,
                                iterations + 64)
        out[i] = w * finite_fracture_point(si, length)


@njit(cache=True, nogil=True)
def front_distance_points(w, s_old, dt, k_prime, e_prime, mu_prime, carter, iterations, length, out):
    """``out[i]``: the distance ``s >= s_old[i]`` at which the asymptote (times the
    finite-fracture factor) with ``V = (s - s_old) / dt`` opens by ``w[i]``: the bisection
    of ``TipAsymptote.front_distance`` on ``[s_old, s_k]``, ``s_k`` the toughness distance."""
    for i in range(w.size):
        wi = max(w[i], 1e-300)
        old = s_old[i]
        s_k = (e_prime * wi / k_prime) ** 2
        if math.isfinite(length):
            if s_k < 0.375 * length:
                s_k = length * (1.0 - math.sqrt(max(1.0 - 2.0 * s_k / length, 0.0)))
            else:
                s_k = s_k / 0.75
        if not s_k > old:
            out[i] = old
            continue
        lo, hi = old, s_k
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            w_bare = wi / finite_fracture_point(mid, length)
            if residual_point(k_prime, e_prime, mu_prime, carter, max(mid, 1e-300), (mid - old) / dt, w_bare) < 0.0:
                lo = mid
            else:
                hi = mid
        out[i] = 0.5 * (lo + hi)


def width(s, velocity, k_prime, e_prime, mu_prime, carter=0.0, iterations=36, length=np.inf):
    """:func:`width_points` over arrays (broadcast), as float64."""
    s, velocity = np.broadcast_arrays(np.asarray(s, np.float64), np.asarray(velocity, np.float64))
    out = np.empty(s.size)
    width_points(np.ascontiguousarray(s).ravel(), np.ascontiguousarray(velocity).ravel(), float(k_prime),
                 float(e_prime), float(mu_prime), float(carter), int(iterations), float(length), out)
    return out.reshape(s.shape)


def front_distance(w, distance_old, dt, k_prime, e_prime, mu_prime, carter=0.0, iterations=64, length=np.inf):
    """:func:`front_distance_points` over arrays (broadcast): ``(s, V)``."""
    w, s_old = np.broadcast_arrays(np.asarray(w, np.float64), np.asarray(distance_old, np.float64))
    out = np.empty(w.size)
    old = np.ascontiguousarray(s_old).ravel()
    front_distance_points(np.ascontiguousarray(w).ravel(), old, float(dt), float(k_prime), float(e_prime),
                          float(mu_prime), float(carter), int(iterations), float(length), out)
    s = out.reshape(w.shape)
    return s, (s - s_old) / dt
