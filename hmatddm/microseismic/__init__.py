"""Synthetic microseismic events from simulations (ref. Ch. 7).

A run's natural-fracture slip becomes point sources with moment tensors (``sources``),
recorded at receivers in vertical observation wells (``forward``), perturbed by seeded
measurement noise (``noise``) and inverted back: location, Brune moment and source
orientation and potency with what the data cannot separate (``inversion``); fracture
traces are fitted to located event clouds (``planes``); ``catalogue`` writes
``events.csv`` and ``maps`` the event map. The H-matrix machinery plays no part here.

    from hmatddm import microseismic as ms
    paths, catalogue = ms.catalogue_for_folder("hmatddm-runs/dfn-3cluster", scene="dfn-3cluster")

Conventions: SI units, ``docs/conventions.md`` (moment tensor ``M_ij = A C_ijkl DD_k n_l``,
a tensile opening has a positive isotropic part), dynamic moduli from the wave speeds.
"""
from .catalogue import (Catalogue, MonitoringSettings, catalogue_for_folder, events_from_run, monitor,
                        onset_recorder, read_events_csv, read_run, run_state_from_simulation,
                        settings_from_section, write_catalogue, write_events_csv)
from .forward import Observations, Well, observe, radiation_factors, receivers_of, wells_from_positions
from .inversion import (RMS_FACTOR_P, RMS_FACTOR_S, SourceSolution, SourceSpread, brune_moment,
                        dislocation_from_moment_tensor, dislocation_twins, invert_source, invert_source_draws, locate,
                        location_error, orientation_error, unresolved_direction)
from .noise import (LARGE_AMPLITUDE_NOISE, LARGE_LOCATION_NOISE, NO_NOISE, SMALL_AMPLITUDE_NOISE,
                    SMALL_LOCATION_NOISE, NoiseLevels, add_noise)
from .planes import fit_traces, strike_errors, true_trace_azimuths
from .sources import (Events, Medium, SlipOnset, decompose, moment_magnitude, moment_tensor, point_sources,
                      seismic_moment, shear_events)

__all__ = ["Catalogue", "MonitoringSettings", "catalogue_for_folder", "events_from_run", "monitor",
           "onset_recorder", "read_events_csv", "read_run", "run_state_from_simulation", "settings_from_section",
           "write_catalogue", "write_events_csv", "Observations", "Well", "observe", "radiation_factors",
           "receivers_of", "wells_from_positions", "RMS_FACTOR_P", "RMS_FACTOR_S", "SourceSolution",
           "SourceSpread", "invert_source_draws", "brune_moment", "dislocation_from_moment_tensor",
           "dislocation_twins", "invert_source", "locate",
           "location_error", "orientation_error", "unresolved_direction", "LARGE_AMPLITUDE_NOISE",
           "LARGE_LOCATION_NOISE", "NO_NOISE", "SMALL_AMPLITUDE_NOISE", "SMALL_LOCATION_NOISE", "NoiseLevels",
           "add_noise", "fit_traces", "strike_errors", "true_trace_azimuths", "Events", "Medium", "SlipOnset",
           "decompose", "moment_magnitude", "moment_tensor", "point_sources", "seismic_moment", "shear_events"]
