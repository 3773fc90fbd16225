"""Two sensors sampled apart, paired on one time axis: the gyros and the accelerometers logged in two files
(``plansim import LOG --accel-log LOG2``) or in rows of their own in one file.

:func:`pair_logs` keeps the slower log's samples and gives each the mean of the faster log's samples in its
interval; :func:`split_interleaved` splits a one-file log whose rows hold one sensor each into the two tables it
pairs. Both take and give :class:`plansim.io.log_table.LogTable` (docs/measured-data.md, ``--accel-log``).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from plansim.io.log_table import LogTable

#: a sample of the log the pairing keeps takes the mean of the other log's samples within half its own period on
#: each side (half-way to its neighbours, at most :data:`PAIRING_REACH` of its usual period away where the kept log
#: has a gap); where none falls there, the other log's nearest sample within this many of the other log's usual
#: periods; farther (the other log has a gap there, or has not started or has stopped), the sample is dropped, and the
#: import reports the gap this leaves in the time column
PAIRING_REACH = 1.0


def pair_logs(gyro: LogTable, accel: LogTable, seconds_per_unit: float = 1.0) -> LogTable:
    """One table of the six channels from a gyro log and an accelerometer log written as two files.

    Loggers that write each sensor to its own file (imu_tk's two files; phone apps such as phyphox and the Android
    and iOS sensor loggers) stamp both with one clock, but the two sensors are not sampled together, and often not
    at the same rate. The samples of the log with the lower rate are kept (the gyro log's at equal rates), each
    with the **mean of the other log's samples in its interval**, half-way to its neighbours (at most
    :data:`PAIRING_REACH` of its usual period on each side); where none falls in it, the other log's nearest sample
    within :data:`PAIRING_REACH` of the other's usual period; where none is so near (the other log not yet started,
    stopped, or in a gap), the sample is dropped.

    Every sample of the faster log is used once, in one mean: the angle a gyro integrates over a turn or a move is
    kept whole (picking one sample in m instead aliases the hand's faster motion into it: the Ferraris session's
    gyros, so decimated to half their rate, turned the moves' fit over to a mirror solution with two scale factors
    near −1, where the mean of each pair fits as the full rate does), and its white noise stays white, its density
    (variance per sample × period) unchanged. An interpolation between neighbours would correlate them and lower the
    variance the noise fit reads, with every uncertainty. The time between a kept sample and the middle of its mean
    (at most half a period of the faster log, at equal rates) does not move a static pose's means; in a turn it
    delays one sensor by less than a sample.

    The gyro log's other columns (a temperature, the table's rate or its unwrapped angle) follow its outputs: as
    logged where its samples are kept, else the mean over the gyro samples paired with each kept sample, the same
    samples whose outputs are averaged. A turn's mean table rate, and the table's angle from rest to rest, are then
    the reference of exactly the gyro outputs that measured them.

    Logs without a time column are paired row by row, and must then have as many rows (imu_tk's files, sampled
    together).

    Parameters
    ----------
    gyro, accel : LogTable
        The two logs as :func:`read_log` reads them, ``channels`` ``gx gy gz`` and ``ax ay az``, their time
        columns in one unit (or both clock times).
    seconds_per_unit : float
        The time columns' unit in seconds (1 for clock times), for the rates and times the pairing reports.

    Returns
    -------
    LogTable
        The six channels on the kept samples, with the gyro log's temperature and table columns; ``path``,
        ``lines``, ``time`` and the header's details are the kept log's, and ``pairing`` says what was done.

    Raises
    ------
    ValueError
        One log has a time column and the other not, or clock times and the other numbers; a time column goes
        backwards; logs without time columns differ in length; the logs do not overlap in time.
    """
    if (gyro.time is None) != (accel.time is None) or (gyro.clock_zero_s is None) != (accel.clock_zero_s is None):
        raise ValueError(f"the gyro log {gyro.path.name!r} and the accelerometer log {accel.path.name!r} must both "
                         "have a time column of one kind (numbers in one unit, or clock times), or neither")
    if gyro.time is None:
        if gyro.channels.shape[0] != accel.channels.shape[0]:
            raise ValueError(f"the gyro log {gyro.path.name!r} has {gyro.channels.shape[0]} samples and the "
                             f"accelerometer log {accel.path.name!r} {accel.channels.shape[0]}: without time columns "
                             "the two are paired row by row and must be as long (give each a time column, --time)")
        return dataclasses.replace(
            gyro, channels=np.hstack([gyro.channels, accel.channels]), names=gyro.names + accel.names,
            ignored=gyro.ignored + accel.ignored, decimal_comma=gyro.decimal_comma or accel.decimal_comma,
            units_row=_paired_units_row(gyro, accel),
            pairing=(f"gyros from {gyro.path.name}, accelerometers from {accel.path.name}: paired row by row "
                     f"({gyro.channels.shape[0]} samples each, no time columns); lines are {gyro.path.name}'s",
                     *_skipped_lines(accel)))
    t_gyro, period_gyro = _clock(gyro, "gyro log")
    t_accel, period_accel = _clock(accel, "accelerometer log")
    if period_accel > period_gyro * (1.0 + 1e-3):
        (kept, t_kept, period_kept), (other, t_other, period_other) = ((accel, t_accel, period_accel),
                                                                        (gyro, t_gyro, period_gyro))
    else:
        (kept, t_kept, period_kept), (other, t_other, period_other) = ((gyro, t_gyro, period_gyro),
                                                                        (accel, t_accel, period_accel))
    # each kept sample's interval: half-way to its neighbours, at most PAIRING_REACH of its period on each side
    half = np.minimum(np.diff(t_kept) / 2.0, PAIRING_REACH * period_kept)
    left = t_kept - np.r_[min(period_kept / 2.0, PAIRING_REACH * period_kept), half]
    right = t_kept + np.r_[half, min(period_kept / 2.0, PAIRING_REACH * period_kept)]
    first, stop = np.searchsorted(t_other, left, side="left"), np.searchsorted(t_other, right, side="left")
    counts = stop - first
    filled = np.flatnonzero(counts > 0)
    empty = counts == 0
    bounds = np.empty(2 * filled.size, dtype=np.intp)  # [first, stop) of each filled interval, disjoint and in order
    bounds[0::2], bounds[1::2] = first[filled], stop[filled]
    # an interval no sample of the other log falls in: its nearest sample, if within PAIRING_REACH of its period
    j = np.clip(np.searchsorted(t_other, t_kept), 1, t_other.size - 1)
    j = np.where(np.abs(t_other[j - 1] - t_kept) <= np.abs(t_other[j] - t_kept), j - 1, j)

    def interval_means(values: np.ndarray) -> np.ndarray:
        """Each kept sample's mean of *values* (the other log's, (N,) or (N, k)) over its interval, or the nearest."""
        out = np.empty((t_kept.size,) + values.shape[1:])
        if filled.size:
            padded = np.concatenate([values, np.zeros((1,) + values.shape[1:])])
            sums = np.add.reduceat(padded, bounds, axis=0)[0::2]
            out[filled] = sums / counts[filled].reshape((-1,) + (1,) * (values.ndim - 1))
        out[empty] = values[j[empty]]
        return out

    means = interval_means(other.channels)
    offset = interval_means(t_other - t_kept[0]) - (t_kept - t_kept[0])
    keep = ~empty | (np.abs(offset) <= PAIRING_REACH * period_other)
    if np.count_nonzero(keep) < 2:
        raise ValueError(f"the gyro log {gyro.path.name!r} ({t_gyro[0]:.6g} to {t_gyro[-1]:.6g}) and the "
                         f"accelerometer log {accel.path.name!r} ({t_accel[0]:.6g} to {t_accel[-1]:.6g}, in the time "
                         "column's unit) do not overlap in time: they must be stamped by one clock")
    gyro_part, accel_part = ((kept.channels[keep], means[keep]) if kept is gyro
                             else (means[keep], kept.channels[keep]))
    def gyro_column(values: np.ndarray | None) -> np.ndarray | None:
        """A column of the gyro log (the temperature, the table's rate or unwrapped angle) on the kept samples: as
        logged where the gyro log is kept, else its mean over the gyro samples paired with each, as their outputs."""
        if values is None:
            return None
        return values[keep] if kept is gyro else interval_means(values)[keep]

    rates = [1.0 / (period * seconds_per_unit) for period in (period_gyro, period_accel)]
    kind = "equal-rate" if abs(period_gyro - period_accel) <= 1e-3 * period_gyro else "slower"
    apart = np.abs(offset[keep]) * seconds_per_unit
    used = counts[keep & ~empty]
    note = (f"gyros from {gyro.path.name} ({rates[0]:.6g} Hz), accelerometers from {accel.path.name} "
            f"({rates[1]:.6g} Hz): each sample of {kept.path.name} (the {kind} log, whose lines are given) takes the "
            f"mean of the samples of {other.path.name} in its interval ({int(used.min()) if used.size else 0} to "
            f"{int(used.max()) if used.size else 0}, {np.mean(used) if used.size else 0:.3g} on average), their "
            f"middle {np.max(apart):.3g} s from it at most ({np.sqrt(np.mean(apart ** 2)):.3g} s RMS)")
    extra = []
    dropped = int(keep.size - np.count_nonzero(keep))
    if np.any(empty & keep):
        extra.append(f"{int(np.count_nonzero(empty & keep))} sample(s) of {kept.path.name} with no sample of "
                     f"{other.path.name} in their interval took its nearest")
    if dropped:
        extra.append(f"{dropped} sample(s) of {kept.path.name} had no sample of {other.path.name} within "
                     f"{PAIRING_REACH:g} of its periods (before it started, after it stopped or in a gap): dropped")
    return dataclasses.replace(
        kept, channels=np.hstack([gyro_part, accel_part]), names=gyro.names + accel.names,
        time=kept.time[keep], temperature=gyro_column(gyro.temperature), temperature_column=gyro.temperature_column,
        table_rate=gyro_column(gyro.table_rate), table_rate_column=gyro.table_rate_column,
        table_angle=gyro_column(gyro.table_angle), table_angle_column=gyro.table_angle_column,
        ignored=gyro.ignored + accel.ignored, first_line=int(kept.lines[keep][0]), lines=kept.lines[keep],
        decimal_comma=gyro.decimal_comma or accel.decimal_comma, units_row=_paired_units_row(gyro, accel),
        pairing=(note, *extra, *_skipped_lines(other)))


def _clock(table: LogTable, what: str) -> tuple[np.ndarray, float]:
    """A log's times on the clock both logs share (its clock time added where it has one) and its usual period
    (the median of its steps), checked: never going backwards, at least two distinct times."""
    t = table.time + (table.clock_zero_s or 0.0)
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        k = int(back[0]) + 1
        raise ValueError(f"{what} {str(table.path)!r}: column {table.time_column!r} goes backwards at line "
                         f"{table.lines[k]} ({float(table.time[k - 1])!r} then {float(table.time[k])!r}); the two "
                         "logs are paired by time, which must not go backwards")
    steps = np.diff(t)
    steps = steps[steps > 0]
    if steps.size == 0:
        raise ValueError(f"{what} {str(table.path)!r}: {t.size} sample(s) with distinct times; expected a recording")
    return t, float(np.median(steps))


def split_interleaved(table: LogTable) -> tuple[LogTable, LogTable]:
    """The gyro and the accelerometer rows of a log that writes each sensor's samples in rows of their own, the
    other sensor's three columns left empty (``table.interleaved``), as two tables for :func:`pair_logs`. A row
    holding both is in both. The temperature and the table's columns (logged on every row) are kept on each half's
    rows: :func:`pair_logs` pairs the gyro half's with the gyros' outputs.

    Raises
    ------
    ValueError
        The log has no time column (the rows cannot be paired without one), or one sensor has fewer than two rows.
    """
    where = f"log {str(table.path)!r}"
    if table.time is None:
        raise ValueError(f"{where}: some rows hold only the gyros or only the accelerometers (the other three columns "
                         "empty): the two are paired by time, so the log needs its time column (--time)")
    halves = []
    for part, sensor in ((slice(0, 3), "gyro"), (slice(3, 6), "accelerometer")):
        rows = np.flatnonzero(np.all(np.isfinite(table.channels[:, part]), axis=1))
        if rows.size < 2:
            raise ValueError(f"{where}: {rows.size} row(s) hold the {sensor}s' values; some rows hold only one "
                             "sensor's (the other three columns empty), and each sensor needs its samples")
        halves.append(dataclasses.replace(
            table, channels=table.channels[rows, part], names=table.names[part], time=table.time[rows],
            temperature=_on_rows(table.temperature, rows), table_rate=_on_rows(table.table_rate, rows),
            table_angle=_on_rows(table.table_angle, rows), lines=table.lines[rows],
            first_line=int(table.lines[rows[0]]), interleaved=False))
    # one file: what was skipped in it is reported once, with the kept half
    return halves[0], dataclasses.replace(halves[1], preamble=(), trailing=())


def _on_rows(values: np.ndarray | None, rows: np.ndarray) -> np.ndarray | None:
    """A per-row column (the temperature, the table's rate or angle) on *rows*, or None where it was not logged."""
    return None if values is None else values[rows]


def _paired_units_row(gyro: LogTable, accel: LogTable) -> tuple[int, tuple[str, ...]] | None:
    """The two logs' units rows as one (the gyro log's line), where both have one."""
    if gyro.units_row is None or accel.units_row is None:
        return None
    return gyro.units_row[0], gyro.units_row[1] + accel.units_row[1]


def _skipped_lines(table: LogTable) -> tuple[str, ...]:
    """What was skipped in the log whose lines are not given (its preamble and trailing lines), in words."""
    notes = []
    if table.preamble:
        notes.append(f"{table.path.name}: {len(table.preamble)} line(s) before its header skipped")
    if table.trailing:
        notes.append(f"{table.path.name}: {len(table.trailing)} line(s) after its last sample skipped (not samples)")
    return tuple(notes)
