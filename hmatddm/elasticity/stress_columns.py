"""The stress that each element of a growing 3D mesh induces at fixed points in a
:class:`hmatddm.LayeredMedium`, kept element by element across calls: the remote-failure
check of a layered run (:meth:`hmatddm.simulation.natural.NaturalNetwork.induced_stress`).

Why: where the layers differ in their moduli, the check evaluates the induced stress at
every intact natural element (the rigorous screen of :mod:`.field_bound` holds for a
homogeneous kernel only) with the image terms (:func:`hmatddm.layered.influence3d.stress_at`,
a direct sum, hundreds of microseconds per point and element), at every growth pass. The
stress is linear in the DDs and each element's term depends on that element alone, so the
terms of the elements a check has seen are kept (one (6, 3) block per point and element: the
stress of a term is symmetric to the bit, the same expression gives ``ik`` and ``ki``, so its
six components are kept and mirrored) and a later check computes only the terms of the
elements appended since, then contracts the kept terms with the current DDs. The stage scene
with stiffer bounding layers (issue 35): every check recomputed 20-500 elements at 2074
points; now each element is computed once per run (benchmarks/RESULTS.md, issue 35).

The terms are those of the direct sum (:func:`hmatddm.layered.stress3d.stress_columns`,
the per-pair function :func:`hmatddm.layered.stress3d.stress_points` sums, each source traced
once, vertical sources in closed form), so the stress is the direct sum's up to the order of
the additions (1e-16 relative). A mesh that is not the
last one plus appended elements (same first elements, bit for bit), another medium, number
of images, correction or set of points starts again; points outside the first call's set
start again too (the intact set only shrinks in a run). Above :data:`MEMORY_BUDGET` bytes
of terms the caller sums directly (:meth:`StressColumns.reuse` returns None).
"""
import numpy as np

from ..errors import InputError
from ..options import AVERAGE_SHIFT

#: Largest size (bytes) of the kept terms (points x elements x 18 float64); beyond it
#: :meth:`StressColumns.reuse` returns None and the caller sums directly. 4 GiB: a sixth
#: of the project's 24 GiB machine; the larger stage of issue 35 with its stiff layers
#: (2092 elements at ~8300 natural targets) keeps 2.5 GB (benchmarks/RESULTS.md).
MEMORY_BUDGET = 4 << 30
#: The six independent components of the symmetric stress (xx, yy, zz, xy, xz, yz) and,
#: for each of the nine (i, k), which of the six it is.
_SYMMETRIC = np.array([0, 4, 8, 1, 2, 5])
_FULL = np.array([0, 3, 4, 3, 1, 5, 4, 5, 2])

__all__ = ["StressColumns", "MEMORY_BUDGET"]


def _geometry(mesh):
    return mesh.centers, mesh.frames, mesh.half_a, mesh.half_b


class StressColumns:
    """The kept terms of the elements seen so far, at the points ``points[rows]``.

    Build with :meth:`reuse` (which starts, extends or refuses), then :meth:`stress`."""

    def __init__(self, points, rows, medium, n_images, singular_correction, near_fraction):
        self.points = points
        self.rows = rows
        self.key = self._key(medium, n_images, singular_correction, near_fraction)
        self.medium = medium
        self.n_images = int(n_images)
        self.singular_correction = singular_correction
        self.near_fraction = float(near_fraction)
        self.point_layer = np.ascontiguousarray(medium.layer_of(points[rows, 2]), dtype=np.int64)
        self.geometry = tuple(np.zeros((0,) + shape) for shape in ((3,), (3, 3), (), ()))
        #: (start, stop, terms (len(rows), 6, 3 (stop - start))) per batch of elements
        self.blocks = []
        #: elements computed over the object's life (the cost)
        self.computed = 0

    @staticmethod
    def _key(medium, n_images, singular_correction, near_fraction):
        return (id(medium), medium.interfaces, medium.shear_modulus, medium.poisson_ratio, medium.images,
                medium.gauss_points, medium.method, int(n_images), singular_correction, float(near_fraction))

    @property
    def n_elements(self):
        return self.geometry[0].shape[0]

    @classmethod
    def reuse(cls, previous, mesh, medium, points, rows, n_images, singular_correction, near_fraction):
        """``previous`` when it can serve ``mesh`` at ``points[rows]``, else a new one, or
        None where the terms are not kept (a 2D mesh, ``n_images`` None, the terms would
        exceed :data:`MEMORY_BUDGET`): the caller sums directly."""
        if mesh.dim != 3 or n_images is None or getattr(mesh, "element_order", 0) != 0:
            return None
        rows = np.asarray(rows, dtype=np.int64)
        if rows.size * mesh.n_elements * 18 * 8 > MEMORY_BUDGET:
            return None
        if previous is not None and previous.serves(mesh, medium, points, rows, n_images, singular_correction,
                                                    near_fraction):
            return previous
        return cls(np.asarray(points, dtype=float), rows.copy(), medium, n_images, singular_correction, near_fraction)

    def serves(self, mesh, medium, points, rows, n_images, singular_correction, near_fraction):
        """Whether ``mesh`` extends the elements seen (the same first ones, bit for bit),
        in the same medium, images and correction, at points among the kept ones."""
        if self._key(medium, n_images, singular_correction, near_fraction) != self.key:
            return False
        if points is not self.points and not np.array_equal(points, self.points):
            return False
        if mesh.n_elements < self.n_elements or not np.all(np.isin(rows, self.rows)):
            return False
        n0 = self.n_elements
        return all(np.array_equal(now[:n0], seen) for now, seen in zip(_geometry(mesh), self.geometry))

    def _extend(self, mesh):
        """Compute the terms of the elements appended since the last call."""
        n0, n = self.n_elements, mesh.n_elements
        if n == n0:
            return
        from ..layered.influence3d import influence_data
        from ..layered.stress3d import stress_columns

        new = mesh.subset(np.arange(n0, n))
        shift = AVERAGE_SHIFT if self.singular_correction == "average" else 0.0
        # built as hd.stress_at builds it (influence3d._prepared): the closed forms that need
        # images are chosen with the number of images
        data = influence_data(new, self.medium, shift, 0.0, self.near_fraction, int(self.n_images), with_table=False)
        terms = stress_columns(data, self.points[self.rows], self.point_layer)  # [m, k, u, a, b]
        m = len(self.rows)  # [m, k, u, a, b] -> [m, a b, k u], the six of the symmetric stress
        terms = terms.transpose(0, 3, 4, 1, 2).reshape(m, 9, 3 * (n - n0))
        self.blocks.append((n0, n, np.ascontiguousarray(terms[:, _SYMMETRIC])))
        del terms
        self.geometry = tuple(np.array(array) for array in _geometry(mesh))
        self.computed += n - n0

    def stress(self, mesh, dd, rows):
        """(len(rows), 3, 3): the stress the DDs ``dd`` (N, 3) of ``mesh`` induce at
        ``points[rows]``; InputError naming a point where it is singular (as
        :func:`hmatddm.kernels.drivers.finite_stress_sum`)."""
        self._extend(mesh)
        dd = np.asarray(dd, dtype=float).reshape(mesh.n_elements, 3)
        total = np.zeros((len(self.rows), 6))
        for start, stop, terms in self.blocks:
            total += terms @ dd[start:stop].reshape(-1)
        total = total[:, _FULL]
        index = np.searchsorted(self.rows, rows) if np.all(self.rows[:-1] <= self.rows[1:]) else \
            np.array([np.flatnonzero(self.rows == r)[0] for r in rows], dtype=np.int64)
        out = total[index].reshape(-1, 3, 3)
        bad = np.flatnonzero(~np.all(np.isfinite(out.reshape(len(out), -1)), axis=1))
        if bad.size:
            raise InputError(f"points[{int(bad[0])}] lies on an element edge, where the stress is singular; move it "
                             "or pass singular_correction='average'")
        return out
