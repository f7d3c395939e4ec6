"""The elasticity operator of a growing mesh: built once, extended by exact border
blocks while the mesh grows a little, rebuilt when it grew too much.

The operator is rebuilt only when the mesh has grown, never inside the nonlinear
iterations of a step. A dense operator in a homogeneous medium is not rebuilt when the mesh
grows: its matrix leads the grown mesh's, and only the new elements' rows and columns are
computed (``ElasticityOperator(leading=)``; on dfn-3cluster at 4x its area the 313 full
assemblies took 1.55 s of the run's 30 s, benchmarks/RESULTS.md, issue 33). A planar 3D
mesh in a homogeneous medium gets the ``hmatrix`` backend's opening and shear operators
apart, and their border blocks apart while it grows in its plane
(:mod:`hmatddm.elasticity.planar`; the same matrix, ~7x faster products for a crack loaded
in opening) unless :data:`SPLIT_PLANAR_MODES` is False; and a planar lattice
mesh gets the FFT operator of :mod:`hmatddm.elasticity.lattice` unless
:data:`LATTICE_PLANAR` is False.

In a :class:`~hmatddm.LayeredMedium` with ``images = "auto"`` a build chooses its number of
images by sampling the influence block with more and more images (:func:`hmatddm.layered.
influence2d.choose_images`): in 3D that sampling cost 84% of the `layered-3d` scene's run (2.4 s
a build, eight builds; benchmarks/RESULTS.md, issue 32). A 3D rebuild keeps the last choice
while the mesh spans the same layers and stays within :data:`IMAGES_KEPT_WITHIN` times the
extent it was chosen on (``image_choice``: kept with the base it was made for, so that a step
tried again from an earlier base starts from that base's choice, and saved in checkpoints, so
that a resumed run builds the same operators). 2D chooses at every build (cheap there).
"""
import warnings
from dataclasses import asdict

import numpy as np

from ..errors import MeshQualityWarning
from ..elasticity.extended import ExtendedElasticityOperator, compresses_borders
from ..layered import LayeredMedium
from ..material import Elastic
from ..elasticity.operator import ElasticityOperator
from ..elasticity.lattice import LatticePlanarOperator, lattice_of
from ..elasticity.planar import PlanarElasticityOperator, PlanarExtendedOperator, is_planar

#: Build a planar mesh's operator as its opening and shear parts (see the module docstring).
SPLIT_PLANAR_MODES = True

#: A planar mesh of equal rectangles on one lattice (the asymptotic front's) in a
#: homogeneous medium gets the FFT operator (:mod:`hmatddm.elasticity.lattice`): exact
#: products, no H-matrix, no border blocks, a new kernel table only when the crack
#: outgrows its box.
LATTICE_PLANAR = True

#: A rebuild keeps the number of images chosen on an earlier mesh (module docstring) while
#: the mesh's extent along every axis is at most this many times that mesh's.
IMAGES_KEPT_WITHIN = 2.0


class GrowingOperator:
    """The operators of one run's meshes (``operator_settings``: an
    :class:`~hmatddm.simulation.settings.OperatorSettings`; ``rebuild_settings``: a
    :class:`~hmatddm.simulation.settings.RebuildSettings`)."""

    def __init__(self, material, operator_settings, rebuild_settings):
        self.material = material
        self.operator_settings, self.rebuild_settings = operator_settings, rebuild_settings
        self.base = None     # the last full build (compressed, for the hmatrix backend)
        self.builds = 0      # full builds so far
        self._mesh = None    # the mesh of the last operator handed out
        self._operator = None
        self._mesh_quality_warned = False

    def __call__(self, mesh):
        """The elasticity operator of ``mesh``: the last one if the mesh is unchanged, the
        compressed base plus exact borders if the mesh only grew a little, else a new build."""
        if self._mesh is mesh:
            return self._operator
        if self._on_lattice(mesh):
            operator = self._lattice_operator(mesh)
            self._operator, self._mesh = operator, mesh
            return operator
        base = self.base
        n = mesh.n_elements
        extends = (base is not None and n >= base.mesh.n_elements
                   and np.array_equal(mesh.centers[:base.mesh.n_elements], base.mesh.centers))
        if extends and n == base.mesh.n_elements:
            operator = base
        elif (extends and self.operator_settings.backend == "hmatrix"
              and self.rebuild_settings.border_fits(base.mesh.n_elements, n - base.mesh.n_elements, base.dof,
                                                    getattr(base, "border_entries_per_pair", None),
                                                    self._border_bytes_per_element(base),
                                                    base.stats["memory_bytes"] if compresses_borders(base) else None)):
            # the border blocks of the elements the last operator had are copied, not re-evaluated
            grown = (PlanarExtendedOperator if isinstance(base, PlanarElasticityOperator) and is_planar(mesh)
                     else ExtendedElasticityOperator)
            operator = grown(base, mesh, previous=self._operator)
        elif extends and self._borders_dense(base):
            operator = self.build(mesh, leading=base)
        else:
            operator = self.build(mesh)
        self._operator, self._mesh = operator, mesh
        return operator

    def _on_lattice(self, mesh):
        """Whether ``mesh`` gets the FFT operator of a lattice (module docstring)."""
        return (LATTICE_PLANAR and self.operator_settings.backend == "hmatrix" and isinstance(self.material, Elastic)
                and lattice_of(mesh) is not None)

    def _lattice_operator(self, mesh):
        """The lattice operator of ``mesh``, sharing the kernel tables of the last one; a
        new table (the crack outgrew its box) counts as a build."""
        settings = asdict(self.operator_settings)
        previous = self._operator if isinstance(self._operator, LatticePlanarOperator) else self.base
        operator = LatticePlanarOperator(mesh, self.material, previous=previous,
                                         singular_correction=settings["singular_correction"], alpha=settings["alpha"])
        self.base = operator
        self.builds += operator.tables_computed
        return operator

    def _border_bytes_per_element(self, base):
        """Bytes of compressed border blocks per added element: measured on the last grown
        operator of ``base``, else expected from the base's own memory per element (twice:
        ``A_on`` and ``A_no``); None when borders of ``base`` stay dense."""
        if not compresses_borders(base):
            return None
        last = self._operator
        if getattr(last, "base", None) is base and last.n_new:
            return last.chunk_bytes / last.n_new
        return 2.0 * base.stats["memory_bytes"] / base.mesh.n_elements

    @property
    def image_choice(self):
        """The base's choice of images (``"auto"`` media, 3D): ``dict(n_images, extent,
        layers)`` of the mesh it was made on, or None (module docstring)."""
        return getattr(self.base, "image_choice", None)

    def _borders_dense(self, base):
        """Whether a grown mesh's dense operator takes ``base``'s matrix as its leading
        block (module docstring): the dense backend in a homogeneous medium."""
        return (self.operator_settings.backend == "dense" and isinstance(self.material, Elastic)
                and type(base) is ElasticityOperator and base.backend == "dense")

    def build(self, mesh, image_choice=None, leading=None):
        """A build of the operator of ``mesh``, which becomes the base; ``image_choice``:
        the choice of images to start from (default: the base's); ``leading``: a dense base
        whose matrix leads this one's (only the new rows and columns are computed; not
        counted in :attr:`builds`)."""
        if self._on_lattice(mesh):
            return self._lattice_operator(mesh)
        # the mesh-quality check runs at every build of a growing mesh until it has warned:
        # once per run
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", MeshQualityWarning)
            settings = dict(asdict(self.operator_settings), check_spacing=not self._mesh_quality_warned)
            split = (SPLIT_PLANAR_MODES and settings["backend"] == "hmatrix" and isinstance(self.material, Elastic)
                     and is_planar(mesh))
            if split:
                self.base = PlanarElasticityOperator(mesh, self.material, **settings)
            else:
                previous = self.image_choice if image_choice is None else image_choice
                self.base = ElasticityOperator(mesh, self.material, n_images=self._kept_images(mesh, previous),
                                               leading=leading, **settings)
                self.base.image_choice = self._remembered_images(mesh, previous)
        for warning in caught:
            if issubclass(warning.category, MeshQualityWarning):
                if not self._mesh_quality_warned:
                    self._mesh_quality_warned = True
                    warnings.warn(f"{warning.message} (warned once per simulation)", MeshQualityWarning,
                                  stacklevel=2)
            else:
                warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
        if leading is None:
            self.builds += 1
        return self.base

    def _chooses_images(self, mesh):
        material = self.material
        return (mesh.dim == 3 and isinstance(material, LayeredMedium) and material.images == "auto"
                and not material.is_homogeneous)

    def _extent_and_layers(self, mesh):
        extent = np.ptp(mesh.centers, axis=0) + 2.0 * np.max(np.maximum(mesh.half_a, mesh.half_b))
        return extent, sorted({int(k) for k in np.unique(self.material.layer_of(mesh.centers[:, 2]))})

    def _kept_images(self, mesh, kept):
        """The number of images of the choice ``kept`` if it still holds for ``mesh`` (module
        docstring), else None (choose on ``mesh``)."""
        if not self._chooses_images(mesh) or kept is None:
            return None
        extent, layers = self._extent_and_layers(mesh)
        if layers != kept["layers"] or np.any(extent > IMAGES_KEPT_WITHIN * np.asarray(kept["extent"]) + 1e-12):
            return None
        return int(kept["n_images"])

    def _remembered_images(self, mesh, previous):
        """The choice of images of the base just built on ``mesh`` from ``previous``."""
        if not self._chooses_images(mesh):
            return None
        n_images = int(self.base.stats.get("n_images", 0))
        if previous is not None and n_images == previous["n_images"] and \
                self._kept_images(mesh, previous) is not None:
            return previous  # kept: the extent it was chosen on stays the reference
        extent, layers = self._extent_and_layers(mesh)
        return dict(n_images=n_images, extent=[float(v) for v in extent], layers=layers)

    def reset(self, base):
        """Go back to ``base`` (an earlier :attr:`base`, or None), forgetting the operators
        made since: a step tried again starts from the operator it started from, as a run
        resumed from that step's checkpoint would (with the choice of images ``base`` was
        made with)."""
        self.base, self._mesh, self._operator = base, None, None

    def restore(self, mesh, compressed_elements, image_choice=None):
        """Rebuild the base an interrupted run had (its first ``compressed_elements``
        elements of ``mesh``, with the run's ``image_choice``), so that a resumed run applies
        the same operator, bit for bit."""
        self.base = self._mesh = self._operator = None
        if 0 < compressed_elements <= mesh.n_elements:
            self.build(mesh.subset(np.arange(compressed_elements)), image_choice)

    @property
    def compressed_elements(self):
        """Elements in the compressed base operator (0 before the first build)."""
        return 0 if self.base is None else self.base.mesh.n_elements
