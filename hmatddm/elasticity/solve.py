"""Solving the DDM system and reading its results (ref. Sec. 2.3, Eqs 2.47-2.49).

* :func:`solve` finds the DDs whose traction equals a given load: direct LU for the
  ``dense`` backend, GMRES preconditioned by the near field for ``hmatrix``.
* :func:`opening`, :func:`slip`: normal and tangential parts of the DD.
* :func:`stress_at`, :func:`mean_stress_at`: the stress the DDs induce anywhere
  (ref. Eq. 2.59; mean stress as in ref. Eqs 5.24-5.28), picking the evaluation for the
  mesh and medium: :mod:`hmatddm.elasticity.fields` (constant elements, homogeneous medium: exact
  sum or the points x elements H-matrix), :mod:`hmatddm.elasticity.nodal` (linear and quadratic
  elements), :mod:`hmatddm.layered.influence2d` (a layered medium).
"""
import numpy as np

from .._validation import finite_array, finite_scalar
from ..errors import InputError
from ..layered.medium import LayeredMedium


def _as_element_major(name, values, n_elements, dof):
    array = finite_array(name, values)
    if array.shape == (n_elements, dof):
        return array.reshape(-1)
    if array.shape == (n_elements * dof,):
        return array
    raise InputError(f"{name} must have shape ({n_elements}, {dof}) or ({n_elements * dof},), got {array.shape}")


def solve(operator, traction, rtol=1e-10, maxiter=None, restart=100, x0=None, return_info=False):
    """DDs (N, d) in the global frame such that ``operator @ dd = traction``; nodal DDs
    (N, n, 2) for a 2D mesh of ``element_order`` 1 or 2 (n = order + 1 nodes).

    Parameters
    ----------
    operator : ElasticityOperator or ExtendedElasticityOperator
        Solved by its own ``solve`` (dense: LU; otherwise preconditioned GMRES).
    traction : (N, d) or (N*d,) array
        Traction sigma.n at the collocation points, element-major, global frame
        (``-p * mesh.normals`` for a crack under net pressure ``p``). Linear and quadratic
        elements: (N, n, 2), (N*n, 2) or flat at the nodes, or (N, 2) applied at every
        node of its element (:func:`hmatddm.elasticity.nodal.nodal_array`).
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
    from .extended import ExtendedElasticityOperator
    from .operator import ElasticityOperator

    if not isinstance(operator, (ElasticityOperator, ExtendedElasticityOperator)):
        raise InputError(f"operator must be an ElasticityOperator, got {type(operator).__name__}")
    rtol = finite_scalar("rtol", rtol)
    if not 0.0 < rtol < 1.0:
        raise InputError(f"rtol must be in (0, 1), got {rtol}")
    n, d = operator.mesh.n_elements, operator.dof
    guess = None
    if operator.mesh.n_nodes > 1:
        from .nodal import nodal_array

        b = nodal_array("traction", traction, operator.mesh, uniform=True).reshape(-1)
        if x0 is not None:
            guess = nodal_array("x0", x0, operator.mesh).reshape(-1)
    else:
        b = _as_element_major("traction", traction, n, d)
        if x0 is not None:
            guess = _as_element_major("x0", x0, n, d)
    x, info = operator.solve(b, x0=guess, rtol=rtol, restart=restart, maxiter=maxiter if maxiter is not None else 20)
    if "residual" not in info:  # a direct solve: measure it
        info["residual"] = float(np.linalg.norm(operator.matvec(x) - b) / max(np.linalg.norm(b), np.finfo(float).tiny))
    dd = x.reshape(n, d) if operator.mesh.n_nodes == 1 else x.reshape(n, operator.mesh.n_nodes, -1)
    return (dd, info) if return_info else dd


def _dd_array(mesh, dd):
    return _as_element_major("dd", dd, mesh.n_elements, mesh.dim).reshape(mesh.n_elements, mesh.dim)


def opening(mesh, dd):
    """Opening ``w = DD . n`` (N,), positive for an open crack (docs/conventions.md §1);
    nodal openings (N, n) for linear and quadratic elements (anywhere along the elements:
    :func:`hmatddm.elasticity.nodal.opening_at`)."""
    if getattr(mesh, "n_nodes", 1) > 1:
        from . import nodal

        return nodal.opening(mesh, dd)
    dd = _dd_array(mesh, dd)
    return np.einsum("ij,ij->i", dd, mesh.normals)


def slip(mesh, dd):
    """Tangential part of the DD, ``DD - w n`` (N, d), in the global frame ((N, n, 2) at
    the nodes of linear and quadratic elements)."""
    if getattr(mesh, "n_nodes", 1) > 1:
        from . import nodal

        return nodal.slip(mesh, dd)
    dd = _dd_array(mesh, dd)
    return dd - opening(mesh, dd)[:, None] * mesh.normals


def stress_at(mesh, material, dd, points, singular_correction="none", method="auto", eps=None, info=None,
              near_fraction=0.0):
    """Stress (M, d, d) induced at ``points`` (M, d) by the DDs ``dd`` (global frame),
    ref. Eq. 2.59. In 2D the in-plane components of the plane-strain stress.

    Parameters
    ----------
    mesh : Mesh2D or Mesh3D
    material : Elastic or LayeredMedium
        A :class:`hmatddm.LayeredMedium` (2D constant elements) sums directly with the
        image terms (ref. Ch. 3); ``method``, ``eps`` and ``info`` do not apply.
    dd : (N, d) or (N*d,) DDs, global frame
    points : (M, d)
    singular_correction : ``"none"`` or ``"average"``
        Points on an element edge raise :class:`InputError` unless ``"average"``
        (the mean of two points moved across the edge, ref. Sec. 6.2.3).
    near_fraction : float in [0, 1)
        Points within ``near_fraction`` of an element's smaller half size of its edge
        (its end in 2D) count as on it (a near miss, where the exact stress is ~1/gap):
        averaged with ``"average"``, refused with ``"none"``. 0 (default): exact hits
        only, so the field close to a crack tip can be sampled. The remote-failure check
        of a simulation uses :data:`hmatddm.elasticity.operator.NEAR_SINGULAR_FRACTION` (0.5), the
        threshold of the DDM operator.
    method : ``"auto"`` (default), ``"direct"`` or ``"tree"``
        ``"direct"``: exact summation over all elements, O(M N), parallel over points.
        ``"tree"``: the points x elements matrix as a rectangular H-matrix of the
        generic engine (:class:`hmatddm.elasticity.fields.StressField`: cluster trees of the points
        and of the elements, blocks with ``min(diam) <= FIELD_ETA * dist`` compressed by
        whole-element ACA to the relative Frobenius accuracy ``eps``, the others exact),
        applied to ``dd``. Measured on DFN scenes (tests/elasticity/test_fields.py checks ``<= eps``,
        benchmarks/bench_fields.py): the largest error of any component is well below
        ``eps`` times the largest induced stress component. ``"auto"``: ``"tree"`` when
        ``M * N >= AUTO_TREE_PAIRS`` and both exceed ``2 * FIELD_LEAF_SIZE``, else
        ``"direct"``.
    eps : float in (0, 1) or None
        Accuracy of the compressed blocks; None: ``DEFAULT_STRESS_EPS`` (1e-5).
    info : dict or None
        Filled with what was done: ``method``, ``seconds``, block counts, largest rank,
        ``pairs_exact`` / ``pairs_compressed`` (point-element pairs in blocks held
        exactly / compressed).

    Linear and quadratic elements (``mesh.element_order`` 1 or 2, ``dd`` nodal): summed
    directly (:func:`hmatddm.elasticity.nodal.stress_at`; ``method="tree"`` is refused, ``eps``
    unused); on an element the mean of its two faces' ``s_xx`` (which jumps there).
    """
    if getattr(mesh, "n_nodes", 1) > 1:  # homogeneous or layered
        from . import nodal

        return nodal.stress_at(mesh, material, dd, points, singular_correction, method, info, near_fraction)
    if isinstance(material, LayeredMedium):  # ref. Ch. 3 image terms, direct sum
        if mesh.dim == 3:
            from ..layered.influence3d import stress_at as layered_stress_at
        else:
            from ..layered.influence2d import stress_at as layered_stress_at

        return layered_stress_at(mesh, material, dd, points, singular_correction, near_fraction)
    from .fields import as_tensors, induced

    return as_tensors(induced(mesh, material, dd, points, "stress", singular_correction, method, eps, info,
                              near_fraction))


def mean_stress_at(mesh, material, dd, points, singular_correction="none", method="auto", eps=None, info=None,
                   near_fraction=0.0):
    """Mean stress ``tr(sigma)/3`` (M,) induced at ``points`` (ref. Eqs 5.24-5.28).

    In 2D (plane strain) ``sigma_zz = nu (sigma_xx + sigma_yy)`` is included, so the
    mean stress is ``(1 + nu)(sigma_xx + sigma_yy) / 3``. Parameters as in
    :func:`stress_at`.
    """
    if getattr(mesh, "n_nodes", 1) > 1:
        stress = stress_at(mesh, material, dd, points, singular_correction, method, eps, info, near_fraction)
        return (1.0 + material.poisson_ratio) * (stress[:, 0, 0] + stress[:, 1, 1]) / 3.0
    if isinstance(material, LayeredMedium) and mesh.dim == 3:  # ref. Ch. 3 image terms, direct sum
        from ..layered.influence3d import mean_stress_at as layered_mean_stress_at

        return layered_mean_stress_at(mesh, material, dd, points, singular_correction, near_fraction)
    from .fields import induced

    return induced(mesh, material, dd, points, "mean", singular_correction, method, eps, info, near_fraction)[:, 0]
