"""The viscosity-dominated (M-vertex) similarity solutions of a plane-strain (KGD) and a
radial (penny) hydraulic fracture, zero toughness and zero leak-off, Newtonian fluid,
computed numerically to 1e-7 (the published constants are 0.03-1% off).

Scalings (those of :func:`hmatddm.analytical.solutions._viscosity_scales`): ``mu' = 12 mu``,
``eps = (mu'/(E' t))^(1/3)``, ``L = (E' Q^3 t^4/mu')^(1/6)`` (KGD, ``Q`` per unit height into
both wings) or ``(1/9)`` (radial); half length or radius ``gamma L``; ``w = eps L Omega(x)``,
``p_net = eps E' Pi(x)``, ``x = xi`` or ``rho`` in ``[0, 1]``.

Equations (derived from ``dw/dt + div q = 0``, ``q = -w^3 grad p / mu'``):

* lubrication, integrated once from the tip (zero flux there)::

      KGD:    Omega^3 Pi' = -gamma^2 [2/3 xi Omega + int_xi^1 Omega]
      radial: rho Omega^3 Pi' = -gamma^2 [4/9 rho^2 Omega + int_rho^1 s Omega ds]

  (from ``1/3 Omega - 2/3 xi Omega' = gamma^-2 (Omega^3 Pi')'`` and ``1/9 Omega - 4/9 rho
  Omega' = gamma^-2 rho^-1 (rho Omega^3 Pi')'``); at the source they give the flux ``Q/2``
  per wing (``gamma int_-1^1 Omega = 1``) and ``rho Omega^3 Pi' -> -1/(2 pi)`` (the log
  singularity ``Pi ~ -B ln rho``, ``2 pi B Omega(0)^3 = 1``) once the volume holds;
* elasticity as the superposition of cracks of half length (radius) ``t`` (Sneddon's
  representation; the KGD form reproduces the point-source pair ``2 - pi |xi|`` of
  :func:`hmatddm.analytical.kgd_m_vertex_profile` exactly)::

      Omega(x) = c gamma int_x^1 t F(t) / sqrt(t^2 - x^2) dt,
      KGD:    c = 4/pi, F(t) = 2 int_0^1 Pi(s t) / sqrt(1 - s^2) ds
      radial: c = 8/pi, F(t) = int_0^1 s Pi(s t) / sqrt(1 - s^2) ds

  and zero toughness is ``F(1) = 0``. Integrated by parts with it, ``F(t) = int_0^1 [k(y/t)
  1(y < t) - k(y)] Pi'(y) dy``, ``k(s) = 2 arccos s`` (KGD) or ``sqrt(1 - s^2)`` (radial):
  the opening is given by the pressure gradient, which lubrication gives, and ``K = 0`` holds
  by construction;
* volume: ``gamma int_-1^1 Omega = 1`` (KGD), ``2 pi gamma^2 int_0^1 Omega rho d rho = 1``.

With ``Omega = gamma W`` the system does not depend on ``gamma`` (``Pi`` neither): ``W = T(W)``
is solved by Newton's method, then ``gamma`` follows from the volume.

Converged constants (module constants below; 16 points give them to 1e-6, 24 to 1e-8; the
tip coefficient is the exact ``beta_m (V t/L)^(1/3) gamma^(2/3)``, ``beta_m = 2^(1/3) 3^(5/6)``,
to 1e-9, although nothing imposes it; other maps ``x(tau)`` give the same digits to 1e-9;
the least-squares power-law series of :mod:`.power_law` at ``n = 1``, an independent method,
gives gamma to 4e-7; benchmarks/bench_m_vertex.py and benchmarks/RESULTS.md, issue 39)::

    KGD:    gamma = 0.6154113,  Omega(0) = 1.1258346,  Pi(0) = 0.5448171
    radial: gamma = 0.6978376,  Omega(0) = 1.1932560,  B = 0.0936740

The published truncated series differ from them by: KGD (Adachi and Detournay 2002, seven
terms) gamma -0.03%, Omega(0) -0.23%, Pi(0) -0.09%; radial (Savitski and Detournay 2002,
zero order) gamma -0.34%, Omega(0) +0.37%, B -1.05%; Dontsov (2016) gamma -0.49%, Omega(0)
-0.26%.

Discretisation: ``W = (1 - x)^(2/3) w(tau)`` with ``x = 1 - (1 - tau^2)^6``, ``w`` a polynomial
in ``tau`` interpolated at ``n`` Chebyshev points of ``[0, 1]``. The map turns the viscous tip
``(1 - x)^(2/3)`` into ``(1 - tau^2)^4`` and the weaker terms (fractional powers of ``1 - x``
above 2/3 at the tip, the source's ``x^2 ln x``) into smooth functions of ``tau``;
``-Pi' (1 - x)^(4/3)`` (times ``rho``, radial) and ``F / (1 - x)^(1/6)`` are interpolated in the
same way (radial: ``F + B ln t``, whose log part opens a cone ``8 B / pi (sqrt(1 - rho^2) - rho
arccos rho)``). The integrals of the kernels against the interpolants are done once per ``n``
by Gauss rules graded toward their singular points.
"""
import functools

import numpy as np

from ..errors import ConvergenceError, InputError

_MAP_POWER = 6  # x = 1 - (1 - tau^2)^6
_GAUSS = 16  # points of a Gauss-Legendre panel
_FAR_LEVELS = 8  # halvings toward the tip of the last panel of a graded rule ending there

# The converged constants (32 points; changes below 1e-8 from 24 to 64 points and between maps)
KGD_M_GAMMA_ACCURATE = 0.6154113  # l / L, accurate to 1e-7
KGD_M_OPENING_ACCURATE = 1.1258346  # Omega(0) = w(0) / (eps L), accurate to 1e-7
KGD_M_PRESSURE_ACCURATE = 0.5448171  # Pi(0) = p(0) / (eps E'), accurate to 1e-7
RADIAL_M_GAMMA_ACCURATE = 0.6978376  # R / L, accurate to 1e-7
RADIAL_M_OPENING_ACCURATE = 1.1932560  # Omega(0), accurate to 1e-7
RADIAL_M_LOG_COEFFICIENT_ACCURATE = 0.0936740  # B of Pi ~ -B ln rho, = 1 / (2 pi Omega(0)^3)


def _nodes(n):
    """Chebyshev points of the first kind on [0, 1] (ascending) and their barycentric weights."""
    j = np.arange(n)
    theta = (2 * j + 1) * np.pi / (2 * n)
    return 0.5 * (1.0 - np.cos(theta)), (-1.0) ** j * np.sin(theta)


def _lagrange(tau, n):
    """Values ``(len(tau), n)`` of the Lagrange basis of the ``n`` Chebyshev points at ``tau``."""
    nodes, weights = _nodes(n)
    tau = np.atleast_1d(np.asarray(tau, dtype=float))
    diff = tau[:, None] - nodes[None, :]
    exact = diff == 0.0
    diff[exact] = 1.0
    terms = weights[None, :] / diff
    basis = terms / terms.sum(axis=1, keepdims=True)
    rows = exact.any(axis=1)
    basis[rows] = exact[rows].astype(float)
    return basis


def _gap(tau):
    """``1 - x = (1 - tau^2)^6`` computed without cancellation, and ``x``."""
    gap = (np.clip(1.0 - tau, 0.0, None) * (1.0 + tau)) ** _MAP_POWER
    return gap, 1.0 - gap


def _dx_dtau(tau):
    return 2.0 * _MAP_POWER * tau * ((1.0 - tau) * (1.0 + tau)) ** (_MAP_POWER - 1)


@functools.lru_cache(maxsize=8)
def _legendre(m):
    return np.polynomial.legendre.leggauss(m)


def _gauss(a, b, m=_GAUSS):
    u, w = _legendre(m)
    return 0.5 * (b - a) * u + 0.5 * (a + b), 0.5 * (b - a) * w


def _graded(a, b, at_a, scale):
    """Nodes and weights on ``[a, b]`` graded toward ``a`` (``at_a``) or ``b`` with a first panel
    of length ``scale`` and ratio 2: a square-root end there (substituted ``u^2``) and any
    near-singular point at distance ~``scale`` beyond it are integrated to round-off."""
    length = b - a
    if length <= 0.0:
        return np.zeros(0), np.zeros(0)
    edges, h = [0.0], scale
    while edges[-1] < length:
        end = edges[-1] + h
        edges.append(length if end > length - 0.5 * h else end)  # no sliver of a last panel
        h *= 2.0
    if at_a and b == 1.0 and _FAR_LEVELS:  # also grade toward the tip tau = 1 (the far end)
        lo, hi = edges[-2], edges[-1]
        edges = edges[:-1] + [hi - (hi - lo) * 0.5**k for k in range(1, _FAR_LEVELS + 1)] + [hi]
    xs, ws = [], []
    for k in range(len(edges) - 1):
        lo, hi = edges[k], edges[k + 1]
        if k == 0:  # d = hi u^2 removes the square root at the end
            u, wu = _gauss(0.0, 1.0)
            d, wd = hi * u * u, 2.0 * hi * u * wu
        else:
            d, wd = _gauss(lo, hi)
        xs.append(d)
        ws.append(wd)
    d, w = np.concatenate(xs), np.concatenate(ws)
    return (a + d, w) if at_a else (b - d, w)


def _k_kernel(radial, one_minus_s, s):
    """``k(s)`` from ``1 - s`` (no cancellation near ``s = 1``): ``2 arccos s`` or ``sqrt(1 - s^2)``."""
    one_minus_s = np.clip(one_minus_s, 0.0, None)
    if radial:
        return np.sqrt(one_minus_s * (1.0 + s))
    return 4.0 * np.arcsin(np.sqrt(0.5 * one_minus_s))


@functools.lru_cache(maxsize=16)
def _operators(n, radial):
    """The linear maps of the discrete system at ``n`` points (cached).

    Returns ``(tau, x, gap, flux, force, opening)``: ``flux @ w`` is the bracket of the
    integrated lubrication divided by ``(1 - x)^(2/3)``; ``force @ p`` is ``F / (1 - x)^(1/6)`` at
    the points for ``-Pi' = p / (x^a (1 - x)^(4/3))`` (``a = 1`` radial, 0 KGD); ``opening @ f``
    is ``W / (1 - x)^(2/3)`` for ``F = (1 - x)^(1/6) f``."""
    tau, _ = _nodes(n)
    gap, x = _gap(tau)
    c = 8.0 / np.pi if radial else 4.0 / np.pi
    # flux: int_x^1 s^a W ds / (1 - x)^(2/3), W = gap^(2/3) w (polynomial in tau: exact Gauss)
    flux = np.empty((n, n))
    for i in range(n):
        t, wt = _graded(tau[i], 1.0, True, 1.0 - tau[i])
        g, s = _gap(t)
        weight = wt * _dx_dtau(t) * g ** (2.0 / 3.0) * (s if radial else 1.0)
        flux[i] = weight @ _lagrange(t, n) / gap[i] ** (2.0 / 3.0)
    lead = 4.0 / 9.0 * x * x if radial else 2.0 / 3.0 * x
    flux += np.diag(lead)
    # force: F(t_i) = -int K(t_i, y) p(y) / (y^a (1 - y)^(4/3)) dy, K = k(y/t) 1(y<t) - k(y)
    force = np.empty((n, n))
    for i in range(n):
        t_gap, t_x = gap[i], x[i]
        scale = min(1.0 - tau[i], tau[i])
        u, wu = _graded(0.0, tau[i], False, scale)
        gu, yu = _gap(u)
        jac = _dx_dtau(u) / gu ** (4.0 / 3.0) / (yu if radial else 1.0)
        inner = _k_kernel(radial, (gu - t_gap) / t_x, yu / t_x) - _k_kernel(radial, gu, yu)
        v, wv = _graded(tau[i], 1.0, True, scale)
        gv, yv = _gap(v)
        jac_v = _dx_dtau(v) / gv ** (4.0 / 3.0) / (yv if radial else 1.0)
        row = (wu * inner * jac) @ _lagrange(u, n) - (wv * _k_kernel(radial, gv, yv) * jac_v) @ _lagrange(v, n)
        force[i] = -row / t_gap ** (1.0 / 6.0)
    # opening: W(x_i) = c int_x^1 t F(t) / sqrt(t^2 - x^2) dt, F = (1 - t)^(1/6) f
    opening = np.empty((n, n))
    for i in range(n):
        scale = min(1.0 - tau[i], tau[i])
        v, wv = _graded(tau[i], 1.0, True, scale)
        gv, tv = _gap(v)
        root = np.sqrt((gap[i] - gv) * (tv + x[i]))
        opening[i] = c * (wv * _dx_dtau(v) * tv * gv ** (1.0 / 6.0) / root) @ _lagrange(v, n) / gap[i] ** (2.0 / 3.0)
    if radial:  # F = (1 - t)^(1/6) f - B ln t, B = p(0): the log part's opening is a cone
        source = _lagrange([0.0], n)[0]
        force += np.outer(np.log(x) / gap ** (1.0 / 6.0), source)
        opening_log = c * _cone(gap) / gap ** (2.0 / 3.0)
        return tau, x, gap, flux, force, opening, np.outer(opening_log, source)
    return tau, x, gap, flux, force, opening, np.zeros((n, n))


def _cone(gap):
    """``sqrt(1 - x^2) - x arccos x = int_0^(1-x) 2 arcsin(sqrt(e/2)) de`` (no cancellation at the tip)."""
    v, wv = _gauss(0.0, 1.0)
    gap = np.atleast_1d(gap)
    e = gap[:, None] * v[None, :] ** 2
    return (4.0 * np.arcsin(np.sqrt(0.5 * e)) * gap[:, None] * v[None, :]) @ wv


def _solve_scaled(n, radial, tol=1e-13, max_iter=50):
    """Newton on ``w = G p(w)``, ``G = opening @ force (+ the radial cone)``, with ``p = -Pi' x^a
    (1 - x)^(4/3) = (flux @ w) / w^3``; returns ``w`` at the points."""
    tau, x, gap, flux, force, opening, opening_log = _operators(n, radial)
    g = opening @ force + opening_log
    w = np.full(n, 1.7 if radial else 1.8)
    for _ in range(max_iter):
        lam = flux @ w
        p = lam / w**3
        residual = w - g @ p
        dp = flux / (w**3)[:, None] - np.diag(3.0 * lam / w**4)
        step = np.linalg.solve(np.eye(n) - g @ dp, -residual)
        w = w + step
        if np.max(np.abs(step)) < tol * np.max(np.abs(w)):
            break
    else:
        raise ConvergenceError(f"M-vertex Newton iteration did not converge (n = {n})",
                               residual=float(np.max(np.abs(residual))), iterations=max_iter)
    return w


class MVertexSolution:
    """One computed M-vertex similarity solution (see the module's docstring).

    Attributes: ``radial`` (bool), ``n`` (points), ``gamma`` (half length or radius over
    ``L``), ``opening_at_source`` (``Omega(0)``), ``pressure_at_source`` (``Pi(0)``, KGD; the
    radial pressure is log-singular there: ``None``), ``log_coefficient`` (radial ``B`` of
    ``Pi ~ -B ln rho``, ``2 pi B Omega(0)^3 = 1``; KGD ``None``), ``tip_coefficient``
    (``lim Omega / (1 - x)^(2/3)``, to compare with ``beta_m (V t / L)^(1/3) gamma^(2/3)``).
    Methods :meth:`opening` and :meth:`pressure` give ``Omega`` and ``Pi`` at ``x`` in
    ``[0, 1)`` (``xi = x / l`` or ``rho = r / R``).
    """

    def __init__(self, radial, n):
        self.radial, self.n = bool(radial), _checked_points(n)
        self._w = _solve_scaled(self.n, self.radial)
        self._p = (_operators(self.n, self.radial)[3] @ self._w) / self._w**3
        t, wt = _graded(0.0, 1.0, True, 0.5)
        gap, x = _gap(t)
        moment = np.sum(wt * _dx_dtau(t) * gap ** (2.0 / 3.0) * self._interpolate(self._w, t) * (x if radial else 1.0))
        self.gamma = (2.0 * np.pi * moment) ** (-1.0 / 3.0) if radial else (2.0 * moment) ** -0.5
        self.opening_at_source = self.gamma * self._interpolate(self._w, 0.0)[0]
        self.tip_coefficient = self.gamma * self._interpolate(self._w, 1.0)[0]
        if radial:
            self.log_coefficient = self._interpolate(self._p, 0.0)[0]
            self.pressure_at_source = None
            # K = 0 with Pi = -B ln rho + R: R(0) = -B (1 - ln 2) - int_0^1 R' sqrt(1 - s^2) ds
            self._r0 = -self.log_coefficient * (1.0 - np.log(2.0)) - np.sum(
                wt * self._regular_slope(t) * np.sqrt(gap * (1.0 + x)))
        else:
            self.log_coefficient = None
            # K = 0: Pi(0) = -(2/pi) int_0^1 arccos(y) Pi'(y) dy
            arccos = 2.0 * np.arcsin(np.sqrt(0.5 * gap))
            self.pressure_at_source = 2.0 / np.pi * np.sum(
                wt * arccos * self._interpolate(self._p, t) * _dx_dtau(t) / gap ** (4.0 / 3.0))

    def _interpolate(self, values, tau):
        return _lagrange(tau, self.n) @ values

    def _regular_slope(self, tau):
        """``dR/dx * dx/dtau`` of the radial ``R = Pi + B ln x`` (finite everywhere)."""
        gap, x = _gap(tau)
        slope = (self.log_coefficient - self._interpolate(self._p, tau) / gap ** (4.0 / 3.0)) / x
        return slope * _dx_dtau(tau)

    @staticmethod
    def _tau(x, name):
        x = np.asarray(x, dtype=float)
        if not np.all(np.isfinite(x)) or np.any((x < 0.0) | (x >= 1.0)):
            raise InputError(f"{name} must be finite and in [0, 1) (inside the fracture)")
        return np.sqrt(1.0 - (1.0 - x) ** (1.0 / _MAP_POWER)), x

    def opening(self, x):
        """``Omega(x)``: the opening in units of ``eps L`` at ``x = xi`` or ``rho`` in ``[0, 1)``."""
        tau, x = self._tau(x, "x")
        flat = tau.ravel()
        return (self.gamma * _gap(flat)[0] ** (2.0 / 3.0) * self._interpolate(self._w, flat)).reshape(x.shape)

    def pressure(self, x):
        """``Pi(x)``: the net pressure in units of ``eps E'``; radial ``+inf`` at ``rho = 0``."""
        tau, x = self._tau(x, "x")
        out = np.empty(tau.size)
        for k, (tk, xk) in enumerate(zip(tau.ravel(), x.ravel())):
            u, wu = _graded(0.0, tk, False, min(1.0 - tk, tk) if tk > 0 else 1.0)
            gu = _gap(u)[0]
            if self.radial:
                integral = np.sum(wu * self._regular_slope(u))
                out[k] = np.inf if xk == 0.0 else self._r0 + integral - self.log_coefficient * np.log(xk)
            else:
                integral = np.sum(wu * self._interpolate(self._p, u) * _dx_dtau(u) / gu ** (4.0 / 3.0))
                out[k] = self.pressure_at_source - integral
        return out.reshape(x.shape)


def _checked_points(points):
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or not 8 <= points <= 128:
        raise InputError(f"points must be an integer in [8, 128], got {points!r}")
    return int(points)


def kgd_m_vertex_numeric(points=32):
    """The plane-strain (KGD) M-vertex computed at ``points`` Chebyshev points
    (:class:`MVertexSolution`); 16 points give the constants to 1e-6, 24 to 1e-8."""
    return MVertexSolution(False, _checked_points(points))


def radial_m_vertex_numeric(points=32):
    """The radial (penny) M-vertex computed at ``points`` Chebyshev points
    (:class:`MVertexSolution`); 16 points give the constants to 1e-6, 24 to 1e-8."""
    return MVertexSolution(True, _checked_points(points))
