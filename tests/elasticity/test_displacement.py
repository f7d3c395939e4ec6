"""Displacements at points (ref. Eqs 2.43, 2.55-2.57): hmatddm.displacement_at against
an independent computation -- Gauss quadrature of the Somigliana identity with Kelvin's
point-force stress, written here apart from the code -- against the stress kernels
(Hooke's law on the finite-difference gradient of the displacement), the jump across
an element, and the compressed (tree) sum against the exact one."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError

NU, G = 0.25, 1.0e9


def _kelvin_stress(r, nu):
    """S[k, i, j]: stress at xi of a unit point force along k at x, r = xi - x (Kelvin;
    2D plane strain: the line force)."""
    d = np.linalg.norm(r)
    h = r / d
    eye = np.eye(len(r))
    mixed = np.einsum("ik,j->kij", eye, h) + np.einsum("jk,i->kij", eye, h) - np.einsum("ij,k->kij", eye, h)
    if len(r) == 3:
        return -(((1 - 2 * nu) * mixed + 3 * np.einsum("i,j,k->kij", h, h, h)) / (8 * np.pi * (1 - nu) * d**2))
    return -(((1 - 2 * nu) * mixed + 2 * np.einsum("i,j,k->kij", h, h, h)) / (4 * np.pi * (1 - nu) * d))


def _somigliana(mesh, dd, points, n=24):
    """u_k(x) = sum over elements of int DD_i sigma^k_ij(xi; x) n_j dS(xi) (the two faces
    of a crack in Somigliana's identity), Gauss-Legendre with n points per side."""
    nodes, weights = np.polynomial.legendre.leggauss(n)
    out = np.zeros((len(points), mesh.dim))
    for e in range(mesh.n_elements):
        frame = mesh.frames[e]
        normal = mesh.normals[e]
        if mesh.dim == 3:
            a, b = mesh.half_a[e], mesh.half_b[e]
            samples = [(mesh.centers[e] + a * u * frame[0] + b * v * frame[1], wu * wv * a * b)
                       for u, wu in zip(nodes, weights) for v, wv in zip(nodes, weights)]
        else:
            a = mesh.half_length[e]
            samples = [(mesh.centers[e] + a * u * frame[0], wu * a) for u, wu in zip(nodes, weights)]
        for t, x in enumerate(points):
            for xi, w in samples:
                out[t] += w * np.einsum("i,kij,j->k", dd[e], _kelvin_stress(xi - x, NU), normal)
    return out


def _mesh3d():
    # two tilted rectangular fractures, cut into 2 x 2 and 2 x 1 elements
    e1 = np.array([1.0, 0.3, 0.2])
    e2 = np.cross([0.1, -0.4, 1.0], e1)
    first = hd.mesh.rectangle([0.0, 0.0, 0.0], e1, e2, 2.0, 1.2, 2, 2)
    second = hd.mesh.rectangle([0.5, 2.5, -0.5], [0.0, 1.0, 0.0], [0.6, 0.0, 0.8], 1.6, 0.8, 2, 1, fracture_id=1)
    return hd.mesh.concatenate([first, second])


def test_3d_against_somigliana_quadrature():
    mesh = _mesh3d()
    rng = np.random.default_rng(3)
    dd = rng.normal(size=(mesh.n_elements, 3)) * 1e-3
    points = np.array([[0.3, -1.1, 1.4], [3.0, 1.0, 0.5], [-2.0, 2.0, -2.0], [0.2, 0.9, 0.6], [8.0, -5.0, 3.0]])
    exact = _somigliana(mesh, dd, points)
    got = hd.displacement_at(mesh, hd.Elastic(G, NU), dd, points, method="direct")
    # the points are at least ~0.5 element sizes from every element: 24^2 Gauss points are exact to ~1e-7
    assert np.max(np.abs(got - exact)) <= 1e-6 * np.max(np.abs(exact))


def test_2d_against_somigliana_quadrature():
    mesh = hd.mesh.concatenate([hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 4),
                                hd.mesh.line([1.5, 0.5], [2.5, 1.7], 3, fracture_id=1)])
    rng = np.random.default_rng(5)
    dd = rng.normal(size=(mesh.n_elements, 2)) * 1e-3
    points = np.array([[0.1, 0.7], [-2.0, -1.0], [2.4, 0.6], [6.0, 4.0], [0.0, -0.3]])
    exact = _somigliana(mesh, dd, points, n=64)
    got = hd.displacement_at(mesh, hd.Elastic(G, NU), dd, points)
    assert np.max(np.abs(got - exact)) <= 1e-7 * np.max(np.abs(exact))


@pytest.mark.parametrize("dim", [2, 3])
def test_jump_across_an_element_is_its_dd(dim):
    if dim == 3:
        mesh = hd.mesh.rectangle([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.6, 0.8], 2.0, 1.0, 1, 1)
    else:
        mesh = hd.mesh.line([0.0, 0.0], [2.0, 1.0], 1)
    dd = np.arange(1.0, dim + 1.0)[None, :] * 1e-3
    inside = mesh.centers[0] + 0.21 * mesh.frames[0, 0]
    step = 1e-9 * mesh.normals[0]
    plus, minus, on = hd.displacement_at(mesh, hd.Elastic(G, NU), dd, np.array([inside + step, inside - step, inside]))
    np.testing.assert_allclose(plus - minus, dd[0], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(on, plus, rtol=1e-6, atol=1e-12)  # on the face: its + side


@pytest.mark.parametrize("dim", [2, 3])
def test_hooke_on_the_displacement_gradient_is_the_stress(dim):
    """Two kernels derived apart (A_ij of ref. Eq. 2.56, S_ijk of Eq. 2.59): the stress of
    Hooke's law on the central-difference gradient of the displacement is the stress."""
    if dim == 3:
        mesh = _mesh3d()
        points = np.array([[0.3, -1.1, 1.4], [2.0, 1.0, 0.4], [-1.5, 1.5, -1.0]])
    else:
        mesh = hd.mesh.line([-1.0, 0.2], [1.0, -0.3], 5)
        points = np.array([[0.1, 0.9], [-1.6, -0.4], [1.3, 0.0]])
    material = hd.Elastic(G, NU)
    dd = np.random.default_rng(7).normal(size=(mesh.n_elements, dim)) * 1e-3
    h = 1e-5
    grad = np.zeros((len(points), dim, dim))  # grad[t, i, j] = d u_i / d x_j
    for j in range(dim):
        shift = np.zeros(dim)
        shift[j] = h
        grad[:, :, j] = (hd.displacement_at(mesh, material, dd, points + shift)
                         - hd.displacement_at(mesh, material, dd, points - shift)) / (2 * h)
    strain = 0.5 * (grad + grad.transpose(0, 2, 1))
    lam = 2 * G * NU / (1 - 2 * NU)
    stress = 2 * G * strain + lam * np.trace(strain, axis1=1, axis2=2)[:, None, None] * np.eye(dim)
    expected = hd.stress_at(mesh, material, dd, points)
    assert np.max(np.abs(stress - expected)) <= 1e-6 * np.max(np.abs(expected))


@pytest.mark.parametrize("dim", [2, 3])
def test_tree_against_direct(dim):
    rng = np.random.default_rng(11)
    if dim == 3:
        mesh = hd.mesh.rectangle([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 20.0, 10.0, 20, 10)
        points = np.column_stack([rng.uniform(-100, 100, 1500), rng.uniform(-100, 100, 1500),
                                  rng.uniform(10, 40, 1500)])
    else:
        mesh = hd.mesh.line([-10.0, 0.0], [10.0, 0.0], 400)
        points = np.column_stack([rng.uniform(-40, 40, 2000), rng.uniform(1, 40, 2000)])
    dd = rng.normal(size=(mesh.n_elements, dim)) * 1e-3
    material = hd.Elastic(G, NU)
    direct = hd.displacement_at(mesh, material, dd, points, method="direct")
    info = {}
    tree = hd.displacement_at(mesh, material, dd, points, method="tree", eps=1e-6, info=info)
    assert info["method"] == "tree" and info["pairs_compressed"] > 0
    assert np.max(np.abs(tree - direct)) <= 1e-6 * np.max(np.abs(direct))


def test_bad_points_and_media_are_refused():
    mesh = hd.mesh.line([-1.0, 0.0], [1.0, 0.0], 2)
    material = hd.Elastic(G, NU)
    with pytest.raises(InputError, match=r"points\[1\] lies on an element edge"):
        hd.displacement_at(mesh, material, np.ones((2, 2)), np.array([[0.0, 1.0], [1.0, 0.0]]))
    with pytest.raises(InputError, match="points"):
        hd.displacement_at(mesh, material, np.ones((2, 2)), np.array([[0.0, np.nan]]))
    # a layered medium has its own kernels (tests/layered/test_layered_displacement.py): equal
    # layers are this uniform rock, and the compressed sum is refused there
    layered = hd.LayeredMedium([0.0], [G, G], [NU, NU])
    points = np.array([[0.0, 1.0], [0.3, -0.5]])
    np.testing.assert_allclose(hd.displacement_at(mesh, layered, np.ones((2, 2)), points),
                               hd.displacement_at(mesh, material, np.ones((2, 2)), points), rtol=1e-13, atol=0.0)
    with pytest.raises(InputError, match="method='tree' is not available in a LayeredMedium"):
        hd.displacement_at(mesh, layered, np.ones((2, 2)), points, method="tree")
