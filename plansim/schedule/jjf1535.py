"""The JJF 1535-2015 procedure (single-axis MEMS gyro) as schedule data, for one gyro axis of the MIMU.

plansim simulates a three-axis unit; the gyro under test is one of its axes (*axis*, default ``"x"``), the
others are recorded and not reduced. :func:`jjf1535_procedure` returns a :class:`Jjf1535Procedure`: a plain
:class:`~plansim.schedule.segments.Schedule` (``procedure = "jjf1535"``) plus the indices of the segments
each clause reads, so that :mod:`plansim.estimate.jjf1535_items` reduces them. No JJF 2003 estimator reads
this schedule: its rate points are ``"rotation"`` segments and its rest records ``"static"`` ones, and it is
simulated by replacing a scenario's schedule (``dataclasses.replace``), not through the scenario file.

What it records (JJF 1535-2015 clause 7.2; all angles rad, rates rad/s, times s, temperatures °C):

- 7.2.1 (and 7.2.2–7.2.4) the rate test, the gyro's input axis up on the vertical table axis: the at-rest
  output, the rate points of :func:`r5_rate_points` in each direction (sampling period 1 s, 7.2.1.1 b);
  at least 30 samples below 100 °/s, at least 5 at or above, 7.2.1.1 c)), the at-rest output again
  (7.2.1.1 d)); *repeats* = Q times, *repeat_interval* apart (7.2.1.1 e): 30 min);
- 7.2.8/7.2.10 the bias record, input axis up, at rest, as consecutive segments of one averaging period P
  each (no settling between), so that each segment's mean is one of eq. (18)'s period means F̄_j; Q times;
- 7.2.12 each body axis up and then down (two-axis position table), headings chosen so that the gyro's
  input axis, when horizontal, lies East–West and senses no Earth rate;
- 7.2.13 one long static record, input axis up, for the Allan analysis;
- 7.2.5/7.2.14 at the upper and the lower temperature, after a soak (the first segment's settle time),
  one rate test and one bias record; the room-temperature ones are those above;
- 7.2.6 the threshold test, input axis up at room temperature: for each direction the at-rest output, the small
  rates of :func:`r5_rate_points` from the largest down (30 samples each, 7.2.6.1 b)–d)), the at-rest output
  again (their mean is F̄_0,j of eq. (13));
- 7.2.7 the resolution test: for each direction and each rate increment ΔΩ_j, from the largest down, the base
  rate (20–50 × the expected threshold, 7.2.7.1 b)) and then the base rate plus ΔΩ_j (30 samples each);
- 7.2.9 the warm-up records: the unit powered off for *repeat_interval*, then recorded from power-on as
  consecutive segments of one averaging period each, *warm_up_records* times (7.2.9.2: the mean over N records).

These last three come after all the others (the segments before them, and so their random draws, are those of
the procedure without them).

Power cycles (:attr:`Jjf1535Procedure.power_on`): the unit is switched on *power_on_lead* (30 min, the warm-up
7.2.8.1 a) allows) before the first segment; it is switched off and on again at the start of the
*repeat_interval* before each further room rate test (7.2.4.1: powered off between the Q calibrations) and each
further bias record (7.2.11.1), and at the start of each warm-up record. The JJF 2003 kernels know no power
cycle: the turn-on bias and the warm-up transient of :mod:`plansim.model.jjf1535_effects` are added to the
segment means by the JJF 1535 Monte Carlo.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from plansim.schedule.segments import Schedule, Segment

DEG = math.pi / 180.0
#: GB/T 321-2005, the R5 basic series of preferred numbers in one decade (10^(k/5) rounded)
R5_SERIES = (1.00, 1.60, 2.50, 4.00, 6.30)
#: JJF 1535 7.2.1.1 c): at least 11 rate points in each direction, the maximum included
MINIMUM_POINTS_PER_DIRECTION = 11
#: 7.2.1.1 c): below this rate at least 30 samples per point, at or above it at least 5
SAMPLES_RATE_LIMIT = 100.0 * DEG
SAMPLES_BELOW = 30
SAMPLES_AT_OR_ABOVE = 5
#: 7.2.1.1 b): the sampling period, s
SAMPLE_PERIOD = 1.0


def _number(name: str, value, where: str, positive: bool = True, minimum: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{where}: {name} = {value!r}; expected a number")
    value = float(value)
    if not math.isfinite(value) or (positive and value <= 0) or (minimum is not None and value < minimum):
        rule = f">= {minimum:g}" if minimum is not None else ("> 0" if positive else "finite")
        raise ValueError(f"{where}: {name} = {value!r}; it must be finite and {rule}")
    return value


def _whole(name: str, value, where: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ValueError(f"{where}: {name} = {value!r}; expected a whole number >= {minimum}")
    return value


def r5_rate_points(maximum: float, minimum: float = 1.0 * DEG, points: int | None = None) -> tuple[float, ...]:
    """The rate points of one direction (JJF 1535 7.2.1.1 c)), increasing, rad/s.

    The R5 preferred numbers (GB/T 321, :data:`R5_SERIES` × 10ⁿ, in °/s) from *minimum* up to below
    *maximum*, then *maximum* itself. With *points* given, the list is thinned evenly (by index, the smallest
    and the maximum kept) to that many; the specification asks for at least 11 (the maximum included).

    Parameters
    ----------
    maximum : float
        The largest input rate, rad/s (the gyro's range).
    minimum : float
        The smallest rate considered, rad/s (default 1 °/s).
    points : int, optional
        How many points to keep, >= 11 and at most the number of candidates.
    """
    where = "r5_rate_points"
    maximum = _number("maximum", maximum, where)
    minimum = _number("minimum", minimum, where)
    if minimum >= maximum:
        raise ValueError(f"{where}: minimum = {minimum / DEG:g} deg/s must be below maximum = {maximum / DEG:g} deg/s")
    lo, hi = minimum / DEG, maximum / DEG
    candidates = []
    for decade in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        for r in R5_SERIES:
            value = round(r * 10.0**decade, 10)
            if lo * (1 - 1e-12) <= value < hi * (1 - 1e-12):
                candidates.append(value * DEG)
    candidates.append(maximum)
    if points is None:
        chosen = candidates
    else:
        points = _whole("points", points, where, MINIMUM_POINTS_PER_DIRECTION)
        if points > len(candidates):
            raise ValueError(f"{where}: points = {points}; the R5 series from {lo:g} to {hi:g} deg/s has only "
                             f"{len(candidates)} points (lower the minimum)")
        step = (len(candidates) - 1) / (points - 1)
        chosen = [candidates[round(k * step)] for k in range(points)]
    if len(chosen) < MINIMUM_POINTS_PER_DIRECTION:
        raise ValueError(f"{where}: {len(chosen)} R5 points from {lo:g} to {hi:g} deg/s; JJF 1535 7.2.1.1 c) asks "
                         f"for at least {MINIMUM_POINTS_PER_DIRECTION} in each direction (lower the minimum)")
    return tuple(chosen)


@dataclass(frozen=True)
class RateRun:
    """One rate test (7.2.1.1): indices of its at-rest segments before and after and of its rate points."""

    temperature: float  # °C
    rest_before: int
    points: tuple[int, ...]
    rest_after: int


@dataclass(frozen=True)
class Jjf1535Procedure:
    """A JJF 1535 schedule and which of its segments each clause reads (indices into ``schedule.segments``).

    ``room_runs``/``room_bias`` are the Q room-temperature rate tests and bias records; ``temperature_runs``/
    ``temperature_bias`` one each at the upper and the lower temperature (in that order); ``g_positions``
    maps a body axis ``"x"``, ``"y"``, ``"z"`` to its (up, down) segments; ``allan`` is the long record.
    """

    schedule: Schedule
    axis: int  # the gyro under test: 0, 1, 2 = x, y, z
    room_temperature: float
    room_runs: tuple[RateRun, ...]
    room_bias: tuple[tuple[int, ...], ...]
    g_positions: dict
    allan: int
    temperature_runs: tuple[RateRun, ...]
    temperature_bias: tuple[tuple[int, ...], ...]
    averaging_period: float  # P, s
    #: 7.2.6: one RateRun per direction (+, −), its points the small rates from the largest down
    threshold_runs: tuple[RateRun, ...] = ()
    #: 7.2.7: per direction (+, −), per increment from the largest down, (base segment, base + increment segment)
    resolution_pairs: tuple[tuple[tuple[int, int], ...], ...] = ()
    #: 7.2.7: the commanded rate increments ΔΩ_j of each pair, rad/s, > 0, from the largest down (signed by direction)
    resolution_increments: tuple[float, ...] = ()
    #: 7.2.9: the warm-up records, each from power-on, one averaging period P per segment
    warm_up: tuple[tuple[int, ...], ...] = ()
    #: 7.2.9.2: the specified ("nominal") bias stability the warm-up time is measured against, rad/s (eq. (18), P)
    specified_stability: float = float("nan")
    #: times the unit is switched on, s from the start of the schedule (the first is before it: negative)
    power_on: tuple[float, ...] = ()

    @property
    def temperatures(self) -> tuple[float, ...]:
        """Room, upper, lower (°C)."""
        return (self.room_temperature,) + tuple(r.temperature for r in self.temperature_runs)

    def recording_starts(self) -> np.ndarray:
        """Time of each segment's first sample from the start of the schedule, s, shape (S,), read-only: the
        schedule's clock, each segment's settle then its samples (as ``plansim.io.recording_data.nominal_time``)."""
        return self._clock[0]

    def power_cycles(self) -> tuple[np.ndarray, np.ndarray]:
        """Per segment, the index into :attr:`power_on` of the power cycle it is recorded in and the time of its
        first sample since that power-on (s); shapes (S,), read-only. Without power-on times: cycle 0, time
        ``inf``."""
        return self._clock[1], self._clock[2]

    @functools.cached_property
    def _clock(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        # computed once per procedure (the Monte Carlo asks for it in every trial)
        clock, starts = 0.0, []
        for segment in self.schedule.segments:
            clock += segment.settle
            starts.append(clock)
            clock += segment.samples / segment.sample_rate
        starts = np.array(starts)
        if not self.power_on:
            cycle, since = np.zeros(starts.size, dtype=np.int64), np.full(starts.size, np.inf)
        else:
            on = np.asarray(self.power_on, dtype=float)
            cycle = np.searchsorted(on, starts, side="right") - 1
            if np.any(cycle < 0):
                raise ValueError("power_on: the first power-on must come before the first segment's first sample")
            cycle, since = cycle.astype(np.int64), starts - on[cycle]
        for array in (starts, cycle, since):
            array.flags.writeable = False
        return starts, cycle, since


# the heading that puts the gyro's input axis East–West when another axis is up (body_to_level: axis i+1 -> East
# at heading 0, axis i+2 -> ±North, turned to West/East by a quarter turn)
def _east_west_heading(gyro: int, up_axis: int) -> float:
    return 0.0 if gyro == (up_axis + 1) % 3 else 0.5 * math.pi


def jjf1535_procedure(maximum_rate: float, axis: str = "x", points: int | None = None,
                      minimum_rate: float = 1.0 * DEG, repeats: int = 3, repeat_interval: float = 1800.0,
                      settle: float = 10.0, sample_rate: float = 1.0 / SAMPLE_PERIOD, averaging_period: float = 10.0,
                      bias_periods: int = 60, position_dwell: float = 60.0, allan_duration: float = 7200.0,
                      room_temperature: float = 20.0, upper_temperature: float = 60.0,
                      lower_temperature: float = -20.0, soak: float = 3600.0,
                      threshold_maximum: float = 0.1 * DEG, threshold_minimum: float = 0.001 * DEG,
                      resolution_base_rate: float = 0.5 * DEG, warm_up_duration: float = 1200.0,
                      warm_up_records: int = 2, specified_stability: float = 10.0 * DEG / 3600.0,
                      power_on_lead: float = 1800.0) -> Jjf1535Procedure:
    """Build the JJF 1535 procedure's segments for the gyro *axis* of the MIMU (see the module docstring).

    Parameters
    ----------
    maximum_rate : float
        The gyro's largest input rate, rad/s (included as a rate point in each direction).
    axis : {"x", "y", "z"}
        The gyro under test.
    points, minimum_rate : int, float
        The rate points per direction, :func:`r5_rate_points`.
    repeats : int
        Q, the number of room-temperature rate tests and bias records (>= 2; 7.2.1.1 e): 3).
    repeat_interval : float
        Time between repeats, s (7.2.1.1 e): 30 min), the settle time of each repeat's first segment.
    settle : float
        Settling time before each other segment, s.
    sample_rate : float
        Hz (7.2.1.1 b): one sample per second). A point below 100 °/s records 30 samples, one at or above 5.
    averaging_period : float
        P, s: the length of each bias-record segment (a whole number of samples).
    bias_periods : int
        Periods per bias record (>= 2).
    position_dwell, allan_duration : float
        Recording time of each 7.2.12 position and of the 7.2.13 record, s.
    room_temperature, upper_temperature, lower_temperature : float
        °C; upper > room > lower.
    soak : float
        Settle time before the first segment at the upper and the lower temperature, s.
    threshold_maximum, threshold_minimum : float
        7.2.6: the small rates of the threshold test, and 7.2.7: the rate increments of the resolution test, are
        the R5 points (:func:`r5_rate_points`) from the minimum to the maximum, rad/s (default 0.001 to 0.1 °/s:
        11 points), recorded from the largest down.
    resolution_base_rate : float
        7.2.7.1 b): the base rate of the resolution test, rad/s (20–50 × the expected threshold; default 0.5 °/s).
    warm_up_duration : float
        Length of each 7.2.9 warm-up record from power-on, s (a whole number of averaging periods, at least 10).
    warm_up_records : int
        N, the number of warm-up records (>= 1); the warm-up time is their mean (7.2.9.2).
    specified_stability : float
        7.2.9.2: the specified bias stability (eq. (18) with this P) the warm-up time is measured against, rad/s
        (default 10 °/h).
    power_on_lead : float
        Time from the first power-on to the first segment's first sample, s (7.2.8.1 a): a warm-up of at most
        30 min; default 30 min).
    """
    where = "jjf1535_procedure"
    if axis not in ("x", "y", "z"):
        raise ValueError(f"{where}: axis = {axis!r}; allowed: 'x', 'y', 'z'")
    gyro = "xyz".index(axis)
    rates = r5_rate_points(maximum_rate, minimum_rate, points)
    repeats = _whole("repeats", repeats, where, 2)
    bias_periods = _whole("bias_periods", bias_periods, where, 2)
    repeat_interval = _number("repeat_interval", repeat_interval, where, positive=False, minimum=0.0)
    settle = _number("settle", settle, where, positive=False, minimum=0.0)
    soak = _number("soak", soak, where, positive=False, minimum=0.0)
    sample_rate = _number("sample_rate", sample_rate, where)
    period = _number("averaging_period", averaging_period, where)
    if abs(period * sample_rate - round(period * sample_rate)) > 1e-9 or round(period * sample_rate) < 1:
        raise ValueError(f"{where}: averaging_period = {period!r} s at sample_rate = {sample_rate!r} Hz; it must "
                         "hold a whole number (>= 1) of samples")
    for name in ("position_dwell", "allan_duration"):
        _number(name, locals()[name], where)
    threshold_rates = r5_rate_points(threshold_maximum, threshold_minimum)
    base_rate = _number("resolution_base_rate", resolution_base_rate, where)
    warm_up_records = _whole("warm_up_records", warm_up_records, where, 1)
    specified_stability = _number("specified_stability", specified_stability, where)
    power_on_lead = _number("power_on_lead", power_on_lead, where, positive=False, minimum=0.0)
    warm_up_duration = _number("warm_up_duration", warm_up_duration, where)
    warm_up_periods = warm_up_duration / period
    if abs(warm_up_periods - round(warm_up_periods)) > 1e-9 or round(warm_up_periods) < 10:
        raise ValueError(f"{where}: warm_up_duration = {warm_up_duration!r} s with averaging_period = {period!r} s; "
                         "it must hold a whole number (>= 10) of averaging periods (7.2.9: the stability of "
                         "eq. (18) needs at least 10 periods after the warm-up time)")
    room = _number("room_temperature", room_temperature, where, positive=False)
    upper = _number("upper_temperature", upper_temperature, where, positive=False)
    lower = _number("lower_temperature", lower_temperature, where, positive=False)
    if not lower < room < upper:
        raise ValueError(f"{where}: temperatures lower = {lower!r}, room = {room!r}, upper = {upper!r} degC; "
                         "allowed only lower < room < upper")
    up = f"+{axis}"
    segments: list[Segment] = []

    def add(**kw) -> int:
        segments.append(Segment(sample_rate=sample_rate, **kw))
        return len(segments) - 1

    def rate_run(name: str, temperature: float, first_settle: float) -> RateRun:
        before = add(label=f"{name}: at rest before", test="static", group=gyro, up=up, rate_axis=up,
                     dwell=SAMPLES_BELOW / sample_rate, settle=first_settle, temperature=temperature)
        idx = []
        for sign in (1.0, -1.0):
            for r in rates:
                n = SAMPLES_BELOW if r < SAMPLES_RATE_LIMIT * (1 - 1e-12) else SAMPLES_AT_OR_ABOVE
                idx.append(add(label=f"{name}: {sign * r / DEG:+.6g} deg/s", test="rotation", group=gyro, up=up,
                               rate=sign * r, rate_axis=up, dwell=n / sample_rate, settle=settle,
                               temperature=temperature))
        after = add(label=f"{name}: at rest after", test="static", group=gyro, up=up, rate_axis=up,
                    dwell=SAMPLES_BELOW / sample_rate, settle=settle, temperature=temperature)
        return RateRun(temperature, before, tuple(idx), after)

    def bias_record(name: str, temperature: float, first_settle: float) -> tuple[int, ...]:
        return tuple(add(label=f"{name}: period {j + 1}", test="static", group=gyro, up=up, rate_axis=up,
                         dwell=period, settle=first_settle if j == 0 else 0.0, temperature=temperature)
                     for j in range(bias_periods))

    room_runs = tuple(rate_run(f"7.2.1 run {q + 1}", room, settle if q == 0 else repeat_interval)
                      for q in range(repeats))
    room_bias = tuple(bias_record(f"7.2.8 record {q + 1}", room, settle if q == 0 else repeat_interval)
                      for q in range(repeats))
    g_positions = {}
    for a, name in enumerate("xyz"):
        heading = 0.0 if a == gyro else _east_west_heading(gyro, a)
        g_positions[name] = tuple(
            add(label=f"7.2.12 {sign}{name} up", test="static", group=gyro, up=f"{sign}{name}", heading=heading,
                rate_axis=up, dwell=float(position_dwell), settle=settle, temperature=room)
            for sign in "+-")
    allan = add(label="7.2.13 static record", test="static", group=gyro, up=up, rate_axis=up,
                dwell=float(allan_duration), settle=settle, temperature=room)
    temperature_runs, temperature_bias = [], []
    for name, t in (("upper", upper), ("lower", lower)):
        temperature_runs.append(rate_run(f"7.2.5 {name} {t:g} degC", t, soak))
        temperature_bias.append(bias_record(f"7.2.14 {name} {t:g} degC", t, settle))
    # 7.2.6, 7.2.7, 7.2.9: after every other segment, so that those keep their random draws
    threshold_runs = []
    for sign, name in ((1.0, "+"), (-1.0, "-")):
        before = add(label=f"7.2.6 threshold {name}: at rest before", test="static", group=gyro, up=up, rate_axis=up,
                     dwell=SAMPLES_BELOW / sample_rate, settle=settle, temperature=room)
        idx = tuple(add(label=f"7.2.6 threshold: {sign * r / DEG:+.6g} deg/s", test="rotation", group=gyro, up=up,
                        rate=sign * r, rate_axis=up, dwell=SAMPLES_BELOW / sample_rate, settle=settle,
                        temperature=room) for r in reversed(threshold_rates))
        after = add(label=f"7.2.6 threshold {name}: at rest after", test="static", group=gyro, up=up, rate_axis=up,
                    dwell=SAMPLES_BELOW / sample_rate, settle=settle, temperature=room)
        threshold_runs.append(RateRun(room, before, idx, after))
    resolution_pairs = []
    for sign in (1.0, -1.0):
        pairs = []
        for r in reversed(threshold_rates):
            pair = tuple(add(label=f"7.2.7 resolution: {sign * base_rate / DEG:+.6g} {extra} deg/s", test="rotation",
                             group=gyro, up=up, rate=sign * (base_rate + step), rate_axis=up,
                             dwell=SAMPLES_BELOW / sample_rate, settle=settle, temperature=room)
                         for extra, step in (("+ 0", 0.0), (f"{sign * r / DEG:+.6g}", r)))
            pairs.append(pair)
        resolution_pairs.append(tuple(pairs))
    warm_up = tuple(
        tuple(add(label=f"7.2.9 warm-up record {n + 1}: period {j + 1}", test="static", group=gyro, up=up,
                  rate_axis=up, dwell=period, settle=repeat_interval if j == 0 else 0.0, temperature=room)
              for j in range(round(warm_up_periods)))
        for n in range(warm_up_records))
    notes = {"jjf1535": f"gyro {axis}; {len(rates)} R5 rate points per direction up to "
                        f"{maximum_rate / DEG:g} deg/s; Q = {repeats}; P = {period:g} s"}
    procedure = Jjf1535Procedure(
        schedule=Schedule(tuple(segments), procedure="jjf1535", notes=notes), axis=gyro,
        room_temperature=room, room_runs=room_runs, room_bias=room_bias, g_positions=g_positions,
        allan=allan, temperature_runs=tuple(temperature_runs), temperature_bias=tuple(temperature_bias),
        averaging_period=period, threshold_runs=tuple(threshold_runs), resolution_pairs=tuple(resolution_pairs),
        resolution_increments=tuple(reversed(threshold_rates)), warm_up=warm_up,
        specified_stability=specified_stability)
    starts = procedure.recording_starts()
    on = [-power_on_lead]
    on += [float(starts[run.rest_before] - segments[run.rest_before].settle) for run in room_runs[1:]]
    on += [float(starts[rec[0]] - segments[rec[0]].settle) for rec in room_bias[1:]]
    on += [float(starts[rec[0]]) for rec in warm_up]
    return dataclasses.replace(procedure, power_on=tuple(sorted(on)))


@dataclass(frozen=True)
class Jjf1535Settings:
    """The settings of :func:`jjf1535_procedure` a lab chooses, SI (rad/s, s, Hz, °C), as one value: what
    ``plansim run jjf1535 --procedure KEY=VALUE`` and ``plansim sweep jjf1535`` vary (:data:`SETTING_KINDS`).

    Every field is an argument of :func:`jjf1535_procedure` of the same name (its docstring says what each one
    is and which clause asks for it); ``points = 0`` keeps every R5 point. ``overrides`` holds the
    ``KEY=VALUE`` items that made it, for the report.
    """

    maximum_rate: float = 100.0 * DEG
    axis: str = "x"
    points: int = 0
    minimum_rate: float = 1.0 * DEG
    repeats: int = 3
    repeat_interval: float = 1800.0
    settle: float = 10.0
    sample_rate: float = 1.0 / SAMPLE_PERIOD
    averaging_period: float = 10.0
    bias_periods: int = 60
    position_dwell: float = 60.0
    allan_duration: float = 7200.0
    room_temperature: float = 20.0
    upper_temperature: float = 60.0
    lower_temperature: float = -20.0
    soak: float = 3600.0
    threshold_maximum: float = 0.1 * DEG
    threshold_minimum: float = 0.001 * DEG
    resolution_base_rate: float = 0.5 * DEG
    warm_up_duration: float = 1200.0
    warm_up_records: int = 2
    specified_stability: float = 10.0 * DEG / 3600.0
    power_on_lead: float = 1800.0
    overrides: tuple[str, ...] = ()

    def procedure(self) -> Jjf1535Procedure:
        """The procedure these settings describe (every check of :func:`jjf1535_procedure` applies)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "overrides"}
        values["points"] = None if values["points"] == 0 else values["points"]
        return jjf1535_procedure(values.pop("maximum_rate"), **values)


#: each setting's kind for ``KEY=VALUE`` (a unit kind of :data:`plansim.units.KINDS`, ``count`` or ``choice``)
SETTING_KINDS = {"maximum_rate": "angular_rate", "axis": "choice", "points": "count", "minimum_rate": "angular_rate",
                 "repeats": "count", "repeat_interval": "time", "settle": "time", "sample_rate": "frequency",
                 "averaging_period": "time", "bias_periods": "count", "position_dwell": "time",
                 "allan_duration": "time", "room_temperature": "temperature", "upper_temperature": "temperature",
                 "lower_temperature": "temperature", "soak": "time", "threshold_maximum": "angular_rate",
                 "threshold_minimum": "angular_rate", "resolution_base_rate": "angular_rate",
                 "warm_up_duration": "time", "warm_up_records": "count", "specified_stability": "angular_rate",
                 "power_on_lead": "time"}
