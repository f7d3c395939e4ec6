"""The application: the ``hmatddm`` command and what it does with run folders (the top of
the house, docs/architecture.md).

* :mod:`.cli`: the command line (``run``, ``scenes``, ``validate``, ``bench``, ``render``,
  ``microseismic``, ``sweep``); ``main`` is the console script.
* :mod:`.runner`: a scene run with its outputs, checkpoints and resume.
* :mod:`.run_folder`: the layout of a run folder, read and written.
* :mod:`.catalogue`: the microseismic event catalogue of a finished run (ref. Sec. 7.4).
* :mod:`.validate`, :mod:`.bench`: the closed-form checks and the H-matrix benchmark.
* :mod:`.ensemble`: seeded ensembles on Dask (``sweep``).

Nothing below this room imports it.
"""
