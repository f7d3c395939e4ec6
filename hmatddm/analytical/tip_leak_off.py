"""The universal tip asymptote with Carter leak-off (Dontsov and Peirce 2015): the
``C^`` terms of ``g_delta`` (:mod:`hmatddm.analytical.tip_asymptote`), for the asymptotic
front of a leaking fracture (:mod:`hmatddm.simulation.asymptotic`).

With Carter's two-face coefficient ``C'`` (m/s^1/2; in this project ``C' = c_l (p -
p_r)``, ref. Eq. 4.25) the opening at distance ``s`` behind a front moving at ``V``
satisfies ``s^ = g_delta(K^, C^)`` with ``C^ = 2 C' s^(1/2) / (V^(1/2) w)`` besides ``K^``
and ``s^`` of the module above. It spans the k, m and m~ limits, the last
``w ~ (C' mu' / E')^(1/4) V^(1/8) s^(5/8)``: leak-off near the front asks for more flux
into it, so the opening is wider than without leak-off at the same ``(s, V)``. A front at
rest (``V = 0``) opens as the toughness asymptote (``K^ = 1`` makes ``g_delta`` vanish for
any ``C^``). :class:`LeakOffTipAsymptote` takes one ``C'`` for every point of a call.

Used by the asymptotic front (:mod:`hmatddm.simulation.asymptotic`) with one ``C'`` per
step at the ribbon's mean pressure; how the elements the front crosses leak, and why, is in
:mod:`hmatddm.simulation.front_leak_off`.
"""
import numpy as np

from .tip_asymptote import TipAsymptote, g_delta


class LeakOffTipAsymptote(TipAsymptote):
    """:class:`~hmatddm.analytical.tip_asymptote.TipAsymptote` with Carter leak-off.

    Parameters
    ----------
    plane_strain_modulus, toughness, viscosity_prime : as the parent's
    carter : C' = 2 C_L in m/s^1/2 (>= 0; 0: the parent's asymptote)
    """

    def __init__(self, plane_strain_modulus, toughness, viscosity_prime, carter=0.0):
        super().__init__(plane_strain_modulus, toughness, viscosity_prime)
        self.carter = float(carter)

    def compiled_carter(self):
        """``C'`` for :mod:`.tip_asymptote_kernels` (None when a subclass changed :meth:`residual`)."""
        return self.carter if type(self).residual is LeakOffTipAsymptote.residual else None

    def residual(self, s, velocity, w):
        """``s^ - g_delta(K^, C^)`` (negative when ``w`` is wider than the asymptote)."""
        s, velocity, w = np.broadcast_arrays(np.asarray(s, float), np.asarray(velocity, float), np.asarray(w, float))
        v = np.maximum(velocity, 0.0)
        moving = v > 0.0
        # a front at rest: s^ = 0 (also where w^3 underflows, which made 0/0 warnings and NaN)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            k_hat = self.k_prime * np.sqrt(s) / (self.e_prime * w)
            s_hat = np.where(moving, self.mu_prime * v * s * s / (self.e_prime * w**3), 0.0)
            c_hat = np.where(moving, 2.0 * self.carter * np.sqrt(s) / (np.sqrt(np.where(moving, v, 1.0)) * w), 0.0)
            return s_hat - g_delta(k_hat, c_hat)

    def width(self, s, velocity, iterations=36, length=np.inf):
        """Opening ``w(s)`` behind a front moving at ``velocity`` (the parent's bisection in
        ``log w``, from the no-leak-off bracket ``[max(w_k, w_m), w_k + w_m]`` widened
        upwards until it holds the root: leak-off widens the opening). Point by point in
        compiled code (:mod:`.tip_asymptote_kernels`) unless a subclass changed :meth:`residual`."""
        if self.compiled_carter() is not None:
            from . import tip_asymptote_kernels

            return tip_asymptote_kernels.width(s, velocity, self.k_prime, self.e_prime, self.mu_prime,
                                               self.compiled_carter(), iterations, length)
        s, velocity = np.broadcast_arrays(np.asarray(s, float), np.asarray(velocity, float))
        s = np.maximum(s, 0.0)
        w_k = self.toughness_width(s)
        w_m = self.viscosity_width(s, velocity)
        positive = s > 0.0
        s_safe = np.where(positive, s, 1.0)
        lo = np.where(positive, np.maximum(np.maximum(w_k, w_m), 1e-300), 1e-300)
        hi = np.where(positive, (w_k + w_m) * (1.0 + 1e-12) + 1e-300, 2e-300)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for _ in range(200):  # hi doubles until it is wider than the asymptote
                narrow = positive & (self.residual(s_safe, velocity, hi) > 0.0)
                if not np.any(narrow):
                    break
                lo = np.where(narrow, hi, lo)
                hi = np.where(narrow, 2.0 * hi, hi)
            for _ in range(iterations + int(np.ceil(np.log2(np.max(hi / lo, initial=2.0))))):
                mid = np.sqrt(lo * hi)
                narrow = self.residual(s_safe, velocity, mid) > 0.0
                lo = np.where(narrow, mid, lo)
                hi = np.where(narrow, hi, mid)
        from .tip_asymptote import finite_fracture_factor

        return np.where(positive, np.sqrt(lo * hi), 0.0) * finite_fracture_factor(s, length)


__all__ = ["LeakOffTipAsymptote"]
