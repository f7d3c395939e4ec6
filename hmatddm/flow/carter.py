"""Carter's leak-off coefficient from the reservoir's properties (ref. Eq. 4.26).

The reference's Eq. 4.26, ``c_l = (k_r phi c / (pi mu))^(1/2)``, is the
compressibility-controlled coefficient of Howard and Fast (1957): the leak-off velocity
through ONE fracture face into a reservoir of permeability ``k_r``, porosity ``phi``, total
compressibility ``c`` and reservoir-fluid viscosity ``mu``, per unit of pressure
difference, is ``c_l (p - p_r) / (t - tau)^(1/2)``. A fracture loses fluid through both
faces, while the reference's mass balance (ref. Eq. 4.27, the lubrication equation of
:mod:`hmatddm.flow.lubrication`) takes ``c_l (p - p_r) / (t - tau)^(1/2)`` per unit of
fracture area: with Eq. 4.26 as printed it counts one face. :func:`carter_coefficient`
returns the two-face coefficient (``faces=2``) that :class:`hmatddm.LeakOff` takes;
``faces=1`` is the reference's reading. (The reference also writes the fracturing fluid's
``c_f`` and ``mu_f`` in Eq. 4.26; the reservoir's fluid and compressibility belong there.)

The leak-off-dominated closed forms that validate it are
:mod:`hmatddm.analytical.leak_off`'s.
"""
import math

from .._validation import finite_scalar
from ..errors import InputError


def _positive(name, value):
    value = finite_scalar(name, value)
    if value <= 0.0:
        raise InputError(f"{name} must be > 0, got {value:.12g}")
    return value


def carter_coefficient(permeability, porosity, total_compressibility, reservoir_viscosity, faces=2):
    """``faces * (k_r phi c / (pi mu))^(1/2)`` in m/(s^1/2 Pa) (ref. Eq. 4.26, module docstring).

    permeability k_r in m^2 (1 mD = 9.869e-16 m^2), porosity in (0, 1), total
    compressibility c in 1/Pa, reservoir-fluid viscosity mu in Pa s; ``faces`` 2 (the
    fracture's both faces: what :class:`hmatddm.LeakOff` takes) or 1 (ref. Eq. 4.27's
    reading of Eq. 4.26)."""
    k = _positive("leak_off.permeability", permeability)
    phi = finite_scalar("leak_off.porosity", porosity)
    if not 0.0 < phi < 1.0:
        raise InputError(f"leak_off.porosity must be in (0, 1), got {phi:.12g}")
    c = _positive("leak_off.reservoir_compressibility", total_compressibility)
    mu = _positive("leak_off.reservoir_viscosity", reservoir_viscosity)
    if faces not in (1, 2):
        raise InputError(f"faces must be 1 or 2, got {faces!r}")
    return faces * math.sqrt(k * phi * c / (math.pi * mu))


__all__ = ["carter_coefficient"]
