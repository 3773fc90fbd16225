"""The dynamic tests' estimators (JJF 1537-2015 7.2.1 eq. (6)–(9), JJF 1535-2015 3.7 and 7.2.15) and the
analytic second-order response they are checked against."""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.estimate.dynamic import (
    HALF_POWER,
    MINUS_3_DB,
    bandwidth_3db,
    bandwidth_curve_fit,
    frequency_response,
    sine_fit,
    wrap_phase,
)
from plansim.model.dynamics import (
    second_order_bandwidth,
    second_order_magnitude,
    second_order_phase,
    second_order_response,
)

TWO_PI = 2.0 * math.pi


# ----------------------------------------------------------------------------- the sine fit, eq. (6)


@pytest.mark.parametrize("frequency, cycles, samples", [(0.37, 2.3, 101), (5.0, 7.77, 400), (80.0, 13.1, 2001),
                                                        (1234.5, 3.01, 97)])
@pytest.mark.parametrize("phase", [0.0, 1.0, -2.5, math.pi, math.pi - 1e-7, -math.pi + 1e-7])
def test_the_sine_fit_recovers_an_exact_sinusoid(frequency, cycles, samples, phase):
    """Non-integer numbers of cycles, a time axis that does not start at 0, phases at and near ±π: E, φ
    and C come back to 1e-9 (φ compared modulo 2π, as it is wrapped to (−π, π])."""
    t = 0.3 + np.linspace(0.0, cycles / frequency, samples)
    E, C = 2.75, -0.4
    fit = sine_fit(t, E * np.cos(TWO_PI * frequency * t + phase) + C, frequency)
    assert abs(fit.amplitude - E) < 1e-9
    assert abs(wrap_phase(fit.phase - phase)) < 1e-9
    assert -math.pi < fit.phase <= math.pi
    assert abs(fit.offset - C) < 1e-9
    assert fit.residual_rms < 1e-9 and fit.samples == samples
    assert np.allclose(fit.fitted(t), E * np.cos(TWO_PI * frequency * t + phase) + C, atol=1e-9)


def test_wrap_phase_maps_onto_the_half_open_interval():
    assert wrap_phase(math.pi) == math.pi and wrap_phase(-math.pi) == math.pi
    assert np.allclose(wrap_phase([0.0, 3 * math.pi, -3.5 * math.pi, 7.0]), [0.0, math.pi, 0.5 * math.pi, 7 - TWO_PI])


def _noisy_fits(t, frequency, E, phase, C, sigma, repeats, seed):
    rng = np.random.default_rng(seed)
    clean = E * np.cos(TWO_PI * frequency * t + phase) + C
    fits = [sine_fit(t, clean + sigma * rng.standard_normal(t.size), frequency) for _ in range(repeats)]
    estimates = np.array([[fit.amplitude, fit.phase, fit.offset] for fit in fits])
    return estimates, np.array([fit.covariance for fit in fits])


def test_the_sine_fit_scatter_matches_the_closed_form_over_whole_cycles():
    """White noise σ, N samples over whole cycles: var(C) = σ²/N, var(E) = 2σ²/N, var(φ) = 2σ²/(N E²)
    (first order in σ/E; here σ/E·√(2/N) = 4.5e-3, so the neglected terms are ~1e-5 relative).

    Tolerance: for n normal repeats the ratio of the sample variance to the true one is χ²_{n−1}/(n−1),
    of standard deviation √(2/(n−1)) = 0.0708 for n = 400; the test accepts |ratio − 1| ≤ 4√(2/(n−1))
    = 0.283. A correct fit fails with probability 1.1e-4 per ratio (χ² tails; the seed is fixed, so the
    outcome is too); the power against a variance wrong by a factor 2 (the 2 in var(E) forgotten, or σ²/N
    for 2σ²/N) is 1 − 3e-8, by a factor 1.5 it is 0.98, by 0.7 it is 0.64. The mean of the fits' own
    covariances (s²(DᵀD)⁻¹ through the delta method) is held to the same closed form, more tightly: each
    s² has a relative standard deviation √(2/(N − 3)), 1/√400 of that for the mean."""
    frequency, cycles, N = 12.5, 8, 512
    t = np.arange(N) * (cycles / frequency) / N  # whole cycles, equally spaced: DᵀD = diag(N/2, N/2, N)
    E, phase, C, sigma, repeats = 1.0, 0.7, 0.2, 0.05, 400
    estimates, covariances = _noisy_fits(t, frequency, E, phase, C, sigma, repeats, seed=20240514)
    closed_form = np.array([2 * sigma**2 / N, 2 * sigma**2 / (N * E**2), sigma**2 / N])  # E, φ, C
    tolerance = 4.0 * math.sqrt(2.0 / (repeats - 1))
    ratios = estimates.var(axis=0, ddof=1) / closed_form
    assert np.all(np.abs(ratios - 1.0) <= tolerance), ratios
    assert np.all(np.abs(estimates.mean(axis=0) - [E, phase, C]) <= 4.0 * np.sqrt(closed_form / repeats))
    reported = covariances[:, [0, 1, 2], [0, 1, 2]].mean(axis=0) / closed_form
    assert np.all(np.abs(reported - 1.0) <= 4.0 * math.sqrt(2.0 / (N - 3)) / math.sqrt(repeats)), reported
    # over whole cycles (E, φ, C) are uncorrelated to first order
    assert np.all(np.abs(covariances.mean(axis=0)[[0, 0, 1], [1, 2, 2]]) < 1e-3 * closed_form.max())


def test_the_fit_s_own_covariance_matches_its_scatter_off_whole_cycles():
    """0.8 of a cycle, C correlated with E and φ: the scatter of 400 fits against the mean reported
    covariance, the variances to the tolerance of the test above and the correlations of (E, C) and (φ, C)
    to 4/√(n − 1) (the standard error of a sample correlation near 0)."""
    frequency, N = 3.0, 300
    t = np.linspace(0.0, 0.8 / frequency, N)
    estimates, covariances = _noisy_fits(t, frequency, 0.8, -2.0, 1.5, 0.04, 400, seed=7)
    reported = covariances.mean(axis=0)
    ratios = estimates.var(axis=0, ddof=1) / np.diag(reported)
    assert np.all(np.abs(ratios - 1.0) <= 4.0 * math.sqrt(2.0 / 399)), ratios
    correlations = np.corrcoef(estimates.T)[[0, 1], [2, 2]]
    predicted = reported[[0, 1], [2, 2]] / np.sqrt(reported[[0, 1], [0, 1]] * reported[2, 2])
    assert np.all(np.abs(predicted) > 0.2)  # the case is one where the correlations matter
    assert np.all(np.abs(correlations - predicted) <= 4.0 / math.sqrt(399)), (correlations, predicted)


def test_the_sine_fit_of_a_constant_gives_zero_amplitude():
    fit = sine_fit(np.arange(10.0), np.full(10, 3.0), 0.123)
    assert fit.amplitude < 1e-12 and abs(fit.offset - 3.0) < 1e-12


def test_sine_fit_rejects_bad_inputs_naming_the_argument():
    t = np.arange(8) * 0.01
    y = np.cos(TWO_PI * 3.0 * t)
    cases = [
        ((t, y[:7], 3.0), ValueError, "t and y"),
        ((t[:3], y[:3], 3.0), ValueError, "t: expected at least 4"),
        ((t, np.where(np.arange(8) == 2, np.nan, y), 3.0), ValueError, "y: every value must be finite"),
        ((np.where(np.arange(8) == 5, np.inf, t), y, 3.0), ValueError, "t: every value must be finite"),
        ((t[::-1], y, 3.0), ValueError, "t: expected strictly increasing"),
        ((np.r_[t[:4], t[3:7]], y, 3.0), ValueError, r"t\[3\] = 0.03 then t\[4\] = 0.03"),
        ((t, y, 0.0), ValueError, "frequency: expected a finite number > 0 Hz, got 0.0"),
        ((t, y, -1.0), ValueError, "frequency: .* got -1.0"),
        ((t, y, math.nan), ValueError, "frequency"),
        ((t, y, "3 Hz"), TypeError, "frequency: expected one number"),
        ((t, y, [3.0, 4.0]), TypeError, "frequency"),
        ((t, ["a"] * 8, 3.0), TypeError, "y: expected numbers"),
        ((t.reshape(2, 4), y.reshape(2, 4), 3.0), ValueError, "t: expected a 1-dimensional"),
        # samples at exactly twice the frequency: sin ωt is zero at every sample
        ((np.arange(8) / 6.0, y, 3.0), ValueError, "frequency: at 3.0 Hz the columns .* linearly dependent"),
    ]
    for args, error, message in cases:
        with pytest.raises(error, match=message):
            sine_fit(*args)


# ----------------------------------------------------------------------------- the frequency response, eq. (7)–(9)


def _table_and_gyro_fits(frequencies, response, A, S0, bias, sigma, repeats, seed, sample_rate=None):
    """Records of the table's rate A cos(ωt + φ_in) and of a gyro S0·|H| A cos(ωt + φ_in + arg H) + bias
    + noise (steady state), each reduced by the sine fit: E_ij, φ_ij, φ_in,ij."""
    rng = np.random.default_rng(seed)
    m = len(frequencies)
    E, phi, phi_in = np.empty((m, repeats)), np.empty((m, repeats)), np.empty((m, repeats))
    for i, f in enumerate(frequencies):
        rate = sample_rate or 40.0 * max(frequencies)  # > 20 × bandwidth (JJF 1537 7.2.1.2 b))
        t = np.arange(int(rate * 10.0 / f)) / rate  # 10 cycles
        for j in range(repeats):
            start = rng.uniform(-math.pi, math.pi)
            table = A * np.cos(TWO_PI * f * t + start)
            gyro = (S0 * abs(response[i]) * A * np.cos(TWO_PI * f * t + start + np.angle(response[i])) + bias
                    + sigma * rng.standard_normal(t.size))
            table_fit, gyro_fit = sine_fit(t, table, f), sine_fit(t, gyro, f)
            E[i, j], phi[i, j], phi_in[i, j] = gyro_fit.amplitude, gyro_fit.phase, table_fit.phase
    return E, phi, phi_in


@pytest.mark.parametrize("S0", [0.0123, -2.5])
def test_a_flat_sensor_gives_ratio_one_and_phase_zero_at_every_frequency(S0):
    """An ideal sensor (H = 1), a random table phase per record, a bias: K_i = 1 and Δφ_i = 0 to 1e-9, the
    sign of the static sensitivity taken out of the phase."""
    frequencies = np.array([1.0, 5.0, 10.0, 20.0, 40.0, 60.0, 80.0])
    A = math.radians(30.0)
    E, phi, phi_in = _table_and_gyro_fits(frequencies, np.ones(7), A, S0, bias=0.3, sigma=0.0, repeats=7, seed=3)
    response = frequency_response(frequencies, E, phi, A, S0, input_phases=phi_in)
    assert response.repeats == 7
    assert np.allclose(response.ratios, 1.0, rtol=0, atol=1e-9)
    assert np.allclose(response.phases, 0.0, rtol=0, atol=1e-9)
    assert np.allclose(response.sensitivities, abs(S0), rtol=1e-9, atol=0)
    assert np.allclose(response.gains_db, 0.0, atol=1e-7)


def test_a_second_order_sensor_gives_its_analytic_response_within_the_estimator_s_uncertainty():
    """f_n = 50 Hz, ζ = 0.4 (a resonance peak of 1.36), white noise on the gyro: K_i and Δφ_i within four
    of their Type A standard uncertainties (s/√n over n = 7 repeats) of |H| and arg H."""
    f_n, zeta, A, S0 = 50.0, 0.4, 0.5, 1.0
    frequencies = np.array([2.0, 10.0, 25.0, 40.0, 50.0, 60.0, 80.0, 100.0])
    H = second_order_response(frequencies, f_n, zeta)
    E, phi, phi_in = _table_and_gyro_fits(frequencies, H, A, S0, bias=0.01, sigma=0.02, repeats=7, seed=11)
    response = frequency_response(frequencies, E, phi, A, S0, input_phases=phi_in)
    assert np.all(np.abs(response.ratios - np.abs(H)) <= 4.0 * response.ratio_std_of_mean)
    assert np.all(np.abs(wrap_phase(response.phases - np.angle(H))) <= 4.0 * response.phase_std_of_mean)
    assert np.all(response.ratio_std_of_mean < 0.01)  # the check has teeth: u(K) ≈ 1e-3
    assert np.allclose(response.phase_lags, -response.phases)


def test_repeated_phases_either_side_of_pi_average_to_pi():
    """Two repeats at π − 0.01 and −π + 0.03 are 0.04 rad apart; their mean is π + 0.01 → −π + 0.01, not
    the arithmetic mean 0.01 of the wrapped values."""
    response = frequency_response([100.0], [[1.0, 1.0]], [[math.pi - 0.01, -math.pi + 0.03]], 1.0, 1.0)
    assert abs(response.phases[0] - (-math.pi + 0.01)) < 1e-12
    assert abs(response.phase_std_of_mean[0] - math.sqrt(2 * 0.02**2) / math.sqrt(2)) < 1e-12


def test_equations_7_to_9_on_a_hand_worked_example():
    """Ē = (2.0 + 2.2)/2 = 2.1 (eq. (7)), S = 2.1/0.5 = 4.2 (eq. (8)), K = 4.2/4.0 = 1.05 (eq. (9));
    the phase −0.3 − 0.1 = −0.4 and −0.2 − 0.0 = −0.2 average to −0.3."""
    response = frequency_response([10.0], [[2.0, 2.2]], [[-0.3, -0.2]], 0.5, 4.0, input_phases=[[0.1, 0.0]])
    assert response.mean_amplitudes[0] == pytest.approx(2.1)
    assert response.sensitivities[0] == pytest.approx(4.2)
    assert response.ratios[0] == pytest.approx(1.05)
    assert response.phases[0] == pytest.approx(-0.3)
    single = frequency_response([10.0, 20.0], [2.0, 1.0], [0.0, -1.0], [0.5, 0.25], 4.0)  # n = 1: no u
    assert single.repeats == 1 and np.allclose(single.ratios, [1.0, 1.0]) and np.all(np.isnan(single.ratio_std_of_mean))


def test_frequency_response_rejects_bad_inputs_naming_the_argument():
    f, E, phi = [1.0, 2.0], [[1.0, 1.1], [0.9, 0.8]], [[0.0, 0.1], [-0.2, -0.3]]
    cases = [
        (([0.0, 2.0], E, phi, 1.0, 1.0), ValueError, "frequencies: expected values > 0 Hz"),
        (([1.0, 2.0, 3.0], E, phi, 1.0, 1.0), ValueError, r"amplitudes: expected shape \(3,\) or \(3, n\)"),
        ((f, [[1.0, -1.0], [1.0, 1.0]], phi, 1.0, 1.0), ValueError, "amplitudes: expected values ≥ 0"),
        ((f, E, [0.0, 0.1], 1.0, 1.0), ValueError, "phases: expected the shape of amplitudes"),
        ((f, E, phi, 0.0, 1.0), ValueError, "input_amplitude: expected values > 0 rad/s"),
        ((f, E, phi, [1.0, 1.0, 1.0], 1.0), ValueError, "input_amplitude: expected one value, one per frequency"),
        ((f, E, phi, 1.0, 0.0), ValueError, "static_sensitivity: expected a finite nonzero"),
        ((f, E, phi, 1.0, "1 V/(rad/s)"), TypeError, "static_sensitivity: expected one number"),
        ((f, E, phi, 1.0, 1.0, [[0.0, math.nan], [0.0, 0.0]]), ValueError, "input_phases: every value must be"),
    ]
    for args, error, message in cases:
        with pytest.raises(error, match=message):
            frequency_response(*args)


# ----------------------------------------------------------------------------- the −3 dB bandwidth


def _interpolation_error_bound(fa, fb, f_star, f_n):
    """max|K''|·(f* − f_a)(f_b − f*)/(2 min|K'|) over [f_a, f_b] for K = 1/√(1 + x⁴), x = f/f_n (ζ = 1/√2):
    K' = −2x³(1 + x⁴)^(−3/2)/f_n, K'' = (12x⁶(1 + x⁴)^(−5/2) − 6x²(1 + x⁴)^(−3/2))/f_n², on a fine grid."""
    x = np.linspace(fa, fb, 100001) / f_n
    first = np.abs(-2 * x**3 * (1 + x**4) ** -1.5) / f_n
    second = np.abs(12 * x**6 * (1 + x**4) ** -2.5 - 6 * x**2 * (1 + x**4) ** -1.5) / f_n**2
    return second.max() * (f_star - fa) * (fb - f_star) / (2 * first.min())


@pytest.mark.parametrize("frequencies", [
    np.linspace(110.0 / 8, 110.0, 8),  # JJF 1535 7.2.15.1 b): 8 points up to the expected bandwidth + 10 Hz
    # and 7.2.15.1 b)'s two inserted points, halfway between the expected bandwidth (100 Hz) and its
    # neighbours 96.25 Hz and 110 Hz
    np.sort(np.r_[np.linspace(110.0 / 8, 110.0, 8), 98.125, 105.0]),
    np.array([10.0, 40.0, 70.0, 95.0, 130.0, 190.0]),  # coarse
    np.linspace(5.0, 200.0, 40),
])
def test_the_bandwidth_of_a_butterworth_second_order_response_is_its_natural_frequency(frequencies):
    """ζ = 1/√2: |H| = 1/√(1 + x⁴) crosses 1/√2 at f_n exactly. The interpolated bandwidth is within the
    bound of linear interpolation (the remainder max|K''|h_a h_b/2 over the chord's slope) of f_n."""
    f_n, zeta = 100.0, 1.0 / math.sqrt(2.0)
    assert second_order_bandwidth(f_n, zeta) == pytest.approx(f_n, rel=1e-15)
    ratios = second_order_magnitude(frequencies, f_n, zeta)
    estimate = bandwidth_3db(frequencies, ratios)
    k = int(np.searchsorted(frequencies, f_n))
    bound = _interpolation_error_bound(frequencies[k - 1], frequencies[k], f_n, f_n)
    assert abs(estimate - f_n) <= bound + 1e-12 * f_n, (estimate, bound)
    assert bound < 0.1 * f_n  # the bound is not vacuous


@pytest.mark.parametrize("zeta", [0.2, 0.5, 1.0, 2.0])
def test_the_bandwidth_of_other_dampings_converges_to_the_analytic_one(zeta):
    """A fine grid (0.1 % of f_n) gives the analytic f_3dB = f_n√(1 − 2ζ² + √((1 − 2ζ²)² + 1)) to 1e-5
    relative, through the resonance peak for ζ < 1/√2 (the first downward crossing counts)."""
    f_n = 40.0
    frequencies = np.arange(1, 4001) * 1e-3 * f_n
    expected = second_order_bandwidth(f_n, zeta)
    assert bandwidth_3db(frequencies, second_order_magnitude(frequencies, f_n, zeta)) == pytest.approx(
        expected, rel=1e-5)
    x = expected / f_n
    assert abs(1 / math.sqrt((1 - x * x) ** 2 + (2 * zeta * x) ** 2) - HALF_POWER) < 1e-14


def test_bandwidth_on_a_hand_worked_example_and_the_exact_3_db_level():
    # K falls from 0.8 at 10 Hz to 0.6 at 20 Hz: 1/√2 is reached at 10 + (0.8 − 0.70711)/0.2·10 = 14.6447 Hz
    assert bandwidth_3db([5.0, 10.0, 20.0, 30.0], [1.0, 0.8, 0.6, 0.3]) == pytest.approx(
        10 + (0.8 - HALF_POWER) / 0.2 * 10, rel=1e-14)
    assert bandwidth_3db([5.0, 10.0, 20.0, 30.0], [1.0, 0.8, 0.6, 0.3], level=MINUS_3_DB) == pytest.approx(
        10 + (0.8 - 10 ** (-0.15)) / 0.2 * 10, rel=1e-14)
    assert bandwidth_3db([1.0, 2.0], [1.0, HALF_POWER]) == pytest.approx(2.0)  # a point on the level


def test_bandwidth_without_a_crossing_raises():
    with pytest.raises(ValueError, match="never falls to the level 0.707107 up to 30 Hz"):
        bandwidth_3db([10.0, 20.0, 30.0], [1.0, 0.9, 0.8])
    with pytest.raises(ValueError, match="already below the level .* at the lowest frequency 10 Hz"):
        bandwidth_3db([10.0, 20.0, 30.0], [0.6, 0.5, 0.4])


def test_bandwidth_rejects_bad_inputs_naming_the_argument():
    cases = [
        (([10.0, 20.0], [1.0, 0.5, 0.2]), ValueError, "frequencies and ratios: expected the same length"),
        (([10.0], [1.0]), ValueError, "frequencies: expected at least 2"),
        (([20.0, 10.0], [1.0, 0.5]), ValueError, "frequencies: expected values > 0 Hz, strictly increasing"),
        (([10.0, 20.0], [1.0, -0.5]), ValueError, "ratios: expected values ≥ 0"),
        (([10.0, 20.0], [1.0, math.inf]), ValueError, "ratios: every value must be finite"),
        (([10.0, 20.0], [1.0, 0.5], 1.5), ValueError, "level: expected 0 < level < 1"),
        (([10.0, 20.0], [1.0, 0.5], "-3 dB"), TypeError, "level: expected one number"),
    ]
    for args, error, message in cases:
        with pytest.raises(error, match=message):
            bandwidth_3db(*args)


# ----------------------------------------------------------------------------- the curve fit of 7.2.15.2


@pytest.mark.parametrize("zeta, expected_bandwidth", [(0.3, 140.0), (1.0 / math.sqrt(2.0), 100.0), (1.2, 60.0)])
@pytest.mark.parametrize("level", [HALF_POWER, MINUS_3_DB])
def test_the_curve_fit_reads_a_second_order_response_s_bandwidth_exactly(zeta, expected_bandwidth, level):
    """JJF 1535 7.2.15.1 b)'s grid on a one-resonance response, normalised to its lowest point as eq. (9) does:
    the fitted curve is the response itself, so its −3 dB point is the analytic one to 1e-9 Hz, at 1/√2 (the
    closed form of plansim.model.dynamics) and at 10^(−3/20) (found independently here by Brent's method on |H|),
    where the chord of bandwidth_3db is off by up to 1.4 Hz (ζ = 0.3)."""
    from scipy.optimize import brentq

    from plansim.schedule.jjf1537 import jjf1535_frequencies

    f_n = 100.0
    frequencies = jjf1535_frequencies(expected_bandwidth)
    ratios = second_order_magnitude(frequencies, f_n, zeta)
    ratios = ratios / ratios[0]
    peak = f_n * math.sqrt(max(1.0 - 2.0 * zeta * zeta, 0.0))  # |H| is falling beyond its peak
    expected = brentq(lambda f: float(second_order_magnitude(f, f_n, zeta)) - level, peak + 1e-9, 10 * f_n,
                      xtol=1e-13)
    if level == HALF_POWER:
        assert expected == pytest.approx(second_order_bandwidth(f_n, zeta), abs=1e-9)
    fit = bandwidth_curve_fit(frequencies, ratios, level)
    assert fit.bandwidth == pytest.approx(expected, abs=1e-9)
    assert (fit.natural_frequency, fit.damping) == pytest.approx((f_n, zeta), rel=1e-9)
    assert fit.gain == pytest.approx(1.0 / second_order_magnitude(frequencies[:1], f_n, zeta)[0], rel=1e-9)
    assert fit.residual_rms < 1e-12


def test_the_curve_fit_s_sensitivities_are_its_derivatives():
    """gradient = ∂f_3dB/∂K_i, checked against central differences of the whole fit (steps of 1e-6 in K)."""
    frequencies = np.linspace(15.0, 130.0, 9)
    ratios = second_order_magnitude(frequencies, 90.0, 0.55) * 1.02
    fit = bandwidth_curve_fit(frequencies, ratios)
    h = 1e-6
    numeric = np.array([(bandwidth_curve_fit(frequencies, ratios + h * e).bandwidth
                         - bandwidth_curve_fit(frequencies, ratios - h * e).bandwidth) / (2 * h)
                        for e in np.eye(frequencies.size)])
    np.testing.assert_allclose(fit.gradient, numeric, rtol=1e-4, atol=1e-4 * np.abs(numeric).max())


def test_the_curve_fit_refuses_an_extrapolation_and_bad_inputs():
    flat = np.ones(8)
    with pytest.raises(ValueError, match="outside the measured band 10 to 80 Hz"):
        bandwidth_curve_fit(np.linspace(10.0, 80.0, 8), flat * 0.999 + 1e-4 * np.arange(8))
    cases = [
        (([10.0, 20.0, 30.0], [1.0, 0.8, 0.5]), ValueError, "frequencies: expected at least 4"),
        (([10.0, 20.0, 30.0, 40.0], [1.0, 0.8, 0.5]), ValueError, "expected at least 4|same length"),
        (([10.0, 30.0, 20.0, 40.0], [1.0, 0.8, 0.5, 0.3]), ValueError, "strictly increasing"),
        (([10.0, 20.0, 30.0, 40.0], [1.0, -0.8, 0.5, 0.3]), ValueError, "ratios: expected values ≥ 0"),
        (([10.0, 20.0, 30.0, 40.0], [1.0, 0.8, 0.5, 0.3], 0.0), ValueError, "level: expected 0 < level < 1"),
    ]
    for args, error, message in cases:
        with pytest.raises(error, match=message):
            bandwidth_curve_fit(*args)


# ----------------------------------------------------------------------------- the analytic response


def test_the_second_order_response_s_magnitude_and_phase_are_those_of_h():
    f = np.array([0.0, 1.0, 30.0, 50.0, 70.0, 500.0])
    H = second_order_response(f, 50.0, 0.3)
    assert H[0] == 1.0
    assert np.allclose(second_order_magnitude(f, 50.0, 0.3), np.abs(H), rtol=1e-14)
    assert np.allclose(second_order_phase(f, 50.0, 0.3), np.angle(H), rtol=0, atol=1e-14)
    assert second_order_phase(50.0, 50.0, 0.3) == pytest.approx(-math.pi / 2)
    assert second_order_magnitude(50.0, 50.0, 0.3) == pytest.approx(1 / 0.6)  # 1/(2ζ) at f_n
    omega, omega_n, zeta = TWO_PI * 70.0, TWO_PI * 50.0, 0.3  # H(s) = ω_n²/(s² + 2ζω_n s + ω_n²) at s = jω
    s = 1j * omega
    assert H[4] == pytest.approx(omega_n**2 / (s * s + 2 * zeta * omega_n * s + omega_n**2), rel=1e-14)


def test_the_analytic_response_rejects_bad_parameters_naming_them():
    with pytest.raises(ValueError, match="natural_frequency: expected a finite number > 0"):
        second_order_magnitude([1.0], 0.0, 0.5)
    with pytest.raises(ValueError, match="damping: expected a finite number > 0"):
        second_order_phase([1.0], 10.0, -0.1)
    with pytest.raises(TypeError, match="damping: expected one number"):
        second_order_bandwidth(10.0, "0.7")
    with pytest.raises(ValueError, match="level: expected 0 < level < 1"):
        second_order_bandwidth(10.0, 0.7, 1.0)
    with pytest.raises(ValueError, match="frequencies: expected finite values ≥ 0 Hz"):
        second_order_response([-1.0], 10.0, 0.7)
