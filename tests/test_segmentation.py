"""The rest detector of plansim.estimate.segmentation: its pieces, and its false alarms on static noise.

The false-alarm test is the calibration the module's thresholds rest on (docs/measured-data.md): logs at
rest with noise of several kinds — white Gaussian, heavy-tailed (Student t, 3 degrees of freedom),
quantised to about its own size, low-pass filtered (correlated), and with the gyro bias drifting — must
come out as one static span, at the default window.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from plansim.estimate.segmentation import (
    DEFAULT_WINDOW,
    moving_mean_variance,
    nearest_axis,
    resolution,
    segment_log,
)
from plansim.estimate.timebase import analyse_time

FS = 100.0
GRAVITY = np.array([0.0, 0.0, 9.81])


def static_noise(kind: str, seconds: float, rng: np.random.Generator) -> np.ndarray:
    """(N, 6) samples of a unit at rest (+z up): gyro noise 0.2 deg/s, accelerometer 0.01 m/s^2 per sample."""
    n = int(seconds * FS)
    scale = np.array([math.radians(0.2)] * 3 + [0.01] * 3)
    e = rng.standard_normal((n, 6))
    if kind == "student_t3":
        e = rng.standard_t(3, (n, 6)) / math.sqrt(3.0)  # unit variance, heavy tails
    elif kind == "low_pass":
        rho = 0.8  # correlation time ~ 4.5 samples
        e = lfilter([1.0 - rho], [1.0, -rho], e, axis=0) / math.sqrt((1.0 - rho) / (1.0 + rho))
    x = e * scale + np.r_[math.radians(0.3), -math.radians(0.1), 0.0, 0.05, -0.02, 9.81]
    if kind == "quantised":  # one step = 3 sigma: most samples sit on one level
        step = 3.0 * scale
        x = np.round(x / step) * step
    elif kind == "drifting":  # the gyro bias wanders by ~2 sigma over the log
        walk = np.cumsum(rng.standard_normal((n, 3)), axis=0) / math.sqrt(n)
        x[:, :3] += 2.0 * scale[:3] * walk
    return x


@pytest.mark.parametrize("kind", ["white", "student_t3", "low_pass", "quantised", "drifting"])
def test_a_log_at_rest_is_one_static_span(kind):
    rng = np.random.default_rng(["white", "student_t3", "low_pass", "quantised", "drifting"].index(kind))
    for _ in range(3):
        x = static_noise(kind, 200.0, rng)
        result = segment_log(x, None, FS)
        assert [(s.kind, s.start, s.stop) for s in result.spans] == [("static", 0, x.shape[0])], kind
        assert result.frozen == (), kind  # step 4c: no chance repeat taken for a frozen channel
        assert result.spans[0].up == "+z" and result.spans[0].orientation == "approximate"


def test_noise_floor_measures_the_noise():
    rng = np.random.default_rng(3)
    x = static_noise("white", 60.0, rng)
    result = segment_log(x, None, FS)
    sigma = result.noise.sigma
    np.testing.assert_allclose(sigma[:3], math.radians(0.2), rtol=0.15)
    np.testing.assert_allclose(sigma[3:], 0.01, rtol=0.15)
    w = result.window
    assert w == round(DEFAULT_WINDOW * FS)
    np.testing.assert_allclose(result.noise.window_sigma, math.radians(0.2) / math.sqrt(w), rtol=0.5)


def test_quantised_noise_is_not_zero():
    rng = np.random.default_rng(4)
    x = static_noise("quantised", 60.0, rng)
    result = segment_log(x, None, FS)
    # the MAD of such a channel is 0; the variance-based estimate is near the true standard deviation
    assert np.all(result.noise.sigma[3:] > 0.005)
    np.testing.assert_allclose(result.noise.resolution[3:], 0.03, rtol=1e-9)


def test_moving_statistics_match_a_direct_computation():
    rng = np.random.default_rng(5)
    x = rng.normal(size=(40, 2)) + 1000.0
    mean, var = moving_mean_variance(x, 7)
    for t in range(40):
        window = x[max(0, t - 3):min(40, t + 4)]
        np.testing.assert_allclose(mean[t], window.mean(axis=0), rtol=0, atol=1e-9)
        np.testing.assert_allclose(var[t], window.var(axis=0), rtol=1e-7, atol=1e-9)
    assert resolution(np.array([[0.0], [0.5], [0.5], [1.5]]))[0] == 0.5


def test_nearest_axis_and_tilt():
    up, tilt = nearest_axis(np.array([0.3, -9.7, 0.1]))
    assert up == "-y" and tilt == pytest.approx(math.atan(math.hypot(0.3, 0.1) / 9.7))


def test_time_analysis_finds_gaps_jitter_and_repeats():
    rng = np.random.default_rng(6)
    t = np.arange(1000) / 100.0 + rng.uniform(-1e-4, 1e-4, 1000)
    t[500:] += 0.05  # 5 samples' worth of time missing before sample 500
    report = analyse_time(t, 1000)
    assert report.sample_rate == pytest.approx(100.0, rel=1e-3)
    assert [k for k, _ in report.gaps] == [500] and report.missing_samples == 5
    assert report.jitter_rms < 2e-4 and report.jitter_max < 3e-4
    t2 = t.copy()
    t2[10] = t2[9]
    assert analyse_time(t2, 1000).repeated == 1
    with pytest.raises(ValueError, match="time decreases at sample 11"):
        t3 = t.copy()
        t3[11] = t3[10] - 1.0
        analyse_time(t3, 1000)
    with pytest.raises(ValueError, match="needs the sample rate"):
        analyse_time(None, 1000)


def test_a_clock_coarser_than_the_sampling_and_a_misstamped_sample():
    """A 100 Hz log whose clock is rounded to 20 ms (steps of 0 and 20 ms) or to whole seconds: the rate is the
    samples over the span, not 1 / the median step (50 Hz, 1 Hz), and its 20 ms or 1 s steps are no gaps; one sample
    stamped with its predecessor's time (a step of 0, then one of 20 ms) is no gap either. A real gap still is."""
    t = np.arange(38000) / 100.0
    rounded = np.round(t / 0.02) * 0.02
    report = analyse_time(rounded, t.size)
    assert report.sample_rate == pytest.approx(100.0, rel=1e-3) and report.gaps == () and report.repeated > 18000
    seconds = np.floor(t)
    report = analyse_time(seconds, t.size)
    assert report.sample_rate == pytest.approx(100.0, rel=5e-3) and report.gaps == ()
    glitch = t[:1000].copy()
    glitch[300] = glitch[299]
    report = analyse_time(glitch, 1000)
    assert report.gaps == () and report.missing_samples == 0 and report.repeated == 1
    glitch[600:] += 0.5
    assert [k for k, _ in analyse_time(glitch, 1000).gaps] == [600]


def test_delivery_stamps_are_not_read_as_dropped_samples_and_a_real_gap_still_is():
    """A clock that jitters by 30 % of the period (0.3 ms RMS per stamp at 1 kHz, a host's stamps) passes 1.5 periods
    in 11 % of its steps: read as a sampling clock, each was a dropped sample (2264 of them), and the rate, taken
    over the other steps, came out 10 % high (1097.8 Hz). The steps are no whole number of the usual one, so they
    are read as delivery times (DELIVERY_FRACTION): no sample dropped, the rate the mean one, the samples' times the
    clock's to the jitter. A real gap of 0.5 s (500 samples) is still found, with its count, and the stretch after
    it is placed on its own stamps."""
    rng = np.random.default_rng(8)
    true = np.arange(20000) / 1000.0
    true[12000:] += 0.5
    stamps = np.sort(true + rng.normal(0.0, 0.3e-3, true.size))
    report = analyse_time(stamps, true.size)
    assert report.delivery and report.dropped == ()
    assert [k for k, _ in report.gaps] == [12000] and report.missing_samples == 500
    assert report.sample_rate == pytest.approx(1000.0, rel=1e-4)
    assert np.max(np.abs(report.sample_times - true)) < 1e-4
    # the same clock jittering by 1 % of the period is a sampling clock: its stamps are the samples' times
    steady = true + rng.normal(0.0, 0.01e-3, true.size)
    report = analyse_time(steady, true.size)
    assert not report.delivery and report.sample_times is None and [k for k, _ in report.gaps] == [12000]


def test_delivery_stamps_of_a_host_that_starts_late_and_drains_a_buffer_stay_in_time_order():
    """Found on a real MPU-6050 log (github.com/sunsided/sensor-fusion, 100 Hz read through a host that stamps each
    row as it arrives, 1-3 ms apart within a read): its first 12 rows were stamped at once, the next 18 at once
    0.25 s later, then one read every 10-55 ms. Read as breaks, the two first reads were each placed on their own
    stamps' mean, and the second overlapped the rest of the log ("time decreases at sample 30" in a log whose time
    never decreases). Over those steps the placed clocks miss no sample: the host read late a buffer the sensor had
    filled since before the log's start, and the stretches are one. Simulated the same way: no gap, the samples'
    times strictly increasing, the rate within 0.1 % and every time within 0.5 s of the truth. A real gap of 2 s
    (200 samples missing) is still found."""
    rng = np.random.default_rng(12)
    n = 6000
    true = (np.arange(n) - 30) / 100.0 + 0.07  # 30 rows buffered before the log started

    def reads(rows_at, first):
        stamps, k, now = np.empty(n), first, float(true[first])
        while k < n:
            now += rng.uniform(0.010, 0.055)
            ready = int(np.searchsorted(true, now, side="right"))
            if ready <= k:
                continue
            stamps[k:ready] = now + np.cumsum(rng.uniform(1e-3, 3e-3, ready - k))
            k = ready
        stamps[:first] = rows_at
        return stamps

    early = np.concatenate([0.008 + np.cumsum(rng.uniform(1e-3, 3e-3, 12)),
                            0.26 + np.cumsum(rng.uniform(1e-3, 3e-3, 18))])
    stamps = np.maximum.accumulate(reads(early, 30))
    report = analyse_time(stamps, n)
    assert report.delivery and report.gaps == () and report.missing_samples == 0
    assert np.all(np.diff(report.sample_times) > 0)
    assert report.sample_rate == pytest.approx(100.0, rel=1e-3)
    assert np.max(np.abs(report.sample_times - true)) < 0.5
    later = stamps.copy()
    first = int(np.flatnonzero(np.diff(stamps) > 0.008)[200]) + 1  # the first row of a read
    later[first:] += 2.0
    report = analyse_time(later, n)
    assert [k for k, _ in report.gaps] == [first] and np.all(np.diff(report.sample_times) > 0)
    assert abs(report.missing_samples - 200) <= 10


def test_a_steady_turn_between_two_rests_is_a_rotation_with_its_rate_and_no_angle():
    """A table holding -90 deg/s for 4 s about z (up): its steady part is a rotation with its measured rate and no
    angle (step 9: the table's rate is the reference), the few samples where the windows straddle the rest and the
    turn are moves, and the three pieces' integrals add up to the whole turn."""
    rng = np.random.default_rng(7)
    rest = static_noise("white", 5.0, rng)
    rate = math.radians(-90.0)  # -360 deg in 4 s about z, which points up
    turning = static_noise("white", 4.0, rng)
    turning[:, 2] += rate
    x = np.vstack([rest, turning, static_noise("white", 5.0, rng)])
    result = segment_log(x, None, FS)
    assert [s.kind for s in result.spans] == ["static", "move", "rotation", "move", "static"]
    rotation = result.spans[2]
    assert rotation.axis == 2 and math.isnan(rotation.angle) and rotation.orientation == "approximate"
    assert math.degrees(rotation.steady_rate) == pytest.approx(-90.0, abs=0.05)
    assert result.steady_turns == ((rotation.start, rotation.stop),)
    assert all("steady turn" in s.reason for s in (result.spans[1], result.spans[3]))
    whole = sum(float(s.integrated[2]) for s in result.spans[1:4])
    assert math.degrees(whole) == pytest.approx(-360.0, abs=0.5)


def _table_turn(rng, up_seconds: float, steady_seconds: float, rate_deg_s: float, then: float | None = None
                ) -> np.ndarray:
    """A table's turn about z (up): a linear spin-up over *up_seconds*, *steady_seconds* at the rate (and as long at
    *then*, reached by a ramp as long), the same stop; the table's rate jitters by half the gyro's noise (a steady
    turn as quiet as a rest could be taken for the quiet stretch, which step 3 takes to be at rest)."""
    ramp = np.linspace(0.0, 1.0, int(up_seconds * FS), endpoint=False)
    level = np.ones(int(steady_seconds * FS))
    profile = np.concatenate([ramp, level])
    if then is not None:
        profile = np.concatenate([profile, 1.0 + (then / rate_deg_s - 1.0) * ramp, then / rate_deg_s * level])
    profile = np.concatenate([profile, profile[-1] * ramp[::-1]])
    turning = static_noise("white", profile.size / FS, rng)
    jitter = np.r_[False, np.diff(profile) == 0.0] & (profile > 0.0)  # where the table holds a rate
    turning[:, 2] += math.radians(rate_deg_s) * profile + jitter * math.radians(0.1) * rng.standard_normal(profile.size)
    return turning


def test_a_table_turn_is_not_labelled_with_the_nearest_quarter_turn():
    """A table's -567 deg turn (1.5 s spin-up, 7.5 s at -63 deg/s, 1.5 s stop) is within 10 deg + 5 % of -540 deg,
    the label it had, and a fit that took it read chi2/dof in the thousands (an independent simulator's rate test).
    Now its steady part is a rotation with the table's rate to give, and the spin-up and stop are moves; so is a
    turn too long for its quarter turn to be told (830 deg), and a turn with two steady rates is two rotations."""
    rng = np.random.default_rng(8)
    for turn, rates in ((_table_turn(rng, 1.5, 7.5, -63.0), [-63.0]), (_table_turn(rng, 1.0, 7.8, 100.0), [100.0]),
                        (_table_turn(rng, 1.0, 5.0, 20.0, then=50.0), [20.0, 50.0])):
        x = np.vstack([static_noise("white", 20.0, rng), turn, static_noise("white", 20.0, rng)])
        result = segment_log(x, None, FS)
        kinds = [s.kind for s in result.spans]
        assert kinds == ["static"] + ["move", "rotation"] * len(rates) + ["move", "static"]
        rotations = result.of_kind("rotation")
        assert [math.degrees(r.steady_rate) for r in rotations] == pytest.approx(rates, abs=0.05)
        assert all(math.isnan(r.angle) for r in rotations)
        whole = sum(float(s.integrated[2]) for s in result.spans[1:-1])
        assert whole == pytest.approx(float(np.sum(turn[:, 2]) / FS), abs=math.radians(0.5))


def test_a_rate_held_longer_than_all_the_rests_is_not_taken_for_the_rest():
    """A minute at +100 °/s and a minute at −100 °/s between three 10 s rests: the turn at one rate holds more of the
    log than the rests together, the run the most quiet samples agree with was the +100 °/s turn, and the log read as
    one static span between two moves (every rest turning at −100 °/s). A log starts and stops at rest: its first and
    last runs agree, and the rest is chosen among the runs that agree with them."""
    for seed in (1, 2):
        rng = np.random.default_rng(seed)
        x = np.vstack([static_noise("white", 10.0, rng), _table_turn(rng, 1.0, 60.0, 100.0),
                       static_noise("white", 10.0, rng), _table_turn(rng, 1.0, 60.0, -100.0),
                       static_noise("white", 10.0, rng)])
        result = segment_log(x, None, FS)
        assert [s.kind for s in result.spans] == ["static", "move", "rotation", "move"] * 2 + ["static"]
        assert [math.degrees(r.steady_rate) for r in result.of_kind("rotation")] == pytest.approx([100.0, -100.0],
                                                                                                   abs=0.05)


def _tip_about_y(rng, seconds: float, start_deg: float, end_deg: float) -> np.ndarray:
    """A unit tipped about its y axis from *start_deg* to *end_deg* (0: +z up, 90: -x up) at a constant rate: the
    gyro y reads the rate, the accelerometers g(-sin θ, 0, cos θ), with :func:`static_noise`'s noise and bias."""
    x = static_noise("white", seconds, rng)
    theta = np.radians(np.linspace(start_deg, end_deg, x.shape[0]))
    x[:, 1] += math.radians(end_deg - start_deg) / seconds
    x[:, 3] += -9.81 * np.sin(theta)
    x[:, 5] += 9.81 * np.cos(theta) - 9.81
    return x


def _at_pose(x: np.ndarray, degrees: float) -> np.ndarray:
    """:func:`static_noise` samples (+z up) moved to the pose *degrees* about y (as :func:`_tip_about_y`)."""
    x = x.copy()
    theta = math.radians(degrees)
    x[:, 3] += -9.81 * math.sin(theta)
    x[:, 5] += 9.81 * math.cos(theta) - 9.81
    return x


def test_a_log_that_starts_and_ends_in_the_same_steady_turn_is_read_from_its_rests_in_two_poses():
    """A table's steady turn of +30 deg/s about z (up) for a minute at each end of the log, and between them 20 s
    rests +z up, -x up (the unit tipped about y) and +z up again. The turns hold more of the log than the rests and
    the log's two ends agree with each other, so the rule 'a log starts and ends at rest' took the turn for the rest
    and every rest for a turn (the previous version: one static span, the bias 30 deg/s off). The rests agree with
    each other across the two poses, a turn about the vertical with no run in another pose (step 6, 'Poses'):
    the three rests are static, with their poses, and the gyro bias is the rests'. The two turns, with a pose on one
    side only, are rotations with their measured rates (they were moves 'not integrated')."""
    for seed in (1, 2):
        rng = np.random.default_rng(seed)
        turn = _table_turn(rng, 1.0, 60.0, 30.0)
        n_up = int(1.0 * FS)
        x = np.vstack([turn[n_up:], static_noise("white", 20.0, rng), _tip_about_y(rng, 2.0, 0.0, 90.0),
                       _at_pose(static_noise("white", 20.0, rng), 90.0), _tip_about_y(rng, 2.0, 90.0, 0.0),
                       static_noise("white", 20.0, rng), _table_turn(rng, 1.0, 60.0, 30.0)[:-n_up]])
        result = segment_log(x, None, FS)
        statics = result.of_kind("static")
        assert [s.up for s in statics] == ["+z", "-x", "+z"], [(s.kind, s.start, s.stop) for s in result.spans]
        assert all(s.stop - s.start >= 18.0 * FS for s in statics)
        # the bias from a quiet stretch of 400 samples or more (8 windows): 0.01 deg/s standard error; 5 of them
        assert np.degrees(result.noise.gyro_bias) == pytest.approx([0.3, -0.1, 0.0], abs=0.05)
        # the steady turns the log starts and ends in are rotations with their rates (step 9), measured against the
        # pose beside each (6000 samples of 0.2 deg/s noise and 0.1 deg/s jitter, a 20 s rest: 0.006 deg/s; 5 of
        # them), and the stop and spin-up between them and the rests are moves
        assert [s.kind for s in result.spans] == ["rotation", "move", "static", "move", "static", "move", "static",
                                                  "move", "rotation"]
        ends = (result.spans[0], result.spans[-1])
        assert [math.degrees(r.steady_rate) for r in ends] == pytest.approx([30.0, 30.0], abs=0.03)
        assert all(math.isnan(r.angle) and r.axis == 2 for r in ends)
        assert result.steady_turns[0][0] == 0 and result.steady_turns[-1][1] == x.shape[0]


def test_a_step_in_a_gyro_bias_does_not_make_the_poses_after_it_turns():
    """Rests +z up, -x up, +z up, -x up, +z up (20 s each, tipped about y), one gyro's bias stepping by 0.5 deg/s
    (25 times its rest threshold) in the middle rest. A run is compared with the nearest rest (step 6): against
    the rest in its pose before the step, the poses after it read as turns or not by the order the runs were
    visited in (a log of the shared real session with such a step lost its last three poses that way)."""
    rng = np.random.default_rng(3)
    pieces = []
    for k, pose in enumerate((0.0, 90.0, 0.0, 90.0, 0.0)):
        if k:
            pieces.append(_tip_about_y(rng, 2.0, 90.0 - pose, pose))
        pieces.append(_at_pose(static_noise("white", 20.0, rng), pose))
    x = np.vstack(pieces)
    x[x.shape[0] // 2:, 0] += math.radians(0.5)
    result = segment_log(x, None, FS)
    statics = result.of_kind("static")
    assert [s.up for s in statics] == ["+z", "-x", "+z", "-x", "+z"], [(s.kind, s.start, s.stop) for s in result.spans]
    assert all(s.stop - s.start >= 18.0 * FS for s in statics) and not result.steady_turns


def test_a_table_rate_of_the_wrong_length_is_refused():
    x = static_noise("white", 20.0, np.random.default_rng(1))
    with pytest.raises(ValueError, match=r"table_rate: shape \(5,\); expected \(2000,\)"):
        segment_log(x, None, FS, table_rate=np.zeros(5))
    with pytest.raises(ValueError, match="table_rate"):
        segment_log(x, None, FS, table_rate=np.full(x.shape[0], np.nan))
    with pytest.raises(ValueError, match=r"table_angle: shape \(5,\); expected \(2000,\)"):
        segment_log(x, None, FS, table_angle=np.zeros(5))
    with pytest.raises(ValueError, match="table_angle"):
        segment_log(x, None, FS, table_angle=np.full(x.shape[0], np.inf))


def test_a_turn_too_long_for_its_quarter_turn_to_be_told_is_a_move():
    """A turn of 830 deg that holds no steady rate: 10 deg + 5 % of it passes half a quarter turn, so the nearest
    whole number of quarter turns (810 deg) is no reference; it is a move, saying why (an independent simulator's
    5891 deg turn had been labelled 5850 deg, and the fit read chi2/dof 3e5). A full turn is still a rotation
    (test_a_turn_by_hand_is_labelled_with_its_quarter_turns)."""
    rng = np.random.default_rng(8)
    turning = static_noise("white", 8.3, rng)
    t = np.arange(turning.shape[0]) / FS
    turning[:, 2] += math.radians(100.0) * (1.0 + 0.5 * np.sin(2.0 * math.pi * t / 0.83))  # never steady
    x = np.vstack([static_noise("white", 20.0, rng), turning, static_noise("white", 20.0, rng)])
    result = segment_log(x, None, FS)
    assert [s.kind for s in result.spans] == ["static", "move", "static"] and not result.steady_turns
    assert "too far for the nearest whole number of quarter turns" in result.spans[1].reason
    assert math.degrees(result.spans[1].integrated[2]) == pytest.approx(830.0, abs=5.0)


def test_a_turn_by_hand_is_labelled_with_its_quarter_turns():
    """A hand turning 360 deg about z (up) in 4 s, never at one rate (its rate swings by half about its mean):
    a rotation labelled -360 deg, with no steady rate."""
    rng = np.random.default_rng(9)
    turning = static_noise("white", 4.0, rng)
    t = np.arange(turning.shape[0]) / FS
    turning[:, 2] += math.radians(-90.0) * (1.0 - np.cos(2.0 * math.pi * t / 4.0))
    x = np.vstack([static_noise("white", 5.0, rng), turning, static_noise("white", 5.0, rng)])
    result = segment_log(x, None, FS)
    assert [s.kind for s in result.spans] == ["static", "rotation", "static"] and not result.steady_turns
    rotation = result.spans[1]
    assert rotation.axis == 2 and rotation.angle == pytest.approx(-2 * math.pi)
    assert math.isnan(rotation.steady_rate) and rotation.orientation == "approximate"
    assert math.degrees(rotation.integrated[2]) == pytest.approx(-360.0, abs=0.5)


def test_no_rest_at_all_is_too_few_static_samples():
    rng = np.random.default_rng(8)
    x = static_noise("white", 30.0, rng)
    # a unit tumbling the whole time: gravity turns about x at 20 deg/s
    angle = np.radians(20.0) * np.arange(x.shape[0]) / FS
    x[:, 0] += math.radians(20.0) + math.radians(5.0) * np.sin(angle * 7)
    x[:, 4] = 9.81 * np.sin(angle)
    x[:, 5] = 9.81 * np.cos(angle)
    with pytest.raises(ValueError, match="too few static samples: no span at rest of at least 1 s"):
        segment_log(x, None, FS)
    with pytest.raises(ValueError, match="too few samples: the log has 50"):
        segment_log(x[:50], None, FS)


# ----------------------------------------------------------------------------- poses of a hand-held session

def _hand(seed: int, **options):
    """A simulated hand session (plansim.simulate.hand_session): 12 poses over the sphere, consumer MEMS noise."""
    from plansim.fit.model import nominal_parameters
    from plansim.model.parameters import PARAMETER_INDEX
    from plansim.simulate.hand_session import hand_session, spread_poses

    theta = nominal_parameters().copy()
    for name, value in options.pop("set", {}).items():
        theta[PARAMETER_INDEX[name]] = value
    return hand_session(theta, spread_poses(12, seed=seed), seed=seed, gyro_noise=8.7e-4, accel_noise=9.8e-3,
                        **options)


def test_rests_in_different_poses_may_differ_by_the_gyros_g_sensitivity():
    """A consumer gyro's g-sensitivity (here 0.15 deg/s/g on each gyro along x, the MPU-6050 data sheet allows 0.1)
    moves its output at rest from pose to pose by more than the rest threshold (6 window-mean sigmas, ~0.05 deg/s):
    every pose is still found, none taken for a turn (step 6 allows for it where no rest shares the pose)."""
    g_sens = math.radians(0.15) / 9.80665
    s = _hand(3, set={"gxx": g_sens, "gyx": g_sens, "gzx": g_sens})
    result = segment_log(s.samples, s.time, 100.0)
    assert len(result.of_kind("static")) == 12 and not result.steady_turns


@pytest.mark.parametrize("sensitivity", [0.3, 1.0])
def test_a_gyro_more_g_sensitive_than_the_allowance_keeps_its_poses_and_a_turn_stays_a_turn(sensitivity):
    """A unit whose gyros are 0.3 or 1 deg/s/g sensitive to g along their own axes (1.5 to 5 times the allowance of
    step 6): its rests in different poses differ along gravity by more than the allowance, and 6 of 12 poses of a
    hand session (at 0.3; 11 of 12 at 1) were read as turns about the vertical. The runs tell the unit's own
    g-sensitivity (step 6a: each gyro's rest output fitted over the runs as bias + drift + G f, each run predicted
    with itself left out): every pose is found. And a table turning at 1 deg/s about the vertical through one pose
    of its own (every sample of that pose) stays a steady turn: left out, its output is 1 deg/s off the fit's along
    its gravity, 20 times the rest threshold."""
    from plansim.io.recording_data import segment_first_samples

    g_sens = math.radians(sensitivity) / 9.80665
    for seed in (3, 4):
        s = _hand(seed, set={"gxx": g_sens, "gyy": g_sens, "gzz": g_sens})
        result = segment_log(s.samples, s.time, 100.0)
        assert len(result.of_kind("static")) == 12 and not result.steady_turns, seed
        k = 5  # the sixth pose turns about the vertical, its whole time
        statics = [i for i, segment in enumerate(s.schedule.segments) if segment.test == "static"]
        first = int(segment_first_samples(s.schedule)[statics[k]])
        count = s.schedule.segments[statics[k]].samples
        turning = s.samples.copy()
        up_in_body = s.orientations[k].T @ np.array([0.0, 0.0, 1.0])
        turning[first:first + count, :3] += math.radians(1.0) * up_in_body
        result = segment_log(turning, s.time, 100.0)
        assert len(result.of_kind("static")) == 11, seed
        assert len(result.steady_turns) == 1
        a, b = result.steady_turns[0]
        assert first <= a and b <= first + count


def test_poses_held_by_a_shaking_hand_are_found_and_flagged():
    """The first pose rests on the bench; in the other eleven a tremor of 0.03 deg at 6 Hz (1.1 deg/s of rate, 20
    times the gyro noise; 5 mg of tilt, half the accelerometer noise) shakes the gyros out of the rest test while
    the accelerometers stay quiet. Every pose is found, the shaking ones by step 6b, each with how hard its gyros
    shook against the bench's; the same poses without the tremor are plain rests. (In a log where every pose
    shakes, the quietest stretch is itself a shaking one: the poses are still found, measured against it.)"""
    amplitudes = np.r_[0.0, np.full(11, math.radians(0.03))]
    shaking = segment_log(*(lambda s: (s.samples, s.time))(_hand(4, tremor=(amplitudes, 6.0))), 100.0)
    still = segment_log(*(lambda s: (s.samples, s.time))(_hand(4)), 100.0)
    assert len(shaking.of_kind("static")) == len(still.of_kind("static")) == 12
    assert not math.isfinite(shaking.of_kind("static")[0].held)
    assert all(math.isfinite(span.held) and span.held > 3 for span in shaking.of_kind("static")[1:])
    assert all(not math.isfinite(span.held) for span in still.of_kind("static"))


def test_a_pose_that_drifts_or_a_slow_turn_is_not_a_held_pose():
    """Held-pose detection must not take motion for a pose: the unit tilting by 1.5 deg over a 'pose' (the
    accelerometers see it), or turning about the vertical at 1 deg/s with the hand shaking (only the gyros see it)."""
    s = _hand(5, tremor=(np.r_[0.0, np.full(11, math.radians(0.03))], 6.0))
    x = s.samples.copy()
    first = np.cumsum([0] + [seg.samples for seg in s.schedule.segments])
    # pose 3 (segment 4): a slow turn about its vertical at 1 deg/s, on the gyros
    a, b = first[4], first[5]
    up = x[a:b, 3:].mean(axis=0)
    x[a:b, :3] += math.radians(1.0) * up / np.linalg.norm(up)
    # pose 5 (segment 8): the specific force turning by 1.5 deg across it
    a, b = first[8], first[9]
    f = x[a:b, 3:].mean(axis=0)
    turn = np.cross(f, [1.0, 0.0, 0.0])
    turn *= math.radians(1.5) / np.linalg.norm(turn)
    ramp = np.linspace(-0.5, 0.5, b - a)[:, None]
    x[a:b, 3:] += ramp * np.cross(turn, f)[None, :]
    spans = segment_log(x, s.time, 100.0).of_kind("static")
    starts = {span.start for span in spans}
    assert len(spans) == 10 and first[4] not in starts and first[8] not in starts


def test_two_equal_samples_at_a_peak_are_not_a_rail_unless_the_value_is_held_twice():
    """Step 10: a fast move's smooth peak falls between two samples, which then read alike (a 16-bit log's
    75.7 deg/s peak, far inside its +-2000 deg/s, was taken for a rail); three equal samples, or two at a value
    reached twice, are a rail."""
    from plansim.estimate.segmentation import SATURATION_RUN, stuck_runs

    peak = np.array([0.0, 5.0, 10.0, 12.0, 12.0, 10.0, 5.0, 0.0])
    assert stuck_runs(peak, 12.0, 1.0) == []
    flat = np.array([0.0, 5.0, 10.0] + [12.0] * SATURATION_RUN + [10.0, 5.0, 0.0])
    assert stuck_runs(flat, 12.0, 1.0) == [(3, 3 + SATURATION_RUN)]
    twice = np.concatenate([peak, peak])
    assert stuck_runs(twice, 12.0, 1.0) == [(3, 5), (11, 13)]
    # entered and left by one step (a slow peak of a quantised channel): never a rail
    assert stuck_runs(np.array([10.0, 11.0, 12.0, 12.0, 12.0, 12.0, 11.0]), 12.0, 1.0) == []


def test_an_isolated_glitch_row_is_cut_out_of_the_poses_not_the_poses_out_of_the_log():
    """A logger's row of six exact zeros (first row, near a pose's end, mid-pose) and a one-channel dropout: each
    is found, no static span holds it, and the poses come out as without it (a pose cut or trimmed around it)."""
    rng = np.random.default_rng(11)
    rest = static_noise("white", 6.0, rng)
    turning = static_noise("white", 3.0, rng)
    turning[:, 2] += math.radians(120.0) * np.sin(np.pi * np.arange(turning.shape[0]) / turning.shape[0]) ** 2
    x = np.concatenate([rest, turning, static_noise("white", 6.0, rng)])
    clean = segment_log(x, None, FS)
    assert clean.glitches == ()
    poses = [(s.start, s.stop) for s in clean.of_kind("static")]
    for row, channels in ((0, slice(0, 6)), (poses[0][1] - 8, slice(0, 6)), (300, slice(0, 6)),
                          (poses[1][0] + 5, slice(5, 6))):
        bad = x.copy()
        bad[row, channels] = 0.0
        result = segment_log(bad, None, FS)
        assert result.glitches == (row,)
        statics = result.of_kind("static")
        assert not any(s.start <= row < s.stop for s in statics)
        # the same poses: pieces of one pose joined back, within a window of the clean extents
        joined = []
        for s in statics:
            if joined and joined[-1][1] == row and s.start == row + 1:
                joined[-1] = (joined[-1][0], s.stop)
            else:
                joined.append((s.start, s.stop))
        assert len(joined) == len(poses)
        for (a, b), (c, d) in zip(joined, poses):
            assert abs(a - c) <= result.window and abs(b - d) <= result.window
        assert all(s.kind != "static" for s in result.spans if s.start <= row < s.stop), row


def test_the_rate_of_a_quantised_jittery_clock_is_its_mean_rate():
    """99.7 Hz, 0.5 ms of jitter, stamps rounded to 0.1 ms: the median step is 10.0 ms (100 Hz); the mean
    period over the steps that are not gaps gives the true rate, and a gap is still found."""
    rng = np.random.default_rng(12)
    n = 6000
    t = np.sort(np.arange(n) / 99.7 + rng.normal(0.0, 5e-4, n))
    t = np.round(t * 1e4) / 1e4
    assert np.median(np.diff(t)) == pytest.approx(0.01)
    report = analyse_time(t, n)
    assert report.sample_rate == pytest.approx(99.7, abs=0.01)
    assert report.gaps == ()
    gapped = np.delete(t, np.arange(3000, 3200))  # 200 samples missing
    report = analyse_time(gapped, gapped.size)
    assert report.sample_rate == pytest.approx(99.7, abs=0.01)
    assert [k for k, _ in report.gaps] == [3000] and report.missing_samples == 200


def test_a_pose_noisier_than_the_quiet_stretch_is_reported_and_sessions_without_one_are_not():
    """Step 11 (found on a real BMI160 tumble whose -x pose had an ay noise 13 times its quiet stretch's, cut by the
    rest detector into a 0.9 s pose and moves, with no word of it): a table log of two poses, the second's ay noise 5
    times the first's, is reported once, with its up axis, the whole of the noisy pose (less a window at each end)
    and a factor that keeps it whole when given as variance_factor. Ten simulated hand sessions of a consumer unit
    (12-31 poses, moves of 3 s) give no report: on 40 such sessions (seeds 0-39, 2026-12-01) none gave one; a
    report rate of 10 % per session would show here with probability 1 - 0.9^10 = 0.65."""
    from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

    rng = np.random.default_rng(21)
    first = static_noise("white", 30.0, rng)
    second = static_noise("white", 30.0, rng)
    second[:, 3:] = second[:, 3:] - np.r_[0.05, -0.02, 9.81] + np.r_[9.81, 0.0, 0.0]  # +x up
    second[:, 4] = 0.05 * rng.standard_normal(second.shape[0])  # ay: 5 times the noise
    phase = np.arange(200) / 200
    turn = static_noise("white", 2.0, rng)
    turn[:, 1] += -math.pi / 2 * FS / 200 * (1 - np.cos(2 * math.pi * phase))  # -90 deg about y: +z up to +x up
    angle = -math.pi / 2 * (phase - np.sin(2 * math.pi * phase) / (2 * math.pi))
    turn[:, 3] += -9.81 * np.sin(angle) - 0.05
    turn[:, 5] += 9.81 * np.cos(angle) - 9.81
    x = np.vstack([first, turn, second])
    result = segment_log(x, None, FS)
    assert [s.up for s in result.of_kind("static")] == ["+z"]
    (noisy,) = result.noisy_poses
    w = result.window
    assert noisy.up == "+x" and 3200 <= noisy.start <= 3200 + 2 * w and x.shape[0] - 2 * w <= noisy.stop
    wider = segment_log(x, None, FS, variance_factor=1.2 * noisy.factor)
    assert [s.up for s in wider.of_kind("static")] == ["+z", "+x"] and wider.noisy_poses == ()
    assert wider.of_kind("static")[1].samples >= 3000 - 2 * w
    for seed in range(10):
        theta, poses = consumer_unit(seed), spread_poses(12 + 2 * seed, seed=seed)
        s = hand_session(theta, poses, seed=seed, gyro_noise=8.7e-4, accel_noise=9.8e-3)
        assert segment_log(s.samples, s.time, FS).noisy_poses == (), seed
