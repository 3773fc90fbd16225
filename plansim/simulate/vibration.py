"""The vibration paper's experiment, simulated: a still IMU, random vibration, still again (docs/dynamic.md).

The set-up of the paper's section 2: samples every 2.5 ms, 100 s still, 300 s under random vibration
(:func:`plansim.model.vibration.paper_profile`, 0.04 g²/Hz, 6.06 g r.m.s.), 100 s still. The IMU sits
level with its axes East, North, Up (x, y, z), so a shaker along z adds the vibration to gravity's
specific force; the gyros sense the Earth rate.

**What is simulated.** The specific force f(t) = g_b + a(t) e (e the vibrated axes) at an internal
rate f_s = ``oversampling`` / Δt (4800 Hz by default: the profile reaches 2000 Hz), the gyro output of
:class:`plansim.model.vibration.VibrationGyro` at that rate (the g² and g³ terms act on the full-band
specific force), and each 2.5 ms sample the mean of the internal samples over its interval (an
integrate-and-dump decimation, the acquisition's anti-alias filter), plus white noise of the angle
random walk N (σ = N/√Δt). The accelerometer output is the mean specific force over the interval plus
white noise of its velocity random walk. The acceleration starts and stops abruptly (no ramp).

**What is estimated** (:mod:`plansim.estimate.vibration`): the shift during vibration, the Welch PSDs,
and the compensation with the static model of a static calibration (the truth plus calibration errors
drawn from the seed: the bias's turn-on repeatability between calibration and test dominates) and with
the dynamic model whose g² and g³ coefficients are fitted by least squares from this record.

**Reproducibility.** Every random number is a function of (seed, stream, sample index)
(:mod:`plansim.kernels.vibration`): the record is the same for any ``chunk``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from plansim.estimate.vibration import (
    StaticModel,
    compensate,
    fit_dynamic,
    output_shift,
    residual_errors,
    welch_psd,
)
from plansim.model.dynamics import one_number
from plansim.model.environment import earth_rate_enu, normal_gravity
from plansim.model.vibration import (
    G2_PER_HZ,
    MONOMIALS,
    VibrationGyro,
    check_count,
    filter_variance,
    flat_profile,
    g2_fit_ratio,
    interval_moments,
    paper_profile,
    predicted_shift,
    seed_key,
    shaped_samples,
    shaping_filter,
)
from plansim.simulate.overrides import apply_overrides
from plansim.units import DEG, HOUR, MICRO_G, STANDARD_GRAVITY

#: the streams of a record (:func:`plansim.model.vibration.shaped_samples`)
STREAM_VIBRATION, STREAM_GYRO_NOISE, STREAM_ACCEL_NOISE, STREAM_CALIBRATION = 0, 3, 6, 9
DEG_H = DEG / HOUR


#: the unit: K and B of the jjf2003 scenario's ADIS16465-1-class MEMS IMU (scenarios/jjf2003.toml), and the
#: cross-axis terms of its g-sensitivity G (rad/s per m/s²; G's diagonal is the setting ``g_own``). The g² and g³
#: terms are settings too (:meth:`VibrationExperiment.gyro`)
UNIT_K = np.array([[1.0021, 0.0004, -0.0007], [-0.0003, 0.9985, 0.0005], [0.0006, -0.0002, 1.0012]])
UNIT_B = np.array([0.12, -0.08, 0.05]) * DEG
UNIT_G_CROSS = np.array([[0.0, -9.0, 6.0], [-7.0, 0.0, 5.0], [4.0, -6.0, 0.0]]) * DEG_H / STANDARD_GRAVITY


#: the fields ``--set`` may change: name -> (unit kind, or "count", "choice", "axes"; lower bound; description)
FIELDS = {
    "profile": ("choice", None, "'paper' (20-80-350-2000 Hz, ±3 dB/octave) or 'flat' (band_low to band_high)"),
    "psd_level": ("acceleration_psd", 0.0, "the plateau (paper) or the level (flat), e.g. '0.04 g^2/Hz'"),
    "band_low": ("frequency", 0.0, "the flat profile's lower edge, e.g. '20 Hz'"),
    "band_high": ("frequency", 0.0, "the flat profile's upper edge, e.g. '938 Hz'"),
    "vibration_axes": ("axes", None, "the shaken body axes, independent: a non-empty subset of 'xyz'"),
    "before": ("time", 0.0, "still time before the vibration, e.g. '100 s'"),
    "during": ("time", 0.0, "vibration time, e.g. '300 s'"),
    "after": ("time", 0.0, "still time after the vibration, e.g. '100 s'"),
    "sample_interval": ("time", 0.0, "the output sample interval, e.g. '2.5 ms' is '0.0025 s'"),
    "oversampling": ("count", 1, "internal samples per output sample (internal rate = oversampling / interval)"),
    "taps": ("count", 3, "FIR taps of the shaping filter (odd)"),
    "latitude": ("angle", None, "the laboratory's latitude, e.g. '39.9 deg' (within ±90°)"),
    "gyro_arw": ("angle_random_walk", 0.0, "gyro angle random walk, e.g. '0.15 deg/sqrt(h)'"),
    "accel_vrw": ("velocity_random_walk", 0.0, "accelerometer noise, e.g. '100 ug/sqrt(Hz)'"),
    "g_own": ("rate_per_acceleration", None, "gyro i's sensitivity to f_i (G's diagonal), e.g. '72 deg/h/g'"),
    "g2_own": ("rate_per_acceleration_squared", None, "gyro i's sensitivity to f_i^2, e.g. '1.6 deg/h/g^2'"),
    "g2_cross": ("rate_per_acceleration_squared", None, "gyro i's sensitivity to f_j^2, j != i"),
    "g2_product": ("rate_per_acceleration_squared", None, "every gyro's sensitivity to f_j f_k, j != k"),
    "g3": ("rate_per_acceleration_cubed", None, "every gyro's sensitivity to f_j^3, e.g. '0.002 deg/h/g^3'"),
    "bias_repeatability": ("angular_rate", 0.0, "σ of the bias change from the static calibration to the test"),
    "scale_error": ("dimensionless", 0.0, "σ of the static calibration's scale-factor error, e.g. '100 ppm'"),
    "misalignment_error": ("angle", 0.0, "σ of its misalignment error, e.g. '0.01 deg'"),
    "g_sensitivity_error": ("rate_per_acceleration", 0.0, "σ of its g-sensitivity error, e.g. '2 deg/h/g'"),
    "welch_segment": ("count", 16, "Welch segment length, samples"),
}

#: the fields of :data:`FIELDS` with a lower bound 0 that may be 0 (an error or a noise switched off)
_MAY_BE_ZERO = ("gyro_arw", "accel_vrw", "bias_repeatability", "scale_error", "misalignment_error",
                "g_sensitivity_error")


@dataclass(frozen=True)
class VibrationExperiment:
    """The experiment's settings, SI (module docstring; :data:`FIELDS` lists what ``--set`` changes)."""

    profile: str = "paper"
    psd_level: float = 0.04 * G2_PER_HZ                 # (m/s²)²/Hz
    band_low: float = 20.0                              # Hz (flat profile)
    band_high: float = 938.0                            # Hz (flat profile: 0.04 g²/Hz × 918 Hz = 6.06 g r.m.s.)
    vibration_axes: str = "z"
    before: float = 100.0                               # s
    during: float = 300.0                               # s
    after: float = 100.0                                # s
    sample_interval: float = 2.5e-3                     # s
    oversampling: int = 12
    taps: int = 1025
    latitude: float = 39.9 * DEG                        # rad
    gyro_arw: float = 0.15 * DEG / 60.0                 # rad/√s
    accel_vrw: float = 100.0 * MICRO_G                  # m/s²/√Hz (≡ m/s/√s)
    g_own: float = 72.0 * DEG_H / STANDARD_GRAVITY      # rad/s per m/s² (0.02 °/s/g)
    g2_own: float = 1.6 * DEG_H / STANDARD_GRAVITY**2   # rad/s per (m/s²)²
    g2_cross: float = 0.8 * DEG_H / STANDARD_GRAVITY**2
    g2_product: float = 0.3 * DEG_H / STANDARD_GRAVITY**2
    g3: float = 0.002 * DEG_H / STANDARD_GRAVITY**3     # rad/s per (m/s²)³
    bias_repeatability: float = 10.0 * DEG_H            # rad/s
    scale_error: float = 100e-6
    misalignment_error: float = 0.01 * DEG              # rad
    g_sensitivity_error: float = 2.0 * DEG_H / STANDARD_GRAVITY  # rad/s per m/s²
    welch_segment: int = 1024
    overrides: tuple = field(default=(), compare=False)

    def __post_init__(self):
        for name, (kind, low, _) in FIELDS.items():
            value = getattr(self, name)
            if kind == "choice":
                if value not in ("paper", "flat"):
                    raise ValueError(f"profile: expected 'paper' or 'flat', got {value!r}")
            elif kind == "axes":
                if not isinstance(value, str) or not value or any(c not in "xyz" for c in value) \
                        or len(set(value)) != len(value):
                    raise ValueError(f"vibration_axes: expected a non-empty subset of 'xyz' (e.g. 'z', 'xyz'), "
                                     f"got {value!r}")
            elif kind == "count":
                object.__setattr__(self, name, check_count(name, value, low))
            else:
                number = one_number(name, value, "SI")
                if not (math.isfinite(number) and (low is None or number > low or (low == 0.0 and number == 0.0
                                                                                      and name in _MAY_BE_ZERO))):
                    bound = "finite" if low is None else f">= {low:g}" if name in _MAY_BE_ZERO else f"> {low:g}"
                    raise ValueError(f"{name}: expected a number {bound} (SI), got {value!r}")
                object.__setattr__(self, name, number)
        if abs(self.latitude) > math.pi / 2:
            raise ValueError(f"latitude: expected a value in [-pi/2, pi/2] rad, got {self.latitude!r}")
        if self.taps % 2 == 0:
            raise ValueError(f"taps: expected an odd integer >= 3, got {self.taps!r}")
        if self.profile == "flat" and not self.band_high > self.band_low:
            raise ValueError(f"band_high: expected > band_low = {self.band_low} Hz, got {self.band_high} Hz")
        top = self.psd_profile().frequencies[-1]
        if self.internal_rate <= 2 * top:
            raise ValueError(f"oversampling: {self.oversampling} gives an internal rate of {self.internal_rate} Hz, "
                             f"at or below twice the profile's top {top} Hz; allowed: oversampling > "
                             f"{2 * top * self.sample_interval:g}")
        for name in ("before", "during", "after"):
            if self.samples(getattr(self, name)) < 1:
                raise ValueError(f"{name}: {getattr(self, name)} s is shorter than one sample interval "
                                 f"{self.sample_interval} s")
        if self.samples(self.during) < self.welch_segment:
            raise ValueError(f"welch_segment: {self.welch_segment} samples is longer than the vibration "
                             f"({self.samples(self.during)} samples); allowed: <= {self.samples(self.during)}")

    @property
    def internal_rate(self) -> float:
        """The rate the vibration and the sensor's physics are simulated at, Hz."""
        return self.oversampling / self.sample_interval

    def samples(self, duration: float) -> int:
        """The number of output samples in *duration* (s), rounded to the nearest."""
        return int(round(duration / self.sample_interval))

    def psd_profile(self):
        if self.profile == "paper":
            return paper_profile(self.psd_level)
        return flat_profile(self.psd_level, self.band_low, self.band_high)

    def gyro(self) -> VibrationGyro:
        """The unit's truth: :data:`UNIT_K`, :data:`UNIT_B` and :data:`UNIT_G_CROSS`, with G's diagonal and the g²
        and g³ terms of these settings. The defaults: ``g_own`` 72 °/h/g = 0.02 °/s/g, a MEMS gyro's usual
        linear-g figure (large enough that the gyro output's PSD follows the vibration's above the white noise,
        as in the paper's Figure 4); g² 1.6 °/h/g² on the own axis and 0.8 °/h/g² across (so that the z gyro
        shifts by ≈ 59 °/h under the paper's 36.7 g², its ≈ 60 °/h), products 0.3 °/h/g²; g³ 0.002 °/h/g³ (a
        shift of 3 D g E[a²] ≈ 0.2 °/h: negligible, as the paper found)."""
        eye = np.eye(3, dtype=bool)
        return VibrationGyro(UNIT_K, UNIT_B, np.where(eye, self.g_own, UNIT_G_CROSS),
                             np.where(eye, self.g2_own, self.g2_cross), np.full((3, 3), self.g2_product),
                             np.full((3, 3), self.g3))

    def axes(self) -> list[int]:
        return ["xyz".index(c) for c in self.vibration_axes]

    def fit_columns(self) -> tuple[str, ...]:
        """The monomials the vibration excites: squares, products and cubes of the shaken axes."""
        names = [c + c for c in self.vibration_axes]
        names += [a + b for a, b in ("xy", "xz", "yz") if a in self.vibration_axes and b in self.vibration_axes]
        names += [c * 3 for c in self.vibration_axes]
        return tuple(n for n in MONOMIALS if n in names)


def with_overrides(settings: VibrationExperiment, overrides) -> VibrationExperiment:
    """*settings* with ``KEY=VALUE`` strings applied: quantities as '<number> <unit>' (:mod:`plansim.units`),
    counts as integers, ``profile`` and ``vibration_axes`` as words
    (:func:`plansim.simulate.overrides.apply_overrides`); an error names the key and what is allowed."""
    return apply_overrides(settings, overrides, {key: spec[0] for key, spec in FIELDS.items()},
                           words=("choice", "axes"),
                           count_minimum={key: spec[1] for key, spec in FIELDS.items() if spec[0] == "count"})


@dataclass(frozen=True)
class VibrationRecord:
    """One simulated record, SI: t (n,) s; gyro (n, 3) rad/s; accel (n, 3) m/s² (the IMU's outputs);
    rate (3,) rad/s the true (Earth) rate; gravity (3,) m/s² the still specific force; during, still (n,)
    masks; variance (3,) the generated E[a_j²] per axis, (m/s²)²; taps the shaping filter; calibration the
    static model a static calibration gives."""

    t: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    rate: np.ndarray
    gravity: np.ndarray
    during: np.ndarray
    still: np.ndarray
    variance: np.ndarray
    taps: np.ndarray
    calibration: StaticModel


def static_calibration(settings: VibrationExperiment, truth: VibrationGyro, key) -> StaticModel:
    """The static model a static calibration gives: the truth plus errors drawn from stream
    :data:`STREAM_CALIBRATION` (the bias error is its change to the day of the test)."""
    z = shaped_samples(key, STREAM_CALIBRATION, np.ones(1), 0, 21)
    dK = np.where(np.eye(3, dtype=bool), settings.scale_error, settings.misalignment_error) * z[:9].reshape(3, 3)
    return StaticModel(K=truth.K + dK, B=truth.B + settings.bias_repeatability * z[9:12],
                       G=truth.G + settings.g_sensitivity_error * z[12:21].reshape(3, 3))


def simulate_record(settings: VibrationExperiment, seed: int, chunk: int = 16384) -> VibrationRecord:
    """The record of the experiment (module docstring); *chunk* output samples per step (changes nothing
    but the memory: about 1 kB per output sample at 12× oversampling)."""
    chunk = check_count("chunk", chunk)
    key = seed_key(seed)
    truth = settings.gyro()
    os_ = settings.oversampling
    dt = settings.sample_interval
    n_before, n_during, n_after = (settings.samples(d) for d in (settings.before, settings.during, settings.after))
    n = n_before + n_during + n_after
    taps = shaping_filter(settings.psd_profile(), settings.internal_rate, settings.taps)
    g = normal_gravity(settings.latitude)
    gravity = np.array([0.0, 0.0, g])
    rate = earth_rate_enu(settings.latitude)
    axes = settings.axes()

    gyro = np.empty((n, 3))
    accel = np.empty((n, 3))
    vib_first, vib_end = n_before * os_, (n_before + n_during) * os_  # internal samples under vibration
    for first in range(0, n, chunk):
        m = min(chunk, n - first)
        lo, hi = first * os_, (first + m) * os_
        f = np.broadcast_to(gravity, (hi - lo, 3)).copy()
        a_lo, a_hi = max(lo, vib_first), min(hi, vib_end)
        if a_hi > a_lo:
            for j in axes:
                f[a_lo - lo:a_hi - lo, j] += shaped_samples(key, STREAM_VIBRATION + j, taps, a_lo - vib_first,
                                                            a_hi - a_lo)
        y = truth.output(rate, f)
        gyro[first:first + m] = y.reshape(m, os_, 3).mean(axis=1)
        accel[first:first + m] = f.reshape(m, os_, 3).mean(axis=1)
        for j in range(3):
            gyro[first:first + m, j] += settings.gyro_arw / math.sqrt(dt) * shaped_samples(
                key, STREAM_GYRO_NOISE + j, np.ones(1), first, m)
            accel[first:first + m, j] += settings.accel_vrw / math.sqrt(dt) * shaped_samples(
                key, STREAM_ACCEL_NOISE + j, np.ones(1), first, m)
    index = np.arange(n)
    during = (index >= n_before) & (index < n_before + n_during)
    variance = np.zeros(3)
    variance[axes] = filter_variance(taps)
    return VibrationRecord(t=index * dt, gyro=gyro, accel=accel, rate=rate, gravity=gravity, during=during,
                           still=~during, variance=variance, taps=taps,
                           calibration=static_calibration(settings, truth, key))


@dataclass(frozen=True)
class VibrationResult:
    """The experiment's figures, SI (rad/s, m/s², Hz); see :func:`run_vibration_experiment`."""

    settings: VibrationExperiment
    seed: int
    record: VibrationRecord
    truth: VibrationGyro
    shift: np.ndarray               # (3,) measured output shift, rad/s
    predicted_shift: np.ndarray     # (3,) closed form Σ S E[a²] + 3 D g E[a²], rad/s
    coefficients: dict              # "g2" and "g2_g3": (3, 9) fitted, columns MONOMIALS
    errors: dict                    # "static", "g2", "g2_g3": residual_errors dicts
    psd: dict                       # "frequency", "gyro", "accel", "profile"
    accel_power_sampled: np.ndarray  # (3,) variance of the 2.5 ms accelerometer output during vibration, (m/s²)²
    rate_estimates: dict            # "static", "g2_g3": (n, 3) rad/s
    predicted: dict | None          # predicted_errors(), or None unless the shaken axis is z alone


def run_vibration_experiment(settings: VibrationExperiment | None = None, seed: int = 20200612,
                             chunk: int = 16384) -> VibrationResult:
    """Simulate the record and reduce it as the paper does (module docstring)."""
    settings = VibrationExperiment() if settings is None else settings
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    record = simulate_record(settings, seed, chunk)
    truth = settings.gyro()
    static = record.calibration
    columns = settings.fit_columns()
    coefficients = {
        "g2": fit_dynamic(record.gyro, record.accel, record.rate, static, [c for c in columns if len(c) == 2]),
        "g2_g3": fit_dynamic(record.gyro, record.accel, record.rate, static, columns),
    }
    average = settings.samples(1.0)
    estimates = {"static": compensate(record.gyro, record.accel, static)}
    for name, c in coefficients.items():
        estimates[name] = compensate(record.gyro, record.accel, static, c)
    errors = {name: residual_errors(est, record.rate, record.during, average) for name, est in estimates.items()}
    fs = 1.0 / settings.sample_interval
    freq, p_gyro = welch_psd(record.gyro[record.during], fs, settings.welch_segment)
    _, p_accel = welch_psd(record.accel[record.during], fs, settings.welch_segment)
    return VibrationResult(
        settings=settings, seed=int(seed), record=record, truth=truth,
        shift=output_shift(record.gyro, record.during, record.still),
        predicted_shift=predicted_shift(truth, record.gravity, record.variance),
        coefficients=coefficients, errors=errors,
        psd={"frequency": freq, "gyro": p_gyro, "accel": p_accel, "profile": settings.psd_profile().level(freq)},
        accel_power_sampled=record.accel[record.during].var(axis=0),
        rate_estimates={"static": estimates["static"], "g2_g3": estimates["g2_g3"]},
        predicted=predicted_errors(settings, record) if settings.vibration_axes == "z" else None,
    )


def predicted_errors(settings: VibrationExperiment, record: VibrationRecord) -> dict:
    """What the model predicts for a shaker along z (gravity's axis), without noise or calibration errors.

    ``sampled_variance``: E[ā²] of the integrate-and-dump accelerometer samples, (m/s²)²
    (:func:`plansim.model.vibration.interval_moments`); ``g2_ratio``: the fitted g² coefficient over the true
    one (:func:`plansim.model.vibration.g2_fit_ratio`); ``static`` (3,), rad/s: the mean error of the static
    model during vibration, S₂(g² + σ²) + D(g³ + 3gσ²) (the g² and g³ terms at rest included, since the
    static model has none); ``g2`` (3,): that minus what the fitted column removes, Ŝ(g² + s²).
    """
    truth = settings.gyro()
    g = record.gravity[2]
    variance, sampled, _ = interval_moments(record.taps, settings.oversampling)
    fraction = float(np.mean(record.during))
    ratio = g2_fit_ratio(g, record.taps, settings.oversampling, fraction)
    S, D = truth.S2[:, 2], truth.D[:, 2]
    static = S * (g * g + variance) + D * (g**3 + 3 * g * variance)
    return {"sampled_variance": sampled, "g2_ratio": ratio, "static": static,
            "g2": static - ratio * S * (g * g + sampled)}


@dataclass(frozen=True)
class VibrationMonteCarlo:
    """The experiment run on *trials* records, seeds ``seed``, ``seed + 1``, … (each reproducible alone with
    ``plansim run vibration_g2 --seed``), SI (rad/s). ``shift`` (N, 3); ``mean_error`` and ``rms_averaged``: per
    compensation (``static``, ``g2``, ``g2_g3``) (N, 3), the mean error during vibration and the r.m.s. of its 1 s
    means; ``g2_ratio`` (N, 3): each gyro's fitted g² coefficient on the shaken axis over the truth's."""

    settings: VibrationExperiment
    seed: int
    trials: int
    shift: np.ndarray
    predicted_shift: np.ndarray
    mean_error: dict
    rms_averaged: dict
    g2_ratio: np.ndarray
    predicted: dict | None

    def summary(self, values: np.ndarray) -> dict:
        """Mean, standard deviation (n − 1) and 2.5 %/97.5 % quantiles over the trials, per axis (3,) each."""
        v = np.asarray(values, dtype=float)
        q = np.quantile(v, [0.025, 0.975], axis=0)
        return {"mean": v.mean(axis=0), "std": v.std(axis=0, ddof=1), "q025": q[0], "q975": q[1]}


def vibration_monte_carlo(settings: VibrationExperiment | None = None, trials: int = 20, seed: int = 20200612,
                          progress=None) -> VibrationMonteCarlo:
    """:func:`run_vibration_experiment` on *trials* records, seeds *seed* … *seed* + trials − 1 (module docstring;
    ``plansim run vibration_g2 --trials N``): how much the shift and the compensation's residual error scatter from
    one record to the next, which one record (the paper's) cannot say. ``progress(done, trials)`` after each."""
    settings = VibrationExperiment() if settings is None else settings
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 2:
        raise ValueError(f"trials = {trials!r}: expected a whole number >= 2 (a spread needs two records)")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    shift, mean_error, rms, ratio = [], {m: [] for m in ("static", "g2", "g2_g3")}, {m: [] for m in
                                                                                       ("static", "g2", "g2_g3")}, []
    predicted_shift, predicted = [], None
    axis = "xyz".index(settings.vibration_axes[0])
    for i in range(int(trials)):
        result = run_vibration_experiment(settings, seed=int(seed) + i)
        shift.append(result.shift)
        for m in mean_error:
            mean_error[m].append(result.errors[m]["mean"])
            rms[m].append(result.errors[m]["rms_averaged"])
        true = result.truth.S2[:, axis]
        fitted = result.coefficients["g2"][:, MONOMIALS.index("xyz"[axis] * 2)]
        ratio.append(np.where(true != 0, fitted / np.where(true != 0, true, 1.0), np.nan))
        predicted_shift.append(result.predicted_shift)
        predicted = result.predicted
        if progress is not None:
            progress(i + 1, int(trials))
    return VibrationMonteCarlo(settings, int(seed), int(trials), np.array(shift), np.mean(predicted_shift, axis=0),
                               {m: np.array(v) for m, v in mean_error.items()},
                               {m: np.array(v) for m, v in rms.items()}, np.array(ratio), predicted)
