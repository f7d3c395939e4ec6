"""Power-law fluids in the finite-volume lubrication (issue 34): the parallel-plate flux of a
power-law fluid (written out here from the velocity profile, apart from the flow code), its
linearisation in the pressure iterate, the truncation at low shear, and n = 1, K = mu against
the Newtonian rows."""
import numpy as np
import pytest
from scipy import integrate

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.flow import Fluid, LeakOff, LubricationModel
from hmatddm.mesh import topology


def _model(mesh, fluid, height=1.0, width_floor=1e-6):
    faces = topology.element_faces(mesh, height=height)
    areas = mesh.areas * (height if mesh.dim == 2 else 1.0)
    return LubricationModel(areas=areas, normals=mesh.normals, faces=faces, fluid=fluid, leak_off=LeakOff(),
                            injection_elements=np.array([0]), injection_rates=np.array([1e-3]),
                            wellbore_volumes=np.array([0.0]), minimum_width=width_floor)


def slot_flux(width, gradient, consistency, flow_index):
    """Flux per unit height of a power-law fluid between plates ``width`` apart under the
    pressure gradient magnitude ``gradient``: the velocity profile integrated numerically.

    The shear stress is ``tau(y) = gradient * y`` from the mid-plane, the shear rate
    ``(tau / K)^(1/n)``, so ``u(y) = int_y^(w/2) (gradient s / K)^(1/n) ds`` and
    ``q = 2 int_0^(w/2) u dy``."""
    half = 0.5 * width

    def velocity(y):
        return integrate.quad(lambda s: (gradient * s / consistency) ** (1.0 / flow_index), y, half)[0]

    return 2.0 * integrate.quad(velocity, 0.0, half, epsrel=1e-11)[0]


@pytest.mark.parametrize("flow_index", [0.4, 0.7, 1.0])
def test_uniform_channel_carries_the_power_law_slot_flux(flow_index):
    length, n_cells, height, width, consistency = 10.0, 20, 2.0, 1e-3, 0.05
    mesh = hd.mesh.line([0, 0], [length, 0], n_cells)
    fluid = Fluid(rheology="power-law", consistency=consistency, flow_index=flow_index)
    model = _model(mesh, fluid, height=height)
    x = mesh.centers[:, 0]
    drop = 2e5
    pressure = 1e6 - drop * (x - x[0]) / (x[-1] - x[0])
    flux = model.face_flux(np.full(n_cells, width), pressure)
    expected = height * slot_flux(width, drop / (x[-1] - x[0]), consistency, flow_index)
    np.testing.assert_allclose(flux, expected, rtol=1e-7)


def test_the_rows_linearise_the_flux_at_the_pressure_iterate():
    # Newton in the pressure: at p = p^k the linear rows carry the exact flux, and their
    # derivative is the flux's (checked by finite differences of face_flux)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 3.0, 4, 3)
    fluid = Fluid(rheology="power-law", consistency=0.2, flow_index=0.5)
    model = _model(mesh, fluid)
    rng = np.random.default_rng(3)
    width = rng.uniform(1e-4, 3e-4, mesh.n_elements)
    pressure = 5e6 + rng.uniform(-1e5, 1e5, mesh.n_elements)
    dt = 1.0
    matrix, rhs = model.assemble(width, width, pressure, dt, np.zeros(mesh.n_elements), pressure_iterate=pressure)
    # rows: outflow of every element = sum of its face fluxes (storage none: c_f = 0)
    outflow = np.zeros(mesh.n_elements)
    flux = model.face_flux(width, pressure)
    np.add.at(outflow, model.faces.first, flux)
    np.subtract.at(outflow, model.faces.second, flux)
    static = model.injection() + model.areas * width / dt
    np.testing.assert_allclose(matrix @ pressure - (rhs - static), outflow, rtol=1e-9, atol=1e-12 * np.abs(flux).max())
    # mass: the face terms cancel over the mesh
    assert abs(np.sum(matrix @ pressure - (rhs - static))) < 1e-12 * np.abs(flux).max()
    np.testing.assert_allclose(abs(matrix - matrix.T).max(), 0.0)
    # the derivative of every row along a random direction
    direction = rng.uniform(-1.0, 1.0, mesh.n_elements) * 1e2
    step = 1e-3

    def outflow_at(p):
        f = model.face_flux(width, p)
        out = np.zeros(mesh.n_elements)
        np.add.at(out, model.faces.first, f)
        np.subtract.at(out, model.faces.second, f)
        return out

    numeric = (outflow_at(pressure + step * direction) - outflow_at(pressure - step * direction)) / (2.0 * step)
    np.testing.assert_allclose(matrix @ direction, numeric, rtol=1e-5, atol=1e-9 * np.abs(numeric).max())


def test_flux_below_the_minimum_shear_rate_is_linear_and_continuous():
    mesh = hd.mesh.line([0, 0], [2.0, 0], 2)
    consistency, n, gamma0, width = 0.3, 0.5, 2.0, 1e-3
    fluid = Fluid(rheology="power-law", consistency=consistency, flow_index=n, minimum_shear_rate=gamma0)
    model = _model(mesh, fluid)
    # the wall shear rate of the power-law flow is (w |grad p| / (2 K))^(1/n): gamma0 at
    gradient0 = 2.0 * consistency * gamma0**n / width
    fluxes = [model.face_flux(np.full(2, width), np.array([g, 0.0]))[0] for g in gradient0 * np.array([0.25, 0.5])]
    assert fluxes[1] == pytest.approx(2.0 * fluxes[0], rel=1e-12)  # linear below
    at = model.face_flux(np.full(2, width), np.array([gradient0, 0.0]))[0]
    assert at == pytest.approx(slot_flux(width, gradient0, consistency, n), rel=1e-7)  # continuous at gamma0
    above = model.face_flux(np.full(2, width), np.array([4.0 * gradient0, 0.0]))[0]
    assert above == pytest.approx(slot_flux(width, 4.0 * gradient0, consistency, n), rel=1e-7)
    # a still fluid keeps a finite, positive conductance
    conductance, correction = model.power_law_conductance(np.full(2, width), np.zeros(2))
    assert conductance[0] > 0.0 and correction[0] == 0.0


def test_n1_power_law_rows_are_the_newtonian_rows():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 4.0, 4, 4)
    newtonian = _model(mesh, Fluid(viscosity=2e-3, compressibility=4e-10))
    power = _model(mesh, Fluid(rheology="power-law", consistency=2e-3, flow_index=1.0, compressibility=4e-10))
    assert power.fluid.viscosity_prime == newtonian.fluid.viscosity_prime
    rng = np.random.default_rng(7)
    width = rng.uniform(1e-4, 2e-4, 16)
    p_old, p_iterate = np.full(16, 5e6), 5e6 + rng.uniform(-1e5, 1e5, 16)
    a, ra = newtonian.assemble(width, width * 0.9, p_old, 2.0, np.zeros(16), pressure_iterate=p_iterate)
    b, rb = power.assemble(width, width * 0.9, p_old, 2.0, np.zeros(16), pressure_iterate=p_iterate)
    np.testing.assert_allclose(b.toarray(), a.toarray(), rtol=1e-13, atol=0.0)
    np.testing.assert_allclose(rb, ra, rtol=1e-13, atol=0.0)


def test_consistency_prime_is_twelve_k_at_n1_and_adachi_detournay_otherwise():
    fluid = Fluid(rheology="power-law", consistency=0.4, flow_index=0.5)
    assert fluid.viscosity_prime == pytest.approx(2.0**1.5 * 2.0**0.5 / 0.5**0.5 * 0.4, rel=1e-14)
    assert Fluid(viscosity=1e-3).viscosity_prime == pytest.approx(12e-3, rel=1e-15)
    # a power-law fluid given a viscosity takes K = mu
    assert Fluid(viscosity=1e-3, rheology="power-law", flow_index=0.7).consistency == 1e-3


@pytest.mark.parametrize("kwargs, field", [
    (dict(rheology="power-law", consistency=0.1, flow_index=1.5), "fluid.flow_index"),
    (dict(rheology="power-law", consistency=0.1, flow_index=0.0), "fluid.flow_index"),
    (dict(rheology="power-law", consistency=0.1, flow_index=-0.5), "fluid.flow_index"),
    (dict(rheology="power-law", consistency=0.0, flow_index=0.5), "fluid.consistency"),
    (dict(rheology="power-law", consistency=-1.0, flow_index=0.5), "fluid.consistency"),
    (dict(rheology="power-law", flow_index=0.5), "fluid.consistency"),
    (dict(rheology="power-law", consistency=0.1, viscosity=1e-3), "fluid.viscosity"),
    (dict(rheology="power-law", consistency=0.1, minimum_shear_rate=0.0), "fluid.minimum_shear_rate"),
    (dict(rheology="bingham", viscosity=1e-3), "fluid.rheology"),
    (dict(viscosity=1e-3, flow_index=0.5), "fluid.flow_index"),
    (dict(viscosity=1e-3, consistency=0.1), "fluid.consistency"),
    (dict(), "fluid.viscosity"),
])
def test_bad_fluids_are_refused_naming_the_field(kwargs, field):
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        Fluid(**kwargs)


def test_newtonian_transmissibility_is_refused_for_a_power_law_fluid():
    mesh = hd.mesh.line([0, 0], [2.0, 0], 2)
    model = _model(mesh, Fluid(rheology="power-law", consistency=0.1, flow_index=0.5))
    with pytest.raises(ValueError, match="power_law_conductance"):
        model.transmissibility(np.full(2, 1e-3))
