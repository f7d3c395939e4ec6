"""Horizontal and vertical pressurised cracks in a three-layer medium (ref. Sec. 3.5.1,
Table 3.2, Figs 3.10-3.17): element order, Gauss points and number of images.

    python benchmarks/bench_layered_elements.py           # table + 8-panel plot (~1 min)

Scene (ref. Fig. 3.9): a middle layer of height h = 1 between interfaces at y = +-h/2,
G_2 = 1 in the middle, G_1 = G_3 = gamma G_2 above and below, nu = 0.2 everywhere; a
crack of length h centred at the origin, horizontal (along x) or vertical (along y, its
tips on the interfaces), under p = 1e-3 G_2, 10 elements. Settings as ref. Table 3.2:
constant / linear / quadratic elements, 1-3 Gauss points of the plain rule for the image
terms (no subdivision, as the reference), 1-8 images.

Each configuration is compared with a converged solution (quadratic elements, 40
elements, 4 Gauss points on up to 64 adaptive sub-segments, 12 images): the error is
the largest difference of the opening at the 10 element midpoints (the shape functions
interpolate the nodes; constant elements carry one value) over the converged largest
opening. Time: matrix build + solve of the configuration (wall and CPU of this process),
after a warm-up compile.
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _common import machine, markdown_table  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.analytical import griffith_opening  # noqa: E402
from hmatddm.layered import LayeredMedium  # noqa: E402
from hmatddm.layered.higher_order2d import dense_matrix  # noqa: E402
from hmatddm.elasticity.nodal import opening_at  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
HEIGHT = 1.0
PRESSURE = 1e-3
NU = 0.2
N_ELEMENTS = 10
NAMES = {0: "constant", 1: "linear", 2: "quadratic"}


def medium(gamma):
    """Three layers: gamma G_2 above and below the middle layer of G_2 = 1 (ref. Table 3.2)."""
    return LayeredMedium(interfaces=[0.5 * HEIGHT, -0.5 * HEIGHT], shear_modulus=[gamma, 1.0, gamma],
                         poisson_ratio=[NU, NU, NU])


def crack(orientation, order, n_elements=N_ELEMENTS):
    half = 0.5 * HEIGHT
    if orientation == "horizontal":
        return hd.mesh.line([-half, 0.0], [half, 0.0], n_elements, element_order=order)
    return hd.mesh.line([0.0, -half], [0.0, half], n_elements, element_order=order)


def solve(orientation, gamma, order, gauss, images, n_elements=N_ELEMENTS, max_subdivisions=1):
    """Openings at the midpoints of the 10 reference elements (and the nodal profile) of
    one configuration, with its build + solve wall and CPU time."""
    mesh = crack(orientation, order, n_elements)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    matrix = dense_matrix(mesh, medium(gamma), images, gauss, max_subdivisions)
    traction = -PRESSURE * np.repeat(mesh.normals, mesh.n_nodes, axis=0).reshape(-1)
    dd = np.linalg.solve(matrix, traction).reshape(mesh.n_elements, mesh.n_nodes, 2)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    # midpoints of the 10-element mesh: element e of n covers [e/n, (e+1)/n] along the crack
    s = (np.arange(N_ELEMENTS) + 0.5) / N_ELEMENTS * n_elements  # in element units of this mesh
    element = np.minimum(s.astype(int), n_elements - 1)
    xi = 2.0 * (s - element) - 1.0
    along = opening_at(mesh, dd, xi)  # (n, 10) every element at every xi
    midpoints = along[element, np.arange(N_ELEMENTS)]
    nodes = mesh.collocation_points @ (mesh.tangents[0])
    nodal = np.einsum("ekd,ed->ek", dd, mesh.normals).reshape(-1)
    return dict(midpoints=midpoints, profile=(nodes, nodal), wall=wall, cpu=cpu)


def converged(orientation, gamma):
    return solve(orientation, gamma, 2, 4, 12, n_elements=40, max_subdivisions=64)


def error(result, reference):
    return float(np.max(np.abs(result["midpoints"] - reference["midpoints"])) / np.max(reference["midpoints"]))


def study():
    """All rows of the table: {(orientation, gamma, order, gauss, images): result}, and
    the converged references."""
    references = {(o, g): converged(o, g) for o in ("horizontal", "vertical") for g in (2.0, 5.0)}
    rows = {}
    for orientation in ("horizontal", "vertical"):
        for gamma in (2.0, 5.0):
            ref = references[(orientation, gamma)]
            configs = {(order, 3, 3) for order in (0, 1, 2)}           # Figs 3.10-3.11
            configs |= {(2, gauss, 8) for gauss in (1, 2, 3)}          # Figs 3.12-3.13
            configs |= {(2, 3, images) for images in range(1, 9)}      # Figs 3.14-3.17
            for order, gauss, images in sorted(configs):
                result = solve(orientation, gamma, order, gauss, images)
                result["error"] = error(result, ref)
                rows[(orientation, gamma, order, gauss, images)] = result
    return rows, references


def conclusions(rows):
    """The reference's conclusions as numbers (max relative opening differences at the
    element midpoints, over the largest opening):

    * ``order_spread``: constant or linear against quadratic (3 Gauss points, 3 images);
    * ``gauss_spread``: 1 or 2 Gauss points against 3 (quadratic, 8 images);
    * ``image_spread``: 1 image against 8 (quadratic, 3 Gauss points);
    each per (orientation, gamma)."""
    def spread(a, b):
        return float(np.max(np.abs(a["midpoints"] - b["midpoints"])) / np.max(b["midpoints"]))

    out = {}
    for orientation in ("horizontal", "vertical"):
        for gamma in (2.0, 5.0):
            key = (orientation, gamma)
            best = rows[(orientation, gamma, 2, 3, 3)]
            out[key] = dict(
                order_spread=max(spread(rows[(orientation, gamma, o, 3, 3)], best) for o in (0, 1)),
                gauss_spread=max(spread(rows[(orientation, gamma, 2, g, 8)], rows[(orientation, gamma, 2, 3, 8)])
                                 for g in (1, 2)),
                image_spread=spread(rows[(orientation, gamma, 2, 3, 1)], rows[(orientation, gamma, 2, 3, 8)]))
    return out


def plot(rows, references, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 4, figsize=(18, 8), sharey=True)
    panels = [("horizontal", 2.0, "order", "3.10"), ("vertical", 2.0, "order", "3.11"),
              ("horizontal", 2.0, "gauss", "3.12"), ("vertical", 2.0, "gauss", "3.13"),
              ("horizontal", 2.0, "images", "3.14"), ("vertical", 2.0, "images", "3.15"),
              ("horizontal", 5.0, "images", "3.16"), ("vertical", 5.0, "images", "3.17")]
    for ax, (orientation, gamma, what, figure) in zip(axes.ravel(), panels):
        if what == "order":
            curves = [(f"{NAMES[o]}", rows[(orientation, gamma, o, 3, 3)]) for o in (0, 1, 2)]
            title = "element type, 3 Gauss points, 3 images"
        elif what == "gauss":
            curves = [(f"{g} Gauss points", rows[(orientation, gamma, 2, g, 8)]) for g in (1, 2, 3)]
            title = "quadratic, 8 images"
        else:
            curves = [(f"{n} image{'s' if n > 1 else ''}", rows[(orientation, gamma, 2, 3, n)]) for n in (1, 2, 3, 8)]
            title = "quadratic, 3 Gauss points"
        for label, result in curves:
            s, w = result["profile"]
            ax.plot(s / HEIGHT, w / HEIGHT, ".-", label=label)
        s, w = references[(orientation, gamma)]["profile"]
        ax.plot(s / HEIGHT, w / HEIGHT, "k-", lw=0.8, label="converged")
        x = np.linspace(-0.5, 0.5, 201)
        ax.plot(x, griffith_opening(x, 0.5, PRESSURE, hd.Elastic(1.0, NU)) / HEIGHT, "k:", lw=0.8,
                label="homogeneous (G_2)")
        ax.set_title(f"ref. Fig. {figure}: {orientation}, gamma = {gamma:g}\n{title}", fontsize=9)
        ax.set_xlabel("x_D" if orientation == "horizontal" else "z_D")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("w_D = w / h")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", default=os.path.join(HERE, "layered_elements.png"))
    args = parser.parse_args()
    for order in (0, 1, 2):  # warm-up: compile
        solve("vertical", 2.0, order, 2, 1, n_elements=2)
    from bench_element_order import calibration

    calib = calibration()
    rows, references = study()
    table = []
    for (orientation, gamma, order, gauss, images), r in rows.items():
        table.append([orientation, f"{gamma:g}", NAMES[order], gauss, images, f"{r['error']:.2e}",
                      f"{np.max(r['midpoints']) / HEIGHT:.4e}", f"{r['wall'] * 1e3:.1f}", f"{r['cpu'] * 1e3:.1f}"])
    print(f"Machine: {machine()}; calibration (LU of a 1500x1500 matrix, best of 3): {calib:.3f} s")
    print("Converged references (quadratic, 40 elements, adaptive image quadrature, 12 images): "
          + ", ".join(f"{o} gamma {g:g}: max w/h {np.max(r['midpoints']):.5e} ({r['wall']:.1f} s)"
                      for (o, g), r in references.items()))
    print(markdown_table(["crack", "gamma", "elements", "Gauss points", "images", "max opening error",
                          "max w/h", "wall ms", "CPU ms"], table))
    print()
    summary = conclusions(rows)
    print(markdown_table(["crack", "gamma", "element type spread", "Gauss point spread", "1 vs 8 images"],
                         [[o, f"{g:g}", f"{v['order_spread']:.2e}", f"{v['gauss_spread']:.2e}",
                           f"{v['image_spread']:.2e}"] for (o, g), v in summary.items()]))
    if args.plot:
        plot(rows, references, args.plot)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
