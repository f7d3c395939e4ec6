"""The floating-point flags (numba's ``fastmath``) of the H-matrix engine's numba loops:
the ACA (:mod:`.aca_pivoting`), the recompression (:mod:`.recompression`) and the
matvec of the stored blocks (:mod:`.matvec`).
"""

# Floating-point flags that let LLVM vectorise dot products (reassociation) while
# keeping NaN/inf semantics, so finiteness checks stay meaningful.
FAST = {"reassoc", "contract", "nsz", "arcp"}
