"""Independent half-space reference: Mindlin's (1936) point-force solution, and from it
the displacement and stress of a rectangular displacement discontinuity (DD) by Gauss
quadrature through reciprocity. Written apart from the code under test (no import from
hmatddm), as ``tests/kelvin_reference.py`` is for the full space.

Mindlin's frame: the solid is ``X3 > 0`` (depth), the free surface ``X3 = 0``, a unit
force at depth ``c`` on the ``X3`` axis. With ``R1 = |X - (0, 0, c)|``,
``R2 = |X - (0, 0, -c)|`` (the image point), the displacement of a unit force along
``X3`` and along ``X1`` is written out below (Mindlin 1936, eqs for the "force at a
point in the interior of a semi-infinite solid"). The tests check this transcription
against the three properties that determine it uniquely: Kelvin's singular part near
the source (and the whole Kelvin field deep below the surface), a traction-free surface,
and equilibrium (Navier's equation) everywhere in the solid.

Our frame (docs/conventions.md §3): ``z`` up, the solid is ``z < surface``. So
``X = (x, y, surface - z)``, and vectors flip their third component.

Derivatives are exact to round-off: the formulas are evaluated on hyper-dual numbers
``f + a e1 + b e2 + c e1 e2`` (``e1^2 = e2^2 = 0``), which carry first and mixed second
derivatives through +, -, *, / and sqrt.

DD field by reciprocity (Betti): with ``G_ak(y; x)`` the displacement at ``y`` along
``a`` of a unit force along ``k`` at ``x``, and ``DD = u(+) - u(-)`` on a surface of
normal ``n`` (pointing to the + side),

    u_k(x) = int DD_r(y) sigma_rs^(k)(y; x) n_s(y) dS(y),
    sigma_rs^(k)(y; x) = lambda delta_rs dG_ak/dy_a + G (dG_rk/dy_s + dG_sk/dy_r),

and the stress at ``x`` is Hooke's law of ``du_k/dx_l``: mixed second derivatives of
``G`` in the field point ``y`` and the source point ``x``.
"""
import numpy as np


class HyperDual:
    """Arrays ``f + a e1 + b e2 + ab e1 e2`` with ``e1^2 = e2^2 = 0``."""

    __array_priority__ = 100

    def __init__(self, f, a=0.0, b=0.0, ab=0.0):
        self.f, self.a, self.b, self.ab = f, a, b, ab

    @staticmethod
    def _wrap(other):
        return other if isinstance(other, HyperDual) else HyperDual(other)

    def __add__(self, other):
        o = self._wrap(other)
        return HyperDual(self.f + o.f, self.a + o.a, self.b + o.b, self.ab + o.ab)

    __radd__ = __add__

    def __neg__(self):
        return HyperDual(-self.f, -self.a, -self.b, -self.ab)

    def __sub__(self, other):
        return self + (-self._wrap(other))

    def __rsub__(self, other):
        return self._wrap(other) + (-self)

    def __mul__(self, other):
        o = self._wrap(other)
        return HyperDual(self.f * o.f, self.f * o.a + self.a * o.f, self.f * o.b + self.b * o.f,
                         self.f * o.ab + self.a * o.b + self.b * o.a + self.ab * o.f)

    __rmul__ = __mul__

    def _chain(self, g, g1, g2):
        return HyperDual(g, g1 * self.a, g1 * self.b, g1 * self.ab + g2 * self.a * self.b)

    def reciprocal(self):
        inv = 1.0 / self.f
        return self._chain(inv, -inv * inv, 2.0 * inv * inv * inv)

    def __truediv__(self, other):
        return self * self._wrap(other).reciprocal()

    def __rtruediv__(self, other):
        return self._wrap(other) * self.reciprocal()

    def sqrt(self):
        root = np.sqrt(self.f)
        return self._chain(root, 0.5 / root, -0.25 / (root * self.f))


def _sqrt(value):
    return value.sqrt() if isinstance(value, HyperDual) else np.sqrt(value)


def mindlin_displacement(x1, x2, x3, c, nu, shear_modulus):
    """Mindlin's displacement (3, 3) nested lists ``U[i][j]``: component ``i`` of a unit
    force along ``X_j`` at ``(0, 0, c)``, field point ``(x1, x2, x3)``, ``x3 > 0``
    (floats, arrays or HyperDual)."""
    k = 1.0 / (16.0 * np.pi * shear_modulus * (1.0 - nu))
    a34 = 3.0 - 4.0 * nu
    b = 4.0 * (1.0 - nu) * (1.0 - 2.0 * nu)
    zm, zp = x3 - c, x3 + c
    r1 = _sqrt(x1 * x1 + x2 * x2 + zm * zm)
    r2 = _sqrt(x1 * x1 + x2 * x2 + zp * zp)
    i1, i2 = 1.0 / r1, 1.0 / r2
    i13, i23 = i1 * i1 * i1, i2 * i2 * i2
    i25 = i23 * i2 * i2
    s = r2 + zp
    i_s = 1.0 / s

    def horizontal(xa, xb):
        """u_a, u_b, u_3 of a unit force along the horizontal axis a (xb: the other)."""
        ua = k * (a34 * i1 + i2 + xa * xa * i13 + a34 * xa * xa * i23 + 2.0 * c * x3 * i23 * (1.0 - 3.0 * xa * xa * i2 * i2)
                  + b * i_s * (1.0 - xa * xa * i2 * i_s))
        ub = k * xa * xb * (i13 + a34 * i23 - 6.0 * c * x3 * i25 - b * i2 * i_s * i_s)
        u3 = k * xa * (zm * i13 + a34 * zm * i23 - 6.0 * c * x3 * zp * i25 + b * i2 * i_s)
        return ua, ub, u3

    def vertical(xa):
        """u_a of a unit force along X3."""
        return k * xa * (zm * i13 + a34 * zm * i23 - b * i2 * i_s + 6.0 * c * x3 * zp * i25)

    u11, u21, u31 = horizontal(x1, x2)
    u22, u12, u32 = horizontal(x2, x1)
    u13, u23 = vertical(x1), vertical(x2)
    u33 = k * (a34 * i1 + (8.0 * (1.0 - nu) ** 2 - a34) * i2 + zm * zm * i13
               + (a34 * zp * zp - 2.0 * c * x3) * i23 + 6.0 * c * x3 * zp * zp * i25)
    return [[u11, u12, u13], [u21, u22, u23], [u31, u32, u33]]


_FLIP = np.array([1.0, 1.0, -1.0])  # our frame <-> Mindlin's (z up <-> depth down)


def green(field, source, surface, nu, shear_modulus, seeds=None):
    """Half-space Green's function in our frame (solid below ``z = surface``): nested
    lists ``G[a][k]``, displacement along ``a`` at ``field`` (Q, 3) of a unit force
    along ``k`` at ``source`` (3,). ``seeds``: ``(field_direction, source_direction)``
    unit vectors (or None) whose derivatives are carried on the e1 and e2 parts."""
    field = np.atleast_2d(np.asarray(field, dtype=np.float64))
    coords = []
    for axis in range(3):
        x = field[:, axis] - (source[axis] if axis < 2 else 0.0)
        if seeds is not None:
            d_field = 0.0 if seeds[0] is None else seeds[0][axis]
            d_source = 0.0 if seeds[1] is None else seeds[1][axis]
            if axis < 2:  # relative horizontal coordinate: field minus source
                x = HyperDual(x, np.full_like(x, d_field), np.full_like(x, -d_source), np.zeros_like(x))
            else:
                x = HyperDual(x, np.full_like(x, d_field), np.zeros_like(x), np.zeros_like(x))
        coords.append(x)
    depth = surface - coords[2]
    c = surface - source[2]
    if seeds is not None and seeds[1] is not None:
        c = HyperDual(np.full(len(field), c), np.zeros(len(field)), np.full(len(field), -seeds[1][2]),
                      np.zeros(len(field)))
    u = mindlin_displacement(coords[0], coords[1], depth, c, nu, shear_modulus)
    return [[_FLIP[a] * _FLIP[k] * u[a][k] for k in range(3)] for a in range(3)]


def _parts(value, part, n):
    if isinstance(value, HyperDual):
        return np.broadcast_to(getattr(value, part), (n,))
    return np.broadcast_to(value if part == "f" else 0.0, (n,))


def green_gradient(field, source, surface, nu, shear_modulus):
    """``dG_ak/dy_b`` at the field points: array (Q, a, k, b)."""
    field = np.atleast_2d(field)
    out = np.zeros((len(field), 3, 3, 3))
    for b, direction in enumerate(np.eye(3)):
        g = green(field, source, surface, nu, shear_modulus, seeds=(direction, None))
        for a in range(3):
            for k in range(3):
                out[:, a, k, b] = _parts(g[a][k], "a", len(field))
    return out


def green_mixed(field, source, surface, nu, shear_modulus):
    """``d^2 G_ak / dy_b dx_l`` (field y, source x): array (Q, a, k, b, l), and ``dG/dy``
    (Q, a, k, b)."""
    field = np.atleast_2d(field)
    mixed = np.zeros((len(field), 3, 3, 3, 3))
    first = np.zeros((len(field), 3, 3, 3))
    for b, d_field in enumerate(np.eye(3)):
        for l, d_source in enumerate(np.eye(3)):
            g = green(field, source, surface, nu, shear_modulus, seeds=(d_field, d_source))
            for a in range(3):
                for k in range(3):
                    mixed[:, a, k, b, l] = _parts(g[a][k], "ab", len(field))
                    if l == 0:
                        first[:, a, k, b] = _parts(g[a][k], "a", len(field))
    return mixed, first


def hooke(gradient, nu, shear_modulus):
    """Stress from a displacement gradient ``du_i/dx_j`` in the last two axes."""
    lam = 2.0 * shear_modulus * nu / (1.0 - 2.0 * nu)
    strain = 0.5 * (gradient + np.swapaxes(gradient, -1, -2))
    trace = np.trace(strain, axis1=-2, axis2=-1)
    return lam * trace[..., None, None] * np.eye(3) + 2.0 * shear_modulus * strain


def point_force_stress(field, source, surface, nu, shear_modulus):
    """Stress at ``field`` (Q, 3) of unit forces along each axis k at ``source``:
    array (Q, k, i, j)."""
    grad = green_gradient(field, source, surface, nu, shear_modulus)  # (Q, a, k, b)
    return hooke(np.transpose(grad, (0, 2, 1, 3)), nu, shear_modulus)


def rectangle_quadrature(center, e1, e2, a, b, order=12, panels=4):
    """Composite Gauss-Legendre rule on the rectangle ``center + s e1 + t e2``,
    ``|s| <= a``, ``|t| <= b``: ``panels x panels`` panels of ``order x order`` points."""
    xg, wg = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(-1.0, 1.0, panels + 1)
    mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * (edges[1:] - edges[:-1])
    u = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
    w = (half[:, None] * wg[None, :]).ravel()
    s, t = np.meshgrid(a * u, b * u, indexing="ij")
    weights = np.outer(a * w, b * w).ravel()
    points = np.asarray(center) + s.reshape(-1, 1) * np.asarray(e1) + t.reshape(-1, 1) * np.asarray(e2)
    return points, weights


def dd_fields(x, center, frame, a, b, surface, nu, shear_modulus, order=12, panels=4):
    """Displacement and stress at ``x`` (3,) of a unit DD along each global axis on the
    rectangle ``(center, frame = (e1, e2, n), half sizes a, b)`` in the half-space below
    ``z = surface``: arrays ``u (r, k)`` and ``sigma (r, i, j)`` (``r``: the DD component)."""
    e1, e2, normal = (np.asarray(v, dtype=np.float64) for v in frame)
    points, weights = rectangle_quadrature(center, e1, e2, a, b, order, panels)
    x = np.asarray(x, dtype=np.float64)
    mixed, first = green_mixed(points, x, surface, nu, shear_modulus)
    lam = 2.0 * shear_modulus * nu / (1.0 - 2.0 * nu)
    eye = np.eye(3)
    # traction on the element of the point-force field: t_r^(k) = sigma_rs^(k) n_s
    div = np.einsum("qaka->qk", first)
    traction = (lam * div[:, None, :] * normal[:, None]  # (q, r, k)
                + shear_modulus * (np.einsum("qrks,s->qrk", first, normal)
                                   + np.einsum("qskr,s->qrk", first, normal)))
    u = np.einsum("q,qrk->rk", weights, traction)
    div_l = np.einsum("qakal->qkl", mixed)
    d_traction = (lam * div_l[:, None, :, :] * normal[None, :, None, None]
                  + shear_modulus * (np.einsum("qrksl,s->qrkl", mixed, normal)
                                     + np.einsum("qskrl,s->qrkl", mixed, normal)))
    grad = np.einsum("q,qrkl->rkl", weights, d_traction)  # du_k/dx_l per DD component r
    del eye
    return u, hooke(grad, nu, shear_modulus)
