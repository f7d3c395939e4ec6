"""The shared wellbore of issue 35 (hmatddm.flow.well) without elasticity: the split of the
pump rate among parallel orifices against closed forms, the linearisation's fixed point,
the Darcy-Weisbach friction between clusters, the pump schedule's exact volume, bad input."""
import math

import numpy as np
import pytest
import scipy.integrate
import scipy.optimize

from hmatddm.errors import InputError
from hmatddm.flow import Cluster
from hmatddm.flow.well import PumpRate, Well, WellSystem, perforation_coefficient

RHO = 1000.0


def orifice(n, d, cd=0.6):
    """a of dp = a q^2, written out: dp = rho q^2 / (2 (Cd A)^2), A = n pi d^2 / 4."""
    area = n * math.pi * d * d / 4.0
    return RHO / (2.0 * (cd * area) ** 2)


def test_the_perforation_coefficient_is_the_orifice_law():
    for n, d, cd in [(1, 0.01, 0.6), (6, 0.012, 0.85), (20, 0.008, 0.5)]:
        assert perforation_coefficient(RHO, n, d, cd) == pytest.approx(orifice(n, d, cd), rel=1e-14)


def test_parallel_orifices_with_equal_downstream_pressures_split_as_their_effective_areas():
    """q_c = Q n_c d_c^2 C_c / sum_j n_j d_j^2 C_j (equal drop over every orifice)."""
    counts, diameters = np.array([3, 6, 4, 8]), np.array([0.01, 0.012, 0.009, 0.011])
    cds = np.array([0.6, 0.7, 0.8, 0.9])
    a = np.array([orifice(n, d, c) for n, d, c in zip(counts, diameters, cds)])
    system = WellSystem(a, np.arange(4.0), 0.0, 0.0)
    q_pump = 0.08
    pressure = np.full(4, 30e6)
    p_h, rates, friction = system.solve(pressure, q_pump, 0.0, 0.0)
    weights = counts * diameters**2 * cds
    expected = q_pump * weights / np.sum(weights)
    np.testing.assert_allclose(rates, expected, rtol=1e-10, atol=0)
    np.testing.assert_allclose(p_h, 30e6 + a * expected**2, rtol=1e-14)
    assert np.all(friction == 0.0)


def test_identical_clusters_take_identical_rates():
    a = np.full(5, orifice(6, 0.01))
    system = WellSystem(a, np.arange(5.0) * 10.0, 0.0, 2.0)
    _, rates, _ = system.solve(np.full(5, 20e6), 0.1, 1e-9, 20e6)
    np.testing.assert_allclose(rates, np.full(5, rates[0]), rtol=1e-14)


def test_two_orifices_with_different_downstream_pressures_match_the_quadratic():
    """a1 x^2 + p1 = a2 (Q - x)^2 + p2 for the first orifice's rate x (both positive)."""
    a1, a2 = orifice(4, 0.01), orifice(8, 0.01)
    p1, p2, q = 20.0e6, 20.3e6, 0.05
    x = np.roots([a1 - a2, 2.0 * a2 * q, -a2 * q * q + p1 - p2])
    x = float(x[(x > 0) & (x < q)][0].real)
    system = WellSystem(np.array([a1, a2]), np.array([0.0, 10.0]), 0.0, 0.0)
    p_h, rates, _ = system.solve(np.array([p1, p2]), q, 0.0, 0.0)
    np.testing.assert_allclose(rates, [x, q - x], rtol=1e-10)
    assert p_h == pytest.approx(p1 + a1 * x * x, rel=1e-13)


def test_the_well_balance_holds_with_storage_and_backflow():
    """sum q + S (p_h - p_h^n) = Qbar to round-off; a high old heel pressure and no pumping
    push fluid out of the well into the fractures, a low one draws fluid back (the
    clusters may cross-flow)."""
    a = np.array([orifice(4, 0.01), orifice(6, 0.01), orifice(5, 0.012)])
    system = WellSystem(a, np.array([0.0, 5.0, 10.0]), 0.0, 1.0)
    pressure = np.array([10e6, 10.2e6, 9.9e6])
    for q_pump, storage, old in [(0.05, 1e-8, 10.5e6), (0.0, 1e-8, 12e6), (0.0, 1e-8, 9e6)]:
        p_h, rates, _ = system.solve(pressure, q_pump, storage, old)
        assert np.sum(rates) + storage * (p_h - old) == pytest.approx(q_pump, abs=1e-14 * (1 + abs(storage * old)))
        np.testing.assert_allclose(system.perforation_friction(rates), p_h - pressure, rtol=1e-9)
    assert np.sum(system.solve(pressure, 0.0, 1e-8, 9e6)[1]) < 0.0  # backflow
    assert np.all(system.solve(pressure, 0.0, 1e-8, 12e6)[1] > 0.0)


def test_the_linearisation_passes_through_the_exact_well_and_its_matrix_is_the_injection():
    a = np.array([orifice(4, 0.01), orifice(6, 0.01), orifice(5, 0.012)])
    system = WellSystem(a, np.array([0.0, 5.0, 10.0]), pipe_b(0.1, 0.1), 0.8)
    pressure = np.array([10e6, 10.2e6, 9.9e6])
    p_h, rates, friction = system.solve(pressure, 0.06, 1e-9, 10.4e6)
    lin = system.linearise(pressure, 0.06, 1e-9, 10.4e6, rate_floor=1e-6)
    assert lin.heel_pressure(pressure) == pytest.approx(p_h, rel=1e-14)
    np.testing.assert_allclose(lin.rates(pressure), rates, rtol=1e-10)
    np.testing.assert_allclose(lin.friction, friction, rtol=1e-14)
    elements = np.array([4, 1, 7])
    matrix, rhs = lin.matrix_terms(elements, 9)
    assert abs(matrix - matrix.T).max() == 0.0
    field = np.random.default_rng(0).uniform(9.5e6, 10.5e6, 9)
    injection = rhs - matrix @ field
    expected = np.zeros(9)
    expected[elements] = lin.rates(field[elements])
    np.testing.assert_allclose(injection, expected, rtol=1e-9, atol=1e-12)
    # the rates of any pressures satisfy the well's balance with the linearised heel pressure
    p = field[elements]
    assert np.sum(lin.rates(p)) + 1e-9 * (lin.heel_pressure(p) - 10.4e6) == pytest.approx(0.06, rel=1e-12)


def test_iterating_the_linearisation_with_fracture_storage_converges_to_the_exact_split():
    """Clusters feeding tanks of compliance c_e (c_e (p_e - p_e^n) = q_e dt): the fixed point of
    linear solves with the well linearised at the last iterate is the nonlinear solution
    (solved apart by scipy.optimize.fsolve on the unknowns q_c and p_h)."""
    a = np.array([orifice(3, 0.01), orifice(6, 0.01), orifice(9, 0.01)])
    system = WellSystem(a, np.array([0.0, 5.0, 10.0]), pipe_b(0.05, 0.08), 0.5)
    compliance = np.array([1e-9, 3e-9, 2e-9])  # m^3/Pa
    p_old = np.array([20e6, 20.1e6, 19.9e6])
    dt, q_pump, storage, heel_old = 10.0, 0.04, 1e-9 * 0.5 / 10.0, 20.2e6

    def residual(x):
        q, p_h = x[:3], x[3]
        p = p_old + q * dt / compliance
        w = system.wellbore_friction(q)
        return np.concatenate([a * q * np.abs(q) - (p_h - w - p), [np.sum(q) + storage * (p_h - heel_old) - q_pump]])

    exact = scipy.optimize.fsolve(residual, np.concatenate([np.full(3, q_pump / 3), [heel_old]]), xtol=1e-14)
    p = p_old.copy()
    elements = np.arange(3)
    for _ in range(60):
        lin = system.linearise(p, q_pump, storage, heel_old, rate_floor=1e-6)
        matrix, rhs = lin.matrix_terms(elements, 3)
        p = np.linalg.solve(np.diag(compliance / dt) + matrix.toarray(), compliance / dt * p_old + rhs)
    np.testing.assert_allclose(lin.rates(p), exact[:3], rtol=1e-8)
    assert lin.heel_pressure(p) == pytest.approx(exact[3], rel=1e-12)


def pipe_b(friction_factor, diameter):
    return 8.0 * friction_factor * RHO / (math.pi**2 * diameter**5)


def test_the_wellbore_friction_is_darcy_weisbach_segment_by_segment():
    """dp = f (L / D) rho v^2 / 2 over each segment, v the mean velocity of the rate it carries."""
    f, diameter = 0.02, 0.1
    area = math.pi * diameter**2 / 4.0
    depths = np.array([30.0, 10.0, 20.0])  # clusters listed out of order along the well
    rates = np.array([0.01, 0.03, 0.02])
    system = WellSystem(np.full(3, 1e9), depths, pipe_b(f, diameter), 0.0)

    def loss(length, q):
        v = q / area
        return f * length / diameter * RHO * v * v / 2.0

    first = loss(10.0, 0.06)        # heel -> 10 m: all three
    second = first + loss(10.0, 0.03)  # 10 -> 20 m: the clusters at 20 and 30 m
    third = second + loss(10.0, 0.01)  # 20 -> 30 m
    np.testing.assert_allclose(system.wellbore_friction(rates), [third, first, second], rtol=1e-13)


def test_the_pump_schedule_volume_is_exact():
    constant = PumpRate((0.0, 10.0, 25.0), (0.02, 0.05, 0.01))
    linear = PumpRate((5.0, 10.0, 25.0), (0.02, 0.05, 0.01), interpolation="linear")
    for schedule in (constant, linear):
        for t0, t1 in [(0.0, 3.0), (2.0, 12.5), (9.0, 40.0), (26.0, 30.0)]:
            points = [t for t in schedule.times if t0 < t < t1]
            numeric = scipy.integrate.quad(schedule.rate, t0, t1, points=points or None, epsabs=1e-14,
                                           epsrel=1e-13)[0]
            assert schedule.volume(t0, t1) == pytest.approx(numeric, rel=1e-11, abs=1e-15)
    assert constant.rate(12.0) == 0.05 and linear.rate(17.5) == pytest.approx(0.03) and linear.rate(1.0) == 0.0


def well(**overrides):
    arguments = dict(schedule=PumpRate((0.0,), (0.05,)), heel=(0.0, 0.0), direction=(1.0, 0.0))
    arguments.update(overrides)
    return Well(**arguments)


def perforated(x, **overrides):
    arguments = dict(perforations=6, perforation_diameter=0.01)
    arguments.update(overrides)
    return Cluster((x, 0.0), **arguments)


@pytest.mark.parametrize("build, field", [
    (lambda: PumpRate((0.0, 10.0, 5.0), (0.1, 0.1, 0.1)), "well.schedule[2] time"),
    (lambda: PumpRate((0.0, 10.0), (0.1, -0.1)), "well.schedule[1] rate"),
    (lambda: PumpRate((0.0,), (0.1,), interpolation="cubic"), "well.interpolation"),
    (lambda: perforated(0.0, perforations=0), "cluster.perforations"),
    (lambda: perforated(0.0, perforations=-3), "cluster.perforations"),
    (lambda: perforated(0.0, perforation_diameter=0.0), "cluster.perforation_diameter"),
    (lambda: perforated(0.0, perforation_diameter=-0.01), "cluster.perforation_diameter"),
    (lambda: perforated(0.0, discharge_coefficient=0.0), "cluster.discharge_coefficient"),
    (lambda: perforated(0.0, discharge_coefficient=1.2), "cluster.discharge_coefficient"),
    (lambda: Cluster((0.0, 0.0), perforations=6), "cluster.perforation_diameter"),
    (lambda: well(friction_factor=0.02), "well.diameter"),
    (lambda: well(volume=-1.0), "well.volume"),
    (lambda: well(direction=(0.0, 0.0)), "well.direction"),
    (lambda: well().system([perforated(0.0), Cluster((5.0, 0.3), perforations=6, perforation_diameter=0.01)]),
     "cluster[1].position"),
    (lambda: well().system([perforated(-5.0)]), "cluster[0].position"),
    (lambda: well().system([perforated(0.0), Cluster((5.0, 0.0))]), "cluster[1].perforations"),
    (lambda: well().system([Cluster((5.0, 0.0), rate=0.01)]), "cluster[0].rate"),
    (lambda: well().system([perforated(5.0, wellbore_volume=1.0)]), "cluster[0].wellbore_volume"),
])
def test_bad_input_names_the_field(build, field):
    with pytest.raises(InputError, match=field.replace("[", r"\[").replace("]", r"\]")):
        build()


def test_a_cluster_is_on_the_well_within_a_millimetre():
    system = well(direction=(2.0, 0.0)).system([perforated(0.0), Cluster((5.0, 0.0005), perforations=6,
                                                                           perforation_diameter=0.01)])
    np.testing.assert_allclose(system.depths, [0.0, 5.0])
    assert not system.direct
    assert well().system([Cluster((3.0, 0.0))]).direct


def test_strong_wellbore_friction_and_a_stopped_cluster_match_the_full_system():
    """Wellbore friction as large as the perforation friction, and a cluster whose fracture
    pressure stops its flow: the exact state against scipy.optimize.fsolve on (q, p_h)."""
    a = np.array([orifice(24, 0.008)] * 4)
    b = pipe_b(0.02, 0.1)
    system = WellSystem(a, np.array([40.0, 50.0, 60.0, 70.0]), b, 10.0)
    for pressure in (np.array([37.0e6, 37.002e6, 37.0e6, 37.001e6]), np.array([37.0e6, 37.3e6, 37.0e6, 37.0e6])):
        p_h, rates, friction = system.solve(pressure, 0.016, 4.4e-10 * 10.0 / 2.0, 37.0e6)

        def residual(x):
            q, heel = x[:4] * 1e-3, x[4] * 1e6
            w = system.wellbore_friction(q)
            return np.concatenate([(a * q * np.abs(q) + w + pressure - heel) / 1e3,
                                   [(np.sum(q) + 2.2e-9 * (heel - 37.0e6) - 0.016) * 1e3]])

        exact = scipy.optimize.fsolve(residual, np.array([4.0, 4.0, 4.0, 4.0, 37.1]), xtol=1e-14)
        np.testing.assert_allclose(rates, exact[:4] * 1e-3, rtol=1e-7, atol=1e-12)
        assert p_h == pytest.approx(exact[4] * 1e6, rel=1e-13)
        np.testing.assert_allclose(a * rates * np.abs(rates) + friction, p_h - pressure, rtol=1e-9, atol=1e-6)
    assert rates[1] < 0.0  # the high-pressure cluster flows back into the well
