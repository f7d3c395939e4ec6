"""The H-matrix against the dense operator on one planar crack: build time, memory,
matvec time and accuracy, and the solution of a pressurised crack with both.

A 3D square crack of 64 x 64 unit elements (4096 elements, 12288 unknowns) in the x-y
plane. The matvec error is measured on a smooth field (an elliptical opening), where
the hypersingular operator cancels its near field and the far-field approximation
shows (docs/conventions.md §7). ``hmatddm bench`` prints the same table at several sizes.

Run: ``python examples/hmatrix_vs_dense.py`` (about 25 s; the dense matrix takes 1.2 GB).
"""
import time

import numpy as np

import hmatddm as hd

SIDE = 64  # elements along each side
EPS = 1e-4


def smooth_opening(mesh):
    half = 0.5 * SIDE
    x, y = mesh.centers[:, 0] / half, mesh.centers[:, 1] / half
    return np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, None))[:, None] * mesh.normals


def timed(function, *args, **kwargs):
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - start


def main():
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], SIDE, SIDE, SIDE, SIDE)
    warm = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4, 4, 4, 4)  # compile the kernels first
    for backend in ("dense", "hmatrix"):
        hd.ElasticityOperator(warm, material, backend=backend).matvec(np.ones(48))

    dense, dense_build = timed(hd.ElasticityOperator, mesh, material, backend="dense")
    hmat, hmat_build = timed(hd.ElasticityOperator, mesh, material, backend="hmatrix", eps=EPS)
    x = smooth_opening(mesh).ravel()
    y_dense, dense_matvec = timed(dense.matvec, x)
    y_hmat, hmat_matvec = timed(hmat.matvec, x)
    matvec_error = np.linalg.norm(y_hmat - y_dense) / np.linalg.norm(y_dense)

    traction = -1e6 * mesh.normals  # 1 MPa net pressure
    dd_dense, dense_solve = timed(hd.solve, dense, traction)
    (dd_hmat, info), hmat_solve = timed(hd.solve, hmat, traction, rtol=1e-8, return_info=True)
    w_dense, w_hmat = hd.opening(mesh, dd_dense), hd.opening(mesh, dd_hmat)
    solve_error = np.max(np.abs(w_hmat - w_dense)) / np.max(np.abs(w_dense))

    print(f"{mesh.n_elements} elements ({3 * mesh.n_elements} unknowns), eps = {EPS:g}")
    print(f"{'':>10}  {'build (s)':>9}  {'memory (MB)':>11}  {'matvec (ms)':>11}  {'solve (s)':>9}")
    print(f"{'dense':>10}  {dense_build:9.2f}  {dense.stats['memory_bytes'] / 2**20:11.1f}  "
          f"{1e3 * dense_matvec:11.2f}  {dense_solve:9.2f}  (LU)")
    print(f"{'hmatrix':>10}  {hmat_build:9.2f}  {hmat.stats['memory_bytes'] / 2**20:11.1f}  "
          f"{1e3 * hmat_matvec:11.2f}  {hmat_solve:9.2f}  ({info['iterations']} GMRES iterations)")
    print(f"compression {hmat.stats['compression']:.1f}x, largest rank {hmat.stats['max_rank']}")
    print(f"matvec error on a smooth opening: {matvec_error:.2e}; max opening difference of the solutions: "
          f"{solve_error:.2e}")


if __name__ == "__main__":
    main()
