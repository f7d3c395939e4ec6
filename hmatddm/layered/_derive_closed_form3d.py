"""What a closed form of the 3D image triples beyond the half-space would take (issue 32,
item 1): the measurements behind the docstring of :mod:`.images3d`. Not imported by the
package; run ``python -m hmatddm.layered._derive_closed_form3d`` (about a minute).

1. :func:`coefficient_degrees`: the coefficient of ``D^n`` of every traced triple (ref.
   Eqs 3.25-3.28, :mod:`.image_tracer3d`) is a polynomial in the source height ``t`` of
   degree at most ``min(n, 2)``: fitted to round-off at 17 heights for every triple of a
   free surface over two interfaces (G, 2G, G), ``images`` 1 to 4, sources in both upper
   layers. The degree does not grow with the number of reflections (measured, not
   derived here: the products of the ``h D`` and ``h^2 D^2`` of successive reflections
   cancel beyond degree 2); the ``D`` order does (up to 5 at ``images=4``). So every
   triple is, like the half-space's image, a point-source field whose weights are
   quadratic in the source height: the integrals over a rectangle with a horizontal side
   are elementary (polynomials of degree <= 2 along the dip times derivatives of ``F``,
   ``L`` and ``1/r``), but each needs its own primitives (item 2).
2. :func:`okada_group_residual`: Okada's (1992) image terms split by his coefficient
   groups (part A: ``a1``, ``a2``; part B: 1, ``a3``; part C: 1, ``a4``, ``a5``; seven
   fields, each summed over the corners exactly as :mod:`.okada3d` sums them) do not span
   the reflected triple of a bi-material interface: least squares with separate weights per
   dislocation component leave 0.3-1.2 % of the field (a half-space, G above = 0: 4e-15).
   So no reweighting of the half-space closed form gives a reflection at an interface
   between two solids; a closed form needs the primitives of the triple's own terms.
3. The one triple beyond the half-space that *is* Okada's: the reflection of a top-layer
   source in the free surface, coefficient for coefficient the half-space's
   (:func:`hmatddm.layered.influence3d.surface_reflection_alone`), now taken in closed form.
"""
import inspect
import re
import types

import numpy as np

from . import okada3d
from .image_tracer3d import trace_points
from .rectangle_quadrature import image_rectangle_stress


def coefficient_degrees(images=(1, 2, 4), n_heights=17):
    """``{(source_layer, images): {(n, degree): count}}`` over the triples of a free
    surface over interfaces at 0, -10, -20 (G, 2G, G): the smallest polynomial degree in
    ``t`` that fits the coefficients of ``D^n`` to 1e-9 of their size."""
    interfaces = np.array([0.0, -10.0, -20.0])
    g = np.array([0.0, 1.0, 2.0, 1.0])
    nu = np.full(4, 0.25)
    found = {}
    for layer, (lo, hi) in ((1, (-9.5, -0.5)), (2, (-19.5, -10.5))):
        heights = np.linspace(lo, hi, n_heights)
        for n_images in images:
            n_pairs, _, _, _, _, coef, _ = trace_points(heights, layer, interfaces, g, nu, n_images)
            counts = {}
            for k in range(n_pairs[0]):
                for order in range(coef.shape[-1]):
                    values = coef[:, k, :, :, order].reshape(n_heights, -1)
                    if np.abs(values).max() == 0.0:
                        continue
                    degree = next(d for d in range(n_heights) if _fits(heights, values, d))
                    counts[order, degree] = counts.get((order, degree), 0) + 1
            found[layer, n_images] = dict(sorted(counts.items()))
    return found


def _fits(heights, values, degree):
    v = np.vander(heights, degree + 1)
    solution = np.linalg.lstsq(v, values, rcond=None)[0]
    return np.abs(v @ solution - values).max() <= 1e-9 * np.abs(values).max()


def _okada_groups():
    """:mod:`.okada3d` with the image corners' coefficients and parts as arguments: its
    source, rewritten (the seven fields of item 2 are its parts with one coefficient on)."""
    source = inspect.getsource(okada3d).replace("cache=True", "cache=False")
    source = source.replace("def _image_corners(q, z, sd, cd, alpha, c4):",
                            "def _image_corners(q, z, sd, cd, alpha, c4, co):")
    source = re.sub(r"    a1 = 0\.5 \* \(1\.0 - alpha\)\n    a2 = 0\.5 \* alpha\n    a3 = \(1\.0 - alpha\) / alpha\n"
                    r"    a4 = 1\.0 - alpha\n    a5 = alpha\n",
                    "    a1, a2, a3, a4, a5, k_a, k_b, k_c = co[0], co[1], co[2], co[3], co[4], co[5], co[6], co[7]\n",
                    source)
    lines, inside = [], False
    for line in source.split("\n"):
        inside = line.strip().startswith("_store(c4") or (inside and not lines[-1].rstrip().endswith(")"))
        if inside:
            line = re.sub(r"a\[(\d+)\]", r"k_a * a[\1]", line)
            line = re.sub(r"\bB(\d{3})\b", r"k_b * B\1", line)
            line = re.sub(r"\bz \* W(\d{3})", r"k_c * z * W\1", line)
            line = re.sub(r"\bU(\d\d)\b", r"k_c * U\1", line)
        lines.append(line)
    source = "\n".join(lines)
    for name, args in (("gradient", "s, c4"), ("_gradient", "work, c4")):
        source = re.sub(rf"(def {name}\([^)]*{args})\)", r"\1, co)", source)
    source = source.replace("_image_corners(q, z, sd, cd, alpha, c4)\n", "_image_corners(q, z, sd, cd, alpha, c4, co)\n")
    source = source.replace("alpha, real, image, work, c4)\n    return", "alpha, real, image, work, c4, co)\n    return")
    source = re.sub(r"(def okada_stress\([^)]*out)\)", r"\1, co)", source)
    source = source.replace("real, image, work, c4)\n    # Hooke", "real, image, work, c4, co)\n    # Hooke")
    module = types.ModuleType("okada_groups")
    exec(compile(source, "okada_groups", "exec"), module.__dict__)
    return module


def okada_group_residual(upper=(0.0, 0.5, 2.0), nu_upper=(0.25, 0.25, 0.3), seed=1, n_points=40):
    """Largest residual (relative to the field) of the least-squares fit of the reflected
    triple's stress (one interface at z = 0, G above in ``upper``, G = 1 below, a tilted
    square of side 0.5 at 0.8 m below it, 40 receivers in the lower layer; image
    quadrature with 12 points on 16 x 16 sub-squares) by the seven Okada groups, weights
    per dislocation component, for each upper modulus."""
    groups = _okada_groups()
    rng = np.random.default_rng(seed)
    strike, dip = 0.4, 1.1
    s = np.array([np.cos(strike), np.sin(strike), 0.0])
    t = np.array([-np.sin(strike) * np.cos(dip), np.cos(strike) * np.cos(dip), np.sin(dip)])
    frame = np.array([s, t, np.cross(s, t)])
    center = np.array([0.1, -0.2, -0.8])
    a = b = 0.25
    _, rows, half = okada3d.halfspace_geometry(frame[None], np.array([a]), np.array([b]))
    points = [np.array([rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(-2.5, -0.05)])
              for _ in range(n_points)]
    work, c4, out = np.empty((5, 3, 3, 3)), np.empty((30, 4)), np.empty((3, 3, 3))

    def okada(co):
        fields = []
        for y in points:
            groups.okada_stress(y, center, rows[0], half[0, 0], half[0, 1], 0.0, 1.0, 0.25, False, True, work, c4, out,
                                np.array(co, dtype=float))
            fields.append(np.einsum("kq,qij->kij", rows[0], out))
        return np.array(fields)

    on = np.eye(5)
    b1, c1 = okada([0, 0, 0, 0, 0, 0, 1, 0]), okada([0, 0, 0, 0, 0, 0, 0, 1])
    basis = [okada([*on[0], 1, 0, 0]), okada([*on[1], 1, 0, 0]), b1, okada([*on[2], 0, 1, 0]) - b1, c1,
             okada([*on[3], 0, 0, 1]) - c1, okada([*on[4], 0, 0, 1]) - c1]
    residuals = []
    for g_up, nu_up in zip(upper, nu_upper):
        target = []
        for y in points:
            image_rectangle_stress(y, 1, center, frame, a, b, 1, np.array([0.0]), np.array([g_up, 1.0]),
                                   np.array([nu_up, 0.25]), 1, 12, 16, out, False, np.zeros(2), np.zeros(2))
            target.append(np.einsum("kq,qij->kij", rows[0], out))
        target = np.array(target)
        worst = 0.0
        for k in range(3):
            m = np.stack([f[:, k].ravel() for f in basis], axis=1)
            weights = np.linalg.lstsq(m, target[:, k].ravel(), rcond=None)[0]
            worst = max(worst, np.abs(m @ weights - target[:, k].ravel()).max())
        residuals.append(worst / np.abs(target).max())
    return residuals


if __name__ == "__main__":
    for key, counts in coefficient_degrees().items():
        print(f"source layer {key[0]}, images={key[1]}: (D order, degree in t): triples {counts}")
    print("Okada groups against the reflected triple, G above = 0 (half-space), 0.5, 2 (nu 0.3):",
          ", ".join(f"{r:.1e}" for r in okada_group_residual()))
