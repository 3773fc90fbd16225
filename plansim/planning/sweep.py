"""Sweeps: one scenario, many schedules, compared in one self-describing Dataset (:func:`sweep`).

Each cell of the grid (:mod:`plansim.planning.grid`) is the base scenario with the cell's overrides.
For each cell the sweep gives

- the prediction of :func:`plansim.planning.predict.predict` (the GUM of the schedule):
  ``u_predicted``, ``bias_predicted``, ``U_predicted``;
- with ``trials > 0``, a Monte Carlo of ``trials`` calibrations (:func:`plansim.runner.run`, seeded from
  the cell's overrides: :func:`plansim.planning.grid.cell_seed`): ``u_mc`` (the standard deviation of
  the error), ``bias_mc`` (its mean) and ``coverage`` (the fraction of trials whose error lies within
  ± ``U_predicted``: how well the predicted expanded uncertainty covers);
- ``table_time_s``, the schedule's table time (dwell and settling of every segment; the settle time
  holds the table's move to the setting);
- ``compliant_jjf2003`` and the rule-by-rule ``jjf2003_rule`` of
  :func:`plansim.schedule.compliance.jjf2003_compliance`, and ``max_rate``.

Executors: ``serial``; ``threads`` (cells side by side in a thread pool: the numba kernels release the
GIL); ``dask`` (a ``dask.distributed`` LocalCluster of processes with one thread each, or an existing
cluster at ``scheduler``; the optional extra ``plansim[dask]``). A cell's numbers depend only on the
base scenario, its overrides and the base seed, so every executor and worker count gives the same
Dataset to the last bit. A failed cell raises a ValueError naming the cell; nothing is returned.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import xarray as xr

from plansim.config import Scenario
from plansim.io.recording import plansim_version
from plansim.io.scenario_file import load_scenario
from plansim.model.parameters import GROUPS, PARAMETERS, group_spec
from plansim.planning.grid import ZIP_DIMENSION, Grid, cell_seed, parse_grid
from plansim.planning.predict import predict
from plansim.schedule.compliance import RULES, jjf2003_compliance
from plansim.simulate.chunks import check_count

EXECUTORS = ("serial", "threads", "dask")
#: what each cell gives, over ``parameter``
PER_PARAMETER = ("u_predicted", "bias_predicted", "U_predicted", "u_mc", "bias_mc", "coverage")


@dataclass(frozen=True)
class CellResult:
    """What one cell gives (SI); the Monte Carlo arrays are NaN when no trial was run."""

    index: tuple[int, ...]
    seed: int
    per_parameter: dict[str, np.ndarray]
    table_time_s: float
    rules: dict[str, bool]
    max_rate: float


def evaluate_cell(scenario: Scenario, index: tuple[int, ...], seed: int, trials: int, path: str = "auto",
                  coverage_probability: float = 0.95) -> CellResult:
    """Predict, and with ``trials > 0`` simulate, one cell's scenario (see the module's docstring)."""
    from plansim.runner import run

    p = predict(scenario, coverage_probability)
    out = {"u_predicted": p.u_predicted.values, "bias_predicted": p.bias_predicted.values,
           "U_predicted": p.U_predicted.values}
    nan = np.full(len(PARAMETERS), np.nan)
    if trials > 0:
        error = run(scenario, trials=trials, seed=seed, path=path)["error"].values
        out["u_mc"] = error.std(axis=0, ddof=1) if trials > 1 else nan
        out["bias_mc"] = error.mean(axis=0)
        out["coverage"] = np.mean(np.abs(error) <= out["U_predicted"][None, :], axis=0)
    else:
        out.update(u_mc=nan, bias_mc=nan, coverage=nan)
    compliance = jjf2003_compliance(scenario.schedule)
    return CellResult(index, seed, out, scenario.schedule.duration, dict(compliance.rules), compliance.max_rate)


def cell_scenarios(scenario: str | os.PathLike, grid: Grid, overrides=()) -> list[tuple[tuple, list[str], Scenario]]:
    """Every cell's ``(index, overrides, scenario)``, each loaded and checked (before any work starts).

    Raises
    ------
    ValueError, TypeError
        A cell whose scenario does not load: the message names the cell's overrides.
    """
    cells = []
    for index, cell in grid.cells():
        try:
            cells.append((index, cell, load_scenario(scenario, [*overrides, *cell])))
        except (ValueError, TypeError) as error:
            raise type(error)(f"sweep cell {'; '.join(cell)}: {error}") from None
    return cells


def sweep(scenario: str | os.PathLike = "jjf2003", grid: Grid | dict | None = None, *, overrides=(),
          trials: int | None = None, seed: int | None = None, executor: str = "serial", workers: int | None = None,
          scheduler: str | None = None, path: str = "auto", coverage_probability: float = 0.95,
          progress: Callable[[int, int], None] | None = None) -> xr.Dataset:
    """Predict, and simulate, every cell of *grid* on the base *scenario* (see the module's docstring).

    Parameters
    ----------
    scenario : str or path
        A built-in scenario's name or a scenario file (``plansim scenarios``).
    grid : Grid or dict
        The grid (:func:`plansim.planning.grid.load_grid`), or a grid document as ``tomllib`` reads it.
    overrides : sequence of str
        ``KEY=VALUE`` set on the base scenario before the cell's own (as ``--set``).
    trials : int, optional
        Monte Carlo trials per cell; 0: the prediction only; default: the base scenario's.
    seed : int, optional
        The base seed (default: the scenario's); each cell's is :func:`plansim.planning.grid.cell_seed`.
    executor : {"serial", "threads", "dask"}
    workers : int, optional
        Threads or Dask worker processes (default: the machine's cores).
    scheduler : str, optional
        Address of a running Dask scheduler (``executor="dask"`` only).
    path : {"auto", "sample", "segment"}
        The simulation path, as in :func:`plansim.runner.run`.
    coverage_probability : float
        p of ``U_predicted`` and ``coverage``.
    progress : callable, optional
        ``progress(cells_done, cells)``.

    Returns
    -------
    xarray.Dataset
        One dimension per grid dimension, plus ``parameter`` and ``rule``; the variables of the module's
        docstring with ``units`` and ``long_name``; provenance in ``attrs``.

    Raises
    ------
    ValueError, TypeError
        Bad arguments, or a cell that does not load or fails (named), before anything is returned.
    """
    if isinstance(grid, dict):
        grid = parse_grid(grid, "(a grid given as a table)")
    if not isinstance(grid, Grid):
        raise TypeError(f"grid: expected a plansim Grid (plansim.planning.grid.load_grid) or a grid table, "
                        f"got {type(grid).__name__}")
    if executor not in EXECUTORS:
        raise ValueError(f"executor = {executor!r}: allowed {', '.join(EXECUTORS)}")
    if workers is not None:
        workers = check_count("workers", workers, 1)
    if scheduler is not None and executor != "dask":
        raise ValueError(f"scheduler = {scheduler!r}: only with executor = 'dask' (got {executor!r})")
    if path not in ("auto", "sample", "segment"):
        raise ValueError(f"path = {path!r}: allowed auto, sample, segment")
    base = load_scenario(scenario, overrides)
    cells = cell_scenarios(scenario, grid, overrides)
    trials = base.trials if trials is None else check_count("trials", trials, 0)
    seed = base.seed if seed is None else check_count("seed", seed, 0)
    tasks = [(sc, index, cell_seed(seed, cell), trials, path, coverage_probability) for index, cell, sc in cells]
    results = _execute(tasks, executor, workers, scheduler, progress, {index: cell for index, cell, _ in cells})
    return _dataset(grid, results, base, overrides, trials, seed, path, coverage_probability)


#: what a failing cell raises, named by the cell (anything else, an interruption say, passes as it is)
CELL_ERRORS = (ValueError, TypeError, ArithmeticError, np.linalg.LinAlgError)


def _execute(tasks, executor: str, workers, scheduler, progress, cell_of: dict) -> list[CellResult]:
    """Every task's :class:`CellResult`, in the tasks' order; *cell_of* maps a cell's index to its overrides."""
    total = len(tasks)
    done = 0
    results: list[CellResult] = []

    def tick():
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total)

    def named(index: tuple, error: BaseException) -> ValueError:
        return ValueError(f"sweep cell {'; '.join(cell_of[index])} failed: {type(error).__name__}: {error}")

    @contextlib.contextmanager
    def cell(index: tuple):
        try:
            yield
        except CELL_ERRORS as error:
            raise named(index, error) from error
        tick()

    if executor == "dask" and total > 1:
        from plansim.planning.dask_executor import run_on_dask

        return run_on_dask(tasks, evaluate_cell, workers, scheduler, tick, named)
    # serial, and the first cell of threads alone: it compiles the kernels before the rest run side by side
    for task in tasks if executor == "serial" else tasks[:1]:
        with cell(task[1]):
            results.append(evaluate_cell(*task))
    if len(results) == total:
        return results
    with ThreadPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
        futures = [pool.submit(evaluate_cell, *task) for task in tasks[1:]]
        try:
            for task, future in zip(tasks[1:], futures):
                with cell(task[1]):
                    results.append(future.result())
        except BaseException:
            for future in futures:
                future.cancel()
            raise
    return results


#: how many combined standard errors a Monte Carlo u must be above another's to count as worse on the Pareto front
PARETO_Z = 2.0


def pareto_front(cost, value, standard_error=None, z: float = PARETO_Z) -> np.ndarray:
    """Which points are on the Pareto front of (cost, value), both smaller-is-better: no other point is at least as
    good in both and better in one. NaN points are never on it; equal points both are.

    With the *standard_error* of each value (a Monte Carlo's scatter), "better in value" means better by more than
    ``z·√(se_a² + se_b²)`` and "at least as good" means not worse by that much: a point is only pushed off the
    front by one that is as cheap and significantly better, or cheaper and not significantly worse. Without it the
    values are taken as exact (a prediction).

    >>> pareto_front([1, 2, 3, 3], [3, 1, 2, 1]).tolist()
    [True, True, False, False]
    >>> pareto_front([1, 2], [1.00, 0.99], standard_error=[0.01, 0.01]).tolist()  # 0.01 is not significant
    [True, False]
    """
    cost = np.asarray(cost, dtype=float)
    value = np.asarray(value, dtype=float)
    if cost.shape != value.shape:
        raise ValueError(f"cost {cost.shape} and value {value.shape}: the shapes must match")
    se = np.zeros_like(value) if standard_error is None else np.asarray(standard_error, dtype=float)
    if se.shape != value.shape or np.any(se < 0):
        raise ValueError(f"standard_error: expected values >= 0 of shape {value.shape}, got {se.shape}")
    c, v, e = cost.ravel(), value.ravel(), se.ravel()
    ok = np.isfinite(c) & np.isfinite(v)
    margin = z * np.sqrt(e[None, :] ** 2 + e[:, None] ** 2)  # [i, j]: point j against point i
    better = v[None, :] < v[:, None] - margin
    as_good = v[None, :] <= v[:, None] + margin
    dominated = ((c[None, :] <= c[:, None]) & as_good & ((c[None, :] < c[:, None]) | better) & ok[None, :])
    return (ok & ~dominated.any(axis=1)).reshape(cost.shape)


def _dataset(grid: Grid, results: list[CellResult], base: Scenario, overrides, trials: int, seed: int, path: str,
             coverage_probability: float) -> xr.Dataset:
    shape = grid.shape
    dims = [d.name for d in grid.dimensions]
    names = [p.name for p in PARAMETERS]
    rules = list(RULES)
    arrays = {key: np.full((*shape, len(names)), np.nan) for key in PER_PARAMETER}
    table_time = np.full(shape, np.nan)
    max_rate = np.full(shape, np.nan)
    seeds = np.zeros(shape, dtype=np.int64)
    verdicts = np.zeros((*shape, len(rules)), dtype=bool)
    for r in results:
        for key in PER_PARAMETER:
            arrays[key][r.index] = r.per_parameter[key]
        table_time[r.index] = r.table_time_s
        max_rate[r.index] = r.max_rate
        seeds[r.index] = r.seed
        verdicts[r.index] = [r.rules[name] for name in rules]
    per = "SI: the unit coordinate of each parameter"
    p_text = f"p = {coverage_probability:g}"
    long_names = {
        "u_predicted": "predicted standard uncertainty u_c (GUM of the schedule)",
        "bias_predicted": "predicted bias (systematic effects the estimators do not correct)",
        "U_predicted": f"predicted expanded uncertainty, {p_text}",
        "u_mc": "Monte Carlo standard deviation of the error (estimate - truth)",
        "bias_mc": "Monte Carlo mean error (estimate - truth)",
        "coverage": f"fraction of Monte Carlo trials with |error| <= U_predicted ({p_text})",
    }
    grid_dims = tuple(dims)
    data = {key: ((*grid_dims, "parameter"), arrays[key],
                  {"units": "1" if key == "coverage" else per, "long_name": long_names[key]})
            for key in PER_PARAMETER if trials > 0 or not key.endswith(("_mc", "coverage"))}
    data["table_time_s"] = (grid_dims, table_time, {"units": "s", "long_name": "table time: dwell and settling "
                                                    "(moves included) of every segment"})
    data["compliant_jjf2003"] = (grid_dims, verdicts.all(axis=-1), {
        "units": "1", "long_name": "the schedule follows every rule of JJF 2003 §7.2 in the rule coordinate"})
    data["jjf2003_rule"] = ((*grid_dims, "rule"), verdicts, {"units": "1", "long_name": "each rule's verdict"})
    data["max_rate"] = (grid_dims, max_rate, {"units": "rad/s", "long_name": "the largest rate point"})
    data["seed"] = (grid_dims, seeds, {"units": "1", "long_name": "the cell's Monte Carlo seed (cell_seed)"})
    groups = list(GROUPS)
    member = np.array([[p.group == g for p in PARAMETERS] for g in groups])  # (group, parameter)
    u = arrays["u_mc"] if trials > 1 else arrays["u_predicted"]
    u_group = np.stack([np.max(u[..., m], axis=-1) for m in member], axis=-1)
    # a Monte Carlo standard deviation of n trials scatters by u/√(2(n − 1)) (normal errors)
    se_group = u_group / np.sqrt(2.0 * (trials - 1)) if trials > 1 else np.zeros_like(u_group)
    front = np.stack([pareto_front(table_time, u_group[..., k], se_group[..., k]) for k in range(len(groups))],
                     axis=-1)
    which = "u_mc" if trials > 1 else "u_predicted"
    data["u_group"] = ((*grid_dims, "group"), u_group, {
        "units": "SI: the group_unit coordinate", "long_name": f"the largest {which} of the group's parameters"})
    data["pareto"] = ((*grid_dims, "group"), front, {
        "units": "1", "long_name": "on the Pareto front of table_time_s against u_group: no other cell is as "
                                   "short and as good, and better in one (with a Monte Carlo: by more than "
                                   f"{PARETO_Z:g} combined standard errors)"})
    coords: dict = {"parameter": ("parameter", names), "unit": ("parameter", [p.si_unit for p in PARAMETERS]),
                    "parameter_group": ("parameter", [p.group for p in PARAMETERS]),
                    "group": ("group", groups),
                    "group_unit": ("group", [group_spec(g).si_unit for g in groups]),
                    "rule": ("rule", rules), "rule_text": ("rule", [RULES[name] for name in rules])}
    for d in grid.dimensions:
        if d.name == ZIP_DIMENSION:
            coords[ZIP_DIMENSION] = (ZIP_DIMENSION, np.arange(len(d)))
            for f, field in enumerate(d.fields):
                coords[field] = (ZIP_DIMENSION, d.labels(f), {"long_name": f"scenario field {field}"})
        else:
            coords[d.name] = (d.name, d.labels(), {"long_name": f"scenario field {d.name}"})
    attrs = {"title": f"plansim sweep of scenario {base.name!r}", "scenario": base.name,
             "scenario_source": base.source, "base_overrides": "; ".join(overrides),
             "grid_source": grid.source, "trials_per_cell": int(trials), "seed": int(seed),
             "simulation_path_option": path, "coverage_probability": float(coverage_probability),
             "plansim_version": plansim_version(),
             "method": "per cell: plansim.predict (GUM) and, with trials, plansim.run seeded by cell_seed "
                       "(docs/planning.md)"}
    return xr.Dataset(data, coords=coords, attrs=attrs)
