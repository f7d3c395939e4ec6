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


def test_records_of_one_type_share_their_held_signatures():
    """A growing simulation makes a new layered record at every operator build: the held
    functions' signatures are made once per record type (:func:`held_signature`), not per
    record -- two meshes of different sizes in one medium give the same signature objects,
    and the kernel still runs on both."""
    import hmatddm as hd
    from hmatddm.elasticity import operator as operators
    from hmatddm.kernels import drivers
    from hmatddm.layered import LayeredMedium

    medium = LayeredMedium([0.0, -2.0], [0.0, 1.0, 2.0], [0.25, 0.25, 0.25], images=1)
    records = []
    for n in (2, 3):
        centers = np.array([[0.7 * k, 0.0, -1.0] for k in range(n)])
        mesh = hd.Mesh3D.from_rectangles(centers, np.tile([1.0, 0, 0], (n, 1)), np.tile([0, 0.6, 0.8], (n, 1)),
                                         np.full(n, 0.2), np.full(n, 0.2))
        records.append(operators.influence_data(mesh, medium))
    first, second = records
    for name in ("image_terms", "vertical_terms", "point_stress"):
        assert getattr(first, name).signature() is getattr(second, name).signature()
    for data in records:
        every = np.arange(data.centers.shape[0], dtype=np.int64)
        out = np.empty((3 * every.size, 3 * every.size))
        drivers.traction_block(data, every, every, out)
        assert np.all(np.isfinite(out))


def test_data_pointer_reads_and_writes_the_flat_array():
    """A pointer indexes a C-contiguous array flat, in place; a boolean array's as bytes."""
    from numba import njit

    from hmatddm.kernels.held_function import data_pointer

    @njit
    def touch(values, flags):
        p, f = data_pointer(values), data_pointer(flags)
        total = p[0] + p[5]
        p[4] = -1.0
        flag = f[1]
        f[2] = 1
        return total, flag

    values, flags = np.arange(6.0).reshape(2, 3), np.array([False, True, False])
    total, flag = touch(values, flags)
    assert total == 5.0 and flag == 1 and values[1, 1] == -1.0 and flags.tolist() == [False, True, True]
