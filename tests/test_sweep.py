"""plansim sweep: the grid file, the JJF 2003 compliance rules, the sweep Dataset, its executors and the command."""

from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest
import xarray as xr

import plansim
from plansim.cli import main
from plansim.io.scenario_file import load_scenario
from plansim.planning import sweep as sweep_module
from plansim.planning.grid import ZIP_DIMENSION, cell_seed, load_grid, parse_grid, toml_value
from plansim.planning.sweep import pareto_front, sweep
from plansim.report.sweep import CELL_KEYS, JSON_KEYS
from plansim.runner import run
from plansim.schedule.builders import jjf2003
from plansim.schedule.compliance import RULES, jjf2003_compliance

GRID = {"vary": {"schedule.dwell": ["10 s", "30 s"], "schedule": {"positions": [6, 12]}}}
FIVE = ["-100 deg/s", "-20 deg/s", "0 deg/s", "20 deg/s", "100 deg/s"]


# --- the grid file -------------------------------------------------------------------------------------------------

def test_dotted_keys_and_nested_tables_are_the_same_field():
    grid = parse_grid(GRID)
    assert [d.name for d in grid.dimensions] == ["schedule.dwell", "schedule.positions"]
    assert grid.shape == (2, 2) and grid.size == 4
    cells = list(grid.cells())
    assert cells[1] == ((0, 1), ['schedule.dwell="10 s"', "schedule.positions=12"])


def test_zip_fields_change_together_along_one_dimension():
    grid = parse_grid({"vary": {"schedule.dwell": ["30 s"]},
                       "zip": {"schedule.rate_points": [FIVE, FIVE[:2] + FIVE[3:]],
                               "schedule.omega_squared_rate": ["100 deg/s", "50 deg/s"]}})
    assert grid.shape == (1, 2) and grid.dimensions[1].name == ZIP_DIMENSION
    _, overrides = list(grid.cells())[1]
    assert overrides[2] == 'schedule.omega_squared_rate="50 deg/s"'
    assert overrides[1].startswith('schedule.rate_points=["-100 deg/s", "-20 deg/s", "20 deg/s"')


@pytest.mark.parametrize("document, words", [
    ({"vary": {"schedule.dwell": "30 s"}}, "non-empty list"),
    ({"vary": {"schedule.dwell": []}}, "non-empty list"),
    ({"vary": {"schedule.dwell": ["30 s", "30 s"]}}, "listed twice"),
    ({"vary": {}}, "no field varies"),
    ({"varry": {"schedule.dwell": ["30 s"]}}, "unknown table"),
    ({"zip": {"schedule.dwell": ["30 s", "60 s"], "schedule.positions": [6]}}, "one length"),
    ({"vary": {"schedule.dwell": ["30 s"]}, "zip": {"schedule.dwell": ["60 s"]}}, "both in [vary] and [zip]"),
])
def test_bad_grids_are_refused_naming_what_is_wrong(document, words):
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
        parse_grid(document)


def test_a_grid_file_that_is_missing_or_not_toml_is_named(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        load_grid(tmp_path / "none.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[vary\n", encoding="utf-8")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_grid(bad)


@pytest.mark.parametrize("value", ["60 s", 'a "quoted" text', 6, 2.5, True, ["-5 deg/s", "5 deg/s"], [1, [2, 3]]])
def test_a_value_written_back_reads_as_itself(value):
    assert tomllib.loads(f"v = {toml_value(value)}")["v"] == value


def test_a_cells_seed_depends_on_its_fields_and_the_base_seed_only():
    a = ['schedule.dwell="10 s"', "schedule.positions=12"]
    assert cell_seed(1, a) == cell_seed(1, list(a))
    assert 0 <= cell_seed(1, a) < 2**63
    assert len({cell_seed(1, a), cell_seed(2, a), cell_seed(1, a[:1]), cell_seed(1, a[::-1])}) == 4


# --- JJF 2003 §7.2 compliance --------------------------------------------------------------------------------------

RATES = [math.radians(w) for w in (-100, -50, -20, -5, 0, 5, 20, 50, 100)]


def test_the_specifications_schedule_is_compliant_and_each_rule_can_fail():
    assert jjf2003_compliance(jjf2003(RATES, math.radians(100))).compliant
    cases = {
        "twelve_positions": jjf2003(RATES, math.radians(100), positions=6),
        "dwell": jjf2003(RATES, math.radians(100), dwell=29.0),
        "rate_points": jjf2003(RATES[::2], math.radians(100)),            # 5 points
        "maximum_both_directions": jjf2003(RATES[1:], math.radians(100)),  # -50 ... +100
    }
    for rule, schedule in cases.items():
        c = jjf2003_compliance(schedule)
        assert [name for name, ok in c.rules.items() if not ok] == [rule]
        assert c.failed() == [RULES[rule]]
    twelve = [math.radians(w) for w in range(-125, 126, 25)]  # 11 points: allowed; 12 are not
    assert jjf2003_compliance(jjf2003(twelve, math.radians(100))).rules["rate_points"]
    assert not jjf2003_compliance(jjf2003(twelve + [math.radians(1)], math.radians(100))).rules["rate_points"]
    assert jjf2003_compliance(jjf2003(RATES, math.radians(100))).max_rate == pytest.approx(math.radians(100))


# --- the sweep -----------------------------------------------------------------------------------------------------

def test_a_predicted_sweep_is_the_prediction_of_each_cells_scenario_and_its_table_time():
    """Each cell's u_predicted is plansim.predict of the scenario with the cell's overrides, to the bit; the table
    time is (dwell + settle) × segments: 12 or 6 positions + 9 rate points × 3 axes + 6 ω² records, settle 10 s."""
    ds = sweep("jjf2003", GRID, trials=0)
    assert ds["u_predicted"].dims == ("schedule.dwell", "schedule.positions", "parameter")
    assert "u_mc" not in ds and "coverage" not in ds
    for i, dwell in enumerate(("10 s", "30 s")):
        for j, positions in enumerate((6, 12)):
            sc = load_scenario("jjf2003", [f'schedule.dwell="{dwell}"', f"schedule.positions={positions}"])
            np.testing.assert_array_equal(ds["u_predicted"].values[i, j], plansim.predict(sc).u_predicted.values)
            assert ds["table_time_s"].values[i, j] == (positions + 27 + 6) * (float(dwell.split()[0]) + 10.0)
            assert bool(ds["compliant_jjf2003"].values[i, j]) == (dwell == "30 s" and positions == 12)
    assert ds["u_group"].sel(group="Bg").values[1, 1] == ds["u_predicted"].values[1, 1, 9:12].max()
    assert list(ds["parameter"].values[9:12]) == ["Bgx", "Bgy", "Bgz"]


def test_the_monte_carlo_of_a_cell_is_plansim_run_with_the_cells_seed():
    ds = sweep("linear_gaussian", {"vary": {"schedule.positions": [6, 12]}}, trials=300, seed=5)
    sc = load_scenario("linear_gaussian", ["schedule.positions=6"])
    seed = int(ds["seed"].values[0])
    assert seed == cell_seed(5, ["schedule.positions=6"])
    e = run(sc, trials=300, seed=seed)["error"].values
    np.testing.assert_array_equal(ds["u_mc"].values[0], e.std(axis=0, ddof=1))
    np.testing.assert_array_equal(ds["bias_mc"].values[0], e.mean(axis=0))
    np.testing.assert_array_equal(ds["coverage"].values[0],
                                  np.mean(np.abs(e) <= ds["U_predicted"].values[0], axis=0))


def test_a_cells_numbers_do_not_depend_on_the_grid_around_it():
    a = sweep("linear_gaussian", {"vary": {"schedule.dwell": ["10 s", "30 s"]}}, trials=50)
    b = sweep("linear_gaussian", {"vary": {"schedule.dwell": ["30 s", "20 s", "10 s"]}}, trials=50)
    for key in ("u_mc", "bias_mc", "u_predicted", "seed"):
        xr.testing.assert_identical(a[key].sel({"schedule.dwell": "10 s"}), b[key].sel({"schedule.dwell": "10 s"}))


def test_serial_and_threads_give_the_same_dataset_to_the_bit():
    grid = {"vary": {"schedule.dwell": ["10 s", "20 s", "30 s"]}}
    serial = sweep("linear_gaussian", grid, trials=200)
    threads = sweep("linear_gaussian", grid, trials=200, executor="threads", workers=2)
    xr.testing.assert_identical(serial, threads)


def test_a_two_process_dask_cluster_gives_the_same_dataset_to_the_bit():
    pytest.importorskip("dask.distributed", reason="the optional extra plansim[dask] is not installed")
    grid = {"vary": {"schedule.dwell": ["10 s", "20 s", "30 s"]}}
    serial = sweep("linear_gaussian", grid, trials=200)
    dask = sweep("linear_gaussian", grid, trials=200, executor="dask", workers=2)
    xr.testing.assert_identical(serial, dask)


def test_a_cell_that_does_not_load_is_named_before_any_work(monkeypatch):
    calls = []
    monkeypatch.setattr(sweep_module, "evaluate_cell", lambda *a: calls.append(a))
    with pytest.raises(ValueError, match=r"sweep cell schedule.positions=7: .*positions"):
        sweep("jjf2003", {"vary": {"schedule.positions": [6, 7]}}, trials=0)
    assert calls == []


@pytest.mark.parametrize("executor", ["serial", "threads"])
def test_a_cell_that_fails_is_named_and_nothing_is_returned(monkeypatch, executor):
    real = sweep_module.evaluate_cell

    def failing(scenario, index, *rest):
        if index == (1,):
            raise ArithmeticError("a singular design")
        return real(scenario, index, *rest)

    monkeypatch.setattr(sweep_module, "evaluate_cell", failing)
    with pytest.raises(ValueError, match=r'sweep cell schedule.dwell="20 s" failed: ArithmeticError: a singular'):
        sweep("linear_gaussian", {"vary": {"schedule.dwell": ["10 s", "20 s", "30 s"]}}, trials=0,
              executor=executor, workers=2)


def test_a_cell_that_fails_on_a_dask_worker_is_named_whatever_its_batch():
    """A worker's batch returns a failed cell in place of its result (and stops there); the submitting side
    raises the named error for that cell, not for the batch."""
    from plansim.planning import dask_executor

    def cell(scenario, index):
        if index == (1,):
            raise ArithmeticError("a singular design")
        return index

    out = dask_executor._batch(cell, [(None, (0,)), (None, (1,)), (None, (2,))])
    assert out[0] == (0,) and len(out) == 2

    class Finished:
        def result(self):
            return out

    with pytest.raises(ValueError, match=r"cell \(1,\): ArithmeticError: a singular design"):
        dask_executor._gather(Finished(), lambda index, e: ValueError(f"cell {index}: {type(e).__name__}: {e}"))


@pytest.mark.parametrize("kwargs, words", [
    ({"executor": "gpu"}, "executor = 'gpu'"), ({"workers": 0}, "workers = 0"), ({"trials": -1}, "trials = -1"),
    ({"trials": 2.5}, "trials = 2.5"), ({"scheduler": "tcp://x:1"}, "only with executor = 'dask'"),
    ({"grid": [1]}, "grid: expected"),
])
def test_bad_arguments_are_refused_naming_the_field(kwargs, words):
    with pytest.raises((ValueError, TypeError), match=words.replace("(", r"\(")):
        sweep("linear_gaussian", **{"grid": {"vary": {"schedule.dwell": ["10 s"]}}, **kwargs})


def test_the_pareto_front_is_the_cells_no_other_beats():
    rng = np.random.default_rng(4)
    cost, value = rng.integers(0, 6, 40).astype(float), rng.integers(0, 6, 40).astype(float)
    front = pareto_front(cost, value)
    for k in range(40):
        beaten = any(cost[m] <= cost[k] and value[m] <= value[k] and (cost[m] < cost[k] or value[m] < value[k])
                     for m in range(40))
        assert front[k] == (not beaten)
    assert not pareto_front([1.0, np.nan], [np.nan, 1.0]).any()


def test_the_pareto_front_allows_for_the_monte_carlo_scatter():
    # with standard errors, a cell is only beaten by one as cheap and better by more than z·√(se_a² + se_b²), or
    # cheaper and not worse by that much (brute force against the rule, z = 2)
    rng = np.random.default_rng(5)
    cost, value = rng.integers(0, 6, 40).astype(float), rng.normal(1.0, 0.05, 40)
    se = np.full(40, 0.02)
    front = pareto_front(cost, value, se)
    for k in range(40):
        beaten = False
        for m in range(40):
            margin = 2.0 * np.hypot(se[m], se[k])
            if cost[m] <= cost[k] and value[m] <= value[k] + margin and (
                    cost[m] < cost[k] or value[m] < value[k] - margin):
                beaten = True
        assert front[k] == (not beaten)
    assert front.any()  # the cheapest of the best is always on it
    # a cell 1 % better but within the scatter does not push a cheaper one off, nor stay on the front itself
    assert pareto_front([1, 2], [1.00, 0.99], standard_error=[0.01, 0.01]).tolist() == [True, False]
    assert pareto_front([1, 2], [1.00, 0.90], standard_error=[0.01, 0.01]).tolist() == [True, True]
    with pytest.raises(ValueError, match="standard_error"):
        pareto_front([1, 2], [1, 2], standard_error=[-1, 0])


# --- the command ---------------------------------------------------------------------------------------------------

def _grid_file(tmp_path):
    path = tmp_path / "grid.toml"
    path.write_text('[vary]\n"schedule.dwell" = ["10 s", "30 s"]\nschedule.positions = [6, 12]\n', encoding="utf-8")
    return path


def test_plansim_sweep_writes_its_dataset_and_figure_and_prints_json(tmp_path, capsys):
    grid = _grid_file(tmp_path)
    out, plot = tmp_path / "s.nc", tmp_path / "s.png"
    assert main(["sweep", "linear_gaussian", "--grid", str(grid), "--trials", "100", "--out", str(out),
                 "--plot", str(plot), "--json", "--executor", "threads"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert tuple(k for k in doc if k != "elapsed_s") == JSON_KEYS
    assert len(doc["cells"]) == 4 and tuple(doc["cells"][0]) == CELL_KEYS
    assert doc["grid"] == {"schedule.dwell": ["10 s", "30 s"], "schedule.positions": [6, 12]}
    with xr.open_dataset(out) as saved:
        expected = sweep("linear_gaussian", load_grid(grid), trials=100)
        xr.testing.assert_allclose(saved["u_mc"], expected["u_mc"], rtol=0, atol=0)
        assert saved.attrs["trials_per_cell"] == 100
    assert plot.stat().st_size > 10_000


def test_plansim_sweep_prints_a_table_per_cell(tmp_path, capsys):
    assert main(["sweep", "--grid", str(_grid_file(tmp_path)), "--predict-only", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "4 cells, the prediction only" in text
    assert "schedule.dwell=30 s; schedule.positions=12" in text and "no: dwell, twelve_positions" in text


@pytest.mark.parametrize("extra, words", [
    (["--trials", "0"], "--trials 0"), (["--workers", "0"], "--workers 0"),
    (["--scheduler", "tcp://x:1"], "only with --executor dask"), (["--set", "schedule.positions=7"], "positions"),
])
def test_plansim_sweep_refuses_bad_input_and_writes_nothing(tmp_path, capsys, extra, words):
    out = tmp_path / "s.nc"
    assert main(["sweep", "--grid", str(_grid_file(tmp_path)), "--out", str(out), *extra]) == 2
    assert words in capsys.readouterr().err
    assert not out.exists() and list(tmp_path.iterdir()) == [tmp_path / "grid.toml"]


def test_the_example_grid_of_the_docs_loads_every_cell():
    """docs/examples/schedules.grid.toml (docs/planning.md): 2 positions × 4 dwells × 3 rate-point lists, each
    cell a valid jjf2003 scenario; 7, 9 and 11 points, all compliant at 12 positions and 30 s."""
    from pathlib import Path

    from plansim.planning.sweep import cell_scenarios

    grid = load_grid(Path(__file__).resolve().parent.parent / "docs" / "examples" / "schedules.grid.toml")
    assert grid.shape == (2, 4, 3)
    cells = cell_scenarios("jjf2003", grid)
    assert len(cells) == 24
    compliant = [index for index, _, sc in cells if jjf2003_compliance(sc.schedule).compliant]
    assert compliant == [(1, d, z) for d in (1, 2, 3) for z in range(3)]
