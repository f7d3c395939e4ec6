"""Why the Ch. 6 network run has no remotely failed natural element (issue 36 item 3): the
Coulomb margin of the natural fractures at the stresses of ref. Table 6.2 against Table 5.2.

    python benchmarks/bench_remote_margin.py

First the far field alone: for a vertical natural fracture at azimuth theta from x, the
ratio of its shear stress to its frictional strength ``tau / (mu (sigma_n - p))`` (1:
failure), at ref. Table 6.2 (S_Hmax 36.44, S_hmin 35.85 MPa, p 27.01 MPa) and at the
S_Hmax 39.44 MPa of ref. Fig. 6.12 / Table 5.2 (p 30.2 MPa). Then the planar fracture of
benchmarks/bench_poroelastic.py (Sec. 5.3.3 set-up, 25 s) with the natural fractures checked
every step, at both stress states, Skempton B = 1 as in Table 6.2: how many elements fail.
"""
import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import sys  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from _common import machine, print_table  # noqa: E402

import bench_poroelastic as study  # noqa: E402

STATES = (("Table 6.2 (S_Hmax 36.44, p 27.01)", 35.85e6, 36.44e6, 27.01e6),
          ("Table 6.2 stresses, S_Hmax 39.44 (Fig. 6.12)", 35.85e6, 39.44e6, 27.01e6),
          ("Table 5.2 (S_Hmax 39.44, p 30.20)", 35.85e6, 39.44e6, 30.20e6))


def ratio(s_hmin, s_hmax, pore, azimuth_deg, friction=0.25):
    """tau / (mu sigma_n') of a vertical plane at ``azimuth_deg`` from x (S_hmin along x)."""
    theta = np.radians(azimuth_deg)
    normal = np.array([-np.sin(theta), np.cos(theta)])
    stress = np.diag([s_hmin, s_hmax])  # compression positive
    traction = stress @ normal
    sigma_n = traction @ normal
    tau = np.linalg.norm(traction - sigma_n * normal)
    return tau / (friction * (sigma_n - pore))


def main():
    print(f"Machine: {machine()}")
    rows = [[name] + [f"{ratio(lo, hi, p, a):.3f}" for a in (15, 30, 45, 60, 75)] for name, lo, hi, p in STATES]
    print_table(["stress state", "theta 15", "30", "45", "60", "75 deg"], rows)
    study.constants = lambda fluid_bulk_modulus, b_only=False: (0.25, 1.0)  # Table 6.2: nu 0.25, B = 1
    rows = []
    for name, lo, hi, p in STATES:
        study.FAR_FIELD = -np.diag([lo, hi, study.S_V])
        study.PORE_PRESSURE = p
        failed = [study.run_case(name, None, 25.0, seed)["failed"] for seed in range(1, 6)]
        rows.append([name, " / ".join(str(f) for f in failed)])
    print_table(["stress state (planar fracture of Sec. 5.3.3, B = 1, 25 s)", "failed NF elements, seeds 1-5"], rows)


if __name__ == "__main__":
    main()
