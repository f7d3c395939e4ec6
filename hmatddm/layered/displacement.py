"""Displacement at points of the DDs of a mesh in a :class:`LayeredMedium` (ref. Eqs 2.43,
2.55-2.57 and Ch. 3): the direct sum of :mod:`.displacement3d` (3D rectangles) and
:mod:`.displacement2d` (2D segments, plane strain), behind
:func:`hmatddm.displacement_at` and the ``[[monitor]]`` section for layered scenes.

The layered stress at points (:func:`.influence3d.stress_at`) has no H-matrix path, and
neither has this: a monitor array has few points.
"""
import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..kernels.drivers import _in_parts

__all__ = ["point_layers", "displacement_at"]


def point_layers(medium, points, vertical):
    """(M,) int64 layer of each point (``points[:, vertical]`` its height): the layer
    below an interface whose upper layer is void (a point on the free surface is in the
    rock), else :meth:`LayeredMedium.layer_of`. InputError naming the first point inside
    a void layer, where there is no rock to displace."""
    height = points[:, vertical]
    layers = np.asarray(medium.layer_of(height), dtype=np.int64)
    g = np.asarray(medium.shear_modulus, dtype=float)
    interfaces = np.asarray(medium.interfaces, dtype=float)
    for k, level in enumerate(interfaces):
        on = (height == level) & (g[layers] == 0.0)
        layers[on] = k + 1
    void = np.flatnonzero(g[layers] == 0.0)
    if void.size:
        i = int(void[0])
        k = int(layers[i])
        side = f"above the free surface at {'xyz'[vertical]} = {interfaces[0]:g}" if k == 0 else \
            f"below the free surface at {'xyz'[vertical]} = {interfaces[-1]:g}"
        raise InputError(f"points[{i}] lies in the void layer {k} ({side}), where there is no rock to displace; "
                         "move it into the rock (a point on the surface is in the rock)")
    return layers


def displacement_at(mesh, medium, dd, points, n_images=None):
    """Displacement (M, d) at ``points`` (M, d) of the global DDs ``dd`` ((N, d) or
    (N*d,)) of the constant elements of ``mesh`` in ``medium`` (direct sum, parallel over
    points). ``n_images``: None: the number the layered stress at points takes
    (:func:`.influence2d.choose_images`). A point on an element edge (an end in 2D),
    where the displacement is log-singular, raises InputError; on an element's face the
    value is its ``+`` side's."""
    if getattr(mesh, "n_nodes", 1) > 1:
        raise InputError("displacement_at in a LayeredMedium takes constant elements (element_order 0)")
    dim = mesh.dim
    points = np.ascontiguousarray(finite_array("points", points, (None, dim)), dtype=np.float64)
    dd = finite_array("dd", dd)
    if dd.shape not in ((mesh.n_elements, dim), (mesh.n_elements * dim,)):
        raise InputError(f"dd must have shape ({mesh.n_elements}, {dim}) or ({mesh.n_elements * dim},), "
                         f"got {dd.shape}")
    dd = np.ascontiguousarray(dd.reshape(mesh.n_elements, dim), dtype=np.float64)
    layers = point_layers(medium, points, dim - 1)
    if dim == 3:
        from .displacement3d import displacement_block
        from .influence3d import choose_images, influence_data, with_images
    else:
        from .displacement2d import displacement_block
        from .influence2d import choose_images, influence_data, with_images
    data = influence_data(mesh, medium, 0.0, 0.0, 0.0, 0)
    if n_images is None:
        n_images = choose_images(mesh, medium, data)
    data = with_images(data, n_images)
    out = np.zeros((len(points), dim))

    def part(start, stop):
        displacement_block(data, points[start:stop], layers[start:stop], dd, out[start:stop])

    # one range of points per thread: each range traces every element's image heights once
    # (milliseconds per height with several interfaces), so fewer, longer ranges trace less
    _in_parts(part, len(points), parts_per_thread=1)
    bad = np.flatnonzero(~np.all(np.isfinite(out), axis=1))
    if bad.size:
        raise InputError(f"points[{int(bad[0])}] lies on an element {'edge' if dim == 3 else 'end'}, where the "
                         "displacement is singular; move it")
    return out
