"""A fracture front located inside the tip elements of a planar fracture on a square grid
(implicit level set, Peirce and Detournay 2008; the approach of planar-3D level-set
simulators such as PyFrac).

Each *ribbon* element ``r`` (a fully fractured element next to the front) carries the
distance ``s_r`` from its centre to the front, found by inverting the tip asymptote
(:mod:`.tip_asymptote`) from its opening. The signed distance ``phi`` (negative inside)
is ``-s_r`` at the ribbon centres and solves the eikonal equation ``|grad phi| = 1``
elsewhere (:class:`FrontField`: first-order fast marching on the cell centres (:mod:`.fast_marching`), outward
through the cells that are not fully fractured and inward through those that are; the
upwind update is exact for a straight front in any direction, so the front does not
favour the grid axes), bilinear between the centres; or, in 3D with ``order = 2``, the front
reconstructed from the ribbon to second order (:mod:`.front_fit`: the ribbon's tangent points,
local curvatures, blended osculating circles; the first-order march puts a convex front
~0.25 ``s_r h / R`` too near, issue 39). A *tip* element is crossed by the
front: its filled fraction and its mean opening (the asymptote ``w(-phi, V)`` averaged
over the whole element, zero outside the front; ``V`` of the nearest ribbon) come from
``n_sub^k`` sample points (``k`` = 2 in 3D, 1 in 2D). Its fluid volume is that mean opening times its area, and its flow faces carry
that opening: the partial element is exactly as wide, on average, as the asymptote.

:class:`PlanarGrid` maps the elements of one planar fracture (3D: equal squares on a
grid; 2D: equal segments on a line) to integer cells and back.
"""
import numpy as np

from ..errors import InputError
from ..mesh import Mesh2D, Mesh3D
from .fast_marching import first_nearest, interpolate, march, nearest_circle
from .front_fit import BAND, MIN_RIBBON, FrontReconstruction

CHANNEL, TIP, EMPTY, FILLED = 0, 1, 2, 3  # FILLED: fully fractured during the last step

#: Nearest-ribbon candidates a k-d tree proposes (FrontField.velocity): a point is at most
#: 4 lattice points' equal nearest (a cell corner), so every tie is among them.
NEAREST_CANDIDATES = 4
#: Below this many (point, ribbon) pairs the brute-force search is as fast.
BRUTE_FORCE_PAIRS = 200_000


class PlanarGrid:
    """The square (3D) or segment (2D) grid of one planar fracture's elements.

    ``k`` in-plane dimensions (2 in 3D, 1 in 2D); element centres are ``origin + h
    (i e_1 [+ j e_2])``. Raises InputError when the mesh is not one planar fracture of
    equal, aligned elements.
    """

    def __init__(self, mesh, tolerance=1e-6):
        self.dim = mesh.dim
        frame = mesh.frames[0]
        if isinstance(mesh, Mesh3D):
            self.k = 2
            h = 2.0 * float(mesh.half_a[0])
            if not (np.allclose(mesh.half_a, h / 2, rtol=tolerance) and np.allclose(mesh.half_b, h / 2, rtol=tolerance)):
                raise InputError("propagation.front = 'asymptotic' needs square elements of one size "
                                 "(initial_fracture with length and height multiples of element_size)")
            self.axes = frame[:2].copy()
        elif isinstance(mesh, Mesh2D):
            self.k = 1
            h = 2.0 * float(mesh.half_length[0])
            if not np.allclose(mesh.half_length, h / 2, rtol=tolerance):
                raise InputError("propagation.front = 'asymptotic' needs segments of one size")
            self.axes = frame[:1].copy()
        else:
            raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
        self.normal = frame[-1].copy()
        if np.unique(mesh.fracture_id).size != 1:
            raise InputError("propagation.front = 'asymptotic' supports one planar fracture "
                             f"(the mesh holds {np.unique(mesh.fracture_id).size})")
        if not np.allclose(mesh.frames, frame[None], atol=tolerance):
            raise InputError("propagation.front = 'asymptotic' supports planar fractures only: "
                             "every element must have the same frame")
        self.h = h
        self.origin = mesh.centers[0].copy()
        offsets = mesh.centers - self.origin
        if np.max(np.abs(offsets @ self.normal)) > tolerance * h:
            raise InputError("propagation.front = 'asymptotic' supports planar fractures only")
        index = offsets @ self.axes.T / h
        if np.max(np.abs(index - np.round(index))) > 1e-4:
            raise InputError("propagation.front = 'asymptotic': the elements are not on one square grid")

    def plane(self, points):
        """In-plane coordinates (M, k) of 3D/2D points."""
        return (np.asarray(points, float) - self.origin) @ self.axes.T

    def cells(self, points):
        """Integer cells (M, k) of points on the grid."""
        return np.round(self.plane(points) / self.h).astype(np.int64)

    def centers(self, cells):
        """Global centres (M, d) of cells (M, k)."""
        return self.origin + (np.asarray(cells, float) * self.h) @ self.axes

    def key(self, cells):
        cells = np.asarray(cells, np.int64).reshape(-1, self.k)
        if self.k == 1:
            return cells[:, 0]
        return cells[:, 0] * 2_000_003 + cells[:, 1]

    def neighbours(self, cells):
        """(M, 2k, k) the edge neighbours of each cell."""
        steps = np.concatenate([np.eye(self.k, dtype=np.int64), -np.eye(self.k, dtype=np.int64)])
        return np.asarray(cells, np.int64)[:, None, :] + steps[None]

    def elements(self, cells, template):
        """A mesh of new elements at ``cells``, frames and sizes of ``template`` element 0."""
        m = len(cells)
        centers = self.centers(cells)
        if self.k == 2:
            return Mesh3D(centers, np.repeat(template.frames[:1], m, axis=0), np.full(m, self.h / 2),
                          np.full(m, self.h / 2), np.full(m, template.fracture_id[0], np.int64))
        return Mesh2D(centers, np.repeat(template.frames[:1], m, axis=0), np.full(m, self.h / 2),
                      np.full(m, template.fracture_id[0], np.int64))


def level_set(points, centers, distances):
    """``min_r (|x - x_r| - s_r)`` and the arg-min ``r`` (points (M, k), in plane): the
    distance to a union of circles (used for nearest ribbons and in tests; compiled,
    :func:`.fast_marching.nearest_circle`)."""
    points = np.ascontiguousarray(points, float).reshape(len(points), -1)
    centers = np.ascontiguousarray(centers, float).reshape(len(centers), -1)
    return nearest_circle(points, centers, np.ascontiguousarray(distances, float))


class FrontField:
    """The signed distance to the front (negative inside) from ribbon distances.

    Parameters
    ----------
    cells : (R, k) int, the ribbon cells;  distances : (R,) ``s_r``;  velocities : (R,)
    channel : (C, k) int, the fully fractured cells (the ribbon among them or not)
    h : cell size;  margin : cells marched beyond the ribbon (>= the farthest front + 2)
    order : 1, the first-order march, bilinear between cell centres; 2 (3D only): the front
    reconstructed from the ribbon to second order (:mod:`.front_fit`), evaluated at the points
    themselves and at the cell centres (``phi``) within ``BAND`` cells of the front (beyond: the
    march; the bilinear march selects)
    """

    def __init__(self, cells, distances, velocities, channel, h, margin, order=1):
        cells = np.asarray(cells, np.int64)
        self.k = cells.shape[1]
        self.h = float(h)
        self.ribbon_points = cells * self.h
        self.distances = np.asarray(distances, float)
        self.velocities = np.asarray(velocities, float)
        margin = int(margin)
        self.low = cells.min(axis=0) - margin
        shape = tuple(cells.max(axis=0) + margin - self.low + 1)
        phi = np.full(shape, np.inf)
        inside = np.zeros(shape, bool)
        channel = np.asarray(channel, np.int64).reshape(-1, self.k) - self.low
        in_box = np.all((channel >= 0) & (channel < np.array(shape)), axis=1)
        inside[tuple(channel[in_box].T)] = True
        known = np.zeros(shape, bool)
        ribbon = tuple((cells - self.low).T)
        known[ribbon] = True
        inside[ribbon] = True
        phi[ribbon] = -self.distances
        march(phi, known, ~inside, self.h)              # outward, phi increasing
        inward = np.where(known, -phi, np.inf)
        march(inward, known, inside & ~known, self.h)   # inward, -phi increasing
        phi[inside & ~known] = -inward[inside & ~known]
        unreached = ~np.isfinite(phi)
        phi[unreached & inside] = -np.inf
        self._front = None
        if order == 2 and self.k == 2 and len(cells) >= MIN_RIBBON:  # else the march (MIN_RIBBON)
            self._front = FrontReconstruction(self.ribbon_points, self.distances, phi, cells - self.low, self.h)
            near = np.abs(phi) < BAND * self.h  # the march beyond (front_fit.BAND)
            index = np.argwhere(near)
            phi[near] = self._front((index + self.low) * self.h)
        elif order not in (1, 2):
            raise ValueError(f"FrontField order must be 1 or 2, got {order}")
        self.order = order
        self.phi = phi  # +inf: beyond the march (outside), -inf: inside, unreached
        self._tree = None  # a k-d tree of the ribbon points (velocity), made on first use

    def at_cells(self, cells):
        """``phi`` at cell centres (M, k) (+inf outside the box)."""
        index = np.asarray(cells, np.int64).reshape(-1, self.k) - self.low
        ok = np.all((index >= 0) & (index < np.array(self.phi.shape)), axis=1)
        out = np.full(len(index), np.inf)
        out[ok] = self.phi[tuple(index[ok].T)]
        return out

    def __call__(self, points):
        """``phi`` at in-plane points (M, k), (multi)linear between cell centres (compiled:
        :func:`.fast_marching.interpolate`; +inf outside the box)."""
        points = np.asarray(points, float).reshape(-1, self.k)
        phi, low = self.phi, self.low.astype(float)
        if self.k == 1:
            phi, low = phi.reshape(-1, 1), np.append(low, 0.0)
            points = np.column_stack([points, np.zeros(len(points))])
        out = np.empty(len(points))
        interpolate(phi, low, self.h, np.ascontiguousarray(points), out)
        if self._front is not None:  # order 2: the reconstruction near the front (front_fit.BAND)
            near = np.abs(out) < BAND * self.h
            out[near] = self._front(points[near])
        return out

    def velocity(self, points):
        """``V`` of the ribbon nearest each point (the first ribbon of the nearest, as
        :func:`level_set` takes it: a k-d tree proposes the :data:`NEAREST_CANDIDATES`
        nearest, among which no lattice point has a tie left out, and the exact distances
        choose; the brute-force search cost points x ribbons, 10% of a 0.25 m radial run)."""
        import scipy.spatial

        points = np.ascontiguousarray(points, float).reshape(-1, self.k)
        ribbon = np.ascontiguousarray(self.ribbon_points, float)
        k = min(NEAREST_CANDIDATES, len(ribbon))
        if len(points) * len(ribbon) <= BRUTE_FORCE_PAIRS or k < NEAREST_CANDIDATES:
            _, nearest = level_set(points, ribbon, np.zeros(len(ribbon)))
            return self.velocities[nearest]
        if self._tree is None:
            self._tree = scipy.spatial.cKDTree(ribbon)
        _, candidates = self._tree.query(points, k=k)
        return self.velocities[first_nearest(points, ribbon, np.ascontiguousarray(candidates, np.int64))]


def sample_offsets(k, n_sub):
    """Midpoints of ``n_sub^k`` sub-cells of a unit cell centred at 0, then its 2^k corners."""
    u = (np.arange(n_sub) + 0.5) / n_sub - 0.5
    if k == 1:
        return u[:, None], np.array([[-0.5], [0.5]])
    x, y = np.meshgrid(u, u, indexing="ij")
    corners = np.array([[-0.5, -0.5], [-0.5, 0.5], [0.5, -0.5], [0.5, 0.5]])
    return np.column_stack([x.ravel(), y.ravel()]), corners


def fill(cells, field, asymptote, n_sub=8, length=np.inf, full_widths=True):
    """Filled fraction, mean opening and "fully inside" of cells (M, k) of the grid.

    The mean opening is the asymptote ``w(-phi, V)`` (with the finite-fracture factor of
    ``length``, :func:`~hmatddm.analytical.tip_asymptote.finite_fracture_factor`) averaged over
    the cell's sample points, zero outside the front. ``full_widths=False``: not evaluated
    for the cells fully inside (0 there), whose opening a caller that does not prescribe it
    never reads (the 3D asymptotic front: a third of the fill's inversions of the asymptote).
    """
    cells = np.asarray(cells, np.int64).reshape(-1, field.k)
    k, h = field.k, field.h
    inner, corners = sample_offsets(k, n_sub)
    m, n_s = len(cells), len(inner)
    centre = cells * h
    points = (centre[:, None, :] + h * inner[None]).reshape(-1, k)
    phi = field(points)
    inside = phi < 0.0
    fraction = inside.reshape(m, n_s).mean(axis=1)
    corner_phi = field((centre[:, None, :] + h * corners[None]).reshape(-1, k))
    full = (fraction == 1.0) & np.all(corner_phi.reshape(m, len(corners)) < 0.0, axis=1)
    wanted = inside if full_widths else inside & ~np.repeat(full, n_s)
    width = np.zeros(len(points))
    if np.any(wanted):
        width[wanted] = asymptote.width(-phi[wanted], field.velocity(points[wanted]), length=length)
    mean_width = width.reshape(m, n_s).mean(axis=1)
    return fraction, mean_width, full


def front_radii(center, field, n_rays=180, step=0.05):
    """Distance from ``center`` (in plane, (2,)) to the front along ``n_rays`` rays (3D):
    the farthest point with ``phi < 0`` (sampled every ``step`` cells, then bisection)."""
    d = np.linalg.norm(field.ribbon_points - center, axis=1)
    r_lo = max(0.0, float(np.min(d)))
    r_hi = float(np.max(d + field.distances)) + 2.0 * field.h
    angles = np.linspace(0.0, 2.0 * np.pi, n_rays, endpoint=False)
    direction = np.column_stack([np.cos(angles), np.sin(angles)])
    n_r = int(np.ceil((r_hi - r_lo) / (step * field.h))) + 2
    radius = np.linspace(r_lo, r_hi, n_r)
    points = center + radius[None, :, None] * direction[:, None, :]
    inside = (field(points.reshape(-1, 2)) < 0.0).reshape(n_rays, n_r)
    last = n_r - 1 - np.argmax(inside[:, ::-1], axis=1)
    lo, hi = radius[last], radius[np.minimum(last + 1, n_r - 1)]
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        phi = field(center + mid[:, None] * direction)
        lo, hi = np.where(phi < 0.0, mid, lo), np.where(phi < 0.0, hi, mid)
    return 0.5 * (lo + hi)
