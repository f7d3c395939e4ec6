"""The closed form of every image triple of a vertical rectangle, derived and checked in
``hmatddm/layered/_derive_closed_form3d.py`` (issue 32, item 1; not yet the operator's
path): the primitive K of F, each term of the stress against the quadrature, and whole
image entries against :func:`hmatddm.layered.rectangle_quadrature.image_rectangle_stress`
on both sides of interfaces between solids."""
import numpy as np
import pytest

from hmatddm.layered import _derive_closed_form3d as derive


def test_k_is_a_vertical_primitive_of_f_with_the_horizontal_derivatives_used():
    pytest.importorskip("sympy")
    assert derive.k_primitive_identities() == [0, 0, 0]


def test_each_stress_term_of_a_vertical_rectangle_by_parts_is_the_quadrature():
    """Random terms ``P(t) d1^a d2^b d3^c B`` of the degrees the stress has, reflection
    and transmission geometries, both branches of ``log(r +- r1)``."""
    assert derive.check_vertical_terms(n_terms=60, seed=2) <= 1e-11


def test_a_term_with_deg_p_above_c_is_refused():
    with pytest.raises(ValueError, match="deg P > c"):
        derive.vertical_term(np.array([0.0, 0.5, -2.0]), 0.0, 0.0, 0.3, -1.6, -1.1, 0.0, -1.0, -1.0, 0, 1, 0, 1,
                             [0.0, 0.0, 1.0])


def test_vertical_rectangle_entries_in_closed_form_are_the_quadrature():
    """Every triple (reflections in interfaces between solids, transmissions), receivers
    in the source's layer and across the interface, the square 0.25 m from it."""
    found = derive.check_vertical_rectangles()
    assert found["bi-material"] <= 1e-12
    assert found["surface + 2 interfaces"] <= 1e-12
