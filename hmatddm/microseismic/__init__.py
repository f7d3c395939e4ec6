"""Synthetic microseismic events from simulations (ref. Ch. 7).

A run's natural-fracture slip becomes point sources with moment tensors (``sources``),
recorded at receivers in vertical observation wells (``forward``), perturbed by seeded
measurement noise (``noise``) and inverted back: location, Brune moment and source
orientation and potency with what the data cannot separate (``inversion``); fracture
traces are fitted to located event clouds (``planes``). The H-matrix machinery plays no
part here, nor do run folders: the catalogue of a finished run (``events.csv``) is the
application's (:mod:`hmatddm.app.catalogue`), and the event map is drawn by
:mod:`hmatddm.render.microseismic_maps` (docs/architecture.md).

    from hmatddm.app.catalogue import catalogue_for_folder
    paths, catalogue = catalogue_for_folder("hmatddm-runs/dfn-3cluster", scene="dfn-3cluster")

Conventions: SI units, ``docs/conventions.md`` (moment tensor ``M_ij = A C_ijkl DD_k n_l``,
a tensile opening has a positive isotropic part), dynamic moduli from the wave speeds.
"""
from .forward import Observations, Well, observe, radiation_factors, receivers_of, wells_from_positions
from .inversion import (RMS_FACTOR_P, RMS_FACTOR_S, SourceSolution, SourceSpread, brune_moment,
                        dislocation_from_moment_tensor, dislocation_twins, invert_source, invert_source_draws, locate,
                        location_error, orientation_error, unresolved_direction)
from .monitoring import MonitoringSettings, check_section, settings_from_section
from .noise import (LARGE_AMPLITUDE_NOISE, LARGE_LOCATION_NOISE, NO_NOISE, SMALL_AMPLITUDE_NOISE,
                    SMALL_LOCATION_NOISE, NoiseLevels, add_noise)
from .planes import fit_traces, strike_errors, true_trace_azimuths
from .sources import (Events, Medium, SlipOnset, decompose, moment_magnitude, moment_tensor, point_sources,
                      seismic_moment, shear_events)

__all__ = ["MonitoringSettings", "check_section", "settings_from_section", "Observations", "Well", "observe", "radiation_factors",
           "receivers_of", "wells_from_positions", "RMS_FACTOR_P", "RMS_FACTOR_S", "SourceSolution",
           "SourceSpread", "invert_source_draws", "brune_moment", "dislocation_from_moment_tensor",
           "dislocation_twins", "invert_source", "locate",
           "location_error", "orientation_error", "unresolved_direction", "LARGE_AMPLITUDE_NOISE",
           "LARGE_LOCATION_NOISE", "NO_NOISE", "SMALL_AMPLITUDE_NOISE", "SMALL_LOCATION_NOISE", "NoiseLevels",
           "add_noise", "fit_traces", "strike_errors", "true_trace_azimuths", "Events", "Medium", "SlipOnset",
           "decompose", "moment_magnitude", "moment_tensor", "point_sources", "seismic_moment", "shear_events"]
