"""Pictures of a simulation: offscreen pyvista snapshots and matplotlib history plots.

* :func:`snapshot`, :func:`snapshots`: PNG views of the fractures coloured by opening,
  with natural-fracture states and slip arrows (:mod:`hmatddm.render.snapshots`).
* :func:`plot_history`: fracture size, maximum opening and wellbore pressure against
  time, with closed-form curves overlaid (:mod:`hmatddm.render.plots`).

Nothing here opens a window; pyvista and matplotlib are imported on first use.
"""
from .plots import plot_history
from .snapshots import snapshot, snapshots

__all__ = ["snapshot", "snapshots", "plot_history"]
