"""Closed-form validation of the dense DDM path: Griffith (2D) and Sneddon (3D)."""
import numpy as np

import hmatddm as hd
from conftest import NU, random_rotation, rotation_2d

P = 1e6


def griffith(material, n=200, angle=0.0, load="pressure"):
    t = np.array([np.cos(angle), np.sin(angle)])
    mesh = hd.mesh.line(-t, t, n)
    op = hd.ElasticityOperator(mesh, material)
    traction = -P * mesh.normals if load == "pressure" else -P * mesh.tangents  # sigma0 . n = tau t
    dd = hd.solve(op, traction)
    s = mesh.centers @ t
    return mesh, dd, s


def test_griffith_opening_within_one_percent(material):
    mesh, dd, s = griffith(material)
    w = hd.opening(mesh, dd)
    exact = hd.analytical.griffith_opening(s, 1.0, P, material)
    inner = np.abs(s) < 0.8
    assert np.max(np.abs(w[inner] - exact[inner])) / exact.max() < 0.01
    assert np.max(np.abs(w[inner] / exact[inner] - 1)) < 0.01
    assert np.allclose(hd.slip(mesh, dd), 0.0, atol=1e-12 * exact.max())


def test_griffith_slip_under_remote_shear(material):
    mesh, dd, s = griffith(material, load="shear")
    slip = dd @ np.array([1.0, 0.0])
    exact = hd.analytical.griffith_opening(s, 1.0, P, material)
    inner = np.abs(s) < 0.8
    # the crack slides in the sense of the remote shear: the + face moves along +x
    assert np.all(slip[inner] > 0)
    assert np.max(np.abs(slip[inner] - exact[inner])) / exact.max() < 0.01
    assert np.allclose(hd.opening(mesh, dd), 0.0, atol=1e-12 * exact.max())


def test_inclined_griffith_is_the_same_crack_rotated(material):
    mesh0, dd0, _ = griffith(material, angle=0.0)
    angle = 0.6
    mesh1, dd1, _ = griffith(material, angle=angle)
    assert np.allclose(dd1, dd0 @ rotation_2d(angle).T, rtol=0, atol=1e-10 * np.abs(dd0).max())


def test_griffith_converges(material):
    errors = []
    for n in (50, 100, 200):
        mesh, dd, s = griffith(material, n=n)
        exact = hd.analytical.griffith_opening(s, 1.0, P, material)
        inner = np.abs(s) < 0.8
        errors.append(np.max(np.abs(hd.opening(mesh, dd)[inner] - exact[inner])) / exact.max())
    assert errors[0] > errors[1] > errors[2]


_PENNIES = {}


def penny(material, h):
    """The pressurised penny crack of radius 1 with elements of size ``h``, solved once
    per (material, h) for the tests of this module (1264 dense 3D elements at h = 0.05)."""
    key = (material.shear_modulus, material.poisson_ratio, h)
    if key not in _PENNIES:
        mesh = hd.mesh.penny([0, 0, 0], [0, 0, 1], 1.0, h)
        op = hd.ElasticityOperator(mesh, material)
        _PENNIES[key] = mesh, hd.solve(op, -P * mesh.normals)
    return _PENNIES[key]


def test_sneddon_volume_error_decreases_with_refinement(material):
    exact = hd.analytical.sneddon_volume(1.0, P, material)
    errors = []
    for h in (0.2, 0.1, 0.05):
        mesh, dd = penny(material, h)
        errors.append(abs(np.sum(hd.opening(mesh, dd) * mesh.areas) - exact) / exact)
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.05


def test_sneddon_on_axis_stresses(material):
    """ref. Eqs 5.30-5.31 and the mean stress of ref. Fig. 5.15, for z/c >= 0.2,
    within 1% of the pressure."""
    mesh, dd = penny(material, 0.05)
    z = np.array([0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0])
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    stress = hd.stress_at(mesh, material, dd, points)
    sigma_r, sigma_z, sigma_mean = hd.analytical.sneddon_axis_stress(z, 1.0, P, NU)
    assert np.max(np.abs(stress[:, 2, 2] - sigma_z)) < 0.01 * P
    assert np.max(np.abs(stress[:, 0, 0] - sigma_r)) < 0.01 * P
    assert np.max(np.abs(stress[:, 1, 1] - sigma_r)) < 0.01 * P
    assert np.max(np.abs(hd.mean_stress_at(mesh, material, dd, points) - sigma_mean)) < 0.01 * P
    # below the crack the same by symmetry
    below = hd.stress_at(mesh, material, dd, points * [1, 1, -1])
    assert np.allclose(below[:, 2, 2], stress[:, 2, 2], rtol=1e-9, atol=1e-9 * P)


def test_3d_invariance_under_rigid_motion(material):
    """Translating and rotating the whole configuration rotates the solution exactly."""
    rng = np.random.default_rng(11)
    base = hd.mesh.concatenate([
        hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 1.0, 6, 3),
        hd.mesh.rectangle([0.5, 0.2, 0.8], [1, 0, 0], [0, 0.6, 0.8], 1.0, 1.0, 3, 3, fracture_id=1),
    ])
    traction = -P * base.normals + 0.3 * P * base.frames[:, 0, :]
    dd0 = hd.solve(hd.ElasticityOperator(base, material), traction)
    rotation = random_rotation(rng)
    moved = base.transformed(rotation, translation=[10.0, -3.0, 7.0])
    dd1 = hd.solve(hd.ElasticityOperator(moved, material), traction @ rotation.T)
    assert np.allclose(dd1, dd0 @ rotation.T, rtol=0, atol=1e-9 * np.abs(dd0).max())


def test_2d_invariance_under_rigid_motion(material):
    segments = hd.mesh.concatenate([hd.mesh.line([-1, 0], [1, 0], 20),
                                    hd.mesh.line([-0.5, 0.5], [0.7, 1.4], 12, fracture_id=1)])
    traction = -P * segments.normals
    dd0 = hd.solve(hd.ElasticityOperator(segments, material), traction)
    rotation = rotation_2d(2.1)
    moved = segments.transformed(rotation, translation=[5.0, 3.0])
    dd1 = hd.solve(hd.ElasticityOperator(moved, material), traction @ rotation.T)
    assert np.allclose(dd1, dd0 @ rotation.T, rtol=0, atol=1e-9 * np.abs(dd0).max())
