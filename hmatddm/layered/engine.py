"""What the coupled flow/propagation engine (:class:`hmatddm.Simulation`) needs from a
:class:`LayeredMedium` in a 2D vertical cross-section: per-element moduli (tip criteria,
self compliance), per-element in-situ stress and toughness, and new tip elements cut at
the interfaces, so that a fracture grows from one layer into the next."""
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from .influence2d import split_at_interfaces


@dataclass(frozen=True)
class ElementMaterials:
    """Per-element elastic constants, with the attribute names of :class:`hmatddm.Elastic`
    (arrays broadcast where the engine uses a scalar material)."""

    shear_modulus: np.ndarray
    poisson_ratio: np.ndarray

    @property
    def youngs_modulus(self):
        return 2.0 * self.shear_modulus * (1.0 + self.poisson_ratio)

    @property
    def plane_strain_modulus(self):
        return self.youngs_modulus / (1.0 - self.poisson_ratio ** 2)


def check_simulation(mesh, medium, natural_fractures, propagation):
    """Refuse the engine settings the layered medium does not support (yet), by name."""
    if mesh.dim != 2:
        raise InputError("material: a LayeredMedium works with 2D meshes (a vertical cross-section) only, so far")
    if getattr(mesh, "element_order", 0) != 0:
        raise InputError("material: a LayeredMedium simulation needs constant elements (element_order 0)")
    if medium.in_situ_stress is not None and medium.in_situ_stress.shape[1] != 2:
        raise InputError(f"material.in_situ_stress must hold 2x2 tensors for a 2D run, got "
                         f"{medium.in_situ_stress.shape[1]}x{medium.in_situ_stress.shape[2]}")
    if natural_fractures is not None:
        raise InputError("natural_fractures: not supported with a LayeredMedium yet")
    if propagation is not None and propagation.front != "element":
        raise InputError("propagation.front: a LayeredMedium supports front = 'element' only, so far")


def uniform(medium):
    """True when nothing differs between layers (moduli, in-situ stress, toughness)."""
    same_stress = medium.in_situ_stress is None or np.all(medium.in_situ_stress == medium.in_situ_stress[0])
    same_toughness = medium.toughness is None or len(set(medium.toughness)) == 1
    return medium.is_homogeneous and same_stress and same_toughness


def element_layers(mesh, medium):
    """Layer of each element (its midpoint's height)."""
    return medium.layer_of(mesh.centers[:, 1]).astype(np.int64)


def element_materials(mesh, medium):
    layers = element_layers(mesh, medium)
    return ElementMaterials(np.asarray(medium.shear_modulus)[layers], np.asarray(medium.poisson_ratio)[layers])


def far_field_traction(mesh, medium, far_field_stress):
    """``-sigma_0 . n`` per element (flat), with the in-situ stress of each element's layer
    where the medium gives one, else ``far_field_stress``."""
    if medium.in_situ_stress is None:
        return -(mesh.normals @ np.asarray(far_field_stress).T).ravel()
    stress = medium.in_situ_stress[element_layers(mesh, medium)]
    return -np.einsum("nij,nj->ni", stress, mesh.normals).ravel()


def layers_ahead(edges, element, edge, medium):
    """Layer just ahead of each tip edge (the rock a tip on an interface grows into)."""
    mid = edges.midpoints[element, edge]
    step = 1e-6 * edges.half_width[element, edge]
    return medium.layer_of(mid[:, 1] + step * edges.ahead[element, edge][:, 1]).astype(np.int64)


def tip_criterion(tips, tip_materials, layers, medium, propagation):
    """``tips`` with ``grows`` re-evaluated against the toughness of the layer ahead of
    each tip (``layers``; ref. Eqs 4.18-4.19); unchanged when the medium has no per-layer
    toughness. The SIFs themselves use the moduli of the tip element's layer."""
    if medium.toughness is None:
        return tips
    toughness = np.asarray(medium.toughness)[layers]
    if propagation.criterion == "mcs":
        grows = tips.k_bar >= toughness
    else:
        grows = tips.energy_release_rate >= toughness ** 2 / tip_materials.plane_strain_modulus
    return replace(tips, grows=grows)


def split_new_elements(grown, parent, rows, medium):
    """New tip elements cut where they cross interfaces (pieces keep the parent tip)."""
    split, index = split_at_interfaces(grown, medium)
    return split, parent[index], rows[index]
