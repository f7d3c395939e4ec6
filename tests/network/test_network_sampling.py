"""Sampling laws of a synthetic network (ref. Sec. 6.2): power-law lengths (Eqs 6.1-6.7)
and von Mises strikes (Eqs 6.8-6.10), recovered by maximum likelihood and moments."""
import numpy as np
import pytest
from scipy import optimize, special, stats

import hmatddm as hd
from hmatddm import network as nw


def _power_law_mle(lengths, l_min, l_max):
    """Maximum-likelihood exponent of the truncated power law Eq. 6.4."""
    log_sum = np.log(lengths).sum()
    n = len(lengths)

    def negative_log_likelihood(a):
        b = a - 1.0
        return -(n * np.log(b) - a * log_sum - n * np.log(l_min ** -b - l_max ** -b))

    return optimize.minimize_scalar(negative_log_likelihood, bounds=(1.0001, 8.0), method="bounded",
                                    options={"xatol": 1e-8}).x


def _axial_mean_and_kappa(azimuths):
    """Mean strike and concentration of axial data by angle doubling (ref. Sec. 6.2.2)."""
    doubled = 2.0 * azimuths
    c, s = np.cos(doubled).mean(), np.sin(doubled).mean()
    mean = np.mod(0.5 * np.arctan2(s, c), np.pi)
    resultant = np.hypot(c, s)
    kappa = optimize.brentq(lambda k: special.i1e(k) / special.i0e(k) - resultant, 1e-9, 1e4)
    return mean, kappa


def _axial_difference(a, b):
    d = np.mod(a - b, np.pi)
    return min(d, np.pi - d)


# ----------------------------------------------------------------------------- lengths

@pytest.mark.parametrize("exponent", [2.0, 2.5, 3.0])
def test_power_law_exponent_recovered_by_maximum_likelihood(exponent):
    lengths = nw.power_law_lengths(20000, exponent, 1.0, 30.0, np.random.default_rng(7))
    assert lengths.min() >= 1.0 and lengths.max() <= 30.0
    assert abs(_power_law_mle(lengths, 1.0, 30.0) - exponent) / exponent < 0.03


def test_power_law_matches_the_cumulative_distribution_eq_6_5():
    a, l0, l1 = 2.0, 1.0, 30.0
    b = a - 1.0
    lengths = nw.power_law_lengths(20000, a, l0, l1, 3)
    cdf = lambda l: (l0 ** -b - l ** -b) / (l0 ** -b - l1 ** -b)  # noqa: E731
    assert stats.kstest(lengths, cdf).pvalue > 1e-3


def test_power_law_exponent_one_is_log_uniform_and_continuous():
    lengths = nw.power_law_lengths(20000, 1.0, 1.0, 30.0, 11)
    cdf = lambda l: np.log(l) / np.log(30.0)  # noqa: E731
    assert stats.kstest(lengths, cdf).pvalue > 1e-3
    # a -> 1 continuously: the same uniforms give nearly the same lengths
    near = nw.power_law_lengths(1000, 1.0 + 1e-10, 1.0, 30.0, 5)
    exact = nw.power_law_lengths(1000, 1.0, 1.0, 30.0, 5)
    assert np.allclose(near, exact, rtol=1e-8)


def test_power_law_without_upper_limit_eq_6_7():
    a = 2.5
    lengths = nw.power_law_lengths(20000, a, 2.0, np.inf, 9)
    assert lengths.min() >= 2.0 and np.all(np.isfinite(lengths))
    estimate = 1.0 + len(lengths) / np.log(lengths / 2.0).sum()  # Pareto MLE
    assert abs(estimate - a) / a < 0.03


def test_power_law_constant_and_empty():
    assert np.all(nw.power_law_lengths(5, 2.0, 3.0, 3.0, 0) == 3.0)
    assert nw.power_law_lengths(0, 2.0, 1.0, 3.0, 0).shape == (0,)


@pytest.mark.parametrize("kwargs, field", [
    (dict(exponent=0.5), "exponent"),
    (dict(l_min=0.0), "l_min"),
    (dict(l_max=0.5), "l_max"),
    (dict(exponent=1.0, l_max=np.inf), "l_max"),
    (dict(n=-1), "n"),
    (dict(n=2.5), "n"),
])
def test_power_law_rejects_bad_input(kwargs, field):
    args = dict(n=10, exponent=2.0, l_min=1.0, l_max=30.0) | kwargs
    with pytest.raises(hd.InputError, match=field):
        nw.power_law_lengths(**args, rng=0)


# ----------------------------------------------------------------------------- orientations

@pytest.mark.parametrize("mean_deg, kappa", [(45.0, 5.0), (170.0, 2.0), (90.0, 20.0)])
def test_von_mises_axial_mean_and_kappa_recovered(mean_deg, kappa):
    azimuths = nw.von_mises_directions(20000, np.radians(mean_deg), kappa, np.random.default_rng(1))
    assert azimuths.min() >= 0.0 and azimuths.max() < np.pi
    mean, kappa_hat = _axial_mean_and_kappa(azimuths)
    assert _axial_difference(mean, np.radians(mean_deg)) < np.radians(1.0)
    assert abs(kappa_hat - kappa) / kappa < 0.05


def test_von_mises_doubled_angle_follows_eq_6_8():
    kappa = 5.0
    azimuths = nw.von_mises_directions(20000, np.pi / 4, kappa, 2)
    doubled = 2.0 * azimuths  # theta' in [0, 2 pi), mean mu' = pi/2 (ref. Fig. 6.3)
    assert stats.kstest(doubled, stats.vonmises(kappa, loc=np.pi / 2).cdf).pvalue > 1e-3


def test_von_mises_kappa_zero_is_uniform():
    azimuths = nw.von_mises_directions(20000, 0.3, 0.0, 4)
    assert stats.kstest(azimuths, stats.uniform(0, np.pi).cdf).pvalue > 1e-3


def test_bimodal_weights_means_and_kappas_recovered():
    means = np.radians([45.0, 120.0])  # the reference's Fig. 6.4 mixture
    kappas, weights = (5.0, 3.0), (0.7, 0.3)
    azimuths, modes = nw.bimodal_directions(20000, means, kappas, weights, np.random.default_rng(8),
                                            return_modes=True)
    fraction = np.mean(modes == 0)
    assert abs(fraction - 0.7) < 3 * np.sqrt(0.7 * 0.3 / 20000)
    for k in range(2):
        mean, kappa_hat = _axial_mean_and_kappa(azimuths[modes == k])
        assert _axial_difference(mean, means[k]) < np.radians(1.5)
        assert abs(kappa_hat - kappas[k]) / kappas[k] < 0.07
    # without the labels: the mixture density Eq. 6.10 fits the doubled angles
    grid = np.linspace(0.0, 2 * np.pi, 20001)
    density = sum(w * np.exp(k * np.cos(grid - 2 * m)) / (2 * np.pi * special.i0(k))  # Eqs. 6.8, 6.10
                  for w, k, m in zip(weights, kappas, means))
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(grid))])
    assert abs(cumulative[-1] - 1.0) < 1e-9
    assert stats.kstest(2.0 * azimuths, lambda x: np.interp(x, grid, cumulative)).pvalue > 1e-3


@pytest.mark.parametrize("kwargs, field", [
    (dict(kappas=(-1.0, 2.0)), "kappas"),
    (dict(weights=(0.7, 0.7)), "weights"),
    (dict(weights=(1.2, -0.2)), "weights"),
    (dict(means=(0.1,)), "same length"),
])
def test_bimodal_rejects_bad_input(kwargs, field):
    args = dict(means=(0.1, 1.0), kappas=(1.0, 2.0), weights=(0.5, 0.5)) | kwargs
    with pytest.raises(hd.InputError, match=field):
        nw.bimodal_directions(10, **args, rng=0)
