"""The block generator: the only thing the H-matrix engine knows about a kernel.

A matrix is made of d x d tensor blocks, one per pair of "elements" (row element i,
column element j). Element i owns the d consecutive unknowns ``d*i .. d*i + d - 1``
(element-major ordering). The generator fills any sub-matrix given by lists of row
and column elements; the compressor never sees anything else.
"""

from dataclasses import dataclass

import numpy as np

from hmatddm.errors import InputError


@dataclass(frozen=True)
class BlockGenerator:
    """Kernel plus geometry of a matrix of d x d element blocks.

    Attributes
    ----------
    kernel : numba dispatcher
        ``kernel(data, rows, cols, out)`` with ``rows``, ``cols`` int64 arrays of
        original element indices; fills ``out`` (float64, shape
        ``(len(rows)*d, len(cols)*d)``) with
        ``out[d*a+p, d*b+q] = A[d*rows[a]+p, d*cols[b]+q]``. Must be an
        ``@numba.njit`` function: the compiled drivers call it directly.
    data : tuple
        Arrays passed to ``kernel`` untouched.
    points : (N, dim) float64 array
        Element centres (dim 2 or 3), used for clustering.
    radii : (N,) float64 array
        Radius of each element; cluster bounding boxes include it.
    dof : int
        Unknowns per element d (1 for scalar kernels, 2 or 3 for DDM).
    """

    kernel: object
    data: tuple
    points: np.ndarray
    radii: np.ndarray
    dof: int

    def __post_init__(self):
        if not hasattr(self.kernel, "py_func"):
            raise InputError("kernel must be a numba @njit function (a numba dispatcher)")
        if not isinstance(self.data, tuple):
            raise InputError("data must be a tuple of arrays passed to the kernel")
        points = np.ascontiguousarray(self.points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] not in (2, 3) or points.shape[0] < 1:
            raise InputError(f"points must have shape (N, 2) or (N, 3) with N >= 1, got {points.shape}")
        if not np.all(np.isfinite(points)):
            raise InputError("points must be finite")
        radii = np.asarray(self.radii, dtype=np.float64)
        if radii.ndim == 0:
            radii = np.full(points.shape[0], float(radii))
        radii = np.ascontiguousarray(radii)
        if radii.shape != (points.shape[0],):
            raise InputError(f"radii must have shape ({points.shape[0]},), got {radii.shape}")
        if not np.all(np.isfinite(radii)) or np.any(radii < 0):
            raise InputError("radii must be finite and >= 0")
        if isinstance(self.dof, bool) or not isinstance(self.dof, (int, np.integer)) or self.dof < 1:
            raise InputError(f"dof must be an integer >= 1, got {self.dof!r}")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "radii", radii)
        object.__setattr__(self, "dof", int(self.dof))

    @property
    def n_elements(self):
        """Number of elements N."""
        return self.points.shape[0]

    @property
    def shape(self):
        """Shape ``(N*d, N*d)`` of the full matrix."""
        n = self.n_elements * self.dof
        return (n, n)

    def fill(self, rows, cols):
        """Return the dense sub-matrix for element lists ``rows`` x ``cols``.

        Costs one kernel call: O(len(rows) * len(cols) * d^2).
        """
        rows = np.ascontiguousarray(rows, dtype=np.int64).ravel()
        cols = np.ascontiguousarray(cols, dtype=np.int64).ravel()
        d = self.dof
        out = np.empty((rows.size * d, cols.size * d), dtype=np.float64)
        if out.size:
            self.kernel(self.data, rows, cols, out)
        return out

    def to_dense(self):
        """Full dense matrix in the original ordering: O((N d)^2) memory."""
        index = np.arange(self.n_elements, dtype=np.int64)
        return self.fill(index, index)
