"""The chapter's procedures and JJF 2003 on the same units (plansim.uncertainty.chapter_comparison,
plansim.runner.compare_chapter_misalignment / compare_chapter_procedures, ``plansim run chapter``): the gyro
misalignments by JJF 2003 §7.2.3 and eq. (6-8), the accelerometer cross-axis terms by the multi-position test and
the 8-position test (eq. (6-9)), the gyro drift model D0–D3 by JJF 2003 eq. (1)–(3) and the chapter's position
test, with its random drift (eq. (6-6))."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats

from plansim.config import parse_scenario
from plansim.estimate.chapter import CHAPTER_EARTH_RATE, RANDOM_DRIFT_FACTOR, cross_axis_ratios
from plansim.model.environment import EARTH_RATE
from plansim.model.parameters import unpack
from plansim.runner import compare_chapter_misalignment, compare_chapter_procedures
from plansim.uncertainty.chapter_comparison import (
    ACCEL_CHAPTER_NAMES,
    ACCEL_RATIO_NAMES,
    CHAPTER_NAMES,
    CHAPTER_TESTS,
    DRIFT_NAMES,
    OFF_DIAGONAL,
    RATIO_NAMES,
    compare_chapter,
    compare_misalignment,
    with_chapter_tests,
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


def test_chapter_names_follow_both_conventions():
    # the X accelerometer's response to an acceleration along Y: Ka[x, y]/Ka[x, x], the chapter's K_yx/K_x
    assert ACCEL_RATIO_NAMES[0] == "Kaxy/Kaxx" and ACCEL_CHAPTER_NAMES[0] == "K_yx/K_x"
    assert DRIFT_NAMES[:4] == ("Bgx", "Gxx", "Gxy", "Gxz") and DRIFT_NAMES[-1] == "Gzz"


@pytest.mark.parametrize("earth_rate", [False, True])
def test_zero_noise_every_test(ideal_document, earth_rate):
    """No noise, no table error: each of the chapter's reductions is exact on the same units.

    Without the Earth rate every estimate of both procedures equals the truth to rounding. With it, the chapter's
    drift model removes the Earth rate at its 15.04107 °/h while plansim simulates 7.292115e-5 rad/s (Δω apart),
    through JJF 2003's ``Kg`` from the same session, which with the Earth rate errs by about 1e-6 (its rate points
    are not whole turns, test_zero_noise_both_procedures); so D0–D3 are exact only to about ``Δω + 1e-6·Ω`` (the
    bounds below: 2Δω + 1e-5·Ω, over g for D1–D3 — a hundred-thousandth of the Earth rate's own effect); and
    JJF 2003's g-sensitivities absorb the vertical Earth rate exactly: the error of ``G[i, j]`` is
    ``Kg[i, j]·Ω·sin φ/g`` (docs/specification.md, "The Earth rate in the g-sensitivity")."""
    ideal_document["environment"]["earth_rate"] = earth_rate
    scenario = parse_scenario(ideal_document)
    result = compare_chapter(scenario, trials=2, seed=4)
    tests = np.array(result.tests)
    assert tuple(dict.fromkeys(result.tests)) == CHAPTER_TESTS and len(result.names) == 6 + 6 + 12
    chapter, jjf = result.errors("chapter"), result.errors("jjf2003")
    gravity = scenario.reduction.reference_gravity
    delta = 2 * abs(CHAPTER_EARTH_RATE - EARTH_RATE) + 1e-5 * EARTH_RATE if earth_rate else 0.0
    assert np.max(np.abs(chapter[:, tests == "accelerometer"])) <= 1e-15
    assert np.max(np.abs(chapter[:, tests == "misalignment"])) <= 1e-12
    drift = chapter[:, tests == "drift"].reshape(2, 3, 4)
    assert np.max(np.abs(drift[..., 0])) <= delta + 1e-18
    assert np.max(np.abs(drift[..., 1:])) <= delta / gravity + 1e-18
    jjf_drift = jjf[:, tests == "drift"].reshape(2, 3, 4)
    assert np.max(np.abs(jjf_drift[..., 0])) <= 1e-18
    Kg = unpack(scenario.truth_nominal)["Kg"]
    absorbed = Kg * EARTH_RATE * math.sin(scenario.environment.latitude) / gravity if earth_rate else 0 * Kg
    np.testing.assert_allclose(jjf_drift[..., 1:], np.broadcast_to(absorbed, (2, 3, 3)), rtol=1e-9, atol=1e-18)
    assert result.random_drift.shape == (2, 3) and np.max(result.random_drift) <= 1e-11
    assert result.earth_rate == (CHAPTER_EARTH_RATE if earth_rate else 0.0)


def test_white_noise_accelerometer_and_drift_closed_forms(ideal_document):
    """White noise only (gyro ARW 0.15 °/√h, accelerometer VRW 0.012 m/s/√h, no quantisation, table error or Earth
    rate), n = 400 trials, seed 21, three repeats of the drift positions.

    Closed forms, with σ² = N²/T the variance of a T-second segment mean (N the ARW or VRW, T = 30 s):
    - eq. (6-9) over the 8 positions: ``Ka[i, j] = (mean of 4 up − mean of 4 down)/(2g)``, variance
      σa²/(8g²), over ``Ka[i, i]²`` for the ratio;
    - the drift model over the 12 positions of a repeat (±x, ±y, ±z at two headings): the design [1, a_X, a_Y,
      a_Z] has orthogonal columns, so D0 has variance σg²/12 and D1–D3 σg²/(4g²) (four positions with ±g on
      each axis); the mean over R = 3 repeats divides both by 3;
    - eq. (6-6): (random drift/2.7)² is the sample variance of D0 over 3 repeats, so 2·(it)/(σg²/12) is χ²(2);
      over the 400 trials and 3 gyros the sum is χ²(2400).

    37 checks together at a false-alarm rate of 1e-3 (Bonferroni, 2.7e-5 each): each sample variance / closed
    form within the χ²(399)/399 quantiles [0.730, 1.325], each mean within 4.20 σ/√n, the pooled χ² within
    its quantiles [0.883, 1.126]. Power: a standard deviation 25 % high fails its check with probability 0.99
    (20 % low: 0.97), a bias of σ/3 with 0.99, a random drift whose variance is 25 % off with 0.9998.
    """
    ideal_document["mimu"]["noise"] = {"gyro_angle_random_walk": "0.15 deg/sqrt(h)",
                                       "accel_velocity_random_walk": "0.012 m/s/sqrt(h)"}
    scenario = parse_scenario(ideal_document)
    n, repeats = 400, 3
    result = compare_chapter(scenario, trials=n, seed=21, tests=("accelerometer", "drift"), repeats=repeats)
    assert result.path == "segment"
    schedule, indices = with_chapter_tests(scenario.schedule, ("accelerometer", "drift"), repeats=repeats)
    T = schedule.segments[indices["drift"][0]].dwell
    assert T == schedule.segments[indices["accelerometer"][0]].dwell == 30.0
    g = scenario.reduction.reference_gravity
    sigma_g2 = scenario.noise.gyro_angle_random_walk**2 / T  # (3,)
    sigma_a2 = scenario.noise.accel_velocity_random_walk**2 / T
    Ka = np.diag(unpack(scenario.truth_nominal)["Ka"])
    rows = np.array([i for i, _ in OFF_DIAGONAL])
    expected = np.concatenate([
        sigma_a2[rows] / (8 * g**2) / Ka[rows] ** 2,
        np.stack([sigma_g2 / 12, sigma_g2 / (4 * g**2), sigma_g2 / (4 * g**2), sigma_g2 / (4 * g**2)],
                 axis=1).ravel() / repeats])
    alpha = 1e-3 / 37
    low, high = stats.chi2.ppf([alpha / 2, 1 - alpha / 2], n - 1) / (n - 1)
    z = stats.norm.isf(alpha / 2)
    errors = result.errors("chapter")
    ratio = errors.var(axis=0, ddof=1) / expected
    assert np.all((ratio > low) & (ratio < high)), dict(zip(result.names, ratio.round(3)))
    assert np.all(np.abs(errors.mean(axis=0)) <= z * np.sqrt(expected / n)), result.names
    dof = 2 * n * 3
    pooled = np.sum((repeats - 1) * (result.random_drift / RANDOM_DRIFT_FACTOR) ** 2 / (sigma_g2 / 12)) / dof
    low2, high2 = stats.chi2.ppf([alpha / 2, 1 - alpha / 2], dof) / dof
    assert low2 < pooled < high2, pooled


def test_runner_wrapper_every_test():
    result = compare_chapter_procedures("jjf2003", trials=20, seed=3)
    assert result.scenario == "jjf2003" and result.truth.shape == (20, 24) and result.repeats == 3
    rows = result.summary()
    assert [r["test"] for r in rows] == ["misalignment"] * 6 + ["accelerometer"] * 6 + ["drift"] * 12
    assert {r["unit"] for r in rows} == {"1", "rad/s", "rad/s/(m/s^2)"}
    assert np.all(np.isfinite(result.chapter)) and np.all(result.random_drift > 0)
    # the same units whichever tests are appended: the misalignments' truth does not depend on the others
    alone = compare_chapter_procedures("jjf2003", trials=20, seed=3, tests=("misalignment",))
    np.testing.assert_array_equal(alone.truth, result.truth[:, :6])


def test_chapter_refusals(ideal_document):
    scenario = parse_scenario(ideal_document)
    with pytest.raises(ValueError, match="tests = 'spin'"):
        compare_chapter(scenario, trials=2, seed=1, tests="spin")
    with pytest.raises(ValueError, match="tests = \\(\\)"):
        compare_chapter(scenario, trials=2, seed=1, tests=())
    with pytest.raises(ValueError, match="repeats = 1"):
        compare_chapter(scenario, trials=2, seed=1, tests=("drift",), repeats=1)
    with pytest.raises(TypeError, match="tests = 3"):
        compare_chapter(scenario, trials=2, seed=1, tests=3)


def test_cli_run_chapter_text_json_plot(capsys, tmp_path):
    from plansim import cli

    plot = tmp_path / "chapter.png"
    assert cli.main(["run", "chapter", "--unit", "linear_gaussian", "--trials", "20", "--seed", "5", "--quiet",
                     "--plot", str(plot)]) == 0
    text = capsys.readouterr().out
    assert text.startswith("plansim run chapter --unit linear_gaussian: 20 trials, seed 5")
    assert "E_yx" in text and "K_yx/K_x" in text and "D0 (x gyro)" in text and "random drift, eq. (6-6)" in text
    assert plot.stat().st_size > 10_000
    assert cli.main(["run", "chapter", "--trials", "20", "--seed", "5", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["procedure"], doc["unit_scenario"], doc["trials"], doc["seed"]) == ("chapter", "jjf2003", 20, 5)
    assert len(doc["quantities"]) == 24 and doc["quantities"][0]["name"] == "Kgxy/Kgxx"
    assert set(doc["quantities"][0]["chapter"]) == {"mean", "std", "rms", "u_mean"}
    assert doc["random_drift"]["unit"] == "rad/s" and len(doc["random_drift"]["median"]) == 3
    # the JSON is the result: the same seed gives the same figures as the library call
    again = compare_chapter_procedures("jjf2003", trials=20, seed=5).summary()
    assert doc["quantities"][13]["jjf2003"]["rms"] == again[13]["jjf2003"]["rms"]


def test_cli_chapter_refusals(capsys):
    from plansim import cli

    for argv, message in (
            (["run", "chapter", "--trials", "1"], "--trials 1: must be >= 2"),
            (["run", "chapter", "--out", "x.nc"], "--out 'x.nc': not available with the procedure chapter"),
            (["run", "chapter", "--procedure", "points=5"], "--procedure 'points=5': only with the procedure jjf1535"),
            (["run", "chapter", "--unit", "chapter"], "--unit 'chapter': chapter is a procedure"),
            (["run", "chapter", "--unit", "nowhere"], "--unit 'nowhere'"),
            (["validate", "chapter"], "the chapter's procedures carry none")):
        assert cli.main(argv) == 2, argv
        assert message in capsys.readouterr().err, argv
    assert cli.main(["scenarios"]) == 0
    assert "chapter" in capsys.readouterr().out
