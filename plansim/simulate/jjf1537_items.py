"""JJF 1537-2015 items 7.2.4–7.2.7, simulated and reduced: amplitude nonlinearity, output change under vibration,
bias change across the vibration and across the shock, and the shock record (docs/dynamic.md).

**Items 7.2.4–7.2.7** (:func:`run_vibration_shock`; :func:`plansim.simulate.jjf1537.run_jjf1537` runs them in the
same trials). The sensor may have a static amplitude nonlinearity after its dynamics, g(v) = v + c₂v²/R + c₃v³/R²
(R the range; ``even_nonlinearity`` c₂, ``odd_nonlinearity`` c₃, both 0 by default: a model choice, the copy of
JJF 1537 naming no model), and its bias may step by ``vibration_bias_shift`` after the vibration and by
``shock_bias_shift`` after the shock (0 by default). At one frequency (``vibration_frequency``) each trial records
n repeats at each of M amplitudes across 10–30 % of the range (7.2.4), then at rest, under vibration at the 7.2.1
amplitude (7.2.5), at rest, the shock (a half-sine pulse through the sensor's dynamics, :func:`shock_records`), at
rest (7.2.6, 7.2.7); :func:`reduce_vibration_shock` reduces them and :func:`vibration_shock_truth` gives the
figures in closed form.

The records come from :func:`plansim.simulate.vibration_table.table_records` and, for the shock, from
:func:`shock_records`; every noise stream is apart from 7.2.1's (:data:`ITEM_STREAMS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.stats

from plansim.estimate.dynamic import amplitude_nonlinearity, mean_change, shock_response, sine_fits
from plansim.kernels.dynamics import input_records
from plansim.kernels.random import root_key
from plansim.model.dynamics import half_sine, static_nonlinearity_harmonics
from plansim.schedule.jjf1537 import VibrationShockSchedule
from plansim.simulate.vibration_table import (
    DEFAULT_SEED,
    DEFAULT_TRIALS,
    DRIFT_STREAM,
    ITEM_PHASE_STREAM,
    ITEM_TABLE_ERROR_STREAM,
    WHITE_BLOCK,
    Jjf1537Experiment,
    check_run,
    discretise,
    table_errors,
    table_records,
)

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
    ``default_rng([seed, trial, ITEM_PHASE_STREAM])`` (:data:`plansim.simulate.vibration_table.ITEM_PHASE_STREAM`)."""
    return np.random.default_rng([int(seed), int(trial), ITEM_PHASE_STREAM]).uniform(-math.pi, math.pi, count)


#: the records the bias's rate random walk runs through, in time order
DRIFT_RECORDS = ("before_vibration", "vibration", "after_vibration", "shock", "after_shock")


def drift_intervals(settings: Jjf1537Experiment) -> np.ndarray:
    """(5, 2) the start and end (s) of the records of :data:`DRIFT_RECORDS`, one after the other from 0."""
    sch = settings.vibration_shock_schedule()
    lengths = np.array([sch.rest_samples(), sch.samples(sch.vibration_time), sch.rest_samples(),
                        sch.shock_samples(), sch.rest_samples()]) / sch.sample_rate
    ends = np.cumsum(lengths)
    return np.column_stack([ends - lengths, ends])


def drift_covariance(settings: Jjf1537Experiment) -> np.ndarray:
    """(5, 5) the covariance of the records' mean drift, output unit²: a rate random walk b(t) = S K W(t) (W a
    standard Wiener process from the first record's start, K = ``gyro_rrw``) averaged over each record [a_i, b_i],

        Cov(b̄_i, b̄_j) = S²K²/(T_i T_j) ∫∫ min(s, t) ds dt over [a_i, b_i] × [a_j, b_j],

    in closed form from F(x, y) = ∫_0^x ∫_0^y min(s, t) ds dt = m²M/2 − m³/6 (m = min(x, y), M = max(x, y)) by
    inclusion–exclusion. A record's own variance is S²K²(a + T/3) (a its start)."""
    iv = drift_intervals(settings)

    def F(x, y):
        m, M = np.minimum(x, y), np.maximum(x, y)
        return m * m * M / 2.0 - m**3 / 6.0

    a, b = iv[:, 0][:, None], iv[:, 1][:, None]
    c, d = iv[:, 0][None, :], iv[:, 1][None, :]
    integral = F(b, d) - F(a, d) - F(b, c) + F(a, c)
    T = iv[:, 1] - iv[:, 0]
    return (settings.scale_factor * settings.gyro_rrw) ** 2 * integral / np.outer(T, T)


def drift_offsets(settings: Jjf1537Experiment, seed: int, trials) -> np.ndarray:
    """(T, 5) the mean drift of each record of :data:`DRIFT_RECORDS` in each of the trials *trials* (T,), output
    unit, drawn from :func:`drift_covariance` (factored once) with ``default_rng([seed, trial, DRIFT_STREAM])``;
    exactly 0 without a random walk. The walk enters each record as this mean, held over the record: the items
    read record means, whose joint distribution is then exactly a rate random walk's (its shape within a record
    is not simulated)."""
    trials = np.asarray(trials, dtype=np.int64).ravel()
    if settings.gyro_rrw == 0.0:
        return np.zeros((trials.size, len(DRIFT_RECORDS)))
    factor = np.linalg.cholesky(drift_covariance(settings))
    z = np.stack([np.random.default_rng([int(seed), int(t), DRIFT_STREAM]).standard_normal(len(DRIFT_RECORDS))
                  for t in trials])
    return z @ factor.T


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
    over whole cycles; and, with a rate random walk, Var(b̄_j − b̄_i) of the two records' mean drift
    (:func:`drift_covariance`) added: S²K²(T_i/3 + g + T_j/3) for records T_i and T_j apart by g, which the
    records' own scatter (their Type A u) never shows.

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
    C = drift_covariance(settings)  # the rate random walk's record means, DRIFT_RECORDS order

    def drifted(i: int, j: int) -> float:  # Var(b̄_j − b̄_i)
        return float(C[i, i] + C[j, j] - 2.0 * C[i, j])

    return {"amplitude_nonlinearity": u_nonlinearity,
            "vibration_output_change": math.sqrt(sigma**2 * (1.0 / sch.samples(sch.vibration_time) + 1.0 / rest)
                                                 + drifted(0, 1)),
            "bias_change_vibration": math.sqrt(sigma**2 * 2.0 / rest + drifted(0, 2)),
            "bias_change_shock": math.sqrt(sigma**2 * 2.0 / rest + drifted(2, 4))}


def simulate_vibration_shock(settings: Jjf1537Experiment, seed: int, trials, chunk: int | None = None) -> dict:
    """The 7.2.4–7.2.7 records of the trials *trials* (T,), output unit: ``linearity`` (T, M, n, N) at the M
    amplitudes, ``vibration`` (T, N_v), ``rest`` (T, 3, N_r) before the vibration, after it (the bias
    shifted by ``vibration_bias_shift``) and after the shock (shifted by both), and ``shock`` (T, N_s), the
    record from the pulse's start (:func:`shock_records`; the record after the shock continues it). Every
    record has its own noise stream above :data:`ITEM_STREAMS`; *chunk* as
    :func:`plansim.simulate.jjf1537.simulate_records`."""
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
    drift = drift_offsets(settings, seed, trials)  # (T, 5), DRIFT_RECORDS
    vibration = table_records(settings, seed, sch.frequency, sch.amplitude, phases[:, -1],
                              sch.samples(sch.vibration_time), base + M * n, chunk, bias_shift=drift[:, 1])
    rest = [table_records(settings, seed, sch.frequency, 0.0, np.zeros(trials.size), sch.rest_samples(),
                          base + M * n + 1 + r, chunk, bias_shift=shift + drift[:, column])
            for r, (shift, column) in enumerate(((0.0, 0), (settings.vibration_bias_shift, 2)))]
    shock, after = shock_records(settings, seed, trials, base + M * n + 3, chunk, drift=drift[:, 3:])
    return {"linearity": linearity, "vibration": vibration, "rest": np.stack(rest + [after], axis=1), "shock": shock}


def shock_records(settings: Jjf1537Experiment, seed: int, trials, after_streams, chunk: int | None = None,
                  drift: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The shock record and the record at rest after it, (T, N_s) and (T, N_r), output unit.

    The sensor is at rest (its filter state zero) when the pulse starts; its input is :func:`shock_input`
    through :func:`shock_filter` (:func:`plansim.kernels.dynamics.input_records`); the bias is B +
    ``vibration_bias_shift`` during the pulse and ``shock_bias_shift`` more from its end. The record after the
    shock continues the filter's state, so a ringing that has not died out by then is in it; its noise is the
    stream *after_streams* (T,), the shock record's :data:`SHOCK_STREAMS` + trial. Without a pulse (``shock_peak``
    or ``g_sensitivity`` 0) the record after the shock is the record at rest it always was, number for number.
    *drift*: (T, 2) the bias's mean drift over the shock record and over the record after it (:func:`drift_offsets`;
    default none).
    """
    sch = settings.vibration_shock_schedule()
    trials = np.asarray(trials, dtype=np.int64).ravel()
    x = shock_input(settings)
    b, a = shock_filter(settings)
    states = np.zeros((trials.size, len(a) - 1))
    pulse, total = sch.pulse_samples(), sch.shock_samples()
    level = settings.bias + settings.vibration_bias_shift
    drift = np.zeros((trials.size, 2)) if drift is None else np.asarray(drift, dtype=float)
    shock = np.empty((trials.size, total))
    after = np.empty((trials.size, sch.rest_samples()))
    own = SHOCK_STREAMS + trials
    for start, stop, first, streams, bias, out in (
            (0, pulse, 0, own, level + drift[:, 0], shock[:, :pulse]),
            (pulse, total, pulse, own, level + settings.shock_bias_shift + drift[:, 0], shock[:, pulse:]),
            (total, x.size, 0, np.asarray(after_streams, dtype=np.int64),
             level + settings.shock_bias_shift + drift[:, 1], after)):
        _driven_records(settings, seed, b, a, states, x[start:stop], first, streams, bias, out, chunk)
    return shock, after


def _driven_records(settings, seed, b, a, states, inputs, first, streams, bias, out, chunk) -> None:
    """:func:`plansim.kernels.dynamics.input_records` over *out* (R, n) in chunks of *chunk* samples (None: one);
    *bias* the output's bias, one for all records or (R,) one per record."""
    n = out.shape[1]
    step = max(n, 1) if chunk is None else int(chunk)
    if step < 1:
        raise ValueError(f"chunk: expected an integer >= 1, got {chunk!r}")
    white = np.empty(step)
    key = root_key(seed)
    R = settings.gyro_range
    streams = np.ascontiguousarray(streams, dtype=np.int64).ravel()
    biases = np.ascontiguousarray(np.broadcast_to(np.asarray(bias, dtype=float), streams.shape))
    for start in range(0, n, step):
        stop = min(start + step, n)
        input_records(b, a, states, np.ascontiguousarray(inputs[start:stop]), first + start, settings.scale_factor,
                      biases, settings.noise_sigma, settings.quantisation, R * settings.scale_factor, key, streams,
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
    """The Monte Carlo of JJF 1537-2015 7.2.4–7.2.7 alone (:func:`plansim.simulate.jjf1537.run_jjf1537` runs it with
    7.2.1–7.2.3): *trials* trials simulated (:func:`simulate_vibration_shock`) and reduced
    (:func:`reduce_vibration_shock`). The numbers depend on (settings, seed, trial) only, not on *chunk_trials*."""
    settings = Jjf1537Experiment() if settings is None else settings
    check_run(seed, trials, chunk_trials)
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

