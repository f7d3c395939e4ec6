"""A pressurised penny-shaped crack against Sneddon's closed form (static, no flow).

A disc of radius 1 m, meshed by square elements of 5 cm (a staircase disc, ~1250
elements), carries a uniform net pressure of 1 MPa in rock with G = 10 GPa and
nu = 0.25. The DDM solution (H-matrix backend, GMRES) is compared with Sneddon's
opening ``4 (1 - nu) p / (pi G) sqrt(c^2 - r^2)`` and volume; the result is written
for ParaView (VTU) and as a PNG snapshot in ``examples_out/pressurised_crack/``.

Run: ``python examples/pressurised_crack.py`` (about 10 s).
"""
import time
from pathlib import Path

import numpy as np

import hmatddm as hd
from hmatddm.io import write_vtu

RADIUS, H, PRESSURE = 1.0, 0.05, 1e6  # m, m, Pa
OUT = Path("examples_out/pressurised_crack")


def main():
    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    mesh = hd.mesh.penny(center=[0, 0, 0], normal=[0, 0, 1], radius=RADIUS, h=H)
    start = time.perf_counter()
    op = hd.ElasticityOperator(mesh, material, backend="hmatrix", eps=1e-4)
    dd, info = hd.solve(op, -PRESSURE * mesh.normals, rtol=1e-10, return_info=True)  # op @ dd = -p n
    seconds = time.perf_counter() - start
    w = hd.opening(mesh, dd)

    r = np.linalg.norm(mesh.centers[:, :2], axis=1)
    exact = hd.analytical.sneddon_opening(r, RADIUS, PRESSURE, material)
    inner = r < 0.8 * RADIUS  # away from the staircase edge
    volume = float(np.sum(w * mesh.areas))
    exact_volume = hd.analytical.sneddon_volume(RADIUS, PRESSURE, material)
    print(f"{mesh.n_elements} elements, H-matrix compression {op.stats['compression']:.1f}x, "
          f"build + solve {seconds:.2f} s ({info['iterations']} GMRES iterations)")
    print(f"opening at the centre: {1e3 * w[np.argmin(r)]:.5f} mm (Sneddon {1e3 * exact.max():.5f} mm)")
    print(f"max relative opening error for r < 0.8 c: {np.max(np.abs(w[inner] - exact[inner])) / exact.max():.2%}")
    print(f"volume {volume:.4e} m^3 (Sneddon {exact_volume:.4e} m^3, {volume / exact_volume - 1:+.2%}; "
          "the staircase disc is not exactly round)")

    path = write_vtu(OUT / "penny.vtu", mesh, {"opening": w, "sneddon_opening": exact, "dd": dd})
    print(f"wrote {path}")
    try:
        from hmatddm.render import snapshot

        print(f"wrote {snapshot(mesh, OUT / 'penny.png', opening=w, view='oblique', title='penny crack, 1 MPa')}")
    except hd.HmatddmError as error:  # no offscreen OpenGL on this machine
        print(f"no snapshot: {error}")


if __name__ == "__main__":
    main()
