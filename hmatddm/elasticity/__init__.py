"""The elasticity layer (docs/architecture.md): displacement discontinuities to tractions,
stresses and openings, over the kernels, the layered media and the H-matrix compressor.

* :mod:`.operator`: :class:`ElasticityOperator`, the DDM traction operator, dense or
  H-matrix (ref. Ch. 2; Eq. 2.56 in 3D), homogeneous or layered (ref. Ch. 3).
* :mod:`.planar`: a planar crack's operator as its opening and shear parts.
* :mod:`.extended`: an operator grown by new elements, reusing its base (border blocks).
* :mod:`.inverse`: the near-field inverse and the preconditioned solve with it.
* :mod:`.solve`: :func:`solve`, :func:`opening`, :func:`slip`, :func:`stress_at`,
  :func:`mean_stress_at`.
* :mod:`.fields`, :mod:`.field_kernels`, :mod:`.field_bound`: stresses at points, direct or
  compressed, and the bound on a far field that lets a stress target be skipped;
  :func:`displacement_at` and :mod:`.displacement_kernels`: displacements at points.
* :mod:`.nodal`: nodal values of linear and quadratic 2D elements (ref. App. B).
"""
from .._lazy import attach

_EXPORTS = {
    "ElasticityOperator": ".operator", "solve": ".solve", "opening": ".solve", "slip": ".solve",
    "stress_at": ".solve", "mean_stress_at": ".solve", "opening_at": ".nodal",
    "PlanarElasticityOperator": ".planar", "ExtendedElasticityOperator": ".extended",
    "displacement_at": ".fields",
}
__getattr__, __dir__ = attach(__name__, _EXPORTS)

__all__ = list(_EXPORTS)
