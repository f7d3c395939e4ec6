"""The stashed tuple of :mod:`hmatddm.kernels.held_function` (:func:`stash`, :func:`item`,
:func:`dereference`): the arrays read back through the pointer, nested tuples and other
dtypes kept, writes seen by later reads, the arrays kept alive by the buffer alone and
freed with it (the layered workspace, :mod:`hmatddm.layered.workspace3d`)."""
import numpy as np
from numba import njit
from numba.core.runtime import _nrt_python, rtsys

from hmatddm.kernels.held_function import dereference, item, stash


@njit(cache=True)
def _stashed_sums(a, b, c):
    work = stash((a.copy(), (b.copy(), c.copy()), np.zeros((2, 3))))  # the buffer their only owner
    at = work[1]
    item(at, 2)[1, 2] = 7.0  # written through the stash, read below
    inner = item(at, 1)
    whole = dereference(at)
    return (item(at, 0).sum(), inner[0].sum(), inner[1].sum(), whole[2][1, 2], whole[0].shape[0],
            inner[1].shape[0], work[0].shape[0])


def test_stash_reads_back_and_frees():
    a = np.random.default_rng(1).normal(size=5)
    b = np.arange(6, dtype=np.int64).reshape(2, 3)
    c = np.array([True, False, True])
    _stashed_sums(a, b, c)  # compiled
    _nrt_python.memsys_enable_stats()  # (numba's own tests count allocations so)
    try:
        before = rtsys.get_allocation_stats()
        s_a, s_b, s_c, written, n_a, n_c, n_buffer = _stashed_sums(a, b, c)
        after = rtsys.get_allocation_stats()
    finally:
        _nrt_python.memsys_disable_stats()
    assert s_a == a.sum() and s_b == b.sum() and s_c == 2
    assert written == 7.0 and n_a == 5 and n_c == 3 and n_buffer > 0
    # every meminfo made in the call (4 arrays and the buffer at least) released
    made = after.mi_alloc - before.mi_alloc
    assert made >= 5 and after.mi_free - before.mi_free == made
