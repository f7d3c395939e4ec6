"""A plane-layered elastic medium (ref. Ch. 3, Fig. 3.2).

Interfaces are planes normal to the project's vertical axis: the second coordinate
``y`` in 2D (the third, ``z``, in 3D), which is the reference's ``x3`` in Ch. 3. Layers
are listed from the top down; interface ``k`` at height ``interfaces[k]`` separates
layer ``k`` (above) from layer ``k + 1`` (below), so heights must strictly decrease.
The top and bottom layers are half-spaces. A layer of zero shear modulus is void
(ref. Sec. 3.4.1: gamma = 0 turns an interface into a free surface); only the top or
the bottom layer may be void.
"""
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..material import Elastic
from ..settings import LAYER, LAYERED_MEDIUM, check_fields, integer

#: Default largest number of reflections of a Hansen potential (``images="auto"`` stops
#: earlier when the next image changes the sampled influence block by < ``image_tol``).
MAX_IMAGES = 30


@dataclass(frozen=True, eq=False)
class LayeredMedium:
    """Parallel elastic layers bonded at planar interfaces (ref. Sec. 3.3).

    The ranges, defaults and units of the per-layer values and of the image options are
    declared once in :data:`hmatddm.settings.LAYER` and :data:`hmatddm.settings.LAYERED_MEDIUM`
    (the scene's ``[[layer]]`` tables read the same declarations).

    Parameters
    ----------
    interfaces : sequence of float
        Interface heights (m, along the vertical axis), strictly decreasing (top down);
        ``n_layers - 1`` of them.
    shear_modulus : sequence of float
        G of each layer, top down (Pa), >= 0; 0 only for the top or bottom layer (void:
        a free surface).
    poisson_ratio : sequence of float
        nu of each layer, in [0, 0.5).
    in_situ_stress : None or (n_layers, d, d)
        Optional per-layer in-situ stress tensor (Pa, tension positive).
    toughness : None or sequence of float
        Optional per-layer fracture toughness K_Ic (Pa m^0.5), > 0 (a void layer may give 0).
    images : int >= 0 or "auto"
        Largest number of reflections of a Hansen potential (ref. Fig. 3.4, n_max);
        transmissions are not counted. ``"auto"``: the smallest number (<= ``MAX_IMAGES``)
        for which one more image changes a sampled influence block by less than
        ``image_tol`` (relative, max norm); the operator reports it in ``stats``.
    image_tol : float in (0, 1)
    gauss_points : int in [1, 32]
        Gauss points per sub-segment for the regular image terms (ref. Eqs 3.12-3.13);
        sub-segments are added where an image lies close to the receiver. 3D rectangles
        take at least :data:`~hmatddm.layered.rectangle_quadrature.NEAR_GAUSS_POINTS` (5)
        per side next to the images, what their entries' 1e-8 needs, and fewer where the
        entry's error bound allows (:func:`~hmatddm.layered.rectangle_quadrature.entry_order`).
    method : "table" or "quadrature"
        3D constant rectangles: ``"table"`` (default) integrates the near image triples by
        quadrature and takes the far ones (the layered remainder, which exists with two or
        more interfaces) from a table built once per medium and mesh extent
        (:mod:`hmatddm.layered.remainder_table3d`); ``"quadrature"`` integrates every
        triple (the cross-check). 2D is the same either way. A 3D half-space (a void layer
        over one solid layer) takes, with ``"table"``, the image and surface terms of every
        rectangle with a horizontal side in closed form (Okada 1992,
        :mod:`hmatddm.layered.okada3d`), whatever ``images``; with two or more solid layers
        under a void, the top layer's rectangles with a horizontal side take their
        reflection in the free surface in closed form (the other image triples as above),
        and vertical rectangles take their near image triples in closed form next to them
        (:mod:`hmatddm.layered.vertical3d`); ``"quadrature"`` integrates them (the
        cross-check).
    table_tol : float in (0, 1e-4]
        Error of the remainder table allowed relative to the largest influence entry.
    """

    interfaces: tuple
    shear_modulus: tuple
    poisson_ratio: tuple
    in_situ_stress: object = None
    toughness: object = None
    images: object = "auto"
    image_tol: float = LAYERED_MEDIUM["image_tol"].default
    gauss_points: int = LAYERED_MEDIUM["gauss_points"].default
    method: str = LAYERED_MEDIUM["method"].default
    table_tol: float = LAYERED_MEDIUM["table_tol"].default

    def __post_init__(self):
        d = _float_list("interfaces", self.interfaces)
        g = _float_list("shear_modulus", self.shear_modulus)
        nu = _float_list("poisson_ratio", self.poisson_ratio)
        if len(g) < 1:
            raise InputError("shear_modulus must list at least one layer")
        if len(d) != len(g) - 1:
            raise InputError(f"interfaces must hold n_layers - 1 = {len(g) - 1} heights (one fewer than the "
                             f"layers in shear_modulus), got {len(d)}")
        if len(nu) != len(g):
            raise InputError(f"poisson_ratio must hold one value per layer ({len(g)}), got {len(nu)}")
        for k in range(len(d) - 1):
            if not d[k] > d[k + 1]:
                raise InputError(f"interfaces must be strictly decreasing (listed top down, no overlap); "
                                 f"interfaces[{k}] = {d[k]} and interfaces[{k + 1}] = {d[k + 1]}")
        for k, value in enumerate(g):
            LAYER["shear_modulus"].value(f"shear_modulus[{k}]", value)
            if value == 0.0 and 0 < k < len(g) - 1:
                raise InputError(f"shear_modulus[{k}] = 0 (void) is allowed only for the top or bottom layer")
        if len(g) > 1 and all(value == 0.0 for value in g):
            raise InputError("shear_modulus must be > 0 in at least one layer")
        if len(g) == 1 and g[0] == 0.0:
            raise InputError("shear_modulus[0] must be > 0 for a single layer")
        for k, value in enumerate(nu):
            LAYER["poisson_ratio"].value(f"poisson_ratio[{k}]", value)
        object.__setattr__(self, "interfaces", tuple(d))
        object.__setattr__(self, "shear_modulus", tuple(g))
        object.__setattr__(self, "poisson_ratio", tuple(nu))
        if self.in_situ_stress is not None:
            s = np.array(self.in_situ_stress, dtype=np.float64)
            if s.ndim != 3 or s.shape[0] != len(g) or s.shape[1] != s.shape[2] or s.shape[1] not in (2, 3):
                raise InputError(f"in_situ_stress must have shape ({len(g)}, d, d) with d = 2 or 3, got {s.shape}")
            if not np.all(np.isfinite(s)) or not np.allclose(s, np.swapaxes(s, 1, 2)):
                raise InputError("in_situ_stress must hold finite symmetric tensors")
            s.setflags(write=False)
            object.__setattr__(self, "in_situ_stress", s)
        if self.toughness is not None:
            k_ic = _float_list("toughness", self.toughness)
            if len(k_ic) != len(g):
                raise InputError(f"toughness must hold one value per layer ({len(g)}), got {list(k_ic)}")
            for k, value in enumerate(k_ic):
                if g[k] > 0.0 or value != 0.0:  # a void layer may give 0: it has no rock to break
                    LAYER["toughness"].value(f"toughness[{k}]", value)
            object.__setattr__(self, "toughness", tuple(k_ic))
        if self.images != "auto":
            try:
                object.__setattr__(self, "images", integer("images", self.images, minimum=0))
            except InputError:
                raise InputError(f"images must be an integer >= 0 or 'auto', got {self.images!r}") from None
        check_fields(self, LAYERED_MEDIUM)

    # -- queries ---------------------------------------------------------------------
    @property
    def n_layers(self):
        return len(self.shear_modulus)

    @property
    def is_homogeneous(self):
        """True when every layer has the same (non-zero) moduli: images vanish."""
        return len(set(self.shear_modulus)) == 1 and len(set(self.poisson_ratio)) == 1

    def layer_of(self, height):
        """Layer index of each height (array-like); a point on an interface belongs to
        the layer above it."""
        h = np.asarray(height, dtype=np.float64)
        d = np.asarray(self.interfaces)
        return np.sum(h[..., None] < d, axis=-1) if d.size else np.zeros(h.shape, dtype=np.int64)

    def material(self, layer):
        """The :class:`hmatddm.Elastic` of a (non-void) layer."""
        if not 0 <= layer < self.n_layers:
            raise InputError(f"layer must be in [0, {self.n_layers - 1}], got {layer}")
        if self.shear_modulus[layer] == 0.0:
            raise InputError(f"layer {layer} is void (shear_modulus = 0): it has no elastic material")
        return Elastic(self.shear_modulus[layer], self.poisson_ratio[layer])

    def arrays(self):
        """``(interfaces, shear_modulus, poisson_ratio)`` as float arrays (numba kernels)."""
        return (np.array(self.interfaces, dtype=np.float64), np.array(self.shear_modulus, dtype=np.float64),
                np.array(self.poisson_ratio, dtype=np.float64))

    @classmethod
    def homogeneous(cls, material, **options):
        """One layer of ``material`` (an :class:`hmatddm.Elastic`)."""
        return cls((), (material.shear_modulus,), (material.poisson_ratio,), **options)


def _float_list(name, values):
    try:
        items = np.asarray(values, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a sequence of numbers") from None
    for k, v in enumerate(items):
        if not np.isfinite(v):
            raise InputError(f"{name}[{k}] must be a finite number, got {v}")
    return [float(v) for v in items]
