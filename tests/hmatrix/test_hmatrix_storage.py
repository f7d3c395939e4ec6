"""Tests of hmatddm/hmatrix/storage.py and assembly.py: the compiled build driver and the stored blocks."""
import pickle

import numpy as np
from numba import types


def _small_hmatrix(eps=1e-7):
    from hmatddm.hmatrix import HMatrix
    from hmatddm.hmatrix.example_kernels import tensor_generator

    rng = np.random.default_rng(3)
    points = rng.random((900, 3)) * np.array([60.0, 4.0, 1.0])
    generator = tensor_generator(points, coupling=0.7)
    return generator, HMatrix.build(generator, eps=eps, eta=1.0, leaf_size=16)


def test_build_driver_is_cacheable_on_disk():
    """The driver's signature names no Python object (the kernel is a first-class
    function type, not its dispatcher), so numba can key an on-disk cache entry on it;
    and the driver has such a cache (cache=True)."""
    from hmatddm.hmatrix.example_kernels import tensor_generator
    from hmatddm.hmatrix.assembly import build_driver

    generator = tensor_generator(np.random.default_rng(0).random((20, 3)), coupling=0.5)
    driver = build_driver(generator.data)
    assert len(driver.signatures) == 1
    signature = driver.signatures[0]
    assert not any(isinstance(t, types.Dispatcher) for t in signature)
    assert isinstance(signature[0], types.FunctionType)
    pickle.dumps(signature)  # what the cache index stores
    assert type(driver._cache).__name__ != "NullCache"
    assert build_driver(generator.data) is driver  # one per data type and process


def test_stored_blocks_are_what_aca_compressed_and_the_kernel_give():
    """Every low-rank block holds exactly aca.aca_compressed's factors on the same
    elements (the function the ACA tests call), every near-field block the kernel's
    exact entries; and the whole H-matrix matches the dense matrix to ~eps."""
    from hmatddm.hmatrix.aca import aca_compressed
    from hmatddm.hmatrix.example_kernels import tensor_kernel

    eps = 1e-7
    generator, h = _small_hmatrix(eps)
    s, permutation, d = h.storage, h.tree.permutation, generator.dof
    assert s.lowrank_rank.size > 20 and np.any(s.dense_is_near)
    for b in range(s.lowrank_rank.size):
        rows = permutation[s.lowrank_row_start[b]:s.lowrank_row_stop[b]].astype(np.int64)
        cols = permutation[s.lowrank_col_start[b]:s.lowrank_col_stop[b]].astype(np.int64)
        ut, vt, rank = aca_compressed(tensor_kernel, generator.data, rows, cols, d, d, eps)
        stored_u, stored_v = h._factors(b)
        assert rank == s.lowrank_rank[b]
        np.testing.assert_array_equal(stored_u, ut.T)
        np.testing.assert_array_equal(stored_v, vt.T)
    for b in np.flatnonzero(s.dense_is_near)[:50]:
        rows = permutation[s.dense_row_start[b]:s.dense_row_stop[b]].astype(np.int64)
        cols = permutation[s.dense_col_start[b]:s.dense_col_stop[b]].astype(np.int64)
        exact = np.empty((d * rows.size, d * cols.size))
        tensor_kernel(generator.data, rows, cols, exact)
        stored = s.dense_values[s.dense_offset[b]:s.dense_offset[b + 1]].reshape(exact.shape)
        np.testing.assert_array_equal(stored, exact)
    n = d * permutation.size
    full = np.empty((n, n))
    tensor_kernel(generator.data, np.arange(permutation.size), np.arange(permutation.size), full)
    x = np.random.default_rng(1).normal(size=n)
    assert np.linalg.norm(h @ x - full @ x) <= 10 * eps * np.linalg.norm(full @ x)


def test_float32_near_field_solves_within_tolerance_of_dense():
    """near_dtype=float32 halves the near-field storage; the matvec and the GMRES solution
    (default preconditioner, which reads the stored near field) stay within a small
    multiple of the float64 storage's error against a dense LU of the DDM operator."""
    import hmatddm as hd
    from hmatddm.hmatrix import BlockGenerator, HMatrix, gmres
    from hmatddm.hmatrix.preconditioners import default_preconditioner
    from hmatddm.kernels.drivers import traction_block
    from hmatddm.elasticity.operator import influence_data

    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 24.0, 24.0, 24, 24)
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    data = influence_data(mesh, material)
    generator = BlockGenerator(kernel=traction_block, data=data, points=mesh.centers, radii=mesh.radii, dof=3)
    dense = hd.ElasticityOperator(mesh, material, backend="dense").to_dense()
    load = (-1e6 * mesh.normals).ravel()
    reference = np.linalg.solve(dense, load)
    x = np.random.default_rng(0).normal(size=load.size)
    errors = {}
    for near_dtype in (np.float64, np.float32):
        h = HMatrix.build(generator, eps=1e-4, eta=3.0, leaf_size=32, near_dtype=near_dtype)
        assert h.storage.dense_values.dtype == near_dtype
        solution, info = gmres(h, load, M=default_preconditioner(h), rtol=1e-10, restart=100, maxiter=20)
        assert info["residual"] <= 1e-10
        errors[near_dtype] = (np.linalg.norm(h @ x - dense @ x) / np.linalg.norm(dense @ x),
                              np.linalg.norm(solution - reference) / np.linalg.norm(reference),
                              h.storage.dense_values.nbytes)
    (_, solution64, bytes64), (matvec32, solution32, bytes32) = errors[np.float64], errors[np.float32]
    assert bytes32 * 2 == bytes64
    assert matvec32 <= 1e-6 and solution32 <= 2e-6  # float32 rounding amplified by the near-field cancellation
    assert solution64 <= 1e-6
