"""Inversion (ref. Sec. 7.3, 7.4.3): exact noise-free location, Brune's moment with the
true and the RMS factors, the source inversion of ref. Tables 7.3-7.4 with one and two
wells, what the amplitudes cannot determine, and seeded noise."""
import numpy as np
import pytest

from hmatddm.errors import InputError
from hmatddm.microseismic.forward import Well, observe, receivers_of
from hmatddm.microseismic.inversion import (brune_moment, dislocation_twins, invert_source, locate, location_error,
                                            orientation_error, reference_objective, spherical_angles,
                                            unit_moment_tensor, unresolved_direction)
from hmatddm.microseismic.noise import NoiseLevels, add_noise, rotate_horizontally
from hmatddm.microseismic.sources import Medium, moment_magnitude, point_sources

MEDIUM = Medium()
NORMAL = np.array([-1.0, 1.0, 0.0]) / np.sqrt(2)   # ref. Sec. 7.4.3: a vertical fracture at the origin
SLIP = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)      # pure shear, 1 mm on 4 m^2
POTENCY = 1e-3 * 4.0
ONE_WELL = [Well(50.0, 0.0)]                       # receivers every 5 m from -20 to 20 m
TWO_WELLS = [Well(50.0, 0.0), Well(50.0, -20.0)]


def _random_events(count, seed):
    rng = np.random.default_rng(seed)
    normals = rng.normal(size=(count, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    slips = np.cross(normals, rng.normal(size=(count, 3)))
    dd = 10 ** rng.uniform(-4, -2.5, size=(count, 1)) * slips / np.linalg.norm(slips, axis=1, keepdims=True)
    return point_sources(rng.uniform(-40, 40, size=(count, 3)) * [1, 1, 0.2], dd, normals, 1.0, MEDIUM)


def _table_source(wells):
    events = point_sources([0.0, 0.0, 0.0], 1e-3 * SLIP, NORMAL, 4.0, MEDIUM)
    receivers, well = receivers_of(wells)
    return events, receivers, observe(events, receivers, MEDIUM, well)


@pytest.mark.parametrize("wells", [[Well(50, 50)], [Well(50, 50), Well(50, -50)]])
def test_noise_free_location_is_exact(wells):
    events = _random_events(200, 1)
    receivers, well = receivers_of(wells)
    obs = observe(events, receivers, MEDIUM, well)
    located = locate(obs, MEDIUM)
    np.testing.assert_allclose(located, events.position, atol=1e-9)
    assert location_error(located, events.position) < 1e-9


def test_location_error_eq_7_30():
    true = np.zeros((4, 3))
    located = np.array([[3.0, 4.0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]])
    assert location_error(located, true) == pytest.approx(np.sqrt(25 / 4))


def test_brune_with_true_factors_is_exact_and_with_rms_factors_is_not():
    events = _random_events(300, 2)
    receivers, well = receivers_of([Well(50, 50)])
    obs = observe(events, receivers, MEDIUM, well)
    true_mw = moment_magnitude(events.seismic_moment)
    for wave in ("p", "s"):
        exact = moment_magnitude(brune_moment(obs, MEDIUM, wave, factors="true"))
        np.testing.assert_allclose(exact, true_mw, atol=1e-10)  # ref. Fig. 7.8
        rms = moment_magnitude(brune_moment(obs, MEDIUM, wave, factors="rms"))
        assert np.max(np.abs(rms - true_mw)) > 0.2  # ref. Fig. 7.7: off by tenths of a unit
    with pytest.raises(InputError, match="wave"):
        brune_moment(obs, MEDIUM, "q")


def test_two_wells_recover_orientation_and_moment_of_tables_7_3_7_4():
    _, receivers, obs = _table_source(TWO_WELLS)
    for constraint in ("general", "double-couple"):
        solution = invert_source([0, 0, 0], receivers, obs.amplitude_p[0], obs.amplitude_s[0], MEDIUM, seed=0,
                                 constraint=constraint)
        assert orientation_error(solution.normal, solution.slip_direction, NORMAL, SLIP) < 0.1
        assert solution.potency == pytest.approx(POTENCY, rel=0.01)
        assert solution.seismic_moment == pytest.approx(MEDIUM.shear_modulus * POTENCY, rel=0.01)
        assert solution.relative_misfit < 1e-6
        # both nodal planes are reported: the fitted pair is the truth or the truth swapped
        assert {tuple(np.round(np.abs(v), 6)) for v in solution.nodal_planes} == {tuple(np.round(np.abs(NORMAL), 6))}


def test_one_well_cannot_see_m_yy_and_leaves_twins_with_other_orientation_and_potency():
    events, receivers, obs = _table_source(ONE_WELL)
    # the source and the well lie in the plane y = 0: M_yy never enters the amplitudes
    t = unresolved_direction([0, 0, 0], receivers)
    np.testing.assert_allclose(np.abs(t), [0, 1, 0], atol=1e-12)
    assert unresolved_direction([0, 0, 0], receivers_of(TWO_WELLS)[0]) is None
    changed = point_sources([0, 0, 0], 1e-3 * SLIP, NORMAL, 4.0, MEDIUM)
    changed.moment_tensor[0, 1, 1] *= -7.0
    other = observe(changed, receivers, MEDIUM)
    np.testing.assert_allclose(other.amplitude_p, obs.amplitude_p, rtol=1e-12)
    np.testing.assert_allclose(other.amplitude_s, obs.amplitude_s, rtol=1e-12)
    # sources with a tensile part (nu.n = -(1 - 2 nu_Poisson)) and half or 2.11 times the
    # potency trade M_yy for another orientation: the same amplitudes at one well ...
    twins = dislocation_twins(events.moment_tensor[0], t, MEDIUM)
    ratios = sorted({round(potency / POTENCY, 6) for _, _, potency in twins})
    assert ratios == [0.5, pytest.approx(2.114531, abs=1e-6)]
    poisson = MEDIUM.poisson_ratio
    two_receivers, two_well = receivers_of(TWO_WELLS)
    truth_two = observe(events, two_receivers, MEDIUM, two_well)
    for normal, slip, potency in twins:
        assert abs(normal @ slip) == pytest.approx(1 - 2 * poisson, rel=1e-9)
        assert orientation_error(normal, slip, NORMAL, SLIP) > 45.0
        twin = point_sources([0, 0, 0], potency / 4.0 * slip, normal, 4.0, MEDIUM)
        seen = observe(twin, receivers, MEDIUM)
        np.testing.assert_allclose(seen.amplitude_p, obs.amplitude_p, rtol=1e-9, atol=1e-9 * obs.amplitude_p.max())
        np.testing.assert_allclose(seen.amplitude_s, obs.amplitude_s, rtol=1e-9, atol=1e-9 * obs.amplitude_s.max())
        # ... but not at the second well
        seen_two = observe(twin, two_receivers, MEDIUM, two_well)
        assert np.max(np.abs(seen_two.amplitude_s - truth_two.amplitude_s)) > 0.05 * truth_two.amplitude_s.max()
    # the global optimiser with one well lands on a source that fits exactly and whose
    # moment tensor equals the truth's (up to sign) except in M_yy
    solution = invert_source([0, 0, 0], receivers, obs.amplitude_p[0], obs.amplitude_s[0], MEDIUM, seed=0)
    assert solution.relative_misfit < 1e-3
    fitted, truth = solution.moment_tensor(MEDIUM), events.moment_tensor[0]
    sign = np.sign(np.sum(fitted * truth) - fitted[1, 1] * truth[1, 1])
    mask = np.ones((3, 3), bool)
    mask[1, 1] = False
    np.testing.assert_allclose(sign * fitted[mask], truth[mask], atol=2e-3 * np.abs(truth).max())
    # a double couple has no trace, which pins M_yy: one well suffices for a pure shear source
    solution = invert_source([0, 0, 0], receivers, obs.amplitude_p[0], obs.amplitude_s[0], MEDIUM, seed=0,
                             constraint="double-couple")
    assert orientation_error(solution.normal, solution.slip_direction, NORMAL, SLIP) < 0.1
    assert solution.potency == pytest.approx(POTENCY, rel=0.01)


def test_reference_objective_sees_only_the_potency_and_not_which_plane_slipped():
    _, receivers, obs = _table_source(TWO_WELLS)
    theta_f, phi_f = spherical_angles(NORMAL)
    theta_s, phi_s = spherical_angles(SLIP)
    args = ([0, 0, 0], receivers, obs.amplitude_p[0], obs.amplitude_s[0], MEDIUM)
    base = reference_objective([theta_f, phi_f, theta_s, phi_s, 1.3e-3, 2.0], *args)
    for scale in (0.1, 3.0, 250.0):  # slip and area trade freely: only d A enters (ref. Table 7.3)
        assert reference_objective([theta_f, phi_f, theta_s, phi_s, 1.3e-3 * scale, 2.0 / scale], *args) == \
            pytest.approx(base, rel=1e-12)
    swapped = reference_objective([theta_s, phi_s, theta_f, phi_f, 1.3e-3, 2.0], *args)
    assert swapped == pytest.approx(base, rel=1e-12)
    assert reference_objective([theta_f, phi_f, theta_s, phi_s, 1e-3, 4.0], *args) < 1e-30 * base + 1e-40
    np.testing.assert_allclose(unit_moment_tensor(NORMAL, SLIP, MEDIUM), unit_moment_tensor(SLIP, NORMAL, MEDIUM))


def test_noise_is_seeded_and_of_the_requested_size():
    events = _random_events(400, 3)
    receivers, well = receivers_of(TWO_WELLS)
    obs = observe(events, receivers, MEDIUM, well)
    levels = NoiseLevels(rotation_deg=10.0, travel_time=2e-3, amplitude_share=0.05)
    a, b = add_noise(obs, levels, seed=7), add_noise(obs, levels, seed=7)
    np.testing.assert_array_equal(a.direction, b.direction)
    np.testing.assert_array_equal(a.amplitude_s, b.amplitude_s)
    assert not np.array_equal(a.direction, add_noise(obs, levels, seed=8).direction)
    assert np.std(a.s_minus_p - obs.s_minus_p) == pytest.approx(2e-3, rel=0.05)
    np.testing.assert_allclose(np.linalg.norm(a.direction, axis=2), 1.0, atol=1e-12)
    np.testing.assert_allclose(a.direction[..., 2], obs.direction[..., 2])
    horizontal = np.arctan2(a.direction[..., 1], a.direction[..., 0]) - np.arctan2(obs.direction[..., 1],
                                                                                    obs.direction[..., 0])
    assert np.degrees(np.std(np.angle(np.exp(1j * horizontal)))) == pytest.approx(10.0, rel=0.05)
    share = (a.amplitude_p - obs.amplitude_p) / obs.amplitude_p.max(axis=1, keepdims=True)
    assert np.std(share) == pytest.approx(0.05, rel=0.05)
    np.testing.assert_array_equal(add_noise(obs, NoiseLevels(), seed=1).direction, obs.direction)
    np.testing.assert_allclose(rotate_horizontally(np.array([1.0, 0, 0]), np.pi / 2), [0, 1, 0], atol=1e-15)
    with pytest.raises(InputError, match="rotation_deg"):
        NoiseLevels(rotation_deg=-1.0)
    # location error grows with noise and shrinks with a second well (ref. Fig. 7.11)
    one = obs.receiver_subset(np.flatnonzero(well == 0))
    error_one = location_error(locate(add_noise(one, levels, 1), MEDIUM), events.position)
    error_two = location_error(locate(add_noise(obs, levels, 1), MEDIUM), events.position)
    assert 0.0 < error_two < error_one


def test_spread_over_noise_draws_is_seeded_and_noise_free_draws_are_exact():
    from hmatddm.microseismic.inversion import invert_source_draws

    _, _, obs = _table_source(TWO_WELLS)
    exact = invert_source_draws(obs, MEDIUM, NoiseLevels(), draws=1, seed=3)
    assert exact.orientation_errors(NORMAL, SLIP)[0] < 0.1 and exact.potency[0] == pytest.approx(POTENCY, rel=1e-6)
    noisy = NoiseLevels(amplitude_share=0.05)
    quick = dict(constraint="double-couple", restarts=1, popsize=10)
    first = invert_source_draws(obs, MEDIUM, noisy, draws=2, seed=3, **quick)
    again = invert_source_draws(obs, MEDIUM, noisy, draws=2, seed=3, **quick)
    np.testing.assert_array_equal(first.potency, again.potency)
    assert first.potency[0] != first.potency[1]  # two different draws
    assert np.all(np.abs(first.potency / POTENCY - 1) < 0.1)
    with pytest.raises(InputError, match="draws"):
        invert_source_draws(obs, MEDIUM, noisy, draws=0)
