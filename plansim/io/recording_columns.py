"""From the columns of a recording file to a checked :class:`~plansim.io.recording_data.Recording`.

Both file formats read a segment table and the sample columns, then hand them here: the segment
table's fields (:data:`SEGMENT_FIELDS`), the format and provenance attributes, and the checks that
the samples agree with the table (:func:`schedule_from_columns`, :func:`assemble`). Every message
names the file (*where*), the column or variable, and what is expected.
"""

from __future__ import annotations

import json

import numpy as np

from plansim.io.recording_data import CHANNEL_UNITS, CHANNELS, FORMAT_NAME, READABLE_VERSIONS, Recording, nominal_time
from plansim.schedule.segments import ORIENTATIONS, TESTS, Schedule, Segment

#: segment table: field -> (units or None for text, long name); the order of the NetCDF variables
SEGMENT_FIELDS: dict[str, tuple[str | None, str]] = {
    "label": (None, "segment label"),
    "test": (None, "what the segment is: " + ", ".join(TESTS)),
    "group": ("1", "group of the segment within its test (position group or rate-test axis)"),
    "up": (None, "body axis pointing up: +x, -x, +y, -y, +z or -z"),
    "heading": ("rad", "heading about the vertical, counter-clockwise seen from above; NaN: not known"),
    "rate": ("rad/s", "table angular rate; NaN: not logged"),
    "rate_axis": (None, "body axis on the table rotation axis: +x, -x, +y, -y, +z or -z"),
    "dwell": ("s", "recording time requested for the segment"),
    "settle": ("s", "settling time before recording"),
    "sample_rate": ("Hz", "sample rate"),
    "temperature": ("degC", "temperature during the segment"),
    "first_sample": ("1", "index along sample of the segment's first sample"),
    "samples": ("1", "number of samples recorded in the segment"),
    "orientation": (None, "how well up and heading are known: " + ", ".join(ORIENTATIONS)),
    "angle": ("rad", "reference angle turned about rate_axis in a rotation segment; NaN: not known"),
}
TEXT_FIELDS = ("label", "test", "up", "rate_axis", "orientation")
INTEGER_FIELDS = ("group", "first_sample", "samples")
FLOAT_FIELDS = ("heading", "rate", "dwell", "settle", "sample_rate", "temperature", "angle")
#: fields that may be NaN in a file (a value not known); the Segment says where NaN is allowed
NAN_FIELDS = ("heading", "rate", "angle")
#: fields added in format version 2: a file without them (version 1, or a lab's table) gets these values
OPTIONAL_FIELDS = {"orientation": "known", "angle": float("nan")}


def schedule_notes_text(schedule: Schedule) -> str:
    """``Schedule.notes`` as JSON text, as the files store it; ``TypeError`` naming the field if it is not JSON."""
    try:
        return json.dumps(schedule.notes)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"schedule.notes = {schedule.notes!r}: it must be JSON-serialisable to be stored in a "
                        f"recording ({exc})") from None



def plain(value: object, where: str = "recording") -> object:
    """numpy scalars and bytes from a file -> plain Python values; bytes that are not UTF-8 are a ValueError."""
    if isinstance(value, bytes):
        try:
            return value.decode("utf-8")
        except UnicodeDecodeError:
            raise ValueError(f"{where}: text {value[:40]!r} is not UTF-8") from None
    if isinstance(value, np.generic):
        return value.item()
    return value


def check_format_attributes(attrs: dict, where: str) -> None:
    """``format`` and ``format_version``, where a file gives them, must be this format's."""
    name = attrs.get("format")
    if name is not None and name != FORMAT_NAME:
        raise ValueError(f"{where}: format = {name!r}; expected {FORMAT_NAME!r}")
    version = attrs.get("format_version")
    if version is not None and (isinstance(version, bool) or version not in READABLE_VERSIONS):
        raise ValueError(f"{where}: format_version = {version!r}; this plansim reads versions "
                         f"{', '.join(map(str, READABLE_VERSIONS))}")


def schedule_notes(text: object, where: str) -> dict:
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



def numeric_column(values: np.ndarray, where: str, name: str, units: str) -> np.ndarray:
    """*values* as float64; ``ValueError`` naming the column if they are not numbers."""
    if values.dtype.kind not in "iuf":
        raise ValueError(f"{where}: {name} holds {values.dtype} values; expected numbers" + (f" in {units}" if units
                                                                                           else ""))
    return values.astype(np.float64, copy=False)


def schedule_from_columns(table: dict, where: str, column_names: dict, procedure: str, notes: dict) -> Schedule:
    """Segments from the columns of a segment table (SI values), checking the sample bookkeeping."""
    lengths = {len(values) for values in table.values()}
    count = lengths.pop() if len(lengths) == 1 else None
    if count is None:
        raise ValueError(f"{where}: the segment table's columns have different lengths")
    if count == 0:
        raise ValueError(f"{where}: the segment table has no segment; a recording needs at least one")
    table = dict(table)
    for name, default in OPTIONAL_FIELDS.items():  # absent from version-1 files and from a lab's own table
        if name not in table:
            table[name] = [default] * count if name in TEXT_FIELDS else np.full(count, default)
    for name in FLOAT_FIELDS + INTEGER_FIELDS:
        values = np.asarray(table[name])
        column = column_names[name]
        if values.dtype.kind not in "iuf":
            raise ValueError(f"{where}: column {column!r} holds {values.dtype} values; expected numbers")
        as_float = values.astype(np.float64)
        bad = np.flatnonzero(np.isinf(as_float) if name in NAN_FIELDS else ~np.isfinite(as_float))
        if bad.size:
            raise ValueError(f"{where}: column {column!r} is {float(values[bad[0]])!r} in segment {int(bad[0])}; "
                             f"expected a finite number in {SEGMENT_FIELDS[name][0]}"
                             + (" or NaN (not known)" if name in NAN_FIELDS else ""))
        if name in INTEGER_FIELDS:
            fractional = np.flatnonzero(values != np.round(values))
            if fractional.size:
                raise ValueError(f"{where}: column {column!r} is {float(values[fractional[0]])!r} in segment "
                                 f"{int(fractional[0])}; expected a whole number")
    for name in TEXT_FIELDS:
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
                              temperature=float(table["temperature"][k]), orientation=table["orientation"][k],
                              angle=float(table["angle"][k]))
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


def assemble(schedule: Schedule, samples: np.ndarray, time: np.ndarray, segment_index: np.ndarray, attrs: dict,
             where: str, count_name: str, segment_name: str, time_name: str, table_where: str,
             channel_names: tuple[str, ...] = CHANNELS, row_offset: int = 0, row_word: str = "sample",
             temperature: np.ndarray | None = None, temperature_name: str = "temperature") -> Recording:
    """Check the samples against the segment table and build the Recording.

    *row_offset* turns a 0-based sample index into what the file's reader sees (a CSV line number);
    *temperature* is the per-sample temperature channel (°C) where the file has one.
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
    if temperature is not None:
        bad_temperature = np.flatnonzero(~np.isfinite(temperature))
        if bad_temperature.size:
            k = int(bad_temperature[0])
            raise ValueError(f"{where}: {temperature_name} is {float(temperature[k])!r} at {row_word} "
                             f"{k + row_offset}; every temperature must be a finite number in degC")
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
        return Recording(samples=samples, schedule=schedule, attrs=attrs, timestamps=timestamps,
                         temperature=temperature)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None
