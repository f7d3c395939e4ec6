"""The HMatrix: a compressed matrix of element blocks, usable as a LinearOperator.

Square operators (d x d blocks, one cluster tree) and rectangular matrices (a row tree
and a column tree of different points, d_r x d_c blocks: e.g. the stress at target
points induced by the DDs of elements, :mod:`hmatddm.elasticity.fields`) are built and applied by
the same code; the near-field extraction (preconditioners) exists for square ones.

Length (over ~400 lines): the one public compressed-matrix class (build for square and
rectangular generators, products, near field, preconditioner hooks, statistics); its
numerical pieces live in ``cluster_tree``, ``block_tree``, ``aca``, ``storage``,
``assembly``, ``matvec`` and ``near_field``.
"""

import math
import time

import numba
import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError

from .assembly import assemble
from .block_tree import block_tree
from .cluster_tree import ClusterTree, cluster_tree
from .generator import BlockGenerator
from .near_field import _bsr_pass, _csr_pass, _element_norms, _sort_block_rows
from .storage import KIND_DENSE, KIND_LOWRANK


# Low-rank factors are stored in single precision when eps >= this (the float32
# rounding, ~1e-7 relative, is then at most 1% of eps), with their trailing columns in
# 16-bit fixed point (factor_precision.py); double precision below.
SINGLE_PRECISION_EPS = 1e-5
#: The ``factor_dtype`` of float32 leading columns and int16 fixed-point trailing columns.
ADAPTIVE = "adaptive"


def _factor_format(factor_dtype, eps):
    """(dtype of the float columns, fixed point or not) for ``factor_dtype``."""
    if factor_dtype is None:
        factor_dtype = ADAPTIVE if eps >= SINGLE_PRECISION_EPS else np.float64
    if isinstance(factor_dtype, str) and factor_dtype == ADAPTIVE:
        return np.dtype(np.float32), True
    return _float_dtype(factor_dtype, "factor_dtype", f"None, {ADAPTIVE!r}, float32 or float64"), False


def _float_dtype(value, name, allowed="float32 or float64"):
    try:
        dtype = np.dtype(value)
    except TypeError:
        dtype = None
    # (``None == np.dtype(np.float64)`` is True: test for None first)
    if dtype is None or dtype not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise InputError(f"{name} must be {allowed}, got {value!r}")
    return dtype


def _check_parameters(eps, eta, leaf_size):
    if isinstance(eps, bool) or not isinstance(eps, (int, float, np.floating, np.integer)) or not (0.0 < eps < 1.0):
        raise InputError(f"eps must be in (0, 1), got {eps!r}")
    if isinstance(eta, bool) or not isinstance(eta, (int, float, np.floating, np.integer)) or not (
        math.isfinite(eta) and eta > 0.0
    ):
        raise InputError(f"eta must be a finite number > 0, got {eta!r}")
    if isinstance(leaf_size, bool) or not isinstance(leaf_size, (int, np.integer)) or leaf_size < 1:
        raise InputError(f"leaf_size must be an integer >= 1, got {leaf_size!r}")


class HMatrix(LinearOperator):
    """Hierarchical matrix approximation of a BlockGenerator's matrix.

    Build with :meth:`HMatrix.build`. Vectors are in the ORIGINAL element-major
    ordering (unknown ``d*i + p`` = component p of element i); the permutation to the
    cluster-tree ordering is applied inside :meth:`matvec` / :meth:`matmat`.
    ``tree`` is the row tree, ``col_tree`` the column tree (the same object for a
    square operator).
    """

    def __init__(self, generator, tree, blocks, storage, eps, eta, leaf_size, build_seconds, col_tree=None):
        super().__init__(dtype=np.dtype(np.float64), shape=generator.shape)
        self.generator = generator
        self.tree = tree
        self.col_tree = tree if col_tree is None else col_tree
        self.blocks = blocks
        self.storage = storage
        self.eps = float(eps)
        self.eta = float(eta)
        self.leaf_size = int(leaf_size)
        self.dof = generator.dof
        self.col_dof = generator.column_dof
        self.n_elements = generator.n_elements
        self.n_col_elements = generator.n_col_elements
        self.build_seconds = float(build_seconds)
        # unknown permutation: permuted unknown d*k + p <-> original d*permutation[k] + p
        self._unknown_permutation = _unknowns(tree.permutation, self.dof)
        self._col_permutation = _unknowns(self.col_tree.permutation, self.col_dof)

    @property
    def rectangular(self):
        """True for a matrix with its own column elements (see :class:`BlockGenerator`)."""
        return self.generator.rectangular

    # ------------------------------------------------------------------ construction
    @classmethod
    def build(cls, generator, eps=1e-4, eta=3.0, leaf_size=64, factor_dtype=None, check_finite=False, groups=None,
              col_leaf_size=None, near_dtype=np.float64, boxes="axis", row_tree=None, col_tree=None):
        """Cluster, partition and compress the matrix of ``generator``.

        Parameters
        ----------
        generator : BlockGenerator
        eps : float in (0, 1)
            Relative Frobenius accuracy asked of every admissible block (ACA
            stopping tolerance and recompression truncation).
        eta : float > 0
            Admissibility ``min(diam) <= eta * dist`` of bounding boxes.
        leaf_size : int >= 1
            Largest number of elements in a leaf cluster.
        factor_dtype : None, "adaptive", numpy.float32 or numpy.float64
            Storage of the low-rank factors. "adaptive": the leading columns of each
            block in float32, the trailing ones (small singular values) in 16-bit
            fixed point, within 0.25 eps of the block (:mod:`.factor_precision`;
            0.57x the float32 memory on the planar crack at eps 1e-4). None:
            "adaptive" when eps >= 1e-5, float64 otherwise.
        near_dtype : numpy.float64 (default) or numpy.float32
            Storage of the dense blocks (the near field: about half of the memory at
            eps 1e-4). float32 halves it; its rounding is amplified by the cancellation
            of the hypersingular near field on smooth fields (N = 10k planar crack at eps
            1e-4: smooth-field error 6e-7 -> 1.1e-6, benchmarks/RESULTS.md), so it is
            an opt-in for large problems at eps >= 1e-4.
        check_finite : bool
            Raise InputError when a stored entry is NaN or inf (reads every stored
            entry once, ~0.3% of the build time). Off by default so that callers can
            give their own, domain-specific message (see :meth:`is_finite`). A NaN met
            by the ACA in a far-field block always raises InputError.
        groups : (N,) int array, optional
            Group of each element (e.g. its fracture): clusters are split between
            whole groups first (see :func:`~hmatddm.hmatrix.cluster_tree.cluster_tree`).
        boxes : "axis" (default) or "oriented"
            Admissibility on axis-aligned bounding boxes, or also on the clusters'
            principal-axis boxes (thin boxes of tilted or vertical fractures at any
            strike; see :mod:`~hmatddm.hmatrix.block_tree`).
        col_leaf_size : int >= 1, optional
            Leaf size of the column tree of a rectangular generator (default
            ``leaf_size``); the row tree is built on ``generator.points``, the column
            tree on ``generator.col_points``.
        row_tree, col_tree : ClusterTree, optional
            Cluster trees already built on ``generator.points`` (and, for a rectangular
            generator, ``generator.col_points``), used instead of new ones: the border
            blocks of a grown mesh reuse the tree of the operator they border
            (:mod:`hmatddm.elasticity.extended`). ``leaf_size`` / ``groups`` then apply
            only to the trees that are built.

        Cost: O(N log N) for the trees, kernel evaluations of the near field plus
        O((m + n) k) per far block, run on numba's thread count.
        """
        if not isinstance(generator, BlockGenerator):
            raise InputError(f"generator must be a BlockGenerator, got {type(generator).__name__}")
        _check_parameters(eps, eta, leaf_size)
        col_leaf_size = leaf_size if col_leaf_size is None else col_leaf_size
        _check_parameters(eps, eta, col_leaf_size)
        dtype, fixed_point = _factor_format(factor_dtype, eps)
        near_dtype = _float_dtype(near_dtype, "near_dtype")
        started = time.perf_counter()
        given_col_tree = col_tree
        tree = (cluster_tree(generator.points, generator.radii, int(leaf_size), groups=groups) if row_tree is None
                else _checked_tree(row_tree, generator.n_elements, "row_tree"))
        col_tree = tree
        if generator.rectangular:
            col_tree = (cluster_tree(generator.col_points, generator.col_radii, int(col_leaf_size))
                        if given_col_tree is None else
                        _checked_tree(given_col_tree, generator.n_col_elements, "col_tree"))
        elif given_col_tree is not None:
            raise InputError("col_tree is for a rectangular generator (col_points); a square one has one tree")
        blocks = block_tree(tree, float(eta), col_tree=col_tree, boxes=boxes)
        try:
            storage = assemble(generator, tree, blocks, float(eps), factor_dtype=dtype, col_tree=col_tree,
                               near_dtype=near_dtype, fixed_point=fixed_point)
        except np.linalg.LinAlgError as error:  # the SVD of a pivot refuses NaN/inf
            raise InputError(f"the kernel returned NaN or inf entries (in a far-field block): {error}") from None
        seconds = time.perf_counter() - started
        hmatrix = cls(generator, tree, blocks, storage, eps, eta, leaf_size, seconds, col_tree=col_tree)
        if check_finite and not hmatrix.is_finite():
            raise InputError("the kernel returned NaN or inf entries; no H-matrix was built")
        return hmatrix

    # ------------------------------------------------------------------ products
    def _matmat(self, X):
        X = np.asarray(X, dtype=np.float64)
        if X.ndim == 1:
            X = X[:, None]
        permuted = np.ascontiguousarray(X[self._col_permutation].T)
        result = self.storage.matmat_permuted(permuted)
        out = np.empty((self.shape[0], X.shape[1]))
        out[self._unknown_permutation] = result.T
        return out

    def _matvec(self, x):
        x = np.asarray(x, dtype=np.float64).reshape(-1)
        result = self.storage.matmat_permuted(x[self._col_permutation].reshape(1, -1))
        out = np.empty(self.shape[0])
        out[self._unknown_permutation] = result[0]
        return out

    # ------------------------------------------------------------------ products in tree order
    @property
    def row_order(self):
        """The row unknowns in the row tree's order: tree-order row ``k`` is row
        ``row_order[k]`` of the matrix."""
        return self._unknown_permutation

    @property
    def col_order(self):
        """The column unknowns in the column tree's order (see :attr:`row_order`)."""
        return self._col_permutation

    def matvec_in_tree_order(self, x):
        """``A x`` with ``x`` and the result in the trees' orders (``x[k]`` is unknown
        ``col_order[k]``; ``result[k]`` is row ``row_order[k]``): several matrices over
        one tree (the border blocks of a grown mesh) permute a vector once, not each."""
        return self.storage.matmat_permuted(np.asarray(x, dtype=np.float64).reshape(1, -1))[0]

    def _adjoint(self):
        raise NotImplementedError("HMatrix does not implement the transpose product")

    # ------------------------------------------------------------------ inspection
    def to_dense(self):
        """Dense array of the approximation (``self.shape``), original ordering."""
        s = self.storage
        d, dc = self.dof, self.col_dof
        dense = np.zeros(self.shape)
        index, col_index = self._unknown_permutation, self._col_permutation
        for b in range(s.dense_offset.size - 1):
            rows = index[d * s.dense_row_start[b]:d * s.dense_row_stop[b]]
            cols = col_index[dc * s.dense_col_start[b]:dc * s.dense_col_stop[b]]
            block = s.dense_values[s.dense_offset[b]:s.dense_offset[b + 1]].reshape(rows.size, cols.size)
            dense[np.ix_(rows, cols)] = block
        for b in range(s.lowrank_rank.size):
            u, v = self._factors(b)
            rows = index[d * s.lowrank_row_start[b]:d * s.lowrank_row_stop[b]]
            cols = col_index[dc * s.lowrank_col_start[b]:dc * s.lowrank_col_stop[b]]
            dense[np.ix_(rows, cols)] = u @ v.T
        return dense

    def _factors(self, b):
        """(U, V) of low-rank block b as float64 (fixed-point columns decoded)."""
        ut, vt = self.storage.factors(b)
        return ut.T, vt.T

    @property
    def stats(self):
        """Dictionary of sizes, ranks and timings (bytes, seconds)."""
        s = self.storage
        memory = s.memory_bytes
        dense_bytes = 8 * self.shape[0] * self.shape[1]
        n_far_dense = int(np.count_nonzero(s.admissible_kind == KIND_DENSE))
        lowrank = s.lowrank_rank
        return {
            "memory_bytes": memory,
            "dense_bytes": dense_bytes,
            "compression": dense_bytes / memory if memory else math.inf,
            "build_seconds": self.build_seconds,
            "far_field_seconds": float(s.far_seconds),
            "near_field_seconds": float(s.near_seconds),
            "n_admissible": int(s.admissible_kind.size),
            "n_lowrank_blocks": int(lowrank.size),
            "n_zero_blocks": int(s.admissible_kind.size - lowrank.size - n_far_dense),
            "n_near_blocks": int(np.count_nonzero(s.dense_is_near)),
            "n_dense_blocks": int(s.dense_is_near.size),
            "max_rank": int(lowrank.max()) if lowrank.size else 0,
            "mean_rank": float(lowrank.mean()) if lowrank.size else 0.0,
            "near_field_bytes": int(s.dense_values.itemsize * (s.dense_offset[-1] - s.dense_offset[n_far_dense])),
            "index_bytes": s.index_bytes,
            "n_clusters": int(self.tree.n_clusters),
            "n_col_clusters": int(self.col_tree.n_clusters),
            "eps": self.eps,
            "eta": self.eta,
            "leaf_size": self.leaf_size,
            "n_elements": int(self.n_elements),
            "n_col_elements": int(self.n_col_elements),
            "dof": int(self.dof),
            "col_dof": int(self.col_dof),
            "factor_dtype": s.factor_format,
            "n_threads": int(numba.get_num_threads()),
        }

    # ------------------------------------------------------------------ checks
    def admissible_block_errors(self, n_samples=1024, seed=0):
        """Relative error of every admissible block on exactly evaluated samples.

        A block with at most ``n_samples`` element pairs is evaluated whole. Otherwise
        random whole row elements (d full rows of the block) and whole column
        elements are evaluated, about ``n_samples`` element pairs in total, at least
        one row and one column element: full rows and columns always contain the
        block's dominant entries, which random entries would mostly miss. The error
        is ``||approx - exact||_F / ||exact||_F`` over the sampled entries (0 when
        both vanish, inf when only the exact samples do). Returns an array aligned
        with ``self.blocks.admissible_rows``. Cost O(n_admissible * n_samples * d^2).
        """
        if isinstance(n_samples, bool) or not isinstance(n_samples, (int, np.integer)) or n_samples < 1:
            raise InputError(f"n_samples must be an integer >= 1, got {n_samples!r}")
        rng = np.random.default_rng(seed)
        s = self.storage
        tree, col_tree = self.tree, self.col_tree
        errors = np.zeros(s.admissible_kind.size)
        for b in range(errors.size):
            rs, re = tree.start[self.blocks.admissible_rows[b]], tree.stop[self.blocks.admissible_rows[b]]
            cs, ce = col_tree.start[self.blocks.admissible_cols[b]], col_tree.stop[self.blocks.admissible_cols[b]]
            me, ne = int(re - rs), int(ce - cs)
            if me * ne <= n_samples:
                samples = [(np.arange(me), np.arange(ne))]
            else:
                n_rows = min(me, max(1, n_samples // (2 * ne)))
                n_cols = min(ne, max(1, n_samples // (2 * me)))
                samples = [(np.sort(rng.choice(me, size=n_rows, replace=False)), np.arange(ne)),
                           (np.arange(me), np.sort(rng.choice(ne, size=n_cols, replace=False)))]
            difference2 = 0.0
            reference2 = 0.0
            for row_pick, col_pick in samples:
                exact = self.generator.fill(tree.permutation[rs + row_pick], col_tree.permutation[cs + col_pick])
                approx = self._admissible_entries(b, me, ne, row_pick, col_pick)
                difference2 += float(np.sum((approx - exact) ** 2))
                reference2 += float(np.sum(exact**2))
            if reference2 > 0:
                errors[b] = math.sqrt(difference2 / reference2)
            else:
                errors[b] = 0.0 if difference2 == 0 else math.inf
        return errors

    def _admissible_entries(self, b, me, ne, row_pick, col_pick):
        """Stored approximation of admissible block b at local row/column elements."""
        s = self.storage
        d, dc = self.dof, self.col_dof
        row_unknowns = (d * row_pick[:, None] + np.arange(d)).ravel()
        col_unknowns = (dc * col_pick[:, None] + np.arange(dc)).ravel()
        kind = s.admissible_kind[b]
        index = s.admissible_index[b]
        if kind == KIND_LOWRANK:
            u, v = self._factors(index)
            return u[row_unknowns] @ v[col_unknowns].T
        if kind == KIND_DENSE:
            block = s.dense_values[s.dense_offset[index]:s.dense_offset[index + 1]].reshape(d * me, dc * ne)
            return block[np.ix_(row_unknowns, col_unknowns)]
        return np.zeros((row_unknowns.size, col_unknowns.size))

    def check_against_dense(self, n_samples=1024, seed=0):
        """Worst sampled relative error over the admissible blocks (see admissible_block_errors)."""
        errors = self.admissible_block_errors(n_samples=n_samples, seed=seed)
        return float(errors.max()) if errors.size else 0.0

    # ------------------------------------------------------------------ near field
    def _near_field_arguments(self, part, threshold):
        self._require_square("the near field")
        if part not in ("near", "leaf_diagonal", "element_diagonal"):
            raise InputError(f"part must be 'near', 'leaf_diagonal' or 'element_diagonal', got {part!r}")
        if isinstance(threshold, bool) or not (
            isinstance(threshold, (int, float, np.floating, np.integer)) and threshold >= 0 and math.isfinite(threshold)
        ):
            raise InputError(f"threshold must be a finite number >= 0, got {threshold!r}")
        s = self.storage
        selected = np.flatnonzero(s.dense_is_near)
        diagonal = s.dense_row_start[selected] == s.dense_col_start[selected]
        if part != "near":
            selected = selected[diagonal]
        element_norm = _element_norms(self.dof, s.dense_row_start, s.dense_row_stop, s.dense_offset, s.dense_values,
                                      np.flatnonzero(s.dense_is_near & (s.dense_row_start == s.dense_col_start)),
                                      self.n_elements)
        return (self.dof, s.dense_row_start, s.dense_row_stop, s.dense_col_start, s.dense_col_stop, s.dense_offset,
                s.dense_values, selected.astype(np.int64), self.tree.permutation.astype(np.int64), element_norm,
                float(threshold), part == "element_diagonal")

    def near_field_csr(self, part="near", threshold=0.0):
        """Sparse CSR matrix (original ordering) of part of the stored exact blocks.

        part: ``"near"`` (all near-field leaf blocks; they include the diagonal
        blocks), ``"leaf_diagonal"`` (the leaf x leaf diagonal blocks only) or
        ``"element_diagonal"`` (the d x d block of each element). ``threshold`` >= 0
        drops whole d x d element blocks (see :meth:`near_field_bsr`: block (i, j) is
        kept when ``||A_ij||_F >= threshold * sqrt(||A_ii||_F ||A_jj||_F)``, and
        always for i == j), so that which couplings are kept does not depend on the
        frame of the unknowns; exact zeros are not stored. Cost O(selected entries).
        """
        arguments = self._near_field_arguments(part, threshold)
        n = self.shape[0]
        indptr = np.zeros(n + 1, dtype=np.int64)
        _csr_pass(*arguments, indptr, indptr[:0], np.zeros(0, dtype=np.int32), np.zeros(0), False)
        np.cumsum(indptr, out=indptr)
        index_dtype = np.int32 if max(indptr[-1], n) < np.iinfo(np.int32).max else np.int64
        indices = np.empty(indptr[-1], dtype=index_dtype)
        data = np.empty(indptr[-1])
        _csr_pass(*arguments, indptr, indptr[:-1].copy(), indices, data, True)
        return sp.csr_matrix((data, indices, indptr.astype(index_dtype)), shape=self.shape)

    def near_field_bsr(self, part="near", threshold=0.0):
        """Block-sparse (BSR, blocks d x d, original element ordering, sorted column
        indices) matrix of part of the stored exact blocks.

        ``part`` as in :meth:`near_field_csr`. ``threshold`` >= 0 keeps element block
        (i, j) when ``||A_ij||_F >= threshold * sqrt(||A_ii||_F ||A_jj||_F)`` (Frobenius
        norms, A_ii the element's own diagonal block) and always keeps i == j; blocks
        that are exactly zero are not stored. Frobenius norms do not change under a
        rotation of the unknowns of each element, so the kept pattern is the same in
        every frame (the entry-wise rule it replaces kept a tilted element's couplings
        differently from an aligned one's). Cost O(selected entries).
        """
        arguments = self._near_field_arguments(part, threshold)
        d = self.dof
        counts = np.zeros(self.n_elements + 1, dtype=np.int64)
        _bsr_pass(*arguments, counts, counts[:0], np.zeros(0, dtype=np.int64), np.zeros((0, d, d)), False)
        indptr = np.cumsum(counts)
        indices = np.empty(indptr[-1], dtype=np.int64)
        data = np.empty((indptr[-1], d, d))
        _bsr_pass(*arguments, indptr, indptr[:-1].copy(), indices, data, True)
        _sort_block_rows(indptr, indices, data)
        index_dtype = np.int32 if max(indptr[-1], self.n_elements) < np.iinfo(np.int32).max else np.int64
        matrix = sp.bsr_matrix((data, indices.astype(index_dtype), indptr.astype(index_dtype)), shape=self.shape,
                               blocksize=(d, d))
        matrix.has_sorted_indices = True
        return matrix

    def element_diagonal_blocks(self):
        """(N, d, d) array: the exact d x d diagonal block of each element (original order)."""
        self._require_square("element_diagonal_blocks")
        s = self.storage
        d = self.dof
        blocks = np.empty((self.n_elements, d, d))
        diagonal = np.flatnonzero(s.dense_is_near & (s.dense_row_start == s.dense_col_start))
        for b in diagonal:
            me = s.dense_row_stop[b] - s.dense_row_start[b]
            dense = s.dense_values[s.dense_offset[b]:s.dense_offset[b + 1]].reshape(me, d, me, d)
            local = np.arange(me)
            blocks[self.tree.permutation[s.dense_row_start[b] + local]] = dense[local, :, local, :]
        return blocks

    def _require_square(self, what):
        if self.rectangular:
            raise InputError(f"{what} exists for square operators only; this H-matrix is rectangular "
                             f"({self.shape[0]}x{self.shape[1]})")

    def is_finite(self):
        """True when every stored entry (dense blocks, U, V) is finite. O(memory)."""
        s = self.storage
        return bool(np.isfinite(s.dense_values).all() and np.isfinite(s.u_values).all()
                    and np.isfinite(s.v_values).all() and np.isfinite(s.u_scale).all()
                    and np.isfinite(s.v_scale).all())

    def __repr__(self):
        st = self.stats
        return (
            f"<HMatrix {self.shape[0]}x{self.shape[1]} (N={self.n_elements}, d={self.dof}"
            + (f"; columns N={self.n_col_elements}, d={self.col_dof}" if self.rectangular else "")
            + f") eps={self.eps:g} "
            f"eta={self.eta:g} leaf_size={self.leaf_size} compression={st['compression']:.2f} "
            f"max_rank={st['max_rank']}>"
        )


def _checked_tree(tree, n_elements, name):
    """``tree`` when it is a ClusterTree over ``n_elements`` elements, else InputError."""
    if not isinstance(tree, ClusterTree) or tree.n_elements != n_elements:
        raise InputError(f"{name} must be a ClusterTree over the generator's {n_elements} elements, got "
                         f"{type(tree).__name__}" + (f" over {tree.n_elements}" if isinstance(tree, ClusterTree) else ""))
    return tree


def _unknowns(permutation, dof):
    """Unknown permutation of an element permutation: ``dof*permutation[k] + p``."""
    return (dof * permutation[:, None] + np.arange(dof)[None, :]).ravel()

