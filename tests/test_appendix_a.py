"""JJF 2003-2022 Appendix A: the printed arithmetic, its slips, the unit readings and the Monte Carlo check."""

from __future__ import annotations

import dataclasses
import math
from decimal import Decimal

import numpy as np
import pytest
from scipy.stats import norm

from plansim.io.scenario_file import load_scenario
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS
from plansim.schedule.segments import Schedule
from plansim.uncertainty import (
    APPENDIX_A,
    UncertaintyComponent,
    acquisition_quantisation_uncertainty,
    appendix_a_budget,
    compare_with_appendix_a,
    errors_in_reading_units,
    expanded_uncertainty_in_si,
    omega_squared_test_rate,
    reading_unit_in_si,
)
from plansim.uncertainty.metrology import coverage_tolerance, coverage_verdict
from plansim.units import DEG, STANDARD_GRAVITY


def half_unit(printed: str) -> float:
    """Half a unit in the last digit of a number as printed, e.g. ``"4.3e-4"`` -> ``5e-6``."""
    return 0.5 * 10.0 ** Decimal(printed).as_tuple().exponent


def round_up(value: float, significant: int) -> float:
    """*value* rounded up (away from zero) to *significant* digits (GUM 7.2.6)."""
    scale = 10.0 ** (math.floor(math.log10(value)) - significant + 1)
    return math.ceil(value / scale - 1e-9) * scale


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("ideal")


# ----------------------------------------------------------------------------- the budgets as data


def test_budgets_cover_the_items_and_parameters_of_appendix_a():
    assert [b.item for b in APPENDIX_A] == ["A.1", "A.2", "A.3", "A.4", "A.5"]
    assert appendix_a_budget("A.1").parameters == ("Kgxx", "Kgyy", "Kgzz")
    assert appendix_a_budget("A.2").parameters == ("Bgx", "Bgy", "Bgz")
    assert set(appendix_a_budget("A.3").parameters) == {p.name for p in PARAMETERS if p.group == "G"}
    assert set(appendix_a_budget("A.4").parameters) == {p.name for p in PARAMETERS
                                                        if p.group == "Kg" and p.row != p.col}
    assert set(appendix_a_budget("A.5").parameters) == {p.name for p in PARAMETERS if p.group == "P"}
    covered = [name for b in APPENDIX_A for name in b.parameters]
    assert len(covered) == len(set(covered)) == 27
    assert all(b.coverage_factor == 2.0 for b in APPENDIX_A)
    with pytest.raises(ValueError, match="A.6"):
        appendix_a_budget("A.6")


def test_printed_values_are_stored_exactly_as_printed():
    printed = {"A.1": (2.12e-4, 4.3e-4), "A.2": (2.68e-4, 5.36e-4), "A.3": (5.02e-3, 1.1e-2),
               "A.4": (2.12e-4, 4.3e-4), "A.5": (5.02e-3, 1.1e-2)}
    for b in APPENDIX_A:
        assert (b.printed_combined_standard_uncertainty, b.printed_expanded_uncertainty) == printed[b.item]
        assert b.component("u1").printed_value == 1.0e-4
        assert b.component("u2").printed_value == 1.41e-4
    assert appendix_a_budget("A.2").component("u3").printed_value == 2.046e-4
    assert appendix_a_budget("A.3").component("u3").printed_value == 5.02e-3
    assert appendix_a_budget("A.5").component("u3").printed_value == 5.02e-3
    assert appendix_a_budget("A.1").component("u3").printed_value == 1.22e-4


def test_component_inputs_reproduce_the_printed_components():
    # A.1.2.1: u1 = U/k = 2e-4/2
    assert appendix_a_budget("A.1").component("u1").value_per_reading == pytest.approx(1.0e-4, rel=1e-12)
    # A.1.2.2, eq. (A.3): δ = 1/2^12, u2 = δ/√3 = 1.4095e-4, printed 1.41e-4
    assert abs(acquisition_quantisation_uncertainty(12) - 1.41e-4) <= half_unit("1.41e-4")
    # A.2.2.3: six readings of 3.41e-5 added linearly; A.3.2.3 / A.5.2.3: two of 2.51e-3
    u3 = appendix_a_budget("A.2").component("u3")
    assert (u3.value_per_reading, u3.count, u3.combination_as_printed) == (3.41e-5, 6, "linear_sum")
    assert abs(u3.combined_as_printed - 2.046e-4) <= half_unit("2.046e-4")
    for item in ("A.3", "A.5"):
        u3 = appendix_a_budget(item).component("u3")
        assert (u3.value_per_reading, u3.count, u3.combination_as_printed) == (2.51e-3, 2, "linear_sum")
        assert abs(u3.combined_as_printed - 5.02e-3) <= half_unit("5.02e-3")
    for b in APPENDIX_A:
        for c in b.components:
            assert abs(c.combined_as_printed - c.printed_value) <= 1e-12


# ----------------------------------------------------------------------------- the printed arithmetic


@pytest.mark.parametrize("item, printed_uc", [("A.1", "2.12e-4"), ("A.2", "2.68e-4"), ("A.3", "5.02e-3"),
                                              ("A.4", "2.12e-4"), ("A.5", "5.02e-3")])
def test_combined_standard_uncertainty_reproduces_the_printed_value(item, printed_uc):
    recomputed = appendix_a_budget(item).recomputed_combined_standard_uncertainty()
    assert abs(recomputed - float(printed_uc)) <= half_unit(printed_uc)


def test_expanded_uncertainty_of_a2_reproduces_the_printed_value():
    recomputed = appendix_a_budget("A.2").recomputed_expanded_uncertainty()  # 5.357e-4
    assert abs(recomputed - 5.36e-4) <= half_unit("5.36e-4")


def test_a3_rounding_slip_arithmetic_gives_1_00e_2_not_1_1e_2():
    for item in ("A.3", "A.5"):
        b = appendix_a_budget(item)
        recomputed = b.recomputed_expanded_uncertainty()  # 2 × 5.023e-3 = 1.0046e-2
        assert abs(recomputed - 1.00e-2) <= half_unit("1.00e-2")
        assert abs(2 * b.printed_combined_standard_uncertainty - 1.00e-2) <= half_unit("1.00e-2")
        assert abs(recomputed - b.printed_expanded_uncertainty) > half_unit("1.1e-2")


def test_a1_a4_printed_4_3e_4_is_not_the_nearest_rounding_of_the_arithmetic():
    # 2 × 2.1158e-4 = 4.23e-4 (and 2 × 2.12e-4 = 4.24e-4): nearest to two digits is 4.2e-4, not 4.3e-4.
    for item in ("A.1", "A.4"):
        b = appendix_a_budget(item)
        recomputed = b.recomputed_expanded_uncertainty()
        assert abs(recomputed - 4.23e-4) <= half_unit("4.23e-4")
        assert abs(recomputed - b.printed_expanded_uncertainty) > half_unit("4.3e-4")


def test_printed_expanded_uncertainties_follow_no_single_rounding_rule():
    # A.1, A.3, A.4, A.5 print k·u_c rounded *up* to two significant digits (GUM 7.2.6 allows it) ...
    for item in ("A.1", "A.3", "A.4", "A.5"):
        b = appendix_a_budget(item)
        assert round_up(b.recomputed_expanded_uncertainty(), 2) == pytest.approx(b.printed_expanded_uncertainty)
    # ... while A.2 prints three digits rounded to nearest (rounding up would give 5.36e-4 too, but
    # two digits rounded up would be 5.4e-4).
    b = appendix_a_budget("A.2")
    assert round_up(b.recomputed_expanded_uncertainty(), 2) == pytest.approx(5.4e-4)
    assert b.printed_expanded_uncertainty == 5.36e-4


def test_linear_sum_slip_against_the_gum_law_of_propagation():
    # A.2: B = mean of 6 readings (eq. (A.4)): c = 1/6, independent readings -> √6·3.41e-5/6
    a2 = appendix_a_budget("A.2").component("u3")
    assert a2.sensitivity_coefficient == pytest.approx(1 / 6)
    assert abs(a2.gum_standard_uncertainty - 1.39e-5) <= half_unit("1.39e-5")
    assert a2.combined_as_printed / a2.gum_standard_uncertainty == pytest.approx(6 * math.sqrt(6))
    # A.3: gxx = (U1 − U2)/2 (eq. (A.6)): c = 1/2 -> √2·2.51e-3/2
    a3 = appendix_a_budget("A.3").component("u3")
    assert a3.sensitivity_coefficient == 0.5
    assert abs(a3.gum_standard_uncertainty - 1.77e-3) <= half_unit("1.77e-3")
    # A.5: p = (U7 − U8)/ω² (eq. (A.10)); read in FS_a/ω² the coefficient is 1 -> √2·2.51e-3
    a5 = appendix_a_budget("A.5").component("u3")
    assert a5.sensitivity_coefficient == 1.0
    assert abs(a5.gum_standard_uncertainty - 3.55e-3) <= half_unit("3.55e-3")
    # the directly given components are unchanged
    for b in APPENDIX_A:
        for symbol in ("u1", "u2"):
            c = b.component(symbol)
            assert c.gum_standard_uncertainty == c.printed_value


def test_component_and_budget_validation_names_the_field():
    with pytest.raises(ValueError, match="combination_as_printed"):
        UncertaintyComponent("u3", "x", "A.9", 1e-4, 2, "quadrature", 1e-4)
    with pytest.raises(ValueError, match="count"):
        UncertaintyComponent("u3", "x", "A.9", 1e-4, 2, "single", 1e-4)
    with pytest.raises(TypeError, match="count"):
        UncertaintyComponent("u3", "x", "A.9", 1e-4, 2.0, "linear_sum", 2e-4)
    with pytest.raises(ValueError, match="value_per_reading"):
        UncertaintyComponent("u3", "x", "A.9", -1e-4, 1, "single", 1e-4)
    with pytest.raises(ValueError, match="unknown parameter 'Kgqq'"):
        dataclasses.replace(APPENDIX_A[0], parameters=("Kgqq",))
    with pytest.raises(ValueError, match="reading_kind"):
        dataclasses.replace(APPENDIX_A[0], reading_kind="percent")
    with pytest.raises(ValueError, match="no component 'u4'"):
        APPENDIX_A[0].component("u4")


# ----------------------------------------------------------------------------- readings of the units


def test_reading_units_in_si(scenario):
    fs_g, fs_a = scenario.acquisition.gyro_full_scale, scenario.acquisition.accel_full_scale
    assert fs_g == pytest.approx(125 * DEG) and fs_a == pytest.approx(8 * STANDARD_GRAVITY)
    g_ref = scenario.reduction.reference_gravity
    omega = omega_squared_test_rate(scenario, 0)
    assert omega == pytest.approx(100 * DEG)
    a1, a2, a3, a4, a5 = APPENDIX_A
    assert reading_unit_in_si(a1, "Kgyy", scenario) == pytest.approx(scenario.truth_nominal[PARAMETER_INDEX["Kgyy"]])
    assert reading_unit_in_si(a4, "Kgxy", scenario) == 1.0
    assert reading_unit_in_si(a2, "Bgz", scenario) == pytest.approx(fs_g)
    assert reading_unit_in_si(a3, "gxy", scenario) == pytest.approx(fs_g / g_ref)
    assert reading_unit_in_si(a5, "pyx", scenario) == pytest.approx(fs_a / omega**2)
    # U_abs = U × the reading unit
    assert expanded_uncertainty_in_si(a2, "Bgx", scenario) == pytest.approx(5.36e-4 * fs_g)
    assert expanded_uncertainty_in_si(a3, "gzz", scenario) == pytest.approx(1.1e-2 * fs_g / g_ref)
    assert expanded_uncertainty_in_si(a5, "pzy", scenario) == pytest.approx(1.1e-2 * fs_a / omega**2)
    # conversion of errors
    assert errors_in_reading_units(a1, "Kgxx", [0.002], scenario, truth=[2.0]) == pytest.approx([1e-3])
    assert errors_in_reading_units(a2, "Bgy", [fs_g * 1e-3], scenario) == pytest.approx([1e-3])
    assert errors_in_reading_units(a5, "pxz", 3 * fs_a / omega**2, scenario) == pytest.approx(3.0)
    with pytest.raises(ValueError, match="not covered by budget A.2"):
        reading_unit_in_si(a2, "Kgxx", scenario)
    with pytest.raises(ValueError, match="non-zero"):
        reading_unit_in_si(a1, "Kgxx", scenario, truth=0.0)


def test_reading_a5_uses_the_test_rate_about_the_input_axis(scenario):
    segments = []
    for s in scenario.schedule.segments:
        if s.test == "omega_squared" and s.group == 2 and s.rate != 0:
            s = dataclasses.replace(s, rate=-2 * s.rate)  # about z: twice the rate, turned the other way
        segments.append(s)
    changed = dataclasses.replace(scenario, schedule=Schedule(tuple(segments)))
    a5 = appendix_a_budget("A.5")
    assert reading_unit_in_si(a5, "pxz", changed) == pytest.approx(reading_unit_in_si(a5, "pxy", changed) / 4)
    without = dataclasses.replace(scenario, schedule=Schedule(tuple(
        s for s in scenario.schedule.segments if not (s.test == "omega_squared" and s.rate != 0))))
    with pytest.raises(ValueError, match="exactly one test rate"):
        reading_unit_in_si(a5, "pyx", without)
    bad = dataclasses.replace(scenario, acquisition=dataclasses.replace(scenario.acquisition, gyro_full_scale=0.0))
    with pytest.raises(ValueError, match="acquisition.gyro_full_scale"):
        reading_unit_in_si(appendix_a_budget("A.2"), "Bgx", bad)


# ----------------------------------------------------------------------------- comparison with Monte Carlo


def synthetic(scenario, sigma_by_item: dict[str, float], trials: int, seed: int = 20220601):
    """Truth and estimate (trials, 39) whose errors are N(0, σ²) in each item's reading units."""
    rng = np.random.default_rng(seed)
    truth = np.tile(scenario.truth_nominal, (trials, 1))
    truth += rng.normal(size=truth.shape) * 1e-3 * np.abs(truth)  # truths differ a little between trials
    estimate = truth.copy()
    for budget in APPENDIX_A:
        sigma = sigma_by_item.get(budget.item, 0.0)
        for name in budget.parameters:
            k = PARAMETER_INDEX[name]
            unit = reading_unit_in_si(budget, name, scenario, truth[:, k])
            estimate[:, k] = truth[:, k] + sigma * rng.standard_normal(trials) * unit
    return truth, estimate


def test_statistics_match_the_normal_errors_they_were_drawn_from(scenario):
    trials = 4000
    sigma = {b.item: 0.6 * b.printed_combined_standard_uncertainty for b in APPENDIX_A}
    truth, estimate = synthetic(scenario, sigma, trials)
    results = compare_with_appendix_a(truth, estimate, scenario)
    assert [r.item for r in results] == ["A.1", "A.2", "A.3", "A.4", "A.5"]
    for r in results:
        s = sigma[r.item]
        n = trials * len(r.parameters)
        assert r.n == n
        assert abs(r.mc_u - s) <= 5 * s / math.sqrt(2 * n)
        assert abs(r.mc_bias) <= 5 * s / math.sqrt(n)
        p = 2 * norm.cdf(r.budget_U / s) - 1
        assert abs(r.coverage - p) <= 5 * math.sqrt(p * (1 - p) / n)
        assert r.mc_U95 == pytest.approx(norm.ppf(0.975) * s, rel=0.05)
        assert r.ratio == pytest.approx(r.mc_u / r.budget_uc)
        assert r.tolerance == pytest.approx(3 * math.sqrt(0.95 * 0.05 / n))
        for pc in r.per_parameter:
            assert abs(pc.std - s) <= 5 * s / math.sqrt(2 * trials)
            assert abs(pc.coverage - p) <= 5 * math.sqrt(p * (1 - p) / trials)
            assert pc.budget_U_si == pytest.approx(r.budget_U * pc.reading_unit_in_si)


def test_verdicts_for_understated_supported_and_overstated_budgets(scenario):
    trials = 3000
    budget_U = {b.item: b.printed_expanded_uncertainty for b in APPENDIX_A}
    sigma = {
        "A.1": budget_U["A.1"] / 1.0,   # coverage 68 %: under-stated
        "A.2": budget_U["A.2"] / 1.96,  # coverage 95 %: supported
        "A.3": budget_U["A.3"] / 2.5,   # coverage 98.8 % but F = 1.3: supported
        "A.4": budget_U["A.4"] / 20.0,  # coverage 100 %, F ≈ 10: over-stated
        "A.5": budget_U["A.5"] / 2.0,   # coverage 95.4 %: supported
    }
    truth, estimate = synthetic(scenario, sigma, trials, seed=7)
    verdicts = {r.item: r for r in compare_with_appendix_a(truth, estimate, scenario)}
    assert verdicts["A.1"].verdict == "under-stated"
    assert verdicts["A.2"].verdict == "supported"
    assert verdicts["A.3"].verdict == "supported"
    assert verdicts["A.5"].verdict == "supported"
    over = verdicts["A.4"]
    assert over.coverage == 1.0
    assert over.overstatement_factor == pytest.approx(20 / 1.96, rel=0.05)
    assert over.verdict == f"over-stated ×{over.overstatement_factor:.3g}"
    # a subset of budgets, in the order given
    only = compare_with_appendix_a(truth, estimate, scenario, budgets=[APPENDIX_A[3], APPENDIX_A[0]])
    assert [r.item for r in only] == ["A.4", "A.1"]


def test_verdict_thresholds():
    n = 1000
    tol = coverage_tolerance(n)
    assert tol == pytest.approx(3 * math.sqrt(0.95 * 0.05 / n))

    def appendix_a_verdict(coverage, n, budget_expanded, mc_U95):  # the comparison's reading of the one verdict
        return coverage_verdict(coverage, n, 0.95, budget_expanded, mc_U95, show_understatement_factor=False)

    assert appendix_a_verdict(0.95 - tol - 1e-9, n, 1.0, 1.0)[0] == "under-stated"
    assert appendix_a_verdict(0.95 - tol + 1e-9, n, 1.0, 1.0)[0] == "supported"
    assert appendix_a_verdict(0.95 + tol, n, 1.0, 0.5)[0] == "supported"  # F = 2 is not > 2
    assert appendix_a_verdict(0.95 + tol, n, 1.0, 0.4) == ("over-stated ×2.5", 2.5)
    assert appendix_a_verdict(0.95 + tol - 1e-9, n, 1.0, 0.1)[0] == "supported"
    verdict, factor = appendix_a_verdict(1.0, n, 1.0, 0.0)
    assert factor == math.inf and verdict.startswith("over-stated")


def test_too_few_trials_are_not_called_supported(scenario):
    """10 trials: A.1 pools 30 errors, A.3 90 — fewer than the 171 a 95 % verdict needs to find an
    over-statement, so a budget 100× too wide is "too few trials to judge", not "supported" (issue 9 §2)."""
    truth, estimate = synthetic(scenario, {b.item: b.printed_combined_standard_uncertainty / 100 for b in APPENDIX_A},
                                10)
    for r in compare_with_appendix_a(truth, estimate, scenario):
        assert r.coverage == 1.0 and r.overstatement_factor > 20
        assert r.verdict == f"too few trials to judge ({r.n} < 171)"


def test_as_dict_has_the_cli_keys(scenario):
    truth, estimate = synthetic(scenario, {b.item: b.printed_combined_standard_uncertainty for b in APPENDIX_A}, 50)
    record = compare_with_appendix_a(truth, estimate, scenario)[2].as_dict()
    for key in ("item", "budget_uc", "budget_U", "mc_u", "mc_U95", "coverage", "mc_bias", "ratio", "verdict",
                "reading", "reading_unit", "per_parameter"):
        assert key in record
    assert record["item"] == "A.3" and record["budget_U"] == 1.1e-2 and record["budget_uc"] == 5.02e-3
    assert record["arithmetic_U"] == pytest.approx(1.0046e-2, rel=1e-4)
    assert "FS_g/g_ref" in record["reading_unit"]
    assert [p["name"] for p in record["per_parameter"]] == list(appendix_a_budget("A.3").parameters)
    import json

    json.dumps(record)


def test_compare_rejects_bad_input(scenario):
    truth, estimate = synthetic(scenario, {}, 10)
    with pytest.raises(ValueError, match=r"truth: shape \(39,\)"):
        compare_with_appendix_a(truth[0], estimate, scenario)
    with pytest.raises(ValueError, match="estimate: shape"):
        compare_with_appendix_a(truth, estimate[:5], scenario)
    with pytest.raises(ValueError, match="at least 2"):
        compare_with_appendix_a(truth[:1], estimate[:1], scenario)
    with pytest.raises(TypeError, match="not an AppendixABudget"):
        compare_with_appendix_a(truth, estimate, scenario, budgets=["A.1"])
    broken = estimate.copy()
    broken[3, PARAMETER_INDEX["pzy"]] = np.nan
    with pytest.raises(ValueError, match="parameter pzy: trial 3"):
        compare_with_appendix_a(truth, broken, scenario)
    zero = truth.copy()
    zero[:, PARAMETER_INDEX["Kgzz"]] = 0.0
    with pytest.raises(ValueError, match="Kgzz"):
        compare_with_appendix_a(zero, estimate, scenario)
    assert len(PARAMETER_NAMES) == truth.shape[1]
