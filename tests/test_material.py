import numpy as np
import pytest

import hmatddm as hd


def test_derived_moduli():
    m = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    assert m.youngs_modulus == pytest.approx(25e9)
    assert m.plane_strain_modulus == pytest.approx(25e9 / (1 - 0.0625))
    assert m.lame_lambda == pytest.approx(10e9)
    assert m.bulk_modulus == pytest.approx(25e9 / (3 * 0.5))


@pytest.mark.parametrize("kwargs, field", [
    (dict(shear_modulus=10e9, poisson_ratio=0.5), "poisson_ratio must be in [0, 0.5)"),
    (dict(shear_modulus=10e9, poisson_ratio=-0.1), "poisson_ratio must be in [0, 0.5)"),
    (dict(shear_modulus=0.0, poisson_ratio=0.2), "shear_modulus must be > 0"),
    (dict(shear_modulus=-1.0, poisson_ratio=0.2), "shear_modulus must be > 0"),
    (dict(shear_modulus=float("nan"), poisson_ratio=0.2), "shear_modulus must be a finite number"),
    (dict(shear_modulus=float("inf"), poisson_ratio=0.2), "shear_modulus must be a finite number"),
    (dict(shear_modulus="stiff", poisson_ratio=0.2), "shear_modulus must be a finite number"),
])
def test_bad_material_is_refused_with_the_field_named(kwargs, field):
    with pytest.raises(hd.InputError, match=field.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
        hd.Elastic(**kwargs)


def test_input_error_is_a_value_error():
    with pytest.raises(ValueError):
        hd.Elastic(shear_modulus=1.0, poisson_ratio=np.float64(0.7))
