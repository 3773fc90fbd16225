"""JJF 2003-2022 Appendix A under every defensible reading of its units (issue 9 §3).

The budgets print numbers without units. Each budget carries its readings (the first, the primary
one, is the reading plansim used alone before); these tests hold the SI size of each reading to
hand values, the "holds under every reading" / "depends on the reading" flag to constructed errors,
and the streamed summary to the per-trial comparison in every reading.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

import plansim
import plansim.runner as runner
from plansim.cli import main
from plansim.model.parameters import PARAMETER_INDEX
from plansim.report.summary import RunStatistics, appendix_a_comparisons, summary_memory_bytes
from plansim.report.table import appendix_a_table, verdict_by_reading_table
from plansim.uncertainty import APPENDIX_A, appendix_a_budget, compare_with_appendix_a
from plansim.uncertainty.appendix_a import (
    Reading,
    errors_in_reading_units,
    expanded_uncertainty_in_si,
    reading_si_unit,
    reading_unit_description,
    reading_unit_in_si,
)
from plansim.uncertainty.appendix_a_comparison import (
    DEPENDS_ON_THE_READING,
    HOLDS_UNDER_EVERY_READING,
    reading_dependence,
    verdict_kind,
)
from plansim.uncertainty.claims import parse_claims

#: the reference gravity of the jjf2003 scenario: local normal gravity at 39.9° N, 50 m (docs/appendix-a.md)
G_REF = 9.8014535


@pytest.fixture(scope="module")
def scenario():
    return plansim.load_scenario("jjf2003")


# ----------------------------------------------------------------------------- the readings as data

def test_each_budget_lists_its_readings_primary_first(scenario):
    names = {b.item: [r.name for r in b.readings] for b in APPENDIX_A}
    assert names == {"A.1": ["relative", "absolute"], "A.2": ["FS_g", "deg/s"],
                     "A.3": ["FS_g/g", "deg/s/g", "deg/h/g"], "A.4": ["absolute"],
                     "A.5": ["FS_a/omega^2", "g/(rad/s)^2", "(m/s^2)/(rad/s)^2"]}
    for b in APPENDIX_A:
        assert b.primary_reading is b.readings[0] and b.readings[0].kind == b.reading_kind
        for name in b.parameters:
            # no reading given = the primary one, by object or by name
            assert reading_unit_in_si(b, name, scenario) == reading_unit_in_si(b, name, scenario, reading=b.readings[0])
            assert reading_unit_in_si(b, name, scenario) == reading_unit_in_si(b, name, scenario,
                                                                                reading=b.readings[0].name)
        assert reading_unit_description(b, scenario) == reading_unit_description(b, scenario, b.readings[0])
        assert all(r.constant == (r.kind != "relative") for r in b.readings)


def test_reading_units_against_hand_values(scenario):
    """The SI size of each reading and the printed U in SI, computed by hand for the jjf2003 scenario
    (FS_g = 125 °/s, FS_a = 8 g, g_ref = 9.8014535 m/s², ω = 100 °/s)."""
    a1, a2, a3, a4, a5 = APPENDIX_A
    assert scenario.reduction.reference_gravity == pytest.approx(G_REF, abs=5e-8)
    deg = math.pi / 180
    # A.1: relative = |K|, absolute = 1; K̂ − K = 2e-3 is 2e-3/1.0021 relative for Kgxx = 1.0021
    assert reading_unit_in_si(a1, "Kgxx", scenario) == pytest.approx(1.0021, rel=1e-12)
    assert reading_unit_in_si(a1, "Kgxx", scenario, reading="absolute") == 1.0
    assert errors_in_reading_units(a1, "Kgxx", 2e-3, scenario, reading="absolute") == pytest.approx(2e-3)
    assert errors_in_reading_units(a1, "Kgxx", 2e-3, scenario) == pytest.approx(2e-3 / 1.0021)
    # A.2: U = 5.36e-4 FS_g = 5.36e-4 × 125 °/s = 0.067 °/s; in °/s it is 5.36e-4 °/s = 5.36e-4·π/180 rad/s
    assert expanded_uncertainty_in_si(a2, "Bgx", scenario) == pytest.approx(5.36e-4 * 125 * deg, rel=1e-12)
    assert expanded_uncertainty_in_si(a2, "Bgy", scenario, reading="deg/s") == pytest.approx(5.36e-4 * math.pi / 180,
                                                                                             rel=1e-15)
    assert expanded_uncertainty_in_si(a2, "Bgz", scenario, reading="deg/s") == pytest.approx(9.35496e-6, rel=1e-5)
    assert errors_in_reading_units(a2, "Bgx", 3 * deg, scenario, reading="deg/s") == pytest.approx(3.0)
    # A.3: °/s per g and °/h per g, g = g_ref: one °/h/g = (π/180/3600)/9.8014535 = 4.94634e-7 rad/s per m/s²
    assert reading_unit_in_si(a3, "gxy", scenario, reading="deg/s/g") == pytest.approx(deg / G_REF, rel=1e-8)
    assert reading_unit_in_si(a3, "gzz", scenario, reading="deg/h/g") == pytest.approx(4.94634e-7, rel=1e-5)
    assert expanded_uncertainty_in_si(a3, "gyx", scenario, reading="deg/h/g") == pytest.approx(
        1.1e-2 * deg / 3600 / G_REF, rel=1e-8)
    assert expanded_uncertainty_in_si(a3, "gxx", scenario) == pytest.approx(1.1e-2 * 125 * deg / G_REF, rel=1e-8)
    # A.4: one reading, the absolute one
    assert [reading_unit_in_si(a4, n, scenario) for n in a4.parameters] == [1.0] * 6
    # A.5: FS_a/ω² = 8 × 9.80665 / (100π/180)² = 25.7547; g/(rad/s)² = g_ref; SI = 1
    assert reading_unit_in_si(a5, "pyx", scenario) == pytest.approx(8 * 9.80665 / (100 * deg) ** 2, rel=1e-12)
    assert reading_unit_in_si(a5, "pyx", scenario) == pytest.approx(25.7547, rel=1e-5)
    assert expanded_uncertainty_in_si(a5, "pzy", scenario, reading="g/(rad/s)^2") == pytest.approx(1.1e-2 * G_REF,
                                                                                                   rel=1e-8)
    assert reading_unit_in_si(a5, "pxz", scenario, reading="(m/s^2)/(rad/s)^2") == 1.0
    # the SI units the readings' sizes are in
    assert reading_si_unit(a2, "deg/s") == "rad/s" and reading_si_unit(a3, "deg/h/g") == "rad/s per m/s^2"
    assert reading_si_unit(a5, "g/(rad/s)^2") == "(m/s^2)/(rad/s)^2" and reading_si_unit(a1) is None
    assert reading_unit_description(a3, scenario, "deg/h/g") == "°/h per g (g = g_ref) = 4.94634e-07 rad/s per m/s^2"


def test_readings_per_g_use_the_reductions_reference_gravity(scenario):
    standard = dataclasses.replace(scenario, reduction=dataclasses.replace(scenario.reduction,
                                                                           reference_gravity=9.80665))
    a3, a5 = appendix_a_budget("A.3"), appendix_a_budget("A.5")
    assert reading_unit_in_si(a3, "gxx", standard, reading="deg/h/g") == pytest.approx(math.pi / 180 / 3600 / 9.80665)
    assert reading_unit_in_si(a5, "pxy", standard, reading="g/(rad/s)^2") == 9.80665
    # readings without g do not move
    assert reading_unit_in_si(a5, "pxy", standard) == reading_unit_in_si(a5, "pxy", scenario)


def test_a_reading_that_is_not_the_budgets_is_refused(scenario):
    a2, a3 = appendix_a_budget("A.2"), appendix_a_budget("A.3")
    with pytest.raises(ValueError, match=r"budget 'A.2' has no reading 'deg/h'; its readings: 'FS_g', 'deg/s'"):
        reading_unit_in_si(a2, "Bgx", scenario, reading="deg/h")
    with pytest.raises(ValueError, match="'deg/h/g' is not a reading of budget A.2"):
        reading_unit_in_si(a2, "Bgx", scenario, reading=a3.readings[2])
    with pytest.raises(TypeError, match="reading = 3"):
        reading_unit_in_si(a2, "Bgx", scenario, reading=3)
    bad = dataclasses.replace(scenario, reduction=dataclasses.replace(scenario.reduction, reference_gravity=0.0))
    with pytest.raises(ValueError, match="reduction.reference_gravity"):
        reading_unit_in_si(a3, "gxx", bad, reading="deg/s/g")


def test_budget_readings_are_checked():
    a2 = appendix_a_budget("A.2")
    with pytest.raises(ValueError, match=r"readings\[0\] is 'deg/s'.*primary"):
        dataclasses.replace(a2, readings=tuple(reversed(a2.readings)))
    with pytest.raises(ValueError, match="repeat a name"):
        dataclasses.replace(a2, readings=(a2.readings[0], a2.readings[0]))
    with pytest.raises(TypeError, match="non-empty tuple of Reading"):
        dataclasses.replace(a2, readings=())
    with pytest.raises(ValueError, match="kind = 'furlong'"):
        Reading("x", "furlong", "x")


# ----------------------------------------------------------------------------- the verdict in every reading

def errors_in_si(scenario, sigma_si: dict[str, float], trials: int, seed: int = 11):
    """Truth and estimate (trials, 39) whose errors are N(0, σ²) in SI for the named parameters."""
    rng = np.random.default_rng(seed)
    truth = np.tile(scenario.truth_nominal, (trials, 1))
    estimate = truth.copy()
    for name, sigma in sigma_si.items():
        estimate[:, PARAMETER_INDEX[name]] += sigma * rng.standard_normal(trials)
    return truth, estimate


def test_verdict_kinds_and_the_flag():
    assert verdict_kind("over-stated ×21.7") == "over-stated"
    assert verdict_kind("under-stated") == "under-stated" and verdict_kind("under-stated ×0.5") == "under-stated"
    assert verdict_kind("too few trials to judge (30 < 171)") == "too few trials"
    assert verdict_kind("supported") == "supported"
    with pytest.raises(ValueError, match="not a verdict"):
        verdict_kind("fine")
    assert reading_dependence(["over-stated ×3", "over-stated ×400"]) == HOLDS_UNDER_EVERY_READING
    assert reading_dependence(["over-stated ×3", "supported"]) == DEPENDS_ON_THE_READING
    assert reading_dependence(["supported"]) == HOLDS_UNDER_EVERY_READING


def test_a_verdict_that_flips_between_readings_depends_on_the_reading(scenario):
    """Bias errors of σ = 2e-5 rad/s (4.1 °/h): U = 5.36e-4 FS_g = 1.17e-3 rad/s covers them all,
    60× wider than needed; U = 5.36e-4 °/s = 9.35e-6 rad/s covers about 36 %."""
    truth, estimate = errors_in_si(scenario, {"Bgx": 2e-5, "Bgy": 2e-5, "Bgz": 2e-5, "Kgxx": 1e-5, "Kgyy": 1e-5,
                                              "Kgzz": 1e-5}, 4000)
    a1, a2 = compare_with_appendix_a(truth, estimate, scenario, budgets=[APPENDIX_A[0], APPENDIX_A[1]])
    fs, dps = a2.readings
    assert (fs.reading, dps.reading) == ("FS_g", "deg/s")
    assert fs.verdict.startswith("over-stated") and fs.coverage == 1.0
    assert dps.verdict == "under-stated"
    assert abs(dps.coverage - (2 * 0.5 * math.erf(9.355e-6 / 2e-5 / math.sqrt(2)))) < 4 * math.sqrt(0.25 / 12000)
    assert a2.reading_dependence == DEPENDS_ON_THE_READING and not a2.holds_under_every_reading
    # the same errors in SI: only the claimed U moves between readings
    assert fs.mc_U95_si == pytest.approx(dps.mc_U95_si, rel=1e-12)
    assert fs.mc_U95_si == pytest.approx(1.96 * 2e-5, rel=0.05)
    assert fs.budget_U_si == pytest.approx((5.36e-4 * 125 * math.pi / 180,) * 3)
    assert dps.budget_U_si == pytest.approx((5.36e-4 * math.pi / 180,) * 3)
    # K errors of 1e-5: over-stated ~22× in both readings — holds
    assert [r.verdict_kind for r in a1.readings] == ["over-stated", "over-stated"]
    assert a1.reading_dependence == HOLDS_UNDER_EVERY_READING and a1.holds_under_every_reading
    # the primary reading repeats the item's own figures
    for c in (a1, a2):
        first = c.readings[0]
        assert (first.coverage, first.mc_U95, first.verdict, first.overstatement_factor) == \
            (c.coverage, c.mc_U95, c.verdict, c.overstatement_factor)


def test_too_few_trials_and_an_under_statement_depend_on_the_reading(scenario):
    """10 trials (30 pooled errors): the FS_g reading covers every error but cannot be judged; the °/s one is short."""
    truth, estimate = errors_in_si(scenario, {"Bgx": 2e-5, "Bgy": 2e-5, "Bgz": 2e-5}, 10, seed=3)
    (a2,) = compare_with_appendix_a(truth, estimate, scenario, budgets=[APPENDIX_A[1]])
    assert [r.verdict_kind for r in a2.readings] == ["too few trials", "under-stated"]
    assert a2.reading_dependence == DEPENDS_ON_THE_READING


def test_a5_over_stated_in_every_reading_holds(scenario):
    tiny = {name: 1e-6 for name in appendix_a_budget("A.5").parameters}  # (m/s²)/(rad/s)²: U95 2e-6 ≪ 0.011
    truth, estimate = errors_in_si(scenario, tiny, 400, seed=5)
    (a5,) = compare_with_appendix_a(truth, estimate, scenario, budgets=[APPENDIX_A[4]])
    assert [r.verdict_kind for r in a5.readings] == ["over-stated"] * 3
    assert a5.holds_under_every_reading
    factors = [r.overstatement_factor for r in a5.readings]
    assert factors[0] / factors[2] == pytest.approx(reading_unit_in_si(APPENDIX_A[4], "pyx", scenario), rel=1e-9)
    assert factors[1] / factors[2] == pytest.approx(G_REF, rel=1e-6)


def test_the_readings_table_marks_what_holds_and_what_depends(scenario):
    truth, estimate = errors_in_si(scenario, {"Bgx": 2e-5, "Bgy": 2e-5, "Bgz": 2e-5, "Kgxx": 1e-5, "Kgyy": 1e-5,
                                              "Kgzz": 1e-5}, 400)
    comparisons = compare_with_appendix_a(truth, estimate, scenario)
    text = verdict_by_reading_table(comparisons)
    lines = text.splitlines()
    assert lines[0].startswith("Verdict by reading")
    assert len(lines) == 2 + sum(len(b.readings) for b in APPENDIX_A)
    a2_rows = [line for line in lines if " FS_g " in line or " deg/s " in line]
    assert a2_rows[0].startswith("A.2") and "DEPENDS on the reading" in a2_rows[0]
    assert "deg/h" in a2_rows[0] and "241.2" in a2_rows[0]  # 5.36e-4 × 125 °/s = 241.2 °/h
    assert "1.93" in a2_rows[1] and "under-stated" in a2_rows[1]
    assert any(line.startswith("A.1") and line.endswith("holds: over-stated") for line in lines)
    assert text in appendix_a_table(comparisons)


def test_as_dict_keeps_its_keys_and_adds_the_readings(scenario):
    truth, estimate = errors_in_si(scenario, {"Bgx": 2e-5, "Bgy": 2e-5, "Bgz": 2e-5}, 300)
    record = compare_with_appendix_a(truth, estimate, scenario)[1].as_dict()
    assert set(record) == {"item", "quantity", "reading", "reading_unit", "parameters", "n", "budget_uc", "budget_U",
                           "coverage_factor", "arithmetic_uc", "arithmetic_U", "mc_bias", "mc_u", "mc_U95",
                           "coverage", "ratio", "tolerance", "overstatement_factor", "verdict", "per_parameter",
                           "readings", "reading_dependence", "holds_under_every_reading"}
    assert [r["reading"] for r in record["readings"]] == ["FS_g", "deg/s"]
    assert set(record["readings"][1]) == {"reading", "unit", "si_unit", "unit_in_si", "budget_U_si", "coverage",
                                          "mc_U95", "mc_U95_si", "overstatement_factor", "verdict", "verdict_kind"}
    assert record["readings"][1]["si_unit"] == "rad/s"
    assert record["reading_dependence"] == DEPENDS_ON_THE_READING and record["holds_under_every_reading"] is False
    json.dumps(record, allow_nan=False)


def test_run_json_carries_the_readings(capsys):
    code = main(["run", "jjf2003", "--trials", "200", "--seed", "4", "--json", "--quiet"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    for entry, budget in zip(doc["appendix_a"], APPENDIX_A):
        assert [r["reading"] for r in entry["readings"]] == [r.name for r in budget.readings]
        assert entry["readings"][0]["verdict"] == entry["verdict"]
        assert entry["reading_dependence"] in (HOLDS_UNDER_EVERY_READING, DEPENDS_ON_THE_READING)


# ----------------------------------------------------------------------------- the summary gives the same numbers

def _same_readings(got, expected):
    assert [c.item for c in got] == [c.item for c in expected]
    for g, e in zip(got, expected):
        assert g.reading_dependence == e.reading_dependence, e.item
        assert len(g.readings) == len(e.readings) == len(appendix_a_budget(e.item).readings)
        for gr, er, reading in zip(g.readings, e.readings, appendix_a_budget(e.item).readings):
            # counts, quantiles and the verdict: identical
            for key in ("reading", "unit", "si_unit", "coverage", "mc_U95", "overstatement_factor", "verdict"):
                assert getattr(gr, key) == getattr(er, key), (e.item, gr.reading, key)
            if reading.constant:
                assert (gr.unit_in_si, gr.budget_U_si, gr.mc_U95_si) == (er.unit_in_si, er.budget_U_si, er.mc_U95_si)
            else:  # the mean |truth| streamed block by block: the same to rounding
                np.testing.assert_allclose(gr.unit_in_si, er.unit_in_si, rtol=1e-12)
                np.testing.assert_allclose(gr.budget_U_si, er.budget_U_si, rtol=1e-12)
                np.testing.assert_allclose(gr.mc_U95_si, er.mc_U95_si, rtol=1e-12)


def test_streamed_statistics_give_every_readings_numbers_in_any_blocks(scenario):
    """Errors spread over many decades (so verdicts differ between readings), fed in uneven blocks."""
    n = 9001
    rng = np.random.default_rng(8)
    truth = np.tile(scenario.truth_nominal, (n, 1)) * (1 + 1e-3 * rng.standard_normal((n, 39)))
    scale = np.abs(scenario.truth_nominal) * 1e-5 + 1e-7
    estimate = truth + scale * rng.standard_normal((n, 39)) * np.exp(rng.normal(size=(n, 39)))
    statistics = RunStatistics(scenario, n)
    start = 0
    for size in (1, 4096, 7, 1000, 3897):
        statistics.add(start, truth[start:start + size], estimate[start:start + size])
        start += size
    assert start == n
    got = appendix_a_comparisons(statistics.dataset({"trials": n}), scenario)
    _same_readings(got, compare_with_appendix_a(truth, estimate, scenario))


def test_a_summary_run_gives_the_per_trial_comparison_in_every_reading(scenario):
    per_trial = plansim.run(scenario, trials=5000, seed=23)
    expected = compare_with_appendix_a(per_trial["truth"].values, per_trial["estimate"].values, scenario)
    summary = runner.run_summary(scenario, trials=5000, seed=23, chunk_size=333)
    got = appendix_a_comparisons(summary, scenario)
    _same_readings(got, expected)
    assert {c.item: c.reading_dependence for c in got} == {
        "A.1": HOLDS_UNDER_EVERY_READING, "A.2": DEPENDS_ON_THE_READING, "A.3": DEPENDS_ON_THE_READING,
        "A.4": HOLDS_UNDER_EVERY_READING, "A.5": DEPENDS_ON_THE_READING}


def test_the_memory_bound_counts_the_further_readings():
    one = [dataclasses.replace(b, readings=b.readings[:1]) for b in APPENDIX_A]
    extra = sum(len(b.readings) - 1 for b in APPENDIX_A)
    assert extra == 6
    assert summary_memory_bytes(10**6) > summary_memory_bytes(10**6, one)


# ----------------------------------------------------------------------------- plansim validate

@pytest.fixture(scope="module")
def report():
    return runner.validate("jjf2003", trials_per_block=2000, max_trials=4000, seed=5)


def test_validate_judges_the_appendix_a_claims_in_every_reading(report):
    from plansim.report.validation import format_report, validation_json

    for check in report.appendix_items:
        budget = appendix_a_budget(check.item)
        assert [r.reading for r in check.readings] == [r.name for r in budget.readings]
        assert (check.readings[0].coverage, check.readings[0].verdict) == (check.coverage, check.verdict)
    a2 = report.item("A.2")
    assert a2.readings[1].verdict.startswith("under-stated") and a2.reading_dependence == DEPENDS_ON_THE_READING
    assert report.item("A.1").reading_dependence == HOLDS_UNDER_EVERY_READING
    doc = validation_json(report)
    assert [r["reading"] for r in doc["appendix_a"][1]["readings"]] == ["FS_g", "deg/s"]
    json.dumps(doc, allow_nan=False)
    text = format_report(report, details=False)
    assert "the number 0.000536 in each reading of its unit (depends on the reading; " \
           "U and the MCM's |E| quantile in deg/h):" in text
    lines = text.splitlines()
    fs_g = next(line for line in lines if line.strip().startswith("FS_g "))
    assert "U =     241.2," in fs_g and "over-stated" in fs_g  # 5.36e-4 × 125 °/s = 241.2 °/h
    assert "A.4 has one reading of its unit (absolute): the verdict holds" in text


def test_validate_reads_a_claims_file_item_but_not_a_claim_with_its_unit(scenario):
    def simulate(trials, seed):
        return np.random.default_rng(seed).normal(size=(trials, 39)) * 1e-6

    from plansim.uncertainty.validation import validate

    items = parse_claims({"items": {"A.2": {"U": 5.36e-4}}}, scenario, "c.toml")
    report = validate(scenario, simulate, items, trials_per_block=1000, max_trials=2000, seed=1)
    assert [r.reading for r in report.item("A.2").readings] == ["FS_g", "deg/s"]
    stated = parse_claims({"parameters": {n: {"U": "10 deg/h"} for n in ("Bgx", "Bgy", "Bgz")}}, scenario, "c.toml")
    report = validate(scenario, simulate, stated, trials_per_block=1000, max_trials=2000, seed=1)
    assert report.item("A.2").readings == ()
