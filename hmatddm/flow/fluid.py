"""Plain data of the fracturing fluid, the leak-off and the injection (ref. Sec. 4.3)."""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..settings import CLUSTER, FLUID, LEAK_OFF


@dataclass(frozen=True)
class Fluid:
    """Slightly compressible Newtonian fluid (ref. Eqs 4.22-4.24).

    Parameters
    ----------
    viscosity : float
        Dynamic viscosity mu_f in Pa s, > 0 (1 cP = 1e-3 Pa s). The lubrication
        equation uses mu' = 12 mu_f (cubic law, ref. Eq. 4.24).
    compressibility : float
        c_f in 1/Pa, >= 0 (ref. Eq. 4.22; 4.4e-4 1/MPa = 4.4e-10 1/Pa).
    """

    viscosity: float
    compressibility: float = 0.0

    def __post_init__(self):
        for name in ("viscosity", "compressibility"):
            object.__setattr__(self, name, FLUID[name].value(name, getattr(self, name)))

    @property
    def viscosity_prime(self):
        """mu' = 12 mu_f (ref. Eq. 4.24)."""
        return 12.0 * self.viscosity


@dataclass(frozen=True)
class LeakOff:
    """Carter leak-off (ref. Eqs 4.25-4.26): rate ``c_l (p - p_r) / sqrt(t - tau)``.

    Parameters
    ----------
    coefficient : float
        c_l in m / (s^1/2 Pa), >= 0 (ref. Table 4.1 units).
    pore_pressure : float
        Reservoir pore pressure p_r in Pa.
    """

    coefficient: float = 0.0
    pore_pressure: float = 0.0

    def __post_init__(self):
        for name in ("coefficient", "pore_pressure"):
            object.__setattr__(self, name, LEAK_OFF[name].value(f"leak_off.{name}", getattr(self, name)))


@dataclass(frozen=True)
class Cluster:
    """A perforation cluster: a wellbore connected to the fracture element nearest
    ``position`` (ref. Eqs 4.34-4.35: uniform wellbore pressure, no perforation loss).

    Parameters
    ----------
    position : (d,) point, m
    rate : float
        Volumetric injection rate q_w in m^3/s, >= 0 (2D: into the whole flow height).
    wellbore_volume : float
        V_w in m^3, >= 0; stores fluid through the compressibility.
    """

    position: tuple
    rate: float
    wellbore_volume: float = 0.0

    def __post_init__(self):
        position = finite_array("cluster.position", self.position)
        if position.ndim != 1 or position.size not in (2, 3):
            raise InputError(f"cluster.position must be a point with 2 or 3 coordinates, got shape {position.shape}")
        object.__setattr__(self, "position", tuple(float(v) for v in position))
        for name in ("rate", "wellbore_volume"):
            object.__setattr__(self, name, CLUSTER[name].value(f"cluster.{name}", getattr(self, name)))

    def nearest_element(self, mesh):
        position = np.asarray(self.position)
        if position.size != mesh.dim:
            raise InputError(f"cluster.position must have {mesh.dim} coordinates for a {mesh.dim}D mesh, "
                             f"got {position.size}")
        return int(np.argmin(np.sum((mesh.centers - position) ** 2, axis=1)))
