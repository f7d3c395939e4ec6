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
faster build). A growing planar crack extends each part by its own border blocks
(:class:`PlanarExtendedOperator`): the h = 0.5 m radial K-vertex run of issue 17 takes 44.7 s
of CPU instead of 106.6 s, with the same errors (AMD EPYC, 1-thread dgemm 30-34 GFLOP/s;
benchmarks/RESULTS.md, session of 2026-12-02, sixth).

A shear part counts as zero when it is below :data:`SHEAR_ROUND_OFF` of the largest
component: projecting an opening ``w n`` stored in global components on the in-plane
axes leaves round-off of that size, which is not a shear DD. Contact (closed elements'
modified rows) works on the element blocks of the whole tensor; :meth:`modified_inverse`
builds the 3 x 3 operator for it on first use.
"""
import numpy as np
from numba import njit
from scipy.sparse.linalg import LinearOperator

from ..element_blocks import join_frame, split_frame
from ..errors import InputError
from ..kernels.drivers import self_blocks, traction_block
from ..material import Elastic
from ..mesh import Mesh3D
from .inverse import solve_with_inverse
from .operator import ElasticityOperator, ProductCounter

#: Relative flatness asked of a planar mesh: every centre within this fraction of the
#: mesh's extent of the plane of the first element, every normal parallel to its normal
#: to this (1 - |cos|) -- round-off of meshes built in a rotated frame, not curvature.
PLANAR_TOLERANCE = 1e-12

#: A product's shear part below this fraction of the largest component of its vector is
#: round-off of the projection (see the module docstring) and is not multiplied.
SHEAR_ROUND_OFF = 1e-13

#: Contact rows keep the modes apart (:func:`split_rows`) when, in each element's frame,
#: their opening-shear entries are below this fraction of the element's largest entry
#: (round-off of rotating ``k I`` or ``I`` into the frame).
SPLIT_ROUND_OFF = 1e-12


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


def split_modes(x, normals, axes):
    """(opening part (N,), shear part (2N,) or None when it is round-off) of the flat,
    global DDs (or tractions) ``x``, in the elements' frames (``normals`` (N, 3), ``axes``
    (N, 2, 3)); compiled (:func:`hmatddm.element_blocks.split_frame`)."""
    opening, shear, largest_shear, largest = split_frame(x, normals, axes)
    if not largest_shear > SHEAR_ROUND_OFF * largest:
        shear = None
    return opening, shear


def split_rows(rows, frames):
    """(opening rows, shear rows) of contact rows ``rows`` (``S``, ``D`` (N, 3, 3) in global
    components) in the elements' frames ``frames`` (N, 3, 3), as :class:`~hmatddm.coupled.
    contact.ContactRows` of 1 and 2 unknowns per element; None when some element's ``S`` or
    ``D`` couples its opening with its shear (a slipping element's friction row), which
    only the 3 x 3 operator can take.

    Rows that keep the modes apart (open: ``S = I``, ``D = 0``; stuck or prescribed:
    ``S = 0``, ``D = k I``; the asymptotic front's tip rows ``DD_i = w_i n_i``) turn
    ``S A + D`` of a planar crack into ``S_n A_nn + D_n`` and ``S_s A_ss + D_s`` (module
    docstring), so each part's modified inverse is that of its own operator."""
    select = np.einsum("eip,epq,ejq->eij", frames, rows.select, frames)
    direct = np.einsum("eip,epq,ejq->eij", frames, rows.direct, frames)
    for blocks in (select, direct):
        scale = np.abs(blocks).max(axis=(1, 2))
        coupling = np.maximum(np.abs(blocks[:, 2, :2]).max(axis=1), np.abs(blocks[:, :2, 2]).max(axis=1))
        if np.any(coupling > SPLIT_ROUND_OFF * scale):
            return None
    n = rows.n
    rows_type = type(rows)  # hmatddm.coupled.contact.ContactRows (a layer above this one)
    normal = rows_type(np.ascontiguousarray(select[:, 2:, 2:]), np.ascontiguousarray(direct[:, 2:, 2:]),
                         np.zeros((n, 1)), (rows.key, "normal"))
    shear = rows_type(np.ascontiguousarray(select[:, :2, :2]), np.ascontiguousarray(direct[:, :2, :2]),
                        np.zeros((n, 2)), (rows.key, "shear"))
    return normal, shear


def split_modified_inverse(normal_inverse, shear_inverse, normals, axes):
    """The approximate inverse (a callable) of a planar crack's ``S A + D`` from its parts'
    (:func:`split_rows`): ``normal_inverse`` a callable, ``shear_inverse`` a function that
    builds the shear part's on first call -- only a right-hand side with a shear part
    needs it (the asymptotic front's tip rows never do)."""
    built = []

    def inverse(r):
        opening, shear = split_modes(r, normals, axes)
        if shear is not None:
            if not built:
                built.append(shear_inverse())
            shear = built[0](shear)
        return join_modes(normal_inverse(opening), shear, normals, axes)

    return inverse


def join_modes(opening, shear, normals, axes):
    """The flat global vector of an opening part and a shear part (None: zero)."""
    return join_frame(opening, shear, normals, axes)


class PlanarElasticityOperator(ElasticityOperator):
    """:class:`~hmatddm.ElasticityOperator` (``hmatrix`` backend) of a planar 3D mesh in a
    homogeneous medium, compressed as an opening operator and a shear operator (the
    shear one on first use; module docstring). Same parameters and methods;
    :attr:`hmatrix` is the opening operator's :class:`~hmatddm.hmatrix.HMatrix` (N x N) and
    :attr:`shear_hmatrix` the shear one (2N x 2N, None until needed)."""

    def __init__(self, mesh, material, backend="hmatrix", eps=None, eta=None, leaf_size=None,
                 singular_correction="none", alpha=None, check_spacing=True):
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
        self._diagonal_blocks = None
        self._parts = {}
        super().__init__(mesh, material, backend="hmatrix", singular_correction=singular_correction, alpha=alpha,
                         check_spacing=check_spacing, **options)

    def _build_compressed(self, eps, eta, leaf_size):
        self._compression = dict(eps=eps, eta=eta, leaf_size=leaf_size)
        self._hmatrix = self._build_part(normal_traction_block, 1)
        self._normals = np.ascontiguousarray(self.data.frames[:, 2])
        self._axes = np.ascontiguousarray(self.data.frames[:, :2])

    def _build_part(self, kernel, dof):
        from ..hmatrix import BlockGenerator, HMatrix

        generator = BlockGenerator(kernel=kernel, data=self.data, points=self.mesh.centers, radii=self.mesh.radii,
                                   dof=dof)
        hmatrix = HMatrix.build(generator, groups=self.mesh.fracture_id, **self._compression)
        if not hmatrix.is_finite():
            self._refuse_singular()
        return hmatrix

    @property
    def border_entries_per_pair(self):
        """Border entries a grown mesh stores per (old, new) element pair: 1 for the opening
        part, 4 more once the shear part is built (the whole operator would store 9)."""
        return 1 + (0 if self._shear is None else 4)

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

    def part(self, name):
        """The ``"normal"`` or ``"shear"`` part as an operator of its own (:class:`OperatorPart`),
        the base of a grown mesh's part (:class:`PlanarExtendedOperator`)."""
        if name not in ("normal", "shear"):
            raise InputError(f"part must be 'normal' or 'shear', got {name!r}")
        if name not in self._parts:  # one object per part: grown operators share by identity
            self._parts[name] = OperatorPart(self, name)
        return self._parts[name]

    def _part_preconditioner(self, name):
        from ..hmatrix import default_preconditioner

        if name == "normal":
            if self._preconditioner is None:
                self._preconditioner = default_preconditioner(self._hmatrix)
            return self._preconditioner
        if self._shear_preconditioner is None:
            self._shear_preconditioner = default_preconditioner(self._shear_operator())
        return self._shear_preconditioner

    # -- the two parts of a vector ----------------------------------------------------
    def _split(self, x):
        return split_modes(x, self._normals, self._axes)

    def _join(self, opening, shear):
        return join_modes(opening, shear, self._normals, self._axes)

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
        """(N, 3, 3): the exact self-influence block of each element (computed once)."""
        if self._diagonal_blocks is None:
            self._diagonal_blocks = self_blocks(self.data)
        return self._diagonal_blocks.copy()

    def approximate_inverse(self, r):
        """One application of each part's near-field preconditioner (the shear part's
        only when ``r`` has one)."""
        opening, shear = self._split(r)
        if shear is not None:
            shear = self._part_preconditioner("shear") @ shear
        return self._join(self._part_preconditioner("normal") @ opening, shear)

    def modified_inverse(self, rows):
        """The approximate inverse of ``S A + D`` (contact rows): each part's modified
        near-field ILU when the rows keep the modes apart (:func:`split_rows`; the shear
        part's on first use), else that of the 3 x 3 operator of the same mesh, built on
        first use (a slipping element's friction row mixes the components of an element)."""
        parts = split_rows(rows, self.data.frames)
        if parts is not None:
            normal_rows, shear_rows = parts
            return split_modified_inverse(self.part("normal").modified_inverse(normal_rows),
                                          lambda: self.part("shear").modified_inverse(shear_rows),
                                          self._normals, self._axes)
        if self._full is None:
            self._full = ElasticityOperator(self.mesh, self.material, backend="hmatrix",
                                            singular_correction=self.singular_correction, alpha=self.alpha,
                                            **self._compression)
        return self._full.modified_inverse(rows)


class OperatorPart:
    """The opening (``"normal"``: 1 unknown per element) or shear (``"shear"``: 2) part of
    a :class:`PlanarElasticityOperator`, with what :class:`~hmatddm.elasticity.extended.
    ExtendedElasticityOperator` asks of a base: ``block_kernel`` for the border blocks,
    products, the part's near-field preconditioner and self blocks."""

    def __init__(self, planar, name):
        self.planar, self.name = planar, name
        self.mesh, self.material, self.backend = planar.mesh, planar.material, "hmatrix"
        self.singular_correction, self.alpha = planar.singular_correction, planar.alpha
        self.dof = 1 if name == "normal" else 2
        self.block_kernel = normal_traction_block if name == "normal" else shear_traction_block
        self.stats = {}
        self._near_field = None

    def near_field_blocks(self):
        """The near-field blocks of :func:`~hmatddm.elasticity.inverse.near_field_blocks`,
        gathered once per part (the asymptotic front modifies their rows at every front
        iteration: 76 ms a gathering at 8.7k elements, 258 of them in a 0.25 m radial run)."""
        from .inverse import near_field_blocks

        if self._near_field is None:
            self._near_field = near_field_blocks(self.hmatrix)
        return self._near_field

    @property
    def hmatrix(self):
        return self.planar.hmatrix if self.name == "normal" else self.planar._shear_operator()

    def matvec(self, x):
        return self.hmatrix.matvec(np.asarray(x, dtype=np.float64).ravel())

    def approximate_inverse(self, r):
        return self.planar._part_preconditioner(self.name) @ np.asarray(r, dtype=np.float64).ravel()

    def element_diagonal_blocks(self):
        return self.hmatrix.element_diagonal_blocks()

    @property
    def shape(self):
        n = self.mesh.n_elements * self.dof
        return (n, n)

    def modified_inverse(self, rows):
        """The block ILU(0) of the part's modified near field ``S A_near + D`` (``rows`` of
        :attr:`dof` unknowns per element, from :func:`split_rows`) as a callable
        (:func:`~hmatddm.elasticity.inverse.modified_near_field_block_ilu`: the asymptotic
        front asks for a new one at every front iteration)."""
        from .inverse import modified_near_field_block_ilu

        if rows.d != self.dof or rows.n != self.mesh.n_elements:
            raise InputError(f"rows must have {self.dof} unknown(s) per element for the {self.name} part and "
                             f"{self.mesh.n_elements} elements, got {rows.d} and {rows.n}")
        inverse = modified_near_field_block_ilu(self, rows)
        return lambda r: inverse @ np.asarray(r, dtype=np.float64).ravel()


class PlanarExtendedOperator(ProductCounter, LinearOperator):
    """A planar crack's operator (``base``, a :class:`PlanarElasticityOperator`) grown by
    elements in its plane: each part extended by its own exact border blocks
    (:class:`~hmatddm.elasticity.extended.ExtendedElasticityOperator` over
    :meth:`PlanarElasticityOperator.part`), the shear part on first use. 1/9 (opening) of
    the border entries, products and border preconditioner of the 3 x 3 border. Contact
    rows (:meth:`modified_inverse`) get the whole-tensor extension on first use."""

    inverse_is_exact = False

    def __init__(self, base, mesh, previous=None):
        if not isinstance(base, PlanarElasticityOperator):
            raise InputError(f"base must be a PlanarElasticityOperator, got {type(base).__name__}")
        if not is_planar(mesh):
            raise InputError("mesh must lie in the base operator's plane (is_planar)")
        from .extended import ExtendedElasticityOperator

        self.base, self.mesh, self.material, self.backend, self.dof = base, mesh, base.material, "hmatrix", 3
        self.n_base = base.mesh.n_elements
        super().__init__(dtype=np.float64, shape=(3 * mesh.n_elements, 3 * mesh.n_elements))
        shares = isinstance(previous, PlanarExtendedOperator) and previous.base is base
        self._normal = ExtendedElasticityOperator(base.part("normal"), mesh, previous._normal if shares else None)
        self._shear_previous = previous._shear if shares else None
        self._shear = None
        self._full = None
        frames = self._normal._data.frames
        self._normals, self._axes = np.ascontiguousarray(frames[:, 2]), np.ascontiguousarray(frames[:, :2])

    @property
    def n_new(self):
        return self.mesh.n_elements - self.n_base

    @property
    def border_bytes(self):
        return self._normal.border_bytes + (0 if self._shear is None else self._shear.border_bytes)

    @property
    def chunk_bytes(self):
        """Bytes of the parts' border chunks (without their ``A_nn``)."""
        return self._normal.chunk_bytes + (0 if self._shear is None else self._shear.chunk_bytes)

    def _shear_operator(self):
        if self._shear is None:
            from .extended import ExtendedElasticityOperator

            self._shear = ExtendedElasticityOperator(self.base.part("shear"), self.mesh, self._shear_previous)
            self._shear_previous = None
        return self._shear

    def _matvec(self, x):
        opening, shear = split_modes(x, self._normals, self._axes)
        return join_modes(self._normal.matvec(opening), None if shear is None else self._shear_operator().matvec(shear),
                          self._normals, self._axes)

    def approximate_inverse(self, r):
        """Each part's block-triangular solve (the shear part's only when ``r`` has one)."""
        opening, shear = split_modes(r, self._normals, self._axes)
        if shear is not None:
            shear = self._shear_operator().approximate_inverse(shear)
        return join_modes(self._normal.approximate_inverse(opening), shear, self._normals, self._axes)

    def preconditioner(self):
        return LinearOperator(self.shape, matvec=self.approximate_inverse, dtype=np.float64)

    def solve(self, rhs, x0=None, rtol=1e-9, restart=100, maxiter=20):
        """``(x, info)``: GMRES preconditioned by :meth:`approximate_inverse`."""
        return solve_with_inverse(self, rhs, self.approximate_inverse, False, x0=x0, rtol=rtol, restart=restart,
                                  maxiter=maxiter)

    def element_diagonal_blocks(self):
        """(N, 3, 3): the base's exact self blocks, then the new elements' (kernel)."""
        return np.concatenate([self.base.element_diagonal_blocks(),
                               self_blocks(self._normal._data, self.n_base, self.mesh.n_elements)])

    def modified_inverse(self, rows):
        """Each part's block-triangular modified inverse when the rows keep the modes
        apart (:func:`split_rows`; the shear part's on first use), else the whole-tensor
        extension's (built on first use): a slipping element's friction row mixes an
        element's components."""
        parts = split_rows(rows, self._normal._data.frames)
        if parts is not None:
            normal_rows, shear_rows = parts
            return split_modified_inverse(self._normal.modified_inverse(normal_rows),
                                          lambda: self._shear_operator().modified_inverse(shear_rows),
                                          self._normals, self._axes)
        if self._full is None:
            from .extended import ExtendedElasticityOperator

            self._full = ExtendedElasticityOperator(self.base, self.mesh)
        return self._full.modified_inverse(rows)
