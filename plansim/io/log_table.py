"""Reading a plain IMU log's table: its columns, in the file's units, every row checked.

The first part of ``plansim import`` (:mod:`plansim.io.log_pairing` pairs two sensors sampled apart,
:mod:`plansim.io.log_import` cuts the table into segments and makes the recording, :mod:`plansim.report.import_summary`
writes what it found as text). A plain log is
one CSV table: a header line of column names (or none: columns named by position), then one row per sample
with six channels (three gyros, three accelerometers) in counts or in physical units, and perhaps a time
column, a sample counter, a temperature and labels. :func:`read_log` reads it; ``parse_*`` read the command
line's per-channel options (``--units``, ``--scale``, ``--offset``, ``--full-scale``).

Every problem with the table is a ``ValueError`` naming the file, the line and the column.
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

from plansim.io.recording_csv import _text_file, _unterminated_last_line
from plansim.io.recording_data import CHANNELS
from plansim.units import KINDS

#: units of the time column -> seconds per unit ("samples": a sample counter, needs the sample rate)
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "samples": math.nan}
#: the delimiters a log may use; the one that splits the header line into the most columns is taken
DELIMITERS = (",", ";", "\t")
#: the delimiter of a log whose columns are separated by runs of spaces (imu_tk, MATLAB's ``save -ascii``)
WHITESPACE = "whitespace"
#: lines a logger may write before the header (its own metadata, such as "Fs,100"): the header is the first line
#: that names every column asked for, searched this far; those before it are skipped and reported
MAX_PREAMBLE_LINES = 50
#: lines after the last sample that are not samples (a logger's footer, a row it did not finish when stopped):
#: skipped and reported up to this many; more, or one followed by samples, stops the import
MAX_TRAILING_LINES = 10
#: rows converted to numbers at a time while reading
_BLOCK_ROWS = 65536
#: a last line without a line break is kept when its values have the decimals of every sample checked in their
#: columns: every FORMAT_SAMPLING-th sample and the one before it
FORMAT_SAMPLING = 64


@dataclass(frozen=True)
class LogTable:
    """The columns read from a plain log, in the file's units.

    ``channels`` (N, 6) in the order gx gy gz ax ay az (or the three of a log of one sensor; NaN where a row
    holds the other sensor's alone, ``interleaved``); ``time`` (N,) in the time column's unit or None;
    ``temperature`` (N,) degC or None; ``names`` the channel column names; ``ignored`` the columns
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
    #: that first sample's clock time in seconds (from the start of its day, plus its date's day number times
    #: 86400 s where it has a date): where two logs are paired (:func:`plansim.io.log_pairing.pair_logs`), their
    #: clocks line up on it
    clock_zero_s: float | None = None
    #: where the gyros and the accelerometers were logged in two files and paired
    #: (:func:`plansim.io.log_pairing.pair_logs`): what was done, in words, for the summary and the recording's
    #: attributes; ``path``, ``lines`` and the time are the file on whose samples the other's were paired
    pairing: tuple[str, ...] = ()
    #: some rows hold only the gyros' three channels or only the accelerometers' (the other three empty, NaN in
    #: ``channels``): two sensors sampled apart, logged in one file (:func:`plansim.io.log_pairing.split_interleaved`)
    interleaved: bool = False
    #: the table's rate column (``--table-rate-column``) in the file's unit, and its name; or None
    table_rate: np.ndarray | None = None
    table_rate_column: str | None = None
    #: the table's angle column (``--table-angle-column``) in the file's unit, and its name; or None
    table_angle: np.ndarray | None = None
    table_angle_column: str | None = None
    #: lines whose six channel columns are all empty: rows of the logger's other packets (an estimate, a status),
    #: skipped
    channelless: tuple[int, ...] = ()


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
#: (not "rps": revolutions per second to some, radians per second to others)
UNIT_SPELLINGS = {"dps": "deg/s", "deg/sec": "deg/s", "°/s": "deg/s", "degree/s": "deg/s", "degrees/s": "deg/s",
                  "rad/sec": "rad/s", "°/h": "deg/h", "dph": "deg/h", "m/s2": "m/s^2",
                  "m/s²": "m/s^2", "m/s/s": "m/s^2", "m/sec^2": "m/s^2", "µg": "ug", "μg": "ug",
                  # as headers write them: EuRoC and Kalibr's "rad s^-1", "m s^-2"
                  "rad s^-1": "rad/s", "rad s-1": "rad/s", "rad·s⁻¹": "rad/s", "deg s^-1": "deg/s",
                  "m s^-2": "m/s^2", "m s-2": "m/s^2", "m·s⁻²": "m/s^2"}


#: a unit written at the end of a column's name, in brackets or parentheses: "X (rad/s)" (phyphox),
#: "w_RS_S_x [rad s^-1]" (EuRoC), "AsX(°/s)" and "AccX(g)" (WitMotion)
_UNIT_IN_NAME = re.compile(r"[(\[]\s*([^()\[\]]+?)\s*[)\]]\s*$")


def header_units(names: tuple[str, ...], units_row: tuple[int, tuple[str, ...]] | None = None
                 ) -> tuple[tuple[str, ...], str] | None:
    """The six channels' units as the log writes them, and where: ``(units, "row of units")`` from a row of units
    under the header, else ``(units, "header")`` from the end of each channel column's name in brackets or
    parentheses (``X (rad/s)``, ``w_RS_S_x [rad s^-1]``, ``AsX(°/s)``), in the spellings :data:`UNIT_SPELLINGS`
    and :data:`plansim.units.KINDS` know. None where any channel's is missing or is not a unit of its kind (a gyro's
    angular rate, an accelerometer's acceleration): a partial or unknown declaration is not guessed from.
    """
    sources = []
    if units_row is not None:
        sources.append(([entry.strip().strip("[]()").strip() for entry in units_row[1]], "row of units"))
    found = [_UNIT_IN_NAME.search(name) for name in names]
    if all(found):
        sources.append(([match.group(1) for match in found], "header"))
    for entries, where in sources:
        units = []
        for k, entry in enumerate(entries):
            unit = UNIT_SPELLINGS.get(entry, UNIT_SPELLINGS.get(entry.lower(), entry))
            if unit not in KINDS["angular_rate" if k < 3 else "acceleration"]:
                break
            units.append(unit)
        else:
            if len(units) == 6:
                return tuple(units), where
    return None


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
             temperature_column: str | None = None, channels: tuple[str, ...] = CHANNELS,
             table_rate_column: str | None = None, table_angle_column: str | None = None) -> LogTable:
    """Read the columns of a plain CSV log, checking every row.

    Parameters
    ----------
    path : str or os.PathLike
        The log: UTF-8 text, optional ``#`` comment lines, a header line of column names (a commented one
        counts, as EuRoC's ``#timestamp [ns],w_RS_S_x [rad s^-1],…``), one row per sample; comma-, semicolon-
        or tab-separated (with ``;`` or tabs, a decimal comma is read: ``0,123``).
    columns : tuple of str or None
        The column names of ``channels`` (gx gy gz ax ay az); columns not named (and not the time or temperature
        column) are ignored. ``None``: the columns must be named as the channels and the log may hold no other.
    time_column, temperature_column : str or None
        Names of the time and temperature columns, if any. A time column of clock times (ISO 8601 date and time,
        ``2024-11-27 14:22:31.504`` or with ``T``, ``/`` or unpadded fields, or the time of day alone,
        ``14:22:31.504``) is read as such, in seconds from its first sample (:func:`_clock_time`); the first
        sample decides.
    channels : tuple of str
        The channels the log holds, in the order of ``columns``: all six, or the gyros' or the accelerometers'
        three where the two are logged in two files (:func:`plansim.io.log_pairing.pair_logs`).
    table_rate_column : str or None
        Name of a column holding the turntable's rate (read in the file's unit; ``plansim import`` converts it).
    table_angle_column : str or None
        Name of a column holding the turntable's angle (its encoder's; read in the file's unit).

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
    names = tuple(channels) if columns is None else tuple(columns)
    n_channels = len(channels)
    if len(names) != n_channels:
        raise ValueError(f"--columns {','.join(names)!r}: {len(names)} names for {where}; expected {n_channels}, "
                         f"in the order {', '.join(channels)}")
    wanted = list(names) + [c for c in (time_column, temperature_column, table_rate_column, table_angle_column)
                            if c is not None]
    repeated = sorted({name for name in wanted if wanted.count(name) > 1})
    if repeated:
        raise ValueError(f"{where}: column {repeated[0]!r} is named for two uses (channels, --time, "
                         "--temperature-column, --table-rate-column, --table-angle-column)")
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
            if tuple(channels) == CHANNELS[:3] and missing[0] in (temperature_column, table_rate_column,
                                                                  table_angle_column):
                hint = (" (with --accel-log the temperature and the table's columns are read from the gyros' log, "
                        "LOG)")
            raise ValueError(f"{where}: column {missing[0]!r} is missing; the header (line {header_line}) has "
                             f"{', '.join(header_names)}{hint}")
        ignored = tuple(name for name in header_names if name not in wanted)
        if columns is None and ignored:
            raise ValueError(f"{where}: column {ignored[0]!r} is not expected: without --columns the log holds "
                             f"exactly the channels {', '.join(channels)} (and the --time, --temperature-column and "
                             "--table-rate-column columns if given); name the six channel columns with --columns (the "
                             "other columns are then ignored)")
        index = [header_names.index(name) for name in wanted]
        width = len(header_names)
        decimal_comma = False
        blocks: list[np.ndarray] = []  # rows converted block by block: floats, not text, are kept
        block: list[list[float]] = []
        lines: list[int] = []
        line_number = header_line
        cut = _unterminated_last_line(target)  # a logger stopped while writing its last row
        formats: list[int] | None = []  # each wanted column's decimals while every sample checked has the same
        clock = None  # the time column holds clock times (decided on the first sample): (days, seconds) of it
        day = 0  # whole days a time of day alone has passed midnight
        previous_stamp = 0.0
        units_row = None
        interleaved = False
        channelless: list[int] = []  # rows with none of the six channels: other packets of the logger
        trailing: list[tuple[int, str, str]] = []  # (line, why, the error it is if a sample follows)
        for row in _rows(fh, delimiter):
            line_number += 1
            if not row or all(not cell.strip() for cell in row):
                continue
            if row[0].lstrip().startswith("#"):
                continue
            if line_number == cut and not (len(row) == width and formats is not None and all(
                    f > 0 and _decimals(row[k]) == f for k, f in zip(index, formats))):
                # a row the logger stopped inside may have lost digits: kept only where every value has the
                # decimals every sample of its column has (a fixed format), which a cut value would not
                trailing.append((line_number, "no line break", ""))
                continue
            if has_header and not lines and units_row is None and len(row) == width and all(
                    row[k].strip() and not _is_number(row[k].strip(), delimiter) for k in index):
                # "s,deg/s,…" under the header
                units_row = (line_number, tuple(row[k].strip() for k in index[:n_channels]))
                continue
            if len(row) != width:
                word = "more" if len(row) > width else "fewer"
                trailing.append((line_number, f"{len(row)} values, not {width}",
                                 f"{where}: line {line_number} has {len(row)} values, {word} than the {width} columns "
                                 f"of the header (line {header_line}); every row holds one value per column"))
                continue
            if time_column is not None:
                text = row[index[n_channels]].strip()
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
                    # seconds from the first sample, read as any number
                    row[index[n_channels]] = repr(seconds - clock[1])
            # a row holding one sensor's three channels, the other's left empty: a log of two sensors sampled apart
            # in one file (every sample in a row of its own, as it came); read as NaN, paired by split_interleaved
            blank = tuple(j for j in range(n_channels) if not row[index[j]].strip())
            if n_channels == 6 and len(blank) == 6:  # none of the six: a row of the logger's other packets
                channelless.append(line_number)
                continue
            if blank and n_channels == 6 and blank in ((0, 1, 2), (3, 4, 5)):
                row = list(row)
                for j in blank:
                    row[index[j]] = "nan"
                interleaved = True
            else:
                blank = ()
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
            if not all(math.isfinite(v) or j in blank for j, v in enumerate(numbers)):
                j = next(j for j, v in enumerate(numbers) if not math.isfinite(v) and j not in blank)
                raise ValueError(f"{where}: column {wanted[j]!r} is {row[index[j]].strip()!r} at line {line_number}; "
                                 "every value must be a finite number (a sample lost by the logger? cut the log before "
                                 "or after it)")
            block.append(numbers)
            lines.append(line_number)
            before_cut = cut is not None and line_number + 1 >= cut
            if formats is not None and (len(lines) % FORMAT_SAMPLING == 1 or before_cut):
                # every FORMAT_SAMPLING-th sample and the one before a last line without a line break
                seen = [_decimals(row[k]) for k in index]
                formats = seen if len(lines) == 1 else (formats if seen == formats else None)
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
    extra = iter(range(n_channels, data.shape[1]))  # the time, temperature and table rate columns, as wanted
    time = data[:, next(extra)] if time_column is not None else None
    temperature = data[:, next(extra)] if temperature_column is not None else None
    table_rate = data[:, next(extra)] if table_rate_column is not None else None
    table_angle = data[:, next(extra)] if table_angle_column is not None else None
    return LogTable(target, data[:, :n_channels], names, time, time_column, temperature, temperature_column,
                    ignored, lines[0], np.array(lines, dtype=np.int64), tuple(preamble), header_line, decimal_comma,
                    has_header, units_row, tuple((line, why) for line, why, _ in trailing),
                    clock[2] if clock else None, ((clock[0] or 0) * 86400.0 + clock[1]) if clock else None,
                    interleaved=interleaved, table_rate=table_rate, table_rate_column=table_rate_column,
                    table_angle=table_angle, table_angle_column=table_angle_column, channelless=tuple(channelless))


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


def _decimals(text: str) -> int:
    """The digits after the decimal point (or comma) of a number written in fixed point, −1 for any other form
    (no decimal point, an exponent): a value cut short shows fewer."""
    t = text.strip()
    if "e" in t or "E" in t:
        return -1
    point = max(t.rfind("."), t.rfind(","))
    return len(t) - point - 1 if point >= 0 else -1


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
