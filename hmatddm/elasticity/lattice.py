"""The operator of a planar crack meshed on a lattice, applied by FFT: exact, no build.

The asymptotic front (:mod:`hmatddm.simulation.asymptotic`) meshes a planar crack with
equal rectangles on a fixed lattice, and a growing crack only adds cells of it. In a
homogeneous whole space the influence of element ``j`` on element ``i`` then depends on
their cell offset alone: the opening part ``A_nn`` and the shear part ``A_ss`` of
:mod:`hmatddm.elasticity.planar` are (block) Toeplitz in the two lattice directions,

    A_nn[i, j] = K(c_i - c_j),    K(o) = n . A(o) n  (ref. Eqs 2.57-2.59, App. A)

and a product is a discrete convolution: scatter the DDs on the cells' box (padded to at
least ``2 span - 1`` per direction, so that the circular convolution does not wrap),
multiply by the FFT of the kernel table ``K`` and gather the cells back. The table is
the kernel itself, evaluated once per padded box size (:func:`fft_length` rounds the box
up to a coarse ladder of sizes, so a growing crack computes a new one a few times per
doubling of its side); the products are exact to round-off -- no ACA, no admissibility,
no recompression, and no border blocks or rebuilds while the crack grows.

This is the method of the planar-3D hydraulic-fracture simulators on regular grids
(Peirce & Detournay 2008's ILSA and its successors); here it replaces the H-matrix of
:class:`~hmatddm.elasticity.planar.PlanarElasticityOperator` whenever the mesh is a
lattice (:func:`lattice_of`), and the H-matrix stays for everything else (networks,
several planes, layered rock). The preconditioner is the same block ILU(0) of the
thresholded near field as the H-matrix's (:data:`hmatddm.hmatrix.preconditioners.DEFAULT_ILU`),
its blocks read from the table.

Measured on the radial K-vertex run (benchmarks/RESULTS.md, issue 33, "the lattice").
"""
import time

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError
from ..material import Elastic
from ..mesh import Mesh3D
from .operator import influence_data
from .planar import PlanarElasticityOperator, is_planar, normal_traction_block, shear_traction_block

#: A mesh is a lattice when every element has the first one's frame and half sides (to
#: this relative tolerance) and every centre is the first one's plus whole cells.
LATTICE_TOLERANCE = 1e-9

#: The near field the preconditioner keeps is looked for among offsets of at most this
#: many cells (the kept blocks of the DDM kernel lie within 3.2 cells at the default
#: threshold; a kept offset on the edge of the search is refused).
NEAR_REACH = 8

#: Box sizes per direction: 2^a times one of these (successive sizes 1.14-1.25x apart).
FFT_FACTORS = (16, 20, 24, 28)


class Lattice:
    """The lattice of a planar mesh: ``origin`` (the first element's centre), ``frame``
    (rows e1, e2, n of every element), ``spacing`` (cell sides along e1, e2) and
    ``cells`` (N, 2) integer offsets of each element from the first."""

    def __init__(self, origin, frame, spacing, cells):
        self.origin, self.frame, self.spacing, self.cells = origin, frame, spacing, cells
        self.low = cells.min(axis=0)
        self.span = cells.max(axis=0) - self.low + 1

    def same_lattice(self, other):
        """Whether ``other`` has the same origin, frame and spacing (bit for bit)."""
        return (other is not None and np.array_equal(self.origin, other.origin)
                and np.array_equal(self.frame, other.frame) and np.array_equal(self.spacing, other.spacing))


def lattice_of(mesh, tolerance=LATTICE_TOLERANCE):
    """The :class:`Lattice` of ``mesh``, or None when it is not one: a planar
    :class:`~hmatddm.mesh.Mesh3D` of equal rectangles with one frame (normals of one sign)
    whose centres lie on whole cells of the first element, no cell taken twice."""
    if not isinstance(mesh, Mesh3D) or not is_planar(mesh):
        return None
    frame = mesh.frames[0]
    if not np.allclose(mesh.frames, frame, rtol=0.0, atol=tolerance):
        return None
    half = np.array([mesh.half_a[0], mesh.half_b[0]])
    if not (np.allclose(mesh.half_a, half[0], rtol=tolerance, atol=0.0)
            and np.allclose(mesh.half_b, half[1], rtol=tolerance, atol=0.0)):
        return None
    spacing = 2.0 * half
    offsets = ((mesh.centers - mesh.centers[0]) @ frame[:2].T) / spacing
    cells = np.rint(offsets)
    if not np.all(np.abs(offsets - cells) <= tolerance * max(1.0, float(np.abs(cells).max()))):
        return None
    cells = cells.astype(np.int64)
    if np.unique(cells[:, 0] * (int(np.ptp(cells[:, 1])) + 1) + (cells[:, 1] - cells[:, 1].min())).size != len(cells):
        return None
    return Lattice(mesh.centers[0].copy(), frame.copy(), spacing, cells)


def fft_length(span):
    """The box size along a direction of ``span`` cells: the smallest 2^a x
    :data:`FFT_FACTORS` >= 2 span - 1 (and >= 2 :data:`NEAR_REACH` + 1)."""
    need = max(2 * int(span) - 1, 2 * NEAR_REACH + 1)
    best, power = None, 1
    while best is None:
        for factor in FFT_FACTORS:
            if factor * power >= need:
                best = factor * power
                break
        power *= 2
    return best


class KernelTable:
    """The kernel of one part (``dof`` 1: opening, 2: shear) on every offset of a box of
    ``shape`` cells (offsets ``-(L // 2) .. L - L // 2 - 1`` per direction, wrapped), its
    FFT, and its near-field blocks. A function of the lattice's frame and spacing, the
    material and ``shape`` only, so operators of a growing crack share it."""

    def __init__(self, lattice, material, singular_correction, alpha, dof, shape):
        start = time.perf_counter()
        self.dof, self.shape = dof, shape
        lx, ly = shape
        ox = np.arange(lx) - lx // 2
        oy = np.arange(ly) - ly // 2
        grid_x, grid_y = np.meshgrid(ox, oy, indexing="ij")
        offsets = np.stack([grid_x.ravel(), grid_y.ravel()], axis=1)
        frame = lattice.frame
        centers = lattice.origin + (offsets * lattice.spacing) @ frame[:2]
        m = len(offsets)
        mesh = Mesh3D(np.ascontiguousarray(centers), np.repeat(frame[None], m, axis=0),
                      np.full(m, 0.5 * lattice.spacing[0]), np.full(m, 0.5 * lattice.spacing[1]),
                      np.zeros(m, dtype=np.int64))
        data = influence_data(mesh, material, singular_correction, alpha)
        source = int(np.flatnonzero((offsets[:, 0] == 0) & (offsets[:, 1] == 0))[0])
        column = np.empty((m * dof, dof))
        kernel = normal_traction_block if dof == 1 else shear_traction_block
        kernel(data, np.arange(m, dtype=np.int64), np.array([source], dtype=np.int64), column)
        if not np.all(np.isfinite(column)):
            raise InputError("the lattice kernel table is not finite: the elements' sides or material are degenerate")
        blocks = column.reshape(m, dof, dof)
        table = np.zeros((dof, dof, lx, ly))
        table[:, :, grid_x.ravel() % lx, grid_y.ravel() % ly] = blocks.transpose(1, 2, 0)
        self.self_block = blocks[source].copy()
        self.table = table
        self.table_hat = np.fft.rfft2(table, axes=(2, 3))
        reach = np.abs(offsets).max(axis=1) <= NEAR_REACH
        self.near_offsets, self.near_blocks = offsets[reach], blocks[reach]
        self.seconds = time.perf_counter() - start

    def kept(self, threshold):
        """(offsets, blocks) of the near field whose blocks are at least ``threshold`` of the
        self block (Frobenius norms; the H-matrix's rule, ``||A_ii|| = ||A_jj||`` here)."""
        norms = np.linalg.norm(self.near_blocks.reshape(len(self.near_blocks), -1), axis=1)
        keep = norms >= threshold * np.linalg.norm(self.self_block)
        keep |= np.all(self.near_offsets == 0, axis=1)
        offsets = self.near_offsets[keep]
        if np.abs(offsets).max() >= NEAR_REACH:
            raise InputError(f"threshold {threshold:g} keeps blocks {NEAR_REACH} cells away: too small for the "
                             "lattice's near-field search")
        return offsets, self.near_blocks[keep]


class LatticeMatrix:
    """One part (``dof`` unknowns per element) of a lattice mesh's operator, N d x N d,
    applied by FFT (module docstring). The methods the planar operator and its
    preconditioners ask of an :class:`~hmatddm.hmatrix.HMatrix`: :meth:`matvec`,
    :meth:`near_field_bsr`, :meth:`element_diagonal_blocks`, :meth:`to_dense`."""

    def __init__(self, lattice, table):
        self.lattice, self.table = lattice, table
        self.dof = table.dof
        self.n_elements = len(lattice.cells)
        self.shape = (self.n_elements * self.dof,) * 2
        self._where = tuple((lattice.cells - lattice.low).T)
        self._near = {}

    @property
    def stats(self):
        return dict(backend="lattice", fft_shape=self.table.shape, memory_bytes=int(self.table.table_hat.nbytes),
                    build_seconds=self.table.seconds, n_elements=self.n_elements, eps=0.0, n_admissible=0,
                    n_dense_blocks=0, max_rank=0)

    def is_finite(self):
        return bool(np.all(np.isfinite(self.table.table_hat)))

    def matvec(self, x):
        """``A x`` (flat, element-major): scatter, FFT convolution, gather."""
        d, (lx, ly) = self.dof, self.table.shape
        x = np.asarray(x, dtype=np.float64).reshape(self.n_elements, d)
        grid = np.zeros((d, lx, ly))
        grid[(slice(None),) + self._where] = x.T
        spectrum = np.fft.rfft2(grid, axes=(1, 2))
        product = np.einsum("abij,bij->aij", self.table.table_hat, spectrum) if d > 1 else \
            self.table.table_hat[0] * spectrum
        y = np.fft.irfft2(product, s=(lx, ly), axes=(1, 2))
        return np.ascontiguousarray(y[(slice(None),) + self._where].T).ravel()

    def matmat(self, X):
        X = np.asarray(X, dtype=np.float64)
        return np.column_stack([self.matvec(X[:, k]) for k in range(X.shape[1])])

    def element_diagonal_blocks(self):
        """(N, d, d): every element's self block (the same on a lattice)."""
        return np.repeat(self.table.self_block[None], self.n_elements, axis=0)

    def near_field_bsr(self, part="near", threshold=0.0):
        """The near field's element blocks at least ``threshold`` of the self block, as a
        BSR matrix in element order with sorted columns (``part``: "near" only)."""
        if part != "near":
            raise InputError(f"part must be 'near' for a lattice operator, got {part!r}")
        key = float(threshold)
        if key not in self._near:
            self._near[key] = self._near_field(key)
        return self._near[key]

    def _near_field(self, threshold):
        offsets, blocks = self.table.kept(threshold)
        cells = self.lattice.cells - self.lattice.low
        index = np.full(tuple(self.lattice.span), -1, dtype=np.int64)
        index[tuple(cells.T)] = np.arange(self.n_elements)
        indptr, cols, kinds = _near_pattern(cells, index, np.ascontiguousarray(offsets, dtype=np.int64))
        d = self.dof
        matrix = sp.bsr_matrix((blocks[kinds], cols, indptr), shape=self.shape, blocksize=(d, d))
        matrix.has_sorted_indices = True
        return matrix

    def to_dense(self):
        """The whole matrix (N d x N d) from the table (tests and small meshes)."""
        d, (lx, ly) = self.dof, self.table.shape
        cells = self.lattice.cells
        offset = cells[:, None, :] - cells[None, :, :]
        blocks = self.table.table[:, :, offset[..., 0] % lx, offset[..., 1] % ly]  # (d, d, N, N)
        return np.ascontiguousarray(blocks.transpose(2, 0, 3, 1)).reshape(self.shape)


@njit(cache=True)
def _near_pattern(cells, index, offsets):
    """CSR pattern (indptr, sorted columns, offset of each entry) of receivers ``i`` and
    sources ``j`` at cell offset ``cells[i] - cells[j]`` in ``offsets``; ``index``: the
    element of each cell of the box, -1 where none."""
    n, m = cells.shape[0], offsets.shape[0]
    span_x, span_y = index.shape
    indptr = np.zeros(n + 1, dtype=np.int64)
    cols = np.empty(n * m, dtype=np.int64)
    kinds = np.empty(n * m, dtype=np.int64)
    count = 0
    for i in range(n):
        start = count
        for k in range(m):
            x, y = cells[i, 0] - offsets[k, 0], cells[i, 1] - offsets[k, 1]
            if 0 <= x < span_x and 0 <= y < span_y and index[x, y] >= 0:
                j, position = index[x, y], count
                while position > start and cols[position - 1] > j:  # insertion: columns sorted
                    cols[position], kinds[position] = cols[position - 1], kinds[position - 1]
                    position -= 1
                cols[position], kinds[position] = j, k
                count += 1
        indptr[i + 1] = count
    return indptr, cols[:count].copy(), kinds[:count].copy()


def lattice_preconditioner(matrix):
    """Block ILU(0) of ``matrix``'s near field at the default threshold
    (:data:`~hmatddm.hmatrix.preconditioners.DEFAULT_ILU`), in element order, as a
    LinearOperator: the H-matrix's default below two-level sizes."""
    from ..hmatrix.block_ilu import block_ilu0, block_ilu_solve
    from ..hmatrix.preconditioners import DEFAULT_ILU

    near = matrix.near_field_bsr(threshold=DEFAULT_ILU["threshold"])
    indptr, indices = near.indptr.astype(np.int64), near.indices.astype(np.int64)
    values, inverse_diagonal, diagonal_position, failed = block_ilu0(indptr, indices, np.ascontiguousarray(near.data))
    if failed >= 0:
        raise RuntimeError(f"lattice block ILU: the pivot block of element {failed} is singular")
    return LinearOperator(matrix.shape, dtype=np.float64, matvec=lambda x: block_ilu_solve(
        indptr, indices, values, inverse_diagonal, diagonal_position, np.ascontiguousarray(x, dtype=np.float64).ravel()))


class LatticePlanarOperator(PlanarElasticityOperator):
    """:class:`~hmatddm.elasticity.planar.PlanarElasticityOperator` of a lattice mesh
    (:func:`lattice_of`) with its parts as :class:`LatticeMatrix` products instead of
    H-matrices. ``previous``: an earlier LatticePlanarOperator of the same lattice (a
    growing crack), whose kernel tables are reused when the box size is the same; the
    mesh checks of :class:`~hmatddm.ElasticityOperator` (coincident and near-parallel
    elements) cannot fail on distinct cells of one plane and are skipped."""

    def __init__(self, mesh, material, previous=None, singular_correction="none", alpha=None, eps=None, eta=None,
                 leaf_size=None):
        if not isinstance(material, Elastic):
            raise InputError(f"material must be an hmatddm.Elastic (a homogeneous medium), got {type(material).__name__}")
        lattice = lattice_of(mesh)
        if lattice is None:
            raise InputError("mesh must be a planar lattice of equal rectangles (lattice_of)")
        LinearOperator.__init__(self, dtype=np.float64, shape=(3 * mesh.n_elements,) * 2)
        self.mesh, self.material, self.backend, self.dof = mesh, material, "hmatrix", 3
        self.singular_correction, self.alpha = singular_correction, alpha
        self.lattice = lattice
        self._compression = {name: value for name, value in (("eps", eps), ("eta", eta), ("leaf_size", leaf_size))
                             if value is not None}
        shares = (isinstance(previous, LatticePlanarOperator) and lattice.same_lattice(previous.lattice)
                  and previous.material == material and previous.singular_correction == singular_correction
                  and previous.alpha == alpha)
        self._tables = previous._tables if shares else {}
        self.tables_computed = 0
        self._data = None
        self._matrix = self._lu = self._preconditioner = self._shear = self._shear_preconditioner = self._full = None
        self._diagonal_blocks = None
        self._parts = {}
        self._normals = np.ascontiguousarray(mesh.frames[:, 2])
        self._axes = np.ascontiguousarray(mesh.frames[:, :2])
        self._hmatrix = self._build_part(None, 1)

    @property
    def data(self):
        """The kernel data of the mesh (made on first use: products never need it)."""
        if self._data is None:
            self._data = influence_data(self.mesh, self.material, self.singular_correction, self.alpha)
        return self._data

    def _build_part(self, kernel, dof):
        shape = tuple(fft_length(span) for span in self.lattice.span)
        key = (dof, shape)
        if key not in self._tables:
            for other in [k for k in self._tables if k[1] != shape]:  # a box the crack outgrew
                del self._tables[other]
            self._tables[key] = KernelTable(self.lattice, self.material, self.singular_correction, self.alpha, dof,
                                            shape)
            self.tables_computed += 1
        return LatticeMatrix(self.lattice, self._tables[key])

    def _shear_operator(self):
        if self._shear is None:
            self._shear = self._build_part(None, 2)
        return self._shear

    def _part_preconditioner(self, name):
        if name == "normal":
            if self._preconditioner is None:
                self._preconditioner = lattice_preconditioner(self._hmatrix)
            return self._preconditioner
        if self._shear_preconditioner is None:
            self._shear_preconditioner = lattice_preconditioner(self._shear_operator())
        return self._shear_preconditioner

    @property
    def stats(self):
        stats = super().stats
        stats.update(backend="lattice", fft_shape=self._hmatrix.table.shape)
        return stats

    def element_diagonal_blocks(self):
        """(N, 3, 3): every element's self block (one kernel call: equal on a lattice)."""
        if self._diagonal_blocks is None:
            from ..kernels.drivers import self_blocks

            one = influence_data(self.mesh.subset([0]), self.material, self.singular_correction, self.alpha)
            self._diagonal_blocks = np.repeat(self_blocks(one), self.mesh.n_elements, axis=0)
        return self._diagonal_blocks.copy()

    def check_against_dense(self, n_samples=64):
        """0.0: the products are exact to round-off (no compressed block)."""
        return 0.0
