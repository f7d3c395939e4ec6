"""Plain data of the fracturing fluid, the leak-off and the injection (ref. Sec. 4.3)."""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..settings import CLUSTER, FLUID, LEAK_OFF


@dataclass(frozen=True)
class Fluid:
    """Slightly compressible fracturing fluid (ref. Eqs 4.22-4.24): Newtonian, or a
    power-law fluid (beyond the reference, which names it as its next step, ref. Sec. 8.2).

    Parameters
    ----------
    viscosity : float
        Newtonian dynamic viscosity mu_f in Pa s, > 0 (1 cP = 1e-3 Pa s); required for
        ``rheology="newtonian"``, not taken by a power-law fluid. The lubrication equation
        uses mu' = 12 mu_f (cubic law, ref. Eq. 4.24).
    compressibility : float
        c_f in 1/Pa, >= 0 (ref. Eq. 4.22; 4.4e-4 1/MPa = 4.4e-10 1/Pa).
    rheology : ``"newtonian"`` or ``"power-law"``
        A power-law (Ostwald-de Waele) fluid has the shear stress ``tau = K gamma_dot^n``.
    consistency : float
        K in Pa s^n, > 0, for ``rheology="power-law"`` (a Newtonian fluid is n = 1, K = mu; a
        power-law fluid given a ``viscosity`` instead takes K = viscosity).
    flow_index : float
        n in (0, 1] (power-law only; 1 for a Newtonian fluid).
    minimum_shear_rate : float
        gamma_0 in 1/s, > 0 (power-law only): where the wall shear rate of the parallel-plate
        flow falls below it, the fluid flows as a Newtonian one of the apparent viscosity
        ``K gamma_0^(n-1)`` (a truncated power law: a still fluid keeps a finite
        conductivity, :mod:`hmatddm.flow.lubrication`). Default 1e-3 1/s, far below the
        shear rates of fracture flow (~1-1e4 1/s).
    density : float
        rho in kg/m^3, > 0 (default 1000): the perforation and wellbore friction of a shared
        well (:mod:`hmatddm.flow.well`); the lubrication equation does not read it.

    The parallel-plate flux of a power-law fluid (Adachi and Detournay 2002, their Eq. 5)
    is ``q = -(w^(2n+1) / M')^(1/n) |dp/dx|^(1/n - 1) dp/dx`` with
    ``M' = 2^(n+1) (2n+1)^n / n^n K`` (:attr:`viscosity_prime`), which is the cubic law with
    ``mu' = 12 mu`` at n = 1.
    """

    viscosity: float = None
    compressibility: float = 0.0
    rheology: str = "newtonian"
    consistency: float = None
    flow_index: float = 1.0
    minimum_shear_rate: float = FLUID["minimum_shear_rate"].default
    density: float = FLUID["density"].default

    def __post_init__(self):
        rheology = FLUID["rheology"].value("fluid.rheology", self.rheology)
        object.__setattr__(self, "rheology", rheology)
        for name in ("compressibility", "flow_index", "minimum_shear_rate", "density"):
            object.__setattr__(self, name, FLUID[name].value(f"fluid.{name}", getattr(self, name)))
        if rheology == "newtonian":
            if self.viscosity is None:
                raise InputError("fluid.viscosity (Pa s) is required for fluid.rheology = 'newtonian'")
            if self.consistency is not None or self.flow_index != 1.0:
                raise InputError("fluid.consistency and fluid.flow_index describe a power-law fluid: set "
                                 "fluid.rheology = 'power-law' (a Newtonian fluid takes fluid.viscosity)")
            object.__setattr__(self, "viscosity", FLUID["viscosity"].value("fluid.viscosity", self.viscosity))
        else:
            if self.consistency is None and self.viscosity is None:
                raise InputError("fluid.consistency (Pa s^n) is required for fluid.rheology = 'power-law'")
            if self.consistency is not None and self.viscosity is not None:
                raise InputError("fluid.viscosity is the Newtonian viscosity; a power-law fluid takes "
                                 "fluid.consistency and fluid.flow_index instead (n = 1, K = mu is Newtonian)")
            if self.consistency is None:  # K = mu (a Newtonian fluid is n = 1, K = mu)
                object.__setattr__(self, "consistency", self.viscosity)
                object.__setattr__(self, "viscosity", None)
            object.__setattr__(self, "consistency", FLUID["consistency"].value("fluid.consistency",
                                                                                self.consistency))

    @property
    def power_law(self):
        """Whether the fluid is a power-law fluid (``rheology="power-law"``, any n)."""
        return self.rheology == "power-law"

    @property
    def consistency_index(self):
        """K in Pa s^n (the viscosity of a Newtonian fluid)."""
        return self.consistency if self.power_law else self.viscosity

    @property
    def viscosity_prime(self):
        """mu' = 12 mu_f (ref. Eq. 4.24); for a power-law fluid Adachi and Detournay's (2002)
        ``M' = 2^(n+1) (2n+1)^n / n^n K`` (Pa s^n), which is 12 K at n = 1."""
        if not self.power_law:
            return 12.0 * self.viscosity
        n = self.flow_index
        return 2.0 ** (n + 1.0) * (2.0 * n + 1.0) ** n / n**n * self.consistency


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


#: C_d of a perforation when a scene gives none (a sharp-edged, unworn perforation; Lecampion
#: and Desroches 2015 use 0.6)
DEFAULT_DISCHARGE_COEFFICIENT = 0.6


@dataclass(frozen=True)
class Cluster:
    """A perforation cluster: a wellbore connected to the fracture element nearest
    ``position`` (ref. Eqs 4.34-4.35: uniform wellbore pressure, no perforation loss), or
    a cluster of a well shared with others (issue 35, :mod:`hmatddm.flow.well`).

    Parameters
    ----------
    position : (d,) point, m
    rate : float or None
        Volumetric injection rate q_w in m^3/s, >= 0 (2D: into the whole flow height);
        required without a well, None with one (the pump schedule sets the rates).
    wellbore_volume : float
        V_w in m^3, >= 0; stores fluid through the compressibility (0 with a well, whose
        ``volume`` stores it).
    perforations : int >= 1 or None
        Number of perforations n of a cluster on a well (None: no perforation friction).
    perforation_diameter : float, m > 0, or None
        Their diameter d (with ``perforations``).
    discharge_coefficient : float in (0, 1] or None
        C_d of the orifice law (default 0.6 with ``perforations``).
    """

    position: tuple
    rate: float = None
    wellbore_volume: float = 0.0
    perforations: int = None
    perforation_diameter: float = None
    discharge_coefficient: float = None

    def __post_init__(self):
        position = finite_array("cluster.position", self.position)
        if position.ndim != 1 or position.size not in (2, 3):
            raise InputError(f"cluster.position must be a point with 2 or 3 coordinates, got shape {position.shape}")
        object.__setattr__(self, "position", tuple(float(v) for v in position))
        for name in ("rate", "wellbore_volume", "perforations", "perforation_diameter", "discharge_coefficient"):
            object.__setattr__(self, name, CLUSTER[name].value(f"cluster.{name}", getattr(self, name)))
        perforated = [name for name in ("perforations", "perforation_diameter") if getattr(self, name) is not None]
        if len(perforated) == 1:
            other = "perforation_diameter" if perforated[0] == "perforations" else "perforations"
            raise InputError(f"cluster.{other} is required with cluster.{perforated[0]} (a cluster's perforations: "
                             f"their count and diameter)")
        if perforated and self.discharge_coefficient is None:
            object.__setattr__(self, "discharge_coefficient", DEFAULT_DISCHARGE_COEFFICIENT)
        if not perforated and self.discharge_coefficient is not None:
            raise InputError("cluster.discharge_coefficient needs cluster.perforations and "
                             "cluster.perforation_diameter (the orifices it describes)")

    @property
    def has_perforations(self):
        return self.perforations is not None

    def nearest_element(self, mesh):
        position = np.asarray(self.position)
        if position.size != mesh.dim:
            raise InputError(f"cluster.position must have {mesh.dim} coordinates for a {mesh.dim}D mesh, "
                             f"got {position.size}")
        return int(np.argmin(np.sum((mesh.centers - position) ** 2, axis=1)))
