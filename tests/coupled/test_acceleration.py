"""Anderson acceleration of the coupled Picard iteration (hmatddm.coupled.acceleration):
on linear maps whose fixed point is known, and on a coupled step with contact, where the
accelerated solve must reach the plain solve's answer within the nonlinear tolerance."""
import numpy as np

from hmatddm.coupled import SchemeSettings, schemes
from hmatddm.coupled.acceleration import IterateMixing
from network_case import check_contact_conditions, network_simulation


def _iterate_linear(matrix, shift, alpha, mixing, iterations, n_u):
    """Iterate ``x <- x + alpha (M x + b - x)`` (split into a 'DD' and a 'pressure' part)
    with ``mixing`` (None: plain); the distance to the fixed point after each iterate."""
    exact = np.linalg.solve(np.eye(len(shift)) - matrix, shift)
    x = np.zeros(len(shift))
    errors = []
    for _ in range(iterations):
        g = x + alpha * (matrix @ x + shift - x)
        nxt = None if mixing is None else mixing.next(x[:n_u], x[n_u:], g[:n_u], g[n_u:])
        x = g if nxt is None else np.concatenate(nxt)
        errors.append(np.max(np.abs(x - exact)) / np.max(np.abs(exact)))
    return errors


def _map(eigenvalues, seed=0):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((len(eigenvalues), len(eigenvalues))))
    return q @ np.diag(eigenvalues) @ q.T, 1.0 + rng.random(len(eigenvalues))


def test_a_period_two_cycle_and_a_slow_mode_converge_accelerated():
    # the two ways the dfn-3cluster iteration at 4x its area lingered (benchmarks/RESULTS.md,
    # issue 33): an eigenvalue at -1 (a cycle of constant amplitude at alpha = 1) and one at
    # 0.93 (a creeping fill); the plain iteration gets nowhere in 30 iterates
    matrix, shift = _map([-1.0, 0.93, 0.2, 0.0, -0.1, 0.05])
    plain = _iterate_linear(matrix, shift, 1.0, None, 30, 3)
    mixing = IterateMixing(1e-6, 1e-6, memory=5)
    accelerated = _iterate_linear(matrix, shift, 1.0, mixing, 30, 3)
    assert plain[-1] > 1e-2
    assert min(accelerated[:12]) < 1e-10
    assert mixing.steps > 0


def test_the_mixing_restarts_when_a_residual_grows():
    mixing = IterateMixing(1.0, 1.0, memory=3)
    x, g = np.array([1.0]), np.array([0.5])
    assert mixing.next(x, x, g, g) is None  # a first iterate: the plain step
    assert mixing.next(g, g, 2.0 * g, 2.0 * g) is None  # its residual grew: restart, the plain step
    assert mixing.restarts == 1


def _contact_run(memory, monkeypatch):
    """The network case of network_case.py (elements fail remotely, join closed and slip: the
    contact active set of tests/coupled/test_contact.py) at a relaxation of 1/2, where the
    plain iteration contracts by 1/2 per iterate."""
    monkeypatch.setattr(schemes, "ANDERSON_MEMORY", memory)
    sim = network_simulation("dense")
    sim.settings = SchemeSettings(**{**sim.settings.__dict__, "relaxation": 0.5, "relaxation_growth": 1.0})
    records = sim.run(12.0)
    return sim, records


def test_an_accelerated_contact_run_reaches_the_plain_answer(monkeypatch):
    plain, plain_records = _contact_run(0, monkeypatch)
    fast, fast_records = _contact_run(schemes.ANDERSON_MEMORY or 5, monkeypatch)
    assert [r["n_elements"] for r in fast_records] == [r["n_elements"] for r in plain_records]
    assert plain_records[-1]["natural_active"] + plain_records[-1]["natural_failed"] >= 1
    assert plain_records[-1]["closed_elements"] >= 1
    np.testing.assert_array_equal(fast.state.contact_status, plain.state.contact_status)
    # the same answer within the nonlinear tolerance (1e-6 relative, of a relaxed iteration
    # at alpha = 1/2: within about tolerance / alpha)
    scale_u, scale_p = np.max(np.abs(plain.state.dd)), np.max(np.abs(plain.state.pressure))
    assert np.max(np.abs(fast.state.dd - plain.state.dd)) < 4e-6 * scale_u
    assert np.max(np.abs(fast.state.pressure - plain.state.pressure)) < 4e-6 * scale_p
    # ... in fewer nonlinear iterations
    total = [sum(r["nonlinear_iterations"] for r in rs[1:]) for rs in (plain_records, fast_records)]
    assert total[1] < total[0]
    # the accelerated answer satisfies the contact conditions
    check_contact_conditions(fast)
