"""Generic hierarchical-matrix engine: cluster tree, block tree, whole-element ACA,
flat storage with a parallel matvec, near-field preconditioners and GMRES.

Knows nothing about elasticity: it compresses the matrix of any
:class:`BlockGenerator` (a numba kernel filling d x d element blocks).
"""

from .generator import BlockGenerator
from .hmatrix import HMatrix
from .preconditioners import block_jacobi, default_preconditioner, near_field_block_ilu, near_field_ilu, near_field_lu
from .solvers import gmres

__all__ = [
    "BlockGenerator",
    "HMatrix",
    "block_jacobi",
    "default_preconditioner",
    "gmres",
    "near_field_block_ilu",
    "near_field_ilu",
    "near_field_lu",
]
