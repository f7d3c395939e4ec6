"""The response of the tabulated layered fields in the frame turned about the vertical towards
the receiver, and its stress in the global frame (issue 32).

The tables of a layered medium (:mod:`.remainder_table3d`, :mod:`.near_table3d`) hold, at a
horizontal offset ``rho`` along the turned frame's x axis, the stress components ``s`` of a
unit moment component ``m`` of a point source (ref. Secs 3.2-3.3; the moment of a DD on a
plane: ref. Eq. 7.3 with isotropic moduli, ``lambda delta b.n + mu (b n + n b)``;
docs/conventions.md §4). The medium is unchanged by the
mirror ``y -> -y`` of that frame, so a component is zero unless ``m`` and ``s`` hold an even
number of ``y`` indices together: 20 of the 36 (:data:`COMPONENTS`), a 4 x 4 block (``xx, yy,
zz, xz``) and a 2 x 2 one (``xy, yz``).

:func:`rotated_stress` turns a DD's moment into that frame, contracts it with the response
and turns the stress back. Written out for this layout: the loop over :data:`COMPONENTS`
through a scratch array (indices loaded from a table, each sum a store and a load) was 107 ns
a point against 32 ns written out (a micro-benchmark, one thread of the 2-core Xeon, dgemm
74-86 GFLOP/s in the same hour; benchmarks/RESULTS.md, fourteenth session); the layout is
checked where this module loads."""
import numpy as np
from numba import njit

#: The 6 symmetric index pairs of a moment or a stress: xx, yy, zz, xy, xz, yz.
PAIRS = np.array([[0, 0], [1, 1], [2, 2], [0, 1], [0, 2], [1, 2]], dtype=np.int64)


def _nonzero_components():
    """``(m, s)`` of the 20 response components that the mirror ``y -> -y`` leaves (the
    number of ``y`` indices of the moment and the stress is even)."""
    count = [int(p == 1) + int(q == 1) for p, q in PAIRS]
    return np.array([[m, s] for m in range(6) for s in range(6) if (count[m] + count[s]) % 2 == 0], dtype=np.int64)


#: ``(m, s)`` of each response component (the order of the tables' values).
COMPONENTS = _nonzero_components()

# the layout _turned_moment_stress is written for: m = xx, yy, zz, xz to s = xx, yy, zz, xz
# (components 0-11, 14-17), m = xy, yz to s = xy, yz (12, 13, 18, 19)
_WRITTEN_FOR = [[m, s] for m in range(6) for s in range(6) if (m in (3, 5)) == (s in (3, 5))]
if COMPONENTS.tolist() != _WRITTEN_FOR:  # pragma: no cover - a changed PAIRS or mirror rule
    raise ImportError("turned_response3d: COMPONENTS no longer in the layout rotated_stress is written for")


@njit(cache=True, inline="always")
def _turned_moment_stress(b0, b1, b2, bn, n0, n1, n2, shear_modulus, lame, r):
    """The stress ``(xx, yy, zz, xy, xz, yz)`` in the turned frame of a unit DD ``(b0, b1,
    b2)`` on a plane of normal ``(n0, n1, n2)`` (both in that frame; ``bn`` their product)
    through the response ``r`` (:data:`COMPONENTS`)."""
    m0 = 2.0 * shear_modulus * b0 * n0 + lame * bn
    m1 = 2.0 * shear_modulus * b1 * n1 + lame * bn
    m2 = 2.0 * shear_modulus * b2 * n2 + lame * bn
    m3 = shear_modulus * (b0 * n1 + b1 * n0)
    m4 = shear_modulus * (b0 * n2 + b2 * n0)
    m5 = shear_modulus * (b1 * n2 + b2 * n1)
    sxx = m0 * r[0] + m1 * r[4] + m2 * r[8] + m4 * r[14]
    syy = m0 * r[1] + m1 * r[5] + m2 * r[9] + m4 * r[15]
    szz = m0 * r[2] + m1 * r[6] + m2 * r[10] + m4 * r[16]
    sxz = m0 * r[3] + m1 * r[7] + m2 * r[11] + m4 * r[17]
    sxy = m3 * r[12] + m5 * r[18]
    syz = m3 * r[13] + m5 * r[19]
    return sxx, syy, szz, sxy, sxz, syz


@njit(cache=True, inline="always")
def _add_turned_back(c, s, weight, stress, out, b):
    """``out[b] += weight *`` the turned frame's ``stress`` in the global frame (``sigma = R^T
    sigma' R``, ``R`` rows ``(c, s, 0), (-s, c, 0), (0, 0, 1)``)."""
    sxx, syy, szz, sxy, sxz, syz = stress
    gxx = c * c * sxx - 2.0 * c * s * sxy + s * s * syy
    gyy = s * s * sxx + 2.0 * c * s * sxy + c * c * syy
    gxy = c * s * (sxx - syy) + (c * c - s * s) * sxy
    gxz = c * sxz - s * syz
    gyz = s * sxz + c * syz
    out[b, 0, 0] += weight * gxx
    out[b, 1, 1] += weight * gyy
    out[b, 2, 2] += weight * szz
    out[b, 0, 1] += weight * gxy
    out[b, 1, 0] += weight * gxy
    out[b, 0, 2] += weight * gxz
    out[b, 2, 0] += weight * gxz
    out[b, 1, 2] += weight * gyz
    out[b, 2, 1] += weight * gyz


@njit(cache=True, inline="always")
def rotated_stress(c, s, normal, shear_modulus, lame, weight, response, out):
    """``out[b, i, k] += weight *`` the stress of the tabulated ``response`` (:data:`COMPONENTS`)
    in the frame turned about z by ``(cos, sin) = (c, s)`` for a unit DD along global ``b`` on
    a plane of (global) ``normal``, the source's moduli ``shear_modulus``, ``lame``."""
    n0 = c * normal[0] + s * normal[1]  # the normal in the turned frame
    n1 = -s * normal[0] + c * normal[1]
    n2 = normal[2]
    # the global DDs x, y, z in the turned frame: (c, -s, 0), (s, c, 0), (0, 0, 1)
    _add_turned_back(c, s, weight, _turned_moment_stress(c, -s, 0.0, normal[0], n0, n1, n2, shear_modulus, lame,
                                                         response), out, 0)
    _add_turned_back(c, s, weight, _turned_moment_stress(s, c, 0.0, normal[1], n0, n1, n2, shear_modulus, lame,
                                                         response), out, 1)
    _add_turned_back(c, s, weight, _turned_moment_stress(0.0, 0.0, 1.0, normal[2], n0, n1, n2, shear_modulus, lame,
                                                         response), out, 2)
