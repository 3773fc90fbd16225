"""Recordings: the raw output of one calibration run, as a lab's data acquisition produces it.

A :class:`Recording` is the segment table (a :class:`~plansim.schedule.segments.Schedule`) plus every
raw sample of the six channels ``gx, gy, gz`` (rad/s) and ``ax, ay, az`` (m/s²), concatenated
segment by segment in schedule order, plus provenance attributes. Simulated recordings come from
:func:`plansim.runner.simulate_and_record`; measured ones are read with :func:`read_recording`. Both go through the
same validation, so a measured file that reads is one the rest of plansim can use.

Files (docs/recording.md describes every field):

- ``.nc`` — one NetCDF-3 file (xarray, ``engine="scipy"``): dimensions ``sample`` and ``segment``;
- ``.csv`` — two files: the samples at the given path and the segment table beside it at
  ``<stem>.segments.csv``.

Time convention: ``Recording.time`` is a *global* time axis in seconds from the start of the schedule
(the moment the table begins to settle into the first segment). Segment *s* starts recording after
every earlier segment's settle time and recording time plus its own settle time; its sample *k* is at
``start_s + k / sample_rate_s``. A segment records for ``samples / sample_rate`` seconds, which is
how the simulation kernel advances its drift processes (equal to ``dwell`` whenever
``dwell × sample_rate`` is a whole number). A measured recording may carry its own timestamps
instead (:attr:`Recording.timestamps`).
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

import numpy as np
import xarray as xr

from plansim.io.files import atomic_write
from plansim.kernels.layout import CHANNELS
from plansim.schedule.segments import Schedule, Segment
from plansim.units import DEG

CHANNEL_UNITS = {"gx": "rad/s", "gy": "rad/s", "gz": "rad/s", "ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2"}
CHANNEL_LONG_NAMES = {
    "gx": "angular rate output of the x gyro (body frame)",
    "gy": "angular rate output of the y gyro (body frame)",
    "gz": "angular rate output of the z gyro (body frame)",
    "ax": "specific force output of the x accelerometer (body frame)",
    "ay": "specific force output of the y accelerometer (body frame)",
    "az": "specific force output of the z accelerometer (body frame)",
}
CSV_CHANNEL_COLUMNS = ("gx_rad_s", "gy_rad_s", "gz_rad_s", "ax_m_s2", "ay_m_s2", "az_m_s2")
CSV_SAMPLE_COLUMNS = ("time_s", "segment") + CSV_CHANNEL_COLUMNS

SOURCES = ("simulated", "measured")
SUFFIXES = (".nc", ".csv")
SEGMENT_TABLE_SUFFIX = ".segments.csv"
FORMAT_NAME = "plansim-recording"
FORMAT_VERSION = 1
UNITS_DESCRIPTION = "SI: gx gy gz rad/s; ax ay az m/s^2; time s; heading rad; rate rad/s; temperature degC"

#: attributes the file formats use themselves; a recording's own attrs may not use these names
RESERVED_ATTRIBUTES = ("format", "format_version", "schedule_procedure", "schedule_notes",
                       "integer_text_attributes")

#: segment table: field -> (units or None for text, long name); the order of the NetCDF variables
SEGMENT_FIELDS: dict[str, tuple[str | None, str]] = {
    "label": (None, "segment label"),
    "test": (None, "JJF 2003 test that uses the segment: multi_position, rate or omega_squared"),
    "group": ("1", "group of the segment within its test (position group or rate-test axis)"),
    "up": (None, "body axis pointing up: +x, -x, +y, -y, +z or -z"),
    "heading": ("rad", "heading about the vertical, counter-clockwise seen from above"),
    "rate": ("rad/s", "table angular rate"),
    "rate_axis": (None, "body axis on the table rotation axis: +x, -x, +y, -y, +z or -z"),
    "dwell": ("s", "recording time requested for the segment"),
    "settle": ("s", "settling time before recording"),
    "sample_rate": ("Hz", "sample rate"),
    "temperature": ("degC", "temperature during the segment"),
    "first_sample": ("1", "index along sample of the segment's first sample"),
    "samples": ("1", "number of samples recorded in the segment"),
}
_TEXT_FIELDS = ("label", "test", "up", "rate_axis")
_INTEGER_FIELDS = ("group", "first_sample", "samples")
_FLOAT_FIELDS = ("heading", "rate", "dwell", "settle", "sample_rate", "temperature")

#: CSV segment table columns, in the order written
CSV_SEGMENT_COLUMNS = ("segment", "label", "test", "group", "up", "heading_deg", "heading_rad", "rate_deg_s",
                       "rate_rad_s", "rate_axis", "dwell_s", "settle_s", "sample_rate_hz", "temperature_degc",
                       "first_sample", "samples")
#: CSV column of each segment field that has a single column (heading and rate have a deg and a rad column)
_CSV_FIELD_COLUMNS = {"label": "label", "test": "test", "group": "group", "up": "up", "rate_axis": "rate_axis",
                      "dwell": "dwell_s", "settle": "settle_s", "sample_rate": "sample_rate_hz",
                      "temperature": "temperature_degc", "first_sample": "first_sample", "samples": "samples"}
#: heading and rate: (rad column, deg column); the rad column is exact, the deg column is for people
_CSV_ANGLE_COLUMNS = {"heading": ("heading_rad", "heading_deg"), "rate": ("rate_rad_s", "rate_deg_s")}
# how far the deg and rad columns may disagree before the file counts as contradictory: far above the
# rounding of a deg ↔ rad conversion (~1e-16 relative) and far below any table's resolution
_ANGLE_AGREEMENT = 1e-9

_NETCDF3_INT_MIN, _NETCDF3_INT_MAX = -(2**31), 2**31 - 1
_HEADER_ATTRIBUTE = re.compile(r"^#\s*([A-Za-z_][A-Za-z0-9_.\-]*)\s*:\s*(.*?)\s*$")


def plansim_version() -> str:
    """The installed plansim version, or ``"unknown"`` when it runs from a source tree not installed."""
    try:
        return metadata.version("plansim")
    except metadata.PackageNotFoundError:
        return "unknown"


def segment_first_samples(schedule: Schedule) -> np.ndarray:
    """Index of the first sample of each segment in the concatenated samples, shape (S,)."""
    counts = np.array([segment.samples for segment in schedule.segments], dtype=np.int64)
    return np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.int64)


def nominal_time(schedule: Schedule) -> np.ndarray:
    """Global time of every sample from the start of the schedule, s, shape (M,).

    Segment *s* starts recording at ``sum_{r<s} (settle_r + samples_r / sample_rate_r) + settle_s``
    and its sample *k* is at that start plus ``k / sample_rate_s`` (see the module docstring).
    """
    parts = []
    clock = 0.0
    for segment in schedule.segments:
        clock += segment.settle
        parts.append(clock + np.arange(segment.samples) / segment.sample_rate)
        clock += segment.samples / segment.sample_rate
    return np.concatenate(parts)


def _normalise_attribute(key: object, value: object) -> str | int | float:
    """Provenance values must survive both file formats: text, whole numbers and real numbers only."""
    if not isinstance(key, str):
        raise TypeError(f"recording attrs: key {key!r} must be a string")
    if key in RESERVED_ATTRIBUTES:
        raise ValueError(f"recording attrs: {key!r} is reserved by the file format; "
                         f"reserved: {', '.join(RESERVED_ATTRIBUTES)}")
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"recording attrs[{key!r}] = {value!r}: booleans do not survive NetCDF-3; "
                        "store a string or a number")
    if isinstance(value, str):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    raise TypeError(f"recording attrs[{key!r}] = {value!r} ({type(value).__name__}): expected str, int or float")


@dataclass(frozen=True, eq=False)
class Recording:
    """Raw samples of one calibration run and the schedule that produced them.

    Parameters
    ----------
    samples : (M, 6) array of float
        Channels ``gx, gy, gz`` (rad/s) and ``ax, ay, az`` (m/s²), segment after segment in schedule
        order; segment *s* contributes ``schedule.segments[s].samples`` rows. Every value is finite.
    schedule : Schedule
        The segment table.
    attrs : dict
        Provenance, values ``str``, ``int`` or ``float``: usually ``plansim_version``, ``scenario``,
        ``seed``, ``trial``, ``source`` (``"simulated"`` or ``"measured"``) and ``units``.
    timestamps : (M,) array of float or None
        Measured time of every sample on a global axis, s, non-decreasing; ``None`` (the default)
        means the nominal time computed from the schedule (:func:`nominal_time`).
    """

    samples: np.ndarray
    schedule: Schedule
    attrs: dict = field(default_factory=dict)
    timestamps: np.ndarray | None = None

    def __post_init__(self):
        if not isinstance(self.schedule, Schedule):
            raise TypeError(f"recording schedule: expected a plansim Schedule, got {type(self.schedule).__name__}")
        samples = np.asarray(self.samples)
        if samples.dtype.kind not in "iuf":
            raise TypeError(f"recording samples: expected real numbers, got dtype {samples.dtype}")
        samples = samples.astype(np.float64, copy=False)
        expected_rows = self.schedule.total_samples
        if samples.shape != (expected_rows, len(CHANNELS)):
            raise ValueError(f"recording samples: shape {samples.shape}; the schedule expects ({expected_rows}, 6): "
                             f"{expected_rows} samples (the sum of each segment's samples) × channels "
                             f"{', '.join(CHANNELS)}")
        bad = ~np.isfinite(samples)
        if bad.any():
            row, column = np.argwhere(bad)[0]
            raise ValueError(f"recording samples: channel {CHANNELS[column]} is {float(samples[row, column])!r} "
                             f"at sample {row}; every sample must be finite")
        if not isinstance(self.attrs, dict):
            raise TypeError(f"recording attrs: expected a dict, got {type(self.attrs).__name__}")
        attrs = {key: _normalise_attribute(key, value) for key, value in self.attrs.items()}
        source = attrs.get("source")
        if source is not None and source not in SOURCES:
            raise ValueError(f"recording attrs['source'] = {source!r}; allowed: {', '.join(SOURCES)}")
        timestamps = self.timestamps
        if timestamps is not None:
            timestamps = np.asarray(timestamps)
            if timestamps.dtype.kind not in "iuf":
                raise TypeError(f"recording timestamps: expected real numbers, got dtype {timestamps.dtype}")
            timestamps = timestamps.astype(np.float64, copy=False)
            _check_time(timestamps, expected_rows, "recording timestamps")
        object.__setattr__(self, "samples", samples)
        object.__setattr__(self, "attrs", attrs)
        object.__setattr__(self, "timestamps", timestamps)

    @property
    def time(self) -> np.ndarray:
        """Time of every sample, s, shape (M,): the timestamps if measured ones are given, else
        :func:`nominal_time` — a global axis from the start of the schedule, settle times included."""
        if self.timestamps is not None:
            return self.timestamps
        return nominal_time(self.schedule)

    @property
    def segment_index(self) -> np.ndarray:
        """Segment number (0-based, schedule order) of every sample, shape (M,)."""
        counts = [segment.samples for segment in self.schedule.segments]
        return np.repeat(np.arange(len(counts), dtype=np.int64), counts)

    @property
    def first_sample(self) -> np.ndarray:
        """Index of each segment's first sample, shape (S,)."""
        return segment_first_samples(self.schedule)

    def segment_samples(self, segment: int) -> np.ndarray:
        """The (n, 6) rows of segment number *segment* (a view, not a copy)."""
        count = len(self.schedule)
        if isinstance(segment, bool) or not isinstance(segment, (int, np.integer)) or not 0 <= segment < count:
            raise ValueError(f"segment = {segment!r}: expected a whole number from 0 to {count - 1}")
        start = int(self.first_sample[segment])
        return self.samples[start:start + self.schedule.segments[segment].samples]

    def segment_means(self) -> np.ndarray:
        """Mean output of every segment, (S, 6): ū = (1/N) Σ_k u_k over its N samples (JJF 2003 eq. (3))."""
        means = np.empty((len(self.schedule), len(CHANNELS)))
        for k, (first, segment) in enumerate(zip(self.first_sample, self.schedule.segments)):
            # a running sum in sample order, then one division: the kernel's arithmetic, so a simulated
            # recording gives bit for bit the means of the Monte Carlo path (numpy's pairwise sum would not)
            running = np.cumsum(self.samples[first:first + segment.samples], axis=0)
            means[k] = running[-1] / segment.samples
        return means

    def __eq__(self, other: object) -> bool:
        """Exact equality: same samples bit for bit, same schedule, attrs and timestamps."""
        if not isinstance(other, Recording):
            return NotImplemented
        if (self.timestamps is None) != (other.timestamps is None):
            return False
        return (self.schedule == other.schedule and self.attrs == other.attrs
                and np.array_equal(self.samples, other.samples)
                and (self.timestamps is None or np.array_equal(self.timestamps, other.timestamps)))

    __hash__ = None


def _check_time(time: np.ndarray, expected_rows: int, where: str) -> None:
    """A time axis must have one finite value per sample and never run backwards."""
    if time.shape != (expected_rows,):
        raise ValueError(f"{where}: shape {time.shape}; expected ({expected_rows},), one time per sample")
    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        raise ValueError(f"{where}: {float(time[bad[0]])!r} at sample {int(bad[0])}; every time must be finite (s)")
    backwards = np.flatnonzero(np.diff(time) < 0)
    if backwards.size:
        k = int(backwards[0]) + 1
        raise ValueError(f"{where}: time decreases at sample {k} ({float(time[k - 1])!r} s then "
                         f"{float(time[k])!r} s); expected a global time axis, never decreasing")


# ----------------------------------------------------------------------------- xarray


def _schedule_notes_text(schedule: Schedule) -> str:
    try:
        return json.dumps(schedule.notes)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"schedule.notes = {schedule.notes!r}: it must be JSON-serialisable to be stored in a "
                        f"recording ({exc})") from None


def recording_to_dataset(recording: Recording) -> xr.Dataset:
    """The recording as an :class:`xarray.Dataset` with dimensions ``sample`` and ``segment``.

    Variables over ``sample``: ``gx gy gz`` (rad/s), ``ax ay az`` (m/s^2); coordinates ``time`` (s, global
    axis) and ``segment_index``. Over ``segment``: the segment table (``label test group up heading rate
    rate_axis dwell settle sample_rate temperature first_sample samples``). Every variable has ``units``
    (numeric ones) and ``long_name`` attributes. Dataset attributes: the recording's ``attrs`` plus
    ``format``, ``format_version``, ``schedule_procedure`` and ``schedule_notes`` (JSON).
    """
    if not isinstance(recording, Recording):
        raise TypeError(f"recording: expected a plansim Recording, got {type(recording).__name__}")
    segments = recording.schedule.segments
    table = {
        "label": np.array([s.label for s in segments], dtype=object),
        "test": np.array([s.test for s in segments], dtype=object),
        "group": np.array([s.group for s in segments], dtype=np.int64),
        "up": np.array([s.up for s in segments], dtype=object),
        "heading": np.array([s.heading for s in segments], dtype=np.float64),
        "rate": np.array([s.rate for s in segments], dtype=np.float64),
        "rate_axis": np.array([s.rate_axis for s in segments], dtype=object),
        "dwell": np.array([s.dwell for s in segments], dtype=np.float64),
        "settle": np.array([s.settle for s in segments], dtype=np.float64),
        "sample_rate": np.array([s.sample_rate for s in segments], dtype=np.float64),
        "temperature": np.array([s.temperature for s in segments], dtype=np.float64),
        "first_sample": recording.first_sample,
        "samples": np.array([s.samples for s in segments], dtype=np.int64),
    }
    data_vars = {}
    for column, name in enumerate(CHANNELS):
        data_vars[name] = ("sample", recording.samples[:, column],
                           {"units": CHANNEL_UNITS[name], "long_name": CHANNEL_LONG_NAMES[name]})
    for name, (units, long_name) in SEGMENT_FIELDS.items():
        attrs = {"long_name": long_name} if units is None else {"units": units, "long_name": long_name}
        data_vars[name] = ("segment", table[name], attrs)
    coords = {
        "time": ("sample", recording.time,
                 {"units": "s", "long_name": "time from the start of the schedule, settle times included"}),
        # not called "segment": a variable may not share its name with the segment dimension
        "segment_index": ("sample", recording.segment_index,
                          {"units": "1", "long_name": "segment of each sample (0-based, schedule order)"}),
    }
    attrs = {"format": FORMAT_NAME, "format_version": FORMAT_VERSION, **recording.attrs,
             "schedule_procedure": recording.schedule.procedure,
             "schedule_notes": _schedule_notes_text(recording.schedule)}
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _plain(value: object) -> object:
    """numpy scalars and bytes from a file -> plain Python values."""
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.generic):
        return value.item()
    return value


def _check_format_attributes(attrs: dict, where: str) -> None:
    name = attrs.get("format")
    if name is not None and name != FORMAT_NAME:
        raise ValueError(f"{where}: format = {name!r}; expected {FORMAT_NAME!r}")
    version = attrs.get("format_version")
    if version is not None and version != FORMAT_VERSION:
        raise ValueError(f"{where}: format_version = {version!r}; this plansim reads version {FORMAT_VERSION}")


def _schedule_notes(text: object, where: str) -> dict:
    """Schedule notes: JSON text (NetCDF attribute) or an already decoded object (CSV header)."""
    if text is None:
        return {}
    if isinstance(text, dict):
        return text
    try:
        notes = json.loads(text) if isinstance(text, str) else None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{where}: schedule_notes = {text!r} is not valid JSON ({exc})") from None
    if not isinstance(notes, dict):
        raise ValueError(f"{where}: schedule_notes = {text!r}; expected a JSON object")
    return notes


def dataset_to_recording(dataset: xr.Dataset, where: str = "dataset") -> Recording:
    """The inverse of :func:`recording_to_dataset`, validating every variable.

    Parameters
    ----------
    dataset : xarray.Dataset
        Variables as :func:`recording_to_dataset` makes them (``time`` and ``segment_index`` may be
        data variables or coordinates). A ``units`` attribute, where present, must be the SI unit.
    where : str
        What to call the dataset in error messages (``read_recording`` passes the file name).

    Returns
    -------
    Recording
        ``timestamps`` is ``None`` when ``time`` equals the nominal time of the schedule exactly, else
        the dataset's ``time``.

    Raises
    ------
    ValueError
        A variable is missing, has the wrong dimension, a wrong ``units`` attribute, a non-finite value,
        or the number of samples disagrees with the segment table.
    """
    if not isinstance(dataset, xr.Dataset):
        raise TypeError(f"{where}: expected an xarray Dataset, got {type(dataset).__name__}")
    attrs = {key: _plain(value) for key, value in dataset.attrs.items()}
    _check_format_attributes(attrs, where)
    procedure = str(attrs.pop("schedule_procedure", "custom"))
    notes = _schedule_notes(attrs.pop("schedule_notes", None), where)
    for key in RESERVED_ATTRIBUTES:
        attrs.pop(key, None)

    def variable(name: str, dimension: str, units: str | None) -> np.ndarray:
        if name not in dataset.variables:
            raise ValueError(f"{where}: variable {name!r} is missing; expected one over dimension {dimension!r}"
                             + (f" in {units}" if units else ""))
        var = dataset.variables[name]
        if var.dims != (dimension,):
            raise ValueError(f"{where}: variable {name!r} has dimensions {var.dims}; expected ({dimension!r},)")
        found_units = var.attrs.get("units")
        if units is not None and found_units is not None and _plain(found_units) != units:
            raise ValueError(f"{where}: variable {name!r} has units {_plain(found_units)!r}; expected {units!r} "
                             "(convert to SI before writing the file)")
        return np.asarray(var.values)

    table = {name: variable(name, "segment", units) for name, (units, _) in SEGMENT_FIELDS.items()}
    for name in _TEXT_FIELDS:
        table[name] = [_plain(value) for value in table[name]]
    schedule = _schedule_from_columns(table, where, column_names={name: name for name in SEGMENT_FIELDS},
                                      procedure=procedure, notes=notes)
    channels = []
    for name in CHANNELS:
        values = variable(name, "sample", CHANNEL_UNITS[name])
        channels.append(_numeric_column(values, where, f"variable {name!r}", CHANNEL_UNITS[name]))
    segment_index = _numeric_column(variable("segment_index", "sample", "1"), where, "variable 'segment_index'", "")
    time = _numeric_column(variable("time", "sample", "s"), where, "variable 'time'", "s")
    return _assemble(schedule, np.column_stack(channels), time, segment_index, attrs,
                     where=where, count_name="dimension 'sample'", segment_name="variable 'segment_index'",
                     time_name="variable 'time'", table_where=where,
                     channel_names=tuple(f"variable {name!r}" for name in CHANNELS))


def _numeric_column(values: np.ndarray, where: str, name: str, units: str) -> np.ndarray:
    if values.dtype.kind not in "iuf":
        raise ValueError(f"{where}: {name} holds {values.dtype} values; expected numbers" + (f" in {units}" if units
                                                                                           else ""))
    return values.astype(np.float64, copy=False)


def _schedule_from_columns(table: dict, where: str, column_names: dict, procedure: str, notes: dict) -> Schedule:
    """Segments from the columns of a segment table (SI values), checking the sample bookkeeping."""
    lengths = {len(values) for values in table.values()}
    count = lengths.pop() if len(lengths) == 1 else None
    if count is None:
        raise ValueError(f"{where}: the segment table's columns have different lengths")
    if count == 0:
        raise ValueError(f"{where}: the segment table has no segment; a recording needs at least one")
    for name in _FLOAT_FIELDS + _INTEGER_FIELDS:
        values = np.asarray(table[name])
        column = column_names[name]
        if values.dtype.kind not in "iuf":
            raise ValueError(f"{where}: column {column!r} holds {values.dtype} values; expected numbers")
        bad = np.flatnonzero(~np.isfinite(values.astype(np.float64)))
        if bad.size:
            raise ValueError(f"{where}: column {column!r} is {float(values[bad[0]])!r} in segment {int(bad[0])}; "
                             f"expected a finite number in {SEGMENT_FIELDS[name][0]}")
        if name in _INTEGER_FIELDS:
            fractional = np.flatnonzero(values != np.round(values))
            if fractional.size:
                raise ValueError(f"{where}: column {column!r} is {float(values[fractional[0]])!r} in segment "
                                 f"{int(fractional[0])}; expected a whole number")
    for name in _TEXT_FIELDS:
        for k, value in enumerate(table[name]):
            if not isinstance(value, str):
                raise ValueError(f"{where}: column {column_names[name]!r} is {value!r} in segment {k}; expected text")
    segments = []
    first_expected = 0
    for k in range(count):
        try:
            segment = Segment(label=table["label"][k], test=table["test"][k], group=int(table["group"][k]),
                              up=table["up"][k], heading=float(table["heading"][k]), rate=float(table["rate"][k]),
                              rate_axis=table["rate_axis"][k], dwell=float(table["dwell"][k]),
                              settle=float(table["settle"][k]), sample_rate=float(table["sample_rate"][k]),
                              temperature=float(table["temperature"][k]))
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{where}: segment {k}: {exc}") from None
        samples = int(table["samples"][k])
        if samples != segment.samples:
            raise ValueError(f"{where}: segment {k} ({segment.label!r}): column {column_names['samples']!r} = "
                             f"{samples} but dwell × sample_rate = {segment.dwell!r} s × {segment.sample_rate!r} Hz "
                             f"gives {segment.samples}; set dwell to samples / sample_rate")
        first_sample = int(table["first_sample"][k])
        if first_sample != first_expected:
            raise ValueError(f"{where}: segment {k} ({segment.label!r}): column {column_names['first_sample']!r} = "
                             f"{first_sample}; expected {first_expected}, the sum of the samples of the segments "
                             "before it")
        first_expected += samples
        segments.append(segment)
    return Schedule(tuple(segments), procedure=procedure, notes=notes)


def _assemble(schedule: Schedule, samples: np.ndarray, time: np.ndarray, segment_index: np.ndarray, attrs: dict,
              where: str, count_name: str, segment_name: str, time_name: str, table_where: str,
              channel_names: tuple[str, ...] = CHANNELS, row_offset: int = 0, row_word: str = "sample") -> Recording:
    """Check the samples against the segment table and build the Recording.

    *row_offset* turns a 0-based sample index into what the file's reader sees (a CSV line number).
    """
    rows = samples.shape[0]
    expected = schedule.total_samples
    if rows != expected:
        raise ValueError(f"{where}: {count_name} has {rows} samples; the segment table ({table_where}) expects "
                         f"{expected}, the sum of its samples column")
    expected_index = np.repeat(np.arange(len(schedule)), [s.samples for s in schedule.segments])
    wrong = np.flatnonzero(segment_index != expected_index)
    if wrong.size:
        k = int(wrong[0])
        found = float(segment_index[k])
        found_text = str(int(found)) if found.is_integer() else repr(found)
        number = int(expected_index[k])
        first = int(np.searchsorted(expected_index, number))
        last = first + schedule.segments[number].samples - 1
        raise ValueError(f"{where}: {segment_name} is {found_text} at {row_word} {k + row_offset}; the segment "
                         f"table ({table_where}) puts it in segment {number}, which holds {row_word}s "
                         f"{first + row_offset} to {last + row_offset} (segments in schedule order)")
    bad = ~np.isfinite(samples)
    if bad.any():
        k, column = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{where}: {channel_names[column]} is {float(samples[k, column])!r} at {row_word} "
                         f"{k + row_offset}; every sample must be a finite number in "
                         f"{CHANNEL_UNITS[CHANNELS[column]]}")
    bad_time = np.flatnonzero(~np.isfinite(time))
    if bad_time.size:
        k = int(bad_time[0])
        raise ValueError(f"{where}: {time_name} is {float(time[k])!r} at {row_word} {k + row_offset}; every time "
                         "must be a finite number of seconds")
    nominal = nominal_time(schedule)
    # a file written by plansim holds the nominal time exactly; anything else is a measured clock, kept
    timestamps = None if np.array_equal(time, nominal) else time
    if timestamps is not None:
        backwards = np.flatnonzero(np.diff(timestamps) < 0)
        if backwards.size:
            k = int(backwards[0]) + 1
            raise ValueError(f"{where}: {time_name} decreases at {row_word} {k + row_offset} "
                             f"({float(timestamps[k - 1])!r} s then {float(timestamps[k])!r} s); expected a global "
                             "time axis, never decreasing")
    try:
        return Recording(samples=samples, schedule=schedule, attrs=attrs, timestamps=timestamps)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None


# ----------------------------------------------------------------------------- files


def _check_path(path: str | os.PathLike) -> Path:
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path = {path!r}: expected a file name (str or os.PathLike)")
    target = Path(path)
    if target.suffix.lower() not in SUFFIXES:
        raise ValueError(f"recording file {str(target)!r}: suffix {target.suffix!r} not supported; allowed: "
                         f"{', '.join(SUFFIXES)} (.csv writes a second file <stem>{SEGMENT_TABLE_SUFFIX})")
    if target.name.lower().endswith(SEGMENT_TABLE_SUFFIX):
        samples_name = target.name[:-len(SEGMENT_TABLE_SUFFIX)] + ".csv"
        raise ValueError(f"recording file {str(target)!r} names a segment table; give the samples file "
                         f"{str(target.with_name(samples_name))!r}, its table is found beside it")
    return target


def segment_table_path(path: str | os.PathLike) -> Path:
    """Where the segment table of the CSV recording *path* lives: ``<stem>.segments.csv`` beside it."""
    target = Path(path)
    return target.with_name(target.stem + SEGMENT_TABLE_SUFFIX)


def write_recording(recording: Recording, path: str | os.PathLike) -> None:
    """Write *recording* to *path*: ``.nc`` (NetCDF-3) or ``.csv`` (samples + ``<stem>.segments.csv``).

    Files are written whole or not at all (temporary file beside the target, then rename); for CSV,
    if either file fails neither new file remains. Existing files are replaced.

    Raises
    ------
    ValueError
        The suffix is not ``.nc`` or ``.csv``, or the folder does not exist.
    """
    if not isinstance(recording, Recording):
        raise TypeError(f"recording: expected a plansim Recording, got {type(recording).__name__}")
    target = _check_path(path)
    if target.suffix.lower() == ".nc":
        _write_netcdf(recording, target)
    else:
        _write_csv(recording, target)


def _netcdf3_attributes(attrs: dict) -> dict:
    """NetCDF-3 has no 64-bit integer attribute: larger whole numbers (seeds) are stored as text and listed."""
    encoded, as_text = {}, []
    for key, value in attrs.items():
        if isinstance(value, int) and not _NETCDF3_INT_MIN <= value <= _NETCDF3_INT_MAX:
            encoded[key] = str(value)
            as_text.append(key)
        else:
            encoded[key] = value
    if as_text:
        encoded["integer_text_attributes"] = " ".join(as_text)
    return encoded


def _write_netcdf(recording: Recording, target: Path) -> None:
    if recording.samples.shape[0] > _NETCDF3_INT_MAX:
        raise ValueError(f"recording file {str(target)!r}: {recording.samples.shape[0]} samples exceed what a "
                         "NetCDF-3 file indexes; write .csv instead")
    dataset = recording_to_dataset(recording)
    dataset.attrs = _netcdf3_attributes(dataset.attrs)
    atomic_write(target, lambda tmp: dataset.to_netcdf(tmp, engine="scipy", format="NETCDF3_64BIT"))


def _header_lines(title: str, attrs: dict) -> list[str]:
    lines = [f"# {title}\n"]
    for key, value in attrs.items():
        lines.append(f"# {key}: {json.dumps(value, ensure_ascii=False)}\n")
    return lines


def _write_csv(recording: Recording, target: Path) -> None:
    table_target = segment_table_path(target)
    _schedule_notes_text(recording.schedule)  # fails early, naming the field, if the notes are not JSON
    # each header value is JSON, so the notes are written as an object, not as JSON text inside JSON
    header_attrs = {"format": FORMAT_NAME, "format_version": FORMAT_VERSION, **recording.attrs,
                    "schedule_procedure": recording.schedule.procedure, "schedule_notes": recording.schedule.notes}
    samples_block = np.column_stack([recording.time, recording.segment_index, recording.samples])
    sample_formats = ["%.17g", "%d"] + ["%.17g"] * len(CHANNELS)

    def write_samples(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.writelines(_header_lines(f"plansim recording (samples); segment table in {table_target.name}",
                                        header_attrs))
            fh.write(",".join(CSV_SAMPLE_COLUMNS) + "\n")
            np.savetxt(fh, samples_block, fmt=sample_formats, delimiter=",")

    def write_table(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(f"# plansim recording (segment table); samples in {target.name}\n")
            writer = csv.writer(fh, lineterminator="\n")
            writer.writerow(CSV_SEGMENT_COLUMNS)
            for k, (segment, first) in enumerate(zip(recording.schedule.segments, recording.first_sample)):
                # repr is the shortest text that reads back to the same float; deg columns are for people
                writer.writerow([k, segment.label, segment.test, segment.group, segment.up,
                                 repr(math.degrees(segment.heading)), repr(float(segment.heading)),
                                 repr(math.degrees(segment.rate)), repr(float(segment.rate)), segment.rate_axis,
                                 repr(float(segment.dwell)), repr(float(segment.settle)),
                                 repr(float(segment.sample_rate)), repr(float(segment.temperature)),
                                 int(first), segment.samples])

    table_in_place = False

    def write_both(tmp_samples: str) -> None:
        nonlocal table_in_place
        write_samples(tmp_samples)
        # the table goes into place only once the samples are complete; the samples follow it
        atomic_write(table_target, write_table)
        table_in_place = True

    try:
        atomic_write(target, write_both)
    except BaseException:
        if table_in_place and table_target.exists():
            table_target.unlink()
        raise


def read_recording(path: str | os.PathLike) -> Recording:
    """Read a recording written by :func:`write_recording` or prepared by a lab (docs/recording.md).

    Parameters
    ----------
    path : str or os.PathLike
        ``.nc`` file, or the samples ``.csv`` (its segment table ``<stem>.segments.csv`` is read too).

    Raises
    ------
    ValueError
        Unsupported suffix, missing file, missing column or variable, a non-finite or non-numeric value,
        a wrong unit, or a number of samples that disagrees with the segment table; the message names
        the file, the column and what is expected.
    """
    target = _check_path(path)
    if not target.is_file():
        raise ValueError(f"recording file {str(target)!r} does not exist")
    if target.suffix.lower() == ".nc":
        return _read_netcdf(target)
    return _read_csv(target)


def _read_netcdf(target: Path) -> Recording:
    where = f"recording file {str(target)!r}"
    try:
        dataset = xr.load_dataset(target, engine="scipy", decode_times=False, decode_timedelta=False)
    except (OSError, TypeError, ValueError) as exc:
        raise ValueError(f"{where}: not a readable NetCDF-3 file ({exc})") from None
    attrs = {key: _plain(value) for key, value in dataset.attrs.items()}
    for key in str(attrs.pop("integer_text_attributes", "")).split():
        try:
            attrs[key] = int(attrs[key])
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"{where}: integer_text_attributes lists {key!r} but attribute {key!r} = "
                             f"{attrs.get(key)!r} is not a whole number") from None
    dataset.attrs = attrs
    return dataset_to_recording(dataset, where=where)


def _read_header(fh, where: str) -> tuple[dict, list[str], int]:
    """Leading ``#`` lines -> attributes (``# key: JSON value``; other text is kept as a string);
    then the column names. Returns (attrs, columns, line number of the column names)."""
    attrs = {}
    line_number = 0
    for line in fh:
        line_number += 1
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            match = _HEADER_ATTRIBUTE.match(stripped)
            if match:
                key, text = match.groups()
                try:
                    attrs[key] = json.loads(text)
                except json.JSONDecodeError:
                    attrs[key] = text
            continue
        columns = next(csv.reader([stripped]))
        columns = [name.strip() for name in columns]
        duplicates = sorted({name for name in columns if columns.count(name) > 1})
        if duplicates:
            raise ValueError(f"{where}: column {duplicates[0]!r} appears more than once in the header (line "
                             f"{line_number})")
        return attrs, columns, line_number
    raise ValueError(f"{where}: no header line; expected the column names")


def _read_table_csv(table_target: Path, procedure: str, notes: dict) -> Schedule:
    where = f"segment table {str(table_target)!r}"
    if not table_target.is_file():
        raise ValueError(f"{where} does not exist; a CSV recording is two files, the samples and "
                         f"<stem>{SEGMENT_TABLE_SUFFIX} beside them")
    with open(table_target, encoding="utf-8-sig", newline="") as fh:
        _, columns, _ = _read_header(fh, where)
        rows = list(csv.reader(fh))
    rows = [row for row in rows if any(cell.strip() for cell in row)]
    required = ["segment"] + list(_CSV_FIELD_COLUMNS.values())
    missing = [name for name in required if name not in columns]
    for rad_column, deg_column in _CSV_ANGLE_COLUMNS.values():
        if rad_column not in columns and deg_column not in columns:
            missing.append(f"{rad_column} or {deg_column}")
    if missing:
        raise ValueError(f"{where}: column {missing[0]!r} is missing; required: {', '.join(required)}, "
                         "heading_rad or heading_deg, rate_rad_s or rate_deg_s")
    position = {name: columns.index(name) for name in columns}

    def cell(row_number: int, row: list[str], column: str, strip: bool = True) -> str:
        index = position[column]
        if index >= len(row):
            raise ValueError(f"{where}: segment row {row_number} has no value in column {column!r}")
        return row[index].strip() if strip else row[index]

    def number(row_number: int, row: list[str], column: str, units: str) -> float:
        text = cell(row_number, row, column)
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{where}: column {column!r} is {text!r} in segment row {row_number}; expected a "
                             f"number in {units}") from None
        if not math.isfinite(value):
            raise ValueError(f"{where}: column {column!r} is {text!r} in segment row {row_number}; expected a "
                             f"finite number in {units}")
        return value

    table: dict[str, list] = {name: [] for name in SEGMENT_FIELDS}
    for k, row in enumerate(rows):
        index_text = cell(k, row, "segment")
        if index_text != str(k):
            raise ValueError(f"{where}: column 'segment' is {index_text!r} in segment row {k}; expected {k} "
                             "(segments numbered from 0 in schedule order)")
        for name in _TEXT_FIELDS:
            # a label is free text, kept exactly; the other text columns are codes
            table[name].append(cell(k, row, _CSV_FIELD_COLUMNS[name], strip=name != "label"))
        for name in ("dwell", "settle", "sample_rate", "temperature", "group", "first_sample", "samples"):
            column = _CSV_FIELD_COLUMNS[name]
            units = SEGMENT_FIELDS[name][0]
            table[name].append(number(k, row, column, "whole numbers" if name in _INTEGER_FIELDS else units))
        for name, (rad_column, deg_column) in _CSV_ANGLE_COLUMNS.items():
            units = SEGMENT_FIELDS[name][0]
            rad = number(k, row, rad_column, units) if rad_column in position else None
            deg = number(k, row, deg_column, units.replace("rad", "deg")) if deg_column in position else None
            if rad is not None and deg is not None and abs(rad - deg * DEG) > _ANGLE_AGREEMENT * max(1.0, abs(rad)):
                raise ValueError(f"{where}: segment row {k}: {deg_column} = {deg!r} and {rad_column} = {rad!r} "
                                 "disagree; give one of them or make them agree")
            # the rad column is exact; the deg column converts the way a scenario file's "deg" does
            table[name].append(rad if rad is not None else deg * DEG)
    columns_for_messages = dict(_CSV_FIELD_COLUMNS)
    columns_for_messages.update({name: f"{rad}/{deg}" for name, (rad, deg) in _CSV_ANGLE_COLUMNS.items()})
    converted = {name: (np.array(values, dtype=np.float64) if name not in _TEXT_FIELDS else values)
                 for name, values in table.items()}
    return _schedule_from_columns(converted, where, column_names=columns_for_messages, procedure=procedure,
                                  notes=notes)


def _read_csv(target: Path) -> Recording:
    where = f"recording file {str(target)!r}"
    table_target = segment_table_path(target)
    with open(target, encoding="utf-8-sig", newline="") as fh:
        attrs, columns, header_line = _read_header(fh, where)
        missing = [name for name in CSV_SAMPLE_COLUMNS if name not in columns]
        if missing:
            raise ValueError(f"{where}: column {missing[0]!r} is missing; required: {', '.join(CSV_SAMPLE_COLUMNS)}")
        use = [columns.index(name) for name in CSV_SAMPLE_COLUMNS]
        try:
            data = np.loadtxt(fh, delimiter=",", usecols=use, ndmin=2, comments=None, dtype=np.float64)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc} (rows counted after the header, line {header_line}); every value of "
                             f"{', '.join(CSV_SAMPLE_COLUMNS)} must be a number") from None
    _check_format_attributes(attrs, where)
    procedure = attrs.pop("schedule_procedure", "custom")
    notes = _schedule_notes(attrs.pop("schedule_notes", None), where)
    for key in RESERVED_ATTRIBUTES:
        attrs.pop(key, None)
    schedule = _read_table_csv(table_target, str(procedure), notes)
    if data.size == 0:
        data = np.empty((0, len(CSV_SAMPLE_COLUMNS)))
    return _assemble(schedule, data[:, 2:], data[:, 0], data[:, 1], attrs, where=where, count_name="the file",
                     segment_name="column 'segment'", time_name="column 'time_s'",
                     table_where=str(table_target), channel_names=tuple(f"column {c!r}" for c in CSV_CHANNEL_COLUMNS),
                     row_offset=header_line + 1, row_word="line")
