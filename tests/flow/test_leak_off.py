"""Carter leak-off (ref. Eqs 4.25-4.26): the coefficient from the reservoir, in scenes,
and a plane-strain run through the K-K~ transition against the closed-form edge."""
import math
import tomllib

import numpy as np
import pytest

import hmatddm as hd
from hmatddm.analytical import kgd_toughness_leak_off_edge
from hmatddm.errors import InputError
from hmatddm.flow import carter_coefficient
from scene_texts import KGD_2D_HEAD

MD = 9.869233e-16  # m^2 per millidarcy


def test_coefficient_from_the_reservoir_counts_both_faces():
    k, phi, c, mu = 0.1 * MD, 0.15, 1e-9, 1e-3
    one_face = math.sqrt(k * phi * c / (math.pi * mu))  # ref. Eq. 4.26 as printed
    assert carter_coefficient(k, phi, c, mu) == pytest.approx(2 * one_face, rel=1e-15)
    assert carter_coefficient(k, phi, c, mu, faces=1) == pytest.approx(one_face, rel=1e-15)
    for kwargs, field in ((dict(permeability=0.0), "leak_off.permeability"), (dict(porosity=1.0), "leak_off.porosity"),
                          (dict(reservoir_viscosity=-1.0), "leak_off.reservoir_viscosity")):
        values = {**dict(permeability=k, porosity=phi, total_compressibility=c, reservoir_viscosity=mu), **kwargs}
        with pytest.raises(InputError, match=field):
            carter_coefficient(**values)


def test_scene_takes_the_reservoir_instead_of_the_coefficient():
    from hmatddm.scene import validate
    from hmatddm.scene.build import leak_off

    text = KGD_2D_HEAD + "end_time = 1.0\n[leak_off]\npore_pressure = 1e5\n"
    reservoir = text + "permeability = 1e-16\nporosity = 0.1\nreservoir_compressibility = 2e-9\nreservoir_viscosity = 5e-4\n"
    scene = validate(tomllib.loads(reservoir))
    assert leak_off(scene).coefficient == pytest.approx(carter_coefficient(1e-16, 0.1, 2e-9, 5e-4), rel=1e-14)
    assert validate(scene) == scene
    with pytest.raises(InputError, match="leak_off.coefficient"):
        validate(tomllib.loads(reservoir + "coefficient = 1e-12\n"))
    with pytest.raises(InputError, match="leak_off.porosity"):
        validate(tomllib.loads(reservoir.replace("porosity = 0.1\n", "")))
    assert leak_off(validate(tomllib.loads(text + "coefficient = 3e-12\n"))).coefficient == 3e-12


def test_kgd_through_the_k_to_k_tilde_transition():
    """Half the injected fluid leaks off by t = 10 s; the half-length follows the K-K~ edge
    (zero viscosity, Carter leak-off with the net pressure in it, benchmarks/bench_leak_off.py)."""
    material, s_hmin, rate, c_l, toughness = hd.Elastic(1e9, 0.25), 20e6, 1e-3, 1e-11, 1e6
    mesh = hd.mesh.line([-0.2, 0.0], [0.2, 0.0], 4)
    sim = hd.Simulation(mesh, material, hd.Fluid(viscosity=1e-5), [hd.Cluster((0.0, 0.0), rate=rate)],
                        -np.diag([2 * s_hmin, s_hmin]), 1.0, propagation=hd.Propagation(toughness=toughness),
                        leak_off=hd.LeakOff(coefficient=c_l, pore_pressure=0.0),
                        initial_pressure=s_hmin + 0.9 * toughness / math.sqrt(0.2 * math.pi), initial_opening=1e-5,
                        backend="dense")
    records = sim.run(end_time=10.0)
    t = np.array([r["time"] for r in records])
    length = np.array([r["half_length"] for r in records])
    edge, _ = kgd_toughness_leak_off_edge(t, rate, c_l, s_hmin, toughness, material.plane_strain_modulus)
    late = t >= 4.0
    assert np.max(np.abs(length[late] / edge[late] - 1.0)) < 0.04
    leaked = 1.0 - records[-1]["fracture_volume"] / records[-1]["injected_volume"]
    assert 0.4 < leaked < 0.6


def _viscous_leak_off_run(end_time, **options):
    """The M~ case of benchmarks/bench_leak_off.py (viscous, K_m 0.15, leak-off dominated)."""
    material, s_hmin = hd.Elastic(1e9, 0.25), 20e6
    mesh = hd.mesh.line([-0.2, 0.0], [0.2, 0.0], 4)
    sim = hd.Simulation(mesh, material, hd.Fluid(viscosity=0.02, compressibility=0.0),
                        [hd.Cluster((0.0, 0.0), rate=4e-3)], -np.diag([2 * s_hmin, s_hmin]), 1.0,
                        propagation=hd.Propagation(toughness=0.1e6),
                        leak_off=hd.LeakOff(coefficient=5e-11, pore_pressure=0.0),
                        initial_pressure=s_hmin + 0.9 * 0.1e6 / math.sqrt(0.2 * math.pi), initial_opening=1e-5,
                        backend="dense", **options)
    return sim, sim.run(end_time=end_time)


def test_viscous_leak_off_front_does_not_stall_when_tips_close():
    """With contact "all" the leaking tip elements close: the M~ fracture keeps growing
    towards the leak-off vertex Q t^1/2 / (pi C'), where with interpenetrating tip
    elements (contact "natural", the default) it stops at 3.55 m from t = 10 s
    (benchmarks/RESULTS.md, issue 36)."""
    sim, records = _viscous_leak_off_run(16.0, contact="all")
    t = np.array([r["time"] for r in records])
    length = np.array([r["half_length"] for r in records])
    net = np.array([r["wellbore_pressure"][0] for r in records]) - 20e6
    vertex = 4e-3 * np.sqrt(t) / (math.pi * 5e-11 * (20e6 + net))
    assert length[-1] > 4.0 and np.all(np.diff(length[t >= 8.0]) >= 0.0)
    assert np.all(np.abs(length[t >= 8.0] / vertex[t >= 8.0] - 1.0) < 0.15)  # ~18% of the fluid is stored
    assert min(r["min_opening"] for r in records) > -1e-9
    stalled, records = _viscous_leak_off_run(14.0)
    assert records[-1]["half_length"] < 3.6 and records[-1]["min_opening"] < -1e-3  # the overlap that stopped it
