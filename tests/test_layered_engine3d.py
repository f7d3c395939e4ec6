"""Layered rock in the 3D engine (ref. Ch. 3 + Ch. 4): rectangles cut at interfaces,
settings refused by name, and coupled runs in layered media."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.layered import LayeredMedium, split_at_interfaces
from hmatddm.layered.engine import crossed_interfaces

G, NU = 10e9, 0.25
THREE_LAYERS = LayeredMedium([1.0, -1.0], [2 * G, G, 2 * G], [NU, NU, NU])


def _vertical_range(pieces):
    low = pieces.centers[:, 2] - pieces.half_a * np.abs(pieces.frames[:, 0, 2]) \
        - pieces.half_b * np.abs(pieces.frames[:, 1, 2])
    high = 2 * pieces.centers[:, 2] - low
    return low, high


@pytest.mark.parametrize("e2", [[0.0, 0.0, 1.0], [0.0, 0.6, 0.8]])  # vertical, dipping 53 deg
def test_rectangles_are_cut_along_interfaces_into_rectangles(e2):
    mesh = hd.mesh.rectangle([0.0, 0.0, 0.2], [1.0, 0.0, 0.0], e2, 2.0, 3.0, 2, 1)  # z from -1 to 1.4 (dipping)
    pieces, index = split_at_interfaces(mesh, THREE_LAYERS)
    assert crossed_interfaces(mesh, THREE_LAYERS) is not None and crossed_interfaces(pieces, THREE_LAYERS) is None
    assert np.isclose(pieces.areas.sum(), mesh.areas.sum(), rtol=1e-14)
    for i in range(mesh.n_elements):
        assert np.isclose(pieces.areas[index == i].sum(), mesh.areas[i], rtol=1e-14)
        assert np.allclose(pieces.frames[index == i], mesh.frames[i])
    low, high = _vertical_range(pieces)
    assert np.any(np.isclose(high, 1.0)) and np.any(np.isclose(low, 1.0))
    vertical = e2[2] == 1.0
    assert pieces.n_elements == mesh.n_elements * (3 if vertical else 2)  # the dipping one reaches z = 1.4 only
    # the pieces tile the parent along e2: each piece's e2 extent ends where the next begins
    along = np.einsum("nj,j->n", pieces.centers - mesh.centers[index], np.asarray(e2))
    for i in range(mesh.n_elements):
        s = np.sort(np.c_[along - pieces.half_b, along + pieces.half_b][index == i], axis=0)
        assert np.allclose(s[1:, 0], s[:-1, 1]) and np.isclose(s[0, 0], -1.5) and np.isclose(s[-1, 1], 1.5)


def test_horizontal_and_contained_elements_are_left_alone():
    flat = hd.mesh.rectangle([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 2.0, 2.0, 2, 2)  # on the interface
    inside = hd.mesh.rectangle([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 2.0, 2.0, 2, 2)  # ends on both
    for mesh in (flat, inside):
        pieces, index = split_at_interfaces(mesh, THREE_LAYERS)
        assert pieces is mesh and np.array_equal(index, np.arange(mesh.n_elements))


def test_a_rectangle_without_horizontal_edge_is_refused_by_name():
    e1 = np.array([1.0, 0.0, 1.0]) / np.sqrt(2)
    e2 = np.cross(e1, np.array([0.3, 1.0, 0.4]) / np.linalg.norm([0.3, 1.0, 0.4]))
    e2 /= np.linalg.norm(e2)
    mesh = hd.Mesh3D.from_rectangles(np.array([[0.0, 0.0, 0.9]]), e1[None], e2[None], np.array([0.5]),
                                     np.array([0.5]))
    with pytest.raises(InputError, match="no horizontal edge"):
        split_at_interfaces(mesh, THREE_LAYERS)


def _vertical_run(medium, propagation=None, mesh=None, **options):
    mesh = hd.mesh.rectangle([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 2.0, 2.0, 2, 2) if mesh is None \
        else mesh
    return hd.Simulation(mesh, medium, hd.Fluid(1e-3), [hd.Cluster((0.0, 0.0, 0.0), 1e-3, 0.01)],
                         np.diag([-1e6, -2e6, -3e6]), 1.0, propagation=propagation, backend="dense", **options)


def test_layered_3d_simulation_refuses_what_it_does_not_support():
    with pytest.raises(InputError, match="propagation.turning"):
        _vertical_run(THREE_LAYERS, hd.Propagation(5e6, turning="any"))
    e1 = np.array([0.0, 1.0, 1.0]) / np.sqrt(2)
    e2 = np.array([np.sqrt(2) / 2, -0.5, 0.5])
    tilted = hd.Mesh3D.from_rectangles(np.array([[0.0, 0.0, 0.0]]), e1[None], e2[None], np.array([0.3]),
                                       np.array([0.3]))
    with pytest.raises(InputError, match="no horizontal edge"):
        _vertical_run(THREE_LAYERS, hd.Propagation(5e6), mesh=tilted)
    with pytest.raises(InputError, match="natural_fractures"):
        _vertical_run(THREE_LAYERS, natural_fractures=hd.mesh.rectangle([3.0, 0, 0], [1, 0, 0], [0, 0, 1], 1, 1, 1, 1))
    with pytest.raises(InputError, match="void layer"):  # the fracture above the free surface
        _vertical_run(LayeredMedium([-2.0], [0.0, G], [NU, NU]))
    stressed = LayeredMedium([1.0, -1.0], [G, G, G], [NU, NU, NU], in_situ_stress=np.zeros((3, 2, 2)))
    with pytest.raises(InputError, match="in_situ_stress must hold 3x3"):
        _vertical_run(stressed)

