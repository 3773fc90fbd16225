"""Recording format version 2: what measured logs need (docs/recording.md).

Hand-placed poses (``orientation``, a heading not known), turns known by angle (``test = "rotation"``,
``angle``), a rate not logged (NaN), motion kept but unused (``move``), the site and a temperature channel.
Version-1 files (written by plansim before these fields existed) still read.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from plansim.io.recording import (
    FORMAT_VERSION,
    Recording,
    read_recording,
    recording_to_dataset,
    segment_table_path,
    write_recording,
)
from plansim.schedule import Schedule, Segment
from test_recording import tiny_recording

VERSION_1 = Path(__file__).resolve().parent / "data" / "recording_v1"


def measured_schedule() -> Schedule:
    common = dict(settle=0.0, sample_rate=50.0)
    return Schedule((
        Segment("static 1 +x up", "static", 0, "+x", heading=math.nan, orientation="approximate", dwell=0.1, **common),
        Segment("turn about x", "rotation", 0, "+x", heading=math.nan, rate=math.nan, angle=-2 * math.pi,
                orientation="approximate", dwell=0.08, **common),
        Segment("static 2 +x up", "static", 0, "+x", heading=math.nan, orientation="approximate", dwell=0.1, **common),
        Segment("table turn", "rotation", 2, "+z", rate=math.radians(10.0), rate_axis="+z", dwell=0.06, **common),
        Segment("move", "move", 0, "-y", heading=math.nan, rate=math.nan, orientation="unknown", dwell=0.04,
                **common),
        Segment("static 3 -y up", "static", 0, "-y", heading=0.5, orientation="unknown", dwell=0.1, **common),
    ), procedure="imported", notes={"detector": {"window_s": 0.5}})


def measured_recording(temperature: bool = True) -> Recording:
    schedule = measured_schedule()
    rng = np.random.default_rng(11)
    m = schedule.total_samples
    samples = rng.normal(size=(m, 6))
    time = 1.7e9 + np.cumsum(rng.uniform(0.019, 0.021, m))
    attrs = {"source": "measured", "site_latitude_deg": 49.6, "site_height_m": 280.0, "operator": "J. Doe"}
    return Recording(samples, schedule, attrs, timestamps=time,
                     temperature=(24.0 + rng.normal(size=m) * 0.1) if temperature else None)


def test_written_files_say_version_2():
    assert FORMAT_VERSION == 2
    assert recording_to_dataset(tiny_recording()).attrs["format_version"] == 2


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_version_1_files_still_read(suffix):
    """Files written by plansim's format version 1 (before orientation, angle, temperature channel)."""
    back = read_recording(VERSION_1 / f"tiny{suffix}")
    assert back == tiny_recording()
    assert all(s.orientation == "known" and math.isnan(s.angle) for s in back.schedule.segments)
    assert back.temperature is None


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
@pytest.mark.parametrize("temperature", [True, False])
def test_measured_fields_round_trip_exactly(tmp_path, suffix, temperature):
    recording = measured_recording(temperature)
    write_recording(recording, tmp_path / f"lab{suffix}")
    back = read_recording(tmp_path / f"lab{suffix}")
    assert back == recording
    segments = back.schedule.segments
    assert [s.orientation for s in segments] == ["approximate"] * 3 + ["known", "unknown", "unknown"]
    assert not segments[0].heading_known and segments[5].heading == 0.5
    assert segments[1].angle == -2 * math.pi and not segments[1].rate_known and segments[1].is_rotating
    assert segments[3].rate == math.radians(10.0) and not segments[3].angle_known
    assert back.attrs["site_latitude_deg"] == 49.6 and back.attrs["site_height_m"] == 280.0
    assert (back.temperature is None) == (not temperature)
    if temperature:
        assert np.array_equal(back.temperature, recording.temperature)


def test_csv_table_shows_angle_and_orientation_and_deg_alone_reads(tmp_path):
    path = tmp_path / "lab.csv"
    write_recording(measured_recording(), path)
    table = segment_table_path(path)
    text = table.read_text(encoding="utf-8")
    header = text.splitlines()[1].split(",")
    assert header[-3:] == ["orientation", "angle_deg", "angle_rad"]
    assert ",approximate,-360.0,-6.283185307179586" in text and ",nan,nan,+x," in text
    # a lab's table with only the degree column of the angle
    import csv
    import io

    rows = list(csv.reader(io.StringIO(text.split("\n", 1)[1])))
    drop = rows[0].index("angle_rad")
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows([row[:drop] + row[drop + 1:] for row in rows])
    table.write_text(buffer.getvalue(), encoding="utf-8")
    back = read_recording(path)
    assert back.schedule.segments[1].angle == pytest.approx(-2 * math.pi, rel=1e-15)
    assert math.isnan(back.schedule.segments[3].angle)


def test_a_lab_table_without_the_new_columns_reads_with_the_defaults(tmp_path):
    path = tmp_path / "run.csv"
    write_recording(tiny_recording(), path)
    table = segment_table_path(path)
    lines = table.read_text(encoding="utf-8").splitlines()
    cut = lines[1].split(",").index("orientation")
    import csv
    import io

    rows = list(csv.reader(io.StringIO("\n".join(lines[1:]))))
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows([row[:cut] for row in rows])
    table.write_text(buffer.getvalue(), encoding="utf-8")
    assert read_recording(path) == tiny_recording()


def test_csv_unknown_values_and_their_limits(tmp_path):
    path = tmp_path / "lab.csv"
    write_recording(measured_recording(), path)
    table = segment_table_path(path)
    original = table.read_text(encoding="utf-8")
    # an angle on a static segment is refused, naming the segment
    table.write_text(original.replace("approximate,nan,nan\n", "approximate,90.0,1.5707963267948966\n", 1),
                     encoding="utf-8")
    with pytest.raises(ValueError, match=r"segment 0: segment 'static 1 \+x up': angle = 1\.57.* only a 'rotation'"):
        read_recording(path)
    # infinity is never "not known"
    table.write_text(original.replace(",approximate,-360.0,-6.283185307179586",
                                      ",approximate,inf,-6.283185307179586", 1), encoding="utf-8")
    with pytest.raises(ValueError, match=r"'angle_deg' is 'inf' in segment row 1; expected a finite number in deg "
                                         r"or nan \(not known\)"):
        read_recording(path)
    # deg and rad of the angle must agree, NaN with NaN only
    table.write_text(original.replace(",approximate,-360.0,-6.283185307179586", ",approximate,nan,-6.283185307179586",
                                      1), encoding="utf-8")
    with pytest.raises(ValueError, match=r"angle_deg = nan and angle_rad = -6\.28.* disagree"):
        read_recording(path)
    # a heading not known: a hand-placed pose, or a table's pose whose heading was not logged (static, rotation)
    table.write_text(original.replace("approximate", "known", 1), encoding="utf-8")
    first = read_recording(path).schedule.segments[0]
    assert first.test == "static" and first.orientation == "known" and not first.heading_known
    # a JJF 2003 test's segment needs its heading, whatever its orientation says
    with pytest.raises(ValueError, match=r"segment 'p'.*heading = nan; a heading may be NaN \(not known\) only when "
                                         "orientation is 'approximate' or 'unknown', or in a 'static' or 'rotation'"):
        Segment("p", "multi_position", 1, "+z", heading=math.nan)
    table.write_text(original.replace("approximate", "roughly", 1), encoding="utf-8")
    with pytest.raises(ValueError, match="orientation = 'roughly'; allowed: known, approximate, unknown"):
        read_recording(path)
    # NaN stays refused where it always was: dwell, temperature
    table.write_text(original.replace(",24.0,", ",nan,", 1) if ",24.0," in original else original.replace(
        ",20.0,0,", ",nan,0,", 1), encoding="utf-8")
    with pytest.raises(ValueError, match="'temperature_degc'.*finite number in degC"):
        read_recording(path)


def test_csv_temperature_channel_must_be_finite(tmp_path):
    path = tmp_path / "lab.csv"
    write_recording(measured_recording(), path)
    lines = path.read_text(encoding="utf-8").splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    assert lines[header].endswith(",temperature_degc")
    lines[header + 4] = ",".join(lines[header + 4].split(",")[:-1] + ["nan"])
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ValueError, match=rf"column 'temperature_degc' is nan at line {header + 5}; every "
                                         "temperature must be a finite number in degC"):
        read_recording(path)


def test_netcdf_temperature_channel_and_version_checks(tmp_path):
    path = tmp_path / "lab.nc"
    write_recording(measured_recording(), path)
    dataset = xr.load_dataset(path, engine="scipy")
    assert dataset["sample_temperature"].attrs["units"] == "degC"
    assert dataset["angle"].attrs["units"] == "rad" and "orientation" in dataset
    broken = dataset.copy(deep=True)
    broken["sample_temperature"].values[3] = np.nan
    broken.to_netcdf(tmp_path / "nan.nc", engine="scipy")
    with pytest.raises(ValueError, match=r"variable 'sample_temperature' is nan at sample 3"):
        read_recording(tmp_path / "nan.nc")
    broken = dataset.copy(deep=True)
    broken["sample_temperature"].attrs["units"] = "K"
    broken.to_netcdf(tmp_path / "kelvin.nc", engine="scipy")
    with pytest.raises(ValueError, match=r"'sample_temperature' has units 'K'; expected 'degC'"):
        read_recording(tmp_path / "kelvin.nc")
    future = dataset.copy()
    future.attrs["format_version"] = 3
    future.to_netcdf(tmp_path / "future.nc", engine="scipy")
    with pytest.raises(ValueError, match="format_version = 3; this plansim reads versions 1, 2"):
        read_recording(tmp_path / "future.nc")


def test_segment_rules_for_unknown_values():
    base = dict(label="s", group=0, up="+z")
    with pytest.raises(ValueError, match="rate = 0.5 rad/s in a 'static' segment; it must be 0"):
        Segment(test="static", rate=0.5, **base)
    with pytest.raises(ValueError, match="rate = 0.0 in a 'rotation' segment; give the rate .* or NaN"):
        Segment(test="rotation", **base)
    with pytest.raises(ValueError, match="rate = nan; a rate may be NaN .* only in a 'rotation' or 'move'"):
        Segment(test="rate", rate=math.nan, **base)
    with pytest.raises(ValueError, match="angle = 3.14 rad in a 'static' segment; only a 'rotation'"):
        Segment(test="static", angle=3.14, **base)
    with pytest.raises(ValueError, match="heading = inf; it must be finite or NaN"):
        Segment(test="static", heading=math.inf, orientation="unknown", **base)
    with pytest.raises(ValueError, match="dwell = nan; it must be finite"):
        Segment(test="static", dwell=math.nan, **base)
    # NaN read from a file is a different object from math.nan: equal segments still compare (and hash) equal
    a = Segment(test="rotation", rate=float("nan"), angle=float("nan"), **base)
    b = Segment(test="rotation", rate=math.nan, **base)
    assert a == b and hash(a) == hash(b)
    # the defaults leave every existing segment as it was
    old = Segment(test="multi_position", **base)
    assert old.orientation == "known" and math.isnan(old.angle) and old.heading_known and old.rate_known


def test_site_attributes_are_checked():
    schedule = measured_schedule()
    samples = np.zeros((schedule.total_samples, 6))
    with pytest.raises(ValueError, match=r"attrs\['site_latitude_deg'\] = 95.0; expected a number from -90 to 90 deg"):
        Recording(samples, schedule, {"site_latitude_deg": 95.0})
    with pytest.raises(ValueError, match=r"attrs\['site_height_m'\] = '280 m'; expected a number"):
        Recording(samples, schedule, {"site_height_m": "280 m"})
    with pytest.raises(ValueError, match=r"site_height_m'\] = nan"):
        Recording(samples, schedule, {"site_height_m": math.nan})
    assert Recording(samples, schedule, {"site_latitude_deg": 50}).attrs["site_latitude_deg"] == 50.0
    with pytest.raises(ValueError, match=r"temperature: shape \(3,\); expected"):
        Recording(samples, schedule, temperature=np.zeros(3))
