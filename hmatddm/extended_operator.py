"""An elasticity operator grown by a few elements without recompressing it.

When a fracture grows, the mesh gains a ring of elements at its front. Rebuilding the
H-matrix for every growth pass would dominate the run time, so the new elements are
added as exact border blocks around the existing operator::

    A = [ A_oo   A_on ]    A_oo: the H-matrix (or dense matrix) already built
        [ A_no   A_nn ]    A_on, A_no, A_nn: exact kernel blocks (dense)

Matvec cost grows by ``2 N m d^2`` for ``m`` new elements, so the simulation rebuilds
the base operator once the border is large (see ``Simulation``). The preconditioner
is block lower-triangular: the base near-field preconditioner for the old unknowns,
then an exact LU of ``A_nn`` for the new ones.
"""
import numpy as np
import scipy.linalg
from scipy.sparse.linalg import LinearOperator

from .errors import InputError
from .kernels.drivers import traction_block
from .operator_inverse import solve_with_inverse
from .operators import ElasticityOperator, influence_data, refuse_singular


class ExtendedElasticityOperator(LinearOperator):
    """``base`` (an ElasticityOperator of the first ``n0`` elements of ``mesh``) plus
    exact border blocks for elements ``n0..N-1``.

    ``previous``: the operator of an earlier growth pass over the same ``base`` (for
    example the last one returned). The border entries of the elements it shares with
    ``mesh`` (the longest common run of unchanged elements after the base's) are copied
    from it; only the rows and columns of the elements added since are evaluated by the
    kernel, so a growth pass costs O(n0 m_added) kernel pairs instead of O(n0 m). Any
    other ``previous`` (another base, changed elements) is ignored.
    """

    def __init__(self, base, mesh, previous=None):
        if not isinstance(base, ElasticityOperator):
            raise InputError(f"base must be an ElasticityOperator, got {type(base).__name__}")
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
        self.n_reused = self._shared_new_elements(previous)
        self.on, self.no, self.nn = self._border_blocks(previous, self.n_reused)
        self._nn_lu = None
        self.border_bytes = self.on.nbytes + self.no.nbytes + self.nn.nbytes

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
        """(A_on, A_no, A_nn): the first ``reused`` new elements' entries copied from
        ``previous``, the rest evaluated."""
        d, n0, n = self.dof, self.n_base, self.mesh.n_elements
        old = np.arange(n0, dtype=np.int64)
        new = np.arange(n0, n, dtype=np.int64)
        added = new[reused:]
        k = reused * d
        on = np.empty((n0 * d, new.size * d))
        no = np.empty((new.size * d, n0 * d))
        nn = np.empty((new.size * d, new.size * d))
        if reused:
            on[:, :k] = previous.on[:, :k]
            no[:k] = previous.no[:k]
            nn[:k, :k] = previous.nn[:k, :k]
            nn[:k, k:] = self._block(self._data, new[:reused], added)
            nn[k:, :k] = self._block(self._data, added, new[:reused])
        if added.size:
            on[:, k:] = self._block(self._data, old, added)
            no[k:] = self._block(self._data, added, old)
            nn[k:, k:] = self._block(self._data, added, added)
        if not (np.all(np.isfinite(on[:, k:])) and np.all(np.isfinite(no[k:])) and np.all(np.isfinite(nn[:, k:]))
                and np.all(np.isfinite(nn[k:]))):
            refuse_singular()
        return on, no, nn

    def _block(self, data, rows, cols):
        out = np.empty((len(rows) * self.dof, len(cols) * self.dof))
        traction_block(data, rows, cols, out)
        return out

    @property
    def n_new(self):
        return self.mesh.n_elements - self.n_base

    def _matvec(self, x):
        x = np.asarray(x, dtype=np.float64).ravel()
        k = self.n_base * self.dof
        x_old, x_new = x[:k], x[k:]
        return np.concatenate([self.base.matvec(x_old) + self.on @ x_new, self.no @ x_old + self.nn @ x_new])

    def _nn_factor(self):
        if self._nn_lu is None:
            self._nn_lu = scipy.linalg.lu_factor(self.nn, check_finite=False)
        return self._nn_lu

    #: The block-triangular inverse ignores ``A_on``: never exact, a solve iterates.
    inverse_is_exact = False

    def approximate_inverse(self, r):
        """Block lower-triangular solve: the base's approximate inverse (LU or
        preconditioner), then LU of ``A_nn``."""
        return self._block_triangular(r, self.base.approximate_inverse, self.no, self._nn_factor())

    def modified_inverse(self, rows):
        """Approximate inverse (a callable) of ``S A + D`` for row operators ``rows``: the
        block-triangular solve with the base's modified inverse and modified blocks."""
        n0 = self.n_base
        base_inverse = self.base.modified_inverse(rows.subset(0, n0))
        no_rows = rows.modify_rows(self.no, n0)
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
        (:func:`hmatddm.operator_inverse.solve_with_inverse`)."""
        return solve_with_inverse(self, rhs, self.approximate_inverse, False, x0=x0, rtol=rtol, restart=restart,
                                  maxiter=maxiter)

    def element_diagonal_blocks(self):
        """(N, d, d): the base operator's self blocks, then those of ``A_nn``."""
        d, m = self.dof, self.n_new
        index = np.arange(m)
        new = self.nn.reshape(m, d, m, d)[index, :, index, :]
        return np.concatenate([self.base.element_diagonal_blocks(), new])


def _flat_arrays(data):
    """The arrays of kernel data (a tuple or named tuple, possibly nested; scalars as
    0-d arrays), in order."""
    if isinstance(data, tuple):
        return [a for item in data for a in _flat_arrays(item)]
    return [np.asarray(data)]
