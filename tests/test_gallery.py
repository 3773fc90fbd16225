"""Every example of docs/gallery.md runs as it is and prints what the gallery says it shows.

The examples are run in this process (``runpy``, with their command-line arguments), small: the hand-held coverage
over 2 sessions, the bandwidth without its optional Monte Carlo but for 5 trials. What they print is checked
against what each claims, not against stored output: the hidden effect is named; the headerless log's poses
and moves are found and its gyro scale factors land within 5 u of the truth, and so do the phone logs' gyro and
accelerometer scale factors once paired; the data sheet the data contradict
is Ba's, and restated it holds, with Bax where the data alone had put it; the fitted curve reads the bandwidth to
1e-9 Hz where the chord is off by more than 0.5 Hz.
"""

from __future__ import annotations

import re
import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


def run_example(name: str, *args: str, capsys) -> str:
    argv = sys.argv
    sys.argv = [str(EXAMPLES / name), *args]
    try:
        runpy.run_path(str(EXAMPLES / name), run_name="__main__")
    finally:
        sys.argv = argv
    return capsys.readouterr().out


def test_every_example_is_in_the_gallery():
    page = (EXAMPLES.parent / "gallery.md").read_text(encoding="utf-8")
    for script in EXAMPLES.glob("*.py"):
        assert f"(examples/{script.name})" in page, f"{script.name} is not in docs/gallery.md"


def test_hidden_effect_is_named(capsys):
    out = run_example("hidden_effect.py", capsys=capsys)
    assert "named: gyro_scale_asymmetry" in out
    assert "Before and after" in out


def test_headerless_log_to_gyro_scale_factors(capsys):
    out = run_example("headerless_log.py", capsys=capsys)
    assert "found: 24 poses, 23 moves, 0 turns" in out
    rows = re.findall(r"(Kg\w\w): ([\d.]+) ± ([\d.]+) \(truth ([\d.]+)\)", out)
    assert len(rows) == 3
    for _name, estimate, u, truth in rows:
        assert abs(float(estimate) - float(truth)) <= 5 * float(u)


def test_phone_logs_are_paired_and_calibrated(capsys):
    out = run_example("phone_logs.py", capsys=capsys)
    assert "each sample of Gyroscope.csv (the slower log, whose lines are given) takes the mean of the samples" in out
    assert "found: 24 poses, 23 moves, 0 turns; units rad/s, m/s^2 from the header" in out
    rows = re.findall(r"(K[ga]\w\w): ([\d.]+) ± ([\d.]+) \(truth ([\d.]+)\)", out)
    assert len(rows) == 6
    for _name, estimate, u, truth in rows:
        assert abs(float(estimate) - float(truth)) <= 5 * float(u)


def test_data_sheet_conflict_names_ba_and_the_restated_data_sheet_holds(capsys):
    out = run_example("data_sheet_conflict.py", capsys=capsys)
    verdicts = re.findall(r"^contradicted: (.*)$", out, flags=re.M)
    assert verdicts == ["Ba", "none"], out
    alone = re.search(r"the data alone: Bax (-?[\d.]+) ± ([\d.]+) ug", out)
    fitted = re.findall(r"Bax = (-?[\d.]+) ± ([\d.]+) ug", out)
    assert alone and len(fitted) == 2, out
    # what the data alone said is what the fit gives once the data sheet no longer pulls, to the printed digits
    assert abs(float(alone[1]) - float(fitted[1][0])) <= 0.1 + 1e-9, out
    assert abs(float(fitted[0][0]) - float(alone[1])) > 10 * float(alone[2]), out  # the prior had pulled it


def test_bandwidth_chord_vs_curve(capsys):
    out = run_example("bandwidth_chord_vs_curve.py", "--trials", "5", capsys=capsys)
    rows = [line.split() for line in out.splitlines() if re.match(r"\s*\d\.\d\d\s", line)]
    assert len(rows) == 5
    assert all(abs(float(row[-1])) < 1e-9 for row in rows)  # the curve
    assert max(abs(float(row[-2])) for row in rows) > 0.5  # the chord
    assert "curve: bias" in out


@pytest.mark.parametrize("sessions", ["2"])
def test_hand_session_coverage_runs(capsys, sessions):
    out = run_example("hand_session_coverage.py", sessions, capsys=capsys)
    assert f"over {9 * int(sessions)} intervals" in out
