"""Static poses and the motion between them, found in a raw IMU log from the data alone.

A plain log is a stream of six channels (gyros in rad/s, accelerometers in m/s²) with no segment
table. :func:`segment_log` finds where the unit was at rest and what happened in between, with
thresholds set by the log's own noise, so the same settings serve a consumer MEMS unit and a tactical
one (docs/measured-data.md describes the method and how its false alarms were calibrated).

The method, step by step (*w* samples in a window, at least ``MIN_WINDOW_SAMPLES``; *h* = w // 2):

1. **Moving statistics.** The mean and variance of every channel over a window of *w* samples centred
   on each sample (truncated at the ends of the log).
2. **Resolution.** Each channel's step: the smallest non-zero difference between two consecutive
   samples. A quantised channel cannot show noise below step/√12, so that is its noise floor.
3. **Quietest stretch.** ``Q``, the stretch of ``max(min_static, QUIET_WINDOWS windows)`` without a time
   gap where the sum over the channels of (moving variance / that channel's median moving variance over
   the log) is smallest. It is taken to be at rest.
4. **Noise.** In ``Q``, per channel: σ = √(median of the moving variance / median of χ²(w−1)/w), the
   robust standard deviation of one sample, at least the quantisation floor (the MAD of the samples
   would be 0 for a channel quantised to about its noise). Then every sample is clipped to ``CLIP`` σ
   about the nearer of the means of the *w* samples before it and the *w* after it (an isolated spike
   cannot look like motion; a step stays sharp, a ramp still shows), the moving statistics are taken
   again on the clipped samples and σ once more from them. Also in ``Q``: the gyro bias b (mean of the
   clipped samples) and the noise of a *w*-sample gyro mean, s = 1.4826 · MAD(m(t + w) − m(t)) / √2 (a
   robust overlapping Allan deviation at τ = *w* samples; at least σ/√w, which it equals for white
   noise, and larger for correlated noise).
4b. **Isolated glitch rows** (:func:`isolated_glitches`): a row of six exact zeros between rows that are not, or
   a sample far off both neighbours (``GLITCH_SIGMA`` σ, ``GLITCH_TAIL`` × the largest such deviation in ``Q``,
   ``GLITCH_RATIO`` × the neighbours' own variation, those neighbours quiet). The detector and a turn's integral
   take such a row as the mean of its neighbours; no static span holds one (a pose is cut at it, a piece shorter
   than a window trimmed off), and ``Segmentation.glitches`` lists them.
4c. **Frozen stretches** (:func:`plansim.estimate.frozen.frozen_runs`, once the static spans are known): a channel
   that repeats one value for longer than its own noise at rest allows (a sensor that stopped updating, a logger
   repeating its last value). No static span holds one (cut as a glitch row is), and a motion across a frozen
   gyro is a move (its integral is not known); ``Segmentation.frozen`` lists them.
5. **Quiet samples.** A sample is quiet when, over its window, Σ_accel var/σ² and Σ_gyro var/σ² are each
   at most the larger of ``VARIANCE_FACTOR`` × 3 (3 is the expected sum at rest) and the median of that
   sum in ``Q`` plus ``SPREAD_FACTOR`` robust standard deviations of it (wider for correlated or
   heavy-tailed noise), and no time gap lies within *h* samples. Runs of at least ``min_static`` seconds
   of quiet samples are kept if they hold one pose: the mean specific force of their first and last
   windows differ by at most ``RATE_FACTOR`` √2 times the noise of a window mean plus ``POSE_TOLERANCE``
   (0.5°) of gravity on each axis (a unit tumbling smoothly can be as quiet as its own quietest stretch,
   but its gravity turns).
5b. **One table rate.** With the table's rate logged (``table_rate``, or the change of its logged angle), each
   run is cut where the table's rate (its mean over a window) leaves max(rest threshold, ``TABLE_STEADY_FRACTION``
   of it) of its value at the piece's start, and pieces of at least ``min_static`` are kept: a table's slow change
   of rate is as quiet as its steady turns.
6. **At rest or turning steadily?** The run that holds ``Q`` is at rest. Working outwards from it, each
   other run is compared with the nearest run at rest. In the same pose (specific force within
   ``SAME_POSE``) it is at rest unless its mean gyro output differs from that run's by more than
   ``RATE_FACTOR`` × s + 2 Ω_E on some axis (Ω_E the Earth rate: a unit at rest sees up to ±Ω_E on any
   axis, depending on its pose; comparing neighbours, a slow drift of the bias over a long log is not a
   turn); otherwise it is a *steady turn* (a rate table holding a rate), and belongs to the motion around
   it. In another pose, the gyros' g-sensitivity alone moves their output from pose to pose (up to 0.1 °/s/g
   for a consumer unit; :data:`plansim.estimate.rests.G_SENSITIVITY_ALLOWANCE` allows twice that): the run is
   then a steady turn only when its output differs from the nearest rest's *along its own gravity* (a table with
   gravity steady turns about the vertical) by more than the threshold there plus that allowance times the
   change of specific force. A turn slower than the threshold cannot be told from rest by any detector
   without a reference; the threshold is reported. Only the nearest rest is asked: a rest in the same pose
   long before differs by the bias's drift since. The run taken to be at rest first is ``Q``'s, unless the
   runs' agreement says otherwise (:func:`first_rest`: a table's steady turn is as quiet as a rest, and
   ``Q`` can fall in one; rests agree across poses, a turn about the vertical does not); the gyro bias b is
   then that run's.
6a. **A gyro more g-sensitive than the allowance.** Runs read as turns in a pose no rest shares are rests
   when the runs' own fit of each gyro's rest output (bias, drift, g-sensitivity) predicts them, left out, to
   within the threshold along their gravity (:func:`rests_by_g_sensitivity`).
6b. **Poses held by hand.** Outside those runs, stretches of at least ``min_static`` where the
   accelerometers pass step 5 and hold one pose while the gyros do not (a hand's tremor: 1 °/s at 5 Hz tilts
   the unit by 0.03°) are poses too, when the attitude the gyros integrate about their mean swings by at
   most ±``POSE_TOLERANCE`` and their mean passes step 6. They are joined to a rest in the same pose at
   most a window away, and marked with how hard the gyros shook (``Span.held``).
7. **Poses.** Each static span's up axis is the body axis nearest its mean specific force; the tilt is
   the angle between the two. The heading cannot be told without a heading reference: it is not
   reported.
8. **Motion.** Between two static spans, the gyro output less the bias (interpolated linearly in time
   between the two spans' mean gyro outputs) is integrated over time. The motion is a *rotation* when
   (a) the integral lies along one body axis (the other two components together at most
   ``OFF_AXIS_FRACTION`` of it), (b) it is within ``10° + 5 %`` of a whole number of quarter turns (the
   nominal angle, not zero), and that tolerance is below half a quarter turn (beyond about 700° the nearest
   quarter turn cannot be told), (c) the unit ends with the same axis up as it
   started, and (d) the turn is about the vertical (the axis within 20° of the mean specific force) or is a
   whole number of full turns. Anything else is a *move*: the unit was carried from one pose to another and no reference
   says by how much. A motion that holds a time gap or a saturated sample is a move too: its integral
   is not known. **With the table's angle or rate logged** (``table_angle``, ``table_rate``), a motion over which
   the table turned by more than ``TABLE_STILL`` has the table's own angle as its reference, whatever it is
   (45°, 10°, 567°), in place of the nearest quarter turn: it is a rotation by that angle, signed as the gyros
   measured it, where (a) holds, the gyros' integral is within ``TABLE_AGREEMENT`` of the table's angle, the
   unit ends with the same axis up, and the turn is about the vertical or a whole number of full turns (within
   10°); a move otherwise, its reason saying which failed.
9. **Steady turns.** Step 8 is for turns by hand against a stop. A motion that holds steady turns (step 6) is a
   table's, which need not stop on a quarter turn (a −567° turn would be labelled −540°): each steady turn is a
   *rotation* of its own with its measured rate (``Span.steady_rate``) and no angle (the table's rate, not in
   the log, is its reference), and the stretches around them (spin-up, change of rate, stop) are *moves*
   (:func:`_motion_pieces`). So is a steady turn the log starts or ends in, against the one pose beside it. A
   time gap between steady turns (a log recorded over each dwell only) does not stop them being split out; the
   piece around them that holds the gap is a move, not integrated.
10. **Saturation.** ``SATURATION_RUN`` or more equal consecutive samples at a channel's largest or smallest
    value in the log (two are enough where the value is held by two such runs or more: a rail reached twice),
    outside the static spans, entered or left by a step of more than ``SATURATION_STEP`` σ, at a value
    more than ``SATURATION_STEP`` σ + one step away from every level the channel holds while quiet (at
    rest or turning steadily): a stretch stuck at a rail. Two equal samples once are not enough: a fast
    move's smooth peak falls between two samples, which then read alike whatever its curvature (a 16-bit
    log's 75.7 °/s peak, far inside its ±2000 °/s, was taken for a rail). A rate held beyond the range for a
    whole steady turn reads as a steady turn at the rail value; no detector can tell it from the data alone.
    Where the channel's **full scale is declared** (``full_scale``), the rule is that instead: every sample at or
    beyond ``1 − FULL_SCALE_MARGIN`` of the full scale in magnitude is at the rail, one sample or many, in a pose
    or in a turn — a steady turn held at the rail included.
11. **Poses noisier than the quiet stretch** (:func:`noisy_poses`, reported, not taken). Within the motion, a
    stretch of at least ``max(min_static, 2 w)`` where the means of every two adjacent windows agree within
    ``STATIONARY_FACTOR`` (or the quiet stretch's median plus ``SPREAD_FACTOR`` robust standard deviations of that
    statistic, if larger) times their own noise, √((s²₁ + s²₂)/w), which holds one pose by the test of step 5 with
    its own noise in place of the quiet stretch's, and whose mean gyro output is a rest's by the test of step 6 (its
    threshold widened to its own window noise where that is larger) looks like a pose held on a vibrating bench or
    with noise that depends on the pose. Its largest summed variance ratio over 3 is the ``variance_factor`` that
    would keep it whole. It is reported (``Segmentation.noisy_poses``) and left as motion: the user decides, since a
    hand holding the unit still is as steady.

Every threshold is a multiple of the log's own noise; the multiples are module constants, chosen by
simulation (tests/test_segmentation.py measures their false alarms on static noise of several kinds).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
import scipy.stats

from plansim.estimate.frozen import Frozen, frozen_mask, frozen_runs
from plansim.estimate.rests import SAME_POSE, at_rest_against, first_rest, rests_by_g_sensitivity
from plansim.model.environment import EARTH_RATE

#: default window of the moving statistics, s
DEFAULT_WINDOW = 0.5
#: default shortest static span, s
DEFAULT_MIN_STATIC = 1.0
#: a window is quiet when its summed variance ratio (3 channels) is at most this many times its expected 3
VARIANCE_FACTOR = 4.0
#: ... or the quietest stretch's median variance ratio plus this many robust standard deviations of it, if larger
SPREAD_FACTOR = 8.0
#: samples are clipped to this many σ about the moving mean before the variances are taken (spikes)
CLIP = 4.0
#: a quiet run is a steady turn when its gyro output differs from the bias by more than this many
#: window-mean noise standard deviations (plus twice the Earth rate)
RATE_FACTOR = 6.0
#: a window holds at least this many samples (fewer make the variance test too noisy)
MIN_WINDOW_SAMPLES = 10
#: a quiet run is one pose when its gravity direction turns by less than this from its first to its last window
POSE_TOLERANCE = math.radians(0.5)
#: the quietest stretch holds at least this many windows
QUIET_WINDOWS = 8
#: a rotation's integral lies along one body axis: the other two components at most this fraction of it
OFF_AXIS_FRACTION = 0.1
#: a rotation's integral is within this of its nominal angle: ANGLE_TOLERANCE_RAD + ANGLE_TOLERANCE_FRACTION × nominal
ANGLE_TOLERANCE_RAD = math.radians(10.0)
ANGLE_TOLERANCE_FRACTION = 0.05
#: a table's logged rate or angle and the gyros' agree when they differ by at most this fraction of the table's
TABLE_AGREEMENT = 0.1
#: a quiet run holds one table rate while the logged rate stays within this fraction of it (or the rest threshold),
#: step 5b: 20 times the rate smoothness a JJF 2003 table is held to (5e-4, Table 1)
TABLE_STEADY_FRACTION = 0.01
#: a motion over which the table's logged angle changed by at most this is not the table's turn (step 8)
TABLE_STILL = math.radians(1.0)
#: a rotation about the vertical: the axis within this angle of the mean specific force
VERTICAL_AXIS_TOLERANCE = math.radians(20.0)
#: a static pose is "approximate" (near a nominal pose) when its tilt from the nearest axis is at most this
APPROXIMATE_TILT = math.radians(15.0)
#: a saturated stretch is entered or left by a step of more than this many σ
SATURATION_STEP = 5.0
#: equal samples in a row at a channel's extreme that make a rail on their own (step 10)
SATURATION_RUN = 3
#: a sample within this fraction of a channel's declared full scale, or beyond it, is at the rail (step 10). A
#: converter's rail is not its part's nominal range: a "±2000 °/s" 16-bit gyro at its nominal 16.4 LSB/(°/s) tops
#: out at 32767 / 16.4 = 1998.0 °/s, 0.1 % below it
FULL_SCALE_MARGIN = 5e-3
#: an isolated glitch row (step 4b): a channel's sample is further than this many σ from the mean of its two
#: neighbours...
GLITCH_SIGMA = 20.0
#: ... and further than this many times the largest such deviation in the quiet stretch (heavy-tailed noise shows
#: its tails there too) ...
GLITCH_TAIL = 30.0
#: ... and further than this many times its neighbours' own variation (|x[k+1] − x[k−1]|, |x[k−1] − x[k−2]|,
#: |x[k+2] − x[k+1]|): a step or a motion onset moves the neighbours too ...
GLITCH_RATIO = 5.0
#: ... while that variation is at most this many times the largest in the quiet stretch (and at least 10 σ): the
#: neighbours are quiet (a knock in a hand-made move, one sample wide, is motion, not a glitch)
GLITCH_QUIET = 2.0
#: step 11: two adjacent windows' means agree when they differ by at most this many times their own noise
STATIONARY_FACTOR = 6.0
#: ... and their variances agree, channel by channel, to within the F distribution's upper STATIONARY_P point
STATIONARY_P = 1e-6
#: robust standard deviation from the median absolute deviation of a normal distribution
MAD_TO_SIGMA = 1.482602218505602

AXES = ("x", "y", "z")


#: a log with no static span but at least this many quiet stretches shorter than ``min_static`` (and at least half
#: a window long) is told, in the error, to try a shorter ``--min-static`` and ``--window``
SHORT_QUIET_HINT = 3


@dataclass(frozen=True)
class NoiseFloor:
    """The log's own noise, measured in its quietest stretch ``[start, stop)``.

    ``sigma`` (6,): per-sample standard deviation (√ median moving variance, at least the quantisation floor), SI;
    ``resolution`` (6,): each channel's smallest step, SI (0 if none); ``gyro_bias`` (3,): mean gyro
    output (clipped samples), rad/s; ``window_sigma`` (3,): noise of a window's gyro mean, rad/s.
    """

    start: int
    stop: int
    sigma: np.ndarray
    resolution: np.ndarray
    gyro_bias: np.ndarray
    window_sigma: np.ndarray


@dataclass(frozen=True)
class Span:
    """One stretch ``[start, stop)`` of the log: ``kind`` is ``"static"``, ``"rotation"`` or ``"move"``.

    Attributes
    ----------
    mean : (6,) array
        Mean output over the span, SI.
    up : str
        Static, and a steady turn (step 9): the body axis nearest the mean specific force. Other motion: the up
        axis of the static span before it (``""`` when there is none).
    tilt : float
        Static: angle between the mean specific force and ``up``, rad (NaN for motion).
    integrated : (3,) array
        Motion: ∫ (gyro − bias) dt over the span, rad (NaN when not known: a gap, a saturated sample, or no
        static span on either side).
    axis : int
        Motion: the body axis (0, 1, 2) of the largest integrated component (−1 when not known).
    angle : float
        Rotation between two rests: the reference angle about ``+axis``, rad: the table's logged angle over the
        span where it was logged (``table_turned``, signed as the gyros measured the turn), else the nominal
        angle, a whole number of quarter turns; NaN otherwise (a steady turn included).
    orientation : str
        ``"approximate"`` (static: tilt ≤ APPROXIMATE_TILT; rotation: about the vertical) or ``"unknown"``.
    steady_rate : float
        Rotation: the measured steady rate about ``+axis``, rad/s, of a steady turn (step 9); NaN for a turn by
        hand.
    reason : str
        Why a motion is a move (empty for the others).
    """

    kind: str
    start: int
    stop: int
    mean: np.ndarray
    up: str = ""
    tilt: float = math.nan
    integrated: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    axis: int = -1
    angle: float = math.nan
    orientation: str = "unknown"
    steady_rate: float = math.nan
    reason: str = ""
    #: motion, with the table's angle or rate logged: the angle the table turned over the span by its own column
    #: (its own sense), rad; NaN otherwise
    table_turned: float = math.nan
    #: static and held by hand (step 6b): the gyros' largest scatter over their quiet stretch's; NaN otherwise
    held: float = math.nan

    @property
    def samples(self) -> int:
        return self.stop - self.start


@dataclass(frozen=True)
class Saturation:
    """Channel ``channel`` (0–5) stuck at ``value`` (SI) over samples ``[start, stop)``."""

    channel: int
    start: int
    stop: int
    value: float


@dataclass(frozen=True)
class NoisyPose:
    """Step 11: samples ``[start, stop)`` within the motion that hold one pose (``up``) with the gyros at rest, but
    noisier than the quiet stretch: ``factor`` is the ``variance_factor`` that would keep the stretch whole (its
    largest summed variance ratio of a group over 3)."""

    start: int
    stop: int
    up: str
    factor: float


@dataclass(frozen=True)
class Segmentation:
    """The result of :func:`segment_log`.

    ``spans`` cover every sample of the log in order; ``noise`` is the noise floor; ``window`` and
    ``min_static`` are in samples; ``variance_threshold`` the bounds on the summed variance ratios
    (accelerometers, gyros) and
    ``rate_threshold`` (3,) the gyro offset, rad/s, beyond which a quiet run is a steady turn;
    ``saturation`` lists the stuck stretches; ``steady_turns`` the quiet runs that were steady turns;
    ``glitches`` the isolated glitch rows (step 4b), in no static span; ``frozen`` the stretches where a channel
    repeats one value for longer than its noise allows (step 4c, :mod:`plansim.estimate.frozen`), in no static span.
    """

    spans: tuple[Span, ...]
    noise: NoiseFloor
    window: int
    min_static: int
    variance_threshold: tuple[float, float]
    rate_threshold: np.ndarray
    saturation: tuple[Saturation, ...]
    steady_turns: tuple[tuple[int, int], ...]
    glitches: tuple[int, ...] = ()
    frozen: tuple[Frozen, ...] = ()
    #: quiet runs at least half a window long but shorter than ``min_static``, within motion: rests too short for
    #: the detector (a hand that paused for a second), which a shorter ``--min-static`` and ``--window`` would take
    short_quiet: tuple[tuple[int, int], ...] = ()
    #: stretches within motion that look like poses noisier than the quiet stretch (step 11), left as motion
    noisy_poses: tuple[NoisyPose, ...] = ()

    def of_kind(self, kind: str) -> list[Span]:
        return [span for span in self.spans if span.kind == kind]


def moving_mean_variance(x: np.ndarray, window: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and (population) variance of each column of *x* over *window* samples centred on each row.

    At the ends of the log the window is truncated to the samples that exist. Returns two (N, C) arrays.
    """
    n = x.shape[0]
    half = window // 2
    lo = np.clip(np.arange(n) - half, 0, n)
    hi = np.clip(np.arange(n) - half + window, 0, n)
    count = (hi - lo).astype(np.float64)
    mean = np.empty(x.shape)
    variance = np.empty(x.shape)
    for c in range(x.shape[1]):  # one column at a time: a few (N,) temporaries, not (N, C) ones
        centre = float(np.median(x[:, c]))
        y = x[:, c] - centre  # small numbers: the running sums keep their precision
        s1 = np.concatenate(([0.0], np.cumsum(y)))
        m = (s1[hi] - s1[lo]) / count
        s1 = np.concatenate(([0.0], np.cumsum(y * y)))
        variance[:, c] = np.maximum((s1[hi] - s1[lo]) / count - m * m, 0.0)
        mean[:, c] = m + centre
    return mean, variance


def resolution(x: np.ndarray) -> np.ndarray:
    """Each column's smallest non-zero step between consecutive samples (0 when there is none)."""
    steps = np.abs(np.diff(x, axis=0))
    scale = np.max(np.abs(x), axis=0) + 1.0
    out = np.zeros(x.shape[1])
    for c in range(x.shape[1]):
        nonzero = steps[:, c][steps[:, c] > 1e-12 * scale[c]]
        out[c] = nonzero.min() if nonzero.size else 0.0
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[start, stop)`` of every run of True in *mask*."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def nearest_axis(vector: np.ndarray) -> tuple[str, float]:
    """The signed body axis nearest *vector* (``"+x"`` …) and the angle between them, rad."""
    j = int(np.argmax(np.abs(vector)))
    norm = float(np.linalg.norm(vector))
    tilt = math.acos(min(1.0, abs(float(vector[j])) / norm)) if norm > 0 else math.nan
    return ("+" if vector[j] >= 0 else "-") + AXES[j], tilt


def _rotate(vector: np.ndarray, axis: int, angle: float) -> np.ndarray:
    """*vector* (body frame) seen after the body turns by *angle* about body axis *axis*."""
    c, s = math.cos(angle), math.sin(angle)
    i, k = (axis + 1) % 3, (axis + 2) % 3
    out = vector.copy()
    # the body turns by +angle, so a fixed vector turns by -angle in body coordinates
    out[i] = c * vector[i] + s * vector[k]
    out[k] = -s * vector[i] + c * vector[k]
    return out


def _quiet_stretch(ratio: np.ndarray, length: int, blocked: np.ndarray) -> int:
    """Start of the *length*-sample stretch with the smallest summed *ratio*, avoiding *blocked* samples."""
    n = ratio.shape[0]
    score = np.where(blocked, np.inf, ratio)
    finite = np.where(np.isfinite(score), score, 0.0)
    sums = np.concatenate(([0.0], np.cumsum(finite)))
    bad = np.concatenate(([0], np.cumsum(~np.isfinite(score))))
    starts = np.arange(n - length + 1)
    total = sums[starts + length] - sums[starts]
    total[(bad[starts + length] - bad[starts]) > 0] = np.inf
    best = int(np.argmin(total))
    if not np.isfinite(total[best]):
        raise ValueError(f"too few static samples: no stretch of {length} samples without a time gap to measure "
                         "the noise in")
    return best


def segment_log(samples: np.ndarray, time: np.ndarray | None, sample_rate: float, *,
                window: float = DEFAULT_WINDOW, min_static: float = DEFAULT_MIN_STATIC,
                gap_starts: np.ndarray | None = None, full_scale: np.ndarray | None = None,
                table_rate: np.ndarray | None = None, table_angle: np.ndarray | None = None,
                variance_factor: float = VARIANCE_FACTOR) -> Segmentation:
    """Find the static spans of a log and classify the motion between them (see the module docstring).

    Parameters
    ----------
    samples : (N, 6) array
        ``gx gy gz`` in rad/s, ``ax ay az`` in m/s², finite.
    time : (N,) array or None
        Time of every sample, s (never decreasing); ``None``: sample k at k / sample_rate.
    sample_rate : float
        Nominal sample rate, Hz.
    window : float
        Window of the moving statistics, s (at least MIN_WINDOW_SAMPLES samples are used).
    min_static : float
        Shortest static span, s.
    variance_factor : float
        A window is quiet where each group's summed variance ratio is at most ``variance_factor`` × 3
        (:data:`VARIANCE_FACTOR` by default; ``plansim import --rest-variance``): raise it for a log whose poses
        are noisier than its quietest stretch.
    gap_starts : (G,) int array or None
        Samples that follow a gap in the time axis (:func:`plansim.estimate.timebase.analyse_time`); windows do not
        reach across them.
    full_scale : (6,) array or None
        Each channel's full scale (the largest magnitude it can read), rad/s or m/s²; NaN where not known,
        ``None``: none known. A declared full scale replaces the detector of step 10 for its channel.
    table_rate : (N,) array or None
        The turntable's rate at every sample (its controller's or encoder's, logged beside the IMU), rad/s; its
        sense does not matter. Given, it decides step 6: a quiet run is a steady turn where the table's mean rate
        over it exceeds the rest threshold, and at rest where it does not, whatever the gyros' agreement says (a
        log in one pose that starts and ends in the same steady turn is otherwise ambiguous). Its integral over
        a motion between two rests is that turn's reference angle (step 8), unless *table_angle* is given.
    table_angle : (N,) array or None
        The turntable's angle at every sample (its encoder's), rad, unwrapped (no jump of half a turn between
        samples); its sense does not matter. Its change over a motion between two rests is that turn's
        reference angle (step 8), whatever the angle: the table's own reference, not the nearest quarter turn.

    Returns
    -------
    Segmentation

    Raises
    ------
    ValueError
        Too few samples or no static span (too few static samples), naming what was looked for.
    """
    x = np.asarray(samples, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 6:
        raise ValueError(f"samples: shape {x.shape}; expected (N, 6): gx gy gz (rad/s), ax ay az (m/s^2)")
    if not np.all(np.isfinite(x)):
        raise ValueError("samples: every value must be finite")
    if not (sample_rate > 0 and math.isfinite(sample_rate)):
        raise ValueError(f"sample_rate = {sample_rate!r} Hz; expected a positive number")
    for name, value in (("window", window), ("min_static", min_static)):
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} = {value!r} s; expected a positive number of seconds")
    if not (variance_factor >= 1.0 and math.isfinite(variance_factor)):
        raise ValueError(f"variance_factor = {variance_factor!r}; expected a number >= 1 (a rest's variance over its "
                         "window may reach this many times the quiet stretch's, per channel)")
    if full_scale is not None:
        full_scale = np.asarray(full_scale, dtype=np.float64)
        if full_scale.shape != (6,) or not np.all(np.isnan(full_scale) | ((full_scale > 0) & np.isfinite(full_scale))):
            raise ValueError(f"full_scale = {full_scale.tolist()!r}; expected 6 positive numbers (rad/s for gx gy gz, "
                             "m/s^2 for ax ay az), NaN where not known")
    n = x.shape[0]
    if table_rate is not None:
        table_rate = np.asarray(table_rate, dtype=np.float64)
        if table_rate.shape != (n,) or not np.all(np.isfinite(table_rate)):
            raise ValueError(f"table_rate: shape {table_rate.shape}; expected ({n},) finite rates (rad/s), one per "
                             "sample")
    if table_angle is not None:
        table_angle = np.asarray(table_angle, dtype=np.float64)
        if table_angle.shape != (n,) or not np.all(np.isfinite(table_angle)):
            raise ValueError(f"table_angle: shape {table_angle.shape}; expected ({n},) finite angles (rad), one per "
                             "sample")
    w = max(MIN_WINDOW_SAMPLES, int(round(window * sample_rate)))
    half = w // 2
    n_min = max(1, int(round(min_static * sample_rate)))
    quiet_length = max(n_min, QUIET_WINDOWS * w)
    if n < quiet_length:
        raise ValueError(f"too few samples: the log has {n}; the noise is measured over a quiet stretch of "
                         f"{quiet_length} samples ({quiet_length / sample_rate:.3g} s: max(min_static, "
                         f"{QUIET_WINDOWS} windows of {window:g} s))")
    times = np.arange(n) / sample_rate if time is None else np.asarray(time, dtype=np.float64)
    gap_starts = np.zeros(0, dtype=np.int64) if gap_starts is None else np.asarray(gap_starts, dtype=np.int64)
    turned = _table_turned(times, table_rate, table_angle)

    # 1-2. moving statistics and resolution
    mean, var = moving_mean_variance(x, w)
    step = resolution(x)
    floor = step / math.sqrt(12.0)
    near_gap = np.zeros(n, dtype=bool)
    for k in gap_starts:
        near_gap[max(0, k - half - 1):min(n, k + half + 1)] = True

    # 3. the quietest stretch
    typical = np.maximum(np.median(var, axis=0), floor**2)
    typical = np.where(typical > 0, typical, 1.0)
    start = _quiet_stretch(np.sum(var / typical, axis=1), quiet_length, near_gap)
    quiet = slice(start, start + quiet_length)

    # 4b. isolated glitch rows (a logger's zero row, a dropout): the detector sees each as the mean of its
    # neighbours, and no static span holds one (they are cut out of the poses below)
    glitch = isolated_glitches(x, quiet, _sigma(var[quiet], w, floor), full_scale)
    logged = x
    if glitch.any():
        x = x.copy()
        rows = np.flatnonzero(glitch)
        below, above = np.maximum(rows - 1, 0), np.minimum(rows + 1, n - 1)
        below = np.where(rows == 0, above, below)
        above = np.where(rows == n - 1, below, above)
        x[rows] = 0.5 * (x[below] + x[above])
        mean, var = moving_mean_variance(x, w)

    # 4. the noise in it; then once more with each sample clipped to CLIP σ about the nearer of the means of
    # the w samples before it and the w samples after it, so that an isolated spike cannot make a window look
    # like motion, while a step (near one of the two means) is not smeared and a ramp (the means follow it)
    # still shows
    sigma = _sigma(var[quiet], w, floor)
    reference = _one_sided_reference(x, w)
    clipped = np.clip(x, reference - CLIP * sigma, reference + CLIP * sigma)
    mean, var = moving_mean_variance(clipped, w)
    sigma = _sigma(var[quiet], w, floor)
    # means, not medians: the median of a quantised channel jumps by whole steps
    bias = clipped[quiet, :3].mean(axis=0)
    lagged = mean[quiet][w:, :3] - mean[quiet][:-w, :3]
    allan = MAD_TO_SIGMA * np.median(np.abs(lagged - np.median(lagged, axis=0)), axis=0) / math.sqrt(2.0)
    window_sigma = np.maximum(allan, sigma[:3] / math.sqrt(w))
    noise = NoiseFloor(start, start + quiet_length, sigma, step, bias, window_sigma)

    # 5. quiet samples and runs: the threshold is VARIANCE_FACTOR × 3, or the quiet stretch's median ratio
    # plus SPREAD_FACTOR robust standard deviations of it if larger (correlated or heavy-tailed noise)
    thresholds = []
    for group in (slice(3, 6), slice(0, 3)):
        ratio = np.sum(var[:, group] / sigma[group] ** 2, axis=1)
        thresholds.append((ratio, _limit(ratio[quiet], variance_factor * 3.0)))
    quiet_mask = ~near_gap
    for ratio, threshold in thresholds:
        quiet_mask &= ratio <= threshold
    variance_threshold = (thresholds[0][1], thresholds[1][1])
    runs = [(a, b) for a, b in _runs(quiet_mask) if b - a >= n_min]
    # one pose from end to end: the specific force of the first and the last window agree (a unit tumbling
    # smoothly can be as quiet as its own quietest stretch, but its gravity turns)
    accel_window = sigma[3:] / math.sqrt(w)
    runs = [(a, b) for a, b in runs if _one_pose(x, a, b, w, accel_window)]

    # 6. rest or steady turn: each run against the nearest run at rest, outwards from the quiet stretch (a
    # slow drift of the bias over a long log is not a turn)
    rate_threshold = RATE_FACTOR * window_sigma + 2.0 * EARTH_RATE
    if table_rate is not None:  # 5b. one table rate from end to end
        runs = _one_table_rate(runs, table_rate, w, float(np.max(rate_threshold)), n_min)
    medians = [clipped[a:b, :3].mean(axis=0) for a, b in runs]
    forces = [x[a:b, 3:].mean(axis=0) for a, b in runs]
    at_rest = [False] * len(runs)
    if runs:
        first = min(range(len(runs)), key=lambda i: 0 if runs[i][0] <= start < runs[i][1]
                    else min(abs(runs[i][0] - start), abs(runs[i][1] - start)))
        # the run that holds the quiet stretch is at rest by assumption (step 3), unless more of the log agrees
        # with another run (step 6: a table's steady turn is as quiet as a rest)
        holds_quiet = runs[first][0] <= start and start + quiet_length <= runs[first][1]
        seed = first_rest(runs, medians, forces, rate_threshold, first)
        if seed != first:
            first, holds_quiet = seed, True
            a, b = runs[seed]
            bias = clipped[a:b, :3].mean(axis=0)
            noise = dataclasses.replace(noise, gyro_bias=bias)
        if table_rate is not None:  # the table's own rate is the reference: it turned, or it did not
            at_rest = [abs(float(np.mean(table_rate[a:b]))) <= float(np.max(rate_threshold)) for a, b in runs]
            if any(at_rest) and not at_rest[first]:  # the bias from a run the table says was at rest
                a, b = max((run for run, rest in zip(runs, at_rest) if rest), key=lambda run: run[1] - run[0])
                bias = clipped[a:b, :3].mean(axis=0)
                noise = dataclasses.replace(noise, gyro_bias=bias)
        else:
            at_rest[first] = holds_quiet or bool(np.all(np.abs(medians[first] - bias) <= rate_threshold))
            for order in (range(first + 1, len(runs)), range(first - 1, -1, -1)):
                rests = [first] if at_rest[first] else []
                for i in order:
                    # against the nearest rest only: a rest in the same pose long before differs by the bias's
                    # drift since, and whether it was asked depended on the order the runs were visited in
                    at_rest[i] = at_rest_against(i, rests[:1], medians, forces, bias, rate_threshold)
                    if at_rest[i]:
                        rests.insert(0, i)  # nearest first
            # 6a. a gyro g-sensitivity beyond the allowance, told by the runs themselves
            centres = [0.5 * (float(times[a]) + float(times[b - 1])) for a, b in runs]
            at_rest = rests_by_g_sensitivity(medians, forces, centres, at_rest, rate_threshold)
    static_runs = [run for run, rest in zip(runs, at_rest) if rest]
    steady = [run for run, rest in zip(runs, at_rest) if not rest]
    # 6b. poses held by hand: the accelerometers quiet and one pose, the gyros shaking about a steady mean
    held = _held_runs(x, times, thresholds[0], near_gap, n_min, w, accel_window, static_runs, steady,
                      [medians[i] for i, rest in enumerate(at_rest) if rest],
                      [forces[i] for i, rest in enumerate(at_rest) if rest], rate_threshold, bias)
    if held:
        static_runs = _merge_same_pose(sorted(static_runs + held), x, w)
        held = [run for run in static_runs if any(run[0] <= a and b <= run[1] for a, b in held)]
    if not static_runs:
        quiet_runs = _runs(quiet_mask)
        longest = max((b - a for a, b in quiet_runs), default=0)
        why = (": quiet, but not taken for a rest (its gravity turns, its gyros read a steady turn, or the quietest "
               f"stretch the noise is measured over, {QUIET_WINDOWS} windows of {w / sample_rate:.3g} s, holds motion "
               f"besides: a shorter --window, e.g. {w / sample_rate / 2:.3g}, may find it)" if longest >= n_min else "")
        short = len(_short_quiet(quiet_runs, w, n_min))
        hint = (f"; {short} quiet stretches are shorter than that: if the log's rests are, try --min-static "
                f"{min_static / 2:.3g} --window {w / sample_rate / 2:.3g}" if short >= SHORT_QUIET_HINT else
                "; if the log's rests are noisier than its quietest stretch, try --rest-variance (default 4)")
        raise ValueError(f"too few static samples: no span at rest of at least {min_static:g} s ({n_min} samples) "
                         f"was found; the longest quiet stretch has {longest} samples ({longest / sample_rate:.3g} "
                         f"s){why}. Quiet: summed variance ratios <= {variance_threshold[0]:.3g} (accelerometers) "
                         f"and {variance_threshold[1]:.3g} (gyros) over windows of {w} samples "
                         f"and the gyro output within the rest threshold{hint} (docs/measured-data.md)")

    # 4c. frozen stretches: one value repeated for longer than the channel's noise at rest allows
    frozen = frozen_runs(logged, static_runs, step)
    frozen_rows = frozen_mask(n, frozen)
    gyro_frozen = frozen_mask(n, frozen, channels=range(3))

    # 4b-c. no static span holds a glitch row or a frozen sample: a pose is cut at each, and a piece shorter than a
    # window is left to the motion beside it (a pose trimmed)
    cut = glitch | frozen_rows
    held_pieces = set()
    if cut.any():
        pieces = []
        for a, b in static_runs:
            cuts = np.flatnonzero(cut[a:b]) + a
            for lo, hi in zip(np.concatenate(([a], cuts + 1)).tolist(), np.concatenate((cuts, [b])).tolist()):
                if hi - lo >= w:
                    pieces.append((lo, hi))
                    if (a, b) in held:
                        held_pieces.add((lo, hi))
        static_runs = pieces
    else:
        held_pieces = set(held)
    if not static_runs:
        raise ValueError(f"too few static samples: every span at rest is cut by isolated glitch rows or frozen "
                         f"samples into pieces shorter than a window of {w} samples")

    # 7-10. poses, motion, steady rates, saturation
    statics = []
    for a, b in static_runs:
        m = x[a:b].mean(axis=0)
        up, tilt = nearest_axis(m[3:])
        shake = float(np.max(np.std(x[a:b, :3], axis=0) / sigma[:3])) if (a, b) in held_pieces else math.nan
        # a pose joined from pieces holds the samples between them too (at most a window of them)
        statics.append(Span("static", a, b, m, up=up, tilt=tilt,
                            orientation="approximate" if tilt <= APPROXIMATE_TILT else "unknown", held=shake))
    saturation = _saturation(x, statics, steady, sigma, step, full_scale)
    spans: list[Span] = []
    previous = None
    for span in statics + [None]:
        lo = 0 if previous is None else previous.stop
        hi = n if span is None else span.start
        if hi > lo and _cut_at_glitch(cut[lo:hi], w, previous, span):
            what = ("a frozen channel (one value repeated, step 4c)" if frozen_rows[lo:hi].any() else
                    "isolated glitch row(s) (step 4b)")
            spans.append(Span("move", lo, hi, logged[lo:hi].mean(axis=0), up=(previous or span).up,
                              reason=f"{what} cut out of the pose around them"))
        elif hi > lo and gyro_frozen[lo:hi].any():
            spans.append(Span("move", lo, hi, x[lo:hi].mean(axis=0), up=(previous or span).up,
                              integrated=np.full(3, np.nan),
                              reason="a gyro frozen inside (one value repeated, step 4c): the turn cannot be "
                                     "integrated"))
        elif hi > lo:
            spans.extend(_motion_pieces(x, times, lo, hi, previous, span, gap_starts, saturation, steady, turned))
        if span is not None:
            spans.append(span)
        previous = span
    in_motion = np.zeros(n, dtype=bool)
    for span in spans:
        if span.kind != "static":
            in_motion[span.start:span.stop] = True
    short_quiet = tuple((a, b) for a, b in _short_quiet(_runs(quiet_mask), w, n_min) if in_motion[a:b].all())
    # 11. poses noisier than the quiet stretch, reported for the user to decide on
    blocked = near_gap | cut | ~in_motion
    for s in saturation:
        blocked[s.start:s.stop] = True
    noisy = noisy_poses(x, mean, var, sigma, w, n_min, quiet, blocked, [t[0] for t in thresholds], variance_factor,
                        statics, rate_threshold, bias)
    return Segmentation(tuple(spans), noise, w, n_min, variance_threshold, rate_threshold, tuple(saturation),
                        tuple(steady), tuple(np.flatnonzero(glitch).tolist()), tuple(frozen), short_quiet,
                        tuple(noisy))


def noisy_poses(x: np.ndarray, mean: np.ndarray, var: np.ndarray, sigma: np.ndarray, w: int, n_min: int,
                quiet: slice, blocked: np.ndarray, ratios: list[np.ndarray], variance_factor: float,
                statics: list[Span], rate_threshold: np.ndarray, bias: np.ndarray) -> list[NoisyPose]:
    """Step 11 of the module docstring: stretches outside *blocked* (the static spans, gaps, glitch and frozen
    rows, rails) that hold one pose with the gyros at rest but are noisier than the quiet stretch.

    *mean*, *var*: the moving statistics of the clipped samples over *w* samples (centred); *ratios*: the summed
    variance ratios of the accelerometers and of the gyros at every sample (step 5); *statics*: the static spans,
    for the gyro test of step 6 against the nearest one."""
    n = x.shape[0]
    half = w // 2
    if n < 2 * w or not statics:
        return []
    # z[k]: the windows [k - w, k) and [k, k + w) (centred moving statistics at k - w + half and k + half)
    k = np.arange(w, n - w + 1)
    before, after = k - w + half, np.minimum(k + half, n - 1)
    floor = (0.1 * sigma) ** 2  # a window far quieter than the quiet stretch (a quantised channel's run of one value)
    noise = np.sqrt((np.maximum(var[before], floor) + np.maximum(var[after], floor)) / w)
    z = np.max(np.abs(mean[after] - mean[before]) / noise, axis=1)
    # ... and their variances agree (a window that holds a motion's onset has a large variance and so a small z)
    spread_ratio = np.max(np.abs(np.log(np.maximum(var[after], floor) / np.maximum(var[before], floor))), axis=1)
    in_quiet = (k >= quiet.start) & (k < quiet.stop)
    steady = np.zeros(n, dtype=bool)
    f_point = math.log(float(scipy.stats.f.isf(STATIONARY_P, w - 1, w - 1)))
    agree = (z <= _limit(z[in_quiet], STATIONARY_FACTOR)) & (spread_ratio <= _limit(spread_ratio[in_quiet], f_point))
    steady[k[agree]] = True
    centres = np.array([0.5 * (span.start + span.stop) for span in statics])
    found = []
    for a, b in _runs(steady & ~blocked):
        if b - a < max(n_min, 2 * w):
            continue
        factor = max(float(np.max(ratio[a:b])) for ratio in ratios) / 3.0
        if factor <= variance_factor:  # as quiet as a rest: another test left it out (its pose or its gyros)
            continue
        if not _one_pose(x, a, b, w, np.sqrt(np.mean(var[a:b, 3:], axis=0) / w)):  # with its own noise
            continue
        gyro_window = np.sqrt(np.mean(var[a:b, :3], axis=0) / w)
        threshold = np.maximum(rate_threshold, RATE_FACTOR * gyro_window + 2.0 * EARTH_RATE)
        nearest = statics[int(np.argmin(np.abs(centres - 0.5 * (a + b))))]
        medians = [x[a:b, :3].mean(axis=0), nearest.mean[:3]]
        forces = [x[a:b, 3:].mean(axis=0), nearest.mean[3:]]
        if not at_rest_against(0, [1], medians, forces, bias, threshold):
            continue
        found.append(NoisyPose(a, b, nearest_axis(forces[0])[0], factor))
    return found


def _short_quiet(runs: list[tuple[int, int]], w: int, n_min: int) -> list[tuple[int, int]]:
    """The quiet *runs* too short for a static span (``min_static``, *n_min* samples) but at least half a window
    (*w* samples) long: rests a hand paused for, which a shorter ``--min-static`` and ``--window`` would take."""
    return [(a, b) for a, b in runs if w // 2 <= b - a < n_min]


def _cut_at_glitch(glitch: np.ndarray, w: int, before: Span | None, after: Span | None) -> bool:
    """Whether the motion between the static spans *before* and *after* (either may be None) is only what step 4b
    cut out of a pose: glitch rows alone, or glitch rows and pieces shorter than a window (*w* samples) at an end
    of the log or between two spans in the same pose."""
    if glitch.all():
        return True
    if not glitch.any() or np.count_nonzero(~glitch) >= 2 * w:
        return False
    if before is None or after is None:
        return True
    f, g = before.mean[3:], after.mean[3:]
    return float(np.dot(f, g)) >= math.cos(SAME_POSE) * float(np.linalg.norm(f) * np.linalg.norm(g))


def _merge_same_pose(runs: list[tuple[int, int]], x: np.ndarray, w: int) -> list[tuple[int, int]]:
    """Join runs at rest that are at most a window apart and in the same pose (specific force within
    :data:`SAME_POSE`): a hand that shakes only now and then splits one pose into quiet and held pieces."""
    out = [runs[0]]
    for a, b in runs[1:]:
        c, d = out[-1]
        f, g = x[c:d, 3:].mean(axis=0), x[a:b, 3:].mean(axis=0)
        if a - d <= w and float(np.dot(f, g)) >= math.cos(SAME_POSE) * float(np.linalg.norm(f) * np.linalg.norm(g)):
            out[-1] = (c, b)
        else:
            out.append((a, b))
    return out


def _held_runs(x, times, accel_test, near_gap, n_min, w, accel_window, static_runs, steady, rest_medians,
               rest_forces, rate_threshold, bias) -> list[tuple[int, int]]:
    """Step 6b: stretches, outside the runs of steps 5-6, where the accelerometers are quiet (their test of step
    5) for at least ``min_static`` and hold one pose, while the gyros scatter more than at rest: a unit held by
    hand, whose tremor the gyros see and the accelerometers hardly do (a tremor of 1 °/s at 5 Hz tilts the unit
    by 0.03°). Such a stretch is a pose when the attitude the gyros integrate about their mean rate swings by
    no more than ±``POSE_TOLERANCE`` (no turn started and stopped inside it) and, as in step 6, its mean gyro
    output is that of a rest (:func:`at_rest_against`: along its own gravity, against the nearest rest)."""
    ratio, threshold = accel_test
    taken = np.zeros(x.shape[0], dtype=bool)
    for a, b in static_runs + steady:
        taken[a:b] = True
    candidates = [(a, b) for a, b in _runs((ratio <= threshold) & ~near_gap & ~taken) if b - a >= n_min]
    medians, forces, where = list(rest_medians), list(rest_forces), [0.5 * (a + b) for a, b in static_runs]
    out = []
    for a, b in candidates:
        if not _one_pose(x, a, b, w, accel_window):
            continue
        gyro = x[a:b, :3]
        centre = gyro.mean(axis=0)
        # the attitude about its steady drift: the shaking may swing it by no more than ±POSE_TOLERANCE
        swing = np.cumsum(gyro - centre, axis=0) * float(np.median(np.diff(times[a:b]))) if b - a > 1 else gyro * 0
        if np.any(np.ptp(swing, axis=0) > 2.0 * POSE_TOLERANCE):
            continue
        medians.append(centre)
        forces.append(x[a:b, 3:].mean(axis=0))
        i = len(medians) - 1
        nearest = sorted(range(i), key=lambda j: abs(where[j] - 0.5 * (a + b)))
        if at_rest_against(i, nearest, medians, forces, bias, rate_threshold):
            out.append((a, b))
            where.append(0.5 * (a + b))
        else:
            medians.pop()
            forces.pop()
    return out


def _one_pose(x: np.ndarray, a: int, b: int, w: int, accel_window: np.ndarray) -> bool:
    """Whether samples ``[a, b)`` hold one pose (step 5): the mean specific force of the first and the last *w*
    samples differ by at most ``RATE_FACTOR`` √2 times *accel_window* (the noise of a window mean, per
    accelerometer) plus ``POSE_TOLERANCE`` of gravity on each axis (a unit tumbling smoothly can be as quiet as its
    own quietest stretch, but its gravity turns)."""
    first, last = x[a:a + w, 3:].mean(axis=0), x[b - w:b, 3:].mean(axis=0)
    allowed = RATE_FACTOR * math.sqrt(2.0) * accel_window + np.linalg.norm(first) * math.sin(POSE_TOLERANCE)
    return bool(np.all(np.abs(last - first) <= allowed))


def _limit(in_quiet: np.ndarray, least: float) -> float:
    """*least*, or the median of a statistic over the quiet stretch plus ``SPREAD_FACTOR`` robust standard
    deviations of it where that is larger (correlated or heavy-tailed noise)."""
    if not in_quiet.size:
        return least
    spread = MAD_TO_SIGMA * float(np.median(np.abs(in_quiet - np.median(in_quiet))))
    return max(least, float(np.median(in_quiet)) + SPREAD_FACTOR * spread)


def _one_sided_reference(x: np.ndarray, w: int) -> np.ndarray:
    """Per sample, whichever of the mean of the *w* samples before it and of the *w* after it is nearer it."""
    n = x.shape[0]
    k = np.arange(n)
    lo, hi = np.maximum(k - w, 0), np.minimum(k + 1 + w, n)
    n_before, n_after = np.maximum(k - lo, 1), np.maximum(hi - k - 1, 1)
    out = np.empty(x.shape)
    for c in range(x.shape[1]):
        centre = float(np.median(x[:, c]))
        sums = np.concatenate(([0.0], np.cumsum(x[:, c] - centre)))
        before = np.where(k > 0, (sums[k] - sums[lo]) / n_before, np.inf) + centre
        after = np.where(k < n - 1, (sums[hi] - sums[k + 1]) / n_after, np.inf) + centre
        out[:, c] = np.where(np.abs(x[:, c] - before) <= np.abs(x[:, c] - after), before, after)
    return out


def isolated_glitches(x: np.ndarray, quiet: slice, sigma: np.ndarray,
                      full_scale: np.ndarray | None = None) -> np.ndarray:
    """Rows of *x* that are isolated glitches (step 4b of the module docstring).

    Parameters
    ----------
    x : (N, 6) array
        The samples, SI.
    quiet : slice
        The quietest stretch ``Q`` (step 3): the largest deviation of a sample from its neighbours' mean there
        sets how heavy the noise's tails are.
    sigma : (6,) array
        Each channel's noise per sample (step 4), SI.
    full_scale : (6,) array or None
        Declared full scales (NaN where not known): a sample at its rail is a reading, never a glitch.

    Returns
    -------
    (N,) bool array
        True for a glitch row: all six channels exactly 0 while a neighbour row is not, or some channel further
        from the mean of its two neighbours (the one neighbour at an end of the log) than :data:`GLITCH_SIGMA` σ,
        :data:`GLITCH_TAIL` times the largest such deviation in ``Q`` and :data:`GLITCH_RATIO` times the
        neighbours' own variation, that variation being quiet (at most :data:`GLITCH_QUIET` times its largest in
        ``Q``, or 10 σ if more).
    """
    n = x.shape[0]
    glitch = np.zeros(n, dtype=bool)
    if n < 4:
        return glitch
    zero = np.all(x == 0.0, axis=1)
    glitch |= zero & ~np.concatenate(([False], zero[:-1])) & ~np.concatenate((zero[1:], [False]))
    padded = np.concatenate((x[2:0:-1], x, x[-2:-4:-1]))  # mirrored: an end's one neighbour stands for both
    before, after = padded[1:-3], padded[3:-1]
    deviation = np.abs(x - 0.5 * (before + after))
    variation = np.maximum.reduce([np.abs(after - before), np.abs(before - padded[:-4]),
                                   np.abs(padded[4:] - after)])
    tail = np.max(deviation[quiet], axis=0)
    threshold = np.maximum(GLITCH_SIGMA * sigma, GLITCH_TAIL * tail)
    quiet_neighbours = variation <= np.maximum(10.0 * sigma, GLITCH_QUIET * np.max(variation[quiet], axis=0))
    far = (deviation > threshold) & (deviation > GLITCH_RATIO * variation) & quiet_neighbours
    if full_scale is not None:
        far &= ~(np.abs(x) >= (1.0 - FULL_SCALE_MARGIN) * np.where(np.isnan(full_scale), np.inf, full_scale))
    return glitch | np.any(far, axis=1)


def _sigma(variance: np.ndarray, w: int, floor: np.ndarray) -> np.ndarray:
    """Per-sample noise from the moving variances of a stretch at rest: a window's variance is σ² χ²(w−1)/w,
    so σ² = median variance / median of χ²(w−1)/w (Wilson–Hilferty); at least the quantisation floor."""
    dof = w - 1
    median_ratio = dof * (1.0 - 2.0 / (9.0 * dof)) ** 3 / w
    sigma = np.maximum(np.sqrt(np.median(variance, axis=0) / median_ratio), floor)
    return np.where(sigma > 0, sigma, np.finfo(float).tiny ** 0.25)  # a perfectly constant channel


def _saturation(x: np.ndarray, statics: list[Span], steady: list[tuple[int, int]], sigma: np.ndarray,
                step: np.ndarray, full_scale: np.ndarray | None = None) -> list[Saturation]:
    """Stretches stuck at a rail: see step 10 of the module docstring."""
    at_rest = np.zeros(x.shape[0], dtype=bool)
    for span in statics:
        at_rest[span.start:span.stop] = True
    found = []
    for c in range(6):
        if full_scale is not None and not np.isnan(full_scale[c]):  # the rail is known: every sample at it
            for a, b in _runs(np.abs(x[:, c]) >= (1.0 - FULL_SCALE_MARGIN) * full_scale[c]):
                found.append(Saturation(c, a, b, float(x[a + int(np.argmax(np.abs(x[a:b, c]))), c])))
            continue
        # the levels the channel holds while quiet (at rest or turning steadily) are not rails
        levels = np.array([span.mean[c] for span in statics] + [float(x[a:b, c].mean()) for a, b in steady])
        margin = SATURATION_STEP * sigma[c] + step[c]
        for value in (x[:, c].max(), x[:, c].min()):
            if np.any(np.abs(levels - value) <= margin):
                continue
            for a, b in stuck_runs(x[:, c], value, SATURATION_STEP * sigma[c]):
                if not at_rest[a:b].any():
                    found.append(Saturation(c, a, b, float(value)))
    return sorted(found, key=lambda s: (s.start, s.channel))


def stuck_runs(values: np.ndarray, value: float, jump: float) -> list[tuple[int, int]]:
    """Runs ``[a, b)`` of samples of *values* equal to *value* (a channel's extreme) that are entered or left by a
    step of more than *jump*: a signal stuck at a rail. A smooth peak of a quantised channel also repeats its
    extreme, but enters and leaves it by one step; a fast one falls between two samples, which then read alike:
    a run needs :data:`SATURATION_RUN` samples, or two when the value is held by two such runs or more (step 10
    of the module docstring)."""
    n = values.shape[0]
    out = []
    for a, b in _runs(values == value):
        if b - a < 2:
            continue
        entry = abs(values[a - 1] - value) if a > 0 else 0.0
        leave = abs(values[b] - value) if b < n else 0.0
        if max(entry, leave) > jump:
            out.append((a, b))
    if len(out) < 2:
        out = [(a, b) for a, b in out if b - a >= SATURATION_RUN]
    return out


def _vertical(force: np.ndarray, axis: int) -> bool:
    """Body axis *axis* lies within :data:`VERTICAL_AXIS_TOLERANCE` of the specific force *force* (either sense)."""
    return math.acos(min(1.0, abs(float(force[axis])) / float(np.linalg.norm(force)))) <= VERTICAL_AXIS_TOLERANCE


def _one_table_rate(runs: list[tuple[int, int]], table_rate: np.ndarray, w: int, threshold: float, n_min: int
                    ) -> list[tuple[int, int]]:
    """Step 5b: each quiet run cut into the stretches over which the table's logged rate (its mean over *w*
    samples, so that an encoder's steps average out) stays within max(*threshold*, ``TABLE_STEADY_FRACTION`` of
    it) of its value at the stretch's start; those of at least *n_min* samples kept. A table's slow change of rate
    is as quiet as its steady turns: a run across one (−5 °/s, a ramp, a rest, a ramp, +5 °/s) is neither one
    steady turn nor a rest."""
    smooth = moving_mean_variance(table_rate[:, None], w)[0][:, 0]
    out = []
    for a, b in runs:
        start = a
        while start < b:
            reference = float(smooth[start])
            tolerance = max(threshold, TABLE_STEADY_FRACTION * abs(reference))
            off = np.flatnonzero(np.abs(smooth[start:b] - reference) > tolerance)
            stop = start + int(off[0]) if off.size else b
            if stop - start >= n_min:
                out.append((start, stop))
            start = stop
    return out


def _table_turned(times: np.ndarray, table_rate: np.ndarray | None, table_angle: np.ndarray | None
                  ) -> np.ndarray | None:
    """The table's angle at each sample's start and after the last, (N + 1,) rad, such that ``turned[hi] −
    turned[lo]`` is the angle the table turned over the samples ``[lo, hi)`` as :func:`_integrate` takes the gyros'
    (each sample's rate held from it to the next): the logged angle (the last repeated), or the logged rate's
    running integral; ``None`` where neither was logged."""
    if table_angle is not None:
        return np.append(table_angle, table_angle[-1])
    if table_rate is None:
        return None
    dt = np.append(np.diff(times), 0.0)
    return np.concatenate(([0.0], np.cumsum(table_rate * dt)))


def _integrate(x: np.ndarray, times: np.ndarray, lo: int, hi: int, before: Span, after: Span
               ) -> tuple[np.ndarray, np.ndarray]:
    """∫ (gyro − bias) dt over ``[lo, hi)``, rad, with the bias linear in time between the static spans *before* and
    *after*'s mean gyro outputs (each sample's rate held from it to the next sample, the last one to the start of
    the next span); and that bias, (hi − lo, 3) rad/s."""
    t_before = times[before.start:before.stop].mean()
    t_after = times[after.start:after.stop].mean()
    weight = (times[lo:hi] - t_before) / (t_after - t_before) if t_after > t_before else np.full(hi - lo, 0.5)
    bias = before.mean[:3] + np.outer(weight, after.mean[:3] - before.mean[:3])
    dt = np.diff(times[lo:hi + 1]) if hi < times.shape[0] else np.append(np.diff(times[lo:hi]), 0.0)
    return np.sum((x[lo:hi, :3] - bias) * dt[:, None], axis=0), bias


def _motion_pieces(x: np.ndarray, times: np.ndarray, lo: int, hi: int, before: Span | None, after: Span | None,
                   gap_starts: np.ndarray, saturation: list[Saturation], steady: list[tuple[int, int]],
                   turned: np.ndarray | None = None) -> list[Span]:
    """The motion ``[lo, hi)`` between the static spans *before* and *after*: one span (:func:`_motion`), or, where
    it holds steady turns (step 6), each steady turn as a ``rotation`` of its own with its measured rate and no
    angle, and the stretches around them (a table's spin-up, a change of rate, its stop) as moves (step 9).

    The nearest whole number of quarter turns is a reference for a turn by hand against a stop, not for a table
    that turns at a rate for a time: a −567° table turn would be labelled −540° (within 10° + 5 %), and a fit that
    took that angle would be 5 % off. The table's rate is the reference, and it holds only over the steady part.
    So a log that starts or ends in a steady turn (recorded into a table's turn, or stopped before the table) has
    its steady part as a rotation too, its rate measured against the one pose beside it (*before* or *after*),
    whose rest output is the bias; the stretch between the log's end and the steady part is a move. A time gap
    between the steady turns (a log recorded over each dwell only, the table's changes of rate not logged) leaves
    them whole: no steady turn holds one (step 6 keeps a window off each gap), and the piece that holds it is a
    move, not integrated."""
    inside = [(a, b) for a, b in steady if a >= lo and b <= hi]
    if not inside or (before is None and after is None):
        return [_motion(x, times, lo, hi, before, after, gap_starts, saturation, turned)]
    side = before if before is not None else after  # the pose whose rest output is the bias, where one is missing
    pieces: list[Span] = []
    edges = [lo] + [v for run in inside for v in run] + [hi]
    for k in range(len(edges) - 1):
        p, q = edges[k], edges[k + 1]
        if q <= p:
            continue
        mean = x[p:q].mean(axis=0)
        if k % 2 == 0 and np.any((gap_starts > p) & (gap_starts <= q)):
            # a log recorded only over each dwell: the settling between them not logged, nothing to integrate
            pieces.append(Span("move", p, q, mean, up=side.up, reason="a time gap inside: the turn cannot be "
                                                                       "integrated"))
            continue
        integrated, bias = _integrate(x, times, p, q, before or side, after or side)
        axis = int(np.argmax(np.abs(integrated)))
        if k % 2 == 0:  # around the steady turns
            if k == 0 and before is None:
                where = "the log's start, in a turn"
            elif q == hi and after is None:
                where = "the log's end, in a turn"
            else:
                where = "a spin-up" if k == 0 else ("a stop" if q == hi else "a change of rate")
            pieces.append(Span("move", p, q, mean, up=side.up, integrated=integrated, axis=axis,
                               reason=f"{where} around a steady turn (step 9): no reference for its angle"))
            continue
        rate = x[p:q, :3].mean(axis=0) - bias.mean(axis=0)
        off = float(np.hypot(*np.delete(rate, axis)))
        # a steady turn about the vertical leaves the specific force as it is: its own pose, which need not be the
        # rest's beside it (a log recorded over each dwell only: the unit turned to another pose in a time gap)
        up, _ = nearest_axis(mean[3:])
        vertical = _vertical(mean[3:], axis)
        if any(s.start < q and s.stop > p for s in saturation):
            why = "a saturated sample inside: the steady rate is not known"
        elif off > OFF_AXIS_FRACTION * abs(float(rate[axis])):
            why = (f"a steady turn not about one body axis ({math.degrees(float(rate[axis])):+.4g} deg/s about "
                   f"{AXES[axis]}, {math.degrees(off):.3g} deg/s about the other two)")
        else:
            why = ""
        if why:
            pieces.append(Span("move", p, q, mean, up=side.up, integrated=integrated, axis=axis, reason=why))
        else:
            pieces.append(Span("rotation", p, q, mean, up=up, integrated=integrated, axis=axis,
                               orientation="approximate" if vertical else "unknown",
                               steady_rate=float(rate[axis])))
    return pieces


def _motion(x: np.ndarray, times: np.ndarray, lo: int, hi: int, before: Span | None, after: Span | None,
            gap_starts: np.ndarray, saturation: list[Saturation], turned: np.ndarray | None = None) -> Span:
    """Classify the motion ``[lo, hi)`` between the static spans *before* and *after* (either may be None), which
    holds no steady turn (or cannot be split at one: :func:`_motion_pieces`). The turn's reference angle is the
    nearest whole number of quarter turns, or, with the table's angle logged (*turned*, :func:`_table_turned`) and
    the table turned by more than :data:`TABLE_STILL`, the table's angle, signed as the gyros measured it, where
    it and the gyros' integral agree within :data:`TABLE_AGREEMENT` (the reason of a move then says what the
    table turned, and ``table_turned`` keeps it). The other tests of step 8 are the same for both."""
    mean = x[lo:hi].mean(axis=0)
    up = before.up if before is not None else (after.up if after is not None else "")
    table = math.nan

    def move(reason: str, integrated: np.ndarray | None = None, axis: int = -1) -> Span:
        if math.isfinite(table):
            reason = f"the table turned {math.degrees(table):+.2f} deg by its column, but {reason}"
        return Span("move", lo, hi, mean, up=up, integrated=np.full(3, np.nan) if integrated is None else integrated,
                    axis=axis, reason=reason, table_turned=table)

    if before is None or after is None:
        return move("no static span on both sides: the bias cannot be removed and no pose closes the motion")
    if np.any((gap_starts > lo) & (gap_starts <= hi)):
        return move("a time gap inside: the turn cannot be integrated")
    if any(s.start < hi and s.stop > lo for s in saturation):
        return move("a saturated sample inside: the turn cannot be integrated")
    integrated, _ = _integrate(x, times, lo, hi, before, after)
    axis = int(np.argmax(np.abs(integrated)))
    main = float(integrated[axis])
    off = float(np.hypot(*np.delete(integrated, axis)))
    if turned is not None and abs(float(turned[hi] - turned[lo])) > TABLE_STILL:
        table = float(turned[hi] - turned[lo])
    by_table = math.isfinite(table)
    if not by_table and abs(main) < math.pi / 4:
        return move(f"turned {math.degrees(main):+.1f} deg about {AXES[axis]}: less than 45 deg", integrated, axis)
    if off > OFF_AXIS_FRACTION * abs(main):
        whose = "the gyros' turn is " if by_table else ""
        return move(f"{whose}not about one body axis: the other axes turned {math.degrees(off):.1f} deg against "
                    f"{math.degrees(main):+.1f} deg about {AXES[axis]}", integrated, axis)
    if by_table:
        if abs(abs(main) - abs(table)) > TABLE_AGREEMENT * abs(table):
            return move(f"the gyros measured {math.degrees(main):+.2f} deg about {AXES[axis]}, more than "
                        f"{TABLE_AGREEMENT:.0%} apart (the column in another unit, or the table not turning about "
                        f"{AXES[axis]}?)", integrated, axis)
        nominal = math.copysign(abs(table), main)
    else:
        nominal = (math.pi / 2) * round(main / (math.pi / 2))
        if ANGLE_TOLERANCE_RAD + ANGLE_TOLERANCE_FRACTION * abs(nominal) >= math.pi / 4:
            return move(f"turned {math.degrees(main):+.1f} deg about {AXES[axis]}: too far for the nearest whole "
                        "number of quarter turns to be told (10 deg + 5 % of it passes half a quarter turn); give "
                        "the turn's angle, or the table's rate over its steady part", integrated, axis)
        if abs(main - nominal) > ANGLE_TOLERANCE_RAD + ANGLE_TOLERANCE_FRACTION * abs(nominal):
            return move(f"turned {math.degrees(main):+.1f} deg about {AXES[axis]}: not near a whole number of "
                        "quarter turns", integrated, axis)
    if before.up != after.up:
        why = "a turn about a horizontal axis, which the fit does not use" if by_table else "no reference for the angle"
        return move(f"the pose changed from {before.up} up to {after.up} up: {why}", integrated, axis)
    g = before.mean[3:]
    vertical = _vertical(g, axis)
    if by_table:  # the table's angle is measured: a whole number of full turns within the hand's tolerance
        full_turns = abs(math.remainder(nominal, 2.0 * math.pi)) <= ANGLE_TOLERANCE_RAD
    else:
        full_turns = abs(nominal) % (2 * math.pi) < 1e-9
    if not vertical and not full_turns:
        turned_by = "it turned" if by_table else f"turned {math.degrees(main):+.1f} deg"
        return move(f"{turned_by} about the horizontal axis {AXES[axis]} without coming back to the same pose",
                    integrated, axis)
    expected = _rotate(g, axis, nominal)
    if float(np.dot(expected, after.mean[3:])) < math.cos(VERTICAL_AXIS_TOLERANCE) * float(
            np.linalg.norm(expected) * np.linalg.norm(after.mean[3:])):
        return move("the gravity direction after the turn does not match the turn", integrated, axis)
    return Span("rotation", lo, hi, mean, up=before.up, integrated=integrated, axis=axis, angle=nominal,
                orientation="approximate" if vertical else "unknown", table_turned=table)
