"""Undrained elastic constants from the drained ones (ref. Sec. 5.3.1, Eqs 5.17-5.21).

Shale is so tight that during a treatment its pore fluid has no time to flow: the rock
deforms *undrained*. Its constitutive law keeps the form of Hooke's law with the
undrained bulk modulus ``K_u`` in place of the drained ``K`` (ref. Eq. 5.17 against
Eq. 5.22), the shear modulus unchanged; the pore pressure follows the mean stress,
``p - p_0 = -B (sigma_m - sigma_m0)`` (ref. Eq. 5.18). So the DDM runs with the undrained
constants and the remote-failure check adds ``-B sigma_m`` to the pore pressure
(:class:`hmatddm.NaturalFractureProperties` ``skempton``).

From the drained bulk modulus ``K``, the shear modulus ``G``, the Biot coefficient
``alpha``, the fluid's bulk modulus ``K_f`` and the porosity ``phi``:

* ``K_s = K / (1 - alpha)``, the bulk modulus of the solid grains (ref. Eq. 5.20);
* ``K_u = K + alpha^2 K_s K_f / (phi K_s + (alpha - phi) K_f)`` (ref. Eq. 5.19);
* ``B = (K_u - K) / (alpha K_u)``, Skempton's coefficient (ref. Eq. 5.21);
* ``nu_u = (3 K_u - 2 G) / (2 (3 K_u + G))``, the undrained Poisson's ratio (isotropic
  elasticity with ``K_u`` and ``G``; the reference tabulates it without an equation).

``alpha = 1`` (incompressible grains) is the limit ``K_u = K + K_f / phi``.

The reference's Table 5.2 rounded ``K_u`` to two decimals in GPa before it computed
``nu_u`` and ``B``: from the printed 19.03 and 11.16 GPa, :func:`from_undrained_bulk_modulus`
gives its 0.3441 / 0.5255 and 0.2524 / 0.01456 to every printed digit; without the
rounding the same inputs give 0.3442 / 0.5256 and 0.2523 / 0.01431 (the gas case's B is
1.7 % smaller than printed, since ``K_u - K`` = 0.128 GPa loses two digits to the rounding).
"""
from dataclasses import dataclass

from .._validation import finite_scalar
from ..errors import InputError
from ..settings import POROELASTIC


def _positive(name, value):
    value = finite_scalar(name, value)
    if value <= 0.0:
        raise InputError(f"{name} must be > 0, got {value:.12g}")
    return value


def undrained_poisson_ratio(undrained_bulk_modulus, shear_modulus):
    """``nu_u = (3 K_u - 2 G) / (2 (3 K_u + G))``: Poisson's ratio of isotropic elasticity
    with bulk modulus ``K_u`` and shear modulus ``G``."""
    k_u, g = undrained_bulk_modulus, shear_modulus
    return (3.0 * k_u - 2.0 * g) / (2.0 * (3.0 * k_u + g))


def from_undrained_bulk_modulus(undrained_bulk_modulus, bulk_modulus, shear_modulus, biot):
    """``(nu_u, B)`` from a given undrained bulk modulus (ref. Eq. 5.21 and the isotropic
    relation): what the reference's Table 5.2 computed from its rounded ``K_u``."""
    k_u = _positive("undrained_bulk_modulus", undrained_bulk_modulus)
    k = _positive("bulk_modulus", bulk_modulus)
    g = _positive("shear_modulus", shear_modulus)
    alpha = POROELASTIC["biot"].value("poroelastic.biot", biot)
    if k_u < k:
        raise InputError(f"undrained_bulk_modulus must be >= bulk_modulus = {k:.12g} Pa, got {k_u:.12g} Pa")
    return undrained_poisson_ratio(k_u, g), (k_u - k) / (alpha * k_u)


@dataclass(frozen=True)
class UndrainedRock:
    """The drained rock, its pore fluid and the undrained constants derived from them
    (ref. Eqs 5.19-5.21; see the module docstring).

    Parameters
    ----------
    shear_modulus : float, G in Pa (> 0; drained and undrained alike)
    bulk_modulus : float, drained K in Pa (> 0)
    biot : float in (0, 1], alpha (>= porosity)
    fluid_bulk_modulus : float, K_f in Pa (> 0)
    porosity : float in (0, 1), phi

    Derived (attributes): ``solid_bulk_modulus`` K_s (inf when alpha = 1),
    ``undrained_bulk_modulus`` K_u, ``undrained_poisson_ratio`` nu_u, ``skempton`` B,
    ``drained_poisson_ratio`` nu. :meth:`from_poisson_ratio` takes the drained nu in place
    of K (a scene's ``[material]``).
    """

    shear_modulus: float
    bulk_modulus: float
    biot: float
    fluid_bulk_modulus: float
    porosity: float

    def __post_init__(self):
        object.__setattr__(self, "shear_modulus", _positive("material.shear_modulus", self.shear_modulus))
        object.__setattr__(self, "bulk_modulus", _positive("poroelastic.bulk_modulus", self.bulk_modulus))
        for name in ("biot", "fluid_bulk_modulus", "porosity"):
            object.__setattr__(self, name, POROELASTIC[name].value(f"poroelastic.{name}", getattr(self, name)))
        if self.biot < self.porosity:
            raise InputError(f"poroelastic.biot must be >= poroelastic.porosity = {self.porosity:.12g} (the grains "
                             f"cannot be softer than the rock, ref. Eq. 5.20), got {self.biot:.12g}")

    @classmethod
    def from_poisson_ratio(cls, shear_modulus, poisson_ratio, biot, fluid_bulk_modulus, porosity):
        """The drained bulk modulus from G and the drained nu: ``K = 2 G (1 + nu) / (3 (1 - 2 nu))``."""
        g = _positive("material.shear_modulus", shear_modulus)
        nu = finite_scalar("material.poisson_ratio", poisson_ratio)
        if not 0.0 <= nu < 0.5:
            raise InputError(f"material.poisson_ratio must be in [0, 0.5), got {nu:.12g}")
        return cls(g, 2.0 * g * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu)), biot, fluid_bulk_modulus, porosity)

    @property
    def solid_bulk_modulus(self):
        """K_s = K / (1 - alpha) (ref. Eq. 5.20)."""
        return float("inf") if self.biot == 1.0 else self.bulk_modulus / (1.0 - self.biot)

    @property
    def undrained_bulk_modulus(self):
        """K_u (ref. Eq. 5.19), written as ``K + alpha^2 K_f / (phi + (alpha - phi) K_f / K_s)``
        so that alpha = 1 (K_s infinite) is its limit."""
        a, phi, k_f = self.biot, self.porosity, self.fluid_bulk_modulus
        grain_term = 0.0 if a == 1.0 else (a - phi) * k_f * (1.0 - a) / self.bulk_modulus
        return self.bulk_modulus + a * a * k_f / (phi + grain_term)

    @property
    def skempton(self):
        """B = (K_u - K) / (alpha K_u) (ref. Eq. 5.21)."""
        k_u = self.undrained_bulk_modulus
        return (k_u - self.bulk_modulus) / (self.biot * k_u)

    @property
    def undrained_poisson_ratio(self):
        return undrained_poisson_ratio(self.undrained_bulk_modulus, self.shear_modulus)

    @property
    def drained_poisson_ratio(self):
        return undrained_poisson_ratio(self.bulk_modulus, self.shear_modulus)

    def summary(self):
        """The derived constants as one line of text (what ``hmatddm run --check`` prints)."""
        k_s = self.solid_bulk_modulus
        return (f"drained K = {self.bulk_modulus / 1e9:.4g} GPa, nu = {self.drained_poisson_ratio:.4f}; "
                f"K_s = {'inf' if k_s == float('inf') else f'{k_s / 1e9:.4g} GPa'} (ref. Eq. 5.20); "
                f"undrained K_u = {self.undrained_bulk_modulus / 1e9:.4g} GPa (Eq. 5.19), "
                f"nu_u = {self.undrained_poisson_ratio:.4f}, Skempton B = {self.skempton:.4g} (Eq. 5.21)")

    def to_dict(self):
        return {"shear_modulus": self.shear_modulus, "bulk_modulus": self.bulk_modulus, "biot": self.biot,
                "fluid_bulk_modulus": self.fluid_bulk_modulus, "porosity": self.porosity,
                "solid_bulk_modulus": self.solid_bulk_modulus,
                "undrained_bulk_modulus": self.undrained_bulk_modulus,
                "undrained_poisson_ratio": self.undrained_poisson_ratio, "skempton": self.skempton,
                "drained_poisson_ratio": self.drained_poisson_ratio}


__all__ = ["UndrainedRock", "undrained_poisson_ratio", "from_undrained_bulk_modulus"]
