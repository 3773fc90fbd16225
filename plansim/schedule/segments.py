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
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

AXIS_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")
TESTS = ("multi_position", "rate", "omega_squared")


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
    """One recorded dwell. Angles in rad, rates in rad/s, times in s, temperature in °C."""

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

    def __post_init__(self):
        where = f"segment {self.label!r}"
        if self.test not in TESTS:
            raise ValueError(f"{where}: test = {self.test!r}; allowed: {', '.join(TESTS)}")
        axis_vector(self.up, f"{where}: up")
        axis_vector(self.rate_axis, f"{where}: rate_axis")
        for name in ("heading", "rate", "dwell", "settle", "sample_rate", "temperature"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise TypeError(f"{where}: {name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise ValueError(f"{where}: {name} = {value!r}; it must be finite")
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
        return self.rate != 0.0

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Schedule:
    """An ordered tuple of segments plus the name of the procedure that built it."""

    segments: tuple[Segment, ...]
    procedure: str = "custom"
    notes: dict = field(default_factory=dict)

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
