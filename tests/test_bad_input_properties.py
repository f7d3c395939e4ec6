"""Property-based bad input (issue: hard cases and reliability): any mutation of a valid
scene either validates or raises InputError naming a field; nothing else escapes."""
import copy
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import hmatddm as hd
import hmatddm.scene as hs
from hmatddm.errors import InputError
from hmatddm.scene.schema import validate

BASE = hs.load_scene("kgd").data
BAD_VALUES = st.one_of(st.none(), st.booleans(), st.text(max_size=5), st.just(math.nan), st.just(math.inf),
                       st.just(-math.inf), st.floats(allow_nan=True, allow_infinity=True),
                       st.integers(min_value=-10**12, max_value=10**12), st.lists(st.floats(), max_size=4),
                       st.dictionaries(st.text(max_size=3), st.integers(), max_size=2))


def _paths(node, prefix=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _paths(value, prefix + (key,))
    elif isinstance(node, list) and node and isinstance(node[0], dict):
        for i, value in enumerate(node):
            yield from _paths(value, prefix + (i,))
    else:
        yield prefix


PATHS = sorted(_paths(BASE), key=str)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(PATHS), BAD_VALUES, st.booleans()), min_size=1, max_size=3))
def test_scene_mutations_end_in_input_error_or_a_valid_scene(mutations):
    scene = copy.deepcopy(BASE)
    for path, value, delete in mutations:
        node = scene
        for key in path[:-1]:
            node = node[key]
        if delete:
            node.pop(path[-1], None)
        else:
            node[path[-1]] = value
    try:
        checked = validate(scene)
    except InputError as error:
        message = str(error)
        assert message and "\n" not in message.strip()
        return
    # a scene that validates must build without any other exception type
    try:
        hs.build_simulation(checked)
    except InputError:
        pass


def test_a_scene_too_large_to_mesh_is_refused_before_its_mesh_is_allocated():
    """The falsifying example hypothesis found: a fracture 5.4e9 m long with 0.25 m
    elements validates, and building it allocated 40 GiB (MemoryError) before
    numerics.max_elements was looked at."""
    scene = copy.deepcopy(BASE)
    scene["initial_fracture"][0]["p1"] = [0.0, 5419433851.0]
    with pytest.raises(InputError, match=r"more than numerics.max_elements = 200,000"):
        hs.build_simulation(validate(scene))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=32), min_size=1, max_size=12),
       st.sampled_from(["centers", "half_a", "e1", "load"]))
@example(values=[38528.0], field="half_a")  # two 77 km squares 3 m apart overlap: a zero pivot, then NaN
def test_api_arrays_with_bad_numbers_raise_input_error(values, field):
    mat = hd.Elastic(10e9, 0.25)
    centers = np.zeros((2, 3))
    centers[1, 0] = 3.0
    e1, e2 = np.tile([1.0, 0, 0], (2, 1)), np.tile([0.0, 1, 0], (2, 1))
    half = np.ones(2)
    arrays = dict(centers=centers, half_a=half, e1=e1)
    if field != "load":
        padded = np.resize(np.asarray(values, float), arrays[field].size).reshape(arrays[field].shape)
        arrays[field] = padded
    try:
        mesh = hd.Mesh3D.from_rectangles(arrays["centers"], arrays["e1"], e2, arrays["half_a"], half)
        load = np.resize(np.asarray(values, float), 6) if field == "load" else -np.ones(6)
        op = hd.ElasticityOperator(mesh, mat)
        dd = hd.solve(op, load)
        assert np.all(np.isfinite(dd))
    except InputError as error:
        assert str(error)


def test_checkpoints_and_scenes_are_read_without_executing_code(tmp_path):
    # checkpoints are numpy .npz read with allow_pickle=False plus JSON; scenes are TOML
    from hmatddm.simulation import checkpoint

    checkpoint.save(tmp_path, 1, {"x": np.arange(3)}, {"time": 1.0})
    npz = tmp_path / "step-000001.npz"
    np.savez(npz, x=np.array([object()], dtype=object))  # a pickled payload
    import hashlib
    import json

    meta = json.loads((tmp_path / "step-000001.json").read_text())
    meta["arrays_sha256"] = hashlib.sha256(npz.read_bytes()).hexdigest()
    (tmp_path / "step-000001.json").write_text(json.dumps(meta))
    try:
        checkpoint.load(tmp_path, 1)
    except (ValueError, checkpoint.CheckpointError):
        pass  # refused: object arrays need pickle
    else:
        raise AssertionError("a pickled checkpoint array was loaded")


def test_api_meshes_are_checked_where_they_are_used():
    """Empty meshes, mismatched array lengths and NaN put into a built mesh are named,
    not left to numpy or scipy (issue 19 item 9)."""
    import pytest

    mat = hd.Elastic(10e9, 0.25)
    empty = hd.Mesh3D(np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros(0), np.zeros(0), np.zeros(0, np.int64))
    with pytest.raises(InputError, match="mesh has no elements"):
        hd.ElasticityOperator(empty, mat)
    centers = np.array([[0.0, 0, 0], [3.0, 0, 0], [6.0, 0, 0]])
    with pytest.raises(InputError, match=r"half_a must have shape \(3\), got \(2,\)"):
        hd.Mesh3D.from_rectangles(centers, [1.0, 0, 0], [0, 1.0, 0], np.ones(2), 1.0)
    with pytest.raises(InputError, match=r"half_b must be a finite number, got nan"):
        hd.Mesh3D.from_rectangles(centers, [1.0, 0, 0], [0, 1.0, 0], 1.0, math.nan)
    mesh = hd.mesh.rectangle([0, 0, 0], [1, 0, 0], [0, 1, 0], 3, 3, 3, 3)
    mesh.centers[4, 1] = np.nan
    for backend in ("dense", "hmatrix"):
        with pytest.raises(InputError, match=r"mesh.centers\[4\] must be finite, got \[0.0, nan, 0.0\]"):
            hd.ElasticityOperator(mesh, mat, backend=backend)
    with pytest.raises(InputError, match=r"mesh.centers\[4\] must be finite"):
        hd.stress_at(mesh, mat, np.zeros((9, 3)), np.ones((1, 3)))
    line = hd.mesh.line([0.0, 0.0], [3.0, 0.0], 3)
    line.half_length[0] = -1.0
    with pytest.raises(InputError, match=r"mesh.half_length\[0\] must be > 0 m, got -1.0"):
        hd.Simulation(line, mat, hd.Fluid(1e-3), [hd.Cluster((1.5, 0.0), rate=1e-3)], -np.eye(2) * 1e6, 1.0)


def test_zero_injection_warns():
    import pytest

    from hmatddm.errors import NoInjectionWarning

    mesh = hd.mesh.line([0.0, 0.0], [3.0, 0.0], 3)
    with pytest.warns(NoInjectionWarning, match="every cluster injects at rate 0"):
        hd.Simulation(mesh, hd.Elastic(10e9, 0.25), hd.Fluid(1e-3), [hd.Cluster((1.5, 0.0), rate=0.0)],
                      -np.eye(2) * 1e6, 1.0)


def test_sweep_refuses_bad_values_before_starting_dask(capsys, monkeypatch):
    import dask.distributed

    from hmatddm.app import cli

    def no_cluster(*args, **kwargs):
        raise AssertionError("a Dask cluster was started for a refused grid")

    monkeypatch.setattr(dask.distributed, "LocalCluster", no_cluster)
    monkeypatch.setattr(dask.distributed, "Client", no_cluster)
    for argv, message in ((["--density", "-1"], "density must be > 0 1/m^2, got -1"),
                          (["--length-exponent", "0.5"], "length_exponent"),
                          (["--realizations", "0"], "realizations must be an integer >= 1, got 0")):
        assert cli.main(["sweep", *argv]) == cli.EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


# -- every key of every embedded scene, through the command line (issue 19 item 6) ---------

def _scene_keys():
    """``(scene, key)`` for every key of every embedded scene as `--set` writes it
    (``numerics.end_time``, ``cluster[1].rate``, ``dimension``), read from the scenes at run
    time, so that sections other sessions add are fuzzed too."""
    import tomllib

    keys = []
    for name in hs.embedded_names():
        raw = tomllib.loads(hs.embedded_text(name))
        for key, value in raw.items():
            if isinstance(value, dict):
                keys += [(name, f"{key}.{leaf}") for leaf in value]
            elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
                keys += [(name, f"{key}[{i}].{leaf}") for i, table in enumerate(value) for leaf in table]
            else:
                keys.append((name, key))
    return keys


SCENE_KEYS = _scene_keys()
# TOML literals: wrong types, non-finite, negative, huge and empty values
FUZZ_VALUES = ('"text"', "true", "[]", "{}", '""', "nan", "inf", "-inf", "-1", "-1e300", "1e300", "0",
               "123456789012345678901", '[1.0, "a"]', "[[1.0]]", "-0.5")


class _WouldRun(Exception):
    """Raised instead of running a scene that passed every check."""


def _run_mutated(scene, path, value):
    """``(exit code or None when the scene would run, stderr, files left in the working folder)``."""
    import contextlib
    import io
    import os
    import tempfile
    from unittest import mock

    from hmatddm.app import cli, runner

    with tempfile.TemporaryDirectory() as folder, contextlib.ExitStack() as stack:
        stack.enter_context(mock.patch.object(runner.SceneRun, "execute", side_effect=_WouldRun))
        stack.enter_context(mock.patch("hmatddm.elasticity.operator.ElasticityOperator.__init__",
                                       side_effect=AssertionError("an operator was built")))
        err = stack.enter_context(contextlib.redirect_stderr(io.StringIO()))
        stack.enter_context(contextlib.redirect_stdout(io.StringIO()))
        cwd = os.getcwd()
        os.chdir(folder)
        try:
            code = cli.main(["run", scene, "--out", "out", "--set", f"{path}={value}"])
        except _WouldRun:
            code = None
        finally:
            os.chdir(cwd)
        return code, err.getvalue().strip(), os.listdir(folder)


@settings(max_examples=250, deadline=None)
@given(st.sampled_from(SCENE_KEYS), st.sampled_from(FUZZ_VALUES))
@example(key=("stage", "well.diameter"), value="1e300")  # D^5 overflowed: an OverflowError, not a message
@example(key=("stage", "well.perforation_diameter"), value="1e300")  # d^4 the same
def test_fuzzed_scene_keys_are_refused_in_one_line_before_the_engine(key, value):
    """Every mutation of an embedded scene either passes every check (and would run) or
    is refused with exit code 2 and one line naming a scene key, without a traceback,
    before any operator or simulation is built, writing nothing."""
    import re

    scene, path = key
    code, message, leftovers = _run_mutated(scene, path, value)
    assert leftovers == [], leftovers  # nothing written (the run itself is not started here)
    if code is None:  # a valid scene: it reached the run
        return
    assert code == 2, (path, value, message)
    assert "Traceback" not in message and "\n" not in message, (path, value, message)
    assert message.startswith("hmatddm: error: "), message
    named = re.findall(r"\b[a-z_]+(?:\[\d+\])?\.[a-z_0-9]+\b", message) or [
        k for k in ("name", "description", "dimension", "height") if re.search(rf"\b{k}\b", message)]
    assert named, (path, value, message)


def test_every_scene_key_refuses_a_value_of_the_wrong_type_naming_itself():
    """A list of lists fits no key of any scene: every key of every embedded scene is
    refused with exit code 2 and one line naming that very key."""
    for scene, path in SCENE_KEYS:
        code, message, leftovers = _run_mutated(scene, path, "[[1.0]]")
        assert code == 2 and "\n" not in message and leftovers == [], (scene, path, message)
        assert path in message, (scene, path, message)
