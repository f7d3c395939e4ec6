"""Synthetic natural-fracture networks (ref. Sec. 6.2): the parameters (:class:`NetworkSpec`),
the network of straight vertical fractures (:class:`Network`) and its meshes, and the
generator that places power-law lengths and von Mises strikes (the sampling laws of
:mod:`hmatddm.network.sampling`) uniformly at a given areal density.

Conventions
-----------
* Plan view, SI units (m). Every fracture is a straight segment in the x-y plane; in
  3D it is a vertical rectangle of the network's ``height`` centred at ``z_center``.
* **Azimuth** ``theta`` is the strike direction measured from the +x axis,
  counter-clockwise, as in the reference ("45 deg and 135 deg from the x axis",
  Fig. 6.14). Strikes are undirected lines (axial data), so azimuths live in
  ``[0, pi)``; a fracture runs from ``p0`` to ``p1 = p0 + l (cos theta, sin theta)``.
  The sampling functions take and return radians; :class:`NetworkSpec` takes degrees.
* **Concentration** ``kappa`` is that of the doubled angle (:mod:`hmatddm.network.sampling`).
* **Density** is the areal density of Eq. 6.12: ``N_NF = rho_NF * A`` fractures
  (fracture *centres*, not trace length) per square metre of the region; ``N_NF`` is
  rounded to the nearest integer and is exactly the number of fractures generated.
"""
from dataclasses import dataclass, field

import numpy as np

from .. import mesh as _mesh
from .._validation import finite_array, finite_scalar, positive_int, positive_scalar
from ..errors import InputError
from ..settings import NETWORK_GENERATOR, NETWORK_GEOMETRY, show
from .sampling import bimodal_directions, power_law_lengths, von_mises_directions  # noqa: F401  (re-exported)


def check_spec(values, prefix=""):
    """The checks between the fields of a network generator (each field already in its
    range of :data:`hmatddm.settings.NETWORK_GENERATOR`): ``values`` maps the field names
    of :class:`NetworkSpec` (the ``network.*`` keys of a scene) to plain numbers and
    lists; messages name ``prefix + field``. Returns the weights of the orientation
    sets (equal when ``values["weights"]`` is None or absent), summing to 1."""
    x_min, x_max, y_min, y_max = values["region"]
    if not (x_min < x_max and y_min < y_max):
        raise InputError(f"{prefix}region must be [x_min, x_max, y_min, y_max] with x_min < x_max and "
                         f"y_min < y_max, got {show(list(values['region']))}")
    area = (x_max - x_min) * (y_max - y_min)
    if round(values["density"] * area) < 1:
        raise InputError(f"{prefix}density must be >= {0.5 / area:.6g} 1/m^2 so that {prefix}region "
                         f"(area {area:.6g} m^2) holds at least one fracture (ref. Eq. 6.12), "
                         f"got {show(values['density'])}")
    if values["l_max"] < values["l_min"]:
        raise InputError(f"{prefix}l_max must be >= {prefix}l_min = {show(values['l_min'])} m, "
                         f"got {show(values['l_max'])}")
    modes = len(values["mean_azimuths_deg"])
    weights = values.get("weights")
    weights = [1.0 / modes] * modes if weights is None else list(weights)
    if len(values["kappas"]) != modes or len(weights) != modes:
        raise InputError(f"{prefix}mean_azimuths_deg, {prefix}kappas and {prefix}weights must have the same "
                         f"length (one entry per orientation set), got {modes}, {len(values['kappas'])}, "
                         f"{len(weights)}")
    if abs(sum(weights) - 1.0) > 1e-9:
        raise InputError(f"{prefix}weights must sum to 1, got {show(weights)} (sum {sum(weights):.6g})")
    fit = min(x_max - x_min, y_max - y_min)
    if values["boundary"] == "resample" and values["l_max"] > fit:
        raise InputError(f"{prefix}l_max must be <= min(region width, region height) = {fit:.6g} m with "
                         f"{prefix}boundary = 'resample' (use 'clip' for longer fractures), "
                         f"got {show(values['l_max'])}")
    return [w / sum(weights) for w in weights]


def _as_tuple(name, value):
    array = np.atleast_1d(finite_array(name, value))
    if array.ndim != 1 or array.size == 0:
        raise InputError(f"{name} must be a number or a non-empty 1D sequence, got shape {array.shape}")
    return tuple(float(v) for v in array)


@dataclass(frozen=True)
class NetworkSpec:
    """Parameters of a synthetic natural-fracture network (ref. Sec. 6.2, Table 6.1).

    Attributes
    ----------
    region : (x_min, x_max, y_min, y_max), m; the plan-view rectangle that holds the
        network. The reference's 100 m x 100 m domain is ``(-50, 50, -50, 50)``.
    density : areal density ``rho_NF`` of Eq. 6.12, fractures (centres) per m^2;
        ``round(density * area)`` fractures are generated (at least one).
    length_exponent : ``a`` of the power law ``f(l) ~ l^-a`` (Eq. 6.1), >= 1.
    l_min, l_max : length limits ``l_0 <= l <= l_1`` (Eq. 6.4), m.
    mean_azimuths_deg : mean strike of each orientation set, degrees from the +x axis
        counter-clockwise (45 deg is the reference's ``mu = pi/4``); a number or a
        sequence (one entry per set, Eq. 6.10).
    kappas : von Mises concentration of the doubled angle of each set, >= 0.
    weights : mixing factor of each set, >= 0, summing to 1; None means equal weights.
    height : height of every (vertical) fracture in 3D, m.
    z_center : depth of the fractures' mid-height, m.
    seed : integer >= 0 for ``numpy.random.default_rng`` (None: fresh entropy).
    boundary : how fractures are kept inside ``region``:

        * ``"resample"`` (default): every fracture keeps its sampled length and strike;
          its centre is drawn uniformly among the positions where the whole fracture
          fits in the region (the same law as redrawing the centre until it fits).
          Lengths and strikes follow Eqs. 6.4 and 6.10 exactly; centres thin out near
          the boundary. Needs ``l_max <= min(region width, region height)``.
        * ``"clip"``: centres are uniform in the region and fractures are cut at its
          boundary, like a mapping window. Positions are exactly uniform; fractures that
          reach the boundary are shorter than sampled (possibly below ``l_min``).
    """

    region: tuple
    density: float
    length_exponent: float = NETWORK_GENERATOR["length_exponent"].default
    l_min: float = NETWORK_GENERATOR["l_min"].default
    l_max: float = NETWORK_GENERATOR["l_max"].default
    mean_azimuths_deg: tuple = tuple(NETWORK_GENERATOR["mean_azimuths_deg"].default)
    kappas: tuple = tuple(NETWORK_GENERATOR["kappas"].default)
    weights: tuple = None
    height: float = NETWORK_GEOMETRY["height"].default
    z_center: float = NETWORK_GEOMETRY["z_center"].default
    seed: int = NETWORK_GENERATOR["seed"].default
    boundary: str = NETWORK_GENERATOR["boundary"].default

    def __post_init__(self):
        def put(name, value):
            object.__setattr__(self, name, value)

        values = {"region": list(finite_array("region", self.region, (4,))),
                  "mean_azimuths_deg": list(_as_tuple("mean_azimuths_deg", self.mean_azimuths_deg)),
                  "kappas": list(_as_tuple("kappas", self.kappas)),
                  "weights": None if self.weights is None else list(_as_tuple("weights", self.weights))}
        for name, setting in {**NETWORK_GENERATOR, **NETWORK_GEOMETRY}.items():
            value = values.get(name, getattr(self, name))
            if not (name == "seed" and value is None):  # seed None: fresh entropy
                put(name, setting.value(name, value))
        put("weights", check_spec(self.__dict__))
        for name in ("region", "mean_azimuths_deg", "kappas", "weights"):
            put(name, tuple(getattr(self, name)))

    @property
    def area(self):
        x_min, x_max, y_min, y_max = self.region
        return (x_max - x_min) * (y_max - y_min)

    @property
    def n_fractures(self):
        """``N_NF = rho_NF A`` (Eq. 6.12), rounded to the nearest integer."""
        return int(np.rint(self.density * self.area))


@dataclass(frozen=True, eq=False)
class Network:
    """A plan-view network of straight vertical fractures, as a struct of arrays.

    Each row is one straight *segment*; a fracture may consist of several collinear
    segments that meet end to end (e.g. after :func:`~hmatddm.network.split_at_intersections`).

    Attributes
    ----------
    p0, p1 : (M, 2) segment end points, m
    fracture_id : (M,) int, the fracture each segment belongs to
    set_id : (M,) int, the orientation set (mode of Eq. 6.10) of each segment
    height : fracture height in 3D, m
    z_center : depth of the fractures' mid-height, m
    region : (x_min, x_max, y_min, y_max) or None
    """

    p0: np.ndarray
    p1: np.ndarray
    fracture_id: np.ndarray
    set_id: np.ndarray
    height: float = 1.0
    z_center: float = 0.0
    region: tuple = field(default=None)

    @classmethod
    def from_segments(cls, p0, p1, fracture_id=None, set_id=None, height=1.0, z_center=0.0, region=None):
        """A network from segment end points ``p0``, ``p1`` (M, 2), validated.

        ``fracture_id`` defaults to ``0..M-1`` (one fracture per segment), ``set_id`` to
        zeros; ``region`` (x_min, x_max, y_min, y_max) defaults to None.
        """
        p0 = finite_array("p0", p0, (None, 2))
        p1 = finite_array("p1", p1, (None, 2))
        if p0.shape != p1.shape:
            raise InputError(f"p0 and p1 must have the same shape, got {p0.shape} and {p1.shape}")
        m = len(p0)
        lengths = np.hypot(*(p1 - p0).T) if m else np.zeros(0)
        scale = max(1.0, float(np.max(np.abs(np.concatenate([p0, p1]))))) if m else 1.0
        bad = np.flatnonzero(lengths <= 1e-12 * scale)
        if bad.size:
            raise InputError(f"segment lengths must be > 0; segment {int(bad[0])} has zero length")
        ids = {}
        for name, value, default in (("fracture_id", fracture_id, np.arange(m)),
                                     ("set_id", set_id, np.zeros(m, dtype=np.int64))):
            value = default if value is None else np.asarray(value)
            if value.shape != (m,) or not (np.issubdtype(value.dtype, np.integer) or m == 0):
                raise InputError(f"{name} must be an integer array of shape ({m},), got {value.dtype} {value.shape}")
            ids[name] = value.astype(np.int64)
        if np.any(ids["fracture_id"] < 0):
            raise InputError("fracture_id must be >= 0")
        if region is not None:
            region = tuple(float(v) for v in finite_array("region", region, (4,)))
            if not (region[0] < region[1] and region[2] < region[3]):
                raise InputError(f"region must be (x_min, x_max, y_min, y_max) with x_min < x_max and "
                                 f"y_min < y_max, got {region}")
        return cls(p0, p1, ids["fracture_id"], ids["set_id"], positive_scalar("height", height),
                   finite_scalar("z_center", z_center), region)

    def __len__(self):
        return len(self.p0)

    @property
    def n_segments(self):
        return len(self.p0)

    @property
    def n_fractures(self):
        """Number of distinct fractures."""
        return int(np.unique(self.fracture_id).size)

    @property
    def lengths(self):
        """(M,) segment lengths, m."""
        d = self.p1 - self.p0
        return np.hypot(d[:, 0], d[:, 1])

    @property
    def azimuths(self):
        """(M,) strikes in ``[0, pi)``, radians from the +x axis counter-clockwise."""
        d = self.p1 - self.p0
        return np.mod(np.arctan2(d[:, 1], d[:, 0]), np.pi)

    @property
    def tangents(self):
        """(M, 2) unit vectors from ``p0`` to ``p1``."""
        d = self.p1 - self.p0
        return d / np.hypot(d[:, 0], d[:, 1])[:, None]

    @property
    def centers(self):
        return 0.5 * (self.p0 + self.p1)

    @property
    def bounds(self):
        """The region, or the bounding box (x_min, x_max, y_min, y_max) of the segments."""
        if self.region is not None:
            return self.region
        points = np.concatenate([self.p0, self.p1])
        return (float(points[:, 0].min()), float(points[:, 0].max()),
                float(points[:, 1].min()), float(points[:, 1].max()))

    def subset(self, index):
        index = np.asarray(index)
        return Network(self.p0[index], self.p1[index], self.fracture_id[index], self.set_id[index],
                       self.height, self.z_center, self.region)

    def _strike_elements(self, element_length):
        """Cut every segment into ``max(1, round(length / element_length))`` equal parts.

        Returns the segment index of each element and its end points. Nodes are convex
        combinations ``(1 - s) p0 + s p1``, so the first and last nodes are exactly
        ``p0`` and ``p1`` (shared intersection points stay shared).
        """
        h = positive_scalar("element_length", element_length)
        if len(self) == 0:
            raise InputError("the network must hold at least one segment to be meshed")
        counts = np.maximum(1, np.rint(self.lengths / h)).astype(np.int64)
        segment = np.repeat(np.arange(len(self)), counts)
        offsets = np.concatenate([[0], np.cumsum(counts)[:-1]])
        local = np.arange(segment.size) - offsets[segment]
        s0 = (local / counts[segment])[:, None]
        s1 = ((local + 1) / counts[segment])[:, None]
        p0, p1 = self.p0[segment], self.p1[segment]
        return segment, (1.0 - s0) * p0 + s0 * p1, (1.0 - s1) * p0 + s1 * p1

    def to_mesh2d(self, element_length):
        """A :class:`~hmatddm.mesh.Mesh2D` (plane strain): every segment cut into
        ``max(1, round(length / element_length))`` equal elements, ordered segment by
        segment from ``p0`` to ``p1``; ``fracture_id`` is the segment's fracture."""
        segment, a, b = self._strike_elements(element_length)
        return _mesh.Mesh2D.from_segments(a, b, fracture_id=self.fracture_id[segment])

    def to_mesh3d(self, element_length, n_height):
        """A :class:`~hmatddm.mesh.Mesh3D` of vertical rectangles spanning the full
        ``height`` (``z_center +- height/2``).

        Along strike each segment is cut as in :meth:`to_mesh2d`; over the height into
        ``n_height`` equal rows. Element axes: ``e1`` the strike tangent (p0 -> p1),
        ``e2 = +z``, normal ``e1 x e2 = (t_y, -t_x, 0)``. Order: segment, then along
        strike, then bottom to top (as :func:`hmatddm.mesh.rectangle`).
        """
        n_height = positive_int("n_height", n_height)
        segment, a, b = self._strike_elements(element_length)
        n_strike = len(segment)
        tangent = b - a
        half_a = 0.5 * np.hypot(tangent[:, 0], tangent[:, 1])
        tangent = tangent / (2.0 * half_a[:, None])
        z = self.z_center + ((np.arange(n_height) + 0.5) / n_height - 0.5) * self.height
        mid = 0.5 * (a + b)
        centers = np.column_stack([np.repeat(mid, n_height, axis=0), np.tile(z, n_strike)])
        e1 = np.column_stack([np.repeat(tangent, n_height, axis=0), np.zeros(n_strike * n_height)])
        e2 = np.array([0.0, 0.0, 1.0])
        return _mesh.Mesh3D.from_rectangles(centers, e1, e2, np.repeat(half_a, n_height),
                                            np.full(n_strike * n_height, 0.5 * self.height / n_height),
                                            fracture_id=np.repeat(self.fracture_id[segment], n_height))


def _clip_to_region(center, half_vector, region):
    """Liang-Barsky: the part of ``center + s * half_vector``, ``s in [-1, 1]``, inside
    ``region``, for centres inside the region. Returns (p0, p1)."""
    x_min, x_max, y_min, y_max = region
    s_lo = np.full(len(center), -1.0)
    s_hi = np.full(len(center), 1.0)
    for axis, (low, high) in enumerate(((x_min, x_max), (y_min, y_max))):
        d = half_vector[:, axis]
        moving = d != 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            to_low = (low - center[:, axis]) / d
            to_high = (high - center[:, axis]) / d
        enter = np.where(d > 0, to_low, to_high)
        leave = np.where(d > 0, to_high, to_low)
        s_lo = np.where(moving, np.maximum(s_lo, enter), s_lo)
        s_hi = np.where(moving, np.minimum(s_hi, leave), s_hi)
    return center + s_lo[:, None] * half_vector, center + s_hi[:, None] * half_vector


def generate_network(spec):
    """Draw the network described by ``spec`` (a :class:`NetworkSpec`).

    Random numbers come from ``numpy.random.default_rng(spec.seed)`` in a fixed order
    (lengths, then set membership and strikes, then centres), so one seed always gives
    the same arrays. ``N = round(density * area)`` fractures (Eq. 6.12); lengths from
    :func:`power_law_lengths`, strikes from :func:`bimodal_directions`, centres uniform
    (see ``spec.boundary`` for how fractures are kept inside the region). Fracture ``k``
    runs from ``p0[k]`` to ``p1[k]`` along its strike; ``fracture_id`` is ``0..N-1``.
    """
    if not isinstance(spec, NetworkSpec):
        raise InputError(f"spec must be a NetworkSpec, got {type(spec).__name__}")
    rng = np.random.default_rng(spec.seed)
    n = spec.n_fractures
    lengths = power_law_lengths(n, spec.length_exponent, spec.l_min, spec.l_max, rng)
    azimuths, modes = bimodal_directions(n, np.radians(spec.mean_azimuths_deg), spec.kappas, spec.weights,
                                         rng, return_modes=True)
    tangent = np.column_stack([np.cos(azimuths), np.sin(azimuths)])
    half_vector = 0.5 * lengths[:, None] * tangent
    x_min, x_max, y_min, y_max = spec.region
    if spec.boundary == "resample":
        reach = np.abs(half_vector)
        cx = rng.uniform(x_min + reach[:, 0], x_max - reach[:, 0])
        cy = rng.uniform(y_min + reach[:, 1], y_max - reach[:, 1])
        center = np.column_stack([cx, cy])
        p0, p1 = center - half_vector, center + half_vector
    else:
        center = np.column_stack([rng.uniform(x_min, x_max, n), rng.uniform(y_min, y_max, n)])
        p0, p1 = _clip_to_region(center, half_vector, spec.region)
    low, high = np.array([x_min, y_min]), np.array([x_max, y_max])
    p0, p1 = np.clip(p0, low, high), np.clip(p1, low, high)  # round-off only
    return Network.from_segments(p0, p1, fracture_id=np.arange(n), set_id=modes, height=spec.height,
                                 z_center=spec.z_center, region=spec.region)


__all__ = ["power_law_lengths", "von_mises_directions", "bimodal_directions", "NetworkSpec", "Network",
           "generate_network"]
