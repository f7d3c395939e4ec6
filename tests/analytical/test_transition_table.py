"""The radial K-M transition tabulated in time (hmatddm.analytical.transition_table) against
the direct solution it interpolates, over the transition and towards both vertices."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.analytical import (RadialTransitionTable, radial_transition, radial_transition_profile,
                                radial_transition_table)

ROCK = hd.Elastic(24e9, 0.25)
PARAMETERS = (0.01, 1e-3, 5e6, ROCK)  # the default scene: K_m 1.8-2.9 over 1-50 s


@pytest.mark.parametrize("viscosity, toughness", [(1e-3, 5e6), (1.0, 0.2e6), (1e-4, 11e6)])
def test_the_table_is_the_direct_solution_to_1e_7(viscosity, toughness):
    """Transition, near the M vertex (K_m < 1) and near the K vertex (K_m > 4)."""
    table = RadialTransitionTable(0.01, viscosity, toughness, ROCK)
    times = np.geomspace(0.3, 300.0, 37)  # between the nodes and over three decades
    radius, width = table.radius_and_width(times)
    direct_radius, direct_width = radial_transition(times, 0.01, viscosity, toughness, ROCK)
    assert np.max(np.abs(radius / direct_radius - 1.0)) < 1e-7
    assert np.max(np.abs(width / direct_width - 1.0)) < 1e-7
    rho = np.linspace(0.0, 1.0, 11)
    r, w = table.profile(rho, 7.3)
    r_direct, w_direct = radial_transition_profile(rho, 7.3, 0.01, viscosity, toughness, ROCK)
    assert r == pytest.approx(r_direct, rel=1e-7) and np.allclose(w, w_direct, rtol=1e-7, atol=0.0)


def test_a_run_asking_step_by_step_solves_about_once_a_decade():
    table = RadialTransitionTable(*PARAMETERS)
    for end in range(1, 101):  # what summary.json asks after each of 100 steps of 1 s
        table.radius_and_width(np.arange(1.0, end + 1.0))
    assert table.solves <= 3  # 1-10 s, then 10-100 s (and the margin), not 100
    table.radius_and_width(np.array([1e-3]))  # earlier than the grid: extends it downwards
    assert table.solves <= 4
    assert radial_transition_table(*PARAMETERS) is radial_transition_table(*PARAMETERS)
    assert radial_transition_table(0.02, 1e-3, 5e6, ROCK) is not radial_transition_table(*PARAMETERS)


def test_bad_times_and_positions_are_refused():
    table = RadialTransitionTable(*PARAMETERS)
    with pytest.raises(hd.InputError, match="t must be > 0"):
        table.radius_and_width(np.array([1.0, 0.0]))
    with pytest.raises(hd.InputError, match="rho must be in"):
        table.profile(np.array([1.2]), 1.0)
    with pytest.raises(hd.InputError, match="nodes_per_decade"):
        RadialTransitionTable(*PARAMETERS, nodes_per_decade=2)
    with pytest.raises(hd.InputError, match="injection_rate"):
        RadialTransitionTable(-1.0, 1e-3, 5e6, ROCK)
