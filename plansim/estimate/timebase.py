"""The time axis of a log: its sample rate, jitter, gaps, dropped samples and delivery stamps.

:func:`analyse_time` reads a log's time column (or a given sample rate) before the log is cut into segments
(:mod:`plansim.estimate.segmentation`): the nominal rate, the jitter of the steps about it, the gaps (more than
:data:`DROPPED_MAX` samples missing), the dropped samples a wireless link loses now and then, steps of zero, a
clock coarser than the sampling, and a column that stamps the samples' delivery rather than their sampling
(docs/measured-data.md, "The sample rate").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: a time step longer than this many sample periods is a gap (at least one sample missing)
GAP_FACTOR = 1.5
#: a break in the time column of at most this many missing samples is a dropped sample (a wireless link loses a row
#: now and then), not a gap: a pose's mean does not need it, and a turn is integrated over the time column, which
#: bridges it (:func:`analyse_time`)
DROPPED_MAX = 2
#: a time column where more than this fraction of the steps are not a whole number of its usual step (within
#: ``DELIVERY_SLACK`` of one) stamps the samples' delivery, not their sampling: a host that stamps what a serial or
#: wireless link hands it in bursts, or a clock that jitters by a large part of the period (:func:`analyse_time`)
DELIVERY_FRACTION = 0.05
DELIVERY_SLACK = 0.25
#: with delivery stamps, a break is a step longer than GAP_FACTOR times this quantile of the steps (the longest
#: usual delivery), not than GAP_FACTOR periods, which a late delivery passes without a sample missing
DELIVERY_QUANTILE = 0.999
#: a time column whose span holds more than this many times the samples its median step implies comes from a clock
#: coarser than the sampling (:func:`analyse_time`)
COARSE_CLOCK_FACTOR = 1.05


@dataclass(frozen=True)
class TimeReport:
    """What a log's time axis says about its sampling.

    Attributes
    ----------
    sample_rate : float
        The nominal sample rate used, Hz (given, or estimated).
    estimated_rate : float
        The number of time steps that are not breaks (gaps, dropped samples) over their summed duration — 1 / the
        mean period, so a clock quantised or jittering about the period gives the true mean rate — Hz; NaN
        without a time column.
    jitter_rms, jitter_max : float
        RMS and largest deviation of a time step from 1 / sample_rate, gaps excluded, s.
    gaps : tuple of (int, float)
        ``(k, dt)``: a gap of dt seconds before sample k (dt > GAP_FACTOR / sample_rate, more than
        :data:`DROPPED_MAX` samples missing).
    missing_samples : int
        Samples missing in the gaps: Σ round(dt × sample_rate) − 1.
    repeated : int
        Time steps of exactly zero.
    dropped : tuple of (int, int)
        ``(k, m)``: m ≤ :data:`DROPPED_MAX` samples dropped before sample k — not a gap.
    delivery : bool
        Whether the time column stamps the samples' delivery, not their sampling (:data:`DELIVERY_FRACTION`).
    sample_times : (N,) array or None
        With delivery stamps, the samples' times: a uniform clock at ``sample_rate`` between breaks, each stretch
        placed on its stamps' mean, s; ``None`` otherwise (the stamps are the sample times).
    """

    sample_rate: float
    estimated_rate: float
    jitter_rms: float
    jitter_max: float
    gaps: tuple[tuple[int, float], ...]
    missing_samples: int
    repeated: int
    dropped: tuple[tuple[int, int], ...] = ()
    delivery: bool = False
    sample_times: np.ndarray | None = None

    @property
    def dropped_samples(self) -> int:
        """Samples dropped in breaks that are not gaps."""
        return sum(m for _, m in self.dropped)

    @property
    def gap_starts(self) -> np.ndarray:
        """Index of the first sample after each gap."""
        return np.array([k for k, _ in self.gaps], dtype=np.int64)


def analyse_time(time: np.ndarray | None, samples: int, sample_rate: float | None = None) -> TimeReport:
    """The sample rate, jitter and gaps of a time axis (s, never decreasing), or of a given sample rate.

    Parameters
    ----------
    time : (N,) array or None
        Time of every sample, s; ``None``: a log without a time column (``sample_rate`` is then required).
    samples : int
        N, the number of samples.
    sample_rate : float or None
        The nominal rate, Hz; ``None``: the mean rate over the time steps that are not breaks (their number over
        their summed duration). Breaks are found against the median step, or against (N − 1)/span where the span
        holds more than :data:`COARSE_CLOCK_FACTOR` times the samples that step implies (a clock coarser than the
        sampling: its steps of 0 are reported as ``repeated``, and a gap is then a step of more than
        ``GAP_FACTOR`` clock steps): a step longer than ``GAP_FACTOR`` times that period.

    Notes
    -----
    A sampling clock, even a jittering or coarse one, advances by whole numbers of its usual step (the median
    step): 1 between samples, 2 or more over a dropped one, 0 where it is coarser than the sampling. A host that
    stamps the rows as a serial, USB or wireless link hands them over does not: rows come in bursts stamped
    microseconds apart, then a step of the burst's length. Where more than :data:`DELIVERY_FRACTION` of the steps
    are further than :data:`DELIVERY_SLACK` from a whole number of the usual step, the column is read as delivery
    times: a break (gap or dropped samples) is then a step longer than ``GAP_FACTOR`` times the
    :data:`DELIVERY_QUANTILE` quantile of the steps (a sample dropped among late deliveries cannot be told), the
    rate is 1 / the least-squares slope of the stamps against the sample number (common to the stretches between
    breaks), and the samples' times are a uniform clock at that rate between breaks (``sample_times``), each
    stretch placed on its stamps' mean.
    """
    if time is None:
        if sample_rate is None:
            raise ValueError("sample rate: a log without a time column needs the sample rate (Hz)")
        return TimeReport(float(sample_rate), math.nan, 0.0, 0.0, (), 0, 0)
    dt = np.diff(np.asarray(time, dtype=np.float64))
    if dt.size and dt.min() < 0:
        k = int(np.argmax(dt < 0)) + 1
        raise ValueError(f"time decreases at sample {k} ({time[k - 1]!r} s then {time[k]!r} s)")
    positive = dt[dt > 0]
    if positive.size == 0:
        raise ValueError("time: the time never advances; give the time column in seconds or the sample rate")
    tick = float(np.median(positive))  # the clock's usual advance
    estimated = 1.0 / tick
    # a clock coarser than the sampling (times rounded to 20 ms at 100 Hz, whole seconds) advances less often than
    # the samples come: more samples than ticks over the log's span, which gaps alone never give (they add time,
    # not samples). The rate is then the samples over the span, and a gap is a step of more than GAP_FACTOR ticks
    duration = float(time[-1] - time[0])
    span_rate = (samples - 1) / duration if duration > 0 else math.nan
    if span_rate > COARSE_CLOCK_FACTOR * estimated:
        estimated = span_rate
    nominal = estimated if sample_rate is None else float(sample_rate)
    period = 1.0 / nominal
    step = max(period, tick)
    ratio = positive / tick
    delivery = bool(np.mean(np.abs(ratio - np.round(ratio)) > DELIVERY_SLACK) > DELIVERY_FRACTION)
    if delivery:
        step = max(step, float(np.quantile(dt, DELIVERY_QUANTILE)))
    gap = dt > GAP_FACTOR * step
    # one sample stamped with its predecessor's time (a step of 0, then one of two periods) is a glitch of the
    # clock, not a gap: nothing is missing
    glitch = np.zeros_like(gap)
    glitch[1:] = (dt[:-1] == 0) & (dt[:-1] + dt[1:] <= (1.0 + GAP_FACTOR) * step)
    gap &= ~glitch
    # the rate: the mean period over the steps that are not breaks (gaps and dropped samples), not 1 / the median
    # step, which a clock quantised to about the period's jitter pins to a whole number of its ticks
    if np.any(~gap) and float(np.sum(dt[~gap])) > 0:
        estimated = float(np.count_nonzero(~gap)) / float(np.sum(dt[~gap]))
        nominal = estimated if sample_rate is None else float(sample_rate)
        period = 1.0 / nominal
    sample_times = None
    if delivery:
        # a uniform clock between breaks: its period the least-squares slope of the stamps against the sample
        # number, common to the stretches (a burst's stamp is late by up to the burst, at either end of the log:
        # the steps' mean would carry that over the log's length), each stretch placed on its stamps' mean
        t = np.asarray(time, dtype=np.float64)
        while True:
            edges = [0, *(int(k) + 1 for k in np.flatnonzero(gap)), samples]
            stretches = list(zip(edges[:-1], edges[1:]))
            centred = [(np.arange(b - a) - (b - a - 1) / 2.0, t[a:b] - np.mean(t[a:b])) for a, b in stretches]
            slope = sum(float(k @ y) for k, y in centred) / sum(float(k @ k) for k, _ in centred)
            if slope > 0:
                estimated = 1.0 / slope
                nominal = estimated if sample_rate is None else float(sample_rate)
                period = 1.0 / nominal
            sample_times = np.empty_like(t)
            for a, b in stretches:
                offset = np.arange(b - a) * period
                sample_times[a:b] = np.mean(t[a:b] - offset) + offset
            # a long step between stamps over which the placed clocks miss no sample is a delivery that stalled
            # (a host that starts reading late, then drains the sensor's buffer), not a break: the stretches on
            # either side are one, placed together (a short burst placed on its own stamps' mean can otherwise
            # overlap its neighbour: a sensor-fusion logger's MPU-6050 log did, 2026-12-01)
            stalled = gap & (np.diff(sample_times) < GAP_FACTOR * period)
            if not np.any(stalled):
                break
            gap &= ~stalled
        # a break's length between the placed stretches, not between two late or early stamps
        dt = np.where(gap, np.diff(sample_times), dt)
    breaks = [(int(k) + 1, float(dt[k]), max(round(dt[k] * nominal) - 1, 1)) for k in np.flatnonzero(gap)]
    gaps = tuple((k, d) for k, d, m in breaks if m > DROPPED_MAX)
    missing = int(sum(m for _, _, m in breaks if m > DROPPED_MAX))
    dropped = tuple((k, m) for k, _, m in breaks if m <= DROPPED_MAX)
    regular = dt[~gap] - period
    jitter_rms = float(np.sqrt(np.mean(regular**2))) if regular.size else 0.0
    jitter_max = float(np.max(np.abs(regular))) if regular.size else 0.0
    return TimeReport(nominal, estimated, jitter_rms, jitter_max, gaps, missing, int(np.count_nonzero(dt == 0)),
                      dropped, delivery, sample_times)
