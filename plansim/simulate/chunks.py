"""Running the kernels of a path over many trials, chunk by chunk, on every core.

Trial *i* draws its numbers from its own random streams (seed and *i* only), so a given seed gives
the same numbers whatever the chunk size or thread count. Working memory is bounded by the chunk
size (two chunks' buffers: the threads simulate the next chunk while the caller uses this one).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from threadpoolctl import threadpool_limits

from plansim.config import Scenario
from plansim.kernels import sample_path, segment_path
from plansim.kernels.layout import N_CHANNELS, N_TRUTH, TRUTH, draws_length
from plansim.kernels.options import worker_threads
from plansim.kernels.physics import draw_systematic
from plansim.kernels.random import root_key
from plansim.simulate.arguments import as_float_arrays, drift_coefficient_table, kernel_arguments, needed_channels
from plansim.simulate.compilation import bound_call, compile_kernels

#: ``progress(done, total)`` after each chunk
ProgressCallback = Callable[[int, int], None]


def check_count(name: str, value, minimum: int = 1) -> int:
    """*value* as an int if it is a whole number >= *minimum*; else TypeError (not an integer, or a bool)
    or ValueError (too small), naming *name*, the value and what is allowed."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} = {value!r}: expected a whole number (int) >= {minimum}, "
                        f"got {type(value).__name__}")
    if value < minimum:
        raise ValueError(f"{name} = {value!r}: expected a whole number >= {minimum}")
    return int(value)


def _check_run_arguments(trials, chunk_size, path):
    check_count("trials", trials)
    check_count("chunk_size", chunk_size)
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
        args = as_float_arrays(kernel_arguments(scenario))
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
        means, truth = np.empty((1, self.segments, 6)), np.empty((1, N_TRUTH))
        if self.path == "sample":
            return [bound_call(sample_path.simulate_chunk, 0, key, **self.args, means_out=means, truth_out=truth)]
        nodes, rates, jitter = self._buffers(1)
        return [bound_call(segment_path.simulate_chunk_nodes, 0, key, **self.nodes_args, truth_out=truth,
                           nodes_out=nodes, rates_out=rates, jitter_out=jitter),
                bound_call(segment_path.simulate_chunk_statistics, 0, key, nodes, rates, jitter,
                           **self.statistics_args, means_out=means)]


#: the most trials one job of the thread pool simulates: a chunk is cut into slices of at most this many,
#: so that an interrupted run stops after one slice per thread (≈ 1.7 s of the sample path on the default
#: scenario) rather than a whole chunk; a job of the segment path still lasts milliseconds
SLICE_TRIALS = 256


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
    buffers = [(np.empty((size, len(scenario.schedule), N_CHANNELS)), np.empty((size, N_TRUTH))) for _ in range(2)]
    starts = list(range(0, trials, chunk_size))
    workers = worker_threads()

    def submit(pool, index):
        start = starts[index]
        count = min(trials, start + chunk_size) - start
        means, truth = buffers[index % 2]
        # contiguous slices, at least one per thread and at most SLICE_TRIALS trials each (so that an
        # interrupted run waits for one short slice per thread, not a whole chunk); each trial's numbers
        # depend on its index only, never on the slicing
        slices = max(min(workers, count), -(-count // SLICE_TRIALS))
        edges = np.linspace(0, count, slices + 1).astype(int)
        return [pool.submit(kernels.run_slice, start + int(a), key, means[a:b], truth[a:b])
                for a, b in zip(edges[:-1], edges[1:])]

    # the kernel threads use every core: a multithreaded BLAS (numpy's, in the caller's reduction between
    # chunks) would only compete with them, its idle threads spinning (10-30 % more CPU for the same run,
    # measured). The limit is process-wide and holds until the last chunk has been used.
    pool = ThreadPoolExecutor(max_workers=workers)
    try:
        with threadpool_limits(limits=1, user_api="blas"):
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
    finally:  # on Ctrl-C, an error or an early close: drop the queued slices, wait only for the running ones
        pool.shutdown(wait=True, cancel_futures=True)


#: trials per reduction block: results are reduced (and summarised) in fixed blocks of trials
#: ``[0, B), [B, 2B), …`` whatever the chunk size, so that every trial's rounding is the same in any run
REDUCTION_BLOCK = 4096


def iterate_blocks(scenario: Scenario, trials: int, seed: int, chunk_size: int = 4096, path: str = "sample",
                   progress: ProgressCallback | None = None, block: int = REDUCTION_BLOCK):
    """Yield ``(start, stop, means, truth)`` in fixed, trial-aligned blocks ``[k·block, (k+1)·block)`` (the
    last one shorter), whatever *chunk_size*.

    The simulation runs chunk by chunk (:func:`iterate_chunks`); this regroups the chunks so that what
    the caller does with a block (a matrix product, a sum) sees the same rows in the same positions for
    any chunk size: its rounding then depends on the trial indices only. A block that lies inside one
    chunk is a view of the chunk's buffers, one that spans chunks is copied into a block buffer
    (``block`` × (S × 6 + 39) × 8 bytes). Either is valid until the next block is asked for. The
    blocks are yielded while the chunks run (BLAS held to one thread, as in :func:`iterate_chunks`).
    """
    _check_run_arguments(trials, chunk_size, path)
    block = check_count("block", block)
    means_buffer = truth_buffer = None
    for start, stop, means, truth in iterate_chunks(scenario, trials, seed, chunk_size, path, progress):
        position = start
        while position < stop:
            first = position - position % block
            last = min(trials, first + block)
            end = min(stop, last)
            if position == first and end == last:  # the whole block is in this chunk
                yield first, last, means[first - start:last - start], truth[first - start:last - start]
            else:
                if means_buffer is None:
                    size = min(block, trials)
                    means_buffer = np.empty((size, *means.shape[1:]))
                    truth_buffer = np.empty((size, truth.shape[1]))
                means_buffer[position - first:end - first] = means[position - start:end - start]
                truth_buffer[position - first:end - first] = truth[position - start:end - start]
                if end == last:
                    yield first, last, means_buffer[:last - first], truth_buffer[:last - first]
            position = end


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
    means = np.empty((trials, len(scenario.schedule), N_CHANNELS))
    truth = np.empty((trials, N_TRUTH))
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
    args = as_float_arrays(kernel_arguments(scenario))
    samples = np.empty((scenario.schedule.total_samples, 6))
    means = np.empty((len(scenario.schedule), N_CHANNELS))
    draws = np.empty(draws_length(len(scenario.schedule)))
    draw_systematic(int(trial), key, args.pop("truth_nominal"), args.pop("truth_spread"),
                    args.pop("error_kind"), args.pop("error_scale"), len(scenario.schedule), draws)
    sample_path.simulate_trial(int(trial), key, draws, **args, means_out=means,
                               samples_out=samples, record=True)
    truth = draws[TRUTH].copy()
    return samples, means, truth
