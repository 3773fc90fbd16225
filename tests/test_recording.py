"""Recordings: exact round trips through .nc and .csv, validation of damaged files, eq. (3) means."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
import xarray as xr

from plansim.io.recording import (
    CHANNELS,
    CSV_SAMPLE_COLUMNS,
    Recording,
    dataset_to_recording,
    nominal_time,
    read_recording,
    recording_to_dataset,
    segment_table_path,
    write_recording,
)
from plansim.runner import simulate_and_record
from plansim.schedule import Schedule, multi_position, rate_test


def tiny_schedule() -> Schedule:
    segments = list(multi_position(6, dwell=0.05, sample_rate=100))
    # a rate segment with an awkward rate and a different sample rate: deg <-> rad and mixed timing
    segments += rate_test([math.radians(10.0), -0.3], axes="y", dwell=0.03, sample_rate=200, settle=2.5)
    return Schedule(tuple(segments), procedure="tiny", notes={"purpose": "tests", "positions": [1, 2]})


def tiny_recording(seed: int = 0) -> Recording:
    schedule = tiny_schedule()
    rng = np.random.default_rng(seed)
    samples = rng.normal(size=(schedule.total_samples, 6)) * np.array([0.1, 0.1, 0.1, 9.8, 9.8, 9.8])
    attrs = {"plansim_version": "0.1.0", "scenario": "tiny", "seed": 2**40 + 3, "trial": 2,
             "source": "simulated", "units": "SI", "note": "label with, comma and \"quotes\" °"}
    return Recording(samples=samples, schedule=schedule, attrs=attrs)


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_round_trip_is_exact(tmp_path, suffix):
    recording = tiny_recording()
    path = tmp_path / f"run{suffix}"
    write_recording(recording, path)
    back = read_recording(path)
    assert back == recording
    assert back.timestamps is None
    assert np.array_equal(back.samples, recording.samples)
    assert back.schedule == recording.schedule
    assert back.schedule.procedure == "tiny" and back.schedule.notes == recording.schedule.notes
    assert back.attrs == recording.attrs and isinstance(back.attrs["seed"], int)
    expected_files = {"run.nc"} if suffix == ".nc" else {"run.csv", "run.segments.csv"}
    assert set(os.listdir(tmp_path)) == expected_files


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_measured_timestamps_survive(tmp_path, suffix):
    recording = tiny_recording()
    jitter = np.random.default_rng(5).uniform(0, 1e-4, recording.samples.shape[0])
    measured = Recording(recording.samples, recording.schedule, {"source": "measured"},
                         timestamps=nominal_time(recording.schedule) + jitter)
    write_recording(measured, tmp_path / f"lab{suffix}")
    back = read_recording(tmp_path / f"lab{suffix}")
    assert back == measured
    assert np.array_equal(back.time, measured.timestamps)


def test_time_convention_is_global_with_settle_times():
    recording = tiny_recording()
    schedule = recording.schedule
    time = recording.time
    first = recording.first_sample
    # first segment: its settle time, then one sample every 1/sample_rate
    assert time[0] == schedule.segments[0].settle
    assert np.allclose(np.diff(time[:5]), 0.01)
    # each later segment starts after the previous recording (samples / sample_rate) and its own settle time
    for k in range(1, len(schedule)):
        previous = schedule.segments[k - 1]
        expected = time[first[k - 1]] + previous.samples / previous.sample_rate + schedule.segments[k].settle
        assert time[first[k]] == pytest.approx(expected, abs=1e-12)
    assert recording.segment_index.tolist() == sum(([k] * s.samples for k, s in enumerate(schedule.segments)), [])


def test_segment_means_are_the_mean_of_each_segment():
    recording = tiny_recording(seed=3)
    means = recording.segment_means()
    assert means.shape == (len(recording.schedule), 6)
    for k in range(len(recording.schedule)):
        rows = recording.samples[recording.segment_index == k]
        np.testing.assert_allclose(means[k], rows.mean(axis=0), rtol=1e-14, atol=1e-15)


def test_dataset_has_units_and_long_names():
    dataset = recording_to_dataset(tiny_recording())
    assert set(dataset.sizes) == {"sample", "segment"}
    assert dataset["gx"].attrs["units"] == "rad/s" and dataset["az"].attrs["units"] == "m/s^2"
    assert dataset["heading"].attrs["units"] == "rad" and dataset["rate"].attrs["units"] == "rad/s"
    assert dataset["temperature"].attrs["units"] == "degC" and dataset["time"].attrs["units"] == "s"
    for name in dataset.variables:
        assert "long_name" in dataset[name].attrs, name
    assert dataset.attrs["source"] == "simulated"
    assert dataset_to_recording(dataset) == tiny_recording()


def test_bad_suffix_names_path_and_allowed(tmp_path):
    with pytest.raises(ValueError, match=r"run\.txt.*\.nc, \.csv"):
        write_recording(tiny_recording(), tmp_path / "run.txt")
    with pytest.raises(ValueError, match=r"\.nc, \.csv"):
        read_recording(tmp_path / "run.h5")
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_failed_write_leaves_nothing(tmp_path, suffix):
    with pytest.raises(ValueError, match="does not exist"):
        write_recording(tiny_recording(), tmp_path / "missing" / f"run{suffix}")
    assert os.listdir(tmp_path) == []


def test_csv_failure_in_the_second_file_leaves_neither(tmp_path, monkeypatch):
    import plansim.io.recording_csv as recording_csv_module

    def broken_writer(*args, **kwargs):
        raise OSError("disk full")

    # the segment table is written through csv.writer; break it after the samples are written
    monkeypatch.setattr(recording_csv_module.csv, "writer", broken_writer)
    with pytest.raises(OSError, match="disk full"):
        write_recording(tiny_recording(), tmp_path / "run.csv")
    assert os.listdir(tmp_path) == []


def write_csv_pair(tmp_path) -> tuple:
    path = tmp_path / "run.csv"
    write_recording(tiny_recording(), path)
    return path, segment_table_path(path)


def drop_csv_column(path, column: str) -> None:
    lines = path.read_text(encoding="utf-8").splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    names = lines[header].split(",")
    drop = names.index(column)
    # samples rows hold numbers only, so splitting on commas is safe for the samples file
    lines[header:] = [",".join(cell for j, cell in enumerate(line.split(",")) if j != drop) for line in lines[header:]]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


@pytest.mark.parametrize("column", ["gy_rad_s", "time_s", "segment"])
def test_csv_missing_sample_column(tmp_path, column):
    path, _ = write_csv_pair(tmp_path)
    drop_csv_column(path, column)
    with pytest.raises(ValueError, match=rf"run\.csv.*column '{column}' is missing"):
        read_recording(path)


def test_csv_missing_table_column(tmp_path):
    path, table = write_csv_pair(tmp_path)
    text = table.read_text(encoding="utf-8").replace(",dwell_s,", ",dwell,", 1)
    table.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match=r"run\.segments\.csv.*column 'dwell_s' is missing"):
        read_recording(path)


def test_csv_missing_table_file(tmp_path):
    path, table = write_csv_pair(tmp_path)
    table.unlink()
    with pytest.raises(ValueError, match=r"run\.segments\.csv.*does not exist"):
        read_recording(path)


def test_csv_nan_sample(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    lines = path.read_text(encoding="utf-8").splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    cells = lines[header + 4].split(",")
    cells[CSV_SAMPLE_COLUMNS.index("ax_m_s2")] = "nan"
    lines[header + 4] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ValueError, match=rf"run\.csv.*'ax_m_s2'.*nan at line {header + 5}.*finite.*m/s\^2"):
        read_recording(path)


def test_csv_text_in_sample(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    lines[-1] = lines[-1].rsplit(",", 1)[0] + ",oops"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"run\.csv.*must be a number"):
        read_recording(path)


def test_csv_wrong_sample_count(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    lines = path.read_text(encoding="utf-8").splitlines()
    path.write_text("\n".join(lines[:-1]) + "\n", encoding="utf-8")
    total = tiny_schedule().total_samples
    with pytest.raises(ValueError, match=rf"run\.csv.*{total - 1} samples.*expects {total}"):
        read_recording(path)


def test_csv_sample_in_the_wrong_segment(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    lines = path.read_text(encoding="utf-8").splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    cells = lines[header + 2].split(",")
    cells[CSV_SAMPLE_COLUMNS.index("segment")] = "1"
    lines[header + 2] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    data_line = header + 3  # 1-based line number of the damaged row
    with pytest.raises(ValueError, match=rf"column 'segment' is 1 at line {data_line}.*segment 0, which holds "
                                         rf"lines {header + 2} to {header + 6}"):
        read_recording(path)


def test_csv_table_nan_and_inconsistent_samples(tmp_path):
    path, table = write_csv_pair(tmp_path)
    original = table.read_text(encoding="utf-8")
    table.write_text(original.replace(",20.0,0,5", ",nan,0,5", 1), encoding="utf-8")
    with pytest.raises(ValueError, match=r"run\.segments\.csv.*'temperature_degc'.*'nan'.*finite number in degC"):
        read_recording(path)
    table.write_text(original.replace(",20.0,0,5", ",20.0,0,6", 1), encoding="utf-8")
    with pytest.raises(ValueError, match=r"segment 0.*'samples' = 6.*gives 5"):
        read_recording(path)


def test_csv_deg_columns_alone_are_enough_and_must_agree(tmp_path):
    path, table = write_csv_pair(tmp_path)
    lines = table.read_text(encoding="utf-8").splitlines()
    # a lab's table: degrees only, no comment line, no rad columns
    import csv
    import io

    rows = list(csv.reader(io.StringIO("\n".join(lines[1:]))))
    keep = [j for j, name in enumerate(rows[0]) if name not in ("heading_rad", "rate_rad_s")]
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows([[row[j] for j in keep] for row in rows])
    table.write_text(buffer.getvalue(), encoding="utf-8")
    back = read_recording(path)
    for read, written in zip(back.schedule.segments, tiny_schedule().segments):
        assert read.rate == pytest.approx(written.rate, rel=1e-15, abs=0)
        assert read.heading == pytest.approx(written.heading, rel=1e-15, abs=0)
    # deg and rad columns that contradict each other are an error, not a silent choice
    contradicting = "\n".join(lines).replace("10.0,0.17453292519943295", "11.0,0.17453292519943295")
    assert contradicting != "\n".join(lines)
    table.write_text(contradicting + "\n", encoding="utf-8")
    with pytest.raises(ValueError, match="rate_deg_s = 11.0 and rate_rad_s .* disagree"):
        read_recording(path)


def test_netcdf_missing_variable_and_nan(tmp_path):
    path = tmp_path / "run.nc"
    write_recording(tiny_recording(), path)
    dataset = xr.load_dataset(path, engine="scipy")
    dataset.drop_vars("gz").to_netcdf(tmp_path / "no_gz.nc", engine="scipy")
    with pytest.raises(ValueError, match=r"no_gz\.nc.*variable 'gz' is missing.*'sample'.*rad/s"):
        read_recording(tmp_path / "no_gz.nc")
    broken = dataset.copy(deep=True)
    broken["ay"].values[7] = np.nan
    broken.to_netcdf(tmp_path / "nan.nc", engine="scipy")
    with pytest.raises(ValueError, match=r"nan\.nc.*variable 'ay' is nan at sample 7.*finite"):
        read_recording(tmp_path / "nan.nc")
    broken = dataset.copy(deep=True)
    broken["heading"].attrs["units"] = "deg"
    broken.to_netcdf(tmp_path / "deg.nc", engine="scipy")
    with pytest.raises(ValueError, match=r"deg\.nc.*'heading' has units 'deg'; expected 'rad'"):
        read_recording(tmp_path / "deg.nc")


def test_netcdf_wrong_sample_count(tmp_path):
    path = tmp_path / "run.nc"
    write_recording(tiny_recording(), path)
    dataset = xr.load_dataset(path, engine="scipy").isel(sample=slice(0, -2))
    dataset.to_netcdf(tmp_path / "short.nc", engine="scipy")
    total = tiny_schedule().total_samples
    with pytest.raises(ValueError, match=rf"short\.nc.*{total - 2} samples.*expects {total}"):
        read_recording(tmp_path / "short.nc")


def test_reading_a_segment_table_as_the_recording_says_which_file(tmp_path):
    path, table = write_csv_pair(tmp_path)
    with pytest.raises(ValueError, match=r"segment table; give the samples file .*run\.csv"):
        read_recording(table)


def test_recording_validation():
    schedule = tiny_schedule()
    good = np.zeros((schedule.total_samples, 6))
    with pytest.raises(ValueError, match=r"shape \(3, 6\).*expects"):
        Recording(np.zeros((3, 6)), schedule)
    bad = good.copy()
    bad[4, 2] = np.inf
    with pytest.raises(ValueError, match="channel gz is inf at sample 4"):
        Recording(bad, schedule)
    with pytest.raises(ValueError, match="source.*allowed: simulated, measured"):
        Recording(good, schedule, {"source": "guessed"})
    with pytest.raises(ValueError, match="reserved"):
        Recording(good, schedule, {"format": "mine"})
    with pytest.raises(TypeError, match="expected str, int or float"):
        Recording(good, schedule, {"list": [1, 2]})
    with pytest.raises(TypeError, match="Schedule"):
        Recording(good, list(schedule.segments))


def test_simulate_and_record_matches_the_engine():
    from plansim.io.scenario_file import load_scenario
    from plansim.kernels.layout import CHANNELS as ENGINE_CHANNELS
    from plansim.simulate.chunks import simulate_recording

    assert CHANNELS == ENGINE_CHANNELS
    scenario = load_scenario("ideal")
    recording = simulate_and_record(scenario, seed=7, trial=1)
    samples, segment_means, _truth = simulate_recording(scenario, 7, 1)
    assert np.array_equal(recording.samples, samples)
    # the same running sum as the kernel: equal bit for bit, not just close
    assert np.array_equal(recording.segment_means(), segment_means)
    assert recording.attrs["source"] == "simulated" and recording.attrs["scenario"] == scenario.name
    assert recording.attrs["seed"] == 7 and recording.attrs["trial"] == 1
    assert recording.schedule is scenario.schedule


# ----------------------------------------------------------------------------- cut short, binary or garbled files


def test_csv_cut_inside_its_last_number_is_refused(tmp_path):
    """A copy that stopped mid-file: the last line keeps all its columns but loses the last number's final
    digits, so every count still agrees. Only the missing line end shows it."""
    path, _ = write_csv_pair(tmp_path)
    text = path.read_text(encoding="utf-8")
    assert text.endswith("\n")
    cut = text[:-4]  # the line end and three digits of the last az
    assert cut.rsplit("\n", 1)[1].count(",") == len(CSV_SAMPLE_COLUMNS) - 1
    path.write_text(cut, encoding="utf-8")
    lines = cut.count("\n") + 1
    with pytest.raises(ValueError, match=rf"run\.csv.*last line \(line {lines}\) does not end with a line break.*"
                                         r"cut short"):
        read_recording(path)


def test_csv_cut_inside_its_last_line_is_refused(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    text = path.read_text(encoding="utf-8")
    path.write_text(text[:text.rindex(",")], encoding="utf-8")  # the last row loses its last column
    with pytest.raises(ValueError, match=r"run\.csv.*(cut short|column)"):
        read_recording(path)


def test_segment_table_cut_at_its_end_is_refused(tmp_path):
    """Its last column (samples, 6) loses its line end: a cut there cannot be told from a complete row."""
    path, table = write_csv_pair(tmp_path)
    text = table.read_text(encoding="utf-8")
    table.write_text(text[:-1], encoding="utf-8")
    with pytest.raises(ValueError, match=r"run\.segments\.csv.*does not end with a line break"):
        read_recording(path)


def test_csv_without_a_final_line_end_but_complete_is_still_refused_with_the_fix(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    path.write_text(path.read_text(encoding="utf-8").rstrip("\n"), encoding="utf-8")
    with pytest.raises(ValueError, match=r"if the file is complete, end it with a line break"):
        read_recording(path)
    path.write_text(path.read_text(encoding="utf-8") + "\r\n", encoding="utf-8")  # CRLF line ends are fine
    assert read_recording(path) == tiny_recording()


def _png_bytes() -> bytes:
    return b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x01\x00\x00\x00\x01\x08\x02\x00\x00\x00" + bytes(32)


GARBLED = {
    "a PNG": _png_bytes(),
    "random bytes": np.random.default_rng(4).bytes(600),
    "UTF-16 text": ",".join(CSV_SAMPLE_COLUMNS).encode("utf-16") + "\n0,0,1,2,3,4,5,6\n".encode("utf-16-le"),
    "an empty file": b"",
    "NUL bytes": b"time_s,segment\x00\x00,gx\n",
}


@pytest.mark.parametrize("suffix", [".csv", ".nc"])
@pytest.mark.parametrize("data", list(GARBLED.values()), ids=list(GARBLED))
def test_a_garbled_recording_is_a_value_error_naming_the_file(tmp_path, data, suffix):
    path = tmp_path / f"lab{suffix}"
    path.write_bytes(data)
    if suffix == ".csv":
        write_recording(tiny_recording(), tmp_path / "good.csv")
        (tmp_path / "good.segments.csv").rename(tmp_path / "lab.segments.csv")
    with pytest.raises(ValueError, match=rf"recording file '.*lab\{suffix}'") as caught:
        read_recording(path)
    assert type(caught.value) is ValueError


def test_a_garbled_segment_table_is_a_value_error_naming_it(tmp_path):
    path, table = write_csv_pair(tmp_path)
    table.write_bytes(_png_bytes())
    with pytest.raises(ValueError, match=r"segment table '.*run\.segments\.csv'.*not UTF-8 text") as caught:
        read_recording(path)
    assert type(caught.value) is ValueError


def test_a_utf16_csv_says_so(tmp_path):
    path, _ = write_csv_pair(tmp_path)
    path.write_bytes(path.read_text(encoding="utf-8").encode("utf-16"))
    with pytest.raises(ValueError, match=r"run\.csv.*UTF-16 text.*save it as UTF-8"):
        read_recording(path)


def test_a_netcdf_cut_short_or_damaged_is_a_value_error_naming_the_file(tmp_path):
    """Every cut of a good file, and bytes flipped at random: never an IndexError, KeyError or struct.error."""
    good = tmp_path / "good.nc"
    write_recording(tiny_recording(), good)
    data = good.read_bytes()
    path = tmp_path / "lab.nc"
    rng = np.random.default_rng(11)
    damaged = [data[:cut] for cut in range(0, len(data), 97)]
    for _ in range(60):
        flipped = np.frombuffer(data, dtype=np.uint8).copy()
        flipped[rng.integers(0, 400, 4)] = rng.integers(0, 256, 4)  # the header: dimensions, names, types
        damaged.append(flipped.tobytes())
    for k, content in enumerate(damaged):
        path.write_bytes(content)
        try:
            read_recording(path)
        except ValueError as exc:
            assert type(exc) is ValueError and "lab.nc" in str(exc), (k, repr(exc))
