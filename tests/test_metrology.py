"""The metrology core (plansim.uncertainty.metrology) on its own: a simulate callable, no scenario.

The adaptive Monte Carlo of JCGM 101 7.9.4 is run on closed-form models whose output distribution
is known (JCGM 101 9.2: an additive model of normal inputs; 9.3-like: a rectangular input), and the
core's imports are checked: numpy, scipy and the standard library only.
"""

from __future__ import annotations

import ast
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from plansim.uncertainty.metrology import adaptive_monte_carlo, coverage_intervals, numerical_tolerance

CORE = Path(__file__).resolve().parent.parent / "plansim" / "uncertainty" / "metrology"


def additive(trials: int, seed: int) -> np.ndarray:
    """Y1 = X1 + X2 + X3 + X4 (four standard normals, JCGM 101 9.2.2) and Y2 = X5, X5 rectangular on [−1, 1]."""
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.standard_normal((trials, 4)).sum(axis=1), rng.uniform(-1.0, 1.0, trials)])


def test_adaptive_procedure_on_a_callable_reaches_the_known_answer():
    mc = adaptive_monte_carlo(additive, ("Y1", "Y2"), seed=11, digits=1, trials_per_block=2000, max_trials=400_000)
    assert mc.converged and mc.names == ("Y1", "Y2") and mc.values.shape == (mc.trials, 2)
    assert np.all(mc.tolerance_met())
    # JCGM 101 9.2.2: u(y) = 2, 95 % interval ±3.92; the rectangular: u = 1/√3, interval ±0.95
    exact_u = np.array([2.0, 1.0 / math.sqrt(3.0)])
    exact_high = np.array([2.0 * stats.norm.ppf(0.975), 0.95])
    # at the stop 2s ≤ δ: each result lies within δ of its limit (≈ 95 %; a factor 2 margin keeps this test steady)
    assert np.all(np.abs(mc.standard_uncertainty - exact_u) <= 2 * mc.tolerance)
    assert np.all(np.abs(mc.high - exact_high) <= 2 * mc.tolerance)
    assert np.all(np.abs(mc.low + exact_high) <= 2 * mc.tolerance)
    assert mc.excess_kurtosis[1] == pytest.approx(-1.2, abs=0.05)
    assert mc.index("Y2") == 1
    # the blocks are the callable's own: block h is simulate(M, seed_h)
    first = additive(mc.trials_per_block, int(np.random.SeedSequence(11).spawn(1)[0].generate_state(1, np.uint64)[0]))
    assert np.array_equal(mc.values[: mc.trials_per_block], first)
    ci = coverage_intervals(first, 0.95)
    assert np.allclose(mc.history[0, 2:], [ci["low"], ci["high"]])


def test_adaptive_procedure_checks_the_callable_and_its_output():
    with pytest.raises(TypeError, match="simulate"):
        adaptive_monte_carlo("not a model", ("Y",), seed=1)
    with pytest.raises(ValueError, match=r"returned shape \(500, 2\); expected \(500, 3\)"):
        adaptive_monte_carlo(additive, ("a", "b", "c"), seed=1, trials_per_block=500, max_trials=1000)
    with pytest.raises(ValueError, match="unknown output 'Y3'"):
        adaptive_monte_carlo(additive, ("Y1", "Y2"), seed=1, trials_per_block=500, max_trials=1000, monitor=["Y3"])
    with pytest.raises(ValueError, match="seed = -1"):
        adaptive_monte_carlo(additive, ("Y1", "Y2"), seed=-1, trials_per_block=500, max_trials=1000)
    assert numerical_tolerance(2.0, 1) == 0.5


def _imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            found.add(node.module)
    return found


def test_the_core_imports_only_numpy_scipy_and_the_standard_library():
    allowed = {"numpy", "scipy", "__future__"} | set(sys.stdlib_module_names)
    for path in sorted(CORE.glob("*.py")):
        outside = {m for m in _imports(path)
                   if m.split(".")[0] not in allowed and not m.startswith("plansim.uncertainty.metrology")}
        assert not outside, f"plansim/uncertainty/metrology/{path.name} imports {sorted(outside)}"


def test_a_verdict_with_too_few_trials_says_so():
    """Below 171 trials a 95 % claim covering every trial is within 3 binomial sd of 95 %: no claim could be
    found over-stated, so "supported" would say nothing (issue 9 §2)."""
    from plansim.uncertainty.metrology import coverage_verdict, minimum_trials_to_judge

    assert minimum_trials_to_judge(0.95) == 171
    verdict, factor = coverage_verdict(1.0, 100, 0.95, 10.0, 1.0)
    assert verdict == "too few trials to judge (100 < 171)" and factor == 10.0
    assert coverage_verdict(0.96, 170, 0.95, 1.5, 1.0)[0].startswith("too few trials to judge")
    # an under-statement is seen with few trials all the same
    assert coverage_verdict(0.5, 100, 0.95, 0.3, 1.0)[0] == "under-stated ×0.3"
    # from 171 trials on the verdict is the usual one
    assert coverage_verdict(1.0, 171, 0.95, 10.0, 1.0)[0] == "over-stated ×10"
    assert coverage_verdict(0.95, 171, 0.95, 1.0, 1.0)[0] == "supported"
    # k = 3: p = 99.73 %, over-statement needs 3 sd below 100 %
    assert minimum_trials_to_judge(0.9973) == math.ceil(9 * 0.9973 / 0.0027 - 1e-9)
    assert minimum_trials_to_judge(1.0) == 1
