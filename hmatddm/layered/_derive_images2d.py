"""Offline derivation (sympy) behind :mod:`hmatddm.layered.images2d`; not imported by
the package (sympy is no runtime dependency). Run: ``python -m hmatddm.layered._derive_images2d``.

1. Derives the 2D reflection and transmission operators of the Hansen potentials
   (ref. Eqs 3.25-3.28) from the interface conditions: with unknown coefficients of
   ``h^n D^n`` (n = 0, 1, 2) in each entry, it imposes continuity of the tangential
   derivative of the displacement and of the traction on ``y3 = 0`` for both point-force
   directions at many points and solves the linear system. The unique solution is
   printed next to the reference's formulas: R matches Eq. 3.26; T12 comes out as
   ``+2 (d1 c4 - d2 c5) h D``, opposite to the sign printed in Eq. 3.27.
2. Checks the closed-form derivatives the numba kernels use,
   ``d1^a d3^b Phi_11 = -K Re(i^b f^(a+b)(w))``, ``d1^a d3^b Phi_31 = -K Im(i^b f^(a+b)(w))``
   with ``f = w log w``, ``w = r1 + i r3`` (a + b >= 2), against sympy's differentiation
   of ref. Eq. 3.23.
"""
import itertools

import numpy as np


def _setup():
    import sympy as sp

    y1, y3, h = sp.symbols("y1 y3 h", real=True)

    def hansen_p(r1, r3):  # ref. Eq. 3.23, Phi_11 / K without its linear term
        return r3 * sp.atan2(r3, r1) - r1 * sp.log(sp.sqrt(r1 ** 2 + r3 ** 2))

    def hansen_q(r1, r3):  # Phi_31 / K
        return -r1 * sp.atan2(r3, r1) - r3 * sp.log(sp.sqrt(r1 ** 2 + r3 ** 2)) + r3

    def displacement(phi1, phi2, delta, s):  # ref. Eq. 3.22 in 2D
        u1 = sp.diff(phi1, y1) - sp.diff(phi2, y1) - 2 * delta * s * sp.diff(phi2, y1, y3)
        u3 = sp.diff(phi1, y3) + sp.diff(phi2, y3) - 2 * delta * s * sp.diff(phi2, y3, 2)
        return u1, u3

    def conditions(u, shear, delta):
        nu = (3 - 1 / delta) / 4
        lam = 2 * shear * nu / (1 - 2 * nu)
        e11, e33 = sp.diff(u[0], y1), sp.diff(u[1], y3)
        e13 = (sp.diff(u[0], y3) + sp.diff(u[1], y1)) / 2
        return [sp.diff(u[0], y1), sp.diff(u[1], y1), lam * (e11 + e33) + 2 * shear * e33, 2 * shear * e13]

    return sp, (y1, y3, h), hansen_p, hansen_q, displacement, conditions


def derive_operators(g1=1.0, g2=2.7, nu1=0.2, nu2=0.35, height=0.8):
    """Solve for R and T; returns (coefficients (2, 2, 2, 3) [R/T, j, k, n], residual)."""
    sp, (y1, y3, h), hansen_p, hansen_q, displacement, conditions = _setup()
    d1, d2 = 1 / (3 - 4 * nu1), 1 / (3 - 4 * nu2)
    points = np.linspace(-3.0, 3.0, 13)

    def evaluate(exprs):
        f = sp.lambdify([y1, y3, h], exprs)
        return np.array([f(t, 0.0, height) for t in points]).ravel()

    rows, rhs = [], []
    for base, sign in ((hansen_p, -1), (hansen_q, 1)):  # Phi_12 = -Phi_11, Phi_32 = Phi_31
        original = (base(y1, y3 - h), sign * base(y1, y3 - h))
        mirrored = (base(y1, -(y3 + h)), sign * base(y1, -(y3 + h)))
        known = evaluate(conditions(displacement(*original, d1, y3 - h), g1, d1))
        columns = []
        for j, k, n in itertools.product(range(2), range(2), range(3)):  # reflected, s = y3 + h
            phi = [0, 0]
            phi[j] = h ** n * sp.diff(mirrored[k], y3, n)
            columns.append(evaluate(conditions(displacement(*phi, d1, y3 + h), g1, d1)))
        for j, k, n in itertools.product(range(2), range(2), range(3)):  # transmitted, s = y3 - h
            phi = [0, 0]
            phi[j] = h ** n * sp.diff(original[k], y3, n)
            columns.append(-evaluate(conditions(displacement(*phi, d2, y3 - h), g2, d2)))
        rows.append(np.array(columns).T)
        rhs.append(-known)
    a, b = np.vstack(rows), np.concatenate(rhs)
    x = np.linalg.lstsq(a, b, rcond=None)[0]
    return x.reshape(2, 2, 2, 3), float(np.linalg.norm(a @ x - b) / np.linalg.norm(b)), (g1, g2, d1, d2, height)


def check_derivatives():
    """Largest relative difference between the closed-form and sympy derivatives."""
    sp, (y1, y3, _), hansen_p, hansen_q, _, _ = _setup()
    r1v, r3v = 0.7, -0.4
    w = complex(r1v, r3v)
    worst = 0.0
    for a in range(5):
        for b in range(7 - a):
            if a + b < 2:
                continue
            k = a + b
            fk = 1.0 / w if k == 2 else (-1) ** k * float(np.prod(np.arange(1, k - 1))) / w ** (k - 1)
            value = (1j ** b) * fk
            for base, part in ((hansen_p, -value.real), (hansen_q, -value.imag)):
                expr = sp.diff(base(y1, y3), y1, a, y3, b) if a else sp.diff(base(y1, y3), y3, b)
                exact = float(expr.subs({y1: r1v, y3: r3v}))
                worst = max(worst, abs(exact - part) / max(abs(exact), 1e-12))
    return worst


def main():
    coef, residual, (g1, g2, d1, d2, height) = derive_operators()
    gamma = g2 / g1
    c1 = (gamma - 1) / (gamma + d1)
    c2 = (gamma * d2 - d1) / (gamma * d2 + 1)
    c4, c5 = 1 - c1, 1 - c2
    print(f"least-squares residual of the interface conditions: {residual:.1e}")
    reference = {"R11 (h D)": (coef[0, 0, 0, 1], 2 * d1 * c1), "R12 (1)": (coef[0, 0, 1, 0], c2),
                 "R12 (h^2 D^2)": (coef[0, 0, 1, 2], -4 * d1 ** 2 * c1), "R21 (1)": (coef[0, 1, 0, 0], c1),
                 "R22 (h D)": (coef[0, 1, 1, 1], -2 * d1 * c1), "T11 (1)": (coef[1, 0, 0, 0], c4),
                 "T12 (h D)": (coef[1, 0, 1, 1], -2 * (d1 * c4 - d2 * c5)), "T22 (1)": (coef[1, 1, 1, 0], c5)}
    for name, (derived, printed) in reference.items():
        print(f"{name:14s} derived {derived:+.6f}   ref. Eqs 3.26-3.27 {printed:+.6f}")
    print(f"closed-form derivatives of the Hansen kernels vs sympy: {check_derivatives():.1e}")


if __name__ == "__main__":
    main()
