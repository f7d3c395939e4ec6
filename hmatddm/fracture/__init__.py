"""Fracture mechanics at the tips (ref. Sec. 4.2.2): SIFs, criteria and growth."""
from .criteria import (OLSON_CORRECTION, circumferential_stress_direction, energy_release_rate,
                       equivalent_mode_one, stress_intensity_factors)
from .crossing import CROSSING_CRITERIA, NaturalFractureProperties, crosses, near_tip_stress, plane_tractions
from .growth import Propagation, TipState, evaluate_tips, new_elements

__all__ = ["NaturalFractureProperties", "CROSSING_CRITERIA", "crosses", "near_tip_stress", "plane_tractions",
           "Propagation", "TipState", "evaluate_tips", "new_elements", "stress_intensity_factors",
           "circumferential_stress_direction", "equivalent_mode_one", "energy_release_rate", "OLSON_CORRECTION"]
