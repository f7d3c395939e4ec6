"""A shared case of the coupled tests (tests/coupled/test_contact.py, test_acceleration.py):
a 2D hydraulic fracture growing towards an inclined natural fracture under a low stress
contrast (its elements fail remotely, join closed and slip), and the contact conditions its
answer must meet. Imported by name (tests/ is on the path: tests/conftest.py)."""
import numpy as np

import hmatddm as hd
from hmatddm.coupled.contact import OPEN, SLIP
from hmatddm.fracture import NaturalFractureProperties


def network_simulation(backend="dense"):
    """The network case's :class:`hmatddm.Simulation`, not run."""
    mat = hd.Elastic(3.415e9, 0.23)
    hf = hd.mesh.line([-0.075, 0], [0.075, 0], 3)
    a = np.deg2rad(60.0)
    center, tangent = np.array([0.2, 0.0]), np.array([np.cos(a), np.sin(a)])
    nf = hd.mesh.line(center - 0.15 * tangent, center + 0.15 * tangent, 6)
    props = NaturalFractureProperties(friction=0.38, cohesion=0.0, tensile_strength=5e6, toughness=0.5e6,
                                      critical_radius=0.005, crossing="mohr-coulomb")
    return hd.Simulation(hf, mat, hd.Fluid(0.135, 4.545e-10), [hd.Cluster((0, 0), 4e-6, 1e-5)],
                         far_field_stress=np.diag([-6e6, -3e6]), time_step=1.0,
                         propagation=hd.Propagation(toughness=2e6), initial_pressure=3.5e6, initial_opening=1e-5,
                         backend=backend, natural_fractures=nf, natural=props, singular_correction="average",
                         alpha=1.0)


def check_contact_conditions(sim):
    """Activated natural elements do not interpenetrate; the contact traction ``c = A dd + B p
    - f`` of closed ones is compressive and within the friction cone, slipping ones on it
    (bands of 1e-3 of the largest opening and closed normal traction)."""
    s = sim.state
    natural = s.origin >= 1
    opening = np.sum(s.dd * s.mesh.normals, axis=1)
    scale = np.max(np.abs(opening))
    assert np.all(opening[natural] >= -1e-3 * scale)
    closed = natural & (s.contact_status != OPEN)
    assert np.any(closed)
    assert np.all(np.abs(opening[closed]) <= 1e-3 * scale)
    operator = sim.operator(s.mesh)
    traction = operator.matvec(s.dd.ravel()) + (s.mesh.normals * s.pressure[:, None]).ravel()
    c = (traction - sim.far_field_traction(s.mesh)).reshape(-1, 2)
    c_n = np.sum(c * s.mesh.normals, axis=1)
    tau = np.abs(np.sum(c * np.stack([-s.mesh.normals[:, 1], s.mesh.normals[:, 0]], axis=1), axis=1))
    strength = -sim.network.properties.friction * c_n
    band = 1e-3 * np.max(np.abs(c_n[closed]))
    assert np.all(c_n[closed] <= band)
    assert np.all(tau[closed] <= strength[closed] + band)
    slipping = natural & (s.contact_status == SLIP)
    np.testing.assert_allclose(tau[slipping], strength[slipping], atol=band)
