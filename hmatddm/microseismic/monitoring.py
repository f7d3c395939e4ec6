"""The ``[microseismic]`` scene section as objects: the observation wells, the medium of
the wave speeds, the noise and the event filter (ref. Secs 7.3-7.4).

Physics-side settings, read by the scene schema (:mod:`hmatddm.scene.schema` checks a
section with :func:`check_section`) and by the application's catalogue of a finished run
(:mod:`hmatddm.app.catalogue`); this module reads no run folder.
"""
from dataclasses import dataclass

from .forward import wells_from_positions
from .noise import NoiseLevels
from .sources import DEFAULT_SHEAR_RATIO, Medium, check_wave_speeds


@dataclass(frozen=True)
class MonitoringSettings:
    """The ``[microseismic]`` scene section as objects (see :func:`settings_from_section`)."""

    wells: tuple
    medium: Medium
    noise: NoiseLevels
    seed: int = 0
    shear_ratio: float = DEFAULT_SHEAR_RATIO
    merge: bool = False


def check_section(section, prefix="microseismic."):
    """Cross-key checks of a ``[microseismic]`` echo (ranges are the schema's): at least
    one well, receiver_bottom <= receiver_top, v_S < sqrt(3)/2 v_P. Returns the echo."""
    settings_from_section(section, prefix)
    return section


def settings_from_section(section, prefix="microseismic."):
    """:class:`MonitoringSettings` of a validated ``[microseismic]`` section; InputError
    messages name ``prefix + key``."""
    check_wave_speeds(section["p_wave_speed"], section["s_wave_speed"], section["density"], prefix)
    wells = wells_from_positions(section["wells"], section["receiver_top"], section["receiver_bottom"],
                                 section["receiver_spacing"], prefix)
    noise = NoiseLevels(section["rotation_noise_deg"], section["travel_time_noise"], section["amplitude_noise"])
    return MonitoringSettings(wells=tuple(wells), medium=Medium(section["p_wave_speed"], section["s_wave_speed"],
                                                                section["density"]),
                              noise=noise, seed=int(section["seed"]), shear_ratio=float(section["shear_ratio"]),
                              merge=bool(section["merge"]))


__all__ = ["MonitoringSettings", "check_section", "settings_from_section"]
