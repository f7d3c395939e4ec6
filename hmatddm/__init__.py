"""hmatddm: hydraulic fractures with the displacement discontinuity method and H-matrices.

Conventions (docs/conventions.md §1): SI units, tension positive, ``DD = u(+) - u(-)`` with
``+`` the face the element normal points to, opening ``w = DD . n > 0`` when open, DD and
tractions in the global frame, element-major.

Quick tour::

    import hmatddm as hd
    mat = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    mesh = hd.mesh.penny([0, 0, 0], [0, 0, 1], radius=1.0, h=0.1)
    op = hd.ElasticityOperator(mesh, mat, backend="hmatrix", eps=1e-4)
    dd = hd.solve(op, -1e6 * mesh.normals)      # crack under 1 MPa net pressure
    w = hd.opening(mesh, dd)

A growing radial fracture (ref. Ch. 4)::

    sim = hd.Simulation(hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3, 3, 3, 3),
                        hd.Elastic(24e9, 0.25), hd.Fluid(viscosity=1e-3, compressibility=4.4e-10),
                        [hd.Cluster((0, 0, 0), rate=0.01, wellbore_volume=0.005)],
                        far_field_stress=-8e6 * np.diag([0, 0, 1]), time_step=1.0,
                        propagation=hd.Propagation(toughness=5e6), initial_pressure=10e6)
    records = sim.run(end_time=50.0)
"""
import os

# numba's OpenMP workers spin-wait by default; on a shared 2-core machine that made one
# small H-matvec take 9.5 ms instead of 0.45 ms (measured, benchmarks/bench_dfn.py).
# Must be set before numba starts its threads; an explicit user setting wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from . import analytical, kernels, mesh, network, topology  # noqa: E402
from .coupled import SchemeSettings
from .errors import ConvergenceError, HmatddmError, InputError, OutputError
from .flow import Cluster, Fluid, LeakOff
from .fracture import NaturalFractureProperties, Propagation
from .material import Elastic
from .mesh import Mesh2D, Mesh3D
from .operators import ElasticityOperator
from .simulation import CheckpointError, Simulation
from .solve import mean_stress_at, opening, slip, solve, stress_at

__version__ = "0.1.0"

__all__ = [
    "Elastic", "Mesh2D", "Mesh3D", "ElasticityOperator", "solve", "opening", "slip", "stress_at",
    "mean_stress_at", "mesh", "analytical", "kernels", "topology", "HmatddmError", "InputError", "ConvergenceError", "OutputError",
    "Fluid", "LeakOff", "Cluster", "Propagation", "NaturalFractureProperties", "network", "SchemeSettings", "Simulation", "CheckpointError",
]
