"""From a plain IMU log (CSV) to a recording with a segment table for the user to review.

A plain log is one CSV table: a header line of column names, then one row per sample with six
channels (three gyros, three accelerometers) in counts or in physical units, and perhaps a time
column, a sample counter, a temperature and labels. :func:`import_log` reads it, converts the
channels to SI, checks the time axis (sample rate, jitter, gaps), finds the static poses and the
motion between them (:func:`plansim.estimate.segmentation.segment_log`) and returns a
:class:`~plansim.io.recording_data.Recording` holding **every** sample of the log, cut into
``static``, ``rotation`` and ``move`` segments (docs/recording.md), with what it found in the
attributes and the schedule notes. ``plansim import`` writes it (docs/measured-data.md).

The middle of ``plansim import``: :func:`plansim.io.log_table.read_log` reads the table,
:mod:`plansim.io.log_pairing` pairs two sensors sampled apart, and
:func:`plansim.report.import_summary.format_summary` writes what was found as text.

Every problem with the log is a ``ValueError`` naming the file, the line and the column; what the
log may still be used for despite a flaw (a gap, a saturated stretch, timing jitter) is a named
:class:`LogWarning`.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plansim.estimate.frozen import repeated_rows
from plansim.estimate.segmentation import (
    APPROXIMATE_TILT,
    AXES,
    DEFAULT_MIN_STATIC,
    DEFAULT_WINDOW,
    FULL_SCALE_MARGIN,
    TABLE_AGREEMENT,
    VARIANCE_FACTOR,
    Segmentation,
    Span,
    segment_log,
)
from plansim.estimate.timebase import DROPPED_MAX, TimeReport, analyse_time
from plansim.fit import recording_noise_models
from plansim.io.log_pairing import pair_logs, split_interleaved
from plansim.io.log_table import (
    TIME_UNITS,
    UNIT_SPELLINGS,
    LogTable,
    header_units,
    parse_full_scale,
    parse_offset,
    parse_scale,
    parse_units,
    read_log,
)
from plansim.io.recording_data import CHANNELS, SITE_ATTRIBUTES, UNITS_DESCRIPTION, Recording, plansim_version
from plansim.schedule.segments import IMPORT_NOTES, TABLE_ANGLE_NOTE, TABLE_RATE_NOTE, Schedule, Segment
from plansim.units import KINDS, STANDARD_GRAVITY

#: a static span's mean specific force must be within this fraction of standard gravity (units check)
GRAVITY_TOLERANCE = 0.3
#: timing jitter (RMS) beyond this fraction of the sample period is a warning
JITTER_WARNING = 0.1
#: a given sample rate that differs from the time column's by more than this fraction is a warning
RATE_MISMATCH_WARNING = 0.01
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
                 "delivery_times", "rest_turning_about_vertical", "glitch", "units_row", "trailing_lines",
                 "units_disagree", "frozen", "repeated_rows", "table_rate_disagrees", "table_rate_sense",
                 "table_turning_at_rest", "table_turn_not_a_rotation", "not_a_table_pose", "short_rests",
                 "rows_without_channels", "noisy_poses")
#: the quiet stretches within motion too short for a static span (``Segmentation.short_quiet``) are warned of
#: (``short_rests``) where there are at least this many and at least as many as the static poses found: a hand
#: session whose rests are shorter than ``--min-static`` (imu_tk's ROS2 session "data1" of GetOverMassif/imu_tk:
#: 25 such stretches beside 4 poses, where 39 to 23 real sessions found 0-6 beside 20-39 poses); up to
#: SHORT_RESTS_LISTED are listed by line
SHORT_RESTS_MIN = 3
SHORT_RESTS_LISTED = 6
#: the ``--rest-variance`` the ``noisy_poses`` warning proposes: this many times the largest factor its stretches
#: need (a margin, so that a stretch's edge is not cut again)
NOISY_POSE_MARGIN = 1.2
#: how the log's poses were set (``--poses``): by hand (each pose's tilt a nuisance of the fit) or by a table that
#: set each up-axis to its grade (JJF 2003's positions: one body axis up or down, turns about the vertical)
POSES = ("hand", "table")
#: with ``--poses table``, a static pose whose specific force is further than this from every body axis is not one
#: of the table's axis-up positions: a MEMS unit's accelerometer misalignments (up to 1-2 %) and biases (up to about
#: 50 mg) tilt its measured specific force by a few degrees at most, the table's own position error by arcseconds
TABLE_POSE_TILT = math.radians(5.0)
#: up to this many glitch rows (or repeated rows) are listed by line in the warning
GLITCHES_LISTED = 10
#: up to this many frozen stretches are listed in the warning
FROZEN_LISTED = 6
#: two saturated stretches of one channel at most this many detector windows apart are one episode (a shake hits
#: the rail once per swing): one warning for it
SATURATION_EPISODE_WINDOWS = 1
#: a static pose whose gyro output is at least this (rad/s) and points along its own specific force (within
#: :data:`VERTICAL_TURN_CONE`) is warned of as possibly a steady turn about the vertical: the one turn that leaves
#: the accelerometers steady, which the detector (step 6) can tell from rest only against a rest elsewhere in the log
VERTICAL_TURN_RATE = math.radians(1.0)
#: a static pose's gyro output that a rest in another pose (its vertical further than twice
#: :data:`VERTICAL_TURN_CONE` from this one's) reads too, to within this (rad/s), is the gyros' bias, not a turn
#: about this pose's vertical: such a turn would add its rate along this vertical alone. Half the warning's rate
VERTICAL_TURN_SHARED = 0.5 * VERTICAL_TURN_RATE
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
    #: per channel (gx … az), the correlation of its noise from one sample to the next over the static poses of
    #: the channel's quiet scatter, as plansim fit reads it: ρ_1 … ρ_L (:func:`plansim.fit.noise.noise_autocorrelation`
    #: through :func:`plansim.fit.recording_noise_models`; empty where none shows)
    correlation: tuple[np.ndarray, ...] = ()


def _lines_listed(table: LogTable, rows) -> str:
    """The file lines of the log's *rows*, the first :data:`GLITCHES_LISTED` of them, for a warning."""
    return ", ".join(str(table.lines[k]) for k in rows[:GLITCHES_LISTED]) + (", …" if len(rows) > GLITCHES_LISTED
                                                                              else "")


def import_log(path: str | os.PathLike, *, columns: tuple[str, ...] | None = None, time_column: str | None = None,
               time_unit: str = "s", units: str | None = None, scale: str | None = None,
               offset: str | None = None, sample_rate: float | None = None, temperature_column: str | None = None,
               temperature: float | None = None, latitude: float | None = None, height: float | None = None,
               window: float = DEFAULT_WINDOW, min_static: float = DEFAULT_MIN_STATIC,
               rest_variance: float = VARIANCE_FACTOR,
               full_scale: str | None = None, accel_log: str | os.PathLike | None = None,
               table_rate_column: str | None = None, table_rate_unit: str = "deg/s",
               table_angle_column: str | None = None, table_angle_unit: str = "deg", poses: str = "hand"
               ) -> ImportResult:
    """Read a plain log and cut it into segments (see the module docstring and docs/measured-data.md).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV log (with ``accel_log``: the gyros' log).
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
    table_rate_column : str or None
        A column holding the turntable's rate (its encoder or its controller's setpoint), in *table_rate_unit*:
        each steady turn's ``rate`` is its mean over the segment, signed as the gyros measured the turn (the
        table's sense and the body axis's may differ), so the fit can use it without editing the table. With
        ``accel_log``, a column of the gyros' log (paired as its samples are: :func:`plansim.io.log_pairing.pair_logs`).
    table_rate_unit : str
        Unit of that column: one of :data:`plansim.units.KINDS` ``angular_rate`` (``deg/s`` by default).
    table_angle_column : str or None
        A column holding the turntable's angle (its encoder's position), in *table_angle_unit*, wrapping or not
        (it is unwrapped: it must not change by half a turn between two samples). Each turn between two rests
        takes the table's change of angle over it as its reference angle, whatever the angle (step 8 of
        :mod:`plansim.estimate.segmentation`), and without *table_rate_column* its rate (the angle's change per
        sample times the sample rate) decides step 6 and gives each steady turn its rate as a rate column does.
        With ``accel_log``, a column of the gyros' log, unwrapped before the pairing averages it.
    table_angle_unit : str
        Unit of that column: one of :data:`plansim.units.KINDS` ``angle`` (``deg`` by default).
    poses : str
        ``--poses``, how the poses were set (:data:`POSES`): ``"hand"`` (default), each static pose's orientation
        ``approximate`` (its tilt a nuisance of the fit); or ``"table"``, a table (or a fixture on it) set each
        pose's up-axis to its grade and turned the unit about the vertical: each static pose within
        :data:`TABLE_POSE_TILT` of a body axis, and each turn about the vertical, is ``known`` with its heading NaN
        (not logged). The fit then takes the table's position errors as Type B inputs (its grade, ``--scenario``)
        and no tilt, and identifies the accelerometers' and gyros' cross-couplings. A pose tilted further keeps its
        hand-placed orientation, named in a warning (``not_a_table_pose``).
    temperature : float or None
        The lab's temperature, degC, for the segment table when the log has no temperature column
        (default 20 degC, noted in the attributes as assumed).
    latitude, height : float or None
        The site, deg and m, written as ``site_latitude_deg`` and ``site_height_m``.
    window, min_static : float
        The detector's window and shortest static span, s.
    rest_variance : float
        How many times the quiet stretch's variance a rest's may reach, per channel (``--rest-variance``; default
        :data:`plansim.estimate.segmentation.VARIANCE_FACTOR`, 4): raise it for a log whose poses are noisier than
        its quietest stretch (a pose on a vibrating bench, noise that depends on the pose).
    full_scale : str or None
        ``--full-scale``: each channel's full scale (the largest magnitude it reads) in ``units``, two or six
        entries; a sample within :data:`plansim.estimate.segmentation.FULL_SCALE_MARGIN` of it is at the rail.
        ``None``: a rail is looked for in the data (step 10 of :mod:`plansim.estimate.segmentation`).
    accel_log : str or os.PathLike or None
        ``--accel-log``: where the accelerometers were logged in a file of their own, that file; ``path`` then
        holds the gyros, the first three ``columns`` are ``path``'s and the last three this file's, the time
        column (same name and unit) is in both and ``temperature_column`` in ``path``. The two are paired by
        :func:`plansim.io.log_pairing.pair_logs`: each sample of the slower, with the mean of the other's samples in
        its interval.

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
    if poses not in POSES:
        raise ValueError(f"--poses {poses!r}; allowed: {', '.join(POSES)} (how the log's poses were set)")
    table_rate_factor = _table_factor("rate", table_rate_column, table_rate_unit)
    table_angle_factor = _table_factor("angle", table_angle_column, table_angle_unit)
    if temperature_column is not None and temperature is not None:
        raise ValueError("--temperature and --temperature-column: give one (the log's column, or the lab's "
                         "temperature)")
    if isinstance(rest_variance, bool) or not isinstance(rest_variance, (int, float)) or \
            not (rest_variance >= 1.0 and math.isfinite(rest_variance)):
        raise ValueError(f"--rest-variance {rest_variance!r}: expected a number >= 1 (how many times the quiet "
                         "stretch's variance a rest's may reach, per channel; default 4)")
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
    seconds_per_unit = TIME_UNITS[time_unit] if time_unit != "samples" else 1.0 / sample_rate
    if accel_log is None:
        table = _unwrapped(read_log(path, columns, time_column, temperature_column,
                                    table_rate_column=table_rate_column, table_angle_column=table_angle_column),
                           table_angle_factor)
        if table.interleaved:  # the gyros' and the accelerometers' samples in rows of their own: paired by time
            table = pair_logs(*split_interleaved(table), seconds_per_unit)
    else:
        if columns is not None and len(columns) != 6:
            raise ValueError(f"--columns {','.join(columns)!r}: {len(columns)} names; expected 6, the gyro log's "
                             f"three ({', '.join(CHANNELS[:3])}) then the accelerometer log's "
                             f"({', '.join(CHANNELS[3:])})")
        halves = (None, None) if columns is None else (columns[:3], columns[3:])
        gyro = _unwrapped(read_log(path, halves[0], time_column, temperature_column, channels=CHANNELS[:3],
                                   table_rate_column=table_rate_column, table_angle_column=table_angle_column),
                          table_angle_factor)
        table = pair_logs(gyro, read_log(accel_log, halves[1], time_column, None, channels=CHANNELS[3:]),
                          seconds_per_unit)
    where = f"log {str(table.path)!r}"
    n = table.channels.shape[0]
    warnings: list[LogWarning] = []
    # the units the log writes for its channels (a row of units, or each name's end: "X (rad/s)"): taken where
    # --units is not given, compared with it where it is; a log in counts (--scale) is read in --units
    declared = header_units(table.names, table.units_row) if counts_per_unit is None else None
    units_source = "--units" if units is not None else "default (rad/s, m/s^2)"
    if declared is not None and units is None:
        unit_names, units_source = declared[0], f"the log's {declared[1]}"
    elif declared is not None and declared[0] != unit_names:
        differ = [c for c in range(6) if declared[0][c] != unit_names[c]]
        warnings.append(LogWarning("units_disagree", "the log's " + declared[1] + " writes " + ", ".join(
            f"{CHANNELS[c]} in {declared[0][c]}" for c in differ) + "; --units says " + ", ".join(
            f"{unit_names[c]}" for c in differ) + ": the channels are read in --units; check which is right (a gyro "
            "read in deg/s as rad/s turns 57 times too far)"))
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

    if table.channelless:
        shown = _first_few([str(k) for k in table.channelless], GLITCHES_LISTED)
        warnings.append(LogWarning("rows_without_channels", f"{len(table.channelless)} row(s) hold none of the six "
                                                            f"channel columns (lines {shown}): rows of the "
                                                            "logger's other packets, skipped"))
    if table.units_row is not None:
        line, entries = table.units_row
        read = ("read as the channels' units" if units_source == "the log's row of units"
                else "they agree with --units" if declared is not None and declared[0] == unit_names
                else f"the channels are read in {', '.join(dict.fromkeys(unit_names))} ({units_source}): check that "
                     "they agree")
        warnings.append(LogWarning("units_row", f"line {line}, under the header, reads {', '.join(entries)} for "
                                                f"{', '.join(CHANNELS)}: a row of units, skipped as a sample; {read}"))
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
    table_rate_si = None if table.table_rate is None else table.table_rate * table_rate_factor
    table_angle_si = None
    if table.table_angle is not None:  # unwrapped as read (_unwrapped); its rate per sample, where no rate column
        table_angle_si = table.table_angle * table_angle_factor
        if table_rate_si is None and n > 1:
            table_rate_si = np.gradient(table_angle_si) * timing.sample_rate
    segmentation = segment_log(samples, time_s, timing.sample_rate, window=window, min_static=min_static,
                               variance_factor=float(rest_variance),
                               gap_starts=timing.gap_starts, full_scale=rail_si, table_rate=table_rate_si,
                               table_angle=table_angle_si)
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
        listed = _lines_listed(table, rows)
        warnings.append(LogWarning("glitch", f"{len(rows)} isolated glitch row(s) (all six channels exactly 0, or "
                                             "a sample far off both its neighbours), on line(s) " + listed + ": kept "
                                             "in the recording as logged, but in no static pose (a pose is cut or "
                                             "trimmed around each); the detector and a turn's integral take each as "
                                             "the mean of its neighbours"))
    if segmentation.frozen:
        frozen = segmentation.frozen
        listed = "; ".join(
            f"{CHANNELS[f.channel]} ({table.names[f.channel]}) at "
            f"{_as_logged(f.value, f.channel, factors, divisors, offsets, unit_names, counts_per_unit is not None)} "
            f"on lines {table.lines[f.start]}-{table.lines[f.stop - 1]} ({f.stop - f.start} samples)"
            for f in frozen[:FROZEN_LISTED]) + ("; …" if len(frozen) > FROZEN_LISTED else "")
        warnings.append(LogWarning("frozen", f"{len(frozen)} stretch(es) where a channel repeats one value for longer "
                                             "than its noise at rest allows (a sensor that stopped updating, or a "
                                             f"logger repeating its last value): {listed}. Kept in the recording as "
                                             "logged, but in no static pose (a pose is cut around each), and a turn "
                                             "across a frozen gyro is a move"))
    repeated = repeated_rows(samples, [(span.start, span.stop) for span in segmentation.of_kind("static")])
    if repeated is not None:
        rows = repeated.rows
        listed = _lines_listed(table, rows)
        warnings.append(LogWarning("repeated_rows", f"{len(rows)} row(s) ({100.0 * len(rows) / n:.2g} % of the log) "
                                   f"repeat the row before in all six channels, where chance gives "
                                   f"{repeated.expected:.2g} (the static poses' channels repeating a value "
                                   "independently), on line(s) " + listed + ": a logger writing rows when its "
                                   "sensors had no new sample (a log written faster than its sensors, a link "
                                   "repeating its last packet)? Kept as logged: such rows are copies, not new samples"))
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
        if magnitude >= VERTICAL_TURN_RATE and along >= math.cos(VERTICAL_TURN_CONE) \
                and not _read_in_another_pose(span, statics):
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
    short = segmentation.short_quiet
    if len(short) >= max(SHORT_RESTS_MIN, len(statics)):
        rate = timing.sample_rate
        # a quiet run of the moving variance is about a window shorter than the rest that holds it
        lengths = [(b - a + segmentation.window) / rate for a, b in short]
        listed = _first_few([f"{table.lines[a]}-{table.lines[b - 1]}" for a, b in short])
        window_s, min_static_s = segmentation.window / rate, segmentation.min_static / rate
        warnings.append(LogWarning("short_rests", f"the motion holds {len(short)} quiet stretches of about "
                                                  f"{min(lengths):.2g}-{max(lengths):.2g} s (lines {listed}), "
                                                  f"as many as the {len(statics)} static pose(s) found or more: "
                                                  f"rests shorter than --min-static {min_static_s:.3g} s? Import "
                                                  f"again with --min-static {min_static_s / 2:.3g} --window "
                                                  f"{window_s / 2:.3g} (docs/measured-data.md)"))
    noisy = segmentation.noisy_poses
    if noisy:
        factor = rest_variance_for(max(pose.factor for pose in noisy))
        rate = timing.sample_rate
        listed = _first_few([f"{table.lines[p.start]}-{table.lines[p.stop - 1]} ({(p.stop - p.start) / rate:.2g} s, "
                             f"{p.up} up)" for p in noisy])
        total = sum(p.stop - p.start for p in noisy) / rate
        warnings.append(LogWarning("noisy_poses", f"{len(noisy)} stretch(es) inside the motion, {total:.3g} s in all "
                                   f"(lines {listed}), hold one pose with "
                                   "the gyros at rest but are noisier than the quiet stretch (a window's variance up "
                                   f"to {max(p.factor for p in noisy):.3g} times its own, where a rest may reach "
                                   f"{float(rest_variance):g}): a bench that vibrates, noise that depends on the pose, "
                                   "or a pause held in the hand? They are left as motion; if they are rests, import "
                                   f"again with --rest-variance {factor:g} (docs/measured-data.md)"))
    for span in segmentation.spans:
        if span.kind == "move" and span.reason.startswith("no static span"):
            warnings.append(LogWarning("unclosed_motion", f"lines {table.lines[span.start]}-"
                                                          f"{table.lines[span.stop - 1]} lie before the first or after "
                                                          "the last static span: kept as a 'move'"))

    table_rates = {}
    if table_rate_si is not None:
        table_rates = _rates_from_table(segmentation, table, table_rate_si, warnings)

    segment_temperature = DEFAULT_TEMPERATURE if temperature is None else float(temperature)
    segments = []
    details = []
    counters = {"static": 0, "rotation": 0, "move": 0}
    for k, span in enumerate(segmentation.spans):
        counters[span.kind] += 1
        seg_temperature = (float(np.mean(table.temperature[span.start:span.stop])) if table.temperature is not None
                           else segment_temperature)
        segments.append(_segment(span, counters[span.kind], timing.sample_rate, seg_temperature,
                                 table_rates.get(k, math.nan), on_table=poses == "table"))
        details.append(_detail(span, table))
        if k in table_rates:
            details[-1]["table_rate_deg_s"] = math.degrees(table_rates[k])
    if poses == "table":
        apart = [(span, segment) for span, segment in zip(segmentation.spans, segments)
                 if span.kind == "static" and segment.orientation != "known"]
        if apart:
            listed = "; ".join(f"lines {table.lines[span.start]}-{table.lines[span.stop - 1]} "
                               f"({math.degrees(span.tilt):.1f} deg from {span.up})" for span, _ in apart[:6])
            warnings.append(LogWarning("not_a_table_pose", f"--poses table: {len(apart)} of the {len(statics)} static "
                                       f"pose(s) lie further than {math.degrees(TABLE_POSE_TILT):g} deg from every "
                                       "body axis, so they are not one of the table's axis-up positions: each keeps a "
                                       "hand-placed orientation (its tilt fitted); " + listed
                                       + ("; …" if len(apart) > 6 else "")))
    schedule = Schedule(tuple(segments), procedure="imported", notes={IMPORT_NOTES: {
        "poses": poses,
        "log": table.path.name,
        "accel_log": None if accel_log is None else Path(accel_log).name,
        "pairing": list(table.pairing),
        "columns": dict(zip(CHANNELS, [("-" if sign < 0 else "") + name for name, sign in zip(table.names, signs)])),
        "ignored_columns": list(table.ignored),
        "units": dict(zip(CHANNELS, unit_names)),
        "units_source": units_source,
        "counts_per_unit": None if counts_per_unit is None else dict(zip(CHANNELS, counts_per_unit)),
        "zero_offset_counts": None if zero_counts is None else dict(zip(CHANNELS, zero_counts)),
        "full_scale": None if rails is None else dict(zip(CHANNELS, rails)),
        "saturation_rule": ("declared full scale (--full-scale): a sample within "
                            f"{FULL_SCALE_MARGIN:.1%} of it" if rails is not None
                            else "found in the data (no --full-scale): a stretch stuck at a channel's extreme"),
        "preamble": list(table.preamble),
        "header": table.has_header,
        "time_column": table.time_column,
        TABLE_RATE_NOTE: table.table_rate_column,
        "table_rate_unit": table_rate_unit if table.table_rate_column is not None else None,
        TABLE_ANGLE_NOTE: table.table_angle_column,
        "table_angle_unit": table_angle_unit if table.table_angle_column is not None else None,
        "time_unit": time_unit if table.time_column is not None else None,
        "detector": {
            "window_samples": segmentation.window,
            "min_static_samples": segmentation.min_static,
            "rest_variance": float(rest_variance),
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
        "imported_from": (table.path.name if accel_log is None
                          else f"{Path(path).name} (gyros), {Path(accel_log).name} (accelerometers)"),
        "plansim_version": plansim_version(),
        "units": UNITS_DESCRIPTION,
        **site,
        "sample_rate_hz": timing.sample_rate,
        "sample_rate_source": ("time column" if sample_rate is None else "--sample-rate") if table.time is not None
        else "--sample-rate (no time column: gaps and jitter cannot be seen)",
        "detector_window_s": segmentation.window / timing.sample_rate,
        "detector_min_static_s": segmentation.min_static / timing.sample_rate,
        "detector_rest_variance": float(rest_variance),
        "import_warnings": ", ".join(dict.fromkeys(w.name for w in warnings)) or "none",
        "heading": "not known for any segment: a plain log has no heading reference",
        "poses": ("set by a table (--poses table): each axis-up pose and each turn about the vertical known to the "
                  "table's grade, its heading not logged" if poses == "table"
                  else "placed by hand (--poses hand): each pose's tilt is fitted"),
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
    # the sensor's own filter (or a host's resampling) correlates neighbouring samples: the per-sample noise of the
    # quiet stretch then understates a segment mean's. Told as plansim fit tells it, over the static poses whose
    # scatter is the channel's quiet one (a hand's tremor makes an oscillating correlation); the quiet stretch
    # alone is too short (400 samples: 4 standard errors of rho_1 are 0.2). The quantiser's level posterior, the
    # costly part of the noise estimate, is not needed here
    noise = recording_noise_models(recording, conditionals=(False,))[0]
    correlation = tuple(np.asarray(channel.autocorrelation) for channel in noise.channels)
    return ImportResult(recording, table, timing, segmentation, unit_names, counts_per_unit, tuple(warnings),
                        zero_counts, tuple(CHANNELS[c] for c in range(6) if signs[c] < 0), correlation)


def _read_in_another_pose(span: Span, statics: list[Span]) -> bool:
    """Whether a rest in another pose (its specific force more than twice :data:`VERTICAL_TURN_CONE` from
    *span*'s) reads *span*'s gyro output to within :data:`VERTICAL_TURN_SHARED`: then that output is the gyros'
    bias, which every pose reads, and not a turn about *span*'s vertical. A hand session whose gyros read their raw
    zero-rate offset (imu_tk's Xsens log: 3.7 deg/s) has a pose whose vertical falls near that offset by chance."""
    force = span.mean[3:] / max(float(np.linalg.norm(span.mean[3:])), 1e-300)
    for other in statics:
        if other is span:
            continue
        direction = other.mean[3:] / max(float(np.linalg.norm(other.mean[3:])), 1e-300)
        apart = float(np.dot(force, direction)) < math.cos(2.0 * VERTICAL_TURN_CONE)
        if apart and float(np.linalg.norm(other.mean[:3] - span.mean[:3])) < VERTICAL_TURN_SHARED:
            return True
    return False


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


def _table_factor(quantity: str, column: str | None, unit: str) -> float:
    """SI per unit of the table's *quantity* column (``"rate"``: :data:`plansim.units.KINDS` ``angular_rate``;
    ``"angle"``: ``angle``), checking its option; NaN where the column is not given."""
    if column is None:
        return math.nan
    kind = "angular_rate" if quantity == "rate" else "angle"
    spelled = UNIT_SPELLINGS.get(unit, unit)
    if spelled not in KINDS[kind]:
        raise ValueError(f"--table-{quantity}-unit {unit!r}: allowed: {', '.join(u for u in KINDS[kind] if u)}")
    return KINDS[kind][spelled]


def _unwrapped(table: LogTable, factor: float) -> LogTable:
    """*table* with its table-angle column unwrapped in the file's unit (*factor* rad per unit), before anything
    averages it (the pairing of two sensors sampled apart): an encoder that wraps at a turn must not change by half
    a turn between two samples."""
    if table.table_angle is None:
        return table
    return dataclasses.replace(table, table_angle=np.unwrap(table.table_angle, period=2.0 * math.pi / factor))


def table_source(table: LogTable, quantity: str = "rate") -> str:
    """The table's column a turn's *quantity* (``"rate"`` or ``"angle"``) comes from, in words."""
    if quantity == "angle":
        if table.table_angle_column is not None:
            return f"the table's angle column {table.table_angle_column!r}"
        return f"the table's rate column {table.table_rate_column!r} (its integral over the turn)"
    if table.table_rate_column is not None:
        return f"the table's rate column {table.table_rate_column!r}"
    return f"the table's angle column {table.table_angle_column!r} (its change per sample)"


def _first_few(items: list[str], limit: int = SHORT_RESTS_LISTED) -> str:
    """The first *limit* of *items*, joined, and how many more there are (for a warning)."""
    return ", ".join(items[:limit]) + (f" and {len(items) - limit} more" if len(items) > limit else "")


def rest_variance_for(factor: float) -> float:
    """The ``--rest-variance`` the ``noisy_poses`` warning proposes for stretches that need *factor*: NOISY_POSE_MARGIN
    times it, rounded up to two significant digits."""
    wanted = NOISY_POSE_MARGIN * factor
    unit = 10.0 ** (math.floor(math.log10(wanted)) - 1)
    return float(f"{math.ceil(wanted / unit - 1e-9) * unit:.2g}")


def _rates_from_table(segmentation, table: LogTable, table_rate: np.ndarray, warnings: list) -> dict[int, float]:
    """Each steady turn's rate from the table's rate (SI, *table_rate*: its rate column, or its angle column's
    change per sample): its mean over the segment, signed as the gyros measured the turn, by span number. Warns
    (``table_rate_disagrees``) where the column's mean and the gyros' measured rate differ by more than
    :data:`~plansim.estimate.segmentation.TABLE_AGREEMENT` of the column's (a column in another unit, or not the
    turning axis's), (``table_turning_at_rest``) where a static pose's column reads more than the rest threshold: a
    pose held by hand (step 6b), since the table's rate decides step 6 for the quiet runs
    (:func:`plansim.estimate.segmentation.segment_log`), (``table_turn_not_a_rotation``) where the table turned
    over a motion between two rests that stays a move (step 8), and (``table_rate_sense``) where the table's sense
    is the opposite of the body axis's in every turn, the steady ones and those between rests."""
    source = table_source(table)
    rates = {}
    disagree, senses, refused = [], set(), []
    for k, span in enumerate(segmentation.spans):
        mean = float(np.mean(table_rate[span.start:span.stop]))
        if span.kind == "static":
            if abs(mean) > float(np.max(segmentation.rate_threshold)):
                warnings.append(LogWarning("table_turning_at_rest", f"the static span on lines "
                                           f"{table.lines[span.start]}-{table.lines[span.stop - 1]}: {source} "
                                           f"reads {math.degrees(mean):+.5g} deg/s over it: a turn about the "
                                           "vertical taken for a rest? Make it a 'rotation' with that rate in the "
                                           "segment table"))
            continue
        if math.isfinite(span.table_turned):  # a motion between two rests, over which the table turned
            where = f"lines {table.lines[span.start]}-{table.lines[span.stop - 1]}"
            if span.kind == "rotation":
                senses.add(span.table_turned * span.angle > 0)
            else:
                refused.append(f"{where}: {span.reason}")
            continue
        if span.kind != "rotation" or not math.isfinite(span.steady_rate):
            continue
        measured = span.steady_rate
        if mean == 0.0 or abs(abs(mean) - abs(measured)) > TABLE_AGREEMENT * abs(mean):
            disagree.append(f"lines {table.lines[span.start]}-{table.lines[span.stop - 1]}: column "
                            f"{math.degrees(mean):+.5g} deg/s, gyros {math.degrees(measured):+.5g} deg/s")
            continue
        rates[k] = math.copysign(abs(mean), measured)
        senses.add(mean * measured > 0)
    if disagree:
        warnings.append(LogWarning("table_rate_disagrees", f"{len(disagree)} steady turn(s) where {source} and the "
                                   f"gyros' measured rate differ by more than {TABLE_AGREEMENT:.0%} (a column in "
                                   "another unit, --table-rate-unit or --table-angle-unit?): their rate is left not "
                                   "known; " + "; ".join(disagree[:4]) + ("; …" if len(disagree) > 4 else "")))
    if refused:
        warnings.append(LogWarning("table_turn_not_a_rotation", f"{len(refused)} motion(s) between two rests over "
                                   "which the table turned are moves, not fitted: " + "; ".join(refused[:4])
                                   + ("; …" if len(refused) > 4 else "")))
    if senses == {False}:
        warnings.append(LogWarning("table_rate_sense", f"{source} has the opposite sign of the gyros' measured turn "
                                   "in every turn: the table's positive sense is the body axis's negative (the unit "
                                   "mounted upside down on it?); each turn's rate and angle are given about the "
                                   "body axis, signed as the gyros measured it"))
    return rates


def _segment(span: Span, number: int, sample_rate: float, temperature: float, table_rate: float = math.nan,
             on_table: bool = False) -> Segment:
    """The segment-table row of *span*; *on_table* (``--poses table``): an axis-up pose within
    :data:`TABLE_POSE_TILT`, and a turn about the vertical, are ``known`` (the table set the up-axis; the heading
    stays NaN, not logged)."""
    common = dict(dwell=span.samples / sample_rate, settle=0.0, sample_rate=sample_rate, temperature=temperature)
    if span.kind == "static":
        held = f", held (gyros shaking {span.held:.3g}x their quiet noise)" if math.isfinite(span.held) else ""
        set_by_table = on_table and span.tilt <= TABLE_POSE_TILT
        return Segment(f"static {number}: {span.up} up{' (table)' if set_by_table else ''}, tilt "
                       f"{math.degrees(span.tilt):.1f} deg{held}", "static", 0, span.up, heading=math.nan,
                       orientation="known" if set_by_table else span.orientation, **common)
    # a turn about the vertical ("approximate") from a pose the table set
    turn_orientation = "known" if on_table and span.orientation == "approximate" else span.orientation
    measured = math.degrees(float(span.integrated[span.axis])) if span.axis >= 0 else math.nan
    if span.kind == "rotation":
        if math.isfinite(span.steady_rate) and math.isfinite(table_rate):  # the table's rate from its column
            label = (f"rotation {number}: steady at {math.degrees(table_rate):+.6g} deg/s about +{AXES[span.axis]} "
                     f"(the table's logged rate; the gyros measured {math.degrees(span.steady_rate):+.6g} deg/s)")
        elif math.isfinite(span.steady_rate):  # a steady turn: the table's rate is its reference, and not logged
            label = (f"rotation {number}: steady at {math.degrees(span.steady_rate):+.5g} deg/s about "
                     f"+{AXES[span.axis]} (measured; {measured:+.2f} deg): give the table's rate")
        elif math.isfinite(span.table_turned):  # a turn between two rests, by the table's logged angle
            label = (f"rotation {number}: {math.degrees(span.angle):+.6g} deg about +{AXES[span.axis]} (the "
                     f"table's angle over it; the gyros measured {measured:+.2f} deg)")
        else:
            label = (f"rotation {number}: {math.degrees(span.angle):+.0f} deg about +{AXES[span.axis]} (measured "
                     f"{measured:+.2f} deg)")
        return Segment(label, "rotation", span.axis, span.up, heading=math.nan, rate=table_rate,
                       rate_axis=f"+{AXES[span.axis]}", angle=span.angle, orientation=turn_orientation, **common)
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
        if math.isfinite(span.table_turned):
            detail["table_turned_deg"] = math.degrees(span.table_turned)
        else:
            detail["why_not_a_rotation"] = span.reason
    return detail

