"""Monte Carlo per JCGM 101 / JCGM 102 (plansim.uncertainty.metrology and .monte_carlo) and `plansim validate`.

Acceptance of issue 3:
(1) linear-Gaussian scenario: GUM and adaptive MCM agree, the validation says "yes" for every
    parameter, the GUM 95 % interval covers the truth within the binomial tolerance;
(3) a non-Gaussian scenario (coarse quantisation without dither) fails validation, with the reason;
(4) the adaptive MCM stops by the 7.9.4 rule and its numerical tolerance is met;
plus JCGM 102 (correlation, joint region) and the claims / CLI plumbing.

Tolerances come from the trial counts: a coverage fraction of n trials has standard deviation
sqrt(p(1 − p)/n) and tests allow COVERAGE_Z of them; a correlation coefficient has standard
deviation (1 − r²)/√n.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats

from plansim.cli import main
from plansim.io.claims import load_claims
from plansim.io.scenario_file import load_scenario
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES
from plansim.report.validation import format_report
from plansim.runner import adaptive_monte_carlo, run, validate
from plansim.uncertainty.claims import appendix_a_claims, parse_claims
from plansim.uncertainty.metrology import (
    block_seeds,
    correlation_matrix,
    coverage_intervals,
    coverage_tolerance,
    coverage_verdict,
    minimum_block_size,
    numerical_tolerance,
    validate_gum,
)
from plansim.uncertainty.monte_carlo import KG_PARAMETERS, joint_region_check

SEED = 7_20_2024
COVERAGE_Z = 4.0  # binomial standard deviations allowed for an observed coverage
P = 0.95


# ----------------------------------------------------------------------------- JCGM 101 building blocks


def test_numerical_tolerance_follows_7_9_2():
    # JCGM 101 7.9.2: u = 0.002 26 regarded to two significant digits: c = 23, l = −4, δ = 0.000 05
    assert numerical_tolerance(0.00226, 2) == pytest.approx(0.5e-4)
    assert numerical_tolerance(0.00226, 1) == pytest.approx(0.5e-3)
    assert numerical_tolerance(9.96e-5, 2) == pytest.approx(0.5e-5)  # c rounds to 100: one more digit
    assert numerical_tolerance(1.0, 1) == pytest.approx(0.5)
    assert np.allclose(numerical_tolerance([0.0, 3.4e-7, 0.047], 1), [0.0, 0.5e-7, 0.5e-2])
    with pytest.raises(ValueError, match="n_dig"):
        numerical_tolerance(1.0, 0)


def test_coverage_intervals_follow_7_7():
    y = np.arange(1.0, 101.0)  # M = 100, p = 0.95: q = 95, r = ⌊(M − q + 1)/2⌋ = 3
    ci = coverage_intervals(y, P)
    assert (ci["low"], ci["high"]) == (3.0, 98.0)
    assert ci["shortest_high"] - ci["shortest_low"] == 95.0
    # an exponential sample: the shortest interval starts at the smallest value
    rng = np.random.default_rng(SEED)
    e = rng.exponential(size=20000)
    ci = coverage_intervals(e, P)
    assert ci["shortest_low"] == e.min()
    assert ci["shortest_high"] - ci["shortest_low"] < ci["high"] - ci["low"]
    # a normal sample: the symmetric interval ends at ±1.96σ within their sampling error
    n = 200_000
    z = rng.standard_normal((n, 2))
    ci = coverage_intervals(z, P)
    q = stats.norm.ppf(0.975)
    sd = math.sqrt(0.025 * 0.975 / n) / stats.norm.pdf(q)  # standard deviation of a sample quantile
    assert np.all(np.abs(ci["high"] - q) <= 5 * sd) and np.all(np.abs(ci["low"] + q) <= 5 * sd)
    with pytest.raises(ValueError, match="too few"):
        coverage_intervals(np.arange(10.0), P)


def test_block_seeds_are_reproducible_and_distinct():
    seeds = block_seeds(SEED, 5)
    assert len(set(seeds)) == 5
    assert block_seeds(SEED, 2, start=3) == seeds[3:5]
    assert block_seeds(SEED + 1, 1) != seeds[:1]
    assert minimum_block_size(P) == 10_000


def test_validate_gum_arithmetic():
    out = validate_gum([0.0, 0.1], [1.96, 1.96], [1.0, 1.0], [-1.96, -1.5], [1.96, 2.5], digits=1)
    assert np.allclose(out.delta, 0.5)
    assert np.allclose(out.d_low, [0.0, abs(0.1 - 1.96 + 1.5)])
    assert np.allclose(out.d_high, [0.0, abs(0.1 + 1.96 - 2.5)])
    assert out.validated.tolist() == [True, True]
    out = validate_gum([0.0], [1.96], [1.0], [-1.645], [1.645], digits=2)  # rectangular: ±1.65u
    assert out.validated.tolist() == [False]


def test_joint_region_of_independent_gaussians():
    """JCGM 102: nine independent normal outputs — ellipsoid χ²₉(0.95) holds 95 %, the box of nine
    k = 2 intervals only 0.9545⁹ ≈ 66 %."""
    rng = np.random.default_rng(SEED)
    n = 40_000
    values = np.zeros((n, 39))
    idx = [PARAMETER_INDEX[name] for name in KG_PARAMETERS]
    values[:, idx] = rng.standard_normal((n, 9)) * np.arange(1, 10)
    check = joint_region_check(values, KG_PARAMETERS, P)
    tol = coverage_tolerance(n, P, COVERAGE_Z)
    assert check.dimension == 9
    assert abs(check.fraction_in_ellipsoid - P) <= tol
    box = (2 * stats.norm.cdf(2) - 1) ** 9
    assert abs(check.fraction_all_marginal - box) <= COVERAGE_Z * math.sqrt(box * (1 - box) / n)
    assert check.misleading and "ellipsoid" in check.message
    assert check.mc_k == pytest.approx(math.sqrt(stats.chi2.ppf(P, 9)), rel=0.02)


# ----------------------------------------------------------------------------- (4) the 7.9.4 stopping rule


@pytest.fixture(scope="module")
def linear():
    return load_scenario("linear_gaussian")


@pytest.fixture(scope="module")
def adaptive(linear):
    return adaptive_monte_carlo(linear, digits=1, trials_per_block=2000, max_trials=200_000, seed=SEED)


def test_adaptive_mcm_stops_by_the_7_9_4_rule(adaptive):
    mc = adaptive
    h, m = mc.blocks, mc.trials_per_block
    assert mc.converged and h >= 2 and mc.errors.shape == (h * m, 39)
    # recompute the rule from the block results: 2s ≤ δ(u of all values) at h blocks …
    def rule(blocks: int) -> bool:
        s = mc.history[:blocks].std(axis=0, ddof=1) / math.sqrt(blocks)
        delta = numerical_tolerance(mc.errors[: blocks * m].std(axis=0, ddof=1), mc.digits)
        return bool(np.all(2 * s <= delta[None, :]))

    assert rule(h)
    assert np.allclose(mc.block_sd, mc.history.std(axis=0, ddof=1) / math.sqrt(h))
    # … and not before: the procedure stopped at the first h that met it
    assert not any(rule(b) for b in range(2, h))
    # the block statistics are each block's y, u, y_low, y_high
    first = mc.errors[:m]
    ci = coverage_intervals(first, P)
    assert np.allclose(mc.history[0], [first.mean(0), first.std(0, ddof=1), ci["low"], ci["high"]])
    assert np.all(mc.tolerance_met())


def test_adaptive_mcm_meets_its_numerical_tolerance(adaptive, linear):
    """y, u, y_low, y_high within δ of a reference Monte Carlo ten times as long (independent seed).

    At the stop 2s ≤ δ, so each result lies within δ of its limit with probability ≳ 95 % (2
    standard deviations); the reference adds s/√10. Over the 4 × 39 results the fraction within δ
    must be at least P(|Z| ≤ 2/√1.1) minus COVERAGE_Z binomial standard deviations."""
    mc = adaptive
    ref_trials = 10 * mc.trials
    ref = run(linear, trials=ref_trials, seed=SEED + 1, path="segment")["error"].values
    ci = coverage_intervals(ref, P)
    reference = np.stack([ref.mean(0), ref.std(0, ddof=1), ci["low"], ci["high"]])
    result = np.stack([mc.estimate, mc.standard_uncertainty, mc.low, mc.high])
    within = np.abs(result - reference) <= mc.tolerance[None, :]
    p_within = 2 * stats.norm.cdf(2 / math.sqrt(1.1)) - 1
    n = within.size
    assert within.mean() >= p_within - COVERAGE_Z * math.sqrt(p_within * (1 - p_within) / n)


def test_adaptive_mcm_is_reproducible_and_checks_its_arguments(linear):
    a = adaptive_monte_carlo(linear, trials_per_block=500, max_trials=1000, seed=3, parameters=["Kgxx"])
    b = adaptive_monte_carlo(linear, trials_per_block=500, max_trials=1000, seed=3, parameters=["Kgxx"])
    assert np.array_equal(a.errors, b.errors) and a.monitored == ("Kgxx",)
    assert not a.converged or a.blocks == 2
    with pytest.raises(ValueError, match="two blocks"):
        adaptive_monte_carlo(linear, trials_per_block=500, max_trials=600)
    with pytest.raises(ValueError, match="trials_per_block"):
        adaptive_monte_carlo(linear, trials_per_block=20)
    with pytest.raises(ValueError, match="unknown parameter 'Kgqq'"):
        adaptive_monte_carlo(linear, trials_per_block=500, max_trials=1000, parameters=["Kgqq"])
    with pytest.raises(TypeError, match="Scenario"):
        adaptive_monte_carlo("linear_gaussian")


# ----------------------------------------------------------------------------- (1) linear-Gaussian: GUM validated


@pytest.fixture(scope="module")
def linear_report(linear):
    # JCGM 101 8.2 runs the validation MCM to δ/5; 1/2 here keeps CI short (the slow test below uses
    # 1/5): at the stop the Monte Carlo noise of d is ≤ δ/4, four of its standard deviations.
    return validate(linear, digits=1, tolerance_fraction=0.5, trials_per_block=5000, seed=SEED)


def test_linear_gaussian_gum_validated_for_every_parameter(linear_report):
    r = linear_report
    assert r.mcm.converged
    failed = {p.name: p.reasons for p in r.parameters if not p.validated}
    assert not failed
    for p in r.parameters:
        assert p.d_low <= p.delta and p.d_high <= p.delta
        assert abs(p.mcm_u - p.gum_u) <= p.delta  # GUM and MCM agree on u to the tolerance
        assert abs(p.mcm_y - p.gum_y) <= p.delta
    assert "validated for 39 of 39" in format_report(r, details=False)


def test_linear_gaussian_gum_interval_covers_the_truth(linear_report):
    r = linear_report
    n = r.mcm.trials
    tol = coverage_tolerance(n, P, COVERAGE_Z)
    coverage = np.array([p.coverage_gum for p in r.parameters])
    assert np.all(np.abs(coverage - P) <= tol), dict(zip(PARAMETER_NAMES, coverage))


def test_linear_gaussian_correlations_gum_versus_mcm(linear_report):
    """JCGM 102: the GUM covariance of the 39 errors against the Monte Carlo correlation matrix."""
    r = linear_report
    n = r.mcm.trials
    gum = r.gum.correlation()
    mcm = r.mcm_correlation
    assert np.allclose(mcm, correlation_matrix(r.mcm.errors))
    sd = (1 - gum**2) / math.sqrt(n)
    off = ~np.eye(39, dtype=bool)
    assert np.all(np.abs(mcm - gum)[off] <= 5 * sd[off] + 1e-12)
    # the three scale factors share the systematic rate error: positively correlated
    i, j = PARAMETER_INDEX["Kgxx"], PARAMETER_INDEX["Kgyy"]
    assert gum[i, j] > 0.5


def test_marginal_k2_intervals_mislead_for_the_kg_matrix(linear_report):
    j = linear_report.joint
    n = linear_report.mcm.trials
    assert j.parameters == KG_PARAMETERS
    tol = coverage_tolerance(n, P, COVERAGE_Z)
    assert abs(j.fraction_in_ellipsoid - P) <= tol
    assert abs(j.gum_fraction_in_ellipsoid - P) <= tol
    assert j.fraction_all_marginal < P - tol and j.misleading
    assert j.box_k > 2.0


@pytest.mark.slow
def test_linear_gaussian_validated_with_the_jcgm_101_8_2_tolerance(linear):
    """As above with the tolerance JCGM 101 8.2 asks of a validation run (δ/5; ~20 s)."""
    r = validate(linear, seed=SEED + 2)
    assert r.mcm.converged and r.tolerance_fraction == pytest.approx(0.2)
    assert all(p.validated for p in r.parameters), {p.name: p.reasons for p in r.parameters if not p.validated}
    tol = coverage_tolerance(r.mcm.trials, P, COVERAGE_Z)
    assert all(abs(p.coverage_gum - P) <= tol for p in r.parameters)


# ----------------------------------------------------------------------------- (3) non-Gaussian: validation fails


@pytest.fixture(scope="module")
def coarse_report():
    # the gyro biases are what the scenario is about; they decide the stop
    return validate("coarse_quantisation", trials_per_block=5000, max_trials=60_000, seed=SEED,
                    monitor=["Bgx", "Bgy", "Bgz"])


def test_coarse_quantisation_fails_validation_and_says_why(coarse_report):
    r = coarse_report
    assert "rectangular" in r.description
    assert np.all(r.mcm.tolerance_met()[[PARAMETER_INDEX[n] for n in ("Bgx", "Bgy", "Bgz")]])
    n = r.mcm.trials
    for name in ("Bgx", "Bgy", "Bgz"):
        p = r.parameter(name)
        assert not p.validated
        assert max(p.d_low, p.d_high) > p.delta
        # the GUM gets u right (the shared-offset quantisation model) …
        assert abs(p.mcm_u - p.gum_u) <= p.delta
        # … but not the shape: one (nearly) rectangular input — the sawtooth of the quantiser, its
        # corners rounded by the little noise — platykurtic far beyond the sampling error of a
        # Gaussian's excess kurtosis (sqrt(24/n)), and a 95 % interval narrower than ±1.96u
        assert r.mcm.excess_kurtosis[PARAMETER_INDEX[name]] < -1.0 < -5 * math.sqrt(24 / n)
        half = 0.5 * (p.mcm_high - p.mcm_low) / p.mcm_u
        assert half < p.gum_k - p.delta / p.mcm_u
        text = " ".join(p.reasons)
        assert "not Gaussian" in text and "quantisation, gyros dominates" in text and "rectangular" in text
        # the GUM's 95 % interval over-covers the truth
        assert p.coverage_gum > P + coverage_tolerance(n, P, COVERAGE_Z)
    report = format_report(r)
    assert "GUM framework validated: no" in report and "because the MCM 95% interval is ±1.6" in report


# ----------------------------------------------------------------------------- claims and coverage of the truth


def test_claims_file_and_verdicts(tmp_path, linear, linear_report):
    path = tmp_path / "claims.toml"
    path.write_text('[items."A.2"]\nU = 5.36e-4\n\n[parameters.Kgxx]\nU = "1e-5"\nk = 2\n\n'
                    '[parameters.Bax]\nU = "50 ug"\nk = 3\n')
    claims = load_claims(path, linear)
    fs_g = linear.acquisition.gyro_full_scale
    assert claims["Bgy"].expanded_uncertainty == pytest.approx(5.36e-4 * fs_g)
    assert claims["Kgxx"].expanded_uncertainty == pytest.approx(1e-5) and claims["Kgxx"].coverage_probability == P
    assert claims["Bax"].coverage_probability == pytest.approx(2 * stats.norm.cdf(3) - 1)
    assert set(claims) == {"Bgx", "Bgy", "Bgz", "Kgxx", "Bax"}
    defaults = appendix_a_claims(linear)
    assert len(defaults) == 27 and defaults["Kgxx"].source == "Appendix A A.1 (printed)"
    # verdicts: a 95 % claim that covers 80 % is under-stated; one that covers everything, 3× wide, over-stated
    assert coverage_verdict(0.80, 10_000, P, 0.6, 1.0)[0].startswith("under-stated")
    assert coverage_verdict(0.9999, 10_000, P, 3.0, 1.0)[0] == "over-stated ×3"
    assert coverage_verdict(0.95, 10_000, P, 1.0, 1.0)[0] == "supported"
    # the linear report's coverage of the Appendix A claims: over-stated by large factors
    kgxx = linear_report.parameter("Kgxx")
    assert kgxx.coverage_claimed == 1.0 and kgxx.claim_verdict.startswith("over-stated")
    assert kgxx.claim_factor == pytest.approx(kgxx.claimed_U / kgxx.mcm_U95_about_truth, rel=1e-9)


@pytest.mark.parametrize("text, error, match", [
    ('[items."A.9"]\nU = 1e-4\n', ValueError, "unknown Appendix A item"),
    ("[parameters.Kgqq]\nU = 1e-4\n", ValueError, "unknown parameter"),
    ('[parameters.Bgx]\nU = "1e-4"\n', ValueError, "not a unit of angular_rate"),
    ('[parameters.Bgx]\nU = "1 deg/h"\nk = 0\n', ValueError, r"\.k = 0"),
    ('[parameters.Bgx]\nUc = "1 deg/h"\n', ValueError, "expected U"),
    ('[items."A.1"]\nU = "1e-4 ppm"\n', ValueError, "plain number"),
    ("[claims]\n", ValueError, "unknown section"),
    ("", ValueError, "no claims"),
])
def test_claims_errors_name_the_field(text, error, match, linear):
    import tomllib

    with pytest.raises(error, match=match):
        parse_claims(tomllib.loads(text), linear, source="c.toml")


# ----------------------------------------------------------------------------- nothing to validate


def test_a_zero_noise_scenario_has_nothing_to_validate(capsys):
    """ideal: every GUM u_c is 0, so δ = 0 and the Monte Carlo would run to --max-trials on round-off
    (issue 9 §2); validate says so before simulating."""
    with pytest.raises(ValueError, match="nothing to validate"):
        validate("ideal", trials_per_block=2000, max_trials=4000, seed=SEED)
    code = main(["validate", "ideal", "--quiet", "--trials-per-block", "2000", "--max-trials", "4000"])
    _, err = capsys.readouterr()
    assert code == 2 and "nothing to validate" in err and "ideal" in err


def test_outputs_without_uncertainty_do_not_hold_the_monte_carlo(linear):
    """Gyro white noise only: the accelerometer parameters have u_c = 0 (δ = 0, which round-off never
    meets); the adaptive procedure stops on the others and still reports every parameter."""
    import dataclasses

    t = linear.turntable
    zero = dataclasses.replace(t.position_accuracy, scale=0.0)
    table = dataclasses.replace(t, **{f.name: zero for f in dataclasses.fields(t) if f.name != "rate_smoothness"},
                                rate_smoothness=0.0)
    noise = dataclasses.replace(linear.noise, accel_velocity_random_walk=np.zeros(3))
    sc = dataclasses.replace(linear, turntable=table, noise=noise, truth_spread=np.zeros_like(linear.truth_spread))
    r = validate(sc, trials_per_block=2000, max_trials=40_000, seed=SEED, tolerance_fraction=0.5)
    silent = {p.name for p in r.parameters if p.gum_u == 0.0}
    assert silent >= {n for n in PARAMETER_NAMES if n[:2] in ("Ka", "Ba") or n[0] == "p"}
    assert r.mcm.converged and not silent & set(r.mcm.monitored)
    assert set(r.mcm.monitored) == set(PARAMETER_NAMES) - silent
    assert len(r.parameters) == 39


# ----------------------------------------------------------------------------- the command line


def test_cli_validate_json_has_the_documented_keys(capsys):
    code = main(["validate", "linear_gaussian", "--json", "--trials-per-block", "2000", "--max-trials", "4000",
                 "--seed", "5"])
    out, _ = capsys.readouterr()
    assert code == 0
    doc = json.loads(out)
    keys = {"name", "gum_u", "gum_dof", "gum_U95", "mcm_u", "mcm_low", "mcm_high", "delta", "d_low", "d_high",
            "validated", "coverage_claimed", "coverage_gum"}
    assert [p["name"] for p in doc["parameters"]] == list(PARAMETER_NAMES)
    for p in doc["parameters"]:
        assert keys <= set(p)
        assert isinstance(p["validated"], bool)
    assert doc["mcm"]["trials"] == 4000 and doc["mcm"]["seed"] == 5
    assert [a["item"] for a in doc["appendix_a"]] == ["A.1", "A.2", "A.3", "A.4", "A.5"]
    json.dumps(doc, allow_nan=False)  # strict JSON


def test_cli_validate_text_and_errors(capsys, tmp_path):
    code = main(["validate", "linear_gaussian", "--trials-per-block", "2000", "--max-trials", "4000", "--quiet",
                 "--summary"])
    out, _ = capsys.readouterr()
    assert code == 0
    assert "Summary (JCGM 101 8" in out and "Appendix A of JJF 2003-2022" in out and "JCGM 102" in out
    code = main(["validate", "linear_gaussian", "--claims", str(tmp_path / "missing.toml")])
    _, err = capsys.readouterr()
    assert code == 2 and "plansim: error" in err and "missing.toml" in err
    code = main(["validate", "linear_gaussian", "--digits", "0"])
    _, err = capsys.readouterr()
    assert code == 2 and "--digits" in err
