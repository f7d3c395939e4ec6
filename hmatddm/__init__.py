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
from ._lazy import attach
from ._version import __version__

# Everything below is imported on first use (PEP 562), so that ``import hmatddm`` is
# quick and loads neither numba, the H-matrix engine, scipy.special, pyvista nor
# matplotlib. The package changes no environment variable: the ``hmatddm`` command sets
# ``OMP_WAIT_POLICY=PASSIVE`` (unless already set) before numba starts its threads, and
# a Python program on a shared machine can do the same (see the README, "Threads").
_EXPORTS = {
    "SchemeSettings": ".coupled", "ConvergenceError": ".errors", "HmatddmError": ".errors",
    "InputError": ".errors", "OutputError": ".errors", "Cluster": ".flow", "Fluid": ".flow", "LeakOff": ".flow",
    "NaturalFractureProperties": ".fracture", "Propagation": ".fracture", "Elastic": ".material",
    "Mesh2D": ".mesh", "Mesh3D": ".mesh", "ElasticityOperator": ".elasticity", "CheckpointError": ".simulation",
    "Simulation": ".simulation", "mean_stress_at": ".elasticity", "opening": ".elasticity", "slip": ".elasticity",
    "solve": ".elasticity", "stress_at": ".elasticity", "opening_at": ".elasticity", "LayeredMedium": ".layered",
    "UndrainedRock": ".fracture", "displacement_at": ".elasticity",
}
# the rooms (docs/architecture.md), and the short names that modules now in a room had
# at the package root, kept so that ``hd.topology``, ``hd.operators``, ... still work
_SUBMODULES = {name: "." + name for name in (
    "analytical", "kernels", "mesh", "network", "simulation", "scene", "render", "io", "hmatrix", "coupled", "flow",
    "fracture", "errors", "material", "layered", "elasticity", "app", "microseismic", "settings", "options")}
_SUBMODULES.update({
    "topology": ".mesh.topology", "shape_functions": ".mesh.shape_functions", "operators": ".elasticity.operator",
    "extended_operator": ".elasticity.extended", "nodal": ".elasticity.nodal", "runner": ".app.runner",
    "ensemble": ".app.ensemble", "validate": ".app.validate", "cli": ".app.cli", "bench_cli": ".app.bench",
})
__getattr__, __dir__ = attach(__name__, _EXPORTS, _SUBMODULES)

__all__ = [
    "Elastic", "Mesh2D", "Mesh3D", "ElasticityOperator", "solve", "opening", "opening_at", "slip", "stress_at",
    "mean_stress_at", "mesh", "analytical", "kernels", "topology", "HmatddmError", "InputError", "ConvergenceError", "OutputError",
    "Fluid", "LeakOff", "Cluster", "Propagation", "NaturalFractureProperties", "network", "SchemeSettings", "Simulation", "CheckpointError",
    "LayeredMedium", "layered", "UndrainedRock", "displacement_at",
]
