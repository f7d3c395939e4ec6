"""Where the per-pair time of the issue-32 lattice goes (issue 32, targets): the 576 randomly
oriented 0.5 m squares 3 m apart (``bench_layered3d_kernel.issue32_mesh``) in a free surface
over two interfaces (``images=4``, the default table path). Prints the dense per-pair CPU
against uniform rock (one run, after a warm-up), the rules the kernel picks per pair
(counted with its own functions: table coverage, ``_image_order`` with the operator's
``entry_tol``, ``one_square_order``), the near triples kept per source, and the cost per
point of the near-triple quadrature (``_integrate``) and of the table's interpolation
(``remainder_rectangle_stress``) on three pairs.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_lattice_profile.py
"""
import sys
import time

import numpy as np
sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from numba import njit
from _common import machine  # noqa: E402
from bench_layered3d_kernel import issue32_mesh  # noqa: E402
from hmatddm.elasticity import operator as operators
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium
from hmatddm.layered.remainder_table3d import remainder_rectangle_stress
from hmatddm.layered.rectangle_quadrature import _image_order, _integrate, one_square_order, square_rule
from hmatddm.layered.image_tracer3d import _trace_range, _traced_buffer, trace_points
from hmatddm.layered.remainder_table3d import keep_near, keep_near_range, rectangle_covered
from hmatddm.layered.image_tracer import trace_capacity
from hmatddm.layered.potentials3d import Workspace
from hmatddm.layered.images2d import _lame
THREE = dict(interfaces=[0.0, -10.0, -20.0], shear_modulus=[0.0, 1.0, 2.0, 1.0], poisson_ratio=[0.25] * 4, images=4)
grid = issue32_mesh()
data = operators.influence_data(grid, LayeredMedium(**THREE))
uni = operators.influence_data(grid, __import__("hmatddm").Elastic(1.0, 0.25))
every = np.arange(576, dtype=np.int64)
out = np.empty((1728, 1728))
drivers.traction_block(data, every[:2], every[:2], np.empty((6, 6)))
drivers.traction_block(uni, every[:2], every[:2], np.empty((6, 6)))
c = time.process_time(); drivers.traction_block(uni, every, every, out); cu = time.process_time() - c
c = time.process_time(); drivers.traction_block(data, every, every, out); cl = time.process_time() - c
print(machine())
print(f"uniform {cu/576**2*1e6:.3f} us/pair, layered {cl/576**2*1e6:.2f} us/pair ({cl/cu:.0f}x)", flush=True)
# components: n-point remainder and n-point near-triple quadrature for the same source/receiver
@njit
def comp(data, i, j, n, R, which):
    xi, eta, wt = square_rule(n, 1)
    ls = data.layer[j]; lr = data.layer[i]
    g = data.shear_modulus; nu = data.poisson_ratio
    image = np.zeros((3, 3, 3))
    cap, no = trace_capacity(ls, g, data.n_images)
    traced = _traced_buffer(xi.shape[0], cap, no)
    _trace_range(data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], ls, data.interfaces, g, nu, data.n_images, xi, eta, 0, xi.shape[0], traced)
    keep_near_range(traced, 0, xi.shape[0], data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], xi, eta, ls, data.table.bottoms, data.table.tops)
    grad = np.empty((3, 3, 3, 3)); ws = Workspace(no); ws1 = Workspace(1); kel = np.zeros((2, 3, 3, 1))
    for r in range(R):
        if which == 0:
            remainder_rectangle_stress(data.table, data.centers[i], lr, data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], ls, g[ls], _lame(g[ls], nu[ls]), xi, eta, wt, image)
        else:
            _integrate(data.centers[i], lr, data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], ls, g, nu, xi, eta, wt, traced, 0, image, grad, ws, ws1, kel, -np.inf, np.inf)
    return traced[0][0]
# pick pairs: same layer 1 (i, j both at depth -3..-9), and layer 2
depth = grid.centers[:, 2]
for name, i, j in (("same layer 1", 0, 70), ("layer 2 -> 2", 300, 330), ("layer 1 -> 2", 250, 100)):
    for n in (2, 3):
        for which, label in ((0, "remainder"), (1, "near-triple quadrature")):
            comp(data, i, j, n, 1, which)
            R = 2000; c = time.process_time(); k = comp(data, i, j, n, R, which); c = time.process_time() - c
            print(f"{name} (z {depth[i]:.0f} <- {depth[j]:.0f}), {n}x{n} points: {label} {c/R*1e6:.2f} us ({c/R/n/n*1e6:.2f} us/point; near triples at a point {k})")

@njit
def stats(data, out):
    n = data.centers.shape[0]
    et = data.entry_tol * data.entry_scale
    for i in range(n):
        lr = data.layer[i]
        for j in range(n):
            ls = data.layer[j]
            point = data.centers[i]
            tab = data.table.pair_index[ls].max() >= 0 and rectangle_covered(data.table, point, lr, data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], ls)
            skip = ls - 1 if data.surface_form[j] and lr == ls else -1
            ng, ns = _image_order(point, lr, data.centers[j], data.frames[j], data.half_a[j], data.half_b[j], ls, data.interfaces, data.gauss_points, data.max_subdivisions, data.far_tol, et, skip)
            nr = 0
            if tab:
                r1 = point[0] - data.centers[j, 0]; r2 = point[1] - data.centers[j, 1]
                beside = max(0.0, np.sqrt(r1*r1 + r2*r2) - data.half_a[j] - data.half_b[j])
                cl = data.table.clearance[ls, lr]
                nr = one_square_order(np.sqrt(cl*cl + beside*beside), data.half_a[j], data.half_b[j], data.gauss_points, data.far_tol, et)
            quad = not (tab and abs(lr - ls) >= 2)
            out[i, j, 0] = lr; out[i, j, 1] = ls; out[i, j, 2] = tab; out[i, j, 3] = ng if quad else 0
            out[i, j, 4] = ns if quad else 0; out[i, j, 5] = nr
out = np.zeros((576, 576, 6), dtype=np.int64)
stats(data, out)
o = out.reshape(-1, 6)
print("pairs", len(o), "tabulated", o[:, 2].mean())
print("quad pairs", (o[:, 3] > 0).mean())
for ng in range(0, 5):
    sel = o[:, 3] == ng
    print("n_gauss", ng, "frac", sel.mean(), "nsub", np.bincount(o[sel, 4]) if sel.any() else "")
print("remainder order", np.bincount(o[:, 5]) / len(o))
print("quad points per pair (mean)", (o[:, 3]**2 * o[:, 4]**2).mean(), "remainder points per pair", (o[:, 5]**2).mean())
# near triples per (ls, lr)
interfaces = np.array(THREE["interfaces"]); g = np.array(THREE["shear_modulus"]); nu = np.array(THREE["poisson_ratio"])
bottoms = data.table.bottoms; tops = data.table.tops
for ls in (1, 2, 3):
    t = {1: -5.0, 2: -15.0, 3: -25.0}[ls]
    tr = trace_points(np.array([t]), ls, interfaces, g, nu, 4)
    n, layer, z, eps, sigma, coef, dcoef = tr
    n0 = n[0]
    k = keep_near(n0, layer[0], z[0], eps[0], sigma[0], coef[0], dcoef[0], t, ls, bottoms, tops)
    print("source layer", ls, "triples", n0, "near", k, "near per receiver layer", np.bincount(layer[0, :k], minlength=4), "all per layer", np.bincount(trace_points(np.array([t]), ls, interfaces, g, nu, 4)[1][0, :n0], minlength=4))

print(machine())
