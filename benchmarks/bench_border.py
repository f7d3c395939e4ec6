"""The border of a grown planar crack: exact dense blocks against compressed ones.

    python benchmarks/bench_border.py                    # 13.5k + 600 and 62k + 1000 elements
    python benchmarks/bench_border.py --sizes 140:600     # n_side:ring pairs

A square grid of ``n_side`` x ``n_side`` unit elements is ordered from its centre out; a
disc of it is the base (a PlanarElasticityOperator's opening part, eps 1e-4) and the next
``ring`` elements its growth. Each row builds the grown operator with dense border blocks
and with compressed ones (hmatddm/elasticity/extended.py), and prints the CPU time of the
border's build, its memory, the CPU time of one product, and the compressed product's
error against the dense one (largest entry, relative), beside the base's build and product.
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

import hmatddm as hd  # noqa: E402
from hmatddm.elasticity import extended  # noqa: E402
from hmatddm.elasticity.planar import PlanarElasticityOperator  # noqa: E402


def cpu(function, repeat=1):
    start = time.process_time()
    for _ in range(repeat):
        result = function()
    return result, (time.process_time() - start) / repeat


def row(n_side, ring):
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    grid = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], float(n_side), float(n_side), n_side, n_side)
    mesh = grid.subset(np.argsort(np.linalg.norm(grid.centers, axis=1), kind="stable"))
    n0 = int(np.pi * (n_side / 2 - 3) ** 2) - ring
    planar, base_build = cpu(lambda: PlanarElasticityOperator(mesh.subset(np.arange(n0)), material))
    base = planar.part("normal")
    grown = mesh.subset(np.arange(n0 + ring))
    x = np.random.default_rng(0).normal(size=n0 + ring)
    _, base_product = cpu(lambda: base.matvec(x[:n0]), 5)
    out = {}
    saved = extended.COMPRESS_MIN_BASE
    try:
        for label, minimum in (("dense", 10**12), ("compressed", saved)):
            extended.COMPRESS_MIN_BASE = minimum
            operator, build = cpu(lambda: extended.ExtendedElasticityOperator(base, grown))
            operator @ x
            y, product = cpu(lambda: operator @ x, 5)
            out[label] = dict(build=build, bytes=operator.chunk_bytes, product=product, y=y)
    finally:
        extended.COMPRESS_MIN_BASE = saved
    error = np.abs(out["compressed"]["y"] - out["dense"]["y"]).max() / np.abs(out["dense"]["y"]).max()
    return [[f"{n0} + {ring}", label, f"{base_build:.1f}", f"{1e3 * base_product:.1f}", f"{value['build']:.2f}",
             f"{value['bytes'] / 1e6:.1f}", f"{1e3 * value['product']:.1f}",
             f"{error:.1e}" if label == "compressed" else "-"] for label, value in out.items()]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="140:600,290:1000", help="n_side:ring pairs")
    args = parser.parse_args()
    from _common import machine, print_table

    print(f"Machine: {machine()}", flush=True)
    body = []
    for pair in args.sizes.split(","):
        n_side, ring = (int(v) for v in pair.split(":"))
        body += row(n_side, ring)
    print_table(["elements (base + ring)", "border", "base build CPU (s)", "base product CPU (ms)",
                 "border build CPU (s)", "border MB", "product CPU (ms)", "error vs dense"], body)


if __name__ == "__main__":
    main()
