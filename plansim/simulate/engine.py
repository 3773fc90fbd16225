"""Thin layer between configuration objects and the kernels: pack SI arrays, run chunks, report progress."""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable

import numpy as np
from scipy.optimize import minimize_scalar

from plansim.model.parameters import N_PARAMETERS
from plansim.scenario import Scenario
from plansim.schedule.segments import Schedule, axis_vector, body_to_level
from plansim.simulate import kernels
from plansim.simulate.random import ZIG_RATIO, ZIG_X, root_key

CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")

#: flicker floor of the Allan deviation per unit bias-instability coefficient B (IEEE Std 952, C.1):
#: σ_A = B·√(2 ln 2 / π) ≈ 0.664 B
FLICKER_FLOOR = math.sqrt(2.0 * math.log(2.0) / math.pi)


def _gauss_markov_allan_peak() -> float:
    """Peak of the Allan deviation of a unit-variance first-order Gauss–Markov process.

    σ_A²(τ)/σ² = (2/x)·[1 − (3 − 4e^{−x} + e^{−2x})/(2x)], x = τ/T_c (e.g. IEEE Std 952 Annex C);
    the peak is ≈ 0.6185 at x ≈ 1.89.
    """
    def minus(x):
        return -(2.0 / x) * (1.0 - (3.0 - 4.0 * math.exp(-x) + math.exp(-2.0 * x)) / (2.0 * x))

    res = minimize_scalar(minus, bounds=(0.1, 20.0), method="bounded", options={"xatol": 1e-10})
    return math.sqrt(-res.fun)


GM_ALLAN_PEAK = _gauss_markov_allan_peak()


def bias_instability_sigma(coefficient: np.ndarray) -> np.ndarray:
    """Stationary σ of the Gauss–Markov process that stands in for bias instability B.

    Chosen so that the process's Allan-deviation peak equals the flicker floor 0.664·B; its
    correlation time (``bias_instability_correlation_time``) places that peak at ≈ 1.89·T_c.
    """
    return np.asarray(coefficient) * FLICKER_FLOOR / GM_ALLAN_PEAK


def schedule_arrays(schedule: Schedule) -> dict[str, np.ndarray]:
    """The nominal schedule as the kernels see it."""
    segs = schedule.segments
    return dict(
        seg_n=np.array([s.samples for s in segs], dtype=np.int64),
        seg_dt=np.array([1.0 / s.sample_rate for s in segs]),
        seg_gap=np.array([s.settle for s in segs]),
        seg_C0=np.array([body_to_level(s.up, s.heading) for s in segs]),
        seg_rate=np.array([s.rate for s in segs]),
        seg_axis=np.array([axis_vector(s.rate_axis) for s in segs]),
        seg_axis_index=np.array(["xyz".index(s.rate_axis[1]) for s in segs], dtype=np.int64),
        seg_temp=np.array([s.temperature for s in segs]),
    )


def kernel_arguments(scenario: Scenario) -> dict[str, object]:
    """Every model input of :func:`plansim.simulate.kernels.simulate_trial`, in SI."""
    e, n, a, t = scenario.effects, scenario.noise, scenario.acquisition, scenario.turntable
    errors = (t.position_accuracy, t.position_repeatability, t.axis_perpendicularity, t.platform_tilt,
              t.fixture_perpendicularity, t.rate_error_systematic, t.rate_error_per_point)
    return dict(
        **schedule_arrays(scenario.schedule),
        truth_nominal=np.asarray(scenario.truth_nominal, float),
        truth_spread=np.asarray(scenario.truth_spread, float),
        n2=e.gyro_nonlinearity_quadratic, n3=e.gyro_nonlinearity_cubic, asym=e.gyro_asymmetry,
        S2=e.gyro_g2_sensitivity, k2=e.accel_second_order,
        gyro_btc=e.gyro_bias_temperature_coefficient, gyro_stc=e.gyro_scale_temperature_coefficient,
        accel_btc=e.accel_bias_temperature_coefficient, accel_stc=e.accel_scale_temperature_coefficient,
        t_ref=float(e.reference_temperature), lever=e.accel_lever_arm,
        gyro_range=float(e.gyro_output_range), accel_range=float(e.accel_output_range),
        white_density=np.concatenate([n.gyro_angle_random_walk, n.accel_velocity_random_walk]),
        bi_sigma=bias_instability_sigma(np.concatenate([n.gyro_bias_instability, n.accel_bias_instability])),
        bi_tau=float(n.bias_instability_correlation_time),
        rrw=np.concatenate([n.gyro_rate_random_walk, n.accel_acceleration_random_walk]),
        markov_sigma=np.concatenate([n.gyro_markov_sigma, n.accel_markov_sigma]),
        markov_tau=float(n.markov_correlation_time),
        drift_interval=float(n.drift_update_interval),
        step_gyro=float(a.gyro_step), step_accel=float(a.accel_step),
        fs_gyro=float(a.gyro_full_scale), fs_accel=float(a.accel_full_scale),
        error_kind=np.array([d.code for d in errors], dtype=np.int64),
        error_scale=np.array([d.scale for d in errors]),
        smoothness=float(t.rate_smoothness),
        gravity=float(scenario.environment.gravity),
        earth_enu=scenario.environment.earth_rate_vector,
    )


def _as_float_arrays(args: dict) -> dict:
    return {k: (np.ascontiguousarray(v, dtype=np.float64) if isinstance(v, np.ndarray) and v.dtype.kind == "f"
                else v) for k, v in args.items()}


ProgressCallback = Callable[[int, int], None]


def stderr_progress(label: str = "simulating") -> ProgressCallback:
    """A progress line on stderr, redrawn in place: trials done / total, rate, time left."""
    start = time.perf_counter()

    def report(done: int, total: int) -> None:
        elapsed = time.perf_counter() - start
        rate = done / elapsed if elapsed > 0 else float("nan")
        left = (total - done) / rate if rate > 0 else float("nan")
        end = "\n" if done >= total else ""
        sys.stderr.write(f"\r{label}: {done}/{total} trials ({rate:,.0f}/s, {left:4.0f} s left)   {end}")
        sys.stderr.flush()

    return report


def simulate_segment_means(scenario: Scenario, trials: int, seed: int, chunk_size: int = 256,
                           progress: ProgressCallback | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run *trials* calibrations on the sample-level path.

    Returns
    -------
    means : (trials, S, 6) array
        Mean output of every segment (rad/s, m/s²).
    truth : (trials, 39) array
        The parameters each simulated unit really had (SI).
    """
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise ValueError(f"trials = {trials!r}: expected a whole number >= 1")
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise ValueError(f"chunk_size = {chunk_size!r}: expected a whole number >= 1")
    key = root_key(seed)
    args = _as_float_arrays(kernel_arguments(scenario))
    S = len(scenario.schedule)
    means = np.empty((trials, S, 6))
    truth = np.empty((trials, N_PARAMETERS))
    for start in range(0, trials, chunk_size):
        stop = min(trials, start + chunk_size)
        kernels.simulate_chunk(start, key, ZIG_X, ZIG_RATIO, **args,
                               means_out=means[start:stop], truth_out=truth[start:stop])
        if progress is not None:
            progress(stop, trials)
    return means, truth


def simulate_recording(scenario: Scenario, seed: int, trial: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every raw sample of one trial (the same numbers that trial gives inside :func:`simulate_segment_means`).

    Returns ``(samples (M, 6), segment means (S, 6), truth (39,))``.
    """
    if isinstance(trial, bool) or not isinstance(trial, (int, np.integer)) or trial < 0:
        raise ValueError(f"trial = {trial!r}: expected a whole number >= 0")
    key = root_key(seed)
    args = _as_float_arrays(kernel_arguments(scenario))
    samples = np.empty((scenario.schedule.total_samples, 6))
    means = np.empty((len(scenario.schedule), 6))
    truth = np.empty(N_PARAMETERS)
    kernels.simulate_trial(int(trial), key, ZIG_X, ZIG_RATIO, **args, means_out=means, truth_out=truth,
                           samples_out=samples, record=True)
    return samples, means, truth
