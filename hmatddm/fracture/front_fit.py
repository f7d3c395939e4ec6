"""A second-order signed distance to a 3D planar fracture's front from its ribbon (issue 39):
the front reconstructed from the ribbon's own distances, not marched from them.

Why: first-order fast marching (:mod:`.fast_marching`) from ribbon centres ``s_r`` behind a
convex front of radius ``R`` puts the front too near by ~0.25 ``s_r h / R``, and the bilinear
interpolation between cell centres adds ~``h^2 / (12 R)`` (the signed distance's Hessian
``1/R`` across the front); both are ``O(h^2 / R)``, a front error in elements that falls only
as ``h / R`` (benchmarks/RESULTS.md, issue 39, "why the far ribbon fails at a 3D toughness
tip"). Here, for any smooth front:

1. **Front points.** Ribbon ``r`` (centre ``x_r``, distance ``s_r``) says the front is tangent
   to the circle of radius ``s_r`` about ``x_r``; the tangent point is ``p_r = x_r + s_r n_r``,
   ``n_r`` the outward normal there. A normal off by an angle ``e`` moves ``p_r`` along that
   circle, ``s_r e^2 / 2`` inside the front: the point is second order in ``e`` (the envelope of
   the ribbon's circles, as in Sethian 1999, "Level set methods and fast marching methods",
   section on building extension velocities from the front).
2. **Normals and curvatures** (:func:`fit_front`): the first normals are the first-order field's
   gradient at the ribbon centres (:func:`ribbon_normals`, central differences); then, in the
   frame ``(n_r, t_r)`` of each front point, the point itself and its neighbours (within
   ``FIT_RADIUS`` and facing the same way) are fitted in weighted least squares by the graph
   ``u = c + b t - (kappa/2) t^2`` (a local quadratic regression, as in moving least squares);
   ``b`` turns the normal, ``kappa`` is the curvature of the graph (``kappa / (1 + b^2)^(3/2)``
   in the turned frame) and the front points are placed again (``FIT_PASSES`` passes); each
   front point stays on its own ribbon's circle (``c`` is not applied: ``SMOOTH_POINTS``). The
   graph's ``t^3`` term is the error: ``O(h / R^2)`` in the curvature, ``O(h^2 / R^2)`` in the
   normal. Why a regression, and why the points are not moved by it (both measured on radial
   runs, issue 39): the curvature of a graph pinned at a point through its neighbours follows
   that point's noise (the simulator's ``s_r`` carry a few 0.01 h from the ribbon's
   inversion) and the 0.25 m radial-k front iteration stalled at 0.1-0.3 elements for 40
   iterations; with the points moved onto the regression a ribbon's own ``s_r`` barely moves
   the front (the regression averages it out), the zigzag of the ribbon's distances is left
   free, and the 0.5 m radial-km run took minutes of front iterations instead of 15 s. Each
   point on its own circle, the curvature and normal from the regression: both converge.
   With fewer than three neighbours: the graph through the point (two), a line (one).
3. **The signed distance** at a point ``y`` (:func:`blend`): the exact signed distance to
   each of the ``BLEND`` nearest front points' osculating circles,

       ``phi_j = (2 d + kappa (d^2 + t^2)) / (1 + ((1 + kappa d)^2 + (kappa t)^2)^(1/2))``

   (``d``, ``t``: ``y - p_j`` along the normal and the tangent; ``|y - c| - 1/kappa`` for a
   circle of centre ``c``, either sign of ``kappa``, ``d`` at ``kappa = 0``; no division by
   ``kappa`` and a denominator >= 1), blended with the weights ``(1 - (r_j / D)^2)^2``, ``r_j``
   the distance to ``p_j`` and ``D`` to the ``BLEND + 1``-th nearest (continuous where the
   nearest set changes); front points whose normal faces away from the nearest one's (the
   other side of a narrow fracture) are left out. The error: the curve against its osculating
   circle over ``~h``, ``O(h^3 / R^2)``, second order in ``h / R`` in elements.

For a circle with exact ``s_r`` the front is then within ~1e-3 h at R = 10 h, ~1e-5 h at 40 h
(the first-order march: 0.04-0.09 h, 0.01-0.02 h; tests/fracture/test_front.py). The front of a plane-strain fracture (one point per tip) is
exact with the first-order march, so only 3D uses this.
"""
import math

import numpy as np
from numba import njit

#: Neighbouring front points fitted per ribbon (a k-d tree proposes this many, the fit keeps
#: those within FIT_RADIUS cells that face the same way).
FIT_NEIGHBOURS = 12
FIT_RADIUS = 3.0
#: Passes of the fit (normals turned, front points placed again).
FIT_PASSES = 3
#: The curvature is held to 1/(MIN_RADIUS h): a front bent tighter than that is not resolved,
#: and a concave circle's far side (2 MIN_RADIUS h from the front) stays beyond BAND.
MIN_RADIUS = 2.0
#: The reconstruction applies within BAND cells of the front (by the first-order field); beyond,
#: the march. Why: the signed distance to a concave circle turns negative again past its
#: centre, and the 0.25 m radial-m run (noisy early curvatures) found hundreds of spurious
#: tip elements outside its front and grew to 2046 elements in 2 s.
BAND = 3.0
#: Move each front point onto its regression (False: the point stays on its own ribbon's circle,
#: only the normal and curvature are the regression's; module docstring).
SMOOTH_POINTS = False
#: Fewer ribbon cells than this: the front is not resolved (a radius below ~3.5 h, a curvature
#: radius within the fit's reach); FrontField keeps the first-order march. The radial-k run at
#: 1 m starts from 3 x 3 elements (8 ribbon cells): reconstructed, its front jumped to 419
#: elements by 5 s (the first-order march: ~150) and stalled there.
MIN_RIBBON = 20
#: Front points blended per evaluation point (and the one beyond them that sets the weights).
BLEND = 4


@njit(cache=True)
def ribbon_normals(phi, index, h):
    """Unit gradients (R, 2) of the grid field ``phi`` (cell centres, spacing ``h``) at the
    cells ``index`` (R, 2): central differences, one-sided where a neighbour is infinite or
    beyond the box; ``(1, 0)`` where neither axis has a finite neighbour."""
    n0, n1 = phi.shape
    out = np.empty((index.shape[0], 2))
    for r in range(index.shape[0]):
        i, j = index[r, 0], index[r, 1]
        centre = phi[i, j]
        g = np.zeros(2)
        for axis in range(2):
            di, dj = (1, 0) if axis == 0 else (0, 1)
            plus = phi[i + di, j + dj] if i + di < n0 and j + dj < n1 else np.inf
            minus = phi[i - di, j - dj] if i - di >= 0 and j - dj >= 0 else np.inf
            if math.isfinite(plus) and math.isfinite(minus):
                g[axis] = (plus - minus) / (2.0 * h)
            elif math.isfinite(plus) and math.isfinite(centre):
                g[axis] = (plus - centre) / h
            elif math.isfinite(minus) and math.isfinite(centre):
                g[axis] = (centre - minus) / h
        norm = math.sqrt(g[0] * g[0] + g[1] * g[1])
        if norm > 0.0:
            out[r, 0], out[r, 1] = g[0] / norm, g[1] / norm
        else:
            out[r, 0], out[r, 1] = 1.0, 0.0
    return out


@njit(cache=True)
def _solve3(m, v):
    """``m^-1 v`` of a symmetric 3x3 by Cramer's rule; ``ok`` False when nearly singular."""
    c00 = m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]
    c01 = m[1, 2] * m[2, 0] - m[1, 0] * m[2, 2]
    c02 = m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]
    det = m[0, 0] * c00 + m[0, 1] * c01 + m[0, 2] * c02
    out = np.zeros(3)
    if not abs(det) > 1e-9 * m[0, 0] * m[1, 1] * m[2, 2]:
        return out, False
    c11 = m[0, 0] * m[2, 2] - m[0, 2] * m[2, 0]
    c12 = m[0, 1] * m[2, 0] - m[0, 0] * m[2, 1]
    c22 = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
    # the inverse of a symmetric matrix is symmetric: its cofactors c_ij = c_ji
    out[0] = (c00 * v[0] + c01 * v[1] + c02 * v[2]) / det
    out[1] = (c01 * v[0] + c11 * v[1] + c12 * v[2]) / det
    out[2] = (c02 * v[0] + c12 * v[1] + c22 * v[2]) / det
    return out, True


@njit(cache=True)
def fit_front(centres, distances, normals, neighbours, h):
    """Front points, normals and curvatures (R, 2), (R, 2), (R,) of ribbons at ``centres``
    (R, 2) with ``distances`` (R,), from first ``normals`` and ``neighbours`` (R, m; -1:
    none): the local quadratic regression of the module docstring, :data:`FIT_PASSES` passes."""
    m = neighbours.shape[1]
    count = centres.shape[0]
    n = normals.copy()
    kappa = np.zeros(count)
    shift = np.zeros(count)
    points = np.empty((count, 2))
    radius2 = (FIT_RADIUS * h) ** 2
    limit = 1.0 / (MIN_RADIUS * h)
    for r in range(count):
        points[r, 0] = centres[r, 0] + distances[r] * n[r, 0]
        points[r, 1] = centres[r, 1] + distances[r] * n[r, 1]
    matrix = np.empty((3, 3))
    rhs = np.empty(3)
    for _ in range(FIT_PASSES):
        turned = np.empty((count, 2))
        for r in range(count):
            nx, ny = n[r, 0], n[r, 1]
            tx, ty = -ny, nx
            matrix[:] = 0.0
            rhs[:] = 0.0
            matrix[0, 0] = 1.0  # the point itself: t = u = 0, weight 1
            used = 0
            for c in range(m):
                j = neighbours[r, c]
                if j < 0 or j == r or n[j, 0] * nx + n[j, 1] * ny < 0.5:
                    continue
                dx = points[j, 0] - points[r, 0]
                dy = points[j, 1] - points[r, 1]
                d2 = dx * dx + dy * dy
                if d2 >= radius2:
                    continue
                w = (1.0 - d2 / radius2) ** 2
                t = (dx * tx + dy * ty) / h
                u = (dx * nx + dy * ny) / h
                basis = (1.0, t, t * t)
                for a in range(3):
                    rhs[a] += w * basis[a] * u
                    for b in range(3):
                        matrix[a, b] += w * basis[a] * basis[b]
                used += 1
            coefficients, ok = _solve3(matrix, rhs)  # u = c0 + c1 t + c2 t^2 (cells)
            if ok and used >= 3:
                c0, b, a = coefficients[0], coefficients[1], coefficients[2]
            elif used >= 2 and matrix[1, 1] * matrix[2, 2] - matrix[1, 2] ** 2 > 1e-9 * matrix[1, 1] * matrix[2, 2]:
                # two neighbours: the graph through the point itself, u = b t + a t^2
                det = matrix[1, 1] * matrix[2, 2] - matrix[1, 2] ** 2
                c0 = 0.0
                b = (rhs[1] * matrix[2, 2] - rhs[2] * matrix[1, 2]) / det
                a = (matrix[1, 1] * rhs[2] - matrix[1, 2] * rhs[1]) / det
            elif matrix[1, 1] > 0.0:  # one: the line u = b t through the point
                c0, b, a = 0.0, rhs[1] / matrix[1, 1], 0.0
            else:
                c0, b, a = 0.0, 0.0, 0.0
            scale = math.sqrt(1.0 + b * b)
            k = -2.0 * a / (h * scale ** 3)
            kappa[r] = min(max(k, -limit), limit)
            shift[r] = c0 * h / scale  # the graph at t = 0, along the turned normal
            turned[r, 0] = (nx - b * tx) / scale
            turned[r, 1] = (ny - b * ty) / scale
        n = turned
        for r in range(count):
            points[r, 0] = centres[r, 0] + distances[r] * n[r, 0]
            points[r, 1] = centres[r, 1] + distances[r] * n[r, 1]
    if SMOOTH_POINTS:  # the regression's front point (smoothed), not the ribbon's own
        for r in range(count):
            points[r, 0] += shift[r] * n[r, 0]
            points[r, 1] += shift[r] * n[r, 1]
    return points, n, kappa


@njit(cache=True)
def circle_distance(d, t, kappa):
    """The signed distance to a circle of curvature ``kappa`` (either sign) through the origin
    with outward normal along ``d``, at the point ``(d, t)`` (module docstring)."""
    a = 1.0 + kappa * d
    b = kappa * t
    return (2.0 * d + kappa * (d * d + t * t)) / (1.0 + math.sqrt(a * a + b * b))


@njit(cache=True)
def blend(points, front, normals, kappa, nearest, reach, out):
    """``out[i]``: the blended signed distance at ``points[i]`` (M, 2) from the front points
    ``nearest[i]`` (M, BLEND + 1), nearest first, ``reach[i]`` their distances (module
    docstring; the last one's distance sets the weights)."""
    m = nearest.shape[1] - 1
    for i in range(points.shape[0]):
        first = nearest[i, 0]
        far = reach[i, m]
        total = 0.0
        weights = 0.0
        for c in range(m):
            j = nearest[i, c]
            if c > 0 and normals[j, 0] * normals[first, 0] + normals[j, 1] * normals[first, 1] <= 0.0:
                continue
            w = (1.0 - (reach[i, c] / far) ** 2) ** 2 if far > 0.0 else 1.0
            if w <= 0.0:
                continue
            dx = points[i, 0] - front[j, 0]
            dy = points[i, 1] - front[j, 1]
            d = dx * normals[j, 0] + dy * normals[j, 1]
            t = -dx * normals[j, 1] + dy * normals[j, 0]
            total += w * circle_distance(d, t, kappa[j])
            weights += w
        if weights > 0.0:
            out[i] = total / weights
        else:  # every front point as far as the last: the nearest one's circle
            j = first
            dx = points[i, 0] - front[j, 0]
            dy = points[i, 1] - front[j, 1]
            out[i] = circle_distance(dx * normals[j, 0] + dy * normals[j, 1],
                                     -dx * normals[j, 1] + dy * normals[j, 0], kappa[j])


class FrontReconstruction:
    """The front of ribbons (R, 2) at ``centres`` with ``distances``, first normals from the
    first-order grid field ``phi`` (cells ``index`` into it), spacing ``h`` (module docstring):
    ``self(points)`` the signed distance at in-plane points (M, 2)."""

    def __init__(self, centres, distances, phi, index, h):
        import scipy.spatial

        centres = np.ascontiguousarray(centres, float)
        self.h = float(h)
        first = ribbon_normals(phi, np.ascontiguousarray(index, np.int64), self.h)
        count = len(centres)
        k = min(FIT_NEIGHBOURS, count)
        _, neighbours = scipy.spatial.cKDTree(centres).query(centres, k=k)
        neighbours = np.ascontiguousarray(np.asarray(neighbours, np.int64).reshape(count, k))
        self.points, self.normals, self.kappa = fit_front(centres, np.ascontiguousarray(distances, float),
                                                          first, neighbours, self.h)
        self._tree = scipy.spatial.cKDTree(self.points)

    def __call__(self, points):
        points = np.ascontiguousarray(points, float).reshape(-1, 2)
        count = len(self.points)
        k = min(BLEND + 1, count)
        reach, nearest = self._tree.query(points, k=k)
        reach = np.asarray(reach, float).reshape(len(points), k)
        nearest = np.asarray(nearest, np.int64).reshape(len(points), k)
        if k < BLEND + 1:  # fewer front points than the blend: the last weight stays > 0
            reach = np.column_stack([reach, 2.0 * reach[:, -1] + self.h])
            nearest = np.column_stack([nearest, nearest[:, -1]])
        out = np.empty(len(points))
        blend(points, self.points, self.normals, self.kappa, np.ascontiguousarray(nearest),
              np.ascontiguousarray(reach), out)
        return out
