"""Regime numbers (hmatddm.analytical.regimes) against formulas written apart from the
code: the dimensionless toughness as a power of the ratio of the M and K length scales,
the leak-off number as the ratio of the leak-off length to the M width scale; and the
regime of every embedded scene with a [reference], with the warning for a vertex that does
not apply over the run."""
import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.analytical import regimes
from hmatddm.errors import InputError
from hmatddm.material import Elastic

ROCK = Elastic(shear_modulus=24e9, poisson_ratio=0.25)


def _primes(material, toughness, viscosity):
    e_prime = 2.0 * material.shear_modulus / (1.0 - material.poisson_ratio)
    return e_prime, np.sqrt(32.0 / np.pi) * toughness, 12.0 * viscosity


def independent_radial_km(t, q, viscosity, toughness, material):
    """K_m = (L_m / L_k)^(5/2): L_m = (E' Q^3 t^4 / mu')^(1/9) the viscosity length scale,
    L_k = (E' Q t / K')^(2/5) the toughness one (Savitski and Detournay 2002, Sec. 2)."""
    e_prime, k_prime, mu_prime = _primes(material, toughness, viscosity)
    length_m = (e_prime * q**3 * t**4 / mu_prime) ** (1.0 / 9.0)
    length_k = (e_prime * q * t / k_prime) ** 0.4
    return (length_m / length_k) ** 2.5


def independent_kgd_km(q, viscosity, toughness, material, t=7.0):
    """K_m = (L_m / L_k)^(3/2) with the plane-strain scales L_m = (E' Q^3 t^4 / mu')^(1/6),
    L_k = (E' Q t / K')^(2/3) (their ratio does not depend on t)."""
    e_prime, k_prime, mu_prime = _primes(material, toughness, viscosity)
    length_m = (e_prime * q**3 * t**4 / mu_prime) ** (1.0 / 6.0)
    length_k = (e_prime * q * t / k_prime) ** (2.0 / 3.0)
    return (length_m / length_k) ** 1.5


def independent_leak_off(t, q, viscosity, c_prime, material, radial):
    """C' t^(1/2) / W_m with the viscosity width scale W_m = eps L_m, eps = (mu'/(E' t))^(1/3)."""
    e_prime, _, mu_prime = _primes(material, 1.0, viscosity)
    length = (e_prime * q**3 * t**4 / mu_prime) ** (1.0 / 9.0 if radial else 1.0 / 6.0)
    width = (mu_prime / (e_prime * t)) ** (1.0 / 3.0) * length
    return c_prime * np.sqrt(t) / width


def test_radial_toughness_number_is_the_ratio_of_the_length_scales():
    t = np.array([0.5, 3.0, 50.0, 1e4])
    for q, mu, k in [(0.01, 1e-3, 5e6), (0.08, 0.1, 1e6), (1e-3, 1e-4, 3e6)]:
        expected = independent_radial_km(t, q, mu, k, ROCK)
        assert np.allclose(regimes.radial_toughness_number(t, q, mu, k, ROCK), expected, rtol=1e-12)
        assert np.all(np.diff(np.log(expected)) / np.diff(np.log(t)) == pytest.approx(1.0 / 9.0))


def test_kgd_toughness_number_is_the_ratio_of_the_length_scales():
    for q, mu, k in [(5e-4, 1e-3, 5e6), (1e-2, 0.1, 1e6)]:
        rock = Elastic(shear_modulus=10e9, poisson_ratio=0.25)
        assert regimes.kgd_toughness_number(q, mu, k, rock) == pytest.approx(
            independent_kgd_km(q, mu, k, rock), rel=1e-12)
        assert independent_kgd_km(q, mu, k, rock, t=7.0) == pytest.approx(independent_kgd_km(q, mu, k, rock, t=900.0))


def test_leak_off_numbers_are_the_leak_off_length_over_the_width_scale():
    t = np.array([1.0, 30.0, 2000.0])
    c_prime = 2.0 * 5e-5  # C' = 2 C_L
    assert np.allclose(regimes.radial_leak_off_number(t, 0.01, 1e-3, c_prime, ROCK),
                       independent_leak_off(t, 0.01, 1e-3, c_prime, ROCK, radial=True), rtol=1e-12)
    assert np.allclose(regimes.kgd_leak_off_number(t, 5e-4, 1e-3, c_prime, ROCK),
                       independent_leak_off(t, 5e-4, 1e-3, c_prime, ROCK, radial=False), rtol=1e-12)
    assert np.all(regimes.radial_leak_off_number(t, 0.01, 1e-3, 0.0, ROCK) == 0.0)
    with pytest.raises(InputError, match="leak_off"):
        regimes.radial_leak_off_number(t, 0.01, 1e-3, -1.0, ROCK)
    with pytest.raises(InputError, match="t must be > 0"):
        regimes.kgd_leak_off_number([0.0], 5e-4, 1e-3, c_prime, ROCK)


def test_which_solution_applies():
    assert regimes.vertex(0.9, "radial") == "M" and regimes.vertex(3.6, "radial") == "K"
    assert regimes.vertex(3.6, "kgd") == "transition" and regimes.vertex(4.0, "kgd") == "K"
    assert regimes.applicable_solution("radial-k", [3.6, 6.0]) == (True, None)
    applies, instead = regimes.applicable_solution("radial-k", [1.8, 2.9])
    assert not applies and "radial-km" in instead and "Dontsov 2016" in instead
    applies, instead = regimes.applicable_solution("radial-m", [0.2, 5.0])
    assert not applies and instead.startswith("radial-km")
    applies, instead = regimes.applicable_solution("radial-m", [4.0, 5.0])  # the other vertex all along
    assert not applies and instead.startswith("radial-k ")
    assert regimes.applicable_solution("radial-km", [0.1, 2.0, 9.0]) == (True, None)
    applies, instead = regimes.applicable_solution("kgd-k", [3.0])
    assert not applies and "Dontsov 2017" in instead and "Garagash" in instead
    with pytest.raises(InputError, match="geometry"):
        regimes.vertex(1.0, "penny")


def test_an_m_tilde_vertex_applies_deep_in_leak_off_and_at_low_toughness_only():
    # the M~ toughness number: radial K' (t / (mu'^4 Q^2 E'^12 C'^2))^(1/16), the ratio of the
    # toughness opening K' L^(1/2) / E' to the M~ width scale at the M~ length L = (Q^2 t / C'^2)^(1/4)
    t, q, mu, k, c_prime = np.array([2.0, 40.0]), 0.01, 1e-3, 3e5, 2e-3
    e_prime, k_prime, mu_prime = _primes(ROCK, k, mu)
    length = (q * q * t / c_prime**2) ** 0.25
    width = (mu_prime**4 * q**6 * t / (e_prime**4 * c_prime**2)) ** (1.0 / 16.0)
    k_m = regimes.radial_toughness_number(t, q, mu, k, ROCK)
    c_m = regimes.radial_leak_off_number(t, q, mu, c_prime, ROCK)
    np.testing.assert_allclose(regimes.m_leak_off_toughness_number(k_m, c_m, "radial"),
                               k_prime * np.sqrt(length) / (e_prime * width), rtol=1e-12)
    assert regimes.m_leak_off_toughness_number([0.3], [50.0], "kgd") == pytest.approx([0.3])
    assert regimes.applicable_solution("kgd-m-leak-off", [0.01], [11.0, 14.0]) == (True, None)
    for k_ms, c_ms in (([0.01], [5.0, 8.0]), ([1.5], [20.0, 30.0])):  # too little leak-off; too tough
        applies, instead = regimes.applicable_solution("kgd-m-leak-off", k_ms, c_ms)
        assert not applies and instead.startswith("kgd-km-leak-off") and "Dontsov 2017" in instead
    # radial: K_m 1.2 is M~ deep in leak-off (K_m C_m^(-1/8) = 0.54 at C_m 600), not at C_m 12 with K_m 2
    assert regimes.applicable_solution("radial-m-leak-off", [1.2, 1.2], [600.0, 700.0]) == (True, None)
    applies, instead = regimes.applicable_solution("radial-m-leak-off", [2.0, 2.0], [12.0, 13.0])
    assert not applies and instead.startswith("radial-km-leak-off") and "Dontsov 2016" in instead
    with pytest.raises(InputError, match="leak_off_numbers"):
        regimes.applicable_solution("radial-m-leak-off", [0.1])


def test_the_m_tilde_limits_are_where_dontsovs_solution_is_one_percent_from_the_vertex():
    # measured with the package's Dontsov 2016 / 2017 at nearly zero toughness: the size is 1%
    # from the vertex's at the limit, more below it, less above it
    from hmatddm.analytical import viscous_leak_off as vl

    mu, c_prime = 1e-3, 2e-3
    for geometry, q in (("kgd", 1e-3), ("radial", 1e-2)):
        limit = regimes.M_LEAK_OFF_LIMITS[geometry]
        number = regimes.kgd_leak_off_number if geometry == "kgd" else regimes.radial_leak_off_number
        # C_m grows as t^(1/6) (KGD), t^(7/18) (radial): the times of C_m = limit x (0.8, 1, 1.25)
        unit = float(number(np.array([1.0]), q, mu, c_prime, ROCK)[0])
        power = 6.0 if geometry == "kgd" else 18.0 / 7.0
        t = (limit * np.array([0.8, 1.0, 1.25]) / unit) ** power
        if geometry == "kgd":
            size = vl.kgd_leak_off_transition(t, q, mu, 1e2, c_prime, ROCK)[0]
            vertex = vl.kgd_m_leak_off_vertex(t, q, mu, c_prime, ROCK)[0]
        else:
            size = vl.radial_leak_off_transition(t, q, mu, 1e2, c_prime, ROCK)[0]
            vertex = vl.radial_m_leak_off_vertex(t, q, mu, c_prime, ROCK)[0]
        error = np.abs(size / vertex - 1.0)
        assert error[0] > 0.0115 and abs(error[1] - 0.01) < 3e-4 and error[2] < 0.0085, (geometry, error)


# every embedded scene with a [reference]: the regime the scene claims, by the formula above
SCENE_REGIMES = {"radial-k": ("K", 4.0), "radial-m": ("M", None), "radial-km": ("transition", None),
                 "default": ("transition", None), "kgd": ("K", 4.0)}


def _scene_inputs(data):
    mat = Elastic(shear_modulus=data["material"]["shear_modulus"], poisson_ratio=data["material"]["poisson_ratio"])
    rate = data["cluster"][0]["rate"]
    if data["dimension"] == 2:
        rate /= data["height"]
    return mat, rate, data["fluid"]["viscosity"], data["propagation"]["toughness"]


# embedded scenes of a power-law fluid with a [reference] (issue 34): the regime they claim
POWER_LAW_SCENES = {"kgd-power-law": "M"}
# embedded scenes whose [reference] has no regime number: the equilibrium height (issue 38)
HEIGHT_SCENES = {"layered-height"}


def test_every_embedded_reference_scene_is_named():
    with_reference = {name for name in hs.embedded_names() if "reference" in hs.load_scene(name).data}
    assert with_reference == set(SCENE_REGIMES) | set(POWER_LAW_SCENES) | HEIGHT_SCENES


def independent_power_law_kgd_km(t, rate, consistency, n, toughness, mat):
    """K_m = K' / (E' eps L^(1/2)) of a power-law KGD fracture in Adachi and Detournay's
    (2002) M-scaling: M' = 2^(n+1) (2n+1)^n n^-n K, eps = (M' / (E' t^n))^(1/(n+2)),
    L = (E' Q^(n+2) t^(2n+2) / M')^(1/(2n+4)); 12 mu, Savitski's K_m at n = 1."""
    e_prime = mat.youngs_modulus / (1.0 - mat.poisson_ratio ** 2)
    m_prime = 2.0 ** (n + 1) * (2 * n + 1) ** n / n ** n * consistency
    eps = (m_prime / (e_prime * t ** n)) ** (1.0 / (n + 2))
    length = (e_prime * rate ** (n + 2) * t ** (2 * n + 2) / m_prime) ** (1.0 / (2 * n + 4))
    k_prime = np.sqrt(32.0 / np.pi) * toughness
    return k_prime / (e_prime * eps * np.sqrt(length))


@pytest.mark.parametrize("name", sorted(POWER_LAW_SCENES))
def test_regime_of_each_power_law_scene(name):
    data = hs.load_scene(name).data
    mat = Elastic(shear_modulus=data["material"]["shear_modulus"], poisson_ratio=data["material"]["poisson_ratio"])
    fluid, numerics = data["fluid"], data["numerics"]
    times = np.array([numerics["time_step"], numerics["end_time"]])
    expected = independent_power_law_kgd_km(times, data["cluster"][0]["rate"] / data["height"], fluid["consistency"],
                                            fluid["flow_index"], data["propagation"]["toughness"], mat)
    regime = hs.reference_regime(data, times)
    assert np.allclose(regime["values"], expected, rtol=1e-12)
    assert POWER_LAW_SCENES[name] == "M" and expected.max() <= 1.0 and regime["applies"]


@pytest.mark.parametrize("name", sorted(SCENE_REGIMES))
def test_regime_of_each_embedded_scene(name):
    data = hs.load_scene(name).data
    mat, rate, viscosity, toughness = _scene_inputs(data)
    numerics = data["numerics"]
    times = np.array([numerics["time_step"], numerics["end_time"]])
    if data["dimension"] == 3:
        expected = independent_radial_km(times, rate, viscosity, toughness, mat)
        low, high = 1.0, 3.5
    else:
        expected = np.full(2, independent_kgd_km(rate, viscosity, toughness, mat))
        low, high = 1.0, 4.0
    regime = hs.reference_regime(data, times)
    assert regime["number"] == "K_m" and np.allclose(regime["values"], expected, rtol=1e-12)
    claimed, at_least = SCENE_REGIMES[name]
    if claimed == "K":
        assert expected.min() >= at_least  # a true toughness-dominated scene, over the whole run
    elif claimed == "M":
        assert expected.max() <= low
    else:
        assert low < expected.min() and expected.max() < high
    assert regime["applies"] and hs.reference_warning(data) is None
    # the reference block records the number at each step and the solution compared with
    records = [dict(time=float(t), radius=1.0, half_length=1.0, max_opening=1e-3, wellbore_pressure=[9e6])
               for t in times]
    rows = hs.reference_values(data, records)
    assert [row["regime"]["value"] for row in rows] == pytest.approx(expected, rel=1e-12)
    assert all(row["solution"]["kind"] == data["reference"]["kind"] and row["solution"]["source"] for row in rows)
    if data["reference"]["kind"] == "radial-km":  # the K-vertex beside the transition solution, net pressure there only
        assert "net_pressure" not in rows[0]["relative_error"]
        assert set(rows[0]["k_vertex"]["relative_error"]) == {"radius", "max_opening", "net_pressure"}


def test_the_table_4_1_set_up_against_its_vertex_warns_and_names_the_transition():
    raw = hs.parse_scene(hs.embedded_text("radial-km")).data
    raw["reference"]["kind"] = "radial-k"
    line = hs.reference_warning(hs.scene_from_dict(raw).data)
    mat, rate, viscosity, toughness = _scene_inputs(raw)
    first, last = independent_radial_km(np.array([1.0, 50.0]), rate, viscosity, toughness, mat)
    assert "\n" not in line and "'radial-k'" in line and "radial-km (Dontsov 2016" in line
    assert f"K_m = {first:.2f} to {last:.2f}" in line


def test_a_transitional_kgd_warns_and_names_the_plane_strain_transition():
    raw = hs.parse_scene(hs.embedded_text("kgd")).data
    raw["propagation"]["toughness"] = 2e6  # K_m ~ 3.5
    line = hs.reference_warning(hs.scene_from_dict(raw).data)
    mat, rate, viscosity, toughness = _scene_inputs(raw)
    k_m = independent_kgd_km(rate, viscosity, toughness, mat)
    assert 1.0 < k_m < 4.0
    assert "'kgd-k'" in line and "Dontsov 2017" in line and f"K_m = {k_m:.2f} between" in line


def test_a_uniform_pressure_vertex_is_compared_with_the_mean_pressure_and_the_injection_beside():
    data = hs.load_scene("radial-k").data
    mat, rate, _, toughness = _scene_inputs(data)
    e_prime = 2.0 * mat.shear_modulus / (1.0 - mat.poisson_ratio)
    t = 20.0
    # K-vertex, written out: R from Q t = 16 p R^3 / (3 E') with p = pi^(1/2) K_Ic / (2 R^(1/2))
    radius = (3.0 * e_prime * rate * t / (8.0 * np.sqrt(np.pi) * toughness)) ** 0.4
    pressure = np.sqrt(np.pi) * toughness / (2.0 * np.sqrt(radius))
    confining = 8e6
    record = dict(time=t, radius=radius, max_opening=1e-3, mean_pressure=confining + 1.02 * pressure,
                  wellbore_pressure=[confining + 1.05 * pressure])
    (row,) = hs.reference_values(data, [record])
    assert row["relative_error"]["net_pressure"] == pytest.approx(0.02)
    assert row["relative_error"]["injection_net_pressure"] == pytest.approx(0.05)
    km = hs.load_scene("radial-km").data  # the K-vertex beside the transition: the same two pressures
    (row,) = hs.reference_values(km, [record])
    assert "net_pressure" not in row["relative_error"]
    vertex_pressure = np.sqrt(np.pi) * 5e6 / (2.0 * np.sqrt(row["k_vertex"]["radius"]))
    assert row["k_vertex"]["relative_error"]["net_pressure"] == pytest.approx(1.02 * pressure / vertex_pressure - 1)
    assert row["k_vertex"]["relative_error"]["injection_net_pressure"] == pytest.approx(
        1.05 * pressure / vertex_pressure - 1)
