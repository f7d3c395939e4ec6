"""Frictional slip of closed cracks against closed forms, dense and hmatrix.

A crack closed by a compressive normal stress and drained at the pore pressure is loaded
past its Coulomb strength (mu = 0.3, C_0 = 1 MPa); one coupled step (krylov scheme) with
contact on every element (:mod:`hmatddm.coupled.contact`) gives its slip, compared with

* 2D, a straight crack at 30 deg: Griffith mode II under the stress drop
  ``tau - (C_0 + mu sigma_n')``: ``s(x) = 2 (1 - nu) drop / G sqrt(a^2 - x^2)``;
* 3D, a penny crack in shear along (1, 1, 0)/sqrt(2):
  ``s(r) = 8 (1 - nu) drop / (pi (2 - nu) G) sqrt(a^2 - r^2)`` along the shear traction.

Printed per case and backend: elements, RMS slip error relative to the largest exact
slip, largest error, nonlinear and GMRES iterations, active-set changes, wall time.

    python benchmarks/bench_contact.py [--quick]
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import hmatddm as hd  # noqa: E402
from _common import machine, markdown_table  # noqa: E402
from hmatddm.mesh import topology  # noqa: E402
from hmatddm.coupled import ElasticSolver, SchemeSettings, StepProblem, solve_step  # noqa: E402
from hmatddm.coupled.contact import SLIP, ContactLaw, ContactModel  # noqa: E402
from hmatddm.flow import LeakOff, LubricationModel, fracture_compliance  # noqa: E402

G, NU = 10e9, 0.25
MATERIAL = hd.Elastic(shear_modulus=G, poisson_ratio=NU)
PORE = 5e6
FRICTION, COHESION = 0.3, 1e6


def drained_step(mesh, stress, backend):
    """One step of a crack whose every element is closed, stuck at the start and drained
    at ``PORE``: ``(dd (N, d), contact model, step info, seconds)``."""
    n, d = mesh.n_elements, mesh.dim
    start = time.perf_counter()
    operator = hd.ElasticityOperator(mesh, MATERIAL, backend=backend, eps=1e-6)
    faces = topology.element_faces(mesh, topology.element_edges(mesh, 1.0))
    flow = LubricationModel(areas=mesh.areas, normals=mesh.normals, faces=faces, fluid=hd.Fluid(1e-3, 1e-9),
                            leak_off=LeakOff(), injection_elements=np.array([0]), injection_rates=np.zeros(1),
                            wellbore_volumes=np.zeros(1), minimum_width=1e-5)
    elastic = ElasticSolver(operator)
    law = ContactLaw(np.ones(n, bool), np.full(n, FRICTION), np.full(n, COHESION))
    contact = ContactModel(law, mesh.normals, np.zeros((n, d)), np.full(n, 1), np.zeros((n, d)),
                           elastic.normal_stiffness(mesh.normals))
    problem = StepProblem(elastic=elastic, normals=mesh.normals, far_field=-(mesh.normals @ stress.T).ravel(),
                          flow=flow, compliance=fracture_compliance(mesh, MATERIAL), dt=1.0, width_old=np.zeros(n),
                          pressure_old=np.full(n, PORE), leak_off_rate=np.zeros(n), contact=contact,
                          fixed_pressure=np.full(n, PORE))
    dd, _, info = solve_step(problem, SchemeSettings(scheme="krylov"), np.zeros(n * d), np.full(n, PORE), 1.0)
    return dd.reshape(n, d), contact, info, time.perf_counter() - start


def griffith_case(n):
    """2D crack of half length 5 m at 30 deg: (mesh, stress, slip(dd), exact)."""
    a, angle = 5.0, np.radians(30.0)
    direction = np.array([np.cos(angle), np.sin(angle)])
    mesh = hd.mesh.line(-a * direction, a * direction, n)
    stress = np.diag([-30e6, -10e6])
    normal = mesh.normals[0]
    tangent = np.array([-normal[1], normal[0]])
    tau = tangent @ stress @ normal
    drop = abs(tau) - (COHESION + FRICTION * -(normal @ stress @ normal + PORE))
    x = mesh.centers @ direction
    exact = np.sign(tau) * 2 * (1 - NU) * drop / G * np.sqrt(a * a - x * x)
    return mesh, stress, lambda dd: dd @ tangent, exact


def penny_case(h):
    """Penny crack of radius 4 m in shear on the z plane: (mesh, stress, slip(dd), exact)."""
    radius = 4.0
    mesh = hd.mesh.penny([0, 0, 0], [0, 0, 1], radius, h)
    shear, normal_stress = 8e6, -10e6
    stress = np.zeros((3, 3))
    stress[2, 2] = normal_stress
    stress[0, 2] = stress[2, 0] = stress[1, 2] = stress[2, 1] = shear / np.sqrt(2)
    drop = shear - (COHESION + FRICTION * -(normal_stress + PORE))
    r = np.linalg.norm(mesh.centers[:, :2], axis=1)
    exact = 8 * (1 - NU) * drop / (np.pi * (2 - NU) * G) * np.sqrt(np.maximum(radius**2 - r * r, 0.0))
    along = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    return mesh, stress, lambda dd: dd @ along, exact


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="the two smallest sizes only")
    args = parser.parse_args(argv)
    cases = [("2D crack at 30°, Griffith mode II", griffith_case, n) for n in (60, 120, 240)]
    cases += [("3D penny in shear", penny_case, h) for h in (0.5, 0.25)]
    if args.quick:
        cases = [cases[0], cases[3]]
    print(machine())
    rows = []
    for name, build, size in cases:
        mesh, stress, slip_of, exact = build(size)
        for backend in ("dense", "hmatrix"):
            dd, contact, info, seconds = drained_step(mesh, stress, backend)
            error = slip_of(dd) - exact
            scale = np.max(np.abs(exact))
            rows.append([name, mesh.n_elements, backend, f"{np.sqrt(np.mean(error ** 2)) / scale:.2e}",
                         f"{np.max(np.abs(error)) / scale:.2e}", info["nonlinear_iterations"],
                         info["linear_iterations"], info["contact_changes"],
                         int(np.count_nonzero(contact.status == SLIP)), f"{seconds:.2f}"])
            print(" | ".join(str(c) for c in rows[-1]), flush=True)
    print()
    print(markdown_table(["case", "N", "backend", "RMS slip error", "max error", "nonlinear its", "GMRES its",
                          "status changes", "slipping", "wall s"], rows))


if __name__ == "__main__":
    main()
