"""Fracture mechanics at the tips (ref. Sec. 4.2.2): SIFs, criteria and growth."""
from .._lazy import attach

_EXPORTS = {
    "OLSON_CORRECTION": ".criteria", "circumferential_stress_direction": ".criteria",
    "energy_release_rate": ".criteria", "equivalent_mode_one": ".criteria", "stress_intensity_factors": ".criteria",
    "CROSSING_CRITERIA": ".crossing", "NaturalFractureProperties": ".crossing", "crosses": ".crossing",
    "near_tip_stress": ".crossing", "plane_tractions": ".crossing", "Propagation": ".growth", "TipState": ".growth",
    "evaluate_tips": ".growth", "new_elements": ".growth",
    "UndrainedRock": ".poroelastic", "from_undrained_bulk_modulus": ".poroelastic",
    "undrained_poisson_ratio": ".poroelastic",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = ["NaturalFractureProperties", "CROSSING_CRITERIA", "crosses", "near_tip_stress", "plane_tractions",
           "Propagation", "TipState", "evaluate_tips", "new_elements", "stress_intensity_factors",
           "circumferential_stress_direction", "equivalent_mode_one", "energy_release_rate", "OLSON_CORRECTION",
           "UndrainedRock", "from_undrained_bulk_modulus", "undrained_poisson_ratio"]
