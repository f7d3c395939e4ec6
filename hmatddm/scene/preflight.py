"""Checks of a validated scene that run before anything heavy is imported or built.

:func:`check_scene` is what ``hmatddm run`` (and ``--check``) does between reading the
scene and starting the engine, so that every refusal comes within a second:

1. :func:`estimate` -- elements, unknowns, memory (dense and H-matrix) and a rough time,
   from the scene's numbers alone (no mesh is built: a 100 m fracture of 0.1 mm
   elements is refused, not allocated). :func:`refuse_too_large` refuses a scene whose
   elements exceed ``numerics.max_elements`` or whose operator would not fit in the
   memory this machine has available.
2. The geometry: the initial meshes (each fracture meshable, no two sharing a
   collocation point), the clusters on the fractures, the natural network, and no
   collocation point on (or within :data:`NEAR_SINGULAR_FRACTION` half sizes of) another
   element's edge when ``numerics.singular_correction = "none"`` -- the check the
   elasticity operator would otherwise make only once it is built (minutes later).

Only numpy is used here (neighbours by :func:`hmatddm.mesh.neighbours.pairs_within`); scipy,
numba, the H-matrix engine, pyvista and matplotlib are not imported.
"""
import math
import os
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from ..options import NEAR_SINGULAR_FRACTION
from .schema import has_natural_fractures, show


# Rough cost model, fitted to benchmarks/RESULTS.md ("H-matrix vs dense": planar and cloud
# geometries, N = 1k-100k, eps 1e-4, 2 cores): H-matrix bytes ~ 80 * 8 d^2 N log2 N (an
# upper bound there by 1.3-3x), build ~ 1e-4 (d/3)^2 N log2 N s, matvec ~ 4e-7 (d/3)^2 N
# log2 N s; dense: 8 (N d)^2 bytes (twice that with its LU), assembly at 7e6 pairs/s.
_H_BYTES = 80.0
_H_BUILD_SECONDS = 1e-4
_H_MATVEC_SECONDS = 4e-7
_DENSE_PAIRS_PER_SECOND = 7e6
_FLOPS = 1e10
_BASE_BYTES = 250e6  # the interpreter, numpy, scipy, numba and the engine
_MATVECS_PER_STEP = 60  # nonlinear x linear iterations of a typical step (RESULTS: 20-200)
_STEP_SECONDS = 0.2     # flow, growth and bookkeeping of a step on a small mesh (default scene: ~0.7 s/step)


@dataclass(frozen=True)
class Estimate:
    """What a scene will need, roughly (see :func:`estimate`)."""

    elements: int            # initial hydraulic elements: the operator at the start (growth adds more)
    natural_elements: int    # natural-fracture elements (stress targets; they join the operator when reached)
    unknowns: int            # DD components and pressures at the start, (d + 1) elements
    dense_bytes: float       # the dense operator at the start, with its LU
    hmatrix_bytes: float     # the H-matrix operator at the start
    backend: str
    memory_bytes: float      # of the scene's backend at the start, plus the process itself
    available_bytes: float   # what this machine has available now (None if unknown)
    build_seconds: float     # one operator build at the start, the scene's backend
    step_seconds: float      # one time step at that size
    joined_bytes: float      # the scene's operator if every natural element joined it (0 without)
    steps: int
    largest: str             # the scene key of the fracture with the most elements

    @property
    def total_elements(self):
        return self.elements + self.natural_elements

    def lines(self):
        """The estimate as text, one line per quantity."""
        available = ("unknown" if self.available_bytes is None else _bytes(self.available_bytes))
        return [
            f"elements: {_count_text(self.elements)} initial + {_count_text(self.natural_elements)} natural = "
            f"{_count_text(self.total_elements)}"
            f" (largest: {self.largest}); unknowns: {_count_text(self.unknowns)}",
            f"memory at the start: dense {_bytes(self.dense_bytes)} (with its LU), H-matrix "
            f"{_bytes(self.hmatrix_bytes)}; this run ({self.backend}): ~{_bytes(self.memory_bytes)} of {available} "
            "available" + (f"; ~{_bytes(self.joined_bytes)} if every natural element joined the operator"
                           if self.natural_elements else ""),
            f"time (rough, 2-core machine): operator build ~{_seconds(self.build_seconds)}, "
            f"~{_seconds(self.step_seconds)} per step, {self.steps} steps ~{_seconds(self.steps * self.step_seconds)}"
            " before growth (growing fractures take longer; a first run also compiles for ~10-60 s)",
        ]

    def to_dict(self):
        return {**asdict(self), "total_elements": self.total_elements}


def _bytes(value):
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if value >= size:
            return f"{value / size:.3g} {unit}"
    return f"{value / 1e3:.3g} kB"


def _seconds(value):
    if value < 60:
        return f"{value:.2g} s"
    if value < 3600:
        return f"{value / 60:.2g} min"
    if value < 86400 * 2:
        return f"{value / 3600:.2g} h"
    return f"{value / 86400:.2g} days"


def available_memory():
    """Bytes of memory available to a new allocation (Linux MemAvailable), or None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


_COUNT_CAP = 1e30  # counts beyond this are only "too many" (and keep the arithmetic finite)


def _capped(count):
    return int(min(float(count), _COUNT_CAP))


def _count_text(count):
    return f"{count:,}" if count < 1e15 else f"{float(count):.3g}"


def _fracture_elements(fracture):
    """Elements of one initial fracture, from its numbers (as the mesh would have them)."""
    size = fracture["element_size"]
    if fracture["shape"] == "rectangle":
        return _capped(min(round(fracture["length"] / size), _COUNT_CAP)
                       * min(round(fracture["height"] / size), _COUNT_CAP))
    if fracture["shape"] == "penny":
        return _capped(max(1.0, math.pi * min(fracture["radius"] / size, _COUNT_CAP) ** 2))
    length = math.dist(fracture["p0"], fracture["p1"])
    return _capped(max(1, round(length / size)))


def _mean_power_law_length(a, l_min, l_max):
    """Mean of the truncated power law ``f(l) ~ l^-a`` on [l_min, l_max] (ref. Eq. 6.4)."""
    if l_max <= l_min:
        return l_min

    ratio = l_max / l_min

    def integral(power):  # of (l / l_min)^power d(l / l_min) over [1, ratio]: finite for any exponent
        if abs(power + 1.0) < 1e-12:
            return math.log(ratio)
        return math.expm1(min((power + 1.0) * math.log(ratio), 700.0)) / (power + 1.0)

    return l_min * integral(1.0 - a) / integral(-a)


def _natural_elements(scene):
    if not has_natural_fractures(scene):
        return 0
    network = scene.get("network", {})
    size = network.get("element_size", 1.0)
    rows = max(1, round(network.get("height", 1.0) / size)) if scene["dimension"] == 3 else 1
    count = sum(max(1, round(math.dist(f["p0"], f["p1"]) / size)) for f in scene.get("natural_fracture", []))
    if "density" in network:
        x_min, x_max, y_min, y_max = network["region"]
        fractures = min(network["density"] * (x_max - x_min) * (y_max - y_min), _COUNT_CAP)
        mean = _mean_power_law_length(network["length_exponent"], network["l_min"], network["l_max"])
        count += round(fractures) * max(1, round(min(mean / size, _COUNT_CAP)))
    return _capped(count * rows)


def _operator_bytes(n, dim):
    """``(dense with its LU, H-matrix)`` bytes of the operator of ``n`` elements."""
    dense = 2.0 * 8.0 * float(n * dim) ** 2
    return dense, min(dense / 2.0, _H_BYTES * 8.0 * dim * dim * n * math.log2(max(n, 2)))


#: Steps a front-following run (numerics.time_step = "auto") is estimated to take once
#: its steps have grown from the first one: a radial fracture grown from a few elements to
#: ~30 element rows of radius takes about that many.
_AUTO_STEPS = 30


def estimate(scene):
    """An :class:`Estimate` of a validated scene, from its numbers (nothing is built)."""
    dim = scene["dimension"]
    counts = [_fracture_elements(f) for f in scene["initial_fracture"]]
    largest = int(np.argmax(counts))
    elements, natural = _capped(sum(counts)), _capped(_natural_elements(scene))
    n = max(1, elements)
    unknowns = (dim + 1) * n
    numerics = scene["numerics"]
    backend = numerics["backend"]
    dense, hmatrix = _operator_bytes(n, dim)
    joined = 0.0
    if natural:
        joined = _BASE_BYTES + 1.15 * _operator_bytes(_capped(n + natural), dim)[0 if backend == "dense" else 1]
    log_n = math.log2(max(n, 2))
    scale = (dim / 3.0) ** 2
    if backend == "dense":
        memory = dense
        build = float(n) ** 2 / _DENSE_PAIRS_PER_SECOND + float(n * dim) ** 3 / 3.0 / _FLOPS
        matvec = 2.0 * float(n * dim) ** 2 / _FLOPS
    else:
        memory = hmatrix
        build = _H_BUILD_SECONDS * scale * n * log_n
        matvec = _H_MATVEC_SECONDS * scale * n * log_n
    if numerics["time_step"] == "auto":  # a rough count: the steps' ramp up, then AUTO_STEPS
        ramp = math.log2(max(2.0, numerics["end_time"] / numerics["first_time_step"]))
        steps = math.ceil(ramp + _AUTO_STEPS / numerics["step_advance"])
    else:
        steps = max(1, math.ceil(numerics["end_time"] / numerics["time_step"] - 1e-9))
    return Estimate(elements=elements, natural_elements=natural, unknowns=unknowns, dense_bytes=dense,
                    hmatrix_bytes=hmatrix, backend=backend, memory_bytes=_BASE_BYTES + 1.15 * memory,
                    available_bytes=available_memory(), build_seconds=build,
                    step_seconds=_STEP_SECONDS + _MATVECS_PER_STEP * matvec, steps=steps, joined_bytes=joined,
                    largest=f"initial_fracture[{largest}] ({_count_text(counts[largest])} elements)")


def refuse_too_many_elements(scene, size):
    """InputError when the scene's elements (its :class:`Estimate` ``size``) exceed
    ``numerics.max_elements``, before anything is allocated; returns the advice on which
    element sizes to raise."""
    cap = scene["numerics"]["max_elements"]
    fix = (f"use a larger element_size ({size.largest.split(' ')[0]}.element_size"
           f"{', network.element_size' if size.natural_elements else ''})")
    if size.total_elements > cap:
        raise InputError(
            f"the scene needs about {_count_text(size.total_elements)} elements ({size.largest}"
            f"{f', {_count_text(size.natural_elements)} natural' if size.natural_elements else ''}), more than "
            f"numerics.max_elements = {cap:,}; ~{_bytes(size.memory_bytes)} with the {size.backend} backend. "
            f"To run it, {fix}, or raise numerics.max_elements if the memory allows")
    return fix


def refuse_too_large(scene, size):
    """InputError when the scene's elements exceed ``numerics.max_elements`` or its
    operator's memory estimate exceeds the memory available; the message names the
    estimate and the settings that change it."""
    fix = refuse_too_many_elements(scene, size)
    if size.available_bytes is not None and size.memory_bytes > size.available_bytes:
        other = "hmatrix" if size.backend == "dense" else "dense"
        other_bytes = size.hmatrix_bytes if other == "hmatrix" else size.dense_bytes
        raise InputError(
            f"the scene needs about {_count_text(size.total_elements)} elements ({size.largest}) and ~"
            f"{_bytes(size.memory_bytes)} of memory with numerics.backend = {size.backend!r}, more than the "
            f"{_bytes(size.available_bytes)} available on this machine; {fix}"
            + (f", or numerics.backend = {other!r} (~{_bytes(_BASE_BYTES + 1.15 * other_bytes)})"
               if _BASE_BYTES + 1.15 * other_bytes < size.available_bytes else ""))


# ---------------------------------------------------------------------------------
# Collocation points on element edges (the operator's singular pairs, in numpy)
# ---------------------------------------------------------------------------------

def _half_sizes(mesh):
    """(N,) the half size of the near-singular test: half length (2D), min(half_a, half_b) (3D)."""
    return mesh.half_length if mesh.dim == 2 else np.minimum(mesh.half_a, mesh.half_b)


def near_edge_pairs(mesh, near_fraction=NEAR_SINGULAR_FRACTION):
    """(receivers, sources, gaps): every pair of distinct elements where the receiver's
    collocation point lies on an edge (2D: an end point) of the source, or closer to one
    than ``near_fraction * min(size_i, size_j)`` (sizes as :func:`_half_sizes`), sorted.

    The same set the operator refuses with ``singular_correction="none"`` (the kernels
    return NaN there), computed geometrically: the point in the source's frame, then its
    distance to the nearest point of the source's boundary.
    """
    from ..mesh.neighbours import pairs_within

    sizes = _half_sizes(mesh)
    reach = mesh.radii * (1.0 + 1e-9) + near_fraction * sizes
    sources, receivers = pairs_within(mesh.centers, reach)
    local = np.einsum("kab,kb->ka", mesh.frames[sources], mesh.centers[receivers] - mesh.centers[sources])
    near = near_fraction * np.minimum(sizes[receivers], sizes[sources])
    if mesh.dim == 2:
        a = mesh.half_length[sources]
        x, y = np.abs(local[:, 0]), local[:, 1]
        tol = 1e-12 * a
        exact = (np.abs(y) <= tol) & (np.abs(x - a) <= tol)
        gap = np.hypot(x - a, y)
    else:
        a, b = mesh.half_a[sources], mesh.half_b[sources]
        x1, x2, x3 = np.abs(local[:, 0]), np.abs(local[:, 1]), local[:, 2]
        tol = 1e-12 * (a + b)
        exact = (np.abs(x3) <= tol) & (((np.abs(x1 - a) <= tol) & (x2 <= b + tol))
                                       | ((np.abs(x2 - b) <= tol) & (x1 <= a + tol)))
        to_a = (x1 - a) ** 2 + np.maximum(x2 - b, 0.0) ** 2 + x3 ** 2
        to_b = (x2 - b) ** 2 + np.maximum(x1 - a, 0.0) ** 2 + x3 ** 2
        gap = np.sqrt(np.minimum(to_a, to_b))
    bad = exact | (gap <= near)
    order = np.lexsort((sources[bad], receivers[bad]))
    return receivers[bad][order], sources[bad][order], gap[bad][order]


def _check_collocation(scene, mesh, natural):
    """Refuse collocation points on or near another element's edge (numerics.singular_correction = "none")."""
    if scene["numerics"]["singular_correction"] != "none":
        return
    from .. import mesh as meshes

    n_initial = mesh.n_elements
    combined = mesh if natural is None else meshes.concatenate([mesh, natural])
    receivers, sources, gaps = near_edge_pairs(combined)
    if not len(receivers):
        return

    def where(element):
        if element < n_initial:
            return f"element {element} of initial_fracture[{int(mesh.fracture_id[element])}]"
        return f"element {element - n_initial} of the natural fractures"

    i, j, gap = int(receivers[0]), int(sources[0]), float(gaps[0])
    size = float(min(_half_sizes(combined)[i], _half_sizes(combined)[j]))
    place = "on an edge" if gap <= 1e-9 * size else f"{gap:.3g} m ({gap / size:.2g} half sizes) from an edge"
    raise InputError(
        f"{len(receivers)} collocation point(s) lie on or near another element's edge: the centre of {where(i)} "
        f"(at {show(combined.centers[i].tolist())}) is {place} of {where(j)}; the DDM kernel is singular there "
        f"(within {NEAR_SINGULAR_FRACTION} half sizes of an edge it pins the solution). Set "
        "numerics.singular_correction = \"average\" (with numerics.alpha = 1.0, ref. Sec. 6.2.3), which treats "
        "such points as touching the edge, or move the fractures apart")


def check_scene(scene):
    """Everything that can refuse a validated scene before the engine starts; returns its
    :class:`Estimate`. Raises InputError (one line, naming the key) on the first problem."""
    size = estimate(scene)
    refuse_too_large(scene, size)
    from .meshes import check_clusters, initial_mesh, natural_mesh  # meshes: numpy and scipy.spatial

    mesh = initial_mesh(scene)       # each fracture meshable, no two sharing a collocation point
    check_clusters(scene, mesh)     # every cluster on an initial fracture
    natural = natural_mesh(scene)    # the network generates and meshes
    _check_collocation(scene, mesh, natural)
    return size
