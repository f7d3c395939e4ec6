"""Stress fields: the stress that the DDs of a mesh induce at points (ref. Eq. 2.59; mean
stress ref. Eqs 5.24-5.28), for the results (:func:`hmatddm.stress_at`,
:func:`hmatddm.mean_stress_at`) and the remote-failure check of a natural-fracture
network (ref. Sec. 5.3).

The stress at M points from N elements is a points x elements matrix applied to the DDs:
row ``n_out * t + c`` is component ``c`` of the stress at point ``t`` (3D: xx, yy, zz, xy,
xz, yz; 2D plane strain: xx, yy, xy; or the mean stress alone, ``n_out = 1``), column
``d * j + q`` the global DD component ``q`` of element ``j`` (or, for given DDs, one
column per element: what it induces with its DD). Its entries come from
:mod:`hmatddm.elasticity.field_kernels` (the per-pair kernels of :mod:`hmatddm.kernels`, contracted
with a local DD and rotated to the global frame, ref. Eq. 2.57). Two ways to apply it:

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

import numpy as np

from .._validation import finite_array, finite_scalar
from ..errors import InputError
from .field_kernels import FieldSources, contribution_block, direct_sum, field_block, field_sources
from ..material import Elastic
from ..mesh import Mesh2D, Mesh3D, check_mesh

#: What a field holds at each point ("displacement": ref. Eqs 2.43, 2.55-2.57, the kernels
#: of :mod:`hmatddm.elasticity.displacement_kernels`).
QUANTITIES = ("stress", "mean", "displacement")
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


def n_components(dim, quantity):
    """Values per point: 6 (3D) or 3 (2D) stress components, 1 for the mean stress, d
    displacement components."""
    if quantity == "displacement":
        return dim
    return 1 if quantity == "mean" else (6 if dim == 3 else 3)


def _kernels(quantity):
    """(contribution_block, field_block, direct_sum) of ``quantity``."""
    if quantity == "displacement":
        from . import displacement_kernels as k

        return k.contribution_block, k.field_block, k.direct_sum
    return contribution_block, field_block, direct_sum


# ---------------------------------------------------------------------------- fields

def _check_common(mesh, material, singular_correction, near_fraction, quantity):
    if not isinstance(mesh, (Mesh2D, Mesh3D)):
        raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
    check_mesh(mesh)
    if getattr(mesh, "n_nodes", 1) > 1:
        raise InputError("StressField takes constant elements (element_order 0); linear and quadratic elements "
                         "are summed by hmatddm.elasticity.nodal.stress_at")
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
        self.quantity = quantity
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
        from ..hmatrix import BlockGenerator

        mesh = self.mesh
        contribution, unit_dd, _ = _kernels(self.quantity)
        kernel, col_dof = (contribution, 1) if self.contracted else (unit_dd, mesh.dim)
        return BlockGenerator(kernel, self.sources, self.points, 0.0, self.n_out, col_points=mesh.centers,
                              col_radii=mesh.radii, col_dof=col_dof)

    def _build(self):
        from ..hmatrix import HMatrix

        return HMatrix.build(self._generator(), eps=self.eps, eta=FIELD_ETA, leaf_size=FIELD_LEAF_SIZE,
                             factor_dtype=np.float64)

    def _build_free(self):
        from ..hmatrix.aca import ACA_TOLERANCE_FACTOR
        from ..hmatrix.product import build_free_product

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
            _kernels(self.quantity)[2](sources, out)
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


def refuse_singular(values, near_fraction, quantity="stress"):
    """InputError naming the first point whose value is singular (NaN: on an edge, or
    within ``near_fraction`` of one, without ``singular_correction='average'``)."""
    bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
    if bad.size and quantity == "displacement":
        raise InputError(f"points[{int(bad[0])}] lies on an element edge, where the displacement is singular; "
                         "move it")
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
    refuse_singular(values, field.near_fraction, quantity)
    return values


def displacement_at(mesh, material, dd, points, method="auto", eps=None, info=None):
    """Displacement (M, d) induced at ``points`` (M, d) by the DDs ``dd`` (global frame,
    (N, d) or (N*d,)) of the constant elements of ``mesh`` in ``material`` (ref. Eqs 2.43,
    2.55-2.57; 2D: the in-plane components of plane strain).

    The far-field displacement decays as 1/r^2 (3D; 1/r in 2D) where the stress decays
    as 1/r^3 (1/r^2): a tiltmeter or a GPS station sees it far from the fracture. On an
    element's face the value is its ``+`` side's (the side its normal points to; the
    displacement jumps by the DD across it); a point on an element edge (an end in 2D),
    where it is log-singular, raises InputError. ``method``, ``eps`` and ``info``: as
    :func:`hmatddm.stress_at` (``"tree"``: the build-free product of a rectangular
    H-matrix, whose far blocks are compressed to ``eps``).

    A :class:`hmatddm.LayeredMedium` (ref. Ch. 3): the closed form of each element's
    layer plus its image terms (:mod:`hmatddm.layered.displacement`), summed directly
    like the layered stress at points (``method="tree"`` is refused, ``eps`` unused); a
    point on the free surface is in the rock, a point inside a void layer is refused.
    """
    from ..layered.medium import LayeredMedium

    if isinstance(material, LayeredMedium):
        if method not in METHODS:
            raise InputError(f"method must be one of {METHODS}, got {method!r}")
        if method == "tree":
            raise InputError("method='tree' is not available in a LayeredMedium: its displacement (like its stress "
                             "at points) is summed directly; pass method='direct' or 'auto'")
        if not isinstance(mesh, (Mesh2D, Mesh3D)):
            raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
        from ..layered.displacement import displacement_at as layered_displacement_at

        started = time.perf_counter()
        values = layered_displacement_at(mesh, material, dd, points)
        if info is not None:
            info.update(method="direct", points=len(values), elements=mesh.n_elements,
                        seconds=time.perf_counter() - started)
        return values
    return induced(mesh, material, dd, points, "displacement", "none", method, eps, info)


__all__ = ["displacement_at", "StressField", "as_tensors", "FieldSources", "field_sources", "field_block", "contribution_block", "direct_sum", "induced", "refuse_singular", "n_components",
           "DEFAULT_STRESS_EPS", "AUTO_TREE_PAIRS", "FIELD_ETA", "FIELD_LEAF_SIZE", "FIELD_MIN_ACA", "METHODS", "QUANTITIES"]
