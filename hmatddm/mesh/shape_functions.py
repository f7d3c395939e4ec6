"""Shape functions of 2D displacement-discontinuity elements (ref. App. B, eqs 43-48).

The intrinsic coordinate ``xi`` runs from -1 to 1 along an element (from ``p0`` to
``p1``). An element of order ``p`` carries ``p + 1`` nodes placed *inside* the element
(Crawford & Curran 1982, the reference's choice), where it is also collocated:

* order 0 (constant): ``xi = 0``, ``N_1 = 1``;
* order 1 (linear): ``xi = -1/sqrt(2), +1/sqrt(2)``, ``N_{1,2} = 1/2 -+ xi/sqrt(2)``
  (ref. eqs 44-45; the reference prints ``-1/sqrt(2)`` for both nodes, the second is
  ``+1/sqrt(2)`` since ``N_2`` is 1 there);
* order 2 (quadratic): ``xi = -sqrt(3)/2, 0, +sqrt(3)/2``,
  ``N_{1,3} = -+xi/sqrt(3) + 2 xi^2/3``, ``N_2 = 1 - 4 xi^2/3`` (ref. eqs 46-48).

The DD along element ``e`` is ``D(xi) = sum_k N_k(xi) D[e, k]`` (global frame).
"""
import math

import numpy as np

from .._validation import finite_array
from ..settings import integer

ELEMENT_ORDERS = (0, 1, 2)

_NODES = {
    0: np.array([0.0]),
    1: np.array([-1.0 / math.sqrt(2.0), 1.0 / math.sqrt(2.0)]),
    2: np.array([-math.sqrt(3.0) / 2.0, 0.0, math.sqrt(3.0) / 2.0]),
}

# N_k(xi) = sum_m c[k, m] xi**m, m = 0, 1, 2 (ref. App. B eqs 43-48)
_COEFFICIENTS = {
    0: np.array([[1.0, 0.0, 0.0]]),
    1: np.array([[0.5, -1.0 / math.sqrt(2.0), 0.0],
                 [0.5, 1.0 / math.sqrt(2.0), 0.0]]),
    2: np.array([[0.0, -1.0 / math.sqrt(3.0), 2.0 / 3.0],
                 [1.0, 0.0, -4.0 / 3.0],
                 [0.0, 1.0 / math.sqrt(3.0), 2.0 / 3.0]]),
}


def check_order(element_order):
    """``element_order`` as an int in (0, 1, 2) (0 constant, 1 linear, 2 quadratic DD
    elements), or InputError naming it."""
    return integer("element_order", element_order, min(ELEMENT_ORDERS), max(ELEMENT_ORDERS))


def nodes(element_order):
    """(order + 1,) intrinsic coordinates of the nodes (collocation points)."""
    return _NODES[check_order(element_order)].copy()


def coefficients(element_order):
    """(order + 1, 3) monomial coefficients: ``N_k(xi) = sum_m c[k, m] xi**m``."""
    return _COEFFICIENTS[check_order(element_order)].copy()


def values(element_order, xi):
    """(M, order + 1) shape function values ``N_k(xi_m)`` at intrinsic coordinates ``xi`` (M,)."""
    xi = finite_array("xi", np.atleast_1d(np.asarray(xi, dtype=float)), (None,))
    powers = np.stack([np.ones_like(xi), xi, xi * xi], axis=1)
    return powers @ coefficients(element_order).T


__all__ = ["ELEMENT_ORDERS", "check_order", "nodes", "coefficients", "values"]
