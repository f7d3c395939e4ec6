"""Geometries of the hard cases, shared by ``tests/test_hard_cases.py`` and
``benchmarks/bench_hard_cases.py`` so that the benchmark's table measures exactly the
meshes the tests check (see benchmarks/RESULTS.md, "Hard cases").

Plain mesh builders (no kernels, no solver): importing this module compiles nothing.
"""
import numpy as np

from .elements import Mesh2D, concatenate, line, rectangle


def graded_line(ratio, layout, coarse=0.1):
    """A crack on [-1, 1] (2D) of ``coarse`` elements with blocks refined ``ratio``
    times: at the centre (``layout="centre"``), at both tips ("tips") or every other
    coarse element ("alternating"). Neighbouring sizes differ by ``ratio``."""
    nodes, x = [-1.0], -1.0
    count = int(round(2.0 / coarse))
    for k in range(count):
        refine = {"centre": k == count // 2, "tips": k in (0, count - 1), "alternating": k % 2 == 1}[layout]
        nodes += list(np.linspace(x, x + coarse, ratio + 1)[1:]) if refine else [x + coarse]
        x += coarse
    nodes = np.array(nodes)
    nodes[-1] = 1.0
    zeros = np.zeros(len(nodes) - 1)
    return Mesh2D.from_segments(np.column_stack([nodes[:-1], zeros]), np.column_stack([nodes[1:], zeros]))


def mixed_scales(dim, seed=1, small=30):
    """One 100 m fracture (1 m elements in 2D, 2 m in 3D) and ``small`` 0.1 m fractures
    (10 elements / 4 x 4 elements) at 0.05 - 5 m from it, random strikes (seeded)."""
    rng = np.random.default_rng(seed)
    if dim == 2:
        parts = [line([-50, 0], [50, 0], 100)]
    else:
        parts = [rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 100.0, 10.0, 50, 5)]
    for k in range(small):
        offset = rng.choice([-1, 1]) * 10 ** rng.uniform(-1.3, 0.7)
        strike = rng.uniform(0, np.pi)
        tangent = np.array([np.cos(strike), np.sin(strike)])
        if dim == 2:
            centre = np.array([rng.uniform(-45, 45), offset])
            parts.append(line(centre - 0.05 * tangent, centre + 0.05 * tangent, 10, fracture_id=k + 1))
        else:
            centre = np.array([rng.uniform(-45, 45), offset, rng.uniform(-4, 4)])
            parts.append(rectangle(centre, [*tangent, 0], [0, 0, 1], 0.1, 0.1, 4, 4, fracture_id=k + 1))
    return concatenate(parts)
