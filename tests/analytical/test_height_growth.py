"""The equilibrium height of a symmetric three-layer stack (Simonson et al. 1978, issue 38):
its stress intensity against the weight-function integral by quadrature, its root."""
import numpy as np
import pytest
from scipy.integrate import quad

from hmatddm.analytical.height_growth import equilibrium_height, three_layer_stress_intensity
from hmatddm.errors import InputError


def weight_function_k(a, net_pressure, contrast, thickness):
    """K_I = int_{-a}^{a} q(y) sqrt((a + y)/(a - y)) dy / sqrt(pi a), q = p_net - d_sigma outside
    the pay zone, by quadrature (written apart from the closed form)."""
    def load(y):
        return net_pressure - (contrast if abs(y) > thickness / 2 else 0.0)

    # y = a sin(theta) removes the end singularity: sqrt((a+y)/(a-y)) dy = a (1 + sin) d theta
    points = [np.arcsin(min(1.0, thickness / (2 * a))), -np.arcsin(min(1.0, thickness / (2 * a)))]
    value, _ = quad(lambda t: load(a * np.sin(t)) * a * (1.0 + np.sin(t)), -np.pi / 2, np.pi / 2,
                    points=points, limit=200)
    return value / np.sqrt(np.pi * a)


@pytest.mark.parametrize("a", [1.0, 3.0, 4.5, 9.0])
def test_the_stress_intensity_is_the_weight_function_integral(a):
    exact = weight_function_k(a, 0.4e6, 0.5e6, 6.0)
    assert three_layer_stress_intensity(a, 0.4e6, 0.5e6, 6.0) == pytest.approx(exact, rel=1e-8)


def test_the_equilibrium_height_is_the_falling_root():
    height = equilibrium_height(0.4e6, 0.5e6, 6.0, 0.5e6)
    assert height > 6.0
    assert weight_function_k(height / 2, 0.4e6, 0.5e6, 6.0) == pytest.approx(0.5e6, rel=1e-7)
    # stable: a little taller is below the toughness, a little shorter above
    assert weight_function_k(0.51 * height, 0.4e6, 0.5e6, 6.0) < 0.5e6 < weight_function_k(0.49 * height, 0.4e6,
                                                                                            0.5e6, 6.0)
    # more pressure, taller; no equilibrium at or above the contrast; none below the toughness' reach
    assert equilibrium_height(0.45e6, 0.5e6, 6.0, 0.5e6) > height
    assert equilibrium_height(0.5e6, 0.5e6, 6.0, 0.5e6) == np.inf
    assert np.isnan(equilibrium_height(0.1e6, 0.5e6, 6.0, 5e6)) and np.isnan(equilibrium_height(-1.0, 0.5e6, 6, 1))
    with pytest.raises(InputError, match="stress_contrast"):
        equilibrium_height(0.4e6, 0.0, 6.0, 0.5e6)
