"""The tip asymptote with Carter leak-off (Dontsov and Peirce 2015) against its limits."""
import numpy as np
import pytest

from hmatddm.analytical.tip_asymptote import TipAsymptote
from hmatddm.analytical.tip_leak_off import LeakOffTipAsymptote

E, MU = 2.67e9, 12 * 0.02
S = np.geomspace(1e-6, 10.0, 9)


def test_without_leak_off_it_is_the_parent():
    np.testing.assert_allclose(LeakOffTipAsymptote(E, 1e5, MU, carter=0.0).width(S, 0.1),
                               TipAsymptote(E, 1e5, MU).width(S, 0.1), rtol=1e-9)


def test_leak_off_widens_and_a_front_at_rest_is_the_toughness_asymptote():
    leaky = LeakOffTipAsymptote(E, 1e5, MU, carter=1e-3)
    assert np.all(leaky.width(S, 0.1) > TipAsymptote(E, 1e5, MU).width(S, 0.1))
    np.testing.assert_allclose(leaky.width(S, 0.0), leaky.toughness_width(S), rtol=1e-9)


def test_leak_off_vertex_near_the_front():
    """m~ limit: w = beta_m~ (4 mu'^2 C'^2 V / E'^2)^(1/8) s^(5/8) with beta_m~ = 4 / (15^(1/4)
    (2^(1/2) - 1)^(1/4)) (Garagash, Detournay and Adachi 2011); the closed form of g_delta
    holds it to about 1 %."""
    carter, velocity = 1e-3, 0.1
    beta = 4.0 / (15.0**0.25 * (np.sqrt(2.0) - 1.0) ** 0.25)
    s = np.array([1e-9, 1e-8])
    expected = beta * (4 * MU**2 * carter**2 * velocity / E**2) ** 0.125 * s**0.625
    got = LeakOffTipAsymptote(E, 1.0, MU, carter=carter).width(s, velocity)
    np.testing.assert_allclose(got, expected, rtol=0.015)
