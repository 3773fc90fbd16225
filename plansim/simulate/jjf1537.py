"""JJF 1537-2015's amplitude- and phase-frequency test on an angular vibration table, simulated (docs/dynamic.md).

**What is simulated.** For each frequency f_i of the schedule (:mod:`plansim.schedule.jjf1537`) and each of
its n repeats, the table turns the gyro about its sensitive axis at the rate ω(t) = A cos(2πf_i t + φ_in),
with a phase φ_in drawn uniformly from the seed per record; the gyro's output is

    y = Q(S · (H ω)(t) + B + σ w),

H the sensor's dynamics (:class:`plansim.model.dynamics.SensorDynamics`: flat, the second-order low-pass
or JJF 1537-2015 eq. (3)'s two resonances), S the scale factor, B the bias, w white noise of the angle
random walk N (σ = S·N/√Δt) and Q the 16-bit-like quantiser of step q with saturation at the range.

**The discretisation.** H(s) is discretised per frequency by the bilinear (Tustin) transform prewarped at
that record's table frequency Ω = 2πf_i:

    s = (Ω / tan(ΩΔt/2)) · (z − 1)/(z + 1),

(``scipy.signal.bilinear`` with fs = Ω/(2 tan(ΩΔt/2))). It maps z = e^{jΩΔt} to s = jΩ exactly, so the
simulated steady-state response at the one frequency a record contains is H(j2πf_i) itself, amplitude and
phase, to rounding: the estimates carry no discretisation bias and the analytic response of
:mod:`plansim.model.dynamics` is the exact truth. It keeps the DC gain (z = 1 ↔ s = 0) and maps the stable
s-plane into the unit disc. A zero-order hold would instead delay a sinusoid by about half a sample (5.2°
at 115 Hz sampled at 4 kHz) and the unwarped Tustin transform shifts frequencies by a factor
1 + (πf/f_s)²/3 (0.3 % at 115 Hz); both would be biases of the simulator, not of the procedure. The noise
is added after H (the angle random walk as the output's white noise), so the filter's response away from
f_i never matters.

The filter runs in :func:`plansim.kernels.dynamics.sine_records` from rest, through a run-in before each
record long enough for the start-up transient to decay below 1e-13 of itself (ln 1e-13/ln r samples, r
the largest pole radius), which is then discarded; the table is assumed to have run up before recording.

**What is estimated** (:mod:`plansim.estimate.dynamic`): per record the three-parameter sine fit (JJF
1537-2015 eq. (6)); per trial the frequency response eq. (7)–(9) with S_0 the sensitivity at the lowest
frequency, the phase response, the −3 dB bandwidth interpolated (JJF 1535-2015 7.2.15.2); over the trials
the bias and standard deviation of each against the analytic truth, and the GUM (JCGM 100) of the same
estimators from the sine fit's closed-form variance.

**Items 7.2.4–7.2.7** (:func:`run_vibration_shock`; :func:`run_jjf1537` runs them in the same trials). The
sensor may have a static amplitude nonlinearity after its dynamics, g(v) = v + c₂v²/R + c₃v³/R² (R the range;
``even_nonlinearity`` c₂, ``odd_nonlinearity`` c₃, both 0 by default: a model choice, the copy of JJF 1537
naming no model), and its bias may step by ``vibration_bias_shift`` after the vibration and by
``shock_bias_shift`` after the shock (0 by default). At one frequency (``vibration_frequency``) each trial
records n repeats at each of M amplitudes across 10–30 % of the range (7.2.4), then at rest, under vibration at
the 7.2.1 amplitude (7.2.5), at rest, the shock (its waveform not simulated: only the bias step it leaves), at
rest (7.2.6, 7.2.7); :func:`reduce_vibration_shock` reduces them and :func:`vibration_shock_truth` gives the
figures in closed form.

**Reproducibility.** Every noise sample is a function of (seed, record, sample index) and the filter state
is carried from chunk to chunk: the numbers do not depend on the chunking, in time or in trials.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.signal
import scipy.stats

from plansim.estimate.dynamic import (
    HALF_POWER,
    amplitude_nonlinearity,
    bandwidth_3db,
    bandwidth_curve_fit,
    frequency_response,
    mean_change,
    shock_response,
    sine_fits,
    wrap_phase,
)
from plansim.kernels.dynamics import input_records, sine_records
from plansim.kernels.random import root_key
from plansim.model.dynamics import (
    SENSOR_MODELS,
    SensorDynamics,
    half_sine,
    one_number,
    static_nonlinearity_harmonics,
)
from plansim.schedule.jjf1537 import (
    LINEARITY_POINTS,
    Jjf1537Schedule,
    VibrationShockSchedule,
    amplitude_in_range,
    jjf1535_frequencies,
    jjf1537_frequencies,
    linearity_amplitudes,
)
from plansim.simulate.overrides import apply_overrides
from plansim.units import DEG, STANDARD_GRAVITY

#: white numbers per block of a record's noise (fixed: the numbers never depend on the chunking)
WHITE_BLOCK = 4096
#: the start-up transient is run in until it has decayed to this fraction of itself
RUN_IN_DECAY = 1e-13
#: the default seed (JJF 1537's number)
DEFAULT_SEED = 1537
#: the default number of Monte Carlo trials of ``plansim run jjf1537``
DEFAULT_TRIALS = 500

#: the fields ``--set`` may change: name -> (unit kind, or "choice"/"count"; description)
FIELDS = {
    "model": ("choice", "the sensor's dynamics: " + ", ".join(SENSOR_MODELS)),
    "natural_frequency": ("frequency", "the (sense-mode) resonance f_n, e.g. '100 Hz'"),
    "damping": ("dimensionless", "its damping ratio, e.g. 0.7"),
    "drive_frequency": ("frequency", "two_resonance: the drive-mode resonance, e.g. '400 Hz'"),
    "drive_damping": ("dimensionless", "two_resonance: its damping ratio"),
    "gyro_range": ("angular_rate", "the gyro's range, e.g. '300 deg/s'"),
    "amplitude_fraction": ("dimensionless", "the table's rate amplitude as a fraction of the range, 0.1-0.3"),
    "grid": ("choice", "'jjf1535' (8 points to the expected bandwidth + 10 Hz, 2 inserted) or 'jjf1537' "
                       "(frequency_count evenly from band_low to band_high)"),
    "expected_bandwidth": ("frequency", "the bandwidth the test is planned for, e.g. '100 Hz'"),
    "band_low": ("frequency", "grid jjf1537: the lowest frequency"),
    "band_high": ("frequency", "grid jjf1537: the highest frequency"),
    "frequency_count": ("count", "grid jjf1537: the number of frequencies, >= 7"),
    "repeats": ("count", "records per frequency, >= 7"),
    "sample_rate": ("frequency", "the output rate, > 20 x expected_bandwidth, e.g. '4 kHz'"),
    "record_time": ("time", "the target record length (whole cycles), e.g. '1 s'"),
    "gyro_arw": ("angle_random_walk", "angle random walk, e.g. '0.5 deg/sqrt(h)'; 0: none"),
    "quantisation": ("angular_rate", "the output's step, e.g. '0.00916 deg/s'; 0: none"),
    "scale_factor": ("dimensionless", "S, output (rad/s) per input rad/s"),
    "bias": ("angular_rate", "the output's bias, e.g. '0.1 deg/s'"),
    "odd_nonlinearity": ("dimensionless", "c3 of g(v) = v + c2 v^2/R + c3 v^3/R^2 (R the range): the gain's "
                                          "relative excess at the full range; 0: linear (default)"),
    "even_nonlinearity": ("dimensionless", "c2 of g(v) (above): the rectification; 0: none (default)"),
    "vibration_frequency": ("frequency", "7.2.4-7.2.7: the table frequency, e.g. '20 Hz'"),
    "linearity_points": ("count", "7.2.4: amplitudes evenly across 10-30 % of the range, >= 3"),
    "vibration_time": ("time", "7.2.5: the record under vibration (whole cycles), e.g. '5 s'"),
    "rest_time": ("time", "7.2.6-7.2.7: each record at rest, e.g. '5 s'"),
    "vibration_bias_shift": ("angular_rate", "7.2.6: the output's bias change the vibration leaves; 0: none"),
    "shock_bias_shift": ("angular_rate", "7.2.7: the output's bias change the shock leaves; 0: none"),
    "shock_peak": ("acceleration", "7.2.7: the half-sine shock's peak acceleration along the gyro's input axis, "
                                   "e.g. '50 g'; 0: no pulse"),
    "shock_duration": ("time", "7.2.7: the half-sine's duration, e.g. '11 ms'"),
    "shock_settle": ("time", "7.2.7: from the pulse's start to the record after the shock, less the pulse, "
                             "e.g. '1 s'"),
    "g_sensitivity": ("rate_per_acceleration", "the gyro's output per acceleration along its input axis (what "
                                               "the shock reaches it through), e.g. '0.01 deg/s/g'; 0: none"),
    "table_amplitude_error": ("dimensionless", "the table's rate amplitude error, relative standard deviation, drawn "
                                               "once per frequency (7.2.1) and amplitude (7.2.4) of each trial, "
                                               "e.g. '0.5 %'; 0: none (default)"),
    "table_phase_error": ("angle", "the table's phase error against its reference signal, standard deviation, drawn "
                                   "once per frequency of each trial, e.g. '0.2 deg'; 0: none (default)"),
}
_CHOICES = {"model": SENSOR_MODELS, "grid": ("jjf1535", "jjf1537")}
_MAY_BE_ZERO = ("gyro_arw", "quantisation", "table_amplitude_error", "table_phase_error")
_ANY_SIGN = ("bias", "odd_nonlinearity", "even_nonlinearity", "vibration_bias_shift", "shock_bias_shift", "shock_peak",
             "g_sensitivity")


@dataclass(frozen=True)
class Jjf1537Experiment:
    """The test's settings, SI (module docstring; :data:`FIELDS` lists what ``--set`` changes).

    Defaults: a ±300 °/s digital MEMS gyro (output in rad/s), 16-bit output (step 600 °/s / 2¹⁶), ARW
    0.5 °/√h, bias 0.1 °/s, second-order dynamics f_n = 100 Hz, ζ = 0.7 (f_3dB = 101.0 Hz); the table at
    20 % of the range (60 °/s); JJF 1535 7.2.15.1 b)'s grid for an expected bandwidth of 100 Hz (10
    points, 13.75–110 Hz); n = 7; 4 kHz; 1 s records; the shock of 7.2.7 a 50 g, 11 ms half-sine along the
    input axis (a common shock-test pulse: the copy of JJF 1537 used here gives none), read through a
    g-sensitivity of 0.01 °/s/g, the record after it 1 s after the pulse's start.
    """

    model: str = "second_order"
    natural_frequency: float = 100.0
    damping: float = 0.7
    drive_frequency: float = 400.0
    drive_damping: float = 0.7
    gyro_range: float = 300.0 * DEG
    amplitude_fraction: float = 0.2
    grid: str = "jjf1535"
    expected_bandwidth: float = 100.0
    band_low: float = 10.0
    band_high: float = 150.0
    frequency_count: int = 8
    repeats: int = 7
    sample_rate: float = 4000.0
    record_time: float = 1.0
    gyro_arw: float = 0.5 * DEG / 60.0            # rad/√s
    quantisation: float = 600.0 * DEG / 2**16     # rad/s
    scale_factor: float = 1.0
    bias: float = 0.1 * DEG                       # rad/s
    odd_nonlinearity: float = 0.0
    even_nonlinearity: float = 0.0
    vibration_frequency: float = 20.0
    linearity_points: int = LINEARITY_POINTS
    vibration_time: float = 5.0
    rest_time: float = 5.0
    vibration_bias_shift: float = 0.0             # output unit (rad/s)
    shock_bias_shift: float = 0.0                 # output unit (rad/s)
    shock_peak: float = 50.0 * STANDARD_GRAVITY   # m/s²
    shock_duration: float = 0.011                 # s
    shock_settle: float = 1.0                     # s
    g_sensitivity: float = 0.01 * DEG / STANDARD_GRAVITY  # rad/s per m/s²
    table_amplitude_error: float = 0.0            # relative standard deviation
    table_phase_error: float = 0.0                # rad, standard deviation
    overrides: tuple = field(default=(), compare=False)

    def __post_init__(self):
        for name, (kind, _) in FIELDS.items():
            value = getattr(self, name)
            if kind == "choice":
                if value not in _CHOICES[name]:
                    raise ValueError(f"{name}: expected one of {', '.join(_CHOICES[name])}, got {value!r}")
            elif kind == "count":
                if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                    raise TypeError(f"{name}: expected an integer, got {value!r}")
            else:
                number = one_number(name, value, "SI")
                ok = math.isfinite(number) and (number > 0 or name in _ANY_SIGN
                                                 or (name in _MAY_BE_ZERO and number == 0))
                if not ok:
                    bound = "finite" if name in _ANY_SIGN else ">= 0" if name in _MAY_BE_ZERO else "> 0"
                    raise ValueError(f"{name}: expected a number {bound} (SI), got {value!r}")
                object.__setattr__(self, name, number)
        amplitude_in_range(self.amplitude_fraction, self.gyro_range)
        self.dynamics()
        self.schedule()
        self.vibration_shock_schedule()

    def dynamics(self) -> SensorDynamics:
        """The sensor's truth (:class:`plansim.model.dynamics.SensorDynamics`)."""
        return SensorDynamics(self.model, self.natural_frequency, self.damping, self.drive_frequency,
                              self.drive_damping)

    def frequencies(self) -> np.ndarray:
        """The table frequencies of the chosen grid, Hz."""
        if self.grid == "jjf1535":
            return jjf1535_frequencies(self.expected_bandwidth)
        return jjf1537_frequencies(self.band_low, self.band_high, self.frequency_count)

    def schedule(self) -> Jjf1537Schedule:
        return Jjf1537Schedule(frequencies=self.frequencies(),
                               amplitude=amplitude_in_range(self.amplitude_fraction, self.gyro_range),
                               gyro_range=self.gyro_range, repeats=self.repeats, sample_rate=self.sample_rate,
                               record_time=self.record_time, expected_bandwidth=self.expected_bandwidth)

    def vibration_shock_schedule(self) -> VibrationShockSchedule:
        """JJF 1537-2015 7.2.4–7.2.7's records (:class:`plansim.schedule.jjf1537.VibrationShockSchedule`): the
        vibration at ``amplitude_fraction`` of the range, ``linearity_points`` amplitudes over 10–30 %."""
        return VibrationShockSchedule(
            frequency=self.vibration_frequency, amplitudes=linearity_amplitudes(self.gyro_range, self.linearity_points),
            amplitude=amplitude_in_range(self.amplitude_fraction, self.gyro_range), gyro_range=self.gyro_range,
            repeats=self.repeats, sample_rate=self.sample_rate, record_time=self.record_time,
            vibration_time=self.vibration_time, rest_time=self.rest_time, shock_duration=self.shock_duration,
            shock_settle=self.shock_settle)

    @property
    def noise_sigma(self) -> float:
        """σ = S·N/√Δt, the white noise's standard deviation per sample, output unit."""
        return self.scale_factor * self.gyro_arw * math.sqrt(self.sample_rate)


def with_overrides(settings: Jjf1537Experiment, overrides) -> Jjf1537Experiment:
    """*settings* with ``KEY=VALUE`` strings applied (quantities as '<number> <unit>', :mod:`plansim.units`;
    :func:`plansim.simulate.overrides.apply_overrides`); an error names the key, the value and what is allowed."""
    return apply_overrides(settings, overrides, {key: spec[0] for key, spec in FIELDS.items()})


def discretise(dynamics: SensorDynamics, frequency: float, sample_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """(b, a) of H(z), a[0] = 1: the bilinear transform of H(s) prewarped at *frequency* (module docstring)."""
    b, a = dynamics.polynomials()
    if len(a) == 1:
        return b / a[0], np.ones(1)
    omega = 2.0 * math.pi * frequency
    bz, az = scipy.signal.bilinear(b, a, fs=omega / (2.0 * math.tan(omega / (2.0 * sample_rate))))
    bz = np.concatenate((np.zeros(len(az) - len(bz)), bz))  # same length as a
    return bz / az[0], az / az[0]


def run_in_samples(a: np.ndarray) -> int:
    """Samples for the filter's start-up transient to decay to :data:`RUN_IN_DECAY` of itself:
    ⌈ln(1e-13)/ln r⌉, r the largest pole radius of 1/A(z) (0 for a filter without poles)."""
    if len(a) == 1:
        return 0
    r = float(np.max(np.abs(np.roots(a))))
    if not r < 1.0:
        raise ValueError(f"the discretised filter has a pole of radius {r!r} >= 1 (unstable)")
    return int(math.ceil(math.log(RUN_IN_DECAY) / math.log(r))) + 1


def table_phases(seed: int, trial: int, shape: tuple[int, int]) -> np.ndarray:
    """φ_in of trial *trial*'s records (m, n), uniform on [−π, π), from ``default_rng([seed, trial])``."""
    return np.random.default_rng([int(seed), int(trial)]).uniform(-math.pi, math.pi, shape)


#: the substreams of the table's errors, apart from :func:`table_phases`' ([seed, trial]) and :func:`item_phases`'
#: ([seed, trial, 1])
TABLE_ERROR_STREAM, ITEM_TABLE_ERROR_STREAM = 2, 3


def table_errors(settings: Jjf1537Experiment, seed: int, trial: int, count: int, stream: int = TABLE_ERROR_STREAM
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(ε, δ), each (count,): the table's relative amplitude errors ε ~ N(0, ``table_amplitude_error``²) and phase
    errors δ ~ N(0, ``table_phase_error``²) (rad) of trial *trial*, one per setting (a frequency of 7.2.1, an
    amplitude of 7.2.4), from ``default_rng([seed, trial, stream])``. The table turns at A(1 + ε) and phase φ_in + δ
    while the lab reads A and φ_in: an error that acts once per setting, so the n repeats do not average it down.
    Exactly 0 when the settings have none (the records are then those of a perfect table, number for number)."""
    draws = np.random.default_rng([int(seed), int(trial), int(stream)]).standard_normal((2, count))
    return settings.table_amplitude_error * draws[0], settings.table_phase_error * draws[1]


def simulate_records(settings: Jjf1537Experiment, seed: int, index: int, trials, chunk: int | None = None,
                     phases: np.ndarray | None = None, amplitude_errors: np.ndarray | None = None) -> np.ndarray:
    """The records at the frequency number *index* for the trials *trials*: (len(trials), n, N_i), output unit.

    *chunk*: samples per kernel call along time (None: the run-in and the record in one call); the result
    does not depend on it. *phases*: (len(trials), n) the table's actual phases (default: :func:`table_phases`);
    *amplitude_errors*: (len(trials),) the table's relative amplitude error at this frequency in each trial
    (default 0: the table turns at the schedule's amplitude).
    """
    schedule = settings.schedule()
    trials = np.asarray(trials, dtype=np.int64).ravel()
    m, n = schedule.frequencies.size, schedule.repeats
    if phases is None:
        phases = np.stack([table_phases(seed, t, (m, n))[index] for t in trials])
    streams = ((trials[:, None] * m + index) * n + np.arange(n)[None, :]).ravel().astype(np.int64)
    errors = np.zeros(trials.size) if amplitude_errors is None else np.asarray(amplitude_errors, dtype=float)
    amplitudes = np.repeat(schedule.amplitude * (1.0 + errors), n)
    out = table_records(settings, seed, float(schedule.frequencies[index]), amplitudes,
                        np.ascontiguousarray(phases).ravel(), int(schedule.samples()[index]), streams, chunk=chunk)
    return out.reshape(trials.size, n, -1)


def table_records(settings: Jjf1537Experiment, seed: int, frequency: float, amplitude, phases, samples: int,
                  streams, chunk: int | None = None, bias_shift: float = 0.0) -> np.ndarray:
    """One record per stream (R,) of *samples* samples: the table at *frequency* (Hz) and rate *amplitude*
    (rad/s, one for all or (R,) one per record; 0: at rest) with the phases *phases* (R,), through the sensor of
    *settings* after its run-in (:func:`plansim.kernels.dynamics.sine_records`), the output bias B + *bias_shift*
    (output unit, as B). (R, samples), output unit; *chunk* as :func:`simulate_records` (the numbers do not depend
    on it)."""
    streams = np.ascontiguousarray(streams, dtype=np.int64).ravel()
    amplitudes = np.ascontiguousarray(np.broadcast_to(np.asarray(amplitude, dtype=float), streams.shape))
    if not np.any(amplitudes):  # at rest: the dynamics pass nothing
        b, a, lead = np.ones(1), np.ones(1), 0
    else:
        b, a = discretise(settings.dynamics(), frequency, settings.sample_rate)
        lead = run_in_samples(a)
    rows = streams.size
    states = np.zeros((rows, len(a) - 1))
    out = np.empty((rows, lead + samples))
    step = lead + samples if chunk is None else int(chunk)
    if step < 1:
        raise ValueError(f"chunk: expected an integer >= 1, got {chunk!r}")
    white = np.empty(step + 1)
    key = root_key(seed)
    R = settings.gyro_range
    even, odd = settings.even_nonlinearity / R, settings.odd_nonlinearity / R**2
    for start in range(0, lead + samples, step):
        stop = min(start + step, lead + samples)
        sine_records(b, a, states, amplitudes, 2.0 * math.pi * frequency,
                     np.ascontiguousarray(phases, dtype=float).ravel(), 1.0 / settings.sample_rate, start - lead,
                     settings.scale_factor, settings.bias + bias_shift,
                     settings.noise_sigma, settings.quantisation, R * settings.scale_factor, key, streams,
                     WHITE_BLOCK, white, out[:, start:stop], even, odd)
    return out[:, lead:]


@dataclass(frozen=True)
class Jjf1537Result:
    """The Monte Carlo of the test, SI (Hz, rad, rad/s); see :func:`run_jjf1537`.

    Per frequency (m,): ``truth_ratio`` |H(f_i)| and ``truth_phase`` arg H (the analytic response);
    ``noise_free_ratio`` |H(f_i)/H(f_1)| (the ratio eq. (9) estimates with S_0 read at the lowest frequency f_1);
    ``ratios``, ``phases`` (trials, m) the estimates; ``bandwidths`` (trials,) the estimated −3 dB
    bandwidths (nan where the response did not cross the level in the measured band); ``gum`` the GUM
    standard uncertainties of the ratios, phases and bandwidth; ``type_a`` the mean over the trials of
    eq. (7)–(9)'s Type A s/√n of the ratios and phases.
    """

    settings: Jjf1537Experiment
    schedule: Jjf1537Schedule
    seed: int
    trials: int
    truth_ratio: np.ndarray
    truth_phase: np.ndarray
    truth_bandwidth: float
    noise_free_ratio: np.ndarray
    noise_free_bandwidth: float
    ratios: np.ndarray
    phases: np.ndarray
    bandwidths: np.ndarray
    gum: dict
    type_a: dict
    vibration_shock: VibrationShockResult | None = None
    #: (trials,) the bandwidth read from the second-order curve fitted to the K_i (JJF 1535 7.2.15.2,
    #: :func:`plansim.estimate.dynamic.bandwidth_curve_fit`), nan where it is not found; and without noise
    bandwidths_fit: np.ndarray = None
    noise_free_bandwidth_fit: float = math.nan

    def summary(self) -> dict:
        """MC mean, standard deviation and bias against the analytic truth of the ratios, the phases (rad) and
        the bandwidth (Hz); the bandwidth's over the trials where it was found."""
        phase_error = wrap_phase(self.phases - self.truth_phase)
        found = self.bandwidths[np.isfinite(self.bandwidths)]
        fitted = self.bandwidths_fit[np.isfinite(self.bandwidths_fit)]
        ddof = 1 if self.trials > 1 else 0
        return {
            "ratio_mean": self.ratios.mean(axis=0), "ratio_std": self.ratios.std(axis=0, ddof=ddof),
            "ratio_bias": self.ratios.mean(axis=0) - self.truth_ratio,
            "phase_mean": self.truth_phase + phase_error.mean(axis=0),
            "phase_std": phase_error.std(axis=0, ddof=ddof), "phase_bias": phase_error.mean(axis=0),
            "bandwidth_mean": float(found.mean()) if found.size else math.nan,
            "bandwidth_std": float(found.std(ddof=1)) if found.size > 1 else math.nan,
            "bandwidth_bias": float(found.mean()) - self.truth_bandwidth if found.size else math.nan,
            "bandwidth_found": int(found.size),
            "bandwidth_fit_mean": float(fitted.mean()) if fitted.size else math.nan,
            "bandwidth_fit_std": float(fitted.std(ddof=1)) if fitted.size > 1 else math.nan,
            "bandwidth_fit_bias": float(fitted.mean()) - self.truth_bandwidth if fitted.size else math.nan,
            "bandwidth_fit_found": int(fitted.size),
        }


def gum_uncertainties(settings: Jjf1537Experiment, response: np.ndarray, level: float = HALF_POWER) -> dict:
    """The GUM (JCGM 100, first order) standard uncertainties of the estimators, from the sine fit's closed form.

    Over (nearly) whole cycles of N_i samples with white noise of variance σ² = σ_w² + q²/12 (the ARW's
    white noise and the quantiser's, uniform), the fitted amplitude has var(E) = 2σ²/N_i and the phase
    var(φ) = 2σ²/(N_i E_i²) (:func:`plansim.estimate.dynamic.sine_fit`); the n repeats' means
    Ē_i (eq. (7)) have these over n, independent between frequencies. The table's errors act once per
    frequency and do not average over the repeats: u²(Ē_i) gains (Ē_i ε_A)² and u²(Δφ_i) gains δ_φ²
    (ε_A, δ_φ the ``table_amplitude_error`` and ``table_phase_error``, :func:`table_errors`). Then, with
    E_i = S A K_i and S_0 read at the lowest frequency (K_i = Ē_i/Ē_1, eq. (8)–(9)),

        u²(K_i) = u²(Ē_i)/Ē_1² + K_i² u²(Ē_1)/Ē_1²   (i > 1; 0 at i = 1),
        u²(Δφ_i) = 2σ²/(n N_i E_i²) + δ_φ²,

    and the interpolated bandwidth f = f_{k−1} + (K_{k−1} − L)(f_k − f_{k−1})/(K_{k−1} − K_k) has the
    sensitivities ∂f/∂K_{k−1} = (f_k − f_{k−1})(L − K_k)/(K_{k−1} − K_k)², ∂f/∂K_k = (f_k − f_{k−1})
    (K_{k−1} − L)/(K_{k−1} − K_k)², carried to the Ē_j (K_{k−1}, K_k and the reference Ē_1 share Ē_1) and
    summed in quadrature. *response* (m,) is |H(f_i)|, at which the sensitivities are evaluated (E_i =
    |S| A |H(f_i)|, K_i = |H(f_i)/H(f_1)|, the noise-free values); the bandwidth's is nan where the K_i do not
    cross *level*. The curve-fitted bandwidth's (``bandwidth_fit``) carries the fit's sensitivities ∂f/∂K_i
    (:attr:`plansim.estimate.dynamic.CurveFitBandwidth.gradient`) to the Ē_j the same way; nan where the fitted
    curve does not cross *level* inside the band.
    """
    schedule = settings.schedule()
    f = schedule.frequencies
    gain = np.asarray(response, dtype=float)
    K = gain / gain[0]
    n = schedule.repeats
    N = schedule.samples()
    sigma2 = settings.noise_sigma**2 + settings.quantisation**2 / 12.0
    E = abs(settings.scale_factor) * schedule.amplitude * gain  # Ē_i
    # u(Ē_i): the noise over n records, and the table's amplitude error, once per frequency
    u_E = np.sqrt(2.0 * sigma2 / (N * n) + (E * settings.table_amplitude_error) ** 2)
    E1 = E[0]
    u_K = np.sqrt(u_E**2 / E1**2 + K**2 * u_E[0] ** 2 / E1**2)
    u_K[0] = 0.0
    u_phase = np.sqrt(2.0 * sigma2 / (n * N * E**2) + settings.table_phase_error**2)
    u_bw = math.nan
    below = np.flatnonzero(K <= level)
    if K[0] >= level and below.size and below[0] > 0:
        k = int(below[0])
        df, dK = f[k] - f[k - 1], K[k - 1] - K[k]
        grad_K = np.zeros(K.size)
        grad_K[k - 1] = df * (level - K[k]) / dK**2
        grad_K[k] = df * (K[k - 1] - level) / dK**2
        u_bw = _through_ratios(grad_K, K, E1, u_E)
    try:
        u_bw_fit = _through_ratios(bandwidth_curve_fit(f, K, level).gradient, K, E1, u_E)
    except ValueError:
        u_bw_fit = math.nan
    return {"ratio": u_K, "phase": u_phase, "bandwidth": u_bw, "bandwidth_fit": u_bw_fit, "amplitude": u_E,
            "sigma": math.sqrt(sigma2)}


def _through_ratios(grad_K: np.ndarray, K: np.ndarray, E1: float, u_E: np.ndarray) -> float:
    """√Σ_j (∂f/∂Ē_j u(Ē_j))² for f a function of the K_l = Ē_l/Ē_1: ∂K_l/∂Ē_l = 1/Ē_1 (l > 0) and
    ∂K_l/∂Ē_1 = −K_l/Ē_1 (K_1 ≡ 1 carries nothing)."""
    grad_E = grad_K / E1
    grad_E[0] = -float(np.dot(grad_K[1:], K[1:])) / E1
    return float(np.sqrt(np.sum((grad_E * u_E) ** 2)))


#: the noise streams of the 7.2.4–7.2.7 records start here (the 7.2.1 records use 0 … trials·m·n − 1)
ITEM_STREAMS = 2**40
#: the noise streams of the shock records (one per trial), apart from every other record's
SHOCK_STREAMS = ITEM_STREAMS + 2**39
#: the records at rest of 7.2.6–7.2.7: before the vibration, after it, after the shock
REST_RECORDS = ("before_vibration", "after_vibration", "after_shock")
#: the figures of 7.2.4–7.2.7, in the report's order
ITEMS = ("amplitude_nonlinearity", "vibration_output_change", "bias_change_vibration", "bias_change_shock")
#: what the shock record shows, per trial: the peak output (its largest departure from the level before, output
#: unit), saturation (0/1) and the recovery time from the pulse's start (s; longer than the shock record: the
#: record after the shock began before the output settled; nan: not settled even by the end of that record)
SHOCK_FIGURES = ("shock_peak_output", "shock_saturated", "shock_recovery_time")
#: the band of the recovery time: z standard deviations of the output at rest plus one quantisation step, z such
#: that white noise alone leaves the band somewhere in the shock record with this probability
RECOVERY_FALSE_ALARM = 0.01
#: the coverage factor of the intervals whose coverage the Monte Carlo counts
COVERAGE_FACTOR = 2.0


def item_phases(seed: int, trial: int, count: int) -> np.ndarray:
    """The table phases of trial *trial*'s 7.2.4 and 7.2.5 records, uniform on [−π, π), from
    ``default_rng([seed, trial, 1])`` (a generator apart from :func:`table_phases`')."""
    return np.random.default_rng([int(seed), int(trial), 1]).uniform(-math.pi, math.pi, count)


def vibration_shock_truth(settings: Jjf1537Experiment) -> dict:
    """The figures of 7.2.4–7.2.7 of the simulated sensor, in closed form (docs/dynamic.md).

    With a = A|H(j2πf)| the rate amplitude after the dynamics, g's fundamental a + 3c₃'a³/4 and mean c₂'a²/2
    (:func:`plansim.model.dynamics.static_nonlinearity_harmonics`, c₂' = c₂/R, c₃' = c₃/R²): the amplitude
    nonlinearity is :func:`plansim.estimate.dynamic.amplitude_nonlinearity` of the exact fundamentals,

        γ = (3/4)|c₃'| |H|² max_k |A_k² − ⟨A²⟩| / |1 + (3/4) c₃' |H|² ⟨A²⟩|,

    the output change under vibration S c₂'a²/2 (output unit), the bias changes the two shifts; and the shock
    record's noise-free peak output ``shock_peak_output`` (:func:`shock_peak_truth`).
    """
    sch = settings.vibration_shock_schedule()
    gain = float(abs(settings.dynamics().response(sch.frequency)))
    R = settings.gyro_range
    c2, c3 = settings.even_nonlinearity / R, settings.odd_nonlinearity / R**2
    _, fundamental = static_nonlinearity_harmonics(sch.amplitudes * gain, c2, c3)
    mean, _ = static_nonlinearity_harmonics(sch.amplitude * gain, c2, c3)
    exact = np.abs(settings.scale_factor * fundamental)  # the Ē_k without noise
    return {"amplitude_nonlinearity": amplitude_nonlinearity(sch.amplitudes, exact),
            "vibration_output_change": float(settings.scale_factor * mean),
            "bias_change_vibration": settings.vibration_bias_shift, "bias_change_shock": settings.shock_bias_shift,
            "shock_peak_output": shock_peak_truth(settings)}


def shock_input(settings: Jjf1537Experiment) -> np.ndarray:
    """The gyro's input across the shock record and the record after it, rad/s: the g-sensitivity times the
    half-sine (:func:`plansim.model.dynamics.half_sine`), (shock samples + rest samples,)."""
    sch = settings.vibration_shock_schedule()
    total = sch.shock_samples() + sch.rest_samples()
    return settings.g_sensitivity * half_sine(settings.shock_peak, sch.shock_duration, sch.sample_rate, total)


def shock_filter(settings: Jjf1537Experiment) -> tuple[np.ndarray, np.ndarray]:
    """(b, a) of the sensor's dynamics for the shock: :func:`discretise` prewarped at the half-sine's
    fundamental 1/(2·duration) (45 Hz for 11 ms), where most of the pulse's energy lies."""
    return discretise(settings.dynamics(), 0.5 / settings.shock_duration, settings.sample_rate)


def shock_noise_free(settings: Jjf1537Experiment) -> np.ndarray:
    """The shock record's output without noise or quantisation, less the level before the shock (output
    unit): S·g((H x)) and the bias step after the pulse, saturated at the range. ``scipy.signal.lfilter`` on
    :func:`shock_filter`'s coefficients: a check on the kernel as well as the truth."""
    sch = settings.vibration_shock_schedule()
    b, a = shock_filter(settings)
    x = shock_input(settings)[: sch.shock_samples()]
    v = scipy.signal.lfilter(b, a, x)
    R = settings.gyro_range
    v = v + v * v * (settings.even_nonlinearity / R + settings.odd_nonlinearity / R**2 * v)
    level = settings.bias + settings.vibration_bias_shift
    y = settings.scale_factor * v + level
    y[sch.pulse_samples():] += settings.shock_bias_shift
    limit = R * settings.scale_factor
    return np.clip(y, -limit, limit) - level


def shock_peak_truth(settings: Jjf1537Experiment) -> float:
    """The shock record's largest departure from the level before it, noise-free (:func:`shock_noise_free`)."""
    return float(np.max(np.abs(shock_noise_free(settings))))


def vibration_shock_gum(settings: Jjf1537Experiment) -> dict:
    """The GUM (JCGM 100, first order) standard uncertainties of the 7.2.4–7.2.7 figures, by item.

    The three changes of mean (output unit): σ√(1/N₁ + 1/N₂) with σ² = σ_w² + q²/12 (the white noise's and the
    quantiser's), N the two records' samples; the vibration record's mean is its sine fit's C, var(C) = σ²/N
    over whole cycles.

    The amplitude nonlinearity γ = |S_k* − S̄|/S̄ (k* where |S_k − S̄| is largest), evaluated at the noise-free
    S_k: with d_j = S_j − S̄ and s* the sign of d_k*,

        ∂γ/∂S_j = s* [(δ_jk* − 1/M)/S̄ − d_k*/(M S̄²)],        u²(S_j) = 2σ²/(nN A_j²) + (S_j ε_A)²

    (var(E) = 2σ²/N per record, n records; ε_A the table's relative amplitude error, once per amplitude), summed
    in quadrature. nan when γ is not differentiable there: a
    linear sensor (every d_j = 0) or two amplitudes tied for the maximum. It holds while the noise does not
    move the maximum to another amplitude (the runner-up several u below).
    """
    sch = settings.vibration_shock_schedule()
    sigma = math.sqrt(settings.noise_sigma**2 + settings.quantisation**2 / 12.0)
    rest = sch.rest_samples()
    gain = float(abs(settings.dynamics().response(sch.frequency)))
    _, fundamental = static_nonlinearity_harmonics(sch.amplitudes * gain, 0.0,
                                                   settings.odd_nonlinearity / settings.gyro_range**2)
    S = np.abs(settings.scale_factor * fundamental) / sch.amplitudes
    M, mean = S.size, S.mean()
    d = S - mean
    order = np.argsort(-np.abs(d))
    u_nonlinearity = math.nan
    scale = np.max(np.abs(S))
    if abs(d[order[0]]) > 1e-9 * scale and abs(d[order[0]]) - abs(d[order[1]]) > 1e-9 * scale:
        k = int(order[0])
        grad = -np.full(M, 1.0 / M) / mean - d[k] / (M * mean**2)
        grad[k] += 1.0 / mean
        grad *= math.copysign(1.0, d[k])
        u_S = np.sqrt(2.0 * sigma**2 / (sch.repeats * sch.samples(sch.record_time)) / sch.amplitudes**2
                      + (S * settings.table_amplitude_error) ** 2)
        u_nonlinearity = float(np.sqrt(np.sum((grad * u_S) ** 2)))
    return {"amplitude_nonlinearity": u_nonlinearity,
            "vibration_output_change": sigma * math.sqrt(1.0 / sch.samples(sch.vibration_time) + 1.0 / rest),
            "bias_change_vibration": sigma * math.sqrt(2.0 / rest), "bias_change_shock": sigma * math.sqrt(2.0 / rest)}


def simulate_vibration_shock(settings: Jjf1537Experiment, seed: int, trials, chunk: int | None = None) -> dict:
    """The 7.2.4–7.2.7 records of the trials *trials* (T,), output unit: ``linearity`` (T, M, n, N) at the M
    amplitudes, ``vibration`` (T, N_v), ``rest`` (T, 3, N_r) before the vibration, after it (the bias
    shifted by ``vibration_bias_shift``) and after the shock (shifted by both), and ``shock`` (T, N_s), the
    record from the pulse's start (:func:`shock_records`; the record after the shock continues it). Every
    record has its own noise stream above :data:`ITEM_STREAMS`; *chunk* as :func:`simulate_records`."""
    sch = settings.vibration_shock_schedule()
    trials = np.asarray(trials, dtype=np.int64).ravel()
    M, n = sch.amplitudes.size, sch.repeats
    per_trial = M * n + 1 + len(REST_RECORDS)  # streams per trial
    base = ITEM_STREAMS + trials * per_trial
    phases = np.stack([item_phases(seed, t, M * n + 1) for t in trials])  # (T, M n + 1)
    N = sch.samples(sch.record_time)
    linearity = np.empty((trials.size, M, n, N))
    eps = np.stack([table_errors(settings, seed, t, M, ITEM_TABLE_ERROR_STREAM)[0] for t in trials])  # (T, M)
    for k, A in enumerate(sch.amplitudes):
        streams = (base[:, None] + k * n + np.arange(n)[None, :]).ravel()
        amplitudes = np.repeat(float(A) * (1.0 + eps[:, k]), n)  # the table's amplitude error at A_k (7.2.4)
        linearity[:, k] = table_records(settings, seed, sch.frequency, amplitudes, phases[:, k * n:(k + 1) * n],
                                        N, streams, chunk).reshape(trials.size, n, N)
    vibration = table_records(settings, seed, sch.frequency, sch.amplitude, phases[:, -1],
                              sch.samples(sch.vibration_time), base + M * n, chunk)
    rest = [table_records(settings, seed, sch.frequency, 0.0, np.zeros(trials.size), sch.rest_samples(),
                          base + M * n + 1 + r, chunk, bias_shift=shift)
            for r, shift in enumerate((0.0, settings.vibration_bias_shift))]
    shock, after = shock_records(settings, seed, trials, base + M * n + 3, chunk)
    return {"linearity": linearity, "vibration": vibration, "rest": np.stack(rest + [after], axis=1), "shock": shock}


def shock_records(settings: Jjf1537Experiment, seed: int, trials, after_streams, chunk: int | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The shock record and the record at rest after it, (T, N_s) and (T, N_r), output unit.

    The sensor is at rest (its filter state zero) when the pulse starts; its input is :func:`shock_input`
    through :func:`shock_filter` (:func:`plansim.kernels.dynamics.input_records`); the bias is B +
    ``vibration_bias_shift`` during the pulse and ``shock_bias_shift`` more from its end. The record after the
    shock continues the filter's state, so a ringing that has not died out by then is in it; its noise is the
    stream *after_streams* (T,), the shock record's :data:`SHOCK_STREAMS` + trial. Without a pulse (``shock_peak``
    or ``g_sensitivity`` 0) the record after the shock is the record at rest it always was, number for number.
    """
    sch = settings.vibration_shock_schedule()
    trials = np.asarray(trials, dtype=np.int64).ravel()
    x = shock_input(settings)
    b, a = shock_filter(settings)
    states = np.zeros((trials.size, len(a) - 1))
    pulse, total = sch.pulse_samples(), sch.shock_samples()
    level = settings.bias + settings.vibration_bias_shift
    shock = np.empty((trials.size, total))
    after = np.empty((trials.size, sch.rest_samples()))
    own = SHOCK_STREAMS + trials
    for start, stop, first, streams, bias, out in (
            (0, pulse, 0, own, level, shock[:, :pulse]),
            (pulse, total, pulse, own, level + settings.shock_bias_shift, shock[:, pulse:]),
            (total, x.size, 0, np.asarray(after_streams, dtype=np.int64), level + settings.shock_bias_shift, after)):
        _driven_records(settings, seed, b, a, states, x[start:stop], first, streams, bias, out, chunk)
    return shock, after


def _driven_records(settings, seed, b, a, states, inputs, first, streams, bias, out, chunk) -> None:
    """:func:`plansim.kernels.dynamics.input_records` over *out* (R, n) in chunks of *chunk* samples (None: one)."""
    n = out.shape[1]
    step = max(n, 1) if chunk is None else int(chunk)
    if step < 1:
        raise ValueError(f"chunk: expected an integer >= 1, got {chunk!r}")
    white = np.empty(step)
    key = root_key(seed)
    R = settings.gyro_range
    streams = np.ascontiguousarray(streams, dtype=np.int64).ravel()
    for start in range(0, n, step):
        stop = min(start + step, n)
        input_records(b, a, states, np.ascontiguousarray(inputs[start:stop]), first + start, settings.scale_factor,
                      bias, settings.noise_sigma, settings.quantisation, R * settings.scale_factor, key, streams,
                      WHITE_BLOCK, white, out[:, start:stop], settings.even_nonlinearity / R,
                      settings.odd_nonlinearity / R**2)


def reduce_vibration_shock(settings: Jjf1537Experiment, records: dict) -> tuple[dict, dict]:
    """One trial's 7.2.4–7.2.7 records (:func:`simulate_vibration_shock`, without the trial axis) reduced:
    (estimates, Type A standard uncertainties) by the name of :data:`ITEMS`.

    - 7.2.4: the sine fit of eq. (6) of every record, Ē_k over its n repeats (eq. (7)), and
      :func:`plansim.estimate.dynamic.amplitude_nonlinearity` of (A_k, Ē_k); no Type A here (nan).
    - 7.2.5: the mean output under vibration, the sine fit's C (the record less its fitted sinusoid), less the
      mean at rest before it, by :func:`plansim.estimate.dynamic.mean_change`.
    - 7.2.6, 7.2.7: :func:`mean_change` from before to after the vibration, and from after the vibration
      to after the shock.
    - the shock record: :func:`plansim.estimate.dynamic.shock_response` against the levels after the vibration
      and after the shock over the shock record and the record after it together, the band z·s + q (s the
      standard deviation of the record after the shock, q the quantisation step, z = Φ⁻¹(1 − α/(2N)) for their N
      samples and α = :data:`RECOVERY_FALSE_ALARM`, so white noise alone reads a recovery time other than 0 in
      about 1 % of trials): :data:`SHOCK_FIGURES`. A recovery time longer
      than the shock record means the record after the shock began before the output had settled.
    """
    sch = settings.vibration_shock_schedule()
    dt = 1.0 / sch.sample_rate
    lin = records["linearity"]
    fits = sine_fits(np.arange(lin.shape[-1]) * dt, lin, sch.frequency)
    nonlinearity = amplitude_nonlinearity(sch.amplitudes, fits.amplitude.mean(axis=-1))
    vib = records["vibration"]
    t = np.arange(vib.size) * dt
    fit = sine_fits(t, vib, sch.frequency)
    level = vib - fit.amplitude * np.cos(2.0 * math.pi * sch.frequency * t + fit.phase)
    rest = records["rest"]
    output_change, u_output = mean_change(rest[0], level)
    bias_vibration, u_vibration = mean_change(rest[0], rest[1])
    bias_shock, u_shock = mean_change(rest[1], rest[2])
    limit = settings.gyro_range * settings.scale_factor
    shock = records["shock"]
    z = float(scipy.stats.norm.isf(0.5 * RECOVERY_FALSE_ALARM / (shock.size + rest[2].size)))
    band = max(z * float(np.std(rest[2], ddof=1)) + settings.quantisation, 1e-12 * limit)
    response = shock_response(np.concatenate([shock, rest[2]]), float(rest[1].mean()), float(rest[2].mean()), band,
                              sch.sample_rate, limit)
    values = (nonlinearity, output_change, bias_vibration, bias_shock, response.peak, response.saturated,
              response.recovery_time)
    uncertainties = (math.nan, u_output, u_vibration, u_shock)
    return ({k: float(v) for k, v in zip(ITEMS + SHOCK_FIGURES, values)},
            {k: float(u) for k, u in zip(ITEMS, uncertainties)})


@dataclass(frozen=True)
class VibrationShockResult:
    """The Monte Carlo of JJF 1537-2015 7.2.4–7.2.7 (output unit; the nonlinearity dimensionless).

    ``truth``, ``gum``: by item (:data:`ITEMS`), :func:`vibration_shock_truth` and
    :func:`vibration_shock_gum` (the nonlinearity's nan for a linear sensor: a maximum of absolute values);
    ``estimates``, ``type_a``: (trials,) per item, the figure and its Type A u per trial (``estimates`` also
    holds :data:`SHOCK_FIGURES`).
    """

    schedule: VibrationShockSchedule
    truth: dict
    gum: dict
    estimates: dict
    type_a: dict

    def summary(self) -> dict:
        """Per item: MC ``mean``, ``std`` (ddof 1), ``bias`` against the truth, ``type_a_mean``, ``gum``, and
        ``coverage``, the fraction of trials where |estimate − truth| ≤ 2 u_A (nan where there is no u_A)."""
        out = {}
        for name in ITEMS:
            x, u = self.estimates[name], self.type_a[name]
            covered = np.abs(x - self.truth[name]) <= COVERAGE_FACTOR * u
            out[name] = {
                "truth": float(self.truth[name]), "mean": float(x.mean()),
                "std": float(x.std(ddof=1)) if x.size > 1 else math.nan, "bias": float(x.mean() - self.truth[name]),
                "type_a_mean": float(u.mean()), "gum": float(self.gum.get(name, math.nan)),
                "coverage": float(covered.mean()) if np.all(np.isfinite(u)) else math.nan,
            }
        return out

    def shock_summary(self) -> dict:
        """The shock record over the trials: the peak output's ``peak_truth`` (noise-free), ``peak_mean``,
        ``peak_std`` (output unit), ``saturated`` (trials with a sample at the range), ``not_settled``
        (trials whose output was still outside the band when the record after the shock began: a recovery time
        longer than the shock record, or none), and the recovery time's ``median`` and ``max`` over the trials
        that have one (s; nan if none)."""
        recovery = self.estimates["shock_recovery_time"]
        record = self.schedule.shock_samples() / self.schedule.sample_rate
        known = recovery[np.isfinite(recovery)]
        peak = self.estimates["shock_peak_output"]
        return {"peak_truth": float(self.truth["shock_peak_output"]), "peak_mean": float(peak.mean()),
                "peak_std": float(peak.std(ddof=1)) if peak.size > 1 else math.nan,
                "saturated": int(np.sum(self.estimates["shock_saturated"] > 0)),
                "not_settled": int(np.sum(~(recovery <= record))), "shock_record": record,
                "recovery_median": float(np.median(known)) if known.size else math.nan,
                "recovery_max": float(np.max(known)) if known.size else math.nan}


def run_vibration_shock(settings: Jjf1537Experiment | None = None, trials: int = DEFAULT_TRIALS,
                        seed: int = DEFAULT_SEED, chunk_trials: int = 32) -> VibrationShockResult:
    """The Monte Carlo of JJF 1537-2015 7.2.4–7.2.7 alone (:func:`run_jjf1537` runs it with 7.2.1–7.2.3):
    *trials* trials simulated (:func:`simulate_vibration_shock`) and reduced (:func:`reduce_vibration_shock`).
    The numbers depend on (settings, seed, trial) only, not on *chunk_trials*."""
    settings = Jjf1537Experiment() if settings is None else settings
    _check_run(seed, trials, chunk_trials)
    estimates = {k: np.empty(trials) for k in ITEMS + SHOCK_FIGURES}
    type_a = {k: np.empty(trials) for k in ITEMS}
    for first in range(0, trials, chunk_trials):
        _vibration_shock_block(settings, seed, np.arange(first, min(first + chunk_trials, trials)), estimates, type_a)
    return _vibration_shock_result(settings, estimates, type_a)


def _vibration_shock_block(settings, seed, block, estimates, type_a) -> None:
    records = simulate_vibration_shock(settings, seed, block)
    for c, trial in enumerate(block):
        values, u = reduce_vibration_shock(settings, {k: v[c] for k, v in records.items()})
        for name in ITEMS:
            type_a[name][trial] = u[name]
        for name in ITEMS + SHOCK_FIGURES:
            estimates[name][trial] = values[name]


def _vibration_shock_result(settings, estimates, type_a) -> VibrationShockResult:
    return VibrationShockResult(schedule=settings.vibration_shock_schedule(), truth=vibration_shock_truth(settings),
                                gum=vibration_shock_gum(settings), estimates=estimates, type_a=type_a)


def _check_run(seed, trials, chunk_trials) -> None:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise ValueError(f"trials: expected an integer >= 1, got {trials!r}")
    if isinstance(chunk_trials, bool) or not isinstance(chunk_trials, (int, np.integer)) or chunk_trials < 1:
        raise ValueError(f"chunk_trials: expected an integer >= 1, got {chunk_trials!r}")


def run_jjf1537(settings: Jjf1537Experiment | None = None, trials: int = DEFAULT_TRIALS, seed: int = DEFAULT_SEED,
                chunk_trials: int = 32, progress=None) -> Jjf1537Result:
    """Simulate *trials* runs of the test and reduce each as JJF 1537-2015 7.2.1 does (module docstring).

    *chunk_trials*: trials simulated per step (memory only; the numbers do not depend on it). *progress*:
    called as progress(done, total) in trials.
    """
    settings = Jjf1537Experiment() if settings is None else settings
    _check_run(seed, trials, chunk_trials)
    schedule = settings.schedule()
    dynamics = settings.dynamics()
    freqs = schedule.frequencies
    m, n = freqs.size, schedule.repeats
    H = dynamics.response(freqs)
    truth_ratio, truth_phase = np.abs(H), np.angle(H)
    # the fundamental the sine fit reads: |H| A, or g's (a + 3c₃'a³/4) with the amplitude nonlinearity on
    _, fundamental = static_nonlinearity_harmonics(schedule.amplitude * truth_ratio,
                                                   settings.even_nonlinearity / settings.gyro_range,
                                                   settings.odd_nonlinearity / settings.gyro_range**2)
    noise_free = np.abs(fundamental) / abs(fundamental[0])
    try:
        noise_free_bw = bandwidth_3db(freqs, noise_free)
    except ValueError:
        noise_free_bw = math.nan
    try:
        noise_free_bw_fit = bandwidth_curve_fit(freqs, noise_free).bandwidth
    except ValueError:
        noise_free_bw_fit = math.nan

    ratios = np.empty((trials, m))
    phases = np.empty((trials, m))
    bandwidths = np.full(trials, math.nan)
    bandwidths_fit = np.full(trials, math.nan)
    ratio_u = np.empty((trials, m))
    phase_u = np.empty((trials, m))
    A = schedule.amplitude
    item_estimates = {k: np.empty(trials) for k in ITEMS + SHOCK_FIGURES}
    item_type_a = {k: np.empty(trials) for k in ITEMS}
    for first in range(0, trials, chunk_trials):
        block = np.arange(first, min(first + chunk_trials, trials))
        table = np.stack([table_phases(seed, t, (m, n)) for t in block])  # (c, m, n): what the lab reads
        errors = [table_errors(settings, seed, t, m) for t in block]
        eps = np.stack([e[0] for e in errors])                              # (c, m) amplitude, relative
        delta = np.stack([e[1] for e in errors])                            # (c, m) phase, rad
        E = np.empty((block.size, m, n))
        phi = np.empty((block.size, m, n))
        for i in range(m):
            records = simulate_records(settings, seed, i, block, phases=table[:, i, :] + delta[:, i, None],
                                       amplitude_errors=eps[:, i])
            t = np.arange(records.shape[-1]) * schedule.interval
            for c in range(block.size):  # one trial's n records at a time: the same numbers whatever the chunk
                fits = sine_fits(t, records[c], freqs[i])  # JJF 1537-2015 eq. (6), per record
                E[c, i, :] = fits.amplitude
                phi[c, i, :] = fits.phase
        for c, trial in enumerate(block):
            S0 = E[c, 0].mean() / A  # the zero-frequency sensitivity, read at the lowest frequency
            response = frequency_response(freqs, E[c], phi[c], A, S0, input_phases=table[c])
            ratios[trial] = response.ratios
            phases[trial] = response.phases
            ratio_u[trial] = response.ratio_std_of_mean
            phase_u[trial] = response.phase_std_of_mean
            try:
                bandwidths[trial] = bandwidth_3db(freqs, response.ratios)
            except ValueError:
                pass
            try:  # JJF 1535 7.2.15.2's reading: a curve fitted to the scale factor against frequency
                bandwidths_fit[trial] = bandwidth_curve_fit(freqs, response.ratios).bandwidth
            except ValueError:
                pass
        _vibration_shock_block(settings, seed, block, item_estimates, item_type_a)  # 7.2.4–7.2.7
        if progress is not None:
            progress(int(block[-1]) + 1, trials)
    return Jjf1537Result(
        settings=settings, schedule=schedule, seed=int(seed), trials=int(trials), truth_ratio=truth_ratio,
        truth_phase=truth_phase, truth_bandwidth=dynamics.bandwidth(), noise_free_ratio=noise_free,
        noise_free_bandwidth=noise_free_bw, ratios=ratios, phases=phases, bandwidths=bandwidths,
        gum=gum_uncertainties(settings, truth_ratio),
        type_a={"ratio": ratio_u.mean(axis=0), "phase": phase_u.mean(axis=0)},
        vibration_shock=_vibration_shock_result(settings, item_estimates, item_type_a),
        bandwidths_fit=bandwidths_fit, noise_free_bandwidth_fit=noise_free_bw_fit,
    )
