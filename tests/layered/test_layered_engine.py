"""Layered rock in the coupled flow/propagation engine (ref. Ch. 3 + Ch. 4): a vertical
cross-section of a fracture growing in height, and the [[layer]] scene tables."""
import dataclasses

import numpy as np
import pytest

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.errors import InputError
from hmatddm.coupled import SchemeSettings
from hmatddm.layered import LayeredMedium

G, NU = 10e9, 0.25


def _height_run(material, end_time=8.0, toughness=5e6, scheme="krylov"):
    """KGD-like vertical fracture (x horizontal, y up) under 0.5 MPa horizontal stress."""
    mesh = hd.mesh.line([0.0, -0.375], [0.0, 0.375], 3)
    sim = hd.Simulation(mesh, material, hd.Fluid(1e-4, 4.5e-10), [hd.Cluster((0.0, 0.0), 5e-4, 0.01)],
                        far_field_stress=np.diag([-0.5e6, 0.0]), time_step=1.0,
                        propagation=hd.Propagation(toughness=toughness), initial_pressure=0.6e6,
                        initial_opening=1e-5, backend="dense", scheme=scheme)
    records = sim.run(end_time=end_time)
    return sim, records


@pytest.mark.parametrize("paused", [False, True])
def test_equal_layers_give_the_homogeneous_run_to_round_off(paused):
    """With and without growth passes decided on paused GMRES iterates (the default: with;
    in a layered medium the margin uses the layer ahead's toughness, as the homogeneous run
    uses the rock's), the two runs take the same solver path."""
    settings = SchemeSettings(scheme="krylov")
    if not paused:
        settings = dataclasses.replace(settings, provisional_linear_rtol=settings.first_linear_rtol)
    homogeneous, records_h = _height_run(hd.Elastic(G, NU), scheme=settings)
    layered, records_l = _height_run(LayeredMedium([1.0, -1.0], [G, G, G], [NU, NU, NU]), scheme=settings)
    assert layered.state.mesh.n_elements == homogeneous.state.mesh.n_elements > 3  # it grew, past y = +-1
    scale = np.abs(homogeneous.state.dd).max()
    assert np.max(np.abs(layered.state.dd - homogeneous.state.dd)) <= 1e-12 * scale
    assert np.allclose([r["wellbore_pressure"] for r in records_l], [r["wellbore_pressure"] for r in records_h],
                       rtol=1e-12, atol=0.0)


def test_growth_across_interfaces_cuts_elements_there():
    """Stiffer bounding layers (gamma = 2): the fracture grows through both interfaces,
    its new elements end on them (none straddles), and each part lies in one layer."""
    medium = LayeredMedium([1.0, -1.0], [2 * G, G, 2 * G], [NU, NU, NU], images=2)
    sim, _ = _height_run(medium)
    mesh = sim.state.mesh
    p0, p1 = mesh.endpoints
    low, high = np.minimum(p0[:, 1], p1[:, 1]), np.maximum(p0[:, 1], p1[:, 1])
    assert low.min() < -1.0 and high.max() > 1.0
    for height in medium.interfaces:
        assert not np.any((low < height - 1e-9) & (high > height + 1e-9))
        assert np.any(np.isclose(low, height)) and np.any(np.isclose(high, height))


def test_per_layer_toughness_and_stress_contain_the_height():
    """The same stiffness everywhere, but bounding layers much tougher (40x) or more
    stressed (+9.5 MPa), interfaces at y = +-1: over 8 s the homogeneous run grows to
    y = 3.4 at a falling pressure; the tough layers stop the tips within one element
    of the interface (the toughness is that of the layer ahead of a tip), the stressed
    ones let them in by less than 1 m while the pressure builds up (partial penetration
    at a net pressure close to the stress contrast: 8.4 MPa against 9.5 MPa)."""
    homogeneous, records = _height_run(hd.Elastic(G, NU))
    p_homogeneous = records[-1]["wellbore_pressure"][0]
    assert homogeneous.state.mesh.endpoints[1][:, 1].max() > 3.0
    tough = LayeredMedium([1.0, -1.0], [G, G, G], [NU, NU, NU], toughness=[200e6, 5e6, 200e6])
    stressed = LayeredMedium([1.0, -1.0], [G, G, G], [NU, NU, NU],
                             in_situ_stress=np.array([np.diag([-10e6, 0.0]), np.diag([-0.5e6, 0.0]),
                                                      np.diag([-10e6, 0.0])]))
    for medium, reach in ((tough, 0.25), (stressed, 1.0)):
        sim, records = _height_run(medium)
        p0, p1 = sim.state.mesh.endpoints
        assert max(p0[:, 1].max(), p1[:, 1].max()) <= 1.0 + reach + 1e-9
        assert min(p0[:, 1].min(), p1[:, 1].min()) >= -1.0 - reach - 1e-9
        assert records[-1]["wellbore_pressure"][0] > 3.0 * p_homogeneous


def test_layered_simulation_refuses_what_it_does_not_support():
    medium = LayeredMedium([0.0], [G, 2 * G], [NU, NU])
    mesh3d = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 1.0, 1.0, 1, 1)  # vertical, across z = 0
    with pytest.raises(InputError, match="crosses the layer interface at z = 0"):
        hd.Simulation(mesh3d, medium, hd.Fluid(1e-3), [hd.Cluster((0, 0, 0), 0.01)], np.zeros((3, 3)), 1.0)
    stressed = LayeredMedium([0.0], [G, 2 * G], [NU, NU], in_situ_stress=np.zeros((2, 3, 3)))
    with pytest.raises(InputError, match="in_situ_stress"):
        hd.Simulation(hd.mesh.line([0.0, -1.0], [0.0, -0.5], 2), stressed, hd.Fluid(1e-3),
                      [hd.Cluster((0.0, -0.75), 0.01)], np.zeros((2, 2)), 1.0)


def test_layered_height_scene_builds_and_steps():
    scene = hs.load_scene("layered-height")
    sim = hs.build_simulation(scene.data)
    assert isinstance(sim.material, LayeredMedium) and sim.material.n_layers == 3
    assert sim.material.in_situ_stress[0, 0, 0] == -1.0e6 and sim.material.in_situ_stress[1, 0, 0] == -0.5e6
    records = sim.run(end_time=3.0)
    assert records[-1]["fracture_volume"] > 0.0


@pytest.mark.parametrize("layers, field", [
    ([dict(shear_modulus=1e9, poisson_ratio=0.2), dict(shear_modulus=1e9, poisson_ratio=0.2)], r"layer\[0\].bottom"),
    ([dict(bottom=1.0, shear_modulus=1e9, poisson_ratio=0.2), dict(bottom=0.0, shear_modulus=1e9, poisson_ratio=0.2)],
     r"layer\[1\].bottom"),
    ([dict(bottom=1.0, shear_modulus=1e9, poisson_ratio=0.2), dict(bottom=2.0, shear_modulus=1e9, poisson_ratio=0.2),
      dict(shear_modulus=1e9, poisson_ratio=0.2)], r"layer\[1\].bottom"),
    ([dict(bottom=1.0, shear_modulus=-1e9, poisson_ratio=0.2), dict(shear_modulus=1e9, poisson_ratio=0.2)],
     r"layer\[0\].shear_modulus"),
])
def test_bad_layer_tables_are_refused_by_name(layers, field):
    raw = hs.load_scene("layered-height").data
    text = hs.parse_scene(hs.load_scene("layered-height").to_toml()).data
    assert text == raw
    raw = dict(raw)
    raw["layer"] = layers
    with pytest.raises(InputError, match=field):
        hs.scene_from_dict(raw)
