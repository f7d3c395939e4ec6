"""Remote failure of natural fractures (hmatddm.simulation.natural, ref. Sec. 5.3): the
screened check (stress bound, margins kept from the last check) finds what the full check
finds, in 2D and 3D, over a sequence of growing meshes and changing DDs."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.fracture.crossing import NaturalFractureProperties
from hmatddm.simulation.natural import NaturalNetwork


def _scene(dim, rng):
    """Hydraulic fracture opened by 2 MPa, natural elements of random strike around it
    (near and far), properties close to failure."""
    mat = hd.Elastic(6.62e9, 0.25)
    if dim == 2:
        hf = hd.mesh.line([-5, 0], [5, 0], 20)
        centers = np.column_stack([rng.uniform(-25, 25, 400), rng.uniform(-25, 25, 400)])
        angle = rng.uniform(0, np.pi, 400)
        tangent = np.column_stack([np.cos(angle), np.sin(angle)])
        nf = hd.Mesh2D.from_segments(centers - 0.25 * tangent, centers + 0.25 * tangent)
        far = np.diag([-39.44e6, -35.85e6])
    else:
        hf = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 0, 1], 8.0, 4.0, 8, 4)
        centers = np.column_stack([rng.uniform(-12, 12, 400), rng.uniform(-12, 12, 400), rng.uniform(-3, 3, 400)])
        angle = rng.uniform(0, np.pi, 400)
        e1 = np.column_stack([np.cos(angle), np.sin(angle), np.zeros(400)])
        e2 = np.tile([0.0, 0.0, 1.0], (400, 1))
        nf = hd.Mesh3D.from_rectangles(centers, e1, e2, np.full(400, 0.25), np.full(400, 0.25))
        far = np.diag([-39.44e6, -35.85e6, -45e6])
    dd = hd.solve(hd.ElasticityOperator(hf, mat), -2e6 * hf.normals)
    props = NaturalFractureProperties(friction=0.25, cohesion=0.0, pore_pressure=30.2e6 * 0.98, skempton=0.5)
    return mat, hf, dd, nf, far, props


def _grown(hf, dim, extra):
    """``hf`` with ``extra`` elements appended beyond its +x end (same line/plane)."""
    if dim == 2:
        right = hf.endpoints[1][:, 0].max()
        return hd.mesh.concatenate([hf, hd.mesh.line([right, 0], [right + 0.5 * extra, 0], extra)])
    right = hf.centers[:, 0].max() + hf.half_a.max()
    part = hd.mesh.rectangle([right + 0.5 * extra, 0, 0], [1, 0, 0], [0, 0, 1], float(extra), 4.0, extra, 4)
    return hd.mesh.concatenate([hf, part])


@pytest.mark.parametrize("dim", [2, 3])
def test_screened_remote_failure_finds_what_the_full_check_finds(dim):
    rng = np.random.default_rng(3)
    mat, hf, dd, nf, far, props = _scene(dim, rng)
    network = NaturalNetwork(nf, props)
    intact = np.ones(nf.n_elements, bool)
    intact[:20] = False
    meshes = [(hf, dd), (hf, 1.3 * dd), (hf, 0.9 * dd)]
    grown = _grown(hf, dim, 2)
    grown_dd = np.vstack([1.3 * dd, np.tile(dd[-1], (grown.n_elements - hf.n_elements, 1))])
    meshes += [(grown, grown_dd), (grown, 1.1 * grown_dd)]
    meshes += [(hf.subset(np.arange(1, hf.n_elements)), dd[1:])]  # not an extension: the memory restarts
    used = []
    for mesh, d in meshes:
        full = NaturalNetwork(nf, props).remote_failure(mesh, d, mat, far, intact)
        info = {}
        screened = network.remote_failure(mesh, d, mat, far, intact, screen=True, info=info)
        failed = full[0]
        assert 0 < np.count_nonzero(failed) < np.count_nonzero(intact)
        assert np.array_equal(screened[0], failed)
        for full_values, values in zip(full[1:], screened[1:]):  # equal where evaluated, zero elsewhere
            evaluated = values != 0.0
            assert np.count_nonzero(evaluated) <= info["evaluated"]
            np.testing.assert_allclose(values[evaluated], full_values[evaluated], rtol=1e-12)
            np.testing.assert_allclose(values[failed], full_values[failed], rtol=1e-12)
        assert info["targets"] == np.count_nonzero(intact) and info["evaluated"] < info["targets"]
        used.append(info["memory"])
    assert used == [False, True, True, True, True, False]


def test_screen_needs_a_homogeneous_medium_of_constant_elements():
    from hmatddm.simulation.natural import _screenable

    mat = hd.Elastic(6.62e9, 0.25)
    assert _screenable(hd.mesh.line([-5, 0], [5, 0], 20), mat)
    assert not _screenable(hd.mesh.line([-5, 0], [5, 0], 20, element_order=1), mat)
    assert not _screenable(hd.mesh.line([-5, 0], [5, 0], 20), object())


def test_a_run_with_remote_failures_is_the_same_screened_or_not(monkeypatch):
    # the scene of test_contact.py: a weak, critically stressed natural fracture fails
    # remotely next to a pressurised crack; the run screens its checks, the reference
    # evaluates every target at every check
    def run():
        mat = hd.Elastic(10e9, 0.25)
        hf = hd.mesh.line([-2.0, 0.0], [2.0, 0.0], 8)
        a = np.deg2rad(30.0)
        center, tangent = np.array([3.0, 0.6]), np.array([np.cos(a), np.sin(a)])
        far_nf = hd.mesh.line([-30.0, 20.0], [30.0, 20.0], 40, fracture_id=1)  # far: cleared by the bound
        nf = hd.mesh.concatenate([hd.mesh.line(center - 1.0 * tangent, center + 1.0 * tangent, 4), far_nf])
        props = NaturalFractureProperties(friction=0.3, cohesion=0.0, tensile_strength=0.0, toughness=0.5e6,
                                          critical_radius=0.005, pore_pressure=5e6, skempton=0.5)
        sim = hd.Simulation(hf, mat, hd.Fluid(1e-3, 1e-9), [hd.Cluster((0, 0), 1e-3, 0.0)],
                            far_field_stress=np.diag([-14e6, -9e6]), time_step=1.0, initial_pressure=9.5e6,
                            initial_opening=1e-4, backend="dense", natural_fractures=nf, natural=props,
                            singular_correction="average", alpha=1.0)
        return sim, sim.run(3.0)

    screened, records = run()
    checks = []
    original = NaturalNetwork.remote_failure

    def unscreened(self, *args, screen=False, info=None, **kwargs):
        checks.append(screen)
        return original(self, *args, screen=False, info=info, **kwargs)

    monkeypatch.setattr(NaturalNetwork, "remote_failure", unscreened)
    reference, reference_records = run()
    assert checks and all(checks)  # the run screens
    assert records[-1]["natural_failed"] > 0 and screened.network.screen_memory is not None
    assert [r["natural_failed"] for r in records] == [r["natural_failed"] for r in reference_records]
    np.testing.assert_array_equal(screened.state.origin, reference.state.origin)
    np.testing.assert_array_equal(screened.state.pressure, reference.state.pressure)
    np.testing.assert_array_equal(screened.state.dd, reference.state.dd)
