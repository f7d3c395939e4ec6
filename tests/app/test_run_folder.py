"""hmatddm.app.run_folder: the files of a run's output folder (a whole run through them:
tests/app/test_runner.py)."""
import math

import numpy as np
import pytest

from hmatddm.app import run_folder
from hmatddm.errors import InputError


def test_summary_round_trip_writes_plain_json_with_null_for_non_finite(tmp_path):
    document = {"steps": [{"time": np.float64(1.5), "n": np.int64(3), "bad": math.nan}],
                "array": np.arange(3), "inf": np.inf}
    run_folder.write_json(tmp_path / run_folder.SUMMARY, document)
    back = run_folder.read_summary(tmp_path)
    assert back == {"steps": [{"time": 1.5, "n": 3, "bad": None}], "array": [0, 1, 2], "inf": None}
    assert run_folder.read_summary(tmp_path / "nowhere") is None
    (tmp_path / run_folder.SUMMARY).write_text("{ half", encoding="utf-8")
    with pytest.raises(InputError, match="not a readable summary.json"):
        run_folder.read_summary(tmp_path)


def test_vtu_files_are_named_and_found_by_step(tmp_path):
    assert run_folder.vtu_name(7) == "vtu/step-000007.vtu"
    (tmp_path / run_folder.VTU_DIR).mkdir()
    for step in (12, 3, 7):
        (tmp_path / run_folder.vtu_name(step)).write_text("")
    (tmp_path / run_folder.VTU_DIR / "notes.txt").write_text("")
    assert list(run_folder.vtu_steps(tmp_path)) == [3, 7, 12]


def test_json_text_encodes_each_step_record_once_and_reads_back_as_plain_json():
    import json

    steps = [{"step": k, "time": np.float64(0.5 * k), "bad": math.nan} for k in range(3)]
    document = {"scene": {"name": "x", "list": [1, 2]}, "steps": steps, "reference": [{"time": 1.0}], "empty": []}
    encoded = {}
    plain = json.loads(run_folder.json_text(document))
    assert plain == {"scene": {"name": "x", "list": [1, 2]}, "reference": [{"time": 1.0}], "empty": [],
                     "steps": [{"step": k, "time": 0.5 * k, "bad": None} for k in range(3)]}
    assert json.loads(run_folder.json_text(document, encoded)) == plain
    assert len(encoded) == 3  # the step records only, not the reference's entries
    steps.append({"step": 3, "time": 1.5, "bad": 0.0})
    steps[0]["time"] = 99.0  # a written record is not encoded again: its first text stays
    again = json.loads(run_folder.json_text(document, encoded))
    assert len(encoded) == 4 and again["steps"][0]["time"] == 0.0 and again["steps"][3]["time"] == 1.5
    assert json.loads(run_folder.json_text(document))["steps"][0]["time"] == 99.0
    assert run_folder.json_text({}) == "{}"
