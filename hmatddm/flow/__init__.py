"""Lubrication flow in the fractures (ref. Sec. 4.3): fluid data and the FVM matrices."""
from .._lazy import attach

_EXPORTS = {
    "Cluster": ".fluid", "Fluid": ".fluid", "LeakOff": ".fluid", "LubricationModel": ".lubrication",
    "fracture_compliance": ".lubrication", "Proppant": ".proppant", "PumpSchedule": ".pump_schedule",
    "carter_coefficient": ".carter", "PumpRate": ".well", "Well": ".well",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = ["Fluid", "LeakOff", "Cluster", "LubricationModel", "fracture_compliance", "Proppant", "PumpSchedule",
           "carter_coefficient", "PumpRate", "Well"]
