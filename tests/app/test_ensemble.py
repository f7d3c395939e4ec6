"""Seeded ensembles on Dask (hmatddm.app.ensemble): same numbers as a serial loop."""
import pytest

from hmatddm.app import ensemble
from hmatddm.errors import InputError

pytest.importorskip("dask.distributed")


def test_sweep_on_a_local_cluster_matches_serial_and_orders_results():
    grid = ensemble.parameter_grid(density=[0.05, 0.1], length_exponent=[2.0])
    rows = ensemble.sweep(grid, realizations=2, n_workers=2)
    assert [(r["density"], r["seed"]) for r in rows] == [(0.05, 0), (0.05, 1), (0.1, 0), (0.1, 1)]
    for row in rows:
        serial = ensemble.intersection_frequency_task({"density": row["density"], "length_exponent": 2.0}, row["seed"])
        assert row["intersection_frequency"] == serial["intersection_frequency"]
    table = ensemble.summarize(rows)
    assert len(table) == 2 and all(t["count"] == 2 for t in table)
    # denser networks are crossed more often along the y axis (ref. Fig. 6.9)
    assert table[1]["mean"] > table[0]["mean"]
    assert "intersection frequency" in ensemble.format_table(table)


def test_bad_grid_is_refused():
    with pytest.raises(InputError, match="grid axis"):
        ensemble.parameter_grid(density=[])
    with pytest.raises(InputError, match="realizations"):
        ensemble.sweep([{"density": 0.05}], realizations=0)


def test_sweep_command_prints_a_table(capsys):
    from hmatddm.app import cli

    assert cli.main(["sweep", "--realizations", "1", "--density", "0.05", "--length-exponent", "3",
                     "--workers", "1"]) == cli.EXIT_OK
    assert "| 3.0 | 0.05 |" in capsys.readouterr().out
