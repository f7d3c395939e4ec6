"""Influence data of a 2D mesh of constant DD elements in a :class:`LayeredMedium`:
element layers, the straddling check, the interface splitter and the automatic number
of images. The kernels are :mod:`.images2d` (kernel data :class:`.segments2d.LayeredSegments`,
served by the drivers of :mod:`hmatddm.kernels.drivers`)."""
import numpy as np

from ..errors import InputError
from ..kernels.drivers import finite_stress_sum, traction_block, with_self_max
from ..mesh import Mesh2D
from . import segments2d
from .medium import MAX_IMAGES

#: Largest number of sub-segments of an element for the image quadrature.
MAX_SUBDIVISIONS = 64
#: Relative tolerance (of the element length) within which an end point counts as on
#: an interface.
_ON_INTERFACE = 1e-9


def element_layers(mesh, medium):
    """(N,) layer of each element of a 2D mesh (of its midpoint); InputError naming the
    first element that straddles an interface, lies along one (unless all layers have the
    same moduli), or sits in a void layer."""
    if mesh.dim != 2:
        raise InputError("element_layers of influence2d takes a Mesh2D (3D: hmatddm.layered.influence3d)")
    p0, p1 = mesh.endpoints
    return layers_of_extents(medium, np.minimum(p0[:, 1], p1[:, 1]), np.maximum(p0[:, 1], p1[:, 1]),
                             _ON_INTERFACE * np.maximum(mesh.half_length, 1e-300), mesh.fracture_id)


def layers_of_extents(medium, lo, hi, tol, fracture_id, noun="element"):
    """(N,) layer of elements spanning the heights ``lo .. hi`` (N,) (of their middle
    height), 2D or 3D; InputError naming the first one that straddles an interface (by
    more than ``tol``), lies in one (unless all layers have the same moduli), or sits in
    a void layer."""
    if not medium.is_homogeneous:  # equal layers: any layer will do
        for k, height in enumerate(medium.interfaces):
            inside = (lo < height - tol) & (hi > height + tol)
            if np.any(inside):
                e = int(np.flatnonzero(inside)[0])
                raise InputError(f"{noun} {e} (fracture {int(fracture_id[e])}) straddles interface {k} at height "
                                 f"{height:g} (it spans heights {lo[e]:g} .. {hi[e]:g}); {noun}s must end on "
                                 "interfaces: split them with hd.layered.split_at_interfaces(mesh, medium)")
            along = (np.abs(lo - height) <= tol) & (np.abs(hi - height) <= tol)
            if np.any(along):
                e = int(np.flatnonzero(along)[0])
                raise InputError(f"{noun} {e} lies along interface {k} (height {height:g}); each {noun} must lie "
                                 "inside one layer (move it off the interface)")
    layers = medium.layer_of(0.5 * (lo + hi)).astype(np.int64)
    void = np.flatnonzero(np.asarray(medium.shear_modulus)[layers] == 0.0)
    if void.size:
        e = int(void[0])
        raise InputError(f"{noun} {e} lies in layer {int(layers[e])}, which is void (shear_modulus = 0)")
    return layers


def split_at_interfaces(mesh, medium):
    """A copy of a constant-element 2D ``mesh`` whose elements crossing interfaces are
    cut there (pieces keep the element's direction and fracture id); elements inside one
    layer are kept as they are. Returns ``(mesh, parent)`` with ``parent[k]`` the index
    of the original element of new element ``k``."""
    if mesh.dim != 2:
        raise InputError("split_at_interfaces works with 2D meshes (Mesh2D) only")
    p0, p1 = mesh.endpoints
    d = np.asarray(medium.interfaces)
    new0, new1, parent = [], [], []
    for e in range(mesh.n_elements):
        a, b = p0[e], p1[e]
        cuts = [0.0, 1.0]
        dy = b[1] - a[1]
        tol = _ON_INTERFACE * mesh.half_length[e]
        for height in d:
            if min(a[1], b[1]) < height - tol and max(a[1], b[1]) > height + tol:
                cuts.append((height - a[1]) / dy)
        cuts = sorted(cuts)
        for s0, s1 in zip(cuts[:-1], cuts[1:]):
            q0 = a + s0 * (b - a)
            q1 = a + s1 * (b - a)
            for k in range(len(d)):  # land cut points exactly on the interface
                if abs(q0[1] - d[k]) <= tol:
                    q0[1] = d[k]
                if abs(q1[1] - d[k]) <= tol:
                    q1[1] = d[k]
            new0.append(q0)
            new1.append(q1)
            parent.append(e)
    parent = np.array(parent, dtype=np.int64)
    split = Mesh2D.from_segments(np.array(new0), np.array(new1), fracture_id=mesh.fracture_id[parent])
    return split, parent


def influence_data(mesh, medium, singular_shift, alpha, near_fraction, n_images):
    """The kernel data (:class:`segments2d.LayeredSegments`) of a constant-element 2D
    ``mesh`` in ``medium`` with ``n_images`` images; ``alpha > 0`` fills ``self_max``
    for ref. Eq. 6.11."""
    layers = element_layers(mesh, medium)
    interfaces, g, nu = medium.arrays()
    return with_self_max(segments2d.LayeredSegments(
        mesh.centers, mesh.frames, mesh.half_length, layers, interfaces, g, nu, n_images=int(n_images),
        gauss_points=int(medium.gauss_points), max_subdivisions=int(MAX_SUBDIVISIONS),
        singular_shift=float(singular_shift), near_fraction=float(near_fraction), alpha=float(alpha),
        self_max=np.zeros(mesh.n_elements)))


def with_images(data, n_images):
    """The kernel data with another number of images."""
    return data._replace(n_images=int(n_images))


def choose_images(mesh, medium, data, max_samples=24, max_sources=2000):
    """``medium.images`` when it is a number; for ``"auto"`` the smallest number of
    images after which one more image changes the sampled influence block by less than
    ``medium.image_tol``, measured on what the solution feels: the tractions at up to
    ``max_samples`` receivers (chosen evenly) due to a uniform unit DD along x, then y (z),
    on (up to ``max_sources``) all elements, relative to their largest value. (The
    largest single entry is a poor measure: the image terms are small next to the
    self-influence of an element but add up coherently over a crack; for the crack of
    ref. Table 3.1 at gamma = 0.75 one image changes the largest entry by 9e-5 and the
    opening by 4%.) Single-layer and homogeneous media: 0."""
    if medium.images != "auto":
        return medium.images
    if medium.n_layers == 1 or medium.is_homogeneous:
        return 0
    n = mesh.n_elements
    rows = np.unique(np.linspace(0, n - 1, min(n, max_samples)).round().astype(np.int64))
    cols = np.unique(np.linspace(0, n - 1, min(n, max_sources)).round().astype(np.int64))
    dof = mesh.dim  # constant elements, 2D or 3D (hmatddm.layered.influence3d)
    block = np.empty((dof * len(rows), dof * len(cols)))

    def response(k):
        traction_block(with_images(data, k), rows, cols, block)
        return np.stack([block[:, q::dof].sum(axis=1) for q in range(dof)])

    previous = response(0)
    for k in range(1, MAX_IMAGES + 1):
        current = response(k)
        scale = max(np.max(np.abs(current)), 1e-300)
        if np.max(np.abs(current - previous)) <= medium.image_tol * scale:
            return k - 1
        previous = current
    return MAX_IMAGES


def stress_at(mesh, medium, dd, points, singular_correction="none", near_fraction=0.0, n_images=None):
    """Stress (M, 2, 2) at ``points`` (M, 2) in a layered medium from the DDs ``dd`` of a
    constant-element 2D mesh (direct sum; points in void layers get zero; a point on an
    interface belongs to the layer above). ``n_images``: None = ``medium.images``, or
    for ``"auto"`` the number an :class:`ElasticityOperator` of ``mesh`` would choose."""
    from .._validation import finite_array

    if getattr(mesh, "element_order", 0) > 0:
        raise InputError("a LayeredMedium supports constant elements (element_order 0) so far")
    points = finite_array("points", points, (None, 2))
    dd = finite_array("dd", dd).reshape(mesh.n_elements, 2)
    shift = 1e-3 if singular_correction == "average" else 0.0
    data = influence_data(mesh, medium, shift, 0.0, near_fraction, 0)
    if n_images is None:
        n_images = choose_images(mesh, medium, data)
    data = with_images(data, n_images)
    point_layer = medium.layer_of(points[:, 1]).astype(np.int64)
    return finite_stress_sum(data, points, dd, point_layer, "element end")
