"""Issue 32: the Gauss rule of the 3D image quadrature chosen by the error of an entry.

1. ``--bound``: the error of ``n x n`` Gauss points on one square's image stress
   (:func:`hmatddm.layered.rectangle_quadrature.image_rectangle_stress`, ``n`` = 1-6) against
   14 points on 2 x 2 sub-squares, for randomly oriented rectangles (half sides 0.25 m and
   0.125-0.25 m) at 4 to ~100 half sides from their nearest singular point (the receiver's
   mirror in the interface, or the rectangle itself for a receiver across it), in a
   half-space, 2:1, 1:5 and 5:1 bi-materials and three layers under a free surface (G, 2G, G
   and G, 5G, G; four images). Prints, per ``n``, the largest ``K`` of ``error <= K
   ratio^(-2n) G_max 4 a b / d^3`` (``ratio = d / max(a, b)``) over the samples whose error is
   above round-off, against :data:`ENTRY_BOUND`, and the same error in units of the rule the
   quadrature used up to the eleventh session (``IMAGE_BOUND 40 n ratio^(-2n)``).
2. ``--near``: every entry of 0.5 m squares (random orientations) centred 0.4-0.6 m from an
   interface or a free surface, three columns, against the many-point quadrature (8 points
   per side on every (sub-)square, ``far_tol = entry_tol = 0``), with the medium's default
   settings: error relative to the largest entry (issue 32 asks 1e-8) and the CPU of the
   whole matrix (compiled first). Run it in another tree with ``PYTHONPATH=<tree> python -P``
   to compare.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_layered3d_entry_rule.py [--bound] [--near]
[--samples 150] [--seeds 1,2,3]``."""
import argparse
import time

import numpy as np

import hmatddm as hd
from hmatddm.kernels import drivers
from hmatddm.layered import LayeredMedium
from hmatddm.layered.influence3d import influence_data
from hmatddm.layered.rectangle_quadrature import image_rectangle_stress, nearest_singularity

try:
    from _common import machine, markdown_table
except ImportError:  # run from the repository root
    from benchmarks._common import machine, markdown_table

BOUND_MEDIA = {"half-space": ([0.0], [0.0, 1.0]), "bi-material 2:1": ([0.0], [2.0, 1.0]),
               "bi-material 1:5": ([0.0], [1.0, 5.0]), "bi-material 5:1": ([0.0], [5.0, 1.0]),
               "three layers G, 2G, G": ([0.0, -10.0, -20.0], [0.0, 1.0, 2.0, 1.0]),
               "three layers G, 5G, G": ([0.0, -10.0, -20.0], [0.0, 1.0, 5.0, 1.0])}
ORDERS = 6


def _sample(rng, interfaces, shear_modulus):
    """One rectangle and receiver: ``(y, receiver layer, centre, frame, a, b, source layer,
    n_images)``, or None if the receiver is within 4 half sides of a singular point (the
    quadrature subdivides there)."""
    frame = np.linalg.qr(rng.normal(size=(3, 3)))[0].T.copy()
    a = 0.25
    b = a * rng.uniform(0.5, 1.0)
    offset = rng.normal(size=2) * rng.uniform(0.0, 4.0)
    if len(interfaces) == 3:  # a source in the middle layer, receivers in all three
        center = np.array([0.0, 0.0, -rng.uniform(10.3, 19.7)])
        y = np.array([offset[0], offset[1], -rng.uniform(5.0, 25.0)])
        receiver_layer = 1 if y[2] > -10.0 else (2 if y[2] > -20.0 else 3)
        source_layer, n_images = 2, 4
    else:
        center = np.array([0.0, 0.0, -rng.uniform(0.3, 6.0)])
        across = shear_modulus[0] > 0.0 and rng.random() < 0.3
        y = np.array([offset[0], offset[1], rng.uniform(0.05, 6.0) * (1.0 if across else -1.0)])
        receiver_layer, source_layer, n_images = (0 if across else 1), 1, 1
    dmin = nearest_singularity(y, receiver_layer, center, frame, a, b, source_layer, np.asarray(interfaces, float))
    if dmin < 4.0 * max(a, b):
        return None
    return y, receiver_layer, center, frame, a, b, source_layer, n_images, dmin


def bound(seeds, samples):
    """Rows ``(medium, n, samples, K measured, K in units of the old rule)``."""
    rows = []
    for name, (interfaces, shear_modulus) in BOUND_MEDIA.items():
        itf = np.asarray(interfaces, float)
        g = np.asarray(shear_modulus, float)
        nu = np.full(g.shape[0], 0.25)
        found = [[] for _ in range(ORDERS)]
        for seed in seeds:
            rng = np.random.default_rng(seed)
            for _ in range(samples):
                drawn = _sample(rng, interfaces, shear_modulus)
                if drawn is None:
                    continue
                y, lr, center, frame, a, b, ls, n_images, dmin = drawn
                reference = np.empty((3, 3, 3))
                out = np.empty((3, 3, 3))
                image_rectangle_stress(y, lr, center, frame, a, b, ls, itf, g, nu, n_images, 14, 2, reference, False,
                                       np.zeros(g.shape[0]), np.zeros(g.shape[0]))
                size = g.max() * 4.0 * a * b / dmin ** 3
                ratio = dmin / max(a, b)
                for n in range(1, ORDERS + 1):
                    image_rectangle_stress(y, lr, center, frame, a, b, ls, itf, g, nu, n_images, n, 1, out, False,
                                           np.zeros(g.shape[0]), np.zeros(g.shape[0]))
                    error = np.abs(out - reference).max()
                    if error > 1e-14 * np.abs(reference).max():  # above round-off
                        found[n - 1].append((error / (size * ratio ** (-2.0 * n)), ratio))
        for n in range(1, ORDERS + 1):
            k = np.array(found[n - 1]) if found[n - 1] else np.zeros((1, 2))
            worst = k[np.argmax(k[:, 0])]
            rows.append([name, n, len(found[n - 1]), worst[0], worst[1], worst[0] / (10.0 * 40.0 * n)])
    return rows


NEAR_CASES = {
    "half-space": (LayeredMedium([0.0], [0.0, 1.0], [0.25, 0.25], images=1), [-0.45, -0.8, -1.6, -2.9]),
    "bi-material 5:1": (LayeredMedium([0.0], [5.0, 1.0], [0.25, 0.25], images=1), [0.4, 0.6, -0.4, -0.6, -0.8, -1.6]),
    "three layers, 1 image": (LayeredMedium([0.0, -1.5, -3.0], [0.0, 1.0, 2.0, 1.0], [0.25, 0.3, 0.2, 0.25], images=1),
                              [-0.5, -1.0, -2.0, -2.5, -3.5, -4.5]),
    "three layers, 4 images": (LayeredMedium([0.0, -2.0, -4.0], [0.0, 1.0, 2.0, 1.0], [0.25] * 4, images=4),
                               [-0.45, -1.6, -2.4, -3.6, -4.4, -5.0]),
}
COLUMNS = [(0.0, 0.0), (1.3, 0.4), (0.6, -0.9)]


def _matrix(data):
    every = np.arange(data.centers.shape[0], dtype=np.int64)
    out = np.empty((3 * every.size, 3 * every.size))
    drivers.traction_block(data, every[:2], every[:2], np.empty((6, 6)))
    c0, t0 = time.process_time(), time.perf_counter()
    drivers.traction_block(data, every, every, out)
    return out, time.process_time() - c0, time.perf_counter() - t0


def near(seeds):
    """Rows ``(medium, seed, elements, error / largest, CPU s, wall s)``."""
    rows = []
    for name, (medium, depths) in NEAR_CASES.items():
        for seed in seeds:
            rng = np.random.default_rng(seed)
            centers = np.array([[x, y, z] for z in depths for x, y in COLUMNS], float)
            frames = np.linalg.qr(rng.normal(size=(len(centers), 3, 3)))[0]
            half = np.full(len(centers), 0.25)
            mesh = hd.Mesh3D.from_rectangles(centers, frames[:, :, 0], frames[:, :, 1], half, half)
            data = influence_data(mesh, medium, 0.0, 0.0, 0.0, medium.images)
            got, cpu, wall = _matrix(data)
            want, *_ = _matrix(data._replace(gauss_points=8, far_tol=0.0, entry_tol=0.0))
            rows.append([name, seed, len(centers), f"{np.abs(got - want).max() / np.abs(want).max():.1e}",
                         f"{cpu:.2f}", f"{wall:.2f}"])
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bound", action="store_true")
    parser.add_argument("--near", action="store_true")
    parser.add_argument("--samples", type=int, default=150, help="rectangles a medium and seed (--bound)")
    parser.add_argument("--seeds", default="1,2,3")
    args = parser.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    print(machine())
    if args.bound or not args.near:
        rows = bound(seeds, args.samples)
        print(markdown_table(["medium", "n", "samples above round-off", "largest K measured", "at ratio",
                              "in units of the old rule (10 x 40 n)"],
                             [[m, n, s, f"{k:.3g}", f"{r:.1f}", f"{o:.2g}"] for m, n, s, k, r, o in rows]))
        worst = {}
        for _, n, _, k, _, _ in rows:
            worst[n] = max(worst.get(n, 0.0), k)
        from hmatddm.layered.rectangle_quadrature import ENTRY_BOUND
        print(markdown_table(["n", "largest K, every medium", "ENTRY_BOUND", "margin"],
                             [[n, f"{k:.3g}", ENTRY_BOUND[min(n, len(ENTRY_BOUND)) - 1],
                               f"{ENTRY_BOUND[min(n, len(ENTRY_BOUND)) - 1] / max(k, 1e-300):.1f}"]
                              for n, k in sorted(worst.items())]))
    if args.near:
        print(markdown_table(["medium", "seed", "elements", "max error / max entry", "CPU s", "wall s"], near(seeds)))
    print(machine())


if __name__ == "__main__":
    main()
