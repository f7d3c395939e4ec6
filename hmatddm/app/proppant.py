"""The proppant outputs of a run folder (issue 34, :mod:`hmatddm.simulation.proppant_step`):
the .vtu cell fields ``proppant_fraction`` and ``propped_width``, the concentration snapshot
``snapshots/step-NNNNNN_proppant.png`` and ``proppant_history.png``."""
from pathlib import Path

import numpy as np

from .run_folder import PROPPANT_HISTORY, SNAPSHOT_DIR, snapshot_title


def proppant_fields(simulation):
    """``proppant_fraction`` and ``propped_width`` of every element of the run's view; {}
    without proppant."""
    from ..simulation.proppant_step import cell_fields

    return cell_fields(simulation)


def write_proppant_snapshot(out, simulation, name):
    """``snapshots/step-NNNNNN_proppant.png`` of the simulation's state: the proppant volume
    fraction of its active elements (:func:`hmatddm.render.proppant.plot_proppant`)."""
    from ..render.proppant import plot_proppant
    from ..simulation.proppant_step import concentration, flow_areas

    s = simulation.state
    width = np.sum(s.dd * s.mesh.normals, axis=1)
    fraction = concentration(simulation, s.proppant_volume, width, flow_areas(simulation, s.mesh))
    title = (f"{snapshot_title(name, s.time, s.mesh)}: proppant volume fraction, "
             f"{simulation.proppant.density * float(np.sum(s.proppant_volume)):.4g} kg in place")
    path = Path(out) / SNAPSHOT_DIR / f"step-{s.step:06d}_proppant.png"
    return plot_proppant(s.mesh, fraction, path, simulation.proppant.packing_limit, title)


def write_proppant_history(out, records, name):
    """``proppant_history.png``: proppant mass pumped and in the fractures against time."""
    from ..render.proppant import plot_proppant_history

    return plot_proppant_history(records, Path(out) / PROPPANT_HISTORY, title=f"{name}: proppant mass")
