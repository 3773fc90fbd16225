"""The recording as data: one calibration run's raw samples, its segment table and provenance.

A :class:`Recording` is the segment table (a :class:`~plansim.schedule.segments.Schedule`) plus every
raw sample of the six channels ``gx, gy, gz`` (rad/s) and ``ax, ay, az`` (m/s²), concatenated
segment by segment in schedule order, plus provenance attributes; its constructor checks all of it.
The files are :mod:`plansim.io.recording_netcdf` and :mod:`plansim.io.recording_csv`;
:mod:`plansim.io.recording` is the public face (``read_recording``, ``write_recording``).

Time convention: ``Recording.time`` is a *global* time axis in seconds from the start of the schedule
(the moment the table begins to settle into the first segment). Segment *s* starts recording after
every earlier segment's settle time and recording time plus its own settle time; its sample *k* is at
``start_s + k / sample_rate_s``. A segment records for ``samples / sample_rate`` seconds, which is
how the simulation kernel advances its drift processes (equal to ``dwell`` whenever
``dwell × sample_rate`` is a whole number). A measured recording may carry its own timestamps
instead (:attr:`Recording.timestamps`), and a temperature channel (:attr:`Recording.temperature`).

Format version 2 added what measured logs need (docs/recording.md): the segment fields ``orientation``
and ``angle``, NaN for a value not known (heading, rate, angle: see
:class:`~plansim.schedule.segments.Segment`), the site attributes ``site_latitude_deg`` and
``site_height_m``, and the per-sample temperature channel. Version 1 files read as before.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import metadata

import numpy as np

from plansim.kernels.layout import CHANNELS
from plansim.schedule.segments import Schedule

__all__ = ["CHANNELS", "CHANNEL_LONG_NAMES", "CHANNEL_UNITS", "FORMAT_NAME", "FORMAT_VERSION", "READABLE_VERSIONS",
           "RESERVED_ATTRIBUTES", "SITE_ATTRIBUTES", "SOURCES", "UNITS_DESCRIPTION", "Recording", "nominal_time",
           "plansim_version", "segment_first_samples"]

CHANNEL_UNITS = {"gx": "rad/s", "gy": "rad/s", "gz": "rad/s", "ax": "m/s^2", "ay": "m/s^2", "az": "m/s^2"}
CHANNEL_LONG_NAMES = {
    "gx": "angular rate output of the x gyro (body frame)",
    "gy": "angular rate output of the y gyro (body frame)",
    "gz": "angular rate output of the z gyro (body frame)",
    "ax": "specific force output of the x accelerometer (body frame)",
    "ay": "specific force output of the y accelerometer (body frame)",
    "az": "specific force output of the z accelerometer (body frame)",
}

SOURCES = ("simulated", "measured")
FORMAT_NAME = "plansim-recording"
FORMAT_VERSION = 2
#: the versions this plansim reads: 1 (before the measured-log fields) and 2
READABLE_VERSIONS = (1, 2)
#: the site, where known: attribute -> (unit, lowest, highest); both optional
SITE_ATTRIBUTES = {"site_latitude_deg": ("deg", -90.0, 90.0), "site_height_m": ("m", -11000.0, 9000.0)}
UNITS_DESCRIPTION = "SI: gx gy gz rad/s; ax ay az m/s^2; time s; heading, angle rad; rate rad/s; temperature degC"

#: attributes the file formats use themselves; a recording's own attrs may not use these names
RESERVED_ATTRIBUTES = ("format", "format_version", "schedule_procedure", "schedule_notes",
                       "integer_text_attributes")



def plansim_version() -> str:
    """The installed plansim version, or ``"unknown"`` when it runs from a source tree not installed."""
    try:
        return metadata.version("plansim")
    except metadata.PackageNotFoundError:
        return "unknown"


def segment_first_samples(schedule: Schedule) -> np.ndarray:
    """Index of the first sample of each segment in the concatenated samples, shape (S,)."""
    counts = np.array([segment.samples for segment in schedule.segments], dtype=np.int64)
    return np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.int64)


def nominal_time(schedule: Schedule) -> np.ndarray:
    """Global time of every sample from the start of the schedule, s, shape (M,).

    Segment *s* starts recording at ``sum_{r<s} (settle_r + samples_r / sample_rate_r) + settle_s``
    and its sample *k* is at that start plus ``k / sample_rate_s`` (see the module docstring).
    """
    parts = []
    clock = 0.0
    for segment in schedule.segments:
        clock += segment.settle
        parts.append(clock + np.arange(segment.samples) / segment.sample_rate)
        clock += segment.samples / segment.sample_rate
    return np.concatenate(parts)


def _normalise_attribute(key: object, value: object) -> str | int | float:
    """Provenance values must survive both file formats: text, whole numbers and real numbers only."""
    if not isinstance(key, str):
        raise TypeError(f"recording attrs: key {key!r} must be a string")
    if key in RESERVED_ATTRIBUTES:
        raise ValueError(f"recording attrs: {key!r} is reserved by the file format; "
                         f"reserved: {', '.join(RESERVED_ATTRIBUTES)}")
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"recording attrs[{key!r}] = {value!r}: booleans do not survive NetCDF-3; "
                        "store a string or a number")
    if isinstance(value, str):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    raise TypeError(f"recording attrs[{key!r}] = {value!r} ({type(value).__name__}): expected str, int or float")


@dataclass(frozen=True, eq=False)
class Recording:
    """Raw samples of one calibration run and the schedule that produced them.

    Parameters
    ----------
    samples : (M, 6) array of float
        Channels ``gx, gy, gz`` (rad/s) and ``ax, ay, az`` (m/s²), segment after segment in schedule
        order; segment *s* contributes ``schedule.segments[s].samples`` rows. Every value is finite.
    schedule : Schedule
        The segment table.
    attrs : dict
        Provenance, values ``str``, ``int`` or ``float``: usually ``plansim_version``, ``scenario``,
        ``seed``, ``trial``, ``source`` (``"simulated"`` or ``"measured"``) and ``units``.
        Where known, the site: ``site_latitude_deg`` (geodetic latitude, deg, −90 to 90) and
        ``site_height_m`` (height above the ellipsoid, m); both numbers, both optional.
    timestamps : (M,) array of float or None
        Measured time of every sample on a global axis, s, non-decreasing; ``None`` (the default)
        means the nominal time computed from the schedule (:func:`nominal_time`).
    temperature : (M,) array of float or None
        Measured temperature of every sample, °C, finite; ``None`` (the default) when the log has no
        temperature channel (each segment's ``temperature`` is then all there is).
    """

    samples: np.ndarray
    schedule: Schedule
    attrs: dict = field(default_factory=dict)
    timestamps: np.ndarray | None = None
    temperature: np.ndarray | None = None

    def __post_init__(self):
        if not isinstance(self.schedule, Schedule):
            raise TypeError(f"recording schedule: expected a plansim Schedule, got {type(self.schedule).__name__}")
        samples = np.asarray(self.samples)
        if samples.dtype.kind not in "iuf":
            raise TypeError(f"recording samples: expected real numbers, got dtype {samples.dtype}")
        samples = samples.astype(np.float64, copy=False)
        expected_rows = self.schedule.total_samples
        if samples.shape != (expected_rows, len(CHANNELS)):
            raise ValueError(f"recording samples: shape {samples.shape}; the schedule expects ({expected_rows}, 6): "
                             f"{expected_rows} samples (the sum of each segment's samples) × channels "
                             f"{', '.join(CHANNELS)}")
        bad = ~np.isfinite(samples)
        if bad.any():
            row, column = np.argwhere(bad)[0]
            raise ValueError(f"recording samples: channel {CHANNELS[column]} is {float(samples[row, column])!r} "
                             f"at sample {row}; every sample must be finite")
        if not isinstance(self.attrs, dict):
            raise TypeError(f"recording attrs: expected a dict, got {type(self.attrs).__name__}")
        attrs = {key: _normalise_attribute(key, value) for key, value in self.attrs.items()}
        source = attrs.get("source")
        if source is not None and source not in SOURCES:
            raise ValueError(f"recording attrs['source'] = {source!r}; allowed: {', '.join(SOURCES)}")
        for key, (unit, lowest, highest) in SITE_ATTRIBUTES.items():
            if key not in attrs:
                continue
            value = attrs[key]
            if isinstance(value, str) or not lowest <= value <= highest:  # NaN fails the comparison
                raise ValueError(f"recording attrs[{key!r}] = {value!r}; expected a number from {lowest:g} to "
                                 f"{highest:g} {unit}")
            attrs[key] = float(value)
        timestamps = self.timestamps
        if timestamps is not None:
            timestamps = np.asarray(timestamps)
            if timestamps.dtype.kind not in "iuf":
                raise TypeError(f"recording timestamps: expected real numbers, got dtype {timestamps.dtype}")
            timestamps = timestamps.astype(np.float64, copy=False)
            _check_time(timestamps, expected_rows, "recording timestamps")
        temperature = self.temperature
        if temperature is not None:
            temperature = np.asarray(temperature)
            if temperature.dtype.kind not in "iuf":
                raise TypeError(f"recording temperature: expected real numbers (degC), got dtype {temperature.dtype}")
            temperature = temperature.astype(np.float64, copy=False)
            if temperature.shape != (expected_rows,):
                raise ValueError(f"recording temperature: shape {temperature.shape}; expected ({expected_rows},), "
                                 "one temperature per sample")
            bad = np.flatnonzero(~np.isfinite(temperature))
            if bad.size:
                raise ValueError(f"recording temperature: {float(temperature[bad[0]])!r} at sample {int(bad[0])}; "
                                 "every temperature must be finite (degC)")
        object.__setattr__(self, "samples", samples)
        object.__setattr__(self, "attrs", attrs)
        object.__setattr__(self, "timestamps", timestamps)
        object.__setattr__(self, "temperature", temperature)

    @property
    def time(self) -> np.ndarray:
        """Time of every sample, s, shape (M,): the timestamps if measured ones are given, else
        :func:`nominal_time` — a global axis from the start of the schedule, settle times included."""
        if self.timestamps is not None:
            return self.timestamps
        return nominal_time(self.schedule)

    @property
    def segment_index(self) -> np.ndarray:
        """Segment number (0-based, schedule order) of every sample, shape (M,)."""
        counts = [segment.samples for segment in self.schedule.segments]
        return np.repeat(np.arange(len(counts), dtype=np.int64), counts)

    @property
    def first_sample(self) -> np.ndarray:
        """Index of each segment's first sample, shape (S,)."""
        return segment_first_samples(self.schedule)

    def segment_samples(self, segment: int) -> np.ndarray:
        """The (n, 6) rows of segment number *segment* (a view, not a copy)."""
        count = len(self.schedule)
        if isinstance(segment, bool) or not isinstance(segment, (int, np.integer)) or not 0 <= segment < count:
            raise ValueError(f"segment = {segment!r}: expected a whole number from 0 to {count - 1}")
        start = int(self.first_sample[segment])
        return self.samples[start:start + self.schedule.segments[segment].samples]

    def segment_means(self) -> np.ndarray:
        """Mean output of every segment, (S, 6): ū = (1/N) Σ_k u_k over its N samples (JJF 2003 eq. (3))."""
        means = np.empty((len(self.schedule), len(CHANNELS)))
        for k, (first, segment) in enumerate(zip(self.first_sample, self.schedule.segments)):
            # a running sum in sample order, then one division: the kernel's arithmetic, so a simulated
            # recording gives bit for bit the means of the Monte Carlo path (numpy's pairwise sum would not)
            running = np.cumsum(self.samples[first:first + segment.samples], axis=0)
            means[k] = running[-1] / segment.samples
        return means

    def __eq__(self, other: object) -> bool:
        """Exact equality: same samples bit for bit, same schedule, attrs, timestamps and temperature."""
        if not isinstance(other, Recording):
            return NotImplemented
        for name in ("timestamps", "temperature"):
            mine, theirs = getattr(self, name), getattr(other, name)
            if (mine is None) != (theirs is None) or (mine is not None and not np.array_equal(mine, theirs)):
                return False
        return (self.schedule == other.schedule and self.attrs == other.attrs
                and np.array_equal(self.samples, other.samples))

    __hash__ = None


def _check_time(time: np.ndarray, expected_rows: int, where: str) -> None:
    """A time axis must have one finite value per sample and never run backwards."""
    if time.shape != (expected_rows,):
        raise ValueError(f"{where}: shape {time.shape}; expected ({expected_rows},), one time per sample")
    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        raise ValueError(f"{where}: {float(time[bad[0]])!r} at sample {int(bad[0])}; every time must be finite (s)")
    backwards = np.flatnonzero(np.diff(time) < 0)
    if backwards.size:
        k = int(backwards[0]) + 1
        raise ValueError(f"{where}: time decreases at sample {k} ({float(time[k - 1])!r} s then "
                         f"{float(time[k])!r} s); expected a global time axis, never decreasing")

