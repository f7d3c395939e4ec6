"""Solving the DDM system and evaluating its results (ref. Sec. 2.3, Eqs 2.47-2.49).

* :func:`solve` finds the DDs whose traction equals a given load: direct LU for the
  ``dense`` backend, GMRES preconditioned by the near field for ``hmatrix``.
* :func:`opening`, :func:`slip`: normal and tangential parts of the DD.
* :func:`stress_at`, :func:`mean_stress_at`: the stress the DDs induce anywhere
  (ref. Eq. 2.59; mean stress as in ref. Eqs 5.24-5.28).
"""
import numpy as np

from ._validation import finite_array, finite_scalar
from .errors import ConvergenceError, InputError
from .kernels import element_data, kernel_module
from .material import Elastic
from .mesh import Mesh2D, Mesh3D


def _as_element_major(name, values, n_elements, dof):
    array = finite_array(name, values)
    if array.shape == (n_elements, dof):
        return array.reshape(-1)
    if array.shape == (n_elements * dof,):
        return array
    raise InputError(f"{name} must have shape ({n_elements}, {dof}) or ({n_elements * dof},), got {array.shape}")


def solve(operator, traction, rtol=1e-10, maxiter=None, restart=100, x0=None, return_info=False):
    """DDs (N, d) in the global frame such that ``operator @ dd = traction``.

    Parameters
    ----------
    operator : ElasticityOperator
    traction : (N, d) or (N*d,) array
        Traction sigma.n at the collocation points, element-major, global frame
        (``-p * mesh.normals`` for a crack under net pressure ``p``).
    rtol : float
        Relative residual ``||b - A x|| / ||b||`` asked of GMRES (``hmatrix``), in (0, 1).
        The dense backend solves directly (LU) and ignores it.
    maxiter, restart : int
        GMRES limits (``maxiter`` counts restart cycles; default allows 20 cycles).
    x0 : optional initial guess, same shapes as ``traction``.
    return_info : bool
        Also return a dict with ``iterations`` and ``residual``.

    Raises
    ------
    ConvergenceError
        GMRES stopped above ``rtol``; the message and ``.residual`` give what was reached.
    """
    from .operators import ElasticityOperator

    if not isinstance(operator, ElasticityOperator):
        raise InputError(f"operator must be an ElasticityOperator, got {type(operator).__name__}")
    rtol = finite_scalar("rtol", rtol)
    if not 0.0 < rtol < 1.0:
        raise InputError(f"rtol must be in (0, 1), got {rtol}")
    n, d = operator.mesh.n_elements, operator.dof
    b = _as_element_major("traction", traction, n, d)
    if operator.backend == "dense":
        import scipy.linalg

        x = scipy.linalg.lu_solve(operator.lu(), b, check_finite=False)
        residual = float(np.linalg.norm(operator.matvec(x) - b) / max(np.linalg.norm(b), np.finfo(float).tiny))
        info = dict(iterations=0, residual=residual)
    else:
        from .hmatrix import gmres

        guess = None if x0 is None else _as_element_major("x0", x0, n, d)
        x, info = gmres(operator, b, M=operator.preconditioner(), rtol=rtol, restart=restart,
                        maxiter=maxiter if maxiter is not None else 20, x0=guess)
    if not np.all(np.isfinite(x)):
        raise ConvergenceError("the solution contains NaN or inf", residual=float("nan"))
    dd = x.reshape(n, d)
    return (dd, info) if return_info else dd


def _dd_array(mesh, dd):
    return _as_element_major("dd", dd, mesh.n_elements, mesh.dim).reshape(mesh.n_elements, mesh.dim)


def opening(mesh, dd):
    """Opening ``w = DD . n`` (N,), positive for an open crack (DESIGN.md section 1)."""
    dd = _dd_array(mesh, dd)
    return np.einsum("ij,ij->i", dd, mesh.normals)


def slip(mesh, dd):
    """Tangential part of the DD, ``DD - w n`` (N, d), in the global frame."""
    dd = _dd_array(mesh, dd)
    return dd - opening(mesh, dd)[:, None] * mesh.normals


def _check_points(mesh, points):
    return np.ascontiguousarray(finite_array("points", points, (None, mesh.dim)))


def stress_at(mesh, material, dd, points, singular_correction="none"):
    """Stress (M, d, d) induced at ``points`` (M, d) by the DDs ``dd`` (global frame).

    Direct summation over all elements (O(M N), parallel over points). In 2D the
    in-plane components of the plane-strain stress are returned. Points on an element
    edge raise :class:`InputError` unless ``singular_correction="average"``.
    """
    if not isinstance(mesh, (Mesh2D, Mesh3D)):
        raise InputError(f"mesh must be a Mesh2D or Mesh3D, got {type(mesh).__name__}")
    if not isinstance(material, Elastic):
        raise InputError(f"material must be an hmatddm.Elastic, got {type(material).__name__}")
    if singular_correction not in ("none", "average"):
        raise InputError(f"singular_correction must be one of ('none', 'average'), got {singular_correction!r}")
    dd = np.ascontiguousarray(_dd_array(mesh, dd))
    points = _check_points(mesh, points)
    shift = 1e-3 if singular_correction == "average" else 0.0
    centers, frames, half_a, half_b, params, _ = element_data(mesh, material, singular_shift=shift)
    out = np.empty((len(points), mesh.dim, mesh.dim))
    kernels = kernel_module(mesh)
    if mesh.dim == 2:
        kernels.stress_at_points(points, centers, frames, half_a, params, dd, out)
    else:
        kernels.stress_at_points(points, centers, frames, half_a, half_b, params, dd, out)
    bad = np.flatnonzero(~np.all(np.isfinite(out.reshape(len(points), -1)), axis=1))
    if bad.size:
        raise InputError(f"points[{int(bad[0])}] lies on an element edge, where the stress is singular; "
                         "move it or pass singular_correction='average'")
    return out


def mean_stress_at(mesh, material, dd, points):
    """Mean stress ``tr(sigma)/3`` (M,) induced at ``points`` (ref. Eqs 5.24-5.28).

    In 2D (plane strain) ``sigma_zz = nu (sigma_xx + sigma_yy)`` is included, so the
    mean stress is ``(1 + nu)(sigma_xx + sigma_yy) / 3``.
    """
    stress = stress_at(mesh, material, dd, points)
    trace = np.trace(stress, axis1=1, axis2=2)
    if mesh.dim == 2:
        return (1.0 + material.poisson_ratio) * trace / 3.0
    return trace / 3.0
