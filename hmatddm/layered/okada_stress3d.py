"""From Okada's (1992) displacement gradients to the global stress and traction: Hooke's
law in Okada's frame (``x`` along the strike, ``z`` up), turned about ``z`` to the global
frame, and the unit dislocations (strike, up-dip, tensile) mapped to the global DD by the
rows ``(strike, up-dip, normal)``. Shared by the finite rectangle (:mod:`.okada3d`) and the
point source (:mod:`.okada_point3d`)."""
import math

from numba import njit

#: ``|cos(dip)|`` below this is vertical (Okada 1992's 1e-6).
COS_ZERO = 1e-6


@njit(cache=True, inline="always")
def dip_and_medium(s0, s1, okada, shear_modulus, poisson_ratio):
    """``(sin dip, cos dip, lambda, alpha)``: the dip of the up-dip row of ``okada`` seen
    along the strike ``(s0, s1)`` (``|cos| <`` :data:`COS_ZERO`: vertical, Okada's own
    rule), Lame's lambda and Okada's medium constant ``alpha = (lambda + mu) / (lambda + 2
    mu)``."""
    t1 = -s1 * okada[1, 0] + s0 * okada[1, 1]
    t2 = okada[1, 2]
    inverse = 1.0 / math.sqrt(t1 * t1 + t2 * t2)
    cd = t1 * inverse
    sd = t2 * inverse
    if abs(cd) < COS_ZERO:
        cd = 0.0
        sd = 1.0
    lam = 2.0 * shear_modulus * poisson_ratio / (1.0 - 2.0 * poisson_ratio)
    return sd, cd, lam, 0.5 / (1.0 - poisson_ratio)  # (lambda + mu) / (lambda + 2 mu)


@njit(cache=True, inline="always")
def accumulate(acc, w, v):
    """``acc + w v`` of two 27-tuples of displacement derivatives (``9 k + 3 j + i``:
    ``du_i / dx_j`` of dislocation ``k``), written out: a Gauss or corner sum carried in a
    tuple stays in registers, where stores to an array would stop LLVM from vectorising the
    loop (the point source's points, the finite source's corners)."""
    return (acc[0] + w * v[0], acc[1] + w * v[1], acc[2] + w * v[2], acc[3] + w * v[3], acc[4] + w * v[4],
            acc[5] + w * v[5], acc[6] + w * v[6], acc[7] + w * v[7], acc[8] + w * v[8], acc[9] + w * v[9],
            acc[10] + w * v[10], acc[11] + w * v[11], acc[12] + w * v[12], acc[13] + w * v[13], acc[14] + w * v[14],
            acc[15] + w * v[15], acc[16] + w * v[16], acc[17] + w * v[17], acc[18] + w * v[18], acc[19] + w * v[19],
            acc[20] + w * v[20], acc[21] + w * v[21], acc[22] + w * v[22], acc[23] + w * v[23], acc[24] + w * v[24],
            acc[25] + w * v[25], acc[26] + w * v[26])


@njit(cache=True, inline="always")
def add_gradient(acc, gradient):
    """``gradient[k, i, j] += acc[9 k + 3 j + i]`` (:func:`accumulate`'s order), each index a
    constant (a tuple indexed by a variable is copied to memory first)."""
    gradient[0, 0, 0] += acc[0]
    gradient[0, 1, 0] += acc[1]
    gradient[0, 2, 0] += acc[2]
    gradient[0, 0, 1] += acc[3]
    gradient[0, 1, 1] += acc[4]
    gradient[0, 2, 1] += acc[5]
    gradient[0, 0, 2] += acc[6]
    gradient[0, 1, 2] += acc[7]
    gradient[0, 2, 2] += acc[8]
    gradient[1, 0, 0] += acc[9]
    gradient[1, 1, 0] += acc[10]
    gradient[1, 2, 0] += acc[11]
    gradient[1, 0, 1] += acc[12]
    gradient[1, 1, 1] += acc[13]
    gradient[1, 2, 1] += acc[14]
    gradient[1, 0, 2] += acc[15]
    gradient[1, 1, 2] += acc[16]
    gradient[1, 2, 2] += acc[17]
    gradient[2, 0, 0] += acc[18]
    gradient[2, 1, 0] += acc[19]
    gradient[2, 2, 0] += acc[20]
    gradient[2, 0, 1] += acc[21]
    gradient[2, 1, 1] += acc[22]
    gradient[2, 2, 1] += acc[23]
    gradient[2, 0, 2] += acc[24]
    gradient[2, 1, 2] += acc[25]
    gradient[2, 2, 2] += acc[26]


@njit(cache=True, inline="always")
def global_stress(work, s0, s1, lam, shear_modulus, okada, out):
    """``out[q, i, j]``: the global stress of a unit global DD ``q`` from the displacement
    gradient ``work[3, k, i, j]`` (Okada's frame, unit dislocation ``k``: strike, up-dip,
    tensile) through Hooke's law, turned about ``z`` by the strike ``(s0, s1)`` to the
    global frame and mapped by the rows ``okada`` (strike, up-dip, normal) to the global
    DD; ``work[4]`` scratch."""
    # Hooke's law into work[4], then about z to the global frame: R^T sigma R, R rows the
    # (x, y, z) axes of Okada's frame, each step through the other slot
    for k in range(3):
        tr = lam * (work[3, k, 0, 0] + work[3, k, 1, 1] + work[3, k, 2, 2])
        for i in range(3):
            for j in range(3):
                work[4, k, i, j] = shear_modulus * (work[3, k, i, j] + work[3, k, j, i])
            work[4, k, i, i] += tr
        for i in range(3):
            a0 = work[4, k, i, 0] * s0 - work[4, k, i, 1] * s1
            a1 = work[4, k, i, 0] * s1 + work[4, k, i, 1] * s0
            work[3, k, i, 0] = a0
            work[3, k, i, 1] = a1
            work[3, k, i, 2] = work[4, k, i, 2]
        for j in range(3):
            b0 = work[3, k, 0, j] * s0 - work[3, k, 1, j] * s1
            b1 = work[3, k, 0, j] * s1 + work[3, k, 1, j] * s0
            work[4, k, 0, j] = b0
            work[4, k, 1, j] = b1
            work[4, k, 2, j] = work[3, k, 2, j]
    for q in range(3):
        f0 = okada[0, q]
        f1 = okada[1, q]
        f2 = okada[2, q]
        for i in range(3):
            for j in range(3):
                out[q, i, j] = f0 * work[4, 0, i, j] + f1 * work[4, 1, i, j] + f2 * work[4, 2, i, j]


@njit(cache=True, inline="always")
def global_traction(work, s0, s1, lam, shear_modulus, okada, normal, block):
    """``block[p, q] +=`` the global traction ``sigma . normal`` (component ``p``) of a unit
    global DD ``q`` from the displacement gradient ``work[3, k, i, j]`` of
    :func:`global_stress`: the normal turned into Okada's frame once, no stress tensor turned
    back; ``work[4]`` scratch."""
    n0 = s0 * normal[0] + s1 * normal[1]
    n1 = -s1 * normal[0] + s0 * normal[1]
    n2 = normal[2]
    for k in range(3):
        tr = lam * (work[3, k, 0, 0] + work[3, k, 1, 1] + work[3, k, 2, 2])
        t0 = (shear_modulus * (2.0 * work[3, k, 0, 0] * n0 + (work[3, k, 0, 1] + work[3, k, 1, 0]) * n1
                               + (work[3, k, 0, 2] + work[3, k, 2, 0]) * n2) + tr * n0)
        t1 = (shear_modulus * ((work[3, k, 1, 0] + work[3, k, 0, 1]) * n0 + 2.0 * work[3, k, 1, 1] * n1
                               + (work[3, k, 1, 2] + work[3, k, 2, 1]) * n2) + tr * n1)
        t2 = (shear_modulus * ((work[3, k, 2, 0] + work[3, k, 0, 2]) * n0 + (work[3, k, 2, 1] + work[3, k, 1, 2]) * n1
                               + 2.0 * work[3, k, 2, 2] * n2) + tr * n2)
        work[4, k, 0, 0] = t0 * s0 - t1 * s1
        work[4, k, 0, 1] = t0 * s1 + t1 * s0
        work[4, k, 0, 2] = t2
    for q in range(3):
        f0 = okada[0, q]
        f1 = okada[1, q]
        f2 = okada[2, q]
        for p in range(3):
            block[p, q] += f0 * work[4, 0, 0, p] + f1 * work[4, 1, 0, p] + f2 * work[4, 2, 0, p]


@njit(cache=True, inline="always")
def accumulate_strain(acc, w, v):
    """``acc + w e`` of 18-tuples: ``e`` the strains of the 27 derivatives ``v``
    (:func:`accumulate`'s order) per dislocation ``k``: ``6 k +`` (0, 1, 2) the normal strains
    ``xx, yy, zz``, (3, 4, 5) the engineering shears ``xy, xz, yz``. The stress needs no
    more (Hooke's law), and 18 sums in registers are cheaper than 27 (the point source's Gauss
    sum ~20%, benchmarks/RESULTS.md, issue 32)."""
    return (acc[0] + w * v[0], acc[1] + w * v[4], acc[2] + w * v[8], acc[3] + w * (v[1] + v[3]),
            acc[4] + w * (v[2] + v[6]), acc[5] + w * (v[5] + v[7]),
            acc[6] + w * v[9], acc[7] + w * v[13], acc[8] + w * v[17], acc[9] + w * (v[10] + v[12]),
            acc[10] + w * (v[11] + v[15]), acc[11] + w * (v[14] + v[16]),
            acc[12] + w * v[18], acc[13] + w * v[22], acc[14] + w * v[26], acc[15] + w * (v[19] + v[21]),
            acc[16] + w * (v[20] + v[24]), acc[17] + w * (v[23] + v[25]))


@njit(cache=True, inline="always")
def set_strain(acc, gradient):
    """``gradient[k, i, j]`` (3, 3, 3): the symmetric gradient of :func:`accumulate_strain`'s
    sums (what :func:`global_stress` turns into the same stress as the whole gradient)."""
    for k in range(3):
        gradient[k, 0, 0] = acc[6 * k]
        gradient[k, 1, 1] = acc[6 * k + 1]
        gradient[k, 2, 2] = acc[6 * k + 2]
        for i, j, m in ((0, 1, 3), (0, 2, 4), (1, 2, 5)):
            gradient[k, i, j] = 0.5 * acc[6 * k + m]
            gradient[k, j, i] = 0.5 * acc[6 * k + m]


@njit(cache=True, inline="always")
def accumulate_traction(acc, w, v, n0, n1, n2, shear_modulus, lam):
    """``acc + w t`` of 9-tuples: ``t[3 k + p]`` the traction (Okada's frame) on the normal
    ``(n0, n1, n2)`` (Okada's frame) of the 27 derivatives ``v`` (:func:`accumulate`'s order)
    through Hooke's law, as :func:`global_traction` makes it after the sum. Nine sums in
    registers instead of 27 (the point source's Gauss sum, benchmarks/RESULTS.md, issue 32)."""
    g = shear_modulus
    tr0 = lam * (v[0] + v[4] + v[8])
    tr1 = lam * (v[9] + v[13] + v[17])
    tr2 = lam * (v[18] + v[22] + v[26])
    return (acc[0] + w * (g * (2.0 * v[0] * n0 + (v[1] + v[3]) * n1 + (v[2] + v[6]) * n2) + tr0 * n0),
            acc[1] + w * (g * ((v[1] + v[3]) * n0 + 2.0 * v[4] * n1 + (v[5] + v[7]) * n2) + tr0 * n1),
            acc[2] + w * (g * ((v[2] + v[6]) * n0 + (v[5] + v[7]) * n1 + 2.0 * v[8] * n2) + tr0 * n2),
            acc[3] + w * (g * (2.0 * v[9] * n0 + (v[10] + v[12]) * n1 + (v[11] + v[15]) * n2) + tr1 * n0),
            acc[4] + w * (g * ((v[10] + v[12]) * n0 + 2.0 * v[13] * n1 + (v[14] + v[16]) * n2) + tr1 * n1),
            acc[5] + w * (g * ((v[11] + v[15]) * n0 + (v[14] + v[16]) * n1 + 2.0 * v[17] * n2) + tr1 * n2),
            acc[6] + w * (g * (2.0 * v[18] * n0 + (v[19] + v[21]) * n1 + (v[20] + v[24]) * n2) + tr2 * n0),
            acc[7] + w * (g * ((v[19] + v[21]) * n0 + 2.0 * v[22] * n1 + (v[23] + v[25]) * n2) + tr2 * n1),
            acc[8] + w * (g * ((v[20] + v[24]) * n0 + (v[23] + v[25]) * n1 + 2.0 * v[26] * n2) + tr2 * n2))


@njit(cache=True, inline="always")
def add_traction(acc, s0, s1, okada, block):
    """``block[p, q] +=`` the global traction (component ``p``) of a unit global DD ``q``
    from :func:`accumulate_traction`'s sums: turned about ``z`` by the strike ``(s0, s1)``
    and mapped by the rows ``okada`` (as the end of :func:`global_traction`)."""
    for q in range(3):
        f0 = okada[0, q]
        f1 = okada[1, q]
        f2 = okada[2, q]
        t0 = f0 * acc[0] + f1 * acc[3] + f2 * acc[6]
        t1 = f0 * acc[1] + f1 * acc[4] + f2 * acc[7]
        block[0, q] += t0 * s0 - t1 * s1
        block[1, q] += t0 * s1 + t1 * s0
        block[2, q] += f0 * acc[2] + f1 * acc[5] + f2 * acc[8]
