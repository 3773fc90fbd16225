"""Within-segment tests (plansim.diagnose.within): the null noise generator, the statistics, the calibrated
family-wise false-alarm rate and the power on patterns the segment means cannot show.

Statistical tests use fixed seeds; their tolerances come from the binomial law of the number of trials and say
their power.
"""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import allantools
import numpy as np
import pytest
from scipy.stats import binom

from plansim.diagnose.within import (
    TESTS,
    segment_statistics,
    simulate_noise,
    turning_noise_before_quantiser,
    within_segment_tests,
)
from plansim.fit.noise import FLICKER_VARIANCE, ChannelNoise, turning_residuals
from plansim.kernels.layout import CHANNELS
from plansim.schedule.segments import Segment

FS = 100.0
N = 5e-4  # white noise, per √Hz
SIGMA = N * math.sqrt(FS)  # per sample


def channel(white=N, B=0.0, K=0.0, q=0.0, name="gx"):
    empty = np.zeros(0)
    return ChannelNoise(name, white, B, K, q, 4, 4000, empty, empty, empty)


def noise(**kwargs):
    return SimpleNamespace(channels=tuple(channel(name=c, **kwargs) for c in CHANNELS))


def static_segments(count=4, dwell=10.0):
    return [Segment(label=f"pose {k}", test="static", group=0, up="+x", dwell=dwell, sample_rate=FS)
            for k in range(count)]


def white_samples(segments, rng, sigma=SIGMA):
    return [sigma * rng.standard_normal((s.samples, 6)) for s in segments]


# ------------------------------------------------------------------------------------------- the null noise
def test_simulated_flicker_has_the_allan_floor_the_fit_assumes():
    # B only: the Allan deviation of the simulated samples at τ in the flat part equals √(2 ln 2/π)·B (IEEE 952)
    B = 1e-4
    x = simulate_noise(channel(white=0.0, B=B), 20000, FS, 8, np.random.default_rng(1))
    taus = np.array([1.0, 3.0, 10.0])
    floors = []
    for row in x:
        t, adev, *_ = allantools.oadev(row, rate=FS, data_type="freq", taus=taus)
        floors.append(adev)
    ratio = np.mean(floors, axis=0) / (math.sqrt(FLICKER_VARIANCE) * B)
    assert np.all(np.abs(ratio - 1.0) < 0.15), ratio  # 8 records of 200 s: the estimator's own scatter ~5 %


def test_simulated_white_noise_and_quantiser():
    x = simulate_noise(channel(), 4000, FS, 50, np.random.default_rng(2))
    assert np.std(x) == pytest.approx(SIGMA, rel=0.02)  # 2·10⁵ samples: SE 0.16 %
    q = 2 * SIGMA
    y = simulate_noise(channel(q=q), 1000, FS, 5, np.random.default_rng(3), level=0.3 * q)
    assert np.allclose(y / q, np.round(y / q))


# ------------------------------------------------------------------------------------------- statistics
def test_statistics_of_known_patterns():
    rng = np.random.default_rng(4)
    n = 2000
    t = np.arange(n) / FS
    white = SIGMA * rng.standard_normal(n)
    sine, _ = segment_statistics(white + 0.5 * SIGMA * np.sin(2 * math.pi * 7.0 * t), FS)
    base, _ = segment_statistics(white, FS)
    _, freq = segment_statistics(white + 0.5 * SIGMA * np.sin(2 * math.pi * 7.0 * t), FS)
    assert sine[TESTS.index("periodic")] > 10 * base[TESTS.index("periodic")]
    assert freq == pytest.approx(7.0, abs=FS / n)
    step, _ = segment_statistics(white + 0.5 * SIGMA * (t > 12.0), FS)
    assert step[TESTS.index("step")] > 8.0  # 0.5σ over 800 and 1200 samples: about 12 standard errors
    flat, f = segment_statistics(np.full(n, 3.0), FS)
    assert np.all(np.isnan(flat)) and np.isnan(f)  # nothing varies: nothing to test


# ------------------------------------------------------------------------------------------- the tests
def test_family_wise_false_alarms_are_at_most_alpha():
    # 60 recordings of white noise (4 segments at rest × 6 channels × 5 tests each): the fraction flagged must
    # not exceed α = 0.2 beyond the binomial 99 % bound (power: a true rate of 0.35 fails it 90 % of the time)
    segments = static_segments()
    alpha, count = 0.2, 60
    flagged = 0
    for i in range(count):
        rng = np.random.default_rng(100 + i)
        result = within_segment_tests(white_samples(segments, rng), segments, noise(), alpha=alpha, draws=99,
                                      seed=i)
        flagged += result.any_flagged
    assert flagged <= binom.ppf(0.99, count, alpha)


def test_filtered_noise_is_tested_against_its_own_correlation():
    """A sensor's own low-pass filter (first order, y_i = ½·y_{i−1} + ½·x_i, ρ₁ = ½) makes trends and steps within a
    segment larger than white noise of the same scatter has. Against a white null every one of these recordings is
    flagged (measured: 60 of 60 at α = 0.2); against the autoregression with the correlation the static segments
    show (ChannelNoise.autocorrelation, from noise_autocorrelation as the fit takes it), at most α within the
    binomial 99 % bound over 60 (measured: 11)."""
    from scipy.signal import lfilter

    from plansim.fit.noise import noise_autocorrelation

    segments = static_segments()
    alpha, count, empty = 0.2, 60, np.zeros(0)

    def recording(i, correlated):
        rng = np.random.default_rng(100 + i)
        x = [lfilter([0.5], [1.0, -0.5], SIGMA * rng.standard_normal((s.samples + 200, 6)), axis=0)[200:]
             for s in segments]
        channels = tuple(ChannelNoise(name, N, 0.0, 0.0, 0.0, 4, 4000, empty, empty, empty,
                                      noise_autocorrelation([(y[:, c], FS) for y in x]) if correlated else empty)
                         for c, name in enumerate(CHANNELS))
        return within_segment_tests(x, segments, SimpleNamespace(channels=channels), alpha=alpha, draws=99,
                                    seed=i).any_flagged

    assert sum(recording(i, correlated=False) for i in range(10)) >= 9  # the white null runs hot
    assert sum(recording(i, correlated=True) for i in range(count)) <= binom.ppf(0.99, count, alpha)


def test_simulated_filtered_noise_has_the_correlation_and_the_long_run_level():
    """The null of a channel with ρ₁ … ρ_L: each sample's σ is N·√(f_s·γ₀/S), so that blocks of 100 samples (far
    beyond the correlation) vary as white noise of density N would, N²·f_s/100; and ρ₁ is the channel's."""
    from plansim.fit.noise import noise_autocorrelation

    rho = np.array([0.6, 0.3, 0.1])
    ch = dataclasses.replace(channel(), autocorrelation=rho)
    x = simulate_noise(ch, 20000, FS, 20, np.random.default_rng(7))
    assert noise_autocorrelation([(row, FS) for row in x])[:3] == pytest.approx(rho, abs=0.01)  # 4·10⁵ samples
    blocks = x.reshape(20, -1, 100).mean(axis=-1)
    # 4000 blocks: the variance's relative SE is √(2/4000) = 2.2 %, 10 % is 4.5 of those
    assert np.var(blocks) == pytest.approx(SIGMA**2 / 100, rel=0.1)


@pytest.mark.parametrize("pattern, test", [
    ("sine", "periodic"), ("step", "step"), ("burst", "burst"), ("noisier", "scatter"), ("trend", "trend"),
    ("settling", "transient")])
def test_patterns_inside_one_segment_are_found_and_named(pattern, test):
    segments = static_segments()
    rng = np.random.default_rng(7)
    samples = white_samples(segments, rng)
    n = segments[2].samples
    t = np.arange(n) / FS
    x = samples[2][:, 0]
    if pattern == "sine":
        x += 0.5 * SIGMA * np.sin(2 * math.pi * 3.0 * t)
    elif pattern == "step":
        x += 0.6 * SIGMA * (t > 4.0)
    elif pattern == "burst":
        x += 3.0 * SIGMA * rng.standard_normal(n) * ((t > 2.0) & (t < 3.0))
    elif pattern == "noisier":
        x += 1.5 * SIGMA * rng.standard_normal(n)
    elif pattern == "settling":  # a decay from the segment's start, 3 % of it (t from 0)
        x += 3.0 * SIGMA * np.exp(-t / (0.03 * n / FS))
    else:
        x += 0.12 * SIGMA * t
    result = within_segment_tests(samples, segments, noise(), alpha=0.05, draws=199, seed=1)
    first = result.flagged[0]
    assert (first["channel"], first["segment"]) == ("gx", 2)
    assert test in {f["test"] for f in result.flagged if f["segment"] == 2}
    if pattern == "sine":
        periodic = next(f for f in result.flagged if f["test"] == "periodic")
        assert periodic["frequency_hz"] == pytest.approx(3.0, abs=0.1)
        assert periodic["amplitude"] == pytest.approx(0.5 * SIGMA, rel=0.2)
    if pattern == "step":
        step = next(f for f in result.flagged if f["test"] == "step")
        assert step["at_s"] == pytest.approx(4.0, abs=0.5)
    if pattern == "settling":
        transient = next(f for f in result.flagged if f["test"] == "transient")
        assert transient["time_constant_s"] == pytest.approx(0.03 * n / FS)
        assert transient["size"] == pytest.approx(3.0 * SIGMA, rel=0.15)


def test_turning_segments_are_tested_without_the_tables_harmonics():
    # a turning segment carries the table's harmonics of its angle (here a tilt's once-per-turn sine 20 times the
    # noise): removed before the tests, so it is not flagged; a burst inside it is; it takes no part in scatter
    turning = Segment(label="turning", test="rate", group=0, up="+x", rate=1.0, rate_axis="+x", dwell=10.0,
                      sample_rate=FS)
    segments = static_segments(3) + [turning]
    rng = np.random.default_rng(8)
    samples = white_samples(segments, rng)
    angle = np.arange(turning.samples) / FS
    samples[3][:, 0] += 20 * SIGMA * np.sin(angle + 0.3) + 2 * SIGMA * np.cos(2 * angle)
    result = within_segment_tests(samples, segments, noise(), draws=99, seed=2)
    assert result.segments == (0, 1, 2, 3) and not result.any_flagged
    assert np.all(np.isnan(result.statistic[TESTS.index("scatter"), :, 3]))
    samples[3][400:500, 0] += 3 * SIGMA * rng.standard_normal(100)
    burst = within_segment_tests(samples, segments, noise(), draws=99, seed=2)
    assert {(f["segment"], f["test"]) for f in burst.flagged} >= {(3, "burst")}


def _coarse_turning_recording(rng, q, sigma):
    """3 segments at rest and one turning at 1 rad/s, every channel through a quantiser of step q with white
    noise sigma before it; the turning segment's signal sweeps the codes (a once-per-turn sine of 1.5 q)."""
    turning = Segment(label="turning", test="rate", group=0, up="+x", rate=1.0, rate_axis="+x", dwell=10.0,
                      sample_rate=FS)
    segments = static_segments(3) + [turning]
    angle = np.arange(turning.samples) / FS
    samples = []
    for k, segment in enumerate(segments):
        level = 0.3 * q + (1.5 * q * np.sin(angle + 0.3) if k == 3 else 0.0)
        x = level[:, None] + sigma * rng.standard_normal((segment.samples, 6)) if k == 3 else \
            level + sigma * rng.standard_normal((segment.samples, 6))
        samples.append(q * np.round(x / q))
    return segments, samples, angle


def test_the_noise_before_the_quantiser_of_a_turning_segment_is_recovered():
    """σ = 0.6 q before the quantiser, a signal sweeping three codes along the turn: the σ that gives the observed
    scatter is σ within 5 % (the scatter of 1000 samples has a relative sd of 1/√2000 = 2.2 %, and ds/dσ ≈ 1;
    5 % is 2.2 of those)."""
    q, sigma = 1.0, 0.6
    rng = np.random.default_rng(31)
    segments, samples, _ = _coarse_turning_recording(rng, q, sigma)
    x = samples[3][:, 0]
    residual = turning_residuals(x, 1.0, FS)
    sd = float(np.std(residual, ddof=5))
    found = turning_noise_before_quantiser(x - residual, q, sd, 1.0, FS)
    assert found == pytest.approx(sigma, rel=0.05)
    assert turning_noise_before_quantiser(x - residual, q, 1e-3 * q, 1.0, FS) == 0.0  # less scatter than the sweep


def test_a_turning_channel_that_sits_on_its_codes_is_not_dithered():
    """An accelerometer at rest on one code through a rate test (jjf2003's 12-bit accelerometers), its level a
    hair above half-way between two codes and the fit's smooth signal rippling by round-off: its scatter about the
    fit, 2.4e-15 of a 0.077 m/s^2 step, is round-off. Any σ of that order pushes samples across the half-code, so
    the scatter jumps: Brent's method, asked for 1 % of 2.4e-15, did not converge on such a channel and stopped a
    121-recording diagnose-check at its 13th (``plansim diagnose-check jjf2003 --null 1 --per-effect 30 --sizes 5
    --effects clock_fast,noise_burst,scale_change,segment_offset --seed 701``). Here, 1e-12 above the half-code, it
    returned σ = 2.2e-13, a 'noise' of round-off; a scatter within ROUND_OFF of a step now reads as none (σ = 0:
    not dithered, not tested, as a channel on one code at rest)."""
    q, rate = 0.07661445312499993, -math.radians(100.0)
    n = 3000
    smooth = 128.5 * q + 1e-12 + 4e-15 * np.sin(rate * np.arange(n) / FS)
    assert turning_noise_before_quantiser(smooth, q, 2.4e-15, rate, FS) == 0.0
    # a scatter above round-off is still matched: at the half-code a noise of 0.3 % of a step already splits the
    # samples between two codes and gives a scatter of 0.3 q
    assert 0.0 < turning_noise_before_quantiser(smooth, q, 0.3 * q, rate, FS) < 0.01 * q


def test_coarsely_quantised_turning_segments_are_tested_through_the_quantiser():
    """A turning segment whose signal sweeps the codes of a quantiser at 0.5 step of noise (jjf2003's 12-bit gyros):
    its null goes through the quantiser about the segment's own smooth signal. 40 recordings at α = 0.2: flagged
    at most the binomial 99 % bound (13 of 40; a true rate of 0.4 fails it 90 % of the time — white noise at the
    observed scatter, the former null, ran at 0.18–0.24 for α = 0.05 there). A burst of 4 q inside the turn is
    found."""
    q, sigma = 1.0, 0.5
    count, alpha, flagged = 40, 0.2, 0
    for i in range(count):
        segments, samples, _ = _coarse_turning_recording(np.random.default_rng(200 + i), q, sigma)
        result = within_segment_tests(samples, segments, noise(white=sigma / math.sqrt(FS), q=q), alpha=alpha,
                                      draws=99, seed=i)
        assert 3 in result.segments and np.any(np.isfinite(result.statistic[:, :, 3]))
        flagged += result.any_flagged
    assert flagged <= binom.ppf(0.99, count, alpha)
    segments, samples, _ = _coarse_turning_recording(np.random.default_rng(7), q, sigma)
    x = samples[3][:, 0] + 4.0 * q * np.round(np.random.default_rng(8).standard_normal(1000)) * (
        (np.arange(1000) >= 400) & (np.arange(1000) < 500))
    samples[3][:, 0] = x
    burst = within_segment_tests(samples, segments, noise(white=sigma / math.sqrt(FS), q=q), draws=99, seed=3)
    assert (3, "burst", "gx") in {(f["segment"], f["test"], f["channel"]) for f in burst.flagged}


def test_undithered_channels_are_not_tested():
    segments = static_segments(3)
    samples = white_samples(segments, np.random.default_rng(8))
    coarse = noise(q=20 * SIGMA)  # the noise far below one step
    quantised = [20 * SIGMA * np.round(x / (20 * SIGMA) + 0.3) for x in samples]
    assert np.all(np.isnan(within_segment_tests(quantised, segments, coarse, draws=49).statistic))


def test_bad_arguments_are_refused():
    segments = static_segments(2)
    samples = white_samples(segments, np.random.default_rng(9))
    with pytest.raises(ValueError, match="alpha"):
        within_segment_tests(samples, segments, noise(), alpha=1.5)
    with pytest.raises(ValueError, match="draws"):
        within_segment_tests(samples, segments, noise(), draws=5)
