"""Frozen channels: one value repeated for longer than the channel's noise allows (step 4c of segmentation); and
rows that repeat the row before in every channel more often than chance gives (:func:`repeated_rows`).

A sensor that stops updating, or a logger that repeats its last value while the sensor's data do not arrive,
writes one value over and over. Not at a rail (that is saturation, step 10), the stretch looks like the
quietest of rests: the pose it falls in takes the frozen value into its mean and its scatter shrinks, and a turn
across it integrates a constant rate. Nothing else in the import sees it.

**The rule.** A noisy channel repeats a value by chance, and how often is measured in the log itself. Over the
static spans, take the maximal runs of consecutive equal samples (length ≥ 2), their median length L₀ and
*n_L*, the number at least *L* long. The per-sample rate at which a run goes on is
r = max over L of ((n_L + 1)/(n_L₀ + 1))^(1/(L − L₀)), L from L₀ + 1 to the :data:`FROZEN_TAIL_QUANTILE`
quantile of the lengths, each tail holding at least :data:`FROZEN_TAIL_COUNT` runs (L₀ + 1 always counts). For
white noise on a quantiser L₀ = 2 and every L gives the same r, the chance that the next sample repeats. A log
written at *m* times its sensor's rate holds every value for *m* rows (runs of m, 2m, 3m …): the median gives
L₀ = m, and the largest rate the rate per row, p^(1/m), where the first tail alone would give p. Only up to the
quantile, so that a handful of frozen runs cannot raise the rate that should find them. With fewer than
:data:`FROZEN_MIN_RUNS` runs (a channel whose noise spans many codes, or that is not quantised at all), L₀ = 2 and
r = :data:`FROZEN_PRIOR_RATE`. A run of *k* equal samples, anywhere in the log, is **frozen** when
(n_L₀ + 1)·r^(k − L₀) ≤ :data:`FROZEN_FALSE_ALARM`: fewer than that many runs so long are expected in the whole
channel; unless its value is the channel's largest or smallest (a rail: saturation's, step 10). A channel whose
noise at rest spans less than :data:`FROZEN_DITHER` quantisation step (its pooled standard deviation within
the static spans) is not tested: such a channel sits on one code while at rest, and a long run is what it does.

What it costs: on the shared Ferraris session the gyros (0.77–0.94 steps of noise) are not tested; on the
accelerometers (2.7–4.0 steps, r = 0.09–0.16) a run must last 10–13 samples (0.1 s) to be frozen, and the longest
there is 6. An accelerometer frozen there for 2 s in a pose is found to the sample (tests/test_frozen.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: expected number of runs at least as long as a frozen one, in one channel of a log without any
FROZEN_FALSE_ALARM = 1e-6
#: the rate is taken over tails up to this quantile of the run lengths (a few frozen runs lie beyond it)
FROZEN_TAIL_QUANTILE = 0.99
#: the tail's slope is taken from this quantile of the run lengths to the top one
FROZEN_MIDDLE_QUANTILE = 0.9
#: a tail counts only with at least this many runs in it
FROZEN_TAIL_COUNT = 5
#: fewer runs of equal samples than this in the static spans: the rate is not measured, and this is taken
FROZEN_MIN_RUNS = 20
#: per-sample rate taken where it is not measured (a channel that hardly ever repeats a value)
FROZEN_PRIOR_RATE = 0.5
#: a channel whose noise at rest is below this many quantisation steps (standard deviation) is not tested
FROZEN_DITHER = 1.0


@dataclass(frozen=True)
class Frozen:
    """Channel ``channel`` (0–5) holds ``value`` (SI) over samples ``[start, stop)``."""

    channel: int
    start: int
    stop: int
    value: float


def equal_runs(values: np.ndarray) -> list[tuple[int, int]]:
    """``[start, stop)`` of every maximal run of at least two consecutive equal samples of *values*."""
    same = np.diff(values) == 0
    edges = np.diff(np.concatenate(([0], same.astype(np.int8), [0])))
    return [(a, b + 1) for a, b in zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist())]


def run_rate(lengths: np.ndarray) -> tuple[float, int, int]:
    """The per-sample rate at which a run of equal samples goes on, from the lengths (≥ 2) of the runs at rest
    (module docstring): (r, L₀, n_L₀)."""
    lengths = np.asarray(lengths)
    if lengths.size < FROZEN_MIN_RUNS:
        return FROZEN_PRIOR_RATE, 2, int(lengths.size)
    base = int(np.median(lengths))
    held = int(np.count_nonzero(lengths >= base))
    top = int(math.floor(float(np.quantile(lengths, FROZEN_TAIL_QUANTILE))))
    rates = [((beyond + 1) / (held + 1)) ** (1.0 / (tail - base))
             for tail in range(base + 1, max(top, base + 1) + 1)
             if (beyond := int(np.count_nonzero(lengths >= tail))) >= FROZEN_TAIL_COUNT or tail == base + 1]
    # the tail's own slope, between the runs past the middle quantile and those past the top one: where runs of
    # one code go on more often than the others' (a quantiser's middle code), the tail is theirs
    middle = int(math.ceil(float(np.quantile(lengths, FROZEN_MIDDLE_QUANTILE))))
    if top > middle and (beyond := int(np.count_nonzero(lengths >= top))) >= FROZEN_TAIL_COUNT:
        rates.append(((beyond + 1) / (int(np.count_nonzero(lengths >= middle)) + 1)) ** (1.0 / (top - middle)))
    return float(min(max(rates), 1.0)), base, held


def frozen_runs(x: np.ndarray, rests: list[tuple[int, int]], step: np.ndarray) -> list[Frozen]:
    """The frozen stretches of *x* (module docstring).

    Parameters
    ----------
    x : (n, C) array
        The samples as logged, SI.
    rests : list of (start, stop)
        The static spans, where the chance runs are counted.
    step : (C,) array
        Each channel's quantisation step (0: none found).

    Returns
    -------
    list of :class:`Frozen`, in order of start.
    """
    found = []
    for c in range(x.shape[1]):
        rails = (float(x[:, c].min()), float(x[:, c].max()))  # a run at a channel's extreme is saturation's
        pieces = [x[a:b, c] for a, b in rests if b - a >= 2]
        if not pieces:
            continue
        spread = math.sqrt(float(np.mean([np.var(p) for p in pieces])))
        if step[c] > 0 and spread < FROZEN_DITHER * step[c]:
            continue
        lengths = np.array([b - a for p in pieces for a, b in equal_runs(p)])
        rate, base, held = run_rate(lengths)
        if rate >= 1.0:
            continue
        # (n_L₀ + 1)·r^(k − L₀) ≤ FROZEN_FALSE_ALARM
        shortest = base + math.log(FROZEN_FALSE_ALARM / (held + 1)) / math.log(rate)
        for a, b in equal_runs(x[:, c]):
            if b - a >= shortest and float(x[a, c]) not in rails:
                found.append(Frozen(c, a, b, float(x[a, c])))
    return sorted(found, key=lambda f: (f.start, f.channel))


def frozen_mask(n: int, frozen: list[Frozen], channels=range(6)) -> np.ndarray:
    """(n,) True on every sample that lies in a frozen stretch of one of *channels*."""
    mask = np.zeros(n, dtype=bool)
    for f in frozen:
        if f.channel in channels:
            mask[f.start:f.stop] = True
    return mask


#: a log's rows that repeat the row before in every channel are reported where so many or more would come by chance
#: with at most this probability (Poisson, at the rate the static poses' channels repeat a value independently)
REPEATED_ROWS_PROBABILITY = 1e-6


@dataclass(frozen=True)
class RepeatedRows:
    """Rows (indices) that repeat the row before in every channel, and how many chance would give."""

    rows: tuple[int, ...]
    expected: float


def repeated_rows(x: np.ndarray, rests: list[tuple[int, int]]) -> RepeatedRows | None:
    """The rows of *x* equal to the row before in every channel, where more of them are found than chance allows.

    A logger that writes a row when its sensors have no new sample repeats the last one (a wireless link, a host
    polling faster than the sensor, a log written at twice its sensor's rate). One such row is not a frozen stretch
    (:func:`frozen_runs`: a channel held for longer than its noise allows), but many are: the noise's samples are
    then not the rows, and a time column stamps copies. Chance: in the static spans, channel c repeats its previous
    value with probability p_c (with one added to the count and to the pairs); the channels' noise is independent,
    so a whole row repeats with probability Π p_c, and over the log's n − 1 pairs the count is Poisson with mean
    (n − 1)·Π p_c. Reported where the count found is at least 3 and has a Poisson upper tail of at most
    :data:`REPEATED_ROWS_PROBABILITY`; else None.
    """
    from scipy.stats import poisson

    n = x.shape[0]
    if n < 2:
        return None
    same = np.all(np.diff(x, axis=0) == 0, axis=1)
    found = int(np.count_nonzero(same))
    if found < 3:
        return None
    chance = 1.0
    for c in range(x.shape[1]):
        equal = sum(int(np.count_nonzero(np.diff(x[a:b, c]) == 0)) for a, b in rests)
        pairs = sum(max(b - a - 1, 0) for a, b in rests)
        chance *= (equal + 1) / (pairs + 2)
    expected = (n - 1) * chance
    if poisson.sf(found - 1, expected) > REPEATED_ROWS_PROBABILITY:
        return None
    return RepeatedRows(tuple((np.flatnonzero(same) + 1).tolist()), expected)
