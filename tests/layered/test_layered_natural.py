"""Natural fractures in a layered medium (hmatddm.layered.engine, ref. Ch. 3 + Ch. 5):
equal layers reproduce the homogeneous run (crossing, deflection and remote failure
alike); a free surface, stiffer rock and per-layer in-situ stress change the remote
failure decision, which agrees with the layered stress fed to Coulomb's criterion by
hand; the rock toughness of the layer where the tip meets a natural fracture decides
the crossing, as the published criterion says by hand; natural fractures drawn across
interfaces are cut there; bad natural-fracture meshes are refused by name."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.layered import LayeredMedium, split_at_interfaces
from hmatddm.simulation.natural import NaturalNetwork

G, NU = 10e9, 0.25
#: ref. Table 5.1 (the crossing scene of tests/fracture/test_crossing.py)
TABLE_5_1 = dict(friction=0.38, cohesion=3.2e6, tensile_strength=5e6, toughness=0.5e6, critical_radius=0.005)


def _spy(monkeypatch, name):
    """Record the arguments and result of every call of NaturalNetwork.<name>."""
    calls = []
    original = getattr(NaturalNetwork, name)

    def spied(self, *args, **kwargs):
        result = original(self, *args, **kwargs)
        calls.append((args, result))
        return result

    monkeypatch.setattr(NaturalNetwork, name, spied)
    return calls


# -- crossing (ref. Sec. 5.2) ----------------------------------------------------------------
def _crossing_run(material, s_hmax, crossing="mohr-coulomb", vertical=False, toughness=2e6):
    """The scene of tests/fracture/test_crossing.py: a fracture along x meets a natural fracture
    across its path at x = 0.2 (``vertical``: the same turned by 90 degrees, growing up
    to a natural fracture at y = 0.2 under a vertical stress ``s_hmax``)."""
    mat = material
    if vertical:
        hf = hd.mesh.line([0.0, -0.075], [0.0, 0.075], 3)
        nf = hd.mesh.line([-0.15, 0.2], [0.15, 0.2], 6)
        far = np.diag([-3e6, -s_hmax])
    else:
        hf = hd.mesh.line([-0.075, 0], [0.075, 0], 3)
        nf = hd.mesh.line([0.2, -0.15], [0.2, 0.15], 6)
        far = np.diag([-s_hmax, -3e6])
    sim = hd.Simulation(hf, mat, hd.Fluid(0.135, 4.545e-10), [hd.Cluster((0, 0), 4e-6, 1e-5)],
                        far_field_stress=far, time_step=1.0, propagation=hd.Propagation(toughness=toughness),
                        initial_pressure=3.5e6, initial_opening=1e-5, backend="dense", natural_fractures=nf,
                        natural=hd.NaturalFractureProperties(**TABLE_5_1, crossing=crossing),
                        singular_correction="average", alpha=1.0)
    return sim, sim.run(20.0)


def _events(records):
    return [(r["n_elements"], r["natural_crossed"], r["natural_deflected"], r["natural_active"],
             r.get("natural_failed")) for r in records]


@pytest.mark.parametrize("s_hmax", [13e6, 6e6], ids=["crosses", "deflects"])
def test_equal_layers_cross_and_deflect_as_the_homogeneous_run(s_hmax):
    # interfaces through the natural fracture and the hydraulic fracture's path
    homogeneous, records_h = _crossing_run(hd.Elastic(3.415e9, 0.23), s_hmax)
    layered, records_l = _crossing_run(LayeredMedium([0.1, -0.1], [3.415e9] * 3, [0.23] * 3), s_hmax)
    assert _events(records_l) == _events(records_h)
    assert sum(r["natural_crossed" if s_hmax > 1e7 else "natural_deflected"] for r in records_h) >= 1
    np.testing.assert_array_equal(layered.state.origin, homogeneous.state.origin)
    scale = np.abs(homogeneous.state.dd).max()
    assert np.max(np.abs(layered.state.dd - homogeneous.state.dd)) <= 1e-12 * scale
    np.testing.assert_allclose(layered.state.pressure, homogeneous.state.pressure, rtol=1e-12)


def test_the_toughness_of_the_layer_where_the_tip_meets_the_natural_fracture_decides(monkeypatch):
    """A fracture grows up from rock of toughness 2 MPa m^1/2 into a layer of 1 MPa m^1/2
    above y = 0.1 and meets a horizontal natural fracture there (K_Ic 0.5 MPa m^1/2, "sif"
    criterion, ref. Sec. 5.2.3). Uniform rock deflects; the layered run crosses, and the
    published criterion with the upper layer's toughness, written here, says the same
    for the stress intensity factors of the run."""
    calls = _spy(monkeypatch, "decide_crossing")
    _, records = _crossing_run(hd.Elastic(3.415e9, 0.23), 13e6, "sif", vertical=True)
    assert sum(r["natural_deflected"] for r in records) >= 1 and sum(r["natural_crossed"] for r in records) == 0
    calls.clear()
    medium = LayeredMedium([0.1], [3.415e9] * 2, [0.23] * 2, toughness=[1e6, 2e6])
    sim, records = _crossing_run(medium, 13e6, "sif", vertical=True)
    assert sum(r["natural_crossed"] for r in records) >= 1 and sum(r["natural_deflected"] for r in records) == 0
    assert calls

    def k_bar(k_1, k_2, theta):  # ref. Eq. 4.10
        return 0.5 * np.cos(theta / 2) * (k_1 * (1 + np.cos(theta)) - 3 * k_2 * np.sin(theta))

    for (k_1, k_2, theta, ahead, normal, element, far_field, toughness), crossed in calls:
        assert sim.network.mesh.centers[element, 1] == pytest.approx(0.2)  # the natural fracture, upper layer
        assert toughness == 1e6 and np.array_equal(far_field, np.diag([-3e6, -13e6]))
        phi = np.arctan2(normal[0], ahead[0])  # the natural fracture runs along x
        along = max(k_bar(k_1, k_2, phi), k_bar(k_1, k_2, phi - np.sign(phi) * np.pi))
        by_hand = k_bar(k_1, k_2, theta) / medium.toughness[0] > along / TABLE_5_1["toughness"]
        lower_rock = k_bar(k_1, k_2, theta) / medium.toughness[1] > along / TABLE_5_1["toughness"]
        assert bool(crossed) == by_hand and by_hand and not lower_rock


# -- remote failure (ref. Sec. 5.3) -------------------------------------------------------
def _remote_run(material, pore_pressure=2e6, end_time=1.0, **options):
    """A pressurised crack along y = 0 next to a natural fracture at 30 degrees that spans
    y = 0.1 .. 1.1 (the scene of tests/simulation/test_simulation_natural.py)."""
    hf = hd.mesh.line([-2.0, 0.0], [2.0, 0.0], 8)
    a = np.deg2rad(30.0)
    center, tangent = np.array([3.0, 0.6]), np.array([np.cos(a), np.sin(a)])
    nf = hd.mesh.line(center - 1.0 * tangent, center + 1.0 * tangent, 4)
    props = hd.NaturalFractureProperties(friction=0.3, cohesion=0.0, tensile_strength=0.0, toughness=0.5e6,
                                         critical_radius=0.005, pore_pressure=pore_pressure, skempton=0.5)
    sim = hd.Simulation(hf, material, hd.Fluid(1e-3, 1e-9), [hd.Cluster((0, 0), 1e-3, 0.0)],
                        far_field_stress=np.diag([-14e6, -9e6]), time_step=1.0, initial_pressure=9.5e6,
                        initial_opening=1e-4, backend="dense", natural_fractures=nf, natural=props,
                        singular_correction="average", alpha=1.0, **options)
    return sim, None if end_time is None else sim.run(end_time)


def test_equal_layers_fail_remotely_as_the_homogeneous_run():
    homogeneous, records_h = _remote_run(hd.Elastic(G, NU), 3e6, end_time=3.0)
    layered, records_l = _remote_run(LayeredMedium([0.5, -0.2], [G] * 3, [NU] * 3), 3e6, end_time=3.0)
    assert records_h[-1]["natural_failed"] >= 2
    assert _events(records_l) == _events(records_h)
    np.testing.assert_array_equal(layered.state.origin, homogeneous.state.origin)
    scale = np.abs(homogeneous.state.dd).max()
    assert np.max(np.abs(layered.state.dd - homogeneous.state.dd)) <= 1e-12 * scale


HALF_SPACE = LayeredMedium([1.5], [0.0, G], [NU, NU], images=8)
#: a free surface at y = 1.5, stiffer rock above y = 0.3 with a smaller horizontal stress
THREE_LAYERS = LayeredMedium([1.5, 0.3], [0.0, 2 * G, G], [NU, 0.3, NU], images=8,
                             in_situ_stress=[np.zeros((2, 2)), np.diag([-12e6, -9e6]), np.diag([-14e6, -9e6])])


@pytest.mark.parametrize("medium", [HALF_SPACE, THREE_LAYERS], ids=["half-space", "three-layers"])
def test_layers_change_the_remote_failure_as_coulomb_says_by_hand(monkeypatch, medium):
    """The first remote-failure check of the run fails fewer natural elements than in
    uniform rock, and exactly those that the layered stress at their centres
    (hd.stress_at with the medium), plus the in-situ stress of their layer and the
    undrained pore-pressure change with their layer's nu, fail by Coulomb's criterion."""
    calls = _spy(monkeypatch, "remote_failure")
    _remote_run(hd.Elastic(G, NU))
    failed_homogeneous = calls[0][1][0]
    calls.clear()
    sim, _ = _remote_run(medium)
    (mesh, dd, *_), (failed, normal, shear, pore_change) = calls[0]
    nf = sim.network.mesh
    if medium is THREE_LAYERS:  # cut at y = 0.3: the pieces end there
        assert nf.n_elements == 5 and np.isclose(np.sort(np.r_[nf.endpoints[0][:, 1], nf.endpoints[1][:, 1]]),
                                                 0.3).sum() == 2
    assert 0 < np.count_nonzero(failed) < np.count_nonzero(failed_homogeneous)
    # by hand: ref. Sec. 5.3, Eq. 5.18
    props = sim.network.properties
    layers = medium.layer_of(nf.centers[:, 1])
    induced = hd.stress_at(mesh, medium, dd, nf.centers, singular_correction="average", near_fraction=0.5)
    nu = np.array(medium.poisson_ratio)[layers]
    dp = -props.skempton * (1.0 + nu) * (induced[:, 0, 0] + induced[:, 1, 1]) / 3.0
    in_situ = np.diag([-14e6, -9e6]) if medium.in_situ_stress is None else medium.in_situ_stress[layers]
    total = induced + in_situ
    traction = np.einsum("mij,mj->mi", total, nf.normals)
    sigma_n = np.sum(traction * nf.normals, axis=1)
    tau = np.linalg.norm(traction - sigma_n[:, None] * nf.normals, axis=1)
    effective = sigma_n + props.pore_pressure + dp
    strength = props.cohesion - props.friction * effective
    by_hand = (tau >= strength) | (effective >= props.tensile_strength)
    np.testing.assert_array_equal(failed, by_hand)
    assert np.min(np.abs(tau - strength)) > 1e-3 * np.abs(total).max()  # not a tie
    np.testing.assert_allclose(normal, sigma_n, rtol=1e-12)
    np.testing.assert_allclose(pore_change, dp, rtol=1e-12)


def test_a_layered_run_with_natural_fractures_resumes_to_the_same_numbers(tmp_path):
    """The network cut at the interface and its remote failures survive a checkpoint."""
    whole, records = _remote_run(THREE_LAYERS, end_time=3.0)
    assert records[0]["natural_failed"] >= 1
    _remote_run(THREE_LAYERS, end_time=1.0, checkpoint_dir=tmp_path)
    resumed = _remote_run(THREE_LAYERS, end_time=None, checkpoint_dir=tmp_path)[0]
    resumed_records = resumed.run(3.0, resume=True)
    assert [r["step"] for r in resumed_records] == [r["step"] for r in records]
    assert _events(resumed_records) == _events(records)
    np.testing.assert_array_equal(resumed.state.dd, whole.state.dd)
    np.testing.assert_array_equal(resumed.state.failed, whole.state.failed)


# -- natural-fracture meshes and the interfaces ----------------------------------------------
def test_natural_fractures_across_interfaces_are_cut_in_3d_and_in_differing_2d_layers():
    medium3d = LayeredMedium([1.0, -1.0], [2 * G, G, 2 * G], [NU] * 3)
    nf3d = hd.mesh.rectangle([3.0, 0.0, 0.0], [0, 1, 0], [0, 0, 1], 2.0, 3.0, 2, 3, fracture_id=4)
    sim = hd.Simulation(hd.mesh.rectangle([0.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 2.0, 2.0, 2, 2), medium3d,
                        hd.Fluid(1e-3), [hd.Cluster((0.0, 0.0, 0.0), 1e-3)], np.diag([-1e6, -2e6, -3e6]), 1.0,
                        backend="dense", natural_fractures=nf3d)
    expected, _ = split_at_interfaces(nf3d, medium3d)
    assert sim.network.mesh.n_elements == expected.n_elements == 10  # the top and bottom rows cut in two
    np.testing.assert_array_equal(sim.network.mesh.centers, expected.centers)
    assert np.isclose(sim.network.mesh.areas.sum(), nf3d.areas.sum(), rtol=1e-14)
    nf2d = hd.mesh.line([1.0, -1.5], [1.0, 1.5], 3)
    for medium, pieces in ((LayeredMedium([0.2], [G, G], [NU, NU]), 3),  # equal layers: left as they are
                           (LayeredMedium([0.2], [2 * G, G], [NU, NU]), 4)):
        sim = hd.Simulation(hd.mesh.line([-1.0, 0.0], [0.0, 0.0], 2), medium, hd.Fluid(1e-3),
                            [hd.Cluster((-0.5, 0.0), 1e-3)], np.diag([-1e6, -2e6]), 1.0, backend="dense",
                            natural_fractures=nf2d)
        assert sim.network.mesh.n_elements == pieces


def test_bad_natural_fractures_in_a_layered_medium_are_refused_by_name():
    medium = LayeredMedium([1.0, -1.0], [2 * G, G, 2 * G], [NU] * 3)
    hf3d = hd.mesh.rectangle([0.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 2.0, 2.0, 2, 2)

    def run3d(nf, material=medium):
        return hd.Simulation(hf3d, material, hd.Fluid(1e-3), [hd.Cluster((0.0, 0.0, 0.0), 1e-3)],
                             np.diag([-1e6, -2e6, -3e6]), 1.0, backend="dense", natural_fractures=nf)

    e1 = np.array([1.0, 0.0, 1.0]) / np.sqrt(2)  # no horizontal edge, across z = 1
    e2 = np.cross(e1, np.array([0.3, 1.0, 0.4]))
    e2 /= np.linalg.norm(e2)
    tilted = hd.Mesh3D.from_rectangles(np.array([[3.0, 0.0, 1.0]]), e1[None], e2[None],
                                       np.array([0.5]), np.array([0.5]))
    with pytest.raises(InputError, match="natural_fractures: element 0 crosses the interface at z = 1"):
        run3d(tilted)
    above = hd.mesh.rectangle([3.0, 0.0, 2.0], [0, 1, 0], [0, 0, 1], 1.0, 1.0, 1, 1)
    with pytest.raises(InputError, match="natural_fractures element 0 lies in layer 0, which is void"):
        run3d(above, LayeredMedium([1.0], [0.0, G], [NU, NU]))
    with pytest.raises(InputError, match="natural_fractures must be a Mesh3D"):
        run3d(hd.mesh.line([1.0, -1.0], [1.0, 1.0], 2))

    def run2d(nf):
        return hd.Simulation(hd.mesh.line([-1.0, 0.0], [0.0, 0.0], 2), LayeredMedium([0.5], [2 * G, G], [NU, NU]),
                             hd.Fluid(1e-3), [hd.Cluster((-0.5, 0.0), 1e-3)], np.diag([-1e6, -2e6]), 1.0,
                             backend="dense", natural_fractures=nf)

    with pytest.raises(InputError, match="natural_fractures element 0 lies along interface 0"):
        run2d(hd.mesh.line([1.0, 0.5], [2.0, 0.5], 1))  # a bedding plane on the interface itself
    with pytest.raises(InputError, match="natural_fractures: a LayeredMedium simulation needs constant elements"):
        run2d(hd.mesh.line([1.0, -1.0], [1.0, -0.2], 2, element_order=1))


# -- 3D ------------------------------------------------------------------------------------
def _run_3d(material, natural):
    """A vertical fracture in the x-z plane grows along x, within z = -1 .. 1, to a
    vertical natural fracture at x = 1.75 that reaches z = +-1.5."""
    hf = hd.mesh.rectangle([0.0, 0.0, 0.0], [1, 0, 0], [0, 0, 1], 2.0, 2.0, 2, 2)
    props = hd.NaturalFractureProperties(friction=0.6, cohesion=0.0, tensile_strength=0.0, toughness=0.5e6,
                                         critical_radius=0.005, pore_pressure=0.0, skempton=0.5)
    sim = hd.Simulation(hf, material, hd.Fluid(1e-3, 4.4e-10), [hd.Cluster((0.0, 0.0, 0.0), 2e-3, 0.01)],
                        np.diag([-8e6, -3e6, -12e6]), 1.0,
                        propagation=hd.Propagation(toughness=1e6, turning="plan",
                                                   bounds=((-np.inf, np.inf), (-np.inf, np.inf), (-1.0, 1.0))),
                        initial_pressure=3.5e6, initial_opening=1e-4, backend="dense",
                        singular_correction="average", alpha=1.0, natural_fractures=natural, natural=props)
    return sim, sim.run(4.0)


@pytest.mark.slow  # the 3D layered kernels compile cold in minutes; the run itself takes seconds
def test_equal_layers_reproduce_the_homogeneous_3d_run_with_natural_fractures():
    """The natural fracture crosses both interfaces: the layered run cuts it there, so the
    homogeneous run is given the same pieces."""
    medium = LayeredMedium([1.0, -1.0], [G] * 3, [NU] * 3)
    natural = hd.mesh.rectangle([1.75, 0.0, 0.0], [0, 1, 0], [0, 0, 1], 2.0, 3.0, 2, 3, fracture_id=5)
    pieces, _ = split_at_interfaces(natural, medium)
    homogeneous, records_h = _run_3d(hd.Elastic(G, NU), pieces)
    layered, records_l = _run_3d(medium, natural)
    np.testing.assert_array_equal(layered.network.mesh.centers, pieces.centers)
    assert sum(r["natural_deflected"] + r["natural_crossed"] for r in records_h) >= 1
    assert _events(records_l) == _events(records_h)
    np.testing.assert_array_equal(layered.state.origin, homogeneous.state.origin)
    scale = np.abs(homogeneous.state.dd).max()
    assert np.max(np.abs(layered.state.dd - homogeneous.state.dd)) <= 1e-10 * scale


@pytest.mark.slow  # the 3D layered kernels compile cold in minutes; the run itself takes seconds
def test_3d_remote_failure_sees_the_stiffer_layers_as_the_layered_stress_says(monkeypatch):
    """Stiffer bounding layers (gamma = 2): the natural fracture is cut at both interfaces,
    and the first remote-failure check's normal stress on every intact element is the
    layered stress at its centre (hd.stress_at with the medium) plus the far field."""
    calls = _spy(monkeypatch, "remote_failure")
    medium = LayeredMedium([1.0, -1.0], [2 * G, G, 2 * G], [NU] * 3, images=1)
    natural = hd.mesh.rectangle([1.75, 0.0, 0.0], [0, 1, 0], [0, 0, 1], 2.0, 3.0, 2, 3, fracture_id=5)
    sim, records = _run_3d(medium, natural)
    assert sim.network.mesh.n_elements == 10 and sum(r["natural_deflected"] for r in records) >= 1
    (mesh, dd, *_), (failed, normal, shear, _) = calls[0]
    nf = sim.network.mesh
    intact = normal != 0.0
    assert np.count_nonzero(intact) >= 6
    total = hd.stress_at(mesh, medium, dd, nf.centers, singular_correction="average", near_fraction=0.5) \
        + np.diag([-8e6, -3e6, -12e6])
    traction = np.einsum("mij,mj->mi", total, nf.normals)
    sigma_n = np.sum(traction * nf.normals, axis=1)
    tau = np.linalg.norm(traction - sigma_n[:, None] * nf.normals, axis=1)
    np.testing.assert_allclose(normal[intact], sigma_n[intact], rtol=1e-12)
    np.testing.assert_allclose(shear[intact], tau[intact], rtol=1e-10, atol=1e-9 * np.abs(total).max())
    homogeneous = hd.stress_at(mesh, hd.Elastic(G, NU), dd, nf.centers, singular_correction="average",
                               near_fraction=0.5)
    assert np.abs(total - homogeneous - np.diag([-8e6, -3e6, -12e6]))[intact].max() > 1e-3 * np.abs(total).max()


def test_the_network_check_takes_each_elements_layer_when_called_directly():
    """NaturalNetwork.remote_failure with a LayeredMedium and no per-element values: the
    Poisson's ratio of each target's layer, as the engine passes it."""
    hf = hd.mesh.line([-2.0, 0.0], [2.0, 0.0], 8)
    dd = hd.solve(hd.ElasticityOperator(hf, THREE_LAYERS, backend="dense"), -2e6 * hf.normals)
    nf = split_at_interfaces(hd.mesh.line([3.0, -0.4], [3.0, 1.0], 4), THREE_LAYERS)[0]
    props = hd.NaturalFractureProperties(friction=0.3, pore_pressure=2e6, skempton=0.5)
    intact = np.ones(nf.n_elements, bool)
    direct = NaturalNetwork(nf, props).remote_failure(hf, dd, THREE_LAYERS, np.diag([-14e6, -9e6]), intact)
    nu = np.array(THREE_LAYERS.poisson_ratio)[THREE_LAYERS.layer_of(nf.centers[:, 1])]
    assert len(set(nu)) == 2
    given = NaturalNetwork(nf, props).remote_failure(hf, dd, THREE_LAYERS, np.diag([-14e6, -9e6]), intact,
                                                     poisson_ratio=nu)
    for a, b in zip(direct, given):
        np.testing.assert_array_equal(a, b)
