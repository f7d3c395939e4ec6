"""Python's garbage collector kept off the old heap while numba compiles (issue 32: the cold
compile of the 3D layered kernels).

numba's compiler makes and drops many container objects (its inlining copies blocks with
their scopes, typing and lowering make new IR), which trigger Python's collections; each
full collection walks every object of the process, and in a process that has imported
numba, llvmlite and numpy and compiled much already that heap is large. In
``benchmarks/bench_layered3d_compile.py`` 46 full collections took 7.1 s of an 82 s cold
compile (8.3 s with the young generations; Intel Xeon at dgemm ~71-76 GFLOP/s, 1 thread;
benchmarks/RESULTS.md, issue 32, twelfth session). From the start of the outermost compile
to its end, the objects that existed before it are frozen (:func:`gc.freeze`: the collector no longer examines them) and
unfrozen after (:func:`gc.unfreeze`), and again at the start of each compile it nests
(the objects of the compiles finished within it): the garbage a compile makes is still
collected (what was not yet when a nested compile began, after the outermost one), the
compiled code and every result are the same. Nothing is done while the process has
frozen objects of its own (a caller's :func:`gc.freeze`, e.g. before forking) or its
collector disabled.

Through numba's event API (``numba:compile``, the events
``benchmarks/compile_profile.py`` times), registered once, on the first import of
:mod:`hmatddm.kernels.drivers` (what every compiled kernel imports).
"""
import gc
import threading

from numba.core import event

__all__ = ["install"]

_state = threading.local()


class _FrozenDuringCompile(event.Listener):
    """Freezes the heap at the outermost compile's start, unfreezes it at its end (numba
    compiles under one global lock; the depth is per thread all the same)."""

    def on_start(self, ev):
        depth = getattr(_state, "depth", 0)
        if depth == 0:
            _state.froze = gc.isenabled() and gc.get_freeze_count() == 0
        if _state.froze:  # again at each nested compile: what the finished ones made too
            gc.freeze()
        _state.depth = depth + 1

    def on_end(self, ev):
        depth = getattr(_state, "depth", 0)
        if depth == 0:  # a compile begun before the listener was registered
            return
        _state.depth = depth - 1
        if depth == 1 and _state.froze:
            _state.froze = False
            gc.unfreeze()


_LISTENER = None


def install():
    """Register the listener (once per process)."""
    global _LISTENER
    if _LISTENER is None:
        _LISTENER = _FrozenDuringCompile()
        event.register("numba:compile", _LISTENER)
    return _LISTENER
