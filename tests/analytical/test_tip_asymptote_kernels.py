"""The compiled inversions of the tip asymptote (hmatddm/analytical/tip_asymptote_kernels.py)
against the vectorised numpy bisection they replace, which still runs for a subclass that
changes ``residual`` (here one that only forwards it)."""
import numpy as np
import pytest

from hmatddm.analytical import tip_asymptote_kernels
from hmatddm.analytical.tip_asymptote import TipAsymptote, g_delta
from hmatddm.analytical.tip_leak_off import LeakOffTipAsymptote

E_PRIME, K_IC, MU_PRIME = 2.0e10, 1.0e6, 12.0 * 0.1


class NumpyTip(TipAsymptote):
    def residual(self, s, velocity, w):
        return super().residual(s, velocity, w)


class NumpyLeakOffTip(LeakOffTipAsymptote):
    def residual(self, s, velocity, w):
        return super().residual(s, velocity, w)


def _points(seed=3, n=400):
    rng = np.random.default_rng(seed)
    s = 10.0 ** rng.uniform(-6, 2, n)  # 1 um .. 100 m behind the front
    velocity = 10.0 ** rng.uniform(-8, 1, n)
    velocity[::7] = 0.0  # fronts at rest
    s[::11] = 0.0  # on the front
    return s, velocity


def test_g_delta_point_is_numpy_g_delta():
    rng = np.random.default_rng(0)
    k_hat = rng.uniform(0.0, 1.2, 300)
    c_hat = np.concatenate([np.zeros(100), 10.0 ** rng.uniform(-4, 5, 200)])  # through the series at C > 1e3
    compiled = np.array([tip_asymptote_kernels.g_delta_point(k, c) for k, c in zip(k_hat, c_hat)])
    # the closed form of f keeps ~eps 4 C^4 of it (below the series at C = 10: 1e-11)
    np.testing.assert_allclose(compiled, g_delta(k_hat, c_hat), rtol=1e-10, atol=1e-15)


@pytest.mark.parametrize("length", [np.inf, 30.0])
def test_width_matches_the_numpy_bisection(length):
    s, velocity = _points()
    compiled = TipAsymptote(E_PRIME, K_IC, MU_PRIME).width(s, velocity, length=length)
    reference = NumpyTip(E_PRIME, K_IC, MU_PRIME).width(s, velocity, length=length)
    assert np.all(np.isfinite(compiled))
    np.testing.assert_allclose(compiled, reference, rtol=1e-10, atol=0.0)
    assert np.all(compiled[s == 0.0] == 0.0)


@pytest.mark.parametrize("carter", [1e-6, 1e-4])
def test_leak_off_width_matches_the_numpy_bisection(carter):
    s, velocity = _points(seed=5)
    compiled = LeakOffTipAsymptote(E_PRIME, K_IC, MU_PRIME, carter).width(s, velocity, length=40.0)
    reference = NumpyLeakOffTip(E_PRIME, K_IC, MU_PRIME, carter).width(s, velocity, length=40.0)
    np.testing.assert_allclose(compiled, reference, rtol=1e-10, atol=0.0)


@pytest.mark.parametrize("kind", ["plain", "leak-off"])
@pytest.mark.parametrize("length", [np.inf, 25.0])
def test_front_distance_matches_the_numpy_bisection(kind, length):
    rng = np.random.default_rng(11)
    s_old = 10.0 ** rng.uniform(-3, 0.5, 300)
    w = 10.0 ** rng.uniform(-5, -2, 300)
    if kind == "plain":
        fast, slow = TipAsymptote(E_PRIME, K_IC, MU_PRIME), NumpyTip(E_PRIME, K_IC, MU_PRIME)
    else:
        fast, slow = LeakOffTipAsymptote(E_PRIME, K_IC, MU_PRIME, 1e-5), NumpyLeakOffTip(E_PRIME, K_IC, MU_PRIME, 1e-5)
    s_fast, v_fast = fast.front_distance(w, s_old, 0.5, length=length)
    s_slow, v_slow = slow.front_distance(w, s_old, 0.5, length=length)
    assert np.any(s_fast > s_old) and np.any(s_fast == s_old)  # fronts that move and fronts at rest
    np.testing.assert_allclose(s_fast, s_slow, rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(v_fast, v_slow, rtol=1e-8, atol=1e-12 * np.abs(v_slow).max())


def test_width_inverts_front_distance():
    """The two inversions agree with each other: the opening at the distance found is the
    opening given."""
    tip = TipAsymptote(E_PRIME, K_IC, MU_PRIME)
    s_old = np.linspace(0.05, 2.0, 40)
    w = 1.5 * tip.toughness_width(s_old + 0.3)
    s, v = tip.front_distance(w, s_old, 1.0, length=20.0)
    np.testing.assert_allclose(tip.width(s, v, length=20.0), w, rtol=1e-9)
