"""The orchestrator: scenario -> Monte Carlo calibrations -> self-describing results; one trial -> a recording.

``run`` simulates *trials* calibrations of the scenario, reduces each with the JJF 2003 formulas
and returns an :class:`xarray.Dataset` with ``truth``, ``estimate`` and ``error`` over
(``trial``, ``parameter``); parameter labels are the specification's symbols, values are SI with a
``units`` attribute, and the provenance (package version, scenario, seed, path) is in ``attrs``.

``run_summary`` runs the same trials but keeps only their statistics, streamed block by block
(:mod:`plansim.report.summary`), and writes the per-trial arrays to a file block by block when asked
(:mod:`plansim.io.results`): its memory does not grow with the trials beyond the exact quantiles'
tails (5–10 % of the trials, :func:`plansim.report.summary.summary_memory_bytes`).

Both reduce the trials in fixed blocks of :data:`~plansim.simulate.chunks.REDUCTION_BLOCK` trials
aligned on the trial index, each block as one matrix product of the same shape, so a trial's
estimate is the same to the last bit whatever the chunk size and however many trials the run has.
Before a run, :func:`estimate_memory` adds up what it will hold and the run is refused when that
exceeds the memory available.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
import tomli_w
import xarray as xr

import plansim
from plansim.config import Scenario
from plansim.estimate import reduce, reduction_matrix
from plansim.estimate.jjf1535 import allan_polynomial_fit
from plansim.estimate.jjf1535_items import reduce_items
from plansim.fit.noise import allan_deviation
from plansim.io.recording import UNITS_DESCRIPTION, Recording, plansim_version, segment_first_samples
from plansim.io.results import ResultsFile
from plansim.io.scenario_file import load_scenario
from plansim.kernels.layout import CHANNELS, N_CHANNELS, N_TRUTH
from plansim.kernels.options import worker_threads
from plansim.model.parameters import N_PARAMETERS
from plansim.report.summary import RunStatistics, check_budgets, parameter_coordinates, summary_memory_bytes
from plansim.simulate.chunks import (
    REDUCTION_BLOCK,
    SEGMENT_BLOCK,
    ProgressCallback,
    check_count,
    iterate_blocks,
    simulate_recording,
)
from plansim.simulate.jjf1535_effects import without_jjf1535_effects
from plansim.simulate.paths import PATH_NAMES, choose_path
from plansim.uncertainty import APPENDIX_A, AppendixABudget
from plansim.uncertainty.chapter_comparison import (
    CHAPTER_TESTS,
    CHAPTER_TURN_RATE,
    DRIFT_REPEATS,
    ChapterComparison,
    compare_chapter,
    compare_misalignment,
)
from plansim.uncertainty.jjf1535_monte_carlo import Jjf1535MonteCarlo, jjf1535_monte_carlo, jjf1535_scenario

if TYPE_CHECKING:
    from plansim.uncertainty.monte_carlo import CalibrationMonteCarlo
    from plansim.uncertainty.validation import ValidationReport

#: working memory a run needs beyond its arrays and buffers, bytes: Python objects, numba's compiled code and,
#: on a cold start, the compiler (peak RSS of a 2-trial run of the default: 0.23 GB warm, 0.33 GB while
#: compiling, with a second process compiling beside it; the process's RSS before the run is already
#: outside the available memory, so this is an allowance for its growth)
WORKING_ALLOWANCE = 256 * 2**20
def _scenario_of(scenario: Scenario | str) -> Scenario:
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, str):
        return load_scenario(scenario)
    raise TypeError(f"scenario = {scenario!r}: expected a Scenario, a built-in scenario name or a TOML path")


def _run_arguments(scenario, trials, seed, chunk_size) -> tuple[Scenario, int, int]:
    sc = _scenario_of(scenario)
    trials = check_count("trials", sc.trials if trials is None else trials)
    seed = check_count("seed", sc.seed if seed is None else seed, minimum=0)
    check_count("chunk_size", chunk_size)
    return sc, trials, seed


# ----------------------------------------------------------------------------- memory

def available_memory() -> int | None:
    """Memory this process can still take without swapping, bytes: ``MemAvailable`` of /proc/meminfo (the
    kernel's estimate), less if a cgroup (container) limit leaves less; None where neither is known."""
    available = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    available = int(line.split()[1]) * 1024
                    break
    except OSError:
        pass
    if available is None:
        try:
            available = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):
            return None
    try:
        with open("/sys/fs/cgroup/memory.max") as fh:
            limit = fh.read().strip()
        with open("/sys/fs/cgroup/memory.current") as fh:
            current = int(fh.read().strip())
        if limit != "max":
            available = min(available, max(0, int(limit) - current))
    except (OSError, ValueError):
        pass
    return available


def estimate_memory(scenario: Scenario, trials: int, chunk_size: int = 4096, keep_trials: bool = True,
                    keep_segment_means: bool = False,
                    budgets: Iterable[AppendixABudget] = APPENDIX_A) -> dict[str, int]:
    """What a run will hold, bytes, item by item (beyond the process as it is now).

    Parameters
    ----------
    scenario : Scenario
        The run's scenario (its number of segments S sizes the buffers).
    trials, chunk_size : int
        As in :func:`run`.
    keep_trials : bool
        True for :func:`run` (three (trials × 39) float64 arrays: 936 bytes per trial), False for
        :func:`run_summary` (the statistics' kept tails instead, :func:`plansim.report.summary.summary_memory_bytes`).
    keep_segment_means : bool
        :func:`run` keeping every segment mean (S × 6 × 8 bytes per trial).
    budgets : iterable of AppendixABudget
        The Appendix A budgets a summary run compares with.

    Returns
    -------
    dict
        ``{what: bytes}``; their sum is the estimate.
    """
    segments = len(scenario.schedule)
    means_row = segments * N_CHANNELS * 8
    chunk = min(chunk_size, trials)
    block = min(REDUCTION_BLOCK, trials)
    items = {}
    if keep_trials:
        items["per-trial arrays (truth, estimate, error)"] = 3 * trials * N_PARAMETERS * 8
        if keep_segment_means:
            items["segment means"] = trials * means_row
    else:
        items["exact quantiles' tails"] = summary_memory_bytes(trials, budgets)
    items["chunk buffers (two chunks)"] = 2 * chunk * (means_row + N_TRUTH * 8)
    items["reduction blocks"] = block * (means_row + N_TRUTH * 8) + REDUCTION_BLOCK * (means_row + 4 * N_PARAMETERS * 8)
    # the segment path's hand-over arrays: 7 node values, 1 rate and 6 jitters per segment and trial
    items["kernel buffers"] = worker_threads() * SEGMENT_BLOCK * segments * (7 * N_CHANNELS + 1 + N_CHANNELS) * 8
    items["working allowance"] = WORKING_ALLOWANCE
    return items


def check_memory(trials: int, needed: dict[str, int], available: int | None = None) -> None:
    """ValueError naming the trials, the estimate and the limit when *needed* exceeds the available memory.

    *available* defaults to :func:`available_memory` (no check if that is unknown).
    """
    limit = available_memory() if available is None else available
    total = sum(needed.values())
    if limit is None or total <= limit:
        return
    largest = max(needed, key=needed.get)
    raise ValueError(
        f"trials = {trials}: this run needs about {total / 1e9:.3g} GB of memory ({largest}: "
        f"{needed[largest] / 1e9:.3g} GB), more than the {limit / 1e9:.3g} GB available (MemAvailable); "
        "run fewer trials, or keep only the statistics (plansim.runner.run_summary, which can stream the "
        "per-trial arrays to a file: `plansim run` without --plot, with --out for the arrays)")


# ----------------------------------------------------------------------------- the runs

def _reduced_blocks(sc: Scenario, trials: int, seed: int, chunk_size: int, chosen: str,
                    progress: ProgressCallback | None):
    """Yield ``(start, stop, truth, estimate, means)`` in fixed trial-aligned blocks of REDUCTION_BLOCK trials.

    Every block is reduced with the same shape, (REDUCTION_BLOCK × 6S) @ (6S × 39): a shorter last block
    is padded with copies of its last row (results dropped), so trial *i* sits at row ``i mod
    REDUCTION_BLOCK`` of a product of one shape in any run, and its rounding is the same (a
    matrix-vector product of one row, which BLAS computes otherwise, never occurs).
    """
    # the JJF 2003 formulas are linear in the segment means: one matrix product per block
    matrix = reduction_matrix(sc.schedule, sc.reduction.reference_gravity, sc.reduction.omega_squared_sign)
    padded = None
    for start, stop, means, truth in iterate_blocks(sc, trials, seed, chunk_size, chosen, progress):
        count = stop - start
        flat = means.reshape(count, -1)
        if count < REDUCTION_BLOCK:
            if padded is None:
                padded = np.empty((REDUCTION_BLOCK, flat.shape[1]))
            padded[:count] = flat
            padded[count:] = flat[count - 1]
            flat = padded
        if matrix is not None:
            estimate = (flat @ matrix)[:count]
        else:
            estimate = reduce(flat.reshape(REDUCTION_BLOCK, *means.shape[1:]), sc.schedule,
                              sc.reduction.reference_gravity, sc.reduction.omega_squared_sign)[:count]
        yield start, stop, truth, estimate, means


def _path_attributes(chosen: str, path: str, reasons) -> dict:
    return {"simulation_path": PATH_NAMES[chosen], "simulation_path_requested": path,
            "segment_path_not_exact_because": "; ".join(reasons) if reasons else "(exact)"}


def run(scenario: Scenario | str = "jjf2003", trials: int | None = None, seed: int | None = None,
        chunk_size: int = 4096, progress: ProgressCallback | None = None,
        keep_segment_means: bool = False, path: str = "auto") -> xr.Dataset:
    """Monte Carlo of the scenario's calibration, every trial kept.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario object, a built-in name (``plansim scenarios``) or a TOML path.
    trials, seed : int, optional
        Override the scenario's ``[monte_carlo]`` values: ``trials`` a whole number >= 1, ``seed`` >= 0
        (TypeError if not an integer, ValueError if out of range).
    chunk_size : int
        Trials per kernel call (>= 1); results do not depend on it, to the last bit.
    progress : callable, optional
        ``progress(done, total)`` after each chunk.
    keep_segment_means : bool
        Also return the mean output of every segment (trial × segment × channel).
    path : {"auto", "sample", "segment"}
        Simulation path. ``auto`` takes the segment-statistics path only where it is exact
        (:func:`plansim.simulate.paths.segment_path_exactness`); the path used and, if the
        segment path was not exact, why, are in ``attrs``.

    Returns
    -------
    xarray.Dataset
        ``truth``, ``estimate``, ``error`` (= estimate − truth) over (trial, parameter), SI.

    Raises
    ------
    ValueError
        Also when the arrays would not fit in the memory available (:func:`estimate_memory`,
        :func:`check_memory`); :func:`run_summary` keeps only the statistics.
    """
    sc, trials, seed = _run_arguments(scenario, trials, seed, chunk_size)
    chosen, reasons = choose_path(sc, path)
    check_memory(trials, estimate_memory(sc, trials, chunk_size, keep_trials=True,
                                         keep_segment_means=keep_segment_means))
    truth = np.empty((trials, N_PARAMETERS))
    estimate = np.empty((trials, N_PARAMETERS))
    means = np.empty((trials, len(sc.schedule), N_CHANNELS)) if keep_segment_means else None
    for start, stop, t, e, m in _reduced_blocks(sc, trials, seed, chunk_size, chosen, progress):
        truth[start:stop] = t
        estimate[start:stop] = e
        if means is not None:
            means[start:stop] = m
    results = results_dataset(sc, truth, estimate, seed, means)
    results.attrs.update(_path_attributes(chosen, path, reasons))
    return results


def run_summary(scenario: Scenario | str = "jjf2003", trials: int | None = None, seed: int | None = None,
                chunk_size: int = 4096, progress: ProgressCallback | None = None, path: str = "auto",
                out: str | os.PathLike | ResultsFile | None = None,
                budgets: Iterable[AppendixABudget] | None = None) -> xr.Dataset:
    """Monte Carlo of the scenario's calibration, keeping only its statistics (and the per-trial arrays on file).

    The same trials as :func:`run` with the same arguments, to the last bit; what is kept is
    summarised block by block (:class:`plansim.report.summary.RunStatistics`): per parameter the
    moments, the exact 2.5 %, 97.5 % quantiles of the error and 95 % of ``|error|``, and the
    Appendix A comparison's statistics and coverage counts. Memory: the kept tails of the quantiles
    (about 110 MB at 10⁶ trials) and a few blocks of trials.

    Parameters
    ----------
    scenario, trials, seed, chunk_size, progress, path
        As in :func:`run`.
    out : path or plansim.io.results.ResultsFile, optional
        Also write ``truth``, ``estimate`` and ``error`` per trial, block by block, as the NetCDF-4 file
        :func:`run` would give. A path is written whole or not at all (a temporary file beside it,
        renamed at the end; removed on any exception, KeyboardInterrupt included). An open
        :class:`~plansim.io.results.ResultsFile` is filled but not committed: the caller commits it
        (to commit several outputs together) or discards it.
    budgets : iterable of AppendixABudget, optional
        Appendix A budgets to compare with (default all of :data:`plansim.uncertainty.APPENDIX_A`;
        none with 1 trial). :func:`plansim.report.summary.appendix_a_comparisons` turns the result
        into :class:`plansim.uncertainty.ItemComparison` objects.

    Returns
    -------
    xarray.Dataset
        Over ``parameter`` (SI): ``truth_mean``, ``error_mean``, ``error_std`` (ddof = 1; NaN with one
        trial), ``error_min``, ``error_max``, ``abs_error_q95``, ``error_quantile`` (× ``quantile`` 0.025,
        0.975); over ``item`` (and ``parameter``): the Appendix A statistics in each budget's reading unit.
        ``attrs``: the provenance of :func:`run` (scenario TOML, seed, trials, paths, version).
    """
    sc, trials, seed = _run_arguments(scenario, trials, seed, chunk_size)
    budgets = APPENDIX_A if budgets is None else check_budgets(budgets)
    chosen, reasons = choose_path(sc, path)
    check_memory(trials, estimate_memory(sc, trials, chunk_size, keep_trials=False, budgets=budgets))
    template = results_dataset(sc, np.empty((0, N_PARAMETERS)), np.empty((0, N_PARAMETERS)), seed)
    template.attrs.update(trials=trials, **_path_attributes(chosen, path, reasons))
    statistics = RunStatistics(sc, trials, budgets)
    if out is None or isinstance(out, ResultsFile):
        _stream(sc, trials, seed, chunk_size, chosen, progress, statistics, template, out)
    else:
        with ResultsFile(out) as results_file:
            _stream(sc, trials, seed, chunk_size, chosen, progress, statistics, template, results_file)
            results_file.commit()
    summary = statistics.dataset(dict(template.attrs))
    summary.attrs["title"] = f"plansim Monte Carlo summary of scenario {sc.name!r}"
    return summary


def _stream(sc, trials, seed, chunk_size, chosen, progress, statistics: RunStatistics, template: xr.Dataset,
            out: ResultsFile | None) -> None:
    """Feed the reduced blocks to *statistics* and, if given, to the results file *out*."""
    if out is not None:
        out.check_space(trials)
        out.start(template, trials)
    for start, _stop, truth, estimate, _means in _reduced_blocks(sc, trials, seed, chunk_size, chosen, progress):
        error = statistics.add(start, truth, estimate)
        if out is not None:
            out.write(start, truth=truth, estimate=estimate, error=error)


def results_dataset(sc: Scenario, truth: np.ndarray, estimate: np.ndarray, seed: int,
                    segment_means: np.ndarray | None = None) -> xr.Dataset:
    """Wrap the arrays of a run as a self-describing Dataset."""
    n = truth.shape[0]
    coords = {"trial": ("trial", np.arange(n), {"long_name": "Monte Carlo trial (one simulated calibration)"}),
              **parameter_coordinates()}
    common = {"units": "SI (per parameter: see the 'units' coordinate)"}
    data = {
        "truth": (("trial", "parameter"), truth, {**common, "long_name": "true parameter of the simulated unit"}),
        "estimate": (("trial", "parameter"), estimate,
                     {**common, "long_name": "JJF 2003 estimate from the simulated recording"}),
        "error": (("trial", "parameter"), estimate - truth,
                  {**common, "long_name": "estimation error (estimate − truth)"}),
    }
    if segment_means is not None:
        coords["segment"] = ("segment", [s.label for s in sc.schedule.segments])
        coords["channel"] = ("channel", list(CHANNELS))
        data["segment_mean"] = (("trial", "segment", "channel"), segment_means,
                                {"units": "rad/s (gyro), m/s^2 (accelerometer)", "long_name": "mean output, eq. (3)"})
    attrs = {
        "title": f"plansim Monte Carlo of scenario {sc.name!r}",
        "scenario": sc.name,
        "scenario_description": sc.description,
        "scenario_source": sc.source or "a Scenario object built in Python",
        "scenario_overrides": "; ".join(sc.overrides),
        "scenario_toml": tomli_w.dumps(sc.document),
        # NetCDF-3 attributes hold 32-bit integers only: larger seeds are kept as text
        "seed": int(seed) if int(seed) <= 2**31 - 1 else str(int(seed)),
        "trials": int(n),
        "simulation_path": "sample-level",
        "plansim_version": plansim.__version__,
        "reduction_block_trials": REDUCTION_BLOCK,
        "reference_gravity_m_s2": float(sc.reduction.reference_gravity),
        "reference_gravity_choice": sc.reduction.reference_gravity_label,
        "local_gravity_m_s2": float(sc.environment.gravity),
        "latitude_deg": math.degrees(sc.environment.latitude),
        "created_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def simulate_and_record(scenario, seed: int, trial: int = 0) -> Recording:
    """Simulate one trial of *scenario* and return every raw sample as a :class:`Recording`.

    Parameters
    ----------
    scenario : plansim.config.Scenario
        The simulated world and schedule.
    seed : int
        Root seed, >= 0 (the same as for :func:`run`).
    trial : int
        Trial number, >= 0; the recording holds the same numbers that trial gives in a Monte Carlo run.

    Returns
    -------
    Recording
        ``attrs`` holds ``plansim_version``, ``scenario``, ``seed``, ``trial``, ``source = "simulated"``
        and ``units``. The true parameters of the simulated unit are not kept; call
        :func:`plansim.simulate.chunks.simulate_recording` for them.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario (see plansim.io.scenario_file.load_scenario), "
                        f"got {type(scenario).__name__}")
    samples, _segment_means, _truth = simulate_recording(scenario, seed, trial)
    attrs = {"plansim_version": plansim_version(), "scenario": scenario.name, "seed": int(seed),
             "trial": int(trial), "source": "simulated", "units": UNITS_DESCRIPTION}
    return Recording(samples=samples, schedule=scenario.schedule, attrs=attrs)


def error_simulator(scenario: Scenario, path: str = "auto"):
    """The scenario's calibration as ``simulate(trials, seed) -> (trials, 39)`` errors, and the name of its path.

    Parameters
    ----------
    scenario : Scenario
    path : {"auto", "sample", "segment"}
        As in :func:`run`.

    Returns
    -------
    simulate : callable
        ``run(scenario, trials, seed, path)["error"].values``: estimate − truth, SI.
    path_name : str
        The simulation path ``run`` takes for this scenario (its ``attrs["simulation_path"]``).
    """
    chosen, _ = choose_path(scenario, path)

    def simulate(trials: int, seed: int) -> np.ndarray:
        return run(scenario, trials=trials, seed=seed, path=path)["error"].values

    return simulate, PATH_NAMES[chosen]


def adaptive_monte_carlo(scenario: Scenario, *, path: str = "auto", **options) -> CalibrationMonteCarlo:
    """JCGM 101 7.9.4 adaptive Monte Carlo of the scenario's calibration (outputs: the 39 errors).

    Parameters
    ----------
    scenario : Scenario
    path : {"auto", "sample", "segment"}
        Simulation path.
    **options
        ``digits``, ``trials_per_block``, ``max_trials``, ``seed``, ``tolerance``, ``parameters``,
        ``coverage_probability``, ``progress`` of
        :func:`plansim.uncertainty.monte_carlo.calibration_monte_carlo`.
    """
    from plansim.uncertainty.monte_carlo import calibration_monte_carlo

    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    simulate, path_name = error_simulator(scenario, path)
    return calibration_monte_carlo(simulate, scenario, path=path_name, **options)


def validate(scenario: Scenario | str = "jjf2003", claims=None, *, path: str = "auto", **options) -> ValidationReport:
    """``plansim validate``: GUM budget, adaptive MCM, JCGM 101 §8 validation and coverage of the truth.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario, a built-in name or a TOML path.
    claims : mapping of parameter name -> Claim, optional
        Default: the Appendix A budgets as printed.
    path : {"auto", "sample", "segment"}
        Simulation path of the Monte Carlo.
    **options
        The keyword arguments of :func:`plansim.uncertainty.validation.validate` (``digits``,
        ``trials_per_block``, ``max_trials``, ``seed``, ``tolerance_fraction``,
        ``coverage_probability``, ``joint_parameters``, ``monitor``, ``progress``).
    """
    from plansim.uncertainty.validation import validate as validate_scenario

    sc = _scenario_of(scenario)
    simulate, path_name = error_simulator(sc, path)
    return validate_scenario(sc, simulate, claims, path=path_name, **options)


def compare_chapter_misalignment(scenario: Scenario | str = "jjf2003", trials: int = 1000, seed: int | None = None,
                                 rate: float = CHAPTER_TURN_RATE, turns: int = 1,
                                 path: str = "auto") -> ChapterComparison:
    """The gyro misalignments of the same units by JJF 2003 §7.2.3 and by the chapter's ± rate turns, eq. (6-8).

    *scenario* (a built-in name, a TOML path or a :class:`~plansim.config.Scenario`; default ``jjf2003``)
    is simulated with its JJF 2003 schedule plus the turns (*rate* rad/s, *turns* whole turns each way,
    about x, y and z); see :func:`plansim.uncertainty.chapter_comparison.compare_misalignment`. *seed*
    defaults to the scenario's.
    """
    sc = _scenario_of(scenario)
    seed = sc.seed if seed is None else seed
    return compare_misalignment(sc, trials, seed, rate=rate, turns=turns, path=path)


def compare_chapter_procedures(scenario: Scenario | str = "jjf2003", trials: int = 1000, seed: int | None = None,
                               tests=CHAPTER_TESTS, rate: float = CHAPTER_TURN_RATE, turns: int = 1,
                               repeats: int = DRIFT_REPEATS, path: str = "auto", chunk_size: int = 256,
                               progress: ProgressCallback | None = None) -> ChapterComparison:
    """The textbook chapter's procedures and JJF 2003 on the same units: gyro misalignments (eq. (6-8)),
    accelerometer cross-axis terms (the 8-position test, eq. (6-9)) and the gyro drift model D0–D3 with its
    random drift (eq. (6-6)).

    *scenario* (a built-in name, a TOML path or a :class:`~plansim.config.Scenario`; default ``jjf2003``)
    is simulated with its JJF 2003 schedule plus the chapter's tests; see
    :func:`plansim.uncertainty.chapter_comparison.compare_chapter`. *seed* defaults to the scenario's.
    ``plansim run chapter --unit SCENARIO`` prints its summary.
    """
    sc = _scenario_of(scenario)
    seed = sc.seed if seed is None else seed
    return compare_chapter(sc, trials, seed, tests, rate=rate, turns=turns, repeats=repeats, path=path,
                           chunk_size=chunk_size, progress=progress)


def jjf1535_run(scenario: Scenario | str = "jjf2003", trials: int = 1000, seed: int | None = None,
                procedure=None, path: str = "auto", keep_table: bool = False,
                progress: ProgressCallback | None = None) -> Jjf1535MonteCarlo:
    """The x gyro of *scenario*'s units through JJF 1535-2015, its items against the truth and Appendix A.

    *scenario* (a built-in name, a TOML path or a :class:`~plansim.config.Scenario`; default ``jjf2003``) gives the
    unit, noise, effects and laboratory; see :func:`plansim.uncertainty.jjf1535_monte_carlo.jjf1535_monte_carlo`
    (also for *progress*, ``progress(done, total)`` after each chunk of trials). *seed* defaults to the scenario's.
    ``plansim run jjf1535 --unit SCENARIO`` prints its :meth:`~Jjf1535MonteCarlo.summary`.
    """
    sc = _scenario_of(scenario)
    seed = sc.seed if seed is None else seed
    return jjf1535_monte_carlo(sc, trials, seed, procedure=procedure, path=path, keep_table=keep_table,
                               progress=progress)


def jjf1535_angle_random_walk(scenario: Scenario | str = "jjf2003", seed: int | None = None, trial: int = 0,
                              procedure=None, keep_table: bool = False) -> tuple[float, float]:
    """7.2.13 on one simulated session: ``(ARW reported, ARW simulated)``, rad/√s.

    The session's samples (:func:`plansim.simulate.chunks.simulate_recording`) give K (eq. (5), the Q room runs'
    mean, :func:`plansim.estimate.jjf1535_items.reduce_items`); the long static record divided by K is eq. (21);
    its overlapping Allan variance at octave-spaced τ (:func:`plansim.fit.noise.allan_deviation`) is eq. (22)–(24);
    eq. (25)–(26), the five-term polynomial by least squares and ARW = √A₋₁, is
    :func:`plansim.estimate.jjf1535.allan_polynomial_fit`. The simulated value is the scenario's
    ``gyro_angle_random_walk`` of the gyro under test.
    """
    sc = _scenario_of(scenario)
    seed = sc.seed if seed is None else seed
    world, procedure = jjf1535_scenario(sc, procedure, keep_table)
    # the record of 7.2.13 is long after every power-on: the JJF 1535 effects (added to means only) left out
    samples, means, _truth = simulate_recording(without_jjf1535_effects(world), seed, trial)
    K = reduce_items(means, procedure, sc.reduction.reference_gravity)["scale_factor"]
    schedule = procedure.schedule
    start = int(segment_first_samples(schedule)[procedure.allan])
    record = schedule.segments[procedure.allan]
    rates = samples[start: start + record.samples, procedure.axis] / K
    tau, adev, _dof = allan_deviation(rates, record.sample_rate)
    reported = allan_polynomial_fit(tau, adev**2).angle_random_walk
    return reported, float(sc.noise.gyro_angle_random_walk[procedure.axis])
