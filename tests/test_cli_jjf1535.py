"""`plansim run jjf1535`, `plansim validate jjf1535` and the procedure in `plansim scenarios` (docs/jjf1535.md)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import plansim.io.scenario_file
import plansim.runner
from plansim import cli
from plansim.estimate.jjf1535_items import ITEMS
from plansim.io.scenario_file import load_scenario
from plansim.report.jjf1535 import GROUPS, ITEM_KEYS, LABELS, NOT_SIMULATED, SI_UNITS
from plansim.runner import jjf1535_run
from plansim.uncertainty.jjf1535_monte_carlo import FIGURE_ALSO, jjf1535_monte_carlo

TRIALS, SEED = 50, 3


def _run(capsys, *options: str) -> tuple[int, str, str]:
    code = cli.main(["run", "jjf1535", *options])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def no_simulation(monkeypatch):
    """Any Monte Carlo of JJF 1535 fails the test: bad input must be refused before the work starts."""

    def refuse(*args, **kwargs):
        raise AssertionError("the JJF 1535 Monte Carlo ran")

    monkeypatch.setattr(plansim.runner, "jjf1535_run", refuse)


def test_every_item_is_in_one_certificate_group_with_a_label_and_an_si_unit():
    grouped = [name for _title, names in GROUPS for name in names]
    assert sorted(grouped) == sorted(ITEMS) and len(set(grouped)) == len(grouped)
    assert set(LABELS) == set(ITEMS)
    assert {unit for _clause, _eq, unit, _scale in ITEMS.values()} <= set(SI_UNITS)


def test_the_text_report_groups_the_items_as_the_certificate_with_their_units(capsys):
    code, out, err = _run(capsys, "--trials", str(TRIALS), "--seed", str(SEED), "--quiet")
    assert code == 0 and err == ""
    assert f"scenario 'jjf2003': {TRIALS} trials, seed {SEED}, segment path" in out.splitlines()[0]
    titles = [title for title, _names in GROUPS] + ["Not in this Monte Carlo"]
    starts = [out.index(f"\n{title}\n") for title in titles]
    assert starts == sorted(starts), "the groups are out of order"
    sections = dict(zip(titles, [out[a:b] for a, b in zip(starts, starts[1:] + [len(out)])]))
    for title, names in GROUPS:
        for name in names:
            unit = ITEMS[name][2]
            line = next(line for line in sections[title].splitlines() if line.strip().startswith(LABELS[name]))
            assert f" {unit} " in line, line
    scale = sections["Scale factor items"]
    assert "Appendix A.1 U = 1.1e-03 (relative)" in scale and "coverage" in scale
    bias = sections["Bias items"]
    assert bias.count("Appendix A.2 U = 1.1e-03 (relative)") == 2  # B0 and the up/down mean
    assert "reported figure: mean" in bias  # the bias stability has no true value
    assert "angle random walk" in bias and "deg/sqrt(h)" in bias
    assert "reported figure: mean" in sections["Threshold, resolution, warm-up time"]  # a tested rate, its scatter
    assert "  bandwidth " in sections["Not in this Monte Carlo"]
    for item in ("threshold", "resolution", "warm-up time", "bias repeatability", "SF repeatability"):
        assert f"  {item} " not in sections["Not in this Monte Carlo"]
    assert len(NOT_SIMULATED) == 1


def test_the_json_has_stable_keys_and_the_numbers_of_the_python_summary_in_si(capsys):
    code, out, err = _run(capsys, "--trials", str(TRIALS), "--seed", str(SEED), "--quiet", "--json")
    assert code == 0 and err == ""
    doc = json.loads(out)
    assert {"procedure", "unit_scenario", "trials", "seed", "path", "units", "items", "angle_random_walk",
            "not_simulated", "plansim_version", "elapsed_s", "overrides"} <= set(doc)
    assert (doc["procedure"], doc["unit_scenario"], doc["trials"], doc["seed"]) == ("jjf1535", "jjf2003", TRIALS, SEED)
    rows = jjf1535_run("jjf2003", trials=TRIALS, seed=SEED).summary()  # the same seed: the same numbers
    assert [item["item"] for item in doc["items"]] == [r["item"] for r in rows]
    for item, row in zip(doc["items"], rows):
        assert tuple(item) == ITEM_KEYS
        scale = ITEMS[row["item"]][3]
        assert item["unit"] == SI_UNITS[row["unit"]]
        if "mean_error" in row:
            for key in ("truth", "mean_error", "std_error", "mc_U95"):
                assert item[key] == pytest.approx(row[key] * scale, rel=1e-12, abs=1e-300), (row["item"], key)
            if "mean" in row:  # threshold, resolution, warm-up time, the repeatabilities: the figure's scatter too
                assert row["item"] in FIGURE_ALSO
                assert item["figure"] == pytest.approx({k: row[k] * scale for k in ("mean", "std", "q025", "q975")},
                                                       rel=1e-12)
            else:
                assert item["figure"] is None
        else:
            assert all(item[key] is None for key in ("truth", "mean_error", "std_error", "mc_U95"))
            assert item["figure"] == pytest.approx({k: row[k] * scale for k in ("mean", "std", "q025", "q975")},
                                                   rel=1e-12)
        assert item["undetermined"] == row["undetermined"] == 0.0
        budgeted = ("budget_U", "coverage", "mean_relative_error", "std_relative_error", "mc_U95_relative")
        if "budget" in row:
            assert item["budget"] == row["budget"]
            assert all(item[key] == row[key] for key in budgeted)
        else:
            assert item["budget"] is None and all(item[key] is None for key in budgeted)
    assert {i["item"] for i in doc["items"] if i["budget"]} == {"scale_factor", "bias", "bias_up_down"}
    arw = doc["angle_random_walk"]
    assert arw["unit"] == "rad/s^0.5" and math.isclose(arw["reported"], arw["simulated"], rel_tol=0.15)


def test_progress_goes_to_stderr_unless_quiet(capsys):
    code, out, err = _run(capsys, "--trials", "20", "--seed", "1")
    assert code == 0 and "plansim run jjf1535 --unit jjf2003: 20/20 trials" in err and err.endswith("\n")
    assert "20/20" not in out


def test_unit_takes_a_toml_path_and_set_overrides_it(capsys, tmp_path):
    unit = tmp_path / "mylab.toml"
    unit.write_text((Path(plansim.io.scenario_file.builtin_scenarios()["linear_gaussian"])).read_text())
    code, out, err = _run(capsys, "--unit", str(unit), "--trials", "4", "--seed", "2", "--quiet", "--json",
                          "--set", "environment.latitude=\"30 deg\"")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["unit_scenario"] == "mylab" and doc["trials"] == 4
    assert doc["overrides"] == ['environment.latitude="30 deg"']


def test_the_monte_carlo_reports_progress_and_does_not_depend_on_its_chunks():
    unit = load_scenario("jjf2003")
    calls = []
    small = jjf1535_monte_carlo(unit, 20, 1, chunk_size=7, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(7, 20), (14, 20), (20, 20)]
    whole = jjf1535_monte_carlo(unit, 20, 1)
    assert np.array_equal(small.values, whole.values) and np.array_equal(small.truth, whole.truth, equal_nan=True)


@pytest.mark.parametrize("options, words", [
    (["--unit", "nosuch"], ["--unit 'nosuch'", "no built-in scenario", "jjf2003"]),
    (["--unit", "jjf1535"], ["--unit 'jjf1535'", "is a procedure"]),
    (["--trials", "0"], ["--trials 0", ">= 2"]),
    (["--trials", "1"], ["--trials 1", ">= 2"]),
    (["--seed", "-1"], ["--seed -1", ">= 0"]),
    (["--out", "r.nc"], ["--out 'r.nc'", "not available with the procedure jjf1535"]),
    (["--plot", "f.png"], ["--plot 'f.png'", "not available with the procedure jjf1535"]),
    (["--chunk-size", "8"], ["--chunk-size 8", "not available with the procedure jjf1535"]),
])
def test_bad_input_exits_2_naming_the_option_before_any_work(capsys, tmp_path, monkeypatch, no_simulation,
                                                            options, words):
    monkeypatch.chdir(tmp_path)
    code, out, err = _run(capsys, *options)
    assert code == 2 and out == "", err
    assert err.startswith("plansim: error: ") and err.count("\n") == 1, err
    for word in words:
        assert word in err, err
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_unit_is_refused_with_a_scenario_file(capsys, monkeypatch):
    monkeypatch.setattr(plansim.runner, "run_summary", lambda *a, **k: pytest.fail("the run started"))
    code = cli.main(["run", "jjf2003", "--unit", "ideal"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and "--unit 'ideal'" in err and "only with a procedure" in err


def test_validate_jjf1535_refuses_claims_saying_what_is_not_built_and_exits_2(capsys, monkeypatch):
    import plansim.uncertainty.jjf1535_validation as validation

    monkeypatch.setattr(validation, "validate_jjf1535", lambda *a, **k: pytest.fail("the validation started"))
    code = cli.main(["validate", "jjf1535", "--claims", "claims.toml"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.startswith("plansim: error: --claims: not available with 'plansim validate jjf1535'")
    assert "plansim run jjf1535 --claims" in err
    code = cli.main(["validate", "jjf2003", "--unit", "ideal"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and "--unit 'ideal'" in err and "only with a procedure" in err


def test_validate_jjf1535_compares_the_gum_with_the_monte_carlo_and_exits_0(capsys):
    """Two blocks of 50 trials (the shape of the report, not its statistics: tests/test_jjf1535_gum.py)."""
    from plansim.uncertainty.jjf1535_gum import GUM_ITEMS, NOT_PROPAGATED

    code = cli.main(["validate", "jjf1535", "--unit", "ideal", "--seed", "3", "--trials-per-block", "50",
                     "--max-trials", "100", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    assert d["procedure"] == "jjf1535" and d["unit_scenario"] == "ideal"
    assert d["mcm"]["trials"] == 100 and d["mcm"]["seed"] == 3 and d["mcm"]["blocks"] == 2
    assert [c["item"] for c in d["items"]] == list(GUM_ITEMS)
    for c in d["items"]:
        assert c["gum_u"] > 0 and c["mcm_u"] > 0 and c["u_ratio"] == pytest.approx(c["mcm_u"] / c["gum_u"])
        assert {"delta", "d_low", "d_high", "validated", "u_ratio_tolerance", "scatter_agrees", "coverage_gum",
                "coverage_verdict", "gum_U95", "mcm_low", "mcm_high"} <= set(c)
    assert [b["item"] for b in d["gum_budgets"]] == list(GUM_ITEMS)
    assert d["not_propagated"] == NOT_PROPAGATED
    code = cli.main(["validate", "jjf1535", "--unit", "ideal", "--seed", "3", "--trials-per-block", "50",
                     "--max-trials", "100", "--quiet", "--summary"])
    out, err = capsys.readouterr()
    assert code == 0 and err == "", err
    assert out.startswith("plansim validate jjf1535 — unit scenario 'ideal'")
    assert "GUM framework validated for" in out and "Not propagated" in out and "== scale_factor" not in out


def test_scenarios_lists_jjf1535_as_a_procedure_not_a_scenario_file(capsys):
    assert cli.main(["scenarios"]) == 0
    lines = capsys.readouterr().out.splitlines()
    (line,) = [line for line in lines if line.split()[0] == "jjf1535"]
    first = len(lines) - len(cli.simulation.EXPERIMENTS) - len(cli.simulation.PROCEDURES)
    assert line == lines[first]  # after the scenarios, the first procedure, before the experiments (vibration_g2)
    assert [entry.split()[0] for entry in lines[first:first + len(cli.simulation.PROCEDURES)]] == list(
        cli.simulation.PROCEDURES)
    assert "[procedure, not a scenario file: plansim run jjf1535 --unit SCENARIO] JJF 1535-2015" in line
    last = first + len(cli.simulation.PROCEDURES)
    assert all("[procedure" not in other for other in lines[:first] + lines[last:])
