"""Builders for the JJF 2003-2022 procedures.

- :func:`multi_position` — §7.2.2 / §7.2.4, Appendix C: each axis up and down; the 12-position
  version records each twice, 180° apart about the vertical, and averages each pair into one of
  the six groups of eq. (6)–(11); the 6-position version records each once.
- :func:`rate_test` — §7.2.1 / §7.2.3: each axis in turn on the (vertical) table axis, N rate
  points including ± the maximum, ≥ 30 s per point.
- :func:`omega_squared_test` — §7.2.5: each axis vertical, 30 s at rest (U7) then 30 s at rate ω (U8).
- :func:`jjf2003` — the whole procedure: 12 positions, the rate test on x, y, z, the ω² test.

All angles in rad, rates in rad/s, times in s.
"""

from __future__ import annotations

import math

from plansim.schedule.segments import Schedule, Segment

#: group number (column of JJF 2003 eq. (6) matrix A) -> body axis pointing up
GROUP_UP = {1: "+x", 2: "-x", 3: "+y", 4: "-y", 5: "+z", 6: "-z"}


def _common(dwell, settle, sample_rate, temperature):
    return dict(dwell=float(dwell), settle=float(settle), sample_rate=float(sample_rate),
                temperature=float(temperature))


def multi_position(positions: int = 12, dwell: float = 30.0, settle: float = 10.0,
                   sample_rate: float = 100.0, temperature: float = 20.0) -> list[Segment]:
    """Segments of the 12- or 6-position test (JJF 2003 §7.2.2 a), Appendix C)."""
    if positions not in (6, 12):
        raise ValueError(f"schedule.positions = {positions!r}; allowed: 6 or 12")
    headings = (0.0, math.pi) if positions == 12 else (0.0,)
    out = []
    for group, up in GROUP_UP.items():
        for h in headings:
            out.append(Segment(label=f"pos{group}{'ab'[headings.index(h)]} {up} up, heading {math.degrees(h):.0f} deg",
                               test="multi_position", group=group, up=up, heading=h,
                               **_common(dwell, settle, sample_rate, temperature)))
    return out


def rate_test(rates, axes: str = "xyz", dwell: float = 30.0, settle: float = 10.0,
              sample_rate: float = 100.0, temperature: float = 20.0) -> list[Segment]:
    """Segments of the rate test (JJF 2003 §7.2.1): each axis up, on the vertical table axis."""
    rates = [float(r) for r in rates]
    if len(set(rates)) < 2:
        raise ValueError(f"schedule.rate_points = {rates!r}: at least 2 distinct rate points are needed for the "
                         "line fit of JJF 2003 eq. (5) (the specification asks for 7 to 11)")
    out = []
    for axis in axes:
        if axis not in "xyz":
            raise ValueError(f"rate_test(axes={axes!r}): each axis must be one of x, y, z")
        for r in rates:
            out.append(Segment(label=f"rate {axis} {math.degrees(r):+.6g} deg/s", test="rate", group="xyz".index(axis),
                               up=f"+{axis}", rate=r, rate_axis=f"+{axis}",
                               **_common(dwell, settle, sample_rate, temperature)))
    return out


def omega_squared_test(rate: float, dwell: float = 30.0, settle: float = 10.0,
                       sample_rate: float = 100.0, temperature: float = 20.0) -> list[Segment]:
    """Segments of the accelerometer angular-rate sensitivity test (JJF 2003 §7.2.5)."""
    if not rate > 0:
        raise ValueError(f"schedule.omega_squared_rate = {rate!r} rad/s; it must be > 0")
    out = []
    for i, axis in enumerate("xyz"):
        common = _common(dwell, settle, sample_rate, temperature)
        out.append(Segment(label=f"omega2 {axis} at rest (U7)", test="omega_squared", group=i,
                           up=f"+{axis}", rate=0.0, rate_axis=f"+{axis}", **common))
        out.append(Segment(label=f"omega2 {axis} rotating (U8)", test="omega_squared", group=i,
                           up=f"+{axis}", rate=float(rate), rate_axis=f"+{axis}", **common))
    return out


def jjf2003(rate_points, omega_squared_rate: float, positions: int = 12, dwell: float = 30.0,
            settle: float = 10.0, sample_rate: float = 100.0, temperature_start: float = 20.0,
            temperature_end: float | None = None) -> Schedule:
    """The full JJF 2003 procedure: multi-position, rate test on x, y, z, and the ω² test.

    The temperature goes linearly from *temperature_start* to *temperature_end* over the test
    (each segment at the temperature of its recording mid-time); equal ends give a constant one.
    """
    common = dict(dwell=dwell, settle=settle, sample_rate=sample_rate, temperature=temperature_start)
    segments = (multi_position(positions, **common) + rate_test(rate_points, **common)
                + omega_squared_test(omega_squared_rate, **common))
    schedule = Schedule(tuple(segments), procedure="jjf2003")
    end = temperature_start if temperature_end is None else temperature_end
    return with_temperature_ramp(schedule, temperature_start, end)


def with_temperature_ramp(schedule: Schedule, start: float, end: float) -> Schedule:
    """Set each segment's temperature on a linear ramp over the test (°C, at recording mid-time)."""
    total = schedule.duration
    t = 0.0
    out = []
    for s in schedule.segments:
        mid = t + s.settle + 0.5 * s.dwell
        t += s.settle + s.dwell
        temp = start + (end - start) * (mid / total if total > 0 else 0.0)
        out.append(Segment(**{**s.as_dict(), "temperature": temp}))
    return Schedule(tuple(out), procedure=schedule.procedure, notes=schedule.notes)
