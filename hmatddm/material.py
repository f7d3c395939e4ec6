"""Linear isotropic elastic material (ref. Ch. 2, Eq. 2.1: Hooke's law)."""
from dataclasses import dataclass, field

from .settings import MATERIAL


@dataclass(frozen=True)
class Elastic:
    """Homogeneous, isotropic, linear elastic rock.

    Parameters
    ----------
    shear_modulus : float
        G in Pa, finite and > 0.
    poisson_ratio : float
        nu, in [0, 0.5). (Negative ratios are physically possible but are refused:
        the fracture criteria of the reference assume nu >= 0.)

    Derived moduli (SI): ``youngs_modulus`` E = 2G(1+nu), ``plane_strain_modulus``
    E' = E / (1 - nu^2), ``lame_lambda`` = 2 G nu / (1 - 2 nu), ``bulk_modulus``.
    """

    shear_modulus: float
    poisson_ratio: float
    youngs_modulus: float = field(init=False)
    plane_strain_modulus: float = field(init=False)
    lame_lambda: float = field(init=False)
    bulk_modulus: float = field(init=False)

    def __post_init__(self):
        g = MATERIAL["shear_modulus"].value("shear_modulus", self.shear_modulus)
        nu = MATERIAL["poisson_ratio"].value("poisson_ratio", self.poisson_ratio)
        object.__setattr__(self, "shear_modulus", g)
        object.__setattr__(self, "poisson_ratio", nu)
        e = 2.0 * g * (1.0 + nu)
        object.__setattr__(self, "youngs_modulus", e)
        object.__setattr__(self, "plane_strain_modulus", e / (1.0 - nu * nu))
        object.__setattr__(self, "lame_lambda", 2.0 * g * nu / (1.0 - 2.0 * nu))
        object.__setattr__(self, "bulk_modulus", 2.0 * g * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu)))
