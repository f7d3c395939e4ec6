"""Closed-form checks of the whole chain (mesh -> kernels -> operator -> solve), as a table.

Each check returns its error against a closed form and the tolerance it must meet;
``hmatddm validate`` prints them (``--json`` for scripts).
"""
import functools
import time

import numpy as np

from .. import analytical
from ..material import Elastic
from ..mesh import line, penny
from ..elasticity.operator import ElasticityOperator
from ..elasticity.solve import opening, solve, stress_at

SHEAR_MODULUS, POISSON_RATIO, PRESSURE = 10e9, 0.25, 1e6


def _griffith(material, backend, load):
    mesh = line([-1.0, 0.0], [1.0, 0.0], 200)
    op = ElasticityOperator(mesh, material, backend=backend)
    traction = -PRESSURE * (mesh.normals if load == "pressure" else mesh.tangents)
    dd = solve(op, traction, rtol=1e-12)
    value = opening(mesh, dd) if load == "pressure" else dd[:, 0]
    s = mesh.centers[:, 0]
    exact = analytical.griffith_opening(s, 1.0, PRESSURE, material)
    inner = np.abs(s) < 0.8
    return float(np.max(np.abs(value[inner] - exact[inner])) / exact.max())


def _penny_volume(material, backend):
    mesh = penny([0, 0, 0], [0, 0, 1], 1.0, 0.05)
    dd = solve(ElasticityOperator(mesh, material, backend=backend), -PRESSURE * mesh.normals, rtol=1e-10)
    exact = analytical.sneddon_volume(1.0, PRESSURE, material)
    return float(abs(np.sum(opening(mesh, dd) * mesh.areas) - exact) / exact)


def _penny_axis(material):
    mesh = penny([0, 0, 0], [0, 0, 1], 1.0, 0.05)
    dd = solve(ElasticityOperator(mesh, material), -PRESSURE * mesh.normals)
    z = np.array([0.2, 0.5, 1.0, 2.0])
    stress = stress_at(mesh, material, dd, np.column_stack([0 * z, 0 * z, z]))
    _, sigma_z, sigma_mean = analytical.sneddon_axis_stress(z, 1.0, PRESSURE, POISSON_RATIO)
    mean = np.trace(stress, axis1=1, axis2=2) / 3
    return float(max(np.max(np.abs(stress[:, 2, 2] - sigma_z)), np.max(np.abs(mean - sigma_mean))) / PRESSURE)


@functools.lru_cache(maxsize=1)
def _radial_m_asymptotic(h=1.0, end_time=6.0):
    """Ref. Table 4.1 M case with the asymptotic front (issue 16), h = 1 m, to 6 s (R ~ 8 h):
    relative errors of the radius, the centre opening (M-vertex) and the circularity."""
    from ..flow import Cluster, Fluid
    from ..fracture import Propagation
    from ..mesh import rectangle
    from ..simulation import Simulation

    material = Elastic(shear_modulus=24e9, poisson_ratio=0.25)
    mesh = rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3 * h, 3 * h, 3, 3)
    sim = Simulation(mesh, material, Fluid(1e-3, 4.4e-10), [Cluster((0, 0, 0), 0.01, 0.005)],
                     far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                     propagation=Propagation(toughness=1e6, front="asymptotic"), initial_pressure=10e6,
                     initial_opening=4e-6)
    record = sim.run(end_time)[-1]
    radius, width = analytical.radial_m_vertex(end_time, 0.01, 1e-3, material)
    i = sim.injection_elements[0]
    centre = float(sim.state.dd[i] @ sim.state.mesh.normals[i])
    return dict(radius=abs(record["radius"] / radius - 1.0), width=abs(centre / width - 1.0),
                circularity=record["front_circularity"] - 1.0)


def checks():
    """(name, function, tolerance) of every check, cheapest first."""
    material = Elastic(shear_modulus=SHEAR_MODULUS, poisson_ratio=POISSON_RATIO)
    return [
        ("Griffith opening, 200 segments, |x|<0.8a (dense)", lambda: _griffith(material, "dense", "pressure"), 0.01),
        ("Griffith slip, remote shear (dense)", lambda: _griffith(material, "dense", "shear"), 0.01),
        ("Sneddon volume, staircase h=c/20 (dense)", lambda: _penny_volume(material, "dense"), 0.05),
        ("Sneddon on-axis stress, z/c>=0.2, /p (dense)", lambda: _penny_axis(material), 0.01),
        ("radial M-vertex radius, asymptotic front, h=1 m, 6 s", lambda: _radial_m_asymptotic()["radius"], 0.02),
        ("radial M-vertex centre opening, same run", lambda: _radial_m_asymptotic()["width"], 0.03),
        ("radial front circularity max/min - 1, same run", lambda: _radial_m_asymptotic()["circularity"], 0.05),
    ]


def run_checks(stream=None):
    """Run every check; a list of dicts with name, error, tolerance, passed, seconds.

    ``stream``: where to print a progress line per check (``[k/n] name ... error PASS
    (seconds)``; the first includes the numba compilation) and a last line with the
    wall and CPU time of all of them."""
    from ..simulation.progress import TaskProgress

    listed = checks()
    progress = TaskProgress(len(listed), stream=stream, enabled=stream is not None)
    rows = []
    for name, function, tolerance in listed:
        progress.start(name)
        t0 = time.perf_counter()
        error = function()
        rows.append(dict(name=name, error=error, tolerance=tolerance, passed=bool(error <= tolerance),
                         seconds=time.perf_counter() - t0))
        progress.done(f"error {error:.2e} {'PASS' if error <= tolerance else 'FAIL'}")
    progress.finish()
    return rows


def format_table(rows):
    width = max(len(r["name"]) for r in rows)
    lines = [f"{'check':<{width}}  {'error':>9}  {'tolerance':>9}  {'time (s)':>8}  result",
             "-" * (width + 42)]
    for r in rows:
        lines.append(f"{r['name']:<{width}}  {r['error']:9.2e}  {r['tolerance']:9.1e}  {r['seconds']:8.2f}  "
                     f"{'PASS' if r['passed'] else 'FAIL'}")
    return "\n".join(lines)
