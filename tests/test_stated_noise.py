"""The segment means against the slow noise the lab states for its unit (plansim.diagnose.stated).

The stated noise's covariance of segment means is checked against the averaged process simulated exactly; the
test itself on recordings simulated by plansim with fixed seeds: a slow disturbance that the noise estimated from
the recording takes up is flagged, the same recording without it is not.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.checks.diagnose_check import _acquire, _without_quantiser
from plansim.diagnose.procedure import diagnose, diagnosis_json, levels, scenario_diagnose_options
from plansim.diagnose.scores import undithered_channels
from plansim.diagnose.stated import STATED_NOISE_MARGIN, stated_noise_test
from plansim.fit import fit_recording, resolve_site, scenario_fit_options
from plansim.fit.noise import StatedSlowNoise, stated_slow_noise
from plansim.io.scenario_file import load_scenario
from plansim.report.diagnose import diagnose_report
from plansim.runner import simulate_and_record
from plansim.simulate.arguments import bias_instability_sigma

DEG_PER_H = math.radians(1.0) / 3600.0


def _averages(paths: np.ndarray, dt: float, spans) -> np.ndarray:
    """(trials, len(spans)) the mean of each path over each (start, duration) span, s."""
    return np.column_stack([paths[:, int(round(a / dt)):int(round((a + T) / dt))].mean(axis=1) for a, T in spans])


def test_the_stated_noise_of_segment_means_is_the_averaged_process():
    """A Gauss–Markov process (σ 1, τ 50 s) and a random walk (K 0.1/√s from t = 0), simulated exactly at 0.25 s over
    3000 paths, averaged over three segments (100 s at 0–100 s, 30 s at 130–160 s, 60 s at 400–460 s): the sample
    covariance of the averages matches StatedSlowNoise.mean_covariance entry by entry within 5 of its standard
    errors and 2 % (the first segment's variance: 0.57 σ², standard error 0.015 σ²; the unaveraged σ² would be about
    30 standard errors off, so the check sees the averaging)."""
    rng = np.random.default_rng(7)
    dt, n, trials, tau = 0.25, 1840, 3000, 50.0
    spans = [(0.0, 100.0), (130.0, 30.0), (400.0, 60.0)]
    times = np.array([a + T / 2 for a, T in spans])
    durations = np.array([T for _, T in spans])
    phi = math.exp(-dt / tau)
    x = np.empty((trials, n))
    x[:, 0] = rng.standard_normal(trials)
    shocks = rng.standard_normal((trials, n)) * math.sqrt(1 - phi**2)
    for k in range(1, n):
        x[:, k] = phi * x[:, k - 1] + shocks[:, k]
    # the walk's value at the end of each step (its offset of dt/2 against the continuous average is negligible)
    walk = 0.1 * np.cumsum(rng.standard_normal((trials, n)) * math.sqrt(dt), axis=1)
    zero = np.zeros(6)
    gm = StatedSlowNoise(np.full(6, 1.0), tau, zero, 0.0, zero)
    rw = StatedSlowNoise(zero, tau, zero, 0.0, np.full(6, 0.1))
    for paths, stated in ((x, gm), (walk, rw)):
        a = _averages(paths, dt, spans)
        sample = np.cov(a, rowvar=False)
        expected = stated.mean_covariance(0, times, durations)
        se = np.sqrt((expected**2 + np.outer(np.diag(expected), np.diag(expected))) / (trials - 1))
        assert np.all(np.abs(sample - expected) < 5 * se + 0.02 * np.abs(expected)), (sample, expected)
    assert gm.mean_covariance(0, times, durations)[0, 0] == pytest.approx(2 * (2 - 1 + math.exp(-2)) / 4)


def test_the_stated_slow_noise_is_the_scenarios_as_plansim_simulates_it():
    jjf = stated_slow_noise(load_scenario("jjf2003"))
    assert np.allclose(jjf.bias_instability_sigma[:3], bias_instability_sigma(2 * DEG_PER_H))
    assert jjf.correlation_time == 100.0 and "scenario 'jjf2003'" in jjf.source
    assert "bias instability σ 2.15 deg/h over 100 s" == jjf.describe(0)
    plain = stated_slow_noise(load_scenario("linear_gaussian"))
    assert not np.any(plain.bias_instability_sigma) and plain.describe(3) == "no slow noise"


@pytest.fixture(scope="module")
def recordings():
    return _recordings(22)


def _recordings(seed: int):
    """A jjf2003 recording and the same with a 97 s sine of 20 deg/h on gx (before the quantiser), and the scenario."""
    scenario = load_scenario("jjf2003")
    clean = simulate_and_record(_without_quantiser(scenario), seed=seed, trial=0)
    samples = np.array(clean.samples, dtype=float)
    t = np.arange(samples.shape[0]) / 100.0
    disturbed = samples.copy()
    disturbed[:, 0] += 20 * DEG_PER_H * np.sin(2 * np.pi * t / 97.0)
    return [type(clean)(_acquire(scenario, x), clean.schedule, dict(clean.attrs)) for x in (samples, disturbed)], \
        scenario


def test_a_slow_disturbance_the_recordings_own_noise_takes_up_is_beyond_the_stated_noise(recordings):
    """A disturbance on gx with a 97 s period and 20 deg/h amplitude (a table's or a building's, outside any
    catalogue): the samples' Allan fit and the between-segment noise take it up as gx's noise (its segment means'
    predicted s.d. rose to about 10 deg/h), so the lack of fit, weighed against that noise, does not flag it
    (p 0.77 on this seed). Against the slow noise jjf2003 states (2 deg/h over 100 s, taken up to twice that), gx's
    means scatter 3.5 times what the statement allows: flagged, on gx alone, p below 1e-20, and the report says so.
    The same recording without the disturbance: gx, gy, gz at 0.6-0.8 of the statement, not flagged."""
    (null, disturbed), scenario = recordings
    site, options = resolve_site(scenario=scenario), scenario_diagnose_options(scenario)
    d = diagnose(disturbed, site, null_draws=200, seed=22, **options)
    test = d.stated_noise_after
    assert test.flagged and test.p_value < 1e-20 and test.level == levels(0.05)["stated_noise"]
    assert [item["channel"] for item in test.flagged_channels()] == ["gx"]
    assert test.flagged_channels()[0]["sd_ratio"] > 2.5
    assert {item["channel"] for item in test.channels} == {"gx", "gy", "gz"}  # the 12-bit accelerometers undithered
    assert d.unexplained["flagged"] and d.unexplained["stated_noise"][0]["channel"] == "gx"
    report = diagnose_report(d)
    assert "SCATTER BEYOND THE STATED NOISE" in report and "gx: its segment means scatter" in report
    assert "Nothing unexplained remains" not in report
    out = diagnosis_json(d)
    assert out["stated_noise_after"]["flagged"] and out["levels"]["stated_noise"] == pytest.approx(0.0025)
    quiet = diagnose(null, site, null_draws=200, seed=22, **options).stated_noise_after
    assert not quiet.flagged and all(item["sd_ratio"] < 1.0 for item in quiet.channels)
    assert quiet.margin == STATED_NOISE_MARGIN


def test_bad_input_is_named(recordings):
    (null, _), scenario = recordings
    fit = fit_recording(null, resolve_site(scenario=scenario), **scenario_fit_options(scenario))
    stated = stated_slow_noise(scenario)
    durations = np.full(fit.observed.shape[0], 30.0)
    with pytest.raises(ValueError, match="margin"):
        stated_noise_test(fit, stated, durations, alpha=0.01, margin=0.5)
    with pytest.raises(ValueError, match="alpha"):
        stated_noise_test(fit, stated, durations, alpha=1.5)
    with pytest.raises(ValueError, match="durations"):
        stated_noise_test(fit, stated, durations[:-1], alpha=0.01)
    with pytest.raises(TypeError, match="StatedSlowNoise"):
        stated_noise_test(fit, {"sigma": 1.0}, durations, alpha=0.01)


def test_a_name_that_fits_only_part_of_an_effect_is_said_to():
    """ax += 2.6e-5 (m/s²)⁻¹ · f_y² (2.5e-3 m/s² at 1 g, about 10 times an ax segment mean's u; outside the catalogue,
    whose K2 is ax += k·f_x²) on a linear_gaussian recording: on the static poses f_y² = g² − f_x² − f_z², so K2's x
    component takes part of it and is named. What it leaves, the lack of fit weighed against ax's re-estimated
    noise does not flag on this seed; against the statement (linear_gaussian
    states no slow noise) ax scatters 3.4 times what it allows, the residual is unexplained, and the report says the
    name may fit only part of what is there."""
    scenario = load_scenario("linear_gaussian")
    clean = simulate_and_record(scenario, seed=41, trial=0)
    samples = np.array(clean.samples, dtype=float)
    samples[:, 3] += 2.6e-5 * samples[:, 4] ** 2
    recording = type(clean)(samples, clean.schedule, dict(clean.attrs))
    d = diagnose(recording, resolve_site(scenario=scenario), null_draws=300, seed=41,
                 **scenario_diagnose_options(scenario))
    assert d.selected == ("accel_quadratic",) and not d.lack_of_fit_after.flagged
    assert d.unexplained["flagged"] and [item["channel"] for item in d.unexplained["stated_noise"]] == ["ax"]
    assert d.unexplained["partial_match"] == [{"effect": "accel_quadratic", "channels": ["ax"]}]
    assert "the name may fit only part of what is there" in diagnose_report(d)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["jjf2003", "linear_gaussian"])
def test_with_no_margin_the_statement_is_the_null(name):
    """20 null recordings (seeds 9000-9019) fitted as plansim fit does (the lack of fit's noise model), each channel
    tested against the scenario's own stated noise with no margin (margin 1: H0 exactly true): Q/ν averages 1 within
    3 of its standard errors (each Q/ν has s.d. √(2/ν) ≈ 0.22 at ν ≈ 42; the channels of one recording are treated as
    independent, which they nearly are), and p < 0.05 in a share inside the binomial 99 % band. It is 1.03 on
    jjf2003's 64 tests (4 below 0.05) and 0.98 on linear_gaussian's 120 (7) (docs/closing-the-loop.md). Power: with
    jjf2003's bias instability left out of H0, Q/ν averaged 1.45 over the first 10 recordings' 33 tests (about 16 of
    the band's standard errors above 1) and the test fired on 9 of them."""
    from scipy.stats import binom

    scenario = load_scenario(name)
    site, options, stated = resolve_site(scenario=scenario), scenario_fit_options(scenario), stated_slow_noise(scenario)
    ratios, p_values, dofs = [], [], []
    for i in range(20):
        recording = simulate_and_record(scenario, seed=9000 + i, trial=0)
        fit = fit_recording(recording, site, **options)
        segments = recording.schedule.segments
        durations = [segments[k].samples / segments[k].sample_rate for k in fit.used]
        test = stated_noise_test(fit, stated, durations, alpha=0.05, margin=1.0, excluded=undithered_channels(fit))
        for item in test.channels:
            ratios.append(item["statistic"] / item["dof"])
            p_values.append(item["p_value"])
            dofs.append(item["dof"])
    n = len(ratios)
    se = math.sqrt(2.0 / np.mean(dofs)) / math.sqrt(n)
    assert abs(np.mean(ratios) - 1.0) < 3 * se, (np.mean(ratios), se, n)
    low, high = binom.ppf(0.005, n, 0.05), binom.ppf(0.995, n, 0.05)
    assert low <= np.sum(np.array(p_values) < 0.05) <= high, (np.sum(np.array(p_values) < 0.05), n)
