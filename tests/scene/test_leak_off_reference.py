"""A scene with Carter leak-off judged by a closed form with leak-off (issue 39): the
``[reference] kind`` ``kgd-k-leak-off`` / ``radial-k-leak-off`` (the K-K~ edges of
:mod:`hmatddm.analytical.leak_off`), its leak-off number in the reference block, the
schema's refusals, and a short run against it."""
import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.errors import InputError
from hmatddm.scene.build import _closed_form

# bench_leak_off.py's "K to K~" case as a scene: G 1 GPa, sigma_0 - p_r = 20 MPa, Q 1e-3
# m^2/s, c_l 1e-11 m/(s^1/2 Pa) (C' = 2e-4 m/s^1/2), K_Ic 1 MPa m^1/2, mu 1e-5 Pa s;
# 0.4 m initial fracture of 0.1 m elements, the element front (the asymptotic front refuses
# leak-off)
KGD_LEAK_OFF = """
dimension = 2
[material]
shear_modulus = 1e9
poisson_ratio = 0.25
[fluid]
viscosity = 1e-5
compressibility = 0.0
[stress]
s_hmin = 20e6
s_hmax = 40e6
[[cluster]]
position = [0.0, 0.0]
rate = 1e-3
[[initial_fracture]]
shape = "line"
p0 = [-0.2, 0.0]
p1 = [0.2, 0.0]
element_size = 0.1
[propagation]
toughness = 1e6
front = "element"
[leak_off]
coefficient = 1e-11
pore_pressure = 0.0
[numerics]
time_step = 1.0
end_time = 20.0
backend = "dense"
initial_pressure = 21.28e6
initial_opening = 1e-5
[reference]
kind = "kgd-k-leak-off"
"""


def scene(text=KGD_LEAK_OFF, **changes):
    raw = hs.parse_scene(text).data
    for dotted, value in changes.items():
        section, key = dotted.split(".")
        raw[section][key] = value
    return hs.scene_from_dict(raw, "leak-off").data


def test_the_edge_is_the_k_vertex_without_leak_off_and_the_carter_size_with_much():
    # independent limits: tiny c_l -> the KGD K vertex l = (E' Q t / (2 pi^1/2 K_Ic))^(2/3);
    # much leak-off (sigma_0 - p_r = 200 MPa) -> the leak-off vertex l = Q t^1/2 / (pi C'), C' = c_l (sigma_0 - p_r + p_net)
    e_prime = 2.0 * 1e9 / (1.0 - 0.25)
    t = np.array([5.0, 20.0])
    storage = _closed_form(scene(**{"leak_off.coefficient": 1e-16}), t)
    k_vertex = (e_prime * 1e-3 * t / (2.0 * np.sqrt(np.pi) * 1e6)) ** (2.0 / 3.0)
    np.testing.assert_allclose(storage["half_length"], k_vertex, rtol=2e-3)
    leaky = _closed_form(scene(**{"leak_off.coefficient": 1e-10, "stress.s_hmin": 200e6, "stress.s_hmax": 400e6}), t)
    carter = 1e-3 * np.sqrt(t) / (np.pi * 1e-10 * (200e6 + leaky["net_pressure"]))
    np.testing.assert_allclose(leaky["half_length"], carter, rtol=0.01)
    # Griffith's opening at the well and the uniform net pressure K_Ic / (pi l)^(1/2)
    np.testing.assert_allclose(leaky["net_pressure"], 1e6 / np.sqrt(np.pi * leaky["half_length"]), rtol=1e-12)
    np.testing.assert_allclose(leaky["max_opening"], 4.0 * leaky["net_pressure"] * leaky["half_length"] / e_prime,
                               rtol=1e-12)


def test_the_reference_block_records_the_leak_off_number():
    data = scene()
    rows = hs.reference_values(data, [{"time": 10.0, "half_length": 4.0, "max_opening": 1e-3,
                                       "wellbore_pressure": [20.2e6], "mean_pressure": 20.2e6}])
    regime = rows[0]["regime"]
    # C_m = (C'^6 E' t / (mu' Q^3))^(1/6), C' = c_l (sigma_0 - p_r), written out here
    e_prime = 2.0 * 1e9 / (1.0 - 0.25)
    c_prime = 1e-11 * 20e6
    c_m = (c_prime**6 * e_prime * 10.0 / (12.0 * 1e-5 * 1e-3**3)) ** (1.0 / 6.0)
    assert regime["leak_off"]["number"] == "C_m"
    assert regime["leak_off"]["value"] == pytest.approx(c_m, rel=1e-12)
    k_m = 4.0 * np.sqrt(2.0 / np.pi) * 1e6 / (e_prime**3 * 12.0 * 1e-5 * 1e-3) ** 0.25
    assert regime["value"] == pytest.approx(k_m, rel=1e-12) and regime["vertex"] == "K"
    assert regime["applies_over_run"] and regime["solution_that_applies"] is None
    assert rows[0]["solution"]["kind"] == "kgd-k-leak-off" and "Carter" in rows[0]["solution"]["source"]
    assert hs.reference_warning(data) is None


def test_a_viscous_leak_off_scene_is_warned_off_the_edge():
    line = hs.reference_warning(scene(**{"fluid.viscosity": 1.0}))
    assert line is not None and "'kgd-k-leak-off'" in line


def test_an_m_tilde_vertex_is_warned_off_where_too_little_has_leaked():
    # KGD_M_LEAK_OFF below as kgd-m-leak-off: C_m = (C'^6 E' t / (mu' Q^3))^(1/6) 4.4 at 0.5 s,
    # 6.2 at 4 s, under the 10.4 where Dontsov's half-length is 1% from the vertex's: warned,
    # naming Dontsov 2017; four times the leak-off coefficient (C_m x 4): no warning
    e_prime = 2.0 * 1e9 / (1.0 - 0.25)
    raw = hs.parse_scene(KGD_M_LEAK_OFF).data
    raw["reference"]["kind"] = "kgd-m-leak-off"
    line = hs.reference_warning(hs.scene_from_dict(raw, "m-leak-off").data)
    first, last = (((2e-3) ** 6 * e_prime * t / (12e-3 * 1e-3**3)) ** (1.0 / 6.0) for t in (0.5, 4.0))
    assert line is not None and "\n" not in line and "'kgd-m-leak-off'" in line
    assert f"C_m = {first:.2f} to {last:.2f}" in line and "C_m >= 10.4" in line
    assert "kgd-km-leak-off (Dontsov 2017" in line
    raw["leak_off"]["coefficient"] = 4e-10
    assert hs.reference_warning(hs.scene_from_dict(raw, "m-leak-off").data) is None


def test_the_radial_m_tilde_vertex_is_carters_radius_and_dontsovs_opening():
    # R = (2 Q t^(1/2) / C')^(1/2) / pi (mass balance, all leaked), w0 = 1.0600 (mu'^4 Q^6 t /
    # (E'^4 C'^2))^(1/16), written out here; C' = c_l (s_v - p_r) = 2e-10 x 20 MPa
    from hmatddm.app.profiles import closed_form_profile

    data = radial_m_leak_off_scene(first_step=1.5)
    t = np.array([2.0, 8.0])
    curves = _closed_form(data, t)
    e_prime, c_prime = 2.0 * 1e9 / (1.0 - 0.25), 4e-3
    np.testing.assert_allclose(curves["radius"], np.sqrt(2.0 * 2e-2 * np.sqrt(t) / c_prime) / np.pi, rtol=1e-12)
    np.testing.assert_allclose(curves["max_opening"],
                               1.0600 * ((12 * 2.5e-5) ** 4 * 2e-2**6 * t / (e_prime**4 * c_prime**2)) ** (1 / 16),
                               rtol=1e-12)
    profile = closed_form_profile(data, 8.0)
    assert max(profile["opening"]) == pytest.approx(curves["max_opening"][1], rel=1e-9) and "M~" in profile["label"]
    assert max(profile["position"]) == pytest.approx(curves["radius"][1], rel=1e-9)
    # C_m 13.0 at the first step (1.5 s) to 25 at 8 s, K_m C_m^(-1/8) below 0.1: the vertex applies
    assert hs.reference_warning(data) is None
    rows = hs.reference_values(data, [dict(time=8.0, radius=1.0, max_opening=1e-4, wellbore_pressure=[20.1e6])])
    assert rows[0]["regime"]["leak_off"]["value"] == pytest.approx(
        c_prime * (e_prime**4 * 8.0**7 / ((12 * 2.5e-5) ** 4 * 2e-2**6)) ** (1 / 18), rel=1e-12)
    assert rows[0]["solution"]["kind"] == "radial-m-leak-off" and rows[0]["regime"]["applies_over_run"]
    # from 0.5 s (C_m 8.5) it does not, and the warning names Dontsov 2016
    line = hs.reference_warning(radial_m_leak_off_scene(first_step=0.5))
    assert "C_m = 8.49 to 24.95" in line and "radial-km-leak-off (Dontsov 2016" in line


def test_the_schema_pairs_leak_off_with_the_leak_off_kinds():
    with pytest.raises(InputError, match="leak_off.coefficient must be > 0.*kind = 'kgd-k'"):
        scene(**{"leak_off.coefficient": 0.0})
    with pytest.raises(InputError, match="assumes no leak-off.*'kgd-k-leak-off'"):
        scene(**{"reference.kind": "kgd-k"})
    with pytest.raises(InputError, match="reference.kind"):
        scene(**{"reference.kind": "kgd-k-leakoff"})


def test_a_radial_leak_off_edge_starts_at_the_radial_k_vertex():
    raw = hs.parse_scene(hs.embedded_text("radial-k")).data
    raw["leak_off"] = {"coefficient": 1e-18}
    raw["propagation"]["front"] = "element"
    raw["reference"]["kind"] = "radial-k-leak-off"
    data = hs.scene_from_dict(raw, "radial-leak-off").data
    t = np.array([10.0, 50.0])
    edge = _closed_form(data, t)
    vertex = _closed_form(data, t, kind="radial-k")
    np.testing.assert_allclose(edge["radius"], vertex["radius"], rtol=2e-3)
    np.testing.assert_allclose(edge["max_opening"], vertex["max_opening"], rtol=2e-3)
    assert np.all(edge["leak_off_number"] > 0.0)


def test_a_leak_off_run_follows_the_edge():
    # measured: half-length -1.4..+1.4% from 5 s on (-2.7% at 2 s), opening and net pressure
    # -1..-8% (the element front's steps); 52% of the fluid leaked off by 20 s, C_m 1.4-1.7,
    # K_m 14.6 (0.4 s CPU)
    data = scene()
    simulation = hs.build_simulation(data)
    records = simulation.run(20.0)
    rows = hs.reference_values(data, records)
    assert records[-1]["leaked_volume"] > 0.4 * records[-1]["injected_volume"]
    for row in rows[4:]:
        assert abs(row["relative_error"]["half_length"]) < 0.03


def test_the_profile_beside_a_leak_off_run_is_the_edges_griffith_crack():
    from hmatddm.app.profiles import closed_form_profile

    data = scene()
    profile = closed_form_profile(data, 10.0)
    curves = _closed_form(data, [10.0])
    assert max(profile["opening"]) == pytest.approx(float(curves["max_opening"][0]), rel=1e-3)
    assert max(profile["position"]) == pytest.approx(float(curves["half_length"][0]), rel=1e-9)
    assert np.allclose(profile["net_pressure"], float(curves["net_pressure"][0]))
    assert "K-K~ edge" in profile["label"]


def test_the_asymptotic_front_with_leak_off_follows_the_edge():
    # the same scene on the asymptotic front (5 initial elements: the well at a centre); the tip
    # asymptote with leak-off, each element leaking from when the front crosses its centre.
    # Measured: half-length -0.12 / +0.05 / -0.03%, net pressure +0.54 / +0.09 / +0.13% at 5,
    # 10, 20 s (the element front: -1.4 / +1.1 / -1.3% and -5.9 / -7.9 / -0.3%); 2.6 s CPU
    raw = hs.parse_scene(KGD_LEAK_OFF).data
    raw["propagation"]["front"] = "asymptotic"
    raw["initial_fracture"][0].update(p0=[-0.25, 0.0], p1=[0.25, 0.0])
    data = hs.scene_from_dict(raw, "leak-off-asymptotic").data
    records = hs.build_simulation(data).run(20.0)
    rows = hs.reference_values(data, records)
    assert records[-1]["leaked_volume"] > 0.45 * records[-1]["injected_volume"]
    for record, row in zip(records, rows):
        if record["time"] >= 5.0:
            assert abs(row["relative_error"]["half_length"]) < 0.005
            assert abs(row["relative_error"]["max_opening"]) < 0.01
            assert abs(row["relative_error"]["net_pressure"]) < 0.01
        assert abs(record["budget"]["residual"]) < 1e-8 * record["injected_volume"]


def test_the_viscous_leak_off_kinds_give_their_closed_forms():
    # kgd-m-leak-off: the M~ vertex with C' = c_l (sigma_0 - p_r); radial-km-leak-off: Dontsov 2016
    from hmatddm.analytical.viscous_leak_off import kgd_m_leak_off_vertex, radial_leak_off_transition
    from hmatddm.app.profiles import closed_form_profile

    data = scene(**{"fluid.viscosity": 1e-3, "reference.kind": "kgd-m-leak-off"})
    t = np.array([5.0, 20.0])
    curves = _closed_form(data, t)
    length, w0 = kgd_m_leak_off_vertex(t, 1e-3, 1e-3, 1e-11 * 20e6, data_material(data))
    np.testing.assert_allclose(curves["half_length"], length, rtol=1e-12)
    np.testing.assert_allclose(curves["max_opening"], w0, rtol=1e-12)
    assert np.all(curves["leak_off_number"] > 0.0)
    # p(0) = 0.7515 (E'^3 mu' C'^2 / (Q t))^(1/4), the similarity solution's
    e_prime = 2.0 * 1e9 / (1.0 - 0.25)
    np.testing.assert_allclose(curves["net_pressure"], 0.7515 * (e_prime**3 * 12e-3 * (2e-4) ** 2 / (1e-3 * t)) ** 0.25,
                               rtol=1e-12)
    profile = closed_form_profile(data, 20.0)
    assert max(profile["opening"]) == pytest.approx(w0[1], rel=1e-9) and "M~" in profile["label"]
    raw = hs.parse_scene(hs.embedded_text("radial-k")).data
    raw["leak_off"] = {"coefficient": 1e-11}
    raw["propagation"]["front"] = "element"
    raw["reference"]["kind"] = "radial-km-leak-off"
    radial = hs.scene_from_dict(raw, "radial-viscous-leak-off").data
    curves = _closed_form(radial, t)
    excess = 1e-11 * (hs.build.confining_stress(radial) - radial["leak_off"]["pore_pressure"])
    radius, width, _ = radial_leak_off_transition(t, radial["cluster"][0]["rate"], radial["fluid"]["viscosity"],
                                                  radial["propagation"]["toughness"], excess, data_material(radial))
    np.testing.assert_allclose(curves["radius"], radius, rtol=1e-12)
    np.testing.assert_allclose(curves["max_opening"], width, rtol=1e-12)
    assert max(closed_form_profile(radial, 20.0)["opening"]) == pytest.approx(width[1], rel=1e-6)
    raw["reference"]["kind"] = "radial-k"
    with pytest.raises(InputError, match="'radial-km-leak-off' \\(viscous\\)"):
        hs.scene_from_dict(raw, "radial-viscous-leak-off")


# the bench_leak_off.py radial M~ row as a scene: Q 2e-2 m^3/s, mu 2.5e-5 Pa s, K_Ic 10 kPa m^1/2,
# c_l 2e-10 m/(s^1/2 Pa) at s_v - p_r = 20 MPa (C' = 4e-3 m/s^1/2), G 1 GPa, nu 0.25; 3 x 3
# initial elements of 0.2 m on the asymptotic front
RADIAL_M_LEAK_OFF = """
dimension = 3
[material]
shear_modulus = 1e9
poisson_ratio = 0.25
[fluid]
viscosity = 2.5e-5
compressibility = 0.0
[stress]
s_hmin = 40e6
s_hmax = 40e6
s_v = 20e6
[[cluster]]
position = [0.0, 0.0, 0.0]
rate = 2e-2
[[initial_fracture]]
shape = "rectangle"
center = [0.0, 0.0, 0.0]
e1 = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
length = 0.6
height = 0.6
element_size = 0.2
[propagation]
toughness = 1e4
front = "asymptotic"
[leak_off]
coefficient = 2e-10
pore_pressure = 0.0
[numerics]
time_step = "auto"
first_time_step = FIRST
max_time_step = LONGEST
step_advance = 0.3
end_time = END
backend = "dense"
initial_pressure = 20e6
initial_opening = 1e-6
[reference]
kind = "radial-m-leak-off"
"""


def radial_m_leak_off_scene(first_step=0.05, end_time=8.0):
    text = RADIAL_M_LEAK_OFF.replace("FIRST", repr(first_step)).replace("END", repr(end_time)).replace(
        "LONGEST", repr(max(first_step, 0.5)))
    return hs.scene_from_dict(hs.parse_scene(text).data, "radial-m-leak-off").data


def data_material(data):
    from hmatddm.scene.build import material

    return material(data)


# A viscous, leak-off-dominated KGD fracture (issue 36): mu 1e-3 Pa s, K_Ic 1 kPa m^1/2 (K_m 0.011),
# c_l 1e-10 m/(s^1/2 Pa) (C' = 2e-3 m/s^1/2), Q 1e-3 m^2/s: C_m 4.4 to 6.2 over 0.5-4 s, 2.4-3.9%
# of the fluid stored (the M~ vertex stores none), on 0.05 m elements of the asymptotic front; the
# first step (0.5 s) is long enough that the 3 initial elements, leaking from t = 0, do not take
# all the fluid; steps that move the front 0.3 elements
KGD_M_LEAK_OFF = KGD_LEAK_OFF.replace("viscosity = 1e-5", "viscosity = 1e-3").replace(
    "coefficient = 1e-11", "coefficient = 1e-10").replace("toughness = 1e6", "toughness = 1e3").replace(
    'front = "element"', 'front = "asymptotic"').replace("p0 = [-0.2, 0.0]", "p0 = [-0.075, 0.0]").replace(
    "p1 = [0.2, 0.0]", "p1 = [0.075, 0.0]").replace("element_size = 0.1", "element_size = 0.05").replace(
    "time_step = 1.0", 'time_step = "auto"\nfirst_time_step = 0.5\nmax_time_step = 0.5\nstep_advance = 0.3').replace(
    "end_time = 20.0", "end_time = 4.0").replace("initial_pressure = 21.28e6", "initial_pressure = 20e6").replace(
    "initial_opening = 1e-5", "initial_opening = 1e-6").replace('kind = "kgd-k-leak-off"', 'kind = "kgd-km-leak-off"')


def test_a_viscous_leak_off_run_follows_dontsovs_solution_towards_the_m_tilde_vertex():
    # measured (0.05 m) from 2 s on: half-length -2.2..-0.5% and inlet opening -3.2..-0.4% from
    # Dontsov 2017 (kgd-km-leak-off); from the M~ vertex -4.6..-2.7% and -4.2..-1.5% (the 2.4% of
    # the fluid still stored: Dontsov's own solution sits -2.3% / -1.2% from the vertex); the
    # budget's residual below 1e-7 of the injected volume; the wellbore net pressure -3.0..+2.3%
    # from the vertex's (its similarity solution's 0.7515 P); 4-8 s CPU
    from hmatddm.analytical.viscous_leak_off import kgd_m_leak_off_vertex

    data = hs.scene_from_dict(hs.parse_scene(KGD_M_LEAK_OFF).data, "m-leak-off").data
    records = hs.build_simulation(data).run(4.0)
    rows = hs.reference_values(data, records)
    late = [(record, row) for record, row in zip(records, rows) if record["time"] >= 2.0]
    assert len(late) >= 4 and records[-1]["leaked_volume"] > 0.97 * records[-1]["injected_volume"]
    for record, row in late:
        assert row["regime"]["leak_off"]["value"] > 5.5
        assert abs(row["relative_error"]["half_length"]) < 0.03
        assert abs(row["relative_error"]["max_opening"]) < 0.04
        assert abs(record["budget"]["residual"]) < 1e-6 * record["injected_volume"]
    t = np.array([record["time"] for record, _ in late])
    length, w0 = kgd_m_leak_off_vertex(t, 1e-3, 1e-3, 2e-3, data_material(data))
    assert np.all(np.abs(np.array([record["half_length"] for record, _ in late]) / length - 1.0) < 0.05)
    assert np.all(np.abs(np.array([record["max_opening"] for record, _ in late]) / w0 - 1.0) < 0.05)
    net = np.array([record["wellbore_pressure"][0] - 20e6 for record, _ in late])
    assert np.all(np.abs(net / kgd_m_leak_off_vertex(t, 1e-3, 1e-3, 2e-3, data_material(data), pressure=True)[2] - 1.0)
                  < 0.04)


def test_a_radial_run_reaches_the_m_tilde_vertex():
    # RADIAL_M_LEAK_OFF on 0.2 m elements to 1.6 s (bench_leak_off.py --viscous --radial 1 runs it
    # to 8 s: from the M~ vertex R -0.4..+0.2%, w0 +2.6..+1.2%; at 0.1 m R -0.3%, w0 +0.2% at 4 s).
    # The run starts at C_m 3.5 (0.05 s), so the vertex is warned off over it; from 1.2 s on (C_m >=
    # 11.9, where the vertex is within 1% of Dontsov's solution) measured R +0.0..+0.13%, w0
    # +2.1..+2.6%, roundness 1.047: held to 1%, 4% and 1.06; nearly all the fluid leaked. 10 s CPU
    # (issue 33: with each front iteration's solve starting at a grown-back alpha, the stagnation
    # rule and the exact Schur complement: R -0.0..+0.09%, w0 +1.8..+2.8%, roundness 1.044, 8 s CPU)
    data = radial_m_leak_off_scene(end_time=1.6)
    assert "C_m = 3.47 to 13.34" in hs.reference_warning(data)
    records = hs.build_simulation(data).run(1.6)
    rows = hs.reference_values(data, records)
    late = [(record, row) for record, row in zip(records, rows) if record["time"] >= 1.2]
    assert len(late) >= 2 and records[-1]["leaked_volume"] > 0.97 * records[-1]["injected_volume"]
    for record, row in late:
        assert row["regime"]["leak_off"]["value"] >= 11.4
        assert abs(row["relative_error"]["radius"]) < 0.01
        assert abs(row["relative_error"]["max_opening"]) < 0.04
        assert abs(record["budget"]["residual"]) < 1e-6 * record["injected_volume"]
        assert record["front_circularity"] < 1.06
