"""Builders for the textbook procedures of "IMU error analysis and calibration" (chapter 6, §6.2).

The segments are plain :class:`~plansim.schedule.segments.Segment` objects that no JJF 2003 estimator
reads (``test = "rotation"`` or ``"static"``), so they can be appended to a JJF 2003 schedule and the
whole still passes :func:`plansim.estimate.check_design`; :mod:`plansim.estimate.chapter` reduces them.

- :func:`rate_turns` — the ± rate misalignment runs of eq. (6-8): each axis up, on the vertical table
  axis, one whole turn (or several) at +Ω, then the same at −Ω (the chapter: one turn at ±10 °/s).
- :func:`eight_positions` — the 8-position accelerometer test, per axis under test: that axis up at
  four headings 90° apart, then down at the same four headings (the chapter's Table 6-3 is not
  reproduced in the text plansim follows; docs/chapter-procedures.md says why these eight).
- :func:`drift_positions` — the position test of the gyro drift model D0 + D1·a_X + D2·a_Y + D3·a_Z:
  each axis up and down at the given headings, optionally repeated (the chapter's repeats more than
  12 h apart give the random drift).

All angles in rad, rates in rad/s, times in s, temperatures in °C.
"""

from __future__ import annotations

import math

from plansim.schedule.segments import Segment

#: one whole turn, rad (the chapter's M = 360° of eq. (6-8))
FULL_TURN = 2.0 * math.pi
#: the chapter's rate for the misalignment runs of eq. (6-8): ±10 °/s
CHAPTER_TURN_RATE = 10.0 * math.pi / 180.0
#: the four headings of one half of the 8-position test, rad
EIGHT_POSITION_HEADINGS = (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)


def _axes(axes: str, where: str) -> str:
    if not isinstance(axes, str) or not axes or any(a not in "xyz" for a in axes) or len(set(axes)) != len(axes):
        raise ValueError(f"{where}: axes = {axes!r}; give distinct letters among 'x', 'y', 'z' (e.g. 'xyz')")
    return axes


def _positive(name: str, value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{where}: {name} = {value!r}; expected a number")
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{where}: {name} = {value!r}; it must be finite and > 0")
    return float(value)


def _headings(headings, where: str) -> tuple[float, ...]:
    try:
        out = tuple(float(h) for h in headings)
    except (TypeError, ValueError):
        raise TypeError(f"{where}: headings = {headings!r}; expected a sequence of angles in rad") from None
    if not out or not all(math.isfinite(h) for h in out):
        raise ValueError(f"{where}: headings = {headings!r}; give at least one finite angle (rad)")
    return out


def rate_turns(rate: float = CHAPTER_TURN_RATE, turns: int = 1, axes: str = "xyz", settle: float = 10.0,
               sample_rate: float = 100.0, temperature: float = 20.0) -> list[Segment]:
    """Segments of the chapter's ± rate misalignment runs (eq. (6-8)).

    For each axis *a* in *axes*: ``+a`` up and on the vertical table axis, *turns* whole turns at
    +*rate*, then *turns* whole turns at −*rate*. Each is a ``"rotation"`` segment (``group`` = the axis
    index 0/1/2) whose ``angle`` is ±2π·*turns* and whose recording lasts exactly those turns
    (``dwell = 2π·turns/rate``), so the recorded angle is the chapter's M = 360° per turn.

    Parameters
    ----------
    rate : float
        Table rate Ω, rad/s, > 0 (the chapter: 10 °/s).
    turns : int
        Whole turns per run, >= 1 (the chapter: 1).
    axes : str
        The axes turned, in order (default ``"xyz"``).
    settle, sample_rate, temperature : float
        As for every segment (s, Hz, °C). ``sample_rate × dwell`` must be a whole number of samples,
        so that the samples cover the turns exactly.
    """
    where = "rate_turns"
    rate = _positive("rate", rate, where)
    if isinstance(turns, bool) or not isinstance(turns, int) or turns < 1:
        raise ValueError(f"{where}: turns = {turns!r}; expected a whole number >= 1")
    sample_rate = _positive("sample_rate", sample_rate, where)
    dwell = FULL_TURN * turns / rate
    samples = dwell * sample_rate
    if abs(samples - round(samples)) > 1e-6 * max(1.0, samples):
        raise ValueError(f"{where}: rate = {math.degrees(rate):g} deg/s, turns = {turns} and sample_rate = "
                         f"{sample_rate:g} Hz give {samples:.6g} samples per run; choose them so that the samples "
                         "cover the whole turns (a whole number of samples)")
    dwell = round(samples) / sample_rate  # floor(dwell × sample_rate) is then exactly that number
    out = []
    for axis in _axes(axes, where):
        for sign in (1.0, -1.0):
            out.append(Segment(label=f"turn {axis} {sign * math.degrees(rate):+.6g} deg/s x{turns}", test="rotation",
                               group="xyz".index(axis), up=f"+{axis}", rate=sign * rate, rate_axis=f"+{axis}",
                               angle=sign * FULL_TURN * turns, dwell=dwell, settle=float(settle),
                               sample_rate=sample_rate, temperature=float(temperature)))
    return out


def eight_positions(axes: str = "xyz", headings=EIGHT_POSITION_HEADINGS, dwell: float = 30.0, settle: float = 10.0,
                    sample_rate: float = 100.0, temperature: float = 20.0) -> list[Segment]:
    """Segments of the 8-position accelerometer test, one set of eight per axis in *axes*.

    For each axis *a*: ``+a`` up at each heading, then ``−a`` up at each heading (the default four
    headings 0°, 90°, 180°, 270° make eight positions). ``"static"`` segments, ``group`` = the axis index.
    """
    where = "eight_positions"
    headings = _headings(headings, where)
    out = []
    for axis in _axes(axes, where):
        for up in (f"+{axis}", f"-{axis}"):
            for h in headings:
                out.append(Segment(label=f"8-pos {axis}: {up} up, heading {math.degrees(h):.6g} deg", test="static",
                                   group="xyz".index(axis), up=up, heading=h, dwell=float(dwell), settle=float(settle),
                                   sample_rate=float(sample_rate), temperature=float(temperature)))
    return out


def drift_positions(headings=(0.0, math.pi), repeats: int = 1, dwell: float = 30.0, settle: float = 10.0,
                    sample_rate: float = 100.0, temperature: float = 20.0) -> list[Segment]:
    """Segments of the position test of the gyro drift model D0 + D1·a_X + D2·a_Y + D3·a_Z.

    Each of ``+x −x +y −y +z −z`` up at each heading, the whole set *repeats* times (the chapter repeats
    it more than 12 h apart for the random drift; plansim records the repeats one after the other).
    ``"static"`` segments, ``group`` = the repeat index 0, 1, …
    """
    where = "drift_positions"
    headings = _headings(headings, where)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"{where}: repeats = {repeats!r}; expected a whole number >= 1")
    out = []
    for r in range(repeats):
        for up in ("+x", "-x", "+y", "-y", "+z", "-z"):
            for h in headings:
                out.append(Segment(label=f"drift run {r + 1}: {up} up, heading {math.degrees(h):.6g} deg",
                                   test="static", group=r, up=up, heading=h, dwell=float(dwell),
                                   settle=float(settle), sample_rate=float(sample_rate),
                                   temperature=float(temperature)))
    return out
