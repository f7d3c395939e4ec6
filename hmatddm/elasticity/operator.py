"""The elasticity operator: DD (global frame) -> traction sigma.n at the collocation points.

One interface, two backends (docs/conventions.md §§1, 2, 6):

* ``"dense"``: the full influence matrix (ref. Eq. 2.47 with the coefficients of
  ref. Eqs 2.57-2.59), assembled in parallel by the numba kernels. The reference path.
* ``"hmatrix"``: the same matrix compressed by :mod:`hmatddm.hmatrix` (cluster tree,
  tensor ACA, recompression); every entry it approximates is checked against the
  kernels in the tests.

Unknowns are element-major: ``[e0_x, e0_y, (e0_z,) e1_x, ...]``. A pressurised crack
with net pressure ``p`` satisfies ``op @ dd = -p n``. A 2D mesh of linear or quadratic
elements (``mesh.element_order`` 1 or 2) has ``2 (order + 1)`` unknowns per element,
node-major inside the element (docs/conventions.md §2), collocated at its nodes.
"""
import dataclasses
import time

import numpy as np
from scipy.sparse.linalg import LinearOperator

from ..errors import InputError
from ..kernels import drivers, element_data
from ..layered.medium import LayeredMedium
from ..material import Elastic
from ..mesh import Mesh2D, Mesh3D, check_mesh, check_parallel_spacing
from .inverse import modified_near_field_inverse, solve_with_inverse

from ..options import (AVERAGE_SHIFT, BACKENDS, DEFAULT_EPS, DEFAULT_ETA, DEFAULT_LEAF_SIZE,  # noqa: F401
                       NEAR_SINGULAR_FRACTION, SINGULAR_CORRECTIONS)
from ..settings import OPERATOR


class ProductCounter:
    """Counts the products of an operator (``products``: calls of :meth:`matvec`, columns
    of :meth:`matmat`), the cost unit of a solve that a simulation records per step."""

    products = 0

    def matvec(self, x):
        self.products += 1
        return super().matvec(x)

    def matmat(self, X):
        self.products += int(np.shape(X)[1]) if np.ndim(X) == 2 else 1
        return super().matmat(X)

    def _matmat(self, X):
        # column by column through the uncounted _matvec (scipy's default goes through the
        # counted matvec and would count each column twice); a class with its own _matmat
        # overrides this one
        X = np.asarray(X, dtype=np.float64)
        return np.column_stack([self._matvec(X[:, k]) for k in range(X.shape[1])])


class ElasticityOperator(ProductCounter, LinearOperator):
    """DDM influence operator of a mesh in a homogeneous elastic medium.

    Parameters
    ----------
    mesh : Mesh2D or Mesh3D
    material : Elastic or LayeredMedium
        A :class:`hmatddm.LayeredMedium` (2D, constant elements) adds the image terms of
        ref. Ch. 3 to the closed-form kernel of each source element's layer; its
        ``images``, ``image_tol`` and ``gauss_points`` set them, and ``stats["n_images"]``
        reports the number used. Elements must not straddle interfaces
        (:func:`hmatddm.layered.split_at_interfaces`).
    backend : {"dense", "hmatrix"}
    eps : float
        ACA / recompression tolerance of the ``hmatrix`` backend, in (0, 1).
        The default 1e-4 keeps the smooth-field error of a pressurised crack below
        about 1e-4 (see benchmarks/RESULTS.md).
    eta : float
        Admissibility parameter, ``min(diam) <= eta * dist``, > 0.
    leaf_size : int
        Largest number of elements in a leaf cluster, >= 1.
    singular_correction : {"none", "average"}
        Collocation points lying on an element edge (2D: on a segment end), or closer
        to one than :data:`NEAR_SINGULAR_FRACTION` (0.5) of the smaller half size of
        the two elements (a near-miss junction, where the exact entry is ~1/gap and
        pins the solution), are singular. ``"none"`` refuses such meshes with an error
        naming the elements and the gap; ``"average"`` moves the point onto the nearest
        edge point and takes the mean of two neighbouring points across the edge there
        (ref. Sec. 6.2.3), i.e. treats a near miss as a junction.
    alpha : float or None
        If given (>= 1), blocks whose largest entry exceeds ``alpha`` times the largest
        entry of the source element's self block are scaled down (ref. Eq. 6.11).
        Applied entry-wise in the kernel, so both backends see the same matrix.
    n_images : int or None
        A :class:`hmatddm.LayeredMedium` with ``images="auto"``: this number of images
        instead of the choice made on ``mesh`` (a growing run's rebuilds keep their choice
        while the mesh stays within twice its extent:
        :class:`hmatddm.simulation.growing_operator.GrowingOperator`); >= 0.
    leading : ElasticityOperator or None
        ``backend="dense"`` in a homogeneous medium: a dense operator of a mesh whose
        elements are this mesh's first ones (:func:`leads`), same material and options.
        Its matrix is this one's leading block, copied; only the new elements' rows and
        columns are computed (a growing run's growth pass:
        :class:`~hmatddm.simulation.growing_operator.GrowingOperator`). Every entry is
        one pair's, so the matrix is the one a full build gives, bit for bit.
    check_spacing : bool
        False skips the check below (a growing run that has warned once already:
        :class:`~hmatddm.simulation.growing_operator.GrowingOperator`, whose check at
        every build of a 470-element network took 0.48 s of its 313 builds).

    Warns
    -----
    hmatddm.errors.MeshQualityWarning
        When elements of different fractures are near-parallel and closer than the
        elements resolve (:func:`hmatddm.mesh.close_parallel_pairs`): the solution can
        be wrong there (negative openings); the message gives the element size to use.
    """

    def __init__(self, mesh, material, backend="dense", eps=DEFAULT_EPS, eta=DEFAULT_ETA,
                 leaf_size=DEFAULT_LEAF_SIZE, singular_correction="none", alpha=None, n_images=None,
                 leading=None, check_spacing=True):
        if not isinstance(mesh, (Mesh2D, Mesh3D)):
            raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
        if not isinstance(material, (Elastic, LayeredMedium)):
            raise InputError(f"material must be an hmatddm.Elastic or hmatddm.LayeredMedium, got "
                             f"{type(material).__name__}")
        backend, singular_correction, eps, eta, leaf_size, alpha = (
            OPERATOR[name].value(name, value) for name, value in
            (("backend", backend), ("singular_correction", singular_correction), ("eps", eps), ("eta", eta),
             ("leaf_size", leaf_size), ("alpha", alpha)))

        if leading is not None and backend != "dense":
            raise InputError(f"leading is for backend='dense' only, got backend={backend!r}")
        check_mesh(mesh)
        _refuse_coincident(mesh)
        if check_spacing:
            check_parallel_spacing(mesh, stacklevel=2)
        self.mesh = mesh
        self.material = material
        self.backend = backend
        self.dof = mesh.dim * mesh.n_nodes  # unknowns per element
        self.singular_correction = singular_correction
        self.alpha = alpha
        n = mesh.n_elements * self.dof
        super().__init__(dtype=np.float64, shape=(n, n))

        if n_images is not None and (isinstance(n_images, bool) or not isinstance(n_images, (int, np.integer))
                                     or n_images < 0):
            raise InputError(f"n_images must be an integer >= 0 or None, got {n_images!r}")
        if n_images is not None and not (isinstance(material, LayeredMedium) and material.images == "auto"):
            n_images = None  # a fixed number of images, or no layers: the medium's own
        self.data = influence_data(mesh, material, singular_correction, alpha,
                                   None if n_images is None else int(n_images))

        t0 = time.perf_counter()
        if backend == "dense":
            self._matrix = np.empty(self.shape)
            if leading is None:
                drivers.traction_matrix(self.data, self._matrix)
            else:
                _bordered_matrix(self, leading)
            self._hmatrix = None
            if not np.all(np.isfinite(self._matrix)):
                self._refuse_singular()
            build = time.perf_counter() - t0
            nbytes = self._matrix.nbytes
            self._stats = dict(backend="dense", memory_bytes=nbytes, dense_bytes=nbytes, compression=1.0,
                               build_seconds=build, n_admissible=0, n_dense_blocks=1, max_rank=0,
                               eps=0.0, eta=eta, leaf_size=leaf_size, n_elements=mesh.n_elements, dof=self.dof)
        else:
            self._matrix = None
            self._build_compressed(eps, eta, leaf_size)
        if isinstance(material, LayeredMedium):
            self._stats["n_images"] = int(getattr(self.data, "n_images", 0))  # equal layers: 0
        self._lu = None
        self._preconditioner = None

    def _build_compressed(self, eps, eta, leaf_size):
        """The ``hmatrix`` backend's build (:class:`hmatddm.elasticity.planar.PlanarElasticityOperator`
        builds two)."""
        from ..hmatrix import BlockGenerator, HMatrix

        mesh = self.mesh
        generator = BlockGenerator(kernel=drivers.traction_block, data=self.data,
                                   points=mesh.centers, radii=mesh.radii, dof=self.dof)
        # 3D: clusters split between whole fractures first (clouds of tall fractures:
        # -24% build CPU, -12% memory at 40k, benchmarks/RESULTS.md "Solver at scale")
        groups = mesh.fracture_id if mesh.dim == 3 else None
        self._hmatrix = HMatrix.build(generator, eps=eps, eta=eta, leaf_size=leaf_size, groups=groups)
        if not self._hmatrix.is_finite():
            self._refuse_singular()
        self._stats = dict(self._hmatrix.stats)
        self._stats["backend"] = "hmatrix"

    # -- LinearOperator interface -------------------------------------------------
    def _matvec(self, x):
        x = np.asarray(x, dtype=np.float64).ravel()
        if self._matrix is not None:
            return self._matrix @ x
        return self._hmatrix.matvec(x)

    def _matmat(self, X):
        X = np.asarray(X, dtype=np.float64)
        if self._matrix is not None:
            return self._matrix @ X
        return self._hmatrix.matmat(X)

    def _adjoint(self):
        if self._matrix is None:
            raise NotImplementedError("the hmatrix backend has no adjoint; use backend='dense'")
        return LinearOperator(self.shape, matvec=lambda y: self._matrix.T @ y, dtype=self.dtype)

    # -- public extras --------------------------------------------------------------
    @property
    def stats(self):
        """Build statistics (memory_bytes, dense_bytes, compression, build_seconds, ...)."""
        return dict(self._stats)

    @property
    def hmatrix(self):
        """The underlying :class:`hmatddm.hmatrix.HMatrix` (``None`` for ``dense``)."""
        return self._hmatrix

    def to_dense(self):
        """The full matrix (a copy for ``dense``, expanded from blocks for ``hmatrix``)."""
        if self._matrix is not None:
            return self._matrix.copy()
        return self._hmatrix.to_dense()

    def dense_view(self):
        """The full matrix for reading: ``dense``'s own, read-only (no copy: the contact
        factor of every solve reads it, 518 copies of up to 16 MB on dfn-3cluster at 4x its
        area), else :meth:`to_dense`."""
        if self._matrix is None:
            return self.to_dense()
        view = self._matrix.view()
        view.flags.writeable = False
        return view

    def exact_block(self, rows, cols):
        """Exact entries for element index arrays ``rows`` x ``cols`` from the kernels."""
        rows = np.ascontiguousarray(rows, dtype=np.int64)
        cols = np.ascontiguousarray(cols, dtype=np.int64)
        out = np.empty((len(rows) * self.dof, len(cols) * self.dof))
        drivers.traction_block(self.data, rows, cols, out)
        return out

    def check_against_dense(self, n_samples=64):
        """Worst relative error of any admissible block, on sampled exact entries.

        Dense backend: 0.0 (it is the exact matrix).
        """
        if self._hmatrix is None:
            return 0.0
        return self._hmatrix.check_against_dense(n_samples=n_samples)

    def preconditioner(self):
        """:func:`hmatddm.hmatrix.default_preconditioner` of the ``hmatrix`` backend (near-field
        block ILU, two-level from 20 000 elements; built once and cached)."""
        if self._hmatrix is None:
            return None
        if self._preconditioner is None:
            from ..hmatrix import default_preconditioner

            self._preconditioner = default_preconditioner(self._hmatrix)
        return self._preconditioner

    def element_diagonal_blocks(self):
        """(N, d, d): the exact self-influence block of each element."""
        if self._matrix is None:
            return self._hmatrix.element_diagonal_blocks()
        n, d = self.mesh.n_elements, self.dof
        index = np.arange(n)
        return np.ascontiguousarray(self._matrix.reshape(n, d, n, d)[index, :, index, :])

    # -- solving (the same methods on every operator; hmatddm.elasticity.inverse) ---
    @property
    def inverse_is_exact(self):
        """True when :meth:`approximate_inverse` is exact (the dense LU), so a solve needs
        no iteration."""
        return self._matrix is not None

    def approximate_inverse(self, r):
        """``A^-1 r`` approximately: the LU solve (exact) for ``dense``, one application of
        :meth:`preconditioner` for ``hmatrix``."""
        r = np.asarray(r, dtype=np.float64).ravel()
        if self._matrix is not None:
            import scipy.linalg

            return scipy.linalg.lu_solve(self.lu(), r, check_finite=False)
        return self.preconditioner() @ r

    def modified_inverse(self, rows):
        """Approximate inverse (a callable) of ``S A + D`` for row operators ``rows``
        (:class:`hmatddm.coupled.contact.ContactRows`): the LU of the modified matrix
        (exact) for ``dense``, the ILU of the modified near field for ``hmatrix``."""
        if self._matrix is not None:
            import scipy.linalg

            factors = scipy.linalg.lu_factor(rows.modify_dense(self.to_dense()), check_finite=False)
            return lambda r: scipy.linalg.lu_solve(factors, np.asarray(r, dtype=np.float64).ravel(),
                                                   check_finite=False)
        inverse = modified_near_field_inverse(self, rows)
        return lambda r: inverse @ np.asarray(r, dtype=np.float64).ravel()

    def solve(self, rhs, x0=None, rtol=1e-9, restart=100, maxiter=20):
        """``(x, info)`` with ``A x = rhs`` (flat): see :func:`hmatddm.elasticity.inverse.solve_with_inverse`."""
        return solve_with_inverse(self, rhs, self.approximate_inverse, self.inverse_is_exact, x0=x0, rtol=rtol,
                                  restart=restart, maxiter=maxiter)

    def lu(self):
        """LU factors of the dense matrix (cached; ``dense`` backend only)."""
        if self._matrix is None:
            raise InputError("lu() needs backend='dense'")
        if self._lu is None:
            import scipy.linalg

            self._lu = scipy.linalg.lu_factor(self._matrix, check_finite=False)
        return self._lu

    # -- helpers ------------------------------------------------------------------------
    def _refuse_singular(self):
        refuse_singular(self.mesh, self.data)


def _refuse_coincident(mesh):
    """Two elements of one plane of which one holds the other's centre (coincident, or
    overlapping) make the matrix singular, or nearly so: refuse them. Each centre is looked
    for within its element's circumradius, so a mesh whose elements only touch costs one
    k-d tree query per element."""
    from scipy.spatial import cKDTree

    radii = np.asarray(mesh.radii, dtype=np.float64)
    tolerance = 1e-9 * float(np.min(radii))
    # half sizes in the element's frame (rows e1, [e2,] n; 2D: tangent, normal)
    half = np.column_stack([mesh.half_a, mesh.half_b]) if mesh.dim == 3 else mesh.half_length[:, None]
    near = cKDTree(mesh.centers).query_ball_point(mesh.centers, radii * (1.0 + 1e-9) + tolerance)
    counts = np.fromiter(map(len, near), dtype=np.int64, count=len(near))
    if np.all(counts <= 1):  # every centre alone within its element's circumradius (a mesh that only touches)
        return
    first = np.repeat(np.arange(len(near)), counts)
    second = np.concatenate([np.asarray(found, dtype=np.int64) for found in near])
    keep = (first != second) & (np.abs(np.einsum("ij,ij->i", mesh.normals[first], mesh.normals[second]))
                                > 1.0 - 1e-9)
    first, second = first[keep], second[keep]
    local = np.einsum("eij,ej->ei", mesh.frames[first], mesh.centers[second] - mesh.centers[first])
    inside = (np.abs(local[:, -1]) <= tolerance) & np.all(np.abs(local[:, :-1]) < half[first] - tolerance, axis=1)
    if np.any(inside):
        k = int(np.flatnonzero(inside)[0])
        i, j = int(first[k]), int(second[k])
        kind = "coincide (same centre and plane)" if np.all(np.abs(local[k]) <= tolerance) else \
            f"overlap (the centre of element {j} lies inside element {i}, in its plane)"
        raise InputError(f"elements {min(i, j)} and {max(i, j)} {kind}, which makes the DDM system singular; "
                         "remove or re-mesh one of them")


def leads(leading_mesh, mesh):
    """Whether the elements of ``leading_mesh`` are the first ones of ``mesh`` (same kind,
    element order and arrays)."""
    if type(leading_mesh) is not type(mesh) or leading_mesh.element_order != mesh.element_order:
        return False
    n = leading_mesh.n_elements
    return n <= mesh.n_elements and all(
        np.array_equal(getattr(leading_mesh, field.name), getattr(mesh, field.name)[:n])
        for field in dataclasses.fields(mesh) if isinstance(getattr(mesh, field.name), np.ndarray))


def _bordered_matrix(operator, leading):
    """``operator``'s dense matrix from ``leading``'s (its leading block) and the new
    elements' rows and columns from the kernels (the ``leading`` parameter)."""
    if not (isinstance(leading, ElasticityOperator) and leading._matrix is not None
            and isinstance(operator.material, Elastic) and leading.material == operator.material
            and leading.singular_correction == operator.singular_correction and leading.alpha == operator.alpha
            and leads(leading.mesh, operator.mesh)):
        raise InputError("leading must be a dense ElasticityOperator in the same homogeneous material, with the "
                         "same singular_correction and alpha, of a mesh whose elements are this mesh's first ones")
    n, dof, start = operator.mesh.n_elements, operator.dof, leading.mesh.n_elements
    s, out = start * dof, operator._matrix
    out[:s, :s] = leading._matrix
    everything = np.arange(n, dtype=np.int64)
    if start < n:
        if start:
            band = np.empty((s, out.shape[1] - s))
            drivers.traction_block(operator.data, everything[:start], everything[start:], band)
            out[:s, s:] = band
        drivers.traction_block(operator.data, everything[start:], everything, out[s:])


def influence_data(mesh, material, singular_correction="none", alpha=None, n_images=None):
    """The kernel data record (see :mod:`hmatddm.kernels.drivers`) that fills exact
    influence blocks of ``mesh`` with the same options (NaN averaging of singular and
    near-singular points, Eq. 6.11 scaling) as the operator uses."""
    shift = AVERAGE_SHIFT if singular_correction == "average" else 0.0
    if isinstance(material, LayeredMedium) and material.is_homogeneous:
        material = material.material(0)  # equal layers: no image, the uniform-rock kernel
    if isinstance(material, LayeredMedium):  # ref. Ch. 3: closed form + image terms
        return _layered_influence_data(mesh, material, shift, alpha, n_images)
    self_max = None
    if alpha is not None:
        self_max = drivers.self_block_maxima(element_data(mesh, material, singular_shift=shift,
                                                          near_fraction=NEAR_SINGULAR_FRACTION))
    return element_data(mesh, material, singular_shift=shift, alpha=alpha or 0.0, self_max=self_max,
                        near_fraction=NEAR_SINGULAR_FRACTION)


def _layered_influence_data(mesh, medium, shift, alpha, n_images=None):
    """Kernel data of a layered medium; ``n_images`` None: the medium's choice (for
    ``"auto"``, made on this mesh), else that number (an extended operator keeps its base's)."""
    from ..layered import influence2d, influence3d

    if mesh.dim == 2 and mesh.element_order > 0:  # linear / quadratic elements (ref. Sec. 3.5)
        from ..layered import higher_order2d as layered_higher_order

        if n_images is None:
            n_images = layered_higher_order.image_count(mesh, medium, shift)
        return layered_higher_order.influence_data(mesh, medium, shift, alpha or 0.0, NEAR_SINGULAR_FRACTION,
                                                   n_images)
    influence = influence3d if mesh.dim == 3 else influence2d  # constant rectangles / segments
    if n_images is None:
        data = influence.influence_data(mesh, medium, shift, 0.0, NEAR_SINGULAR_FRACTION, 0)
        n_images = influence.choose_images(mesh, medium, data)
    return influence.influence_data(mesh, medium, shift, alpha or 0.0, NEAR_SINGULAR_FRACTION, n_images)


def smaller_half_sides(mesh):
    """(N,) the half size the near-singular test uses: the half length in 2D, the
    smaller half side ``min(half_a, half_b)`` in 3D."""
    return mesh.half_length.copy() if mesh.dim == 2 else np.minimum(mesh.half_a, mesh.half_b)


def singular_pairs(mesh, data):
    """(receivers, sources): every element pair whose influence block is singular
    (a collocation point on, or nearer than the near-singular distance to, another
    element's edge), sorted. Candidates come from a KD-tree on the centres."""
    from scipy.spatial import cKDTree

    near_fraction = float(data.near_fraction)
    reach = mesh.radii * (1.0 + 1e-9) + near_fraction * smaller_half_sides(mesh)
    if mesh.n_nodes > 1:  # collocation nodes of linear / quadratic elements lie off the centre
        reach = reach + np.max(mesh.radii)
    tree = cKDTree(mesh.centers)
    found = tree.query_ball_point(mesh.centers, reach)
    counts = np.array([len(f) for f in found], dtype=np.int64)
    sources = np.repeat(np.arange(mesh.n_elements, dtype=np.int64), counts)
    receivers = np.fromiter((i for f in found for i in f), dtype=np.int64, count=int(counts.sum()))
    keep = receivers != sources
    receivers, sources = receivers[keep], sources[keep]
    bad = np.zeros(len(receivers), dtype=np.bool_)
    drivers.singular_pairs(data, receivers, sources, bad)
    order = np.lexsort((sources[bad], receivers[bad]))
    return receivers[bad][order], sources[bad][order]


def refuse_singular(mesh=None, data=None):
    """Raise the InputError of a mesh with collocation points on (or, closer than
    :data:`NEAR_SINGULAR_FRACTION` half sizes, near) element edges; given the mesh and
    its kernel data, the message names the first such pair and its gap."""
    fix = ("use singular_correction='average' (and alpha=1.0, ref. Sec. 6.2.3), which treats such points "
           "as touching the edge; or mesh the intersection end to end, e.g. with "
           "hd.network.split_at_intersections(network, tol=...), whose tol (relative to the network's "
           "bounding-box diagonal) also snaps near misses when it exceeds the gap")
    what = (f"the DDM kernel is singular on an element edge (e.g. a T-intersection where an element ends on "
            f"another element's centre) and ~1/gap within {NEAR_SINGULAR_FRACTION} half sizes of one (a near "
            f"miss), which pins the solution")
    if mesh is not None:
        receivers, sources = singular_pairs(mesh, data)
        if len(receivers):
            i, j = int(receivers[0]), int(sources[0])
            gap = float(drivers.edge_distance(data, i, j))
            half_sides = smaller_half_sides(mesh)
            size = float(min(half_sides[i], half_sides[j]))
            point = "centre" if mesh.n_nodes == 1 else "collocation node"
            where = ("on an edge" if gap <= 1e-9 * size else
                     f"{gap:.3g} m ({gap / size:.2g} of the smaller half size) from an edge")
            raise InputError(
                f"{len(receivers)} collocation point(s) lie on or near another element's edge: element {i} "
                f"(fracture {int(mesh.fracture_id[i])}) has its {point} {where} of element {j} (fracture "
                f"{int(mesh.fracture_id[j])}); {what}. To fix it, {fix}")
    raise InputError(f"the mesh has collocation points on or near element edges; {what}. To fix it, {fix}")
