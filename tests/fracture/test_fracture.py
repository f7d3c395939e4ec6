"""Tip SIFs, the maximum circumferential stress criterion and growth (ref. Sec. 4.2.2)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.mesh import topology
from hmatddm.errors import InputError
from hmatddm.fracture import (Propagation, circumferential_stress_direction, energy_release_rate,
                              equivalent_mode_one, evaluate_tips, new_elements)


def test_mcs_direction_limits():
    # pure mode I: straight ahead; pure mode II: -+70.53 degrees (Erdogan and Sih 1963)
    assert circumferential_stress_direction(1.0, 0.0) == 0.0
    np.testing.assert_allclose(np.rad2deg(circumferential_stress_direction(0.0, 1.0)), -70.5288, atol=1e-3)
    np.testing.assert_allclose(np.rad2deg(circumferential_stress_direction(0.0, -1.0)), 70.5288, atol=1e-3)


@pytest.mark.parametrize("k_1, k_2", [(1.0, 0.3), (1.0, -0.7), (0.2, 1.0), (-0.5, 1.0)])
def test_mcs_direction_maximises_the_hoop_stress(k_1, k_2):
    # sigma_theta_theta sqrt(2 pi r) = cos(t/2) [K_I cos^2(t/2) - 3/2 K_II sin t]; its max over t
    theta = np.linspace(-np.pi + 1e-6, np.pi - 1e-6, 200001)
    hoop = np.cos(theta / 2) * (k_1 * np.cos(theta / 2) ** 2 - 1.5 * k_2 * np.sin(theta))
    best = theta[np.argmax(hoop)]
    theta_0 = circumferential_stress_direction(k_1, k_2)
    np.testing.assert_allclose(theta_0, best, atol=1e-4)
    # ref. Eq. 4.10 is that maximum
    np.testing.assert_allclose(equivalent_mode_one(k_1, k_2, theta_0), hoop.max(), rtol=1e-6)


def test_energy_release_rate_of_pure_mode_one(material):
    np.testing.assert_allclose(energy_release_rate(2e6, 0.0, material), 4e12 / material.plane_strain_modulus)


def test_olson_sif_of_a_griffith_crack(material):
    # K_I = p sqrt(pi a) from the tip element DD of a 2D DDM solution (ref. Eqs 4.18-4.19)
    a, p = 1.0, 1e6
    for n in (20, 40):
        mesh = hd.mesh.line([-a, 0], [a, 0], n)
        dd = hd.solve(hd.ElasticityOperator(mesh, material), -p * mesh.normals)
        edges = topology.element_edges(mesh)
        tips = evaluate_tips(mesh, edges, np.array([n - 1, 0]), np.array([0, 1]), dd, material,
                             Propagation(toughness=1.0))
        np.testing.assert_allclose(tips.k_1, p * np.sqrt(np.pi * a), rtol=0.03)
        np.testing.assert_allclose(tips.k_2, 0.0, atol=1e-6 * p)
        assert np.all(tips.grows)


def test_mode_two_sif_sign_turns_the_crack_away_from_the_slip(material):
    # remote shear on a line crack: the +t tip turns by -70 degrees for K_II > 0
    mesh = hd.mesh.line([-1, 0], [1, 0], 20)
    dd = hd.solve(hd.ElasticityOperator(mesh, material), -1e6 * mesh.tangents)
    edges = topology.element_edges(mesh)
    tips = evaluate_tips(mesh, edges, np.array([19, 0]), np.array([0, 1]), dd, material, Propagation(toughness=1.0))
    # slip along +t: at the +t tip (ahead = +t) K_II > 0, at the -t tip (ahead = -t) K_II < 0
    assert tips.k_2[0] < 0 < tips.k_2[1] or tips.k_2[0] > 0 > tips.k_2[1]
    np.testing.assert_allclose(np.abs(np.rad2deg(tips.theta)), 70.53, atol=0.5)
    # antisymmetry: both tips turn to the same side of the crack line (a rotating crack)
    grown, parent = new_elements(mesh, edges, tips, Propagation(toughness=1.0))
    assert np.sign(grown.centers[0, 1]) == -np.sign(grown.centers[1, 1])


def test_new_2d_elements_continue_the_crack():
    mesh = hd.mesh.line([-1, 0], [1, 0], 2)
    edges = topology.element_edges(mesh)
    tips = hd.fracture.TipState(np.array([1, 0]), np.array([0, 1]), *(np.zeros(2),) * 3,
                                np.array([0.3, 0.3]), np.zeros(2), np.zeros(2), np.array([True, True]))
    grown, parent = new_elements(mesh, edges, tips, Propagation(toughness=1.0))
    p0, p1 = grown.endpoints
    np.testing.assert_allclose(p0[0], [1.0, 0.0], atol=1e-12)      # hinged on the +t tip
    np.testing.assert_allclose(p1[1], [-1.0, 0.0], atol=1e-12)     # hinged on the -t tip
    # turned towards the normal (+y) by 0.3 rad at both ends, tangent sense kept
    np.testing.assert_allclose(grown.tangents[0], [np.cos(0.3), np.sin(0.3)], atol=1e-12)
    np.testing.assert_allclose(grown.tangents[1], [np.cos(0.3), -np.sin(0.3)], atol=1e-12)
    np.testing.assert_allclose(p0[1], [-1 - np.cos(0.3), np.sin(0.3)], atol=1e-12)
    faces = topology.element_faces(hd.mesh.concatenate([mesh, grown]))
    assert faces.n_faces == 3


def test_new_3d_elements_fill_a_front_once_and_respect_bounds():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 3.0, 3.0, 3, 3)
    edges = topology.element_edges(mesh)
    faces = topology.element_faces(mesh, edges)
    element, edge = topology.tip_edges(mesh, faces, edges)
    n = len(element)
    tips = hd.fracture.TipState(element, edge, *(np.zeros(n),) * 3, np.zeros(n), np.zeros(n), np.zeros(n),
                                np.ones(n, bool))
    grown, _ = new_elements(mesh, edges, tips, Propagation(toughness=1.0))
    assert grown.n_elements == 12  # one ring without corners, no duplicates
    bounded, _ = new_elements(mesh, edges, tips, Propagation(toughness=1.0, bounds=((-9, 9), (-9, 9), (-1.5, 1.5))))
    assert bounded.n_elements == 6 and np.all(np.abs(bounded.centers[:, 2]) < 1.5)


def test_plan_view_turning_keeps_vertical_fractures_vertical():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 1.0, 1.0, 1, 1)
    edges = topology.element_edges(mesh)
    tips = hd.fracture.TipState(np.zeros(4, np.int64), np.arange(4), *(np.zeros(4),) * 3, np.full(4, 0.4),
                                np.zeros(4), np.zeros(4), np.ones(4, bool))
    grown, _ = new_elements(mesh, edges, tips, Propagation(toughness=1.0, turning="plan"))
    np.testing.assert_allclose(grown.normals[:, 2], 0.0, atol=1e-12)  # still vertical
    turned = np.abs(grown.normals[:, 1]) < 0.999
    assert turned.sum() == 2  # only the two vertical edges turned
    faces = topology.element_faces(hd.mesh.concatenate([mesh, grown]))
    assert faces.n_faces == 4


@pytest.mark.parametrize("kwargs, field", [
    (dict(toughness=0.0), "toughness"), (dict(toughness=1.0, criterion="max"), "criterion"),
    (dict(toughness=1.0, turning="yes"), "turning"), (dict(toughness=1.0, correction=3.0), "correction"),
    (dict(toughness=1.0, max_growth_passes=-1), "max_growth_passes"),
    (dict(toughness=1.0, bounds=((1, 0),)), "bounds"),
    (dict(toughness=1.0, critical_energy_release_rate=-1.0), "critical_energy_release_rate"),
])
def test_bad_propagation_input(kwargs, field):
    with pytest.raises(InputError, match=field):
        Propagation(**kwargs)
