"""Thread count per operation: serial below a size, fewer threads on a busy machine,
and the same numbers whatever the count."""
import numba
import numpy as np
import pytest

from hmatddm.hmatrix import HMatrix, _threads
from hmatddm.hmatrix.example_kernels import matrix_generator


def test_threads_for_runs_small_work_on_one_thread_and_restores_the_count(monkeypatch):
    monkeypatch.setattr(_threads, "ADAPT_TO_LOAD", False)
    before = numba.get_num_threads()
    with _threads.threads_for(10, serial_below=100) as used:
        assert used == 1 and numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
    with _threads.threads_for(1000, serial_below=100) as used:
        assert used == before == numba.get_num_threads()


def test_threads_leave_the_cores_busy_with_other_processes(monkeypatch):
    monkeypatch.setattr(numba, "get_num_threads", lambda: 2)
    monkeypatch.setattr(_threads.os, "cpu_count", lambda: 2)
    for others, expected in ((0.0, 2), (0.4, 2), (0.6, 1), (1.8, 1)):
        monkeypatch.setattr(_threads, "background_cores", lambda others=others: others)
        assert _threads.threads_to_use(10**9, serial_below=100) == expected
    monkeypatch.setattr(_threads, "ADAPT_TO_LOAD", False)
    assert _threads.threads_to_use(10**9, serial_below=100) == 2


def test_background_cores_is_a_finite_non_negative_number():
    first = _threads.background_cores()
    assert np.isfinite(first) and first >= 0.0


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs two numba threads")
def test_serial_and_parallel_matvec_are_bit_identical(monkeypatch):
    rng = np.random.default_rng(0)
    points = rng.random((1200, 3))
    distance = np.linalg.norm(points[:, None] - points[None], axis=2)
    h = HMatrix.build(matrix_generator(1.0 / (distance + 0.05), points), eps=1e-6, leaf_size=32)
    x = rng.normal(size=(h.shape[1], 3))
    monkeypatch.setattr(_threads, "ADAPT_TO_LOAD", False)
    numba.set_num_threads(2)
    monkeypatch.setattr(_threads, "SERIAL_MATVEC_ENTRIES", 0)
    parallel = h @ x
    monkeypatch.setattr(_threads, "SERIAL_MATVEC_ENTRIES", 10**12)
    serial = h @ x
    assert np.array_equal(parallel, serial)


def test_single_threaded_blas_holds_every_blas_library_at_one_thread_and_restores_it():
    """Inside the block every loaded BLAS runs one thread (as threadpoolctl reads it), nested
    blocks change nothing, and the counts before come back after, also after an exception."""
    from threadpoolctl import threadpool_info, threadpool_limits

    def blas_threads():
        return sorted(info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas")

    with threadpool_limits(limits=2, user_api="blas"):
        before = blas_threads()
        assert before and max(before) == 2
        with _threads.single_threaded_blas():
            assert set(blas_threads()) == {1}
            with _threads.single_threaded_blas():
                assert set(blas_threads()) == {1}
            assert set(blas_threads()) == {1}
        assert blas_threads() == before
        with pytest.raises(RuntimeError):
            with _threads.single_threaded_blas():
                raise RuntimeError("inside")
        assert blas_threads() == before
