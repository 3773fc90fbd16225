"""Does a schedule follow the rules JJF 2003-2022 §7.2 sets for its tests? :func:`jjf2003_compliance`.

The rules, each checked on the segments (not on the scenario's keywords, so a custom schedule is
judged the same way):

``rate_points``
    §7.2.1 c): on each axis's rate test, 7 to 11 distinct rate points (zero counts as a point).
``maximum_both_directions``
    §7.2.1 c) asks for the maximum input rate among the points; here: on each axis the largest
    positive and the largest negative point have the same magnitude. How close that magnitude must
    be to the sensor's range the specification does not say, and a point at the range itself clips
    a unit whose bias is not zero (plansim.config.saturation); :attr:`Compliance.max_rate` reports it
    for the user to judge against the range.
``dwell``
    §7.2.1 c), §7.2.2, §7.2.5: every segment of the rate, multi-position and ω² tests records ≥ 30 s.
``twelve_positions``
    §7.2.2 and Appendix C: the multi-position test holds each of the six axis-up attitudes twice, at
    headings 180° apart (the 6-position variant is not the specification's).
``omega_squared``
    §7.2.5: on each axis, a record at rest and one rotating (U7, U8).

All SI (s, rad/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from plansim.schedule.segments import Schedule

#: JJF 2003 §7.2.1 c): 7 to 11 rate points
RATE_POINTS_MIN, RATE_POINTS_MAX = 7, 11
#: JJF 2003 §7.2.1 c), §7.2.2, §7.2.5: at least 30 s at each rate and position, s
MINIMUM_DWELL = 30.0
#: rates equal to this relative tolerance are one rate point (the table's setting, not a measured value)
SAME_RATE = 1e-9

RULES = {
    "rate_points": "§7.2.1 c): 7 to 11 distinct rate points on each axis",
    "maximum_both_directions": "§7.2.1 c): the largest rate point in both directions, equal magnitudes",
    "dwell": "§7.2.1 c), §7.2.2, §7.2.5: every rate, position and ω² record ≥ 30 s",
    "twelve_positions": "§7.2.2, Appendix C: six attitudes, each at two headings 180° apart",
    "omega_squared": "§7.2.5: on each axis a record at rest and one rotating",
}


@dataclass(frozen=True)
class Compliance:
    """The verdict of each rule of :data:`RULES`, and the largest rate point (rad/s; 0 without a rate test)."""

    rules: dict[str, bool]
    max_rate: float

    @property
    def compliant(self) -> bool:
        return all(self.rules.values())

    def failed(self) -> list[str]:
        """The text of each rule not met."""
        return [RULES[name] for name, ok in self.rules.items() if not ok]


def _distinct(values) -> list[float]:
    out: list[float] = []
    for v in sorted(values):
        if not out or not math.isclose(v, out[-1], rel_tol=SAME_RATE, abs_tol=0.0):
            out.append(v)
    return out


def jjf2003_compliance(schedule: Schedule) -> Compliance:
    """Check *schedule* against the rules of JJF 2003 §7.2 (:data:`RULES`).

    Parameters
    ----------
    schedule : plansim.schedule.Schedule

    Returns
    -------
    Compliance
        One boolean per rule, ``compliant`` when all hold, and the largest rate point.

    Examples
    --------
    >>> from plansim.schedule.builders import jjf2003
    >>> r = [math.radians(w) for w in (-100, -50, -20, -5, 0, 5, 20, 50, 100)]
    >>> jjf2003_compliance(jjf2003(r, math.radians(100))).compliant
    True
    >>> jjf2003_compliance(jjf2003(r, math.radians(100), positions=6)).failed()
    ['§7.2.2, Appendix C: six attitudes, each at two headings 180° apart']
    """
    if not isinstance(schedule, Schedule):
        raise TypeError(f"schedule: expected a plansim Schedule, got {type(schedule).__name__}")
    segments = schedule.segments
    rates_by_axis = {axis: [s.rate for s in segments if s.test == "rate" and s.rate_axis.lstrip("+-") == axis]
                     for axis in "xyz"}
    distinct = {axis: _distinct(r) for axis, r in rates_by_axis.items()}
    counts_ok = all(RATE_POINTS_MIN <= len(d) <= RATE_POINTS_MAX for d in distinct.values())
    symmetric = all(len(d) >= 2 and d[0] < 0 < d[-1]
                    and math.isclose(-d[0], d[-1], rel_tol=SAME_RATE, abs_tol=0.0) for d in distinct.values())
    tested = [s for s in segments if s.test in ("rate", "multi_position", "omega_squared")]
    dwell_ok = bool(tested) and all(s.dwell >= MINIMUM_DWELL for s in tested)
    positions = [s for s in segments if s.test == "multi_position"]
    attitudes: dict[str, list[float]] = {}
    for s in positions:
        attitudes.setdefault(s.up, []).append(s.heading)
    twelve = (len(positions) == 12 and sorted(attitudes) == sorted(("+x", "-x", "+y", "-y", "+z", "-z"))
              and all(len(h) == 2 and math.isclose(abs(h[0] - h[1]) % (2 * math.pi), math.pi, abs_tol=1e-9)
                      for h in attitudes.values()))
    omega = [s for s in segments if s.test == "omega_squared"]
    omega_ok = all(any(s.rate == 0 and s.up.lstrip("+-") == axis for s in omega)
                   and any(s.rate != 0 and s.up.lstrip("+-") == axis for s in omega) for axis in "xyz")
    largest = max((abs(r) for d in distinct.values() for r in d), default=0.0)
    return Compliance({"rate_points": counts_ok, "maximum_both_directions": symmetric, "dwell": dwell_ok,
                       "twelve_positions": twelve, "omega_squared": omega_ok}, float(largest))
