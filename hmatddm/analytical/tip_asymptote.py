"""The universal tip asymptote of a hydraulic fracture and its inversion.

A fracture tip moving at speed ``V`` opens, at distance ``s`` behind the front, by
``w(s)`` that spans three limits (Garagash, Detournay and Adachi 2011):

* toughness (k):  ``w = K' s^(1/2) / E'``
* viscosity (m):  ``w = beta_m (mu' V / E')^(1/3) s^(2/3)``,  ``beta_m = 2^(1/3) 3^(5/6)``
* leak-off (m~):  ``w ~ (C' mu' / E')^(1/4) V^(1/8) s^(5/8)`` (in ``g_delta`` only)

with ``K' = 4 (2/pi)^(1/2) K_Ic``, ``E'`` the plane-strain modulus, ``mu' = 12 mu`` and
``C' = 2 C_L`` (Carter). Dontsov and Peirce (2015, J. Fluid Mech. 781 R1) give a closed
form that is uniformly accurate (about 1%) between them: with

    K^ = K' s^(1/2) / (E' w),   C^ = 2 C' s^(1/2) / (V^(1/2) w),   s^ = mu' V s^2 / (E' w^3)

the opening satisfies ``s^ = g_delta(K^, C^)``,

    g_delta(K, C) = f(K, b(delta) C, C_1(delta)),
    f(K, C, C_1) = [1 - K^3 - 3/2 C (1 - K^2) + 3 C^2 (1 - K) - 3 C^3 ln((C + 1)/(C + K))] / (3 C_1),
    delta = beta_m^3 / 3 (1 + beta_c C) f(K, beta_c C, beta_m^3 / 3),
    C_1(delta) = 4 (1 - 2 delta) / (delta (1 - delta)) tan(pi delta),
    C_2(delta) = 16 (1 - 3 delta) / (3 delta (2 - 3 delta)) tan(3 pi delta / 2),   b = C_2 / C_1,

(``beta_c = 0.9911799823``, the constant of their paper). ``K^ = 1`` is the k-vertex
(``s^ = 0``), ``K^ = C^ = 0`` gives ``delta = 1/3``, ``C_1 = 6 sqrt(3) = beta_m^3 / 3`` and the
m-vertex. ``g_delta`` and ``residual`` here are vectorised numpy; ``width`` and
``front_distance`` bisect (robust, no derivative) point by point in compiled code
(:mod:`.tip_asymptote_kernels`, the same formulas).

The asymptote is the opening of a semi-infinite crack. A fracture of radius (3D) or
half-length (2D) ``L`` opens by ``w(s) (1 - s/(2L))^lambda`` near its front: exactly so for
the K-vertex (Sneddon's penny and Griffith's crack, ``lambda = 1/2``) and in Dontsov's (2016)
approximate radial solution at any ``K_m`` (``lambda`` = 0.487 at the M-vertex;
:func:`hmatddm.analytical.radial_transition_profile`). :func:`finite_fracture_factor` is that
factor with ``lambda = 1/2``; ``width`` and ``front_distance`` take ``length = L`` to include it
(default infinite: the bare asymptote). Without it the inversion at ``s ~ h`` behind the front
reads the toughness ``(1 - s/(2L))^(-1/2)`` too high: +3% at ``L = 18 h``, which put the K-vertex
radius 1.2% short at h = 1 m (issue 16).
"""


def finite_fracture_factor(s, length):
    """``(1 - s/(2L))^(1/2)``, the opening of a fracture of radius or half-length ``L`` at
    distance ``s`` from its front relative to the semi-infinite asymptote (module docstring);
    1 for ``L = inf``. Held at its value ``(3/4)^(1/2)`` beyond ``s = L/2`` (a point that far
    from the front is not in any tip region; it keeps ``w(s)`` increasing)."""
    return np.sqrt(1.0 - 0.5 * np.minimum(np.asarray(s, float), 0.5 * length) / length)
import numpy as np

from .tip_asymptote_constants import _C1_M, BETA_C, BETA_M, BETA_M3, SERIES_FROM, SERIES_TERMS  # noqa: F401


def toughness_prime(toughness):
    """K' = 4 (2/pi)^(1/2) K_Ic."""
    return 4.0 * np.sqrt(2.0 / np.pi) * toughness


def _f(k_hat, c_hat, c_1):
    """Dontsov and Peirce's ``f(K, C, C_1)``.

    The closed form cancels terms of size ``C^3`` down to ``f ~ (1 - K^4) / (4 C C_1)``: in
    double precision it keeps ``eps 4 C^4`` of it, 1e-5 at ``C = 340`` and 1e-3 at ``C =
    1e3``. Expanding the logarithm, ``ln((C + 1)/(C + K)) = sum_j (-1)^(j+1) (1 - K^j) / (j
    C^j)``, the first three terms cancel the polynomial exactly and::

        f = sum_{j >= 4} (-1)^j (1 - K^j) / (j C^(j-3)) / C_1

    which converges for ``C > 1``; beyond ``C = SERIES_FROM`` (10) its first
    :data:`SERIES_TERMS` (20) terms leave < 1e-20 relative (the k-m~ edge, where Dontsov
    2016's code also takes a series, there of three terms from ``C = 1e3``).
    """
    k = np.minimum(k_hat, 1.0)
    c = c_hat
    series_point = c > SERIES_FROM
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        log_term = np.where(c > 0.0, c**3 * np.log((c + 1.0) / (c + k)), 0.0)
        closed = (1.0 - k**3 - 1.5 * c * (1.0 - k * k) + 3.0 * c * c * (1.0 - k) - 3.0 * log_term) / (3.0 * c_1)
        inverse = 1.0 / np.where(series_point, c, SERIES_FROM)
        series = np.zeros(np.shape(inverse))
        for j in range(4 + SERIES_TERMS - 1, 3, -1):  # smallest terms first
            series = series + (-1.0) ** j * (1.0 - k**j) / j * inverse ** (j - 3)
    return np.where(series_point, series / c_1, closed)


def g_delta(k_hat, c_hat):
    """Dontsov and Peirce's ``g_delta(K^, C^)`` (module docstring)."""
    k_hat, c_hat = np.asarray(k_hat, float), np.asarray(c_hat, float)
    g_0 = _f(k_hat, BETA_C * c_hat, _C1_M)
    delta = np.clip(_C1_M * (1.0 + BETA_C * c_hat) * g_0, 1e-9, 1.0 / 3.0)
    c_1 = 4.0 * (1.0 - 2.0 * delta) / (delta * (1.0 - delta)) * np.tan(np.pi * delta)
    c_2 = 16.0 * (1.0 - 3.0 * delta) / (3.0 * delta * (2.0 - 3.0 * delta)) * np.tan(1.5 * np.pi * delta)
    return _f(k_hat, c_hat * c_2 / c_1, c_1)


class TipAsymptote:
    """The universal asymptote for one rock and fluid.

    Parameters
    ----------
    plane_strain_modulus : E', Pa
    toughness : K_Ic, Pa m^1/2 (> 0)
    viscosity_prime : mu' = 12 mu, Pa s

    Without leak-off (``C^ = 0``): the simulations that use it have no tip leak-off
    (:class:`~hmatddm.Simulation` refuses an asymptotic front with a Carter coefficient).
    """

    def __init__(self, plane_strain_modulus, toughness, viscosity_prime):
        self.e_prime = float(plane_strain_modulus)
        self.k_prime = float(toughness_prime(toughness))
        self.mu_prime = float(viscosity_prime)

    def compiled_carter(self):
        """The Carter ``C'`` with which :mod:`.tip_asymptote_kernels` evaluates this
        asymptote (0: none), or None when a subclass changed :meth:`residual` (its own
        bisection then runs in numpy)."""
        return 0.0 if type(self).residual is TipAsymptote.residual else None

    def residual(self, s, velocity, w):
        """``s^ - g_delta(K^, C^)``: negative when ``w`` is wider than the asymptote at
        ``(s, V)``, positive when narrower (``w >= K' s^(1/2)/E'``)."""
        s, velocity, w = np.broadcast_arrays(np.asarray(s, float), np.asarray(velocity, float), np.asarray(w, float))
        v = np.maximum(velocity, 0.0)
        k_hat = self.k_prime * np.sqrt(s) / (self.e_prime * w)
        s_hat = self.mu_prime * v * s * s / (self.e_prime * w**3)
        return s_hat - g_delta(k_hat, np.zeros_like(k_hat))

    def toughness_width(self, s):
        return self.k_prime * np.sqrt(np.asarray(s, float)) / self.e_prime

    def viscosity_width(self, s, velocity):
        return BETA_M * (self.mu_prime * np.maximum(velocity, 0.0) / self.e_prime) ** (1.0 / 3.0) * \
            np.asarray(s, float) ** (2.0 / 3.0)

    def width(self, s, velocity, iterations=36, length=np.inf):
        """Opening ``w(s)`` at distance ``s >= 0`` behind a front moving at ``velocity``
        (times :func:`finite_fracture_factor` of ``length``).

        Bisection in ``log w`` between ``max(w_k, w_m)`` and ``w_k + w_m`` (the
        asymptote lies between them; tests/analytical/test_tip_asymptote.py checks it over 16 decades
        of ``s``), so 36 halvings of a ratio <= 2 give ~1e-11 relative precision.
        Point by point in compiled code (:mod:`.tip_asymptote_kernels`) unless a subclass
        changed :meth:`residual`.
        """
        if self.compiled_carter() is not None:
            from . import tip_asymptote_kernels

            return tip_asymptote_kernels.width(s, velocity, self.k_prime, self.e_prime, self.mu_prime,
                                               self.compiled_carter(), iterations, length)
        s, velocity = np.broadcast_arrays(np.asarray(s, float), np.asarray(velocity, float))
        s = np.maximum(s, 0.0)
        w_k = self.toughness_width(s)
        w_m = self.viscosity_width(s, velocity)
        positive = s > 0.0
        lo = np.where(positive, np.maximum(np.maximum(w_k, w_m), 1e-300), 1e-300)
        hi = np.where(positive, (w_k + w_m) * (1.0 + 1e-12) + 1e-300, 2e-300)
        s_safe = np.where(positive, s, 1.0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # s = 0 rows: replaced by 0 below
            for _ in range(iterations):
                mid = np.sqrt(lo * hi)
                narrow = self.residual(s_safe, velocity, mid) > 0.0
                lo = np.where(narrow, mid, lo)
                hi = np.where(narrow, hi, mid)
        return np.where(positive, np.sqrt(lo * hi), 0.0) * finite_fracture_factor(s, length)

    def front_distance(self, w, distance_old, dt, iterations=64, length=np.inf):
        """Invert the asymptote for the distance ``s`` from a point of opening ``w`` to the
        front, with ``V = (s - s_old) / dt`` (the front never retreats: ``s >= s_old``).

        ``w(s, (s - s_old)/dt)`` grows with ``s``; it equals ``K' s_old^(1/2)/E'`` at
        ``s = s_old`` and exceeds ``w`` at the toughness distance ``s_k = (E' w / K')^2``,
        so the root is bracketed in ``[s_old, s_k]`` when ``s_k > s_old`` (else the front
        stands still). With a finite ``length`` ``L`` the opening is read against the asymptote
        times :func:`finite_fracture_factor` (which keeps that product growing with ``s``):
        ``s_k`` solves ``s (1 - s/(2L)) = (E' w / K')^2`` (``s (3/4)`` beyond ``L/2``).
        Returns ``(s, V)``. Point by point in compiled code (:mod:`.tip_asymptote_kernels`)
        unless a subclass changed :meth:`residual`.
        """
        if self.compiled_carter() is not None:
            from . import tip_asymptote_kernels

            return tip_asymptote_kernels.front_distance(w, distance_old, dt, self.k_prime, self.e_prime,
                                                        self.mu_prime, self.compiled_carter(), iterations, length)
        w, s_old = np.broadcast_arrays(np.asarray(w, float), np.asarray(distance_old, float))
        w = np.maximum(w, 1e-300)
        s_k = (self.e_prime * w / self.k_prime) ** 2
        if np.isfinite(length):
            near = s_k < 0.375 * length  # s (1 - s/(2L)) at s = L/2
            s_k = np.where(near, length * (1.0 - np.sqrt(np.maximum(1.0 - 2.0 * s_k / length, 0.0))), s_k / 0.75)
        moves = s_k > s_old
        lo = s_old.copy()
        hi = np.where(moves, s_k, s_old)
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            w_bare = w / finite_fracture_factor(mid, length)
            wide = self.residual(np.maximum(mid, 1e-300), (mid - s_old) / dt, w_bare) < 0.0  # wider than asymptote
            lo = np.where(moves & wide, mid, lo)
            hi = np.where(moves & ~wide, mid, hi)
        s = np.where(moves, 0.5 * (lo + hi), s_old)
        return s, (s - s_old) / dt
