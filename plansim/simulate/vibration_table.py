"""The angular vibration table of JJF 1537-2015 and the gyro on it: the experiment's settings and the records.

:class:`Jjf1537Experiment` holds the settings of ``plansim run jjf1537`` (:data:`FIELDS` lists what ``--set``
changes); :func:`table_records` makes the records of a table turning a gyro, used by the amplitude- and
phase-frequency test (:mod:`plansim.simulate.jjf1537`) and by items 7.2.4–7.2.7
(:mod:`plansim.simulate.jjf1537_items`). docs/dynamic.md.

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

**Reproducibility.** Every noise sample is a function of (seed, record, sample index) and the filter state
is carried from chunk to chunk: the numbers do not depend on the chunking, in time or in trials.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.signal

from plansim.kernels.dynamics import sine_records
from plansim.kernels.random import root_key
from plansim.model.dynamics import SENSOR_MODELS, SensorDynamics, one_number
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
    "gyro_rrw": ("rate_random_walk", "7.2.5-7.2.7: the bias's rate random walk across the records at rest, vibration "
                                     "and shock, e.g. '10 deg/h/sqrt(h)'; 0: none (default)"),
    "table_phase_error": ("angle", "the table's phase error against its reference signal, standard deviation, drawn "
                                   "once per frequency of each trial, e.g. '0.2 deg'; 0: none (default)"),
}
_CHOICES = {"model": SENSOR_MODELS, "grid": ("jjf1535", "jjf1537")}
_MAY_BE_ZERO = ("gyro_arw", "quantisation", "table_amplitude_error", "table_phase_error", "gyro_rrw")
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
    gyro_rrw: float = 0.0                         # rad/s/√s, the bias's rate random walk (7.2.5–7.2.7)
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


#: the random substreams of a trial, ``default_rng([seed, trial, stream])``, one table for every draw of the test so
#: that no two share one: 7.2.4's and 7.2.5's table phases (:func:`plansim.simulate.jjf1537_items.item_phases`), the
#: table's errors of 7.2.1 and of 7.2.4 (:func:`table_errors`), the bias's drift
#: (:func:`plansim.simulate.jjf1537_items.drift_offsets`); 7.2.1's table phases use ``[seed, trial]``
#: (:func:`table_phases`)
ITEM_PHASE_STREAM, TABLE_ERROR_STREAM, ITEM_TABLE_ERROR_STREAM, DRIFT_STREAM = 1, 2, 3, 4


def table_errors(settings: Jjf1537Experiment, seed: int, trial: int, count: int, stream: int = TABLE_ERROR_STREAM
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(ε, δ), each (count,): the table's relative amplitude errors ε ~ N(0, ``table_amplitude_error``²) and phase
    errors δ ~ N(0, ``table_phase_error``²) (rad) of trial *trial*, one per setting (a frequency of 7.2.1, an
    amplitude of 7.2.4), from ``default_rng([seed, trial, stream])``. The table turns at A(1 + ε) and phase φ_in + δ
    while the lab reads A and φ_in: an error that acts once per setting, so the n repeats do not average it down.
    Exactly 0 when the settings have none (the records are then those of a perfect table, number for number)."""
    draws = np.random.default_rng([int(seed), int(trial), int(stream)]).standard_normal((2, count))
    return settings.table_amplitude_error * draws[0], settings.table_phase_error * draws[1]


def table_records(settings: Jjf1537Experiment, seed: int, frequency: float, amplitude, phases, samples: int,
                  streams, chunk: int | None = None, bias_shift=0.0) -> np.ndarray:
    """One record per stream (R,) of *samples* samples: the table at *frequency* (Hz) and rate *amplitude* (rad/s, one
    for all or (R,) one per record; 0: at rest) with the phases *phases* (R,), through the sensor of *settings*
    after its run-in (:func:`plansim.kernels.dynamics.sine_records`), the output bias B + *bias_shift* (output
    unit, as B; one for all or (R,) one per record). (R, samples), output unit; *chunk*: samples per kernel call
    along time (None: the run-in and the record in one call); the numbers do not depend on it."""
    streams = np.ascontiguousarray(streams, dtype=np.int64).ravel()
    amplitudes = np.ascontiguousarray(np.broadcast_to(np.asarray(amplitude, dtype=float), streams.shape))
    biases = settings.bias + np.ascontiguousarray(np.broadcast_to(np.asarray(bias_shift, dtype=float), streams.shape))
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
                     settings.scale_factor, biases,
                     settings.noise_sigma, settings.quantisation, R * settings.scale_factor, key, streams,
                     WHITE_BLOCK, white, out[:, start:stop], even, odd)
    return out[:, lead:]


def check_run(seed, trials, chunk_trials) -> None:
    """A run's seed (>= 0), trials and chunk_trials (>= 1), each a ValueError naming it."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise ValueError(f"trials: expected an integer >= 1, got {trials!r}")
    if isinstance(chunk_trials, bool) or not isinstance(chunk_trials, (int, np.integer)) or chunk_trials < 1:
        raise ValueError(f"chunk_trials: expected an integer >= 1, got {chunk_trials!r}")

