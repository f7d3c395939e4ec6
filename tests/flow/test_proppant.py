"""Proppant transport (issue 34, hmatddm.flow.proppant): mass conservation, hindered settling
of a static column against the kinematic-wave speed of Richardson and Zaki, monotone transport
of a pumped concentration, bridging, the packing limit and the packed bed of a closing element."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.flow.proppant import (Proppant, TransportGeometry, propped_width, slurry_viscosity_factor,
                                   transport)
from hmatddm.mesh import topology

SAND = Proppant(diameter=3e-4)  # 300 um quartz in water


def vertical_column(cells, height, width=1.0):
    """A vertical fracture (x-z plane), one element wide and ``cells`` high."""
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], width, height, 1, cells)  # z in [-h/2, h/2]
    faces = topology.element_faces(mesh)
    return mesh, TransportGeometry.of(mesh.areas, faces, mesh.centers, vertical=[0.0, 0.0, 1.0])


def test_mass_is_conserved_to_round_off_every_step():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 6.0, 4.0, 6, 4)
    faces = topology.element_faces(mesh)
    geometry = TransportGeometry.of(mesh.areas, faces, mesh.centers, vertical=[0.0, 0.0, 1.0])
    rng = np.random.default_rng(5)
    width = rng.uniform(2e-3, 4e-3, mesh.n_elements)
    volume = 0.2 * mesh.areas * width * rng.uniform(0.0, 1.0, mesh.n_elements)
    injection = np.zeros(mesh.n_elements)
    injection[7] = 2e-5
    total = volume.sum()
    for step in range(20):
        new_width = width * rng.uniform(0.95, 1.08, mesh.n_elements)
        flux = rng.normal(0.0, 5e-4, faces.n_faces)
        volume, _, screened = transport(geometry, SAND, volume, width, new_width, flux, 1.0, 1e-3,
                                        injection=injection)
        total += 1.0 * injection.sum() - screened
        assert abs(volume.sum() - total) <= 1e-10 * total
        assert np.all(volume >= 0.0)
        assert np.all(volume <= SAND.packing_limit * mesh.areas * new_width * (1.0 + 1e-12))
        width = new_width


def test_static_column_settles_at_the_hindered_stokes_velocity():
    # a suspension at c0 in a closed column: its top (the shock between clear fluid and c0) falls
    # at f(c0)/c0 = v_St (1 - c0)^m (kinematic waves, Richardson-Zaki flux f(c) = c v_St (1-c)^m)
    cells, height, c0, mu = 400, 4.0, 0.1, 0.05  # 50 cP: v_St = 1.6 mm/s
    mesh, geometry = vertical_column(cells, height)
    width = np.full(cells, 5e-3)
    volume = c0 * mesh.areas * width
    expected = SAND.settling_velocity(c0, mu)
    assert expected == pytest.approx(SAND.stokes_velocity(mu) * (1.0 - c0) ** 4.65, rel=1e-14)
    dt, steps = 10.0, 60  # the top falls ~0.9 m: ~90 elements
    for _ in range(steps):
        volume, _, _ = transport(geometry, SAND, volume, width, width, np.zeros(geometry.first.size), dt, mu)
    c = volume / (mesh.areas * width)
    z = mesh.centers[:, 2]
    order = np.argsort(z)
    z, c = z[order], c[order]
    # the top of the equivalent sharp suspension: the proppant above mid-height over c0
    above = z > 0.0
    top = np.sum(c[above] * height / cells) / c0
    assert 0.5 * height - top == pytest.approx(expected * dt * steps, rel=0.01)
    # and the half-concentration point of the (smeared, self-sharpening) top shock
    upper = np.flatnonzero(c > 0.5 * c0).max()
    fraction = (0.5 * c0 - c[upper + 1]) / (c[upper] - c[upper + 1])
    half = z[upper] + fraction * (z[upper + 1] - z[upper])
    assert 0.5 * height - half == pytest.approx(expected * dt * steps, rel=0.03)
    # below the top the suspension keeps c0 until the bed; the bed is packed, never above c_max
    middle = (z > -0.5 * height + 1.0) & (z < top - 0.1)
    np.testing.assert_allclose(c[middle], c0, rtol=1e-9)
    assert c.max() <= SAND.packing_limit * (1.0 + 1e-12)
    assert c[0] == pytest.approx(SAND.packing_limit, rel=1e-9)


def test_pumped_concentration_travels_without_under_or_overshoot():
    # a horizontal channel (2D plan view: no settling) of uniform opening and flux, c0 pumped in
    cells, c0, q = 50, 0.2, 1e-3
    mesh = hd.mesh.line([0.0, 0.0], [10.0, 0.0], cells)
    faces = topology.element_faces(mesh, height=1.0)
    geometry = TransportGeometry.of(mesh.areas * 1.0, faces, mesh.centers)
    width = np.full(cells, 2e-3)
    order = np.argsort(mesh.centers[:, 0])
    inlet = order[0]
    flux = np.where(mesh.centers[faces.second, 0] > mesh.centers[faces.first, 0], q, -q)
    injection = np.zeros(cells)
    injection[inlet] = c0 * q
    volume = np.zeros(cells)
    for _ in range(30):
        volume, _, _ = transport(geometry, SAND, volume, width, width, flux, 0.5, 1e-3, injection=injection)
        c = volume / (geometry.areas * width)
        assert np.all(c >= 0.0) and np.all(c <= c0 * (1.0 + 1e-12))
        assert np.all(np.diff(c[order]) <= 1e-15)  # monotone: no new extremum behind the front
    # the slurry swept 30 x 0.5 x 1e-3 / (2e-3 x 0.2) = 37.5 elements: the first 20 are at c0
    # (the upwind front is smeared over a few elements)
    np.testing.assert_allclose(c[order[:20]], c0, rtol=1e-5)
    assert volume.sum() == pytest.approx(30 * 0.5 * c0 * q, rel=1e-12)


def test_bridging_stops_proppant_at_the_tip_and_the_bed_stays_on_closure():
    cells, c0, q = 10, 0.2, 1e-4
    mesh = hd.mesh.line([0.0, 0.0], [5.0, 0.0], cells)
    faces = topology.element_faces(mesh, height=1.0)
    geometry = TransportGeometry.of(mesh.areas * 1.0, faces, mesh.centers)
    order = np.argsort(mesh.centers[:, 0])
    width = np.full(cells, 2e-3)
    width[order[-3:]] = 5e-4  # the tip: narrower than 3 diameters (0.9 mm)
    flux = np.where(mesh.centers[faces.second, 0] > mesh.centers[faces.first, 0], q, -q)
    injection = np.zeros(cells)
    injection[order[0]] = c0 * q
    volume, screened = np.zeros(cells), 0.0
    for _ in range(400):
        volume, _, rejected = transport(geometry, SAND, volume, width, width, flux, 1.0, 1e-3, injection=injection)
        screened += rejected
    c = volume / (geometry.areas * width)
    assert np.all(volume[order[-3:]] == 0.0)  # nothing crossed the bridged faces
    # the bed packs back from the bridge to the inlet; then the pump screens out
    np.testing.assert_allclose(c[order[:-3]], SAND.packing_limit, rtol=1e-9)
    assert screened > 0.0
    assert volume.sum() + screened == pytest.approx(400.0 * c0 * q, rel=1e-10)
    # the fracture closes (no flow): the proppant stays, as a bed of propped width V / (c_max S)
    closed = np.full(cells, 1e-6)
    kept, _, _ = transport(geometry, SAND, volume, width, closed, np.zeros(faces.n_faces), 1.0, 1e-3)
    np.testing.assert_allclose(kept, volume, rtol=0.0, atol=1e-18)
    bed = propped_width(kept, geometry.areas, SAND.packing_limit)
    assert bed[order[-4]] == pytest.approx(width[order[-4]], rel=1e-9)
    assert np.all(bed[order[-3:]] == 0.0)


def test_slurry_viscosity_and_settling_laws():
    c = np.array([0.0, 0.3, 0.59, 0.6])
    factor = slurry_viscosity_factor(c, 0.6)
    assert factor[0] == 1.0 and factor[1] == pytest.approx(4.0, rel=1e-14) and np.isinf(factor[3])
    assert SAND.stokes_velocity(1e-3) == pytest.approx(1650.0 * 9.81 * 9e-8 / 18e-3, rel=1e-14)


@pytest.mark.parametrize("kwargs, field", [
    (dict(diameter=-1e-4), "proppant.diameter"), (dict(diameter=0.0), "proppant.diameter"),
    (dict(diameter=3e-4, packing_limit=1.2), "proppant.packing_limit"),
    (dict(diameter=3e-4, density=0.0), "proppant.density"),
    (dict(diameter=3e-4, bridging_factor=0.5), "proppant.bridging_factor"),
])
def test_bad_proppant_is_refused_naming_the_field(kwargs, field):
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        Proppant(**kwargs)


def test_concentration_at_the_packing_limit_is_refused():
    with pytest.raises(InputError, match=r"cluster.concentration must be in \[0, 0.6\)"):
        SAND.check_concentration("cluster.concentration", 0.6)
    with pytest.raises(InputError, match=r"cluster.concentration must be in \[0, 0.6\)"):
        SAND.check_concentration("cluster.concentration", [0.1, -0.1])
    assert SAND.check_concentration("cluster.concentration", [0.0, 0.3]).tolist() == [0.0, 0.3]
