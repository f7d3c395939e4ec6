"""Generic hierarchical-matrix engine: cluster tree, block tree, whole-element ACA,
flat storage with parallel matvec, near-field preconditioners and GMRES.

Knows nothing about elasticity: it compresses any :class:`BlockGenerator`.
"""

from .generator import BlockGenerator
from .hmatrix import HMatrix

__all__ = ["BlockGenerator", "HMatrix"]
