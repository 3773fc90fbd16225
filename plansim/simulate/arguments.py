"""The scenario as the kernels see it: plain SI arrays packed in the order of :mod:`plansim.kernels.layout`.

Also the noise model's stand-ins (bias instability as a Gauss–Markov process whose Allan peak is
the flicker floor), the per-segment drift coefficients of the segment path, and the exact
noise-free segment means of given draws vectors (used by the GUM sensitivities).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from plansim.config import Scenario
from plansim.kernels import segment_path
from plansim.kernels.drift import drift_coefficients
from plansim.kernels.layout import EFFECT_ROWS, TABLE_ERRORS, TRUTH, draws_length
from plansim.schedule.segments import Schedule, Segment, axis_vector, body_to_level

#: flicker floor of the Allan deviation per unit bias-instability coefficient B (IEEE Std 952, C.1):
#: σ_A = B·√(2 ln 2 / π) ≈ 0.664 B
FLICKER_FLOOR = math.sqrt(2.0 * math.log(2.0) / math.pi)


def gauss_markov_allan_peak() -> float:
    """Peak of the Allan deviation of a unit-variance first-order Gauss–Markov process, computed.

    σ_A²(τ)/σ² = (2/x)·[1 − (3 − 4e^{−x} + e^{−2x})/(2x)], x = τ/T_c (e.g. IEEE Std 952 Annex C);
    the peak is ≈ 0.6174 at x ≈ 1.893 (``scipy.optimize.minimize_scalar``). Its value is written
    down as :data:`GM_ALLAN_PEAK`, which tests check against this function.
    """
    from scipy.optimize import minimize_scalar  # here only: it takes 0.7 s to import

    def minus(x):
        return -(2.0 / x) * (1.0 - (3.0 - 4.0 * math.exp(-x) + math.exp(-2.0 * x)) / (2.0 * x))

    res = minimize_scalar(minus, bounds=(0.1, 20.0), method="bounded", options={"xatol": 1e-10})
    return math.sqrt(-res.fun)


#: :func:`gauss_markov_allan_peak` (flat at its maximum, so exact to the last digit whatever the tolerance
#: on x); written down rather than computed at import, which cost every run 0.7 s of importing scipy.optimize
GM_ALLAN_PEAK = 0.6173642831444414


def bias_instability_sigma(coefficient: np.ndarray) -> np.ndarray:
    """Stationary σ of the Gauss–Markov process that stands in for bias instability B.

    Chosen so that the process's Allan-deviation peak equals the flicker floor 0.664·B; its
    correlation time (``bias_instability_correlation_time``) places that peak at ≈ 1.89·T_c.
    """
    return np.asarray(coefficient) * FLICKER_FLOOR / GM_ALLAN_PEAK


def schedule_arrays(schedule: Schedule) -> dict[str, np.ndarray]:
    """The nominal schedule as the kernels see it (new arrays; built once per distinct schedule)."""
    return {name: array.copy() for name, array in _schedule_arrays(schedule.segments).items()}


@functools.lru_cache(maxsize=64)
def _schedule_arrays(segs: tuple[Segment, ...]) -> dict[str, np.ndarray]:
    """:func:`schedule_arrays` of the segments *segs* (a planner asks for the same schedule many times over)."""
    poses = {(s.up, s.heading): None for s in segs}  # a schedule repeats few poses and axes
    poses = {pose: _body_to_level(*pose) for pose in poses}
    axes = {s.rate_axis: _axis_vector(s.rate_axis) for s in segs}
    return dict(
        seg_n=np.array([s.samples for s in segs], dtype=np.int64),
        seg_dt=np.array([1.0 / s.sample_rate for s in segs]),
        seg_gap=np.array([s.settle for s in segs]),
        seg_C0=np.array([poses[s.up, s.heading] for s in segs]),
        seg_rate=np.array([s.rate for s in segs]),
        seg_axis=np.array([axes[s.rate_axis] for s in segs]),
        seg_axis_index=np.array(["xyz".index(s.rate_axis[1]) for s in segs], dtype=np.int64),
        seg_temp=np.array([s.temperature for s in segs]),
    )


@functools.lru_cache(maxsize=256)
def _body_to_level(up: str, heading: float) -> np.ndarray:
    """:func:`plansim.schedule.segments.body_to_level` once per pose (read-only): schedules repeat a few poses."""
    matrix = body_to_level(up, heading)
    matrix.flags.writeable = False
    return matrix


@functools.lru_cache(maxsize=64)
def _axis_vector(name: str) -> np.ndarray:
    """:func:`plansim.schedule.segments.axis_vector` once per axis (read-only)."""
    vector = axis_vector(name)
    vector.flags.writeable = False
    return vector


def kernel_arguments(scenario: Scenario) -> dict[str, object]:
    """Every model input of the kernels, in SI (see :mod:`plansim.kernels.sample_path`).

    Raises ``ValueError`` if the scenario sets an effect the kernels do not simulate
    (:data:`plansim.config.scenario.JJF1535_EFFECTS`: the JJF 1535 Monte Carlo applies those to segment means,
    :mod:`plansim.simulate.jjf1535_effects`, and hands the kernels the unit without them).
    """
    e, n, a, t = scenario.effects, scenario.noise, scenario.acquisition, scenario.turntable
    unsimulated = e.jjf1535_effects_set()
    if unsimulated:
        raise ValueError(f"mimu.effects.{unsimulated[0]} = {getattr(e, unsimulated[0]).tolist()!r} (SI): the "
                         "simulation kernels do not simulate it; only the JJF 1535 Monte Carlo does "
                         "('plansim run jjf1535 --unit SCENARIO', docs/jjf1535.md); allowed here: 0 (off) for "
                         + ", ".join(f"mimu.effects.{name}" for name in unsimulated))
    errors = [getattr(t, name) for name in TABLE_ERRORS]
    sensor = np.array([getattr(e, row) for row in EFFECT_ROWS], dtype=float)
    noise = np.column_stack([
        np.concatenate([n.gyro_angle_random_walk, n.accel_velocity_random_walk]),
        bias_instability_sigma(np.concatenate([n.gyro_bias_instability, n.accel_bias_instability])),
        np.concatenate([n.gyro_rate_random_walk, n.accel_acceleration_random_walk]),
        np.concatenate([n.gyro_markov_sigma, n.accel_markov_sigma]),
    ])
    return dict(
        truth_nominal=np.asarray(scenario.truth_nominal, float),
        truth_spread=np.asarray(scenario.truth_spread, float),
        error_kind=np.array([d.code for d in errors], dtype=np.int64),
        error_scale=np.array([d.scale for d in errors]),
        **schedule_arrays(scenario.schedule),
        sensor=sensor, S2=np.asarray(e.gyro_g2_sensitivity, float), lever=np.asarray(e.accel_lever_arm, float),
        t_ref=float(e.reference_temperature),
        acquisition=np.array([e.gyro_output_range, e.accel_output_range, a.gyro_step, a.accel_step,
                              a.gyro_full_scale, a.accel_full_scale], dtype=float),
        noise=noise,
        noise_times=np.array([n.bias_instability_correlation_time, n.markov_correlation_time,
                              n.drift_update_interval], dtype=float),
        smoothness=float(t.rate_smoothness),
        gravity=float(scenario.environment.gravity),
        earth_enu=np.asarray(scenario.environment.earth_rate_vector, float),
    )


def as_float_arrays(args: dict) -> dict:
    return {k: (np.ascontiguousarray(v, dtype=np.float64) if isinstance(v, np.ndarray) and v.dtype.kind == "f"
                else v) for k, v in args.items()}


def needed_channels(schedule: Schedule) -> np.ndarray:
    """(S, 6) 1 where a JJF 2003 estimator uses the channel's mean: rate test -> gyros,
    multi-position -> all six, ω² test -> accelerometers."""
    out = np.zeros((len(schedule), 6), dtype=np.int64)
    for k, s in enumerate(schedule.segments):
        if s.test == "rate":
            out[k, :3] = 1
        elif s.test == "omega_squared":
            out[k, 3:] = 1
        else:
            out[k, :] = 1
    return out


def drift_coefficient_table(scenario: Scenario) -> np.ndarray:
    """(S, 3, 5) unit-σ drift coefficients per segment for GM bias instability, GM drift, random walk (a new array)."""
    n = scenario.noise
    return _drift_coefficient_table(scenario.schedule.segments, n.bias_instability_correlation_time,
                                    n.markov_correlation_time, n.drift_update_interval).copy()


@functools.lru_cache(maxsize=64)
def _drift_coefficient_table(segs: tuple[Segment, ...], bias_instability_time: float, markov_time: float,
                             update_interval: float) -> np.ndarray:
    """:func:`drift_coefficient_table` once per distinct schedule and noise times (read-only)."""
    out = np.zeros((len(segs), 3, 5))
    recorded = [(s.samples, s.sample_rate) for s in segs]
    for samples, rate in set(recorded):  # a schedule records few distinct (samples, rate) pairs
        at = [k for k, pair in enumerate(recorded) if pair == (samples, rate)]
        for p, tau in enumerate((bias_instability_time, markov_time, None)):
            out[at, p] = _drift_coefficients(samples, 1.0 / rate, update_interval, tau)
    out.flags.writeable = False
    return out


#: :func:`plansim.kernels.drift.drift_coefficients`, once per distinct argument: a schedule repeats few
#: (samples, rate) pairs (135 evaluations -> a handful), and a planner the same schedules many times over
_drift_coefficients = functools.lru_cache(maxsize=1024)(drift_coefficients)


def nominal_draws(scenario: Scenario) -> np.ndarray:
    """A draws vector with the nominal truth, every table error zero and every start phase zero."""
    draws = np.zeros(draws_length(len(scenario.schedule)))
    draws[TRUTH] = scenario.truth_nominal
    return draws


#: the arguments of the noise-free kernels (:func:`plansim.kernels.segment_path.noise_free_means`,
#: :func:`plansim.kernels.segment_path.noise_free_mean_derivatives`) that describe the scenario
NOISE_FREE_ARGUMENTS = ("seg_n", "seg_dt", "seg_C0", "seg_rate", "seg_axis", "seg_axis_index", "seg_temp", "sensor",
                        "S2", "lever", "t_ref", "gravity", "earth_enu")


def noise_free_arguments(scenario: Scenario, arguments: dict | None = None) -> dict[str, object]:
    """The scenario's arguments of the noise-free kernels (:data:`NOISE_FREE_ARGUMENTS`), as they take them.

    Parameters
    ----------
    scenario : Scenario
    arguments : dict, optional
        :func:`kernel_arguments` of *scenario*, if the caller has them already (they cost a
        millisecond on the default schedule).
    """
    args = as_float_arrays(kernel_arguments(scenario) if arguments is None else arguments)
    return {k: args[k] for k in NOISE_FREE_ARGUMENTS}


def noise_free_segment_means(scenario: Scenario, draws: np.ndarray) -> np.ndarray:
    """Exact noise-free segment means (n, S, 6) for draws vectors (n, D) (layout: plansim.kernels.physics)."""
    draws = np.ascontiguousarray(draws, dtype=float)
    if draws.ndim != 2 or draws.shape[1] != draws_length(len(scenario.schedule)):
        raise ValueError(f"draws: expected shape (n, {draws_length(len(scenario.schedule))}), got {draws.shape}")
    out = np.empty((draws.shape[0], len(scenario.schedule), 6))
    segment_path.noise_free_means(draws, **noise_free_arguments(scenario), means_out=out)
    return out
