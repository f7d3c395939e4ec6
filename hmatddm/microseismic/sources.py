"""Microseismic sources: the dynamic medium, moment tensors, moment and magnitude, the
ISO/DC/CLVD decomposition, and events from the slip a run computes (ref. Secs 7.2.1, 7.4.1).

Conventions (``docs/conventions.md``): SI units; the displacement discontinuity is
``DD = u(+) - u(-)`` with the unit normal ``n`` pointing to the ``+`` face, so that the
moment tensor (ref. Eq. 7.3)

    M_ij = A C_ijkl DD_k n_l = A [lambda (DD.n) delta_ij + mu (DD_i n_j + DD_j n_i)]

has the sign of Aki & Richards: a tensile opening gives a positive isotropic part.
``lambda`` and ``mu`` are the DYNAMIC Lame constants of the wave speeds and density
(ref. Eqs 7.27-7.28, Table 7.1), not the static moduli the run was solved with.

The seismic moment of an event is ``M0 = mu A d`` (ref. Eq. 7.1) with ``d = |DD|`` the
magnitude of the final displacement discontinuity (the reference's "slip vector",
which holds the tensile part; for a pure shear event it is the slip). With this ``d``
the far-field amplitudes are exactly ``M0 F / (4 pi rho v^3 r)`` (ref. Eqs 7.15-7.20),
and ``M0 = ||M||_F / sqrt(2)`` for a pure double couple.
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .._validation import finite_array
from ..errors import InputError
from ..settings import MICROSEISMIC

MAGNITUDE_OFFSET = 6.0  # ref. Eq. 7.2 (M0 in N m)
DEFAULT_SHEAR_RATIO = MICROSEISMIC["shear_ratio"].default  # ref. Eq. 7.29


def check_wave_speeds(p_wave_speed, s_wave_speed, density, prefix=""):
    """Validated ``(v_P, v_S, rho)``; messages name ``prefix + field``.

    Ranges and units are :data:`hmatddm.settings.MICROSEISMIC`'s; besides,
    ``v_S < (sqrt(3)/2) v_P`` so that the bulk modulus is positive (``v_S >= v_P``
    is always refused)."""
    vp, vs, rho = (MICROSEISMIC[name].value(prefix + name, value) for name, value in
                   (("p_wave_speed", p_wave_speed), ("s_wave_speed", s_wave_speed), ("density", density)))
    limit = 0.5 * np.sqrt(3.0) * vp
    if vs >= limit:
        raise InputError(f"{prefix}s_wave_speed must be < sqrt(3)/2 * {prefix}p_wave_speed = {limit:.6g} m/s "
                         f"(v_S < v_P, and a positive bulk modulus), got {vs:.6g}")
    return vp, vs, rho


@dataclass(frozen=True)
class Medium:
    """A homogeneous isotropic elastic medium seen by seismic waves (ref. Table 7.1).

    Parameters are the P- and S-wave speeds (m/s) and the density (kg/m^3); the
    dynamic moduli follow from them (ref. Eqs 7.27-7.28)."""

    p_wave_speed: float = MICROSEISMIC["p_wave_speed"].default
    s_wave_speed: float = MICROSEISMIC["s_wave_speed"].default
    density: float = MICROSEISMIC["density"].default

    def __post_init__(self):
        vp, vs, rho = check_wave_speeds(self.p_wave_speed, self.s_wave_speed, self.density)
        object.__setattr__(self, "p_wave_speed", vp)
        object.__setattr__(self, "s_wave_speed", vs)
        object.__setattr__(self, "density", rho)

    @property
    def shear_modulus(self):
        """Dynamic shear modulus ``rho v_S^2`` (Pa)."""
        return self.density * self.s_wave_speed ** 2

    @property
    def lame_lambda(self):
        """Dynamic first Lame constant ``rho (v_P^2 - 2 v_S^2)`` (Pa)."""
        return self.density * (self.p_wave_speed ** 2 - 2.0 * self.s_wave_speed ** 2)

    @property
    def young_modulus(self):
        """Dynamic Young's modulus (Pa), ref. Eq. 7.27."""
        vp2, vs2 = self.p_wave_speed ** 2, self.s_wave_speed ** 2
        return self.density * vs2 * (3.0 * vp2 - 4.0 * vs2) / (vp2 - vs2)

    @property
    def poisson_ratio(self):
        """Dynamic Poisson's ratio, ref. Eq. 7.28."""
        vp2, vs2 = self.p_wave_speed ** 2, self.s_wave_speed ** 2
        return (vp2 - 2.0 * vs2) / (2.0 * (vp2 - vs2))

    @property
    def distance_per_s_minus_p(self):
        """``v_P v_S / (v_P - v_S)`` (m/s): distance per second of S-P time, ref. Eq. 7.23."""
        return self.p_wave_speed * self.s_wave_speed / (self.p_wave_speed - self.s_wave_speed)


def moment_tensor(displacement_discontinuity, normal, area, medium):
    """Moment tensors ``(E, 3, 3)`` of sources with DD ``(E, 3)``, unit normal ``(E, 3)``
    and area ``(E,)`` (ref. Eq. 7.3; sign convention in the module docstring)."""
    dd = np.atleast_2d(np.asarray(displacement_discontinuity, dtype=float))
    n = np.atleast_2d(np.asarray(normal, dtype=float))
    area = np.broadcast_to(np.asarray(area, dtype=float), dd.shape[:1])
    opening = np.sum(dd * n, axis=1)
    tensor = medium.shear_modulus * (dd[:, :, None] * n[:, None, :] + n[:, :, None] * dd[:, None, :])
    tensor += (medium.lame_lambda * opening)[:, None, None] * np.eye(3)
    return tensor * area[:, None, None]


def seismic_moment(displacement_discontinuity, area, medium):
    """``M0 = mu A |DD|`` (N m), ref. Eq. 7.1 with the dynamic shear modulus."""
    dd = np.atleast_2d(np.asarray(displacement_discontinuity, dtype=float))
    return medium.shear_modulus * np.asarray(area, dtype=float) * np.linalg.norm(dd, axis=1)


def moment_magnitude(moment):
    """``Mw = 2/3 log10(M0) - 6.0`` (M0 in N m), ref. Eq. 7.2. Refuses M0 <= 0."""
    moment = np.asarray(moment, dtype=float)
    if np.any(~np.isfinite(moment)) or np.any(moment <= 0.0):
        raise InputError("seismic moment must be finite and > 0 N m to have a moment magnitude")
    return 2.0 / 3.0 * np.log10(moment) - MAGNITUDE_OFFSET


def moment_from_magnitude(magnitude):
    """Inverse of :func:`moment_magnitude` (N m)."""
    return 10.0 ** (1.5 * (np.asarray(magnitude, dtype=float) + MAGNITUDE_OFFSET))


def decompose(moment_tensors):
    """ISO/DC/CLVD shares of moment tensors ``(E, 3, 3)`` (ref. Eq. 7.4).

    Convention: Vavrycuk (2015, J. Seismol. 19, 231-252, Eqs 8-10), the one used for
    microseismic moment tensors::

        C_ISO  = tr(M) / (3 |M_max|)
        C_CLVD = 2 eps (1 - |C_ISO|),   eps = -M*_min / |M*_max|
        C_DC   = 1 - |C_ISO| - |C_CLVD|

    ``|M_max|`` is the largest absolute eigenvalue of ``M``; ``M*`` are the eigenvalues
    of the deviatoric part, ``M*_min`` and ``M*_max`` the smallest and largest in
    absolute value. ``|C_ISO| + |C_DC| + |C_CLVD| = 1``; ISO and CLVD are signed
    (positive for an opening crack: ISO 5/9 and CLVD 4/9 when lambda = mu), DC >= 0.

    Returns ``(iso, dc, clvd)`` arrays ``(E,)``.
    """
    tensors = np.asarray(moment_tensors, dtype=float).reshape(-1, 3, 3)
    symmetric = 0.5 * (tensors + np.swapaxes(tensors, 1, 2))
    eigen = np.linalg.eigvalsh(symmetric)
    largest = np.max(np.abs(eigen), axis=1)
    if np.any(largest <= 0.0):
        raise InputError("moment tensor is zero: no decomposition (an event needs a non-zero DD)")
    trace = np.sum(eigen, axis=1)
    iso = trace / (3.0 * largest)
    deviatoric = eigen - trace[:, None] / 3.0
    order = np.argsort(np.abs(deviatoric), axis=1)
    smallest = np.take_along_axis(deviatoric, order[:, :1], axis=1)[:, 0]
    biggest = np.abs(np.take_along_axis(deviatoric, order[:, 2:], axis=1)[:, 0])
    epsilon = np.divide(-smallest, biggest, out=np.zeros_like(smallest), where=biggest > 0.0)
    clvd = 2.0 * epsilon * (1.0 - np.abs(iso))
    dc = np.clip(1.0 - np.abs(iso) - np.abs(clvd), 0.0, 1.0)
    return iso, dc, clvd


def is_shear_failure(displacement_discontinuity, normal, shear_ratio=DEFAULT_SHEAR_RATIO):
    """``|DD_t| >= shear_ratio |DD_n|`` and ``|DD_t| > 0`` (ref. Eq. 7.29)."""
    dd = np.atleast_2d(np.asarray(displacement_discontinuity, dtype=float))
    n = np.atleast_2d(np.asarray(normal, dtype=float))
    normal_part = np.sum(dd * n, axis=1)
    tangential = np.linalg.norm(dd - normal_part[:, None] * n, axis=1)
    return (tangential > 0.0) & (tangential >= shear_ratio * np.abs(normal_part))


@dataclass
class Events:
    """A catalogue of point sources (struct of arrays, one row per event).

    ``position`` (E, 3) m; ``time`` (E,) s (onset); ``step`` (E,); ``moment_tensor``
    (E, 3, 3) N m; ``seismic_moment`` (E,) N m; ``potency`` (E,) ``A |DD|`` m^3;
    ``area`` (E,) m^2; ``displacement_discontinuity`` and ``normal`` (E, 3) (area-weighted
    means for merged events); ``fracture_id`` (E,); ``elements`` (E,) number of
    elements merged into each event (1 without merging).
    """

    position: np.ndarray
    time: np.ndarray
    step: np.ndarray
    moment_tensor: np.ndarray
    seismic_moment: np.ndarray
    potency: np.ndarray
    area: np.ndarray
    displacement_discontinuity: np.ndarray
    normal: np.ndarray
    fracture_id: np.ndarray
    elements: np.ndarray = field(default=None)

    def __post_init__(self):
        if self.elements is None:
            self.elements = np.ones(len(self.time), dtype=np.int64)

    def __len__(self):
        return int(len(self.time))

    @property
    def moment_magnitude(self):
        return moment_magnitude(self.seismic_moment)

    def decomposition(self):
        """``(iso, dc, clvd)`` shares, see :func:`decompose`."""
        return decompose(self.moment_tensor)

    def subset(self, index):
        index = np.asarray(index)
        return Events(**{name: getattr(self, name)[index] for name in self.__dataclass_fields__})


def point_sources(position, displacement_discontinuity, normal, area, medium, time=None, step=None,
                  fracture_id=None):
    """Events of given point sources (no filter), e.g. a synthetic source for a test."""
    position = finite_array("position", np.atleast_2d(position), shape=(None, 3))
    dd = finite_array("displacement_discontinuity", np.atleast_2d(displacement_discontinuity), shape=(None, 3))
    normal = finite_array("normal", np.atleast_2d(normal), shape=(None, 3))
    count = len(position)
    if len(dd) != count or len(normal) != count:
        raise InputError(f"position, displacement_discontinuity and normal must have the same number of rows, "
                         f"got {count}, {len(dd)}, {len(normal)}")
    lengths = np.linalg.norm(normal, axis=1)
    if np.any(np.abs(lengths - 1.0) > 1e-6):
        raise InputError("normal must hold unit vectors")
    area = np.broadcast_to(finite_array("area", area), (count,)).astype(float)
    if np.any(area <= 0.0):
        raise InputError("area must be > 0 m^2")
    if np.any(np.linalg.norm(dd, axis=1) <= 0.0):
        raise InputError("displacement_discontinuity must be non-zero for every source")
    zeros = np.zeros(count)
    return Events(position=position, time=zeros if time is None else np.asarray(time, float),
                  step=np.zeros(count, np.int64) if step is None else np.asarray(step, np.int64),
                  moment_tensor=moment_tensor(dd, normal, area, medium),
                  seismic_moment=seismic_moment(dd, area, medium),
                  potency=area * np.linalg.norm(dd, axis=1), area=area, displacement_discontinuity=dd,
                  normal=normal, fracture_id=np.full(count, -1, np.int64) if fracture_id is None
                  else np.asarray(fracture_id, np.int64))


def merge_neighbours(events, radius, medium):
    """Merge events of the same fracture that start in the same step and whose centres
    lie within ``radius[i] + radius[j]`` (m, e.g. the elements' half diagonals) into one
    event each: moment tensors and potencies add, the position is the area-weighted
    centroid, the time the common onset."""
    count = len(events)
    if count == 0:
        return events
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (count,))
    pairs = cKDTree(events.position).query_pairs(1.0001 * 2.0 * float(radius.max()), output_type="ndarray")
    if len(pairs):
        i, j = pairs[:, 0], pairs[:, 1]
        distance = np.linalg.norm(events.position[i] - events.position[j], axis=1)
        keep = ((distance <= 1.0001 * (radius[i] + radius[j])) & (events.step[i] == events.step[j])
                & (events.fracture_id[i] == events.fracture_id[j]))
        i, j = i[keep], j[keep]
    else:
        i = j = np.zeros(0, dtype=np.int64)
    graph = coo_matrix((np.ones(len(i)), (i, j)), shape=(count, count))
    groups, labels = connected_components(graph, directed=False)

    def summed(values):
        out = np.zeros((groups,) + values.shape[1:])
        np.add.at(out, labels, values)
        return out

    area = summed(events.area)
    weighted = events.area[:, None]
    first = np.zeros(groups, dtype=np.int64)
    first[labels[::-1]] = np.arange(count)[::-1]
    potency_vector = summed(events.displacement_discontinuity * weighted)
    return Events(position=summed(events.position * weighted) / area[:, None], time=events.time[first],
                  step=events.step[first], moment_tensor=summed(events.moment_tensor),
                  seismic_moment=medium.shear_modulus * summed(events.potency), potency=summed(events.potency),
                  area=area, displacement_discontinuity=potency_vector / area[:, None],
                  normal=_unit(summed(events.normal * weighted)), fracture_id=events.fracture_id[first],
                  elements=summed(events.elements.astype(float)).astype(np.int64))


def _unit(vectors):
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


class SlipOnset:
    """The first time each element slips, from a series of states (ref. Sec. 7.4.1).

    Feed it states in time order with :meth:`observe` (the .vtu series of a run, or
    ``Simulation.view()`` after every step); elements are matched between states by
    their centres (elements never move; the mesh grows and natural elements join it).
    An element's onset is the first observed state in which the caller flags it as
    slipping (a failed natural element with non-zero slip); once set it stays. The time
    resolution is that of the states fed (``output.every`` steps for a .vtu series).
    """

    def __init__(self, tolerance=1e-6):
        self.tolerance = float(tolerance)
        self.centers = np.zeros((0, 3))
        self.time = np.zeros(0)
        self.step = np.zeros(0, dtype=np.int64)

    def observe(self, centers, slipping, time, step):
        """Record the onset of elements at ``centers`` (M, d) flagged ``slipping`` (M,)."""
        centers = _as_3d(centers)[np.asarray(slipping, dtype=bool)]
        if len(centers) == 0:
            return
        if len(self.centers):
            distance, _ = cKDTree(self.centers).query(centers, distance_upper_bound=self.tolerance)
            centers = centers[~np.isfinite(distance)]
        self.centers = np.vstack([self.centers, centers])
        self.time = np.concatenate([self.time, np.full(len(centers), float(time))])
        self.step = np.concatenate([self.step, np.full(len(centers), int(step), dtype=np.int64)])

    def onset(self, centers, final_time, final_step):
        """``(time, step)`` of the elements at ``centers``; never observed: the final ones."""
        centers = _as_3d(centers)
        time = np.full(len(centers), float(final_time))
        step = np.full(len(centers), int(final_step), dtype=np.int64)
        if len(self.centers) and len(centers):
            distance, index = cKDTree(self.centers).query(centers, distance_upper_bound=self.tolerance)
            found = np.isfinite(distance)
            time[found], step[found] = self.time[index[found]], self.step[index[found]]
        return time, step


def _as_3d(points):
    points = np.atleast_2d(np.asarray(points, dtype=float))
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points


def shear_events(centers, normals, displacement_discontinuity, areas, medium, fracture_id, onset=None,
                 final_time=0.0, final_step=0, shear_ratio=DEFAULT_SHEAR_RATIO, merge=False, radius=None):
    """Events of the elements that failed in shear (ref. Sec. 7.4.1, Eq. 7.29).

    ``centers``, ``normals`` and ``displacement_discontinuity`` are (N, 2) in a
    plane-strain run (embedded at z = 0) or (N, 3); ``areas`` (N,) m^2 (in 2D the segment
    length times the flow height); the arrays hold the candidate elements only (the
    failed natural ones). The DD is the final, quasi-static one (ref. Eq. 7.14).
    ``onset`` is a :class:`SlipOnset` (None: every event at ``final_time``). ``merge``
    joins neighbouring elements that start in the same step (``radius``: their half
    diagonals); the default, one event per element, is the reference's choice and keeps
    the location of every event on its element.
    """
    shear_ratio = MICROSEISMIC["shear_ratio"].value("shear_ratio", shear_ratio)
    centers, normals = _as_3d(centers), _as_3d(normals)
    dd = _as_3d(displacement_discontinuity)
    areas = np.asarray(areas, dtype=float)
    fracture_id = np.asarray(fracture_id, dtype=np.int64)
    keep = is_shear_failure(dd, normals, shear_ratio) if len(dd) else np.zeros(0, bool)
    centers, normals, dd, areas, fracture_id = centers[keep], normals[keep], dd[keep], areas[keep], fracture_id[keep]
    if onset is None:
        time = np.full(len(centers), float(final_time))
        step = np.full(len(centers), int(final_step), dtype=np.int64)
    else:
        time, step = onset.onset(centers, final_time, final_step)
    order = np.lexsort((fracture_id, time))
    events = Events(position=centers[order], time=time[order], step=step[order],
                    moment_tensor=moment_tensor(dd[order], normals[order], areas[order], medium),
                    seismic_moment=seismic_moment(dd[order], areas[order], medium),
                    potency=areas[order] * np.linalg.norm(dd[order], axis=1), area=areas[order],
                    displacement_discontinuity=dd[order], normal=normals[order], fracture_id=fracture_id[order])
    if merge and len(events):
        if radius is None:
            raise InputError("merge needs the element radii (radius)")
        events = merge_neighbours(events, np.asarray(radius, dtype=float)[keep][order], medium)
    return events
