"""Natural fractures inside the time loop (ref. Ch. 5): encounters, crossing, activation,
remote failure.

Intact natural-fracture elements are stress *targets*, not unknowns (docs/conventions.md §5).
They join the active system when fluid reaches them:

* a growing tip whose next element would cut an intact natural element applies the
  crossing criterion (:func:`hmatddm.fracture.crossing.crosses`); on deflection the
  natural element is activated and connected to the tip element for flow (an extra
  face), otherwise the new element is added through it;
* a tip of an activated natural element whose next element lands on the neighbouring
  intact element of the same natural fracture activates that element (the fluid runs
  along the natural fracture); at the natural fracture's end new elements are created
  in the maximum circumferential stress direction, so the hydraulic fracture leaves it.

Remote failure (ref. Sec. 5.3): the stress the active elements induce on every intact
natural element, plus the far field and the undrained pore-pressure change
``dp = -B d sigma_m`` (ref. Eq. 5.18), is checked against Coulomb's criterion.

In a :class:`hmatddm.LayeredMedium` the same machinery runs with the layers
(:mod:`hmatddm.layered.engine`): the induced stress includes the image terms, the far
field and Poisson's ratio are those of each natural element's layer, and the crossing
criterion takes the in-situ stress and toughness of the layer where the tip meets the
natural fracture.
"""
import time

import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from ..elasticity.field_bound import stress_bound
from ..fracture.crossing import NaturalFractureProperties, crosses
from ..layered.medium import LayeredMedium
from ..material import Elastic
from ..mesh import Mesh2D, Mesh3D, check_mesh
from ..elasticity.operator import NEAR_SINGULAR_FRACTION
from ..elasticity.solve import stress_at


#: Natural element centres per leaf of :meth:`NaturalNetwork.target_tree`.
TARGET_LEAF_SIZE = 32


def plan_segments(mesh):
    """Plan-view (x, y) end points of every element: the segment itself in 2D, the
    horizontal mid-line of a (vertical) rectangle in 3D, and the vertical half size."""
    if isinstance(mesh, Mesh3D):
        e1, e2 = mesh.frames[:, 0, :], mesh.frames[:, 1, :]
        horizontal_first = np.abs(e1[:, 2]) <= np.abs(e2[:, 2])
        axis = np.where(horizontal_first[:, None], e1, e2)
        half = np.where(horizontal_first, mesh.half_a, mesh.half_b)
        vertical = np.where(horizontal_first, mesh.half_b, mesh.half_a) * np.abs(np.where(
            horizontal_first[:, None], e2, e1)[:, 2])
        p0 = (mesh.centers - half[:, None] * axis)[:, :2]
        p1 = (mesh.centers + half[:, None] * axis)[:, :2]
        return p0, p1, vertical
    p0, p1 = mesh.endpoints
    return p0, p1, np.full(mesh.n_elements, np.inf)


def _segment_intersection(a0, a1, b0, b1):
    """Parameter ``s`` along a (in [0, 1]) where segments a and b cross, or None."""
    da, db = a1 - a0, b1 - b0
    denominator = da[0] * db[1] - da[1] * db[0]
    if denominator == 0.0 or abs(denominator) < 1e-12 * np.linalg.norm(da) * np.linalg.norm(db):
        return None
    w = b0 - a0
    s = (w[0] * db[1] - w[1] * db[0]) / denominator
    t = (w[0] * da[1] - w[1] * da[0]) / denominator
    if -1e-9 <= s <= 1.0 + 1e-9 and -1e-9 <= t <= 1.0 + 1e-9:
        return s
    return None


class NaturalNetwork:
    """The intact/active bookkeeping of the natural-fracture elements of a run."""

    def __init__(self, mesh, properties):
        self.mesh = mesh
        self.properties = properties
        self.p0, self.p1, self.vertical_half = plan_segments(mesh)
        self.tree = cKDTree(mesh.centers)
        self.reach = 2.0 * float(mesh.radii.max())
        #: :class:`ScreenMemory` of the last screened remote-failure check (a cache: a
        #: check finds the same failures with or without it)
        self.screen_memory = None
        #: :class:`hmatddm.elasticity.stress_columns.StressColumns` of the last layered
        #: check (a cache: each active element's stress at the targets, computed once)
        self.stress_columns = None
        self._target_tree = None

    def target_tree(self):
        """Cluster tree of the natural element centres (the remote-failure targets), built
        at the first call (its leaves are bounded whole by the screened check)."""
        if self._target_tree is None:
            from ..hmatrix.cluster_tree import cluster_tree

            self._target_tree = cluster_tree(self.mesh.centers, 0.0, TARGET_LEAF_SIZE)
        return self._target_tree

    def encounter(self, candidate_mesh, index, hinge, intact):
        """The intact natural element cut by candidate ``index`` (hinged at ``hinge``),
        nearest the hinge; ``None`` when there is none."""
        center = candidate_mesh.centers[index]
        cand_p0, cand_p1, cand_vertical = plan_segments(candidate_mesh.subset([index]))
        start = hinge[:2] if len(hinge) > 2 else hinge
        end = start + 2.0 * (center[:2] - start) if len(center) > 2 else start + 2.0 * (center - start)
        best, best_s = None, np.inf
        for e in self.tree.query_ball_point(center, self.reach + float(candidate_mesh.radii[index])):
            if not intact[e]:
                continue
            if len(center) > 2 and abs(center[2] - self.mesh.centers[e, 2]) >= cand_vertical[0] + self.vertical_half[e]:
                continue
            s = _segment_intersection(start, end, self.p0[e], self.p1[e])
            if s is not None and s < best_s:
                best, best_s = e, s
        if best is None:
            return None
        return best, start + best_s * (end - start)

    def decide_crossing(self, tips_k1, tips_k2, tips_theta, ahead, normal, element, far_field, rock_toughness):
        """True to cross natural element ``element`` (tip frame: ``ahead``, ``normal``);
        ``far_field`` and ``rock_toughness``: those where the tip meets it (in a layered
        medium, of that layer: :func:`hmatddm.layered.engine.crossing_setting`)."""
        tangent = self.p1[element] - self.p0[element]
        tangent = tangent / np.linalg.norm(tangent)
        if len(ahead) > 2:  # the natural fracture's plan-view direction, in 3D
            tangent = np.array([tangent[0], tangent[1], 0.0])
        phi = np.arctan2(tangent @ normal, tangent @ ahead)
        frame = np.stack([ahead, normal])
        stress_tip = frame @ far_field @ frame.T
        return crosses(tips_k1, tips_k2, tips_theta, phi, stress_tip, rock_toughness, self.properties)

    def induced_stress(self, active_mesh, dd, material, targets, singular_correction="average", info=None,
                       method="auto", n_images=None):
        """Stress (len(targets), d, d) the active elements induce at the centres of the
        natural elements ``targets`` (:func:`hmatddm.stress_at`). Targets within half an
        element size of an active element's edge are near misses (stress ~1/gap),
        averaged like the DDM operator's collocation points. ``material`` a
        :class:`hmatddm.LayeredMedium`: the direct layered sum with ``n_images`` images
        (None: the medium's choice; ``method`` and ``info`` do not apply); in 3D with
        ``n_images`` given, each active element's terms are kept across calls
        (:class:`hmatddm.elasticity.stress_columns.StressColumns`: the elements appended
        since the last call are the only ones computed)."""
        near = NEAR_SINGULAR_FRACTION if singular_correction == "average" else 0.0
        if isinstance(material, LayeredMedium):
            from ..elasticity.stress_columns import StressColumns

            self.stress_columns = StressColumns.reuse(self.stress_columns, active_mesh, material, self.mesh.centers,
                                                      targets, n_images, singular_correction, near)
            if self.stress_columns is not None:
                return self.stress_columns.stress(active_mesh, dd, targets)
            from ..layered.engine import induced_stress

            return induced_stress(active_mesh, material, dd, self.mesh.centers[targets], singular_correction, near,
                                  n_images)
        return stress_at(active_mesh, material, dd, self.mesh.centers[targets],
                         singular_correction=singular_correction, near_fraction=near, info=info, method=method)

    def remote_failure(self, active_mesh, dd, material, far_field, intact, singular_correction="average",
                       screen=False, info=None, poisson_ratio=None, n_images=None):
        """Coulomb check on the intact elements (ref. Sec. 5.3).

        Returns ``(failed, normal, shear, pore_pressure_change)`` over the natural
        elements (zeros where not intact).

        ``material``: an :class:`hmatddm.Elastic` or a :class:`hmatddm.LayeredMedium`
        (the induced stress with the image terms, ``n_images`` of them, see
        :meth:`induced_stress`); ``far_field``: the (d, d) in-situ stress, or one per
        natural element (M, d, d) (a layered medium's per layer); ``poisson_ratio`` (M,)
        or None (the material's, of each element's layer): per natural element, for the
        2D mean stress.

        ``screen``: evaluate the induced stress (exact sum) only at the targets that may
        fail; the others keep zeros like the elements that are not intact. ``failed``,
        and the values where it is True, are those of the full check (see
        :class:`ScreenMemory`). Only in a homogeneous medium with constant elements
        (elsewhere every target is evaluated; see
        :func:`hmatddm.layered.engine.remote_failure_setting` for layers). ``info`` (dict or None) receives
        ``targets``, ``evaluated``, ``screen_seconds``, ``memory`` (whether the last
        check's margins were used) and the stress evaluation's ``stress`` info.
        """
        n = self.mesh.n_elements
        failed = np.zeros(n, dtype=bool)
        normal_stress = np.zeros(n)
        shear_stress = np.zeros(n)
        pore_change = np.zeros(n)
        targets = np.flatnonzero(intact)
        started = time.perf_counter()
        screened = screen and targets.size > 0 and _screenable(active_mesh, material)
        cleared = None
        if screened:
            near = NEAR_SINGULAR_FRACTION if singular_correction == "average" else 0.0
            memory = self.screen_memory
            if memory is None or not memory.holds(active_mesh, material, far_field, near):
                memory = ScreenMemory.start(self, active_mesh, material, far_field, near)
            cleared, cleared_margin = memory.clear(active_mesh, material, dd, self, targets)
            evaluate = targets[~cleared]
        else:
            evaluate = targets
        stress_info = {}
        if info is not None:
            info.update(targets=int(targets.size), evaluated=int(evaluate.size), memory=bool(screened and memory.used),
                        screen_seconds=time.perf_counter() - started, stress=stress_info)
        if evaluate.size:
            # the exact sum when screening: a target's value does not depend on which others
            # are evaluated (with "auto" the count would choose the method)
            stress = self.induced_stress(active_mesh, dd, material, evaluate, singular_correction, info=stress_info,
                                         method="direct" if screened else "auto", n_images=n_images)
            if poisson_ratio is not None:
                nu = np.asarray(poisson_ratio)[evaluate]
            elif isinstance(material, LayeredMedium):  # the layer of each target
                nu = np.asarray(material.poisson_ratio)[material.layer_of(self.mesh.centers[evaluate, -1])]
            else:
                nu = material.poisson_ratio
            if self.properties.skempton > 0.0:
                pore_change[evaluate] = -self.properties.skempton * _mean_stress(stress, nu)
            stress = stress + (far_field if np.ndim(far_field) == 2 else np.asarray(far_field)[evaluate])
            normal_stress[evaluate], shear_stress[evaluate] = _normal_and_shear(stress, self.mesh.normals[evaluate])
            failed[evaluate] = _coulomb(self.properties, normal_stress[evaluate], shear_stress[evaluate],
                                        pore_change[evaluate])
        if screened:
            margin = np.full(n, -np.inf)
            margin[targets[cleared]] = cleared_margin
            if evaluate.size:
                margin[evaluate] = failure_margin(self.properties, material, stress, self.mesh.normals[evaluate],
                                                  active_mesh.dim, pore_change[evaluate])
            self.screen_memory = memory.after(active_mesh, dd, margin)
        return failed, normal_stress, shear_stress, pore_change


class ScreenMemory:
    """What the last screened remote-failure check of a :class:`NaturalNetwork` knew:
    the active elements and DDs it saw, and for every natural element a margin: an
    induced-stress change (Frobenius norm) it can take from that state without failing.

    A check with DDs ``dd`` bounds, at each target, the change of the induced stress
    since the last check (:func:`hmatddm.elasticity.field_bound.stress_bound` of the DD changes,
    the new elements' DDs whole) and evaluates the stress only where the bound reaches
    the margin. The margins then become: the evaluated targets' own
    (:func:`failure_margin` at their exact stress), the others' less the bound. A first
    check (or one whose elements are not the last one's plus appended ones, or another
    material, far field or correction) starts from the far field alone: margin = what
    the far field leaves, change = the whole induced stress. The bound is rigorous, so
    a target left out cannot fail: the check finds what the full one finds.
    """

    def __init__(self, centers, frames, sizes, dd, margin, key, used):
        self.centers, self.frames, self.sizes, self.dd = centers, frames, sizes, dd
        self.margin, self.key, self.used = margin, key, used

    @staticmethod
    def _key(material, far_field, near):
        return (type(material), float(material.shear_modulus), float(material.poisson_ratio),
                np.asarray(far_field, dtype=float).tobytes(), float(near))

    @classmethod
    def start(cls, network, active_mesh, material, far_field, near):
        """No elements seen yet: each natural element's margin under the far field."""
        dim = active_mesh.dim
        margin = failure_margin(network.properties, material, far_field, network.mesh.normals, dim)
        empty = np.zeros((0, dim))
        return cls(empty, np.zeros((0, dim, dim)), np.zeros((0, 2)), empty, margin,
                   cls._key(material, far_field, near), used=False)

    def holds(self, active_mesh, material, far_field, near):
        """Whether ``active_mesh`` extends the elements seen (same first ones) in the same
        material, far field and singular-point correction."""
        n0 = self.centers.shape[0]
        if self._key(material, far_field, near) != self.key or active_mesh.n_elements < n0 \
                or active_mesh.dim != self.centers.shape[1]:
            return False
        return bool(np.array_equal(active_mesh.centers[:n0], self.centers)
                    and np.array_equal(active_mesh.frames[:n0], self.frames)
                    and np.array_equal(_sizes(active_mesh)[:n0], self.sizes))

    def clear(self, active_mesh, material, dd, network, targets):
        """``(cleared, margin)``: the ``targets`` (natural elements of ``network``) whose
        induced stress cannot have changed by their margin since the last check, and
        their margin left."""
        n0 = self.centers.shape[0]
        change = np.array(dd, dtype=float).reshape(active_mesh.n_elements, active_mesh.dim)
        change[:n0] -= self.dd
        limit = np.full(network.mesh.n_elements, -np.inf)  # -inf: not a target
        limit[targets] = self.margin[targets]
        bound = stress_bound(active_mesh, material, change, network.mesh.centers, self.key[4], limit=limit,
                             point_tree=network.target_tree())[targets]
        margin = self.margin[targets]
        cleared = bound < margin
        return cleared, margin[cleared] - bound[cleared]

    def after(self, active_mesh, dd, margin):
        """The memory of a check of ``active_mesh`` with ``dd`` that left ``margin``."""
        dd = np.array(dd, dtype=float).reshape(active_mesh.n_elements, active_mesh.dim)
        return ScreenMemory(np.array(active_mesh.centers), np.array(active_mesh.frames), _sizes(active_mesh), dd,
                            margin, self.key, used=True)


def _sizes(mesh):
    """(N, 2) the half sizes of the elements (2D: the half length twice)."""
    if isinstance(mesh, Mesh3D):
        return np.column_stack([mesh.half_a, mesh.half_b])
    return np.column_stack([mesh.half_length, mesh.half_length])


def _screenable(mesh, material):
    """Whether :func:`hmatddm.elasticity.field_bound.stress_bound` applies: constant elements in a
    homogeneous medium."""
    return isinstance(material, Elastic) and isinstance(mesh, (Mesh2D, Mesh3D)) and getattr(mesh, "n_nodes", 1) == 1


def _mean_stress(stress, poisson_ratio):
    """Mean of induced stress tensors (M, d, d) (ref. Eqs 5.24-5.28): in 2D plane strain
    sigma_zz = nu (sigma_xx + sigma_yy) joins the trace (``poisson_ratio``: nu, scalar or (M,))."""
    trace = np.trace(stress, axis1=1, axis2=2)
    return trace / 3.0 if stress.shape[1] == 3 else (1.0 + poisson_ratio) * trace / 3.0


def _normal_and_shear(stress, normals):
    """Normal stress and shear traction magnitude of stress tensors (M, d, d) on planes of
    unit ``normals`` (M, d)."""
    traction = np.einsum("mij,mj->mi", stress, normals)
    sigma_n = np.sum(traction * normals, axis=1)
    return sigma_n, np.linalg.norm(traction - sigma_n[:, None] * normals, axis=1)


def _coulomb(props, sigma_n, tau, pore_change):
    """Coulomb's criterion or the tensile one (ref. Sec. 5.3), with the undrained pore
    pressure change ``pore_change`` (ref. Eq. 5.18)."""
    effective = sigma_n + props.pore_pressure + pore_change
    return (tau >= props.cohesion - props.friction * effective) | (effective >= props.tensile_strength)


def failure_margin(properties, material, stress, normals, dim, pore_change=0.0):
    """(M,) the induced-stress change (Frobenius norm) that natural elements of unit
    ``normals`` (M, d) can take from ``stress`` (the far field (d, d), or total stress
    tensors (M, d, d)) and ``pore_change`` without failing (ref. Sec. 5.3): with
    ``|d sigma|_F < margin`` neither Coulomb's criterion nor the tensile one can hold.

    A change of norm ``S`` changes the normal stress and the shear traction by at most
    ``S`` each, and the undrained pore pressure ``-B sigma_m`` (ref. Eq. 5.18) by at most
    ``B f S`` (``f`` = sqrt(3)/3 in 3D; (1 + nu) sqrt(2)/3 in 2D plane strain); so
    ``tau + S < c - mu (sigma_n + p + dp) - |mu| (1 + B f) S`` and
    ``sigma_n + p + dp + (1 + B f) S < T`` keep the element intact. Negative where
    ``stress`` fails it already.
    """
    props = properties
    stress = np.asarray(stress, dtype=float)
    if stress.ndim == 2:
        stress = np.broadcast_to(stress, (len(normals),) + stress.shape)
    sigma_n, tau = _normal_and_shear(stress, normals)
    effective = sigma_n + props.pore_pressure + pore_change
    pore = props.skempton * (np.sqrt(3.0) / 3.0 if dim == 3 else (1.0 + material.poisson_ratio) * np.sqrt(2.0) / 3.0)
    shear = (props.cohesion - props.friction * effective - tau) / (1.0 + abs(props.friction) * (1.0 + pore))
    tensile = (props.tensile_strength - effective) / (1.0 + pore)
    return np.minimum(shear, tensile)


def natural_network(mesh, natural_fractures, properties=None):
    """The :class:`NaturalNetwork` of a run on hydraulic fractures ``mesh``: the checked
    ``natural_fractures`` (same mesh type), their fracture ids moved past those of
    ``mesh`` so that they never collide, and their ``properties`` (default
    :class:`~hmatddm.NaturalFractureProperties` if None)."""
    if type(natural_fractures) is not type(mesh):
        raise InputError(f"natural_fractures must be a {type(mesh).__name__} like mesh, "
                         f"got {type(natural_fractures).__name__}")
    check_mesh(natural_fractures, "natural_fractures")
    properties = NaturalFractureProperties() if properties is None else properties
    if not isinstance(properties, NaturalFractureProperties):
        raise InputError("natural must be an hmatddm.NaturalFractureProperties or None")
    offset = int(mesh.fracture_id.max()) + 1 - int(natural_fractures.fracture_id.min())
    shifted = natural_fractures.subset(np.arange(natural_fractures.n_elements))
    object.__setattr__(shifted, "fracture_id", natural_fractures.fracture_id + offset)
    return NaturalNetwork(shifted, properties)
