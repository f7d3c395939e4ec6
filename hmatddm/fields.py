"""Stress fields: the stress that the DDs of a mesh induce at points (ref. Eq. 2.59; mean
stress ref. Eqs 5.24-5.28), for the results (:func:`hmatddm.stress_at`,
:func:`hmatddm.mean_stress_at`) and the remote-failure check of a natural-fracture
network (ref. Sec. 5.3).

The stress at M points from N elements is a points x elements matrix applied to the DDs:
row ``n_out * t + c`` is component ``c`` of the stress at point ``t`` (3D: xx, yy, zz, xy,
xz, yz; 2D plane strain: xx, yy, xy; or the mean stress alone, ``n_out = 1``), column
``d * j + q`` the global DD component ``q`` of element ``j`` (or, for given DDs, one
column per element: what it induces with its DD). Its entries come from the
per-pair kernels of :mod:`hmatddm.kernels` (``local_stress_corrected`` of
:mod:`~hmatddm.kernels.rectangle3d` and :mod:`~hmatddm.kernels.line2d`), contracted with
a local DD and rotated to the global frame (ref. Eq. 2.57). Two ways to apply it:

* ``"direct"``: the exact sum over all elements, parallel over a fixed split of the points
  (the result does not depend on the thread count), each pair's DD contracted before the
  one rotation;
* ``"tree"``: the block tree of a rectangular H-matrix of the generic engine
  (:mod:`hmatddm.hmatrix`: a cluster tree of the points, one of the elements,
  whole-element ACA of the far blocks). For one evaluation of given DDs (:func:`induced`,
  behind ``hd.stress_at``) the matrix has one column per element (the ranks of the
  contracted sum) and is applied to ones without being stored
  (:func:`hmatddm.hmatrix.product.build_free_product`: each far block's ACA at
  ``ACA_TOLERANCE_FACTOR * eps``, ``U (V^T 1)`` added at once); :class:`StressField`
  without DDs builds and keeps the matrix of unit DD components (ACA, recompression to
  ``eps``) for further DDs on the same points and elements.
"""
import time
import warnings
from typing import NamedTuple

import numpy as np
from numba import njit, prange
from numba.core.errors import NumbaPerformanceWarning

from ._validation import finite_array, finite_scalar
from .errors import InputError
from .kernels.line2d import local_stress_corrected as _segment_local_stress
from .kernels.rectangle3d import local_stress_corrected as _rectangle_local_stress
from .material import Elastic
from .mesh import Mesh2D, Mesh3D, check_mesh

#: What a field holds at each point.
QUANTITIES = ("stress", "mean")
METHODS = ("auto", "direct", "tree")
#: Relative Frobenius accuracy asked of every compressed block (``method="tree"``, and
#: ``"auto"`` on large problems): the largest error of any component is then about
#: 0.01-0.1 ``eps`` times the largest induced stress (measured, benchmarks/bench_fields.py).
DEFAULT_STRESS_EPS = 1e-5
#: ``method="auto"`` compresses when (points x elements) reaches this and both counts
#: exceed twice the leaf size. Measured (benchmarks/bench_fields.py, RESULTS.md "One-shot
#: product"): the one-shot product of given DDs costs the exact sum's CPU at ~2.4e6 pairs
#: in 3D (4,447 points x 540 elements), 0.55x at 1.9e7; in 2D it wins from 3e6 pairs.
AUTO_TREE_PAIRS = 4_000_000
#: Admissibility ``min(diam) <= eta * dist`` and leaf size of both cluster trees. Stricter
#: than the operator's 3: the field must stay within ~1e-7 of its largest component at
#: ``DEFAULT_STRESS_EPS`` (measured 1.4e-6 in 2D with 3, benchmarks/RESULTS.md).
FIELD_ETA = 1.0
FIELD_LEAF_SIZE = 64
#: Far blocks of the one-shot product with fewer points or elements than this are summed
#: exactly (ranks of the six components are 30-60: the ACA does not pay below).
FIELD_MIN_ACA = 64
_DIRECT_CHUNKS = 64  # fixed split of the point range in the direct sum


def n_components(dim, quantity):
    """Values per point: 6 (3D) or 3 (2D) stress components, 1 for the mean stress."""
    return 1 if quantity == "mean" else (6 if dim == 3 else 3)


# ---------------------------------------------------------------------------- kernels

class FieldSources(NamedTuple):
    """What the field kernels read (numba reads the fields by name): the target
    ``points`` (M, dim), the elements (``centers``, ``frames`` with the local axes as
    rows, half sizes ``half_a``, ``half_b``; in 2D both are the half length), the
    material, the singular-point treatment: ``singular_shift`` (0: NaN at singular
    points, else the averaging offset of ref. Sec. 6.2.3) and ``near_fraction``, and the
    global DDs ``dd`` (N, dim) that :func:`contribution_block` folds into its columns."""

    points: np.ndarray
    centers: np.ndarray
    frames: np.ndarray
    half_a: np.ndarray
    half_b: np.ndarray
    shear_modulus: float
    poisson_ratio: float
    singular_shift: float
    near_fraction: float
    dd: np.ndarray


def field_sources(mesh, material, points, singular_correction="none", near_fraction=0.0, dd=None):
    """The :class:`FieldSources` of ``mesh`` seen from ``points`` (contiguous float64
    arrays: one compiled specialisation of each kernel, whatever slicing or
    concatenation produced the mesh)."""
    half_a, half_b = (mesh.half_length, mesh.half_length) if mesh.dim == 2 else (mesh.half_a, mesh.half_b)
    arrays = (np.ascontiguousarray(a, dtype=np.float64) for a in (points, mesh.centers, mesh.frames, half_a, half_b))
    dd = np.zeros((mesh.n_elements, mesh.dim)) if dd is None else dd
    return FieldSources(*arrays, float(material.shear_modulus), float(material.poisson_ratio),
                        1e-3 if singular_correction == "average" else 0.0, float(near_fraction),
                        np.ascontiguousarray(dd, dtype=np.float64))


@njit(cache=True, inline="always")
def _may_touch_boundary(x1, x2, x3, a, b, distance):
    """False when the local point is certainly farther than ``distance`` from the
    rectangle's boundary (a bounding test, so that the far pairs skip the nearest
    boundary point search of ``local_stress_corrected``)."""
    if abs(x3) > distance:
        return False
    u = abs(x1)
    v = abs(x2)
    if u > a + distance or v > b + distance:
        return False
    return abs(u - a) <= distance or abs(v - b) <= distance


@njit(cache=True, nogil=True, inline="always")
def _local_response(sources, point, j, work3, work2):
    """Local stress of element ``j`` at ``point`` per unit local DD component
    (``work3[k]`` in 3D, ``work2[k]`` in 2D): the kernels' ``local_stress_corrected``
    (points on an edge or end, or within ``near_fraction`` of the element's smaller half
    size of one, are averaged across it when ``singular_shift > 0``, else NaN)."""
    centers = sources.centers
    frame = sources.frames[j]
    g = sources.shear_modulus
    nu = sources.poisson_ratio
    if centers.shape[1] == 3:
        dx = point[0] - centers[j, 0]
        dy = point[1] - centers[j, 1]
        dz = point[2] - centers[j, 2]
        x1 = frame[0, 0] * dx + frame[0, 1] * dy + frame[0, 2] * dz
        x2 = frame[1, 0] * dx + frame[1, 1] * dy + frame[1, 2] * dz
        x3 = frame[2, 0] * dx + frame[2, 1] * dy + frame[2, 2] * dz
        a = sources.half_a[j]
        b = sources.half_b[j]
        near = sources.near_fraction * min(a, b)
        if near > 0.0 and not _may_touch_boundary(x1, x2, x3, a, b, near):
            near = 0.0
        _rectangle_local_stress(x1, x2, x3, a, b, g, nu, sources.singular_shift, work3, near)
    else:
        dx = point[0] - centers[j, 0]
        dy = point[1] - centers[j, 1]
        a = sources.half_a[j]
        _segment_local_stress(frame[0, 0] * dx + frame[0, 1] * dy, frame[1, 0] * dx + frame[1, 1] * dy, a, g, nu,
                              sources.singular_shift, work2, sources.near_fraction * a)


@njit(cache=True, nogil=True, inline="always")
def _components(work3, work2, dim, l0, l1, l2, frame, n_out, nu, out):
    """``out[:n_out]``: the global components of the stress of local DD ``(l0, l1, l2)``
    (``l2`` unused in 2D) from the local responses: ``s = sum_k l_k work[k]``, rotated
    ``F^T s F`` (``frame`` rows are the local axes, ref. Eq. 2.57), or the mean stress
    ``tr(s)/3`` (2D plane strain: ``(1 + nu) tr(s) / 3``, since ``s_zz = nu tr(s)``)."""
    if dim == 3:
        s00 = l0 * work3[0, 0, 0] + l1 * work3[1, 0, 0] + l2 * work3[2, 0, 0]
        s11 = l0 * work3[0, 1, 1] + l1 * work3[1, 1, 1] + l2 * work3[2, 1, 1]
        s22 = l0 * work3[0, 2, 2] + l1 * work3[1, 2, 2] + l2 * work3[2, 2, 2]
        if n_out == 1:
            out[0] = (s00 + s11 + s22) / 3.0
            return
        s01 = l0 * work3[0, 0, 1] + l1 * work3[1, 0, 1] + l2 * work3[2, 0, 1]
        s02 = l0 * work3[0, 0, 2] + l1 * work3[1, 0, 2] + l2 * work3[2, 0, 2]
        s12 = l0 * work3[0, 1, 2] + l1 * work3[1, 1, 2] + l2 * work3[2, 1, 2]
        t00 = s00 * frame[0, 0] + s01 * frame[1, 0] + s02 * frame[2, 0]
        t01 = s00 * frame[0, 1] + s01 * frame[1, 1] + s02 * frame[2, 1]
        t02 = s00 * frame[0, 2] + s01 * frame[1, 2] + s02 * frame[2, 2]
        t10 = s01 * frame[0, 0] + s11 * frame[1, 0] + s12 * frame[2, 0]
        t11 = s01 * frame[0, 1] + s11 * frame[1, 1] + s12 * frame[2, 1]
        t12 = s01 * frame[0, 2] + s11 * frame[1, 2] + s12 * frame[2, 2]
        t20 = s02 * frame[0, 0] + s12 * frame[1, 0] + s22 * frame[2, 0]
        t21 = s02 * frame[0, 1] + s12 * frame[1, 1] + s22 * frame[2, 1]
        t22 = s02 * frame[0, 2] + s12 * frame[1, 2] + s22 * frame[2, 2]
        out[0] = frame[0, 0] * t00 + frame[1, 0] * t10 + frame[2, 0] * t20
        out[1] = frame[0, 1] * t01 + frame[1, 1] * t11 + frame[2, 1] * t21
        out[2] = frame[0, 2] * t02 + frame[1, 2] * t12 + frame[2, 2] * t22
        out[3] = frame[0, 0] * t01 + frame[1, 0] * t11 + frame[2, 0] * t21
        out[4] = frame[0, 0] * t02 + frame[1, 0] * t12 + frame[2, 0] * t22
        out[5] = frame[0, 1] * t02 + frame[1, 1] * t12 + frame[2, 1] * t22
        return
    s00 = l0 * work2[0, 0, 0] + l1 * work2[1, 0, 0]
    s11 = l0 * work2[0, 1, 1] + l1 * work2[1, 1, 1]
    if n_out == 1:
        out[0] = (1.0 + nu) * (s00 + s11) / 3.0
        return
    s01 = l0 * work2[0, 0, 1] + l1 * work2[1, 0, 1]
    t00 = s00 * frame[0, 0] + s01 * frame[1, 0]
    t01 = s00 * frame[0, 1] + s01 * frame[1, 1]
    t10 = s01 * frame[0, 0] + s11 * frame[1, 0]
    t11 = s01 * frame[0, 1] + s11 * frame[1, 1]
    out[0] = frame[0, 0] * t00 + frame[1, 0] * t10
    out[1] = frame[0, 1] * t01 + frame[1, 1] * t11
    out[2] = frame[0, 0] * t01 + frame[1, 0] * t11


@njit(cache=True, nogil=True, inline="always")
def _contribution(sources, point, j, n_out, work3, work2, value):
    """``value[:n_out]``: the components at ``point`` of element ``j`` with its global DD
    ``sources.dd[j]``, contracted in the local frame before the one rotation."""
    frame = sources.frames[j]
    dd = sources.dd[j]
    _local_response(sources, point, j, work3, work2)
    l0 = frame[0, 0] * dd[0] + frame[0, 1] * dd[1]
    l1 = frame[1, 0] * dd[0] + frame[1, 1] * dd[1]
    l2 = 0.0
    if dd.shape[0] == 3:
        l0 += frame[0, 2] * dd[2]
        l1 += frame[1, 2] * dd[2]
        l2 = frame[2, 0] * dd[0] + frame[2, 1] * dd[1] + frame[2, 2] * dd[2]
    _components(work3, work2, dd.shape[0], l0, l1, l2, frame, n_out, sources.poisson_ratio, value)


@njit(cache=True, nogil=True, parallel=True)  # see _KERNEL_NOTE
def field_block(data, rows, cols, out):
    """Block generator kernel of the points x elements matrix (see
    :class:`hmatddm.hmatrix.BlockGenerator`): ``out[n_out * a + c, d * b + q]`` =
    component ``c`` at point ``rows[a]`` from a unit global DD component ``q`` of
    element ``cols[b]``. ``data``: :class:`FieldSources`; ``n_out`` (6, 3 or 1) is read
    from the shape of ``out``."""
    points = data.points
    dim = data.centers.shape[1]
    n_out = out.shape[0] // rows.shape[0]
    nu = data.poisson_ratio
    work3 = np.empty((3, 3, 3))
    work2 = np.empty((2, 2, 2))
    value = np.empty(6)
    for a in range(rows.shape[0]):
        point = points[rows[a]]
        for b in range(cols.shape[0]):
            j = cols[b]
            frame = data.frames[j]
            _local_response(data, point, j, work3, work2)
            for q in range(dim):
                # local components of the unit global DD q: column q of the frame
                _components(work3, work2, dim, frame[0, q], frame[1, q], frame[dim - 1, q], frame, n_out, nu,
                            value)
                for c in range(n_out):
                    out[n_out * a + c, dim * b + q] = value[c]


@njit(cache=True, nogil=True, parallel=True)  # see _KERNEL_NOTE
def contribution_block(data, rows, cols, out):
    """Block generator kernel of the points x elements matrix of given DDs, one column
    per element: ``out[n_out * a + c, b]`` = component ``c`` at point ``rows[a]`` of
    element ``cols[b]`` with its DD ``data.dd[cols[b]]``; the field is this matrix
    times a vector of ones."""
    n_out = out.shape[0] // rows.shape[0]
    work3 = np.empty((3, 3, 3))
    work2 = np.empty((2, 2, 2))
    value = np.empty(6)
    for a in range(rows.shape[0]):
        point = data.points[rows[a]]
        for b in range(cols.shape[0]):
            _contribution(data, point, cols[b], n_out, work3, work2, value)
            for c in range(n_out):
                out[n_out * a + c, b] = value[c]


@njit(cache=True, parallel=True)
def direct_sum(sources, out):
    """``out[t] = sum_j`` (stress at point ``t`` of element ``j`` with its global DD
    ``sources.dd[j]``), exact, ``n_out = out.shape[1]``. Each pair contracts its DD
    before the one rotation; parallel over a fixed split of the points, the sum over
    ``j`` in element order (the result does not depend on the thread count)."""
    points = sources.points
    m = points.shape[0]
    n_out = out.shape[1]
    n_chunks = min(_DIRECT_CHUNKS, m)
    for chunk in prange(n_chunks):
        work3 = np.empty((3, 3, 3))
        work2 = np.empty((2, 2, 2))
        value = np.empty(6)
        for t in range(chunk * m // n_chunks, (chunk + 1) * m // n_chunks):
            for c in range(n_out):
                out[t, c] = 0.0
            for j in range(sources.frames.shape[0]):
                _contribution(sources, points[t], j, n_out, work3, work2, value)
                for c in range(n_out):
                    out[t, c] += value[c]


# _KERNEL_NOTE: the block kernels hold no prange, but compiled with parallel=True (numba's
# parfor pipeline) they run ~3x faster per pair than with the default pipeline, like the
# exact sum (measured on the bench_fields.py 3D scene, 64-point blocks: 1.04 -> 0.36 s
# CPU); numba's warning that nothing was parallelised is silenced below.
warnings.filterwarnings("ignore", message=r"(?s).*The keyword argument 'parallel=True' was specified but no",
                        category=NumbaPerformanceWarning)


# ---------------------------------------------------------------------------- fields

def _check_common(mesh, material, singular_correction, near_fraction, quantity):
    if not isinstance(mesh, (Mesh2D, Mesh3D)):
        raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
    check_mesh(mesh)
    if getattr(mesh, "n_nodes", 1) > 1:
        raise InputError("StressField takes constant elements (element_order 0); linear and quadratic elements "
                         "are summed by hmatddm.nodal.stress_at")
    if not isinstance(material, Elastic):
        raise InputError(f"material must be an hmatddm.Elastic, got {type(material).__name__}")
    if singular_correction not in ("none", "average"):
        raise InputError(f"singular_correction must be one of ('none', 'average'), got {singular_correction!r}")
    near_fraction = finite_scalar("near_fraction", near_fraction)
    if not 0.0 <= near_fraction < 1.0:
        raise InputError(f"near_fraction must be in [0, 1), got {near_fraction}")
    if quantity not in QUANTITIES:
        raise InputError(f"quantity must be one of {QUANTITIES}, got {quantity!r}")
    return near_fraction


class StressField:
    """The stress that the DDs of ``mesh`` induce at fixed ``points``, ready to apply to
    any DDs (ref. Eq. 2.59).

    Parameters
    ----------
    mesh : Mesh2D or Mesh3D (constant elements)
    material : Elastic
    points : (M, d)
    quantity : ``"stress"`` (the global components, 6 in 3D, 3 in 2D) or ``"mean"``
    singular_correction, near_fraction : as :func:`hmatddm.stress_at`
    method : ``"auto"``, ``"direct"`` or ``"tree"`` (see :func:`hmatddm.stress_at`)
    eps : float in (0, 1) or None (``DEFAULT_STRESS_EPS``)
    dd : (N, d) or None
        None: the field applies to any DDs, ``field(dd)`` (the H-matrix has ``d`` columns
        per element, unit global DD components). Given: the field of these DDs only,
        ``field()``; the H-matrix has one column per element (what the element induces
        with its DD), so ``eps`` bounds each block's error relative to what its elements
        actually induce, and its ranks are those of the contracted sum (about a third).

    With ``"tree"`` and no ``dd`` the H-matrix is built once here (its build is most of
    the cost) and each call is one matvec; with ``dd`` the one-shot product
    (:func:`hmatddm.hmatrix.product.build_free_product`, nothing stored) is computed here
    and each call returns it; ``"direct"`` sums the kernels at every call.
    ``field(dd)`` returns the (M, n_out) components; ``field.info`` says what was done.
    """

    def __init__(self, mesh, material, points, quantity="stress", singular_correction="none", method="auto",
                 eps=None, near_fraction=0.0, dd=None):
        near_fraction = _check_common(mesh, material, singular_correction, near_fraction, quantity)
        if method not in METHODS:
            raise InputError(f"method must be one of {METHODS}, got {method!r}")
        eps = DEFAULT_STRESS_EPS if eps is None else finite_scalar("eps", eps)
        if not 0.0 < eps < 1.0:
            raise InputError(f"eps must be in (0, 1), got {eps}")
        self.mesh = mesh
        self.points = np.ascontiguousarray(finite_array("points", points, (None, mesh.dim)))
        self.n_out = n_components(mesh.dim, quantity)
        self.eps = float(eps)
        self.near_fraction = near_fraction
        self.contracted = dd is not None
        self.sources = field_sources(mesh, material, self.points, singular_correction, near_fraction,
                                     None if dd is None else _dd_array(mesh, dd))
        m, n = len(self.points), mesh.n_elements
        if method == "auto":
            method = "tree" if m * n >= AUTO_TREE_PAIRS and min(m, n) > 2 * FIELD_LEAF_SIZE else "direct"
        if min(m, n) <= FIELD_LEAF_SIZE:
            method = "direct"  # one leaf: nothing to compress
        self.method = method
        self.hmatrix = None
        started = time.perf_counter()
        self.info = {"method": method, "eps": self.eps, "points": m, "elements": n}
        self._product = None
        if method == "tree" and self.contracted:
            # one evaluation: the build-free product (ACA per far block, U (V^T 1) added
            # at once, nothing stored), computed here; the call returns it
            self._product = self._build_free()
        elif method == "tree":
            self.hmatrix = self._build()
            self.info.update(self._tree_info())
        else:
            self.info.update(n_far=0, n_near=1, pairs_exact=m * n, pairs_compressed=0)
        self.info["build_seconds"] = time.perf_counter() - started

    def _generator(self):
        from .hmatrix import BlockGenerator

        mesh = self.mesh
        kernel, col_dof = (contribution_block, 1) if self.contracted else (field_block, mesh.dim)
        return BlockGenerator(kernel, self.sources, self.points, 0.0, self.n_out, col_points=mesh.centers,
                              col_radii=mesh.radii, col_dof=col_dof)

    def _build(self):
        from .hmatrix import HMatrix

        return HMatrix.build(self._generator(), eps=self.eps, eta=FIELD_ETA, leaf_size=FIELD_LEAF_SIZE,
                             factor_dtype=np.float64)

    def _build_free(self):
        from .hmatrix.aca import ACA_TOLERANCE_FACTOR
        from .hmatrix.product import build_free_product

        generator = self._generator()
        values, counts = build_free_product(generator, np.ones(self.mesh.n_elements), ACA_TOLERANCE_FACTOR * self.eps,
                                            eta=FIELD_ETA, leaf_size=FIELD_LEAF_SIZE, min_aca_elements=FIELD_MIN_ACA)
        self.info.update(counts, build_free=True)
        return values.reshape(len(self.points), self.n_out)

    def _tree_info(self):
        h = self.hmatrix
        s = h.storage
        rows = h.tree.size[h.blocks.admissible_rows]
        cols = h.col_tree.size[h.blocks.admissible_cols]
        compressed = s.admissible_kind != 1  # low rank or zero (hmatrix.storage.KIND_DENSE = 1)
        pairs_compressed = int(np.sum(rows[compressed] * cols[compressed]))
        ranks = s.lowrank_rank
        return {"n_far": int(rows.size), "n_near": int(h.blocks.near_rows.size),
                "n_fallback": int(np.count_nonzero(~compressed)), "max_rank": int(ranks.max()) if ranks.size else 0,
                "pairs_compressed": pairs_compressed,
                "pairs_exact": len(self.points) * self.mesh.n_elements - pairs_compressed,
                "memory_bytes": int(s.memory_bytes)}

    def __call__(self, dd=None):
        """(M, n_out) components induced by the global DDs ``dd`` ((N, d) or (N*d,);
        omitted for a field built with its ``dd``)."""
        if self.contracted and dd is not None:
            raise InputError("this StressField was built for its own dd; call it without dd")
        if not self.contracted and dd is None:
            raise InputError("dd is required: this StressField applies to any DDs")
        started = time.perf_counter()
        m = len(self.points)
        sources = self.sources if dd is None else self.sources._replace(dd=_dd_array(self.mesh, dd))
        if m == 0:
            out = np.zeros((0, self.n_out))
        elif self._product is not None:
            out = self._product.copy()
        elif self.hmatrix is not None:
            x = np.ones(self.mesh.n_elements) if self.contracted else sources.dd.reshape(-1)
            out = self.hmatrix.matvec(x).reshape(m, self.n_out)
        else:
            out = np.empty((m, self.n_out))
            direct_sum(sources, out)
        self.info["apply_seconds"] = time.perf_counter() - started
        return out


def as_tensors(values):
    """(M, d, d) symmetric tensors from (M, 6) components (xx, yy, zz, xy, xz, yz) or
    (M, 3) (xx, yy, xy)."""
    if values.shape[1] == 6:
        return values[:, [0, 3, 4, 3, 1, 5, 4, 5, 2]].reshape(-1, 3, 3)
    return values[:, [0, 2, 2, 1]].reshape(-1, 2, 2)


def _dd_array(mesh, dd):
    """``dd`` as a contiguous (N, d) float64 array ((N, d) or (N*d,) given)."""
    dd = finite_array("dd", dd)
    if dd.shape not in ((mesh.n_elements, mesh.dim), (mesh.n_elements * mesh.dim,)):
        raise InputError(f"dd must have shape ({mesh.n_elements}, {mesh.dim}) or "
                         f"({mesh.n_elements * mesh.dim},), got {dd.shape}")
    return np.ascontiguousarray(dd.reshape(mesh.n_elements, mesh.dim), dtype=np.float64)


def refuse_singular(values, near_fraction):
    """InputError naming the first point whose value is singular (NaN: on an edge, or
    within ``near_fraction`` of one, without ``singular_correction='average'``)."""
    bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
    if bad.size:
        where = "on an element edge" if near_fraction == 0.0 else \
            f"on an element edge or within near_fraction = {near_fraction:g} half sizes of one"
        raise InputError(f"points[{int(bad[0])}] lies {where}, where the stress is singular; "
                         "move it or pass singular_correction='average'")


def induced(mesh, material, dd, points, quantity, singular_correction="none", method="auto", eps=None, info=None,
            near_fraction=0.0):
    """(M, n_out) components of ``quantity`` induced at ``points`` by ``dd``, singular
    points refused; what :func:`hmatddm.stress_at` and :func:`hmatddm.mean_stress_at`
    compute for constant elements in a homogeneous medium."""
    started = time.perf_counter()
    field = StressField(mesh, material, points, quantity, singular_correction, method, eps, near_fraction, dd=dd)
    values = field()
    if info is not None:
        info.update(field.info, seconds=time.perf_counter() - started)
    refuse_singular(values, field.near_fraction)
    return values


__all__ = ["StressField", "as_tensors", "FieldSources", "field_sources", "field_block", "contribution_block", "direct_sum", "induced", "refuse_singular", "n_components",
           "DEFAULT_STRESS_EPS", "AUTO_TREE_PAIRS", "FIELD_ETA", "FIELD_LEAF_SIZE", "FIELD_MIN_ACA", "METHODS", "QUANTITIES"]
