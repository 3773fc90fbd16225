"""A schedule is data: an ordered list of recorded segments.

Each :class:`Segment` is one dwell of the table in which the MIMU output is recorded: where the
MIMU points (which body axis is up, and the heading about the vertical), the table rate about a
body axis, how long the table settles before recording, how long it records, at what sample rate
and at what temperature. ``test`` and ``group`` say which JJF 2003 reduction uses the segment.

Frames: the local-level frame is East-North-Up; the body frame is the MIMU's case (the reference
axes of JJF 2003 clause 5). With ``up = "+x"`` and ``heading = 0`` the body axes point
x → Up, y → East, z → North; the other ``up`` values follow by cyclic permutation
(axis *i* → ±Up, axis *i+1* → East, axis *i+2* → ±North), and ``heading`` turns the MIMU
about the vertical, counter-clockwise seen from above.

Measured logs need more than a laboratory's table gives (docs/recording.md): a pose placed by hand is
known only roughly or not at all (``orientation``), a turn may be known by its angle rather than its
rate (``test = "rotation"``, ``angle``), and a rate may not have been logged. A value that is not known
is NaN — ``heading`` (when ``orientation`` is not ``"known"``, or in a ``"static"`` or ``"rotation"`` segment
whose up-axis a table set but whose heading was not logged), ``rate`` and ``angle`` (of a ``"rotation"``);
infinity is never allowed.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

AXIS_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")
#: the JJF 2003 tests, then the segment kinds of measured logs: ``static`` (at rest, no JJF 2003 role: a
#: hand-placed pose, a long static record), ``rotation`` (a turn known by its angle and/or its rate) and
#: ``move`` (motion between poses with no reference: kept so that the log is complete, used by no estimator)
TESTS = ("multi_position", "rate", "omega_squared", "static", "rotation", "move")
#: how well a segment's pose (``up``, ``heading``) is known: exactly (a table), approximately (the
#: nearest nominal pose of a hand-placed unit), or not at all
ORIENTATIONS = ("known", "approximate", "unknown")


def axis_vector(name: str, field_name: str = "axis") -> np.ndarray:
    """Unit vector of a signed body axis name such as ``"-y"``."""
    if name not in AXIS_NAMES:
        raise ValueError(f"{field_name} = {name!r}: expected one of {', '.join(AXIS_NAMES)}")
    v = np.zeros(3)
    v["xyz".index(name[1])] = 1.0 if name[0] == "+" else -1.0
    return v


def body_to_level(up: str, heading: float) -> np.ndarray:
    """Direction-cosine matrix C_nb (body -> East-North-Up) for a nominal position."""
    u = axis_vector(up, "up")
    i = int(np.argmax(np.abs(u)))
    sign = u[i]
    c = np.zeros((3, 3))
    c[:, i] = (0.0, 0.0, sign)  # axis i -> ±Up
    c[:, (i + 1) % 3] = (1.0, 0.0, 0.0)  # axis i+1 -> East
    c[:, (i + 2) % 3] = (0.0, sign, 0.0)  # axis i+2 -> ±North (right-handed)
    ch, sh = math.cos(heading), math.sin(heading)
    rz = np.array([[ch, -sh, 0.0], [sh, ch, 0.0], [0.0, 0.0, 1.0]])
    return rz @ c


@dataclass(frozen=True)
class Segment:
    """One recorded dwell. Angles in rad, rates in rad/s, times in s, temperature in °C.

    Parameters
    ----------
    label : str
        Free text.
    test : str
        One of :data:`TESTS`: the JJF 2003 test that uses the segment, or ``static``, ``rotation``, ``move``.
    group : int
        Position group (multi-position) or axis 0/1/2 (rate, ω², rotation); free otherwise.
    up : str
        Body axis pointing up (for a ``rotation``, at its start): ``+x -x +y -y +z -z``.
    heading : float
        Heading about the vertical, rad. NaN (not known) is allowed when ``orientation`` is not ``"known"``.
    rate : float
        Table rate about ``rate_axis``, rad/s. A ``static`` segment has 0; a ``rotation`` a non-zero rate or
        NaN (the rate was not logged); a ``move`` any rate or NaN.
    rate_axis : str
        Body axis on the rotation axis.
    dwell, settle : float
        Recording time and settling time before it, s.
    sample_rate : float
        Hz.
    temperature : float
        °C.
    orientation : str
        One of :data:`ORIENTATIONS` (default ``"known"``): ``"approximate"`` means ``up``/``heading`` are the
        nearest nominal pose of a pose known only roughly (hand-placed); ``"unknown"`` means they are
        placeholders. ``"known"`` with ``heading`` NaN (a ``"static"`` or ``"rotation"`` segment only): a table
        set the up-axis, to its grade, but its heading about the vertical was not logged (``plansim import
        --poses table``).
    angle : float
        Reference angle turned about ``rate_axis`` during a ``rotation`` segment, rad (signed like ``rate``);
        NaN (the default) when not known, and always NaN for the other tests.
    """

    label: str
    test: str
    group: int
    up: str
    heading: float = 0.0
    rate: float = 0.0
    rate_axis: str = "+x"
    dwell: float = 30.0
    settle: float = 10.0
    sample_rate: float = 100.0
    temperature: float = 20.0
    orientation: str = "known"
    angle: float = math.nan

    def __post_init__(self):
        where = f"segment {self.label!r}"
        if self.test not in TESTS:
            raise ValueError(f"{where}: test = {self.test!r}; allowed: {', '.join(TESTS)}")
        if self.orientation not in ORIENTATIONS:
            raise ValueError(f"{where}: orientation = {self.orientation!r}; allowed: {', '.join(ORIENTATIONS)}")
        axis_vector(self.up, f"{where}: up")
        axis_vector(self.rate_axis, f"{where}: rate_axis")
        # which numbers may be NaN (= not known), and why
        may_be_unknown = {
            "heading": (self.orientation != "known" or self.test in ("static", "rotation"),
                        "a heading may be NaN (not known) only when orientation is 'approximate' or 'unknown', or in a "
                        "'static' or 'rotation' segment (a table's pose whose heading was not logged)"),
            "rate": (self.test in ("rotation", "move"), "a rate may be NaN (not logged) only in a 'rotation' or "
                                                         "'move' segment"),
            "angle": (True, ""),
        }
        for name in ("heading", "rate", "dwell", "settle", "sample_rate", "temperature", "angle"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise TypeError(f"{where}: {name} must be a number, got {value!r}")
            if math.isnan(value):
                allowed, rule = may_be_unknown.get(name, (False, "it must be finite"))
                if not allowed:
                    raise ValueError(f"{where}: {name} = nan; {rule}")
                object.__setattr__(self, name, math.nan)  # one NaN object: equal segments compare equal
            elif not math.isfinite(value):
                raise ValueError(f"{where}: {name} = {value!r}; it must be finite" +
                                 (" or NaN (not known)" if may_be_unknown.get(name, (False,))[0] else ""))
        if self.test != "rotation" and not math.isnan(self.angle):
            raise ValueError(f"{where}: angle = {self.angle!r} rad in a {self.test!r} segment; only a 'rotation' "
                             "segment has an angle (NaN elsewhere)")
        if self.test == "static" and self.rate != 0.0:
            raise ValueError(f"{where}: rate = {self.rate!r} rad/s in a 'static' segment; it must be 0")
        if self.test == "rotation" and self.rate == 0.0:
            raise ValueError(f"{where}: rate = 0.0 in a 'rotation' segment; give the rate (rad/s) or NaN if it was "
                             "not logged")
        if self.dwell <= 0:
            raise ValueError(f"{where}: dwell = {self.dwell!r} s; it must be > 0")
        if self.settle < 0:
            raise ValueError(f"{where}: settle = {self.settle!r} s; it must be >= 0")
        if self.sample_rate <= 0:
            raise ValueError(f"{where}: sample_rate = {self.sample_rate!r} Hz; it must be > 0")
        if self.samples < 1:
            raise ValueError(f"{where}: dwell × sample_rate gives no sample; record at least one")

    @property
    def samples(self) -> int:
        """Number of samples recorded: floor(dwell × sample_rate)."""
        return int(math.floor(self.dwell * self.sample_rate + 1e-9))

    @property
    def is_rotating(self) -> bool:
        """True when the table turns: a non-zero rate, or a ``rotation`` whose rate was not logged."""
        return self.rate != 0.0

    @property
    def rate_known(self) -> bool:
        """False when the rate was not logged (``rate`` is NaN)."""
        return not math.isnan(self.rate)

    @property
    def angle_known(self) -> bool:
        """True when a ``rotation``'s reference angle is given (``angle`` is not NaN)."""
        return not math.isnan(self.angle)

    @property
    def heading_known(self) -> bool:
        """False when the heading is not known (``heading`` is NaN)."""
        return not math.isnan(self.heading)

    def as_dict(self) -> dict:
        return asdict(self)


#: the key of :attr:`Schedule.notes` under which ``plansim import`` records how it read the log
#: (:func:`plansim.io.log_import.import_log` writes it; the fit and the import summary read it:
#: :attr:`Schedule.import_notes`)
IMPORT_NOTES = "import"
#: … its entries naming the table's columns the log held (the column's name, or None): its rate, its angle
TABLE_RATE_NOTE = "table_rate_column"
TABLE_ANGLE_NOTE = "table_angle_column"
TABLE_COLUMN_NOTES = (TABLE_RATE_NOTE, TABLE_ANGLE_NOTE)


@dataclass(frozen=True)
class Schedule:
    """An ordered tuple of segments plus the name of the procedure that built it."""

    segments: tuple[Segment, ...]
    procedure: str = "custom"
    notes: dict = field(default_factory=dict)

    @property
    def import_notes(self) -> dict:
        """How ``plansim import`` read the log (``notes[IMPORT_NOTES]``); empty for a schedule it did not write."""
        return self.notes.get(IMPORT_NOTES, {})

    def __post_init__(self):
        if not self.segments:
            raise ValueError("schedule: it has no segment; a calibration needs at least one")

    def __len__(self) -> int:
        return len(self.segments)

    def select(self, test: str) -> list[int]:
        """Indices of the segments used by *test*."""
        return [k for k, s in enumerate(self.segments) if s.test == test]

    @property
    def duration(self) -> float:
        """Total time of the test, settling included, s."""
        return float(sum(s.settle + s.dwell for s in self.segments))

    @property
    def total_samples(self) -> int:
        return int(sum(s.samples for s in self.segments))
