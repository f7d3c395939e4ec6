"""File output that other programs read: VTK XML for ParaView, written atomically.

* :func:`write_vtu`: one mesh with per-element fields (``.vtu``, unstructured grid).
* :func:`write_pvd`: a time collection of ``.vtu`` files (``.pvd``), for ParaView's
  time slider.
* :func:`read_vtu`, :func:`read_pvd`: read them back (for tests and post-processing).
* :func:`atomic_output`: the write-to-a-temporary-then-rename helper every writer uses,
  so that a reader (or a crash) never sees a half-written file, and a failed write (a
  full disk, a folder that is not writable) raises :class:`~hmatddm.errors.OutputError`
  naming the file, its folder and the reason, with the previous file left intact.
"""
from .atomic import atomic_output
from .vtk import read_pvd, read_vtu, write_pvd, write_vtu
from ..errors import OutputError  # noqa: F401  (re-exported)

__all__ = ["write_vtu", "write_pvd", "read_vtu", "read_pvd", "atomic_output", "OutputError"]
