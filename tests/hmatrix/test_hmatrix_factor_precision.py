"""Tests of hmatddm/hmatrix/factor_precision.py: adaptive-precision low-rank factors
(float32 leading columns, 16-bit fixed-point trailing columns), against the float64
factors of the same ACA and against dense matrices."""

import numpy as np
import pytest

from hmatddm.errors import InputError
from hmatddm.hmatrix import HMatrix
from hmatddm.hmatrix.example_kernels import tensor_generator
from hmatddm.hmatrix.factor_precision import FIXED_POINT_SHARE, factor_columns, fixed_point_columns, split_factors


def _decaying_factors(rng, m, n, rank, decay):
    """U^T (singular values folded in) and orthonormal V^T, sigma_q = decay**q."""
    u, _ = np.linalg.qr(rng.standard_normal((m, rank)))
    v, _ = np.linalg.qr(rng.standard_normal((n, rank)))
    sigma = decay ** np.arange(rank)
    return np.ascontiguousarray((u * sigma).T), np.ascontiguousarray(v.T)


@pytest.mark.parametrize("decay", [0.3, 0.6, 0.9])
def test_fixed_point_tail_is_within_its_share_of_eps(decay):
    """The decoded block differs from the float64 one by at most share * eps of its
    norm (the bound the split spends), and the split keeps the leading columns."""
    rng = np.random.default_rng(4)
    m, n, rank, eps = 120, 90, 18, 1e-4
    ut, vt = _decaying_factors(rng, m, n, rank, decay)
    ranks, rows, cols = np.array([rank]), np.array([m]), np.array([n])
    head, u_head, v_head, u_fixed, v_fixed, u_scale, v_scale = split_factors(
        ranks, rows, cols, ut.ravel(), vt.ravel(), eps, FIXED_POINT_SHARE)
    h = int(head[0])
    assert 0 < h < rank  # the largest column stays float, the smallest go to fixed point
    assert u_head.size == h * m and v_fixed.size == (rank - h) * n and u_fixed.dtype == np.int16
    assert np.all(u_scale[:h] == 0) and np.all(u_scale[h:] > 0)
    decoded_u = factor_columns(u_head, 0, u_fixed, 0, u_scale, 0, rank, h, m)
    decoded_v = factor_columns(v_head, 0, v_fixed, 0, v_scale, 0, rank, h, n)
    exact = ut.T @ vt
    error = np.linalg.norm(decoded_u.T @ decoded_v - exact)
    assert error <= FIXED_POINT_SHARE * eps * np.linalg.norm(exact)
    np.testing.assert_array_equal(decoded_u[:h], ut[:h])  # float64 store here: head exact
    # a looser share moves more columns to fixed point, a zero share none
    assert fixed_point_columns(ut.ravel(), vt.ravel(), 0, 0, rank, m, n, eps, 4 * FIXED_POINT_SHARE) <= h
    assert fixed_point_columns(ut.ravel(), vt.ravel(), 0, 0, rank, m, n, eps, 0.0) == rank


def test_zero_and_nan_columns():
    rng = np.random.default_rng(5)
    ut, vt = _decaying_factors(rng, 40, 30, 6, 0.2)
    ut[5] = 0.0
    one = (np.array([6]), np.array([40]), np.array([30]))
    head, _, _, u_fixed, _, u_scale, _ = split_factors(*one, ut.ravel(), vt.ravel(), 1e-4, FIXED_POINT_SHARE)
    assert head[0] < 6 and u_scale[5] == 0.0 and not np.any(u_fixed[-40:])
    ut[4, 3] = np.nan  # a NaN is never hidden in an int16 code
    head, u_head, *_ = split_factors(*one, ut.ravel(), vt.ravel(), 1e-4, FIXED_POINT_SHARE)
    assert head[0] == 6 and np.isnan(u_head).any()


@pytest.fixture(scope="module")
def tensor_case():
    rng = np.random.default_rng(3)
    points = rng.random((1500, 3)) * np.array([60.0, 4.0, 1.0])
    generator = tensor_generator(points, coupling=0.7)
    eps = 1e-4
    built = {fmt: HMatrix.build(generator, eps=eps, eta=1.0, leaf_size=16, factor_dtype=fmt)
             for fmt in (np.float64, np.float32, "adaptive")}
    return generator, eps, built


def test_adaptive_blocks_against_the_float64_factors_of_the_same_aca(tensor_case):
    """Every block of the adaptive store is within (share * eps + float32 rounding) of the
    float64 store's block, which holds the same ACA factors unrounded."""
    _, eps, built = tensor_case
    exact, adaptive = built[np.float64].storage, built["adaptive"].storage
    assert np.array_equal(exact.lowrank_rank, adaptive.lowrank_rank)
    assert adaptive.u_fixed.size > 0 and adaptive.factor_format == "float32+int16"
    assert exact.factor_format == "float64" and exact.u_fixed.size == 0
    assert np.all(exact.lowrank_head == exact.lowrank_rank)
    worst = 0.0
    for b in range(exact.lowrank_rank.size):
        ut, vt = exact.factors(b)
        au, av = adaptive.factors(b)
        reference = ut.T @ vt
        worst = max(worst, np.linalg.norm(au.T @ av - reference) / np.linalg.norm(reference))
    assert worst <= FIXED_POINT_SHARE * eps + 1e-6


def test_adaptive_storage_is_smaller_and_its_products_agree(tensor_case):
    generator, eps, built = tensor_case
    h32, ha = built[np.float32], built["adaptive"]
    assert ha.storage.lowrank_bytes < 0.75 * h32.storage.lowrank_bytes
    assert ha.stats["memory_bytes"] == ha.storage.dense_values.nbytes + ha.storage.lowrank_bytes
    full = generator.to_dense()
    x = np.random.default_rng(1).standard_normal((full.shape[0], 3))
    expanded = ha.to_dense()
    np.testing.assert_allclose(ha @ x, expanded @ x, rtol=0, atol=1e-11 * np.abs(expanded @ x).max())
    assert np.linalg.norm(ha @ x - full @ x) <= 10 * eps * np.linalg.norm(full @ x)
    # the parallel and the one-thread matvec kernels read the fixed-point columns alike
    from hmatddm.hmatrix.matvec import _matmat_permuted, _matmat_serial

    permuted = np.ascontiguousarray(x[ha._col_permutation].T)
    np.testing.assert_array_equal(ha.storage._matmat_permuted(permuted, _matmat_permuted),
                                  ha.storage._matmat_permuted(permuted, _matmat_serial))


def test_adaptive_is_the_default_above_1e_5_and_bad_formats_are_refused(tensor_case):
    generator, _, _ = tensor_case
    assert HMatrix.build(generator, eps=1e-3, eta=1.0, leaf_size=64).stats["factor_dtype"] == "float32+int16"
    assert HMatrix.build(generator, eps=1e-6, eta=1.0, leaf_size=64).stats["factor_dtype"] == "float64"
    with pytest.raises(InputError, match="factor_dtype.*adaptive"):
        HMatrix.build(generator, factor_dtype="fixed")


def test_ddm_solution_with_adaptive_factors_matches_dense():
    """GMRES on the planar-crack DDM operator, adaptive factors: the solution is within the
    same tolerance of a dense LU as with float32 factors."""
    import hmatddm as hd
    from hmatddm.hmatrix import BlockGenerator, gmres
    from hmatddm.hmatrix.preconditioners import default_preconditioner
    from hmatddm.kernels.drivers import traction_block
    from hmatddm.elasticity.operator import influence_data

    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 24.0, 24.0, 24, 24)
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    generator = BlockGenerator(kernel=traction_block, data=influence_data(mesh, material), points=mesh.centers,
                               radii=mesh.radii, dof=3)
    dense = hd.ElasticityOperator(mesh, material, backend="dense").to_dense()
    load = (-1e6 * mesh.normals).ravel()
    reference = np.linalg.solve(dense, load)
    errors = {}
    for fmt in (np.float32, "adaptive"):
        h = HMatrix.build(generator, eps=1e-4, eta=3.0, leaf_size=16, factor_dtype=fmt)
        solution, info = gmres(h, load, M=default_preconditioner(h), rtol=1e-10, restart=100, maxiter=20)
        assert info["residual"] <= 1e-10
        errors[fmt] = np.linalg.norm(solution - reference) / np.linalg.norm(reference)
    assert errors["adaptive"] <= 1e-6 and errors["adaptive"] <= 2 * errors[np.float32] + 1e-8
