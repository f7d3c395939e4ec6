"""Independent reference for the DDM kernels: Gauss quadrature of the Kelvin solution.

The stress induced at ``x`` by a displacement discontinuity ``DD = u(+) - u(-)`` on a
surface with unit normal ``n`` (pointing to the + side) follows from Volterra's formula

    u_k(x) = - int m_pq d/dx_q G_kp(x - y) dS(y),   m_pq = lambda dd.n delta_pq + G (dd_p n_q + dd_q n_p)

with Kelvin's point-force solution G_kp (ref. App. A eq. 5); its stress is the
hypersingular Kelvin kernel of ref. App. A eqs 4 and 8. Here the second derivatives of
G_kp are written out by hand and integrated by tensor Gauss-Legendre quadrature, which is
accurate for points well separated from the element. No code is shared with the kernels.
"""
import numpy as np


def _kelvin_second_derivatives_3d(r, nu, shear_modulus):
    """d^2 G_kp / dx_q dx_s for separations r (Q, 3): array (Q, k, p, q, s)."""
    A = 1.0 / (16.0 * np.pi * shear_modulus * (1.0 - nu))
    I = np.eye(3)
    rn = np.linalg.norm(r, axis=1)
    r3, r5, r7 = rn**-3, rn**-5, rn**-7
    d = -(3 - 4 * nu) * np.einsum("kp,Qqs->Qkpqs", I, I[None] * r3[:, None, None]
                                  - 3 * np.einsum("Qq,Qs->Qqs", r, r) * r5[:, None, None])
    d += (np.einsum("kq,ps->kpqs", I, I) + np.einsum("pq,ks->kpqs", I, I))[None] * r3[:, None, None, None, None]
    d -= 3 * (np.einsum("kq,Qp,Qs->Qkpqs", I, r, r) + np.einsum("pq,Qk,Qs->Qkpqs", I, r, r)) * r5[:, None, None, None, None]
    d -= 3 * (np.einsum("ks,Qp,Qq->Qkpqs", I, r, r) + np.einsum("ps,Qk,Qq->Qkpqs", I, r, r)
              + np.einsum("qs,Qk,Qp->Qkpqs", I, r, r)) * r5[:, None, None, None, None]
    d += 15 * np.einsum("Qk,Qp,Qq,Qs->Qkpqs", r, r, r, r) * r7[:, None, None, None, None]
    return A * d


def _kelvin_second_derivatives_2d(r, nu, shear_modulus):
    """Plane strain: G_kp = -1/(8 pi G (1-nu)) [(3-4nu) delta ln r - r_k r_p / r^2]."""
    A = -1.0 / (8.0 * np.pi * shear_modulus * (1.0 - nu))
    I = np.eye(2)
    rsq = np.einsum("Qi,Qi->Q", r, r)
    r2, r4, r6 = 1 / rsq, rsq**-2, rsq**-3
    # d/dq d/ds ln r = delta_qs / r^2 - 2 r_q r_s / r^4
    dlog = I[None] * r2[:, None, None] - 2 * np.einsum("Qq,Qs->Qqs", r, r) * r4[:, None, None]
    d = (3 - 4 * nu) * np.einsum("kp,Qqs->Qkpqs", I, dlog)
    # d/dq d/ds (r_k r_p / r^2)
    t = (np.einsum("kq,ps->kpqs", I, I) + np.einsum("ks,pq->kpqs", I, I))[None] * r2[:, None, None, None, None]
    t -= 2 * (np.einsum("kq,Qp,Qs->Qkpqs", I, r, r) + np.einsum("pq,Qk,Qs->Qkpqs", I, r, r)
              + np.einsum("ks,Qp,Qq->Qkpqs", I, r, r) + np.einsum("ps,Qk,Qq->Qkpqs", I, r, r)
              + np.einsum("qs,Qk,Qp->Qkpqs", I, r, r)) * r4[:, None, None, None, None]
    t += 8 * np.einsum("Qk,Qp,Qq,Qs->Qkpqs", r, r, r, r) * r6[:, None, None, None, None]
    return A * (d - t)


def stress_from_dd(x, quad_points, quad_weights, normal, nu, shear_modulus):
    """Global stress at ``x`` per unit global DD component: array (q, i, j)."""
    dim = len(x)
    lam = 2 * shear_modulus * nu / (1 - 2 * nu)
    r = x[None, :] - quad_points
    second = (_kelvin_second_derivatives_3d if dim == 3 else _kelvin_second_derivatives_2d)(r, nu, shear_modulus)
    # integrate d2G over the element: (k, p, q, s)
    d2 = np.einsum("Q,Qkpqs->kpqs", quad_weights, second)
    I = np.eye(dim)
    out = np.zeros((dim, dim, dim))
    for comp in range(dim):
        dd = I[comp]
        m = lam * (dd @ normal) * I + shear_modulus * (np.outer(dd, normal) + np.outer(normal, dd))
        grad_u = -np.einsum("pq,kpqs->ks", m, d2)  # du_k/dx_s
        strain = 0.5 * (grad_u + grad_u.T)
        out[comp] = lam * np.trace(strain) * I + 2 * shear_modulus * strain
    return out


def rectangle_quadrature(center, e1, e2, a, b, order=24):
    xg, wg = np.polynomial.legendre.leggauss(order)
    s, t = np.meshgrid(a * xg, b * xg, indexing="ij")
    w = np.outer(a * wg, b * wg).ravel()
    pts = center + s.reshape(-1, 1) * e1 + t.reshape(-1, 1) * e2
    return pts, w


def segment_quadrature(center, tangent, a, order=40):
    xg, wg = np.polynomial.legendre.leggauss(order)
    return center + (a * xg)[:, None] * tangent, a * wg
