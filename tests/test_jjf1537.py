"""JJF 1537-2015's angular vibration test simulated (docs/dynamic.md, "The JJF 1537 procedure simulated"): the IIR
kernel, the discretisation, the schedule, chunking and seeds, the zero-noise identity, the Monte Carlo against the
analytic response and the GUM, items 7.2.4–7.2.7 (amplitude nonlinearity, output change under vibration, bias
change across vibration and shock), and ``plansim run jjf1537``."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
import scipy.signal

from plansim import cli
from plansim.estimate.dynamic import amplitude_nonlinearity, bandwidth_curve_fit, mean_change, sine_fit, sine_fits
from plansim.kernels.dynamics import iir_filter
from plansim.model.dynamics import (
    SensorDynamics,
    second_order_bandwidth,
    second_order_response,
    static_nonlinearity_harmonics,
)
from plansim.schedule.jjf1537 import Jjf1537Schedule, VibrationShockSchedule, jjf1535_frequencies
from plansim.simulate.jjf1537 import run_jjf1537, simulate_records
from plansim.simulate.jjf1537_items import (
    ITEMS,
    drift_covariance,
    drift_intervals,
    drift_offsets,
    run_vibration_shock,
    simulate_vibration_shock,
)
from plansim.simulate.vibration_table import (
    ITEM_TABLE_ERROR_STREAM,
    Jjf1537Experiment,
    discretise,
    run_in_samples,
    table_errors,
    with_overrides,
)
from plansim.units import DEG

#: a short test: 7 frequencies x 7 repeats of 0.25 s at 4 kHz
SHORT = dict(grid="jjf1537", band_low=20.0, band_high=140.0, frequency_count=7, record_time=0.25)


def _coefficients(model="second_order", frequency=60.0):
    dyn = SensorDynamics(model, 100.0, 0.4, 300.0, 0.5)
    return discretise(dyn, frequency, 4000.0)


@pytest.mark.parametrize("model", ["second_order", "two_resonance"])
def test_kernel_filter_matches_lfilter_and_chunks_bit_for_bit(model):
    b, a = _coefficients(model)
    x = np.random.default_rng(3).standard_normal(5000)
    expected = scipy.signal.lfilter(b, a, x)
    out = np.empty_like(x)
    iir_filter(b, a, x, np.zeros(len(a) - 1), out)
    np.testing.assert_allclose(out, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    chunked = np.empty_like(x)
    state = np.zeros(len(a) - 1)
    for start in range(0, x.size, 777):  # the state carried across chunks
        iir_filter(b, a, x[start:start + 777], state, chunked[start:start + 777])
    assert np.array_equal(chunked, out)


@pytest.mark.parametrize("model", ["second_order", "two_resonance"])
@pytest.mark.parametrize("frequency", [13.75, 101.0, 400.0])
def test_prewarped_bilinear_is_exact_at_the_table_frequency(model, frequency):
    dyn = SensorDynamics(model, 100.0, 0.4, 300.0, 0.5)
    b, a = discretise(dyn, frequency, 4000.0)
    _, h = scipy.signal.freqz(b, a, worN=[frequency], fs=4000.0)
    assert abs(h[0] - dyn.response(frequency)) < 1e-12
    _, h0 = scipy.signal.freqz(b, a, worN=[0.0], fs=4000.0)  # and the DC gain
    assert abs(h0[0] - 1.0) < 1e-12


def test_two_resonance_is_the_product_and_its_bandwidth_is_on_the_level():
    dyn = SensorDynamics("two_resonance", 100.0, 0.7, 400.0, 0.7)
    f = np.array([0.0, 50.0, 100.0, 250.0])
    np.testing.assert_allclose(dyn.response(f), second_order_response(f, 100.0, 0.7)
                               * second_order_response(f, 400.0, 0.7), rtol=1e-15)
    bw = dyn.bandwidth()
    assert abs(abs(dyn.response(bw)) - 2**-0.5) < 1e-12
    assert bw < second_order_bandwidth(100.0, 0.7)  # the drive mode only takes away
    second = SensorDynamics("second_order", 100.0, 0.6)
    assert second.bandwidth() == second_order_bandwidth(100.0, 0.6)


def test_jjf1535_grid_has_eight_points_and_two_inserted():
    f = jjf1535_frequencies(100.0)
    np.testing.assert_allclose(f, sorted([*(np.arange(1, 9) * 13.75), (96.25 + 100) / 2, (100 + 110) / 2]))


def test_schedule_refuses_what_jjf1537_does_not_allow():
    ok = dict(frequencies=np.arange(1, 8) * 10.0, amplitude=1.0, gyro_range=5.0)
    Jjf1537Schedule(**ok)
    with pytest.raises(ValueError, match=r"frequencies: expected at least 7"):
        Jjf1537Schedule(**{**ok, "frequencies": [10, 20, 30, 40, 50, 60]})
    with pytest.raises(ValueError, match=r"repeats: expected an integer >= 7"):
        Jjf1537Schedule(**ok, repeats=6)
    with pytest.raises(ValueError, match=r"amplitude: expected 10-30 % of the range"):
        Jjf1537Schedule(**{**ok, "amplitude": 2.0})
    with pytest.raises(ValueError, match=r"sample_rate: expected > 20 x the expected bandwidth 100 Hz"):
        Jjf1537Schedule(**ok, sample_rate=2000.0)
    with pytest.raises(ValueError, match=r"model: expected one of flat, second_order, two_resonance, got 'third'"):
        Jjf1537Experiment(model="third")
    with pytest.raises(ValueError, match=r"--set 'damping=x'"):
        with_overrides(Jjf1537Experiment(), ["damping=x"])
    with pytest.raises(ValueError, match=r"KEY one of model"):
        with_overrides(Jjf1537Experiment(), ["nope=1"])


def test_overrides_read_units():
    s = with_overrides(Jjf1537Experiment(), ["natural_frequency=0.12 kHz", "gyro_range=500 deg/s", "damping=0.5"])
    assert (s.natural_frequency, s.damping) == (120.0, 0.5)
    assert s.gyro_range == pytest.approx(500 * DEG)
    assert s.overrides == ("natural_frequency=0.12 kHz", "gyro_range=500 deg/s", "damping=0.5")


def test_batched_sine_fits_equal_one_by_one():
    t = np.arange(1000) / 4000.0
    y = np.random.default_rng(5).standard_normal((2, 3, t.size)) + np.cos(2 * np.pi * 37.0 * t + 0.3)
    fits = sine_fits(t, y, 37.0)
    for idx in np.ndindex(2, 3):
        one = sine_fit(t, y[idx], 37.0)
        assert fits.amplitude[idx] == pytest.approx(one.amplitude, rel=1e-12)
        assert fits.phase[idx] == pytest.approx(one.phase, abs=1e-12)
        assert fits.offset[idx] == pytest.approx(one.offset, abs=1e-12)
        assert fits.residual_rms[idx] == pytest.approx(one.residual_rms, rel=1e-12)


@pytest.mark.parametrize("model", ["second_order", "two_resonance"])
def test_records_do_not_depend_on_the_chunking(model):
    s = Jjf1537Experiment(model=model, **SHORT)
    whole = simulate_records(s, 11, 3, [0, 1, 2])
    for chunk in (1, 97, 777):  # chunks in time, across the run-in's end
        assert np.array_equal(simulate_records(s, 11, 3, [0, 1, 2], chunk=chunk), whole)
    assert np.array_equal(simulate_records(s, 11, 3, [2]), whole[2:])  # and in trials
    assert not np.array_equal(simulate_records(s, 12, 3, [0, 1, 2]), whole)
    assert run_in_samples(discretise(s.dynamics(), 20.0, 4000.0)[1]) > 0


def test_same_seed_same_numbers_whatever_the_trial_chunks():
    s = Jjf1537Experiment(**SHORT)
    one = run_jjf1537(s, trials=5, seed=3, chunk_trials=2)
    two = run_jjf1537(s, trials=5, seed=3, chunk_trials=5)
    assert np.array_equal(one.ratios, two.ratios) and np.array_equal(one.phases, two.phases)
    assert np.array_equal(one.bandwidths, two.bandwidths)
    assert not np.array_equal(run_jjf1537(s, trials=5, seed=4).ratios, one.ratios)


@pytest.mark.parametrize("model", ["flat", "second_order", "two_resonance"])
def test_zero_noise_identity(model):
    """No noise and no quantisation: a flat sensor gives K_i = 1 and Δφ_i = 0, and any sensor the noise-free
    procedure's K_i = |H(f_i)/H(f_1)| and Δφ_i = arg H(f_i), to 1e-9 (the prewarped discretisation is exact at
    the table frequency; the run-in leaves < 1e-13 of the start-up transient)."""
    s = Jjf1537Experiment(model=model, gyro_arw=0.0, quantisation=0.0, bias=0.3, scale_factor=1.01, **SHORT)
    r = run_jjf1537(s, trials=2, seed=1)
    np.testing.assert_allclose(r.ratios, np.broadcast_to(r.noise_free_ratio, r.ratios.shape), rtol=0, atol=1e-9)
    np.testing.assert_allclose(r.phases, np.broadcast_to(r.truth_phase, r.phases.shape), rtol=0, atol=1e-9)
    if model == "flat":
        np.testing.assert_allclose(r.ratios, 1.0, rtol=0, atol=1e-9)
        np.testing.assert_allclose(r.phases, 0.0, rtol=0, atol=1e-9)
        assert np.all(np.isnan(r.bandwidths))  # never falls: above the band
    else:
        np.testing.assert_allclose(r.bandwidths, r.noise_free_bandwidth, rtol=0, atol=1e-9)
        # the K_i agree to 1e-9; the fit carries that through its sensitivities (|∂f/∂K| summed, Hz)
        carried = 1e-9 * np.abs(bandwidth_curve_fit(r.schedule.frequencies, r.noise_free_ratio).gradient).sum()
        np.testing.assert_allclose(r.bandwidths_fit, r.noise_free_bandwidth_fit, rtol=0, atol=carried)
        if model == "second_order":  # the curve is the response: JJF 1535 7.2.15.2's reading is exact
            assert r.noise_free_bandwidth_fit == pytest.approx(r.truth_bandwidth, abs=1e-9)


def test_second_order_sensor_gives_its_response_within_the_mc_uncertainty_and_the_gum():
    """The default second-order sensor (f_n 100 Hz, ζ 0.7) with its noise and quantiser, 200 trials, seed 21.

    The MC mean of each K_i, Δφ_i and of the bandwidth is within 5 s/√T of the noise-free procedure's value
    (T = 200 trials, s the MC standard deviation: the estimators are unbiased to first order in the noise, so a
    correct simulation fails one of these 20 checks with probability < 20 × 5.7e-7 = 1.1e-5); the noise-free values
    differ from the analytic |H(f_i)| only by the reference S_0 read at the lowest frequency, which is checked
    in closed form. The MC standard deviations match the GUM's u within 4/√(2(T − 1)) = 0.20 relative (4 times
    the relative standard error of a standard deviation from T normal samples)."""
    trials = 200
    r = run_jjf1537(Jjf1537Experiment(), trials=trials, seed=21)
    s = r.summary()
    np.testing.assert_allclose(r.noise_free_ratio, r.truth_ratio / r.truth_ratio[0], rtol=1e-15)
    se = 5.0 / math.sqrt(trials)
    assert np.all(np.abs(s["ratio_mean"] - r.noise_free_ratio)[1:] <= se * s["ratio_std"][1:])
    assert np.all(np.abs(s["phase_bias"]) <= se * s["phase_std"])
    assert s["bandwidth_found"] == trials
    assert abs(s["bandwidth_mean"] - r.noise_free_bandwidth) <= se * s["bandwidth_std"]
    assert abs(r.truth_bandwidth - second_order_bandwidth(100.0, 0.7)) == 0.0
    tolerance = 4.0 / math.sqrt(2 * (trials - 1))
    np.testing.assert_allclose(s["ratio_std"][1:] / r.gum["ratio"][1:], 1.0, atol=tolerance)
    np.testing.assert_allclose(s["phase_std"] / r.gum["phase"], 1.0, atol=tolerance)
    assert s["bandwidth_std"] / r.gum["bandwidth"] == pytest.approx(1.0, abs=tolerance)


def test_the_curve_fit_removes_the_chord_s_bias_that_the_interpolation_leaves():
    """ζ = 0.3 (f_3dB = 145.37 Hz) on JJF 1535 7.2.15.1 b)'s grid for an expected 140 Hz, 200 trials, seed 23.

    The chord between the two points either side of the level misses the curved response by 1.41 Hz, about 240
    of its own s: its MC mean sits on the noise-free procedure's value, not the truth. The second-order curve of
    JJF 1535 7.2.15.2 fitted to the same K_i is unbiased: its MC mean is within 5 s/√T of the truth (a correct
    estimator fails this with probability 5.7e-7 to first order), and its s matches its GUM u within
    4/√(2(T − 1)) = 0.20 relative, as the ratios' do above."""
    trials = 200
    settings = Jjf1537Experiment(damping=0.3, expected_bandwidth=140.0, vibration_frequency=20.0)
    r = run_jjf1537(settings, trials=trials, seed=23)
    s = r.summary()
    assert s["bandwidth_found"] == s["bandwidth_fit_found"] == trials
    assert abs(s["bandwidth_mean"] - r.noise_free_bandwidth) <= 5.0 / math.sqrt(trials) * s["bandwidth_std"]
    assert abs(s["bandwidth_bias"]) > 100.0 * s["bandwidth_std"]
    assert abs(s["bandwidth_fit_bias"]) <= 5.0 / math.sqrt(trials) * s["bandwidth_fit_std"]
    assert s["bandwidth_fit_std"] / r.gum["bandwidth_fit"] == pytest.approx(1.0, abs=4.0 / math.sqrt(2 * (trials - 1)))


def test_the_table_s_errors_without_noise_reach_the_estimates_exactly():
    """No noise, a linear sensor: with the table turning at A(1 + ε_i) and phase φ_in + δ_i while the lab reads A
    and φ_in (:func:`table_errors`, once per frequency of a trial), eq. (7)–(9) give K_i = K_i⁰(1 + ε_i)/(1 + ε_1)
    and Δφ_i = arg H(f_i) + δ_i, to 1e-9; 7.2.4's amplitude nonlinearity of the linear sensor is that of
    S(1 + ε_k), max |ε_k − ε̄|/(1 + ε̄). Errors of 1 % and 1° make every term visible."""
    s = Jjf1537Experiment(gyro_arw=0.0, quantisation=0.0, table_amplitude_error=0.01, table_phase_error=math.radians(1),
                          **SHORT)
    seed, trials = 4, 3
    r = run_jjf1537(s, trials=trials, seed=seed)
    m = r.schedule.frequencies.size
    for t in range(trials):
        eps, delta = table_errors(s, seed, t, m)
        assert np.all(eps != 0) and np.all(delta != 0)
        np.testing.assert_allclose(r.ratios[t], r.noise_free_ratio * (1 + eps) / (1 + eps[0]), rtol=0, atol=1e-9)
        np.testing.assert_allclose(r.phases[t], r.truth_phase + delta, rtol=0, atol=1e-9)
        k_eps = table_errors(s, seed, t, s.linearity_points, ITEM_TABLE_ERROR_STREAM)[0]
        expected = np.max(np.abs(k_eps - k_eps.mean())) / (1 + k_eps.mean())
        assert r.vibration_shock.estimates["amplitude_nonlinearity"][t] == pytest.approx(expected, abs=1e-9)
    perfect = run_jjf1537(dataclasses.replace(s, table_amplitude_error=0.0, table_phase_error=0.0), trials=1,
                          seed=seed)
    np.testing.assert_allclose(perfect.ratios[0], r.noise_free_ratio, rtol=0, atol=1e-9)


def test_the_table_s_errors_do_not_average_over_the_repeats_and_the_gum_carries_them():
    """Table errors of 0.1 % and 0.05° (10 times the noise's part of u(K) and of u(Δφ) over n = 7), 200 trials,
    seed 29: the MC standard deviations of K_i, Δφ_i and of both bandwidths match the GUM with the table's terms
    within 4/√(2(T − 1)) = 0.20 relative (the relative standard error of a standard deviation, times 4), where the
    GUM without them would be 3 to 10 times too small; the means stay on the noise-free values within 5 s/√T."""
    trials = 200
    s = Jjf1537Experiment(table_amplitude_error=1e-3, table_phase_error=math.radians(0.05), vibration_frequency=20.0)
    r = run_jjf1537(s, trials=trials, seed=29)
    summary = r.summary()
    tolerance = 4.0 / math.sqrt(2 * (trials - 1))
    np.testing.assert_allclose(summary["ratio_std"][1:] / r.gum["ratio"][1:], 1.0, atol=tolerance)
    np.testing.assert_allclose(summary["phase_std"] / r.gum["phase"], 1.0, atol=tolerance)
    assert summary["bandwidth_std"] / r.gum["bandwidth"] == pytest.approx(1.0, abs=tolerance)
    assert summary["bandwidth_fit_std"] / r.gum["bandwidth_fit"] == pytest.approx(1.0, abs=tolerance)
    noise_only = run_jjf1537(dataclasses.replace(s, table_amplitude_error=0.0, table_phase_error=0.0), trials=2,
                             seed=29).gum
    assert np.all(r.gum["ratio"][1:] > 3 * noise_only["ratio"][1:]) and np.all(r.gum["phase"] > 3 * noise_only["phase"])
    se = 5.0 / math.sqrt(trials)
    assert np.all(np.abs(summary["ratio_mean"] - r.noise_free_ratio)[1:] <= se * summary["ratio_std"][1:])
    assert np.all(np.abs(summary["phase_bias"]) <= se * summary["phase_std"])


def test_cli_json_and_plot(capsys, tmp_path):
    plot = tmp_path / "bode.png"
    code = cli.main(["run", "jjf1537", "--trials", "3", "--seed", "5", "--json", "--quiet", "--plot", str(plot),
                     "--set", "record_time=0.25 s"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert err == ""  # --quiet: no progress line
    doc = json.loads(out)
    assert set(doc) == {"experiment", "seed", "trials", "overrides", "plansim_version", "elapsed_s", "units",
                        "settings", "frequencies", "truth", "noise_free", "monte_carlo", "gum", "type_a_mean",
                        "vibration_shock"}
    assert (doc["experiment"], doc["seed"], doc["trials"]) == ("jjf1537", 5, 3)
    assert doc["overrides"] == ["record_time=0.25 s"]
    assert len(doc["frequencies"]) == len(doc["monte_carlo"]["ratio_mean"]) == len(doc["gum"]["ratio"]) == 10
    assert doc["truth"]["bandwidth"] == pytest.approx(second_order_bandwidth(100.0, 0.7))
    assert doc["monte_carlo"]["bandwidth_found"] == 3 and doc["monte_carlo"]["bandwidth_fit_found"] == 3
    assert doc["noise_free"]["bandwidth_fit"] == pytest.approx(doc["truth"]["bandwidth"], abs=1e-9)
    assert doc["gum"]["bandwidth_fit"] > 0
    assert doc["settings"]["table_amplitude_error"] == 0.0 and doc["settings"]["table_phase_error"] == 0.0
    assert plot.stat().st_size > 10_000
    items = doc["vibration_shock"]
    assert set(items["items"]) == set(ITEMS) and items["shock_waveform_simulated"] is True
    assert set(items["shock"]) == {"peak_truth", "peak_mean", "peak_std", "saturated", "not_settled", "shock_record",
                                   "recovery_median", "recovery_max"}
    assert items["items"]["amplitude_nonlinearity"]["gum"] is None  # no GUM for a maximum: null, strict JSON
    assert items["items"]["bias_change_shock"]["truth"] == 0.0


def test_cli_text_and_bad_input(capsys):
    assert cli.main(["run", "jjf1537", "--trials", "2", "--set", "record_time=0.25 s"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("plansim run jjf1537: seed 1537, 2 trials") and "-3 dB bandwidth: truth" in out
    assert "7.2.4 amplitude nonlinearity (ppm)" in out and "7.2.7 bias change, shock (deg/h)" in out
    assert "shock: half-sine 50 g, 11 ms along the input axis" in out and "peak output" in out
    assert "2/2 trials" in err  # the progress line
    assert cli.main(["run", "jjf1537", "--set", "repeats=5"]) == 2
    assert "repeats: expected an integer >= 7" in capsys.readouterr().err
    assert cli.main(["run", "jjf1537", "--set", "amplitude_fraction=0.05"]) == 2
    assert "amplitude_fraction: expected 0.1 to 0.3" in capsys.readouterr().err
    assert cli.main(["run", "jjf1537", "--set", "linearity_points=2"]) == 2
    assert "linearity_points: expected an integer >= 3, got 2" in capsys.readouterr().err
    assert cli.main(["run", "jjf1537", "--set", "vibration_frequency=3 kHz"]) == 2
    assert "vibration_frequency: expected < half the sample rate 4000 Hz, got 3000.0" in capsys.readouterr().err
    assert cli.main(["run", "jjf1537", "--set", "shock_bias_shift=1 m"]) == 2
    assert "--set 'shock_bias_shift=1 m'" in capsys.readouterr().err
    assert cli.main(["run", "jjf1537", "--trials", "1"]) == 2
    assert "--trials 1: must be >= 2" in capsys.readouterr().err
    assert cli.main(["run", "jjf1537", "--out", "x.nc"]) == 2
    assert "--out 'x.nc': not available with the test jjf1537" in capsys.readouterr().err


def test_settings_equal_after_round_trip():
    s = Jjf1537Experiment(damping=0.5)
    assert dataclasses.replace(s, overrides=("x",)) == s


def test_cli_says_when_the_bandwidth_is_outside_the_band(capsys):
    assert cli.main(["run", "jjf1537", "--trials", "2", "--quiet", "--set", "model=flat", "--set",
                     "record_time=0.25 s", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)  # inf and nan are null: strict JSON
    assert doc["truth"]["bandwidth"] is None and doc["monte_carlo"]["bandwidth_found"] == 0
    assert cli.main(["run", "jjf1537", "--trials", "2", "--quiet", "--set", "natural_frequency=200 Hz", "--set",
                     "record_time=0.25 s"]) == 0
    assert "not found in any trial: the response does not fall through -3.01 dB between 13.75 and 110 Hz" in \
        capsys.readouterr().out


#: a short 7.2.4–7.2.7 test: 0.25 s records at 20 Hz (5 whole cycles, 1000 samples), 5 s at rest and in vibration
SHORT_ITEMS = dict(record_time=0.25)


@pytest.mark.parametrize("even, odd", [(0.0, 0.0), (0.3, 0.0), (0.0, -0.2), (0.1, 0.05)])
def test_nonlinearity_harmonics_are_those_of_the_sampled_cycle(even, odd):
    """The mean and the fundamental of g(a cos θ) = a cos θ + c₂a²cos²θ + c₃a³cos³θ over one cycle, from 64
    samples (exact for harmonics up to 3: the discrete orthogonality of cos kθ on 64 equally spaced points)."""
    a = 0.7
    theta = 2 * np.pi * np.arange(64) / 64
    v = a * np.cos(theta)
    g = v + even * v**2 + odd * v**3
    mean, fundamental = static_nonlinearity_harmonics(a, even, odd)
    assert g.mean() == pytest.approx(float(mean), abs=1e-15)
    assert 2 * np.mean(g * np.cos(theta)) == pytest.approx(float(fundamental), abs=1e-15)


def test_estimators_of_the_items():
    A = np.array([1.0, 2.0, 3.0])
    assert amplitude_nonlinearity(A, 5.0 * A) == 0.0  # linear: 0 whatever the scale factor
    # S = 1, 1, 1.3: mean 1.1, largest deviation 0.2
    assert amplitude_nonlinearity(A, [1.0, 2.0, 3.9]) == pytest.approx(0.2 / 1.1, rel=1e-15)
    before, after = np.array([1.0, 3.0]), np.array([2.0, 4.0, 6.0])
    change, u = mean_change(before, after)
    assert change == pytest.approx(2.0) and u == pytest.approx(math.sqrt(4.0 / 3 + 2.0 / 2))
    with pytest.raises(ValueError, match=r"input_amplitudes: expected at least 3 values"):
        amplitude_nonlinearity([1.0, 2.0], [1.0, 2.0])
    with pytest.raises(ValueError, match=r"input_amplitudes: expected values > 0 rad/s"):
        amplitude_nonlinearity([0.0, 1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(TypeError, match=r"before: expected numbers"):
        mean_change("x", [1.0, 2.0])
    with pytest.raises(ValueError, match=r"after: expected at least 2 samples along the last axis"):
        mean_change([[1.0, 2.0]], [[1.0], [2.0]])


def test_items_schedule_and_settings_refuse_bad_input():
    ok = dict(frequency=20.0, amplitudes=[1.0, 1.2, 1.5], amplitude=1.0, gyro_range=5.0)
    VibrationShockSchedule(**ok)
    with pytest.raises(ValueError, match=r"amplitudes: expected at least 3 distinct values within 10-30 % of the "
                                         r"range, 0.5 to 1.5 rad/s .*got \[1.0, 1.2, 1.6\]"):
        VibrationShockSchedule(**{**ok, "amplitudes": [1.0, 1.2, 1.6]})
    with pytest.raises(TypeError, match=r"amplitudes: expected numbers"):
        VibrationShockSchedule(**{**ok, "amplitudes": ["a", "b", "c"]})
    with pytest.raises(ValueError, match=r"vibration_frequency: expected < half the sample rate 4000 Hz, got 2500"):
        VibrationShockSchedule(**{**ok, "frequency": 2500.0})
    with pytest.raises(ValueError, match=r"rest_time: expected a finite number > 0 s, got 0"):
        VibrationShockSchedule(**ok, rest_time=0)
    with pytest.raises(ValueError, match=r"linearity_points: expected an integer >= 3, got 2"):
        Jjf1537Experiment(linearity_points=2)
    with pytest.raises(ValueError, match=r"odd_nonlinearity: expected a number finite"):
        Jjf1537Experiment(odd_nonlinearity=math.inf)
    with pytest.raises(TypeError, match=r"shock_bias_shift: expected one number \(SI\), got 'x'"):
        Jjf1537Experiment(shock_bias_shift="x")
    s = with_overrides(Jjf1537Experiment(), ["vibration_bias_shift=-20 deg/h", "odd_nonlinearity=0.01",
                                             "vibration_frequency=40 Hz"])
    assert s.vibration_bias_shift == pytest.approx(-20 * DEG / 3600) and s.odd_nonlinearity == 0.01
    assert s.vibration_shock_schedule().frequency == 40.0


@pytest.mark.parametrize("model", ["flat", "second_order", "two_resonance"])
def test_items_zero_noise_identity(model):
    """No noise, no quantiser. With the nonlinearity off, the amplitude nonlinearity and the output change under
    vibration are 0 to 1e-12 and the bias changes are the shifts to 1e-15 rad/s.

    With it on, g(v) = v + c₂'v² + c₃'v³ (c₂' = c₂/R, c₃' = c₃/R²) after the dynamics, v = a cos θ, a = A|H| at
    f = 20 Hz (200 samples per cycle at 4 kHz: the records are exactly whole cycles). By cos³θ = (3cos θ + cos 3θ)/4
    and the orthogonality of the harmonics over whole cycles, the sine fit reads E_k = S(a_k + (3/4)c₃'a_k³),
    so S_k = E_k/A_k = S|H|(1 + (3/4)c₃'|H|²A_k²) and, with ⟨·⟩ the mean over the M amplitudes,

        γ = max_k |S_k − ⟨S⟩|/⟨S⟩ = (3/4)|c₃'||H|² max_k |A_k² − ⟨A²⟩| / (1 + (3/4)c₃'|H|²⟨A²⟩);

    for A_k = 30, 45, 60, 75, 90 °/s (R = 300 °/s), ⟨A²⟩ = 20250/5 = 4050 (°/s)² and the largest deviation
    8100 − 4050 = 4050 (°/s)² at 90 °/s (900 − 4050 = −3150 at 30 °/s). The even term adds nothing to the
    fundamental (cos²θ = (1 + cos 2θ)/2) but rectifies: the mean under vibration rises by S c₂'a²/2, the output
    change of 7.2.5. γ, a difference of sensitivities
    (dimensionless), to 1e-12 absolute (the run-in leaves 1e-13 of the start-up transient in each E_k); the
    output change to 1e-12 relative."""
    base = dict(model=model, gyro_arw=0.0, quantisation=0.0, scale_factor=1.01, bias=0.3, **SHORT_ITEMS)
    off = run_vibration_shock(Jjf1537Experiment(**base, vibration_bias_shift=1e-4, shock_bias_shift=-3e-4),
                              trials=2, seed=1)
    assert np.all(np.abs(off.estimates["amplitude_nonlinearity"]) <= 1e-12)
    assert np.all(np.abs(off.estimates["vibration_output_change"]) <= 1e-12)
    np.testing.assert_allclose(off.estimates["bias_change_vibration"], 1e-4, rtol=0, atol=1e-15)
    np.testing.assert_allclose(off.estimates["bias_change_shock"], -3e-4, rtol=0, atol=1e-15)

    c2, c3 = 0.04, -0.06
    settings = Jjf1537Experiment(**base, even_nonlinearity=c2, odd_nonlinearity=c3)
    on = run_vibration_shock(settings, trials=2, seed=1)
    R, S = settings.gyro_range, 1.01
    H2 = abs(settings.dynamics().response(20.0)) ** 2
    A2 = (np.array([30.0, 45.0, 60.0, 75.0, 90.0]) * DEG) ** 2
    assert A2.mean() == pytest.approx(4050 * DEG**2) and np.max(np.abs(A2 - A2.mean())) == pytest.approx(4050 * DEG**2)
    gamma = 0.75 * abs(c3) / R**2 * H2 * 4050 * DEG**2 / (1 + 0.75 * c3 / R**2 * H2 * 4050 * DEG**2)
    change = S * c2 / R * H2 * (60 * DEG) ** 2 / 2
    np.testing.assert_allclose(on.estimates["amplitude_nonlinearity"], gamma, rtol=0, atol=1e-12)
    np.testing.assert_allclose(on.estimates["vibration_output_change"], change, rtol=1e-12)
    assert on.truth["amplitude_nonlinearity"] == pytest.approx(gamma, rel=1e-12)
    assert on.truth["vibration_output_change"] == pytest.approx(change, rel=1e-12)


def test_item_records_do_not_depend_on_the_chunking():
    s = Jjf1537Experiment(**SHORT_ITEMS, odd_nonlinearity=0.1)
    whole = simulate_vibration_shock(s, 11, [0, 1, 2])
    alone = simulate_vibration_shock(s, 11, [2])
    for key in whole:
        assert np.array_equal(simulate_vibration_shock(s, 11, [0, 1, 2], chunk=777)[key], whole[key])
        assert np.array_equal(alone[key], whole[key][2:])
    one = run_vibration_shock(s, trials=5, seed=3, chunk_trials=2)
    two = run_vibration_shock(s, trials=5, seed=3, chunk_trials=5)
    for name in ITEMS:
        assert np.array_equal(one.estimates[name], two.estimates[name])
    assert not np.array_equal(run_vibration_shock(s, trials=2, seed=4).estimates[ITEMS[1]],
                              one.estimates[ITEMS[1]][:2])


def test_items_monte_carlo_against_the_truth_and_the_coverage_of_their_uncertainty():
    """The default noise (ARW 0.5 °/√h, the 16-bit quantiser), a cubic (c₃ = 0.1) and a rectifying (c₂ = 0.02)
    nonlinearity, bias shifts of +30 °/h after the vibration and −50 °/h after the shock; T = 300 trials, seed 7.

    - Every figure's MC mean is within 5 s/√T of the truth: the changes of mean are unbiased; the nonlinearity's
      maximum |S_k − ⟨S⟩| is at 90 °/s (|A² − ⟨A²⟩| = 4050 (°/s)²), its runner-up at 30 °/s (3150) is
      (1 − 3150/4050) γ ≈ 750 ppm below it, 2.4 times the standard deviation of the difference of the two
      deviations (u(S) ≈ 300 ppm at 30 °/s with 0.25 s records), so the maximum stays at 90 °/s, where the
      estimator is smooth and unbiased to first order, in all but about 1 % of the trials. A correct
      simulation fails one of these 4 checks with probability < 4 × 5.7e-7.
    - The MC standard deviations equal the GUM's within 4/√(2(T − 1)) = 0.16 relative (4 relative standard
      errors of a standard deviation from T normal samples): the changes' σ√(1/N₁ + 1/N₂), the nonlinearity's
      first-order u at 90 °/s (``vibration_shock_gum``).
    - The coverage of ± 2 u_A (the Type A u of ``mean_change``, 20 000 samples a record: normal to 1e-4) is
      p = 0.9545 within 4√(p(1 − p)/T) = 0.048 (4 binomial standard errors: failure probability < 6.4e-5 each).
    """
    trials = 300
    s = Jjf1537Experiment(**SHORT_ITEMS, odd_nonlinearity=0.1, even_nonlinearity=0.02,
                          vibration_bias_shift=30 * DEG / 3600, shock_bias_shift=-50 * DEG / 3600)
    summary = run_vibration_shock(s, trials=trials, seed=7).summary()
    for name in ITEMS:
        fig = summary[name]
        assert abs(fig["mean"] - fig["truth"]) <= 5.0 * fig["std"] / math.sqrt(trials), name
    p = math.erf(2.0 / math.sqrt(2.0))
    for name in ITEMS:
        fig = summary[name]
        assert fig["std"] / fig["gum"] == pytest.approx(1.0, abs=4.0 / math.sqrt(2 * (trials - 1))), name
    for name in ITEMS[1:]:
        fig = summary[name]
        assert fig["coverage"] == pytest.approx(p, abs=4.0 * math.sqrt(p * (1 - p) / trials)), name
        assert fig["type_a_mean"] / fig["gum"] == pytest.approx(1.0, rel=0.02), name
    assert summary["bias_change_shock"]["truth"] == pytest.approx(-50 * DEG / 3600)


def test_the_drift_covariance_is_that_of_a_rate_random_walk_s_record_means():
    """Cov(b̄_i, b̄_j) of a rate random walk S K W(t) averaged over the five records, against a midpoint quadrature
    of (1/(T_i T_j)) ∫∫ min(s, t) (400 × 400 points per pair: error < 1e-4 relative); a record's own variance is
    S²K²(a + T/3) exactly."""
    s = Jjf1537Experiment(**SHORT_ITEMS, gyro_rrw=1e-3, scale_factor=1.3)
    C = drift_covariance(s)
    iv = drift_intervals(s)
    K2 = (1.3 * 1e-3) ** 2
    for i in range(5):
        a, b = iv[i]
        assert C[i, i] == pytest.approx(K2 * (a + (b - a) / 3.0), rel=1e-12)
        for j in range(5):
            u = iv[i, 0] + (np.arange(400) + 0.5) / 400 * (iv[i, 1] - iv[i, 0])
            v = iv[j, 0] + (np.arange(400) + 0.5) / 400 * (iv[j, 1] - iv[j, 0])
            assert C[i, j] == pytest.approx(K2 * np.minimum.outer(u, v).mean(), rel=1e-4), (i, j)
    np.testing.assert_array_equal(drift_offsets(dataclasses.replace(s, gyro_rrw=0.0), 3, [0]), np.zeros((1, 5)))


def test_a_drifting_bias_reaches_the_records_means_exactly_without_noise():
    """No white noise, no quantiser: each record at rest reads B + its shift + its drawn mean drift, exactly."""
    s = Jjf1537Experiment(**SHORT_ITEMS, gyro_arw=0.0, quantisation=0.0, gyro_rrw=1e-3, vibration_bias_shift=2e-4,
                          shock_peak=0.0)
    records = simulate_vibration_shock(s, 5, [0, 1])
    for t, drift in enumerate(drift_offsets(s, 5, [0, 1])):
        expected = s.bias + np.array([drift[0], 2e-4 + drift[2], 2e-4 + drift[4]])
        np.testing.assert_allclose(records["rest"][t].mean(axis=-1), expected, rtol=0, atol=1e-15)
        np.testing.assert_allclose(records["rest"][t].std(axis=-1), 0.0, atol=1e-15)


def test_a_drifting_bias_widens_the_bias_changes_beyond_their_type_a_u():
    """A rate random walk of 2000 °/h/√h across 5 s records (mean-drift sd ≈ 5 times the records' white noise on
    the changes), 200 trials, seed 13: the MC standard deviations of the three changes of mean match the GUM with
    the drift within 4/√(2(T − 1)) = 0.20 relative, while the records' own Type A u (which cannot see a drift
    between records) covers the bias change across the vibration in well under the nominal 95 % (below 60 %:
    with u_A/u ≈ 0.2, P(|e| ≤ 2u_A) ≈ 0.31)."""
    trials = 200
    s = Jjf1537Experiment(**SHORT_ITEMS, linearity_points=3, gyro_rrw=2000 * DEG / 3600 / 60)
    summary = run_vibration_shock(s, trials=trials, seed=13).summary()
    for name in ITEMS[1:]:
        fig = summary[name]
        assert fig["std"] / fig["gum"] == pytest.approx(1.0, abs=4.0 / math.sqrt(2 * (trials - 1))), name
        assert fig["gum"] > 3 * fig["type_a_mean"], name
    assert summary["bias_change_vibration"]["coverage"] < 0.6
