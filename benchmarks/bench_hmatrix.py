"""H-matrix against dense: memory, time and error, on 3D rectangular DDM meshes.

    python benchmarks/bench_hmatrix.py                 # full study (about an hour on 2 cores)
    python benchmarks/bench_hmatrix.py --quick         # N = 1k, 4k only, short eps sweep
    python benchmarks/bench_hmatrix.py --case planar --n 10000 --eps 1e-4   # one case, JSON
    python benchmarks/bench_hmatrix.py --tree-study 4000   # cloud: principal-axis vs fractures-first tree
    python benchmarks/bench_hmatrix.py --rank-study 4000   # cloud: far-block ranks by kind (same/two fractures) and level
    python benchmarks/bench_hmatrix.py --memory-study 10000,40000 --variants 1e-4:32:float64,1e-4:16:float32
                                                       # planar: where the memory goes, growth exponents
    python benchmarks/bench_hmatrix.py --aca-study 10000 --aca-factors 0.1,0.3,0.5
                                                       # far blocks: ACA tolerance vs cost, ranks, block error

Three studies, each printed as a markdown table and saved (JSON + PNG) in benchmarks/out/:

1. scaling: N = 1k, 4k, 10k (dense where it fits) and 40k, 100k (H only) on a planar
   square crack and on a cloud of vertical natural-fracture-like rectangles; build time,
   memory, compression, matvec time, GMRES iterations and time to rtol 1e-8 (crack under
   uniform pressure), error against dense (smooth-field and random-vector matvec error;
   solution error where the dense solve is affordable). Without dense, the smooth-field
   error is measured on 300 exact rows computed by the kernel.
2. speed against error: eps from 1e-2 to 1e-10 at N = 10k (planar): build time, memory,
   worst sampled admissible-block error, smooth-field matvec error, solution error.
3. growth exponents: log-log slopes of build time and memory against N.

Each case runs in its own process, so the peak memory reported is that case's.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out")
P = 1e6


def planar(n):
    import hmatddm as hd

    side = int(round(np.sqrt(n)))
    return hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], float(side), float(side), side, side)


def cloud(n, seed=0):
    """Vertical fractures (10 m high, 8-40 m long, random strike), 1 m elements, that do
    not cross or touch (at least 2 m apart in plan view: intersections are a separate
    problem, see the hard-case suite), in a square domain with about 0.005 fractures/m^2."""
    import hmatddm as hd

    rng = np.random.default_rng(seed)
    parts, traces, total, k = [], [], 0, 0
    domain = np.sqrt(n / 240 / 0.005)
    while total < n:
        length = min(int(rng.integers(8, 41)), max(1, (n - total) // 10))
        strike = rng.uniform(0, np.pi)
        e1 = np.array([np.cos(strike), np.sin(strike), 0.0])
        center = np.array([*rng.uniform(-domain / 2, domain / 2, 2), 0.0])
        trace = (center[:2] - 0.5 * length * e1[:2], center[:2] + 0.5 * length * e1[:2])
        if any(_segment_distance(trace, other) < 2.0 for other in traces):
            continue
        traces.append(trace)
        parts.append(hd.mesh.rectangle(center, e1, [0, 0, 1], float(length), 10.0, length, 10, fracture_id=k))
        total += length * 10
        k += 1
    return hd.mesh.concatenate(parts)


def _segment_distance(s, t):
    """Shortest distance between two plan-view segments (0 when they cross)."""
    (p, q), (r, u) = s, t
    d1, d2 = q - p, u - r
    cross = lambda a, b: a[0] * b[1] - a[1] * b[0]  # noqa: E731
    denom = cross(d1, d2)
    if denom != 0.0:
        a = cross(r - p, d2) / denom
        b = cross(r - p, d1) / denom
        if 0 <= a <= 1 and 0 <= b <= 1:
            return 0.0

    def point_segment(x, a, b):
        h = np.clip(np.dot(x - a, b - a) / np.dot(b - a, b - a), 0, 1)
        return np.linalg.norm(x - a - h * (b - a))

    return min(point_segment(p, r, u), point_segment(q, r, u), point_segment(r, p, q), point_segment(u, p, q))


def smooth_field(mesh):
    """Elliptical opening over each fracture (docs/conventions.md §7: the field that matters)."""
    dd = np.zeros((mesh.n_elements, 3))
    for k in np.unique(mesh.fracture_id):
        idx = np.flatnonzero(mesh.fracture_id == k)
        local = (mesh.centers[idx] - mesh.centers[idx].mean(axis=0)) @ mesh.frames[idx[0], :2].T
        half = np.abs(local).max(axis=0) + np.array([mesh.half_a[idx[0]], mesh.half_b[idx[0]]])
        w = np.sqrt(np.clip(1 - np.sum((local / half) ** 2, axis=1), 0, None))
        dd[idx] = 1e-3 * w[:, None] * mesh.normals[idx]
    return dd.ravel()


def run_case(geometry, n, eps, dense_limit, solve_limit, check_blocks, rtol=1e-8):
    """One measurement; returns a dict (run in a fresh process by the driver)."""
    import hmatddm as hd
    from _common import peak_rss_bytes

    mesh = (planar if geometry == "planar" else cloud)(n)
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    row = dict(geometry=geometry, n=mesh.n_elements, eps=eps, rtol=rtol)
    c0 = time.process_time()
    op = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=eps)
    row["build_cpu_s"] = time.process_time() - c0
    stats = op.stats
    row.update(build_s=stats["build_seconds"], memory_mb=stats["memory_bytes"] / 2**20,
               dense_mb=stats["dense_bytes"] / 2**20, compression=stats["compression"],
               max_rank=stats["max_rank"], n_admissible=stats["n_admissible"])
    x_smooth = smooth_field(mesh)
    x_random = np.random.default_rng(1).normal(size=op.shape[1])
    op.matvec(x_smooth)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        y_smooth = op.matvec(x_smooth)
        times.append(time.perf_counter() - t0)
    row["matvec_s"] = float(np.median(times))
    y_random = op.matvec(x_random)

    traction = -P * mesh.normals
    t0 = time.perf_counter()
    dd, info = hd.solve(op, traction, rtol=rtol, return_info=True)
    row.update(gmres_s=time.perf_counter() - t0 + 0.0, gmres_iterations=info["iterations"])
    row["preconditioners"] = compare_preconditioners(op, traction.ravel(), rtol)
    if check_blocks:
        row["worst_block_error"] = float(op.check_against_dense(n_samples=200))
    row["peak_rss_mb"] = peak_rss_bytes() / 2**20  # the H-matrix run only, before any dense work

    if mesh.n_elements <= dense_limit:
        ref = dense_reference(mesh, material, x_smooth, x_random, traction, op, solve_limit)
        row.update({k: ref[k] for k in ("dense_build_s", "dense_matvec_s", "dense_solve_s")})
        row["smooth_error"] = float(np.linalg.norm(y_smooth - ref["smooth"]) / np.linalg.norm(ref["smooth"]))
        row["random_error"] = float(np.linalg.norm(y_random - ref["random"]) / np.linalg.norm(ref["random"]))
        row["solution_error"] = float(np.linalg.norm(dd.ravel() - ref["dd"]) / np.linalg.norm(ref["dd"]))
    else:
        rows = np.sort(np.random.default_rng(2).choice(mesh.n_elements, 300, replace=False))
        exact = op.exact_block(rows, np.arange(mesh.n_elements)) @ x_smooth
        index = (3 * rows[:, None] + np.arange(3)).ravel()
        row["smooth_error"] = float(np.linalg.norm(y_smooth[index] - exact) / np.linalg.norm(exact))
        row["smooth_error_sampled"] = True
    return row


def compare_preconditioners(op, b, rtol):
    """Setup (wall and CPU), memory, GMRES iterations and time of the near-field block
    ILU and of the two-level preconditioner built on it, for the same right-hand side."""
    from hmatddm.hmatrix import gmres, near_field_block_ilu, two_level
    from hmatddm.hmatrix.preconditioners import DEFAULT_ILU

    out = {}
    t0, c0 = time.perf_counter(), time.process_time()
    ilu = near_field_block_ilu(op.hmatrix, **DEFAULT_ILU)
    ilu_setup, ilu_cpu = time.perf_counter() - t0, time.process_time() - c0
    t0, c0 = time.perf_counter(), time.process_time()
    both = two_level(op.hmatrix, smoother=ilu)
    setup, cpu = time.perf_counter() - t0, time.process_time() - c0
    solutions = {}
    for name, M, setup_s, setup_cpu, extra in (("block_ilu", ilu, ilu_setup, ilu_cpu, ilu.nbytes),
                                                ("two_level", both, ilu_setup + setup, ilu_cpu + cpu,
                                                 ilu.nbytes + both.coarse["coarse_bytes"])):
        t0, c0 = time.perf_counter(), time.process_time()
        x, info = gmres(op, b, M=M, rtol=rtol, restart=100, maxiter=20)
        out[name] = dict(setup_s=setup_s, setup_cpu_s=setup_cpu, gmres_s=time.perf_counter() - t0,
                         gmres_cpu_s=time.process_time() - c0, iterations=info["iterations"],
                         memory_mb=extra / 2**20)
        solutions[name] = x
    out["two_level"]["coarse_size"] = both.coarse["coarse_size"]
    out["two_level"]["difference"] = float(np.linalg.norm(solutions["two_level"] - solutions["block_ilu"])
                                           / np.linalg.norm(solutions["block_ilu"]))
    return out


def tree_study(n, leaf_size=32):
    """Cloud of N elements: H-matrix with the principal-axis cluster tree against one split
    between whole fractures first (``groups=fracture_id``); build wall and CPU, memory,
    near field, ranks and the sampled smooth-field error. Returns a list of dicts."""
    import hmatddm as hd
    from hmatddm.hmatrix import BlockGenerator, HMatrix
    from hmatddm.kernels.drivers import traction_block
    from hmatddm.elasticity.operator import influence_data

    mesh = cloud(n)
    data = influence_data(mesh, hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25))
    generator = BlockGenerator(kernel=traction_block, data=data, points=mesh.centers, radii=mesh.radii, dof=3)
    x = smooth_field(mesh)
    rows = np.sort(np.random.default_rng(2).choice(mesh.n_elements, 300, replace=False))
    exact_rows = np.empty((3 * rows.size, 3 * mesh.n_elements))
    traction_block(data, rows, np.arange(mesh.n_elements), exact_rows)
    exact = exact_rows @ x
    index = (3 * rows[:, None] + np.arange(3)).ravel()
    out = []
    for tree, groups in (("principal axis", None), ("fractures first", mesh.fracture_id)):
        t0, c0 = time.perf_counter(), time.process_time()
        h = HMatrix.build(generator, eps=1e-4, eta=3.0, leaf_size=leaf_size, groups=groups)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        st = h.stats
        error = float(np.linalg.norm((h @ x)[index] - exact) / np.linalg.norm(exact))
        out.append(dict(n=mesh.n_elements, tree=tree, build_s=wall, build_cpu_s=cpu, memory_mb=st["memory_bytes"] / 2**20,
                        near_mb=st["near_field_bytes"] / 2**20, max_rank=st["max_rank"], mean_rank=st["mean_rank"],
                        smooth_error=error))
        print(json.dumps(out[-1]), flush=True)
    return out


def rank_study(n, eps=1e-4, leaf_size=32):
    """Cloud of N elements (fractures-first tree, as ElasticityOperator builds it): rank and
    memory of the admissible blocks by kind (both clusters on the same fracture, on two
    different fractures, or a cluster holding several fractures) and row-cluster level.
    Returns a list of dicts, one per (kind, level)."""
    import hmatddm as hd
    from hmatddm.hmatrix import BlockGenerator, HMatrix
    from hmatddm.hmatrix.storage import KIND_DENSE, KIND_LOWRANK
    from hmatddm.kernels.drivers import traction_block
    from hmatddm.elasticity.operator import influence_data

    mesh = cloud(n)
    data = influence_data(mesh, hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25))
    generator = BlockGenerator(kernel=traction_block, data=data, points=mesh.centers, radii=mesh.radii, dof=3)
    h = HMatrix.build(generator, eps=eps, eta=3.0, leaf_size=leaf_size, groups=mesh.fracture_id)
    s, t = h.storage, h.tree
    fracture = mesh.fracture_id[t.permutation]
    one = np.array([fracture[t.start[c]:t.stop[c]].min() == fracture[t.start[c]:t.stop[c]].max()
                    for c in range(t.n_clusters)])
    table = {}
    for b, (r, c) in enumerate(zip(h.blocks.admissible_rows, h.blocks.admissible_cols)):
        kind = ("several fractures" if not (one[r] and one[c]) else
                "same fracture" if fracture[t.start[r]] == fracture[t.start[c]] else "two fractures")
        m, k_cols = 3 * int(t.stop[r] - t.start[r]), 3 * int(t.stop[c] - t.start[c])
        rank, size = 0, 0
        if s.admissible_kind[b] == KIND_LOWRANK:
            rank = int(s.lowrank_rank[s.admissible_index[b]])
            head = int(s.lowrank_head[s.admissible_index[b]])  # float columns; the rest int16 + 2 scales each
            size = (head * s.u_values.itemsize + (rank - head) * s.u_fixed.itemsize) * (m + k_cols) + 16 * rank
        elif s.admissible_kind[b] == KIND_DENSE:
            rank, size = min(m, k_cols), m * k_cols * s.dense_values.itemsize
        row = table.setdefault((kind, int(t.level[r])), dict(kind=kind, level=int(t.level[r]), blocks=0, max_rank=0,
                                                              rank_sum=0, mb=0.0))
        row["blocks"] += 1
        row["max_rank"] = max(row["max_rank"], rank)
        row["rank_sum"] += rank
        row["mb"] += size / 2**20
    out = [dict(r, mean_rank=r["rank_sum"] / r["blocks"]) for _, r in sorted(table.items())]
    for r in out:
        print(json.dumps(r), flush=True)
    return out


def aca_study(n, factors, geometry="cloud", eps=1e-4, stride=9, leaf_size=32):
    """Every ``stride``-th far block of the N-element ``geometry`` (tree as ElasticityOperator
    builds it), compressed as the build does (whole-element ACA at ``factor * eps``, then
    recompression at eps) for each ACA tolerance factor: process CPU time of the kernel
    evaluations, the ACA steps and the recompression (one thread), mean ACA and stored
    rank, and the stored block's relative Frobenius error against the exact block (worst,
    median, count above eps). Returns a list of dicts, one per factor."""
    import hmatddm as hd
    from hmatddm.hmatrix import aca, aca_loop
    from hmatddm.hmatrix._threads import single_threaded_blas
    from hmatddm.hmatrix.block_tree import block_tree
    from hmatddm.hmatrix.cluster_tree import cluster_tree
    from hmatddm.kernels.drivers import traction_block
    from hmatddm.elasticity.operator import influence_data

    mesh = (planar if geometry == "planar" else cloud)(n)
    data = influence_data(mesh, hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25))
    tree = cluster_tree(mesh.centers, mesh.radii, leaf_size, groups=None if geometry == "planar" else mesh.fracture_id)
    blocks = block_tree(tree, 3.0)
    p = tree.permutation
    sample = []
    for b in range(0, blocks.admissible_rows.size, stride):
        rows = p[tree.start[blocks.admissible_rows[b]]:tree.stop[blocks.admissible_rows[b]]].astype(np.int64)
        cols = p[tree.start[blocks.admissible_cols[b]]:tree.stop[blocks.admissible_cols[b]]].astype(np.int64)
        exact = np.empty((3 * rows.size, 3 * cols.size))
        traction_block(data, rows, cols, exact)
        sample.append((rows, cols, exact))
    aca.aca_steps()  # the steps compiled for the drivers' signatures before the direct calls below

    def compress(rows, cols, factor, cpu):
        """(ACA rank, stored U'^T, V'^T, stored rank), or None when the ACA gave up."""
        ut, vt, gram, r, c, rv, cv, ints, floats, request, index = aca_loop.aca_start(rows.size, cols.size, 3, 3,
                                                                                      factor * eps)
        while request != aca_loop.REQUEST_DONE:
            t0 = time.process_time()
            if request == aca_loop.REQUEST_ROW:
                traction_block(data, rows[index:index + 1], cols, r)
            else:
                traction_block(data, rows, cols[index:index + 1], c)
            t1 = time.process_time()
            ut, vt, gram, request, index = aca_loop.aca_advance(ut, vt, gram, r, c, rv, cv, ints, floats)
            cpu["kernel"] += t1 - t0
            cpu["aca"] += time.process_time() - t1
        if aca_loop.aca_gave_up(ints):
            return None  # the build stores the block dense: exact
        t0 = time.process_time()
        u2, v2, k2 = aca.recompress_state(ut, vt, gram, ints, eps)
        cpu["recompression"] += time.process_time() - t0
        return int(ints[1]), u2, v2, k2

    out = []
    with single_threaded_blas():
        compress(sample[0][0], sample[0][1], factors[0], dict(kernel=0.0, aca=0.0, recompression=0.0))  # compile
        for factor in factors:
            cpu = dict(kernel=0.0, aca=0.0, recompression=0.0)
            aca_rank, ranks, errors, gave_up = [], [], [], 0
            for rows, cols, exact in sample:
                result = compress(rows, cols, factor, cpu)
                if result is None:
                    gave_up += 1
                    continue
                aca_rank.append(result[0])
                ranks.append(result[3])
                errors.append(np.linalg.norm(result[1].T @ result[2] - exact) / np.linalg.norm(exact) / eps)
            errors = np.array(errors)
            out.append(dict(geometry=geometry, n=mesh.n_elements, eps=eps, factor=factor, blocks=len(sample),
                            gave_up=gave_up, **{k + "_cpu_s": v for k, v in cpu.items()},
                            total_cpu_s=sum(cpu.values()), aca_rank=float(np.mean(aca_rank)),
                            stored_rank=float(np.mean(ranks)), worst_error_over_eps=float(errors.max()),
                            median_error_over_eps=float(np.median(errors)), above_eps=int((errors > 1.0).sum())))
    for r in out:
        print(json.dumps(r), flush=True)
    return out


def print_aca_table(rows):
    from _common import markdown_table

    header = ["geometry", "N", "eps", "ACA at", "blocks", "CPU kernel / ACA / recompression (s)", "total CPU (s)",
              "ACA rank", "stored rank", "block error / eps, worst / median", "blocks above eps", "gave up (dense)"]
    print(markdown_table(header, [[r["geometry"], r["n"], f"{r['eps']:.0e}", f"{r['factor']:g} eps", r["blocks"],
                                   f"{r['kernel_cpu_s']:.2f} / {r['aca_cpu_s']:.2f} / {r['recompression_cpu_s']:.2f}",
                                   f"{r['total_cpu_s']:.2f}", f"{r['aca_rank']:.1f}", f"{r['stored_rank']:.1f}",
                                   f"{r['worst_error_over_eps']:.2f} / {r['median_error_over_eps']:.2f}",
                                   r["above_eps"], r["gave_up"]] for r in rows]))


def sampled_smooth_error(mesh, data, y, n_rows=300, chunk=10):
    """Relative error of ``y`` (an H-matrix product with the smooth field) on ``n_rows``
    exact rows computed by the kernel, ``chunk`` rows at a time (bounded memory at 250k)."""
    from hmatddm.kernels.drivers import traction_block

    x = smooth_field(mesh)
    rows = np.sort(np.random.default_rng(2).choice(mesh.n_elements, n_rows, replace=False))
    exact = np.empty(3 * rows.size)
    columns = np.arange(mesh.n_elements)
    for k in range(0, rows.size, chunk):
        part = rows[k:k + chunk]
        block = np.empty((3 * part.size, 3 * mesh.n_elements))
        traction_block(data, part, columns, block)
        exact[3 * k:3 * k + 3 * part.size] = block @ x
    index = (3 * rows[:, None] + np.arange(3)).ravel()
    return float(np.linalg.norm(y[index] - exact) / np.linalg.norm(exact))


def memory_case(n, eps=1e-4, leaf_size=32, near_dtype="float64", geometry="planar", boxes="axis", factor="default",
                eta=3.0):
    """Planar crack (or cloud, fractures-first tree as ElasticityOperator builds it) of N elements: where the H-matrix memory goes (near-field dense
    blocks, far blocks stored dense, low-rank factors, index), build wall and CPU time,
    peak RSS and the sampled smooth-field error, with the near field stored as
    ``near_dtype``, admissibility on ``boxes`` ("axis" or "oriented"), low-rank factors stored as ``factor``
    ("default": HMatrix.build's choice, "adaptive", "float32" or "float64"), admissibility
    parameter ``eta``. Returns a dict (run in a fresh
    process by --memory-study)."""
    import hmatddm as hd
    from _common import peak_rss_bytes
    from hmatddm.hmatrix import BlockGenerator, HMatrix
    from hmatddm.kernels.drivers import traction_block
    from hmatddm.elasticity.operator import influence_data

    mesh = (planar if geometry == "planar" else cloud)(n)
    data = influence_data(mesh, hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25))
    generator = BlockGenerator(kernel=traction_block, data=data, points=mesh.centers, radii=mesh.radii, dof=3)
    groups = None if geometry == "planar" else mesh.fracture_id
    with open("/proc/loadavg") as f:
        load = float(f.read().split()[0])
    t0, c0 = time.perf_counter(), time.process_time()
    factor_dtype = None if factor == "default" else factor if factor == "adaptive" else np.dtype(factor)
    h = HMatrix.build(generator, eps=eps, eta=eta, leaf_size=leaf_size, near_dtype=np.dtype(near_dtype),
                      groups=groups, boxes=boxes, factor_dtype=factor_dtype)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    s = h.storage
    near = int(sum(s.dense_offset[b + 1] - s.dense_offset[b] for b in np.flatnonzero(s.dense_is_near)))
    item = s.dense_values.itemsize
    row = dict(geometry=geometry, boxes=boxes, n=mesh.n_elements, eps=eps, eta=eta, leaf_size=leaf_size,
               near_dtype=str(np.dtype(near_dtype)), n_admissible=int(s.admissible_kind.size),
               build_s=wall, build_cpu_s=cpu, load_before=load, memory_mb=s.memory_bytes / 2**20,
               near_mb=near * item / 2**20, far_dense_mb=(s.dense_values.size - near) * item / 2**20,
               lowrank_mb=s.lowrank_bytes / 2**20, index_mb=s.index_bytes / 2**20,
               factor_dtype=s.factor_format, max_rank=int(s.lowrank_rank.max(initial=0)),
               mean_rank=float(s.lowrank_rank.mean()) if s.lowrank_rank.size else 0.0,
               peak_rss_mb=peak_rss_bytes() / 2**20)
    row["kb_per_element"] = s.memory_bytes / mesh.n_elements / 1024
    x = smooth_field(mesh)
    t0 = time.perf_counter()
    y = h @ x
    row["first_matvec_s"] = time.perf_counter() - t0  # with first-use costs (page faults, thread start)
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        h @ x
        times.append(time.perf_counter() - t0)
    row["matvec_s"] = float(np.median(times))
    row["smooth_error"] = sampled_smooth_error(mesh, data, y)
    return row


def memory_table(rows):
    from _common import markdown_table

    header = ["geometry", "boxes", "N", "eps", "eta", "leaf", "near field", "factors", "build wall / CPU (s)", "load", "H memory (MB)", "near field (MB)",
              "far dense (MB)", "low-rank (MB)", "KB / element", "mean / max rank", "peak RSS (MB)",
              "matvec first / median of 3 (s)", "smooth-field error (sampled)"]
    body = [[r.get("geometry", "planar"), r.get("boxes", "axis"), r["n"], f"{r['eps']:.0e}", f"{r.get('eta', 3.0):g}", r["leaf_size"], r["near_dtype"], r.get("factor_dtype", "float32"), f"{r['build_s']:.1f} / {r['build_cpu_s']:.1f}",
             f"{r['load_before']:.1f}", f"{r['memory_mb']:.0f}", f"{r['near_mb']:.0f}", f"{r['far_dense_mb']:.0f}",
             f"{r['lowrank_mb']:.0f}", f"{r['kb_per_element']:.1f}", f"{r['mean_rank']:.1f} / {r['max_rank']}",
             f"{r['peak_rss_mb']:.0f}", _matvec_cell(r), f"{r['smooth_error']:.1e}"] for r in rows if "failed" not in r]
    return markdown_table(header, body)


def _matvec_cell(row):
    """The first product (with its first-use costs) and the median of the next three; rows
    of older runs hold one timing of the first product."""
    if "first_matvec_s" not in row:
        return f"{row['matvec_s']:.2f} (first only)" if "matvec_s" in row else "-"
    return f"{row['first_matvec_s']:.2f} / {row['matvec_s']:.2f}"


def memory_slopes(rows):
    """Log-log slopes of build CPU time and memory against N per (geometry, eps, leaf, near dtype);
    eta other than 3 is named with the geometry."""
    out = {}
    variant = lambda r: (r.get("geometry", "planar") + ("" if r.get("boxes", "axis") == "axis" else " oriented")  # noqa: E731
                         + ("" if r.get("eta", 3.0) == 3.0 else f" eta {r['eta']:g}"),
                         r["eps"], r["leaf_size"], r["near_dtype"] + "/" + r.get("factor_dtype", "float32"))
    for key in sorted({variant(r) for r in rows if "failed" not in r}):
        sel = sorted((r for r in rows if "failed" not in r and variant(r) == key), key=lambda r: r["n"])
        if len(sel) >= 2:
            n = np.log([r["n"] for r in sel])
            out[key] = dict(sizes=[r["n"] for r in sel],
                            build_cpu=float(np.polyfit(n, np.log([r["build_cpu_s"] for r in sel]), 1)[0]),
                            memory=float(np.polyfit(n, np.log([r["memory_mb"] for r in sel]), 1)[0]))
    return out


def spawn_memory(n, eps, leaf_size, near_dtype, geometry="planar", boxes="axis", factor="default", eta=3.0):
    cmd = [sys.executable, os.path.abspath(__file__), "--memory-case", json.dumps(
        dict(n=n, eps=eps, leaf_size=leaf_size, near_dtype=near_dtype, geometry=geometry, boxes=boxes,
             factor=factor, eta=eta))]
    print("  running", cmd[-1], flush=True)
    result = subprocess.run(cmd, capture_output=True, text=True, cwd=HERE)
    if result.returncode != 0:
        print(result.stdout, result.stderr, file=sys.stderr)
        return dict(geometry=geometry, n=n, eps=eps, leaf_size=leaf_size, near_dtype=near_dtype,
                    failed=result.stderr.strip().splitlines()[-1:])
    return json.loads(result.stdout.strip().splitlines()[-1])


def dense_reference(mesh, material, x_smooth, x_random, traction, op, solve_limit):
    """Dense products and solution, cached in benchmarks/out/ (the eps sweep reuses them)."""
    import hmatddm as hd

    import hashlib

    digest = hashlib.sha1(mesh.centers.tobytes() + mesh.frames.tobytes()).hexdigest()[:12]
    path = os.path.join(OUT, f"dense_{mesh.n_elements}_{digest}.npz")
    if os.path.exists(path):
        with np.load(path) as f:
            return {k: (float(f[k]) if f[k].ndim == 0 else f[k]) for k in f.files}
    t0 = time.perf_counter()
    dense = hd.ElasticityOperator(mesh, material, backend="dense")
    ref = dict(dense_build_s=time.perf_counter() - t0)
    t0 = time.perf_counter()
    ref["smooth"] = dense.matvec(x_smooth)
    ref["dense_matvec_s"] = time.perf_counter() - t0
    ref["random"] = dense.matvec(x_random)
    t0 = time.perf_counter()
    if mesh.n_elements <= solve_limit:
        ref["dd"] = hd.solve(dense, traction).ravel()
    else:  # dense matvecs inside GMRES, preconditioned by the H near field, to a tight tolerance
        from hmatddm.hmatrix import gmres

        ref["dd"], _ = gmres(dense, traction.ravel(), M=op.preconditioner(), rtol=1e-12, restart=200, maxiter=5)
    ref["dense_solve_s"] = time.perf_counter() - t0
    os.makedirs(OUT, exist_ok=True)
    np.savez(path, **ref)
    return ref


def spawn(geometry, n, eps, dense_limit=10_000, solve_limit=4_000, check_blocks=False, rtol=1e-8):
    cmd = [sys.executable, os.path.abspath(__file__), "--case", geometry, "--n", str(n), "--eps", str(eps),
           "--rtol", str(rtol),
           "--dense-limit", str(dense_limit), "--solve-limit", str(solve_limit)]
    if check_blocks:
        cmd.append("--check-blocks")
    print("  running", " ".join(cmd[2:]), flush=True)
    result = subprocess.run(cmd, capture_output=True, text=True, cwd=HERE)
    if result.returncode != 0:
        print(result.stdout, result.stderr, file=sys.stderr)
        return dict(geometry=geometry, n=n, eps=eps, failed=result.stderr.strip().splitlines()[-1:])
    return json.loads(result.stdout.strip().splitlines()[-1])


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def scaling_table(rows):
    from _common import markdown_table

    header = ["geometry", "N", "build (s)", "H memory (MB)", "dense (MB)", "compression", "max rank",
              "matvec (ms)", "GMRES its", "GMRES (s)", "peak RSS (MB)", "dense build (s)", "dense matvec (ms)",
              "smooth-field error", "random-vector error", "solution error"]
    body = []
    for r in rows:
        if "failed" in r:
            body.append([r["geometry"], r["n"], "failed: " + " ".join(r["failed"])] + [""] * (len(header) - 3))
            continue
        smooth = fmt(r.get("smooth_error"), ".1e") + (" (sampled)" if r.get("smooth_error_sampled") else "")
        body.append([r["geometry"], r["n"], fmt(r["build_s"], ".1f"), fmt(r["memory_mb"], ".0f"),
                     fmt(r["dense_mb"], ".0f"), fmt(r["compression"], ".1f"), r["max_rank"],
                     fmt(r["matvec_s"] * 1e3, ".0f"), r["gmres_iterations"], fmt(r["gmres_s"], ".1f"),
                     fmt(r["peak_rss_mb"], ".0f"), fmt(r.get("dense_build_s"), ".1f"),
                     fmt(None if r.get("dense_matvec_s") is None else r["dense_matvec_s"] * 1e3, ".0f"),
                     smooth, fmt(r.get("random_error"), ".1e"), fmt(r.get("solution_error"), ".1e")])
    return markdown_table(header, body)


def eps_table(rows):
    from _common import markdown_table

    header = ["eps", "build (s)", "memory (MB)", "compression", "max rank", "matvec (ms)", "GMRES its",
              "worst block error", "smooth-field error", "solution error"]
    body = [[f"{r['eps']:.0e}", fmt(r["build_s"], ".1f"), fmt(r["memory_mb"], ".0f"), fmt(r["compression"], ".1f"),
             r["max_rank"], fmt(r["matvec_s"] * 1e3, ".0f"), r["gmres_iterations"],
             fmt(r.get("worst_block_error"), ".1e"), fmt(r.get("smooth_error"), ".1e"),
             fmt(r.get("solution_error"), ".1e")] for r in rows if "failed" not in r]
    return markdown_table(header, body)


def slopes(rows):
    out = {}
    for geometry in ("planar", "cloud"):
        sel = [r for r in rows if r.get("geometry") == geometry and "failed" not in r and r["n"] >= 4000]
        if len(sel) >= 2:
            n = np.log([r["n"] for r in sel])
            out[geometry] = dict(build=float(np.polyfit(n, np.log([r["build_s"] for r in sel]), 1)[0]),
                                 memory=float(np.polyfit(n, np.log([r["memory_mb"] for r in sel]), 1)[0]),
                                 matvec=float(np.polyfit(n, np.log([r["matvec_s"] for r in sel]), 1)[0]))
    return out


def plots(scaling, sweep):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for geometry, marker in (("planar", "o"), ("cloud", "s")):
        sel = [r for r in scaling if r.get("geometry") == geometry and "failed" not in r]
        if not sel:
            continue
        n = [r["n"] for r in sel]
        axes[0].loglog(n, [r["memory_mb"] for r in sel], marker + "-", label=f"H, {geometry}")
        axes[1].loglog(n, [r["build_s"] for r in sel], marker + "-", label=f"H build, {geometry}")
        dn = [r["n"] for r in sel if "dense_build_s" in r]
        axes[1].loglog(dn, [r["dense_build_s"] for r in sel if "dense_build_s" in r], marker + "--",
                       label=f"dense assembly, {geometry}")
    nn = np.array([1e3, 1e5])
    axes[0].loglog(nn, 8 * (3 * nn) ** 2 / 2**20, "k:", label="dense (8 (3N)^2 bytes)")
    axes[0].set(xlabel="elements N", ylabel="memory (MB)", title="memory, eps = 1e-4")
    axes[1].set(xlabel="elements N", ylabel="seconds", title="build time, 2 threads")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "hmatrix_scaling.png"), dpi=110)

    if sweep:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        eps = [r["eps"] for r in sweep if "failed" not in r]
        ok = [r for r in sweep if "failed" not in r]
        for key, label in (("worst_block_error", "worst block error"), ("smooth_error", "smooth-field matvec error"),
                           ("solution_error", "solution error")):
            axes[0].loglog(eps, [r.get(key, np.nan) for r in ok], "o-", label=label)
        axes[0].loglog(eps, eps, "k:", label="eps")
        axes[0].set(xlabel="eps", ylabel="relative error", title="accuracy, planar N = 10k")
        axes[1].semilogx([r["smooth_error"] for r in ok], [r["build_s"] for r in ok], "o-", label="build (s)")
        axes[1].semilogx([r["smooth_error"] for r in ok], [r["memory_mb"] / 100 for r in ok], "s-",
                         label="memory (100 MB)")
        axes[1].set(xlabel="smooth-field error", ylabel="cost", title="cost against error")
        for ax in axes:
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(HERE, "hmatrix_eps.png"), dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--case", choices=["planar", "cloud"])
    parser.add_argument("--n", type=int)
    parser.add_argument("--eps", type=float, default=1e-4)
    parser.add_argument("--dense-limit", type=int, default=10_000)
    parser.add_argument("--solve-limit", type=int, default=4_000)
    parser.add_argument("--check-blocks", action="store_true")
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--sizes", default=None, help="comma-separated N (default 1000,4000,10000,40000,100000)")
    parser.add_argument("--skip-sweep", action="store_true")
    parser.add_argument("--geometries", default="planar,cloud", help="comma-separated: planar, cloud")
    parser.add_argument("--tree-study", type=int, default=None, metavar="N",
                        help="cloud of N elements: principal-axis tree against fractures-first tree, then exit")
    parser.add_argument("--memory-study", default=None, metavar="N,N,...",
                        help="memory per element by kind (near field, low rank) and its growth, then exit")
    parser.add_argument("--variants", default="1e-4:32:float64,1e-4:32:float32",
                        help="memory study: comma-separated eps:leaf:near_dtype[:geometry[:boxes[:factors[:eta]]]] "
                             "(geometry planar or cloud; boxes axis or oriented: admissibility on axis-aligned or "
                             "oriented cluster boxes; factors default, adaptive, float32 or float64; eta the "
                             "admissibility parameter, default 3)")
    parser.add_argument("--rank-study", type=int, default=None, metavar="N",
                        help="cloud of N elements: rank and memory of far blocks by kind and level, then exit")
    parser.add_argument("--aca-study", type=int, default=None, metavar="N",
                        help="every 9th far block of N-element cloud and planar meshes: ACA tolerance factor against "
                             "CPU split, ranks and stored block error (one thread), then exit")
    parser.add_argument("--aca-factors", default="0.1,0.3", help="ACA tolerance factors (times eps) for --aca-study")
    parser.add_argument("--memory-case", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    sys.path.insert(0, HERE)
    if args.memory_case:
        print(json.dumps(memory_case(**json.loads(args.memory_case))))
        return
    if args.memory_study:
        from _common import machine

        print(f"Machine: {machine()}")
        rows = []
        for n in (int(v) for v in args.memory_study.split(",")):
            for variant in args.variants.split(","):
                parts = variant.split(":")
                eps, leaf, near_dtype, geometry, boxes, factor, eta = parts + ["planar", "axis", "default", "3"][len(parts) - 3:]
                rows.append(spawn_memory(n, float(eps), int(leaf), near_dtype, geometry, boxes, factor, float(eta)))
                print(json.dumps(rows[-1]), flush=True)
        os.makedirs(OUT, exist_ok=True)
        with open(os.path.join(OUT, "hmatrix_memory.json"), "w") as f:
            json.dump(rows, f, indent=1)
        print("\n## Memory per element\n")
        print(memory_table(rows))
        for (geometry, eps, leaf, near_dtype), s in memory_slopes(rows).items():
            print(f"- {geometry}, eps {eps:.0e}, leaf {leaf}, near {near_dtype}: N = {s['sizes']}: build CPU exponent "
                  f"{s['build_cpu']:.2f}, memory exponent {s['memory']:.2f}")
        return
    if args.tree_study:
        tree_study(args.tree_study)
        return
    if args.aca_study:
        from _common import machine

        print(f"Machine: {machine()}")
        factors = [float(f) for f in args.aca_factors.split(",")]
        rows = [r for g in args.geometries.split(",") for r in aca_study(args.aca_study, factors, geometry=g,
                                                                         eps=args.eps)]
        print_aca_table(rows)
        return
    if args.rank_study:
        rank_study(args.rank_study)
        return
    if args.case:
        print(json.dumps(run_case(args.case, args.n, args.eps, args.dense_limit, args.solve_limit,
                                  args.check_blocks, args.rtol)))
        return
    from _common import machine

    os.makedirs(OUT, exist_ok=True)
    sizes = [1000, 4000] if args.quick else [1000, 4000, 10000, 40000, 100000]
    if args.sizes:
        sizes = [int(s) for s in args.sizes.split(",")]
    print(f"Machine: {machine()}")
    scaling = [spawn(g, n, 1e-4) for g in args.geometries.split(",") for n in sizes]
    path = os.path.join(OUT, "hmatrix_scaling.json")
    if os.path.exists(path):  # keep the rows of geometries not re-run now
        with open(path) as f:
            scaling = [r for r in json.load(f) if r.get("geometry") not in args.geometries.split(",")] + scaling
    with open(path, "w") as f:
        json.dump(scaling, f, indent=1)
    sweep = []
    sweep_path = os.path.join(OUT, "hmatrix_eps.json")
    if args.skip_sweep and os.path.exists(sweep_path):
        with open(sweep_path) as f:
            sweep = json.load(f)
    if not args.skip_sweep:
        n_sweep = 4000 if args.quick else 10000
        eps_list = [1e-2, 1e-4, 1e-6] if args.quick else [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10]
        sweep = [spawn("planar", n_sweep, e, solve_limit=4000, check_blocks=True, rtol=1e-11) for e in eps_list]
        with open(os.path.join(OUT, "hmatrix_eps.json"), "w") as f:
            json.dump(sweep, f, indent=1)
    print("\n## Scaling (eps = 1e-4, eta = 3, leaf 32)\n")
    print(scaling_table(scaling))
    if sweep:
        print(f"\n## Speed against error (planar, N = {sweep[0].get('n')}, GMRES rtol 1e-11)\n")
        print(eps_table(sweep))
    print("\n## Growth exponents (log-log slope against N, N >= 4000)\n")
    for geometry, s in slopes(scaling).items():
        print(f"- {geometry}: build {s['build']:.2f}, memory {s['memory']:.2f}, matvec {s['matvec']:.2f}")
    plots(scaling, sweep)


if __name__ == "__main__":
    main()
