"""Crossing criteria (ref. Sec. 5.2) and natural fractures in the time loop (ref. Ch. 5)."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.fracture import NaturalFractureProperties, crosses, near_tip_stress, plane_tractions
from hmatddm.simulation.natural import NaturalNetwork

TABLE_5_1 = dict(friction=0.38, cohesion=3.2e6, tensile_strength=5e6, toughness=0.5e6, critical_radius=0.005)


def test_near_tip_field_matches_the_hoop_stress_formula():
    # sigma_theta_theta at theta: cos(t/2)[K_I cos^2(t/2) - 3/2 K_II sin t] / sqrt(2 pi r)
    for theta in (0.3, 1.0, -1.2):
        sxx, syy, sxy = near_tip_stress(1.0, 0.4, 0.01, theta)
        hoop, _ = plane_tractions(sxx, syy, sxy, theta)  # normal stress on the radial plane
        expected = np.cos(theta / 2) * (np.cos(theta / 2) ** 2 - 1.5 * 0.4 * np.sin(theta)) / np.sqrt(2 * np.pi * 0.01)
        np.testing.assert_allclose(hoop, expected, rtol=1e-12)


@pytest.mark.parametrize("angle", [60.0, 90.0])
def test_mohr_coulomb_decision_is_monotone_in_the_stress_contrast(angle):
    natural = NaturalFractureProperties(**TABLE_5_1, crossing="mohr-coulomb")
    values = [crosses(2e6, 0.0, 0.0, np.deg2rad(angle), np.diag([-s, -3e6]), 2e6, natural)
              for s in (6e6, 8e6, 10e6, 13e6, 20e6, 40e6)]
    assert values == sorted(values)


@pytest.mark.parametrize("angle", [90.0])
def test_mohr_coulomb_crosses_at_high_stress_contrast_and_turns_at_low(angle):
    # ref. Sec. 5.2.4 (Table 5.1): S_hmin 3 MPa; the HF grows along S_Hmax (tip frame x)
    natural = NaturalFractureProperties(**TABLE_5_1, crossing="mohr-coulomb")
    phi = np.deg2rad(angle)
    decisions = {}
    for s_hmax in (6e6, 8e6, 10e6, 13e6):
        far = np.diag([-s_hmax, -3e6])
        decisions[s_hmax] = crosses(2e6, 0.0, 0.0, phi, far, 2e6, natural)
    assert decisions[13e6] and not decisions[6e6]


@pytest.mark.parametrize("criterion", ["sif", "energy"])
def test_sif_and_energy_criteria_ignore_the_far_field(criterion):
    # ref. Sec. 5.2.4: only the Mohr-Coulomb criterion depends on the stress contrast
    natural = NaturalFractureProperties(**TABLE_5_1, crossing=criterion)
    for angle in (30.0, 60.0, 90.0):
        phi = np.deg2rad(angle)
        low = crosses(2e6, 0.0, 0.0, phi, np.diag([-6e6, -3e6]), 2e6, natural)
        high = crosses(2e6, 0.0, 0.0, phi, np.diag([-13e6, -3e6]), 2e6, natural)
        assert low == high
    # a natural fracture as tough as the rock is crossed head-on; a weak one at 30 deg deflects
    strong = NaturalFractureProperties(**dict(TABLE_5_1, toughness=2e6), crossing=criterion)
    assert crosses(2e6, 0.0, 0.0, np.pi / 2, np.diag([-6e6, -3e6]), 2e6, strong)
    assert not crosses(2e6, 0.0, 0.0, np.deg2rad(30), np.diag([-6e6, -3e6]), 2e6, natural)


def _crossing_run(s_hmax, angle=90.0):
    mat = hd.Elastic(3.415e9, 0.23)
    hf = hd.mesh.line([-0.075, 0], [0.075, 0], 3)
    a = np.deg2rad(angle)
    center, tangent = np.array([0.2, 0.0]), np.array([np.cos(a), np.sin(a)])
    nf = hd.mesh.line(center - 0.15 * tangent, center + 0.15 * tangent, 6)
    sim = hd.Simulation(hf, mat, hd.Fluid(0.135, 4.545e-10), [hd.Cluster((0, 0), 4e-6, 1e-5)],
                        far_field_stress=np.diag([-s_hmax, -3e6]), time_step=1.0,
                        propagation=hd.Propagation(toughness=2e6), initial_pressure=3.5e6, initial_opening=1e-5,
                        backend="dense", natural_fractures=nf,
                        natural=NaturalFractureProperties(**TABLE_5_1, crossing="mohr-coulomb"),
                        singular_correction="average", alpha=1.0)
    records = sim.run(20.0)
    return sim, records


def test_hydraulic_fracture_crosses_or_follows_the_natural_fracture():
    crossed, records = _crossing_run(13e6)
    assert sum(r["natural_crossed"] for r in records) >= 1 and records[-1]["natural_active"] == 0
    s = crossed.state
    assert np.any((s.origin == 0) & (s.mesh.centers[:, 0] > 0.19) & (np.abs(s.mesh.centers[:, 1]) < 0.03))

    deflected, records = _crossing_run(6e6)
    assert sum(r["natural_deflected"] for r in records) >= 1 and records[-1]["natural_active"] >= 1
    s = deflected.state
    # the tip stopped at the natural fracture: nothing beyond it on the crack line
    assert not np.any((s.origin == 0) & (s.mesh.centers[:, 0] > 0.19) & (np.abs(s.mesh.centers[:, 1]) < 0.03))
    for record in records:
        assert np.isfinite(record["max_opening"]) and np.isfinite(record["wellbore_pressure"][0])


def test_remote_failure_is_near_the_fracture_and_grows_with_skempton():
    # a pressurised crack loads natural fractures at 45 degrees; critically stressed
    # planes fail close to the crack only (ref. Sec. 5.3.3)
    mat = hd.Elastic(6.62e9, 0.25)
    hf = hd.mesh.line([-5, 0], [5, 0], 40)
    dd = hd.solve(hd.ElasticityOperator(hf, mat), -2e6 * hf.normals)
    far = np.diag([-39.44e6, -35.85e6])
    centers = np.array([[x, y] for x in (-3.0, 0.0, 3.0, 6.0) for y in (0.5, 1.5, 4.0, 15.0, 30.0)])
    tangent = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4)])
    nf = hd.Mesh2D.from_segments(centers - 0.25 * tangent, centers + 0.25 * tangent)
    counts = {}
    for name, skempton in (("none", 0.0), ("gas", 0.01456), ("oil", 0.5255)):
        props = NaturalFractureProperties(friction=0.25, cohesion=0.0, pore_pressure=30.2e6 * 0.98,
                                          skempton=skempton)
        failed, normal, shear, dp = NaturalNetwork(nf, props).remote_failure(hf, dd, mat, far, np.ones(len(nf), bool))
        assert np.all(np.isfinite(normal)) and np.all(np.isfinite(shear))
        counts[name] = int(failed.sum())
        far_away = np.abs(centers[:, 1]) >= 15.0
        assert not np.any(failed[far_away])
    assert counts["none"] >= 1
    assert counts["oil"] >= counts["gas"] >= counts["none"]


def test_bad_natural_properties():
    with pytest.raises(InputError, match="natural.crossing"):
        NaturalFractureProperties(crossing="maybe")
    with pytest.raises(InputError, match="natural.skempton"):
        NaturalFractureProperties(skempton=1.5)
    with pytest.raises(InputError, match="natural.critical_radius"):
        NaturalFractureProperties(critical_radius=0.0)


@pytest.mark.parametrize("hydraulic_x", [2.5, 2.1], ids=["hydraulic-tip-lands-on-it", "hydraulic-tip-deflects-into-it"])
def test_two_tips_reaching_one_natural_element_activate_it_once(monkeypatch, hydraulic_x):
    """A hydraulic tip and the tip of an activated natural element that reach the same
    intact natural element in one growth pass (the hydraulic candidate lands on it, or
    cuts it and is deflected into it): it is activated once and the second tip is
    connected to it. Before, a hydraulic element was added on top of it, a singular pair
    that stopped the 3D DFN benchmark (t = 64 s with 10 elements over the height, t = 58 s
    with 20)."""
    from types import SimpleNamespace

    from hmatddm.mesh import topology
    from hmatddm.simulation import growth_pass, linking
    from hmatddm.simulation.state import State, StepEvents

    # natural fracture in the plane y = 0: 4 x 2 elements of 1 m, centres z = -0.5, 0.5
    natural = hd.mesh.rectangle([2.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 4.0, 2.0, 4, 2)
    target = int(np.argmin(np.linalg.norm(natural.centers - [2.5, 0.0, -0.5], axis=1)))
    above = int(np.argmin(np.linalg.norm(natural.centers - [2.5, 0.0, 0.5], axis=1)))
    # a hydraulic element in the plane x = hydraulic_x whose +y tip edge is 0.5 m from y = 0
    hydraulic = hd.mesh.rectangle([hydraulic_x, -1.0, -0.5], [0, 1, 0], [0, 0, 1], 1.0, 1.0, 1, 1)
    sim = hd.Simulation(hydraulic, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, 4.4e-10),
                        [hd.Cluster((hydraulic_x, -1.0, -0.5), 1e-3, 0.0)], -np.diag([20e6, 30e6, 40e6]), 1.0,
                        propagation=hd.Propagation(toughness=1e6), backend="dense", natural_fractures=natural,
                        natural=NaturalFractureProperties(**TABLE_5_1, crossing="mohr-coulomb"))
    # the active mesh: the hydraulic element and the activated natural element above the target
    mesh = hd.mesh.concatenate([hydraulic, natural.subset(np.array([above]))])
    origin, natural_index = np.array([0, 1]), np.array([-1, above])
    intact = np.ones(natural.n_elements, bool)
    intact[above] = False
    edges = topology.element_edges(mesh, None)
    faces = topology.element_faces(mesh, edges)
    tip_edges = [int(np.argmax(edges.ahead[0, :, 1])), int(np.argmin(edges.ahead[1, :, 2]))]  # +y and -z
    # the hydraulic tip's candidate continues its plane across y = 0; the natural tip's
    # candidate is the target (the next element of its own fracture, downwards)
    hydraulic_candidate = hd.mesh.rectangle([hydraulic_x, 0.0, -0.5], [0, 1, 0], [0, 0, 1], 1.0, 1.0, 1, 1)
    candidates = hd.mesh.concatenate([hydraulic_candidate, natural.subset(np.array([target]))])
    tips = SimpleNamespace(edge=np.array(tip_edges), k_1=np.zeros(2), k_2=np.zeros(2), theta=np.zeros(2))
    monkeypatch.setattr(growth_pass, "evaluate_tips", lambda *args, **kwargs: tips)
    monkeypatch.setattr(growth_pass, "new_elements",
                        lambda *args, **kwargs: (candidates, np.array([0, 1]), np.array([0, 1])))
    monkeypatch.setattr(sim.network, "decide_crossing", lambda *args, **kwargs: False)  # always deflect
    events = StepEvents()
    state = State(mesh, np.zeros((2, 3)), np.zeros(2), np.zeros(2), 0.0, 0, 1.0, 0.0, 0.0, origin=origin,
                  natural_index=natural_index, intact=intact, failed=np.zeros(natural.n_elements, bool),
                  extra_faces=np.zeros((0, 6)))
    growth = growth_pass.grow(sim, state, edges, faces, None, events)
    new, connections = growth.elements, growth.connections
    assert new.mesh.n_elements == 1 and list(new.natural_index) == [target] and list(new.origin) == [1]
    assert list(new.parent) == [0]
    deflected = [(0, 0)] if hydraulic_x != 2.5 else []  # the deflected tip's own link
    assert [(c.target, c.tip) for c in connections] == deflected + [(0, 1)]
    assert all(c.target_is_new for c in connections)
    assert events.natural_deflected == len(deflected)
    # the natural tip and the target share an edge: the mesh topology gives their face,
    # and the explicit link is dropped (no doubled conductance); the deflected hydraulic
    # tip keeps its link
    grown_mesh = hd.mesh.concatenate([mesh, new.mesh])
    links = np.array([c.face(first_new=2) for c in connections])
    plain = topology.element_faces(grown_mesh, topology.element_edges(grown_mesh, None))
    assert {1, 2} in [{int(a), int(b)} for a, b in zip(plain.first, plain.second)]
    faces = linking.with_links(plain, links)
    assert len(faces.first) == len(plain.first) + len(deflected)


@pytest.mark.parametrize("crosses", [False, True], ids=["arrested", "crosses"])
def test_a_tip_that_cuts_a_natural_element_already_in_the_system_decides_and_connects(monkeypatch, crosses):
    """A hydraulic candidate whose path cuts a natural element that is already in the
    system (activated earlier, or failed remotely) without landing on it: the crossing
    criterion decides, and the tip joins that element's flow either way (arrested into it,
    or a branch that goes on across it). Before, only intact elements were looked for on
    the path, and the candidate went through the open natural fracture unconnected."""
    from types import SimpleNamespace

    from hmatddm.mesh import topology
    from hmatddm.simulation import growth_pass
    from hmatddm.simulation.state import State, StepEvents

    natural = hd.mesh.rectangle([2.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 4.0, 2.0, 4, 2)
    target = int(np.argmin(np.linalg.norm(natural.centers - [2.5, 0.0, -0.5], axis=1)))
    hydraulic = hd.mesh.rectangle([2.1, -1.0, -0.5], [0, 1, 0], [0, 0, 1], 1.0, 1.0, 1, 1)
    sim = hd.Simulation(hydraulic, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3, 4.4e-10),
                        [hd.Cluster((2.1, -1.0, -0.5), 1e-3, 0.0)], -np.diag([20e6, 30e6, 40e6]), 1.0,
                        propagation=hd.Propagation(toughness=1e6), backend="dense", natural_fractures=natural,
                        natural=NaturalFractureProperties(**TABLE_5_1, crossing="mohr-coulomb"))
    mesh = hd.mesh.concatenate([hydraulic, natural.subset(np.array([target]))])  # the target is in the system
    origin, natural_index = np.array([0, 1]), np.array([-1, target])
    intact = np.ones(natural.n_elements, bool)
    intact[target] = False
    edges = topology.element_edges(mesh, None)
    faces = topology.element_faces(mesh, edges)
    tip_edge = int(np.argmax(edges.ahead[0, :, 1]))  # +y, towards the natural fracture
    # the candidate continues the hydraulic plane across y = 0, 0.4 m beside the target's centre
    candidate = hd.mesh.rectangle([2.1, 0.0, -0.5], [0, 1, 0], [0, 0, 1], 1.0, 1.0, 1, 1)
    tips = SimpleNamespace(edge=np.array([tip_edge]), k_1=np.zeros(1), k_2=np.zeros(1), theta=np.zeros(1))
    monkeypatch.setattr(growth_pass, "evaluate_tips", lambda *args, **kwargs: tips)
    monkeypatch.setattr(growth_pass, "new_elements", lambda *args, **kwargs: (candidate, np.array([0]), np.array([0])))
    decisions = []
    monkeypatch.setattr(sim.network, "decide_crossing", lambda *args, **kwargs: decisions.append(args[5]) or crosses)
    events = StepEvents()
    state = State(mesh, np.zeros((2, 3)), np.zeros(2), np.zeros(2), 0.0, 0, 1.0, 0.0, 0.0, origin=origin,
                  natural_index=natural_index, intact=intact, failed=np.zeros(natural.n_elements, bool),
                  extra_faces=np.zeros((0, 6)))
    growth = growth_pass.grow(sim, state, edges, faces, None, events)
    assert decisions == [target]  # the criterion was asked about the element on the path
    assert [(c.target, c.tip, c.target_is_new) for c in growth.connections] == [(1, 0, False)]
    if crosses:
        assert events.natural_crossed == 1 and events.natural_deflected == 0
        assert growth.elements.mesh.n_elements == 1 and list(growth.elements.origin) == [0]
    else:
        assert events.natural_deflected == 1 and events.natural_crossed == 0
        assert growth.elements is None or growth.elements.mesh.n_elements == 0
        # the next pass: the tip, now linked to the element, stays arrested there (no new
        # decision, no event counted again, nothing grows)
        from hmatddm.simulation import linking

        linked = linking.with_links(faces, np.array([c.face(first_new=2) for c in growth.connections]))
        again = StepEvents()
        assert growth_pass.grow(sim, state, edges, linked, None, again) is None
        assert decisions == [target] and again.natural_deflected == again.natural_crossed == 0


def test_energy_criterion_with_mode_two_toughness():
    """G / G_c in each direction with G_c = (K_Ic^2 + K_IIc^2) / E' (ref. Eqs 5.11-5.16,
    squares restored), written out here from Nuismer's K-bar (ref. Eqs 5.13-5.14); E'
    cancels from each ratio."""
    from hmatddm.fracture.crossing import crosses

    def k_bar(k1, k2, theta):
        c = 0.5 * np.cos(0.5 * theta)
        return (c * (k1 * (1 + np.cos(theta)) - 3 * k2 * np.sin(theta)),
                c * (k1 * np.sin(theta) + k2 * (3 * np.cos(theta) - 1)))

    k1, k2, theta_0, phi = 1.0e6, 0.2e6, -0.2, np.radians(60.0)
    rock_kic, nf_kic = 2.0e6, 1.0e6
    far = np.zeros((2, 2))

    def expected(nf_kiic, rock_kiic):
        ahead = sum(v**2 for v in k_bar(k1, k2, theta_0)) / (rock_kic**2 + rock_kiic**2)
        along = max(sum(v**2 for v in k_bar(k1, k2, a)) for a in (phi, phi - np.pi)) / (nf_kic**2 + nf_kiic**2)
        return ahead > along

    outcomes = set()
    for nf_kiic in (0.0, 1.0e6, 3.0e6):
        for rock_kiic in (0.0, 2.0e6):
            props = NaturalFractureProperties(crossing="energy", toughness=nf_kic, shear_toughness=nf_kiic,
                                              rock_shear_toughness=rock_kiic)
            got = crosses(k1, k2, theta_0, phi, far, rock_kic, props)
            assert got == expected(nf_kiic, rock_kiic)
            outcomes.add(got)
    assert outcomes == {True, False}  # the mode II toughness decides between crossing and deflection here
    with pytest.raises(InputError, match="natural.shear_toughness"):
        NaturalFractureProperties(shear_toughness=-1.0)
