"""The built-in scenario ``appendix_a_inputs``: a world made of JJF 2003 Appendix A's own inputs (issue 9 §3).

Its noise is chosen to reproduce the printed repeatabilities (scenarios/appendix_a_inputs.toml,
docs/appendix-a.md). These tests hold the world to those inputs and each budget's Monte Carlo
``u`` (primary reading) to what the printed inputs give where they act:

- A.1: ``sqrt(u1² + u3²)`` (u2, one quantised reading, is dithered away in a 30 s mean);
- A.2: u3 by the GUM, ``√6·3.41e-5/6`` (u1 and u2 have no path into a static mean);
- A.4: u3 (a relative rate error does not move a coefficient near 0);
- A.5: the GUM recombination of the printed inputs, 3.55e-3 (= ``√2·2.51e-3``);
- A.3: not its own inputs: its group outputs are A.2's (the two clauses give the same readings
  repeatabilities 74× apart), so ``√2·3.41e-5/2``.

None of them reproduces its *printed* u_c, and the tests say so.

Tolerance: the standard deviation of *n* normal errors has a relative standard error
``1/sqrt(2(n − 1))``; each check allows 5 of them with ``n`` = the number of trials (pooled errors
of one trial can be correlated, so the trials, not the pooled count, set the tolerance):
5.6 % at 4000 trials.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import plansim
from plansim.io.scenario_file import builtin_scenarios
from plansim.uncertainty import APPENDIX_A, appendix_a_budget, compare_with_appendix_a
from plansim.uncertainty.appendix_a import reading_unit_in_si
from plansim.units import DEG, HOUR

TRIALS = 4000
#: 5 relative standard errors of a standard deviation estimated from TRIALS normal values
TOLERANCE = 5 / math.sqrt(2 * (TRIALS - 1))


@pytest.fixture(scope="module")
def scenario():
    return plansim.load_scenario("appendix_a_inputs")


@pytest.fixture(scope="module")
def results(scenario):
    return plansim.run(scenario, trials=TRIALS, seed=31)


@pytest.fixture(scope="module")
def items(scenario, results):
    return {c.item: c for c in compare_with_appendix_a(results["truth"].values, results["estimate"].values, scenario)}


def std_of(results, name):
    return float(np.std(results["error"].sel(parameter=name).values, ddof=1))


def test_it_is_built_in_and_holds_only_appendix_a_inputs(scenario):
    assert "appendix_a_inputs" in builtin_scenarios()
    assert scenario.name == "appendix_a_inputs"
    assert not np.any(scenario.environment.earth_rate_vector)
    assert not np.any(scenario.truth_spread)
    t = scenario.turntable
    assert t.rate_error_systematic.kind == "normal" and t.rate_error_systematic.standard_uncertainty == 1e-4  # A.1.2.1
    for name in ("position_accuracy", "position_repeatability", "axis_perpendicularity", "platform_tilt",
                 "fixture_perpendicularity", "rate_error_per_point"):
        assert getattr(t, name).standard_uncertainty == 0.0, name
    assert t.rate_smoothness == 0.0
    assert scenario.acquisition.bits == 12  # A.1.2.2
    # the same gyro noise gives A.1's and A.2's repeatability: rate points 30 s, positions 318 s
    dwell = {test: {s.dwell for s in scenario.schedule.segments if s.test == test}
             for test in ("multi_position", "rate", "omega_squared")}
    assert dwell == {"multi_position": {318.0}, "rate": {30.0}, "omega_squared": {30.0}}


def test_the_noise_reproduces_the_printed_repeatabilities(scenario):
    """The scenario's white noise, propagated by hand through the schedule, gives A.1.2.3, A.2.2.3 and A.5.2.3."""
    gyro_arw = 6.45 * DEG / math.sqrt(HOUR)          # rad/√s, as in the TOML
    accel_vrw = 64.7 / math.sqrt(HOUR)               # m/s/√s
    rates = [s.rate for s in scenario.schedule.segments if s.test == "rate" and s.group == 0]
    spread = math.sqrt(sum((r - np.mean(rates)) ** 2 for r in rates))  # 2.8061 rad/s
    fs_g, fs_a = scenario.acquisition.gyro_full_scale, scenario.acquisition.accel_full_scale
    assert gyro_arw / math.sqrt(30) / spread == pytest.approx(1.22e-4, rel=1e-3)        # A.1.2.3: u3 of K
    assert gyro_arw / math.sqrt(2 * 318) / fs_g == pytest.approx(3.41e-5, rel=1e-3)     # A.2.2.3: one group output
    assert accel_vrw / math.sqrt(30) / fs_a == pytest.approx(2.51e-3, rel=1e-3)          # A.5.2.3: one 30 s mean


def test_the_world_reproduces_the_inputs_of_the_budgets(scenario, results):
    """Read back from the estimates: the scatter of the inputs the noise was chosen for."""
    fs_g = scenario.acquisition.gyro_full_scale
    # A.4.2.3 (and A.1.2.3): the repeatability of a Kg coefficient, 1.22e-4
    for name in appendix_a_budget("A.4").parameters:
        assert std_of(results, name) == pytest.approx(1.22e-4, rel=TOLERANCE), name
    # A.2.2.3: B is the mean of 6 group outputs, so one output scatters by √6 × σ(B): 3.41e-5 FS_g
    for name in appendix_a_budget("A.2").parameters:
        assert math.sqrt(6) * std_of(results, name) / fs_g == pytest.approx(3.41e-5, rel=TOLERANCE), name
    # A.5.2.3: p = (U8 − U7)/ω², so one output scatters by σ(p)/√2: 2.51e-3 FS_a/ω²
    a5 = appendix_a_budget("A.5")
    for name in a5.parameters:
        unit = reading_unit_in_si(a5, name, scenario)
        assert std_of(results, name) / unit / math.sqrt(2) == pytest.approx(2.51e-3, rel=TOLERANCE), name


def expected_u(budget) -> float:
    """What the printed inputs give in this world (module docstring), in the budget's primary reading."""
    u1, u2, u3 = (budget.component(s) for s in ("u1", "u2", "u3"))
    if budget.item == "A.1":
        return math.hypot(u1.printed_value, u3.printed_value)
    if budget.item in ("A.2", "A.4"):
        return u3.gum_standard_uncertainty
    if budget.item == "A.3":  # the group outputs of A.2, half-differenced
        a2 = appendix_a_budget("A.2").component("u3")
        return math.sqrt(2) * a2.value_per_reading / 2
    return math.sqrt(sum(c.gum_standard_uncertainty ** 2 for c in budget.components))  # A.5


@pytest.mark.parametrize("item", ["A.1", "A.2", "A.3", "A.4", "A.5"])
def test_each_budgets_u_is_what_its_printed_inputs_give_here(items, item):
    budget = appendix_a_budget(item)
    c = items[item]
    assert c.mc_u == pytest.approx(expected_u(budget), rel=TOLERANCE)
    for p in c.per_parameter:
        assert p.std == pytest.approx(expected_u(budget), rel=TOLERANCE), p.name


def test_a5_reproduces_the_gum_recombination_of_its_printed_inputs_not_its_printed_u_c(items):
    a5 = appendix_a_budget("A.5")
    gum = math.sqrt(sum(c.gum_standard_uncertainty ** 2 for c in a5.components))  # 3.55e-3
    assert gum == pytest.approx(3.55e-3, rel=2e-3)
    assert items["A.5"].mc_u == pytest.approx(gum, rel=TOLERANCE)
    assert abs(items["A.5"].mc_u - a5.printed_combined_standard_uncertainty) > 5 * TOLERANCE * gum


def test_no_printed_u_c_is_reproduced(items):
    """The world is made of the printed inputs, yet no budget's printed u_c comes out (module docstring)."""
    for budget in APPENDIX_A:
        c = items[budget.item]
        assert abs(c.mc_u / budget.printed_combined_standard_uncertainty - 1) > 3 * TOLERANCE, budget.item


def test_the_verdicts_in_this_world(items):
    """A.1 and A.4 supported in every reading; the others depend on the reading."""
    assert [r.verdict for r in items["A.1"].readings] == ["supported", "supported"]
    assert [r.verdict for r in items["A.4"].readings] == ["supported"]
    assert items["A.2"].readings[0].verdict.startswith("over-stated") and items["A.2"].readings[1].verdict == \
        "under-stated"
    assert [r.verdict_kind for r in items["A.5"].readings] == ["supported", "under-stated", "under-stated"]
    assert not items["A.3"].holds_under_every_reading


def test_the_bias_is_only_noise(results):
    """No Earth rate, lever arm or drift: every estimator is unbiased to its Monte Carlo noise."""
    for name in ("gxx", "gyy", "gzz", "pxy", "pzy", "Kgxx", "Bgz"):
        e = results["error"].sel(parameter=name).values
        assert abs(e.mean()) <= 5 * e.std(ddof=1) / math.sqrt(e.size), name
