"""`hmatddm run` warns in one line when the [reference] closed form does not apply over the
run (issue 39): the tiny radial scene of the runner tests is ref. Table 4.1's K column,
whose K_m (1.8 at 1 s) is in the K-M transition, compared with the K-vertex."""
import io

import numpy as np
import pytest

import hmatddm.scene as hs
from hmatddm.app import runner
from scene_texts import RADIAL_3D_BODY

QUIET_OUTPUT = "\n[output]\nvtu = false\nsnapshots = false\n"


def test_run_warns_once_when_the_vertex_does_not_apply(tmp_path):
    text = 'name = "tiny-warn"\n' + RADIAL_3D_BODY.replace("end_time = 2.0", "end_time = 1.0") + QUIET_OUTPUT
    scene = hs.parse_scene(text)
    stream = io.StringIO()
    runner.run_scene(scene, tmp_path / "run", stream=stream)
    lines = [line for line in stream.getvalue().splitlines() if "warning: reference.kind" in line]
    assert len(lines) == 1
    # K_m = K' (t^2 / (mu'^5 Q^3 E'^13))^(1/18) at t = 1 s, written out here
    e_prime = 2.0 * 24e9 / 0.75
    k_m = np.sqrt(32.0 / np.pi) * 5e6 * (1.0 / (0.012**5 * 0.01**3 * e_prime**13)) ** (1.0 / 18.0)
    assert f"K_m = {k_m:.2f} between t = 1 and 1 s" in lines[0]
    assert "radial-km (Dontsov 2016" in lines[0]


def test_no_warning_where_the_vertex_applies(tmp_path):
    body = RADIAL_3D_BODY.replace("end_time = 2.0", "end_time = 1.0").replace("toughness = 5e6", "toughness = 11e6")
    text = 'name = "tiny-k"\n' + body + QUIET_OUTPUT
    stream = io.StringIO()
    runner.run_scene(hs.parse_scene(text), tmp_path / "run", stream=stream)
    assert "warning" not in stream.getvalue()


def test_the_record_holds_the_opening_weighted_mean_pressure():
    """``mean_pressure`` (the K-vertex comparison's pressure) against the state, summed here."""
    scene = hs.parse_scene('name = "tiny-mean"\n' + RADIAL_3D_BODY.replace("end_time = 2.0", "end_time = 1.0"))
    simulation = hs.build_simulation(scene.data)
    (record,) = simulation.run(1.0)
    state = simulation.state
    opening = np.clip(np.einsum("ij,ij->i", state.dd, state.mesh.normals), 0.0, None)
    weights = state.mesh.areas * opening
    expected = float(weights @ state.pressure / weights.sum())
    assert record["mean_pressure"] == pytest.approx(expected, rel=1e-12)
    assert min(state.pressure) <= record["mean_pressure"] <= max(state.pressure)
    assert record["mean_pressure"] < record["wellbore_pressure"][0]  # the well holds the viscous drop
