"""JJF 1537-2015 7.2.7's shock as a waveform: the half-sine pulse (plansim.model.dynamics.half_sine), the records
driven through the sensor's dynamics (plansim.kernels.dynamics.input_records,
plansim.simulate.jjf1537_items.shock_records) and what the shock record shows
(plansim.estimate.dynamic.shock_response): peak, saturation, recovery time."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.signal

from plansim.estimate.dynamic import shock_response
from plansim.model.dynamics import half_sine
from plansim.simulate.jjf1537_items import (
    ITEM_STREAMS,
    REST_RECORDS,
    run_vibration_shock,
    shock_filter,
    shock_input,
    shock_noise_free,
    shock_records,
    simulate_vibration_shock,
)
from plansim.simulate.vibration_table import Jjf1537Experiment, table_records, with_overrides
from plansim.units import DEG, STANDARD_GRAVITY

#: short records: the tests look at the shock, not at 7.2.4–7.2.6
SHORT = dict(record_time=0.25, vibration_time=0.5, rest_time=0.5, linearity_points=3, repeats=7)
QUIET = dict(gyro_arw=0.0, quantisation=0.0)


def test_half_sine_shape():
    """50 g, 11 ms at 4 kHz: 44 samples inside the pulse (t = 0 … 10.75 ms), zero after; the peak at t = 5.5 ms
    is a sample (k = 22); the sum over the pulse is Σ_{k<N} sin(πk/N) = cot(π/(2N)) (N = 44), which tends to
    the continuous pulse's mean 2·peak/π (here 4.2e-4 below it)."""
    peak = 50 * STANDARD_GRAVITY
    a = half_sine(peak, 0.011, 4000.0, 100)
    assert a.shape == (100,) and np.all(a[44:] == 0.0) and np.all(a[1:44] > 0) and a[0] == 0.0
    assert a[22] == pytest.approx(peak, rel=1e-15) and np.argmax(a) == 22
    assert a[:44].sum() == pytest.approx(peak / math.tan(math.pi / 88), rel=1e-13)
    assert a[:44].sum() / 44 == pytest.approx(2 * peak / math.pi, rel=5e-4)
    assert np.all(half_sine(0.0, 0.011, 4000.0, 50) == 0.0)
    with pytest.raises(ValueError, match="duration"):
        half_sine(peak, 0.0, 4000.0, 10)
    with pytest.raises(ValueError, match="samples: expected an integer >= 0, got -1"):
        half_sine(peak, 0.011, 4000.0, -1)


@pytest.mark.parametrize("model", ["second_order", "two_resonance"])
def test_zero_noise_shock_record_is_the_filtered_pulse(model):
    """No noise, no quantiser: the shock record less the level before it is S·(H x)(t_k) with x the g-sensitivity
    times the half-sine, H the discretised dynamics — the numba kernel against scipy.signal.lfilter on the same
    coefficients, to 1e-13 of the peak — and the record after it continues the same filtered signal; the bias
    step of the shock appears from the pulse's end."""
    s = Jjf1537Experiment(model=model, **SHORT, **QUIET, scale_factor=1.01, bias=0.3, vibration_bias_shift=1e-3,
                          shock_bias_shift=-2e-3, shock_peak=100 * STANDARD_GRAVITY, g_sensitivity=0.1 * DEG /
                          STANDARD_GRAVITY, shock_settle=0.05)
    sch = s.vibration_shock_schedule()
    shock, after = shock_records(s, 3, [0, 1], [10, 11])
    level = s.bias + s.vibration_bias_shift
    expected = shock_noise_free(s)
    peak = np.max(np.abs(expected))
    assert peak > 1.0 * DEG  # a response of ~16 deg/s: the test sees the dynamics
    np.testing.assert_allclose(shock - level, np.broadcast_to(expected, shock.shape), rtol=0, atol=1e-13 * peak)
    b, a = shock_filter(s)
    whole = 1.01 * scipy.signal.lfilter(b, a, shock_input(s))
    whole[sch.pulse_samples():] += s.shock_bias_shift
    np.testing.assert_allclose(after - level, np.broadcast_to(whole[sch.shock_samples():], after.shape), rtol=0,
                               atol=1e-13 * peak)
    assert s.vibration_shock_schedule().pulse_samples() == 44


def test_shock_records_do_not_depend_on_the_chunking_and_without_a_pulse_the_rest_record_is_unchanged():
    """Any sample chunk gives the same numbers bit for bit (state carried, noise indexed by sample); with no
    pulse (shock_peak 0) the record after the shock is exactly the record at rest it was before the shock had a
    waveform (table_records at rest on its own stream, bias shifted by both shifts)."""
    s = Jjf1537Experiment(**SHORT, model="two_resonance", shock_settle=0.05)
    whole = shock_records(s, 5, [0, 3], [20, 21])
    for chunk in (1, 7, 1000):
        for a, b in zip(shock_records(s, 5, [0, 3], [20, 21], chunk=chunk), whole):
            assert np.array_equal(a, b)
    flat = with_overrides(s, ["shock_peak=0 g"])
    records = simulate_vibration_shock(flat, 5, [0, 2])
    sch = flat.vibration_shock_schedule()
    per_trial = sch.amplitudes.size * sch.repeats + 1 + len(REST_RECORDS)
    streams = ITEM_STREAMS + np.array([0, 2]) * per_trial + sch.amplitudes.size * sch.repeats + 3
    old = table_records(flat, 5, sch.frequency, 0.0, np.zeros(2), sch.rest_samples(), streams,
                        bias_shift=flat.vibration_bias_shift + flat.shock_bias_shift)
    assert np.array_equal(records["rest"][:, 2], old)


def test_saturation_and_peak():
    """A 1000 g pulse through 0.5 °/s/g asks for 500 °/s of a ±300 °/s gyro: every trial saturates and the peak
    reads the range less the level before the shock (noise-free: exactly)."""
    s = Jjf1537Experiment(**SHORT, **QUIET, bias=0.01, shock_peak=1000 * STANDARD_GRAVITY,
                          g_sensitivity=0.5 * DEG / STANDARD_GRAVITY)
    result = run_vibration_shock(s, trials=2, seed=1)
    summary = result.shock_summary()
    assert summary["saturated"] == 2
    assert summary["peak_truth"] == pytest.approx(s.gyro_range - s.bias, rel=1e-12)
    np.testing.assert_allclose(result.estimates["shock_peak_output"], summary["peak_truth"], rtol=1e-12)


def test_a_ringing_sensor_not_settled_biases_the_bias_change_by_its_tail():
    """A lightly damped sense mode (ζ = 0.02 at 100 Hz: time constant 1/(ζω) = 80 ms) rings after a 100 g pulse
    read at 0.1 °/s/g; with the record after the shock 50 ms after the pulse's start, noise-free, the recovery time
    is longer than the shock record (the laboratory is warned), and the bias change of 7.2.7 reads the shift plus
    the ringing's mean over the record after the shock — exactly that mean, from scipy.signal.lfilter. Settled
    (1 s) the same holds, with a share at least 1000 times smaller."""
    base = dict(**SHORT, **QUIET, model="two_resonance", damping=0.02, shock_peak=100 * STANDARD_GRAVITY,
                g_sensitivity=0.1 * DEG / STANDARD_GRAVITY, shock_bias_shift=1e-4)
    short = Jjf1537Experiment(**base, shock_settle=0.05)
    result = run_vibration_shock(short, trials=2, seed=2)
    summary = result.shock_summary()
    assert summary["not_settled"] == 2 and summary["recovery_median"] > summary["shock_record"]

    def tail_mean(settings):
        b, a = shock_filter(settings)
        tail = scipy.signal.lfilter(b, a, shock_input(settings))[settings.vibration_shock_schedule().shock_samples():]
        return tail.mean()

    share = tail_mean(short)
    np.testing.assert_allclose(result.estimates["bias_change_shock"], 1e-4 + share, rtol=0, atol=1e-14)
    assert abs(share) > 1e-6  # ~0.1 deg/h: not negligible, which is what the warning is for
    long = Jjf1537Experiment(**base, shock_settle=1.0)
    settled = run_vibration_shock(long, trials=2, seed=2)
    assert settled.shock_summary()["not_settled"] == 0
    np.testing.assert_allclose(settled.estimates["bias_change_shock"], 1e-4 + tail_mean(long), rtol=0, atol=1e-14)
    assert abs(tail_mean(long)) < 1e-3 * abs(share)


def test_shock_response_by_hand():
    """A hand-made record at 1 kHz: level 0 before, 1 after, band 0.1; samples 0–2 the pulse (5, 3, 2), then
    0.95, 1.2 (outside), 1.05, 1.0: the last sample outside is index 4, so the recovery time is 5 ms; the peak
    |y − 0| is 5; nothing at the range 10."""
    y = np.array([5.0, 3.0, 2.0, 0.95, 1.2, 1.05, 1.0])
    r = shock_response(y, 0.0, 1.0, 0.1, 1000.0, 10.0)
    assert (r.peak, r.saturated, r.recovery_time) == (5.0, False, 0.005)
    assert math.isnan(shock_response(y[:5], 0.0, 1.0, 0.1, 1000.0, 10.0).recovery_time)  # ends outside
    assert shock_response(np.ones(4), 0.0, 1.0, 0.1, 1000.0, 1.0).saturated
    assert shock_response(np.ones(4), 1.0, 1.0, 0.1, 1000.0, 10.0).recovery_time == 0.0
    with pytest.raises(ValueError, match="band: expected a finite number > 0, got 0"):
        shock_response(y, 0.0, 1.0, 0, 1000.0, 10.0)
    with pytest.raises(ValueError, match="record: expected a non-empty 1-D array"):
        shock_response(np.array([1.0, np.nan]), 0.0, 1.0, 0.1, 1000.0, 10.0)


def test_settings_read_units_and_refuse_a_pulse_too_short_to_draw():
    s = with_overrides(Jjf1537Experiment(**SHORT), ["shock_duration=11 ms", "shock_peak=30 g",
                                                    "g_sensitivity=0.05 deg/s/g", "shock_settle=200 ms"])
    assert (s.shock_duration, s.shock_settle) == (pytest.approx(0.011), pytest.approx(0.2))
    assert s.shock_peak == pytest.approx(30 * STANDARD_GRAVITY) and s.g_sensitivity == pytest.approx(
        0.05 * DEG / STANDARD_GRAVITY)
    with pytest.raises(ValueError, match="shock_duration: 0.001 s gives 4 samples at 4000 Hz; the half-sine needs >= "
                                         "8"):
        Jjf1537Experiment(**SHORT, shock_duration=0.001)
    with pytest.raises(ValueError, match="shock_settle"):
        with_overrides(Jjf1537Experiment(**SHORT), ["shock_settle=0 s"])
