"""JJF 1535-2015 items of one gyro from the segment means of a :class:`~plansim.schedule.jjf1535.Jjf1535Procedure`,
and their true values in plansim's model.

:func:`reduce_items` applies the estimators of :mod:`plansim.estimate.jjf1535` (eq. (4)–(20), 7.2.12) to the means
of one simulated (or measured) session; :func:`true_items` gives each item's value for the simulated unit, from the
model's parameters. Everything is SI: rates rad/s, scale factors in output unit per rad/s (plansim's gyro output is
itself a rate in rad/s, so K is dimensionless: output °/s per input °/s), g-sensitivities rad/s per m/s², temperature
coefficients per °C. :data:`ITEMS` gives each item's clause, equations and the unit JJF 1535 reports it in.

The mapping (gyro *i* = the procedure's axis; plansim's eq. (1) plus its effects, docs/model.md):

- K (7.2.1, eq. (5), mean over Q): ``Kg[i, i]·(1 + κ_i·(T_room − T_ref))``;
- B0 (7.2.8, eq. (15)–(17)): the model's bias at room temperature referred to the input,
  ``(Bg[i] + β_i·(T_room − T_ref))/K``. The record has the input axis
  up, so it also holds ``G[i, i]·g`` and the vertical Earth rate: eq. (16) reports them as bias (a slip of the
  procedure, not of plansim), whereas the mean of the 7.2.12 up and down records (``bias_up_down``) cancels both;
- g-sensitivity along body axis a (7.2.12): ``G[i, a]/K``; the gyro's figure is the largest magnitude;
- scale-factor temperature sensitivity (eq. (11)): ``|κ_i|/(1 + κ_i·(T_room − T_ref))``;
- bias temperature sensitivity (eq. (27), each B_i = F̄_i/K with the room K): ``|β_i|/K``;
- nonlinearity (eq. (6)–(7)) and asymmetry (eq. (8)–(9)): the figure of the unit's noise-free response
  ``K·Ω + n2·Ω² + n3·Ω³ + ½·α·Kg[i, i]·|Ω|`` at the schedule's rates (with only α set, the asymmetry is |α|);
- bias stability (eq. (18)–(19)) has no value in the model: it is a property of the noise and the averaging;
- scale-factor repeatability (7.2.4, eq. (10)): 0 (the model's scale factor does not change at a power-on);
- threshold (7.2.6, eq. (12)–(13)): the dead zone d_i; resolution (7.2.7, eq. (14)): the input step r_i
  (:mod:`plansim.model.jjf1535_effects`). Both are properties of the unit, not of the procedure: the procedure
  reports a tested rate (increment), so its error is at least the distance to the next tested one;
- warm-up time (7.2.9): the 7.2.9.2 criterion on the noise-free warm-up transient (:func:`true_warm_up_time`);
- bias repeatability (7.2.11, eq. (20)): the turn-on bias's standard deviation referred to the input, σ_on/K.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.estimate.jjf1535 import (
    bias,
    bias_g_sensitivity,
    bias_repeatability,
    bias_stability,
    rate_point_mean,
    resolution,
    scale_factor_asymmetry,
    scale_factor_fit,
    scale_factor_nonlinearity,
    scale_factor_repeatability,
    temperature_sensitivity,
    threshold,
    warm_up_time,
)
from plansim.model.jjf1535_effects import exponential_segment_mean, own_axis_response
from plansim.model.parameters import unpack
from plansim.schedule.jjf1535 import Jjf1535Procedure, RateRun
from plansim.units import DEG, HOUR, STANDARD_GRAVITY

_DEG_H = DEG / HOUR
#: item -> (clause, equations, the unit JJF 1535 reports it in, SI value of one such unit)
ITEMS = {
    "scale_factor": ("7.2.1", "(4)-(5), mean of Q", "(deg/s)/(deg/s)", 1.0),
    "nonlinearity": ("7.2.2", "(6)-(7)", "ppm", 1e-6),
    "asymmetry": ("7.2.3", "(8)-(9)", "ppm", 1e-6),
    "scale_temperature_sensitivity": ("7.2.5", "(11)", "ppm/degC", 1e-6),
    "bias": ("7.2.8", "(15)-(17)", "deg/h", _DEG_H),
    "bias_up_down": ("7.2.12 records", "(F_up + F_down)/(2K)", "deg/h", _DEG_H),
    "bias_stability": ("7.2.10", "(18)-(19)", "deg/h", _DEG_H),
    "g_sensitivity_x": ("7.2.12", "(F_up - F_down)/(2gK)", "(deg/h)/g", _DEG_H / STANDARD_GRAVITY),
    "g_sensitivity_y": ("7.2.12", "(F_up - F_down)/(2gK)", "(deg/h)/g", _DEG_H / STANDARD_GRAVITY),
    "g_sensitivity_z": ("7.2.12", "(F_up - F_down)/(2gK)", "(deg/h)/g", _DEG_H / STANDARD_GRAVITY),
    "g_sensitivity": ("7.2.12", "largest |g-sensitivity|", "(deg/h)/g", _DEG_H / STANDARD_GRAVITY),
    "bias_temperature_sensitivity": ("7.2.14", "(27)", "(deg/h)/degC", _DEG_H),
    "scale_repeatability": ("7.2.4", "(10)", "ppm", 1e-6),
    "threshold": ("7.2.6", "(12)-(13)", "deg/s", DEG),
    "resolution": ("7.2.7", "(14)", "deg/s", DEG),
    "warm_up_time": ("7.2.9", "7.2.9.2, mean of N", "s", 1.0),
    "bias_repeatability": ("7.2.11", "(20)", "deg/h", _DEG_H),
}


def _run_data(means: np.ndarray, schedule, run: RateRun, gyro: int) -> tuple[np.ndarray, np.ndarray]:
    """The run's nominal rates and its point means less the mean of the at-rest outputs before and after."""
    rates = np.array([schedule.segments[k].rate for k in run.points])
    rest = 0.5 * (means[run.rest_before, gyro] + means[run.rest_after, gyro])
    return rates, means[list(run.points), gyro] - rest


def reduce_items(means, procedure: Jjf1535Procedure, gravity: float) -> dict[str, float]:
    """Every JJF 1535 item the procedure's segment means give, SI (:data:`ITEMS`).

    Parameters
    ----------
    means : (S, 6) array
        The mean output of every segment of ``procedure.schedule`` (channels gx, gy, gz, ax, ay, az; SI).
    procedure : Jjf1535Procedure
        The nominal procedure (what the laboratory commanded).
    gravity : float
        The laboratory's value of 1 g in 7.2.12, m/s².
    """
    if not isinstance(procedure, Jjf1535Procedure):
        raise TypeError(f"procedure: expected a Jjf1535Procedure, got {type(procedure).__name__}")
    means = np.asarray(means, dtype=float)
    if means.shape != (len(procedure.schedule), 6):
        raise ValueError(f"means: expected shape ({len(procedure.schedule)}, 6) (one row per segment), "
                         f"got {means.shape}")
    i = procedure.axis
    sched = procedure.schedule
    room = [_run_data(means, sched, run, i) for run in procedure.room_runs]
    K_runs = np.array([scale_factor_fit(r, f).scale_factor for r, f in room])
    K = float(K_runs.mean())
    out = {
        "scale_factor": K,
        "nonlinearity": float(np.mean([scale_factor_nonlinearity(r, f) for r, f in room])),
        "asymmetry": float(np.mean([scale_factor_asymmetry(r, f) for r, f in room])),
    }
    K_hot_cold = [scale_factor_fit(*_run_data(means, sched, run, i)).scale_factor for run in procedure.temperature_runs]
    out["scale_temperature_sensitivity"] = temperature_sensitivity([K, *K_hot_cold], procedure.temperatures)
    records = [means[list(rec), i] for rec in procedure.room_bias]
    # each segment of a record is one averaging period P: its mean is one F̄_j of eq. (18)
    out["bias"] = float(np.mean([bias(K, rec) for rec in records]))
    out["bias_stability"] = float(np.mean([bias_stability(K, rec, 1) for rec in records]))
    up, down = procedure.g_positions["xyz"[i]]
    out["bias_up_down"] = 0.5 * (bias(K, means[[up], i]) + bias(K, means[[down], i]))
    for name, (up, down) in procedure.g_positions.items():
        out[f"g_sensitivity_{name}"] = bias_g_sensitivity(K, means[[up], i], means[[down], i], gravity)
    out["g_sensitivity"] = max(abs(out[f"g_sensitivity_{a}"]) for a in "xyz")
    hot_cold = [float(rate_point_mean(means[list(rec), i])) / K for rec in procedure.temperature_bias]
    out["bias_temperature_sensitivity"] = temperature_sensitivity([out["bias"], *hot_cold], procedure.temperatures,
                                                                  relative=False)
    # 7.2.4 eq. (10): the Q room runs' K, a power cycle between them
    out["scale_repeatability"] = scale_factor_repeatability(K_runs)
    # 7.2.11 eq. (20): the Q room bias records' B0m, each in its own power cycle
    out["bias_repeatability"] = bias_repeatability([bias(K, rec) for rec in records])
    out.update(_threshold_resolution_warm_up(means, procedure, K))
    return out


def _threshold_resolution_warm_up(means: np.ndarray, procedure: Jjf1535Procedure, K: float) -> dict[str, float]:
    """7.2.6, 7.2.7 and 7.2.9 from one session's means, with the room K (7.2.6.1 a), 7.2.7.1 a)); NaN for an item
    the procedure does not record (a procedure built without those segments) or cannot determine."""
    i, sched = procedure.axis, procedure.schedule
    out = dict.fromkeys(("threshold", "resolution", "warm_up_time"), math.nan)
    if procedure.threshold_runs:
        # eq. (12)-(13) per direction, F̄_0,j the mean of the at-rest outputs before and after; the larger (7.2.6.1 e))
        per_direction = []
        for run in procedure.threshold_runs:
            rates = np.array([sched.segments[k].rate for k in run.points])
            zero = 0.5 * (means[run.rest_before, i] + means[run.rest_after, i])
            per_direction.append(threshold(K, rates, means[list(run.points), i], zero))
        out["threshold"] = _larger(per_direction)
    if procedure.resolution_pairs:
        # eq. (14) per direction on the output increments F(base + ΔΩ_j) − F(base); the larger (7.2.7.1 f))
        per_direction = []
        for sign, pairs in zip((1.0, -1.0), procedure.resolution_pairs):
            increments = sign * np.asarray(procedure.resolution_increments)  # as commanded
            output_increments = np.array([means[b, i] - means[a, i] for a, b in pairs])
            per_direction.append(resolution(K, increments, output_increments))
        out["resolution"] = _larger(per_direction)
    if procedure.warm_up:
        out["warm_up_time"] = _mean_warm_up_time([means[list(rec), i] / K for rec in procedure.warm_up], procedure)
    return out


def _larger(per_direction: list[float]) -> float:
    """7.2.6.1 e), 7.2.7.1 f): the larger of the two directions' figures; NaN if either is undetermined (Python's
    ``max`` would drop a NaN that comes second)."""
    return math.nan if any(math.isnan(x) for x in per_direction) else max(per_direction)


def _mean_warm_up_time(records: list[np.ndarray], procedure: Jjf1535Procedure) -> float:
    """7.2.9.2: each record's warm-up time (its segments are the P-second period means from power-on), their mean."""
    since = procedure.power_cycles()[1]  # each record starts at power-on: its times are those since then
    times = [since[list(rec)] for rec in procedure.warm_up]
    values = [warm_up_time(t, rates, procedure.specified_stability, 1) for t, rates in zip(times, records)]
    return float(np.mean(values))


def true_warm_up_time(procedure: Jjf1535Procedure, scale_factor: float, amplitude: float,
                      time_constant: float) -> float:
    """The unit's warm-up time by 7.2.9's own definition: :func:`~plansim.estimate.jjf1535.warm_up_time` on the
    noise-free transient ``A·exp(−t/τ)`` (:mod:`plansim.model.jjf1535_effects`) of each warm-up record, its
    period means in closed form, divided by the true K; 0 without a transient. So the zero-noise identity holds by
    construction, and with noise the error is what the noise adds to the criterion."""
    if not procedure.warm_up:
        return math.nan
    _cycle, since = procedure.power_cycles()
    records = []
    for rec in procedure.warm_up:
        segments = [procedure.schedule.segments[k] for k in rec]
        transient = exponential_segment_mean(since[list(rec)], [s.samples for s in segments],
                                             [1.0 / s.sample_rate for s in segments], amplitude, time_constant)
        records.append(transient / scale_factor)
    return _mean_warm_up_time(records, procedure)


def true_items(truth, procedure: Jjf1535Procedure, *, scale_temperature_coefficient: float = 0.0,
               bias_temperature_coefficient: float = 0.0, reference_temperature: float = 20.0,
               asymmetry: float = 0.0, nonlinearity_quadratic: float = 0.0,
               nonlinearity_cubic: float = 0.0, dead_zone: float = 0.0, resolution: float = 0.0,
               warm_up_amplitude: float = 0.0, warm_up_time_constant: float = 0.0,
               turn_on_bias: float = 0.0) -> dict[str, float]:
    """The simulated unit's value of each item that has one (the module docstring's mapping), SI.

    Parameters
    ----------
    truth : (39,) array
        The unit's parameters (:data:`plansim.model.parameters.PARAMETER_NAMES`, SI).
    procedure : Jjf1535Procedure
        Its rates and temperatures.
    scale_temperature_coefficient, bias_temperature_coefficient, reference_temperature : float
        κ (1/°C), β (rad/s/°C) and T_ref (°C) of the gyro under test (``Scenario.effects``).
    asymmetry, nonlinearity_quadratic, nonlinearity_cubic : float
        α (1), n2 (1/(rad/s)), n3 (1/(rad/s)²) of the gyro under test.
    dead_zone, resolution, warm_up_amplitude, warm_up_time_constant, turn_on_bias : float
        d (rad/s), r (rad/s), A (rad/s), τ (s) and σ_on (rad/s) of the gyro under test
        (:mod:`plansim.model.jjf1535_effects`).
    """
    p = unpack(np.asarray(truth, dtype=float))
    i = procedure.axis
    kg = float(p["Kg"][i, i])
    kappa, beta = float(scale_temperature_coefficient), float(bias_temperature_coefficient)
    K = kg * (1.0 + kappa * (procedure.room_temperature - float(reference_temperature)))
    bias_room = float(p["Bg"][i]) + beta * (procedure.room_temperature - float(reference_temperature))
    rates = np.array([procedure.schedule.segments[k].rate for k in procedure.room_runs[0].points])
    response = own_axis_response(rates, K, kg, nonlinearity_quadratic, nonlinearity_cubic, asymmetry)
    out = {"scale_factor": K,
           "nonlinearity": scale_factor_nonlinearity(rates, response),
           "asymmetry": scale_factor_asymmetry(rates, response),
           "scale_temperature_sensitivity": abs(kappa) / (1.0 + kappa * (procedure.room_temperature
                                                                         - float(reference_temperature))),
           "bias": bias_room / K,
           "bias_up_down": bias_room / K,
           "bias_stability": math.nan,
           "bias_temperature_sensitivity": abs(beta) / K,
           "scale_repeatability": 0.0,
           "threshold": float(dead_zone),
           "resolution": float(resolution),
           "warm_up_time": true_warm_up_time(procedure, K, float(warm_up_amplitude), float(warm_up_time_constant)),
           "bias_repeatability": float(turn_on_bias) / K}
    for a, name in enumerate("xyz"):
        out[f"g_sensitivity_{name}"] = float(p["G"][i, a]) / K
    out["g_sensitivity"] = max(abs(out[f"g_sensitivity_{a}"]) for a in "xyz")
    return out
