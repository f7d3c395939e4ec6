"""Time steps that follow the front (numerics.time_step = "auto",
hmatddm/simulation/step_control.py): the controller, the front count, bad settings, a
KGD run against its closed form and the fixed-step run, and a resume that takes the
same steps."""
import numpy as np
import pytest

import hmatddm as hd
from hmatddm.errors import InputError
from hmatddm.mesh import topology
from hmatddm.scene import build_simulation, load_scene
from hmatddm.simulation.step_control import GROWTH, StepControl, advance_of_step, front_elements

KGD = dict(shear_modulus=10e9, poisson_ratio=0.25, toughness=5e6, viscosity=1e-4, rate=5e-4)


def kgd(time_step="auto", checkpoint_dir=None, **control):
    mat = hd.Elastic(KGD["shear_modulus"], KGD["poisson_ratio"])
    mesh = hd.mesh.line([-0.375, 0], [0.375, 0], 3)
    return hd.Simulation(mesh, mat, hd.Fluid(KGD["viscosity"], 4.5e-10), [hd.Cluster((0, 0), KGD["rate"], 0.01)],
                         far_field_stress=np.diag([0.0, -0.5e6]), time_step=time_step,
                         propagation=hd.Propagation(toughness=KGD["toughness"]), initial_pressure=0.6e6,
                         initial_opening=1e-5, backend="dense", checkpoint_dir=checkpoint_dir,
                         step_control=StepControl(**control) if control else None)


def test_the_next_step_follows_the_front_within_its_bounds():
    control = StepControl(advance=1.0, first=0.1, minimum=0.05, maximum=3.0)
    assert control.next_step(1.0, 1.0) == 1.0           # on target
    assert control.next_step(1.0, 4.0) == 1.0 / GROWTH  # too fast: at most halved
    assert control.next_step(1.0, 0.8) == pytest.approx(1.25)
    assert control.next_step(1.0, 0.0) == GROWTH        # no growth: doubled
    assert control.next_step(2.0, 0.0) == 3.0           # ... up to the longest step
    assert control.next_step(0.06, 10.0) == 0.05        # ... down to the shortest


def test_front_elements_are_those_with_an_uncovered_edge():
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3.0, 3.0, 3, 3)
    faces = topology.element_faces(mesh, topology.element_edges(mesh, 1.0))
    assert front_elements(faces, mesh.n_elements, 4) == 8  # all but the centre
    assert advance_of_step(16, 8) == 2.0 and advance_of_step(3, 0) == 0.0


@pytest.mark.parametrize("settings, key", [
    (dict(advance=0.0), "step_advance"), (dict(advance=-1.0), "step_advance"),
    (dict(minimum=-1.0), "min_time_step"), (dict(maximum=0.0), "max_time_step"),
    (dict(first=0.0), "first_time_step"), (dict(minimum=2.0, maximum=1.0), "min_time_step"),
    (dict(first=5.0, maximum=1.0), "first_time_step"),
])
def test_bad_step_settings_are_refused_naming_the_key(settings, key):
    with pytest.raises(InputError, match=key):
        StepControl(**settings)


def test_bad_step_settings_in_a_scene_name_the_key():
    with pytest.raises(InputError, match="numerics.step_advance"):
        load_scene("kgd", overrides=["numerics.time_step=auto", "numerics.step_advance=0"])
    with pytest.raises(InputError, match="numerics.time_step"):
        load_scene("kgd", overrides=["numerics.time_step=soon"])
    with pytest.raises(InputError, match="step_control"):
        kgd(time_step=1.0, advance=1.0)
    with pytest.raises(InputError, match="numerics.first_time_step must lie in"):  # refused before a build
        load_scene("kgd", overrides=["numerics.time_step=auto", "numerics.min_time_step=2"])
    with pytest.raises(InputError, match="numerics.min_time_step must be <= numerics.max_time_step"):
        load_scene("kgd", overrides=["numerics.time_step=auto", "numerics.min_time_step=2",
                                     "numerics.max_time_step=1"])


def test_auto_steps_reproduce_the_closed_form_and_the_fixed_steps():
    fixed = kgd(time_step=1.0).run(20.0)
    auto_simulation = kgd(first=0.1)
    auto = auto_simulation.run(20.0)
    steps = np.array([r["time_step"] for r in auto])
    assert auto[-1]["time"] == 20.0 and np.isclose(steps.sum(), 20.0)
    assert steps[0] == 0.1 and steps.max() <= GROWTH * 20.0
    assert np.all(steps[1:-1] <= GROWTH * steps[:-2] + 1e-12)
    mat = auto_simulation.material
    length, width, _ = hd.analytical.kgd_k_vertex(20.0, KGD["rate"], KGD["toughness"], mat)
    for records in (fixed, auto):
        assert abs(records[-1]["half_length"] / length - 1) < 0.06
        assert abs(records[-1]["max_opening"] / width - 1) < 0.06
    assert abs(auto[-1]["max_opening"] / fixed[-1]["max_opening"] - 1) < 0.03
    # the front crosses about one element per step: growth passes stay few per step
    growing = [r for r in auto if r["elements_added"] > 0]
    assert np.mean([r["growth_passes"] for r in growing]) <= 3


class _Stop(Exception):
    pass


def test_a_run_stopped_after_a_checkpoint_resumes_with_the_same_steps(tmp_path):
    full = kgd(first=0.1).run(12.0)

    def stop_at_step_6(simulation, record):  # the checkpoint of step 6 is on disk
        if record["step"] == 6:
            raise _Stop

    with pytest.raises(_Stop):
        kgd(first=0.1, checkpoint_dir=tmp_path).run(12.0, callback=stop_at_step_6)
    records = kgd(first=0.1, checkpoint_dir=tmp_path).run(12.0, resume=True)
    assert [r["time"] for r in records] == [r["time"] for r in full]
    assert [r["time_step"] for r in records] == [r["time_step"] for r in full]
    assert [r["max_opening"] for r in records] == [r["max_opening"] for r in full]


def test_a_scene_runs_with_auto_steps(tmp_path):
    scene = load_scene("kgd", overrides=["numerics.time_step=auto", "numerics.first_time_step=0.5",
                                         "numerics.end_time=6"])
    simulation = build_simulation(scene.data)
    records = simulation.run(6.0)
    assert simulation.step_control.first == 0.5 and records[0]["time_step"] == 0.5
    assert records[-1]["time"] == 6.0


def test_a_run_continued_past_its_end_time_keeps_the_pace_of_its_steps():
    """A step shortened to end at ``end_time`` does not shrink the next run's steps."""
    reference = kgd(first=0.1).run(8.0)
    k = len(reference) // 2
    planned = reference[k]["time_step"]
    end = reference[k - 1]["time"] + 0.05 * planned  # step k cut to 5% of its length
    simulation = kgd(first=0.1)
    simulation.run(end)
    assert simulation.records[-1]["time_step"] == pytest.approx(0.05 * planned)
    simulation.run(8.0)
    after = [r["time_step"] for r in simulation.records if r["time"] > end]
    assert after[0] >= 0.5 * planned  # without the planned step: at most 2 x 5%


def test_every_step_records_its_elasticity_products(monkeypatch):
    """``matvecs`` of a record counts the products with the elasticity operator its solves
    made: at least one per GMRES iteration (none here: the dense operator's exact Schur
    complement solves without one, and its residual checks are products), and all of them,
    against a count of the dense operator's products made apart (its ``_matvec``, patched
    here) over the run."""
    from hmatddm.elasticity.operator import ElasticityOperator

    calls = []
    original = ElasticityOperator._matvec
    monkeypatch.setattr(ElasticityOperator, "_matvec", lambda self, x: calls.append(1) or original(self, x))
    simulation = kgd(time_step=0.5)
    calls.clear()
    records = [simulation.step() for _ in range(4)]
    assert all(r["matvecs"] >= r["linear_iterations"] >= 0 and r["matvecs"] > 0 for r in records)
    assert sum(r["matvecs"] for r in records) == len(calls)


def test_a_step_that_does_not_converge_is_tried_again_at_half_its_length(monkeypatch):
    """With front-following steps a step whose solve raises ConvergenceError starts again
    from the same state at half its length (recorded in ``step_retries``) and the run goes
    on; at min_time_step the error reaches the caller."""
    from hmatddm.errors import ConvergenceError
    from hmatddm.simulation import step_solve

    original = step_solve.solve

    def refuses_long_steps(simulation, trial, start, t_old, t_new, *args):
        if t_new - t_old > 0.3:
            raise ConvergenceError("too long a step for this test", iterations=1)
        return original(simulation, trial, start, t_old, t_new, *args)

    monkeypatch.setattr(step_solve, "solve", refuses_long_steps)
    simulation = kgd(first=1.0, minimum=0.1)
    record = simulation.step()
    assert record["time_step"] == pytest.approx(0.25) and record["step_retries"] == 2
    assert record["time"] == pytest.approx(0.25) and simulation.state.step == 1
    reference = kgd(first=0.25, minimum=0.1)
    monkeypatch.setattr(step_solve, "solve", original)
    first = reference.step()
    np.testing.assert_array_equal(simulation.state.dd, reference.state.dd)  # the same step as a fresh 0.25 s one
    assert first["step_retries"] == 0
    monkeypatch.setattr(step_solve, "solve", refuses_long_steps)
    with pytest.raises(ConvergenceError):
        kgd(first=1.0, minimum=0.6).step()


def test_a_fixed_step_that_does_not_converge_is_split_and_the_run_stays_on_its_grid(monkeypatch):
    """A fixed step whose solve raises ConvergenceError is redone in halves from the same
    state (the 4x-area dfn-3cluster run at t = 27 s: an element filling from below the
    minimum width has no reachable solution over 1 s, two 0.5 s steps converge); the steps
    after it make up the rest of the fixed step, so the run comes back to its grid; past
    MAX_FIXED_STEP_SPLITS halvings the error reaches the caller."""
    from hmatddm.errors import ConvergenceError
    from hmatddm.simulation import simulation as simulation_module
    from hmatddm.simulation import step_solve

    original = step_solve.solve
    longest = [0.3]

    def refuses_long_steps(simulation, trial, start, t_old, t_new, *args):
        if t_new - t_old > longest[0]:
            raise ConvergenceError("too long a step for this test", iterations=1)
        return original(simulation, trial, start, t_old, t_new, *args)

    monkeypatch.setattr(step_solve, "solve", refuses_long_steps)
    simulation = kgd(time_step=1.0)
    records = simulation.run(2.0)
    times = [r["time"] for r in records]
    assert records[0]["time"] == 0.25 and records[0]["step_retries"] == 2
    assert 1.0 in times and times[-1] == 2.0  # back on the grid of 1 s steps, exactly
    assert all(r["time_step"] <= 0.3 for r in records) and simulation.state.time_step == 1.0
    longest[0] = 0.5 / 2.0 ** simulation_module.MAX_FIXED_STEP_SPLITS  # shorter than the shortest split
    with pytest.raises(ConvergenceError):
        kgd(time_step=1.0).step()


def test_a_failing_step_cut_to_end_at_end_time_is_halved_from_its_own_length(monkeypatch):
    """A step cut to end at ``end_time`` (0.4 s of a 1 s fixed step) that does not converge
    is tried again at half of itself, not at half the fixed step (0.5 s, cut to the same
    0.4 s: the identical solves again, seen on runs resumed to an end off their grid)."""
    from hmatddm.errors import ConvergenceError
    from hmatddm.simulation import step_solve

    original = step_solve.solve
    tried = []

    def refuses_long_steps(simulation, trial, start, t_old, t_new, *args):
        tried.append(round(t_new - t_old, 12))
        if t_new - t_old > 0.15:
            raise ConvergenceError("too long a step for this test", iterations=1)
        return original(simulation, trial, start, t_old, t_new, *args)

    monkeypatch.setattr(step_solve, "solve", refuses_long_steps)
    simulation = kgd(time_step=1.0)
    record = simulation.step(end_time=0.4)
    assert tried[:3] == [0.4, 0.2, 0.1]
    assert record["step_retries"] == 2 and record["time"] == pytest.approx(0.1)


def test_operators_count_each_product_once():
    """``products`` of an elasticity operator: one per matvec, one per column of a matmat,
    for the dense, H-matrix and grown operators alike."""
    from hmatddm.elasticity.extended import ExtendedElasticityOperator

    material = hd.Elastic(shear_modulus=10e9, poisson_ratio=0.25)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 8.0, 8.0, 8, 8)
    base = hd.ElasticityOperator(mesh.subset(np.arange(40)), material, backend="hmatrix", leaf_size=16)
    for operator in (hd.ElasticityOperator(mesh, material), base, ExtendedElasticityOperator(base, mesh)):
        X = np.random.default_rng(1).normal(size=(operator.shape[0], 3))
        operator @ X
        operator.matvec(X[:, 0])
        operator @ X[:, 1]
        assert operator.products == 5
