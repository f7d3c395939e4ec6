"""What the coupled flow/propagation engine (:class:`hmatddm.Simulation`) needs from a
:class:`LayeredMedium`, in a 2D vertical cross-section or in 3D: per-element moduli (tip
criteria, self compliance), per-element in-situ stress and toughness, and new tip
elements cut at the interfaces, so that a fracture grows from one layer into the next.

Natural fractures (ref. Ch. 5) run as in uniform rock, with the layers:

* their mesh is cut at the interfaces like new tip elements (:func:`natural_fracture_mesh`:
  in 3D always, in 2D where the layers differ), so a network drawn without regard to the
  layers is accepted; an element that cannot be cut (3D, no horizontal edge), lies along
  an interface between different layers, or lies in a void layer is refused by name;
* remote failure (ref. Sec. 5.3) evaluates the induced stress at the intact elements with
  the image terms (the layered :func:`hmatddm.stress_at`, direct sum, with the number of
  images of the run's operator), adds the in-situ stress of each element's layer and
  takes Poisson's ratio of its layer for the undrained pore-pressure change (2D); the
  rigorous screen of :mod:`hmatddm.elasticity.field_bound` holds for a homogeneous kernel only, so
  it is used where all layers have the same moduli (the images vanish: the medium's
  stress is the homogeneous one) and every target is evaluated otherwise
  (:func:`remote_failure_setting`);
* the crossing criterion (ref. Sec. 5.2) uses the in-situ stress and the rock toughness
  of the layer where the tip meets the natural fracture (:func:`crossing_setting`); the
  stress intensity factors come from the layered solution with the tip layer's moduli,
  so the images act on the decision through them (the near-tip field of ref. Eqs 5.6-5.8
  is that of a crack tip inside one layer).

The vertical axis is the last coordinate (``y`` in 2D, ``z`` in 3D; docs/conventions.md
§3). In 3D a new rectangle that crosses an interface is cut along it into two
rectangles, which needs one of its edges to be horizontal (vertical, horizontal and
dipping elements whose strike edge is horizontal; ``propagation.turning`` "none" or
"plan" keep it so); an element whose edges are all inclined is refused by name.
"""
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..mesh import Mesh3D

#: Relative tolerance (of the element size) under which an element touching an
#: interface does not count as crossing it.
_CROSSING_TOL = 1e-9


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
    if mesh.dim not in (2, 3):
        raise InputError(f"mesh: a LayeredMedium works with 2D or 3D meshes, got dimension {mesh.dim}")
    if getattr(mesh, "element_order", 0) != 0:
        raise InputError("material: a LayeredMedium simulation needs constant elements (element_order 0)")
    if medium.in_situ_stress is not None and medium.in_situ_stress.shape[1] != mesh.dim:
        raise InputError(f"material.in_situ_stress must hold {mesh.dim}x{mesh.dim} tensors for a {mesh.dim}D run, "
                         f"got {medium.in_situ_stress.shape[1]}x{medium.in_situ_stress.shape[2]}")
    if propagation is not None and propagation.front != "element":
        raise InputError("propagation.front: a LayeredMedium supports front = 'element' only, so far")
    void = np.flatnonzero(np.asarray(medium.shear_modulus)[element_layers(mesh, medium)] == 0.0)
    if void.size:
        raise InputError(f"mesh: element {void[0]} lies in a void layer (shear_modulus = 0, beyond the free "
                         f"surface); fractures must lie in the rock")
    if mesh.dim == 3:
        crossing = crossed_interfaces(mesh, medium)
        if crossing is not None:
            element, height = crossing
            raise InputError(f"mesh: element {element} crosses the layer interface at z = {height:g}; elements "
                             f"must end on interfaces (docs/conventions.md §3): mesh each layer separately")
        if propagation is not None and medium.n_layers > 1:
            if propagation.turning == "any":
                raise InputError("propagation.turning: 'any' may tilt new 3D elements so that an interface cuts "
                                 "them obliquely; use 'plan' or 'none' with a LayeredMedium")
            inclined = np.flatnonzero(~_has_horizontal_edge(mesh))
            if inclined.size:
                raise InputError(f"mesh: element {inclined[0]} has no horizontal edge, so new elements grown from "
                                 f"it could not be cut along an interface into rectangles; with a LayeredMedium "
                                 f"and propagation, give every 3D element a horizontal edge (e1 or e2 with z = 0)")


def natural_fracture_mesh(mesh, natural_fractures, medium):
    """The natural-fracture mesh of a layered run: ``natural_fractures`` cut at the
    interfaces (:func:`hmatddm.layered.split_at_interfaces`; in 3D always, the 3D kernels
    refuse a straddling rectangle; in 2D only where the layers differ, as new tip elements
    are), each piece keeping its fracture id. InputError naming ``natural_fractures`` for
    higher-order elements, a 3D element crossing an interface without a horizontal edge,
    an element along an interface between different layers or in a void layer. A mesh of
    another type than ``mesh`` is returned as it is (the engine refuses it)."""
    if type(natural_fractures) is not type(mesh):
        return natural_fractures
    if getattr(natural_fractures, "element_order", 0) != 0:
        raise InputError("natural_fractures: a LayeredMedium simulation needs constant elements (element_order 0)")
    if mesh.dim == 3 or not uniform(medium):
        if mesh.dim == 3:
            try:
                natural_fractures, _ = split_rectangles(natural_fractures, medium)
            except InputError as error:  # an element without a horizontal edge: name the field
                raise InputError(str(error).replace("mesh:", "natural_fractures:", 1)) from None
        else:
            from .influence2d import split_at_interfaces

            natural_fractures, _ = split_at_interfaces(natural_fractures, medium)
    from .influence2d import layers_of_extents

    if mesh.dim == 3:
        low, high = _vertical_extent(natural_fractures)
        tol = _CROSSING_TOL * np.maximum(natural_fractures.half_a, natural_fractures.half_b)
    else:
        p0, p1 = natural_fractures.endpoints
        low, high = np.minimum(p0[:, 1], p1[:, 1]), np.maximum(p0[:, 1], p1[:, 1])
        tol = _CROSSING_TOL * natural_fractures.half_length
    layers_of_extents(medium, low, high, tol, natural_fractures.fracture_id, noun="natural_fractures element")
    return natural_fractures


def remote_failure_setting(network_mesh, medium, far_field_stress):
    """``(material, far_field, poisson_ratio)`` of the remote-failure check of the natural
    elements ``network_mesh`` (ref. Sec. 5.3): the :class:`hmatddm.Elastic` of the layers
    where they all have the same moduli (no images: the screened check applies), else
    the medium; the in-situ stress of each element's layer (M, d, d) where the medium
    gives one, else ``far_field_stress``; Poisson's ratio of each element's layer (M,)."""
    layers = element_layers(network_mesh, medium)
    material = medium.material(0) if medium.is_homogeneous else medium
    far_field = far_field_stress if medium.in_situ_stress is None else medium.in_situ_stress[layers]
    return material, far_field, np.asarray(medium.poisson_ratio)[layers]


def crossing_setting(medium, height, far_field_stress, toughness):
    """``(far_field, rock_toughness)`` of the crossing criterion (ref. Sec. 5.2) where a
    tip meets a natural fracture at ``height``: the in-situ stress and toughness of that
    layer where the medium gives them, else ``far_field_stress`` and ``toughness``."""
    layer = int(medium.layer_of(height))
    if medium.in_situ_stress is not None:
        far_field_stress = medium.in_situ_stress[layer]
    if medium.toughness is not None:
        toughness = medium.toughness[layer]
    return far_field_stress, toughness


def induced_stress(mesh, medium, dd, points, singular_correction, near_fraction, n_images):
    """Stress (M, d, d) the DDs ``dd`` of the constant elements ``mesh`` induce at
    ``points`` in ``medium`` with ``n_images`` images (None: the medium's choice), by
    the direct layered sum of :mod:`.influence2d` / :mod:`.influence3d`."""
    if mesh.dim == 3:
        from .influence3d import stress_at
    else:
        from .influence2d import stress_at
    return stress_at(mesh, medium, dd, points, singular_correction, near_fraction, n_images)


def _has_horizontal_edge(mesh):
    frames = mesh.frames
    return (np.abs(frames[:, 0, 2]) <= 1e-9) | (np.abs(frames[:, 1, 2]) <= 1e-9)


def _vertical_extent(mesh):
    """Lowest and highest height of each 3D element."""
    reach = mesh.half_a * np.abs(mesh.frames[:, 0, 2]) + mesh.half_b * np.abs(mesh.frames[:, 1, 2])
    return mesh.centers[:, 2] - reach, mesh.centers[:, 2] + reach


def crossed_interfaces(mesh, medium):
    """``(element, height)`` of the first 3D element that crosses an interface, or None."""
    if not medium.interfaces:
        return None
    low, high = _vertical_extent(mesh)
    tol = _CROSSING_TOL * np.maximum(mesh.half_a, mesh.half_b)
    for height in medium.interfaces:
        bad = np.flatnonzero((low < height - tol) & (high > height + tol))
        if bad.size:
            return int(bad[0]), float(height)
    return None


def split_rectangles(mesh, medium):
    """Cut the 3D elements of ``mesh`` that cross interfaces along them: ``(mesh, index)``
    with ``index`` the original element of every piece (pieces in order along the cut
    axis). The cut runs parallel to the element's horizontal edge, so every piece is a
    rectangle with the parent's frame; InputError for an element without one."""
    if not medium.interfaces:
        return mesh, np.arange(mesh.n_elements)
    heights = np.asarray(medium.interfaces)
    centers, frames, half_a, half_b, index = [], [], [], [], []
    for i in range(mesh.n_elements):
        e1, e2 = mesh.frames[i, 0], mesh.frames[i, 1]
        halves = [mesh.half_a[i], mesh.half_b[i]]
        # the axis along which the height varies (the other edge is horizontal)
        if abs(e1[2]) <= 1e-9:
            axis = 1
        elif abs(e2[2]) <= 1e-9:
            axis = 0
        else:
            axis = -1
        direction = mesh.frames[i, max(axis, 0)]
        half = halves[max(axis, 0)]
        cz, slope = mesh.centers[i, 2], direction[2]
        tol = _CROSSING_TOL * max(halves)
        inside = heights[(heights > cz - half * abs(slope) + tol) & (heights < cz + half * abs(slope) - tol)]
        if inside.size == 0 or abs(slope) <= 1e-9:
            cuts = []
        elif axis < 0:
            raise InputError(f"mesh: element {i} crosses the interface at z = {inside[0]:g} and has no horizontal "
                             f"edge, so it cannot be cut into rectangles (use propagation.turning 'plan' or 'none')")
        else:
            cuts = sorted((inside - cz) / slope)
        ends = [-half] + list(cuts) + [half]
        for lo, hi in zip(ends[:-1], ends[1:]):
            centers.append(mesh.centers[i] + 0.5 * (lo + hi) * direction)
            frames.append(mesh.frames[i])
            size = [mesh.half_a[i], mesh.half_b[i]]
            size[max(axis, 0)] = 0.5 * (hi - lo)
            half_a.append(size[0])
            half_b.append(size[1])
            index.append(i)
    index = np.asarray(index, dtype=np.int64)
    if index.size == mesh.n_elements:
        return mesh, index
    return Mesh3D(np.asarray(centers), np.ascontiguousarray(frames), np.asarray(half_a), np.asarray(half_b),
                  mesh.fracture_id[index].copy()), index


def uniform(medium):
    """True when nothing differs between layers (moduli, in-situ stress, toughness)."""
    same_stress = medium.in_situ_stress is None or np.all(medium.in_situ_stress == medium.in_situ_stress[0])
    same_toughness = medium.toughness is None or len(set(medium.toughness)) == 1
    return medium.is_homogeneous and same_stress and same_toughness


def element_layers(mesh, medium):
    """Layer of each element (its midpoint's height)."""
    return medium.layer_of(mesh.centers[:, mesh.dim - 1]).astype(np.int64)


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
    return medium.layer_of(mid[:, -1] + step * edges.ahead[element, edge][:, -1]).astype(np.int64)


def tip_criterion(tips, tip_materials, layers, medium, propagation):
    """``tips`` with ``grows`` re-evaluated against the toughness of the layer ahead of
    each tip (``layers``; ref. Eqs 4.18-4.19) where the medium gives per-layer toughness;
    a tip never grows into a void layer (through a free surface). The SIFs themselves use
    the moduli of the tip element's layer."""
    grows = tips.grows
    if medium.toughness is not None:
        toughness = np.asarray(medium.toughness)[layers]
        if propagation.criterion == "mcs":
            grows = tips.k_bar >= toughness
        else:
            grows = tips.energy_release_rate >= toughness ** 2 / tip_materials.plane_strain_modulus
    grows = grows & (np.asarray(medium.shear_modulus)[layers] > 0.0)
    return replace(tips, grows=grows)


def split_new_elements(grown, parent, rows, medium, mesh=None):
    """New tip elements cut where they cross interfaces (pieces keep the parent tip);
    pieces in a void layer (beyond a free surface) are dropped, and so is a piece that
    lands on an element of ``mesh`` (the current mesh) or on an earlier piece: a tip
    growing up to an interface and the tip of a piece already cut there, beside it,
    reach the same cell only after the cut (the candidates differed before it).
    ``(None, None, None)`` when no piece is left."""
    if grown.dim == 3:
        split, index = split_rectangles(grown, medium)
    else:
        from .influence2d import split_at_interfaces

        split, index = split_at_interfaces(grown, medium)
    solid = np.asarray(medium.shear_modulus)[element_layers(split, medium)] > 0.0
    if not np.all(solid) and np.any(solid):
        keep = np.flatnonzero(solid)
        split, index = split.subset(keep), index[keep]
    keep = _new_cells(split, mesh)
    if keep.size == 0:
        return None, None, None
    if keep.size < split.n_elements:
        split, index = split.subset(keep), index[keep]
    return split, parent[index], rows[index]


def _new_cells(pieces, mesh):
    """Indices of the pieces whose centre is farther than half their smaller size from
    every centre of ``mesh`` and from every earlier kept piece (the rule of
    :func:`hmatddm.fracture.new_elements`, applied after the cut)."""
    from scipy.spatial import cKDTree

    size = np.minimum(pieces.half_a, pieces.half_b) if pieces.dim == 3 else pieces.half_length
    keep = np.ones(pieces.n_elements, dtype=bool)
    if mesh is not None and mesh.n_elements:
        distance, _ = cKDTree(mesh.centers).query(pieces.centers)
        keep &= distance > 0.5 * size
    chosen = []
    for m in np.flatnonzero(keep):
        if all(np.linalg.norm(pieces.centers[m] - pieces.centers[q]) > 0.5 * size[m] for q in chosen):
            chosen.append(m)
    return np.asarray(chosen, dtype=np.int64)
