"""Thin layer between configuration objects and the kernels: pack SI arrays, run chunks, report progress."""

from __future__ import annotations

import math
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from collections.abc import Callable

import numba
import numpy as np
from threadpoolctl import threadpool_limits

from plansim.model.parameters import N_PARAMETERS
from plansim.scenario import Scenario
from plansim.schedule.segments import Schedule, axis_vector, body_to_level
from plansim.simulate import sample_path, segment_path
from plansim.simulate.physics import EFFECT_ROWS, draw_systematic, draws_length
from plansim.simulate.compilation import bound_call, compile_kernels
from plansim.simulate.random import root_key

CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")

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
    """Every model input of the kernels, in SI (see :mod:`plansim.simulate.sample_path`)."""
    e, n, a, t = scenario.effects, scenario.noise, scenario.acquisition, scenario.turntable
    errors = (t.position_accuracy, t.position_repeatability, t.axis_perpendicularity, t.platform_tilt,
              t.fixture_perpendicularity, t.rate_error_systematic, t.rate_error_per_point)
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


PATHS = ("auto", "sample", "segment")
PATH_NAMES = {"sample": "sample-level", "segment": "segment-statistics"}


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
    """(S, 3, 5) unit-σ drift coefficients per segment for GM bias instability, GM drift, random walk."""
    n = scenario.noise
    out = np.zeros((len(scenario.schedule), 3, 5))
    taus = (n.bias_instability_correlation_time, n.markov_correlation_time, None)
    table = {}  # a schedule repeats few (samples, rate) pairs: 135 evaluations -> a handful
    for k, s in enumerate(scenario.schedule.segments):
        for p, tau in enumerate(taus):
            arguments = (s.samples, 1.0 / s.sample_rate, n.drift_update_interval, tau)
            if arguments not in table:
                table[arguments] = segment_path.drift_coefficients(*arguments)
            out[k, p] = table[arguments]
    return out


def output_bound(scenario: Scenario) -> np.ndarray:
    """A conservative bound on |noise-free output| per channel (gx…az, SI) over the whole schedule.

    Every coefficient is taken at |nominal| + 6 × its unit-to-unit spread and every input at its
    largest magnitude: rate r = max |table rate| + Ω_ie, specific force f = g + r²·|lever arm|,
    temperature offset the largest |T − T_ref|. Plain NumPy (no kernel to compile).
    """
    from plansim.model.parameters import unpack

    e = scenario.effects
    m = unpack(np.abs(scenario.truth_nominal) + 6 * np.abs(scenario.truth_spread))
    segments = scenario.schedule.segments
    r = max(abs(s.rate) for s in segments) + float(np.linalg.norm(scenario.environment.earth_rate_vector))
    dT = max(abs(s.temperature - e.reference_temperature) for s in segments)
    g = scenario.environment.gravity
    f = g + r * r * np.linalg.norm(e.accel_lever_arm, axis=1).max()
    kg_diag = np.diag(m["Kg"])
    gyro = (m["Kg"].sum(1) * r + m["Bg"] + np.abs(e.gyro_bias_temperature_coefficient) * dT + m["G"].sum(1) * f
            + np.abs(e.gyro_g2_sensitivity).sum(1) * f * f + kg_diag * np.abs(e.gyro_scale_temperature_coefficient) * dT * r
            + np.abs(e.gyro_nonlinearity_quadratic) * r**2 + np.abs(e.gyro_nonlinearity_cubic) * r**3
            + 0.5 * np.abs(e.gyro_asymmetry) * kg_diag * r)
    ka_diag = np.diag(m["Ka"])
    accel = (m["Ka"].sum(1) * f + m["Ba"] + np.abs(e.accel_bias_temperature_coefficient) * dT + m["P"].sum(1) * r * r
             + ka_diag * np.abs(e.accel_scale_temperature_coefficient) * dT * f + np.abs(e.accel_second_order) * f * f)
    return np.concatenate([gyro, accel])


def segment_path_exactness(scenario: Scenario) -> list[str]:
    """Reasons the segment-statistics path would not be exact for *scenario* (empty list: it is).

    Checks, each stated in :mod:`plansim.simulate.segment_path`: no gyro asymmetry; no
    saturation (:func:`output_bound` plus 6σ of white noise and drift inside the output range and
    the acquisition full scale); for quantised channels that the noise does not dither, drift small
    against the noise (≤ 0.1σ) so that its variation within a segment does not move the quantiser;
    and some white noise on every quantised channel an estimator reads while the table turns.
    """
    reasons = []
    e, a = scenario.effects, scenario.acquisition
    if np.any(e.gyro_asymmetry != 0):
        reasons.append("gyro asymmetry is on: |ω| is not a polynomial in the table angle")
    noise = kernel_arguments(scenario)["noise"]
    sample_dt = min(1.0 / s.sample_rate for s in scenario.schedule.segments)
    white = noise[:, 0] / math.sqrt(sample_dt)
    drift_sigma = np.sqrt(noise[:, 1] ** 2 + noise[:, 3] ** 2 + noise[:, 2] ** 2 * scenario.schedule.duration)
    bound = output_bound(scenario) + 6 * (white + drift_sigma)
    limits = np.array([e.gyro_output_range] * 3 + [e.accel_output_range] * 3)
    if a.bits:
        limits = np.minimum(limits, [a.gyro_full_scale] * 3 + [a.accel_full_scale] * 3)
    for c in np.flatnonzero(bound >= limits):
        reasons.append(f"channel {CHANNELS[c]} may saturate: bound {bound[c]:.4g} >= limit {limits[c]:.4g} (SI)")
    if a.bits:
        steps = np.array([a.gyro_step] * 3 + [a.accel_step] * 3)
        n_max = max(seg.samples for seg in scenario.schedule.segments)
        bias = steps / np.pi * np.exp(-2 * np.pi**2 * white**2 / steps**2)
        dithered = bias <= segment_path.RELATIVE_TOLERANCE * white / math.sqrt(n_max)
        for c in np.flatnonzero(~dithered & (drift_sigma > 0.1 * np.maximum(white, 1e-300))):
            reasons.append(f"channel {CHANNELS[c]}: drift σ {drift_sigma[c]:.3g} > 0.1 × white σ {white[c]:.3g} "
                           "in a quantiser the noise does not dither")
        # without noise a quantiser's output is a staircase in the table angle while the table turns,
        # which an average over θ at nodes cannot catch (at rest it is plain rounding, which is exact)
        rotating = np.array([seg.rate != 0.0 for seg in scenario.schedule.segments])
        needed_turning = needed_channels(scenario.schedule)[rotating].any(axis=0)
        for c in np.flatnonzero((white == 0.0) & needed_turning):
            reasons.append(f"channel {CHANNELS[c]} is quantised without white noise while the table turns: its "
                           "output is a staircase in the table angle, not a smooth function to average")
    return reasons


def choose_path(scenario: Scenario, path: str = "auto") -> tuple[str, list[str]]:
    """``(path, reasons)``: *auto* takes the segment-statistics path only where it is exact."""
    if path not in PATHS:
        raise ValueError(f"path = {path!r}; allowed: {', '.join(PATHS)}")
    if path == "sample":
        return "sample", []
    reasons = segment_path_exactness(scenario)
    if path == "auto":
        return ("sample" if reasons else "segment"), reasons
    return "segment", reasons


def nominal_draws(scenario: Scenario) -> np.ndarray:
    """A draws vector with the nominal truth, every table error zero and every start phase zero."""
    draws = np.zeros(draws_length(len(scenario.schedule)))
    draws[:N_PARAMETERS] = scenario.truth_nominal
    return draws


def noise_free_segment_means(scenario: Scenario, draws: np.ndarray) -> np.ndarray:
    """Exact noise-free segment means (n, S, 6) for draws vectors (n, D) (layout: plansim.simulate.physics)."""
    draws = np.ascontiguousarray(draws, dtype=float)
    if draws.ndim != 2 or draws.shape[1] != draws_length(len(scenario.schedule)):
        raise ValueError(f"draws: expected shape (n, {draws_length(len(scenario.schedule))}), got {draws.shape}")
    args = _as_float_arrays(kernel_arguments(scenario))
    out = np.empty((draws.shape[0], len(scenario.schedule), 6))
    keep = ("seg_n", "seg_dt", "seg_C0", "seg_rate", "seg_axis", "seg_axis_index", "seg_temp", "sensor", "S2",
            "lever", "t_ref", "gravity", "earth_enu")
    segment_path.noise_free_means(draws, **{k: args[k] for k in keep}, means_out=out)
    return out


def _check_run_arguments(trials, chunk_size, path):
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise ValueError(f"trials = {trials!r}: expected a whole number >= 1")
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise ValueError(f"chunk_size = {chunk_size!r}: expected a whole number >= 1")
    if path not in ("sample", "segment"):
        raise ValueError(f"path = {path!r}; allowed: 'sample', 'segment'")


#: trials per call of the segment path's two kernels: their hand-over arrays (17.6 kB per trial for
#: the default schedule) stay in the core's cache between the two calls
SEGMENT_BLOCK = 64

_NODES_ARGUMENTS = ("truth_nominal", "truth_spread", "error_kind", "error_scale", "seg_C0", "seg_rate", "seg_axis",
                    "seg_axis_index", "seg_temp", "sensor", "S2", "lever", "t_ref", "smoothness", "gravity",
                    "earth_enu")
_STATISTICS_ARGUMENTS = ("seg_n", "seg_dt", "seg_gap", "seg_rate", "acquisition", "noise", "noise_times",
                         "smoothness", "drift_coeffs", "needed")


class _PathKernels:
    """The kernels of one path with their scenario arguments bound: ``run_slice(first, key, means, truth)``
    fills a slice of trials; ``calls(key)`` lists each entry kernel with arguments of the right types
    (for :func:`plansim.simulate.compilation.compile_kernels`)."""

    def __init__(self, scenario: Scenario, path: str):
        args = _as_float_arrays(kernel_arguments(scenario))
        self.path = path
        self.segments = len(scenario.schedule)
        if path == "segment":
            args["drift_coeffs"] = drift_coefficient_table(scenario)
            args["needed"] = needed_channels(scenario.schedule)
            self.nodes_args = {k: args[k] for k in _NODES_ARGUMENTS}
            self.statistics_args = {k: args[k] for k in _STATISTICS_ARGUMENTS}
        else:
            self.args = args

    def _buffers(self, trials: int):
        return (np.empty((trials, self.segments, segment_path.DETERMINISTIC_NODES, 6)),
                np.empty((trials, self.segments)), np.empty((trials, self.segments, 6)))

    def run_slice(self, first: int, key: np.ndarray, means: np.ndarray, truth: np.ndarray) -> None:
        if self.path == "sample":
            sample_path.simulate_chunk(first, key, **self.args, means_out=means, truth_out=truth)
            return
        count = means.shape[0]
        nodes, rates, jitter = self._buffers(min(SEGMENT_BLOCK, count))
        for a in range(0, count, SEGMENT_BLOCK):
            b = min(count, a + SEGMENT_BLOCK)
            k = b - a
            segment_path.simulate_chunk_nodes(first + a, key, **self.nodes_args, truth_out=truth[a:b],
                                              nodes_out=nodes[:k], rates_out=rates[:k], jitter_out=jitter[:k])
            segment_path.simulate_chunk_statistics(first + a, key, nodes[:k], rates[:k], jitter[:k],
                                                   **self.statistics_args, means_out=means[a:b])

    def calls(self, key: np.ndarray) -> list[tuple[object, tuple]]:
        means, truth = np.empty((1, self.segments, 6)), np.empty((1, N_PARAMETERS))
        if self.path == "sample":
            return [bound_call(sample_path.simulate_chunk, 0, key, **self.args, means_out=means, truth_out=truth)]
        nodes, rates, jitter = self._buffers(1)
        return [bound_call(segment_path.simulate_chunk_nodes, 0, key, **self.nodes_args, truth_out=truth,
                           nodes_out=nodes, rates_out=rates, jitter_out=jitter),
                bound_call(segment_path.simulate_chunk_statistics, 0, key, nodes, rates, jitter,
                           **self.statistics_args, means_out=means)]


def iterate_chunks(scenario: Scenario, trials: int, seed: int, chunk_size: int = 4096, path: str = "sample",
                   progress: ProgressCallback | None = None):
    """Yield ``(start, stop, means, truth)`` chunk by chunk; a chunk's buffers are valid until the next
    one is asked for (copy what you keep).

    Working memory is bounded by *chunk_size* whatever the number of trials (two chunks' buffers:
    the threads simulate the next chunk while the caller uses this one); trial *i* gives the same
    numbers in any chunk (its random streams depend on the seed and *i* only). The path's kernels
    are compiled (or loaded from numba's cache) first, on every core
    (:func:`plansim.simulate.compilation.compile_kernels`).
    """
    _check_run_arguments(trials, chunk_size, path)
    key = root_key(seed)
    kernels = _PathKernels(scenario, path)
    compile_kernels(kernels.calls(key))
    size = min(chunk_size, trials)
    buffers = [(np.empty((size, len(scenario.schedule), 6)), np.empty((size, N_PARAMETERS))) for _ in range(2)]
    starts = list(range(0, trials, chunk_size))
    workers = numba.get_num_threads()  # honours numba.set_num_threads / NUMBA_NUM_THREADS

    def submit(pool, index):
        start = starts[index]
        count = min(trials, start + chunk_size) - start
        means, truth = buffers[index % 2]
        # contiguous slices, one per thread; each trial's numbers depend on its index only
        edges = np.linspace(0, count, min(workers, count) + 1).astype(int)
        return [pool.submit(kernels.run_slice, start + int(a), key, means[a:b], truth[a:b])
                for a, b in zip(edges[:-1], edges[1:])]

    # the kernel threads use every core: a multithreaded BLAS (numpy's, in the caller's reduction between
    # chunks) would only compete with them, its idle threads spinning (10-30 % more CPU for the same run,
    # measured). The limit is process-wide and holds until the last chunk has been used.
    with threadpool_limits(limits=1, user_api="blas"), ThreadPoolExecutor(max_workers=workers) as pool:
        jobs = submit(pool, 0)
        for index, start in enumerate(starts):
            for job in jobs:
                job.result()
            if index + 1 < len(starts):
                jobs = submit(pool, index + 1)  # into the other buffers, while the caller uses these
            stop = min(trials, start + chunk_size)
            means, truth = buffers[index % 2]
            yield start, stop, means[: stop - start], truth[: stop - start]
            if progress is not None:
                progress(stop, trials)


def simulate_segment_means(scenario: Scenario, trials: int, seed: int, chunk_size: int = 256,
                           progress: ProgressCallback | None = None, path: str = "sample"
                           ) -> tuple[np.ndarray, np.ndarray]:
    """Run *trials* calibrations on the sample-level (``path="sample"``) or segment-statistics path.

    Returns
    -------
    means : (trials, S, 6) array
        Mean output of every segment (rad/s, m/s²).
    truth : (trials, 39) array
        The parameters each simulated unit really had (SI).
    """
    _check_run_arguments(trials, chunk_size, path)
    means = np.empty((trials, len(scenario.schedule), 6))
    truth = np.empty((trials, N_PARAMETERS))
    for start, stop, m, t in iterate_chunks(scenario, trials, seed, chunk_size, path, progress):
        means[start:stop] = m
        truth[start:stop] = t
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
    draws = np.empty(draws_length(len(scenario.schedule)))
    draw_systematic(int(trial), key, args.pop("truth_nominal"), args.pop("truth_spread"),
                    args.pop("error_kind"), args.pop("error_scale"), len(scenario.schedule), draws)
    sample_path.simulate_trial(int(trial), key, draws, **args, means_out=means,
                               samples_out=samples, record=True)
    truth = draws[:N_PARAMETERS].copy()
    return samples, means, truth
