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
from .operator_inverse import solve_with_inverse
from .operators import ElasticityOperator, influence_data, refuse_singular


class ExtendedElasticityOperator(LinearOperator):
    """``base`` (an ElasticityOperator of the first ``n0`` elements of ``mesh``) plus
    exact border blocks for elements ``n0..N-1``."""

    def __init__(self, base, mesh):
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
        kernels, data = influence_data(mesh, base.material, base.singular_correction, base.alpha,
                                       n_images=base.stats.get("n_images"))  # layered: the base's images
        old = np.arange(n0, dtype=np.int64)
        new = np.arange(n0, n, dtype=np.int64)
        self.on = self._block(kernels, data, old, new)
        self.no = self._block(kernels, data, new, old)
        self.nn = self._block(kernels, data, new, new)
        if not (np.all(np.isfinite(self.on)) and np.all(np.isfinite(self.no)) and np.all(np.isfinite(self.nn))):
            refuse_singular()
        self._nn_lu = None
        self.border_bytes = self.on.nbytes + self.no.nbytes + self.nn.nbytes

    def _block(self, kernels, data, rows, cols):
        out = np.empty((len(rows) * self.dof, len(cols) * self.dof))
        kernels.traction_block(data, rows, cols, out)
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
