"""Near image triples in closed form beyond the half-space (issue 32, item 1, continued):
the free surface's reflection (okada3d) and every near triple of a vertical rectangle
(vertical3d); per-pair CPU of the dense traction matrix with and without them.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_layered_surface_form.py
    NUMBA_NUM_THREADS=1 python benchmarks/bench_layered_surface_form.py --shallow

Meshes: the issue's 576 randomly oriented 0.5 m squares on a 3 m lattice at 3-27 m depth
(random frames: no horizontal side, so no closed form anywhere), the same lattice with
vertical squares of random strike (:func:`vertical_lattice`) and with random strike and dip
(every square has a horizontal side; ``bench_halfspace_okada.strike_dip_mesh``). Media:
uniform rock, a half-space (``images=1``, every image in closed form,
:mod:`hmatddm.layered.okada3d`) and a free surface over
interfaces at z = -10, -20 m (G, 2G, G, ``images=4``, the remainder table) with the top
layer's surface reflection and the vertical squares' near triples in closed form (the
default), without the vertical closed form (``vertical_form`` off), and without either
(the path before). Whole 576 x 576 matrices, one thread, after a warm-up, in one
process; error of 6 rows against the quadrature of every triple with 8 Gauss points per
side on every (sub-)square (``method="quadrature"``). ``--shallow``: the same on fractures
next to the free surface and an interface (:func:`shallow_meshes`).
"""
import dataclasses
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, markdown_table  # noqa: E402
from bench_halfspace_okada import strike_dip_mesh  # noqa: E402
from bench_layered3d_kernel import _timed, issue32_mesh  # noqa: E402

import hmatddm as hd  # noqa: E402
from hmatddm.elasticity import operator as operators  # noqa: E402
from hmatddm.layered import LayeredMedium  # noqa: E402
from hmatddm.mesh import rectangle  # noqa: E402

G, NU = 1.0, 0.25
THREE = dict(interfaces=[0.0, -10.0, -20.0], shear_modulus=[0.0, G, 2 * G, G], poisson_ratio=[NU] * 4, images=4)


def vertical_lattice(seed=0):
    """The lattice of :func:`issue32_mesh` with vertical squares of random strike."""
    grid = issue32_mesh(seed=seed)
    rng = np.random.default_rng(seed)
    n = grid.n_elements
    strike = rng.uniform(0.0, 2.0 * np.pi, n)
    e1 = np.stack([np.cos(strike), np.sin(strike), np.zeros(n)], axis=1)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    return hd.Mesh3D.from_rectangles(grid.centers, e1, up, grid.half_a, grid.half_b)


def shallow_meshes():
    """Fractures next to the free surface and the interfaces, where the near triples are
    near: a vertical crack of 32 x 16 squares of 0.5 m whose top edge is 0.25 m under the
    surface, the same crack across the first interface (z from -14 to -6, element edges on
    z = -10), and a horizontal sill of 24 x 24 squares at 1 m depth (each over 400
    elements, so the table is built)."""
    crack = rectangle([0.0, 0.0, -0.25 - 4.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 16.0, 8.0, 32, 16)
    across = rectangle([0.0, 0.0, -10.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 16.0, 8.0, 32, 16)
    sill = rectangle([0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 12.0, 12.0, 24, 24)
    return (("vertical crack 0.25 m under the surface", crack), ("vertical crack across the interface at -10", across),
            ("horizontal sill at 1 m depth", sill))


def main():
    print(machine(), flush=True)
    table = []
    meshes = (("vertical squares, random strike", vertical_lattice()), ("strike and dip", strike_dip_mesh()),
              ("issue 32 (random frames)", issue32_mesh()))
    if "--shallow" in sys.argv:
        meshes = shallow_meshes()
    for mesh_name, grid in meshes:
        every = np.arange(grid.n_elements, dtype=np.int64)
        err_rows = every[::len(every) // 6][:6]
        base = None
        cases = [("uniform rock", "-", hd.Elastic(G, NU), None),
                 ("half-space, images=1", "closed form (okada3d)", LayeredMedium([0.0], [0.0, G], [NU, NU], images=1),
                  None),
                 ("surface + 2 interfaces, images=4", "table + surface + vertical in closed form (default)",
                  LayeredMedium(**THREE), None),
                 ("surface + 2 interfaces, images=4", "table + surface in closed form", LayeredMedium(**THREE),
                  "no vertical"),
                 ("surface + 2 interfaces, images=4", "table, quadrature of the near triples (before)",
                  LayeredMedium(**THREE), "off")]
        for name, path, medium, variant in cases:
            c0 = time.process_time()
            data = operators.influence_data(grid, medium)
            setup = time.process_time() - c0
            closed = "-"
            if isinstance(medium, LayeredMedium):
                none = np.zeros(grid.n_elements, dtype=bool)
                if variant in ("no vertical", "off"):
                    data = data._replace(vertical_form=none)
                if variant == "off":
                    data = data._replace(surface_form=none)
                closed = (f"{int(data.closed_form.sum())} / {int(data.surface_form.sum())} / "
                          f"{int(data.vertical_form.sum())}")
            _, cpu, wall = _timed(data, every, every)
            per = cpu / every.size ** 2 * 1e6
            base = base or per
            error = "-"
            if isinstance(medium, LayeredMedium):
                reference = operators.influence_data(
                    grid, dataclasses.replace(medium, method="quadrature", gauss_points=8))._replace(far_tol=0.0,
                                                                                                     entry_tol=0.0)
                want, *_ = _timed(reference, err_rows, every)
                got, *_ = _timed(data, err_rows, every)
                error = f"{np.abs(got - want).max() / np.abs(want).max():.1e}"
            table.append([mesh_name, name, path, closed, f"{setup:.1f}", f"{cpu:.2f}", f"{wall:.2f}", f"{per:.2f}",
                          f"{per / base:.0f}", error])
            print(table[-1], flush=True)
    print(markdown_table(["mesh", "medium", "path", "closed-form sources (half-space / surface / vertical)",
                          "setup CPU s (table)", "CPU s", "wall s", "CPU us / pair", "x uniform",
                          "max error / max entry (6 rows, vs 8-point quadrature)"], table))
    print(machine())


if __name__ == "__main__":
    main()
