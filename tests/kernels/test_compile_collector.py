"""The collector frozen off the old heap while numba compiles (:mod:`hmatddm.kernels.compile_collector`):
the process's collector state is the same after a compile, a failed one included, and a
caller's own frozen objects are left alone."""
import gc

import numba
import pytest

from hmatddm.kernels import compile_collector, drivers  # noqa: F401 (drivers installs the listener)


def _fresh():
    """A new dispatcher (compiled on its first call, not cached)."""
    @numba.njit
    def twice(x):
        return 2 * x

    return twice


def test_compile_leaves_the_collector_as_it_was():
    assert compile_collector._LISTENER is not None
    before = gc.get_freeze_count()
    assert _fresh()(3) == 6
    assert gc.get_freeze_count() == before
    assert gc.isenabled()


def test_a_failed_compile_unfreezes():
    @numba.njit
    def wrong(x):
        return x.no_such_attribute

    with pytest.raises(numba.core.errors.TypingError):
        wrong(1.0)
    assert gc.get_freeze_count() == 0
    assert getattr(compile_collector._state, "depth", 0) == 0


def test_a_callers_frozen_objects_are_left_frozen():
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        assert _fresh()(2) == 4
        # neither unfrozen (0) nor frozen again (the compile's objects added); objects
        # freed meanwhile leave the count
        assert 0 < gc.get_freeze_count() <= frozen
    finally:
        gc.unfreeze()
