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
"""
import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from ..fracture.crossing import NaturalFractureProperties, crosses
from ..mesh import Mesh3D, check_mesh
from ..operators import NEAR_SINGULAR_FRACTION
from ..solve import stress_at


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
        """True to cross natural element ``element`` (tip frame: ``ahead``, ``normal``)."""
        tangent = self.p1[element] - self.p0[element]
        tangent = tangent / np.linalg.norm(tangent)
        if len(ahead) > 2:  # the natural fracture's plan-view direction, in 3D
            tangent = np.array([tangent[0], tangent[1], 0.0])
        phi = np.arctan2(tangent @ normal, tangent @ ahead)
        frame = np.stack([ahead, normal])
        stress_tip = frame @ far_field @ frame.T
        return crosses(tips_k1, tips_k2, tips_theta, phi, stress_tip, rock_toughness, self.properties)

    def induced_stress(self, active_mesh, dd, material, targets, singular_correction="average"):
        """Stress (len(targets), d, d) the active elements induce at the centres of the
        natural elements ``targets`` (:func:`hmatddm.stress_at`). Targets within half an
        element size of an active element's edge are near misses (stress ~1/gap),
        averaged like the DDM operator's collocation points."""
        near = NEAR_SINGULAR_FRACTION if singular_correction == "average" else 0.0
        return stress_at(active_mesh, material, dd, self.mesh.centers[targets],
                         singular_correction=singular_correction, near_fraction=near)

    def remote_failure(self, active_mesh, dd, material, far_field, intact, singular_correction="average"):
        """Coulomb check on the intact elements (ref. Sec. 5.3).

        Returns ``(failed, normal, shear, pore_pressure_change)`` over the natural
        elements (zeros where not intact).
        """
        n = self.mesh.n_elements
        failed = np.zeros(n, dtype=bool)
        normal_stress = np.zeros(n)
        shear_stress = np.zeros(n)
        pore_change = np.zeros(n)
        targets = np.flatnonzero(intact)
        if targets.size == 0:
            return failed, normal_stress, shear_stress, pore_change
        stress = self.induced_stress(active_mesh, dd, material, targets, singular_correction)
        if self.properties.skempton > 0.0:
            # mean of the induced stress (ref. Eqs 5.24-5.28), from the same evaluation: in
            # 2D plane strain sigma_zz = nu (sigma_xx + sigma_yy) joins the trace
            trace = np.trace(stress, axis1=1, axis2=2)
            mean = trace / 3.0 if stress.shape[1] == 3 else (1.0 + material.poisson_ratio) * trace / 3.0
            pore_change[targets] = -self.properties.skempton * mean
        stress = stress + far_field
        normals = self.mesh.normals[targets]
        traction = np.einsum("mij,mj->mi", stress, normals)
        sigma_n = np.sum(traction * normals, axis=1)
        tau = np.linalg.norm(traction - sigma_n[:, None] * normals, axis=1)
        props = self.properties
        strength = props.cohesion - props.friction * (sigma_n + props.pore_pressure + pore_change[targets])
        failed[targets] = (tau >= strength) | (sigma_n + props.pore_pressure + pore_change[targets]
                                               >= props.tensile_strength)
        normal_stress[targets], shear_stress[targets] = sigma_n, tau
        return failed, normal_stress, shear_stress, pore_change


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
