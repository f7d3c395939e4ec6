"""Influence data of a 3D mesh of constant rectangles in a :class:`LayeredMedium`:
element layers, the straddling check, the automatic number of images and the stress
at points (the splitter is :func:`hmatddm.layered.split_at_interfaces`). The kernels
are :mod:`.images3d` (kernel data :class:`.images3d.LayeredRectangles`, served by the
drivers of :mod:`hmatddm.kernels.drivers`)."""
import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..kernels.drivers import with_self_max
from . import images3d, okada3d, okada_point3d, remainder_build3d, stress3d, vertical3d
from .image_tracer3d import trace_points
from .influence2d import choose_images as _choose_images
from .influence2d import layers_of_extents, with_images
from .rectangle_quadrature import ENTRY_TOL, NEAR_GAUSS_POINTS, entry_scale

#: Largest number of sub-squares per side of a rectangle for the image quadrature.
MAX_SUBDIVISIONS = 16
#: Fewest elements for which ``method="table"`` builds the remainder table: below, every
#: triple is integrated (the table's build, seconds, costs more than it saves: measured on
#: ``layered-3d``, 73 elements, 50.3 s of CPU with the table against 44.3 s without; on the
#: 576 squares of issue 32, 6 s to build and 22.5 s to assemble against 88.6 s;
#: benchmarks/RESULTS.md, issue 32).
TABLE_MIN_ELEMENTS = 400
#: Relative tolerance (of the element size) within which a corner counts as on an interface.
_ON_INTERFACE = 1e-9

__all__ = ["element_layers", "influence_data", "with_images", "choose_images", "stress_at",
           "mean_stress_at"]


def element_layers(mesh, medium):
    """(N,) layer of each rectangle (of its centre); InputError naming the first
    rectangle that straddles an interface, lies in one (unless all layers have the same
    moduli), or sits in a void layer (:func:`.influence2d.layers_of_extents`)."""
    if mesh.dim != 3:
        raise InputError("element_layers of influence3d takes a Mesh3D")
    z = mesh.corners()[:, :, 2]
    return layers_of_extents(medium, z.min(axis=1), z.max(axis=1), _ON_INTERFACE * np.maximum(mesh.radii, 1e-300),
                             mesh.fracture_id, noun="rectangle")


def influence_data(mesh, medium, singular_shift, alpha, near_fraction, n_images, with_table=True):
    """The kernel data (:class:`images3d.LayeredRectangles`) of ``mesh`` in ``medium``
    with ``n_images`` images; ``alpha > 0`` fills ``self_max`` for ref. Eq. 6.11. With
    ``medium.method == "table"``, far image triples (two or more interfaces) and at least
    :data:`TABLE_MIN_ELEMENTS` elements, the layered remainder's table
    (:func:`remainder_table`). In a half-space (:func:`is_half_space`) with ``medium.method``
    other than ``"quadrature"``, the elements with a horizontal side take their image and
    surface terms in closed form (:mod:`.okada3d`; ``closed_form``), the others by the image
    quadrature's rule of Okada's point source (:mod:`.okada_point3d`; ``point_form``).
    With two or more solid layers under a void (:func:`surface_form`), the elements of the
    top solid layer with a horizontal side take their reflection in the free surface in
    closed form (``surface_form``) and their other triples by quadrature. Vertical
    rectangles in a medium with interfaces (not a half-space, not ``"quadrature"``, at least
    one image) take their near triples in closed form next to them (``vertical_form``,
    :mod:`.vertical3d`). The quadrature takes at least :data:`.rectangle_quadrature.NEAR_GAUSS_POINTS`
    per side next to the images (the medium's ``gauss_points`` when larger), and on one square
    the points :func:`.rectangle_quadrature.entry_order` needs for :data:`ENTRY_TOL` of the
    largest entry. ``with_table=False``: never a table (the stress at points,
    :func:`stress_at`, takes every triple itself)."""
    layers = element_layers(mesh, medium)
    interfaces, g, nu = medium.arrays()
    scale = entry_scale(mesh.half_a, mesh.half_b, layers, g, nu) / g.max() if interfaces.shape[0] > 0 else 0.0
    table = remainder_build3d.empty_table(g.shape[0])
    if (with_table and medium.method == "table" and n_images > 0 and interfaces.shape[0] >= 2
            and mesh.n_elements >= TABLE_MIN_ELEMENTS):
        table = remainder_table(mesh, medium, layers, int(n_images), scale * g.max())[0]
    closed, okada, half = okada3d.halfspace_geometry(mesh.frames, mesh.half_a, mesh.half_b)
    surface = closed & (layers == 1) & surface_form(medium, int(n_images))
    vertical = (closed & (np.abs(okada[:, 1, 2]) >= vertical3d.VERTICAL) & (interfaces.shape[0] > 0)
                & (medium.method != "quadrature") & (int(n_images) >= 1) & (not is_half_space(medium)))
    if not is_half_space(medium) or medium.method == "quadrature":
        closed[:] = False
    # a half-space source without a horizontal side: Okada's point source at the Gauss points
    point = np.zeros(mesh.n_elements, dtype=np.bool_)
    if is_half_space(medium) and medium.method != "quadrature":
        rows, has_strike = okada_point3d.point_frames(mesh.frames[:, 2])
        point = has_strike & ~closed
        okada[point] = rows[point]
    return with_self_max(images3d.with_image_terms(images3d.LayeredRectangles(
        mesh.centers, mesh.frames, mesh.half_a, mesh.half_b, layers, interfaces, g, nu, n_images=int(n_images),
        gauss_points=max(int(medium.gauss_points), NEAR_GAUSS_POINTS), max_subdivisions=int(MAX_SUBDIVISIONS),
        singular_shift=float(singular_shift), near_fraction=float(near_fraction), alpha=float(alpha),
        self_max=np.zeros(mesh.n_elements), entry_tol=float(ENTRY_TOL), entry_scale=float(scale), table=table,
        closed_form=closed, okada=okada, okada_half=half,
        surface=float(interfaces[0]) if interfaces.shape[0] else 0.0, surface_form=surface, vertical_form=vertical,
        point_form=point)))


def is_half_space(medium):
    """True when ``medium`` is a half-space: one solid layer under a void one (a free
    surface at ``interfaces[0]``), the case :mod:`.okada3d` gives in closed form."""
    return medium.n_layers == 2 and medium.shear_modulus[0] == 0.0 and medium.shear_modulus[1] > 0.0


def surface_form(medium, n_images):
    """True when the sources of the top solid layer of ``medium`` take their reflection in
    the free surface in closed form (:mod:`.okada3d`) and the rest of their images by the
    image method: two or more solid layers under a void one (a half-space, one solid layer,
    takes every image in closed form: :func:`is_half_space`), ``method`` other than
    ``"quadrature"``, at least one image, and the reflection alone at its point
    (:func:`surface_reflection_alone`)."""
    return (medium.n_layers >= 3 and medium.shear_modulus[0] == 0.0 and medium.method != "quadrature"
            and n_images >= 1 and surface_reflection_alone(medium, n_images))


def surface_reflection_alone(medium, n_images):
    """True when the triple of the top solid layer whose point is the source's mirror in
    the free surface (``2 d_0 - t``, ``eps = -1``) is, at three source heights, the
    half-space's image triple coefficient for coefficient, so that no other path of the
    tracer merged into it (:func:`.image_tracer3d.merge_coincident`; a merged path would
    need reflections at depths whose alternating sum is the surface's, a coincidence of
    the layer thicknesses) and :mod:`.okada3d` gives exactly that triple's field."""
    interfaces, g, nu = medium.arrays()
    top, bottom = interfaces[0], interfaces[1]
    heights = top + (bottom - top) * np.array([0.2, 0.5, 0.8])
    layered = trace_points(heights, 1, interfaces, g, nu, n_images)
    half = trace_points(heights, 1, interfaces[:1], g[:2], nu[:2], 1)
    orders = half[5].shape[-1]
    for p, t in enumerate(heights):
        n_pairs, layer, z, eps = layered[0][p], layered[1][p], layered[2][p], layered[3][p]
        found = [k for k in range(n_pairs) if layer[k] == 1 and eps[k] < 0.0
                 and abs(z[k] - (2.0 * top - t)) <= 1e-12 * (1.0 + abs(z[k]))]
        if len(found) != 1 or half[0][p] != 1:
            return False
        coef, dcoef = layered[5][p, found[0]], layered[6][p, found[0]]
        scale = np.abs(half[5][p, 0]).max()
        if coef.shape[-1] < orders or np.abs(coef[:, :, orders:]).max(initial=0.0) > 1e-13 * scale:
            return False
        if (np.abs(coef[:, :, :orders] - half[5][p, 0]).max() > 1e-13 * scale
                or np.abs(dcoef[:, :, :orders] - half[6][p, 0]).max() > 1e-13 * np.abs(half[6][p, 0]).max()):
            return False
    return True


#: Tables built in this process, by medium, images, tolerance and domain (the latest few).
_TABLES = {}
_KEEP_TABLES = 4


def remainder_table(mesh, medium, layers, n_images, largest_entry):
    """``(table, stats)``: the remainder table of ``medium`` at ``n_images`` covering
    ``mesh`` (:func:`.remainder_build3d.build_table` to ``medium.table_tol`` of
    ``largest_entry``), reused for every mesh with the same
    :func:`.remainder_build3d.table_domain` (a growing fracture builds it again only when
    its extent doubles; a resumed run gets the table of the run it resumes)."""
    interfaces, g, nu = medium.arrays()
    domain = remainder_build3d.table_domain(mesh, layers, interfaces, g)
    key = (medium.interfaces, medium.shear_modulus, medium.poisson_ratio, float(medium.table_tol), int(n_images),
           domain, float(largest_entry))
    if key in _TABLES:
        table, stats = _TABLES.pop(key)
    else:
        table, stats = remainder_build3d.build_table(mesh, layers, interfaces, g, nu, n_images, medium.table_tol,
                                                     largest_entry)
    _TABLES[key] = (table, stats)
    while len(_TABLES) > _KEEP_TABLES:
        del _TABLES[next(iter(_TABLES))]
    return table, stats


def choose_images(mesh, medium, data, max_samples=12, max_sources=120):
    """The number of images (see :func:`hmatddm.layered.influence2d.choose_images`,
    same criterion, with the 3D kernels, on fewer samples: a 3D pair with many images
    costs milliseconds). A half-space with ``images="auto"``: 1, the exact number (one
    reflection in the free surface), without sampling."""
    if medium.images == "auto" and is_half_space(medium):
        return 1
    return _choose_images(mesh, medium, data, max_samples, max_sources)


def _prepared(mesh, medium, dd, points, singular_correction, near_fraction, n_images):
    from ..options import AVERAGE_SHIFT

    points = finite_array("points", points, (None, 3))
    dd = finite_array("dd", dd).reshape(mesh.n_elements, 3)
    shift = AVERAGE_SHIFT if singular_correction == "average" else 0.0
    data = influence_data(mesh, medium, shift, 0.0, near_fraction, 0, with_table=False)
    if n_images is None:
        n_images = choose_images(mesh, medium, data)
    if int(n_images) == 0:
        return points, dd, data
    # built again for the number of images: the closed forms that need at least one
    # (surface_form, vertical_form) are decided with it
    return points, dd, influence_data(mesh, medium, shift, 0.0, near_fraction, int(n_images), with_table=False)


def stress_at(mesh, medium, dd, points, singular_correction="none", near_fraction=0.0, n_images=None):
    """Stress (M, 3, 3) at ``points`` (M, 3) in a layered medium from the DDs ``dd``
    (N, 3) of a :class:`Mesh3D` (direct sum, parallel over points, each source's image
    triples traced once: :mod:`.stress3d`; vertical rectangles' triples in closed form
    next to their images; points in void layers get zero; a point on an interface
    belongs to the layer above).
    ``n_images``: None = ``medium.images``, or for ``"auto"`` the number an
    :class:`ElasticityOperator` of ``mesh`` would choose."""
    if mesh.dim != 3:
        raise InputError("influence3d.stress_at takes a Mesh3D")
    points, dd, data = _prepared(mesh, medium, dd, points, singular_correction, near_fraction, n_images)
    out = stress3d.stress_sum(data, points, dd, medium.layer_of(points[:, 2]).astype(np.int64))
    bad = np.flatnonzero(~np.all(np.isfinite(out.reshape(len(out), -1)), axis=1))
    if bad.size:  # the message of kernels.drivers.finite_stress_sum
        raise InputError(f"points[{int(bad[0])}] lies on an element edge, where the stress is singular; move it or "
                         "pass singular_correction='average'")
    return out


def mean_stress_at(mesh, medium, dd, points, singular_correction="none", near_fraction=0.0, n_images=None):
    """Mean stress ``tr(sigma) / 3`` (M,) at ``points``; see :func:`stress_at`."""
    stress = stress_at(mesh, medium, dd, points, singular_correction, near_fraction, n_images)
    return np.trace(stress, axis1=1, axis2=2) / 3.0
