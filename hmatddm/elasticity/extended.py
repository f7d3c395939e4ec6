"""An elasticity operator grown by a few elements without recompressing it.

When a fracture grows, the mesh gains a ring of elements at its front. Rebuilding the
H-matrix for every growth pass would dominate the run time, so the new elements are
added as border blocks around the existing operator::

    A = [ A_oo   A_on ]    A_oo: the H-matrix (or dense matrix) already built
        [ A_no   A_nn ]    A_on, A_no: exact kernel blocks, or compressed (below)
                           A_nn: exact kernel block (dense)

Dense borders cost ``2 N m d^2`` per product for ``m`` new elements, so the simulation
rebuilds the base operator once the border is large (see ``Simulation``). The preconditioner
is block lower-triangular: the base near-field preconditioner for the old unknowns,
then an exact LU of ``A_nn`` for the new ones.

Large borders are compressed: once the base is an H-matrix of a few thousand elements,
a chunk of added elements gets ``A_on`` and ``A_no`` as rectangular H-matrices (the base's
cluster tree against a tree of the chunk, same ``eps`` and ``eta`` as the base), so a
border costs ``O((N + m) k)`` entries instead of ``N m`` and its size no longer forces a
rebuild of the base at every ring of a large mesh (see :data:`COMPRESS_MIN_BASE`; 62k
elements + a ring of 1000: 27 MB and 3.5 s instead of 1 GB and 26 s, benchmarks/RESULTS.md,
issue 33).

Growth passes share work (a pass adds a few elements to the last pass's mesh): the border
is kept as one chunk of ``A_on`` columns and ``A_no`` rows per batch of added elements,
so the chunks of the elements a pass shares with the previous one are reused as they are
(no copy of the whole border per pass); the LU of ``A_nn`` grows by one level per batch
(:class:`~hmatddm.elasticity.growing_lu.GrowingBlockLU`: the Schur complement of the added block, not a new
factorisation of the whole block); and the product of the base with the old unknowns is
kept for the last vector (a pass's first residual multiplies the previous pass's last
iterate, whose old part it already multiplied).
"""
from typing import NamedTuple

import numpy as np
import scipy.linalg
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError
from ..hmatrix.preconditioners import DEFAULT_ILU
from ..kernels.drivers import traction_block
from .growing_lu import GrowingBlockLU
from .inverse import solve_with_inverse
from .operator import ElasticityOperator, ProductCounter, influence_data, refuse_singular


#: Border blocks the block-triangular preconditioner keeps (relative Frobenius norm, as the
#: base's near-field block ILU keeps its blocks).
NEAR_THRESHOLD = DEFAULT_ILU["threshold"]

#: A chunk of added elements gets compressed border blocks (rectangular H-matrices over
#: the base's cluster tree) when the base is an H-matrix of at least this many elements
#: and the chunk's dense border would hold at least :data:`COMPRESS_MIN_PAIRS` element
#: pairs; smaller chunks stay dense (an ACA of a few columns saves nothing).
COMPRESS_MIN_BASE = 2048
COMPRESS_MIN_PAIRS = 2**18

#: The near field of a compressed chunk's rows (the blocks :data:`NEAR_THRESHOLD` keeps)
#: is looked for among the old elements within this many times the sum of the two largest
#: element radii. On a planar square grid the kept blocks lie within 3.2 element sides
#: (4.5 radii) of the receiver, for the opening, shear and whole-tensor kernels alike; the
#: search reaches 6 x 2 radii = 8.5 sides.
NEAR_SEARCH_RADII = 6.0


class ExtendedElasticityOperator(ProductCounter, LinearOperator):
    """``base`` (an ElasticityOperator of the first ``n0`` elements of ``mesh``) plus
    border blocks for elements ``n0..N-1``: exact, or compressed to the base's ``eps``
    (module docstring).

    ``base`` may also be one part of a planar crack's operator
    (:meth:`hmatddm.elasticity.planar.PlanarElasticityOperator.part`): its ``dof`` unknowns
    per element and its ``block_kernel`` then give the border blocks.

    ``previous``: the operator of an earlier growth pass over the same ``base`` (for
    example the last one returned). The border chunks and the ``A_nn`` factor levels of
    the elements it shares with ``mesh`` (the longest common run of unchanged elements
    after the base's) are taken from it (chunks as views, ``A_nn``'s entries copied); only
    the rows and columns of the elements added since are evaluated by the kernel, so a
    growth pass costs O(n0 m_added) kernel pairs instead of O(n0 m). Any other
    ``previous`` (another base, changed elements) is ignored.
    """

    def __init__(self, base, mesh, previous=None):
        if not (isinstance(base, ElasticityOperator) or hasattr(base, "block_kernel")):
            raise InputError(f"base must be an ElasticityOperator, got {type(base).__name__}")
        self._kernel = getattr(base, "block_kernel", traction_block)
        n0, n = base.mesh.n_elements, mesh.n_elements
        if n <= n0 or not np.array_equal(mesh.centers[:n0], base.mesh.centers):
            raise InputError(f"mesh must extend the base operator's mesh ({n0} elements) by appending elements, "
                             f"got {n} elements")
        self.base = base
        self.mesh = mesh
        self.material = base.material
        self.backend = base.backend
        self.dof = d = base.dof
        self.n_base = n0
        super().__init__(dtype=np.float64, shape=(n * d, n * d))
        data = influence_data(mesh, base.material, base.singular_correction, base.alpha,
                              n_images=base.stats.get("n_images"))  # layered: the base's images
        self._data = data
        shares = isinstance(previous, ExtendedElasticityOperator) and previous.base is base
        self._base_blocks = previous._base_blocks if shares else None  # the base's element self blocks
        self._base_search = previous._base_search if shares else None  # a k-d tree of the base's centres
        self.chunks, self.nn, self.n_reused = self._border_blocks(previous, self._shared_new_elements(previous))
        self._base_product = previous._base_product if shares else _LastProduct(base.matvec)
        self._nn_levels = GrowingBlockLU(self.nn, previous._nn_levels.prefix(self.n_reused * self.dof)
                                         if self.n_reused else None)
        self.border_bytes = sum(chunk.nbytes for chunk in self.chunks) + self.nn.nbytes

    def _shared_new_elements(self, previous):
        """How many of ``previous``'s border elements are elements ``n0, n0 + 1, ...`` of
        this mesh unchanged (same kernel data), 0 if ``previous`` cannot be reused."""
        if not isinstance(previous, ExtendedElasticityOperator) or previous.base is not self.base:
            return 0
        n0, n_previous = self.n_base, previous.mesh.n_elements
        mine, theirs = _flat_arrays(self._data), _flat_arrays(previous._data)
        if len(mine) != len(theirs):
            return 0
        shared = min(n_previous, self.mesh.n_elements)
        for a, b in zip(mine, theirs):
            if a.ndim >= 1 and b.ndim >= 1 and a.shape[0] == self.mesh.n_elements and b.shape[0] == n_previous:
                if a.shape[1:] != b.shape[1:] or a.dtype != b.dtype:
                    return 0
                differ = np.flatnonzero(np.any((a[:shared] != b[:shared]).reshape(shared, -1), axis=1))
                if differ.size:
                    shared = int(differ[0])
            elif not (a.shape == b.shape and np.array_equal(a, b)):
                return 0  # a per-mesh setting (material, options) changed
        return max(shared - n0, 0)

    def _border_blocks(self, previous, reused):
        """(chunks, A_nn, reused): the chunks (:class:`BorderChunk`) of the first ``reused``
        new elements taken from ``previous`` (views, not copies; a compressed chunk only
        whole: ``reused`` drops to its start when the shared run ends inside it), one chunk
        evaluated for the rest; ``A_nn`` with its shared block copied from ``previous``."""
        d, n0, n = self.dof, self.n_base, self.mesh.n_elements
        old = np.arange(n0, dtype=np.int64)
        new = np.arange(n0, n, dtype=np.int64)
        k = reused * d
        chunks = []
        if reused:
            for chunk in previous.chunks:
                if chunk.start >= k:
                    break
                keep = min(chunk.stop, k) - chunk.start
                if keep == chunk.stop - chunk.start:
                    chunks.append(chunk)
                elif chunk.compressed:
                    k = chunk.start
                    break
                else:
                    chunks.append(BorderChunk(chunk.start, chunk.start + keep, chunk.on_t[:keep], chunk.no[:keep],
                                              chunk.near[:keep]))
            reused = k // d
        added = new[reused:]
        nn = np.empty((new.size * d, new.size * d))
        if reused:
            nn[:k, :k] = previous.nn[:k, :k]
            nn[:k, k:] = self._block(self._data, new[:reused], added)
            nn[k:, :k] = self._block(self._data, added, new[:reused])
        if added.size:
            nn[k:, k:] = self._block(self._data, added, added)
            if not np.all(np.isfinite(nn[k:, k:])):
                refuse_singular()
            if self._compresses(added.size):
                chunks.append(self._compressed_chunk(k, added, nn[k:, k:]))
            else:
                on, no = self._block(self._data, old, added), self._block(self._data, added, old)
                if not (np.all(np.isfinite(on)) and np.all(np.isfinite(no))):
                    refuse_singular()
                # A_on stored transposed: a product with a few columns of a C-ordered A_on runs
                # ~1.4x slower (short BLAS rows) than with the rows of its transpose
                chunks.append(BorderChunk(k, new.size * d, np.ascontiguousarray(on.T), no,
                                          self._near_rows(no, nn[k:, k:])))
        if not (np.all(np.isfinite(nn[:, k:])) and np.all(np.isfinite(nn[k:]))):
            refuse_singular()
        return chunks, nn, reused

    def _compresses(self, m):
        """Whether a chunk of ``m`` added elements gets compressed border blocks."""
        return compresses_borders(self.base) and self.n_base * m >= COMPRESS_MIN_PAIRS and m >= 2

    @property
    def chunk_bytes(self):
        """Bytes of the border chunks (``A_on`` and ``A_no``, without ``A_nn``)."""
        return sum(chunk.nbytes for chunk in self.chunks)

    def _compressed_chunk(self, k, added, nn_added):
        """A :class:`BorderChunk` of the ``added`` elements (unknowns ``k..`` of the new
        ones) whose ``A_on`` and ``A_no`` are rectangular H-matrices: the rows (columns) of
        the old elements clustered by the base's tree, the added ones by a tree of their
        own, compressed with the base's ``eps``, ``eta`` and leaf size."""
        from ..hmatrix import BlockGenerator, HMatrix
        from ..hmatrix.cluster_tree import cluster_tree

        base = self.base.hmatrix
        mesh, d, n0 = self.mesh, self.dof, self.n_base
        first = int(added[0])
        if not np.array_equal(added, np.arange(first, first + added.size)):
            raise AssertionError("the added elements must be consecutive")  # appended by construction
        old_points, old_radii = mesh.centers[:n0], mesh.radii[:n0]
        new_points, new_radii = mesh.centers[added], mesh.radii[added]
        new_tree = cluster_tree(new_points, new_radii, base.leaf_size)
        options = dict(eps=base.eps, eta=base.eta, leaf_size=base.leaf_size)
        try:
            on = HMatrix.build(BlockGenerator(self._kernel, self._data, old_points, old_radii, d, new_points, new_radii,
                                              d, row_offset=0, col_offset=first),
                               row_tree=base.tree, col_tree=new_tree, **options)
            no = HMatrix.build(BlockGenerator(self._kernel, self._data, new_points, new_radii, d, old_points, old_radii,
                                              d, row_offset=first, col_offset=0),
                               row_tree=new_tree, col_tree=base.tree, **options)
        except InputError:  # NaN or inf in a far block
            refuse_singular()
        if not (on.is_finite() and no.is_finite()):
            refuse_singular()
        near = self._near_rows_searched(added, nn_added)
        return BorderChunk(k, k + added.size * d, on, no, near)

    def _near_rows_searched(self, added, nn_added):
        """The near field of the border rows of ``added`` (as :meth:`_near_rows`), its
        blocks looked for among the old elements within :data:`NEAR_SEARCH_RADII` element
        radii (the border itself is compressed)."""
        import scipy.spatial

        d, n0, mesh = self.dof, self.n_base, self.mesh
        if self._base_search is None:
            self._base_search = scipy.spatial.cKDTree(mesh.centers[:n0])
        reach = NEAR_SEARCH_RADII * (mesh.radii[added] + float(mesh.radii[:n0].max()))
        candidates = self._base_search.query_ball_point(mesh.centers[added], reach, return_sorted=True)
        m = added.size
        old_norms = np.linalg.norm(self._base_diagonal_blocks(), axis=(1, 2))
        index = np.arange(m)
        new_norms = np.linalg.norm(nn_added.reshape(m, d, m, d)[index, :, index, :], axis=(1, 2))
        columns, values, counts = [], [], np.zeros(m, dtype=np.int64)
        for a in range(m):
            cols = np.asarray(candidates[a], dtype=np.int64)
            if cols.size == 0:
                continue
            blocks = self._block(self._data, added[a:a + 1], cols).reshape(d, cols.size, d).transpose(1, 0, 2)
            norms = np.sqrt(np.einsum("jpq,jpq->j", blocks, blocks))
            keep = norms >= NEAR_THRESHOLD * np.sqrt(new_norms[a] * old_norms[cols])
            columns.append(cols[keep])
            values.append(blocks[keep])
            counts[a] = int(np.count_nonzero(keep))
        indptr = np.concatenate([[0], np.cumsum(counts)])
        cols = np.concatenate(columns) if columns else np.zeros(0, dtype=np.int64)
        blocks = np.concatenate(values) if values else np.zeros((0, d, d))
        return sp.bsr_matrix((blocks, cols, indptr), shape=(m * d, n0 * d), blocksize=(d, d)).tocsr()

    @property
    def on(self):
        """``A_on`` (old rows, new columns) as one array (assembled from the chunks;
        compressed chunks as their H-matrices' dense arrays)."""
        return np.concatenate([chunk.dense_on() for chunk in self.chunks], axis=1)

    @property
    def no(self):
        """``A_no`` (new rows, old columns) as one array (assembled from the chunks)."""
        return np.concatenate([chunk.dense_no() for chunk in self.chunks], axis=0)

    def _near_rows(self, no, nn):
        """The near field of the border rows ``no`` (new elements x old elements; ``nn``: the
        new elements' own block) as a sparse matrix: the element blocks that
        :data:`hmatddm.hmatrix.preconditioners.DEFAULT_ILU`'s threshold keeps in the base's
        block ILU, ``||A_ij||_F >= threshold sqrt(||A_ii||_F ||A_jj||_F)``."""
        d, n0 = self.dof, self.n_base
        m = no.shape[0] // d
        old_norms = np.linalg.norm(self._base_diagonal_blocks(), axis=(1, 2))
        index = np.arange(m)
        new_norms = np.linalg.norm(nn.reshape(m, d, m, d)[index, :, index, :], axis=(1, 2))
        blocks = no.reshape(m, d, n0, d)
        norms = np.sqrt(np.einsum("ipjq,ipjq->ij", blocks, blocks))
        keep = norms >= NEAR_THRESHOLD * np.sqrt(new_norms[:, None] * old_norms[None, :])
        rows, cols = np.nonzero(keep)
        indptr = np.concatenate([[0], np.cumsum(np.count_nonzero(keep, axis=1))])
        return sp.bsr_matrix((blocks[rows, :, cols, :], cols, indptr), shape=no.shape, blocksize=(d, d)).tocsr()

    def _block(self, data, rows, cols):
        out = np.empty((len(rows) * self.dof, len(cols) * self.dof))
        self._kernel(data, rows, cols, out)
        return out

    @property
    def n_new(self):
        return self.mesh.n_elements - self.n_base

    def _matvec(self, x):
        x = np.asarray(x, dtype=np.float64).ravel()
        k = self.n_base * self.dof
        x_old, x_new = x[:k], x[k:]
        out = np.empty(self.shape[0])
        top, bottom = out[:k], out[k:]
        top[:] = self._base_product(x_old)
        compressed = [chunk for chunk in self.chunks if chunk.compressed]
        for chunk in self.chunks:
            if not chunk.compressed:
                chunk.add_column_product(x_new[chunk.start:chunk.stop], top)
        if compressed:  # the old unknowns in the base tree's order, summed there, scattered once
            order = compressed[0].on_t.row_order
            top_in_order = np.zeros(k)
            for chunk in compressed:
                top_in_order += chunk.on_t.matvec_in_tree_order(x_new[chunk.start:chunk.stop][chunk.on_t.col_order])
            top[order] += top_in_order
        self._border_rows(x_old, bottom)
        bottom += self.nn @ x_new
        return out

    def _border_rows(self, x_old, out):
        """``out = A_no x_old``, chunk by chunk (the compressed ones from one permuted
        copy of ``x_old``)."""
        x_in_order = None
        for chunk in self.chunks:
            if chunk.compressed:
                if x_in_order is None:
                    x_in_order = x_old[chunk.no.col_order]
                out[chunk.start:chunk.stop][chunk.no.row_order] = chunk.no.matvec_in_tree_order(x_in_order)
            else:
                chunk.row_product(x_old, out[chunk.start:chunk.stop])
        return out

    #: The block-triangular inverse ignores ``A_on``: never exact, a solve iterates.
    inverse_is_exact = False

    def approximate_inverse(self, r):
        """Block lower-triangular solve: the base's approximate inverse (LU or
        preconditioner), then LU of ``A_nn``."""
        k = self.n_base * self.dof
        r = np.asarray(r, dtype=np.float64).ravel()
        x = np.empty(self.shape[0])
        x[:k] = self.base.approximate_inverse(r[:k])
        near = np.empty(self.shape[0] - k)
        for chunk in self.chunks:
            near[chunk.start:chunk.stop] = chunk.near @ x[:k]
        x[k:] = self._nn_levels.solve(r[k:] - near)
        return x

    def modified_inverse(self, rows):
        """Approximate inverse (a callable) of ``S A + D`` for row operators ``rows``: the
        block-triangular solve with the base's modified inverse and modified blocks (the
        border rows' near field, as :meth:`approximate_inverse` takes it: a dense ``A_no``
        of a compressed border would cost its whole size at every new set of rows)."""
        n0 = self.n_base
        base_inverse = self.base.modified_inverse(rows.subset(0, n0))
        no_rows = rows.modify_rows(sp.vstack([chunk.near for chunk in self.chunks], format="csr"), n0)
        nn_lu = scipy.linalg.lu_factor(rows.subset(n0, rows.n).modify_dense(self.nn), check_finite=False)
        return lambda r: self._block_triangular(r, base_inverse, no_rows, nn_lu)

    def _block_triangular(self, r, base_inverse, no, nn_lu):
        k = self.n_base * self.dof
        r = np.asarray(r, dtype=np.float64).ravel()
        x_old = base_inverse(r[:k])
        x_new = scipy.linalg.lu_solve(nn_lu, r[k:] - no @ x_old, check_finite=False)
        return np.concatenate([x_old, x_new])

    def preconditioner(self):
        return LinearOperator(self.shape, matvec=self.approximate_inverse, dtype=np.float64)

    def solve(self, rhs, x0=None, rtol=1e-9, restart=100, maxiter=20):
        """``(x, info)``: GMRES preconditioned by :meth:`approximate_inverse`
        (:func:`hmatddm.elasticity.inverse.solve_with_inverse`)."""
        return solve_with_inverse(self, rhs, self.approximate_inverse, False, x0=x0, rtol=rtol, restart=restart,
                                  maxiter=maxiter)

    def element_diagonal_blocks(self):
        """(N, d, d): the base operator's self blocks, then those of ``A_nn``."""
        d, m = self.dof, self.n_new
        index = np.arange(m)
        new = self.nn.reshape(m, d, m, d)[index, :, index, :]
        return np.concatenate([self._base_diagonal_blocks(), new])

    def _base_diagonal_blocks(self):
        """The base's element self blocks, computed once for the operators of one base (a
        Python loop over the H-matrix's diagonal leaves; every growth pass asks for them)."""
        if self._base_blocks is None:
            self._base_blocks = self.base.element_diagonal_blocks()
        return self._base_blocks


def compresses_borders(base):
    """Whether the border chunks of operators grown from ``base`` may be compressed: an
    H-matrix base of at least :data:`COMPRESS_MIN_BASE` elements."""
    return getattr(base, "hmatrix", None) is not None and base.mesh.n_elements >= COMPRESS_MIN_BASE


def _flat_arrays(data):
    """The arrays of kernel data (a tuple or named tuple, possibly nested; scalars as
    0-d arrays), in order."""
    if isinstance(data, tuple):
        return [a for item in data for a in _flat_arrays(item)]
    return [np.asarray(data)]


class BorderChunk(NamedTuple):
    """The border of the new unknowns ``start:stop`` (counted from the first new one):
    ``on_t`` = ``A_on[:, start:stop]`` transposed (C order), ``no`` = ``A_no[start:stop]``;
    in a compressed chunk, ``on_t`` is the rectangular H-matrix of ``A_on[:, start:stop]``
    (not transposed) and ``no`` that of ``A_no[start:stop]``."""

    start: int
    stop: int
    on_t: object
    no: object
    near: object  # the near field of ``no`` (scipy CSR), which the preconditioner uses

    @property
    def compressed(self):
        return not isinstance(self.no, np.ndarray)

    @property
    def nbytes(self):
        """Bytes the border blocks hold (an H-matrix's stored factors and blocks)."""
        if self.compressed:
            return int(self.on_t.stats["memory_bytes"] + self.no.stats["memory_bytes"])
        return self.on_t.nbytes + self.no.nbytes

    def add_column_product(self, x, out):
        """``out += A_on[:, start:stop] x``."""
        if self.compressed:
            out += self.on_t.matvec(x)
        else:
            out += x @ self.on_t

    def row_product(self, x_old, out):
        """``out[:] = A_no[start:stop] x_old``."""
        if self.compressed:
            out[:] = self.no.matvec(x_old)
        else:
            np.dot(self.no, x_old, out=out)

    def dense_on(self):
        return self.on_t.to_dense() if self.compressed else self.on_t.T

    def dense_no(self):
        return self.no.to_dense() if self.compressed else self.no


class _LastProduct:
    """``matvec(x)``, kept for the last ``x`` (shared by the operators of one base)."""

    def __init__(self, matvec):
        self.matvec = matvec
        self.x, self.product = None, None

    def __call__(self, x):
        if self.x is not None and self.x.shape == x.shape and np.array_equal(self.x, x):
            return self.product
        product = self.matvec(x)
        self.x, self.product = x.copy(), product
        return product
