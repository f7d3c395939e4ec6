"""Finite-volume lubrication (ref. Eqs 4.27-4.40) against Poiseuille flow and balances."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.mesh import topology
from hmatddm.errors import InputError
from hmatddm.flow import Cluster, Fluid, LeakOff, LubricationModel, fracture_compliance


def _model(mesh, fluid, leak_off=LeakOff(), width_floor=1e-6, height=1.0, rate=1e-3, volume=0.0):
    faces = topology.element_faces(mesh, height=height)
    areas = mesh.areas * (height if mesh.dim == 2 else 1.0)
    return LubricationModel(areas=areas, normals=mesh.normals, faces=faces, fluid=fluid, leak_off=leak_off,
                            injection_elements=np.array([0]), injection_rates=np.array([rate]),
                            wellbore_volumes=np.array([volume]), minimum_width=width_floor)


def test_steady_channel_matches_poiseuille():
    # a 1D channel of uniform width: flux between the end cells = w^3 H dp / (mu' L)
    length, n, height, width = 10.0, 20, 2.0, 1e-3
    mesh = hd.mesh.line([0, 0], [length, 0], n)
    fluid = Fluid(viscosity=1e-3)
    model = _model(mesh, fluid, height=height)
    k = model.transmissibility(np.full(n, width))
    dx = length / n
    np.testing.assert_allclose(k, width**3 * height / (fluid.viscosity_prime * dx), rtol=1e-12)
    # linear pressure from 2 MPa to 1 MPa: every face carries the Poiseuille flux of the whole channel
    x = mesh.centers[:, 0]
    pressure = 2e6 - 1e6 * (x - x[0]) / (x[-1] - x[0])
    flux = k * (pressure[model.faces.first] - pressure[model.faces.second])
    np.testing.assert_allclose(flux, width**3 * height * 1e6 / (fluid.viscosity_prime * (x[-1] - x[0])), rtol=1e-12)


def test_size_jump_interpolates_the_face_width():
    # cells of length 1 and 3 side by side: the width at the face is interpolated linearly
    mesh = hd.Mesh2D.from_segments(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[1.0, 0.0], [4.0, 0.0]]))
    fluid = Fluid(viscosity=2e-3)
    model = _model(mesh, fluid)
    k = model.transmissibility(np.array([1e-3, 2e-3]))
    face_width = (1.5 * 1e-3 + 0.5 * 2e-3) / 2.0
    np.testing.assert_allclose(k, [face_width**3 / (fluid.viscosity_prime * 2.0)], rtol=1e-12)


def test_rows_conserve_mass_and_storage_balances():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 4.0, 4.0, 4, 4)
    fluid = Fluid(viscosity=1e-3, compressibility=4e-10)
    model = _model(mesh, fluid, volume=0.01)
    width = np.linspace(1e-4, 2e-4, mesh.n_elements)
    dt = 2.0
    matrix, rhs = model.assemble(width, width, np.full(16, 5e6), dt, np.zeros(16))
    # uniform pressure change: only storage responds (transmissibility rows sum to zero)
    storage = fluid.compressibility * (model.areas * width + model.wellbore_storage()) / dt
    np.testing.assert_allclose(matrix @ np.ones(16), storage, rtol=1e-9)
    np.testing.assert_allclose(abs(matrix - matrix.T).max(), 0.0)
    # with no width change and p = p_old, the rhs minus old width terms is the injection
    residual = matrix @ np.full(16, 5e6) - (rhs - model.areas * width / dt)
    np.testing.assert_allclose(residual.sum(), -1e-3, rtol=1e-9)


def test_carter_leak_off_integrates_exactly():
    mesh = hd.mesh.line([0, 0], [1, 0], 2)
    model = _model(mesh, Fluid(1e-3), leak_off=LeakOff(coefficient=1e-12, pore_pressure=1e6))
    creation = np.array([0.0, 3.0])
    rate = model.leak_off_rate(creation, 2.0, 4.0)
    # volume per unit pressure and area over the step: 2 c (sqrt(t1 - tau) - sqrt(t0 - tau))
    np.testing.assert_allclose(rate * 2.0, [2e-12 * (2.0 - np.sqrt(2.0)), 2e-12 * 1.0], rtol=1e-12)


def test_self_compliance_formula():
    mat = hd.Elastic(10e9, 0.25)
    line = hd.mesh.line([0, 0], [2, 0], 1)
    np.testing.assert_allclose(fracture_compliance(line, mat), np.pi * 0.75 * 1.0 / 10e9)
    square = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 2.0, 2.0, 1, 1)
    np.testing.assert_allclose(fracture_compliance(square, mat), np.pi * 0.75 / 10e9 / np.sqrt(2.0))


@pytest.mark.parametrize("make, field", [
    (lambda: Fluid(viscosity=0.0), "viscosity"),
    (lambda: Fluid(viscosity=1e-3, compressibility=-1.0), "compressibility"),
    (lambda: LeakOff(coefficient=-1e-9), "leak_off.coefficient"),
    (lambda: Cluster((0.0, 0.0), rate=-1.0), "cluster.rate"),
    (lambda: Cluster((0.0, 0.0, 0.0, 1.0), rate=1.0), "cluster.position"),
    (lambda: Cluster((0.0, 0.0), rate=1.0, wellbore_volume=float("nan")), "cluster.wellbore_volume"),
])
def test_bad_fluid_input_names_the_field(make, field):
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        make()
