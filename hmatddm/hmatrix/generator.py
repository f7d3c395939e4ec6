"""The block generator: the only thing the H-matrix engine knows about a kernel.

A matrix is made of tensor blocks, one per pair of "elements" (row element i, column
element j). Square operators (rows and columns are the same elements, e.g. the DDM
traction matrix) have d x d blocks and element i owns the d consecutive unknowns
``d*i .. d*i + d - 1`` (element-major ordering). Rectangular matrices (e.g. stress
components at target points x DD components of elements) have their own column
geometry and d_r x d_c blocks: row element i owns rows ``d_r*i ..``, column element j
columns ``d_c*j ..``. The generator fills any sub-matrix given by lists of row and
column elements; the compressor never sees anything else.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class BlockGenerator:
    """Kernel plus geometry of a matrix of element blocks.

    Attributes
    ----------
    kernel : numba dispatcher
        ``kernel(data, rows, cols, out)`` with ``rows``, ``cols`` int64 arrays of
        original element indices; fills ``out`` (float64, shape
        ``(len(rows)*d_r, len(cols)*d_c)``) with
        ``out[d_r*a+p, d_c*b+q] = A[d_r*rows[a]+p, d_c*cols[b]+q]``. Must be an
        ``@numba.njit`` function: the compiled drivers call it directly.
    data : tuple
        Arrays passed to ``kernel`` untouched.
    points : (N, dim) float64 array
        Row element centres (dim 2 or 3), used for clustering.
    radii : (N,) float64 array
        Radius of each row element; cluster bounding boxes include it.
    dof : int
        Unknowns per row element d_r (1 for scalar kernels, 2 or 3 for DDM).
    col_points, col_radii, col_dof : optional
        The column elements of a rectangular matrix (centres (N_c, dim), radii, unknowns
        per element d_c); None (default): the columns are the row elements (a square
        operator, d_c = d_r).
    row_offset, col_offset : int >= 0
        The kernel's index of row element ``i`` is ``row_offset + i`` (of column element
        ``j``: ``col_offset + j``): a matrix over consecutive slices of the elements of a
        larger kernel data, e.g. the border blocks between the old and the added elements
        of a grown mesh (:mod:`hmatddm.elasticity.extended`). Default 0.
    """

    kernel: object
    data: tuple
    points: np.ndarray
    radii: np.ndarray
    dof: int
    col_points: np.ndarray = None
    col_radii: np.ndarray = None
    col_dof: int = None
    row_offset: int = 0
    col_offset: int = 0

    def __post_init__(self):
        if not hasattr(self.kernel, "py_func"):
            raise InputError("kernel must be a numba @njit function (a numba dispatcher)")
        if not isinstance(self.data, tuple):
            raise InputError("data must be a tuple of arrays passed to the kernel")
        points, radii, dof = _geometry("", self.points, self.radii, self.dof)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "radii", radii)
        object.__setattr__(self, "dof", dof)
        given = [name for name in ("col_points", "col_radii", "col_dof") if getattr(self, name) is not None]
        if given and len(given) < 3:
            raise InputError(f"col_points, col_radii and col_dof come together (a rectangular matrix), got only {given}")
        if given:
            col_points, col_radii, col_dof = _geometry("col_", self.col_points, self.col_radii, self.col_dof)
            if col_points.shape[1] != points.shape[1]:
                raise InputError(f"col_points must have dimension {points.shape[1]} like points, got {col_points.shape}")
            object.__setattr__(self, "col_points", col_points)
            object.__setattr__(self, "col_radii", col_radii)
            object.__setattr__(self, "col_dof", col_dof)
        for name in ("row_offset", "col_offset"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise InputError(f"{name} must be an integer >= 0, got {value!r}")
            object.__setattr__(self, name, int(value))
        if self.col_offset and not self.rectangular:
            raise InputError("col_offset needs the column elements of a rectangular matrix (col_points)")

    @property
    def rectangular(self):
        """True when the columns are their own elements (``col_points`` given)."""
        return self.col_points is not None

    @property
    def n_elements(self):
        """Number of row elements N."""
        return self.points.shape[0]

    @property
    def n_col_elements(self):
        """Number of column elements (N for a square operator)."""
        return self.col_points.shape[0] if self.rectangular else self.points.shape[0]

    @property
    def column_dof(self):
        """Unknowns per column element d_c (``dof`` for a square operator)."""
        return self.col_dof if self.rectangular else self.dof

    @property
    def shape(self):
        """Shape ``(N*d_r, N_c*d_c)`` of the full matrix."""
        return (self.n_elements * self.dof, self.n_col_elements * self.column_dof)

    def kernel_rows(self, rows):
        """The kernel's indices (int64, C order) of row elements ``rows``."""
        rows = np.ascontiguousarray(rows, dtype=np.int64).ravel()
        return rows + self.row_offset if self.row_offset else rows

    def kernel_cols(self, cols):
        """The kernel's indices (int64, C order) of column elements ``cols``."""
        cols = np.ascontiguousarray(cols, dtype=np.int64).ravel()
        offset = self.col_offset if self.rectangular else self.row_offset
        return cols + offset if offset else cols

    def fill(self, rows, cols):
        """Return the dense sub-matrix for element lists ``rows`` x ``cols``.

        Costs one kernel call: O(len(rows) * len(cols) * d_r * d_c).
        """
        rows, cols = self.kernel_rows(rows), self.kernel_cols(cols)
        out = np.empty((rows.size * self.dof, cols.size * self.column_dof), dtype=np.float64)
        if out.size:
            self.kernel(self.data, rows, cols, out)
        return out

    def to_dense(self):
        """Full dense matrix in the original ordering: O(N d_r N_c d_c) memory."""
        return self.fill(np.arange(self.n_elements, dtype=np.int64), np.arange(self.n_col_elements, dtype=np.int64))


def _geometry(prefix, points, radii, dof):
    """Checked ``(points, radii, dof)`` of the row (``prefix=""``) or column elements."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3) or points.shape[0] < 1:
        raise InputError(f"{prefix}points must have shape (N, 2) or (N, 3) with N >= 1, got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise InputError(f"{prefix}points must be finite")
    radii = np.asarray(radii, dtype=np.float64)
    if radii.ndim == 0:
        radii = np.full(points.shape[0], float(radii))
    radii = np.ascontiguousarray(radii)
    if radii.shape != (points.shape[0],):
        raise InputError(f"{prefix}radii must have shape ({points.shape[0]},), got {radii.shape}")
    if not np.all(np.isfinite(radii)) or np.any(radii < 0):
        raise InputError(f"{prefix}radii must be finite and >= 0")
    if isinstance(dof, bool) or not isinstance(dof, (int, np.integer)) or dof < 1:
        raise InputError(f"{prefix}dof must be an integer >= 1, got {dof!r}")
    return points, radii, int(dof)
