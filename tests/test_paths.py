"""The two simulation paths give the same error distributions; the runner picks the exact one.

Both paths draw the unit's truth and every table error from the same stream (stream 0 of the
trial), so for a given seed trial i has identical systematic draws on both paths and only the
noise differs. That makes paired tests possible and powerful:

- **mean**: d_i = error_sample,i − error_segment,i has mean 0 if the segment path is exact in
  mean (the quantisation bias, a deterministic function of the draws, cancels);
  we require |mean d| ≤ 5·sd(d)/√n.
- **variance**: x_i = (e_s,i − ē_s)² − (e_g,i − ē_g)² has mean var_s − var_g; we require
  |mean x| ≤ 5·sd(x)/√n.

Power (stated, measured per test): with n trials the smallest mean discrepancy the test can flag
is 5·sd(d)/√n and the smallest variance discrepancy 5·sd(x)/√n; the tests also assert that these
detectable limits are small against the error spread itself (≤ 0.5 σ for the mean, ≤ 60 % for the
variance at n = 240), so a passing test is not a blind one.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy import stats

import plansim
from plansim.config import parse_scenario
from plansim.io.scenario_file import builtin_scenarios
from plansim.kernels.drift import drift_coefficients
from plansim.kernels.quantiser import (
    fourier_damping,
    fourier_terms_needed,
    moments_from_damping,
    quantised_gaussian_moments,
    sin_cos_turns,
)
from plansim.kernels.segment_path import arc_weights
from plansim.model.parameters import PARAMETER_NAMES
from plansim.simulate.chunks import simulate_segment_means
from plansim.simulate.paths import choose_path

Z = 5.0  # standard errors allowed; two-sided p ≈ 6e-7 per comparison (39 parameters × 3 scenarios)


def _document(name: str) -> dict:
    with open(builtin_scenarios()[name], "rb") as fh:
        return tomllib.load(fh)


def _effects_document() -> dict:
    """Every effect the segment path models, on at once, with drift of every kind and a temperature ramp."""
    doc = _document("ideal")
    doc["environment"]["earth_rate"] = True
    doc["mimu"]["noise"] = {
        "gyro_angle_random_walk": "0.3 deg/sqrt(h)", "accel_velocity_random_walk": "0.05 m/s/sqrt(h)",
        "gyro_bias_instability": "5 deg/h", "accel_bias_instability": "20 ug",
        "gyro_rate_random_walk": "3 deg/h/sqrt(h)", "accel_acceleration_random_walk": "5 ug/sqrt(s)",
        "gyro_markov_sigma": "3 deg/h", "accel_markov_sigma": "10 ug", "markov_correlation_time": "200 s",
    }
    doc["mimu"]["effects"] = {
        "gyro_nonlinearity_quadratic": "50 ppm/(deg/s)", "gyro_nonlinearity_cubic": "0.5 ppm/(deg/s)^2",
        "gyro_g2_sensitivity": [["0.5 deg/h/g^2"] * 3] * 3, "accel_second_order": "50 ug/g^2",
        "gyro_bias_temperature_coefficient": "2 deg/h/degC", "gyro_scale_temperature_coefficient": "50 ppm/degC",
        "accel_bias_temperature_coefficient": "10 ug/degC", "accel_scale_temperature_coefficient": "30 ppm/degC",
        "accel_lever_arm": [["3 mm", "-4 mm", "2 mm"]] * 3,
    }
    doc["acquisition"] = {"bits": 16, "gyro_full_scale": "125 deg/s", "accel_full_scale": "8 g"}
    doc["turntable"] = {"position_accuracy": "10 arcsec", "axis_perpendicularity": {"standard_uncertainty": "5 arcsec"},
                        "rate_error_per_point": "1e-5", "rate_smoothness": "0.05 %"}
    doc["schedule"]["temperature_start"] = "20 degC"
    doc["schedule"]["temperature_end"] = "26 degC"
    doc["schedule"]["rate_points"] = ["-100 deg/s", "-37 deg/s", "-3 deg/s", "11 deg/s", "53 deg/s", "100 deg/s"]
    return doc


def _paired_check(sample: np.ndarray, segment: np.ndarray, label: str) -> None:
    n = sample.shape[0]
    for k, name in enumerate(PARAMETER_NAMES):
        es, eg = sample[:, k], segment[:, k]
        d = es - eg
        sd_d = d.std(ddof=1)
        assert abs(d.mean()) <= Z * sd_d / math.sqrt(n) + 1e-300, \
            f"{label} {name}: mean differs by {d.mean():.3g} (limit {Z * sd_d / math.sqrt(n):.3g})"
        x = (es - es.mean()) ** 2 - (eg - eg.mean()) ** 2
        limit = Z * x.std(ddof=1) / math.sqrt(n)
        assert abs(x.mean()) <= limit + 1e-300, \
            f"{label} {name}: variance differs by {x.mean():.3g} (limit {limit:.3g}; var {es.var():.3g})"
        # power: the detectable limits are small against the spread of the errors
        spread = max(es.std(ddof=1), eg.std(ddof=1))
        if spread > 0:
            assert Z * sd_d / math.sqrt(n) <= 0.5 * spread * math.sqrt(2), f"{label} {name}: mean test blind"
            assert limit <= 0.6 * max(es.var(ddof=1), eg.var(ddof=1)) * math.sqrt(4.0), \
                f"{label} {name}: variance test blind"


def _errors(sc, trials, seed, path):
    from plansim.estimate import reduce

    means, truth = simulate_segment_means(sc, trials, seed, chunk_size=64, path=path)
    return reduce(means, sc.schedule, sc.reduction.reference_gravity, sc.reduction.omega_squared_sign) - truth, truth


@pytest.mark.slow
@pytest.mark.parametrize("label, document", [
    ("jjf2003 (12-bit quantisation without dither, bias instability, lever arm, Earth rate, table errors)",
     lambda: _document("jjf2003")),
    ("every modelled effect, all drift kinds, 16-bit, temperature ramp, non-whole turns", _effects_document),
])
def test_both_paths_give_the_same_error_distributions(label, document):
    sc = parse_scenario(document())
    assert choose_path(sc)[0] == "segment", choose_path(sc)[1]
    trials = 240
    sample, truth_s = _errors(sc, trials, 2024, "sample")
    segment, truth_g = _errors(sc, trials, 2024, "segment")
    np.testing.assert_array_equal(truth_s, truth_g)  # same systematic draws on both paths
    _paired_check(sample, segment, label)


def test_runner_takes_the_segment_path_only_where_it_is_exact():
    assert choose_path(plansim.load_scenario("jjf2003")) == ("segment", [])
    doc = _document("jjf2003")
    doc["mimu"]["effects"]["gyro_asymmetry"] = "100 ppm"
    path, reasons = choose_path(parse_scenario(doc))
    assert path == "sample" and "asymmetry" in reasons[0]
    doc = _document("jjf2003")
    doc["schedule"]["rate_points"] = ["-124 deg/s", "124 deg/s"]
    path, reasons = choose_path(parse_scenario(doc))
    assert path == "sample" and any("saturate" in r for r in reasons)
    results = plansim.run(parse_scenario(doc), trials=2, seed=1)
    assert results.attrs["simulation_path"] == "sample-level"
    assert "saturate" in results.attrs["segment_path_not_exact_because"]
    results = plansim.run("jjf2003", trials=2, seed=1)
    assert results.attrs["simulation_path"] == "segment-statistics"
    with pytest.raises(ValueError, match="path = 'fast'"):
        choose_path(parse_scenario(doc), "fast")


def test_a_noiseless_quantiser_on_a_turning_table_takes_the_sample_path():
    """Quantised without noise, a turning channel's output is a staircase in the table angle: the
    segment path's average over θ at nodes is not exact for it, so the runner refuses that path.
    At rest the same quantiser is plain rounding, which the segment path reproduces exactly."""
    doc = _document("ideal")
    doc["acquisition"] = {"bits": 12, "gyro_full_scale": "125 deg/s", "accel_full_scale": "8 g"}
    path, reasons = choose_path(parse_scenario(doc))
    assert path == "sample"
    assert any("gx is quantised without white noise" in r for r in reasons), reasons
    assert any("ax is quantised without white noise" in r for r in reasons), reasons  # the ω² test turns too
    doc["mimu"]["noise"] = {"gyro_angle_random_walk": "0.15 deg/sqrt(h)",
                            "accel_velocity_random_walk": "0.012 m/s/sqrt(h)"}
    assert choose_path(parse_scenario(doc)) == ("segment", [])


def test_results_do_not_depend_on_the_chunk_size_on_the_segment_path():
    sc = plansim.load_scenario("jjf2003")
    a, _ = simulate_segment_means(sc, 37, seed=3, chunk_size=37, path="segment")
    b, _ = simulate_segment_means(sc, 37, seed=3, chunk_size=5, path="segment")
    np.testing.assert_array_equal(a, b)


# ----------------------------------------------------------------------------- the exact pieces


@pytest.mark.parametrize("J", [7, 21, 69])
@pytest.mark.parametrize("delta, n", [(math.radians(1.0), 3000), (2 * math.pi / 100, 500), (0.3, 7),
                                      (2 * math.pi / 7, 14)])
def test_arc_weights_average_trigonometric_polynomials_exactly(J, delta, n):
    rng = np.random.default_rng(J * n)
    w = np.empty(J)
    arc_weights(J, delta, n, w)
    for m in range((J - 1) // 2 + 1):
        theta0 = rng.uniform(0, 2 * math.pi)
        def f(th, m=m):
            return np.cos(m * th) + 0.3 * np.sin(m * th)
        exact = f(theta0 + np.arange(n) * delta).mean()
        assert abs(exact - np.sum(w * f(theta0 + 2 * math.pi * np.arange(J) / J))) < 1e-11


@pytest.mark.parametrize("sigma", [0.0, 0.01, 0.05, 0.15, 0.1999, 0.2, 0.41, 0.9, 2.0, 7.0])
@pytest.mark.parametrize("mu", [0.0, 0.13, 0.4999, 0.5, 3.37, -12.71, 1234.56])
def test_quantised_gaussian_moments_match_the_level_sums(sigma, mu):
    q = 1.0
    mean, var = quantised_gaussian_moments(mu, sigma, q)
    if sigma == 0.0:
        assert mean == math.floor(mu + 0.5) and var == 0.0
        return
    levels = np.arange(np.floor((mu - 40 * sigma) / q) - 2, np.ceil((mu + 40 * sigma) / q) + 3)
    p = stats.norm.cdf(((levels + 0.5) * q - mu) / sigma) - stats.norm.cdf(((levels - 0.5) * q - mu) / sigma)
    exact_mean = np.sum(levels * q * p)
    exact_var = np.sum((levels * q - exact_mean) ** 2 * p)
    assert abs(mean - exact_mean) < 1e-11 and abs(var - exact_var) < 1e-11


@pytest.mark.parametrize("sigma", [0.2, 0.25, 0.41, 0.58, 1.0])
@pytest.mark.parametrize("bias_tolerance, variance_tolerance", [(1e-4, 1e-4), (1e-6, 1e-7), (1e-9, 1e-10)])
def test_a_cut_fourier_series_moves_the_moments_within_its_tolerances(sigma, bias_tolerance, variance_tolerance):
    """fourier_terms_needed keeps the fewest terms whose dropped tail moves the quantised mean and
    variance by at most the given amounts: checked against the full series over a period of μ."""
    q = 1.0
    coefficients = np.empty((1, 3, 8))
    row = np.int64(0)
    full = fourier_damping(sigma, q, coefficients, row)
    kept = fourier_terms_needed(coefficients, row, full, sigma, bias_tolerance, variance_tolerance)
    assert 0 <= kept <= full  # 0: even the first term is below tolerance (the noise dithers)
    worst_mean = worst_var = 0.0
    for mu in np.linspace(-0.5, 0.5, 201):
        m_full, v_full = moments_from_damping(mu, sigma, q, coefficients, row, full)
        m_cut, v_cut = moments_from_damping(mu, sigma, q, coefficients, row, kept)
        worst_mean, worst_var = max(worst_mean, abs(m_cut - m_full)), max(worst_var, abs(v_cut - v_full))
    assert worst_mean <= bias_tolerance and worst_var <= variance_tolerance
    if kept > 1:  # and one term fewer would not do: the cut is the fewest terms
        fewer = np.int64(kept - 1)
        moved = max(max(abs(moments_from_damping(mu, sigma, q, coefficients, row, fewer)[i]
                            - moments_from_damping(mu, sigma, q, coefficients, row, full)[i]) / tolerance
                        for i, tolerance in ((0, bias_tolerance), (1, variance_tolerance)))
                    for mu in np.linspace(-0.5, 0.5, 201))
        assert moved > 0.5  # within a factor 2 of the bound: the bound is not loose by orders


def test_sin_cos_in_turns_matches_numpy_to_a_few_ulp():
    """The quantiser phases use a polynomial sin/cos of 2πt; checked against numpy over many turns,
    at the quarter-turn seams (where the reduction switches branch) and at exact quarters."""
    rng = np.random.default_rng(7)
    quarters = np.arange(-40, 41) / 4.0
    seams = (np.arange(-40, 41) + 0.5) / 4.0
    turns = np.concatenate([rng.uniform(-50.0, 50.0, 20_000), quarters, seams, seams + 1e-12, seams - 1e-12])
    got = np.array([sin_cos_turns(t) for t in turns])
    reference = 2.0 * np.pi * (turns - np.floor(turns))  # numpy's sin/cos on [0, 2π)
    assert np.max(np.abs(got[:, 0] - np.sin(reference))) < 4e-15
    assert np.max(np.abs(got[:, 1] - np.cos(reference))) < 4e-15
    at_quarters = np.array([sin_cos_turns(t) for t in quarters])
    k = np.arange(-40, 41) % 4  # exact at the quarter turns: (0, 1), (1, 0), (0, −1), (−1, 0)
    assert np.array_equal(at_quarters[:, 0], np.array([0.0, 1.0, 0.0, -1.0])[k])
    assert np.array_equal(at_quarters[:, 1], np.array([1.0, 0.0, -1.0, 0.0])[k])


@pytest.mark.parametrize("tau", [None, 5.0, 100.0])
def test_drift_coefficients_match_a_direct_simulation(tau):
    """The held drift's (segment mean, end state) covariance against 40 000 direct simulations."""
    n, dt, hold = 300, 0.01, 0.1
    a, c, l11, l21, l22 = drift_coefficients(n, dt, hold, tau)
    rng = np.random.default_rng(11)
    m = 40000
    x = np.zeros(m)  # start at 0: the mean and end are then the pure innovation parts
    block = int(round(hold / dt))
    total = np.zeros(m)
    for start in range(0, n, block):
        size = min(block, n - start)
        total += size * x
        duration = size * dt
        if tau is None:
            x = x + math.sqrt(duration) * rng.standard_normal(m)
        else:
            phi = math.exp(-duration / tau)
            x = phi * x + math.sqrt(1 - phi**2) * rng.standard_normal(m)
    mean = total / n
    cov = np.cov(mean, x)
    expected = np.array([[l11**2, l11 * l21], [l11 * l21, l21**2 + l22**2]])
    tolerance = Z * np.sqrt((expected**2 + np.outer(np.diag(expected), np.diag(expected))) / (m - 1))
    assert np.all(np.abs(cov - expected) <= tolerance)
    if tau is not None:
        assert abs(c - math.exp(-n * dt / tau)) < 1e-12
