"""The tip asymptote of a hydraulic fracture driven by a power-law fluid (beyond the reference,
which stops at Newtonian fluids, ref. Sec. 8.2), for the asymptotic front.

A power-law fluid (``tau = K gamma_dot^n``) has the parallel-plate flux
``q = -(w^(2n+1) / M')^(1/n) |p'|^(1/n - 1) p'`` with ``M' = 2^(n+1) (2n+1)^n / n^n K``
(Adachi and Detournay 2002). Behind a front moving at ``V`` without leak-off, a
semi-infinite crack opens by

* toughness (k): ``w_k = K' s^(1/2) / E'``
* viscosity (m): ``w_m = beta_mn (M' V^n / E')^(1/(n+2)) s^(2/(n+2))``,
  ``beta_mn^(n+2) = 2 (n+2)^2 / n tan(pi n / (n+2))``

(the m-vertex: lubrication ``p' = M' V^n / w^(n+1)`` with the elastic pressure of
``w = B s^alpha``, ``p = -(E'/4) alpha |cot(pi alpha)| B s^(alpha-1)``, ``alpha = 2/(n+2)``;
at n = 1 ``beta_m^3 = 18 sqrt(3)`` of :mod:`hmatddm.analytical.tip_asymptote`). Between the
two, Dontsov and Kresse (2018, J. Fluid Mech.; the power-law generalisation of the zero-order
k-m transition, with the fitted ``theta(n)`` as the EPFL PyFrac code's power-law tip inversion
uses it; the paper itself was not consulted here) approximate the opening by

    w~ = (1 + (beta_mn^(n+2) x~^(2-n))^(1/(1+theta)))^((1+theta)/(n+2)),
    w~ = E' w / (K' s^(1/2)),  x~ = (s / l)^(1/2),  l = (K'^(n+2) / (M' V^n E'^(n+1)))^(2/(2-n)),
    theta = 0.0452 n^2 - 0.178 n + 0.1753,

which is, with ``a = (n+2)/(1+theta)``, the closed form ``w = (w_k^a + w_m^a)^(1/a)``: exact
at both vertices, within a few percent between them (the fitted ``theta``). At n = 1 the
project's Newtonian asymptote (Dontsov and Peirce 2015, uniformly ~1%) is the better one:
:func:`tip_asymptote` returns it there, so that a power-law fluid of n = 1 runs exactly as the
Newtonian fluid.
"""
import numpy as np

from .._validation import positive_scalar
from ..errors import InputError
from .tip_asymptote import TipAsymptote, finite_fracture_factor


def beta_power_law(flow_index):
    """``beta_mn = (2 (n+2)^2 / n tan(pi n / (n+2)))^(1/(n+2))`` of the power-law m-vertex."""
    n = float(flow_index)
    return (2.0 * (n + 2.0) ** 2 / n * np.tan(np.pi * n / (n + 2.0))) ** (1.0 / (n + 2.0))


def transition_theta(flow_index):
    """Dontsov and Kresse's (2018) fitted exponent ``theta(n) = 0.0452 n^2 - 0.178 n + 0.1753``."""
    n = float(flow_index)
    return 0.0452 * n * n - 0.178 * n + 0.1753


class PowerLawTipAsymptote(TipAsymptote):
    """The k-m asymptote of a power-law fluid (module docstring), with the interface of
    :class:`~hmatddm.analytical.tip_asymptote.TipAsymptote` (``width``, ``front_distance``,
    ``residual``) that the asymptotic front and :func:`hmatddm.fracture.front.fill` use.

    Parameters
    ----------
    plane_strain_modulus : E', Pa
    toughness : K_Ic, Pa m^1/2 (> 0)
    consistency_prime : M' = 2^(n+1) (2n+1)^n / n^n K, Pa s^n
    flow_index : n in (0, 1]
    """

    def __init__(self, plane_strain_modulus, toughness, consistency_prime, flow_index):
        super().__init__(plane_strain_modulus, toughness, consistency_prime)
        n = positive_scalar("flow_index", flow_index)
        if n > 1.0:
            raise InputError(f"flow_index must be in (0, 1], got {n}")
        self.n = n
        self.beta = beta_power_law(n)
        self.exponent = (n + 2.0) / (1.0 + transition_theta(n))  # a of w = (w_k^a + w_m^a)^(1/a)

    def viscosity_width(self, s, velocity):
        n = self.n
        return self.beta * (self.mu_prime * np.maximum(velocity, 0.0) ** n / self.e_prime) ** (1.0 / (n + 2.0)) * \
            np.asarray(s, float) ** (2.0 / (n + 2.0))

    def _bare_width(self, s, velocity):
        a = self.exponent
        w_k = self.toughness_width(s)
        w_m = self.viscosity_width(s, velocity)
        big = np.maximum(w_k, w_m)
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(big > 0.0, np.minimum(w_k, w_m) / np.where(big > 0.0, big, 1.0), 0.0)
        return big * (1.0 + ratio**a) ** (1.0 / a)

    def residual(self, s, velocity, w):
        """``w(s, V) / w - 1`` of the bare asymptote: negative when ``w`` is wider than it,
        positive when narrower (the sign convention of the Newtonian ``residual``)."""
        s, velocity, w = np.broadcast_arrays(np.asarray(s, float), np.asarray(velocity, float), np.asarray(w, float))
        return self._bare_width(np.maximum(s, 0.0), velocity) / w - 1.0

    def width(self, s, velocity, iterations=None, length=np.inf):
        """Opening ``w(s)`` at distance ``s >= 0`` behind a front moving at ``velocity`` (the
        closed form of the module docstring), times
        :func:`~hmatddm.analytical.tip_asymptote.finite_fracture_factor` of ``length``.
        (``iterations`` is accepted for the interface and unused: no inversion is needed.)"""
        s, velocity = np.broadcast_arrays(np.asarray(s, float), np.asarray(velocity, float))
        s = np.maximum(s, 0.0)
        return self._bare_width(s, velocity) * finite_fracture_factor(s, length)


def tip_asymptote(plane_strain_modulus, toughness, viscosity_prime, flow_index=1.0):
    """The tip asymptote of a fluid of flow index ``n`` with ``viscosity_prime`` ``M'`` (``mu' =
    12 mu`` at n = 1): the Newtonian :class:`~hmatddm.analytical.tip_asymptote.TipAsymptote` at
    n = 1, else :class:`PowerLawTipAsymptote`."""
    if float(flow_index) == 1.0:
        return TipAsymptote(plane_strain_modulus, toughness, viscosity_prime)
    return PowerLawTipAsymptote(plane_strain_modulus, toughness, viscosity_prime, flow_index)
