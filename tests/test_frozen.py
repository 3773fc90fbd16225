"""Frozen channels (plansim.estimate.frozen, step 4c of the import's detector, docs/measured-data.md).

A channel that repeats one value for longer than its noise at rest allows is found, cut out of the pose it falls
in and named by the import (warning ``frozen``); a turn across a frozen gyro is a move. The false alarms: none on
noise at rest of five kinds, on quantised hand sessions from 0.7 to 3 steps of noise, on logs written at two and
three times their sensor's rate, and on the shared real session. The rule's level (FROZEN_FALSE_ALARM = 1e-6
runs per channel) would give about 5e-4 false stretches over the 480 channels tested here; one would fail the test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from plansim.estimate.frozen import FROZEN_PRIOR_RATE, equal_runs, frozen_runs, repeated_rows, run_rate
from plansim.estimate.segmentation import resolution, segment_log
from plansim.io.log_import import import_log

FS = 100.0
REAL = Path(__file__).resolve().parents[2] / "shared/data/real/imucal-ferraris"
NOISE = np.array([math.radians(0.2)] * 3 + [0.01] * 3)


def quantised_rest(seconds: float, rng: np.random.Generator, steps: float = 2.0) -> np.ndarray:
    """(N, 6) samples at rest (+z up), white noise of *steps* quantisation steps on every channel."""
    n = int(seconds * FS)
    x = rng.standard_normal((n, 6)) * NOISE + np.r_[math.radians(0.3), -math.radians(0.1), 0.0, 0.05, -0.02, 9.81]
    step = NOISE / steps
    return np.round(x / step) * step


def turn_log(rng: np.random.Generator) -> np.ndarray:
    """6 s at rest, a quarter turn about z (up) by hand in 3 s, 6 s at rest; quantised."""
    turning = quantised_rest(3.0, rng)
    profile = np.sin(np.pi * np.arange(turning.shape[0]) / turning.shape[0]) ** 2  # integrates to 1.5 s
    turning[:, 2] += math.radians(60.0) * profile
    step = NOISE[2] / 2.0
    turning[:, 2] = np.round(turning[:, 2] / step) * step
    return np.concatenate([quantised_rest(6.0, rng), turning, quantised_rest(6.0, rng)])


def test_run_rate_is_the_chance_a_run_goes_on_per_sample_also_in_a_log_written_faster_than_its_sensor():
    """White noise of 0.8 steps on a quantiser, centred on a code: long runs are runs of that code, so the rate is
    the chance that a sample on it is followed by another, P(|z| < 0.625) = 0.468 (0.334 averaged over the codes,
    which the tail must not take). Measured over 60 000 samples, within 0.04: it reads 0.44, a little low, as
    its top quantiles still hold runs of other codes (the rule's level, 1e-6 runs per channel, leaves room for
    that: a rate 0.03 low shortens a frozen run by one or two samples). Each value written twice (three times): the
    median run is 2 (3) and the rate per row the square (cube) root, 0.65 for 0.69 (0.75 for 0.78)."""
    rng = np.random.default_rng(1)
    x = np.round(rng.standard_normal(60000) * 0.8)
    stay = float(np.mean(x[1:][x[:-1] == 0] == 0))
    assert stay == pytest.approx(0.468, abs=0.01) and float(np.mean(np.diff(x) == 0)) == pytest.approx(0.334, abs=0.01)
    lengths = np.array([b - a for a, b in equal_runs(x)])
    rate, base, _ = run_rate(lengths)
    assert base == 2 and rate == pytest.approx(stay, abs=0.04)
    for m in (2, 3):
        held = np.repeat(x, m)
        rate, base, _ = run_rate(np.array([b - a for a, b in equal_runs(held)]))
        assert base == m and rate == pytest.approx(stay ** (1.0 / m), abs=0.04)
    assert run_rate(np.array([2, 2, 3]))[0] == FROZEN_PRIOR_RATE  # too few runs to measure it


def test_a_frozen_channel_in_a_pose_is_cut_out_and_a_frozen_gyro_in_a_turn_makes_it_a_move():
    rng = np.random.default_rng(4)
    x = turn_log(rng)
    clean = segment_log(x, None, FS)
    assert clean.frozen == ()
    assert [s.kind for s in clean.spans] == ["static", "rotation", "static"]
    # ay holds its value for 1 s inside the first pose
    frozen = x.copy()
    frozen[200:300, 4] = frozen[199, 4]
    result = segment_log(frozen, None, FS)
    assert len(result.frozen) == 1
    f = result.frozen[0]
    assert f.channel == 4 and f.start <= 199 and f.stop == 300 and f.value == frozen[199, 4]
    statics = result.of_kind("static")
    assert not any(s.start < f.stop and f.start < s.stop for s in statics)
    cut = [s for s in result.spans if s.start < f.stop and f.start < s.stop]
    assert [s.kind for s in cut] == ["move"] and "frozen" in cut[0].reason
    assert [s.kind for s in result.spans].count("rotation") == 1  # the turn is as it was
    # gz holds its value for 0.3 s a third of the way into the turn (not at its peak: a run at a channel's largest
    # value is a rail's, step 10): its integral is not known
    turning = clean.spans[1]
    at = turning.start + (turning.stop - turning.start) // 3
    frozen = x.copy()
    frozen[at:at + 30, 2] = frozen[at, 2]
    result = segment_log(frozen, None, FS)
    assert [(f.channel, f.start, f.stop) for f in result.frozen] == [(2, at, at + 30)]
    assert [s.kind for s in result.spans] == ["static", "move", "static"]
    assert "gyro frozen" in result.spans[1].reason and np.all(np.isnan(result.spans[1].integrated))


@pytest.mark.parametrize("steps", [1.0, 2.0, 4.0])
def test_no_frozen_stretch_in_quantised_noise_at_rest_nor_in_a_log_written_faster_than_its_sensor(steps):
    rng = np.random.default_rng(int(steps * 10))
    for _ in range(4):
        x = turn_log(rng) if steps == 2.0 else quantised_rest(60.0, rng, steps)
        for m in (1, 2, 3):
            held = np.repeat(x, m, axis=0)
            assert segment_log(held, None, FS * m).frozen == (), (steps, m)
    # and a stretch frozen for 1 s is still found in the log held twice
    held = np.repeat(x, 2, axis=0)
    held[1000:1200, 3] = held[999, 3]
    found = segment_log(held, None, 2 * FS).frozen
    assert [f.channel for f in found] == [3] and found[0].start <= 998 and 1200 <= found[0].stop <= 1204


@pytest.mark.parametrize("ratio", [0.7, 1.0, 1.5, 3.0])
def test_no_frozen_stretch_in_quantised_hand_sessions(ratio):
    """Simulated consumer-unit hand sessions (24 poses, moves by hand), quantised to 0.7–3 steps of noise."""
    from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

    for seed in range(4):
        s = hand_session(consumer_unit(seed), spread_poses(24, seed=seed), sample_rate=FS, seed=seed,
                         gyro_noise=1.2e-3, accel_noise=1.4e-2, gyro_step=1.2e-3 / ratio, accel_step=1.4e-2 / ratio,
                         tremor=(1e-2, 5.0) if seed % 2 else (0.0, 0.0))
        result = segment_log(s.samples, s.time, FS)
        assert result.frozen == (), (ratio, seed)
        assert repeated_rows(s.samples, [(p.start, p.stop) for p in result.of_kind("static")]) is None, (ratio, seed)


def test_a_channel_that_sits_on_one_code_at_rest_is_not_tested():
    """Noise of a third of a step: the channel holds one code for most of a rest; long runs are what it does."""
    rng = np.random.default_rng(7)
    x = quantised_rest(60.0, rng, steps=1.0 / 3.0)
    rests = [(0, x.shape[0])]
    assert frozen_runs(x, rests, resolution(x)) == []
    codes, counts = np.unique(x[:, 2], return_counts=True)
    assert counts.max() > 0.8 * x.shape[0]  # gz, centred on a code, sits on it


def test_the_real_session_has_none_and_a_frozen_accelerometer_in_it_is_named_by_the_import(tmp_path):
    log = REAL / "example_ferraris_session.csv"
    if not log.is_file():
        pytest.skip(f"the shared real data example_ferraris_session.csv is not beside the repository ({REAL})")
    columns = ("gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z")
    clean = import_log(log, columns=columns, units="deg/s,m/s^2", sample_rate=102.4)
    assert clean.segmentation.frozen == () and clean.warnings == ()
    lines = log.read_text().splitlines()
    rows = [line.split(",") for line in lines[1:]]
    for row in rows[600:800]:  # acc_y holds sample 599's value for 2 s, in the first pose (+x up)
        row[5] = rows[599][5]
    bad = tmp_path / "frozen.csv"
    bad.write_text("\n".join([lines[0]] + [",".join(row) for row in rows]) + "\n")
    result = import_log(bad, columns=columns, units="deg/s,m/s^2", sample_rate=102.4)
    assert [w.name for w in result.warnings] == ["frozen"]
    assert "ay (acc_y)" in result.warnings[0].message and "lines 601-801 (201 samples)" in result.warnings[0].message
    # no static segment of the recording holds a frozen sample
    start = 0
    for segment in result.recording.schedule.segments:
        if segment.test == "static":
            assert start + segment.samples <= 599 or start >= 800, segment.label
        start += segment.samples
    assert len(result.segmentation.of_kind("static")) == len(clean.segmentation.of_kind("static")) + 1


def test_rows_that_repeat_the_row_before_are_counted_against_chance(tmp_path):
    """The Ferraris session: no row repeats the one before in all six channels (chance gives 0.7 over its 10 376
    rows). With 30 rows copied from the row before (a link repeating its last packet), or written at twice its rate
    (every row twice), the import warns `repeated_rows`, with the count and what chance gives; a few copies
    (chance's Poisson tail above 1e-6) are not reported."""
    log = REAL / "example_ferraris_session.csv"
    if not log.is_file():
        pytest.skip(f"the shared real data example_ferraris_session.csv is not beside the repository ({REAL})")
    columns = ("gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z")
    lines = log.read_text().splitlines()
    rows = lines[1:]
    rng = np.random.default_rng(2)
    copied = sorted(rng.choice(np.arange(1, len(rows)), 30, replace=False).tolist())
    bad = list(rows)
    for k in copied:
        bad[k] = ",".join([rows[k].split(",")[0]] + rows[k - 1].split(",")[1:])
    path = tmp_path / "copies.csv"
    path.write_text("\n".join([lines[0]] + bad) + "\n")
    result = import_log(path, columns=columns, units="deg/s,m/s^2", sample_rate=102.4)
    (warning,) = [w for w in result.warnings if w.name == "repeated_rows"]
    assert warning.message.startswith("30 row(s) (0.29 % of the log) repeat the row before in all six channels, "
                                      "where chance gives 0.")
    assert f"on line(s) {copied[0] + 2}, " in warning.message
    twice = tmp_path / "twice.csv"
    doubled = [",".join([str(i)] + row.split(",")[1:]) for i, row in enumerate(r for r in rows for _ in range(2))]
    twice.write_text("\n".join([lines[0]] + doubled) + "\n")
    result = import_log(twice, columns=columns, units="deg/s,m/s^2", sample_rate=204.8)
    assert [w.message.split(" row(s)")[0] for w in result.warnings if w.name == "repeated_rows"] == ["10376"]
    x = np.loadtxt(log, delimiter=",", skiprows=1)[:, 1:]
    few = x.copy()
    few[[1000, 4000, 7000]] = few[[999, 3999, 6999]]
    assert repeated_rows(few, [(0, few.shape[0])]) is None
