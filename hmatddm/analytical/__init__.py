"""Closed-form solutions (the bottom of the house, docs/architecture.md): what the tests,
the validation table and the scenes' ``[reference]`` blocks compare with.

* :mod:`.solutions`: Griffith and Sneddon cracks, the radial and KGD vertex solutions
  (K and M), their regime numbers and the radial K-M transition (Dontsov 2016).
* :mod:`.regimes`: the regime numbers (dimensionless toughness and leak-off, radial and
  KGD), where each vertex applies, and the closed forms a scene's ``[reference]`` names.
* :mod:`.tip_asymptote`: the universal tip asymptote (Dontsov and Peirce 2015), inverted
  by the asymptotic front.
* :mod:`.transition_table`: the radial K-M transition tabulated in time, for a run that
  compares with it at every step.
* :mod:`.m_vertex_numeric`: the KGD and radial M-vertex similarity solutions computed to
  1e-7 (the published constants above carry 0.03-1%).
* :mod:`.leak_off`: leak-off-dominated sizes (the K~ and M~ vertices) and the plane-strain
  K-K~ edge.
* :mod:`.viscous_leak_off`: the plane-strain M~ vertex and Dontsov's (2016, 2017) radial and
  plane-strain solutions at any toughness, viscosity and leak-off.

Names of :mod:`.solutions` are exported here (``hd.analytical.radial_k_vertex``), loaded
on first use (scipy.special is not imported with the package).
"""
from .._lazy import attach

_SOLUTIONS = (
    "griffith_opening", "sneddon_opening", "sneddon_volume", "sneddon_axis_stress", "toughness_scale",
    "radial_k_vertex", "radial_m_vertex", "kgd_k_vertex", "radial_m_vertex_profile", "well_element_radius",
    "radial_m_vertex_pressure", "kgd_m_vertex_profile", "kgd_m_vertex", "radial_regime", "kgd_regime",
    "radial_transition_profile", "radial_transition",
)
_LEAK_OFF = ("kgd_leak_off_half_length", "radial_leak_off_radius", "kgd_toughness_leak_off_edge",
             "radial_toughness_leak_off_edge")
_REGIMES = (
    "radial_toughness_number", "kgd_toughness_number", "radial_leak_off_number", "kgd_leak_off_number",
    "applicable_solution", "m_leak_off_toughness_number",
)
_TABLES = ("RadialTransitionTable", "radial_transition_table")
_M_VERTEX = ("kgd_m_vertex_numeric", "radial_m_vertex_numeric")
_VISCOUS_LEAK_OFF = ("kgd_m_leak_off_vertex", "kgd_m_leak_off_profile", "kgd_leak_off_transition",
                     "radial_leak_off_transition", "radial_leak_off_profile", "radial_m_leak_off_vertex",
                     "radial_m_leak_off_profile")
_EXPORTS = {**{name: ".solutions" for name in _SOLUTIONS}, **{name: ".leak_off" for name in _LEAK_OFF},
            **{name: ".regimes" for name in _REGIMES}, **{name: ".transition_table" for name in _TABLES},
            **{name: ".m_vertex_numeric" for name in _M_VERTEX},
            **{name: ".viscous_leak_off" for name in _VISCOUS_LEAK_OFF}}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = (list(_SOLUTIONS) + list(_LEAK_OFF) + list(_REGIMES) + list(_TABLES) + list(_M_VERTEX)
           + list(_VISCOUS_LEAK_OFF))
