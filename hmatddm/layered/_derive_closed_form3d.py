"""What a closed form of the 3D image triples beyond the half-space would take (issue 32,
item 1): the measurements behind the docstring of :mod:`.images3d`. Not imported by the
package; run ``python -m hmatddm.layered._derive_closed_form3d`` (about a minute).

1. :func:`coefficient_degrees`: the coefficient of ``D^n`` of every traced triple (ref.
   Eqs 3.25-3.28, :mod:`.image_tracer3d`) is a polynomial in the source height ``t`` of
   degree at most ``min(n, 2)``: fitted to round-off at 17 heights for every triple of a
   free surface over two interfaces (G, 2G, G), ``images`` 1 to 4, sources in both upper
   layers. The degree does not grow with the number of reflections (measured, not
   derived here: the products of the ``h D`` and ``h^2 D^2`` of successive reflections
   cancel beyond degree 2); the ``D`` order does (up to 5 at ``images=4``). So every
   triple is, like the half-space's image, a point-source field whose weights are
   quadratic in the source height: the integrals over a rectangle with a horizontal side
   are elementary (polynomials of degree <= 2 along the dip times derivatives of ``F``,
   ``L`` and ``1/r``), but each needs its own primitives (item 2).
2. :func:`okada_group_residual`: Okada's (1992) image terms split by his coefficient
   groups (part A: ``a1``, ``a2``; part B: 1, ``a3``; part C: 1, ``a4``, ``a5``; seven
   fields, each summed over the corners exactly as :mod:`.okada3d` sums them) do not span
   the reflected triple of a bi-material interface: least squares with separate weights per
   dislocation component leave 0.3-1.2 % of the field (a half-space, G above = 0: 4e-15).
   So no reweighting of the half-space closed form gives a reflection at an interface
   between two solids; a closed form needs the primitives of the triple's own terms.
3. The one triple beyond the half-space that *is* Okada's: the reflection of a top-layer
   source in the free surface, coefficient for coefficient the half-space's
   (:func:`hmatddm.layered.influence3d.surface_reflection_alone`), now taken in closed form.
4. Every triple of a *vertical* rectangle in closed form (the comment block before
   :func:`k_primitive_identities`): :func:`check_vertical_terms` checks each stress term
   ``P(t) d1^a d2^b d3^c B`` against the quadrature (5e-13), and
   :func:`check_vertical_rectangles` whole image entries against
   :func:`.rectangle_quadrature.image_rectangle_stress` (bi-material and a free surface
   over two interfaces, receivers on both sides: 1.4e-14, 2.8e-14 of the largest). The
   Python prototype of :mod:`.vertical3d`, the operator's compiled path.
"""
import inspect
import re
import types

import numpy as np

from . import okada3d
from .image_tracer3d import trace_points
from .rectangle_quadrature import image_rectangle_stress


def coefficient_degrees(images=(1, 2, 4), n_heights=17):
    """``{(source_layer, images): {(n, degree): count}}`` over the triples of a free
    surface over interfaces at 0, -10, -20 (G, 2G, G): the smallest polynomial degree in
    ``t`` that fits the coefficients of ``D^n`` to 1e-9 of their size."""
    interfaces = np.array([0.0, -10.0, -20.0])
    g = np.array([0.0, 1.0, 2.0, 1.0])
    nu = np.full(4, 0.25)
    found = {}
    for layer, (lo, hi) in ((1, (-9.5, -0.5)), (2, (-19.5, -10.5))):
        heights = np.linspace(lo, hi, n_heights)
        for n_images in images:
            n_pairs, _, _, _, _, coef, _ = trace_points(heights, layer, interfaces, g, nu, n_images)
            counts = {}
            for k in range(n_pairs[0]):
                for order in range(coef.shape[-1]):
                    values = coef[:, k, :, :, order].reshape(n_heights, -1)
                    if np.abs(values).max() == 0.0:
                        continue
                    degree = next(d for d in range(n_heights) if _fits(heights, values, d))
                    counts[order, degree] = counts.get((order, degree), 0) + 1
            found[layer, n_images] = dict(sorted(counts.items()))
    return found


def _fits(heights, values, degree):
    v = np.vander(heights, degree + 1)
    solution = np.linalg.lstsq(v, values, rcond=None)[0]
    return np.abs(v @ solution - values).max() <= 1e-9 * np.abs(values).max()


def _okada_groups():
    """:mod:`.okada3d` with the image corners' coefficients and parts as arguments: its
    source, rewritten (the seven fields of item 2 are its parts with one coefficient on)."""
    source = inspect.getsource(okada3d).replace("cache=True", "cache=False")
    source = source.replace("def _image_corners(q, z, sd, cd, alpha, c4):",
                            "def _image_corners(q, z, sd, cd, alpha, c4, co):")
    source = re.sub(r"    a1 = 0\.5 \* \(1\.0 - alpha\)\n    a2 = 0\.5 \* alpha\n    a3 = \(1\.0 - alpha\) / alpha\n"
                    r"    a4 = 1\.0 - alpha\n    a5 = alpha\n",
                    "    a1, a2, a3, a4, a5, k_a, k_b, k_c = co[0], co[1], co[2], co[3], co[4], co[5], co[6], co[7]\n",
                    source)
    lines, inside = [], False
    for line in source.split("\n"):
        inside = re.match(r"v\d = _turned\(", line.strip()) is not None or (
            inside and not lines[-1].rstrip().endswith(")"))
        if inside:
            line = re.sub(r"a\[(\d+)\]", r"k_a * a[\1]", line)
            line = re.sub(r"\bB(\d{3})\b", r"k_b * B\1", line)
            line = re.sub(r"\bz \* W(\d{3})", r"k_c * z * W\1", line)
            line = re.sub(r"\bU(\d\d)\b", r"k_c * U\1", line)
        lines.append(line)
    source = "\n".join(lines)
    for name, args in (("gradient", "s, c4"), ("_gradient", "work, c4")):
        source = re.sub(rf"(def {name}\([^)]*{args})\)", r"\1, co)", source)
    source = source.replace("_image_corners(q, z, sd, cd, alpha, c4)\n", "_image_corners(q, z, sd, cd, alpha, c4, co)\n")
    source = source.replace("alpha, real, image, work, c4)\n    return", "alpha, real, image, work, c4, co)\n    return")
    source = re.sub(r"(def okada_stress\([^)]*out)\)", r"\1, co)", source)
    source = source.replace("real, image, work, c4)\n    # Hooke", "real, image, work, c4, co)\n    # Hooke")
    module = types.ModuleType("okada_groups")
    exec(compile(source, "okada_groups", "exec"), module.__dict__)
    return module


def okada_group_residual(upper=(0.0, 0.5, 2.0), nu_upper=(0.25, 0.25, 0.3), seed=1, n_points=40):
    """Largest residual (relative to the field) of the least-squares fit of the reflected
    triple's stress (one interface at z = 0, G above in ``upper``, G = 1 below, a tilted
    square of side 0.5 at 0.8 m below it, 40 receivers in the lower layer; image
    quadrature with 12 points on 16 x 16 sub-squares) by the seven Okada groups, weights
    per dislocation component, for each upper modulus."""
    groups = _okada_groups()
    rng = np.random.default_rng(seed)
    strike, dip = 0.4, 1.1
    s = np.array([np.cos(strike), np.sin(strike), 0.0])
    t = np.array([-np.sin(strike) * np.cos(dip), np.cos(strike) * np.cos(dip), np.sin(dip)])
    frame = np.array([s, t, np.cross(s, t)])
    center = np.array([0.1, -0.2, -0.8])
    a = b = 0.25
    _, rows, half = okada3d.halfspace_geometry(frame[None], np.array([a]), np.array([b]))
    points = [np.array([rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(-2.5, -0.05)])
              for _ in range(n_points)]
    work, c4, out = np.empty((5, 3, 3, 3)), np.empty((30, 4)), np.empty((3, 3, 3))

    def okada(co):
        fields = []
        for y in points:
            groups.okada_stress(y, center, rows[0], half[0, 0], half[0, 1], 0.0, 1.0, 0.25, False, True, work, c4, out,
                                np.array(co, dtype=float))
            fields.append(np.einsum("kq,qij->kij", rows[0], out))
        return np.array(fields)

    on = np.eye(5)
    b1, c1 = okada([0, 0, 0, 0, 0, 0, 1, 0]), okada([0, 0, 0, 0, 0, 0, 0, 1])
    basis = [okada([*on[0], 1, 0, 0]), okada([*on[1], 1, 0, 0]), b1, okada([*on[2], 0, 1, 0]) - b1, c1,
             okada([*on[3], 0, 0, 1]) - c1, okada([*on[4], 0, 0, 1]) - c1]
    residuals = []
    for g_up, nu_up in zip(upper, nu_upper):
        target = []
        for y in points:
            image_rectangle_stress(y, 1, center, frame, a, b, 1, np.array([0.0]), np.array([g_up, 1.0]),
                                   np.array([nu_up, 0.25]), 1, 12, 16, out, False, np.zeros(2), np.zeros(2))
            target.append(np.einsum("kq,qij->kij", rows[0], out))
        target = np.array(target)
        worst = 0.0
        for k in range(3):
            m = np.stack([f[:, k].ravel() for f in basis], axis=1)
            weights = np.linalg.lstsq(m, target[:, k].ravel(), rcond=None)[0]
            worst = max(worst, np.abs(m @ weights - target[:, k].ravel()).max())
        residuals.append(worst / np.abs(target).max())
    return residuals




# --- 4. Vertical rectangles: the reduction a closed form of every triple can use ------------
#
# A vertical rectangle, strike along x (any strike is turned there: the layers are invariant
# under turns about z), points (c1 + xi, c2, t), |xi| <= A, t_bot <= t <= t_top; a triple's
# point (c1 + xi, c2, z0 + eps t) with eps = dz/dt = +-1, gauge sigma. Every term of its
# stress (potentials3d._pair_stress_gradient through _potential_table) is
# P(t) d1^a d2^b d3^c B(r) with r = y - point, B = F or L of gauge sigma and deg P <= 3 (the
# coefficient, degree <= min(n, 2), times s = y3 - z of degree 1). Because
# d3 g(r) = -eps d/dt g along the rectangle, the t integral is exact by parts,
#     int P d3^c g dt = sum_i (-1)^i (-eps)^(i+1) [P^(i) d3^(c-1-i) g]_bottom^top,
# which needs d3^-1 of F (K below) and of L (-sigma F) when deg P = c; the xi integral is a
# difference of d1^(a-1) at the two ends for a >= 1; for a = 0 the Laplace equation turns
# d2^2 into -d1^2 - d3^2 until b <= 1, and then (for the degrees the stress has, checked
# here) the d3 order left is high enough that d1^-1 only acts on derivatives of 1/r:
# d1^-1 (1/r) = log(r + r1), whose derivatives are potentials3d's L with the axes turned.
# K = 3/4 r3 r + (rho^2/4 - r3^2/2) L - rho^2/8 (gauge +1, rho^2 = r1^2 + r2^2) has
# d3 K = F, d1 K = (r3 d1 F + r1 L) / 2, d2 K = (r3 d2 F + r2 L) / 2 (sympy, below).


def k_primitive_identities():
    """The three identities of ``K`` (gauge +1), checked with sympy: residuals (all 0)."""
    import sympy as sp
    r1, r2 = sp.symbols("r1 r2", real=True)
    r3 = sp.symbols("r3", positive=True)
    r = sp.sqrt(r1 ** 2 + r2 ** 2 + r3 ** 2)
    big_l = sp.log(r + r3)
    big_f = r - r3 * big_l
    rho2 = r1 ** 2 + r2 ** 2
    k = sp.Rational(3, 4) * r3 * r + (rho2 / 4 - r3 ** 2 / 2) * big_l - rho2 / 8
    return [sp.simplify(sp.diff(k, r3) - big_f), sp.simplify(sp.diff(k, r1) - (r3 * sp.diff(big_f, r1) + r1 * big_l) / 2),
            sp.simplify(sp.diff(k, r2) - (r3 * sp.diff(big_f, r2) + r2 * big_l) / 2)]


def _point_tables(r1, r2, r3, sigma, n_c=10):
    """``(base, sf, sl)`` of :mod:`.potentials3d` at ``r`` for gauge ``sigma``:
    ``base[kind, a, b, c]`` the derivatives of F (0) and L (1), ``sf, sl`` the horizontal
    ones of the gauge +1 functions at ``(r1, r2, sigma r3)``."""
    from .potentials3d import _base_table, base_derivatives, inverse_distance_scratch
    sf, sl, ser = np.empty((6, 6)), np.empty((6, 6)), np.empty((4, 6))
    q = np.empty((6, 6, n_c - 1))
    base = np.empty((2, 6, 6, n_c))
    base_derivatives(r1, r2, sigma * r3, sf, sl, q, ser, inverse_distance_scratch(n_c - 1), 6 + n_c)
    _base_table(sigma, n_c, sf, sl, q, base, 6 + n_c)
    return base, sf, sl


def _derivative(kind, a, b, m, r1, r2, r3, sigma):
    """``d1^a d2^b d3^m B`` at ``r`` for ``m >= -1`` (``d3^-1``: ``K`` for F, ``-sigma F``
    for L)."""
    base, sf, sl = _point_tables(r1, r2, r3, sigma)
    if m >= 0:
        return base[kind, a, b, m]
    if kind == 1:
        return -sigma * sf[a, b]
    rho3 = sigma * r3  # K of gauge sigma is sigma K(r1, r2, sigma r3)
    if a >= 1:
        value = rho3 * sf[a, b] + r1 * sl[a - 1, b] + ((a - 1) * sl[a - 2, b] if a >= 2 else 0.0)
    elif b >= 1:
        value = rho3 * sf[0, b] + r2 * sl[0, b - 1] + ((b - 1) * sl[0, b - 2] if b >= 2 else 0.0)
    else:
        rho2 = r1 * r1 + r2 * r2
        r = np.sqrt(rho2 + rho3 * rho3)
        return sigma * (0.75 * rho3 * r + (0.25 * rho2 - 0.5 * rho3 * rho3) * sl[0, 0] - 0.125 * rho2)
    return sigma * 0.5 * value


def _strike_primitive_difference(kind, b, m, ends, r2, r3, sigma):
    """``[d1^-1 d2^b d3^m B]`` between the two values of ``r1`` in ``ends`` (hi - lo), for
    ``b <= 1`` and ``m`` high enough that ``d3^m B`` is a derivative of ``1/r``: F needs
    ``m >= 2`` (``d3^2 F = -1/r``), L ``m >= 1`` (``d3 L = sigma / r``). ``d1^-1 (1/r)``:
    ``log(r + r1)``, or ``-log(r - r1)`` when both ends are negative (no cancellation); the
    same branch at both ends."""
    from .potentials3d import base_derivatives, inverse_distance_scratch
    if kind == 0 and m < 2 or kind == 1 and m < 1:
        raise ValueError(f"d1^-1 of d3^{m} of {'FL'[kind]}: not a derivative of 1/r")
    k = m - 2 if kind == 0 else m - 1
    scale = -1.0 if kind == 0 else sigma
    flip = max(ends) < 0.0
    values = []
    for r1 in ends:
        sf, sl, ser = np.empty((6, 6)), np.empty((6, 6)), np.empty((4, 6))
        q = np.empty((6, 6, 2))  # sl's second index uses d_r1 (1/r) (Laplace)
        base_derivatives(r2, r3, -r1 if flip else r1, sf, sl, q, ser, inverse_distance_scratch(2), 8)  # axes turned: (r2, r3, r1)
        # d3^k of a function of (r2, r3, -r1) is the u2 derivative; flipping r1 changes no sign here
        values.append(-sl[b, k] if flip else sl[b, k])
    return scale * (values[1] - values[0])


def vertical_term(y, c1, c2, half_strike, t_bot, t_top, z0, eps, sigma, kind, a, b, c, poly):
    """``int int P(t) d1^a d2^b d3^c B(y - (c1 + xi, c2, z0 + eps t)) dxi dt`` over the
    vertical rectangle, by the reduction above (``poly``: coefficients of ``P``, lowest
    first)."""
    from numpy.polynomial import polynomial as npoly
    if a == 0 and b >= 2:
        return (-vertical_term(y, c1, c2, half_strike, t_bot, t_top, z0, eps, sigma, kind, 2, b - 2, c, poly)
                - vertical_term(y, c1, c2, half_strike, t_bot, t_top, z0, eps, sigma, kind, 0, b - 2, c + 2, poly))
    poly = np.trim_zeros(np.asarray(poly, dtype=float), "b")
    ends = (y[0] - c1 - half_strike, y[0] - c1 + half_strike)
    r2 = y[1] - c2
    total = 0.0
    for i in range(len(poly)):
        m = c - 1 - i
        if m < -1:
            raise ValueError("deg P > c: not a total derivative along the dip")
        weight = (-1.0) ** i * (-eps) ** (i + 1)
        derivative = npoly.polyder(poly, i) if i else poly
        for t, side in ((t_top, 1.0), (t_bot, -1.0)):
            r3 = y[2] - (z0 + eps * t)
            if a >= 1:
                strike = (_derivative(kind, a - 1, b, m, ends[1], r2, r3, sigma)
                          - _derivative(kind, a - 1, b, m, ends[0], r2, r3, sigma))
            else:
                strike = _strike_primitive_difference(kind, b, m, ends, r2, r3, sigma)
            total += side * weight * npoly.polyval(t, derivative) * strike
    return total


def vertical_term_quadrature(y, c1, c2, half_strike, t_bot, t_top, z0, eps, sigma, kind, a, b, c, poly, n=48):
    """The same integral by an ``n x n`` Gauss rule (the check)."""
    from numpy.polynomial import polynomial as npoly
    x, w = np.polynomial.legendre.leggauss(n)
    total = 0.0
    for xi, wx in zip(x * half_strike, w * half_strike):
        for tt, wt in zip(0.5 * (t_top + t_bot) + 0.5 * (t_top - t_bot) * x, 0.5 * (t_top - t_bot) * w):
            base, _, _ = _point_tables(y[0] - c1 - xi, y[1] - c2, y[2] - (z0 + eps * tt), sigma)
            total += wx * wt * npoly.polyval(tt, poly) * base[kind, a, b, c]
    return total


def check_vertical_terms(n_terms=60, seed=3):
    """Largest relative difference of :func:`vertical_term` and the quadrature over random
    terms of the degrees the stress has (F: ``a + b >= 1``, ``deg P <= a + b + c - 4``; L:
    ``deg P <= a + b + c - 3``; ``deg P <= min(c, 3)``), for the reflection in an interface
    at z = 0 of a rectangle under it (``eps = -1``, gauge -1, receivers under the interface)
    and for a transmission (``eps = +1``, the receiver in the layer below, gauge -1)."""
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(n_terms):
        kind = int(rng.integers(2))
        while True:
            a, b, c = (int(v) for v in rng.integers(0, 5, 3))
            order = a + b + c
            top = min(c, 3, order - (4 if kind == 0 else 3))
            if a + b <= 4 and order <= 7 and top >= 0 and (kind == 1 or a + b >= 1):
                break
        poly = rng.normal(size=top + 1)
        t_bot, t_top = -1.6, -1.1  # the source: 0.5 m high, 1.1 m under the interface
        if rng.random() < 0.5:
            eps, z0 = -1.0, 0.0  # reflection: point at -t above the interface
            y = np.array([rng.uniform(-1.0, 1.0), rng.uniform(-0.6, 0.6), rng.uniform(-2.5, -0.2)])
        else:
            eps, z0 = 1.0, 0.0  # transmission to the layer under z = -2: the point stays at t
            y = np.array([rng.uniform(-1.0, 1.0), rng.uniform(-0.6, 0.6), rng.uniform(-3.5, -2.2)])
        got = vertical_term(y, 0.1, 0.05, 0.3, t_bot, t_top, z0, eps, -1.0, kind, a, b, c, poly)
        want = vertical_term_quadrature(y, 0.1, 0.05, 0.3, t_bot, t_top, z0, eps, -1.0, kind, a, b, c, poly)
        worst = max(worst, abs(got - want) / max(abs(want), 1e-300))
    return worst


def vertical_rectangle_image_stress(y, receiver_layer, center, half_strike, half_dip, source_layer, interfaces,
                                    shear_modulus, poisson_ratio, n_images):
    """``out[b, i, k]``: the complementary stress at ``y`` of a unit global DD ``b`` on the
    vertical rectangle ``e1 = x``, ``e2 = z`` (normal ``-y``) by the reduction of item 4,
    triple by triple, as :func:`.rectangle_quadrature.image_rectangle_stress` gives it by
    quadrature: each triple's coefficients are quadratic in the source height (item 1), so
    three traced heights give them exactly; the potential tables of
    :func:`.potentials3d._pair_stress_gradient` are replaced by their integrals over the
    rectangle (:func:`vertical_term`; the ``s``-weighted ones apart), and its ``_stress``
    and the moment contraction are used as they are. Derivative orders bound it to
    triples of ``D`` order <= 3 (``images`` <= 2): the tables stop at 5 horizontal
    derivatives. The prototype of :mod:`.vertical3d` (which holds more orders)."""
    from ..kernels import rectangle3d
    from .images2d import _lame, receiver_constants
    from .potentials3d import _contract, _stress
    t_bot, t_top = center[2] - half_dip, center[2] + half_dip
    heights = np.array([t_bot, center[2], t_top])
    n_pairs, layer, z, eps, sigma, coef, dcoef = trace_points(heights, source_layer, interfaces, shear_modulus,
                                                              poisson_ratio, n_images)
    inverse = np.linalg.inv(np.vander(heights, 3, increasing=True))
    g_r, delta_r, lame_r = receiver_constants(shear_modulus, poisson_ratio, receiver_layer)
    gradient = np.zeros((3, 3, 3, 3))
    for k in range(n_pairs[0]):
        if layer[0, k] != receiver_layer:
            continue
        e, sg = eps[0, k], sigma[0, k]
        z0 = z[1, k] - e * heights[1]
        assert (n_pairs == n_pairs[0]).all() and (layer[:, k] == layer[0, k]).all() and (eps[:, k] == e).all()
        assert np.allclose(z[:, k], z0 + e * heights, rtol=0.0, atol=1e-12)
        cpoly = np.einsum("pq,qfjn->fjnp", inverse, coef[:, k])  # quadratic in t, lowest first
        dpoly = np.einsum("pq,qfjn->fjnp", inverse, dcoef[:, k])
        for n in range(cpoly.shape[2]):  # the degrees of item 1 (the fit's round-off above them dropped)
            cpoly[:, :, n, min(n, 2) + 1:] = 0.0
            dpoly[:, :, n, min(n, 2):] = 0.0
        s_poly = np.array([y[2] - z0, -e])  # s = y3 - z(t)

        def table(polys, order, weighted):
            out = np.zeros((3, 3, 6, 6, 6))
            for f in range(3):
                for j in range(3):
                    if f == 2 and j == 2:
                        continue
                    kind, ia, ib = (1, 0, 0) if f == 2 else ((0, 1, 0) if (f == 0) == (j < 2) else (0, 0, 1))
                    for o in range(order, (order + 2) if j == 1 else (order + 1)):
                        if weighted and (j != 1 or o == order):
                            continue  # the s term reads t1 one order up only
                        for a in range(o + 1):
                            for b in range(o + 1 - a):
                                c = o - a - b
                                if weighted and c == 0:
                                    continue
                                value = 0.0
                                for n in range(polys.shape[2]):
                                    poly = polys[f, j, n]
                                    if weighted:
                                        poly = np.polynomial.polynomial.polymul(poly, s_poly)
                                    if np.abs(poly).max() > 0.0:
                                        value += vertical_term(y, center[0], center[1], half_strike, t_bot, t_top, z0,
                                                               e, sg, kind, a + ia, b + ib, c + n, poly)
                                out[f, j, a, b, c] = value
            return out

        plain, weighted = table(cpoly, 3, False), table(cpoly, 3, True)
        dplain, dweighted = table(dpoly, 2, False), table(dpoly, 2, True)
        for f in range(3):
            for plain_t, weighted_t, da, db, dc, scale, q in ((plain, weighted, 1, 0, 0, -1.0, 0),
                                                              (plain, weighted, 0, 1, 0, -1.0, 1),
                                                              (dplain, dweighted, 0, 0, 0, 1.0, 2),
                                                              (plain, weighted, 0, 0, 1, -e, 2)):
                _stress(plain_t, f, da, db, dc, scale, 0.0, delta_r, g_r, lame_r, gradient[f, q])
                with_s, without = np.zeros((3, 3)), np.zeros((3, 3))
                _stress(weighted_t, f, da, db, dc, scale, 1.0, delta_r, g_r, lame_r, with_s)
                _stress(weighted_t, f, da, db, dc, scale, 0.0, delta_r, g_r, lame_r, without)
                gradient[f, q] += with_s - without
            for i in range(3):
                for kk in range(3):
                    a = (i == 0) + (kk == 0)
                    b = (i == 1) + (kk == 1)
                    c = (i == 2) + (kk == 2)
                    gradient[f, 2, i, kk] += 4.0 * g_r * delta_r * e * plain[f, 1, a, b, c + 1]
    g_s, nu_s = shear_modulus[source_layer], poisson_ratio[source_layer]
    frame = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    out = np.zeros((3, 3, 3))
    _contract(gradient, frame[2], g_s, _lame(g_s, nu_s), 1.0, out)
    if receiver_layer != source_layer:  # minus the whole space of the source's material
        uniform = np.empty((3, 3, 3))
        rectangle3d.stress_pair(np.asarray(y, float), np.asarray(center, float), frame, half_strike, half_dip, g_s,
                                nu_s, 0.0, uniform, np.empty((3, 3, 3)))
        out -= uniform
    return out


def check_vertical_rectangles(seed=4):
    """Largest difference, relative to the largest entry, of
    :func:`vertical_rectangle_image_stress` and the image quadrature (12 points on 16 x 16
    sub-squares) at receivers on both sides of the interfaces: a bi-material (G 2 : 1) with
    the square 0.25 m under the interface, and a free surface over two interfaces
    (G, 2G, G, ``images=2``) with the square 0.25 m over the first one."""
    rng = np.random.default_rng(seed)
    cases = (("bi-material", np.array([0.0]), np.array([2.0, 1.0]), np.array([0.3, 0.25]), 1, 1,
              np.array([0.1, 0.05, -0.5]), (0, 1)),
             ("surface + 2 interfaces", np.array([0.0, -2.0, -4.0]), np.array([0.0, 1.0, 2.0, 1.0]),
              np.array([0.25, 0.3, 0.2, 0.25]), 2, 1, np.array([0.1, 0.05, -1.5]), (1, 2)))
    found = {}
    for name, interfaces, g, nu, n_images, layer, center, receivers in cases:
        worst = scale = 0.0
        for receiver_layer in receivers:
            top = interfaces[receiver_layer - 1] if receiver_layer > 0 else interfaces[0] + 2.0
            bottom = interfaces[receiver_layer] if receiver_layer < len(interfaces) else interfaces[-1] - 2.0
            for _ in range(4):
                y = np.array([rng.uniform(-1.0, 1.0), rng.uniform(-0.8, 0.8), rng.uniform(bottom + 0.05, top - 0.05)])
                if abs(y[1] - center[1]) < 0.2 and abs(y[2] - center[2]) < 0.35:
                    y[1] += 0.5  # away from the source (its own near field is the uniform kernel's)
                got = vertical_rectangle_image_stress(y, receiver_layer, center, 0.25, 0.25, layer, interfaces, g, nu,
                                                      n_images)
                want = np.empty((3, 3, 3))
                frame = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
                image_rectangle_stress(y, receiver_layer, center, frame, 0.25, 0.25, layer, interfaces, g, nu,
                                       n_images, 12, 16, want, False, np.zeros(len(g)), np.zeros(len(g)))
                worst = max(worst, np.abs(got - want).max())
                scale = max(scale, np.abs(want).max())
        found[name] = worst / scale
    return found


if __name__ == "__main__":
    for key, counts in coefficient_degrees().items():
        print(f"source layer {key[0]}, images={key[1]}: (D order, degree in t): triples {counts}")
    print("Okada groups against the reflected triple, G above = 0 (half-space), 0.5, 2 (nu 0.3):",
          ", ".join(f"{r:.1e}" for r in okada_group_residual()))
    print("K identities (0 each):", k_primitive_identities())
    print("vertical rectangles, terms by parts against the quadrature:", f"{check_vertical_terms():.1e}")
    print("vertical rectangles, whole image entries against the quadrature:", check_vertical_rectangles())
