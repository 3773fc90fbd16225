"""Recordings as CSV: the samples at the given path and the segment table beside it at ``<stem>.segments.csv``.

Both files are UTF-8 text with a header line of column names (each name carries its unit); the
samples file starts with ``# key: JSON value`` lines that hold the provenance. Floats are written
with 17 significant digits, so they read back exactly (docs/recording.md describes every column).
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from plansim.io.files import atomic_write
from plansim.io.recording_columns import (
    INTEGER_FIELDS,
    NAN_FIELDS,
    OPTIONAL_FIELDS,
    SEGMENT_FIELDS,
    TEXT_FIELDS,
    assemble,
    check_format_attributes,
    schedule_from_columns,
    schedule_notes,
    schedule_notes_text,
)
from plansim.io.recording_data import CHANNELS, FORMAT_NAME, FORMAT_VERSION, RESERVED_ATTRIBUTES, Recording
from plansim.schedule.segments import Schedule
from plansim.units import DEG

SEGMENT_TABLE_SUFFIX = ".segments.csv"
CSV_CHANNEL_COLUMNS = ("gx_rad_s", "gy_rad_s", "gz_rad_s", "ax_m_s2", "ay_m_s2", "az_m_s2")
CSV_SAMPLE_COLUMNS = ("time_s", "segment") + CSV_CHANNEL_COLUMNS
#: the samples file's optional temperature channel, degC
CSV_TEMPERATURE_COLUMN = "temperature_degc"

#: CSV segment table columns, in the order written
CSV_SEGMENT_COLUMNS = ("segment", "label", "test", "group", "up", "heading_deg", "heading_rad", "rate_deg_s",
                       "rate_rad_s", "rate_axis", "dwell_s", "settle_s", "sample_rate_hz", "temperature_degc",
                       "first_sample", "samples", "orientation", "angle_deg", "angle_rad")
#: CSV column of each segment field that has a single column (heading and rate have a deg and a rad column)
_CSV_FIELD_COLUMNS = {"label": "label", "test": "test", "group": "group", "up": "up", "rate_axis": "rate_axis",
                      "dwell": "dwell_s", "settle": "settle_s", "sample_rate": "sample_rate_hz",
                      "temperature": "temperature_degc", "first_sample": "first_sample", "samples": "samples",
                      "orientation": "orientation"}
#: heading, rate and angle: (rad column, deg column); the rad column is exact, the deg column is for people
_CSV_ANGLE_COLUMNS = {"heading": ("heading_rad", "heading_deg"), "rate": ("rate_rad_s", "rate_deg_s"),
                      "angle": ("angle_rad", "angle_deg")}
# how far the deg and rad columns may disagree before the file counts as contradictory: far above the
# rounding of a deg ↔ rad conversion (~1e-16 relative) and far below any table's resolution
_ANGLE_AGREEMENT = 1e-9

def _disagree(rad: float, deg: float) -> bool:
    """The rad and deg columns of one value contradict each other (NaN agrees only with NaN)."""
    if math.isnan(rad) or math.isnan(deg):
        return math.isnan(rad) != math.isnan(deg)
    return abs(rad - deg * DEG) > _ANGLE_AGREEMENT * max(1.0, abs(rad))


_HEADER_ATTRIBUTE = re.compile(r"^#\s*([A-Za-z_][A-Za-z0-9_.\-]*)\s*:\s*(.*?)\s*$")


def segment_table_path(path: str | os.PathLike) -> Path:
    """Where the segment table of the CSV recording *path* lives: ``<stem>.segments.csv`` beside it."""
    target = Path(path)
    return target.with_name(target.stem + SEGMENT_TABLE_SUFFIX)


def _header_lines(title: str, attrs: dict) -> list[str]:
    lines = [f"# {title}\n"]
    for key, value in attrs.items():
        lines.append(f"# {key}: {json.dumps(value, ensure_ascii=False)}\n")
    return lines


def write_csv(recording: Recording, target: Path) -> None:
    table_target = segment_table_path(target)
    schedule_notes_text(recording.schedule)  # fails early, naming the field, if the notes are not JSON
    # each header value is JSON, so the notes are written as an object, not as JSON text inside JSON
    header_attrs = {"format": FORMAT_NAME, "format_version": FORMAT_VERSION, **recording.attrs,
                    "schedule_procedure": recording.schedule.procedure, "schedule_notes": recording.schedule.notes}
    columns = CSV_SAMPLE_COLUMNS
    samples_block = np.column_stack([recording.time, recording.segment_index, recording.samples])
    sample_formats = ["%.17g", "%d"] + ["%.17g"] * len(CHANNELS)
    if recording.temperature is not None:
        columns = columns + (CSV_TEMPERATURE_COLUMN,)
        samples_block = np.column_stack([samples_block, recording.temperature])
        sample_formats.append("%.17g")

    def write_samples(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.writelines(_header_lines(f"plansim recording (samples); segment table in {table_target.name}",
                                        header_attrs))
            fh.write(",".join(columns) + "\n")
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
                                 int(first), segment.samples, segment.orientation,
                                 repr(math.degrees(segment.angle)), repr(float(segment.angle))])

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


#: how much of a file's start is checked for binary content before it is parsed, bytes
_HEAD_BYTES = 8192


@contextmanager
def _text_file(path: Path, where: str) -> Iterator:
    """Open *path* as UTF-8 text for the CSV reader; every way it fails to be text is a ValueError naming it.

    Before parsing: unreadable, empty, UTF-16 (byte-order mark), NUL bytes or undecodable bytes at the
    start (a binary file renamed .csv). While parsing (inside the ``with`` block): undecodable bytes
    further on, and the csv module's errors.
    """
    try:
        with open(path, "rb") as raw:
            head = raw.read(_HEAD_BYTES)
    except OSError as exc:
        raise ValueError(f"{where} cannot be read: {exc.strerror or exc}") from None
    if not head:
        raise ValueError(f"{where} is empty; expected a header line of column names, then one row per "
                         "sample or segment")
    if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise ValueError(f"{where} is UTF-16 text; plansim reads UTF-8 CSV: save it as UTF-8")
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        # a multi-byte character cut by the end of the head is not an error
        if exc.start < len(head) - 3:
            raise ValueError(_not_utf8(where, exc)) from None
    if b"\x00" in head:
        raise ValueError(f"{where} holds NUL bytes: binary data or UTF-16 text, not a UTF-8 CSV file")
    try:
        with open(path, encoding="utf-8-sig", newline="") as fh:
            yield fh
    except UnicodeDecodeError as exc:
        raise ValueError(_not_utf8(where, exc)) from None
    except csv.Error as exc:
        raise ValueError(f"{where}: not a readable CSV file ({exc})") from None
    except OSError as exc:
        raise ValueError(f"{where} cannot be read: {exc.strerror or exc}") from None


def _not_utf8(where: str, exc: UnicodeDecodeError) -> str:
    byte = exc.object[exc.start]
    return (f"{where} is not UTF-8 text (byte 0x{byte:02x} cannot be decoded): binary data, such as an image or "
            "a NetCDF file renamed .csv? A CSV recording is UTF-8 text (docs/recording.md)")


def _unterminated_last_line(path: Path) -> int | None:
    """The number (1-based) of a file's last line if it does not end with a line break, else None."""
    with open(path, "rb") as raw:
        size = raw.seek(0, os.SEEK_END)
        raw.seek(max(0, size - 64))
        tail = raw.read().rstrip(b" \t")
        if not tail or tail[-1:] in (b"\n", b"\r"):
            return None
        raw.seek(0)
        return sum(block.count(b"\n") for block in iter(lambda: raw.read(1 << 20), b"")) + 1


def _check_line_end(path: Path, where: str) -> None:
    """A complete file ends with a line break: text after the last one may be a number cut short.

    A file cut inside its last number keeps every row and column, so no count shows it; plansim ends
    every line it writes, and so do spreadsheet and acquisition exports.
    """
    last = _unterminated_last_line(path)
    if last is not None:
        raise ValueError(f"{where}: the last line (line {last}) does not end with a line break: the file may "
                         "have been cut short inside its last number (a copy or transfer that stopped); if the file "
                         "is complete, end it with a line break")


def _read_header(fh, where: str) -> tuple[dict, list[str], int]:
    """Leading ``#`` lines -> attributes (``# key: JSON value``; other text is kept as a string);
    then the column names. Returns (attrs, columns, line number of the column names)."""
    attrs = {}
    line_number = 0
    for line in fh:
        line_number += 1
        if "\x00" in line:
            raise ValueError(f"{where}: line {line_number} holds NUL characters: binary data or UTF-16 text, not a "
                             "UTF-8 CSV file")
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
    with _text_file(table_target, where) as fh:
        _, columns, _ = _read_header(fh, where)
        rows = list(csv.reader(fh))
    _check_line_end(table_target, where)
    rows = [row for row in rows if any(cell.strip() for cell in row)]
    required = ["segment"] + [column for name, column in _CSV_FIELD_COLUMNS.items() if name not in OPTIONAL_FIELDS]
    missing = [name for name in required if name not in columns]
    for name, (rad_column, deg_column) in _CSV_ANGLE_COLUMNS.items():
        if rad_column not in columns and deg_column not in columns and name not in OPTIONAL_FIELDS:
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

    def number(row_number: int, row: list[str], column: str, units: str, nan_allowed: bool = False) -> float:
        text = cell(row_number, row, column)
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{where}: column {column!r} is {text!r} in segment row {row_number}; expected a "
                             f"number in {units}") from None
        if math.isinf(value) or (math.isnan(value) and not nan_allowed):
            raise ValueError(f"{where}: column {column!r} is {text!r} in segment row {row_number}; expected a "
                             f"finite number in {units}" + (" or nan (not known)" if nan_allowed else ""))
        return value

    # the optional fields (format version 2) are read where their columns are present
    present = {name for name, column in _CSV_FIELD_COLUMNS.items() if column in position}
    present |= {name for name, pair in _CSV_ANGLE_COLUMNS.items() if any(column in position for column in pair)}
    present |= {"first_sample", "samples"}
    table: dict[str, list] = {name: [] for name in SEGMENT_FIELDS if name in present}
    for k, row in enumerate(rows):
        index_text = cell(k, row, "segment")
        if index_text != str(k):
            raise ValueError(f"{where}: column 'segment' is {index_text!r} in segment row {k}; expected {k} "
                             "(segments numbered from 0 in schedule order)")
        for name in TEXT_FIELDS:
            # a label is free text, kept exactly; the other text columns are codes
            if name in table:
                table[name].append(cell(k, row, _CSV_FIELD_COLUMNS[name], strip=name != "label"))
        for name in ("dwell", "settle", "sample_rate", "temperature", "group", "first_sample", "samples"):
            column = _CSV_FIELD_COLUMNS[name]
            units = SEGMENT_FIELDS[name][0]
            table[name].append(number(k, row, column, "whole numbers" if name in INTEGER_FIELDS else units))
        for name, (rad_column, deg_column) in _CSV_ANGLE_COLUMNS.items():
            if name not in table:
                continue
            units = SEGMENT_FIELDS[name][0]
            nan_allowed = name in NAN_FIELDS
            rad = number(k, row, rad_column, units, nan_allowed) if rad_column in position else None
            deg = (number(k, row, deg_column, units.replace("rad", "deg"), nan_allowed) if deg_column in position
                   else None)
            if rad is not None and deg is not None and _disagree(rad, deg):
                one_nan = (" (nan is 'not known': a value filled into one column of the pair must be filled into "
                           "both, or the other column deleted)" if math.isnan(rad) != math.isnan(deg) else "")
                raise ValueError(f"{where}: segment row {k}: {deg_column} = {deg!r} and {rad_column} = {rad!r} "
                                 f"disagree{one_nan}; give one of them or make them agree")
            # the rad column is exact; the deg column converts the way a scenario file's "deg" does
            table[name].append(rad if rad is not None else deg * DEG)
    columns_for_messages = dict(_CSV_FIELD_COLUMNS)
    columns_for_messages.update({name: f"{rad}/{deg}" for name, (rad, deg) in _CSV_ANGLE_COLUMNS.items()})
    converted = {name: (np.array(values, dtype=np.float64) if name not in TEXT_FIELDS else values)
                 for name, values in table.items()}
    return schedule_from_columns(converted, where, column_names=columns_for_messages, procedure=procedure,
                                  notes=notes)


def read_csv(target: Path) -> Recording:
    where = f"recording file {str(target)!r}"
    table_target = segment_table_path(target)
    with _text_file(target, where) as fh:
        attrs, columns, header_line = _read_header(fh, where)
        missing = [name for name in CSV_SAMPLE_COLUMNS if name not in columns]
        if missing:
            raise ValueError(f"{where}: column {missing[0]!r} is missing; required: {', '.join(CSV_SAMPLE_COLUMNS)}"
                             + ("" if table_target.exists() else f", with its segment table {table_target.name!r} "
                                "beside it. Is it a raw log? Turn it into a recording first: plansim import "
                                f"{target.name} --out rec.nc (docs/measured-data.md)"))
        read_columns = CSV_SAMPLE_COLUMNS + ((CSV_TEMPERATURE_COLUMN,) if CSV_TEMPERATURE_COLUMN in columns else ())
        use = [columns.index(name) for name in read_columns]
        try:
            data = np.loadtxt(fh, delimiter=",", usecols=use, ndmin=2, comments=None, dtype=np.float64)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc} (rows counted after the header, line {header_line}); every value of "
                             f"{', '.join(read_columns)} must be a number") from None
    _check_line_end(target, where)
    check_format_attributes(attrs, where)
    procedure = attrs.pop("schedule_procedure", "custom")
    notes = schedule_notes(attrs.pop("schedule_notes", None), where)
    for key in RESERVED_ATTRIBUTES:
        attrs.pop(key, None)
    schedule = _read_table_csv(table_target, str(procedure), notes)
    if data.size == 0:
        data = np.empty((0, len(read_columns)))
    channels = slice(2, 2 + len(CSV_CHANNEL_COLUMNS))
    temperature = data[:, -1] if CSV_TEMPERATURE_COLUMN in read_columns else None
    return assemble(schedule, data[:, channels], data[:, 0], data[:, 1], attrs, where=where, count_name="the file",
                     segment_name="column 'segment'", time_name="column 'time_s'",
                     table_where=str(table_target), channel_names=tuple(f"column {c!r}" for c in CSV_CHANNEL_COLUMNS),
                     row_offset=header_line + 1, row_word="line", temperature=temperature,
                     temperature_name=f"column {CSV_TEMPERATURE_COLUMN!r}")
