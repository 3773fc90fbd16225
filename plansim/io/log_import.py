"""From a plain IMU log (CSV) to a recording with a segment table for the user to review.

A plain log is one CSV table: a header line of column names, then one row per sample with six
channels (three gyros, three accelerometers) in counts or in physical units, and perhaps a time
column, a sample counter, a temperature and labels. :func:`import_log` reads it, converts the
channels to SI, checks the time axis (sample rate, jitter, gaps), finds the static poses and the
motion between them (:func:`plansim.estimate.segmentation.segment_log`) and returns a
:class:`~plansim.io.recording_data.Recording` holding **every** sample of the log, cut into
``static``, ``rotation`` and ``move`` segments (docs/recording.md), with what it found in the
attributes and the schedule notes. ``plansim import`` writes it (docs/measured-data.md).

Every problem with the log is a ``ValueError`` naming the file, the line and the column; what the
log may still be used for despite a flaw (a gap, a saturated stretch, timing jitter) is a named
:class:`LogWarning`.
"""

from __future__ import annotations

import csv
import datetime
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from plansim.estimate.segmentation import (
    APPROXIMATE_TILT,
    AXES,
    DEFAULT_MIN_STATIC,
    DEFAULT_WINDOW,
    DROPPED_MAX,
    FULL_SCALE_MARGIN,
    Segmentation,
    Span,
    TimeReport,
    analyse_time,
    segment_log,
)
from plansim.io.recording_csv import _text_file, _unterminated_last_line
from plansim.io.recording_data import CHANNELS, SITE_ATTRIBUTES, UNITS_DESCRIPTION, Recording, plansim_version
from plansim.schedule.segments import Schedule, Segment
from plansim.units import KINDS, STANDARD_GRAVITY

#: default names of the six channel columns, in the order gx gy gz ax ay az
DEFAULT_COLUMNS = CHANNELS
#: units of the time column -> seconds per unit ("samples": a sample counter, needs the sample rate)
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "samples": math.nan}
#: the delimiters a log may use; the one that splits the header line into the most columns is taken
DELIMITERS = (",", ";", "\t")
#: the delimiter of a log whose columns are separated by runs of spaces (imu_tk, MATLAB's ``save -ascii``)
WHITESPACE = "whitespace"
#: a static span's mean specific force must be within this fraction of standard gravity (units check)
GRAVITY_TOLERANCE = 0.3
#: timing jitter (RMS) beyond this fraction of the sample period is a warning
JITTER_WARNING = 0.1
#: a given sample rate that differs from the time column's by more than this fraction is a warning
RATE_MISMATCH_WARNING = 0.01
#: lines a logger may write before the header (its own metadata, such as "Fs,100"): the header is the first line
#: that names every column asked for, searched this far; those before it are skipped and reported
MAX_PREAMBLE_LINES = 50
#: lines after the last sample that are not samples (a logger's footer, a row it did not finish when stopped):
#: skipped and reported up to this many; more, or one followed by samples, stops the import
MAX_TRAILING_LINES = 10
#: rows converted to numbers at a time while reading
_BLOCK_ROWS = 65536
#: the range of a lab temperature given with --temperature, degC: the widest a MEMS IMU is rated for (automotive
#: and military grades run from -55 to +125 degC), with a margin
LAB_TEMPERATURE = (-100.0, 200.0)
#: the temperature assumed for each segment when the log has no temperature channel, degC
DEFAULT_TEMPERATURE = 20.0
#: a sample more than this fraction beyond its channel's declared full scale is an error: a sensor cannot read
#: beyond its rail, so the full scale or the units are wrong (the margin allows a converter whose rail lies a little
#: beyond its part's nominal range)
FULL_SCALE_EXCEEDED = 0.02

WARNING_NAMES = ("gap", "jitter", "repeated_time", "sample_rate_mismatch", "saturated", "tilted_pose",
                 "unclosed_motion", "held_pose", "unusual_sample_rate", "constant_channel", "dropped_samples",
                 "delivery_times", "rest_turning_about_vertical", "glitch", "units_row", "trailing_lines")
#: up to this many glitch rows are listed by line in the warning
GLITCHES_LISTED = 10
#: two saturated stretches of one channel at most this many detector windows apart are one episode (a shake hits
#: the rail once per swing): one warning for it
SATURATION_EPISODE_WINDOWS = 1
#: a static pose whose gyro output is at least this (rad/s) and points along its own specific force (within
#: :data:`VERTICAL_TURN_CONE`) is warned of as possibly a steady turn about the vertical: the one turn that leaves
#: the accelerometers steady, which the detector (step 6) can tell from rest only against a rest elsewhere in the log
VERTICAL_TURN_RATE = math.radians(1.0)
#: half-angle of the cone about the specific force within which such a gyro output counts as along it. A bias of
#: random direction falls in it by chance 1 − cos 10° = 1.5 % of the time
VERTICAL_TURN_CONE = math.radians(10.0)
#: a sample rate from the time column outside this range (Hz) is a warning: an IMU log is sampled at 1 Hz to 100 kHz,
#: and a rate outside it is most often a time column in another unit than --time-unit says (ms read as s: 1000 Hz
#: reads as 1 Hz)
PLAUSIBLE_SAMPLE_RATE = (1.0, 1e5)


#: up to this many tilted poses are warned of one by one; more, in one warning that lists them
TILTED_LISTED_APART = 3


@dataclass(frozen=True)
class LogWarning:
    """A flaw of the log that does not stop the import: ``name`` (one of :data:`WARNING_NAMES`) and text."""

    name: str
    message: str


@dataclass(frozen=True)
class LogTable:
    """The columns read from a plain log, in the file's units.

    ``channels`` (N, 6) in the order gx gy gz ax ay az; ``time`` (N,) in the time column's unit or None;
    ``temperature`` (N,) degC or None; ``names`` the six channel column names; ``ignored`` the columns
    not used; ``first_line`` the file line of the first sample (1-based).
    """

    path: Path
    channels: np.ndarray
    names: tuple[str, ...]
    time: np.ndarray | None
    time_column: str | None
    temperature: np.ndarray | None
    temperature_column: str | None
    ignored: tuple[str, ...]
    first_line: int
    lines: np.ndarray = field(repr=False, default=None)  # the file line of every sample
    #: lines before the header that are not comments and not the header: a logger's own metadata
    #: ("Fs,100"), skipped and reported, never read as numbers (:data:`MAX_PREAMBLE_LINES` at most)
    preamble: tuple[str, ...] = ()
    header_line: int = 1  # the file line of the header (1-based)
    decimal_comma: bool = False  # some values were written with a decimal comma (";"- or tab-separated logs)
    #: False: the log has no header line; its columns are named by their position, "1" for the first
    has_header: bool = True
    #: a row of units just under the header ("s,deg/s,…"): its line and the channels' six entries, skipped
    units_row: tuple[int, tuple[str, ...]] | None = None
    #: ``(line, why)`` of the lines after the last sample that are not samples (a footer, a row the logger did
    #: not finish, a last line with no line break): skipped (:data:`MAX_TRAILING_LINES` at most)
    trailing: tuple[tuple[int, str], ...] = ()
    #: the first sample's clock time where the time column holds clock times (``time`` is then in seconds from
    #: it), else None
    clock_start: str | None = None


@dataclass(frozen=True)
class ImportResult:
    """What :func:`import_log` gives: the recording, the detector's findings and the warnings."""

    recording: Recording
    table: LogTable
    timing: TimeReport
    segmentation: Segmentation
    units: tuple[str, ...]
    scale: tuple[float, ...] | None
    warnings: tuple[LogWarning, ...]
    offset: tuple[float, ...] | None = None  # counts at zero input (--offset), or None
    #: the channels read reversed (a leading '-' in ``columns``: an axis whose sign the log has the other way)
    reversed_channels: tuple[str, ...] = ()


def _split_list(text: str, option: str) -> list[str]:
    items = [item.strip() for item in str(text).split(",")]
    if not items or any(not item for item in items):
        raise ValueError(f"{option} {text!r}: expected a comma-separated list without empty entries")
    return items


def parse_units(text: str | None) -> tuple[str, ...]:
    """The unit of each of the six channels from ``--units``: two entries (gyros, accelerometers) or six.

    Gyro units are those of :data:`plansim.units.KINDS` ``angular_rate`` (rad/s, deg/s, deg/h), accelerometer
    units those of ``acceleration`` (m/s^2, g, mg, ug). ``None``: SI (rad/s, m/s^2).
    """
    if text is None:
        return ("rad/s",) * 3 + ("m/s^2",) * 3
    items = _split_list(text, "--units")
    if len(items) == 2:
        items = [items[0]] * 3 + [items[1]] * 3
    if len(items) != 6:
        raise ValueError(f"--units {text!r}: {len(items)} entries; expected 2 (gyro unit, accelerometer unit) or 6 "
                         f"(one per channel {', '.join(CHANNELS)})")
    for k, unit in enumerate(items):
        kind = "angular_rate" if k < 3 else "acceleration"
        items[k] = unit = UNIT_SPELLINGS.get(unit, unit)
        if unit not in KINDS[kind]:
            hint = f" ({SCALED_UNITS[unit]})" if unit in SCALED_UNITS else ""
            raise ValueError(f"--units {text!r}: {unit!r} for channel {CHANNELS[k]}{hint}; allowed: "
                             f"{', '.join(u for u in KINDS[kind] if u)}")
    return tuple(items)


#: other spellings of the units of :data:`plansim.units.KINDS` that logs and data sheets use (``--units``)
UNIT_SPELLINGS = {"dps": "deg/s", "deg/sec": "deg/s", "°/s": "deg/s", "degree/s": "deg/s", "degrees/s": "deg/s",
                  "rad/sec": "rad/s", "rps": "rad/s", "°/h": "deg/h", "dph": "deg/h", "m/s2": "m/s^2",
                  "m/s²": "m/s^2", "m/s/s": "m/s^2", "m/sec^2": "m/s^2", "µg": "ug", "μg": "ug"}
#: units that are a scaled unit of KINDS: how to read them (``--units``' error)
SCALED_UNITS = {"mdps": "1e-3 deg/s: give --units deg/s with --scale 1000", "mdeg/s": "give --units deg/s with "
                "--scale 1000", "mrad/s": "give --units rad/s with --scale 1000", "m/s^2*1000": "give --units m/s^2 "
                "with --scale 1000", "mm/s^2": "give --units m/s^2 with --scale 1000"}


def parse_scale(text: str | None) -> tuple[float, ...] | None:
    """Counts per unit from ``--scale``: two entries (gyros, accelerometers) or six; ``None``: not counts."""
    return _per_channel(text, "--scale", "counts per gyro unit, counts per accelerometer unit", positive=True)


def parse_offset(text: str | None) -> tuple[float, ...] | None:
    """The counts read at zero input from ``--offset`` (an unsigned converter's mid-scale, e.g. 32768): two
    entries (gyros, accelerometers) or six; ``None``: 0. Subtracted before ``--scale`` divides."""
    return _per_channel(text, "--offset", "counts at zero input of the gyros, of the accelerometers", positive=False)


def parse_full_scale(text: str | None) -> tuple[float, ...] | None:
    """Each channel's full scale from ``--full-scale``, in the channels' ``--units`` (not counts): two entries
    (gyros, accelerometers) or six; ``None``: not known (the rail is then looked for in the data)."""
    return _per_channel(text, "--full-scale", "gyro full scale, accelerometer full scale", positive=True,
                        allowed="a positive full scale in the channel's unit (--units)")


def _per_channel(text: str | None, option: str, pair: str, positive: bool,
                 allowed: str = "a positive number of counts per unit") -> tuple[float, ...] | None:
    """Two entries (gyros, accelerometers) or six numbers of *option*; ``None`` when not given."""
    if text is None:
        return None
    items = _split_list(text, option)
    if len(items) == 2:
        items = [items[0]] * 3 + [items[1]] * 3
    if len(items) != 6:
        raise ValueError(f"{option} {text!r}: {len(items)} entries; expected 2 ({pair}) or 6 (one per channel)")
    values = []
    for k, item in enumerate(items):
        try:
            value = float(item)
        except ValueError:
            raise ValueError(f"{option} {text!r}: {item!r} for channel {CHANNELS[k]} is not a number") from None
        if not math.isfinite(value) or (positive and not value > 0):
            expected = allowed if positive else "a finite number of counts"
            raise ValueError(f"{option} {text!r}: {item!r} for channel {CHANNELS[k]}; expected {expected}")
        values.append(value)
    return tuple(values)


def read_log(path: str | os.PathLike, columns: tuple[str, ...] | None = None, time_column: str | None = None,
             temperature_column: str | None = None) -> LogTable:
    """Read the columns of a plain CSV log, checking every row.

    Parameters
    ----------
    path : str or os.PathLike
        The log: UTF-8 text, optional ``#`` comment lines, a header line of column names (a commented one
        counts, as EuRoC's ``#timestamp [ns],w_RS_S_x [rad s^-1],…``), one row per sample; comma-, semicolon-
        or tab-separated (with ``;`` or tabs, a decimal comma is read: ``0,123``).
    columns : tuple of 6 str or None
        The column names of gx gy gz ax ay az; columns not named (and not the time or temperature column)
        are ignored. ``None``: the columns must be named ``gx gy gz ax ay az`` and the log may hold no other.
    time_column, temperature_column : str or None
        Names of the time and temperature columns, if any. A time column of clock times (ISO 8601 date and time,
        ``2024-11-27 14:22:31.504`` or with ``T``, ``/`` or unpadded fields, or the time of day alone,
        ``14:22:31.504``) is read as such, in seconds from its first sample (:func:`_clock_time`); the first
        sample decides.

    Raises
    ------
    ValueError
        The file is missing or not text; a column is missing, named twice or not expected; a row has more
        or fewer values than the header; a value is not a finite number. The message names the file, the
        line and the column.
    """
    target = Path(path)
    where = f"log {str(target)!r}"
    if not target.is_file():
        raise ValueError(f"{where} does not exist")
    names = DEFAULT_COLUMNS if columns is None else tuple(columns)
    if len(names) != 6:
        raise ValueError(f"--columns {','.join(names)!r}: {len(names)} names; expected 6, in the order "
                         f"{', '.join(CHANNELS)}")
    wanted = list(names) + [c for c in (time_column, temperature_column) if c is not None]
    repeated = sorted({name for name in wanted if wanted.count(name) > 1})
    if repeated:
        raise ValueError(f"{where}: column {repeated[0]!r} is named for two uses (channels, --time, "
                         "--temperature-column)")
    with _text_file(target, where) as fh:
        header_line = 0
        header = None
        has_header = True
        first = None  # the first line that is not a comment: the header, unless a preamble precedes it
        previous = None  # the last line read that is not a comment
        preamble: list[str] = []
        for line in iter(fh.readline, ""):  # readline, not iteration: the look-ahead below may seek back
            header_line += 1
            stripped = line.strip()
            if not stripped:
                continue
            if stripped.startswith("#"):
                # a commented header names the columns too (EuRoC, TUM-VI, Kalibr: "#timestamp [ns],w_RS_S_x …")
                # read without its '#' ("timestamp [ns]") or as it stands ("#timestamp [ns]", as a user copies it)
                uncommented = stripped.lstrip("#").strip()
                if uncommented and set(wanted) <= set(_names(uncommented)):
                    header = uncommented
                    break
                if set(wanted) <= set(_names(stripped)):
                    header = stripped
                    break
                continue
            if _all_numbers(stripped) and _next_row_alike(fh, stripped):
                if previous is not None and _width(previous[1]) == _width(stripped):
                    # the line before names as many columns: the header, though not the columns asked for
                    header_line, header = previous
                    preamble = preamble[:-1]
                    break
                # no header line: the first sample (a row of numbers followed by another of as many); the
                # columns are named by their position, 1 for the first
                has_header = False
                header_line -= 1
                header = line
                break
            previous = (header_line, line)
            if first is None:
                first = (header_line, line)
            if set(wanted) <= set(_names(line)):
                header = line
                break
            preamble.append(stripped)
            if len(preamble) > MAX_PREAMBLE_LINES:
                break
        if header is None and first is not None:
            header_line, header = first  # no line names every column: report against the first one
            preamble = []
        if header is None:
            raise ValueError(f"{where}: no header line; expected a line of column names, then one row per sample")
        if preamble or not has_header:  # lines were read past the header; read again from just after it
            fh.seek(0)
            for _ in range(header_line):
                fh.readline()
        delimiter = _delimiter(header)
        header_names = _names(header) if has_header else [str(k + 1) for k in range(len(_split(header, delimiter)))]
        duplicates = sorted({name for name in header_names if header_names.count(name) > 1})
        if duplicates:
            raise ValueError(f"{where}: column {duplicates[0]!r} appears more than once in the header "
                             f"(line {header_line})")
        missing = [name for name in wanted if name not in header_names]
        if missing and not has_header:
            raise ValueError(f"{where}: column {missing[0]!r} is missing: the log has no header line (line "
                             f"{header_line + 1} is its first sample, {len(header_names)} columns); name the columns "
                             "by their position, 1 for the first, e.g. --columns 2,3,4,5,6,7 --time 1")
        if missing:
            hint = "" if columns is not None else (" (name the six channel columns with --columns GX,GY,GZ,AX,AY,AZ)")
            raise ValueError(f"{where}: column {missing[0]!r} is missing; the header (line {header_line}) has "
                             f"{', '.join(header_names)}{hint}")
        ignored = tuple(name for name in header_names if name not in wanted)
        if columns is None and ignored:
            raise ValueError(f"{where}: column {ignored[0]!r} is not expected: without --columns the log holds "
                             f"exactly the channels {', '.join(CHANNELS)} (and the --time and --temperature-column "
                             "columns if given); name the six channel columns with --columns (the other columns "
                             "are then ignored)")
        index = [header_names.index(name) for name in wanted]
        width = len(header_names)
        decimal_comma = False
        blocks: list[np.ndarray] = []  # rows converted block by block: floats, not text, are kept
        block: list[list[float]] = []
        lines: list[int] = []
        line_number = header_line
        cut = _unterminated_last_line(target)  # a logger stopped while writing its last row
        clock = None  # the time column holds clock times (decided on the first sample): (days, seconds) of it
        day = 0  # whole days a time of day alone has passed midnight
        previous_stamp = 0.0
        units_row = None
        trailing: list[tuple[int, str, str]] = []  # (line, why, the error it is if a sample follows)
        for row in _rows(fh, delimiter):
            line_number += 1
            if not row or all(not cell.strip() for cell in row):
                continue
            if row[0].lstrip().startswith("#"):
                continue
            if line_number == cut:
                trailing.append((line_number, "no line break", ""))
                continue
            if has_header and not lines and units_row is None and len(row) == width and all(
                    row[k].strip() and not _is_number(row[k].strip(), delimiter) for k in index):
                units_row = (line_number, tuple(row[k].strip() for k in index[:6]))  # "s,deg/s,…" under the header
                continue
            if len(row) != width:
                word = "more" if len(row) > width else "fewer"
                trailing.append((line_number, f"{len(row)} values, not {width}",
                                 f"{where}: line {line_number} has {len(row)} values, {word} than the {width} columns "
                                 f"of the header (line {header_line}); every row holds one value per column"))
                continue
            if time_column is not None:
                text = row[index[6]].strip()
                if clock is None:  # the first sample decides
                    clock = False if _is_number(text, delimiter) else (_clock_time(text) or False)
                if clock:
                    stamp = _clock_time(text)
                    if stamp is None or (stamp[0] is None) != (clock[0] is None):  # a date where the first had none
                        trailing.append((line_number, f"{time_column} is {text!r}",
                                         f"{where}: column {time_column!r} is {text!r} at line {line_number}; "
                                         f"expected a clock time, as the first sample's ({clock[2]!r})"))
                        continue
                    if stamp[0] is None:  # a time of day: it passes midnight where it falls by more than 12 h
                        if lines and stamp[1] + day * 86400.0 < previous_stamp - 43200.0:
                            day += 1
                        seconds = stamp[1] + day * 86400.0
                    else:
                        seconds = (stamp[0] - clock[0]) * 86400.0 + stamp[1]
                    previous_stamp = seconds
                    row = list(row)
                    row[index[6]] = repr(seconds - clock[1])  # seconds from the first sample, read as any number
            try:
                numbers = [float(row[k]) for k in index]
            except ValueError:
                numbers = None
                if delimiter != ",":  # a decimal comma (a spreadsheet's export in many locales): 0,123;4,5
                    try:
                        numbers = [float(row[k].replace(",", ".", 1)) if row[k].count(",") == 1 else float(row[k])
                                   for k in index]
                        decimal_comma = True
                    except ValueError:
                        numbers = None
            if numbers is None:
                j = next(j for j, k in enumerate(index) if not _is_number(row[k], delimiter))
                trailing.append((line_number, f"{wanted[j]} is {row[index[j]].strip()!r}",
                                 f"{where}: column {wanted[j]!r} is {row[index[j]].strip()!r} at line {line_number}; "
                                 "expected a number"))
                continue
            if trailing:  # a line that is not a sample, followed by samples: the log is broken there
                raise ValueError(trailing[0][2])
            if not all(map(math.isfinite, numbers)):
                j = next(j for j, v in enumerate(numbers) if not math.isfinite(v))
                raise ValueError(f"{where}: column {wanted[j]!r} is {row[index[j]].strip()!r} at line {line_number}; "
                                 "every value must be a finite number (a sample lost by the logger? cut the log before "
                                 "or after it)")
            block.append(numbers)
            lines.append(line_number)
            if len(block) == _BLOCK_ROWS:
                blocks.append(np.array(block, dtype=np.float64))
                block = []
        if block:
            blocks.append(np.array(block, dtype=np.float64))
    if not blocks:
        if trailing and trailing[0][2]:
            raise ValueError(trailing[0][2])
        raise ValueError(f"{where}: no sample after the header (line {header_line})")
    if len(trailing) > MAX_TRAILING_LINES:
        raise ValueError(next(error for _, _, error in trailing if error))
    data = np.concatenate(blocks)
    time = data[:, 6] if time_column is not None else None
    temperature = data[:, -1] if temperature_column is not None else None
    return LogTable(target, data[:, :6], names, time, time_column, temperature, temperature_column, ignored,
                    lines[0], np.array(lines, dtype=np.int64), tuple(preamble), header_line, decimal_comma,
                    has_header, units_row, tuple((line, why) for line, why, _ in trailing),
                    clock[2] if clock else None)


def _delimiter(line: str) -> str:
    """The delimiter of a line: the one of :data:`DELIMITERS` that splits it into the most fields, or
    :data:`WHITESPACE` when none of them splits it and runs of spaces do."""
    best = max(DELIMITERS, key=lambda d: len(next(csv.reader([line], delimiter=d))))
    if len(next(csv.reader([line], delimiter=best))) == 1 and len(line.split()) > 1:
        return WHITESPACE
    return best


def _split(line: str, delimiter: str) -> list[str]:
    """The fields of one line at *delimiter* (:data:`WHITESPACE`: runs of spaces and tabs)."""
    if delimiter == WHITESPACE:
        return line.split()
    return next(csv.reader([line], delimiter=delimiter))


def _rows(fh, delimiter: str):
    """The rows of the rest of an open log, each a list of fields."""
    if delimiter != WHITESPACE:
        yield from csv.reader(fh, delimiter=delimiter)
        return
    for line in fh:
        yield line.split()


def _names(line: str) -> list[str]:
    """The stripped fields of one line, split at its own delimiter."""
    return [name.strip() for name in _split(line, _delimiter(line))]


def _all_numbers(line: str) -> bool:
    """Whether a line is a sample, not a header: at least two fields, every one a number."""
    delimiter = _delimiter(line)
    fields = _split(line, delimiter)
    return len(fields) >= 2 and all(_is_number(f.strip(), delimiter) for f in fields)


def _width(line: str) -> int:
    """The number of fields of one line at its own delimiter."""
    return len(_split(line, _delimiter(line)))


def _next_row_alike(fh, line: str) -> bool:
    """Whether the next line of *fh* that is not blank or a comment is a row of numbers as wide as *line* (or
    there is none): a lone numeric line of a logger's preamble ("2024,11,27") is not taken for a sample."""
    width = _width(line)
    position = fh.tell()
    try:
        for following in iter(fh.readline, ""):
            text = following.strip()
            if text and not text.startswith("#"):
                return _all_numbers(text) and _width(text) == width
        return True
    finally:
        fh.seek(position)


#: a clock time in a time column: an optional date (year, month, day; '-', '/' or '.' between, unpadded fields too)
#: and a time of day (hours, minutes, seconds with a fraction after '.' or ','), an optional zone that is ignored
_CLOCK_TIME = re.compile(r"^(?:(\d{4})[-/.](\d{1,2})[-/.](\d{1,2})[ T])?(\d{1,2}):(\d{2}):(\d{2}(?:[.,]\d+)?)"
                         r"\s*(?:Z|[+-]\d{2}:?\d{2})?$")


def _clock_time(text: str) -> tuple[int | None, float, str] | None:
    """A clock time's (day number or None for a time of day alone, seconds into the day, the text); None if the
    text is not one (:data:`_CLOCK_TIME`)."""
    match = _CLOCK_TIME.match(text.strip())
    if match is None:
        return None
    year, month, day, hours, minutes, seconds = match.groups()
    try:
        days = None if year is None else datetime.date(int(year), int(month), int(day)).toordinal()
    except ValueError:
        return None
    if int(hours) > 23 or int(minutes) > 59 or float(seconds.replace(",", ".")) >= 61.0:
        return None
    return days, int(hours) * 3600.0 + int(minutes) * 60.0 + float(seconds.replace(",", ".")), text.strip()


def _is_number(text: str, delimiter: str = ",") -> bool:
    try:
        float(text)
    except ValueError:
        if delimiter == "," or text.count(",") != 1:
            return False
        try:
            float(text.replace(",", ".", 1))
        except ValueError:
            return False
    return True


def import_log(path: str | os.PathLike, *, columns: tuple[str, ...] | None = None, time_column: str | None = None,
               time_unit: str = "s", units: str | None = None, scale: str | None = None,
               offset: str | None = None, sample_rate: float | None = None, temperature_column: str | None = None,
               temperature: float | None = None, latitude: float | None = None, height: float | None = None,
               window: float = DEFAULT_WINDOW, min_static: float = DEFAULT_MIN_STATIC,
               full_scale: str | None = None) -> ImportResult:
    """Read a plain log and cut it into segments (see the module docstring and docs/measured-data.md).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV log.
    columns : tuple of 6 str or None
        Channel column names in the order gx gy gz ax ay az (default: those names).
    time_column : str or None
        The time column; ``None``: the log has none and ``sample_rate`` is required.
    time_unit : str
        Unit of the time column: ``s``, ``ms``, ``us``, ``ns`` or ``samples`` (a sample counter; needs
        ``sample_rate``).
    units : str or None
        ``--units``: the channels' units (or, with ``scale``, the unit the counts are per); default SI.
    scale : str or None
        ``--scale``: counts per unit, two or six entries; ``None``: the channels are in ``units``.
    offset : str or None
        ``--offset``: the counts read at zero input, two or six entries (needs ``scale``); the channels are
        ``(counts − offset) / scale``. ``None``: 0.
    sample_rate : float or None
        Hz. Without a time column, required; with one, the nominal rate (default: estimated from it).
    temperature_column : str or None
        A temperature column in degC, kept as the recording's temperature channel.
    temperature : float or None
        The lab's temperature, degC, for the segment table when the log has no temperature column
        (default 20 degC, noted in the attributes as assumed).
    latitude, height : float or None
        The site, deg and m, written as ``site_latitude_deg`` and ``site_height_m``.
    window, min_static : float
        The detector's window and shortest static span, s.
    full_scale : str or None
        ``--full-scale``: each channel's full scale (the largest magnitude it reads) in ``units``, two or six
        entries; a sample within :data:`plansim.estimate.segmentation.FULL_SCALE_MARGIN` of it is at the rail.
        ``None``: a rail is looked for in the data (step 10 of :mod:`plansim.estimate.segmentation`).

    Raises
    ------
    ValueError
        A bad log (see :func:`read_log`), a bad option (naming it, the value and what is allowed), time
        going backwards, no static span (too few static samples), or accelerometer outputs at rest far from
        1 g (wrong units or scale).
    """
    unit_names = parse_units(units)
    counts_per_unit = parse_scale(scale)
    if counts_per_unit is not None and units is None:
        raise ValueError(f"--scale {scale!r} needs --units: say which unit the counts are per (e.g. --units "
                         "deg/s,g)")
    zero_counts = parse_offset(offset)
    rails = parse_full_scale(full_scale)
    if zero_counts is not None and counts_per_unit is None:
        raise ValueError(f"--offset {offset!r} needs --scale (and --units): the offset is in counts")
    if time_unit not in TIME_UNITS:
        raise ValueError(f"--time-unit {time_unit!r}; allowed: {', '.join(TIME_UNITS)}")
    if sample_rate is not None and not (sample_rate > 0 and math.isfinite(sample_rate)):
        raise ValueError(f"--sample-rate {sample_rate!r}: expected a positive number of Hz")
    if time_column is None and sample_rate is None:
        raise ValueError("the log's sample rate is not known: give --time COLUMN (the time of each sample) or "
                         "--sample-rate HZ")
    if time_unit == "samples" and sample_rate is None:
        raise ValueError("--time-unit samples: a sample counter needs --sample-rate HZ")
    if temperature_column is not None and temperature is not None:
        raise ValueError("--temperature and --temperature-column: give one (the log's column, or the lab's "
                         "temperature)")
    for option, value in (("--window", window), ("--min-static", min_static)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{option} {value!r}: expected a positive number of seconds")
    if temperature is not None and not (math.isfinite(temperature)
                                        and LAB_TEMPERATURE[0] <= temperature <= LAB_TEMPERATURE[1]):
        raise ValueError(f"--temperature {temperature!r}: expected the lab's temperature, {LAB_TEMPERATURE[0]:g} to "
                         f"{LAB_TEMPERATURE[1]:g} degC (the widest range a MEMS IMU is rated for)")
    site = {}
    for key, value, option in (("site_latitude_deg", latitude, "--latitude"), ("site_height_m", height, "--height")):
        if value is None:
            continue
        unit, lowest, highest = SITE_ATTRIBUTES[key]
        if not lowest <= value <= highest:
            raise ValueError(f"{option} {value!r}: expected a number from {lowest:g} to {highest:g} {unit}")
        site[key] = float(value)

    # a leading '-' reverses a channel: an axis whose sign the log has the other way (plansim fit says where a
    # scale factor comes out negative)
    signs = np.ones(6)
    if columns is not None:
        signs = np.array([-1.0 if str(name).startswith("-") and len(str(name)) > 1 else 1.0 for name in columns])
        columns = tuple(str(name)[1:].strip() if sign < 0 else name for name, sign in zip(columns, signs))
    table = read_log(path, columns, time_column, temperature_column)
    where = f"log {str(table.path)!r}"
    n = table.channels.shape[0]
    factors = np.array([KINDS["angular_rate" if k < 3 else "acceleration"][u] for k, u in enumerate(unit_names)])
    divisors = (np.ones(6) if counts_per_unit is None else np.array(counts_per_unit)) * signs
    offsets = np.zeros(6) if zero_counts is None else np.array(zero_counts)
    samples = (table.channels - offsets) / divisors * factors
    rail_si = None if rails is None else np.array(rails) * factors
    if rail_si is not None:  # a sensor cannot read beyond its rail: the full scale (or the units) are wrong
        for c in range(6):
            k = int(np.argmax(np.abs(samples[:, c])))
            if abs(samples[k, c]) > (1.0 + FULL_SCALE_EXCEEDED) * rail_si[c]:
                raise ValueError(f"--full-scale {full_scale!r}: channel {CHANNELS[c]} ({table.names[c]}) reads "
                                 f"{samples[k, c] / factors[c]:.6g} {unit_names[c]} at line {table.lines[k]}, beyond "
                                 f"its full scale of {rails[c]:g} {unit_names[c]}; expected the range the sensor "
                                 "reads (in --units), e.g. 2000,16 with --units deg/s,g")

    warnings: list[LogWarning] = []
    if table.units_row is not None:
        line, entries = table.units_row
        warnings.append(LogWarning("units_row", f"line {line}, under the header, reads {', '.join(entries)} for "
                                                f"{', '.join(CHANNELS)}: a row of units, skipped, not read; the "
                                                f"channels are read in {', '.join(dict.fromkeys(unit_names))} "
                                                "(--units): check that they agree"))
    if table.trailing:
        shown = "; ".join(f"line {line}: {why}" for line, why in table.trailing[:4])
        warnings.append(LogWarning("trailing_lines", f"{len(table.trailing)} line(s) after the last sample (line "
                                                     f"{table.lines[-1]}) are not samples, skipped: {shown}"
                                                     + ("; …" if len(table.trailing) > 4 else "")
                                                     + " (a footer, or a row the logger did not finish)"))
    time_s = None
    if table.clock_start is not None and time_unit != "s":
        raise ValueError(f"--time-unit {time_unit}: column {table.time_column!r} holds clock times "
                         f"({table.clock_start!r}), read in seconds from the first; leave --time-unit out")
    if table.time is not None:
        seconds = (1.0 / sample_rate) if time_unit == "samples" else TIME_UNITS[time_unit]
        time_s = table.time * seconds
        backwards = np.flatnonzero(np.diff(time_s) < 0)
        if backwards.size:
            k = int(backwards[0]) + 1
            raise ValueError(f"{where}: column {table.time_column!r} goes backwards at line {table.lines[k]} "
                             f"({float(table.time[k - 1])!r} then {float(table.time[k])!r} {time_unit}, line "
                             f"{table.lines[k - 1]} "
                             "then this one); the time of a log never decreases (rows out of order, or two logs "
                             "pasted together?)")
    try:
        timing = analyse_time(time_s, n, sample_rate)
    except ValueError as exc:
        raise ValueError(f"{where}: column {table.time_column!r}: {exc}") from None
    period = 1.0 / timing.sample_rate
    if timing.dropped:
        warnings.append(LogWarning("dropped_samples", f"{timing.dropped_samples} sample(s) dropped in "
                                                      f"{len(timing.dropped)} place(s), at most {DROPPED_MAX} in a row "
                                                      f"(first before line {table.lines[timing.dropped[0][0]]}): kept "
                                                      "inside poses and turns, a turn integrated over the time column"))
    if timing.gaps:
        k, dt = max(timing.gaps, key=lambda g: g[1])
        warnings.append(LogWarning("gap", f"{len(timing.gaps)} gap(s) in the time column, {timing.missing_samples} "
                                          f"sample(s) missing; the largest, {dt:.6g} s, before line {table.lines[k]}. "
                                          "No static span holds a gap, and a turn across one has no angle"))
    if timing.repeated:
        warnings.append(LogWarning("repeated_time", f"{timing.repeated} time step(s) of exactly 0 s: the time "
                                                    "column's resolution is coarser than the sample period?"))
    if timing.delivery:
        warnings.append(LogWarning("delivery_times", f"column {table.time_column!r} stamps the rows' delivery, not "
                                                     "their sampling (its steps are no whole number of its usual "
                                                     f"step: bursts, or jitter of {timing.jitter_rms:.3g} s RMS, "
                                                     f"largest {timing.jitter_max:.3g} s, against a period of "
                                                     f"{period:.6g} s): the samples are taken as evenly spaced at "
                                                     f"{timing.sample_rate:.6g} Hz between gaps; a dropped sample "
                                                     "cannot be told from a late one"))
    elif timing.jitter_rms > JITTER_WARNING * period:
        warnings.append(LogWarning("jitter", f"timing jitter {timing.jitter_rms:.3g} s RMS (largest "
                                             f"{timing.jitter_max:.3g} s) is more than {JITTER_WARNING:.0%} of the "
                                             f"sample period {period:.6g} s"))
    if sample_rate is not None and time_s is not None and math.isfinite(timing.estimated_rate) and time_unit != \
            "samples" and abs(timing.estimated_rate / sample_rate - 1.0) > RATE_MISMATCH_WARNING:
        warnings.append(LogWarning("sample_rate_mismatch", f"--sample-rate {sample_rate:g} Hz but the time column "
                                                           f"gives {timing.estimated_rate:.6g} Hz"))

    if time_s is not None and time_unit != "samples" and not \
            PLAUSIBLE_SAMPLE_RATE[0] <= timing.sample_rate <= PLAUSIBLE_SAMPLE_RATE[1]:
        per_unit = {u: timing.sample_rate * TIME_UNITS[time_unit] / f for u, f in TIME_UNITS.items()
                    if u not in (time_unit, "samples")}
        usual = [f"{u} ({rate:.6g} Hz)" for u, rate in per_unit.items()
                 if PLAUSIBLE_SAMPLE_RATE[0] <= rate <= PLAUSIBLE_SAMPLE_RATE[1]]
        warnings.append(LogWarning("unusual_sample_rate", f"column {table.time_column!r} read in {time_unit} gives "
                                                          f"{timing.sample_rate:.6g} Hz, outside the "
                                                          f"{PLAUSIBLE_SAMPLE_RATE[0]:g}-{PLAUSIBLE_SAMPLE_RATE[1]:g} "
                                                          "Hz of IMU logs: is the time in another unit? "
                                                          + (f"(--time-unit {', '.join(usual)})" if usual else "")))
    for c in range(6):
        if n > 1 and np.ptp(table.channels[:, c]) == 0:
            warnings.append(LogWarning("constant_channel", f"channel {CHANNELS[c]} ({table.names[c]}) reads "
                                                           f"{table.channels[0, c]:.6g} in every one of the {n} "
                                                           "rows: a dead or disconnected sensor, or a wrong "
                                                           "column? plansim fit refuses a channel that never "
                                                           "changes"))

    if timing.sample_times is not None:
        time_s = timing.sample_times
    segmentation = segment_log(samples, time_s, timing.sample_rate, window=window, min_static=min_static,
                               gap_starts=timing.gap_starts, full_scale=rail_si)
    statics = segmentation.of_kind("static")
    at_rest = float(np.median([np.linalg.norm(span.mean[3:]) for span in statics]))
    if abs(at_rest / STANDARD_GRAVITY - 1.0) > GRAVITY_TOLERANCE:
        unit_text = ", ".join(dict.fromkeys(unit_names[3:]))
        if counts_per_unit is not None:
            unit_text += f" at {', '.join(f'{c:g}' for c in counts_per_unit[3:])} counts per unit"
        raise ValueError(f"{where}: at rest the accelerometers read {at_rest:.3f} m/s^2 (median over "
                         f"{len(statics)} static span(s)); expected about {STANDARD_GRAVITY} m/s^2 (1 g). Are the "
                         f"accelerometer columns, units or scale right? (read as {unit_text})")
    if segmentation.glitches:
        rows = segmentation.glitches
        listed = ", ".join(str(table.lines[k]) for k in rows[:GLITCHES_LISTED]) + (", …" if len(rows) >
                                                                                   GLITCHES_LISTED else "")
        warnings.append(LogWarning("glitch", f"{len(rows)} isolated glitch row(s) (all six channels exactly 0, or "
                                             "a sample far off both its neighbours), on line(s) " + listed + ": kept "
                                             "in the recording as logged, but in no static pose (a pose is cut or "
                                             "trimmed around each); the detector and a turn's integral take each as "
                                             "the mean of its neighbours"))
    for episode in _saturation_episodes(segmentation.saturation, SATURATION_EPISODE_WINDOWS * segmentation.window):
        c, start, stop = episode[0].channel, episode[0].start, max(s.stop for s in episode)
        first, last = table.lines[start], table.lines[stop - 1]
        extent = f"lines {first}-{last} ({(stop - start) / timing.sample_rate:.3g} s)"
        values = sorted({s.value for s in episode})
        shown = " and ".join(_as_logged(v, c, factors, divisors, offsets, unit_names, counts_per_unit is not None)
                             for v in values)
        channel = f"channel {CHANNELS[c]} ({table.names[c]})"
        stretches = "" if len(episode) == 1 else f" in {len(episode)} stretches"
        pose = next((span for span in statics if span.start < stop and start < span.stop), None)
        in_pose = ("" if pose is None else f"; inside the static pose on lines {table.lines[pose.start]}-"
                   f"{table.lines[pose.stop - 1]}, whose mean it clips: remove that segment from the table")
        if rails is None:
            text = (f"{channel} stuck at {shown} (its extreme){stretches} on {extent}: a rail? A turn "
                    "over it has no angle")
        else:
            text = (f"{channel} reads {shown}, at its full scale of {rails[c]:g} {unit_names[c]} (--full-scale)"
                    f"{stretches}, on {extent}: a turn over it has no angle")
        warnings.append(LogWarning("saturated", text + in_pose))
    tilted = [span for span in statics if span.orientation == "unknown"]
    if len(tilted) <= TILTED_LISTED_APART:
        for span in tilted:
            warnings.append(LogWarning("tilted_pose", f"the static span on lines {table.lines[span.start]}-"
                                                      f"{table.lines[span.stop - 1]} is tilted "
                                                      f"{math.degrees(span.tilt):.1f} deg from {span.up}: orientation "
                                                      "'unknown'"))
    else:  # a session of poses spread over the sphere (imu_tk's): one warning, every span in it
        spans = "; ".join(f"{table.lines[span.start]}-{table.lines[span.stop - 1]} ({math.degrees(span.tilt):.1f} "
                          f"deg from {span.up})" for span in tilted)
        warnings.append(LogWarning("tilted_pose", f"{len(tilted)} of the {len(statics)} static spans are tilted more "
                                                  f"than {math.degrees(APPROXIMATE_TILT):.0f} deg from every axis, "
                                                  f"orientation 'unknown' (poses spread over the sphere, as a "
                                                  f"hand-held session places them, expect it); lines {spans}"))
    for span in statics:
        rate, force = span.mean[:3], span.mean[3:]
        magnitude = float(np.linalg.norm(rate))
        along = abs(float(np.dot(rate, force))) / max(magnitude * float(np.linalg.norm(force)), 1e-300)
        if magnitude >= VERTICAL_TURN_RATE and along >= math.cos(VERTICAL_TURN_CONE):
            warnings.append(LogWarning("rest_turning_about_vertical", f"the static span on lines "
                                       f"{table.lines[span.start]}-{table.lines[span.stop - 1]} reads "
                                       f"{math.degrees(magnitude):.3g} deg/s on its gyros, within "
                                       f"{math.degrees(math.acos(min(along, 1.0))):.2g} deg of its vertical: a "
                                       "steady turn about the vertical looks like rest to the accelerometers; with "
                                       "no rest elsewhere in the log to compare with, it is taken for one, its "
                                       "rate for the gyros' bias. If the table was turning, make it a 'rotation' with "
                                       "its rate in the segment table (docs/measured-data.md, \"Review and edit "
                                       "the segment table\")"))
    held = [span for span in statics if math.isfinite(span.held)]
    if held:
        warnings.append(LogWarning("held_pose", f"{len(held)} static pose(s) held by hand: the accelerometers are "
                                                "quiet and hold one pose while the gyros shake (up to "
                                                f"{max(span.held for span in held):.3g} times their quiet noise); the "
                                                "fit gives such a pose's means their own scatter"))
    for span in segmentation.spans:
        if span.kind == "move" and span.reason.startswith("no static span"):
            warnings.append(LogWarning("unclosed_motion", f"lines {table.lines[span.start]}-"
                                                          f"{table.lines[span.stop - 1]} lie before the first or after "
                                                          "the last static span: kept as a 'move'"))

    segment_temperature = DEFAULT_TEMPERATURE if temperature is None else float(temperature)
    segments = []
    details = []
    counters = {"static": 0, "rotation": 0, "move": 0}
    for span in segmentation.spans:
        counters[span.kind] += 1
        seg_temperature = (float(np.mean(table.temperature[span.start:span.stop])) if table.temperature is not None
                           else segment_temperature)
        segments.append(_segment(span, counters[span.kind], timing.sample_rate, seg_temperature))
        details.append(_detail(span, table))
    schedule = Schedule(tuple(segments), procedure="imported", notes={"import": {
        "log": table.path.name,
        "columns": dict(zip(CHANNELS, [("-" if sign < 0 else "") + name for name, sign in zip(table.names, signs)])),
        "ignored_columns": list(table.ignored),
        "units": dict(zip(CHANNELS, unit_names)),
        "counts_per_unit": None if counts_per_unit is None else dict(zip(CHANNELS, counts_per_unit)),
        "zero_offset_counts": None if zero_counts is None else dict(zip(CHANNELS, zero_counts)),
        "full_scale": None if rails is None else dict(zip(CHANNELS, rails)),
        "saturation_rule": ("declared full scale (--full-scale): a sample within "
                            f"{FULL_SCALE_MARGIN:.1%} of it" if rails is not None
                            else "found in the data (no --full-scale): a stretch stuck at a channel's extreme"),
        "preamble": list(table.preamble),
        "header": table.has_header,
        "time_column": table.time_column,
        "time_unit": time_unit if table.time_column is not None else None,
        "detector": {
            "window_samples": segmentation.window,
            "min_static_samples": segmentation.min_static,
            "variance_threshold_accel": segmentation.variance_threshold[0],
            "variance_threshold_gyro": segmentation.variance_threshold[1],
            "rest_rate_threshold_rad_s": segmentation.rate_threshold.tolist(),
            "quiet_lines": [int(table.lines[segmentation.noise.start]),
                            int(table.lines[segmentation.noise.stop - 1])],
            "noise_sigma_si": dict(zip(CHANNELS, segmentation.noise.sigma.tolist())),
            "gyro_bias_rad_s": segmentation.noise.gyro_bias.tolist(),
        },
        "segments": details,
        "warnings": [{"name": w.name, "message": w.message} for w in warnings],
    }})
    attrs = {
        "source": "measured",
        "imported_from": table.path.name,
        "plansim_version": plansim_version(),
        "units": UNITS_DESCRIPTION,
        **site,
        "sample_rate_hz": timing.sample_rate,
        "sample_rate_source": ("time column" if sample_rate is None else "--sample-rate") if table.time is not None
        else "--sample-rate (no time column: gaps and jitter cannot be seen)",
        "detector_window_s": segmentation.window / timing.sample_rate,
        "detector_min_static_s": segmentation.min_static / timing.sample_rate,
        "import_warnings": ", ".join(dict.fromkeys(w.name for w in warnings)) or "none",
        "heading": "not known for any segment: a plain log has no heading reference",
    }
    if table.time is not None:
        attrs.update({"sample_rate_estimated_hz": timing.estimated_rate, "time_jitter_rms_s": timing.jitter_rms,
                      "time_jitter_max_s": timing.jitter_max, "time_gaps": len(timing.gaps),
                      "time_gap_missing_samples": timing.missing_samples,
                      "time_gap_largest_s": max((dt for _, dt in timing.gaps), default=0.0),
                      "time_dropped_samples": timing.dropped_samples,
                      "time_stamps": "delivery: the samples taken as evenly spaced between gaps" if timing.delivery
                      else "sampling"})
        if table.clock_start is not None:
            attrs["time_clock_start"] = table.clock_start
    if table.temperature is None:
        how = "given (--temperature)" if temperature is not None else "assumed (the log has no temperature)"
        attrs["segment_temperature"] = f"{segment_temperature:g} degC, {how}"
    for c, name in enumerate(CHANNELS):
        attrs[f"noise_{name}_si"] = float(segmentation.noise.sigma[c])
    timestamps = None if time_s is None else time_s
    try:
        recording = Recording(samples, schedule, attrs, timestamps=timestamps, temperature=table.temperature)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None
    return ImportResult(recording, table, timing, segmentation, unit_names, counts_per_unit, tuple(warnings),
                        zero_counts, tuple(CHANNELS[c] for c in range(6) if signs[c] < 0))


def _saturation_episodes(saturation, apart: int) -> list[list]:
    """The saturated stretches grouped per channel into episodes: a stretch at most *apart* samples after the
    previous one of its channel belongs to the same episode. In order of each episode's first sample."""
    episodes: dict[int, list[list]] = {}
    for s in sorted(saturation, key=lambda s: (s.channel, s.start)):
        mine = episodes.setdefault(s.channel, [])
        if mine and s.start - max(t.stop for t in mine[-1]) <= apart:
            mine[-1].append(s)
        else:
            mine.append([s])
    return sorted((e for mine in episodes.values() for e in mine), key=lambda e: (e[0].start, e[0].channel))


def _as_logged(value: float, c: int, factors, divisors, offsets, unit_names, counts: bool) -> str:
    """A channel's SI *value* as the file has it, with its unit: counts (and the SI value), or the --units unit."""
    si_unit = "rad/s" if c < 3 else "m/s^2"
    if counts:
        return f"{value / factors[c] * divisors[c] + offsets[c]:.6g} counts ({value:.6g} {si_unit})"
    return f"{value / factors[c] * divisors[c]:.6g} {unit_names[c]}"


def _segment(span: Span, number: int, sample_rate: float, temperature: float) -> Segment:
    common = dict(dwell=span.samples / sample_rate, settle=0.0, sample_rate=sample_rate, temperature=temperature)
    if span.kind == "static":
        held = f", held (gyros shaking {span.held:.3g}x their quiet noise)" if math.isfinite(span.held) else ""
        return Segment(f"static {number}: {span.up} up, tilt {math.degrees(span.tilt):.1f} deg{held}", "static", 0,
                       span.up, heading=math.nan, orientation=span.orientation, **common)
    measured = math.degrees(float(span.integrated[span.axis])) if span.axis >= 0 else math.nan
    if span.kind == "rotation":
        if math.isfinite(span.steady_rate):  # a steady turn: the table's rate is its reference, and not logged
            label = (f"rotation {number}: steady at {math.degrees(span.steady_rate):+.5g} deg/s about "
                     f"+{AXES[span.axis]} (measured; {measured:+.2f} deg): give the table's rate")
        else:
            label = (f"rotation {number}: {math.degrees(span.angle):+.0f} deg about +{AXES[span.axis]} (measured "
                     f"{measured:+.2f} deg)")
        return Segment(label, "rotation", span.axis, span.up, heading=math.nan, rate=math.nan,
                       rate_axis=f"+{AXES[span.axis]}", angle=span.angle, orientation=span.orientation, **common)
    about = f"turned {measured:+.1f} deg about {AXES[span.axis]}" if span.axis >= 0 else "not integrated"
    return Segment(f"move {number}: {about}", "move", 0, span.up or "+z", heading=math.nan, rate=math.nan,
                   orientation="unknown", **common)


def _detail(span: Span, table: LogTable) -> dict:
    detail = {"kind": span.kind, "lines": [int(table.lines[span.start]), int(table.lines[span.stop - 1])],
              "mean_si": [float(v) for v in span.mean]}
    if span.kind == "static":
        detail["tilt_deg"] = math.degrees(span.tilt)
    else:
        detail["integrated_deg"] = [None if not math.isfinite(v) else math.degrees(float(v)) for v in span.integrated]
        if span.kind == "rotation":
            detail["steady_rate_deg_s"] = math.degrees(span.steady_rate) if math.isfinite(span.steady_rate) else None
        else:
            detail["why_not_a_rotation"] = span.reason
    return detail


def format_summary(result: ImportResult) -> str:
    """The import's findings as text, every number with its unit (what ``plansim import`` prints)."""
    table, timing, seg = result.table, result.timing, result.segmentation
    rec = result.recording
    lines = [f"plansim import {table.path.name}: {rec.samples.shape[0]} samples"]
    unit_text = ", ".join(dict.fromkeys(result.units))
    if result.scale is not None:
        unit_text = "counts: " + ", ".join(f"{c:g}/{u}" for c, u in zip(result.scale, result.units))
        if result.offset is not None:
            unit_text += " after subtracting " + ", ".join(f"{c:g}" for c in result.offset) + " counts (--offset)"
    lines.append("  channels: " + " ".join(f"{c}={'-' if c in result.reversed_channels else ''}{n}"
                                           for c, n in zip(CHANNELS, table.names)) + f" ({unit_text})"
                 + (f"; ignored: {', '.join(table.ignored)}" if table.ignored else ""))
    if not table.has_header:
        lines.append(f"  no header line: columns named by position, 1 for the first (first sample on line "
                     f"{table.first_line})")
    if table.decimal_comma:
        lines.append("  numbers with a decimal comma (0,123) read as such: the values are separated by ';' or tabs")
    if table.preamble:
        shown = "; ".join(table.preamble[:4]) + ("; …" if len(table.preamble) > 4 else "")
        where = f"the header (line {table.header_line})" if table.has_header else f"line {table.first_line}"
        lines.append(f"  before {where}: {len(table.preamble)} line(s) skipped, not read as data: {shown}")
    if table.clock_start is not None:
        lines.append(f"  time: column {table.time_column!r} holds clock times, read in seconds from the first "
                     f"({table.clock_start})")
    if table.time is None:
        lines.append(f"  sample rate: {timing.sample_rate:.6g} Hz (given; no time column: gaps and jitter cannot be "
                     "seen)")
    else:
        lines.append(f"  sample rate: {timing.sample_rate:.6g} Hz (from column {table.time_column!r}: "
                     f"{timing.estimated_rate:.6g} Hz); jitter {timing.jitter_rms:.3g} s RMS, "
                     f"{timing.jitter_max:.3g} s at most; {len(timing.gaps)} gap(s), {timing.missing_samples} "
                     "sample(s) missing")
    noise = seg.noise
    gyro = " ".join(f"{c} {math.degrees(v):.3g}" for c, v in zip(CHANNELS[:3], noise.sigma[:3]))
    accel = " ".join(f"{c} {v:.3g}" for c, v in zip(CHANNELS[3:], noise.sigma[3:]))
    density = " ".join(f"{c} {math.degrees(v) * 60.0 / math.sqrt(timing.sample_rate):.3g}"
                       for c, v in zip(CHANNELS[:3], noise.sigma[:3]))
    lines.append(f"  noise per sample (quiet stretch, lines {table.lines[noise.start]}-{table.lines[noise.stop - 1]}): "
                 f"{gyro} deg/s; {accel} m/s^2 (as white noise: {density} deg/sqrt(h))")
    rate = " ".join(f"{math.degrees(v):.3g}" for v in seg.rate_threshold)
    lines.append(f"  at rest: variance ratios <= {seg.variance_threshold[0]:.3g} (accelerometers), "
                 f"{seg.variance_threshold[1]:.3g} (gyros) over {seg.window} samples "
                 f"({seg.window / timing.sample_rate:.3g} s), for at least {seg.min_static / timing.sample_rate:.3g} "
                 f"s; a quiet stretch turning faster than {rate} deg/s (x y z) is a steady turn")
    counts = {kind: len(seg.of_kind(kind)) for kind in ("static", "rotation", "move")}
    lines.append(f"  segments: {counts['static']} static, {counts['rotation']} rotation, {counts['move']} move")
    lines.append(f"  {'#':>3}  {'test':8s}  {'lines':>13s}  {'duration':>9s}  label")
    for k, (span, segment) in enumerate(zip(seg.spans, rec.schedule.segments)):
        rows = f"{table.lines[span.start]}-{table.lines[span.stop - 1]}"
        lines.append(f"  {k:3d}  {segment.test:8s}  {rows:>13s}  {span.samples / timing.sample_rate:7.2f} s  "
                     f"{segment.label}")
    lines.append("  heading: not known (a plain log has no heading reference): heading = nan, orientation = "
                 "approximate for the static poses")
    rotations = seg.of_kind("rotation")
    if any(not math.isfinite(r.steady_rate) for r in rotations):
        lines.append("  rotations: angle = the whole number of quarter turns nearest the measured integral (bias "
                     "removed); check it against what was done; rate = nan (not logged)")
    if any(math.isfinite(r.steady_rate) for r in rotations):
        lines.append("  steady turns: angle = nan and rate = nan (a table's rate is not in the log): give each one "
                     "the rate the table held for the fit to use it (in the segment table, rate_deg_s and "
                     "rate_rad_s, or one of them with the other column deleted); the moves beside them are the "
                     "table's spin-up and stop")
    for warning in result.warnings:
        lines.append(f"  warning [{warning.name}]: {warning.message}")
    return "\n".join(lines)
