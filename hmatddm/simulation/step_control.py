"""Time steps that follow the front (``numerics.time_step = "auto"``).

A fixed step lets the front cross more elements per step as the elements shrink, and
every element row it crosses costs a growth pass (a new solve on the grown mesh): at a
quarter of the element size the radial K scene took 11 passes per step. Planar
level-set simulators instead choose each step so that the front advances about one
element; this module does the same for any mesh, element front or asymptotic front:

* the *advance* of a step is the number of elements it added over the number of
  elements on the front at its start (elements with an edge that no flow face covers:
  tips, and the edges of natural fractures), i.e. the element rows the front crossed;
* the next step is the last one times ``target / advance`` (the front velocity of the
  last step, assumed to hold for the next), at most ``GROWTH`` times longer and at least
  ``1 / GROWTH`` times shorter; a step without growth doubles the next one;
* every step lies in ``[min_time_step, max_time_step]``; the first is
  ``first_time_step``; a run's last step still ends exactly at its end time;
* a step whose solve does not converge is tried again at half its length, from the same
  state and base operator, down to ``min_time_step`` (:meth:`hmatddm.Simulation.step`;
  ``step_retries`` in the record).

The chosen step sizes are in every record (``time_step``) and in the checkpoints, so a
resumed run takes the same steps.
"""
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..settings import NUMERICS

#: The most a step may grow (or shrink) against the previous one.
GROWTH = 2.0


@dataclass(frozen=True)
class StepControl:
    """The settings of front-following steps (see the module docstring): ``advance``
    (element rows per step, ``numerics.step_advance``), ``first`` (s), ``minimum`` (s),
    ``maximum`` (s, None: no bound)."""

    advance: float = 1.0
    first: float = 0.1
    minimum: float = 1e-3
    maximum: float = None

    def __post_init__(self):
        for field, key in (("advance", "step_advance"), ("first", "first_time_step"), ("minimum", "min_time_step"),
                           ("maximum", "max_time_step")):
            object.__setattr__(self, field, NUMERICS[key].value(key, getattr(self, field)))
        if self.maximum is not None and self.minimum > self.maximum:
            raise InputError(f"min_time_step must be <= max_time_step, got {self.minimum:g} s > {self.maximum:g} s")
        if not self.minimum <= self.first <= (np.inf if self.maximum is None else self.maximum):
            raise InputError(f"first_time_step must lie in [min_time_step, max_time_step] = [{self.minimum:g}, "
                             f"{'inf' if self.maximum is None else f'{self.maximum:g}'}] s, got {self.first:g} s")

    def next_step(self, last_step, advance):
        """The step after one of ``last_step`` seconds whose front advanced ``advance``
        element rows."""
        if advance > 0.0:
            factor = min(GROWTH, max(1.0 / GROWTH, self.advance / advance))
        else:
            factor = GROWTH
        step = max(self.minimum, last_step * factor)
        return step if self.maximum is None else min(step, self.maximum)


def front_elements(faces, n_elements, edges_per_element):
    """The number of elements with at least one edge no flow face covers (``faces``: a
    :class:`hmatddm.mesh.topology.Faces` of the mesh, extra connections included)."""
    covered = np.zeros(n_elements, dtype=np.int64)
    np.add.at(covered, faces.first, 1)
    np.add.at(covered, faces.second, 1)
    return int(np.count_nonzero(covered < edges_per_element))


def advance_of_step(elements_added, front):
    """Element rows a step crossed: ``elements_added`` over the ``front`` elements at
    its start (0 without a front)."""
    return elements_added / front if front > 0 else 0.0
