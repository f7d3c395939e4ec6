"""Hard cases of the elasticity layer: geometries where the DDM is numerically fragile.

Every case checks, on small meshes: no NaN/inf (matrix, solution, stresses), the
``hmatrix`` backend solves to the same DDs as ``dense`` (eps 1e-6), and the answer
matches a closed form or converges under refinement. The full table (larger meshes,
GMRES iterations, timings) is ``benchmarks/bench_hard_cases.py``.

Cases (numbers as in benchmarks/RESULTS.md, "Hard cases"):
1. T and X intersections, and an element end on another element's centre
   (ref. Sec. 6.2.3): NaN averaging + Eq. 6.11 scaling against conforming meshes;
   near-miss junctions.
2. Two parallel pressurised cracks from 10 element sizes apart to a fraction of one.
3. Thin elements (aspect up to 1:20) and neighbouring sizes differing up to 50x.
4. Collocation points on the extension of element edges.
5. Fractures of 0.1 m and 100 m in one operator (cluster tree and ACA).
6. A tilted penny crack against Sneddon and a curved (arc) 2D crack.
7. The unscaled and scaled fully coupled system (ref. Fig. 4.13).

No case is marked ``xfail`` any more: the last known failures (mixed scales in one ACA
block, close parallel cracks in restarted GMRES) were fixed and pass as ordinary tests.
A case that fails again must be fixed or marked ``xfail(strict=True)`` with its
mechanism in the reason. Meshes that are deliberately below the resolution of constant
elements assert the :class:`~hmatddm.errors.MeshQualityWarning` they raise (see
:func:`solve_both`) instead of leaving it in the run's warning summary.
"""
import warnings

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import hmatddm as hd
from hmatddm import analytical as an
from hmatddm import network as nw
from hmatddm.mesh.hard_cases import graded_line, mixed_scales
from hmatddm.kernels import rectangle3d

P = 1e6          # net pressure, Pa
EPS = 1e-6       # H-matrix tolerance of the backend comparisons
AGREE = 10 * EPS  # asked agreement of hmatrix and dense DDs (relative 2-norm)


# ----------------------------------------------------------------------------- helpers
def solve_both(mesh, material, load=None, leaf_size=16, eps=EPS, check_warning=True, **options):
    """Solve ``op @ dd = load`` (default: pressure P) with both backends.

    Returns (dense dd, hmatrix dd, relative difference, hmatrix GMRES info, dense op).
    Asserts that the matrix, both solutions and the induced stresses are finite, and
    (unless ``check_warning`` is False, for callers that inspect the warnings
    themselves) that building each operator warns with ``MeshQualityWarning`` exactly
    when :func:`hmatddm.mesh.close_parallel_pairs` finds pairs.
    """
    load = -P * mesh.normals if load is None else load
    expect = check_warning and len(hd.mesh.close_parallel_pairs(mesh).first) > 0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", hd.errors.MeshQualityWarning)
        dense = hd.ElasticityOperator(mesh, material, backend="dense", **options)
        hmat = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=eps, leaf_size=leaf_size, **options)
    quality = [w for w in caught if issubclass(w.category, hd.errors.MeshQualityWarning)]
    for other in caught:
        if other not in quality:
            warnings.warn_explicit(other.message, other.category, other.filename, other.lineno)
    if check_warning:
        assert len(quality) == (2 if expect else 0), [str(w.message) for w in quality]
    else:
        for w in quality:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    assert np.all(np.isfinite(dense.to_dense()))
    dd = hd.solve(dense, load)
    dd_h, info = hd.solve(hmat, load, return_info=True)
    assert np.all(np.isfinite(dd)) and np.all(np.isfinite(dd_h))
    # stresses at a few points off the elements (centres moved along their normals)
    pick = np.arange(0, mesh.n_elements, max(1, mesh.n_elements // 7))
    probe = mesh.centers[pick] + 0.37 * mesh.radii[pick, None] * mesh.normals[pick]
    stress = hd.stress_at(mesh, material, dd, probe, singular_correction=options.get("singular_correction", "none"))
    assert np.all(np.isfinite(stress))
    difference = np.linalg.norm(dd_h - dd) / np.linalg.norm(dd)
    return dd, dd_h, difference, info, dense


def volume(mesh, dd):
    """Crack volume (3D) or cross-section area (2D, per unit height)."""
    return float(np.sum(hd.opening(mesh, dd) * mesh.areas))


def griffith_area(half_length, material):
    """Area of the Griffith opening profile, pi a^2 (1 - nu) p / G."""
    return np.pi * half_length**2 * (1 - material.poisson_ratio) * P / material.shear_modulus


# ------------------------------------------------------------- 1. intersections
def junction_2d(kind, n=21):
    """Non-conforming 2D T or X: the main crack (n odd) has a centre at the origin,
    where the branch ends (T) or has a node (X)."""
    main = hd.mesh.line([-1, 0], [1, 0], n)
    if kind == "T":
        branch = hd.mesh.line([0, 0], [0, 1], (n + 1) // 2, fracture_id=1)
    else:
        branch = hd.mesh.line([0, -1], [0, 1], n + 1, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


def junction_3d(kind, nx=9):
    """Non-conforming vertical 3D T or X (height 2): the branch's vertical edge runs
    through the centres of the main fracture's middle column."""
    h = 4.0 / nx
    nz = int(round(2.0 / h))
    main = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 4.0, 2.0, nx, nz)
    if kind == "T":
        branch = hd.mesh.rectangle([0, 1, 0], [0, 1, 0], [0, 0, 1], 2.0, 2.0, (nx + 1) // 2, nz, fracture_id=1)
    else:
        branch = hd.mesh.rectangle([0, 0, 0], [0, 1, 0], [0, 0, 1], 4.0, 2.0, nx + 1, nz, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


def junction_network(kind, half, height=1.0):
    """The same T (branch from the main crack's midpoint to +y) or X as plan-view segments."""
    start = 0.0 if kind == "T" else -half
    return nw.Network.from_segments([[-half, 0], [0, start]], [[half, 0], [0, half]], height=height)


def conforming_2d(kind, n=21):
    return nw.split_at_intersections(junction_network(kind, 1.0)).to_mesh2d(2.0 / n)


def conforming_3d(kind, nx=9):
    h = 4.0 / nx
    return nw.split_at_intersections(junction_network(kind, 2.0, height=2.0)).to_mesh3d(h, int(round(2.0 / h)))


JUNCTIONS = [("2D", "T"), ("2D", "X"), ("3D", "T"), ("3D", "X")]


def _junction(dim, kind):
    return junction_2d(kind) if dim == "2D" else junction_3d(kind)


def _conforming(dim, kind):
    return conforming_2d(kind) if dim == "2D" else conforming_3d(kind)


@pytest.mark.parametrize("dim, kind", JUNCTIONS)
def test_non_conforming_junction_is_refused_without_correction(material, dim, kind):
    with pytest.raises(hd.InputError, match="singular_correction='average'"):
        hd.ElasticityOperator(_junction(dim, kind), material)
    with pytest.raises(hd.InputError, match="singular_correction='average'"):
        hd.ElasticityOperator(_junction(dim, kind), material, backend="hmatrix")


@pytest.mark.parametrize("dim, kind", JUNCTIONS)
def test_reference_correction_at_junction_is_finite_and_backends_agree(material, dim, kind):
    """NaN averaging + Eq. 6.11 with alpha = 1 (ref. Sec. 6.2.3)."""
    mesh = _junction(dim, kind)
    dd, _, difference, info, _ = solve_both(mesh, material, singular_correction="average", alpha=1.0)
    assert difference < AGREE
    assert info["iterations"] < 40
    assert np.all(hd.opening(mesh, dd) > 0)


@pytest.mark.parametrize("dim, kind", JUNCTIONS)
def test_conforming_junction_needs_no_correction_and_matches_the_reference_treatment(material, dim, kind):
    """Exact treatment (split at the intersection, meshed end to end) with the default
    "none": no collocation point on an edge. The two treatments of the same pressurised
    junction give crack volumes within 3% (measured 0.3-1.9%)."""
    exact = _conforming(dim, kind)
    dd_exact, _, difference, info, _ = solve_both(exact, material)
    assert difference < AGREE and info["iterations"] < 40
    approximate = _junction(dim, kind)
    dd_approx, _, _, _, _ = solve_both(approximate, material, singular_correction="average", alpha=1.0)
    assert volume(approximate, dd_approx) == pytest.approx(volume(exact, dd_exact), rel=0.03)


def test_conforming_t_junction_converges_under_refinement(material):
    volumes = []
    for n in (10, 20, 40, 80):  # h = 2/n divides both pieces
        mesh = conforming_2d("T", n)
        volumes.append(volume(mesh, hd.solve(hd.ElasticityOperator(mesh, material), -P * mesh.normals)))
    steps = np.abs(np.diff(volumes))
    assert np.all(steps[1:] < 0.75 * steps[:-1])  # Cauchy: first order (ratio ~0.5)


def test_element_end_on_a_collocation_point_in_a_rotated_frame(material):
    """The branch ends on the main crack's centre in a rotated frame, where the end
    point is only equal to the centre up to round-off: still detected as singular."""
    angle = 0.3
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    mesh = junction_2d("T").transformed(rotation, (0.123, -4.56))
    with pytest.raises(hd.InputError):
        hd.ElasticityOperator(mesh, material)
    dd, _, difference, _, _ = solve_both(mesh, material, singular_correction="average", alpha=1.0)
    assert difference < AGREE
    reference, _, _, _, _ = solve_both(junction_2d("T"), material, singular_correction="average", alpha=1.0)
    np.testing.assert_allclose(hd.opening(mesh, dd), hd.opening(junction_2d("T"), reference), rtol=1e-8)


def near_miss_t(gap, n=21):
    """T whose branch ends ``gap`` element lengths above the main crack's centre."""
    h = 2.0 / n
    main = hd.mesh.line([-1, 0], [1, 0], n)
    branch = hd.mesh.line([0, gap * h], [0, 1], 11, fracture_id=1)
    return hd.mesh.concatenate([main, branch])


@pytest.mark.parametrize("gap", [1e-8, -1e-8, 1e-4])
def test_near_miss_t_junction_matches_the_touching_one(material, gap):
    """A branch ending ``gap`` element lengths above (or, negative, beyond) the main
    crack's centre: the exact entry is ~1/gap (the volume was 57% off, cond 1e9). Points
    nearer than NEAR_SINGULAR_FRACTION half sizes to an edge are singular: refused by
    name without correction, and with "average" treated as the touching T, whose
    volume is within 1% of the conforming mesh's."""
    mesh = near_miss_t(gap)
    for backend in ("dense", "hmatrix"):
        with pytest.raises(hd.InputError, match=r"element 10 \(fracture 0\).* m \(.*of the smaller half size\) "
                                                r"from an edge of element 21.*singular_correction='average'"
                                                r".*split_at_intersections"):
            hd.ElasticityOperator(mesh, material, backend=backend)
    exact = conforming_2d("T")
    reference = volume(exact, hd.solve(hd.ElasticityOperator(exact, material), -P * exact.normals))
    dd, _, difference, info, _ = solve_both(mesh, material, singular_correction="average", alpha=1.0)
    assert difference < AGREE and info["iterations"] < 40
    assert volume(mesh, dd) == pytest.approx(reference, rel=0.02)  # measured 0.9%, was 57% off
    touching = near_miss_t(0.0)
    dd_touching = hd.solve(hd.ElasticityOperator(touching, material, singular_correction="average", alpha=1.0),
                           -P * touching.normals)
    w, w_touching = hd.opening(mesh, dd), hd.opening(touching, dd_touching)
    assert np.abs(w - w_touching).max() < 10 * abs(gap) * w_touching.max()  # measured 0.45 |gap|


def test_near_miss_t_junction_snapped_by_split_at_intersections(material):
    """Workaround that works today: a tolerance larger than the gap turns the near miss
    into an exact T (tol is relative to the bounding-box diagonal)."""
    gap = 1e-6
    near = nw.Network.from_segments([[-1, 0], [0, gap]], [[1, 0], [0, 1]])
    snapped = nw.split_at_intersections(near, tol=1e-4).to_mesh2d(0.1)
    exact = conforming_2d("T", 20)
    v_snapped = volume(snapped, hd.solve(hd.ElasticityOperator(snapped, material), -P * snapped.normals))
    v_exact = volume(exact, hd.solve(hd.ElasticityOperator(exact, material), -P * exact.normals))
    assert v_snapped == pytest.approx(v_exact, rel=1e-5)


# ------------------------------------------------------------- 2. parallel cracks
def parallel_2d(spacing, n=20, stagger=0.0):
    h = 2.0 / n
    lower = hd.mesh.line([-1, 0], [1, 0], n)
    upper = hd.mesh.line([-1 + stagger * h, spacing], [1 + stagger * h, spacing], n, fracture_id=1)
    return hd.mesh.concatenate([lower, upper])


def test_parallel_cracks_2d_stress_shadow(material):
    """Opening of each crack falls monotonically as the spacing shrinks from 10 to 1
    element sizes, stays between the coalesced limit (1/2) and the single crack, and
    tends to the single crack (and Griffith) at large spacing."""
    n, h = 20, 0.1
    single = hd.mesh.line([-1, 0], [1, 0], n)
    w_single = hd.opening(single, hd.solve(hd.ElasticityOperator(single, material), -P * single.normals))
    griffith = an.griffith_opening(single.centers[:, 0], 1.0, P, material)
    inner = np.abs(single.centers[:, 0]) < 0.5
    assert np.max(np.abs(w_single - griffith)[inner]) < 0.04 * griffith.max()
    reductions = []
    for spacing in (100.0, 10 * h, 5 * h, 2 * h, h):
        for stagger in (0.0, 0.5):
            mesh = parallel_2d(spacing, n, stagger)
            dd, _, difference, info, _ = solve_both(mesh, material)
            assert difference < AGREE and info["iterations"] < 60
            w = hd.opening(mesh, dd)
            assert np.all(w > 0)
            if stagger == 0.0:
                reductions.append(w[:n].sum() / w_single.sum())
                np.testing.assert_allclose(w[:n], w[n:], rtol=1e-8)  # mirror symmetry
    assert reductions[0] == pytest.approx(1.0, abs=1e-3)
    assert np.all(np.diff(reductions) < 0)
    assert 0.5 < reductions[-1] < 0.6


def test_parallel_cracks_closer_than_an_element_are_flagged(material):
    """Two parallel cracks h/10 apart: with constant DD elements the antisymmetric mode of
    the thin bridge is softer than the collocation error of the opening-slip coupling,
    and the solution is finite but wrong (negative openings, -0.64 x the single crack).
    A discretisation limit: building the operator warns (MeshQualityWarning, with
    hd.mesh.close_parallel_pairs) and names the element size that resolves the bridge;
    at that size the warning goes and both cracks stay open with the coalesced shadow."""
    import re

    mesh = parallel_2d(0.1 * 0.1)
    pattern = (r"20 pair\(s\) .*elements \d+ \(fracture 0\) and \d+ \(fracture 1\): spacing 0\.01 m with "
               r"elements of h = 0\.1 m .*refine both fractures to elements of h <= (\S+) m")
    with pytest.warns(hd.errors.MeshQualityWarning, match=pattern) as record:
        dd, _, difference, _, _ = solve_both(mesh, material, check_warning=False)  # both backends warn
    assert len(record) == 2
    assert difference < AGREE
    w = hd.opening(mesh, dd)
    np.testing.assert_allclose(w[:20], w[20:], rtol=1e-8)  # still mirror symmetric ...
    # ... but not positive (measured min -2.8 x max): what the warning is about
    size = float(re.search(pattern, str(record[0].message)).group(1))
    n = int(np.ceil(2.0 / size))  # 592 elements per crack
    refined = parallel_2d(0.01, n)
    with warnings.catch_warnings():
        warnings.simplefilter("error", hd.errors.MeshQualityWarning)
        op = hd.ElasticityOperator(refined, material)
    w = hd.opening(refined, hd.solve(op, -P * refined.normals))
    single = hd.mesh.line([-1, 0], [1, 0], n)
    w_single = hd.opening(single, hd.solve(hd.ElasticityOperator(single, material), -P * single.normals))
    assert np.all(w > 0)
    assert 0.5 < w[:n].sum() / w_single.sum() < 0.55  # converged shadow 0.502 (s/L = 0.005)


def test_parallel_cracks_below_an_element_recover_under_refinement(material):
    """At fixed spacing s = 0.01 (1% of the length) the opening is meaningful once h <~ 2 s."""
    single = hd.mesh.line([-1, 0], [1, 0], 100)
    w_single = hd.opening(single, hd.solve(hd.ElasticityOperator(single, material), -P * single.normals))
    mesh = parallel_2d(0.01, n=100)  # s/h = 0.5
    dd, _, difference, _, _ = solve_both(mesh, material)
    w = hd.opening(mesh, dd)
    assert difference < 1e-4  # cond ~1e4: the H error is amplified (measured 3e-8 .. 1e-5)
    assert np.all(w > 0)
    assert 0.5 < w[:100].sum() / w_single.sum() < 0.6


def test_gmres_converges_for_close_parallel_cracks(material):
    """Two 2 m cracks 0.01 m apart with h = spacing (N = 400) have cond 5e6 (a thin
    bridge, stiffness ~ (s/L)^3, which the local near-field ILU cannot see). With the
    former scalar ILU, GMRES needed 158 iterations in one Krylov space, more than the
    restart length of hd.solve (100), and restarted GMRES(100) stalled at a residual
    1e-6 for 2000 iterations. The solver now continues a stagnating cycle in a twice
    larger space instead of restarting it (hmatddm/hmatrix/solvers.py): 268
    iterations with that ILU; the block ILU default needs 95."""
    mesh = parallel_2d(0.01, n=200)  # s/h = 1: flagged, the bridge is not resolved
    with pytest.warns(hd.errors.MeshQualityWarning, match="200 pair"):
        op = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=EPS, leaf_size=16)
    hd.solve(op, -P * mesh.normals)
    # With the block ILU default, 95 iterations fit in GMRES(100); GMRES(20) still
    # stalls (residual 2e-3 after its 400-iteration budget) unless the restart grows.
    load = -P * mesh.normals
    dd, info = hd.solve(op, load, restart=20, return_info=True)
    assert info["restart"] > 20 and info["iterations"] < 400
    with pytest.warns(hd.errors.MeshQualityWarning, match="200 pair"):
        dense = hd.ElasticityOperator(mesh, material)
    reference = hd.solve(dense, load)
    assert np.linalg.norm(dd - reference) < 1e-3 * np.linalg.norm(reference)  # cond 5e6 (measured 1e-5)


def test_parallel_pennies_3d_stress_shadow(material):
    radius, h = 1.0, 0.25
    single = hd.mesh.penny([0, 0, 0], [0, 0, 1], radius, h)
    v_single = volume(single, hd.solve(hd.ElasticityOperator(single, material), -P * single.normals))
    assert v_single == pytest.approx(an.sneddon_volume(radius, P, material), rel=0.25)  # staircase, h = R/4
    ratios = []
    for spacing in (50.0, 10 * h, 4 * h, 2 * h, h):
        upper = hd.mesh.penny([0, 0, spacing], [0, 0, 1], radius, h, fracture_id=1)
        mesh = hd.mesh.concatenate([single, upper])
        dd, _, difference, info, _ = solve_both(mesh, material)
        assert difference < AGREE and info["iterations"] < 60
        assert np.all(hd.opening(mesh, dd) > 0)
        ratios.append(volume(mesh, dd) / (2 * v_single))
    assert ratios[0] == pytest.approx(1.0, abs=1e-3)
    assert np.all(np.diff(ratios) < 0) and ratios[-1] > 0.5


# -------------------------------------------------------- 3. thin and graded elements
@pytest.mark.parametrize("layout", ["centre", "tips", "alternating"])
@pytest.mark.parametrize("ratio", [10, 50])
def test_graded_2d_mesh_against_griffith(material, ratio, layout):
    mesh = graded_line(ratio, layout)
    sizes = mesh.areas
    assert np.max(np.maximum(sizes[1:] / sizes[:-1], sizes[:-1] / sizes[1:])) == pytest.approx(ratio)
    dd, _, difference, info, _ = solve_both(mesh, material)
    assert difference < AGREE and info["iterations"] < 60
    x = mesh.centers[:, 0]
    w = hd.opening(mesh, dd)
    griffith = an.griffith_opening(x, 1.0, P, material)
    inner = np.abs(x) < 0.5
    # uniform coarse mesh: 2.8%; the size jumps do not make it worse
    assert np.max(np.abs(w - griffith)[inner]) < 0.035 * griffith.max()
    assert volume(mesh, dd) == pytest.approx(griffith_area(1.0, material), rel=0.06)


def test_thin_elements_3d_square_crack(material):
    """A 2 x 2 square crack with 4 columns of elements 1:1 .. 1:20 (refined across
    only): the error is bounded by the coarse direction and falls as the thin
    direction is refined; nothing degenerates at aspect 20."""
    reference = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 16, 16)
    v_reference = volume(reference, hd.solve(hd.ElasticityOperator(reference, material), -P * reference.normals))
    errors = []
    for aspect in (1, 5, 20):
        mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 4, 4 * aspect)
        dd, _, difference, info, _ = solve_both(mesh, material)
        assert difference < AGREE and info["iterations"] < 40
        assert np.abs(hd.slip(mesh, dd)).max() < 1e-10 * hd.opening(mesh, dd).max()
        errors.append(abs(volume(mesh, dd) / v_reference - 1))
    assert np.all(np.diff(errors) < 0)


def test_refined_patch_3d(material):
    """9 x 9 square crack whose centre element is replaced by 20 x 20 elements (size
    jump 20, N = 480): the coarse openings move by < 0.5% and the crack volume by < 0.5%."""
    n, L, r = 9, 2.0, 20
    uniform = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], L, L, n, n)
    centre = np.flatnonzero(np.all(np.abs(uniform.centers) < 1e-12, axis=1))
    coarse = uniform.subset(np.setdiff1d(np.arange(uniform.n_elements), centre))
    patch = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], L / n, L / n, r, r, fracture_id=0)
    mesh = hd.mesh.concatenate([coarse, patch])
    dd, _, difference, info, _ = solve_both(mesh, material, leaf_size=32)
    assert difference < AGREE and info["iterations"] < 40
    w_uniform = hd.opening(uniform, hd.solve(hd.ElasticityOperator(uniform, material), -P * uniform.normals))
    w = hd.opening(mesh, dd)
    keep = np.setdiff1d(np.arange(uniform.n_elements), centre)
    assert np.max(np.abs(w[:coarse.n_elements] - w_uniform[keep])) < 5e-3 * w_uniform.max()
    assert volume(mesh, dd) == pytest.approx(volume(uniform, hd.solve(hd.ElasticityOperator(uniform, material),
                                                                       -P * uniform.normals)), rel=5e-3)


# ------------------------------------------------------- 4. edge extension lines
def test_3d_kernel_is_finite_and_lipschitz_on_edge_extension_lines(material):
    """Points on the extension of an edge (in the element plane, beyond a corner) are
    where log(r + x) type terms are singular in naive formulas: finite here, and a
    shift by d changes the stress by O(d)."""
    a, b = 0.5, 0.25
    g, nu = material.shear_modulus, material.poisson_ratio
    on_line = [(x1, s * b, 0.0) for x1 in (-3 * a, -1.5 * a, 1.5 * a, 3 * a) for s in (-1, 1)]
    on_line += [(s * a, x2, 0.0) for x2 in (-3 * b, -1.2 * b, 1.2 * b, 3 * b) for s in (-1, 1)]
    on_line += [(a, b, 0.3), (2 * a, 2 * b, 0.0)]
    base, shifted = np.empty((3, 3, 3)), np.empty((3, 3, 3))
    for point in on_line:
        rectangle3d.local_stress(*point, a, b, g, nu, base)
        assert np.all(np.isfinite(base))
        scale = np.abs(base).max()
        slopes = []
        for d in (1e-6, 1e-8, 1e-10):
            for direction in np.eye(3):
                for sign in (1, -1):
                    rectangle3d.local_stress(*(np.array(point) + sign * d * a * direction), a, b, g, nu, shifted)
                    slopes.append(np.abs(shifted - base).max() / scale / d)
        assert max(slopes) < 100  # |d sigma| <= C d with C ~ a / (distance to the corner)


def offset_coplanar(shift=0.0, n=6):
    """Two coplanar square cracks side by side, the second moved by half an element
    (+ shift) so that its centres lie on the extension lines of the first's edges."""
    h = 1.0 / n
    first = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 1.0, 1.0, n, n)
    second = hd.mesh.rectangle([1.5, 0.5 * h + shift, 0], [1, 0, 0], [0, 1, 0], 1.0, 1.0, n, n, fracture_id=1)
    return hd.mesh.concatenate([first, second])


def test_collocation_points_on_edge_extension_lines_3d(material):
    mesh = offset_coplanar()
    dd, _, difference, info, dense = solve_both(mesh, material)
    assert difference < AGREE and info["iterations"] < 40
    for shift in (1e-7, -1e-7):
        moved = offset_coplanar(shift)
        matrix = hd.ElasticityOperator(moved, material).to_dense()
        assert np.abs(matrix - dense.to_dense()).max() < 1e-5 * np.abs(matrix).max()
        dd_moved = hd.solve(hd.ElasticityOperator(moved, material), -P * moved.normals)
        assert np.abs(dd_moved - dd).max() < 1e-5 * np.abs(dd).max()


def test_collocation_points_on_segment_extensions_2d(material):
    """Collinear 2D cracks: every centre lies on the extension of the other crack's
    segments; a gap of a tenth of an element between the tips."""
    left = hd.mesh.line([-2.05, 0], [-0.05, 0], 20)
    right = hd.mesh.line([0.05, 0], [2.05, 0], 20, fracture_id=1)
    mesh = hd.mesh.concatenate([left, right])
    dd, _, difference, _, _ = solve_both(mesh, material)
    assert difference < AGREE
    w = hd.opening(mesh, dd)
    np.testing.assert_allclose(w[:20], w[20:][::-1], rtol=1e-8)
    assert np.all(w > 0)


# ---------------------------------------------------- 5. scale separation (0.1 m - 100 m)
def per_fracture_error(mesh, dd, dd_h):
    return max(np.linalg.norm(dd_h[mesh.fracture_id == f] - dd[mesh.fracture_id == f])
               / np.linalg.norm(dd[mesh.fracture_id == f]) for f in np.unique(mesh.fracture_id))


@pytest.mark.parametrize("dim", [2, 3])
def test_mixed_scales_per_fracture_and_per_block_error(material, dim):
    mesh = mixed_scales(dim, small=30 if dim == 2 else 20)
    dd, dd_h, difference, info, _ = solve_both(mesh, material, leaf_size=32)
    assert difference < AGREE and info["iterations"] < 40
    assert per_fracture_error(mesh, dd, dd_h) < AGREE  # small fractures too, not only the norm
    op = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=EPS, leaf_size=32)
    assert op.check_against_dense(n_samples=64) < 10 * EPS


def test_mixed_scales_block_error_at_default_eps(material):
    """At the default eps 1e-4 in 2D, a plain partial ACA kept one block of this seed
    (rows and columns of the 100 m fracture plus several 0.1 m ones) at rank 5-6 with
    2.8e-2 error: its pivots all fell in the large fracture, whose rows and columns do
    not see the small fractures' interaction, and the stop test (last cross only)
    passed. The ACA now checks the residual of unvisited rows and columns before
    stopping (ACA+-like, hmatddm/hmatrix/aca_loop.py)."""
    mesh = mixed_scales(2, seed=2)
    op = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=1e-4, leaf_size=32)
    assert op.check_against_dense(n_samples=64) < 10 * 1e-4  # was 4.3e-2; measured 3.7e-4


# ------------------------------------------------------ 6. tilted and curved cracks
TILTED = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)


def test_tilted_penny_against_sneddon(material):
    errors = []
    centre = np.array([0.3, -0.2, 0.1])
    for h in (0.25, 0.125):
        aligned = hd.mesh.penny(centre, [0, 0, 1], 1.0, h)
        tilted = hd.mesh.penny(centre, TILTED, 1.0, h)
        dd, _, difference, info, _ = solve_both(tilted, material, leaf_size=32)
        assert difference < AGREE and info["iterations"] < 40
        w = hd.opening(tilted, dd)
        assert np.linalg.norm(hd.slip(tilted, dd), axis=1).max() < 1e-12 * w.max()
        w_aligned = hd.opening(aligned, hd.solve(hd.ElasticityOperator(aligned, material), -P * aligned.normals))
        np.testing.assert_allclose(w, w_aligned, rtol=1e-10)  # the same crack, rotated
        errors.append(volume(tilted, dd) / an.sneddon_volume(1.0, P, material) - 1)
        r = np.linalg.norm(tilted.centers - centre, axis=1)
        inner = r < 0.5
        sneddon = an.sneddon_opening(r[inner], 1.0, P, material)
        assert np.max(np.abs(w[inner] / sneddon - 1)) < (0.09 if h == 0.25 else 0.06)
    assert 0 < errors[1] < 0.65 * errors[0]  # staircase error ~ h


def test_tilted_penny_needs_no_more_gmres_iterations(material):
    """DDs are global-frame unknowns, so a tilted element's normal-normal coupling is
    spread over all 9 entries of its 3x3 blocks; the former default ILU dropped
    entries one by one (threshold of the row's diagonal, spilu drop_tol) and needed 9
    iterations aligned and 13 tilted (13 vs 20 at h = R/16). The default is now a
    block ILU(0) on element blocks kept by Frobenius norm (hmatddm/hmatrix/
    preconditioners.py): 7 and 7 (11 and 11 at R/16)."""
    iterations = []
    for normal in ([0, 0, 1], TILTED):
        mesh = hd.mesh.penny([0, 0, 0], normal, 1.0, 0.125)
        op = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=EPS, leaf_size=32)
        iterations.append(hd.solve(op, -P * mesh.normals, return_info=True)[1]["iterations"])
    assert iterations[1] <= iterations[0] + 1


def test_rotated_rectangle_equals_aligned(material):
    rotation = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))[0]
    rotation *= np.sign(np.linalg.det(rotation))
    aligned = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 1.0, 10, 5)
    rotated = aligned.transformed(rotation, (1.0, 2.0, 3.0))
    dd, _, difference, _, _ = solve_both(rotated, material)
    assert difference < AGREE
    w = hd.opening(aligned, hd.solve(hd.ElasticityOperator(aligned, material), -P * aligned.normals))
    np.testing.assert_allclose(hd.opening(rotated, dd), w, rtol=1e-10)


def arc(half_angle, n, radius=1.0):
    """Circular arc crack of ``n`` chords, symmetric about the +y axis."""
    t = np.linspace(-half_angle, half_angle, n + 1) + np.pi / 2
    nodes = radius * np.column_stack([np.cos(t), np.sin(t)])
    return hd.Mesh2D.from_segments(nodes[1:], nodes[:-1])


@pytest.mark.parametrize("half_angle_deg", [5.0, 90.0, 144.0])
def test_arc_crack_converges_under_refinement(material, half_angle_deg):
    half_angle = np.radians(half_angle_deg)
    volumes = []
    for n in (16, 32, 64):
        mesh = arc(half_angle, n)
        dd, _, difference, info, _ = solve_both(mesh, material)
        assert difference < AGREE and info["iterations"] < 40
        assert np.all(hd.opening(mesh, dd) > 0)
        volumes.append(volume(mesh, dd))
    steps = np.diff(volumes)
    order = np.log2(steps[0] / steps[1])
    assert 0.8 < order < 1.2  # first order, like the straight crack
    if half_angle_deg == 5.0:  # nearly straight: Griffith with the arc length
        extrapolated = volumes[-1] + steps[-1] / (2**order - 1)
        # within 0.5%: the 10 degree arc's curvature (chord vs arc length: 0.13% in area)
        assert extrapolated == pytest.approx(griffith_area(half_angle, material), rel=5e-3)


# ------------------------------------------------------- 7. coupled system scaling
def coupled_system(length, n):
    from hmatddm.mesh import topology
    from hmatddm.coupled import ElasticSolver, StepProblem
    from hmatddm.coupled.scaled_system import _CoupledLinearSystem
    from hmatddm.flow import LeakOff, LubricationModel, fracture_compliance

    mesh = hd.mesh.line([-length / 2, 0], [length / 2, 0], n)
    mat = hd.Elastic(10e9, 0.25)
    fluid = hd.Fluid(viscosity=1e-3, compressibility=4.5e-10)
    flow = LubricationModel(areas=mesh.areas, normals=mesh.normals, faces=topology.element_faces(mesh, height=1.0),
                            fluid=fluid, leak_off=LeakOff(coefficient=0.0, pore_pressure=0.5e6),
                            injection_elements=np.array([n // 2]), injection_rates=np.array([5e-4]),
                            wellbore_volumes=np.array([0.5]), minimum_width=1e-5)
    op = hd.ElasticityOperator(mesh, mat, backend="dense")
    width_old = 1e-4 * (1 - (mesh.centers[:, 0] / (0.525 * length)) ** 2)
    problem = StepProblem(elastic=ElasticSolver(op, rtol=1e-11), normals=mesh.normals,
                          far_field=np.tile([0.0, 0.5e6], n), flow=flow,
                          compliance=fracture_compliance(mesh, mat), dt=1.0, width_old=width_old,
                          pressure_old=np.full(n, 1e6), leak_off_rate=flow.leak_off_rate(np.zeros(n), 0.0, 1.0))
    dd0 = (width_old[:, None] * mesh.normals).ravel()
    p0 = np.full(n, 1e6)
    matrix, flow_rhs = problem.flow_matrices(dd0)
    system = _CoupledLinearSystem(problem, matrix, dd0, p0)
    b = np.zeros((2 * n, n))
    for i in range(n):
        b[2 * i:2 * i + 2, i] = mesh.normals[i]
    full = np.block([[op.to_dense(), b], [problem.coupling.toarray(), matrix.toarray()]])
    scaled = np.column_stack([system.operator @ e for e in np.eye(full.shape[0])])
    return full, np.concatenate([problem.far_field, flow_rhs]), scaled, system, flow_rhs


@pytest.mark.parametrize("length", [3.0, 30.0, 300.0])
def test_scaling_of_the_coupled_system(length):
    """ref. Fig. 4.13: cond ~1e16-1e21 unscaled, 1e2-1e5 scaled (grows with the crack).
    GMRES on the unscaled system meets its residual test with a wrong answer (the
    elastic rows, ~1e11 Pa/m, hide the flow rows); on the scaled one it recovers the
    direct solution."""
    full, rhs, scaled, system, flow_rhs = coupled_system(length, 10)
    cond_full, cond_scaled = np.linalg.cond(full), np.linalg.cond(scaled)
    assert cond_full > 1e15 and cond_scaled < 1e-10 * cond_full and cond_scaled < 1e6
    direct = np.linalg.solve(full, rhs)
    y, _ = spla.gmres(system.operator, system.rhs(flow_rhs), rtol=1e-12, atol=0.0, restart=100, maxiter=20)
    dd, p = system.split(y)
    np.testing.assert_allclose(np.concatenate([dd, p]), direct, rtol=0, atol=1e-8 * np.abs(direct).max())
    x, _ = spla.gmres(full, rhs, rtol=1e-9, atol=0.0, restart=100, maxiter=20)
    assert np.linalg.norm(full @ x - rhs) <= 1e-9 * np.linalg.norm(rhs)  # "converged" ...
    assert np.linalg.norm(x[20:] - direct[20:]) > 1e-3 * np.linalg.norm(direct[20:])  # ... to a wrong pressure
