"""JJF 1537-2015's amplitude- and phase-frequency test on an angular vibration table, simulated (docs/dynamic.md).

The table, the sensor and their settings are :mod:`plansim.simulate.vibration_table`; items 7.2.4–7.2.7
(:mod:`plansim.simulate.jjf1537_items`) run in the same trials.

**What is estimated** (:mod:`plansim.estimate.dynamic`): per record the three-parameter sine fit (JJF
1537-2015 eq. (6)); per trial the frequency response eq. (7)–(9) with S_0 the sensitivity at the lowest
frequency, the phase response, the −3 dB bandwidth interpolated (JJF 1535-2015 7.2.15.2); over the trials
the bias and standard deviation of each against the analytic truth, and the GUM (JCGM 100) of the same
estimators from the sine fit's closed-form variance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.estimate.dynamic import (
    HALF_POWER,
    bandwidth_3db,
    bandwidth_curve_fit,
    frequency_response,
    sine_fits,
    wrap_phase,
)
from plansim.model.dynamics import static_nonlinearity_harmonics
from plansim.schedule.jjf1537 import Jjf1537Schedule
from plansim.simulate.jjf1537_items import (
    ITEMS,
    SHOCK_FIGURES,
    VibrationShockResult,
    _vibration_shock_block,
    _vibration_shock_result,
)
from plansim.simulate.vibration_table import (
    DEFAULT_SEED,
    DEFAULT_TRIALS,
    Jjf1537Experiment,
    check_run,
    table_errors,
    table_phases,
    table_records,
)


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


def run_jjf1537(settings: Jjf1537Experiment | None = None, trials: int = DEFAULT_TRIALS, seed: int = DEFAULT_SEED,
                chunk_trials: int = 32, progress=None) -> Jjf1537Result:
    """Simulate *trials* runs of the test and reduce each as JJF 1537-2015 7.2.1 does (module docstring).

    *chunk_trials*: trials simulated per step (memory only; the numbers do not depend on it). *progress*:
    called as progress(done, total) in trials.
    """
    settings = Jjf1537Experiment() if settings is None else settings
    check_run(seed, trials, chunk_trials)
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
