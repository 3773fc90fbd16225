"""plansim plan: targets, the search for the shortest schedule, its Monte Carlo verification, the CLI.

Reference values: the scenario's own prediction (targets equal to it are met by the scenario's own schedule, so
the plan can be no longer), the JJF 2003 §7.2 rules (plansim.schedule.compliance) and, in the slow test, the
issue's acceptance: targets equal to the default's achieved U, met in a Monte Carlo.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

import plansim
from plansim.cli import main
from plansim.model.parameters import PARAMETER_INDEX, PARAMETERS, parameter
from plansim.planning.plan import Target, allowance, parse_targets, plan, predicted_U
from plansim.schedule.compliance import jjf2003_compliance

EXAMPLE = "docs/examples/targets.toml"


def own_targets(scenario, scale: float = 1.0) -> dict[str, Target]:
    U = predicted_U(scenario)
    return {p.name: Target(p.name, scale * float(U[i]), "the scenario's own prediction")
            for i, p in enumerate(PARAMETERS)}


# ------------------------------------------------------------------------------------------- targets
def test_targets_groups_parameters_and_units():
    scenario = plansim.load_scenario("jjf2003")
    targets = parse_targets({"targets": {"Bg": "10 deg/h", "Bgx": "5 deg/h", "Kg": 2e-5}}, scenario)
    assert set(targets) == {"Bgx", "Bgy", "Bgz"} | {p.name for p in PARAMETERS if p.group == "Kg"}
    assert targets["Bgx"].U == pytest.approx(5 * parameter("Bgx").display_factor)  # the parameter beats its group
    assert targets["Bgy"].U == pytest.approx(math.radians(10) / 3600)
    assert targets["Kgxy"].U == 2e-5


def test_targets_from_appendix_a_are_its_27_printed_claims():
    scenario = plansim.load_scenario("jjf2003")
    targets = parse_targets({"targets": {"from_appendix_a": True}}, scenario)
    assert len(targets) == 27
    assert all(t.U > 0 and "Appendix A" in t.source for t in targets.values())


@pytest.mark.parametrize("document, error, message", [
    ({"targets": {"Bq": "1 deg/h"}}, ValueError, "'Bq'"),
    ({"targets": {"Bg": "1 m/s"}}, ValueError, "targets.Bg"),
    ({"targets": {"Bg": "-1 deg/h"}}, ValueError, "> 0"),
    ({"targets": {"from_appendix_a": "yes"}}, TypeError, "from_appendix_a"),
    ({"targets": {}}, ValueError, "no target"),
    ({"goals": {}}, ValueError, r"\[targets\]"),
])
def test_bad_targets_are_refused_naming_the_field(document, error, message):
    with pytest.raises(error, match=message):
        parse_targets(document, plansim.load_scenario("jjf2003"))


def test_allowance_is_bonferroni():
    assert allowance(1) == pytest.approx(1.6449, abs=1e-4)
    assert allowance(39) == pytest.approx(3.0157, abs=1e-3)


# ------------------------------------------------------------------------------------------- the search
@pytest.fixture(scope="module")
def gaussian_plan():
    scenario = plansim.load_scenario("linear_gaussian")
    return scenario, plan(scenario, own_targets(scenario))


def test_plan_is_no_longer_than_the_schedule_that_set_the_targets(gaussian_plan):
    scenario, result = gaussian_plan
    assert result.table_time <= scenario.schedule.duration
    assert result.table_time == result.scenario.schedule.duration
    for name, target in result.targets.items():
        assert result.predicted[name] <= target.U * (1 + 1e-12)


def test_removing_any_segment_of_the_plan_breaks_a_target(gaussian_plan):
    scenario, result = gaussian_plan
    assert len(result.removable) == len(result.scenario.schedule)
    assert not [why for why in result.removable if why.startswith("nothing")]
    # checked independently for one segment of each test: remove it, predict again
    index = np.array([PARAMETER_INDEX[n] for n in result.targets])
    limit = np.array([t.U for t in result.targets.values()])
    segments = result.scenario.schedule.segments
    for test in ("multi_position", "rate", "omega_squared"):
        k = next(i for i, s in enumerate(segments) if s.test == test)
        smaller = dataclasses.replace(result.scenario.schedule, segments=segments[:k] + segments[k + 1:])
        try:
            plansim.estimate.check_design(smaller)
        except ValueError:
            continue  # the estimators cannot reduce it: broken
        U = predicted_U(dataclasses.replace(result.scenario, schedule=smaller))
        assert np.max(U[index] / limit) > 1.0


def test_compliant_plan_keeps_the_rules_and_costs_time(gaussian_plan):
    scenario, free = gaussian_plan
    ruled = plan(scenario, free.targets, compliant=True)
    assert jjf2003_compliance(ruled.scenario.schedule).compliant
    assert ruled.table_time >= free.table_time
    assert ruled.time_with_rules == ruled.table_time and ruled.time_without_rules == pytest.approx(free.table_time)
    assert free.time_with_rules == pytest.approx(ruled.table_time)


def test_targets_below_the_floors_are_refused_naming_them():
    scenario = plansim.load_scenario("jjf2003")
    targets = own_targets(scenario)
    targets["Kaxx"] = Target("Kaxx", targets["Kaxx"].U / 3, "a third of the quantiser floor")
    with pytest.raises(ValueError, match=r"Kaxx \(3"):
        plan(scenario, targets)


def test_monte_carlo_verification_of_a_plan():
    # linear_gaussian: the GUM holds, the Monte Carlo U agrees with the prediction (within the family-wise
    # allowance of its standard error, tests in tests/test_predict.py); 400 trials keep it short
    scenario = plansim.load_scenario("linear_gaussian")
    result = plan(scenario, own_targets(scenario, 1.1), trials=400, seed=5)
    assert result.trials == 400 and result.rounds >= 1
    met = result.met_in_monte_carlo()
    assert all(met.values()) or result.rounds == 4  # rounds exhausted would be reported, not hidden
    for U_mc, se in result.monte_carlo.values():
        assert 0 < se < U_mc


# ------------------------------------------------------------------------------------------- CLI
def test_cli_plan_writes_a_scenario_plansim_run_takes(tmp_path, capsys):
    out = tmp_path / "plan.toml"
    code = main(["plan", "jjf2003", "--targets", EXAMPLE, "--trials", "200", "--seed", "3", "--out", str(out),
                 "--json", "--quiet"])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    from plansim.report.plan import JSON_KEYS, TARGET_KEYS

    assert set(JSON_KEYS) <= set(report) and all(set(TARGET_KEYS) <= set(t) for t in report["targets"])
    planned = plansim.load_scenario(out)
    assert planned.schedule.duration == pytest.approx(report["table_time_s"])
    assert report["table_time_s"] <= report["time_with_rules_s"]
    assert main(["run", str(out), "--trials", "20", "--quiet"]) == 0


def test_cli_plan_refuses_bad_options_before_any_work(tmp_path, capsys):
    assert main(["plan", "--targets", EXAMPLE, "--trials", "1"]) != 0
    assert "--trials 1" in capsys.readouterr().err
    assert main(["plan", "--targets", EXAMPLE, "--out", str(tmp_path / "plan.txt")]) != 0
    assert "--out" in capsys.readouterr().err
    assert main(["plan", "--targets", str(tmp_path / "missing.toml")]) != 0
    assert "missing.toml" in capsys.readouterr().err


# ------------------------------------------------------------------------------------------- acceptance
@pytest.mark.slow
def test_plan_meets_the_defaults_achieved_uncertainty_in_monte_carlo():
    # the acceptance: targets equal to the default's achieved U (2·RMS error of 4000 trials); the plan is
    # no longer than the default, meets every target in its own 4000-trial Monte Carlo (family-wise 5 % test,
    # plansim.planning.plan.allowance), and removing any one segment breaks a target or the reduction
    scenario = plansim.load_scenario("jjf2003")
    error = plansim.run(scenario, trials=4000, seed=11)["error"].values
    U = 2.0 * np.sqrt(np.mean(error**2, axis=0))
    targets = {p.name: Target(p.name, float(U[i]), "default achieved") for i, p in enumerate(PARAMETERS)}
    result = plan(scenario, targets, trials=4000, seed=12)
    assert result.table_time <= scenario.schedule.duration
    assert all(result.met_in_monte_carlo().values())
    assert not [why for why in result.removable if why.startswith("nothing")]
