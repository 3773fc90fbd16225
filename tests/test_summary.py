"""Summary runs (statistics streamed block by block) and streamed results files (issue 9 §2, "Memory")."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
import xarray as xr

import plansim
import plansim.runner as runner
from plansim.config import parse_scenario
from plansim.io.results import ResultsFile
from plansim.report.summary import RunStatistics, appendix_a_comparisons
from plansim.report.table import parameter_summary
from plansim.uncertainty import APPENDIX_A, compare_with_appendix_a

TRIALS = 3000


@pytest.fixture(scope="module")
def scenario():
    return plansim.load_scenario("jjf2003")


@pytest.fixture(scope="module")
def per_trial(scenario):
    return plansim.run(scenario, trials=TRIALS, seed=17)


@pytest.fixture(scope="module")
def summary(scenario):
    return runner.run_summary(scenario, trials=TRIALS, seed=17, chunk_size=333)


def _close(a, b, rtol=1e-12, atol=0.0):
    """|a − b| <= rtol·|b| + atol, elementwise (atol may be an array)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert np.all(np.abs(a - b) <= rtol * np.abs(b) + atol), np.max(np.abs(a - b) / (rtol * np.abs(b) + atol))


def test_the_summary_moments_are_those_of_the_trials(per_trial, summary):
    error, truth = per_trial["error"].values, per_trial["truth"].values
    std = np.std(error, axis=0, ddof=1)
    _close(summary["error_std"].values, std)
    # a mean near zero against its spread: compare to the rounding of a sum of the errors
    _close(summary["error_mean"].values, np.mean(error, axis=0), atol=1e-13 * std)
    _close(summary["truth_mean"].values, np.mean(truth, axis=0), atol=1e-13 * np.std(truth, axis=0))
    np.testing.assert_array_equal(summary["error_min"].values, error.min(axis=0))
    np.testing.assert_array_equal(summary["error_max"].values, error.max(axis=0))


def test_the_summary_quantiles_are_numpys_exactly(per_trial, summary):
    error = per_trial["error"].values
    for k in range(error.shape[1]):
        assert summary["error_quantile"].values[k, 0] == np.quantile(error[:, k], 0.025)
        assert summary["error_quantile"].values[k, 1] == np.quantile(error[:, k], 0.975)
        assert summary["abs_error_q95"].values[k] == np.quantile(np.abs(error[:, k]), 0.95)


def test_the_summary_gives_the_appendix_a_comparison_of_the_trials(scenario, per_trial, summary):
    expected = compare_with_appendix_a(per_trial["truth"].values, per_trial["estimate"].values, scenario)
    got = appendix_a_comparisons(summary, scenario)
    assert [c.item for c in got] == [c.item for c in expected]
    for g, e in zip(got, expected):
        # counts, quantiles, the verdict and everything printed from the budget: identical
        for key in ("item", "quantity", "reading_unit", "parameters", "n", "budget_U", "mc_U95", "coverage",
                    "tolerance", "overstatement_factor", "verdict", "arithmetic_U"):
            assert getattr(g, key) == getattr(e, key), (e.item, key)
        _close(g.mc_u, e.mc_u)
        _close(g.ratio, e.ratio)
        _close(g.mc_bias, e.mc_bias, atol=1e-13 * e.mc_u)
        for gp, ep in zip(g.per_parameter, e.per_parameter):
            assert (gp.name, gp.U95, gp.coverage) == (ep.name, ep.U95, ep.coverage)
            _close(gp.std, ep.std)
            _close(gp.mean, ep.mean, atol=1e-13 * ep.std)
            _close(gp.reading_unit_in_si, ep.reading_unit_in_si)
            _close(gp.budget_U_si, ep.budget_U_si)


def test_few_trials_give_the_same_appendix_a_verdicts(scenario):
    """With few trials the verdict says so; the summary must say the same."""
    trials = plansim.run(scenario, trials=20, seed=2)
    expected = compare_with_appendix_a(trials["truth"].values, trials["estimate"].values, scenario)
    got = appendix_a_comparisons(runner.run_summary(scenario, trials=20, seed=2, chunk_size=3), scenario)
    assert [(c.item, c.verdict, c.coverage, c.mc_U95, c.n) for c in got] == \
        [(c.item, c.verdict, c.coverage, c.mc_U95, c.n) for c in expected]


def test_parameter_summary_reads_a_summary_as_it_reads_the_trials(per_trial, summary):
    for a, b in zip(parameter_summary(summary), parameter_summary(per_trial)):
        assert (a["name"], a["unit"]) == (b["name"], b["unit"])
        _close(a["std_error"], b["std_error"])
        _close(a["mean_error"], b["mean_error"], atol=1e-13 * b["std_error"])


def _without_time(dataset: xr.Dataset) -> xr.Dataset:
    dataset = dataset.copy()
    dataset.attrs.pop("created_utc")
    return dataset


@pytest.mark.parametrize("chunk_size", [1, 4096])
def test_the_summary_does_not_depend_on_the_chunk_size(scenario, summary, chunk_size):
    other = runner.run_summary(scenario, trials=TRIALS, seed=17, chunk_size=chunk_size)
    xr.testing.assert_identical(_without_time(other), _without_time(summary))


def test_the_summary_keeps_the_provenance_of_run(per_trial, summary):
    for key, value in per_trial.attrs.items():
        if key not in ("created_utc", "title"):
            assert summary.attrs[key] == value, key
    assert summary["error_std"].attrs["units"].startswith("SI") and "long_name" in summary["error_std"].attrs


@pytest.mark.parametrize("n", [1, 2, 3, 5, 20, 21, 39, 40, 41, 99, 101, 4097, 9001])
def test_kept_tails_give_numpys_quantiles_for_any_count_with_ties(scenario, n):
    rng = np.random.default_rng(n)
    truth = rng.normal(size=(n, 39))
    estimate = truth + np.round(rng.normal(size=(n, 39)), 1)  # many ties
    statistics = RunStatistics(scenario, n, budgets=())
    for start in range(0, n, 1000):
        statistics.add(start, truth[start:start + 1000], estimate[start:start + 1000])
    result = statistics.dataset({"trials": n})
    error = estimate - truth
    for k in range(39):
        assert result["error_quantile"].values[k, 0] == np.quantile(error[:, k], 0.025)
        assert result["error_quantile"].values[k, 1] == np.quantile(error[:, k], 0.975)
        assert result["abs_error_q95"].values[k] == np.quantile(np.abs(error[:, k]), 0.95)


def test_one_trial_has_no_spread_and_no_appendix_a(scenario):
    summary = runner.run_summary(scenario, trials=1, seed=3)
    assert np.all(np.isnan(summary["error_std"].values)) and "item" not in summary.dims
    assert appendix_a_comparisons(summary, scenario) == []
    assert all(row["std_error"] == 0.0 for row in parameter_summary(summary))


# ----------------------------------------------------------------------------- streamed results files

def test_a_streamed_results_file_holds_the_trials_of_run(tmp_path, scenario, per_trial, summary):
    path = tmp_path / "r.nc"
    streamed = runner.run_summary(scenario, trials=TRIALS, seed=17, chunk_size=333, out=path)
    xr.testing.assert_identical(_without_time(streamed), _without_time(summary))
    with xr.open_dataset(path) as ds:
        for name in ("truth", "estimate", "error"):
            assert np.array_equal(ds[name].values, per_trial[name].values), name
            assert ds[name].attrs == per_trial[name].attrs
        assert set(ds.variables) == set(per_trial.variables)
        np.testing.assert_array_equal(ds["trial"].values, np.arange(TRIALS))
        for name in per_trial.coords:
            assert list(ds[name].values) == list(per_trial[name].values), name
        for key, value in per_trial.attrs.items():
            if key != "created_utc":
                assert ds.attrs[key] == value, key
    assert [p.name for p in tmp_path.iterdir()] == ["r.nc"]


def test_a_results_file_reruns_from_its_attributes_whatever_the_chunk_size(tmp_path):
    """Re-running a results file needs its scenario TOML, seed, trials and path, not its chunk size."""
    path = tmp_path / "r.nc"
    runner.run_summary("jjf2003", trials=700, seed=9, chunk_size=7, out=path)
    with xr.open_dataset(path) as ds:
        scenario = parse_scenario(tomllib.loads(ds.attrs["scenario_toml"]), name=ds.attrs["scenario"])
        again = plansim.run(scenario, trials=int(ds.attrs["trials"]), seed=int(ds.attrs["seed"]),
                            path=ds.attrs["simulation_path_requested"], chunk_size=333)
        for name in ("truth", "estimate", "error"):
            assert np.array_equal(again[name].values, ds[name].values), name
        assert "chunk_size" not in ds.attrs


@pytest.mark.parametrize("exception", [KeyboardInterrupt, RuntimeError])
def test_an_interrupted_streamed_run_leaves_no_file(tmp_path, exception):
    def interrupt(done, total):
        if done >= 200:
            raise exception("stop")

    with pytest.raises(exception):
        runner.run_summary("jjf2003", trials=600, seed=1, chunk_size=100, progress=interrupt, out=tmp_path / "r.nc")
    assert list(tmp_path.iterdir()) == []


def test_a_results_file_left_without_commit_is_removed(tmp_path):
    with ResultsFile(tmp_path / "r.nc") as out:
        runner.run_summary("ideal", trials=3, seed=1, out=out)
        assert len(list(tmp_path.iterdir())) == 1  # the temporary file, complete, not yet committed
    assert list(tmp_path.iterdir()) == []
    with ResultsFile(tmp_path / "r.nc") as out:
        runner.run_summary("ideal", trials=3, seed=1, out=out)
        out.commit()
    assert [p.name for p in tmp_path.iterdir()] == ["r.nc"]


def test_a_results_file_in_a_missing_folder_is_refused_before_the_run(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        runner.run_summary("ideal", trials=3, seed=1, out=tmp_path / "missing" / "r.nc")


def test_a_results_file_that_will_not_fit_on_disk_is_refused(tmp_path, monkeypatch):
    import shutil
    from collections import namedtuple

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(10**6, 0, 10**6))
    with pytest.raises(ValueError, match=r"trials = 3000: the results file .* needs about .* GB free"):
        runner.run_summary("ideal", trials=3000, seed=1, out=tmp_path / "r.nc")
    assert list(tmp_path.iterdir()) == []


# ----------------------------------------------------------------------------- memory and trials

def test_a_run_that_will_not_fit_in_memory_is_refused_naming_the_trials_the_estimate_and_the_limit(monkeypatch):
    monkeypatch.setattr(runner, "available_memory", lambda: 600 * 2**20)
    with pytest.raises(ValueError, match=r"trials = 1000000: this run needs about 1\.\d+ GB of memory "
                                         r"\(per-trial arrays .*\), more than the 0\.629 GB available"):
        plansim.run("jjf2003", trials=1_000_000, seed=1)
    # the statistics alone fit where the arrays did not
    needed = sum(runner.estimate_memory(plansim.load_scenario("jjf2003"), 1_000_000, keep_trials=False).values())
    assert needed < 600 * 2**20
    with pytest.raises(ValueError, match=r"trials = 100000000: this run needs about"):
        runner.run_summary("jjf2003", trials=100_000_000, seed=1)


def test_the_memory_estimate_counts_the_arrays_a_run_keeps():
    sc = plansim.load_scenario("jjf2003")
    per_trial = runner.estimate_memory(sc, 1_000_000)
    assert per_trial["per-trial arrays (truth, estimate, error)"] == 3 * 1_000_000 * 39 * 8
    means = runner.estimate_memory(sc, 1000, keep_segment_means=True)["segment means"]
    assert means == 1000 * len(sc.schedule) * 6 * 8
    assert runner.available_memory() is None or runner.available_memory() > 0


@pytest.mark.parametrize("function", [plansim.run, runner.run_summary])
@pytest.mark.parametrize("trials, exception", [(0, ValueError), (-1, ValueError), (1.5, TypeError),
                                               (False, TypeError)])
def test_both_runs_check_the_trials(function, trials, exception):
    with pytest.raises(exception, match=rf"trials = {trials!r}"):
        function("ideal", trials=trials, seed=1)


def test_budgets_must_be_appendix_a_budgets():
    with pytest.raises(TypeError, match="not an AppendixABudget"):
        runner.run_summary("ideal", trials=3, seed=1, budgets=["A.1"])
    summary = runner.run_summary("ideal", trials=3, seed=1, budgets=APPENDIX_A[:2])
    assert list(summary["item"].values) == ["A.1", "A.2"]


def test_a_per_trial_dataset_is_written_in_the_same_layout(tmp_path, per_trial, scenario):
    from plansim.io.results import write_results

    streamed, written = tmp_path / "streamed.nc", tmp_path / "written.nc"
    runner.run_summary(scenario, trials=TRIALS, seed=17, out=streamed)
    with_means = plansim.run(scenario, trials=TRIALS, seed=17, keep_segment_means=True)
    write_results(with_means, written)
    with xr.open_dataset(streamed) as a, xr.open_dataset(written) as b:
        assert "segment_mean" not in b and "segment" not in b.coords
        a.attrs.pop("created_utc"), b.attrs.pop("created_utc")
        xr.testing.assert_identical(a, b)


# ----------------------------------------------------------------------------- plansim run

def test_plansim_run_keeps_no_trial_without_plot(capsys, monkeypatch, tmp_path):
    """`plansim run` (and `--out`) go through the summary: plansim.run, which keeps every trial, is not called."""
    from plansim.cli import main

    def refuse(*args, **kwargs):
        raise AssertionError("plansim run kept every trial")

    monkeypatch.setattr(runner, "run", refuse)
    out = tmp_path / "r.nc"
    assert main(["run", "jjf2003", "--trials", "300", "--seed", "5", "--quiet", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Kgxx" in text and "A.5" in text and "wrote results" in text
    assert out.read_bytes()[:8] == b"\x89HDF\r\n\x1a\n"  # NetCDF-4, streamed
    monkeypatch.undo()
    expected = plansim.run("jjf2003", trials=300, seed=5)
    with xr.open_dataset(out) as ds:
        for name in ("truth", "estimate", "error"):
            assert np.array_equal(ds[name].values, expected[name].values), name
