"""Anderson acceleration of the asymptotic front's fixed point
(hmatddm.simulation.front_acceleration): on a linear contraction, where the answer is known,
and on a 3D radial run against the plain relaxed iteration."""
import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.simulation.asymptotic import AsymptoticFront
from hmatddm.simulation.front_acceleration import front_mixing


def _iterate(g, x, accelerate, tolerance=1e-10, limit=500):
    mixing = front_mixing()
    for iteration in range(1, limit + 1):
        residual = g(x) - x
        if np.max(np.abs(residual)) < tolerance:
            return x, iteration
        step = mixing.step(x, residual) if accelerate else None
        x = x + (residual if step is None else step)
    return x, limit


def test_anderson_reaches_the_fixed_point_of_a_slow_contraction_in_few_iterations():
    rng = np.random.default_rng(7)
    q, _ = np.linalg.qr(rng.normal(size=(30, 30)))
    a = q @ np.diag(np.linspace(0.5, 0.97, 30)) @ q.T  # contraction, slowest mode 0.97
    b = rng.normal(size=30)
    exact = np.linalg.solve(np.eye(30) - a, b)

    def g(x):
        return a @ x + b

    plain, plain_iterations = _iterate(g, np.zeros(30), accelerate=False)
    fast, fast_iterations = _iterate(g, np.zeros(30), accelerate=True)
    assert np.allclose(plain, exact, atol=1e-8) and np.allclose(fast, exact, atol=1e-8)
    assert fast_iterations < plain_iterations / 5  # ~700 plain (0.97^k), tens accelerated


def test_a_residual_that_grows_restarts_the_history():
    mixing = front_mixing()
    assert mixing.step(np.zeros(3), np.ones(3)) is None  # the first iterate: the caller's step
    assert mixing.step(np.ones(3), 0.5 * np.ones(3)) is not None
    assert mixing.step(np.full(3, 1.5), 2.0 * np.ones(3)) is None and mixing.restarts == 1


def test_an_accelerated_3d_front_gives_the_plain_answer_in_fewer_iterations(monkeypatch):
    def run(accelerate):
        monkeypatch.setattr(AsymptoticFront, "accelerate", accelerate)
        # at the former tolerance 1e-3 the plain iteration's slow tail shows (at the default
        # 1e-2 the mixing saves 3 of 28 iterations here)
        scene = hs.load_scene("radial-k", overrides=["initial_fracture[0].element_size=0.5", "numerics.end_time=5",
                                                     "numerics.backend=dense", "propagation.front_tolerance=1e-3"])
        return hs.build_simulation(scene.data).run(5.0)

    plain, fast = run(False), run(True)
    assert sum(r["front_iterations"] for r in fast) < 0.8 * sum(r["front_iterations"] for r in plain)
    assert fast[-1]["radius"] == pytest.approx(plain[-1]["radius"], rel=2e-3)
    assert fast[-1]["max_opening"] == pytest.approx(plain[-1]["max_opening"], rel=5e-3)
