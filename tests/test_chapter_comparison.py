"""The gyro misalignments of the same units by JJF 2003 §7.2.3 and by the chapter's eq. (6-8)
(plansim.uncertainty.chapter_comparison, plansim.runner.compare_chapter_misalignment)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from plansim.config import parse_scenario
from plansim.estimate.chapter import cross_axis_ratios
from plansim.model.parameters import unpack
from plansim.runner import compare_chapter_misalignment
from plansim.uncertainty.chapter_comparison import (
    CHAPTER_NAMES,
    OFF_DIAGONAL,
    RATIO_NAMES,
    compare_misalignment,
    with_rate_turns,
)
from plansim.units import DEG

ARW = 0.15 * DEG / 60.0  # 0.15 °/√h in rad/√s


def test_names_follow_both_conventions():
    # plansim: row = gyro, column = rate axis (Kgxy = X gyro to a rate about Y); the chapter: E_yx = X gyro
    # (output) to a rate about Y (input), over the X gyro's scale factor
    assert RATIO_NAMES[0] == "Kgxy/Kgxx" and CHAPTER_NAMES[0] == "E_yx"
    assert RATIO_NAMES[3] == "Kgyz/Kgyy" and CHAPTER_NAMES[3] == "E_zy"
    assert len(set(OFF_DIAGONAL)) == 6 and all(b != a for b, a in OFF_DIAGONAL)


@pytest.mark.parametrize("earth_rate", [False, True])
def test_zero_noise_both_procedures(ideal_document, earth_rate):
    """No noise, no table error: eq. (6-8) is exact with or without the Earth rate (whole turns); JJF 2003's
    slope is exact without it and takes some of it (turns that are not whole) with it."""
    ideal_document["environment"]["earth_rate"] = earth_rate
    scenario = parse_scenario(ideal_document)
    result = compare_misalignment(scenario, trials=2, seed=4)
    truth = cross_axis_ratios(unpack(scenario.truth_nominal)["Kg"])
    rows, cols = np.array(OFF_DIAGONAL).T
    np.testing.assert_allclose(result.truth, np.broadcast_to(truth[rows, cols], (2, 6)), atol=1e-15)
    assert np.max(np.abs(result.errors("chapter"))) <= 1e-12
    jjf = np.max(np.abs(result.errors("jjf2003")))
    assert jjf > 1e-9 if earth_rate else jjf <= 1e-12


def test_white_noise_scatter_matches_closed_form(ideal_document):
    """White gyro noise only (ARW 0.15 °/√h, no table error, no Earth rate), n = 400 trials, seed 13.

    Closed forms: a segment mean of T seconds has variance ARW²/T. JJF 2003's slope (eq. (5)) over the nine
    30 s rate points x_k has variance (ARW²/30)/Σ(x_k − x̄)², so its misalignment error has that over
    Kg[b, b]²; eq. (6-8) over one turn each way at Ω = 10 °/s (T = 36 s) has 2(ARW²/36)/(2Ω·Kg[b, b])².
    (The error of the scale factor in the denominator adds (Kg[b, a]/Kg[b, b])² ≈ 1e-6 of that: negligible.)

    Checks, 24 in all, together at a false-alarm rate of 1e-3 (Bonferroni, 4.2e-5 each): each sample
    variance / closed form within the χ²(399)/399 quantiles [0.736, 1.317], each mean within 4.10 σ/√n.
    Power (σ = 2.95e-5 for eq. (6-8), 2.84e-6 for JJF 2003, so σ/√n = 1.47e-6 and 1.42e-7): a standard
    deviation 25 % above its closed form (variance × 1.56) fails its check with probability 0.99; a bias of
    1e-5 in eq. (6-8)'s misalignment (2 % of a 5e-4 one) with probability 0.996, and of 1e-6 in JJF 2003's
    with 0.998; a factor 2 lost in eq. (6-8) (a bias the size of the misalignment) always.
    """
    ideal_document["mimu"]["noise"] = {"gyro_angle_random_walk": "0.15 deg/sqrt(h)"}
    scenario = parse_scenario(ideal_document)
    n = 400
    result = compare_misalignment(scenario, trials=n, seed=13)
    assert result.path == "segment"
    K = np.diag(unpack(scenario.truth_nominal)["Kg"])
    rates = np.array([s.rate for s in scenario.schedule.segments if s.test == "rate" and s.group == 0])
    spread = np.sum((rates - rates.mean()) ** 2)
    omega = 10 * DEG
    b = np.array([row for row, _ in OFF_DIAGONAL])
    expected = {"jjf2003": (ARW**2 / 30.0) / spread / K[b] ** 2,
                "chapter": 2 * (ARW**2 / 36.0) / (2 * omega * K[b]) ** 2}
    alpha = 1e-3 / 24
    low, high = stats.chi2.ppf([alpha / 2, 1 - alpha / 2], n - 1) / (n - 1)
    z = stats.norm.isf(alpha / 2)
    for procedure, variance in expected.items():
        errors = result.errors(procedure)
        ratio = errors.var(axis=0, ddof=1) / variance
        assert np.all((ratio > low) & (ratio < high)), f"{procedure}: variance / closed form = {ratio}"
        assert np.all(np.abs(errors.mean(axis=0)) <= z * np.sqrt(variance / n)), procedure
    # the chapter's one turn at 10 °/s has √(25850/200) ≈ 11 times JJF 2003's scatter under white noise
    assert math.sqrt(expected["chapter"][0] / expected["jjf2003"][0]) == pytest.approx(
        math.sqrt(2 / 36 * 30 * spread / (4 * omega**2)), rel=1e-12)


def test_runner_wrapper_and_summary():
    result = compare_chapter_misalignment("jjf2003", trials=20, seed=2, turns=2)
    assert result.scenario == "jjf2003" and result.turns == 2 and result.truth.shape == (20, 6)
    rows = result.summary()
    assert [r["name"] for r in rows] == list(RATIO_NAMES)
    errors = result.errors("chapter")
    assert rows[0]["chapter"]["rms"] == pytest.approx(math.sqrt(np.mean(errors[:, 0] ** 2)), rel=1e-12)
    assert rows[0]["chapter"]["u_mean"] == pytest.approx(np.std(errors[:, 0], ddof=1) / math.sqrt(20), rel=1e-12)
    assert np.all(np.isfinite(result.jjf2003)) and np.all(np.isfinite(result.chapter))


def test_refusals(ideal_document):
    scenario = parse_scenario(ideal_document)
    with pytest.raises(TypeError, match="scenario: expected a plansim Scenario"):
        compare_misalignment("jjf2003", trials=2, seed=1)
    with pytest.raises(ValueError, match="trials = 1"):
        compare_misalignment(scenario, trials=1, seed=1)
    with pytest.raises(ValueError, match="procedure = 'both'"):
        compare_misalignment(scenario, trials=2, seed=1).errors("both")
    extended = with_rate_turns(scenario.schedule)
    assert len(extended) == len(scenario.schedule) + 6 and extended.segments[-1].test == "rotation"
