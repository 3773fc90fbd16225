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

**Reproducibility.** Every noise sample is a function of (seed, record, sample index) and the filter state
is carried from chunk to chunk: the numbers do not depend on the chunking, in time or in trials.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
import scipy.signal

from plansim.estimate.dynamic import HALF_POWER, bandwidth_3db, frequency_response, sine_fits, wrap_phase
from plansim.kernels.dynamics import sine_records
from plansim.kernels.random import root_key
from plansim.model.dynamics import SENSOR_MODELS, SensorDynamics, one_number
from plansim.schedule.jjf1537 import Jjf1537Schedule, amplitude_in_range, jjf1535_frequencies, jjf1537_frequencies
from plansim.units import DEG, parse_quantity

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
}
_CHOICES = {"model": SENSOR_MODELS, "grid": ("jjf1535", "jjf1537")}
_MAY_BE_ZERO = ("gyro_arw", "quantisation")
_ANY_SIGN = ("bias",)


@dataclass(frozen=True)
class Jjf1537Experiment:
    """The test's settings, SI (module docstring; :data:`FIELDS` lists what ``--set`` changes).

    Defaults: a ±300 °/s digital MEMS gyro (output in rad/s), 16-bit output (step 600 °/s / 2¹⁶), ARW
    0.5 °/√h, bias 0.1 °/s, second-order dynamics f_n = 100 Hz, ζ = 0.7 (f_3dB = 101.0 Hz); the table at
    20 % of the range (60 °/s); JJF 1535 7.2.15.1 b)'s grid for an expected bandwidth of 100 Hz (10
    points, 13.75–110 Hz); n = 7; 4 kHz; 1 s records.
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

    @property
    def noise_sigma(self) -> float:
        """σ = S·N/√Δt, the white noise's standard deviation per sample, output unit."""
        return self.scale_factor * self.gyro_arw * math.sqrt(self.sample_rate)


def with_overrides(settings: Jjf1537Experiment, overrides) -> Jjf1537Experiment:
    """*settings* with ``KEY=VALUE`` strings applied (quantities as '<number> <unit>', :mod:`plansim.units`);
    an error names the key, the value and what is allowed."""
    changes = {}
    for item in overrides:
        key, sep, text = str(item).partition("=")
        key, text = key.strip(), text.strip().strip("'\"")
        if not sep or key not in FIELDS:
            raise ValueError(f"--set {item!r}: expected KEY=VALUE with KEY one of {', '.join(FIELDS)}")
        kind = FIELDS[key][0]
        if kind == "choice":
            changes[key] = text
        elif kind == "count":
            try:
                changes[key] = int(text)
            except ValueError:
                raise ValueError(f"--set {item!r}: {key} expects an integer") from None
        else:
            try:
                changes[key] = parse_quantity(text if kind != "dimensionless" else _number_or_text(text), kind, key)
            except ValueError as exc:
                raise ValueError(f"--set {item!r}: {exc}") from None
    return dataclasses.replace(settings, **changes, overrides=tuple(settings.overrides) + tuple(overrides))


def _number_or_text(text: str):
    try:
        return float(text)
    except ValueError:
        return text


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


def simulate_records(settings: Jjf1537Experiment, seed: int, index: int, trials, chunk: int | None = None,
                     phases: np.ndarray | None = None) -> np.ndarray:
    """The records at the frequency number *index* for the trials *trials*: (len(trials), n, N_i), output unit.

    *chunk*: samples per kernel call along time (None: the run-in and the record in one call); the result
    does not depend on it. *phases*: (len(trials), n) table phases (default: :func:`table_phases`).
    """
    schedule = settings.schedule()
    trials = np.asarray(trials, dtype=np.int64).ravel()
    m, n = schedule.frequencies.size, schedule.repeats
    f = float(schedule.frequencies[index])
    N = int(schedule.samples()[index])
    b, a = discretise(settings.dynamics(), f, schedule.sample_rate)
    lead = run_in_samples(a)
    if phases is None:
        phases = np.stack([table_phases(seed, t, (m, n))[index] for t in trials])
    rows = trials.size * n
    streams = ((trials[:, None] * m + index) * n + np.arange(n)[None, :]).ravel().astype(np.int64)
    states = np.zeros((rows, len(a) - 1))
    out = np.empty((rows, lead + N))
    step = lead + N if chunk is None else int(chunk)
    if step < 1:
        raise ValueError(f"chunk: expected an integer >= 1, got {chunk!r}")
    white = np.empty(step + 1)
    key = root_key(seed)
    for start in range(0, lead + N, step):
        stop = min(start + step, lead + N)
        sine_records(b, a, states, schedule.amplitude, 2.0 * math.pi * f, np.ascontiguousarray(phases).ravel(),
                     schedule.interval, start - lead, settings.scale_factor, settings.bias, settings.noise_sigma,
                     settings.quantisation, settings.gyro_range * settings.scale_factor, key, streams, WHITE_BLOCK,
                     white, out[:, start:stop])
    return out[:, lead:].reshape(trials.size, n, N)


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

    def summary(self) -> dict:
        """MC mean, standard deviation and bias against the analytic truth of the ratios, the phases (rad) and
        the bandwidth (Hz); the bandwidth's over the trials where it was found."""
        phase_error = wrap_phase(self.phases - self.truth_phase)
        found = self.bandwidths[np.isfinite(self.bandwidths)]
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
        }


def gum_uncertainties(settings: Jjf1537Experiment, response: np.ndarray, level: float = HALF_POWER) -> dict:
    """The GUM (JCGM 100, first order) standard uncertainties of the estimators, from the sine fit's closed form.

    Over (nearly) whole cycles of N_i samples with white noise of variance σ² = σ_w² + q²/12 (the ARW's
    white noise and the quantiser's, uniform), the fitted amplitude has var(E) = 2σ²/N_i and the phase
    var(φ) = 2σ²/(N_i E_i²) (:func:`plansim.estimate.dynamic.sine_fit`); the n repeats' means
    Ē_i (eq. (7)) have these over n, independent between frequencies. Then, with E_i = S A K_i and S_0
    read at the lowest frequency (K_i = Ē_i/Ē_1, eq. (8)–(9)),

        u²(K_i) = u²(Ē_i)/Ē_1² + K_i² u²(Ē_1)/Ē_1²   (i > 1; 0 at i = 1),
        u²(Δφ_i) = 2σ²/(n N_i E_i²),

    and the interpolated bandwidth f = f_{k−1} + (K_{k−1} − L)(f_k − f_{k−1})/(K_{k−1} − K_k) has the
    sensitivities ∂f/∂K_{k−1} = (f_k − f_{k−1})(L − K_k)/(K_{k−1} − K_k)², ∂f/∂K_k = (f_k − f_{k−1})
    (K_{k−1} − L)/(K_{k−1} − K_k)², carried to the Ē_j (K_{k−1}, K_k and the reference Ē_1 share Ē_1) and
    summed in quadrature. *response* (m,) is |H(f_i)|, at which the sensitivities are evaluated (E_i =
    |S| A |H(f_i)|, K_i = |H(f_i)/H(f_1)|, the noise-free values); the bandwidth's is nan where the K_i do not
    cross *level*.
    """
    schedule = settings.schedule()
    f = schedule.frequencies
    gain = np.asarray(response, dtype=float)
    K = gain / gain[0]
    n = schedule.repeats
    N = schedule.samples()
    sigma2 = settings.noise_sigma**2 + settings.quantisation**2 / 12.0
    E = abs(settings.scale_factor) * schedule.amplitude * gain  # Ē_i
    u_E = np.sqrt(2.0 * sigma2 / (N * n))                          # u(Ē_i)
    E1 = E[0]
    u_K = np.sqrt(u_E**2 / E1**2 + K**2 * u_E[0] ** 2 / E1**2)
    u_K[0] = 0.0
    u_phase = np.sqrt(2.0 * sigma2 / (n * N * E**2))
    u_bw = math.nan
    below = np.flatnonzero(K <= level)
    if K[0] >= level and below.size and below[0] > 0:
        k = int(below[0])
        df, dK = f[k] - f[k - 1], K[k - 1] - K[k]
        grad_K = np.zeros(K.size)
        grad_K[k - 1] = df * (level - K[k]) / dK**2
        grad_K[k] = df * (K[k - 1] - level) / dK**2
        # K_l = Ē_l/Ē_1: ∂K_l/∂Ē_l = 1/Ē_1 (l > 0), ∂K_l/∂Ē_1 = −K_l/Ē_1
        grad_E = grad_K / E1
        grad_E[0] = -float(np.dot(grad_K[1:], K[1:])) / E1
        u_bw = float(np.sqrt(np.sum((grad_E * u_E) ** 2)))
    return {"ratio": u_K, "phase": u_phase, "bandwidth": u_bw, "amplitude": u_E, "sigma": math.sqrt(sigma2)}


def run_jjf1537(settings: Jjf1537Experiment | None = None, trials: int = DEFAULT_TRIALS, seed: int = DEFAULT_SEED,
                chunk_trials: int = 32, progress=None) -> Jjf1537Result:
    """Simulate *trials* runs of the test and reduce each as JJF 1537-2015 7.2.1 does (module docstring).

    *chunk_trials*: trials simulated per step (memory only; the numbers do not depend on it). *progress*:
    called as progress(done, total) in trials.
    """
    settings = Jjf1537Experiment() if settings is None else settings
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise ValueError(f"trials: expected an integer >= 1, got {trials!r}")
    if isinstance(chunk_trials, bool) or not isinstance(chunk_trials, (int, np.integer)) or chunk_trials < 1:
        raise ValueError(f"chunk_trials: expected an integer >= 1, got {chunk_trials!r}")
    schedule = settings.schedule()
    dynamics = settings.dynamics()
    freqs = schedule.frequencies
    m, n = freqs.size, schedule.repeats
    H = dynamics.response(freqs)
    truth_ratio, truth_phase = np.abs(H), np.angle(H)
    noise_free = truth_ratio / truth_ratio[0]
    try:
        noise_free_bw = bandwidth_3db(freqs, noise_free)
    except ValueError:
        noise_free_bw = math.nan

    ratios = np.empty((trials, m))
    phases = np.empty((trials, m))
    bandwidths = np.full(trials, math.nan)
    ratio_u = np.empty((trials, m))
    phase_u = np.empty((trials, m))
    A = schedule.amplitude
    for first in range(0, trials, chunk_trials):
        block = np.arange(first, min(first + chunk_trials, trials))
        table = np.stack([table_phases(seed, t, (m, n)) for t in block])  # (c, m, n)
        E = np.empty((block.size, m, n))
        phi = np.empty((block.size, m, n))
        for i in range(m):
            records = simulate_records(settings, seed, i, block, phases=table[:, i, :])
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
        if progress is not None:
            progress(int(block[-1]) + 1, trials)
    return Jjf1537Result(
        settings=settings, schedule=schedule, seed=int(seed), trials=int(trials), truth_ratio=truth_ratio,
        truth_phase=truth_phase, truth_bandwidth=dynamics.bandwidth(), noise_free_ratio=noise_free,
        noise_free_bandwidth=noise_free_bw, ratios=ratios, phases=phases, bandwidths=bandwidths,
        gum=gum_uncertainties(settings, truth_ratio),
        type_a={"ratio": ratio_u.mean(axis=0), "phase": phase_u.mean(axis=0)},
    )
