"""Synthetic natural-fracture networks (ref. Sec. 6.2): count, region, sampled laws in a
network, seeds, validation of NetworkSpec, meshes."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm import network as nw
from test_network_sampling import _axial_difference, _axial_mean_and_kappa, _power_law_mle

# ----------------------------------------------------------------------------- networks

REGION = (-50.0, 50.0, -50.0, 50.0)


def test_network_count_is_density_times_area_eq_6_12():
    for density in (0.05, 0.1):
        for boundary in ("resample", "clip"):
            spec = nw.NetworkSpec(region=REGION, density=density, boundary=boundary, seed=3)
            assert spec.n_fractures == round(density * 100 * 100)
            network = nw.generate_network(spec)
            assert len(network) == network.n_fractures == spec.n_fractures
            assert np.array_equal(network.fracture_id, np.arange(spec.n_fractures))
    odd = nw.NetworkSpec(region=(0, 7, 0, 3), density=0.5, l_max=3.0, seed=0)  # 10.5 -> 10 (half to even)
    assert len(nw.generate_network(odd)) == round(0.5 * 21)


@pytest.mark.parametrize("boundary", ["resample", "clip"])
def test_fractures_stay_inside_the_region(boundary):
    spec = nw.NetworkSpec(region=(10.0, 60.0, -5.0, 25.0), density=0.5, length_exponent=1.5, l_min=1.0,
                          l_max=30.0, kappas=0.0, boundary=boundary, seed=12)
    network = nw.generate_network(spec)
    points = np.concatenate([network.p0, network.p1])
    assert points[:, 0].min() >= 10.0 and points[:, 0].max() <= 60.0
    assert points[:, 1].min() >= -5.0 and points[:, 1].max() <= 25.0
    assert np.all(network.lengths > 0) and np.all(network.lengths <= 30.0 + 1e-12)
    if boundary == "clip":  # some fractures were cut at the boundary
        assert np.any(network.lengths < 1.0 - 1e-9) or np.any(np.isclose(points, 10.0) | np.isclose(points, 60.0))


def test_resampled_network_keeps_the_sampled_laws():
    spec = nw.NetworkSpec(region=REGION, density=2.0, length_exponent=2.5, l_min=1.0, l_max=30.0,
                          mean_azimuths_deg=30.0, kappas=4.0, seed=21)
    network = nw.generate_network(spec)
    assert len(network) == 20000
    assert abs(_power_law_mle(network.lengths, 1.0, 30.0) - 2.5) / 2.5 < 0.03
    mean, kappa = _axial_mean_and_kappa(network.azimuths)
    assert _axial_difference(mean, np.radians(30.0)) < np.radians(1.0)
    assert abs(kappa - 4.0) / 4.0 < 0.05
    # the strike runs from p0 to p1
    assert np.allclose(network.tangents, np.column_stack([np.cos(network.azimuths), np.sin(network.azimuths)]))


def test_network_bimodal_sets():
    spec = nw.NetworkSpec(region=REGION, density=1.0, mean_azimuths_deg=(45.0, 135.0), kappas=(5.0, 5.0),
                          weights=(0.25, 0.75), seed=2)
    network = nw.generate_network(spec)
    fraction = np.mean(network.set_id == 0)
    assert abs(fraction - 0.25) < 3 * np.sqrt(0.25 * 0.75 / len(network))
    for k, mean_deg in enumerate((45.0, 135.0)):
        mean, _ = _axial_mean_and_kappa(network.azimuths[network.set_id == k])
        assert _axial_difference(mean, np.radians(mean_deg)) < np.radians(2.0)


def test_clip_keeps_centres_uniform_and_scanline_count_matches_density():
    """Clip mode: fractures are a uniform (binomial) process of centres. A scan line
    along y far from the boundary then crosses on average
    ``density * L * E[l] * E|cos(theta)|`` fractures, which checks the density unit."""
    density, l_min, l_max, a, kappa = 0.1, 1.0, 10.0, 2.0, 5.0
    counts = []
    for seed in range(10):
        spec = nw.NetworkSpec(region=REGION, density=density, length_exponent=a, l_min=l_min, l_max=l_max,
                              mean_azimuths_deg=45.0, kappas=kappa, boundary="clip", seed=seed)
        network = nw.generate_network(spec)
        counts.append(nw.scanline_frequency(network, (0.0, -30.0), (0.0, 30.0)) * 60.0)
    mean_length = np.log(l_max / l_min) / (1 / l_min - 1 / l_max)  # E[l] for a = 2 (Eq. 6.4)
    theta = nw.von_mises_directions(200000, np.pi / 4, kappa, 0)
    expected = density * 60.0 * mean_length * np.mean(np.abs(np.cos(theta)))
    standard_error = np.sqrt(expected / len(counts))  # Poisson-like counts
    assert abs(np.mean(counts) - expected) < 4 * standard_error


def test_same_seed_same_network_and_other_seed_differs():
    spec = nw.NetworkSpec(region=REGION, density=0.05, mean_azimuths_deg=(45, 135), kappas=(5, 5), seed=42)
    first, second = nw.generate_network(spec), nw.generate_network(spec)
    for name in ("p0", "p1", "fracture_id", "set_id"):
        assert np.array_equal(getattr(first, name), getattr(second, name))
    other = nw.generate_network(nw.NetworkSpec(region=REGION, density=0.05, mean_azimuths_deg=(45, 135),
                                               kappas=(5, 5), seed=43))
    assert not np.array_equal(first.p0, other.p0)
    # the sampling functions accept Generators and seeds alike
    assert np.array_equal(nw.power_law_lengths(5, 2.0, 1, 3, 1), nw.power_law_lengths(5, 2.0, 1, 3, 1))


@pytest.mark.parametrize("kwargs, field", [
    (dict(region=(0, -1, 0, 1)), "region"),
    (dict(region=(0, 1, 0)), "region"),
    (dict(density=-0.1), "density"),
    (dict(density=1e-6), "density"),
    (dict(length_exponent=0.9), "length_exponent"),
    (dict(l_min=0.0), "l_min"),
    (dict(l_max=0.5), "l_max"),
    (dict(l_max=200.0), "l_max"),
    (dict(kappas=-2.0), "kappas"),
    (dict(mean_azimuths_deg=float("nan")), "mean_azimuths_deg"),
    (dict(mean_azimuths_deg=(45, 135), kappas=(5, 5), weights=(0.5, 0.6)), "weights"),
    (dict(mean_azimuths_deg=(45, 135), kappas=(5,)), "same length"),
    (dict(height=0.0), "height"),
    (dict(z_center=np.inf), "z_center"),
    (dict(seed=-1), "seed"),
    (dict(seed=1.5), "seed"),
    (dict(boundary="reflect"), "boundary"),
])
def test_spec_validation_names_the_field(kwargs, field):
    args = dict(region=REGION, density=0.05) | kwargs
    with pytest.raises(hd.InputError, match=field):
        nw.NetworkSpec(**args)


def test_spec_defaults_follow_table_6_1_and_normalise():
    spec = nw.NetworkSpec(region=[-50, 50, -50, 50], density=0.05, mean_azimuths_deg=45, kappas=5)
    assert spec.mean_azimuths_deg == (45.0,) and spec.kappas == (5.0,) and spec.weights == (1.0,)
    assert (spec.l_min, spec.l_max) == (1.0, 30.0)
    assert spec.region == (-50.0, 50.0, -50.0, 50.0)
    assert nw.NetworkSpec(region=REGION, density=0.05, l_max=200.0, boundary="clip").l_max == 200.0
    with pytest.raises(hd.InputError, match="spec"):
        nw.generate_network({"density": 0.05})


# ----------------------------------------------------------------------------- meshes

def _small_network():
    spec = nw.NetworkSpec(region=(-20, 20, -20, 20), density=0.05, length_exponent=2.0, l_min=1.0,
                          l_max=15.0, height=6.0, z_center=-100.0, seed=5)
    return nw.generate_network(spec)


def test_mesh2d_from_network():
    network = _small_network()
    mesh = network.to_mesh2d(element_length=0.5)
    assert isinstance(mesh, hd.Mesh2D)
    counts = np.maximum(1, np.rint(network.lengths / 0.5)).astype(int)
    assert mesh.n_elements == counts.sum()
    assert np.all(np.isfinite(mesh.centers)) and np.all(mesh.areas > 0)
    assert np.array_equal(mesh.fracture_id, np.repeat(network.fracture_id, counts))
    # element sizes are about element_length, and cover each fracture exactly
    assert np.all(mesh.areas[np.repeat(counts, counts) > 1] < 0.5 * 1.5 + 1e-12)
    assert np.allclose(np.bincount(mesh.fracture_id, mesh.areas), network.lengths)
    assert np.allclose(np.abs(np.einsum("ij,ij->i", mesh.tangents, np.repeat(network.tangents, counts, 0))), 1.0)
    # end to end along every fracture
    p0, p1 = mesh.endpoints
    same = mesh.fracture_id[1:] == mesh.fracture_id[:-1]
    assert np.allclose(p1[:-1][same], p0[1:][same], atol=1e-12)
    assert np.allclose(p0[np.r_[True, ~same]], network.p0, atol=1e-12)


def test_mesh3d_from_network():
    network = _small_network()
    mesh = network.to_mesh3d(element_length=1.0, n_height=3)
    counts = np.maximum(1, np.rint(network.lengths / 1.0)).astype(int)
    assert isinstance(mesh, hd.Mesh3D) and mesh.n_elements == 3 * counts.sum()
    assert np.all(mesh.areas > 0) and np.all(np.isfinite(mesh.centers))
    assert np.array_equal(mesh.fracture_id, np.repeat(network.fracture_id, 3 * counts))
    assert np.allclose(np.bincount(mesh.fracture_id, mesh.areas), network.lengths * 6.0)
    assert np.allclose(mesh.half_b, 1.0)
    assert np.allclose(np.unique(np.round(mesh.centers[:, 2], 9)), [-102.0, -100.0, -98.0])
    assert np.allclose(mesh.normals[:, 2], 0.0)  # vertical fractures
    corners = mesh.corners()
    assert corners[:, :, 2].min() >= -103.0 - 1e-9 and corners[:, :, 2].max() <= -97.0 + 1e-9
    # e1 along strike (p0 -> p1), e2 = +z
    assert np.allclose(mesh.frames[:, 1], [0, 0, 1])
    strike = np.repeat(network.tangents, 3 * counts, axis=0)
    assert np.allclose(mesh.frames[:, 0, :2], strike)


def test_mesh_input_validation():
    network = _small_network()
    with pytest.raises(hd.InputError, match="element_length"):
        network.to_mesh2d(0.0)
    with pytest.raises(hd.InputError, match="n_height"):
        network.to_mesh3d(1.0, 0)
    with pytest.raises(hd.InputError, match="fracture_id"):
        nw.Network.from_segments([[0, 0]], [[1, 0]], fracture_id=[0.5])
    with pytest.raises(hd.InputError, match="zero length"):
        nw.Network.from_segments([[0, 0]], [[0, 0]])
