"""The time loop (ref. Ch. 4): KGD and radial fractures against closed forms, the dense
twin, records, mass balance, checkpoints and resume after a kill."""
import json
import os

import numpy as np
import pytest

import hmatddm as hd
from conftest import kill_when_announced
from hmatddm.errors import InputError
from hmatddm.simulation import RECORD_KEYS, CheckpointError
from hmatddm.simulation import checkpoint as checkpoints

KGD = dict(shear_modulus=10e9, poisson_ratio=0.25, toughness=5e6, viscosity=1e-4, rate=5e-4, h=0.25)


def kgd_simulation(checkpoint_dir=None, backend="dense", scheme="krylov"):
    mat = hd.Elastic(KGD["shear_modulus"], KGD["poisson_ratio"])
    mesh = hd.mesh.line([-0.375, 0], [0.375, 0], 3)
    return hd.Simulation(mesh, mat, hd.Fluid(KGD["viscosity"], 4.5e-10), [hd.Cluster((0, 0), KGD["rate"], 0.01)],
                         far_field_stress=np.diag([0.0, -0.5e6]), time_step=1.0,
                         propagation=hd.Propagation(toughness=KGD["toughness"]), initial_pressure=0.6e6,
                         initial_opening=1e-5, backend=backend, scheme=scheme, checkpoint_dir=checkpoint_dir)


def radial_simulation(backend, h=2.0):
    mat = hd.Elastic(24e9, 0.25)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3 * h, 3 * h, 3, 3)
    return hd.Simulation(mesh, mat, hd.Fluid(1e-3, 4.4e-10), [hd.Cluster((0, 0, 0), 0.01, 0.005)],
                         far_field_stress=np.diag([0, 0, -8e6]), time_step=1.0,
                         propagation=hd.Propagation(toughness=5e6), initial_pressure=10e6,
                         initial_opening=1e-5, backend=backend, eps=1e-6), mat


@pytest.fixture(scope="module")
def kgd_run():
    sim = kgd_simulation()
    return sim, sim.run(20.0)


def test_kgd_toughness_dominated_matches_closed_form(kgd_run):
    sim, records = kgd_run
    mat = sim.material
    assert hd.analytical.kgd_regime(KGD["rate"], KGD["viscosity"], KGD["toughness"], mat) > 4  # K-vertex
    for record in records[9:]:
        length, width, pressure = hd.analytical.kgd_k_vertex(record["time"], KGD["rate"], KGD["toughness"], mat)
        # discrete growth: the length moves in steps of one element (h = 0.25 m on l ~ 5 m)
        assert abs(record["half_length"] / length - 1) < 0.06
        assert abs(record["max_opening"] / width - 1) < 0.06
        assert abs((record["wellbore_pressure"][0] - 0.5e6) / pressure - 1) < 0.10


def test_records_have_the_documented_keys_and_balance_mass(kgd_run):
    sim, records = kgd_run
    for record in records:
        assert set(RECORD_KEYS) <= set(record)
        json.dumps(record, allow_nan=False)
    last = records[-1]
    assert last["n_elements"] == sim.state.mesh.n_elements
    initial_volume = 0.75 * 1e-5
    # the fluid stored by compressibility is tiny here (c_f = 4.5e-10 1/Pa)
    np.testing.assert_allclose(last["fracture_volume"] - initial_volume, last["injected_volume"], rtol=2e-3)
    assert np.all(np.diff([r["n_elements"] for r in records]) >= 0)


def test_radial_fracture_dense_and_hmatrix_agree_and_follow_the_closed_form():
    results = {}
    for backend in ("dense", "hmatrix"):
        sim, mat = radial_simulation(backend)
        results[backend] = sim.run(20.0)
    dense, hmat = results["dense"], results["hmatrix"]
    assert [r["n_elements"] for r in dense] == [r["n_elements"] for r in hmat]
    for a, b in zip(dense, hmat):
        np.testing.assert_allclose(b["max_opening"], a["max_opening"], rtol=1e-5)
        np.testing.assert_allclose(b["wellbore_pressure"], a["wellbore_pressure"], rtol=1e-6)
    radius, width, _ = hd.analytical.radial_k_vertex(20.0, 0.01, 5e6, mat)
    # 2 m elements on a 12 m radius (staircase front); benchmarks/ has the refinement study
    assert abs(dense[-1]["radius"] / radius - 1) < 0.08
    assert abs(dense[-1]["max_opening"] / width - 1) < 0.15


def test_resume_reproduces_an_uninterrupted_run(tmp_path, kgd_run):
    _, full = kgd_run
    first = kgd_simulation(tmp_path / "ck")
    first.run(8.0)
    resumed = kgd_simulation(tmp_path / "ck")
    records = resumed.run(20.0, resume=True)
    assert len(records) == len(full)
    for a, b in zip(full, records):
        for key in RECORD_KEYS:
            if key != "solve_seconds":
                assert a[key] == b[key], key


def test_resume_after_sigkill_gives_identical_results(tmp_path, kgd_run):
    """Event-driven, so a busy machine cannot make it flaky: the child announces on
    stdout that step 6 is checkpointed and then waits; it is killed while waiting."""
    _, full = kgd_run
    folder = tmp_path / "killed"
    script = (
        "import sys, time; sys.path[:0] = [%r, %r]  # the test's folder, and tests/ for conftest\n"
        "import test_simulation as t\n"
        "def announce(sim, record):\n"
        "    if record['step'] == 6:\n"
        "        print('checkpointed', record['step'], flush=True)\n"
        "        time.sleep(3600)\n"
        "t.kgd_simulation(%r).run(20.0, callback=announce)\n"
        % (os.path.dirname(__file__), os.path.dirname(os.path.dirname(__file__)), str(folder)))
    announced = kill_when_announced(script)  # blocks until the checkpoint is on disk (or the child dies)
    assert announced.split() == ["checkpointed", "6"], announced
    assert checkpoints.list_checkpoints(folder)[-1] == 6
    resumed = kgd_simulation(folder)
    records = resumed.run(20.0, resume=True)
    assert [r["max_opening"] for r in records] == [r["max_opening"] for r in full]
    assert [r["wellbore_pressure"] for r in records] == [r["wellbore_pressure"] for r in full]


def test_damaged_checkpoint_falls_back_and_foreign_checkpoint_is_refused(tmp_path, caplog):
    folder = tmp_path / "ck"
    kgd_simulation(folder).run(4.0)
    steps = checkpoints.list_checkpoints(folder)
    newest = folder / f"step-{steps[-1]:06d}.npz"
    newest.write_bytes(newest.read_bytes()[:100])  # truncated
    sim = kgd_simulation(folder)
    sim.load_checkpoint()
    assert sim.state.step == steps[-2]
    assert "corrupted or truncated" in caplog.text
    other = kgd_simulation(folder, scheme="fully-coupled")
    with pytest.raises(CheckpointError, match="different run"):
        other.run(6.0, resume=True)


def test_unwritable_checkpoint_folder_is_reported_before_work(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    sim = kgd_simulation(blocker / "ck")
    with pytest.raises(CheckpointError, match="not writable"):
        sim.run(2.0)
    assert sim.records == []


@pytest.mark.parametrize("kwargs, field", [
    (dict(far_field_stress=np.zeros((3, 3))), "far_field_stress"),
    (dict(far_field_stress=np.array([[0.0, 1.0], [0.0, 0.0]])), "symmetric"),
    (dict(time_step=0.0), "time_step"),
    (dict(initial_opening=-1.0), "initial_opening"),
    (dict(backend="gpu"), "backend"),
    (dict(clusters=[]), "clusters"),
    (dict(scheme="magic"), "scheme"),
])
def test_bad_simulation_input(kwargs, field):
    args = dict(mesh=hd.mesh.line([-1, 0], [1, 0], 2), material=hd.Elastic(1e9, 0.2), fluid=hd.Fluid(1e-3),
                clusters=[hd.Cluster((0, 0), 1e-3)], far_field_stress=np.zeros((2, 2)), time_step=1.0)
    args.update(kwargs)
    with pytest.raises(InputError, match=field):
        hd.Simulation(**args)


def test_same_run_twice_gives_identical_numbers():
    # determinism: the H-matrix build, its parallel matvec (one writer per target
    # cluster) and GMRES are deterministic for a fixed thread count, so two runs agree
    # to the last bit
    runs = []
    for _ in range(2):
        sim, _ = radial_simulation("hmatrix", h=2.0)
        runs.append(sim.run(6.0))
    for a, b in zip(*runs):
        assert a["max_opening"] == b["max_opening"] and a["wellbore_pressure"] == b["wellbore_pressure"]
        assert a["n_elements"] == b["n_elements"]


@pytest.mark.parametrize("scheme", ["krylov", "fracture-compliance"])
def test_relaxation_grows_back_after_an_easy_step_in_the_coupled_schemes(monkeypatch, scheme):
    """A step that had to halve alpha leaves it halved for the next step; after a step
    without restart the coupled schemes double it again (up to the initial alpha), the
    segregated ones keep it (ref. Fig. 4.10). Before, one hard step in the 3D DFN benchmark
    left alpha at 1/8 for every later step (~140 iterations a step instead of ~10)."""
    from hmatddm.simulation import step_solve

    solve = step_solve.solve_step
    calls = []

    def solve_halving_once(problem, settings, dd, p, relaxation, provisional=False, splittable=False,
                           accelerate=False):
        calls.append(relaxation)
        dd, p, info = solve(problem, settings, dd, p, relaxation)  # converged: no pending part
        if len(calls) == 1:  # pretend the first solve needed one halving
            info = dict(info, relaxation=relaxation / 2.0, restarts=1)
        return dd, p, info

    monkeypatch.setattr(step_solve, "solve_step", solve_halving_once)
    sim = kgd_simulation(scheme=scheme)
    states = []
    for _ in range(3):
        sim.step()
        states.append(sim.state.relaxation)
    if scheme == "krylov":
        assert states == [0.5, 1.0, 1.0]
    else:  # never above the alpha of the step before
        assert states[0] == 0.5 and states[1] <= states[0] and states[2] <= states[1]
    assert hd.SchemeSettings(scheme=scheme).relaxation_growth == (2.0 if scheme == "krylov" else 1.0)
    with pytest.raises(InputError, match="relaxation_growth"):
        hd.SchemeSettings(scheme=scheme, relaxation_growth=0.5)


def test_checkpoint_metadata_encodes_each_record_once_and_reads_back(tmp_path):
    records = [{"step": k, "time": 0.5 * k, "b": [1, 2]} for k in range(3)]
    document = {"time": 1.5, "records": records, "fingerprint": "x"}
    encoded = {}
    text = checkpoints.metadata_text(document, encoded)
    assert json.loads(text) == document == json.loads(checkpoints.metadata_text(document))
    assert len(encoded) == 3
    records.append({"step": 3, "time": 1.5, "b": []})
    records[0]["time"] = 99.0  # an encoded record is not encoded again
    again = json.loads(checkpoints.metadata_text(document, encoded))
    assert len(encoded) == 4 and again["records"][0]["time"] == 0.0 and again["records"][3]["step"] == 3
    assert json.loads(checkpoints.metadata_text({"records": []})) == {"records": []}
    assert json.loads(checkpoints.metadata_text({"a": 1})) == {"a": 1}
    checkpoints.save(tmp_path, 4, {"x": np.arange(3)}, document, encoded=encoded)
    arrays, metadata = checkpoints.load(tmp_path, 4)
    assert metadata["records"][3] == records[3] and list(arrays["x"]) == [0, 1, 2]
