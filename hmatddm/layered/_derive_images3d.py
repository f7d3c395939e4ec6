"""Offline derivation (sympy) behind :mod:`hmatddm.layered.images3d`; not imported by
the package (sympy is no runtime dependency). Run: ``python -m hmatddm.layered._derive_images3d``.

1. The 3D Hansen potentials of a unit point force (ref. Eq. 3.24) in a *gauge* ``sigma``
   (+1 or -1). With ``u = r + sigma r3`` the base functions are

       F = r - sigma r3 log u,     L = log u,

   harmonic, and singular only on the half-line ``sigma r3 < 0`` of the vertical through
   the point the pair emanates from (ref. Eq. 3.24's ``r1 r / rh^2`` is ``d1 F`` plus a
   ``r3 log rh`` term singular on the whole vertical, which produces no displacement).
   The script solves for the coefficients of

       force 1: phi1 = a d1 F, phi2 = b d1 F, phi3 = c d2 F
       force 2: phi1 = a d2 F, phi2 = b d2 F, phi3 = -c d1 F
       force 3: phi1 = e L,    phi2 = f L,    phi3 = 0

   that reproduce Kelvin's displacement through ref. Eq. 3.22 (with
   ``M_i = eps_ij3 phi3,j``, ref. Eq. 3.17) and prints them (in units of
   ``K = 1/(8 pi G (1 + delta))``).
2. Derives the reflection / transmission operators at an interface (ref. Eqs 3.25-3.28)
   from the interface conditions (continuity of displacement and traction on ``y3 = 0``)
   with unknown coefficients of ``h^n D^n`` (n = 0, 1, 2) in the (phi1, phi2) block and
   the phi3 entry of the operators, for all three force directions, for a source above and below the
   interface (gauge: regular on the interface), and prints the solution next to ref.
   Eqs 3.26-3.27.
"""
import itertools

import numpy as np

#: Operator entries solved for: (potential j, incident potential k, power n of h D); the
#: antiplane potential phi3 decouples from (phi1, phi2) (ref. Sec. 3.3), so the
#: (phi1, phi2) <-> phi3 entries are left out to keep sympy fast.
_ENTRIES = [(j, k, n) for j, k in ((0, 0), (0, 1), (1, 0), (1, 1), (2, 2)) for n in range(3)]


def _setup():
    import sympy as sp

    y1, y2, y3 = sp.symbols("y1 y2 y3", real=True)

    def base(r1, r2, r3, sigma):
        r = sp.sqrt(r1 ** 2 + r2 ** 2 + r3 ** 2)
        u = r + sigma * r3
        return r - sigma * r3 * sp.log(u), sp.log(u)

    def displacement(phi, delta, s):  # ref. Eq. 3.22 with M_i = eps_ij3 phi3,j (Eq. 3.17)
        p1, p2, p3 = phi
        y = (y1, y2, y3)
        u = []
        for i in range(3):
            ui = sp.diff(p1, y[i]) - sp.diff(p2, y[i]) - 2 * delta * s * sp.diff(p2, y[i], y3)
            if i == 2:
                ui += 2 * sp.diff(p2, y3)
            if i == 0:
                ui += sp.diff(p3, y2)
            if i == 1:
                ui -= sp.diff(p3, y1)
            u.append(ui)
        return u

    def traction(u, shear, delta):
        nu = (3 - 1 / delta) / 4
        lam = 2 * shear * nu / (1 - 2 * nu)
        y = (y1, y2, y3)
        div = sum(sp.diff(u[i], y[i]) for i in range(3))
        return [shear * (sp.diff(u[0], y3) + sp.diff(u[2], y1)), shear * (sp.diff(u[1], y3) + sp.diff(u[2], y2)),
                lam * div + 2 * shear * sp.diff(u[2], y3)]

    def potentials(r1, r2, r3, sigma, coefficients):
        """The three force directions' potential triples (K = 1)."""
        a, b, c, e, f = coefficients
        big_f, big_l = base(r1, r2, r3, sigma)
        d1f = sp.diff(big_f, y1)
        d2f = sp.diff(big_f, y2)
        return [(a * d1f, b * d1f, c * d2f), (a * d2f, b * d2f, -c * d1f), (e * big_l, f * big_l, 0)]

    return sp, (y1, y2, y3), base, displacement, traction, potentials


def kelvin_coefficients(nu=0.27):
    """Solve for (a, b, c, e, f) per gauge; returns {sigma: (coefficients, residual)}."""
    sp, (y1, y2, y3), base, displacement, traction, potentials = _setup()
    delta = 1 / (3 - 4 * nu)
    shear = 1.0
    k3 = 1 / (8 * np.pi * shear * (1 + delta))
    rng = np.random.default_rng(3)
    pts = rng.uniform(-2, 2, size=(12, 3))
    out = {}
    for sigma in (1, -1):
        symbols = sp.symbols("a b c e f")
        pots = potentials(y1, y2, y3, sigma, symbols)
        rows, rhs = [], []
        for force in range(3):
            u = displacement(pots[force], delta, y3)
            f = sp.lambdify([y1, y2, y3], [[sp.diff(ui, s) for s in symbols] for ui in u])
            for p in pts:
                if sigma * p[2] < 0:  # stay off the singular half-line side
                    p = p * np.array([1, 1, -1])
                r = np.linalg.norm(p)
                kelvin = [((3 - 4 * nu) * (force == i) + p[i] * p[force] / r ** 2) / (16 * np.pi * (1 - nu) * r)
                          for i in range(3)]
                rows.extend(np.array(f(*p), dtype=float))
                rhs.extend(np.array(kelvin) / k3)
        a, b = np.array(rows), np.array(rhs)
        x = np.linalg.lstsq(a, b, rcond=None)[0]
        out[sigma] = (x, float(np.linalg.norm(a @ x - b) / np.linalg.norm(b)))
    return out, delta


def _base_derivatives(sigma, max_order=4):
    """``{(a, b, c): f(y1, y2, y3)}``: sympy's derivatives of the base functions
    (``d1 F``, ``d2 F``, ``L`` of gauge ``sigma``), lambdified, up to total order ``max_order``."""
    sp, (y1, y2, y3), base, *_ = _setup()
    big_f, big_l = base(y1, y2, y3, sigma)
    out = {}
    for name, expr in (("d1F", sp.diff(big_f, y1)), ("d2F", sp.diff(big_f, y2)), ("L", big_l)):
        table = {(0, 0, 0): expr}
        for order in range(1, max_order + 1):
            for a_ in range(order + 1):
                for b_ in range(order + 1 - a_):
                    c_ = order - a_ - b_
                    if a_ > 0:
                        parent, var = (a_ - 1, b_, c_), y1
                    elif b_ > 0:
                        parent, var = (a_, b_ - 1, c_), y2
                    else:
                        parent, var = (a_, b_, c_ - 1), y3
                    table[(a_, b_, c_)] = sp.diff(table[parent], var)
        out[name] = {k: sp.lambdify([y1, y2, y3], v, "numpy") for k, v in table.items()}
    return out


_KINDS = (("d1F", "d1F", "d2F"), ("d2F", "d2F", "d1F"), ("L", "L", None))  # base of (force, potential)


def _conditions(potential, shear, delta, s):
    """Displacement and traction sigma_i3 on y3 = 0 (arrays over the points) of a triple
    ``potential[j](a, b, c)`` (ref. Eq. 3.22 with M_i = eps_ij3 phi3,j)."""
    def u(i, extra):
        e = [0, 0, 0]
        e[i] += 1
        for k in extra:
            e[k] += 1
        p1, p2, p3 = potential
        v = p1(*e) - p2(*e) - 2 * delta * s * p2(e[0], e[1], e[2] + 1)
        if 2 in extra:  # d3 of -2 delta s phi2,i3 also gives -2 delta phi2,i3 (here e = e_i + e_3)
            v = v - 2 * delta * p2(*e)
        if i == 2:
            v = v + 2 * p2(e[0], e[1], e[2])
        if i == 0:
            v = v + p3(e[0] - 1, e[1] + 1, e[2])
        if i == 1:
            v = v - p3(e[0] + 1, e[1] - 1, e[2])
        return v

    nu = (3 - 1 / delta) / 4
    lam = 2 * shear * nu / (1 - 2 * nu)
    grad = [[u(i, (k,)) for k in range(3)] for i in range(3)]
    div = grad[0][0] + grad[1][1] + grad[2][2]
    traction = [shear * (grad[0][2] + grad[2][0]), shear * (grad[1][2] + grad[2][1]), lam * div + 2 * shear * grad[2][2]]
    return [u(i, ()) for i in range(3)] + traction


def derive_operators(g1=1.0, g2=2.7, nu1=0.2, nu2=0.35, height=0.8, sigma_coefficients=None):
    """Solve for R and T: coefficients (2, 3, 3, 3) [R/T, j, k, n], residual, for a source
    at ``height`` (> 0: above the interface, layer 1 = y3 > 0; < 0: below). The base
    functions' derivatives are sympy's; the interface conditions are sampled at points."""
    d1, d2 = 1 / (3 - 4 * nu1), 1 / (3 - 4 * nu2)
    h = height
    sigma = -1 if h > 0 else 1  # the incident pair travels toward the interface
    coefficients, _ = sigma_coefficients[sigma]
    a_, b_, c_, e_, f_ = coefficients
    scale = ((a_, b_, c_), (a_, b_, -c_), (e_, f_, 0.0))
    derivatives = _base_derivatives(sigma, 5)
    pts = np.random.default_rng(5).uniform(-2.5, 2.5, size=(12, 2))

    def triple(force, j_out, k_in, power, mirrored):
        """Potential j_out = h^n D^n of incident potential k_in (mirrored or not), others 0."""
        kind = _KINDS[force][k_in]

        def value(a, b, c):
            if kind is None or a < 0 or b < 0:
                return np.zeros(len(pts))
            f = derivatives[kind][(a, b, c + power)]
            sign = (-1) ** (c + power) if mirrored else 1.0  # d/dy3 of B(y1, y2, -y3 - h)
            values = np.broadcast_to(np.asarray(f(pts[:, 0], pts[:, 1], -h), dtype=float), (len(pts),))
            return sign * scale[force][k_in] * h ** power * values

        zero = lambda a, b, c: np.zeros(len(pts))  # noqa: E731
        out = [zero, zero, zero]
        out[j_out] = value
        return out

    rows, rhs = [], []
    for force in range(3):
        incident = [triple(force, k, k, 0, False)[k] for k in range(3)]
        known = np.concatenate(_conditions(incident, g1, d1, -h))
        columns = []
        for j, k, n in _ENTRIES:  # reflected, s = y3 + h
            columns.append(np.concatenate(_conditions(triple(force, j, k, n, True), g1, d1, h)))
        for j, k, n in _ENTRIES:  # transmitted, s = y3 - h
            columns.append(-np.concatenate(_conditions(triple(force, j, k, n, False), g2, d2, -h)))
        rows.append(np.array(columns).T)
        rhs.append(-known)
    a, b = np.vstack(rows), np.concatenate(rhs)
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    rank = np.linalg.matrix_rank(a)
    coef = np.zeros((2, 3, 3, 3))
    for m, (j, k, n) in enumerate(_ENTRIES):
        coef[0, j, k, n] = x[m]
        coef[1, j, k, n] = x[len(_ENTRIES) + m]
    return coef, float(np.linalg.norm(a @ x - b) / np.linalg.norm(b)), rank, (g1, g2, d1, d2)


def main():
    kelvin, delta = kelvin_coefficients()
    for sigma, (x, residual) in kelvin.items():
        print(f"gauge {sigma:+d}: (a, b, c, e, f) / K = {np.round(x, 12)}, 2(1+delta) = {2 * (1 + delta):.6f}, "
              f"residual {residual:.1e}")
    for height in (0.8, -0.8):
        coef, residual, rank, (g1, g2, d1, d2) = derive_operators(height=height, sigma_coefficients=kelvin)
        gamma = g2 / g1
        c1 = (gamma - 1) / (gamma + d1)
        c2 = (gamma * d2 - d1) / (gamma * d2 + 1)
        c3 = (1 - gamma) / (1 + gamma)
        c4, c5, c6 = 1 - c1, 1 - c2, 1 + c3
        print(f"source at h = {height:+.1f}: residual of the interface conditions {residual:.1e} "
              f"(rank {rank} of {2 * len(_ENTRIES)})")
        reference = {"R11 (h D)": (coef[0, 0, 0, 1], 2 * d1 * c1), "R12 (1)": (coef[0, 0, 1, 0], c2),
                     "R12 (h^2 D^2)": (coef[0, 0, 1, 2], -4 * d1 ** 2 * c1), "R21 (1)": (coef[0, 1, 0, 0], c1),
                     "R22 (h D)": (coef[0, 1, 1, 1], -2 * d1 * c1), "R33 (1)": (coef[0, 2, 2, 0], c3),
                     "T11 (1)": (coef[1, 0, 0, 0], c4), "T12 (h D)": (coef[1, 0, 1, 1], -2 * (d1 * c4 - d2 * c5)),
                     "T22 (1)": (coef[1, 1, 1, 0], c5), "T33 (1)": (coef[1, 2, 2, 0], c6)}
        for name, (derived, printed) in reference.items():
            print(f"  {name:14s} derived {derived:+.6f}   ref. Eqs 3.26-3.27 {printed:+.6f}")
        listed = {(0, 0, 0, 1), (0, 0, 1, 0), (0, 0, 1, 2), (0, 1, 0, 0), (0, 1, 1, 1), (0, 2, 2, 0), (1, 0, 0, 0),
                  (1, 0, 1, 1), (1, 1, 1, 0), (1, 2, 2, 0)}  # the rest must come out zero
        others = max(abs(coef[idx]) for idx in itertools.product(range(2), range(3), range(3), range(3))
                     if idx not in listed)
        print(f"  largest other coefficient: {others:.1e}")


if __name__ == "__main__":
    main()
