"""Forward model of microseismic events (ref. Sec. 7.2.2): receivers along vertical
observation wells; per event and receiver the P and S travel times, the direction
cosines, the radiation-pattern factors and the low-frequency far-field amplitudes.

For a source with moment tensor ``M`` (N m) seen at distance ``r`` in the direction
``gamma`` (unit vector from the source to the receiver) in a homogeneous isotropic
medium (ref. Eqs 7.15-7.20)::

    Omega_P = |gamma_i gamma_j M_jk gamma_k|            / (4 pi rho v_P^3 r) = M0 F_P / (4 pi rho v_P^3 r)
    Omega_S = |(delta_ij - gamma_i gamma_j) M_jk gamma_k| / (4 pi rho v_S^3 r) = M0 F_S / (4 pi rho v_S^3 r)

with ``F = |R gamma M_hat| / mu`` the radiation-pattern correction factors and
``M_hat = M / (A d)``. Everything is vectorised over events x receivers (chunks of
events bound the memory).
"""
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..settings import MICROSEISMIC

CHUNK = 4096  # events per chunk: (chunk, receivers, 3) arrays stay small


@dataclass(frozen=True)
class Well:
    """A vertical observation well at plan position ``(x, y)`` (m) with receivers every
    ``spacing`` m from ``bottom`` to ``top`` (z, m; ref. Sec. 7.4.2: every 5 m from -20
    to 20 m)."""

    x: float
    y: float
    top: float = MICROSEISMIC["receiver_top"].default
    bottom: float = MICROSEISMIC["receiver_bottom"].default
    spacing: float = MICROSEISMIC["receiver_spacing"].default

    def receivers(self):
        """Receiver positions (K, 3), from the bottom up."""
        count = int(np.floor((self.top - self.bottom) / self.spacing + 1e-9)) + 1
        z = self.bottom + self.spacing * np.arange(count)
        return np.column_stack([np.full(count, self.x), np.full(count, self.y), z])


def wells_from_positions(positions, top=Well.top, bottom=Well.bottom, spacing=Well.spacing, prefix=""):
    """Wells at plan positions ``[[x, y], ...]``; refuses no wells, a bad depth range
    or spacing, naming ``prefix + field``."""
    positions = np.asarray(positions, dtype=float) if len(positions) else np.zeros((0, 2))
    if positions.ndim != 2 or positions.shape[1] != 2 or len(positions) == 0:
        raise InputError(f"{prefix}wells must hold at least one [x, y] well position (m), got "
                         f"{np.asarray(positions).tolist()}")
    if not np.all(np.isfinite(positions)):
        raise InputError(f"{prefix}wells must hold finite [x, y] positions (m)")
    top, bottom, spacing = (MICROSEISMIC[key].value(prefix + key, value) for key, value in
                            (("receiver_top", top), ("receiver_bottom", bottom), ("receiver_spacing", spacing)))
    if bottom > top:
        raise InputError(f"{prefix}receiver_bottom must be <= {prefix}receiver_top = {top:.6g} m, got {bottom:.6g}")
    return [Well(float(x), float(y), top, bottom, spacing) for x, y in positions]


def receivers_of(wells):
    """``(receivers (R, 3), well index (R,))`` of a list of :class:`Well`."""
    if not wells:
        raise InputError("wells must hold at least one observation well")
    parts = [well.receivers() for well in wells]
    return np.vstack(parts), np.concatenate([np.full(len(p), i) for i, p in enumerate(parts)])


def check_receivers(sources, receivers, minimum_distance=1e-6, name="wells"):
    """Refuse receivers on a source (closer than ``minimum_distance`` m): the far-field
    amplitudes and direction cosines are undefined there."""
    sources = np.atleast_2d(np.asarray(sources, dtype=float))
    receivers = finite_array(name, np.atleast_2d(receivers), shape=(None, 3))
    if len(receivers) == 0:
        raise InputError(f"{name} must hold at least one receiver")
    if len(sources) == 0:
        return
    from scipy.spatial import cKDTree

    distance, index = cKDTree(receivers).query(sources)
    worst = int(np.argmin(distance))
    if distance[worst] < minimum_distance:
        raise InputError(f"{name}: receiver at {receivers[index[worst]].tolist()} m lies on a source (event at "
                         f"{sources[worst].tolist()} m, {distance[worst]:.3g} m away); move the well so that every "
                         f"receiver is > {minimum_distance:g} m from every event")


@dataclass
class Observations:
    """What the receivers record, arrays (E, R) unless noted.

    ``distance`` r (m); ``direction`` (E, R, 3) unit vectors from source to receiver;
    ``travel_time_p``, ``travel_time_s`` (s); ``amplitude_p``, ``amplitude_s`` the
    low-frequency amplitudes Omega_0 (m s, the DC level of the displacement spectrum);
    ``factor_p``, ``factor_s`` the radiation-pattern factors F_P, F_S; ``receivers``
    (R, 3) and ``well`` (R,) the receiver positions and the well each belongs to.
    """

    receivers: np.ndarray
    well: np.ndarray
    distance: np.ndarray
    direction: np.ndarray
    travel_time_p: np.ndarray
    travel_time_s: np.ndarray
    amplitude_p: np.ndarray
    amplitude_s: np.ndarray
    factor_p: np.ndarray
    factor_s: np.ndarray

    @property
    def s_minus_p(self):
        """Differential arrival time ``t_S - t_P`` (s), ref. Eq. 7.23."""
        return self.travel_time_s - self.travel_time_p

    def receiver_subset(self, index):
        """The observations of some receivers only (e.g. one well)."""
        index = np.asarray(index)
        return Observations(receivers=self.receivers[index], well=self.well[index],
                            **{name: getattr(self, name)[:, index] for name in
                               ("distance", "direction", "travel_time_p", "travel_time_s", "amplitude_p",
                                "amplitude_s", "factor_p", "factor_s")})


def radiation_projections(moment_tensors, direction):
    """``(|gamma M gamma|, |(I - gamma gamma) M gamma|)`` for moment tensors (E, 3, 3)
    and directions (E, R, 3): the P and S numerators of ref. Eqs 7.15-7.16."""
    projected = np.einsum("eij,erj->eri", moment_tensors, direction)
    p_part = np.einsum("eri,eri->er", projected, direction)
    s_vector = projected - p_part[:, :, None] * direction
    return np.abs(p_part), np.sqrt(np.einsum("eri,eri->er", s_vector, s_vector))


def radiation_factors(moment_tensors, direction, seismic_moment, shear_modulus):
    """``(F_P, F_S)`` (E, R) of ref. Eqs 7.19-7.20: the projections of the unit moment
    tensor ``M_hat = mu M / M0`` over ``mu``."""
    p_part, s_part = radiation_projections(moment_tensors, direction)
    scale = 1.0 / np.asarray(seismic_moment, dtype=float)[:, None]
    return p_part * scale, s_part * scale


def observe(events, receivers, medium, well=None, minimum_distance=1e-6, field="wells"):
    """Noise-free observations of ``events`` (:class:`~hmatddm.microseismic.sources.Events`)
    at ``receivers`` (R, 3) in ``medium`` (ref. Sec. 7.2.2). ``well`` (R,) labels the
    receivers by well (default 0). Refuses a receiver on an event (the message names
    ``field``)."""
    receivers = finite_array("receivers", np.atleast_2d(receivers), shape=(None, 3))
    check_receivers(events.position, receivers, minimum_distance, name=field)
    count, stations = len(events), len(receivers)
    fields = {name: np.empty((count, stations)) for name in
              ("distance", "travel_time_p", "travel_time_s", "amplitude_p", "amplitude_s", "factor_p", "factor_s")}
    direction = np.empty((count, stations, 3))
    p_scale = 1.0 / (4.0 * np.pi * medium.density * medium.p_wave_speed ** 3)
    s_scale = 1.0 / (4.0 * np.pi * medium.density * medium.s_wave_speed ** 3)
    for start in range(0, count, CHUNK):
        part = slice(start, min(count, start + CHUNK))
        offset = receivers[None, :, :] - events.position[part, None, :]
        distance = np.sqrt(np.einsum("eri,eri->er", offset, offset))
        gamma = offset / distance[:, :, None]
        p_part, s_part = radiation_projections(events.moment_tensor[part], gamma)
        fields["distance"][part] = distance
        direction[part] = gamma
        fields["travel_time_p"][part] = distance / medium.p_wave_speed
        fields["travel_time_s"][part] = distance / medium.s_wave_speed
        fields["amplitude_p"][part] = p_scale * p_part / distance
        fields["amplitude_s"][part] = s_scale * s_part / distance
        moment = events.seismic_moment[part, None]
        fields["factor_p"][part] = p_part / moment
        fields["factor_s"][part] = s_part / moment
    well = np.zeros(stations, dtype=np.int64) if well is None else np.asarray(well, dtype=np.int64)
    return Observations(receivers=receivers, well=well, direction=direction, **fields)
