"""The JJF 1537-2015 angular vibration procedure as schedule data: frequencies, amplitude, repeats, sampling.

JJF 1537-2015 7.2.1 (docs/dynamic.md, *The JJF 1537 procedure simulated*):

- 7.2.1.1: a rate amplitude A of 10–30 % of the gyro's range, N ≥ 7 frequencies spread over the working band;
- 7.2.1.2 b): a sample rate above 20 × the gyro's bandwidth;
- 7.2.1.2 c): n ≥ 7 records per frequency.

JJF 1535-2015 7.2.15.1 b) places its frequencies differently: 8 points evenly up to the expected bandwidth
f_e + 10 Hz, and one more halfway between f_e and each of its two neighbours on that grid
(:func:`jjf1535_frequencies`). Either grid is a :class:`Jjf1537Schedule`'s ``frequencies``.

JJF 1537-2015 7.2.4–7.2.7 (amplitude nonlinearity, output change under vibration, bias change before/after
vibration and shock; the copy used here has their titles only, Table 3) are :class:`VibrationShockSchedule`:
M amplitudes across the 10–30 % of 7.2.1.1 at one frequency, one vibration record and three records at
rest (before vibration, after it, after the shock). Frequencies in Hz, rates in rad/s, times in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.model.dynamics import one_number, positive_number

#: JJF 1537-2015 7.2.1: at least this many frequencies and repeats per frequency
MIN_FREQUENCIES = 7
MIN_REPEATS = 7
#: JJF 1537-2015 7.2.1.1: the amplitude as a fraction of the range
AMPLITUDE_FRACTION = (0.10, 0.30)
#: JJF 1537-2015 7.2.1.2 b): the sample rate exceeds this multiple of the bandwidth
RATE_PER_BANDWIDTH = 20.0
#: the fewest samples a half-sine shock pulse may have (plansim's: fewer do not draw its shape)
MIN_PULSE_SAMPLES = 8


def checked_repeats(repeats) -> int:
    """*repeats* as an int, or a ``ValueError`` unless it is an integer ≥ :data:`MIN_REPEATS` (7.2.1.2 c))."""
    if isinstance(repeats, bool) or not isinstance(repeats, (int, np.integer)) or repeats < MIN_REPEATS:
        raise ValueError(f"repeats: expected an integer >= {MIN_REPEATS} (JJF 1537-2015 7.2.1.2 c)), got {repeats!r}")
    return int(repeats)


def jjf1535_frequencies(expected_bandwidth: float, margin: float = 10.0) -> np.ndarray:
    """JJF 1535-2015 7.2.15.1 b): 8 points evenly up to f_e + *margin* (Hz), and the two inserted ones.

    The 8 points are k (f_e + margin)/8, k = 1 … 8; the inserted points are halfway between f_e and the
    grid points just below and just above it (if f_e is itself a grid point, its two neighbours). Sorted,
    10 points (fewer if an inserted point coincides with one on the grid).
    """
    f_e = positive_number("expected_bandwidth", expected_bandwidth, "Hz")
    top = f_e + positive_number("margin", margin, "Hz")
    grid = np.arange(1, 9) * (top / 8.0)
    below = grid[grid < f_e]
    above = grid[grid > f_e]
    inserted = []
    if below.size:
        inserted.append(0.5 * (below[-1] + f_e))
    if above.size:
        inserted.append(0.5 * (f_e + above[0]))
    return np.unique(np.concatenate((grid, inserted)))


def jjf1537_frequencies(band_low: float, band_high: float, count: int = MIN_FREQUENCIES) -> np.ndarray:
    """JJF 1537-2015 7.2.1.1: *count* frequencies evenly from *band_low* to *band_high* (Hz), ends included."""
    lo = positive_number("band_low", band_low, "Hz")
    hi = positive_number("band_high", band_high, "Hz")
    if not hi > lo:
        raise ValueError(f"band_high: expected > band_low = {lo!r} Hz, got {band_high!r}")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 2:
        raise ValueError(f"count: expected an integer >= 2, got {count!r}")
    return np.linspace(lo, hi, int(count))


@dataclass(frozen=True)
class Jjf1537Schedule:
    """One JJF 1537-2015 7.2.1 amplitude/phase-frequency test, as data.

    Attributes
    ----------
    frequencies : ndarray
        f_i, Hz, strictly increasing, ≥ :data:`MIN_FREQUENCIES` of them; the lowest is the reference
        (the zero-frequency sensitivity S_0 of eq. (9) is read there).
    amplitude : float
        A, the table's rate amplitude, rad/s.
    gyro_range : float
        The gyro's range, rad/s; A must be 10–30 % of it (7.2.1.1).
    repeats : int
        n ≥ :data:`MIN_REPEATS` records per frequency (7.2.1.2 c)).
    sample_rate : float
        f_s, Hz, above 20 × ``expected_bandwidth`` (7.2.1.2 b)) and above 2 × the highest frequency.
    record_time : float
        The target length of one record, s: each record is the whole number of cycles c_i =
        max(1, ⌊T f_i⌋) at f_i, N_i = round(c_i f_s/f_i) samples.
    expected_bandwidth : float
        The bandwidth the procedure is planned for, Hz.
    """

    frequencies: np.ndarray
    amplitude: float
    gyro_range: float
    repeats: int = MIN_REPEATS
    sample_rate: float = 4000.0
    record_time: float = 1.0
    expected_bandwidth: float = 100.0

    def __post_init__(self):
        try:
            f = np.array(self.frequencies, dtype=float).ravel()
        except (TypeError, ValueError) as exc:
            raise TypeError(f"frequencies: expected numbers (Hz), got {self.frequencies!r}") from exc
        if f.size < MIN_FREQUENCIES or not np.all(np.isfinite(f)) or f[0] <= 0 or not np.all(np.diff(f) > 0):
            raise ValueError(f"frequencies: expected at least {MIN_FREQUENCIES} finite values > 0 Hz, strictly "
                             f"increasing (JJF 1537-2015 7.2.1.1), got {f.tolist()}")
        f.flags.writeable = False
        object.__setattr__(self, "frequencies", f)
        for name, unit in (("amplitude", "rad/s"), ("gyro_range", "rad/s"), ("sample_rate", "Hz"),
                           ("record_time", "s"), ("expected_bandwidth", "Hz")):
            object.__setattr__(self, name, positive_number(name, getattr(self, name), unit))
        lo, hi = AMPLITUDE_FRACTION
        if not lo * self.gyro_range * (1 - 1e-12) <= self.amplitude <= hi * self.gyro_range * (1 + 1e-12):
            raise ValueError(f"amplitude: expected 10-30 % of the range {self.gyro_range!r} rad/s (JJF 1537-2015 "
                             f"7.2.1.1), i.e. {lo * self.gyro_range:.6g} to {hi * self.gyro_range:.6g} rad/s, "
                             f"got {self.amplitude!r}")
        object.__setattr__(self, "repeats", checked_repeats(self.repeats))
        if not self.sample_rate > RATE_PER_BANDWIDTH * self.expected_bandwidth:
            raise ValueError(f"sample_rate: expected > {RATE_PER_BANDWIDTH:g} x the expected bandwidth "
                             f"{self.expected_bandwidth:g} Hz = {RATE_PER_BANDWIDTH * self.expected_bandwidth:g} Hz "
                             f"(JJF 1537-2015 7.2.1.2 b)), got {self.sample_rate!r}")
        if not self.sample_rate > 2.0 * f[-1]:
            raise ValueError(f"sample_rate: expected > 2 x the highest frequency {f[-1]:g} Hz, got "
                             f"{self.sample_rate!r}")
        if self.samples().min() < 4:
            raise ValueError(f"record_time: {self.record_time!r} s gives fewer than 4 samples at "
                             f"{f[-1]:g} Hz; allowed: longer records")

    @property
    def interval(self) -> float:
        """Δt = 1/f_s, s."""
        return 1.0 / self.sample_rate

    def cycles(self) -> np.ndarray:
        """c_i = max(1, ⌊T f_i⌋): whole cycles per record at each frequency."""
        return np.maximum(1, np.floor(self.record_time * self.frequencies * (1 + 1e-12))).astype(int)

    def samples(self) -> np.ndarray:
        """N_i = round(c_i f_s / f_i): samples per record at each frequency (nearly whole cycles)."""
        return np.round(self.cycles() * self.sample_rate / self.frequencies).astype(int)


def amplitude_in_range(fraction: float, gyro_range: float) -> float:
    """A = *fraction* × *gyro_range* (rad/s), the fraction checked against JJF 1537-2015 7.2.1.1's 10–30 %."""
    x = one_number("amplitude_fraction", fraction)
    lo, hi = AMPLITUDE_FRACTION
    if not (math.isfinite(x) and lo <= x <= hi):
        raise ValueError(f"amplitude_fraction: expected {lo:g} to {hi:g} of the range (JJF 1537-2015 7.2.1.1), "
                         f"got {fraction!r}")
    return x * positive_number("gyro_range", gyro_range, "rad/s")


#: the default number of amplitudes of the amplitude-nonlinearity test (JJF 1537-2015 7.2.4)
LINEARITY_POINTS = 5


def linearity_amplitudes(gyro_range: float, count: int = LINEARITY_POINTS) -> np.ndarray:
    """*count* (≥ 3) amplitudes evenly across 10–30 % of *gyro_range* (rad/s), ends included: the amplitude
    range of JJF 1537-2015 7.2.1.1, read as the range of 7.2.4's amplitudes too."""
    R = positive_number("gyro_range", gyro_range, "rad/s")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 3:
        raise ValueError(f"linearity_points: expected an integer >= 3, got {count!r}")
    lo, hi = AMPLITUDE_FRACTION
    return np.linspace(lo * R, hi * R, int(count))


@dataclass(frozen=True)
class VibrationShockSchedule:
    """JJF 1537-2015 7.2.4–7.2.7 as data: one table frequency, the records at rest and under vibration.

    Per test: at ``frequency`` f, n = ``repeats`` records of whole cycles near ``record_time`` at each of the
    ``amplitudes`` A_k (7.2.4); then at rest for ``rest_time`` (before vibration), under vibration at the
    amplitude ``amplitude`` for ``vibration_time`` (7.2.5), at rest again (after vibration, 7.2.6), the shock
    record (a half-sine pulse of ``shock_duration`` from its first sample, then ``shock_settle`` at rest), and at
    rest (after the shock, 7.2.7), the filter's state carried through from the shock record.

    Attributes
    ----------
    frequency : float
        f, Hz, below f_s/2.
    amplitudes : ndarray
        A_k, rad/s, ≥ 3 distinct, each 10–30 % of ``gyro_range``.
    amplitude : float
        The vibration's rate amplitude, rad/s, 10–30 % of ``gyro_range``.
    gyro_range, sample_rate : float
        rad/s, Hz.
    repeats : int
        n ≥ :data:`MIN_REPEATS` records per amplitude.
    record_time, vibration_time, rest_time : float
        s; the first two rounded down to whole cycles (at least one), N = round(c f_s/f) samples: exactly whole
        cycles when c f_s/f is an integer (20 Hz at 4 kHz), as the closed forms of the tests assume.
    shock_duration, shock_settle : float
        s: the half-sine pulse (at least :data:`MIN_PULSE_SAMPLES` samples) and the time at rest after it before
        the record after the shock.
    """

    frequency: float
    amplitudes: np.ndarray
    amplitude: float
    gyro_range: float
    repeats: int = MIN_REPEATS
    sample_rate: float = 4000.0
    record_time: float = 1.0
    vibration_time: float = 5.0
    rest_time: float = 5.0
    shock_duration: float = 0.011
    shock_settle: float = 1.0

    def __post_init__(self):
        for name, unit in (("frequency", "Hz"), ("amplitude", "rad/s"), ("gyro_range", "rad/s"),
                           ("sample_rate", "Hz"), ("record_time", "s"), ("vibration_time", "s"),
                           ("rest_time", "s"), ("shock_duration", "s"), ("shock_settle", "s")):
            object.__setattr__(self, name, positive_number(name, getattr(self, name), unit))
        try:
            A = np.array(self.amplitudes, dtype=float).ravel()
        except (TypeError, ValueError) as exc:
            raise TypeError(f"amplitudes: expected numbers (rad/s), got {self.amplitudes!r}") from exc
        lo, hi = (x * self.gyro_range for x in AMPLITUDE_FRACTION)
        inside = np.all((A >= lo * (1 - 1e-12)) & (A <= hi * (1 + 1e-12)))
        if A.size < 3 or np.unique(A).size != A.size or not inside:
            raise ValueError(f"amplitudes: expected at least 3 distinct values within 10-30 % of the range, "
                             f"{lo:.6g} to {hi:.6g} rad/s (JJF 1537-2015 7.2.1.1, 7.2.4), got {A.tolist()}")
        A.flags.writeable = False
        object.__setattr__(self, "amplitudes", A)
        if not lo * (1 - 1e-12) <= self.amplitude <= hi * (1 + 1e-12):
            raise ValueError(f"amplitude: expected 10-30 % of the range, {lo:.6g} to {hi:.6g} rad/s, got "
                             f"{self.amplitude!r}")
        object.__setattr__(self, "repeats", checked_repeats(self.repeats))
        if not self.sample_rate > 2.0 * self.frequency:
            raise ValueError(f"vibration_frequency: expected < half the sample rate {self.sample_rate:g} Hz, got "
                             f"{self.frequency!r}")
        if min(self.samples(self.record_time), self.rest_samples()) < 4:
            raise ValueError(f"record_time, rest_time: {self.record_time!r} s and {self.rest_time!r} s give "
                             "fewer than 4 samples; allowed: longer records")
        if self.pulse_samples() < MIN_PULSE_SAMPLES:
            raise ValueError(f"shock_duration: {self.shock_duration!r} s gives {self.pulse_samples()} samples at "
                             f"{self.sample_rate:g} Hz; the half-sine needs >= {MIN_PULSE_SAMPLES} (a longer pulse or "
                             "a higher sample_rate)")

    def samples(self, duration: float) -> int:
        """N = round(c f_s/f) for c = max(1, ⌊duration · f⌋) whole cycles."""
        cycles = max(1, math.floor(duration * self.frequency * (1 + 1e-12)))
        return int(round(cycles * self.sample_rate / self.frequency))

    def rest_samples(self) -> int:
        """round(rest_time · f_s): the samples of one record at rest."""
        return int(round(self.rest_time * self.sample_rate))

    def pulse_samples(self) -> int:
        """The samples t_k = k/f_s inside the half-sine, 0 <= t_k < shock_duration."""
        return int(math.ceil(self.shock_duration * self.sample_rate * (1 - 1e-12)))

    def shock_samples(self) -> int:
        """The shock record: the pulse's samples and round(shock_settle · f_s) after it."""
        return self.pulse_samples() + int(round(self.shock_settle * self.sample_rate))
