"""plansim import: a plain log to a recording whose segment table is found from the data.

- A log simulated by plansim (the default unit: 12-bit acquisition, Earth rate, its own errors), written
  as a plain CSV with a time column and six columns and NOT told the schedule, comes back with its
  static poses (boundaries within the documented tolerance, the right up axes) and its turns (angle,
  steady rate).
- The shared real data (imucal's Ferraris session, MIT licence; read from beside the repository and
  skipped when absent) imports into the sections its annotation names.
- Bad logs get a ValueError naming the file, line and column, or a named warning; nothing is written.
"""

from __future__ import annotations

import csv
import dataclasses
import datetime
import io
import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

from plansim.cli import main
from plansim.config.scenario import ErrorDistribution
from plansim.estimate.segmentation import segment_log
from plansim.fit import TABLE_1_TURNTABLE, fit_recording, resolve_site
from plansim.io.log_import import import_log
from plansim.io.log_table import MAX_PREAMBLE_LINES, MAX_TRAILING_LINES, parse_offset, parse_scale, parse_units
from plansim.io.recording import nominal_time, read_recording, write_recording
from plansim.io.scenario_file import load_scenario
from plansim.model.parameters import PARAMETER_INDEX
from plansim.runner import simulate_and_record
from plansim.schedule import Schedule, Segment
from plansim.schedule.segments import TABLE_COLUMN_NOTES
from plansim.units import STANDARD_GRAVITY

REAL = Path(__file__).resolve().parents[2] / "shared/data/real/imucal-ferraris"
CHANNEL_COLUMNS = "gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z"


# ----------------------------------------------------------------------------- a log simulated by plansim

def simulated_log(settle: float = 0.0):
    """A plansim recording of six poses and two turns about the vertical, and its true segments."""
    def rest(up):
        return Segment(f"{up} up", "multi_position", 1, up, dwell=8.0, settle=settle, sample_rate=100.0)

    def turn(axis, rate_deg, dwell):
        return Segment(f"turn {axis}", "rate", "xyz".index(axis), f"+{axis}", rate=math.radians(rate_deg),
                       rate_axis=f"+{axis}", dwell=dwell, settle=settle, sample_rate=100.0)

    segments = (rest("+x"), turn("x", 60.0, 6.0), rest("+x"), rest("-x"), rest("+y"), turn("y", -45.0, 8.0),
                rest("+y"), rest("-y"), rest("+z"), rest("-z"))
    scenario = dataclasses.replace(load_scenario("jjf2003"), schedule=Schedule(segments))
    return simulate_and_record(scenario, seed=11, trial=3)


def write_plain_log(path: Path, time_ms: np.ndarray, samples_si: np.ndarray) -> None:
    """A plain log as a lab's logger writes it: time in ms, gyros in deg/s, accelerometers in m/s^2."""
    block = np.column_stack([time_ms, np.degrees(samples_si[:, :3]), samples_si[:, 3:]])
    header = "t_ms,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z"
    np.savetxt(path, block, delimiter=",", header=header, comments="", fmt="%.10g")


def test_a_simulated_log_gives_back_its_segments(tmp_path):
    recording = simulated_log()
    log = tmp_path / "sim_log.csv"
    write_plain_log(log, recording.time * 1000.0, recording.samples)
    result = import_log(log, columns=tuple(CHANNEL_COLUMNS.split(",")), time_column="t_ms", time_unit="ms",
                        units="deg/s,m/s^2")
    truth = recording.schedule.segments
    first = recording.first_sample
    true_rests = [(int(first[k]), int(first[k]) + s.samples, s.up) for k, s in enumerate(truth) if not s.is_rotating]
    found = result.segmentation.of_kind("static")
    # consecutive rests with the same up axis and no motion between them (the table did not move) are one rest
    merged = []
    for a, b, up in true_rests:
        if merged and merged[-1][1] == a and merged[-1][2] == up:
            merged[-1] = (merged[-1][0], b, up)
        else:
            merged.append((a, b, up))
    assert len(found) == len(merged)
    half = result.segmentation.window // 2
    for span, (a, b, up) in zip(found, merged):
        assert span.up == up
        # documented tolerance: inside the true rest, at most half a window + 1 sample short at each end
        assert a <= span.start <= a + half + 1, (span.start, a)
        assert b - half - 1 <= span.stop <= b, (span.stop, b)
    # each table turn is a steady turn: its steady part is a rotation with its measured rate and no angle (the
    # table's rate is the reference, and not in the log), between the moves where the rate changes
    spans = result.segmentation.spans
    rotations = [k for k, span in enumerate(spans) if span.kind == "rotation"]
    assert [spans[k].axis for k in rotations] == [0, 1]
    for k, (rate, seconds) in zip(rotations, ((60.0, 6.0), (-45.0, 8.0))):
        r = spans[k]
        assert math.isnan(r.angle) and r.orientation == "approximate"
        # the steady rate measures the unit's own scale factor (about 1 +- 0.3 %)
        assert math.degrees(r.steady_rate) == pytest.approx(rate, rel=0.005)
        assert [spans[k - 1].kind, spans[k + 1].kind] == ["move", "move"]
        # the three pieces hold the whole turn: their integrals add up to it
        whole = sum(float(spans[j].integrated[r.axis]) for j in (k - 1, k, k + 1))
        assert math.degrees(whole) == pytest.approx(rate * seconds, rel=0.005)
        assert r.samples >= (seconds * 100.0) - result.segmentation.window - 2
    # the recording holds every sample, in segments, with the log's clock
    rec = result.recording
    np.testing.assert_allclose(rec.samples, recording.samples, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(rec.time, recording.time, rtol=0, atol=1e-9)
    segments = rec.schedule.segments
    assert [s.test for s in segments] == ["static", "move", "rotation", "move", "static", "move", "static",
                                          "move", "static", "move", "rotation", "move", "static", "move", "static",
                                          "move", "static", "move", "static"]
    for s in segments:
        assert math.isnan(s.heading) and s.rate_known == (s.test == "static") and not s.angle_known
    assert all(s.orientation == "approximate" for s in segments if s.test in ("static", "rotation"))
    assert [s.label.endswith("give the table's rate") for s in segments if s.test == "rotation"] == [True, True]
    assert result.warnings == ()
    assert rec.attrs["sample_rate_hz"] == pytest.approx(100.0, rel=1e-9)
    assert rec.attrs["time_gaps"] == 0 and rec.attrs["import_warnings"] == "none"
    for suffix in (".nc", ".csv"):
        write_recording(rec, tmp_path / f"rec{suffix}")
        assert read_recording(tmp_path / f"rec{suffix}") == rec


def test_a_simulated_log_with_settle_gaps_splits_at_each_gap(tmp_path):
    recording = simulated_log(settle=10.0)
    log = tmp_path / "sim_gaps.csv"
    write_plain_log(log, recording.time * 1000.0, recording.samples)
    result = import_log(log, columns=tuple(CHANNEL_COLUMNS.split(",")), time_column="t_ms", time_unit="ms",
                        units="deg/s,m/s^2")
    assert [w.name for w in result.warnings] == ["gap"]
    assert result.timing.missing_samples == 10 * 1000 - 1000  # ten settle gaps of 10 s, less one step each
    assert len(result.timing.gaps) == len(recording.schedule) - 1
    # no static span or steady turn holds a gap; each turn, logged over its dwell only, is a steady turn with its
    # measured rate and no angle (until 2026-11-30 it was in a move, 'not integrated'), the gaps in moves
    gap_starts = set(result.timing.gap_starts.tolist())
    for span in result.segmentation.of_kind("static") + result.segmentation.of_kind("rotation"):
        assert not any(span.start < k < span.stop for k in gap_starts)
    turns = result.segmentation.of_kind("rotation")
    assert [math.degrees(span.steady_rate) for span in turns] == pytest.approx([60.0, -45.0], rel=0.01)
    assert all(math.isnan(span.angle) for span in turns)
    assert all(any(span.start < k <= span.stop for span in result.segmentation.of_kind("move")) for k in gap_starts)
    ups = [span.up for span in result.segmentation.of_kind("static")]
    assert [u for k, u in enumerate(ups) if k == 0 or u != ups[k - 1]] == ["+x", "-x", "+y", "-y", "+z", "-z"]


# ----------------------------------------------------------------------------- the shared real data

def real(name: str) -> Path:
    path = REAL / name
    if not path.is_file():
        pytest.skip(f"the shared real data {name} is not beside the repository ({REAL})")
    return path


def test_real_ferraris_session_imports_into_its_sections(tmp_path):
    log = real("example_ferraris_session.csv")
    sections = json.loads(real("example_ferraris_session_list.json").read_text())
    result = import_log(log, columns=tuple(CHANNEL_COLUMNS.split(",")), units="deg/s,m/s^2", sample_rate=102.4)
    spans = result.segmentation.spans
    statics = result.segmentation.of_kind("static")
    # every annotated static section lies inside one static span with the right axis up
    for name, up in (("x_p", "+x"), ("x_a", "-x"), ("y_p", "+y"), ("y_a", "-y"), ("z_p", "+z"), ("z_a", "-z")):
        a, b = sections[name]["start"], sections[name]["end"]
        holding = [s for s in statics if s.start <= a and b <= s.stop]
        assert len(holding) == 1 and holding[0].up == up, name
        assert math.degrees(holding[0].tilt) < 6.0
    assert {s.up for s in statics} == {"+x", "-x", "+y", "-y", "+z", "-z"}
    # three rotations, one full turn each about x, y, z, holding the annotated turns; the integrals (bias
    # removed with the static spans on either side) near the -372, -355, -359 deg the data's notes give
    rotations = [s for s in spans if s.kind == "rotation"]
    assert [(r.axis, math.degrees(r.angle)) for r in rotations] == [(0, -360.0), (1, -360.0), (2, -360.0)]
    for r, name, integral in zip(rotations, ("x_rot", "y_rot", "z_rot"), (-372.0, -355.0, -359.0)):
        assert r.start <= sections[name]["start"] and sections[name]["end"] <= r.stop
        assert math.degrees(r.integrated[r.axis]) == pytest.approx(integral, abs=3.0)
        assert math.isnan(r.steady_rate)  # turned by hand
    # the noise (a 16-bit unit: 1/16.4 deg/s and 1/2048 g steps) and nothing flagged
    sigma = result.segmentation.noise.sigma
    assert np.all((np.degrees(sigma[:3]) > 0.02) & (np.degrees(sigma[:3]) < 0.1))
    assert np.all((sigma[3:] > 0.005) & (sigma[3:] < 0.03))
    assert result.warnings == ()
    rec = result.recording
    assert rec.samples.shape == (10376, 6) and rec.timestamps is None
    write_recording(rec, tmp_path / "ferraris.nc")
    assert read_recording(tmp_path / "ferraris.nc") == rec


def test_real_annotated_session_in_counts_with_its_labels_ignored():
    log = real("annotated_session.csv")
    result = import_log(log, columns=tuple(CHANNEL_COLUMNS.split(",")), units="deg/s,g", scale="16.4,2048",
                        sample_rate=204.8)
    assert set(result.table.ignored) == {"part", "samples"}
    statics = result.segmentation.of_kind("static")
    assert [s.up for s in statics] == ["-x", "+x", "-y", "+y", "-z", "+z"]
    # the labels (not given to the import) agree: each static span is mostly its labelled static section and
    # holds most of it; where the unit rested in the same pose at the start of the next (turn) section, the
    # span runs on into it (the sections were cut from one session and pasted together)
    labels = [line.split(",")[0] for line in log.read_text().splitlines()[1:]]
    for span, part in zip(statics, ("x_a", "x_p", "y_a", "y_p", "z_a", "z_p")):
        inside = labels[span.start:span.stop]
        assert max(set(inside), key=inside.count) == part
        assert inside.count(part) >= 0.8 * labels.count(part)
        assert set(inside) <= {part, part[0] + "_rot"}
    for span in statics:
        # 1 g, give or take this unit's accelerometer errors (a z scale error of about 2 % and 0.4 m/s^2 bias)
        assert np.linalg.norm(span.mean[3:]) == pytest.approx(9.80665, rel=0.07)
    # the motions between the pasted sections are no motion the gyros saw: the moves are left out for what they are
    # (a miss of the poses' change of gravity no Kg brings within MOVES_SCATTER_LIMIT: 13.6 deg), not fitted
    from plansim.fit import fit_recording

    fit = fit_recording(result.recording)
    assert fit.moves is None
    assert any("the moves between poses were left out" in note and "still miss the change of gravity" in note
               for note in fit.notes), fit.notes


def test_real_annotated_session_counter_runs_backwards(tmp_path):
    log = real("annotated_session.csv")
    code = main(["import", str(log), "--out", str(tmp_path / "a.nc"), "--columns", CHANNEL_COLUMNS,
                 "--units", "deg/s,g", "--scale", "16.4,2048", "--time", "samples", "--time-unit", "samples",
                 "--sample-rate", "204.8"])
    assert code == 2
    assert os.listdir(tmp_path) == []


# ----------------------------------------------------------------------------- bad logs

def synthetic_log(seed: int = 0, seconds_rest: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    """(time s, samples SI): rest with +z up, a 360 deg turn about z in 2 s, rest."""
    rng = np.random.default_rng(seed)
    fs = 100.0
    n_rest, n_turn = int(seconds_rest * fs), int(2.0 * fs)
    n = 2 * n_rest + n_turn
    x = rng.normal(size=(n, 6)) * np.r_[[math.radians(0.1)] * 3, [0.01] * 3]
    x[:, 5] += 9.81
    x[:, :3] += np.radians([0.3, -0.2, 0.1])
    phase = np.arange(n_turn) / n_turn
    x[n_rest:n_rest + n_turn, 2] += 2 * math.pi * fs / n_turn * (1 - np.cos(2 * math.pi * phase))  # 360 deg
    return np.arange(n) / fs, x


def write_synthetic(path: Path, time: np.ndarray | None, x: np.ndarray, names=("gx", "gy", "gz", "ax", "ay", "az"),
                    extra: dict | None = None) -> None:
    columns = ([("time", time)] if time is not None else []) + list(zip(names, x.T)) + list((extra or {}).items())
    header = ",".join(name for name, _ in columns)
    np.savetxt(path, np.column_stack([values for _, values in columns]), delimiter=",", header=header,
               comments="", fmt="%.12g")


def test_a_clean_synthetic_log_and_the_cli(tmp_path, capsys):
    t, x = synthetic_log()
    log = tmp_path / "log.csv"
    write_synthetic(log, t, x)
    out = tmp_path / "rec.csv"
    assert main(["import", str(log), "--out", str(out), "--time", "time", "--latitude", "49.6", "--height",
                 "280"]) == 0
    text = capsys.readouterr().out
    assert "segments: 2 static, 1 rotation, 0 move" in text and "+360 deg about +z" in text
    assert "sample rate: 100 Hz" in text and "deg/s" in text and "m/s^2" in text
    rec = read_recording(out)
    assert [s.test for s in rec.schedule.segments] == ["static", "rotation", "static"]
    assert rec.schedule.segments[1].angle == pytest.approx(2 * math.pi)
    assert rec.attrs["site_latitude_deg"] == 49.6 and rec.attrs["site_height_m"] == 280.0
    assert rec.attrs["source"] == "measured" and rec.attrs["segment_temperature"].endswith("assumed (the log has "
                                                                                           "no temperature)")
    assert set(os.listdir(tmp_path)) == {"log.csv", "rec.csv", "rec.segments.csv"}
    # the recording may not overwrite the log
    assert main(["import", str(log), "--out", str(log), "--time", "time"]) == 2
    assert "would overwrite the log" in capsys.readouterr().err


def test_import_plot_shades_each_segment_and_draws_the_samples_in_their_units(tmp_path, capsys, monkeypatch):
    """``--plot``: the samples against time, gyros in deg/s and accelerometers in m/s^2, one shaded span per
    segment in its kind's colour on both panels, written with the recording; a bad figure name writes nothing."""
    from matplotlib.colors import to_rgba

    from plansim.report.plot import SEGMENT_SHADES, draw_recording, pyplot, segment_kind

    t, x = synthetic_log()
    log = tmp_path / "log.csv"
    write_synthetic(log, t, x)
    out, figure = tmp_path / "rec.nc", tmp_path / "segments.png"
    assert main(["import", str(log), "--out", str(out), "--time", "time", "--plot", str(figure)]) == 0
    assert "wrote figure" in capsys.readouterr().out
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    recording = read_recording(out)
    fig, (gyros, accels) = draw_recording(recording)
    try:
        kinds = [segment_kind(s) for s in recording.schedule.segments]
        assert kinds == ["static", "rotation", "static"]
        for ax in (gyros, accels):
            shades = [p for p in ax.patches if p.get_alpha() is not None and p.get_alpha() < 0.2]
            assert len(shades) == len(kinds)
            for patch, kind in zip(shades, kinds):
                assert patch.get_facecolor()[:3] == pytest.approx(to_rgba(SEGMENT_SHADES[kind])[:3])
        # the lines are the samples in the panel's unit: the turn's peak in deg/s, gravity in m/s^2
        peak = max(float(np.max(np.abs(line.get_ydata()))) for line in gyros.get_lines())
        assert peak == pytest.approx(math.degrees(float(np.max(np.abs(recording.samples[:, :3])))), rel=1e-12)
        gravity = max(float(np.max(np.abs(line.get_ydata()))) for line in accels.get_lines())
        assert gravity == pytest.approx(float(np.max(np.abs(recording.samples[:, 3:]))), rel=1e-12)
    finally:
        pyplot().close(fig)
    # a long recording is drawn as each channel's envelope over bins: its extremes are the samples' own
    import plansim.report.plot as plot_module

    monkeypatch.setattr(plot_module, "ENVELOPE_ABOVE", 200)
    fig, (gyros, _accels) = draw_recording(recording)
    try:
        assert not gyros.get_lines() and len(gyros.collections) == 3
        top = max(float(np.max(np.abs(c.get_paths()[0].vertices[:, 1]))) for c in gyros.collections)
        assert top == pytest.approx(math.degrees(float(np.max(np.abs(recording.samples[:, :3])))), rel=1e-12)
    finally:
        pyplot().close(fig)
    # a figure format it cannot write: an error before anything is written
    assert main(["import", str(log), "--out", str(tmp_path / "b.nc"), "--time", "time", "--plot",
                 str(tmp_path / "b.txt")]) == 2
    assert "--plot" in capsys.readouterr().err
    assert not (tmp_path / "b.nc").exists() and not (tmp_path / "b.txt").exists()


def test_the_summary_says_when_the_noise_is_correlated_from_sample_to_sample(tmp_path, capsys):
    """The per-sample noise of the quiet stretch understates a segment mean's where the part's filter correlates
    neighbouring samples. The same log with its noise through a first-order filter (pole 0.6: rho_1 = 0.6) is
    said to be correlated in every channel, with its lag-one autocorrelation, as plansim fit reads it, and a mean's
    variance about 4 times the white figure's; the white one is not. Noise whose neighbours cancel in part is said
    to make the per-sample figures overstate a mean's noise, not understate it."""
    from scipy.signal import lfilter

    t, x = synthetic_log(seed=4, seconds_rest=30.0)  # 30 s rest, a 2 s turn, 30 s rest at 100 Hz
    filtered = x.copy()
    for rest in (slice(0, 3000), slice(3200, None)):  # each rest's noise through the filter, its variance kept
        level = x[rest].mean(axis=0)
        filtered[rest] = level + lfilter([math.sqrt(1.0 - 0.6**2)], [1.0, -0.6], x[rest] - level, axis=0)
    # noise whose neighbours partly cancel (w_k - 0.4 w_k-1, scaled: rho_1 = -0.34) makes a mean's noise smaller
    # than the per-sample figure says (found on a real MPU-6050 log, where the summary said "understate")
    cancelling = x.copy()
    for rest in (slice(0, 3000), slice(3200, None)):
        level = x[rest].mean(axis=0)
        cancelling[rest] = level + lfilter([1.0, -0.4], [1.0], x[rest] - level, axis=0) / math.sqrt(1.16)
    for name, samples, said in (("white", x, False), ("filtered", filtered, True), ("cancelling", cancelling, True)):
        log = tmp_path / f"{name}.csv"
        write_synthetic(log, t, samples)
        assert main(["import", str(log), "--out", str(tmp_path / f"{name}.nc"), "--time", "time"]) == 0
        out = capsys.readouterr().out
        assert ("noise correlated from one sample to the next in gx gy gz ax ay az" in out) is said, out
        if name == "filtered":
            rho = [float(v) for v in re.findall(r"lag-one autocorrelation ([0-9.]+) to ([0-9.]+)", out)[0]]
            assert 0.5 < rho[0] <= rho[1] < 0.7  # 6000 samples: a standard error of 0.013
            assert "the per-sample figures above understate a segment mean's noise" in out
            # 1 + 2 sum rho of a first-order filter: (1 + 0.6) / (1 - 0.6) = 4
            low, high = (float(v) for v in re.findall(r"its variance ([0-9.]+) to ([0-9.]+) times theirs", out)[0])
            assert 3.0 < low <= high < 5.0
        if name == "cancelling":
            rho = [float(v) for v in re.findall(r"lag-one autocorrelation (-[0-9.]+) to (-[0-9.]+)", out)[0]]
            assert -0.4 < rho[0] <= rho[1] < -0.28
            assert "negative: neighbouring samples partly cancel" in out
            assert "the per-sample figures above overstate a segment mean's noise" in out
            # 1 + 2 rho_1 = 1 - 0.69 = 0.31
            low, high = (float(v) for v in re.findall(r"its variance ([0-9.]+) to ([0-9.]+) times theirs", out)[0])
            assert 0.2 < low <= high < 0.45


def test_a_temperature_column_becomes_the_temperature_channel(tmp_path):
    t, x = synthetic_log()
    temperature = 25.0 + 0.001 * np.arange(t.size)
    write_synthetic(tmp_path / "log.csv", t, x, extra={"temp_c": temperature})
    result = import_log(tmp_path / "log.csv", time_column="time", temperature_column="temp_c")
    np.testing.assert_allclose(result.recording.temperature, temperature, rtol=1e-12)
    assert result.recording.schedule.segments[0].temperature == pytest.approx(temperature[:350].mean(), abs=0.05)


def expect_error(tmp_path, capsys, argv: list[str], message: str) -> None:
    """The CLI refuses the log with exit status 2, the message on stderr, and writes nothing."""
    before = set(os.listdir(tmp_path))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("plansim: error: ") and message in err, err
    assert set(os.listdir(tmp_path)) == before


def test_bad_logs_are_refused_naming_the_line_and_column(tmp_path, capsys):
    t, x = synthetic_log()
    log = tmp_path / "log.csv"
    out = str(tmp_path / "rec.nc")
    write_synthetic(log, t, x)
    lines = log.read_text().splitlines()

    def variant(edit) -> str:
        copy = list(lines)
        edit(copy)
        path = tmp_path / "bad.csv"
        path.write_text("\n".join(copy) + "\n")
        return str(path)

    # a raw log given to fit instead of import: the error says what to do
    assert main(["fit", str(log)]) == 2
    assert f"Turn it into a recording first: plansim import {log.name} --out rec.nc" in capsys.readouterr().err
    # a lab temperature no IMU runs at (a typo, or kelvin)
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", "--temperature", "1e6"],
                 "--temperature 1000000.0: expected the lab's temperature, -100 to 200 degC")
    # a missing column (without --columns the channels are gx ... az)
    write_synthetic(tmp_path / "bad.csv", t, x, names=("gx", "gy", "gz", "ax", "ay", "acc_z"))
    expect_error(tmp_path, capsys, ["import", str(tmp_path / "bad.csv"), "--out", out, "--time", "time"],
                 "column 'az' is missing")
    # an extra column without --columns
    write_synthetic(tmp_path / "bad.csv", t, x, extra={"counter": np.arange(t.size)})
    expect_error(tmp_path, capsys, ["import", str(tmp_path / "bad.csv"), "--out", out, "--time", "time"],
                 "column 'counter' is not expected")
    # ... which --columns ignores
    assert main(["import", str(tmp_path / "bad.csv"), "--out", out, "--time", "time", "--columns",
                 "gx,gy,gz,ax,ay,az"]) == 0
    os.remove(out)
    capsys.readouterr()
    # a row with one value too many, or one too few
    expect_error(tmp_path, capsys, ["import", variant(lambda c: c.__setitem__(10, c[10] + ",1")), "--out", out,
                                    "--time", "time"], "line 11 has 8 values, more than the 7 columns")
    expect_error(tmp_path, capsys, ["import", variant(lambda c: c.__setitem__(12, c[12].rsplit(",", 1)[0])),
                                    "--out", out, "--time", "time"], "line 13 has 6 values, fewer than the 7")
    # a NaN, and text
    expect_error(tmp_path, capsys, ["import", variant(lambda c: c.__setitem__(20, c[20].rsplit(",", 1)[0] + ",nan")),
                                    "--out", out, "--time", "time"], "column 'az' is 'nan' at line 21")
    expect_error(tmp_path, capsys, ["import", variant(lambda c: c.__setitem__(30, "0.29," + c[30].split(",", 1)[1]
                                                                              .replace(",", ",x", 1))),
                                    "--out", out, "--time", "time"], "at line 31; expected a number")
    # time going backwards
    def backwards(c):
        c[40], c[41] = c[41], c[40]
    expect_error(tmp_path, capsys, ["import", variant(backwards), "--out", out, "--time", "time"],
                 "column 'time' goes backwards at line 42 (0.4 then 0.39 s, line 41 then this one)")
    # no time column and no sample rate; a scale without units; a unit of the wrong kind
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out], "give --time COLUMN")
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", "--scale", "16.4,2048"],
                 "--scale '16.4,2048' needs --units")
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", "--units", "g,deg/s"],
                 "'g' for channel gx; allowed: rad/s, deg/s, deg/h")
    # accelerometers in g read as m/s^2: at rest they read 1, not 9.8
    write_synthetic(tmp_path / "bad.csv", t, x * np.r_[1, 1, 1, [1 / 9.80665] * 3])
    expect_error(tmp_path, capsys, ["import", str(tmp_path / "bad.csv"), "--out", out, "--time", "time"],
                 "at rest the accelerometers read 1.000 m/s^2")
    # a log that never rests: the unit tumbles about x the whole time
    moving = x.copy()
    angle = math.radians(30.0) * t
    moving[:, 0] += math.radians(30.0)
    moving[:, 4], moving[:, 5] = x[:, 4] + 9.81 * np.sin(angle), x[:, 5] - 9.81 + 9.81 * np.cos(angle)
    write_synthetic(tmp_path / "bad.csv", t, moving)
    expect_error(tmp_path, capsys, ["import", str(tmp_path / "bad.csv"), "--out", out, "--time", "time"],
                 "too few static samples")
    # a bad --scale, a bad site
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", "--units", "deg/s,g",
                                    "--scale", "16.4,-2048"], "expected a positive number of counts per unit")
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", "--latitude", "91"],
                 "--latitude 91.0: expected a number from -90 to 90 deg")
    expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", "--window", "0"],
                 "--window 0.0: expected a positive number of seconds")


def test_flawed_logs_import_with_named_warnings(tmp_path):
    t, x = synthetic_log(seconds_rest=6.0)
    log = tmp_path / "log.csv"
    # a gap of 0.5 s inside the first rest: it splits the rest, and is reported
    t_gap = t.copy()
    t_gap[300:] += 0.5
    write_synthetic(log, t_gap, x)
    result = import_log(log, time_column="time")
    assert [w.name for w in result.warnings] == ["gap"]
    assert "50 sample(s) missing" in result.warnings[0].message and "before line 302" in result.warnings[0].message
    assert result.recording.attrs["time_gaps"] == 1 and result.recording.attrs["import_warnings"] == "gap"
    assert not any(s.start < 300 < s.stop for s in result.segmentation.spans if s.kind != "move")
    assert [s.kind for s in result.segmentation.spans] == ["static", "move", "static", "rotation", "static"]
    # a saturated stretch: the z gyro stuck at a rail during the turn; the turn then has no angle
    clipped = x.copy()
    rail = np.max(clipped[:, 2]) * 0.8
    clipped[:, 2] = np.minimum(clipped[:, 2], rail)
    write_synthetic(log, t, clipped)
    result = import_log(log, time_column="time")
    assert "saturated" in [w.name for w in result.warnings]
    assert result.segmentation.of_kind("rotation") == []
    assert any("saturated" in s.reason for s in result.segmentation.of_kind("move"))
    # jitter, and a sample rate that disagrees with the time column
    rng = np.random.default_rng(2)
    write_synthetic(log, t + rng.uniform(-0.0015, 0.0015, t.size), x)
    result = import_log(log, time_column="time", sample_rate=102.0)
    assert {w.name for w in result.warnings} == {"jitter", "sample_rate_mismatch"}


def test_a_declared_full_scale_finds_a_steady_turn_held_at_the_rail(tmp_path, capsys):
    """A turn held beyond the gyro's range reads as a steady turn at the rail: quiet, in one pose, at one level,
    as a table holding that rate would read. From the data alone it cannot be told (step 10 of
    plansim.estimate.segmentation): the turn is taken as a rotation by the wrong angle. With --full-scale the rail
    is known: every sample at it is saturated, the turn is a move, and the warning names the full scale. A single
    clipped sample of a fast peak is found too, and a log that reads beyond its declared full scale is refused."""
    fs = 100.0
    rng = np.random.default_rng(3)
    n_rest, n_ramp, n_hold = 400, 50, 165  # clipped, it turns 450 deg: near a whole number of quarter turns
    n = 2 * n_rest + 2 * n_ramp + n_hold
    x = rng.normal(size=(n, 6)) * np.r_[[0.1] * 3, [0.01] * 3]  # gyros in deg/s
    x[:, 5] += 9.81
    x[:, :3] += [0.3, -0.2, 0.1]
    true_rate = 250.0  # deg/s, for a +/-200 deg/s gyro
    profile = np.concatenate([np.linspace(0, true_rate, n_ramp), np.full(n_hold, true_rate),
                              np.linspace(true_rate, 0, n_ramp)])
    x[n_rest:n_rest + profile.size, 2] += profile
    x[:, 2] = np.minimum(x[:, 2], 200.0)  # the converter's rail
    t = np.arange(n) / fs
    log = tmp_path / "log.csv"
    write_synthetic(log, t, x)
    out = str(tmp_path / "rec.nc")
    # without the full scale, the clipped turn is a rotation by the clipped angle
    blind = import_log(log, time_column="time", units="deg/s,m/s^2")
    assert "saturated" not in [w.name for w in blind.warnings]
    turned = math.degrees(float(blind.segmentation.of_kind("rotation")[0].integrated[2]))
    assert turned < 0.9 * profile.sum() / fs  # the angle the table turned, lost at the rail
    # with it, the turn is a move, and the recording notes the full scale
    assert main(["import", str(log), "--out", out, "--time", "time", "--units", "deg/s,m/s^2",
                 "--full-scale", "200,16"]) == 0
    text = capsys.readouterr().out
    assert "at its full scale of 200 deg/s (--full-scale)" in text
    notes = read_recording(out).schedule.notes["import"]
    assert notes["full_scale"] == {"gx": 200.0, "gy": 200.0, "gz": 200.0, "ax": 16.0, "ay": 16.0, "az": 16.0}
    assert notes["saturation_rule"].startswith("declared full scale")
    known = import_log(log, time_column="time", units="deg/s,m/s^2", full_scale="200,16")
    assert known.segmentation.of_kind("rotation") == []
    assert any("saturated" in span.reason for span in known.segmentation.of_kind("move"))
    (stretch,) = known.segmentation.saturation
    assert stretch.channel == 2 and stretch.stop - stretch.start >= n_hold
    # one clipped sample of a fast peak, in a turn that never holds the rail
    peak = x.copy()
    peak[:, 2] = np.minimum(peak[:, 2], 150.0)
    peak[n_rest + 60, 2] = 200.0
    write_synthetic(log, t, peak)
    found = import_log(log, time_column="time", units="deg/s,m/s^2", full_scale="200,16").segmentation.saturation
    assert [(s.channel, s.start, s.stop) for s in found] == [(2, n_rest + 60, n_rest + 61)]
    # a log that reads beyond its declared full scale, a full scale that is not positive, the wrong count
    for options, message in (
            (["--units", "deg/s,m/s^2", "--full-scale", "100,16"], "channel gz (gz) reads 200 deg/s at line"),
            (["--full-scale", "0,16"],
             "--full-scale '0,16': '0' for channel gx; expected a positive full scale in the channel's unit"),
            (["--full-scale", "1,2,3"], "--full-scale '1,2,3': 3 entries; expected 2")):
        expect_error(tmp_path, capsys, ["import", str(log), "--out", out, "--time", "time", *options], message)
    with pytest.raises(ValueError, match=r"full_scale = \[1.0, -1.0, .*expected 6 positive numbers"):
        segment_log(x, None, fs, full_scale=[1.0, -1.0, 1.0, 1.0, 1.0, 1.0])


def test_a_time_column_in_another_unit_and_a_dead_channel_are_named(tmp_path, capsys):
    """Two mistakes a log from another lab makes (found by feeding plansim such logs): a time column in ms read as
    seconds (100 Hz reads as 0.1 Hz, every pose 100 times too long) is a warning that names the unit that gives a
    usual rate; a channel that reads one value in every row (dead, disconnected, a wrong column) is a warning at
    import, and plansim fit refuses it, naming it, instead of weighing its exact means as exact (a singular fit,
    which failed or not from one run to the next with the BLAS's threads)."""
    t, x = synthetic_log(seconds_rest=6.0)
    log = tmp_path / "log.csv"
    write_synthetic(log, t * 1000.0, x)
    result = import_log(log, time_column="time")
    warning = {w.name: w.message for w in result.warnings}["unusual_sample_rate"]
    assert "0.1 Hz" in warning and "--time-unit ms (100 Hz)" in warning
    assert "unusual_sample_rate" not in {w.name for w in import_log(log, time_column="time", time_unit="ms").warnings}
    dead = x.copy()
    dead[:, 1] = 0.0
    write_synthetic(log, t, dead)
    result = import_log(log, time_column="time")
    assert "channel gy (gy) reads 0 in every one of the" in {w.name: w.message for w in result.warnings}[
        "constant_channel"]
    path = tmp_path / "dead.nc"
    write_recording(result.recording, path)
    assert main(["fit", str(path)]) == 2
    assert "channel gy reads 0 rad/s in every one of its" in capsys.readouterr().err


def test_a_steady_turn_about_the_vertical_with_no_rest_is_warned_of(tmp_path):
    """A table turning steadily at 30 deg/s about the vertical for the whole log (found by feeding plansim such a
    log): the accelerometers are steady, and with no rest elsewhere to compare with, the detector takes the turn
    for rest and its rate for the gyros' bias. The import says so (``rest_turning_about_vertical``) when the gyro
    output is at least 1 deg/s and along the pose's own vertical; a bias of 2 deg/s across the vertical (a
    consumer gyro's), or the synthetic log's 0.37 deg/s, is not warned of."""
    t, x = synthetic_log(seconds_rest=6.0)
    steady = x.copy()
    steady[:, :3] = np.random.default_rng(1).normal(size=(t.size, 3)) * math.radians(0.1)
    steady[:, 2] += math.radians(30.0)
    log = tmp_path / "log.csv"
    write_synthetic(log, t, steady)
    result = import_log(log, time_column="time")
    message = {w.name: w.message for w in result.warnings}["rest_turning_about_vertical"]
    assert "reads 30 deg/s on its gyros" in message and "its rate for the gyros' bias" in message
    assert "rest_turning_about_vertical" in result.recording.attrs["import_warnings"]
    across = steady.copy()
    across[:, 2] -= math.radians(30.0)
    across[:, 0] += math.radians(2.0)
    write_synthetic(log, t, across)
    assert "rest_turning_about_vertical" not in {w.name for w in import_log(log, time_column="time").warnings}
    write_synthetic(log, t, x)
    assert "rest_turning_about_vertical" not in {w.name for w in import_log(log, time_column="time").warnings}


def test_a_gyro_offset_every_pose_reads_is_not_a_turn_about_one_poses_vertical(tmp_path):
    """Found on a real hand session (imu_tk's Xsens test log, its gyros in raw counts less 32768: a zero-rate
    offset of 3.7 deg/s that one of its 39 poses had within 6 deg of its vertical). A simulated 12-pose session
    whose gyro bias, 3.7 deg/s, points along its fourth pose's vertical: every other pose reads the same output,
    so it is the bias, and the import does not warn of a turn about that pose's vertical. The one-pose logs of
    test_a_steady_turn_about_the_vertical_with_no_rest_is_warned_of still are."""
    from plansim.model.parameters import PARAMETER_INDEX
    from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

    theta = consumer_unit(3)
    poses = spread_poses(12, seed=3)
    up = poses[3].T @ np.array([0.0, 0.0, 1.0])  # the fourth pose's vertical in the body frame
    for i, axis in enumerate("xyz"):
        theta[PARAMETER_INDEX[f"Bg{axis}"]] = math.radians(3.7) * up[i]
    s = hand_session(theta, poses, seed=3, gyro_noise=8.7e-4, accel_noise=9.8e-3)
    log = tmp_path / "hand.csv"
    write_synthetic(log, s.time, s.samples)
    result = import_log(log, time_column="time")
    statics = [seg for seg in result.recording.schedule.segments if seg.test == "static"]
    assert len(statics) == 12
    assert "rest_turning_about_vertical" not in {w.name for w in result.warnings}
    # the same output in one pose alone is still warned of: nothing else reads it
    lone = s.samples[: int(s.time.searchsorted(4.0))]
    lone = lone.copy()
    lone[:, :3] = np.radians(3.7) * (lone[:, 3:] / np.linalg.norm(lone[:, 3:], axis=1, keepdims=True))
    lone[:, :3] += 8.7e-4 * np.random.default_rng(4).standard_normal((lone.shape[0], 3))
    write_synthetic(log, s.time[: lone.shape[0]], lone)
    assert "rest_turning_about_vertical" in {w.name for w in import_log(log, time_column="time").warnings}


def test_rests_shorter_than_the_detectors_are_warned_of_with_the_options_that_find_them(tmp_path):
    """Found on a real ROS2 hand session (GetOverMassif/imu_tk, data1): its rests last about a second, the
    detector's --min-static is 1 s, and the import found 4 poses and 3 moves of 12-45 s holding 25 visible rests,
    with no word of them. A simulated session of 16 poses held 0.9 s each: with no rest long enough the error says
    what to try; started with 5 s at rest, as a session is, the warning ``short_rests`` counts the quiet stretches
    inside the motion and gives the options to import again with, which find the 16 poses. The same session with
    5 s rests is not warned of."""
    from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

    theta, poses = consumer_unit(6), spread_poses(16, seed=6)
    short = hand_session(theta, poses, rest=0.9, seed=6, gyro_noise=8.7e-4, accel_noise=9.8e-3)
    log = tmp_path / "short.csv"
    write_synthetic(log, short.time, short.samples)
    # no rest long enough at all: the error says so, and what to try
    with pytest.raises(ValueError, match=r"quiet stretches are shorter than that: if the log's rests are, try "
                                         r"--min-static 0.5 --window 0.25"):
        import_log(log, time_column="time")
    # the log started with the unit at rest for 5 s, as a session does: that pose is found, the rest are not
    rng = np.random.default_rng(6)
    first = short.samples[:90].mean(axis=0) + rng.normal(size=(500, 6)) * np.r_[[8.7e-4] * 3, [9.8e-3] * 3]
    samples = np.vstack([first, short.samples])
    write_synthetic(log, np.arange(samples.shape[0]) / 100.0, samples)
    result = import_log(log, time_column="time")
    statics = sum(seg.test == "static" for seg in result.recording.schedule.segments)
    message = {w.name: w.message for w in result.warnings}["short_rests"]
    found = int(re.search(r"the motion holds (\d+) quiet stretches", message).group(1))
    assert found >= max(3, statics) and statics < 16
    assert "Import again with --min-static 0.5 --window 0.25" in message
    again = import_log(log, time_column="time", min_static=0.5, window=0.25)
    assert sum(seg.test == "static" for seg in again.recording.schedule.segments) == 16  # 5 s and 0.9 s: one pose
    assert "short_rests" not in {w.name for w in again.warnings}
    usual = hand_session(theta, poses, rest=5.0, seed=6, gyro_noise=8.7e-4, accel_noise=9.8e-3)
    write_synthetic(log, usual.time, usual.samples)
    assert "short_rests" not in {w.name for w in import_log(log, time_column="time").warnings}


def test_rest_variance_keeps_a_pose_noisier_than_the_quiet_stretch(tmp_path, capsys):
    """Found on a real BMI160 six-position tumble (a ground-station log): its -x pose, 45 s with the gyros as quiet
    as elsewhere and its means steady, has an ay noise 13 times the quietest stretch's, so the rest detector (a
    window's variance at most 4 times the quiet stretch's per channel) cut it into a 0.9 s pose and moves. Two poses
    of 30 s, the second's ay noise 10 times the first's: by default the second is lost, and the warning
    ``noisy_poses`` names it and the --rest-variance that keeps it; with that factor both are found, each whole, with
    no warning, and the recording's notes keep the factor."""
    rng = np.random.default_rng(9)
    fs, n = 100.0, 3000
    first = rng.normal(size=(n, 6)) * np.r_[[1e-3] * 3, [1e-2] * 3]
    first[:, 5] += 9.81
    second = rng.normal(size=(n, 6)) * np.r_[[1e-3] * 3, 1e-2, 1e-1, 1e-2]
    second[:, 3] += 9.81  # +x up
    phase = np.arange(200) / 200
    turn = rng.normal(size=(200, 6)) * np.r_[[1e-3] * 3, [1e-2] * 3]
    turn[:, 1] += -math.pi / 2 * fs / 200 * (1 - np.cos(2 * math.pi * phase))  # -90 deg about y: +z up to +x up
    angle = -math.pi / 2 * (phase - np.sin(2 * math.pi * phase) / (2 * math.pi))
    turn[:, 3] += -9.81 * np.sin(angle)
    turn[:, 5] += 9.81 * np.cos(angle)
    x = np.vstack([first, turn, second])
    log = tmp_path / "noisy.csv"
    write_synthetic(log, np.arange(x.shape[0]) / fs, x)

    def statics(*options):
        assert main(["import", str(log), "--out", str(tmp_path / "r.nc"), "--time", "time", *options]) == 0
        statics.out = capsys.readouterr().out
        recording = read_recording(tmp_path / "r.nc")
        return recording, [s for s in recording.schedule.segments if s.test == "static"]

    _, default = statics()
    assert "a pose noisier than the quiet stretch above needs --rest-variance" in statics.out  # the summary says
    assert not any(s.up == "+x" and s.samples > 2000 for s in default)
    # the import tells on its own (step 11 of the detector), with the factor that keeps the pose whole
    warned = re.search(r"warning \[noisy_poses\]: 1 stretch\(es\) inside the motion, (\S+) s in all \(lines "
                       r"\S+ \(\S+ s, \+x up\)\).*a rest may reach 4\).*import again with --rest-variance (\S+) ",
                       statics.out)
    assert warned and float(warned.group(1)) > 25.0, statics.out
    factor = warned.group(2)
    recording, wider = statics("--rest-variance", factor)
    assert [s.up for s in wider] == ["+z", "+x"] and all(s.samples > 2500 for s in wider)
    assert "noisy_poses" not in statics.out
    assert recording.attrs["detector_rest_variance"] == float(factor)
    assert recording.schedule.notes["import"]["detector"]["rest_variance"] == float(factor)
    assert main(["import", str(log), "--out", str(tmp_path / "bad.nc"), "--time", "time", "--rest-variance",
                 "0.5"]) == 2
    assert "--rest-variance 0.5: expected a number >= 1" in capsys.readouterr().err


def test_rows_of_other_packets_without_the_six_channels_are_skipped(tmp_path):
    """Found on a real MicroStrain CX5 log (github.com/NCSU-High-Powered-Rocketry-Club/AirbrakesV2): every other
    row is the unit's estimate packet, its six raw channels empty and its time out of order with the raw rows'. The
    import had stopped at the first ("column 'scaledGyroX' is '' at line 4; expected a number"); such rows are
    skipped with a warning naming them, and the recording is the raw rows' alone."""
    t, x = synthetic_log()
    plain = tmp_path / "plain.csv"
    write_synthetic(plain, t, x)
    rows = ["time,gx,gy,gz,ax,ay,az,est"]
    for k in range(t.size):
        rows.append(f"{t[k]:.12g}," + ",".join(f"{v:.12g}" for v in x[k]) + ",")  # as write_synthetic writes
        if k % 2 == 0:
            rows.append(f"{float(t[k]) - 0.5!r},,,,,,,0.25")  # the estimate packet, stamped earlier
    mixed = tmp_path / "mixed.csv"
    mixed.write_text("\n".join(rows) + "\n")
    reference = import_log(plain, time_column="time")
    result = import_log(mixed, time_column="time", columns=("gx", "gy", "gz", "ax", "ay", "az"))
    message = {w.name: w.message for w in result.warnings}["rows_without_channels"]
    assert message.startswith(f"{(t.size + 1) // 2} row(s) hold none of the six channel columns (lines 3, 6, 9")
    np.testing.assert_allclose(result.recording.samples, reference.recording.samples, rtol=0, atol=1e-12)


def test_rows_dropped_here_and_there_are_not_gaps(tmp_path):
    """A wireless IMU loses a row now and then: 5 % of the rows dropped at random (at most two in a row kept that
    way) made every stretch hold a gap, and the log could not be imported at all. They are a named warning now; the
    poses and the turn are found as in the whole log, the turn's angle integrated over the time column."""
    t, x = synthetic_log(seconds_rest=6.0)
    keep = np.random.default_rng(3).random(t.size) > 0.05
    for k in range(2, t.size):  # no run of three dropped rows: that is a gap
        if not keep[k - 2] and not keep[k - 1] and not keep[k]:
            keep[k] = True
    log = tmp_path / "log.csv"
    write_synthetic(log, t[keep], x[keep])
    result = import_log(log, time_column="time")
    names = [w.name for w in result.warnings]
    assert names == ["dropped_samples"], names
    assert f"{int(np.sum(~keep))} sample(s) dropped" in result.warnings[0].message
    assert result.recording.attrs["time_gaps"] == 0 and result.recording.attrs["time_dropped_samples"] == np.sum(~keep)
    assert [s.kind for s in result.segmentation.spans] == ["static", "rotation", "static"]
    rotation = result.segmentation.of_kind("rotation")[0]
    assert abs(rotation.integrated[2] - 2 * math.pi) < math.radians(1.0)


def test_a_host_that_stamps_rows_in_bursts_as_a_serial_link_delivers_them(tmp_path):
    """A logger on a PC stamps each row when the USB-serial link hands it over: rows come four at a time, stamped
    20 us apart, then 40 ms later the next four. The median step (20 us) read as the sample period made the log
    50 kHz with a gap every fourth row, and no pose could be found. The stamps are delivery times now (a named
    warning): the rate is the rows over the time, the samples evenly spaced, and the poses, the turn and its angle
    are those of the same log stamped by its sampling clock."""
    t, x = synthetic_log(seconds_rest=6.0)
    k = np.arange(t.size)
    burst = k // 4 * 4
    delay = np.repeat(np.random.default_rng(4).uniform(0.0, 0.004, t.size // 4 + 1), 4)[:t.size]
    stamps = 12.0 + t[burst + 3] + 0.002 + delay + (k - burst) * 20e-6  # seconds since the logger started
    write_synthetic(tmp_path / "clock.csv", t, x)
    write_synthetic(tmp_path / "host.csv", stamps, x)
    clock = import_log(tmp_path / "clock.csv", time_column="time")
    host = import_log(tmp_path / "host.csv", time_column="time")
    assert [w.name for w in host.warnings] == ["delivery_times"] and not clock.warnings
    assert host.timing.delivery and not clock.timing.delivery
    assert host.timing.sample_rate == pytest.approx(100.0, rel=1e-3) and host.timing.gaps == ()
    assert host.recording.attrs["time_stamps"].startswith("delivery") and clock.recording.attrs["time_stamps"] == \
        "sampling"
    assert [(s.kind, s.start, s.stop) for s in host.segmentation.spans] == \
        [(s.kind, s.start, s.stop) for s in clock.segmentation.spans]
    turn = host.segmentation.of_kind("rotation")[0].integrated[2]
    assert turn == pytest.approx(clock.segmentation.of_kind("rotation")[0].integrated[2], abs=math.radians(0.5))
    # the samples' times are the sampling clock's, to within the deliveries' spread about their mean
    times = host.recording.time - host.recording.time[0]
    assert np.max(np.abs(times - t)) < 0.01


def test_a_units_row_a_footer_and_a_row_the_logger_did_not_finish(tmp_path):
    """Loggers write a row of units under the header, a footer after the data, or stop inside their last row (no
    line break). Each stopped the import; each is now skipped with a named warning, and the samples are those of
    the clean log. A last row without a line break is kept where it is whole: every value with the decimals of
    its column's other samples (a fixed-format logger); one cut inside a value has fewer and is skipped. A line
    that is not a sample with samples after it, or more than MAX_TRAILING_LINES of them at the end, still stops
    it, naming the line."""
    t, x = synthetic_log()
    write_synthetic(tmp_path / "clean.csv", t, x)
    text = (tmp_path / "clean.csv").read_text()
    header, *rows = text.splitlines()
    clean = import_log(tmp_path / "clean.csv", time_column="time")
    cases = {
        "units": ("\n".join([header, "s,rad/s,rad/s,rad/s,m/s^2,m/s^2,m/s^2", *rows]) + "\n", "units_row", "line 2"),
        "footer": ("\n".join([header, *rows, "END OF LOG", f"rows,{len(rows)}"]) + "\n", "trailing_lines",
                   "2 line(s)"),
        "cut": ("\n".join([header, *rows, rows[-1][:9]]), "trailing_lines", "no line break"),
        "short": ("\n".join([header, *rows, rows[-1][:9]]) + "\n", "trailing_lines", "2 values, not 7"),
    }
    for name, (content, warning, words) in cases.items():
        (tmp_path / f"{name}.csv").write_text(content)
        result = import_log(tmp_path / f"{name}.csv", time_column="time")
        assert [w.name for w in result.warnings] == [warning], name
        assert words in result.warnings[0].message, (name, result.warnings[0].message)
        np.testing.assert_array_equal(result.recording.samples, clean.recording.samples)
    # a logger that writes every value with the same decimals: its complete last row without a line break is kept,
    # a row cut inside a value (fewer decimals) is not
    fixed = [",".join(f"{v:.6f}" for v in (t[i], *x[i])) for i in range(len(t))]
    (tmp_path / "fixed.csv").write_text("\n".join([header, *fixed]) + "\n")
    whole = import_log(tmp_path / "fixed.csv", time_column="time")
    assert whole.warnings == ()
    for name, content, kept in (("complete", "\n".join([header, *fixed]), True),
                                ("cut_in_value", "\n".join([header, *fixed[:-1], fixed[-1][:-2]]), False)):
        (tmp_path / f"{name}.csv").write_text(content)
        result = import_log(tmp_path / f"{name}.csv", time_column="time")
        assert [w.name for w in result.warnings] == ([] if kept else ["trailing_lines"]), name
        expected = whole.recording.samples if kept else whole.recording.samples[:-1]
        np.testing.assert_array_equal(result.recording.samples, expected)
    middle = "\n".join([header, *rows[:50], "END OF LOG", *rows[50:]]) + "\n"
    (tmp_path / "middle.csv").write_text(middle)
    with pytest.raises(ValueError, match="line 52 has 1 values, fewer than the 7 columns"):
        import_log(tmp_path / "middle.csv", time_column="time")
    long_footer = "\n".join([header, *rows, *[f"note {k}" for k in range(MAX_TRAILING_LINES + 1)]]) + "\n"
    (tmp_path / "long.csv").write_text(long_footer)
    with pytest.raises(ValueError, match=f"line {len(rows) + 2} has 1 values"):
        import_log(tmp_path / "long.csv", time_column="time")


def test_a_time_column_of_clock_times(tmp_path, capsys):
    """Loggers stamp rows with the clock: '2024-11-27 14:22:31.504' (ISO 8601, or with 'T' and 'Z'), unpadded
    '2024-11-7 9:05:01.5' (WitMotion's software), or the time of day alone, which may pass midnight. Each is read
    in seconds from the first sample and gives the clean log's rate and segments; a row whose time is not a clock
    time stops the import naming its line, and --time-unit does not apply to clock times."""
    t, x = synthetic_log()
    write_synthetic(tmp_path / "seconds.csv", t, x)
    reference = import_log(tmp_path / "seconds.csv", time_column="time")
    start = datetime.datetime(2024, 11, 27, 23, 59, 55, 504000)  # passes midnight 4.5 s in
    forms = {
        "iso": lambda d: d.isoformat(sep=" ", timespec="milliseconds"),
        "isoz": lambda d: d.isoformat(timespec="microseconds") + "Z",
        "unpadded": lambda d: f"{d.year}-{d.month}-{d.day} {d.hour}:{d.minute:02d}:{d.second:02d}.{d.microsecond:06d}",
        "time_of_day": lambda d: d.strftime("%H:%M:%S.%f"),
    }
    header, *rows = (tmp_path / "seconds.csv").read_text().splitlines()
    for name, form in forms.items():
        stamps = [form(start + datetime.timedelta(seconds=float(v))) for v in t]
        text = "\n".join([header, *(f"{stamp},{row.split(',', 1)[1]}" for stamp, row in zip(stamps, rows))]) + "\n"
        (tmp_path / f"{name}.csv").write_text(text)
        result = import_log(tmp_path / f"{name}.csv", time_column="time")
        assert result.table.clock_start == stamps[0], name
        np.testing.assert_allclose(result.recording.time - result.recording.time[0], t - t[0], atol=1e-3)
        assert result.timing.sample_rate == pytest.approx(100.0, rel=1e-4), name
        assert [(s.kind, s.start, s.stop) for s in result.segmentation.spans] == \
            [(s.kind, s.start, s.stop) for s in reference.segmentation.spans], name
        assert not result.warnings and result.recording.attrs["time_clock_start"] == stamps[0]
    assert main(["import", str(tmp_path / "iso.csv"), "--out", str(tmp_path / "r.nc"), "--time", "time"]) == 0
    assert "holds clock times, read in seconds from the first (2024-11-27 23:59:55.504)" in capsys.readouterr().out
    with pytest.raises(ValueError, match="holds clock times .* leave --time-unit out"):
        import_log(tmp_path / "iso.csv", time_column="time", time_unit="ms")
    broken = (tmp_path / "iso.csv").read_text().splitlines()
    broken[40] = "NaT" + broken[40][broken[40].index(","):]
    (tmp_path / "broken.csv").write_text("\n".join(broken) + "\n")
    with pytest.raises(ValueError, match="column 'time' is 'NaT' at line 41; expected a clock time"):
        import_log(tmp_path / "broken.csv", time_column="time")


def test_unit_and_scale_parsing():
    assert parse_units(None) == ("rad/s",) * 3 + ("m/s^2",) * 3
    # the spellings logs and data sheets use; a scaled unit is refused with how to read it
    assert parse_units("dps,m/s2") == ("deg/s",) * 3 + ("m/s^2",) * 3
    assert parse_units("°/s,m/s²") == parse_units("deg/sec,m/s/s") == ("deg/s",) * 3 + ("m/s^2",) * 3
    with pytest.raises(ValueError, match=r"'mdps' for channel gx \(1e-3 deg/s: give --units deg/s with --scale 1000"):
        parse_units("mdps,mg")
    assert parse_units("deg/s,g") == ("deg/s",) * 3 + ("g",) * 3
    assert parse_units("deg/s,deg/s,rad/s,g,mg,m/s^2")[2:4] == ("rad/s", "g")
    with pytest.raises(ValueError, match="3 entries; expected 2 .* or 6"):
        parse_units("deg/s,g,g")
    assert parse_scale("16.4,2048") == (16.4,) * 3 + (2048.0,) * 3
    with pytest.raises(ValueError, match="'x' for channel gx is not a number"):
        parse_scale("x,1")


def test_a_logger_preamble_before_the_header_is_skipped_and_reported(tmp_path, capsys):
    """A logger that writes its own settings before the header (as an MPU-6050 sketch writes "Fs,100"): the header
    is the first line naming every column; the lines before it are skipped, kept in the segment table's notes and
    printed — never read as samples. Samples and segments are those of the same log without the preamble."""
    t, x = synthetic_log()
    plain, with_preamble = tmp_path / "plain.csv", tmp_path / "log.csv"
    write_synthetic(plain, None, x)
    with_preamble.write_text("Fs,100\nLogging Type,0\nWaiting time,3\n" + plain.read_text())
    a = import_log(plain, sample_rate=100.0)
    b = import_log(with_preamble, sample_rate=100.0)
    np.testing.assert_array_equal(a.recording.samples, b.recording.samples)
    assert a.recording.schedule.segments == b.recording.schedule.segments
    assert b.table.preamble == ("Fs,100", "Logging Type,0", "Waiting time,3") and b.table.header_line == 4
    assert b.table.lines[0] == 5 and b.recording.schedule.notes["import"]["preamble"][0] == "Fs,100"
    assert main(["import", str(with_preamble), "--out", str(tmp_path / "rec.nc"), "--sample-rate", "100"]) == 0
    assert "before the header (line 4): 3 line(s) skipped, not read as data: Fs,100; Logging" in capsys.readouterr().out
    # a header that names no column asked for within MAX_PREAMBLE_LINES lines is refused against the first line
    far = tmp_path / "far.csv"
    far.write_text("".join(f"setting {k},{k}\n" for k in range(MAX_PREAMBLE_LINES + 1)) + plain.read_text())
    with pytest.raises(ValueError, match=r"column 'gx' is missing; the header \(line 1\) has setting 0, 0"):
        import_log(far, sample_rate=100.0)


def test_an_offset_in_counts_is_subtracted_before_the_scale(tmp_path, capsys):
    """Raw counts of an unsigned converter (zero input reads 32768): --offset 32768 then --scale gives the same
    samples as the signed counts; without --scale the offset is refused, naming the option."""
    t, x = synthetic_log()
    counts = np.round(x / np.r_[[math.radians(1.0) / 16.4] * 3, [9.80665 / 2048.0] * 3])
    write_synthetic(tmp_path / "signed.csv", t, counts)
    write_synthetic(tmp_path / "unsigned.csv", t, counts + 32768.0)
    signed = import_log(tmp_path / "signed.csv", time_column="time", units="deg/s,g", scale="16.4,2048")
    unsigned = import_log(tmp_path / "unsigned.csv", time_column="time", units="deg/s,g", scale="16.4,2048",
                          offset="32768,32768")
    np.testing.assert_allclose(unsigned.recording.samples, signed.recording.samples, rtol=0, atol=1e-12)
    assert unsigned.recording.schedule.notes["import"]["zero_offset_counts"]["az"] == 32768.0
    assert parse_offset("1,2,3,-4,5,6") == (1.0, 2.0, 3.0, -4.0, 5.0, 6.0) and parse_offset(None) is None
    with pytest.raises(ValueError, match="--offset '32768,x': 'x' for channel ax is not a number"):
        parse_offset("32768,x")
    with pytest.raises(ValueError, match="--offset '32768,32768' needs --scale"):
        import_log(tmp_path / "unsigned.csv", time_column="time", units="deg/s,g", offset="32768,32768")
    # read as signed counts, the unsigned log is 16 g at rest: refused by the 1 g check, naming the scale
    with pytest.raises(ValueError, match="at rest the accelerometers read"):
        import_log(tmp_path / "unsigned.csv", time_column="time", units="deg/s,g", scale="16.4,2048")
    # on the command line a list that starts with a minus sign is the option's value, not another option (argparse
    # alone said "expected one argument"): a negative offset is taken, a negative scale refused naming it
    write_synthetic(tmp_path / "shifted.csv", t, counts - 5.0)
    out = tmp_path / "shifted.nc"
    assert main(["import", str(tmp_path / "shifted.csv"), "--out", str(out), "--time", "time", "--units", "deg/s,g",
                 "--scale", "16.4,2048", "--offset", "-5,-5"]) == 0
    capsys.readouterr()
    np.testing.assert_allclose(read_recording(out).samples, signed.recording.samples, rtol=0, atol=1e-12)
    assert main(["import", str(tmp_path / "signed.csv"), "--out", str(tmp_path / "neg.nc"), "--time", "time",
                 "--units", "deg/s,g", "--scale", "-16.4,-2048"]) == 2
    assert "--scale '-16.4,-2048': '-16.4' for channel gx; expected a positive number" in capsys.readouterr().err
    # so is a --columns list whose first channel is reversed (the sensor-fusion MPU-6050 logs': -gyro_x first)
    write_synthetic(tmp_path / "reversed.csv", t, counts * np.r_[-1.0, 1, 1, 1, 1, 1])
    assert main(["import", str(tmp_path / "reversed.csv"), "--out", str(tmp_path / "rev.nc"), "--time", "time",
                 "--units", "deg/s,g", "--scale", "16.4,2048", "--columns", "-gx,gy,gz,ax,ay,az"]) == 0
    capsys.readouterr()
    np.testing.assert_allclose(read_recording(tmp_path / "rev.nc").samples, signed.recording.samples, rtol=0,
                               atol=1e-12)
    # an option after --columns is still an option
    with pytest.raises(SystemExit) as stop:
        main(["import", str(tmp_path / "reversed.csv"), "--out", str(tmp_path / "rev2.nc"), "--columns", "--time",
              "time"])
    assert stop.value.code == 2 and "--columns: expected one argument" in capsys.readouterr().err


def test_simulated_recording_times_are_the_nominal_ones():
    # the test logs above are built from this clock: global time, settle times included
    recording = simulated_log(settle=10.0)
    assert np.array_equal(recording.time, nominal_time(recording.schedule))


def test_a_commented_header_and_ns_timestamps_as_euroc_writes_them(tmp_path):
    """EuRoC / TUM-VI / Kalibr write '#timestamp [ns],w_RS_S_x [rad s^-1],…' with epoch nanoseconds: the commented
    header names the columns, and 1.4e18 ns read as float64 keep the sample period to 256 ns (2.6e-5 of 10 ms)."""
    t, x = synthetic_log()
    names = ["w_RS_S_x [rad s^-1]", "w_RS_S_y [rad s^-1]", "w_RS_S_z [rad s^-1]", "a_RS_S_x [m s^-2]",
             "a_RS_S_y [m s^-2]", "a_RS_S_z [m s^-2]"]
    stamps = 1403636579758555392 + np.round(t * 1e9).astype(np.int64)
    lines = ["#timestamp [ns]," + ",".join(names)]
    lines += [f"{s}," + ",".join(f"{v:.12g}" for v in row) for s, row in zip(stamps, x)]
    (tmp_path / "data.csv").write_text("\n".join(lines) + "\n")
    result = import_log(tmp_path / "data.csv", columns=tuple(names), time_column="timestamp [ns]", time_unit="ns")
    assert result.timing.sample_rate == pytest.approx(100.0, rel=1e-6)
    assert [s.test for s in result.recording.schedule.segments] == ["static", "rotation", "static"]
    assert result.table.header_line == 1 and not result.table.preamble
    # the time column named as the header line reads, '#' and all, is the same column
    same = import_log(tmp_path / "data.csv", columns=tuple(names), time_column="#timestamp [ns]", time_unit="ns")
    np.testing.assert_array_equal(same.recording.samples, result.recording.samples)
    np.testing.assert_array_equal(same.recording.time, result.recording.time)


def test_semicolons_and_decimal_commas_as_a_spreadsheet_exports_them(tmp_path, capsys):
    """A log exported by a spreadsheet in a locale with decimal commas: 'time;gx;…' and '0,01;0,0052;…'. The values
    are those of the same log written with points; with commas as separators a decimal comma cannot be, and a bad
    value is still refused naming its line and column."""
    t, x = synthetic_log()
    write_synthetic(tmp_path / "points.csv", t, x)
    text = (tmp_path / "points.csv").read_text().replace(",", ";").replace(".", ",")
    (tmp_path / "commas.csv").write_text(text)
    a = import_log(tmp_path / "points.csv", time_column="time")
    b = import_log(tmp_path / "commas.csv", time_column="time")
    np.testing.assert_array_equal(a.recording.samples, b.recording.samples)
    assert b.table.decimal_comma and not a.table.decimal_comma
    assert main(["import", str(tmp_path / "commas.csv"), "--out", str(tmp_path / "r.nc"), "--time", "time"]) == 0
    assert "decimal comma" in capsys.readouterr().out
    bad = text.splitlines()
    bad[5] = bad[5].replace(";", ";x", 1)
    (tmp_path / "bad.csv").write_text("\n".join(bad) + "\n")
    with pytest.raises(ValueError, match="line 6; expected a number"):
        import_log(tmp_path / "bad.csv", time_column="time")


def test_space_separated_and_headerless_logs_as_imu_tk_and_matlab_write_them(tmp_path, capsys):
    """imu_tk's logs and MATLAB's ``save -ascii`` separate columns by runs of spaces, and often write no header:
    a space-separated log with a header reads as the comma one; a headerless one is named by column position (1
    for the first), here in imu_tk's order time, ax, ay, az, gx, gy, gz, and gives the same samples. Without
    --columns a headerless log is refused with how to name its columns; a lone numeric line of a logger's preamble
    ("2024 11 27") is not taken for the first sample."""
    t, x = synthetic_log()
    write_synthetic(tmp_path / "commas.csv", t, x)
    reference = import_log(tmp_path / "commas.csv", time_column="time")
    rows = [f"  {a:.12g}   " + "  ".join(f"{v:.12g}" for v in r) for a, r in zip(t, x)]
    (tmp_path / "spaces.txt").write_text("time   gx gy gz  ax ay az\n" + "\n".join(rows) + "\n")
    spaced = import_log(tmp_path / "spaces.txt", time_column="time")
    np.testing.assert_array_equal(spaced.recording.samples, reference.recording.samples)
    assert spaced.table.has_header and spaced.table.header_line == 1

    acc_first = np.column_stack([t, x[:, 3:], x[:, :3]])
    np.savetxt(tmp_path / "imu_tk.txt", acc_first, fmt="%.12g")  # space-separated, no header
    headerless = import_log(tmp_path / "imu_tk.txt", columns=("5", "6", "7", "2", "3", "4"), time_column="1")
    np.testing.assert_array_equal(headerless.recording.samples, reference.recording.samples)
    assert not headerless.table.has_header and headerless.table.first_line == 1
    assert headerless.recording.schedule.segments == reference.recording.schedule.segments
    assert main(["import", str(tmp_path / "imu_tk.txt"), "--out", str(tmp_path / "r.nc"), "--columns",
                 "5,6,7,2,3,4", "--time", "1"]) == 0
    assert "no header line: columns named by position" in capsys.readouterr().out
    with pytest.raises(ValueError, match=r"column 'gx' is missing: the log has no header line \(line 1 is its first "
                                         r"sample, 7 columns\); name the columns by their position"):
        import_log(tmp_path / "imu_tk.txt", sample_rate=100.0)

    text = (tmp_path / "imu_tk.txt").read_text()
    (tmp_path / "dated.txt").write_text("IMU log\n2024 11 27\n" + text)
    dated = import_log(tmp_path / "dated.txt", columns=("5", "6", "7", "2", "3", "4"), time_column="1")
    np.testing.assert_array_equal(dated.recording.samples, reference.recording.samples)
    assert dated.table.preamble == ("IMU log", "2024 11 27") and dated.table.first_line == 3
    (tmp_path / "dated_header.csv").write_text("2024,11,27\n" + (tmp_path / "commas.csv").read_text())
    with_header = import_log(tmp_path / "dated_header.csv", time_column="time")
    np.testing.assert_array_equal(with_header.recording.samples, reference.recording.samples)
    assert with_header.table.preamble == ("2024,11,27",) and with_header.table.header_line == 2


def test_many_tilted_poses_are_one_warning_that_lists_them(tmp_path):
    """A hand-held session of poses spread over the sphere (plansim.simulate.hand_session, 12 poses): every pose more
    than 15° from every axis is 'unknown' and listed, in one tilted_pose warning rather than one per pose; a log
    with a few such poses (at most TILTED_LISTED_APART) gets one warning each."""
    from plansim.io.log_import import TILTED_LISTED_APART
    from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

    s = hand_session(consumer_unit(3), spread_poses(12, seed=3), seed=3, gravity=9.80, gyro_noise=8.7e-4,
                     accel_noise=9.8e-3, rest=4.0, move=3.0)
    log = tmp_path / "hand.csv"
    write_synthetic(log, s.time, np.array(s.samples))
    result = import_log(log, time_column="time")
    unknown = [span for span in result.segmentation.spans if span.kind == "static" and span.orientation == "unknown"]
    tilted = [w for w in result.warnings if w.name == "tilted_pose"]
    assert len(unknown) > TILTED_LISTED_APART
    assert len(tilted) == 1 and tilted[0].message.startswith(f"{len(unknown)} of the ")
    assert len(re.findall(r"deg from [+-][xyz]\)", tilted[0].message)) == len(unknown)
    # the first three poses alone: a warning each
    cut = int(round(3 * 7.0 * 100.0)) - 150
    write_synthetic(log, s.time[:cut], np.array(s.samples)[:cut])
    few = import_log(log, time_column="time")
    unknown = [span for span in few.segmentation.spans if span.kind == "static" and span.orientation == "unknown"]
    assert len([w for w in few.warnings if w.name == "tilted_pose"]) == len(unknown) <= TILTED_LISTED_APART


def test_a_shake_at_the_rail_is_one_saturated_warning_in_counts(tmp_path):
    """A 6 Hz shake on x clipped at the 16-bit rail hits it once per swing: one warning for the episode, its
    rail in counts and in SI."""
    t, x = synthetic_log(seconds_rest=6.0)
    n_turn = 200
    k = np.arange(n_turn)
    x[600:600 + n_turn, 3] += 25.0 * np.sin(2 * np.pi * 6.0 * k / 100.0) * np.sin(np.pi * k / n_turn) ** 2
    counts = np.clip(np.round(x / np.r_[[math.radians(1 / 16.4)] * 3, [9.80665 / 16384] * 3]), -32768, 32767)
    write_synthetic(tmp_path / "log.csv", t, counts)
    result = import_log(tmp_path / "log.csv", time_column="time", units="deg/s,g", scale="16.4,16384")
    stretches = [s for s in result.segmentation.saturation if s.channel == 3]
    assert len(stretches) > 2
    saturated = [w.message for w in result.warnings if w.name == "saturated"]
    assert len(saturated) == 1 and f"in {len(stretches)} stretches" in saturated[0]
    assert all("counts (" in m and "m/s^2)" in m for m in saturated)


def _rate_table_log(rates_deg_s, scale: float, seed: int, rest_s: float = 6.0, ramp_s: float = 1.0,
                    steady_s: float = 5.0, fs: float = 100.0, table_rate: bool = False):
    """A rate-table log about z (up), written here without plansim's simulator: rests of *rest_s* between turns
    that spin up linearly over *ramp_s*, hold each rate for *steady_s* and stop as they started. The table's rate
    is exact (its jitter is far below the gyro's noise: the turn is as quiet as a rest); the z gyro reads *scale*
    times it plus a bias of 0.2 deg/s; white noise 0.05 deg/s and 0.005 m/s^2 per sample. Returns time and samples
    (gyros in deg/s), and with *table_rate* the table's rate too (deg/s)."""
    rng = np.random.default_rng(seed)
    ramp = np.linspace(0.0, 1.0, int(ramp_s * fs), endpoint=False)
    rest = np.zeros(int(rest_s * fs))
    profile = [rest]
    for rate in rates_deg_s:
        profile += [rate * ramp, np.full(int(steady_s * fs), float(rate)), rate * ramp[::-1], rest]
    rate = np.concatenate(profile)
    x = np.zeros((rate.size, 6))
    x[:, 2] = scale * rate + 0.2
    x[:, :3] += 0.05 * rng.standard_normal((rate.size, 3))
    x[:, 5] = 9.80
    x[:, 3:] += 0.005 * rng.standard_normal((rate.size, 3))
    if table_rate:
        return np.arange(rate.size) / fs, x, rate
    return np.arange(rate.size) / fs, x


def test_a_rate_table_log_is_fitted_once_the_table_rates_are_given(tmp_path, capsys):
    """A user's rate-table log: rests between turns at +-63 and +-100 deg/s with their spin-ups and stops (whole
    turns of +-441 and +-700 deg). Before: the quietest stretch, a steady turn (a table's rate jitter is below the
    gyro's noise), was taken for the rest, every rest for a turn, and the import found one pose; and a 441 deg turn
    was labelled 450 deg (within 10 deg + 5 %), 2 % off. Now each steady part is a rotation with its measured rate and
    no angle, the user fills in the rates the table held, and `plansim fit` gives the z gyro's scale factor within
    its stated uncertainty (|z| < 3.3, a 0.1 % two-sided test), the table's rate errors in it, and leaves the other
    38 parameters not identified."""
    rates = [63, -63, 100, -100]
    scale = 1.003
    t, x = _rate_table_log(rates, scale, seed=21)
    log = tmp_path / "table.csv"
    write_synthetic(log, t, x)
    rec = tmp_path / "rec.csv"
    assert main(["import", str(log), "--out", str(rec), "--time", "time", "--units", "deg/s,m/s^2"]) == 0
    out = capsys.readouterr().out
    assert "give the table's rate" in out and "give each one the rate the table held" in out
    recording = read_recording(rec)
    tests = [s.test for s in recording.schedule.segments]
    assert tests == ["static"] + ["move", "rotation", "move", "static"] * len(rates)
    steady = [s for s in recording.schedule.segments if s.test == "rotation"]
    assert all(not s.rate_known and not s.angle_known and s.rate_axis == "+z" for s in steady)
    # the user fills in the table's rates, both columns of the pair
    table = rec.with_name("rec.segments.csv")
    lines = table.read_text(encoding="utf-8").splitlines()
    header = lines[1].split(",")
    given = iter(rates)
    rows = list(csv.reader(io.StringIO("\n".join(lines[1:]))))
    for row in rows[1:]:
        if row[header.index("test")] == "rotation":
            rate = next(given)
            row[header.index("rate_deg_s")], row[header.index("rate_rad_s")] = str(rate), repr(math.radians(rate))
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows(rows)
    table.write_text(lines[0] + "\n" + buffer.getvalue(), encoding="utf-8")
    assert main(["fit", str(rec), "--latitude", "40", "--height", "50", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["identified"] == ["Kgzz"]
    # the rates are the table's: its rate errors (JJF 2003 Table 1) are in u, its position errors are not (the unit
    # was placed on it by hand)
    assert "its rate errors only" in report["turntable"]
    kgzz = {p["name"]: p for p in report["parameters"]}["Kgzz"]
    assert abs(kgzz["estimate"] - scale) < 3.3 * kgzz["u"], kgzz
    assert kgzz["u"] < 1e-4


def test_a_table_rate_column_gives_each_steady_turn_its_rate(tmp_path, capsys):
    """The rate-table log above with the table's rate logged beside the IMU (its controller's rate, jittering by
    0.001 deg/s), the table's positive sense the body's negative (the unit mounted upside down on it):
    ``--table-rate-column`` gives each steady turn the column's mean over the segment, signed as the gyros measured
    the turn, with a note on the sense, and `plansim fit` gives the z gyro's scale factor within its u with the
    segment table as imported. The same column read in the wrong unit (rad/s as deg/s) disagrees with the gyros by
    57 times: the rates are left not known, with a warning naming the turns."""
    rates = [63, -63, 100, -100]
    scale = 1.003
    t, x, rate = _rate_table_log(rates, scale, seed=22, table_rate=True)
    column = -rate + 0.001 * np.random.default_rng(5).standard_normal(rate.size)
    log = tmp_path / "table.csv"
    write_synthetic(log, t, x, extra={"table_dps": column})
    rec = tmp_path / "rec.nc"
    assert main(["import", str(log), "--out", str(rec), "--time", "time", "--units", "deg/s,m/s^2", "--columns",
                 "gx,gy,gz,ax,ay,az", "--table-rate-column", "table_dps"]) == 0
    out = capsys.readouterr().out
    assert "rate from the table's rate column 'table_dps'" in out and "for 4 of 4" in out
    assert "give each one the rate the table held" not in out and "warning [table_rate_sense]" in out
    recording = read_recording(rec)
    steady = [s for s in recording.schedule.segments if s.test == "rotation"]
    assert [math.degrees(s.rate) for s in steady] == pytest.approx(rates, abs=1e-3)
    # the recording says which table columns the log held, under the keys the fit reads
    assert {key: recording.schedule.import_notes[key] for key in TABLE_COLUMN_NOTES} == {
        "table_rate_column": "table_dps", "table_angle_column": None}
    assert main(["fit", str(rec), "--latitude", "40", "--height", "50", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["identified"] == ["Kgzz"]
    kgzz = {p["name"]: p for p in report["parameters"]}["Kgzz"]
    assert abs(kgzz["estimate"] - scale) < 3.3 * kgzz["u"], kgzz
    # the column in rad/s read as deg/s: 57 times off, the rates left to the user
    write_synthetic(log, t, x, extra={"table_dps": np.radians(column)})
    assert main(["import", str(log), "--out", str(tmp_path / "wrong.nc"), "--time", "time", "--units",
                 "deg/s,m/s^2", "--columns", "gx,gy,gz,ax,ay,az", "--table-rate-column", "table_dps"]) == 0
    out = capsys.readouterr().out
    assert "warning [table_rate_disagrees]: 4 steady turn(s)" in out and "give each one the rate" in out
    wrong = read_recording(tmp_path / "wrong.nc")
    assert all(not s.rate_known for s in wrong.schedule.segments if s.test == "rotation")
    # bad input names the option
    assert main(["import", str(log), "--out", str(tmp_path / "x.nc"), "--time", "time", "--columns",
                 "gx,gy,gz,ax,ay,az", "--table-rate-column", "table_dps", "--table-rate-unit", "rpm"]) == 2
    assert "--table-rate-unit 'rpm'" in capsys.readouterr().err
    assert main(["import", str(log), "--out", str(tmp_path / "x.nc"), "--time", "time", "--columns",
                 "gx,gy,gz,ax,ay,az", "--table-rate-column", "encoder"]) == 2
    assert "column 'encoder' is missing" in capsys.readouterr().err
    assert not (tmp_path / "x.nc").exists()


@pytest.mark.parametrize("column", [True, False])
def test_a_log_recorded_over_each_dwell_only_keeps_its_steady_turns(tmp_path, capsys, column):
    """A rate test logged as a lab's acquisition often logs it: over each dwell only, the table's changes of rate
    not logged (a 3 s gap in the time column before each dwell). The dwells, 8 s each: at rest with -z up, then
    with +z up about the vertical z at -100, -50, -5, 0, +5, +50, +100 deg/s (the unit turned over in the first
    gap). Before: every motion between two rests that held a gap was one move, 'not integrated', steady turns and
    all, so the rate points were lost (a JJF 2003 run logged so lost its 24 rate points); and a steady turn took
    the pose of the rest before it, so the three after the -z rest read as turns about a horizontal axis that the
    fit does not use. Now each steady turn is split out as before, in its own pose, the gaps fall in moves of their
    own, and with the table's rate column (or the rates given by hand) `plansim fit` uses all six turns and gives
    Kgzz within its u (|z| < 3.3)."""
    fs, dwell = 100.0, int(8 * 100)
    rates = [0, -100, -50, -5, 0, 5, 50, 100]
    rng = np.random.default_rng(41)
    rate = np.repeat(np.array(rates, dtype=float), dwell)
    x = np.zeros((rate.size, 6))
    x[:, 2] = 1.003 * rate + 0.2
    x[:, :3] += 0.05 * rng.standard_normal((rate.size, 3))
    x[:, 5] = 9.80
    x[:dwell, 5] = -9.80  # the first rest with -z up
    x[:, 3:] += 0.005 * rng.standard_normal((rate.size, 3))
    t = np.arange(rate.size) / fs + 3.0 * (np.arange(rate.size) // dwell)  # a 3 s gap before each dwell
    log = tmp_path / "dwells.csv"
    write_synthetic(log, t, x, extra={"table_dps": rate})
    options = ["--time", "time", "--units", "deg/s,m/s^2", "--columns", "gx,gy,gz,ax,ay,az"]
    rec = tmp_path / "rec.nc"
    assert main(["import", str(log), "--out", str(rec), *options]
                + (["--table-rate-column", "table_dps"] if column else [])) == 0
    out = capsys.readouterr().out
    assert "warning [gap]: 7 gap(s)" in out, out
    recording = read_recording(rec)
    segments = recording.schedule.segments
    assert [s.test for s in segments if s.test != "move"] == ["static"] + ["rotation"] * 3 + ["static"] + \
        ["rotation"] * 3, [s.label for s in segments]
    turns = [k for k, s in enumerate(segments) if s.test == "rotation"]
    assert all(segments[k].samples > 0.85 * dwell for k in turns)  # each dwell whole, less a window at its ends
    assert [s.up for s in segments if s.test != "move"] == ["-z"] + ["+z"] * 7
    if not column:  # the rates given by hand, as the summary asks
        schedule = dataclasses.replace(recording.schedule, segments=tuple(
            dataclasses.replace(s, rate=math.radians(r)) if s.test == "rotation" else s
            for s, r in zip(segments, _rates_in_order(segments, [-100, -50, -5, 5, 50, 100]))))
        recording = dataclasses.replace(recording, schedule=schedule)
        write_recording(recording, rec)
    assert [round(math.degrees(s.rate), 6) for s in read_recording(rec).schedule.segments if s.test == "rotation"] \
        == [-100, -50, -5, 5, 50, 100]
    assert main(["fit", str(rec), "--latitude", "40", "--height", "50", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(turns) <= {r["segment"] for r in report["residuals"]}  # every turn fitted
    kgzz = {p["name"]: p for p in report["parameters"]}["Kgzz"]
    assert abs(kgzz["estimate"] - 1.003) < 3.3 * kgzz["u"], kgzz


def test_a_table_rate_column_cuts_a_quiet_run_where_the_table_changes_rate(tmp_path, capsys):
    """A rate table that changes rate slowly (0.5 deg/s^2: 10 s from rest to 5 deg/s) is as quiet as its steady
    turns, so rest, ramp and turn were one quiet run: with the table's rate column, a 76 s 'steady turn' at
    -2.16 deg/s held -5 deg/s, the ramp, the rest at 0 and part of the next ramp (a JJF 2003 run logged with its
    changes of rate). Step 5b cuts each quiet run where the table's rate changes: the rests and the turns at -5 and
    +5 deg/s come out whole, each turn with the table's rate, and the ramps are moves."""
    fs = 100.0
    ramp = np.linspace(0.0, 1.0, int(10 * fs), endpoint=False)
    dwell = np.ones(int(20 * fs))
    profile = np.concatenate([0 * dwell, -5 * ramp, -5 * dwell, -5 * ramp[::-1], 0 * dwell, 5 * ramp, 5 * dwell,
                              5 * ramp[::-1], 0 * dwell])
    rng = np.random.default_rng(43)
    x = np.zeros((profile.size, 6))
    x[:, 2] = 1.003 * profile + 0.2
    x[:, :3] += 0.05 * rng.standard_normal((profile.size, 3))
    x[:, 5] = 9.80
    x[:, 3:] += 0.005 * rng.standard_normal((profile.size, 3))
    log = tmp_path / "ramps.csv"
    write_synthetic(log, np.arange(profile.size) / fs, x, extra={"table_dps": profile})
    assert main(["import", str(log), "--out", str(tmp_path / "rec.nc"), "--time", "time", "--units", "deg/s,m/s^2",
                 "--columns", "gx,gy,gz,ax,ay,az", "--table-rate-column", "table_dps"]) == 0
    capsys.readouterr()
    segments = read_recording(tmp_path / "rec.nc").schedule.segments
    kept = [s for s in segments if s.test != "move"]
    assert [s.test for s in kept] == ["static", "rotation", "static", "rotation", "static"], [s.label for s in kept]
    # the column's mean over each turn's samples (a few of the next ramp's are in it: 5 - 1e-4)
    assert [math.degrees(s.rate) for s in kept if s.test == "rotation"] == pytest.approx([-5.0, 5.0], abs=1e-3)
    assert all(s.dwell > 19.0 for s in kept)


def _rates_in_order(segments, rates):
    """Each segment's rate: the next of *rates* for each rotation, None for the others."""
    given = iter(rates)
    return [next(given) if s.test == "rotation" else None for s in segments]


def test_a_table_rate_column_reads_a_one_pose_log_that_starts_and_ends_in_a_turn(tmp_path, capsys):
    """A log in one pose (+z up) that starts and ends in the same steady turn: 40 s at +3 deg/s, a 1 s stop, a 20 s
    rest, a 1 s spin-up, 40 s at +3 deg/s. From the IMU alone it is ambiguous: the turns hold more of the log and
    the log's two ends agree, so the turn is taken for the rest (a 3 deg/s bias, with the
    rest_turning_about_vertical warning) and the rest for a turn. With the table's rate column, the table decides
    step 6: the rest is the one static pose, the gyro bias is its own (0.2 deg/s), and both ends are rotations with
    the column's rate."""
    fs = 100.0
    ramp = np.linspace(0.0, 1.0, int(fs), endpoint=False)
    profile = np.concatenate([np.full(int(40 * fs), 3.0), 3.0 * ramp[::-1], np.zeros(int(20 * fs)), 3.0 * ramp,
                              np.full(int(40 * fs), 3.0)])
    rng = np.random.default_rng(23)
    x = np.zeros((profile.size, 6))
    x[:, 2] = profile + 0.2
    x[:, :3] += 0.05 * rng.standard_normal((profile.size, 3))
    x[:, 5] = 9.80
    x[:, 3:] += 0.005 * rng.standard_normal((profile.size, 3))
    t = np.arange(profile.size) / fs
    log = tmp_path / "turning.csv"
    write_synthetic(log, t, x, extra={"table_dps": profile})
    options = ["--time", "time", "--units", "deg/s,m/s^2", "--columns", "gx,gy,gz,ax,ay,az"]
    assert main(["import", str(log), "--out", str(tmp_path / "alone.nc"), *options]) == 0
    out = capsys.readouterr().out
    assert "warning [rest_turning_about_vertical]" in out  # the IMU alone: the turn taken for the rest
    assert main(["import", str(log), "--out", str(tmp_path / "rec.nc"), *options, "--table-rate-column",
                 "table_dps"]) == 0
    out = capsys.readouterr().out
    assert "rest_turning_about_vertical" not in out and "table_turning_at_rest" not in out
    recording = read_recording(tmp_path / "rec.nc")
    tests = [s.test for s in recording.schedule.segments]
    assert tests == ["rotation", "move", "static", "move", "rotation"], tests
    static = recording.segment_samples(2)
    assert np.degrees(static[:, 2].mean()) == pytest.approx(0.2, abs=0.01)  # 2000 samples of 0.05 deg/s: 0.001
    ends = [recording.schedule.segments[k] for k in (0, 4)]
    # each the column's mean over its own samples (a few of the stop or spin-up's are in the segment: 3 - 1e-4)
    column = [profile[first:first + s.samples].mean() for first, s in zip(recording.first_sample[[0, 4]], ends)]
    assert [math.degrees(s.rate) for s in ends] == pytest.approx(column, rel=1e-12)
    assert column == pytest.approx([3.0, 3.0], abs=1e-3) and all(s.rate_axis == "+z" for s in ends)


def _indexed_turns_log(turns_deg, seed: int, fs: float = 100.0, scale: float = 1.003):
    """A table's indexing log about z (up), written here without plansim's simulator: 6 s rests between turns by
    *turns_deg* that spin up linearly over 1 s, hold their peak for 0.3 s (no steady turn: step 9 does not split
    them) and stop as they started; then a steady turn at 50 deg/s for 8 s between the same ramps. The z gyro reads
    *scale* times the table's rate plus 0.2 deg/s; white noise 0.05 deg/s and 0.005 m/s^2 per sample. Returns time,
    samples (gyros in deg/s), the table's rate (deg/s) and its angle at each sample (deg, the angle turned before
    it), and each turn's whole angle (deg)."""
    ramp = np.linspace(0.0, 1.0, int(fs), endpoint=False)

    def turn(angle, hold):
        peak = angle / (1.0 + hold)
        return np.concatenate([peak * ramp, np.full(int(round(hold * fs)), peak), peak * ramp[::-1]])

    rest = np.zeros(int(6 * fs))
    pieces = [rest]
    for angle in turns_deg:
        pieces += [turn(angle, 0.3), rest]
    pieces += [turn(50.0 * 9.0, 8.0), rest]
    rate = np.concatenate(pieces)
    rng = np.random.default_rng(seed)
    x = np.zeros((rate.size, 6))
    x[:, 2] = scale * rate + 0.2
    x[:, :3] += 0.05 * rng.standard_normal((rate.size, 3))
    x[:, 5] = 9.80
    x[:, 3:] += 0.005 * rng.standard_normal((rate.size, 3))
    angle = np.concatenate(([0.0], np.cumsum(rate[:-1]) / fs))
    whole = [float(np.sum(turn(a, 0.3)) / fs) for a in turns_deg]
    return np.arange(rate.size) / fs, x, rate, angle, whole


@pytest.mark.parametrize("column", ["angle", "rate"])
def test_a_table_angle_or_rate_column_gives_each_turn_between_rests_its_angle(tmp_path, capsys, column):
    """A table indexing about the vertical by 45, -30, 405, 90 and -567 deg (each with its 1 s spin-up and stop,
    no steady part), then a steady turn at 50 deg/s, the table's encoder logged beside the IMU (wrapping at 360 deg,
    0.0001 deg resolution) or its rate. From the IMU alone only the nearest quarter turn is a reference: 45, -30 and
    405 deg are moves, and the -567 deg turn is taken for -540 deg (within 10 deg + 5 %), 4 % off. With the table's
    column each turn between two rests takes the table's own angle over it (step 8), whatever it is: within the
    encoder's resolution of the turn made (the rate column's integral is the angle exactly), signed as the gyros
    measured; the steady turn gets its rate from the angle's change per sample; and `plansim fit` gives the z
    gyro's scale factor within its stated u (|z| < 3.3, a 0.1 % two-sided test) with the segment table as
    imported."""
    turns = [45, -30, 405, 90, -567]
    t, x, rate, angle, whole = _indexed_turns_log(turns, seed=31)
    encoder = np.round((angle + 123.0) % 360.0, 4)
    log = tmp_path / "table.csv"
    write_synthetic(log, t, x, extra={"table": encoder if column == "angle" else rate})
    options = ["--time", "time", "--units", "deg/s,m/s^2", "--columns", "gx,gy,gz,ax,ay,az"]
    assert main(["import", str(log), "--out", str(tmp_path / "alone.nc"), *options]) == 0
    capsys.readouterr()
    alone = [s for s in read_recording(tmp_path / "alone.nc").schedule.segments if s.test != "static"]
    assert [s.test for s in alone[:5]] == ["move", "move", "move", "rotation", "rotation"], [s.label for s in alone]
    assert math.degrees(alone[4].angle) == pytest.approx(-540.0)
    assert main(["import", str(log), "--out", str(tmp_path / "rec.nc"), *options, f"--table-{column}-column",
                 "table"]) == 0
    out = capsys.readouterr().out
    assert "angle = the table's turn from rest to rest" in out and "for 5 of 5" in out, out
    assert "warning [table" not in out, out
    recording = read_recording(tmp_path / "rec.nc")
    rotations = [s for s in recording.schedule.segments if s.test == "rotation"]
    assert len(rotations) == 6
    assert [math.degrees(s.angle) for s in rotations[:5]] == pytest.approx(whole, abs=1e-3)
    assert all(math.isnan(s.rate) for s in rotations[:5]) and math.isnan(rotations[5].angle)
    assert math.degrees(rotations[5].rate) == pytest.approx(50.0, abs=1e-3)
    assert main(["fit", str(tmp_path / "rec.nc"), "--latitude", "40", "--height", "50", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["identified"] == ["Kgzz"]
    kgzz = {p["name"]: p for p in report["parameters"]}["Kgzz"]
    assert abs(kgzz["estimate"] - 1.003) < 3.3 * kgzz["u"], kgzz


@pytest.mark.parametrize("layout", ["gyros faster", "accelerometers faster", "interleaved"])
def test_a_table_column_in_the_gyro_log_is_paired_with_its_outputs(tmp_path, layout):
    """The indexing log of the test above (turns of 45, -30, 405, 90 and -567 deg, then a steady 50 deg/s), the
    encoder's wrapping angle logged in the gyros' file and the accelerometers in a file of their own
    (``--accel-log``), or each sensor in rows of its own in one file, the encoder on every row. Gyros at 200 Hz and
    accelerometers at 100 Hz stamped half-way between two gyro samples: each accelerometer sample is kept with the
    mean of the two gyro samples and of their two encoder readings, so the encoder must be unwrapped before it is
    averaged (a mean of 359.99 and 0.01 deg is 180 deg). The other way round, and interleaved: the gyro samples are
    kept with their own readings. Each turn between two rests takes the table's angle over it, within the
    encoder's resolution of the turn made, and the steady turn the angle's change per sample, as in one file."""
    turns = [45, -30, 405, 90, -567]
    fast = 200.0 if layout == "gyros faster" else 100.0
    t, x, rate, angle, whole = _indexed_turns_log(turns, seed=33, fs=fast)
    encoder = np.round((angle + 123.0) % 360.0, 4)
    gyro, accel = tmp_path / "gyro.csv", tmp_path / "accel.csv"
    if layout == "gyros faster":  # the accelerometers at half the rate, each the mean of two samples
        write_synthetic(gyro, t, x[:, :3], names=("gx", "gy", "gz"), extra={"enc": encoder})
        write_synthetic(accel, t[0::2] + 0.5 / fast, 0.5 * (x[0::2, 3:] + x[1::2, 3:]), names=("ax", "ay", "az"))
    elif layout == "accelerometers faster":  # at twice the rate, 2.5 ms either side of each gyro sample
        write_synthetic(gyro, t, x[:, :3], names=("gx", "gy", "gz"), extra={"enc": encoder})
        write_synthetic(accel, np.column_stack([t - 0.0025, t + 0.0025]).ravel(), np.repeat(x[:, 3:], 2, axis=0),
                        names=("ax", "ay", "az"))
    else:
        blank = np.full((t.size, 3), np.nan)
        rows = np.concatenate([np.column_stack([t, x[:, :3], blank, encoder]),
                               np.column_stack([t + 0.0025, blank, x[:, 3:], encoder])])
        rows = rows[np.argsort(rows[:, 0], kind="stable")]
        text = "\n".join(",".join("" if math.isnan(v) else f"{v:.12g}" for v in row) for row in rows)
        gyro.write_text("time,gx,gy,gz,ax,ay,az,enc\n" + text + "\n")
    second = {} if layout == "interleaved" else {"accel_log": accel}
    imported = import_log(gyro, time_column="time", units="deg/s,m/s^2", columns=("gx", "gy", "gz", "ax", "ay", "az"),
                          table_angle_column="enc", **second)
    assert not [w for w in imported.warnings if w.name.startswith("table")], imported.warnings
    rotations = [s for s in imported.recording.schedule.segments if s.test == "rotation"]
    assert len(rotations) == 6
    assert [math.degrees(s.angle) for s in rotations[:5]] == pytest.approx(whole, abs=1e-3)
    assert math.degrees(rotations[5].rate) == pytest.approx(50.0, abs=1e-3)
    if layout != "interleaved":  # the column looked for in the gyros' log, and the error says so
        with pytest.raises(ValueError, match=r"column 'enc\.x' is missing.*read from the gyros' log, LOG"):
            import_log(gyro, time_column="time", units="deg/s,m/s^2", columns=("gx", "gy", "gz", "ax", "ay", "az"),
                       table_angle_column="enc.x", **second)


@pytest.mark.parametrize("turns", [[90], [90, 90]])
def test_a_turn_by_the_tables_angle_carries_its_angle_error_at_each_rest(tmp_path, turns):
    """Poses placed by hand, the table's encoder logged, every turn fitted by the table's angle (the indexing log
    above, cut before its steady turn). The table's angle at each rest is off by e (its position accuracy, here
    given as a normal u = 10″ and 1°), so a turn by A from rest a to rest b is off by e_b − e_a, and Kgzz, fitted
    through the mean rate A/T, by Kgzz·(e_b − e_a)/A: the fit's table share of u(Kgzz) is √2·u·Kgzz/|A| for one
    turn of 90°. Two turns of 90° share the rest between them, so their errors telescope: √2·u·Kgzz/180° (not
    the 1/√2 of one turn's that independent turns would give). Equal to these closed forms within 0.1 %."""
    t, x, rate, angle, whole = _indexed_turns_log(turns, seed=34)
    k = int(round((6.0 + len(turns) * (2.6 + 6.0)) * 100))
    log = tmp_path / "short.csv"
    write_synthetic(log, t[:k], x[:k], extra={"enc": angle[:k]})
    recording = import_log(log, time_column="time", units="deg/s,m/s^2", table_angle_column="enc").recording
    assert sum(s.test == "rotation" for s in recording.schedule.segments) == len(turns)
    kgzz = PARAMETER_INDEX["Kgzz"]
    for u in (math.radians(10.0 / 3600.0), math.radians(1.0)):
        grade = dataclasses.replace(TABLE_1_TURNTABLE, position_accuracy=ErrorDistribution("normal", u),
                                    position_repeatability=ErrorDistribution("normal", 0.0))
        fit = fit_recording(recording, resolve_site(40.0, 50.0), grade, "the lab's table")
        assert "its angle errors only" in fit.turntable_source, fit.turntable_source
        estimate = fit.joint.estimate[kgzz]
        expected = math.sqrt(2.0) * u * estimate / math.radians(abs(sum(whole)))
        assert fit.joint.contributions["table"][kgzz] == pytest.approx(expected, rel=1e-3)


def test_a_table_angle_column_in_the_wrong_unit_or_not_finite_is_named(tmp_path, capsys):
    """The encoder's column in rad read as deg (the default unit): the table turns 57 times less than the gyros
    measure, so the turns it reads beyond 1 deg are moves, named in one warning (``table_turn_not_a_rotation``);
    read with ``--table-angle-unit rad`` they are rotations. A unit that is no angle and a NaN in the column are
    refused, naming the option or the line."""
    t, x, rate, angle, whole = _indexed_turns_log([90, -180], seed=32)
    log = tmp_path / "table.csv"
    write_synthetic(log, t, x, extra={"enc": np.radians(angle)})
    options = ["--time", "time", "--units", "deg/s,m/s^2", "--columns", "gx,gy,gz,ax,ay,az", "--table-angle-column",
               "enc"]
    assert main(["import", str(log), "--out", str(tmp_path / "wrong.nc"), *options]) == 0
    out = capsys.readouterr().out
    assert "warning [table_turn_not_a_rotation]: 2 motion(s)" in out and "more than 10% apart" in out, out
    assert main(["import", str(log), "--out", str(tmp_path / "rec.nc"), *options, "--table-angle-unit", "rad"]) == 0
    capsys.readouterr()
    rotations = [s for s in read_recording(tmp_path / "rec.nc").schedule.segments if s.test == "rotation"]
    assert [math.degrees(s.angle) for s in rotations[:2]] == pytest.approx(whole, abs=1e-6)
    # the log cut before its steady turn: every turn by the table's angle, whose errors the fit does not know
    k = int(round((6.0 + 2 * (2.6 + 6.0)) * 100))
    write_synthetic(tmp_path / "short.csv", t[:k], x[:k], extra={"enc": np.radians(angle[:k])})
    assert main(["import", str(tmp_path / "short.csv"), "--out", str(tmp_path / "short.nc"), *options,
                 "--table-angle-unit", "rad"]) == 0
    capsys.readouterr()
    assert main(["fit", str(tmp_path / "short.nc"), "--latitude", "40", "--height", "50", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert "its angle errors only (the turns' angles are the table's column 'enc'" in report["turntable"], \
        report["turntable"]
    with pytest.raises(ValueError, match=r"--table-angle-unit 'deg/s': allowed: rad, deg"):
        import_log(log, time_column="time", units="deg/s,m/s^2", table_angle_column="enc", table_angle_unit="deg/s")
    column = np.radians(angle)
    column[700] = np.nan
    write_synthetic(log, t, x, extra={"enc": column})
    with pytest.raises(ValueError, match="enc"):
        import_log(log, time_column="time", units="deg/s,m/s^2", table_angle_column="enc")


def _write_sensor_log(path: Path, time_s: np.ndarray, values: np.ndarray, unit: str) -> None:
    """One sensor's log as phyphox and the phone sensor loggers write it: a time column and three axes, quoted."""
    header = ",".join(f'"{name}"' for name in ("Time (s)", f"X ({unit})", f"Y ({unit})", f"Z ({unit})"))
    np.savetxt(path, np.column_stack([time_s, values]), delimiter=",", header=header, comments="", fmt="%.17g")


def test_gyros_and_accelerometers_logged_in_two_files_are_paired_by_time(tmp_path, capsys):
    """A phone app's two files (phyphox: Gyroscope.csv, Accelerometer.csv, 'Time (s)' and 'X (rad/s)' … in each).
    The accelerometer log runs at twice the rate, its samples 2.5 ms either side of the gyro's, reading the
    accelerometers' true output plus and minus a random d; it starts 0.5 s before the gyro log and stops 0.3 s
    before it. The gyro log is the slower: each of its samples takes the mean of the two accelerometer samples in its
    interval (half-way to its neighbours), which is the recording's own output (d cancels: every sample of the
    faster log is used once, none picked over another), and the last 0.3 s of gyro samples, with no accelerometer
    sample within a period (5 ms), are dropped. The result is cut into the segments the one-file log gives. Then
    the other way round (the gyros faster, the accelerometer log kept), row by row without time columns, and the
    errors."""
    recording = simulated_log()
    t, x = recording.time, recording.samples
    n = t.size
    rng = np.random.default_rng(5)
    columns = ["--columns", "X (rad/s),Y (rad/s),Z (rad/s),X (m/s^2),Y (m/s^2),Z (m/s^2)", "--time", "Time (s)"]
    cut = n - 30  # the accelerometer log stops 0.3 s before the gyro log
    one = tmp_path / "one.csv"
    np.savetxt(one, np.column_stack([t, x])[:cut], delimiter=",", header="time,gx,gy,gz,ax,ay,az", comments="",
               fmt="%.17g")
    reference = import_log(one, time_column="time")
    lead = np.arange(-50, 0) * 0.005 - 0.0075  # and starts 0.5 s before it
    d = rng.normal(scale=0.01, size=(n, 3))
    t_acc = np.concatenate([lead, np.column_stack([t - 0.0025, t + 0.0025])[:cut].ravel()])
    acc = np.concatenate([np.tile(x[0, 3:], (50, 1)), np.stack([x[:, 3:] + d, x[:, 3:] - d], axis=1)[:cut]
                          .reshape(-1, 3)])
    _write_sensor_log(tmp_path / "Gyroscope.csv", t, x[:, :3], "rad/s")
    _write_sensor_log(tmp_path / "Accelerometer.csv", t_acc, acc, "m/s^2")
    out = tmp_path / "rec.nc"
    assert main(["import", str(tmp_path / "Gyroscope.csv"), "--accel-log", str(tmp_path / "Accelerometer.csv"),
                 "--out", str(out), *columns]) == 0
    text = capsys.readouterr().out
    assert "two logs: gyros from Gyroscope.csv (100 Hz), accelerometers from Accelerometer.csv (200 Hz)" in text
    assert ("each sample of Gyroscope.csv (the slower log, whose lines are given) takes the mean of the samples of "
            "Accelerometer.csv in its interval (2 to 2, 2 on average)") in text
    assert "30 sample(s) of Gyroscope.csv had no sample of Accelerometer.csv" in text
    rec = read_recording(out)
    np.testing.assert_array_equal(rec.samples[:, :3], x[:cut, :3])
    np.testing.assert_allclose(rec.samples[:, 3:], x[:cut, 3:], rtol=0, atol=1e-14)
    np.testing.assert_allclose(rec.time, t[:cut], atol=1e-9)
    assert rec.attrs["imported_from"] == "Gyroscope.csv (gyros), Accelerometer.csv (accelerometers)"
    assert [(s.test, s.up) for s in rec.schedule.segments] == [
        (s.test, s.up) for s in reference.recording.schedule.segments]
    assert rec.schedule.notes["import"]["accel_log"] == "Accelerometer.csv"

    # the gyros twice as fast: the accelerometer log is kept (its lines are the ones given), and each of its samples
    # takes the mean of two gyro samples, so the angle the gyros integrate over a turn is kept whole
    _write_sensor_log(tmp_path / "g2.csv", np.column_stack([t - 0.0025, t + 0.0025]).ravel(),
                      np.stack([x[:, :3] + 1e-3, x[:, :3] - 1e-3], axis=1).reshape(-1, 3), "rad/s")
    _write_sensor_log(tmp_path / "a2.csv", t, x[:, 3:], "m/s^2")
    both = import_log(tmp_path / "g2.csv", accel_log=tmp_path / "a2.csv", columns=tuple(columns[1].split(",")),
                      time_column="Time (s)")
    np.testing.assert_allclose(both.recording.samples, x, rtol=0, atol=1e-14)
    assert both.table.path.name == "a2.csv" and both.table.lines[0] == 2
    assert "each sample of a2.csv (the slower log" in both.table.pairing[0]
    # a temperature column in the gyro log follows the kept (accelerometer) samples: the mean over the gyro samples
    # paired with each, as their outputs are
    g2 = (tmp_path / "g2.csv").read_text().splitlines()
    g2t = [g2[0] + ',"Temp (C)"'] + [f"{line},{25.0 + 0.001 * k!r}" for k, line in enumerate(g2[1:])]
    (tmp_path / "g2t.csv").write_text("\n".join(g2t) + "\n")
    warm = import_log(tmp_path / "g2t.csv", accel_log=tmp_path / "a2.csv", columns=tuple(columns[1].split(",")),
                      time_column="Time (s)", temperature_column="Temp (C)")
    assert warm.table.temperature.shape == (n,)
    np.testing.assert_allclose(warm.table.temperature, 25.0 + 0.001 * (np.arange(0, 2 * n, 2) + 0.5), atol=1e-12)

    # no time columns: paired row by row (imu_tk's two files, sampled together), with --sample-rate
    for name, values in (("g3.csv", x[:, :3]), ("a3.csv", x[:, 3:])):
        np.savetxt(tmp_path / name, values, fmt="%.17g")
    rows = import_log(tmp_path / "g3.csv", accel_log=tmp_path / "a3.csv", columns=("1", "2", "3", "1", "2", "3"),
                      sample_rate=100.0)
    np.testing.assert_array_equal(rows.recording.samples, x)
    assert "paired row by row" in rows.table.pairing[0]

    # errors name what is wrong
    np.savetxt(tmp_path / "a4.csv", x[:-5, 3:], fmt="%.17g")
    with pytest.raises(ValueError, match="has 7800 samples and the accelerometer log .a4.csv. 7795"):
        import_log(tmp_path / "g3.csv", accel_log=tmp_path / "a4.csv", columns=("1", "2", "3", "1", "2", "3"),
                   sample_rate=100.0)
    _write_sensor_log(tmp_path / "late.csv", t + 1000.0, x[:, 3:], "m/s^2")
    with pytest.raises(ValueError, match="do not overlap in time"):
        import_log(tmp_path / "Gyroscope.csv", accel_log=tmp_path / "late.csv", columns=tuple(columns[1].split(",")),
                   time_column="Time (s)")
    backwards = t.copy()
    backwards[400] = backwards[398]
    _write_sensor_log(tmp_path / "back.csv", backwards, x[:, 3:], "m/s^2")
    with pytest.raises(ValueError, match="accelerometer log .*back.csv.* goes backwards at line 402"):
        import_log(tmp_path / "Gyroscope.csv", accel_log=tmp_path / "back.csv", columns=tuple(columns[1].split(",")),
                   time_column="Time (s)")
    with pytest.raises(ValueError, match="5 names; expected 6, the gyro log's three"):
        import_log(tmp_path / "Gyroscope.csv", accel_log=tmp_path / "a2.csv", columns=("a", "b", "c", "d", "e"),
                   time_column="Time (s)")


def test_two_sensors_sampled_apart_in_rows_of_their_own_in_one_file(tmp_path, capsys):
    """One file, each sensor's samples in rows of their own as they came, the other sensor's three columns left
    empty (a logger that writes every sample the moment it arrives): the rows are split by sensor and paired as two
    files are (test above). The gyros at 100 Hz, the accelerometers at 200 Hz 2.5 ms either side reading the output
    plus and minus d: the recording's own samples come back. A row with one channel of a triad empty is not such a
    row, and is refused naming its line; without a time column the rows cannot be paired."""
    recording = simulated_log()
    t, x = recording.time, recording.samples
    n = t.size
    d = np.random.default_rng(6).normal(scale=0.01, size=(n, 3))
    def text(values):
        return ",".join("" if math.isnan(v) else repr(float(v)) for v in values)

    blank = np.full(3, math.nan)
    rows = [(float(tk), text([tk, *g, *blank])) for tk, g in zip(t, x[:, :3])]
    for sign, offset in ((1.0, -0.0025), (-1.0, 0.0025)):
        rows += [(float(tk + offset), text([tk + offset, *blank, *a])) for tk, a in zip(t, x[:, 3:] + sign * d)]
    rows.sort()
    log = tmp_path / "interleaved.csv"
    log.write_text("time,gx,gy,gz,ax,ay,az\n" + "\n".join(text for _, text in rows) + "\n")
    out = tmp_path / "rec.nc"
    assert main(["import", str(log), "--time", "time", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert ("two logs: gyros from interleaved.csv (100 Hz), accelerometers from interleaved.csv (200 Hz): each sample "
            "of interleaved.csv (the slower log") in printed and "(2 to 2, 2 on average)" in printed
    rec = read_recording(out)
    np.testing.assert_array_equal(rec.samples[:, :3], x[:, :3])
    np.testing.assert_allclose(rec.samples[:, 3:], x[:, 3:], rtol=0, atol=1e-14)
    # the gyro rows' lines are the ones given: the first is line 3 (line 2 is an accelerometer's, 2.5 ms before it)
    lines = log.read_text().splitlines()
    assert ",,,," in lines[1] and lines[2].endswith(",,,")
    assert import_log(log, time_column="time").table.lines[:3].tolist() == [3, 6, 9]

    broken = lines[:40] + [lines[40].rsplit(",", 1)[0] + ","] + lines[41:]
    assert broken[40].endswith(",") and not broken[40].endswith(",,,")  # az left empty, ax and ay not
    (tmp_path / "broken.csv").write_text("\n".join(broken) + "\n")
    with pytest.raises(ValueError, match="column '(ax|ay|az|gx|gy|gz)' is '' at line 41"):
        import_log(tmp_path / "broken.csv", time_column="time")
    (tmp_path / "no_time.csv").write_text("gx,gy,gz,ax,ay,az\n" + "\n".join(line.split(",", 1)[1] for line in
                                                                          lines[1:]) + "\n")
    with pytest.raises(ValueError, match="paired by time, so the log needs its time column"):
        import_log(tmp_path / "no_time.csv", sample_rate=300.0)


def test_units_the_log_writes_are_read_and_checked(tmp_path, capsys):
    """WitMotion writes 'AsX(°/s)' and 'AccX(g)', phyphox 'X (rad/s)', EuRoC 'w_RS_S_x [rad s^-1]': without --units
    those units are taken (the log in deg/s and g imports as the SI log does), and with --units that differ the
    channels are read in --units under a named warning, naming each channel. A row of units is read the same way;
    a partial declaration (one channel without a unit) is not guessed from."""
    t, x = synthetic_log()
    write_synthetic(tmp_path / "si.csv", t, x)
    reference = import_log(tmp_path / "si.csv", time_column="time")
    wit = np.column_stack([np.degrees(x[:, :3]), x[:, 3:] / STANDARD_GRAVITY])
    names = ("AsX(°/s)", "AsY(°/s)", "AsZ(°/s)", "AccX(g)", "AccY(g)", "AccZ(g)")
    write_synthetic(tmp_path / "wit.csv", t, wit, names=names)
    columns = ["--columns", ",".join(names), "--time", "time"]
    assert main(["import", str(tmp_path / "wit.csv"), "--out", str(tmp_path / "wit.nc"), *columns]) == 0
    printed = capsys.readouterr().out
    assert "(deg/s, g, as the log's header writes them)" in printed
    rec = read_recording(tmp_path / "wit.nc")
    np.testing.assert_allclose(rec.samples, reference.recording.samples, rtol=1e-10, atol=1e-15)  # printed to 12 digits
    assert rec.schedule.notes["import"]["units_source"] == "the log's header"
    # --units that differ: read in --units, and each differing channel named
    result = import_log(tmp_path / "wit.csv", columns=names, time_column="time", units="rad/s,g")
    warning = next(w for w in result.warnings if w.name == "units_disagree")
    assert "header writes gx in deg/s, gy in deg/s, gz in deg/s; --units says rad/s, rad/s, rad/s" in warning.message
    np.testing.assert_allclose(result.recording.samples[:, :3], wit[:, :3], rtol=1e-10)
    # a row of units under a plain header: read as the units
    text = (tmp_path / "wit.csv").read_text().splitlines()
    plain = ["time,gx,gy,gz,ax,ay,az", "s,deg/s,deg/s,deg/s,g,g,g", *text[1:]]
    (tmp_path / "row.csv").write_text("\n".join(plain) + "\n")
    result = import_log(tmp_path / "row.csv", time_column="time")
    np.testing.assert_allclose(result.recording.samples, reference.recording.samples, rtol=1e-10, atol=1e-15)
    assert "read as the channels' units" in next(w.message for w in result.warnings if w.name == "units_row")
    # one name without a unit: nothing is taken (the SI default), and the 1 g check refuses the log in g
    partial = ("AsX(°/s)", "AsY(°/s)", "AsZ", "AccX(g)", "AccY(g)", "AccZ(g)")
    write_synthetic(tmp_path / "partial.csv", t, wit, names=partial)
    with pytest.raises(ValueError, match="1 g"):
        import_log(tmp_path / "partial.csv", columns=partial, time_column="time")
