"""Generic hierarchical-matrix engine: cluster tree, block tree, whole-element ACA,
flat storage with a parallel matvec, near-field and two-level preconditioners and GMRES.

Knows nothing about elasticity: it compresses the matrix of any
:class:`BlockGenerator` (a numba kernel filling d x d element blocks).
"""
from .._lazy import attach

_EXPORTS = {
    "BlockGenerator": ".generator", "HMatrix": ".hmatrix", "block_jacobi": ".preconditioners",
    "default_preconditioner": ".preconditioners", "near_field_block_ilu": ".preconditioners",
    "near_field_ilu": ".preconditioners", "near_field_lu": ".preconditioners", "gmres": ".solvers",
    "two_level": ".preconditioners",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = [
    "BlockGenerator",
    "HMatrix",
    "block_jacobi",
    "default_preconditioner",
    "gmres",
    "near_field_block_ilu",
    "near_field_ilu",
    "near_field_lu",
    "two_level",
]
