"""Lubrication flow in the fractures (ref. Sec. 4.3): fluid data and the FVM matrices."""
from .fluid import Cluster, Fluid, LeakOff
from .lubrication import LubricationModel, fracture_compliance

__all__ = ["Fluid", "LeakOff", "Cluster", "LubricationModel", "fracture_compliance"]
