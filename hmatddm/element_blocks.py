"""Products with block-diagonal operators of one ``d x d`` block per element, compiled.

The coupled solvers apply such operators to every vector of a GMRES iteration: contact
and prescribed-opening rows ``S v + D u`` (:class:`hmatddm.coupled.contact.ContactRows`),
the scaling by the element diagonal blocks of the coupled system
(:mod:`hmatddm.coupled.scaled_system`), the projection of a planar crack's vectors on
each element's normal and in-plane axes (:mod:`hmatddm.elasticity.planar`). As
``np.einsum("eij,ej->ei", ...)`` each took ~200-350 us at 8.7k elements, 29 of 300 s of a
0.25 m radial-k run (issue 33); one compiled pass over the elements takes a tenth of it.
"""
import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _apply(blocks, x, out):
    n, d = blocks.shape[0], blocks.shape[1]
    for e in range(n):
        for i in range(d):
            total = 0.0
            for j in range(d):
                total += blocks[e, i, j] * x[e * d + j]
            out[e * d + i] = total


def apply_blocks(blocks, x):
    """``blocks[e] @ x[e]`` for every element ``e``: ``blocks`` (N, d, d), ``x`` (N d,) or
    (N, d); returns the flat (N d,) product."""
    blocks = np.ascontiguousarray(blocks, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1)
    if x.size != blocks.shape[0] * blocks.shape[1]:
        raise ValueError(f"x has {x.size} entries, the blocks take {blocks.shape[0] * blocks.shape[1]}")
    out = np.empty(x.size)
    _apply(blocks, x, out)
    return out


@njit(cache=True, nogil=True)
def _split(vectors, normals, axes, opening, shear):
    """Opening and shear parts; returns the largest |shear| and the largest |vector entry|."""
    largest_shear, largest = 0.0, 0.0
    for e in range(vectors.shape[0]):
        v0, v1, v2 = vectors[e, 0], vectors[e, 1], vectors[e, 2]
        largest = max(largest, abs(v0), abs(v1), abs(v2))
        opening[e] = v0 * normals[e, 0] + v1 * normals[e, 1] + v2 * normals[e, 2]
        for a in range(2):
            value = axes[e, a, 0] * v0 + axes[e, a, 1] * v1 + axes[e, a, 2] * v2
            shear[2 * e + a] = value
            largest_shear = max(largest_shear, abs(value))
    return largest_shear, largest


def split_frame(x, normals, axes):
    """(opening (N,), shear (2N,), largest |shear|, largest |x entry|) of a flat vector of
    3-component element vectors ``x`` in the elements' frames (``normals`` (N, 3), in-plane
    ``axes`` (N, 2, 3))."""
    vectors = np.ascontiguousarray(x, dtype=np.float64).reshape(-1, 3)
    opening = np.empty(vectors.shape[0])
    shear = np.empty(2 * vectors.shape[0])
    largest_shear, largest = _split(vectors, np.ascontiguousarray(normals), np.ascontiguousarray(axes), opening, shear)
    return opening, shear, largest_shear, largest


@njit(cache=True, nogil=True)
def _join(opening, shear, normals, axes, out, with_shear):
    for e in range(opening.size):
        for k in range(3):
            value = opening[e] * normals[e, k]
            if with_shear:
                value += shear[2 * e] * axes[e, 0, k] + shear[2 * e + 1] * axes[e, 1, k]
            out[3 * e + k] = value


def join_frame(opening, shear, normals, axes):
    """The flat global vector of an opening part (N,) and a shear part (2N,) or None (zero)."""
    opening = np.ascontiguousarray(opening, dtype=np.float64).reshape(-1)
    out = np.empty(3 * opening.size)
    with_shear = shear is not None
    shear = np.ascontiguousarray(shear, dtype=np.float64).reshape(-1) if with_shear else np.zeros(0)
    _join(opening, shear, np.ascontiguousarray(normals), np.ascontiguousarray(axes), out, with_shear)
    return out
