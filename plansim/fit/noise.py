"""The noise of a recording, from its own samples: within-segment scatter and the Allan deviation.

For each channel (gx gy gz ax ay az):

1. **Allan deviation** of every static segment (overlapping, ``allantools.oadev``, octave-spaced τ up
   to half the segment), pooled over the static segments at each τ (weighted by the number of terms),
   and fitted with the IEEE Std 952 (Annex C) model

       σ_A²(τ) = N²/τ + (2 ln 2/π)·B² + K²·τ/3

   (white noise N, bias instability B, rate random walk K; all ≥ 0) by non-negative weighted least
   squares, each point weighted by its own variance 2σ_A⁴/ν (ν: the equivalent degrees of freedom of
   the overlapping Allan variance for white noise, Howe, Allan & Barnes 1981), twice (the second time
   with the first fit's σ_A in the weights).
2. **Within-segment scatter**: the standard deviation of each segment's samples about their mean; in
   a turning segment, about a second-degree trigonometric polynomial in the table angle (the turning
   projection of gravity and the Earth rate is not noise).
3. **Quantisation**: a channel whose values are whole multiples of one step q (found from the data)
   is quantised; where the noise is too small to dither it (σ ≲ q/2), a segment mean carries a
   systematic error of r.m.s. √(Σ_k (q/πk)² e^{−4π²k²σ²/q²} / 2) (q/√12 without noise), which no
   scatter shows. In a static segment, the error is taken given where its samples fall on the levels
   (:func:`quantisation_error_given_levels`), averaged over what the static segments' level counts say
   of the channel's noise before the quantiser (:func:`quantised_noise_posterior`; the scatter cannot tell
   it below q/2, and a point estimate of it understates the error: below). An accelerometer in a turning
   segment on a table is taken the same way, its noise σ widened by its own sweep (the trigonometric
   polynomial in the angle) and, where its samples fall on three levels or more, by its scatter less q²/12
   (Sheppard). On one or two levels that scatter is no dither: a level near a step's edge toggles between two
   codes with a scatter up to q/2 whatever σ (:func:`_turning_dither`). A gyro in a turning segment, and any
   channel in a turn by hand, takes its scatter less q²/12: the rate's jitter is noise before the gyro's
   quantiser that the static segments do not show and one or two levels cannot tell.

**The variance of a segment mean** of duration T is then the Allan variance at τ = T — the mean square
difference between two adjacent such means — from the fitted model: N²/T + (2 ln 2/π)B² + K²T/3. The
white part averages down, the bias-instability part does not (it is the same whatever T), and the random
walk grows. Not σ²/n: that holds for white noise only. In a turning segment the white part is the larger
of N²/T and the segment's own scatter²/n (the table's rate jitter adds white noise the static segments do
not have). A floor of :data:`RELATIVE_FLOOR` of the channel's r.m.s. keeps the weights finite when the
data carry no noise at all (a simulated ``ideal`` recording).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from plansim.kernels.layout import CHANNELS
from plansim.units import to_unit

#: flicker floor of the Allan variance per unit B²: σ_A² = (2 ln 2/π)·B² (IEEE Std 952, C.1)
FLICKER_VARIANCE = 2.0 * math.log(2.0) / math.pi
#: the smallest variance of a segment mean, relative to the channel's r.m.s. squared (noise-free data)
RELATIVE_FLOOR = 1e-12
#: a channel counts as quantised when its static values are multiples of one step to this (relative) and
#: at most this fraction of them are distinct
QUANTISATION_MATCH = 1e-6
#: … and never by more than this fraction of a step
QUANTISATION_OFF_GRID = 0.01
QUANTISATION_DISTINCT = 0.5
#: the gaps of one step may differ by at most this fraction of it where the log's printing rounded the levels
#: (:func:`quantisation_step`)
QUANTISATION_PRINTED = 5e-3
#: the drop in χ² for which the Allan fit takes a bias-instability or random-walk term (per term); calibrated by
#: simulation (tests/test_fit.py): pure white noise in 21 segments of 3000 samples gets one in 0.9 % of 1000 channels
TERM_THRESHOLD = 13.0
#: the lags searched for noise correlated from one sample to the next (:func:`noise_autocorrelation`)
CORRELATION_LAGS = 64
#: a lag counts as correlated where |ρ_k| exceeds this many standard errors 1/√(pairs); the run must start at lag
#: one, which white noise passes in 6e-5 of channels (two-sided)
CORRELATION_Z = 4.0
#: a static segment at least this long (s) is tested for settling (a warm-up) before its noise joins the Allan fit
SETTLING_MIN_DURATION = 300.0
#: it settles where the Allan variance of its first half exceeds its second half's by more than this factor at τ of
#: a sixteenth or an eighth of the half (:func:`settling_ratio`). Calibrated by simulation (docs/fitting.md): over
#: 40 000 stationary draws each of a random walk, and of Gauss–Markov noise correlated over 0.2 and 1 times the
#: segment, the worst exceeds it in 5e-5 (white noise, flicker and filtered noise stay below 25 in 5000 draws each);
#: a 0.3 °/s warm-up settling with a 300 s time constant in a 1200 s rest gives 43-55
SETTLING_RATIO = 30.0
#: the harmonics in the table angle removed from a turning segment before its scatter is taken
TURNING_HARMONICS = 2

UNITS_SI = {"gyro": {"white": "rad/s/sqrt(Hz)", "bias_instability": "rad/s", "rate_random_walk": "rad/s/sqrt(s)",
                     "mean": "rad/s"},
            "accel": {"white": "m/s^2/sqrt(Hz)", "bias_instability": "m/s^2",
                      "rate_random_walk": "m/s^2/sqrt(s)", "mean": "m/s^2"}}


def channel_kind(channel: int) -> str:
    return "gyro" if channel < 3 else "accel"


def allan_deviation(values: np.ndarray, sample_rate: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Overlapping Allan deviation of one channel's samples (rate data), octave-spaced τ up to half the record.

    Parameters
    ----------
    values : (n,) array
        Samples, in the channel's unit (rad/s, m/s²).
    sample_rate : float
        Hz.

    Returns
    -------
    tau : array
        s.
    adev : array
        σ_A(τ), the channel's unit.
    dof : array
        Equivalent degrees of freedom of σ_A²(τ) (white-noise formula of Howe, Allan & Barnes 1981:
        ν = [3(n−1)/(2m) − 2(n−2)/n]·4m²/(4m² + 5), m = τ·rate).
    """
    import allantools  # only the fit needs it: a quarter-second import

    values = np.asarray(values, dtype=float)
    n = values.size
    if n < 3:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    taus, adev, _, _ = allantools.oadev(values, rate=float(sample_rate), data_type="freq", taus="octave")
    keep = (taus * sample_rate <= n / 2) & np.isfinite(adev)
    taus, adev = np.asarray(taus)[keep], np.asarray(adev)[keep]
    m = np.rint(taus * sample_rate)
    dof = (3.0 * (n - 1) / (2.0 * m) - 2.0 * (n - 2) / n) * 4.0 * m**2 / (4.0 * m**2 + 5.0)
    return taus, adev, np.maximum(dof, 1.0)


def pooled_allan_variance(records) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Allan variance of several records of one channel, pooled at each τ.

    Parameters
    ----------
    records : iterable of (values, sample_rate)
        Each record's samples (SI) and its sample rate, Hz; see :func:`allan_deviation`.

    Returns
    -------
    tau, avar, dof : ndarray
        The τ found in any record (s, ascending), the Allan variance there averaged over the records
        weighted by their equivalent degrees of freedom, and the summed degrees of freedom; all empty
        when there is no record.
    """
    pooled: dict[float, list[float]] = {}
    for values, sample_rate in records:
        tau, adev, dof = allan_deviation(values, sample_rate)
        for t, a, d in zip(tau, adev, dof):
            entry = pooled.setdefault(round(float(t), 12), [0.0, 0.0])
            entry[0] += d * a**2
            entry[1] += d
    tau = np.array(sorted(pooled))
    dof = np.array([pooled[t][1] for t in tau])
    avar = np.array([pooled[t][0] / pooled[t][1] for t in tau])
    return tau, avar, dof


def noise_autocorrelation(records, step: float = 0.0) -> np.ndarray:
    """The correlation of a channel's noise from one sample to the next, where the data show one: ρ_1 … ρ_L.

    Each record (a static segment) is taken about its own straight line (a slow drift is not the correlation
    looked for), and the autocorrelation at lag k is pooled over the records:
    ρ_k = Σ_records Σ_i r_i r_{i+k} / Σ_records Σ_i r_i², k = 1 … :data:`CORRELATION_LAGS`. White noise gives
    ρ_k ≈ 0 with standard error 1/√(pairs at lag k); L is the number of leading lags whose |ρ_k| exceeds
    :data:`CORRELATION_Z` such errors. A sensor's own low-pass filter (a MEMS part's digital filter, a log resampled
    by its host) makes L ≥ 1; a white channel gives L = 0 (an empty array) in all but 6e-5 of channels.

    Two kinds of correlation are not a filter's, and give an empty array:

    - correlation over all :data:`CORRELATION_LAGS` lags: slow noise (a drift that is not a straight line, a bias
      instability), which the Allan fit's B and K describe;
    - a quantised channel (*step* > 0) whose samples scatter no more than half a step (as samples on two codes at
      most do): a level that wanders near a code boundary makes runs of one code then of the other, correlated
      as long as the wander is, whatever the noise before the quantiser.

    Parameters
    ----------
    records : iterable of (values, sample_rate)
        As :func:`pooled_allan_variance` takes them.
    step : float, optional
        The channel's quantisation step (0: not quantised), its unit.

    Returns
    -------
    (L,) ndarray
        ρ_1 … ρ_L, dimensionless; empty where the noise shows no correlation.
    """
    products = np.zeros(CORRELATION_LAGS + 1)
    pairs = np.zeros(CORRELATION_LAGS + 1)
    for values, _rate in records:
        x = np.asarray(values, dtype=float)
        n = x.size
        if n < 8:
            continue
        t = np.arange(n) - (n - 1) / 2.0
        r = x - x.mean() - t * (t @ x) / (t @ t)
        lags = min(CORRELATION_LAGS, n // 4)
        for k in range(lags + 1):
            products[k] += r[: n - k] @ r[k:]
            pairs[k] += n - k
    if not products[0] > 0 or (step > 0 and products[0] / pairs[0] <= (step / 2.0) ** 2):
        return np.zeros(0)
    rho = products[1:] / products[0]
    significant = (np.abs(rho) > CORRELATION_Z / np.sqrt(np.maximum(pairs[1:], 1.0))) & (pairs[1:] > 0)
    if np.all(significant):
        return np.zeros(0)
    return rho[:int(np.argmin(significant))]


def allan_model(tau, white: float, bias_instability: float, rate_random_walk: float) -> np.ndarray:
    """σ_A²(τ) = N²/τ + (2 ln 2/π)B² + K²τ/3 (IEEE Std 952, Annex C)."""
    tau = np.asarray(tau, dtype=float)
    return white**2 / tau + FLICKER_VARIANCE * bias_instability**2 + rate_random_walk**2 * tau / 3.0


def _weighted_nnls(basis: np.ndarray, avar: np.ndarray, dof: np.ndarray) -> tuple[np.ndarray, float]:
    """Non-negative weighted least squares of σ_A² on *basis*: coefficients and χ² (weights ν/(2σ_A⁴), the
    second pass with the first fit's σ_A)."""
    from scipy.optimize import nnls

    level = np.where(avar > 0, avar, np.max(avar) if np.any(avar > 0) else 1.0)
    coefficients, chi2 = np.zeros(basis.shape[1]), math.inf
    for _ in range(2):
        weight = np.sqrt(dof / 2.0) / np.maximum(level, 1e-300)
        coefficients, norm = nnls(basis * weight[:, None], avar * weight)
        chi2 = norm**2
        fitted = basis @ coefficients
        if not np.all(fitted > 0):
            break
        level = fitted
    return coefficients, chi2


def fit_allan(tau: np.ndarray, avar: np.ndarray, dof: np.ndarray,
              threshold: float | None = None, filter_term: int = 0) -> tuple[float, float, float]:
    """N, B, K ≥ 0 of :func:`allan_model` by weighted non-negative least squares on σ_A²(τ).

    White noise N is always fitted. Bias instability B and random walk K enter only where the data ask
    for them: a term is added (B, then K, then both) when it lowers the fit's χ² by more than
    *threshold* (default :data:`TERM_THRESHOLD`, calibrated by simulation to add a term to pure white noise
    in about 1 % of channels: docs/fitting.md). Otherwise a non-negative fit always finds a little B or
    K in the scatter of the long-τ points and inflates every segment mean's variance.

    *filter_term* (+1 or −1; 0: none) adds to the white noise the term ∓D/τ², D ≥ 0, that noise correlated over
    L samples has beyond them: for an autocovariance γ_k that vanishes beyond lag L, the Allan variance at
    τ = m samples, m > L, is exactly S/m − 3·Σ_k k·γ_k/m² (S = Σ_k γ_k over all lags, the white level N² per
    unit of sample rate; the expansion of the variance of two adjacent means of m samples). A low-pass filter
    (Σ k·γ_k > 0) puts σ_A² below the white slope: +1. Without the term, the fit lowers N and reads the
    difference as a B that is not there. Fit only τ beyond the correlation (:func:`noise_autocorrelation`).
    """
    threshold = TERM_THRESHOLD if threshold is None else threshold
    if filter_term not in (-1, 0, 1):
        raise ValueError(f"filter_term: expected -1, 0 or +1, got {filter_term!r}")
    tau, avar, dof = (np.asarray(x, dtype=float) for x in (tau, avar, dof))
    if tau.size == 0:
        return math.nan, math.nan, math.nan
    columns = {"N": 1.0 / tau, "B": np.full_like(tau, FLICKER_VARIANCE), "K": tau / 3.0,
               "F": -float(filter_term) / tau**2}
    base = ["N", "F"] if filter_term else ["N"]
    chosen = base
    coefficients, chi2 = _weighted_nnls(np.column_stack([columns[t] for t in base]), avar, dof)
    for extra in (["B"], ["K"], ["B", "K"]):
        trial = base + extra
        if len(tau) <= len(trial):
            continue
        c, x2 = _weighted_nnls(np.column_stack([columns[t] for t in trial]), avar, dof)
        if chi2 - x2 > threshold * (len(trial) - len(chosen)) and x2 < chi2:
            chosen, coefficients, chi2 = trial, c, x2
    values = dict(zip(chosen, coefficients))
    return tuple(float(math.sqrt(max(values.get(t, 0.0), 0.0))) for t in ("N", "B", "K"))


def settling_ratio(values: np.ndarray, sample_rate: float) -> float:
    """How much more a rest's level wanders in its first half than in its second: the largest, over τ of a
    sixteenth and an eighth of the half, of the overlapping Allan variance of the first half over the second's
    (``allantools.oadev``). Stationary noise of any kind (white, flicker, random walk, Gauss–Markov) has increments
    alike in both halves, and the ratio stays near 1 (:data:`SETTLING_RATIO` for its tail); a level that settles
    after power-on (a warm-up, a unit coming to its temperature) moves in the first half only. NaN for a record
    too short to tell (fewer than 64 samples per half)."""
    import allantools

    x = np.asarray(values, dtype=float)
    half = x.size // 2
    if half < 64:
        return math.nan
    ratios = []
    for parts in (16, 8):
        tau = (half // parts) / float(sample_rate)
        first, second = (allantools.oadev(y, rate=float(sample_rate), data_type="freq", taus=[tau])[1]
                         for y in (x[:half], x[half:2 * half]))
        if first.size and second.size and second[0] > 0:
            ratios.append(float(first[0] / second[0]) ** 2)
    return max(ratios) if ratios else math.nan


def settled_part(values: np.ndarray, sample_rate: float) -> tuple[np.ndarray, float | None]:
    """The part of a rest from where it has settled: while the record lasts at least :data:`SETTLING_MIN_DURATION`
    and its :func:`settling_ratio` exceeds :data:`SETTLING_RATIO`, its second half (tested again: a settling slower
    than the rest is long). Returns that part and the first ratio that exceeded (``None``: the record as given)."""
    x = np.asarray(values)
    first = None
    while x.size >= SETTLING_MIN_DURATION * sample_rate:
        ratio = settling_ratio(x, sample_rate)
        if not ratio > SETTLING_RATIO:
            break
        first = ratio if first is None else first
        x = x[x.size // 2:]
    return x, first


#: the Allan fit of correlated noise needs at least this many octaves beyond the correlation (N, the filter's term
#: and one more to test B or K against)
ALLAN_MIN_POINTS = 4


def fit_static_allan(records, tau: np.ndarray, avar: np.ndarray, dof: np.ndarray, step: float = 0.0,
                     correlation_records=None):
    """N, B, K of a channel from its static records' pooled Allan variance, fitted beyond the noise's correlation.

    Where the records show noise correlated over L samples (:func:`noise_autocorrelation`; *step*: the channel's
    quantisation step, 0 if none), the fit takes only
    τ ≥ m₀ samples, m₀ the smallest power of two above L, and the filter's term D/τ² (:func:`fit_allan`), which is
    exact there; elsewhere (white noise, or fewer than :data:`ALLAN_MIN_POINTS` octaves beyond the correlation)
    every τ. *correlation_records* (default *records*): the records the correlation is read from — the quiet
    static segments, where a hand's tremor in the others would read as a filter (its correlation oscillates at
    the tremor's period).

    Returns
    -------
    (N, B, K), rho, start
        :func:`fit_allan`'s outcome; ρ_1 … ρ_L (empty: white); the shortest τ fitted, s.
    """
    rho = noise_autocorrelation(records if correlation_records is None else correlation_records, step)
    if rho.size:
        rate = float(np.median([r for _x, r in records]))
        m0 = 2.0 ** math.ceil(math.log2(rho.size + 1))
        keep = tau * rate >= m0 * (1.0 - 1e-9)
        if np.count_nonzero(keep) >= ALLAN_MIN_POINTS:
            sign = 1 if float(np.arange(1, rho.size + 1) @ rho) >= 0 else -1
            return fit_allan(tau[keep], avar[keep], dof[keep], filter_term=sign), rho, float(tau[keep][0])
    return fit_allan(tau, avar, dof), rho, float(tau[0])


def quantisation_step(segments: list[np.ndarray]) -> float:
    """The step q of a quantised channel, or 0 when the data do not show one.

    Within each segment (a static one: its level does not change) the distinct values of a quantised
    channel are whole multiples of q apart and most samples repeat one of them. So q is the smallest gap
    between distinct values within any segment, accepted when every such gap is a whole multiple of it
    (to :data:`QUANTISATION_MATCH`) and at most :data:`QUANTISATION_DISTINCT` of those segments' samples
    are distinct. A channel constant within every segment (no noise at all, or noise far below the step)
    shows no step: 0. A log printed to a fixed number of decimals rounds every level: the gaps then miss whole
    multiples of the smallest one by up to the rounding, so where they do, the step is the median of the gaps of
    one step, accepted where those differ by at most :data:`QUANTISATION_PRINTED` of it and every gap of n steps is
    within (n + 1) times their spread of n steps (at most :data:`QUANTISATION_OFF_GRID`).

    Parameters
    ----------
    segments : list of (n,) arrays
        One channel's samples in each static segment.
    """
    gaps, distinct, samples = [], 0, 0
    for values in segments:
        levels = np.unique(np.asarray(values, dtype=float))
        if levels.size >= 2:
            gaps.append(np.diff(levels))
            distinct += levels.size
            samples += len(values)
    if not gaps or distinct > QUANTISATION_DISTINCT * samples:
        return 0.0
    gaps = np.concatenate(gaps)
    q = float(gaps.min())
    if q <= 0:
        return 0.0
    if _on_grid(gaps, q):
        return q
    # a log printed to a fixed number of decimals rounds each level: its gaps miss whole multiples of the step by up
    # to twice that rounding, and the smallest gap is the step less it. The gaps of one step show the rounding: the
    # step is their median, and every gap of n steps may miss n steps by (n + 1) times their spread
    one = np.rint(gaps / q) == 1
    q = float(np.median(gaps[one]))
    spread = float(np.max(np.abs(gaps[one] - q)))
    if spread > QUANTISATION_PRINTED * q:
        return 0.0
    ratio = gaps / q
    n = np.rint(ratio)
    allowance = np.minimum((n + 1.0) * spread / q + QUANTISATION_MATCH * np.maximum(ratio, 1.0),
                           QUANTISATION_OFF_GRID)
    return q if bool(np.all(np.abs(ratio - n) <= allowance)) else 0.0


def _on_grid(gaps: np.ndarray, q: float) -> bool:
    """Every one of *gaps* a whole multiple of *q* (to :data:`QUANTISATION_MATCH` relative, at most
    :data:`QUANTISATION_OFF_GRID` of a step)."""
    ratio = np.abs(np.asarray(gaps, dtype=float)) / q
    # a gap may miss a whole multiple by rounding (relative QUANTISATION_MATCH), never by a sizeable part of the
    # step: without that bound, a q far below the data's resolution (two continuous values 1e-19 apart) passes,
    # because every ratio is then huge and so is its allowance
    allowance = np.minimum(QUANTISATION_MATCH * np.maximum(ratio, 1.0), QUANTISATION_OFF_GRID)
    return bool(np.all(np.abs(ratio - np.rint(ratio)) <= allowance))


#: harmonics of the quantiser's Fourier series kept (the dropped tail of Σ 1/k² is < 1/QUANTISATION_HARMONICS)
QUANTISATION_HARMONICS = 2000


def quantisation_harmonics(step: float, sigma) -> np.ndarray:
    """Amplitudes b_k = (q/πk)·e^{−2π²k²σ²/q²}, k = 1…:data:`QUANTISATION_HARMONICS`, shape (K,) + shape(sigma).

    The mean of a quantised Gaussian signal N(μ, σ²) (step q, mid-tread) is μ + Σ_k (−1)^k b_k sin(2πkμ/q)
    (the quantiser's Fourier series; Widrow & Kollár, *Quantization Noise*, ch. 5).
    """
    sigma = np.asarray(sigma, dtype=float)
    k = np.arange(1, QUANTISATION_HARMONICS + 1).reshape((-1,) + (1,) * sigma.ndim)
    if step <= 0:
        return np.zeros(k.shape[:1] + sigma.shape)
    return step / (math.pi * k) * np.exp(-2.0 * math.pi**2 * k**2 * (sigma[None, ...] / step) ** 2)


def quantisation_error_variance(step: float, sigma) -> np.ndarray:
    """Mean square systematic error of the mean of a quantised Gaussian signal whose level is unknown within a step.

    With μ uniform over a step, the bias Σ_k (−1)^k b_k sin(2πkμ/q) (:func:`quantisation_harmonics`) has
    mean square Σ_k b_k²/2: q²/12 at σ = 0, vanishing once σ ≳ q/2 (the noise dithers the quantiser).
    """
    return 0.5 * np.sum(quantisation_harmonics(step, sigma) ** 2, axis=0)


#: the grid of σ/q over which :func:`quantised_noise_sigma` maximises the likelihood (log-spaced), and of the
#: level's position within a step (per segment, profiled out)
SIGMA_GRID = np.geomspace(0.02, 2.0, 81)
LEVEL_GRID = np.linspace(-1.0, 1.0, 401)
#: log-likelihood below its maximum still taken as consistent with the data (a 1-parameter 62 % interval's edge)
LIKELIHOOD_MARGIN = 0.5
#: a segment whose samples fall on more levels than this is dithered by its own scatter: the level-by-level
#: likelihood is not needed (and grows with the levels: a turn caught at a segment's edge spans hundreds)
MAX_LEVELS = 12


def quantised_noise_sigma(step: float, segments: list[np.ndarray]) -> float:
    """The noise σ *before* a quantiser of step q, from static segments' quantised samples, by maximum likelihood.

    Each segment's samples are taken as a constant level μ_s plus Gaussian noise N(0, σ²), then quantised: a
    sample falls on level j (a whole number of steps from the segment's first sample) with probability
    Φ((j + ½ − μ_s/q)/(σ/q)) − Φ((j − ½ − μ_s/q)/(σ/q)). The likelihood of all segments is maximised over one
    σ (a sensor's noise) with each μ_s profiled out, on the grids :data:`SIGMA_GRID` × :data:`LEVEL_GRID`
    (steps) about the segment's sample mean.

    Why not the scatter: below σ ≈ q/2 a segment's sample scatter tells where its level sits in a step rather
    than how noisy the sensor is (a level mid-step shows no scatter, one near a step's edge shows about q/2
    whatever σ), and Sheppard's correction s² − q²/12 fails there. The level-by-level likelihood has no such
    bias: a segment that never leaves its level bounds σ from above, one that toggles between two levels
    fixes it from how often.

    Where few segments toggle, the likelihood is flat below some σ (a segment sitting mid-step says only that
    σ is small): the smallest σ whose log-likelihood is within :data:`LIKELIHOOD_MARGIN` of the maximum is
    returned, the end that takes the quantiser as least dithered and its error as largest. With dithering
    noise the likelihood is sharp and this is the maximum-likelihood value.

    Returns 0.0 when no segment leaves its level (σ ≪ q: the quantiser is not dithered at all) and the
    largest grid value times q when σ ≥ 2q (the dither is then complete and the exact value no longer matters).
    """
    if not step > 0 or not segments:  # also NaN
        return 0.0
    tables = _level_tables(step, segments)
    if not tables or all(t[0].size == 1 for t in tables):
        return 0.0
    tables = _narrow(tables)
    if not tables:
        return float(SIGMA_GRID[-1] * step)
    totals = _sigma_log_likelihood(tables, profile=True)
    return float(SIGMA_GRID[np.flatnonzero(totals >= totals.max() - LIKELIHOOD_MARGIN)[0]] * step)


#: posterior weights below this fraction of the total are dropped (and the rest renormalised)
POSTERIOR_CUTOFF = 1e-6
#: the spread of a stated noise (a data sheet's typical figure) as a prior of σ: log-normal, this standard
#: deviation in ln σ (a factor of 2 at one standard deviation)
STATED_NOISE_LOG_SD = math.log(2.0)


def quantised_noise_posterior(step: float, segments: list[np.ndarray],
                              stated_sigma: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """What the static segments' level counts say of the noise σ before a quantiser of step q: σ values (SI) and
    their posterior weights, on :data:`SIGMA_GRID`·q.

    The model of :func:`quantised_noise_sigma`, with each segment's level integrated out (uniform over
    ±1 step about its sample mean, :data:`LEVEL_GRID`) instead of profiled, and a prior uniform in log σ over the
    grid (σ from 0.02q to 2q: a scale parameter, and the range over which the quantiser goes from not dithered
    to fully dithered), or, with *stated_sigma* (the per-sample σ a data sheet's noise density gives, N·√f_s),
    log-normal about it with :data:`STATED_NOISE_LOG_SD` on the same grid. Weights below
    :data:`POSTERIOR_CUTOFF` are dropped.

    Why not the point estimate: with few segments toggling between levels, σ is poorly determined (on 24 static
    segments of 3000 samples at σ = 0.052q its maximum-likelihood value ranges over 0.036–0.106q), and the
    error of a segment that never leaves its level is a steep function of σ (the larger σ, the further from an
    edge its level must sit). Plugged in, the estimate understates the mean square error of such segments by
    about 27 % there; averaged over this posterior the stated and the actual agree to 1 %
    (tests/test_fit.py).

    Returns ``(array([0.0]), array([1.0]))`` where there is no step or no static segment with two samples (the
    channel taken as not quantised, or not dithered at all) and ``(array([2q]), array([1.0]))`` when every
    segment falls on more than :data:`MAX_LEVELS` levels (dithered beyond the grid).
    """
    if not step > 0 or not segments:  # also NaN
        return np.zeros(1), np.ones(1)
    tables = _level_tables(step, segments)
    if not tables:
        return np.zeros(1), np.ones(1)
    tables = _narrow(tables)
    if not tables:
        return np.array([SIGMA_GRID[-1] * step]), np.ones(1)
    totals = _sigma_log_likelihood(tables, profile=False)
    if stated_sigma is not None and stated_sigma > 0 and math.isfinite(stated_sigma):
        totals = totals - 0.5 * (np.log(SIGMA_GRID * step / stated_sigma) / STATED_NOISE_LOG_SD) ** 2
    weights = np.exp(totals - totals.max())
    weights /= weights.sum()
    keep = weights >= POSTERIOR_CUTOFF
    return SIGMA_GRID[keep] * step, weights[keep] / weights[keep].sum()


def _level_tables(step: float, segments: list[np.ndarray]) -> list:
    """The level tables (:func:`_level_table`) of the segments with two samples or more that have one."""
    tables = [_level_table(values, step) for values in segments if np.asarray(values).size >= 2]
    return [t for t in tables if t is not None]


def _narrow(tables: list) -> list:
    """The tables over at most :data:`MAX_LEVELS` levels. A segment over more is dithered beyond the grid (or not
    static at all: a turn caught at its edge, a hand's tremor); it says nothing about a σ below q and would only
    cost time."""
    return [t for t in tables if t[0].size <= MAX_LEVELS]


def _sigma_log_likelihood(tables: list, profile: bool) -> np.ndarray:
    """The log-likelihood of every segment's level counts at each σ of :data:`SIGMA_GRID`, each segment's level
    profiled out (its maximum over :data:`LEVEL_GRID`) or integrated out (the mean over it, a uniform prior)."""
    width = max(t[0].size for t in tables)
    levels = np.zeros((len(tables), width))
    counts = np.zeros((len(tables), width))
    centres = np.array([t[2] for t in tables])
    for k, (lv, ct, _) in enumerate(tables):
        levels[k, : lv.size] = lv
        counts[k, : ct.size] = ct
    m = centres[:, None] + LEVEL_GRID[None, :]  # (S, M) candidate levels, steps
    totals = np.empty(SIGMA_GRID.size)
    for i, r in enumerate(SIGMA_GRID):
        log_l = _log_likelihood(levels, counts, m, r)
        top = np.max(log_l, axis=1)
        if profile:
            totals[i] = np.sum(top)
        else:
            totals[i] = np.sum(top + np.log(np.mean(np.exp(log_l - top[:, None]), axis=1)))
    return totals


#: a segment spanning more steps than this (or holding a non-finite sample) has no level table: its steps
#: would not fit an integer, and it is spread over far more than :data:`MAX_LEVELS` levels anyway
MAX_SPAN_STEPS = 2.0**40


def _level_table(values, step: float) -> tuple[np.ndarray, np.ndarray, float] | None:
    """(levels, counts, mean) of a segment's samples in whole steps from its first sample; None when the
    segment spans more than :data:`MAX_SPAN_STEPS` steps or holds a non-finite sample."""
    values = np.asarray(values, dtype=float)
    steps = (values - values[0]) / step
    if not np.all(np.isfinite(steps)) or np.max(np.abs(steps)) > MAX_SPAN_STEPS:
        return None
    j = np.rint(steps).astype(np.int64)
    levels, counts = np.unique(j, return_counts=True)
    return levels.astype(float), counts.astype(float), float(np.mean(j))


def _log_likelihood(levels: np.ndarray, counts: np.ndarray, m: np.ndarray, r: float) -> np.ndarray:
    """(S, M) log-likelihood of each segment's level counts (S, L) at true levels m (S, M), steps, noise σ/q = r."""
    from scipy.special import log_ndtr, ndtr

    upper = (levels[:, None, :] + 0.5 - m[:, :, None]) / r
    lower = (levels[:, None, :] - 0.5 - m[:, :, None]) / r
    # log(Φ(u) − Φ(l)) stably: on the upper tail use the mirrored form
    p = np.where(lower > 0, ndtr(-lower) - ndtr(-upper), ndtr(upper) - ndtr(lower))
    with np.errstate(divide="ignore"):
        logp = np.where(p > 0, np.log(np.maximum(p, 1e-300)), log_ndtr(-np.abs(lower)) - 700.0)
    return np.sum(counts[:, None, :] * logp, axis=2)


#: the grid of a segment's true level (steps, about its sample mean) for :func:`quantisation_error_given_levels`
POSTERIOR_GRID = np.linspace(-1.0, 1.0, 801)


def quantisation_error_given_levels(step: float, values, sigma, weights=None, pooled=None) -> float:
    """Mean square error of a static segment's sample mean as its true level, given how its samples fall on the
    quantiser's levels: E[(x̄ − μ)² | the level counts], μ uniform a priori, noise σ before the quantiser.

    The likelihood of the counts at each candidate level μ (:func:`quantised_noise_sigma`'s model) is the
    posterior of μ on :data:`POSTERIOR_GRID`. A segment that never leaves its level leaves μ anywhere in the
    step but within a few σ of its edges, and the error is about q²/12; one that toggles between two levels
    places μ near the edge to within about σ/√n, and its mean is nearly exact. The average over segments is the
    unconditional Σ_k b_k²/2 (:func:`quantisation_error_variance`); per segment, this is what the data say.

    Parameters
    ----------
    step : float
        q.
    values : (n,) array
        The segment's samples of one channel.
    sigma : float or (G,) array
        The noise σ before the quantiser, or the values of its posterior (:func:`quantised_noise_posterior`).
    weights : (G,) array, optional
        The posterior weights of *sigma*: the error is then averaged over them.
    pooled : (N,) array, optional
        The samples of every segment at the same level as this one (this one's included: the same setting,
        :func:`level_clusters`): the level's posterior is then taken from all their counts, and the error is
        that of this segment's own mean.
    """
    sigmas = np.atleast_1d(np.asarray(sigma, dtype=float))
    weights = np.ones(1) if weights is None else np.atleast_1d(np.asarray(weights, dtype=float))
    if sigmas.shape != weights.shape:
        raise ValueError(f"sigma {sigmas.shape} and weights {weights.shape}: expected the same shape")
    if not step > 0:  # also NaN
        return 0.0
    evidence = values if pooled is None else pooled
    table = _level_table(evidence, step)  # once, whatever the number of σ
    if table is None or table[0].size > MAX_LEVELS:  # spread over many levels: dithered by its own scatter (Sheppard)
        own = math.sqrt(max(float(np.var(np.asarray(values, dtype=float), ddof=1)) - step**2 / 12.0, 0.0))
        errors = [float(quantisation_error_variance(step, max(own, r))) for r in sigmas]
    else:
        levels, counts, centre = table
        # this segment's mean, in steps from the evidence's first sample (the table's own mean without pooling)
        mean = centre if pooled is None else float((np.mean(np.asarray(values, dtype=float)) - evidence[0]) / step)
        m = centre + POSTERIOR_GRID[None, :]
        errors = []
        for r in sigmas:
            log_l = _log_likelihood(levels[None, :], counts[None, :], m, max(r / step, float(SIGMA_GRID[0])))[0]
            posterior = np.exp(log_l - log_l.max())
            errors.append(float(np.sum(posterior * (mean - m[0]) ** 2) / np.sum(posterior) * step**2))
    return float(sum(w * e for w, e in zip(weights, errors)) / np.sum(weights))


def level_clusters(segment_samples: list[np.ndarray], segments, indices, channel: int, step: float) -> list[list[int]]:
    """The static segments (*indices*) of one channel that read one level: the same nominal input to the channel
    and sample means within a step of each other.

    The same nominal input: the same up-axis and temperature, a known orientation, and for a gyro also the same
    heading (the Earth rate turns with it); for an accelerometer the heading does not matter (gravity is along
    the up-axis whatever it is: the two headings of the 12 positions of JJF 2003 Appendix C read one level).
    Within such a setting, segments whose means lie more than a step apart are split (a drift, a table that did
    not return to the same place): each cluster is sorted by mean and cut where neighbours differ by more than q.
    A segment on its own is a cluster of one.
    """
    gyro = channel < 3
    settings: dict[tuple, list[int]] = {}
    for k in indices:
        s = segments[k]
        if s.orientation != "known" or (gyro and not math.isfinite(s.heading)):
            key = ("alone", k)
        else:
            key = (s.up, float(s.temperature)) + ((round(float(s.heading), 9),) if gyro else ())
        settings.setdefault(key, []).append(k)
    clusters = []
    for members in settings.values():
        means = sorted((float(np.mean(segment_samples[k][:, channel])), k) for k in members)
        current = [means[0][1]]
        for (previous, _), (mean, k) in zip(means, means[1:]):
            if not (step > 0 and abs(mean - previous) <= step):
                clusters.append(current)
                current = []
            current.append(k)
        clusters.append(current)
    return clusters


def dither_for_error(step: float, mean_square: float) -> float:
    """The σ at which :func:`quantisation_error_variance` equals *mean_square* (0 at ≥ q²/12): the harmonics of
    the quantiser's error that a conditional error (:func:`quantisation_error_given_levels`) stands for."""
    if step <= 0 or mean_square >= step**2 / 12.0:
        return 0.0
    ratios, table = _dither_table()  # the mean square over q², decreasing in σ/q
    return float(np.interp(mean_square / step**2, table[::-1], ratios[::-1]) * step)


@functools.lru_cache(maxsize=1)
def _dither_table() -> tuple[np.ndarray, np.ndarray]:
    """σ/q on a grid of 801 from 0 to 2 and :func:`quantisation_error_variance` there for q = 1: the error scales
    with q², so one table serves every step (it was computed anew for each segment: 2000 harmonics × 801)."""
    ratios = np.linspace(0.0, 2.0, 801)
    table = quantisation_error_variance(1.0, ratios)
    ratios.setflags(write=False)
    table.setflags(write=False)
    return ratios, table


@dataclass(frozen=True)
class ChannelNoise:
    """The noise of one channel, SI (see :data:`UNITS_SI`)."""

    channel: str
    white: float  # N: rad/s/√Hz (= rad/√s) or m/s²/√Hz
    bias_instability: float  # B: rad/s or m/s²
    rate_random_walk: float  # K: rad/s/√s or m/s²/√s
    quantisation_step: float  # q, the channel's unit; 0: not quantised
    static_segments: int
    static_samples: int
    tau: np.ndarray = field(repr=False)
    adev: np.ndarray = field(repr=False)
    dof: np.ndarray = field(repr=False)
    #: ρ_1 … ρ_L of the static noise where it is correlated from sample to sample (:func:`noise_autocorrelation`)
    autocorrelation: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    #: the shortest τ the Allan fit took, s (:func:`fit_static_allan`)
    allan_start: float = math.nan

    @property
    def kind(self) -> str:
        return channel_kind(CHANNELS.index(self.channel))

    def units(self) -> dict[str, str]:
        return UNITS_SI[self.kind]


@dataclass(frozen=True)
class NoiseEstimate:
    """:func:`estimate_noise`'s outcome for the segments it was given (S of them)."""

    channels: tuple[ChannelNoise, ...]
    within_std: np.ndarray  # (S, 6) scatter of the samples within each segment
    mean_variance: np.ndarray  # (S, 6) variance of each segment mean from the noise model
    mean_variance_dof: np.ndarray  # (S, 6) its degrees of freedom (inf: known exactly)
    quantisation_variance: np.ndarray  # (S, 6) the part of mean_variance due to a non-dithered quantiser
    quantisation_sigma: np.ndarray  # (S, 6) the noise σ per sample before the quantiser (dithering it)
    notes: tuple[str, ...] = ()
    #: (S, 6) the mean square quantisation error of each segment mean over a level unknown within its step, before
    #: its counts are looked at (σ averaged over its posterior): what the error's size is independently of where
    #: this recording's levels happen to fall (plansim.fit.joint takes the uncertainty of the levels from it)
    quantisation_prior_variance: np.ndarray | None = None

    def subset(self, rows) -> NoiseEstimate:
        """The same estimate for the segments *rows* (indices into the S given), in that order."""
        return NoiseEstimate(self.channels, self.within_std[rows], self.mean_variance[rows],
                             self.mean_variance_dof[rows], self.quantisation_variance[rows],
                             self.quantisation_sigma[rows], self.notes,
                             None if self.quantisation_prior_variance is None
                             else self.quantisation_prior_variance[rows])


def turning_design(n: int, rate: float, sample_rate: float) -> np.ndarray:
    """(n, 1 + 2·TURNING_HARMONICS) columns 1, cos hθ, sin hθ (h = 1 … TURNING_HARMONICS) of a turning segment's
    angle θ = rate·t: the table's own harmonics (a tilt of its axis turns gravity and the Earth rate with it,
    wobble, the rate's once-per-turn error)."""
    angle = rate * np.arange(n) / sample_rate
    columns = [np.ones(n)]
    for h in range(1, TURNING_HARMONICS + 1):
        columns += [np.cos(h * angle), np.sin(h * angle)]
    return np.column_stack(columns)


@functools.lru_cache(maxsize=64)
def _turning_basis(n: int, rate: float, sample_rate: float) -> np.ndarray:
    """An orthonormal basis (n, rank) of :func:`turning_design`'s columns (SVD, rank to 1e-10 of the largest
    singular value), kept for the null draws of the same segment (``plansim diagnose``'s within tests fit
    thousands of draws of one turning segment)."""
    u, s, _ = np.linalg.svd(turning_design(n, rate, sample_rate), full_matrices=False)
    basis = u[:, s > 1e-10 * s.max()]
    basis.setflags(write=False)
    return basis


def turning_residuals(values: np.ndarray, rate: float, sample_rate: float) -> np.ndarray:
    """A turning segment's samples (n, …) less their least-squares fit by :func:`turning_design` (n > its columns):
    the projection onto the orthogonal complement of the design's columns."""
    values = np.asarray(values, dtype=float)
    basis = _turning_basis(values.shape[0], float(rate), float(sample_rate))
    flat = values.reshape(values.shape[0], -1)
    return (flat - basis @ (basis.T @ flat)).reshape(values.shape)


def _turning_scatter(values: np.ndarray, rate: float, sample_rate: float) -> tuple[np.ndarray, int, np.ndarray]:
    """Scatter (6,) of a turning segment's samples about a degree-2 trigonometric polynomial in the angle
    (:func:`turning_design`), its degrees of freedom, and the polynomial's r.m.s. (6,) about its mean: how far the
    signal itself sweeps the quantiser's levels (0 for a segment too short to fit it)."""
    n = values.shape[0]
    columns = 1 + 2 * TURNING_HARMONICS
    if n <= columns + 1:
        return (np.std(values, axis=0, ddof=1) if n > 1 else np.zeros(6)), max(n - 1, 1), np.zeros(values.shape[1])
    residual = turning_residuals(values, rate, sample_rate)
    dof = n - columns
    return np.sqrt(np.sum(residual**2, axis=0) / dof), dof, np.std(values - residual, axis=0)


def stated_steps(scenario) -> np.ndarray:
    """(6,) the quantisation step a scenario's ``[acquisition]`` states for gx gy gz ax ay az, SI (2·full
    scale/2^bits; 0 where it quantises nothing)."""
    a = scenario.acquisition
    return np.array([a.gyro_step] * 3 + [a.accel_step] * 3, dtype=float)


def stated_white_noise(scenario) -> np.ndarray:
    """(6,) the white-noise densities a scenario states for gx gy gz ax ay az (its ``[mimu.noise]`` angle and
    velocity random walks: rad/s/√Hz, m/s²/√Hz), NaN where it states none (0): :func:`estimate_noise`'s
    *stated_white*."""
    noise = scenario.noise
    stated = np.concatenate([np.broadcast_to(noise.gyro_angle_random_walk, 3),
                             np.broadcast_to(noise.accel_velocity_random_walk, 3)]).astype(float)
    return np.where(stated > 0, stated, np.nan)


def allan_slow_variance(channel: ChannelNoise, duration: float) -> float:
    """The variance that a channel's slow noise, as its Allan fit gives it, adds to the mean of a segment of
    *duration* s: (2 ln 2/π)·B² + K²·T/3 (the bias-instability floor and the rate random walk over the segment;
    IEEE Std 952-1997 Annex C); 0 where the channel's noise was not estimated."""
    if math.isnan(channel.white):
        return 0.0
    return float(np.nan_to_num(FLICKER_VARIANCE * channel.bias_instability**2
                               + channel.rate_random_walk**2 * duration / 3.0))


@dataclass(frozen=True)
class StatedSlowNoise:
    """The slow noise a lab states for its unit (a scenario's ``[mimu.noise]``), per channel gx gy gz ax ay az, SI,
    as plansim simulates it: a first-order Gauss–Markov bias instability (stationary σ from the stated B,
    :func:`plansim.simulate.arguments.bias_instability_sigma`, correlation time ``correlation_time``), a
    Gauss–Markov drift (σ, ``markov_correlation_time``) and a rate random walk K from the recording's start."""

    bias_instability_sigma: np.ndarray  # (6,) rad/s, m/s²
    correlation_time: float  # s
    markov_sigma: np.ndarray  # (6,) rad/s, m/s²
    markov_correlation_time: float  # s
    rate_random_walk: np.ndarray  # (6,) rad/s/√s, m/s²/√s
    source: str = ""

    def mean_covariance(self, c: int, times: np.ndarray, durations: np.ndarray) -> np.ndarray:
        """(S, S) covariance of channel *c*'s stated slow noise averaged over segments of *durations* (s) centred at
        *times* (s from the recording's start; segments that do not overlap). A Gauss–Markov process of σ, τ averaged
        over T: variance σ²·2(τ/T)²(T/τ − 1 + e^{−T/τ}), and between two segments σ²·e^{−|Δt|/τ}·g(T_s)·g(T_r),
        g(T) = sinh(T/2τ)/(T/2τ); a random walk K·W(t): K²·(t_s − T_s/2 + T_s/3) on the diagonal and K² times the
        earlier segment's middle time off it."""
        t = np.asarray(times, dtype=float)
        T = np.maximum(np.asarray(durations, dtype=float), 1e-12)
        out = np.zeros((t.size, t.size))
        for sigma, tau in ((self.bias_instability_sigma[c], self.correlation_time),
                           (self.markov_sigma[c], self.markov_correlation_time)):
            if not sigma > 0 or not tau > 0:
                continue
            x = T / tau
            g = np.where(x > 1e-6, np.sinh(0.5 * x) / np.maximum(0.5 * x, 1e-300), 1.0)
            block = np.exp(-np.abs(t[:, None] - t[None, :]) / tau) * np.outer(g, g)
            np.fill_diagonal(block, np.where(x > 1e-6, 2.0 * (x - 1.0 + np.exp(-x)) / np.maximum(x, 1e-300) ** 2,
                                             1.0))
            out += sigma**2 * block
        K = self.rate_random_walk[c]
        if K > 0:
            earlier = np.minimum(t[:, None], t[None, :])
            out += K**2 * earlier
            out[np.diag_indices(t.size)] += K**2 * (-T / 2.0 + T / 3.0)
        return out

    def describe(self, c: int) -> str:
        """The statement for channel *c* in words (deg/h or µg; the random walk in SI)."""
        kind, unit = ("angular_rate", "deg/h") if channel_kind(c) == "gyro" else ("acceleration", "ug")
        parts = [f"{what} σ {float(to_unit(sigma, kind, unit)):.3g} {unit} over {tau:g} s"
                 for what, sigma, tau in (("bias instability", self.bias_instability_sigma[c], self.correlation_time),
                                          ("drift", self.markov_sigma[c], self.markov_correlation_time)) if sigma > 0]
        if self.rate_random_walk[c] > 0:
            parts.append(f"random walk {self.rate_random_walk[c]:.3g} {UNITS_SI[channel_kind(c)]['rate_random_walk']}")
        return ", ".join(parts) if parts else "no slow noise"


def stated_slow_noise(scenario) -> StatedSlowNoise:
    """The slow noise *scenario* states for its unit (:class:`StatedSlowNoise`; zeros where it states none)."""
    from plansim.simulate.arguments import bias_instability_sigma

    n = scenario.noise

    def both(gyro, accel) -> np.ndarray:
        return np.concatenate([np.broadcast_to(gyro, 3), np.broadcast_to(accel, 3)]).astype(float)

    return StatedSlowNoise(bias_instability_sigma(both(n.gyro_bias_instability, n.accel_bias_instability)),
                           float(n.bias_instability_correlation_time),
                           both(n.gyro_markov_sigma, n.accel_markov_sigma), float(n.markov_correlation_time),
                           both(n.gyro_rate_random_walk, n.accel_acceleration_random_walk),
                           source=f"scenario {scenario.name!r}, [mimu.noise]")


#: a static segment whose scatter exceeds the others' at this upper-tail probability (F test, forward search) is
#: "noisier than the others": a pose held by hand, a knock; its mean takes its own scatter (:func:`estimate_noise`)
NOISIER_PROBABILITY = 1e-3


def _noisier_segments(within: np.ndarray, within_dof: np.ndarray, static: list[int], step: float) -> list[int]:
    """The static segments whose per-sample scatter exceeds that of the channel's quiet ones: a forward search
    (Atkinson and Riani, *Robust Diagnostic Regression Analysis*, 2000). Ordered by scatter, the segments join a
    pool one by one from the quietest; each must pass the F test against the pool so far (s²/s²_pool at most the
    1 − :data:`NOISIER_PROBABILITY` quantile of F(ν, ν_pool), ν = samples − 1); the first that fails, and every
    noisier one after it, are flagged. A pool grown from the quietest end is not inflated by the shaking
    segments it is to find, however many of them there are (a hand may hold all but one pose).
    Not for a channel quantised to about its noise (scatter < 2 steps): there the scatter says where a level sits
    in its step, not how noisy the segment is."""
    from scipy.stats import f as f_distribution

    usable = [k for k in static if within_dof[k] >= 2 and not (step > 0 and within[k] < 2.0 * step)]
    if len(usable) < 3:
        return []
    order = sorted(usable, key=lambda k: within[k])
    pool_ss, pool_dof = within[order[0]] ** 2 * within_dof[order[0]], within_dof[order[0]]
    for n, k in enumerate(order[1:], start=1):
        ratio = 0.0 if within[k] == 0 else (within[k] ** 2 / (pool_ss / pool_dof) if pool_ss > 0 else math.inf)
        if ratio > f_distribution.ppf(1.0 - NOISIER_PROBABILITY, within_dof[k], pool_dof):
            return sorted(order[n:])
        pool_ss += within[k] ** 2 * within_dof[k]
        pool_dof += within_dof[k]
    return []


def estimate_noise(segment_samples: list[np.ndarray], segments, stated_white=None, stated_step=None,
                   noisier: bool = True, conditional: bool = True) -> NoiseEstimate:
    """The noise of each channel and the variance of each segment mean, from the samples alone.

    Parameters
    ----------
    segment_samples : list of (n_s, 6) arrays
        Each segment's samples, SI.
    segments : sequence of Segment
        The same segments (their rate and sample rate).
    stated_white : (6,) array_like, optional
        The white-noise density each channel is stated to have (a data sheet's angle and velocity random walk:
        rad/s/√Hz, m/s²/√Hz; NaN where not stated). Used only where the data cannot show it: as the prior of
        the noise before a quantiser the noise does not dither (:func:`quantised_noise_posterior`).
    stated_step : (6,) array_like, optional
        The acquisition's stated quantisation step of each channel, SI (a lab's ADC: 2·full scale/2^bits; 0 or NaN
        where not stated). Used only for a channel that does not vary within any static segment and whose step
        no sibling channel shows, when its levels are whole multiples of it apart: read as exact
        there, its segment means would make every parameter that depends on it look exact (jjf2003's 12-bit
        accelerometers, σ 0.05 of a step: in one null recording of about 140, all three read one code in each of
        their 18 poses, on three levels only, and K_a,zz came out with u = 1.4e-10 against an error of 7e-4).

    noisier : bool
        Give the static segments that scatter more than the channel's quiet ones their own scatter and leave them
        out of the Allan fit (:func:`_noisier_segments`; default). ``plansim diagnose`` turns it off: there such a
        segment is a finding of the within-segment tests, and its mean is tested as any other's (a segment a turn
        spilled into is off, not merely noisy; weighed by its own scatter it left the rest to catalogue names).
    conditional : bool
        A static segment's quantisation error given where its samples fall
        (:func:`quantisation_error_given_levels`; default), or, with False, over a level unknown within a step:
        :func:`quantisation_error_variance` at the noise σ its scatter shows less q²/12 (Sheppard), q²/12 for a
        segment that never leaves its code (the resolution of a digital reading, JCGM 100 F.2.2.1). ``plansim
        diagnose`` takes the latter: its tests need a null that holds whatever the level's place in its step,
        and the conditional error leans on a σ the level counts barely identify (docs/fitting.md) — on 40 null
        recordings of jjf2003 it left the K2 and g² efficient scores' mean square at 1.6–1.7 and 1.3 instead of 1.

    Returns
    -------
    NoiseEstimate
    """
    return estimate_noise_models(segment_samples, segments, stated_white, stated_step, noisier, (conditional,))[0]


def estimate_noise_models(segment_samples: list[np.ndarray], segments, stated_white=None, stated_step=None,
                          noisier: bool = True, conditionals=(True, False)) -> tuple[NoiseEstimate, ...]:
    """:func:`estimate_noise` under each static quantisation model in *conditionals* (``conditional`` =
    True/False there), from one pass over the samples: the channels' noise, the scatter and the level counts are
    the samples', whatever the model of a static mean's quantisation error. ``plansim diagnose`` takes both (its
    candidates' tests under the one, its lack of fit under the other).

    Returns
    -------
    tuple of NoiseEstimate
        One per entry of *conditionals*, in its order; they share ``channels`` and ``within_std``.
    """
    conditionals = tuple(conditionals)
    if not conditionals or not all(isinstance(c, (bool, np.bool_)) for c in conditionals):
        raise TypeError(f"conditionals = {conditionals!r}: expected one or more bools (True: a static mean's "
                        "quantisation error given its level counts; False: over a level unknown within its step)")
    stated_q = np.zeros(6) if stated_step is None else np.nan_to_num(np.asarray(stated_step, dtype=float), nan=0.0)
    if stated_q.shape != (6,) or np.any(stated_q < 0):
        raise ValueError(f"stated_step: expected 6 steps >= 0 (gx gy gz ax ay az, SI; 0 or NaN: not stated), got "
                         f"{stated_step!r}")
    S = len(segments)
    if S != len(segment_samples):
        raise ValueError(f"segment_samples: {len(segment_samples)} segments, segments: {S}")
    static = [k for k, s in enumerate(segments) if not s.is_rotating and segment_samples[k].shape[0] >= 3]
    notes = []
    within = np.zeros((S, 6))
    within_dof = np.zeros(S)
    sweep = np.zeros((S, 6))
    for k, (s, x) in enumerate(zip(segments, segment_samples)):
        if s.is_rotating and s.rate_known:
            within[k], within_dof[k], sweep[k] = _turning_scatter(x, s.rate, s.sample_rate)
        elif x.shape[0] > 1:
            within[k], within_dof[k] = np.std(x, axis=0, ddof=1), x.shape[0] - 1
    everything = np.concatenate(segment_samples, axis=0)
    rms = np.sqrt(np.mean(everything**2, axis=0))
    steps = [quantisation_step([segment_samples[k][:, c] for k in static]) for c in range(6)]
    found = list(steps)  # the steps the data show within segments
    for c in range(6):  # a channel constant within every segment may share its sibling channels' quantiser
        if steps[c] == 0.0 and static and all(np.ptp(segment_samples[k][:, c]) == 0 for k in static):
            kind = range(0, 3) if c < 3 else range(3, 6)
            levels = np.array([segment_samples[k][0, c] for k in static])  # the one value of each static segment
            for q in sorted({found[j] for j in kind if found[j] > 0}):
                codes = levels / q
                if np.all(np.abs(codes - np.rint(codes)) <= QUANTISATION_MATCH * np.maximum(np.abs(codes), 1.0)):
                    steps[c] = q
                    notes.append(f"{CHANNELS[c]} does not vary within any static segment; its levels are whole "
                                 f"multiples of the step {q:.6g} found on its sibling channels: taken as quantised "
                                 "by the same acquisition")
                    break
            else:
                # the levels alone cannot tell a step: noise-free levels of a unit with round parameters sit on a
                # grid too (the 'ideal' scenario's accelerometers: multiples of g·1e-4 to 1e-6 of their gaps)
                if stated_q[c] > 0 and _on_grid(levels - levels[0], stated_q[c]):
                    steps[c] = stated_q[c]
                    notes.append(f"{CHANNELS[c]} does not vary within any static segment, and its levels are whole "
                                 f"multiples of the acquisition's stated step {stated_q[c]:.6g} apart: taken as "
                                 "quantised with it, its noise far below it (each segment mean off by up to half a "
                                 "step)")
                else:
                    notes.append(f"{CHANNELS[c]} does not vary within any static segment: no noise (or noise far "
                                 "below a quantisation step it does not show); its segment means weigh as exact — "
                                 "if the unit is quantised, state its acquisition (plansim fit --scenario), or "
                                 "every parameter that depends on this channel looks exact")
    channels = []
    shaken = np.zeros((S, 6), dtype=bool)  # a static segment that scatters more than the channel's others
    for c, name in enumerate(CHANNELS):
        step = steps[c]
        # the Allan deviation of the static segments, without those that scatter more than the channel's quiet ones
        noisier_ones = _noisier_segments(within[:, c], within_dof, static, step)
        flagged = noisier_ones if noisier else []
        pooled_from = [k for k in static if k not in flagged]
        records = [(segment_samples[k][:, c], segments[k].sample_rate) for k in pooled_from]
        for i, k in enumerate(pooled_from):  # a long rest that settles (a warm-up): its noise from where it has settled
            x, rate_k = records[i]
            settled, first = settled_part(x, rate_k)
            if first is not None:
                records[i] = (settled, rate_k)
                notes.append(f"{name}: static segment {k} ({segments[k].label}) settles: its level wanders "
                             f"{first:.3g} times as much in its first half as in its second (Allan variance at a "
                             "sixteenth or an eighth of the half; a warm-up, a unit coming to its temperature): its "
                             f"noise is taken from its last {settled.size / rate_k:.4g} s, and its mean holds the "
                             "settling (docs/fitting.md)")
        tau, avar, dof = pooled_allan_variance(records)
        rho, start = np.zeros(0), math.nan
        if tau.size:
            # the sensor's filter is seen in the quiet segments: a hand's tremor in the others is not the sensor's
            quiet_records = [(segment_samples[k][:, c], segments[k].sample_rate) for k in static
                             if k not in noisier_ones]
            (white, bias_instability, random_walk), rho, start = fit_static_allan(records, tau, avar, dof, step,
                                                                                   quiet_records)
            if rho.size:
                rate_k = float(np.median([r for _x, r in records]))
                notes.append(f"{name}: its noise is correlated over {rho.size} sample(s) (lag-one autocorrelation "
                             f"{rho[0]:.2f}: the sensor's own filter, or a log resampled by its host): the Allan fit "
                             f"starts at tau = {start:.4g} s ({start * rate_k:.0f} samples), with the filter's term "
                             "(docs/fitting.md)" if start > tau[0] else
                             f"{name}: its noise is correlated over {rho.size} sample(s) (lag-one autocorrelation "
                             f"{rho[0]:.2f}), but too few octaves of the Allan deviation lie beyond it: fitted from "
                             "one sample, where a filter reads as bias instability (docs/fitting.md)")
        else:
            tau = avar = dof = np.zeros(0)
            white = bias_instability = random_walk = math.nan
        shaken[flagged, c] = True
        channels.append(ChannelNoise(name, white, bias_instability, random_walk, step, len(pooled_from),
                                     int(sum(segment_samples[k].shape[0] for k in pooled_from)), tau,
                                     np.sqrt(avar), dof, rho, start))
        if flagged:
            quiet = math.sqrt(sum(within[k, c] ** 2 * within_dof[k] for k in pooled_from)
                              / sum(within_dof[k] for k in pooled_from))
            times = f"{max(within[flagged, c]) / quiet:.3g} times" if quiet > 0 else "more than"
            notes.append(f"{name}: {len(flagged)} static segment(s) scatter more than the channel's others (F test at "
                         f"{NOISIER_PROBABILITY:g}; up to {times} the quiet ones' scatter: a unit held by hand, a "
                         "knock): their means take their own scatter, and the Allan deviation is taken without them")
    if not static:
        notes.append("no static segment: white noise from the within-segment scatter only; bias instability and "
                     "random walk not estimated (NaN)")

    # what the static segments' level counts say of each quantised channel's noise before the quantiser
    stated = np.full(6, math.nan) if stated_white is None else np.asarray(stated_white, dtype=float)
    if stated.shape != (6,):
        raise ValueError(f"stated_white: expected 6 values (gx gy gz ax ay az), got shape {stated.shape}")
    rate = float(np.median([segments[k].sample_rate for k in static])) if static else math.nan
    # segments at one setting read one level: they are one draw of where a level sits in a step, not several (the
    # σ likelihood counts how many levels toggle), and their pooled counts place that level
    clusters = [level_clusters(segment_samples, segments, static, c, ch.quantisation_step)
                if ch.quantisation_step > 0 and static else [] for c, ch in enumerate(channels)]
    pooled = [{k: np.concatenate([segment_samples[r][:, c] for r in cluster]) for cluster in clusters[c]
               for k in cluster} for c in range(6)]
    # (needed only for the error given the level counts: the one costly step, 0.35 s of 0.6 s on jjf2003)
    sigma_before = [quantised_noise_posterior(ch.quantisation_step, [pooled[c][cluster[0]] for cluster in clusters[c]],
                                              stated[c] * math.sqrt(rate) if np.isfinite(stated[c]) else None)
                    if ch.quantisation_step > 0 and static and any(conditionals) else None
                    for c, ch in enumerate(channels)]
    shared = _Shared(segment_samples, segments, tuple(channels), within, within_dof, shaken, rms, static,
                     sigma_before, pooled, tuple(notes), sweep)
    return tuple(_mean_variance(shared, bool(c)) for c in conditionals)


def _turning_dither(shared, k: int, c: int, sigmas: np.ndarray) -> np.ndarray:
    """The noise before the quantiser of turning segment *k*, accelerometer channel *c*, for each σ of the static
    segments' posterior: that σ with the segment's sweep (the trigonometric polynomial in the table angle, e.g.
    gravity turned by the platform's tilt) added in quadrature; and, where the samples fall on three levels or
    more, at least the scatter less q²/12 (Sheppard). Samples on one or two levels say nothing of a σ below q/2:
    a level that sits near a step's edge toggles between two codes with a scatter up to q/2 whatever σ, and
    Sheppard's correction would read that as dither. (A gyro's is not taken so: the table's rate jitter is noise
    before its quantiser that the static segments do not show. Taken so, on `coarse_quantisation` nulls, whose
    8-bit gyros no noise dithers, the lack of fit fired on 14 of 100 instead of 2.)"""
    step = shared.channels[c].quantisation_step
    out = np.sqrt(np.asarray(sigmas, dtype=float) ** 2 + shared.sweep[k, c] ** 2)
    table = _level_table(shared.segment_samples[k][:, c], step)
    if table is None or table[0].size >= 3:
        out = np.maximum(out, math.sqrt(max(shared.within[k, c] ** 2 - step**2 / 12.0, 0.0)))
    return out


@dataclass(frozen=True)
class _Shared:
    """What :func:`estimate_noise_models` takes from the samples once, whatever the quantisation model."""

    segment_samples: list
    segments: list
    channels: tuple
    within: np.ndarray
    within_dof: np.ndarray
    shaken: np.ndarray
    rms: np.ndarray
    static: list
    sigma_before: list
    pooled: list
    notes: tuple
    sweep: np.ndarray


def _mean_variance(shared: _Shared, conditional: bool) -> NoiseEstimate:
    """The variance of each segment mean from the channels' noise model, a static mean's quantisation error given
    its level counts (*conditional*) or over a level unknown within its step (:func:`estimate_noise`)."""
    segment_samples, segments, channels = shared.segment_samples, shared.segments, shared.channels
    within, within_dof, shaken, rms = shared.within, shared.within_dof, shared.shaken, shared.rms
    static, sigma_before, pooled = shared.static, shared.sigma_before, shared.pooled
    S = len(segments)
    variance = np.zeros((S, 6))
    variance_dof = np.full((S, 6), math.inf)
    quantisation = np.zeros((S, 6))
    prior = np.zeros((S, 6))
    dither = np.zeros((S, 6))
    static_dof = max(sum(segment_samples[k].shape[0] - 1 for k in static), 1)
    slow_dof = max(len(static) - 1, 1)
    for k, (s, x) in enumerate(zip(segments, segment_samples)):
        n = x.shape[0]
        duration = n / s.sample_rate
        for c, ch in enumerate(channels):
            own = within[k, c] ** 2 / n
            if math.isnan(ch.white):
                white, white_dof, slow = own, max(within_dof[k], 1), 0.0
            else:
                white, white_dof = ch.white**2 / duration, static_dof
                if s.is_rotating and s.rate_known and own > white:  # a table's rate jitter (a hand's is no noise)
                    white, white_dof = own, max(within_dof[k], 1)
                if shaken[k, c]:  # a pose that shook: its own scatter, of which the white model knows nothing
                    white, white_dof = max(own, white), max(within_dof[k], 1)
                slow = allan_slow_variance(ch, duration)
            own_quantisation = 0.0
            if ch.quantisation_step > 0:
                if (s.is_rotating and (not s.rate_known or channel_kind(c) == "gyro")) or sigma_before[c] is None \
                        or not conditional:
                    # a gyro turning (the rate's jitter dithers it), a turn by hand, or the model over a level
                    # unknown within its step: the scatter less q²/12 (Sheppard)
                    dither[k, c] = math.sqrt(max(within[k, c] ** 2 - ch.quantisation_step**2 / 12.0, 0.0))
                    quantisation[k, c] = float(quantisation_error_variance(ch.quantisation_step, dither[k, c]))
                    prior[k, c] = quantisation[k, c]
                else:
                    # static, or an accelerometer turning on a table (σ widened by its sweep): the error given
                    # where the samples fall, averaged over the sensor's σ as all the static segments' level
                    # counts give it.
                    # The quantiser's harmonics stand for up to q²/12 of it (shared by segments at one level);
                    # beyond that (a segment that toggles rarely: its mean off by most of a step) the excess is
                    # the segment's own error
                    sigmas, weights = sigma_before[c]
                    if s.is_rotating:
                        sigmas = _turning_dither(shared, k, c, sigmas)
                    given = quantisation_error_given_levels(ch.quantisation_step, x[:, c], sigmas, weights,
                                                            pooled=pooled[c].get(k))
                    quantisation[k, c] = min(given, ch.quantisation_step**2 / 12.0)
                    own_quantisation = given - quantisation[k, c]
                    dither[k, c] = dither_for_error(ch.quantisation_step, quantisation[k, c])
                    prior[k, c] = float(np.sum(weights * quantisation_error_variance(ch.quantisation_step, sigmas))
                                        / np.sum(weights))
            floor = (RELATIVE_FLOOR * rms[c]) ** 2
            total = white + slow + quantisation[k, c] + own_quantisation + floor
            variance[k, c] = total
            denominator = white**2 / white_dof + slow**2 / slow_dof
            variance_dof[k, c] = total**2 / denominator if denominator > 0 else math.inf
    return NoiseEstimate(channels, within, variance, variance_dof, quantisation, dither, shared.notes, prior)
