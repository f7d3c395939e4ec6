"""The compressed elasticity operator of a planar crack: opening and in-plane shear apart.

On coplanar elements in a homogeneous whole space the normal traction depends only on
the openings and the shear tractions only on the shear DDs (the coupling terms of ref.
Eqs 2.57-2.59 carry the distance from the plane, which is zero; the kernel returns them
as exact zeros). In each element's own frame (``frames[e]`` = ``(e1, e2, n)``, the
normals equal up to sign) the influence matrix is two matrices::

    A = P_n^T A_nn P_n + P_s^T A_ss P_s     A_nn: N x N (openings),
                                            A_ss: 2N x 2N (shear DDs, e1 and e2)

with ``P_n`` and ``P_s`` the projections of the global, element-major DDs on each
element's normal and in-plane axes (docs/conventions.md §2). Compressed apart, the two
hold ~5/9 of the entries of the 3 x 3 tensor blocks, and a crack loaded in opening
only (a hydraulic fracture under a far-field stress with a principal axis normal to its
plane, the radial and planar benchmarks) never needs ``A_ss``: it is built on the first
product whose shear part is not zero. Products, the near-field preconditioner and the
build then cost what a scalar kernel costs (N = 3969, eps 1e-4, one thread, against the
3 x 3 operator: 8.9x less memory, 6.9x faster products, 9.8x faster ILU solves, 2.9x
faster build; benchmarks/RESULTS.md, issue 17).

A shear part counts as zero when it is below :data:`SHEAR_ROUND_OFF` of the largest
component: projecting an opening ``w n`` stored in global components on the in-plane
axes leaves round-off of that size, which is not a shear DD. Contact (closed elements'
modified rows) works on the element blocks of the whole tensor; :meth:`modified_inverse`
builds the 3 x 3 operator for it on first use.
"""
import numpy as np
from numba import njit

from .errors import InputError
from .kernels.drivers import traction_block
from .material import Elastic
from .mesh import Mesh3D
from .operators import ElasticityOperator

#: Relative flatness asked of a planar mesh: every centre within this fraction of the
#: mesh's extent of the plane of the first element, every normal parallel to its normal
#: to this (1 - |cos|) -- round-off of meshes built in a rotated frame, not curvature.
PLANAR_TOLERANCE = 1e-12

#: A product's shear part below this fraction of the largest component of its vector is
#: round-off of the projection (see the module docstring) and is not multiplied.
SHEAR_ROUND_OFF = 1e-13


def is_planar(mesh, tolerance=PLANAR_TOLERANCE):
    """True when ``mesh`` (3D) lies in one plane: centres and normals (to ``tolerance``)."""
    if not isinstance(mesh, Mesh3D) or mesh.n_elements == 0:
        return False
    normal = mesh.normals[0]
    extent = max(float(np.ptp(mesh.centers, axis=0).max()), float(mesh.radii.max()))
    off_plane = np.abs((mesh.centers - mesh.centers[0]) @ normal)
    parallel = np.abs(mesh.normals @ normal)
    return bool(np.all(off_plane <= tolerance * extent) and np.all(parallel >= 1.0 - tolerance))


@njit(cache=True, nogil=True)
def normal_traction_block(data, rows, cols, out):
    """Block generator of ``A_nn``: ``out[a, b] = n_rows[a] . A(rows[a], cols[b]) n_cols[b]``
    (the normal traction at receiver ``rows[a]`` of a unit opening of ``cols[b]``)."""
    full = np.empty((3 * rows.size, 3 * cols.size))
    traction_block(data, rows, cols, full)
    for a in range(rows.size):
        receiver = data.frames[rows[a], 2]
        for b in range(cols.size):
            source = data.frames[cols[b], 2]
            total = 0.0
            for p in range(3):
                for q in range(3):
                    total += receiver[p] * full[3 * a + p, 3 * b + q] * source[q]
            out[a, b] = total


@njit(cache=True, nogil=True)
def shear_traction_block(data, rows, cols, out):
    """Block generator of ``A_ss``: ``out[2a + k, 2b + l] = e_k(rows[a]) . A(rows[a],
    cols[b]) e_l(cols[b])`` with ``e_0, e_1`` the elements' in-plane axes."""
    full = np.empty((3 * rows.size, 3 * cols.size))
    traction_block(data, rows, cols, full)
    for a in range(rows.size):
        for b in range(cols.size):
            for k in range(2):
                receiver = data.frames[rows[a], k]
                for m in range(2):
                    source = data.frames[cols[b], m]
                    total = 0.0
                    for p in range(3):
                        for q in range(3):
                            total += receiver[p] * full[3 * a + p, 3 * b + q] * source[q]
                    out[2 * a + k, 2 * b + m] = total


class PlanarElasticityOperator(ElasticityOperator):
    """:class:`~hmatddm.ElasticityOperator` (``hmatrix`` backend) of a planar 3D mesh in a
    homogeneous medium, compressed as an opening operator and a shear operator (the
    shear one on first use; module docstring). Same parameters and methods;
    :attr:`hmatrix` is the opening operator's :class:`~hmatddm.hmatrix.HMatrix` (N x N) and
    :attr:`shear_hmatrix` the shear one (2N x 2N, None until needed)."""

    def __init__(self, mesh, material, backend="hmatrix", eps=None, eta=None, leaf_size=None,
                 singular_correction="none", alpha=None):
        if backend != "hmatrix":
            raise InputError(f"backend must be 'hmatrix' for a PlanarElasticityOperator, got {backend!r}")
        if not isinstance(material, Elastic):
            raise InputError(f"material must be an hmatddm.Elastic (a homogeneous medium), got {type(material).__name__}")
        if not is_planar(mesh):
            raise InputError("mesh must be a Mesh3D whose elements lie in one plane (is_planar)")
        options = {name: value for name, value in (("eps", eps), ("eta", eta), ("leaf_size", leaf_size))
                   if value is not None}
        self._shear = None
        self._shear_preconditioner = None
        self._full = None
        super().__init__(mesh, material, backend="hmatrix", singular_correction=singular_correction, alpha=alpha,
                         **options)

    def _build_compressed(self, eps, eta, leaf_size):
        self._compression = dict(eps=eps, eta=eta, leaf_size=leaf_size)
        self._hmatrix = self._build_part(normal_traction_block, 1)
        self._normals = np.ascontiguousarray(self.data.frames[:, 2])
        self._axes = np.ascontiguousarray(self.data.frames[:, :2])

    def _build_part(self, kernel, dof):
        from .hmatrix import BlockGenerator, HMatrix

        generator = BlockGenerator(kernel=kernel, data=self.data, points=self.mesh.centers, radii=self.mesh.radii,
                                   dof=dof)
        hmatrix = HMatrix.build(generator, groups=self.mesh.fracture_id, **self._compression)
        if not hmatrix.is_finite():
            self._refuse_singular()
        return hmatrix

    @property
    def shear_hmatrix(self):
        """The shear operator ``A_ss`` (2N x 2N), None until a product needed it."""
        return self._shear

    def _shear_operator(self):
        if self._shear is None:
            self._shear = self._build_part(shear_traction_block, 2)
        return self._shear

    @property
    def stats(self):
        """The build statistics of the parts built so far, as one operator's: memory, build
        time and block counts summed, ``max_rank`` the larger; ``dense_bytes`` and
        ``compression`` against the whole 3N x 3N matrix; ``parts``: "normal" or
        "normal+shear"."""
        stats = dict(self._hmatrix.stats)
        if self._shear is not None:
            for key in ("memory_bytes", "build_seconds", "n_admissible", "n_dense_blocks"):
                stats[key] += self._shear.stats[key]
            stats["max_rank"] = max(stats["max_rank"], self._shear.stats["max_rank"])
        dense_bytes = 8 * self.shape[0] * self.shape[1]
        stats.update(backend="hmatrix", dof=3, dense_bytes=dense_bytes, compression=dense_bytes / stats["memory_bytes"],
                     n_elements=self.mesh.n_elements, parts="normal" if self._shear is None else "normal+shear")
        return stats

    # -- the two parts of a vector ----------------------------------------------------
    def _split(self, x):
        """(opening part (N,), shear part (2N,) or None when it is round-off)."""
        vectors = np.asarray(x, dtype=np.float64).reshape(-1, 3)
        opening = np.einsum("ek,ek->e", vectors, self._normals)
        shear = np.einsum("eak,ek->ea", self._axes, vectors).ravel()
        scale = np.abs(vectors).max(initial=0.0)
        if not np.any(np.abs(shear) > SHEAR_ROUND_OFF * scale):
            shear = None
        return opening, shear

    def _join(self, opening, shear):
        vectors = opening[:, None] * self._normals
        if shear is not None:
            vectors += np.einsum("ea,eak->ek", shear.reshape(-1, 2), self._axes)
        return vectors.ravel()

    # -- LinearOperator interface -------------------------------------------------
    def _matvec(self, x):
        opening, shear = self._split(x)
        return self._join(self._hmatrix.matvec(opening),
                          None if shear is None else self._shear_operator().matvec(shear))

    def _matmat(self, X):
        X = np.asarray(X, dtype=np.float64)
        return np.column_stack([self._matvec(X[:, k]) for k in range(X.shape[1])])

    def to_dense(self):
        """The full matrix the two compressed parts represent (N^2 x 9 entries)."""
        n = self.mesh.n_elements
        normal = self._hmatrix.to_dense()
        shear = self._shear_operator().to_dense().reshape(n, 2, n, 2)
        dense = np.einsum("ep,ef,fq->epfq", self._normals, normal, self._normals)
        dense += np.einsum("eap,eafb,fbq->epfq", self._axes, shear, self._axes)
        return dense.reshape(3 * n, 3 * n)

    def check_against_dense(self, n_samples=64):
        """Worst relative error of any admissible block of either part (sampled)."""
        errors = [self._hmatrix.check_against_dense(n_samples=n_samples)]
        if self._shear is not None:
            errors.append(self._shear.check_against_dense(n_samples=n_samples))
        return max(errors)

    def preconditioner(self):
        """:meth:`approximate_inverse` as a LinearOperator."""
        from scipy.sparse.linalg import LinearOperator

        return LinearOperator(self.shape, matvec=self.approximate_inverse, dtype=np.float64)

    def element_diagonal_blocks(self):
        """(N, 3, 3): the exact self-influence block of each element (from the kernel, a
        few dozen elements per call)."""
        n = self.mesh.n_elements
        blocks = np.empty((n, 3, 3))
        for start in range(0, n, 32):
            chunk = np.arange(start, min(start + 32, n), dtype=np.int64)
            index = np.arange(chunk.size)
            blocks[chunk] = self.exact_block(chunk, chunk).reshape(chunk.size, 3, chunk.size, 3)[index, :, index, :]
        return blocks

    def approximate_inverse(self, r):
        """One application of each part's near-field preconditioner (the shear part's
        only when ``r`` has one)."""
        from .hmatrix import default_preconditioner

        if self._preconditioner is None:
            self._preconditioner = default_preconditioner(self._hmatrix)
        opening, shear = self._split(r)
        if shear is not None:
            if self._shear_preconditioner is None:
                self._shear_preconditioner = default_preconditioner(self._shear_operator())
            shear = self._shear_preconditioner @ shear
        return self._join(self._preconditioner @ opening, shear)

    def modified_inverse(self, rows):
        """The approximate inverse of ``S A + D`` (contact rows) of the 3 x 3 operator of
        the same mesh, built on first use: contact rows mix the components of an element."""
        if self._full is None:
            self._full = ElasticityOperator(self.mesh, self.material, backend="hmatrix",
                                            singular_correction=self.singular_correction, alpha=self.alpha,
                                            **self._compression)
        return self._full.modified_inverse(rows)
