"""Sweeps of the JJF 1535-2015 procedure: its settings, and the unit's fields, over a grid (``plansim sweep jjf1535``).

The question a lab asks of a JJF 1535 calibration is how long a session must be for the items it reports to be
good enough: how many rate points for a given nonlinearity uncertainty, how many repeats Q for the scale
factor's repeatability, how long an averaging period P for the bias stability. Each cell of the grid
(:mod:`plansim.planning.grid`) is the procedure with the cell's settings (keys ``procedure.KEY``, the fields of
:class:`plansim.schedule.jjf1535.Jjf1535Settings`) on the unit scenario with the cell's other fields (dotted
scenario keys, as ``--set``), and runs the JJF 1535 Monte Carlo (:func:`plansim.runner.jjf1535_run`, seeded by
:func:`plansim.planning.grid.cell_seed` from the cell's overrides). Per cell and item it keeps, SI:

- for an item with a true value: the error's mean, standard deviation and 95 % quantile of |error|
  (``mc_U95``, what a lab could state as its expanded uncertainty for that item);
- for every item whose reported figure is not its true value (no truth: the bias stability; or a figure
  a lab quotes: threshold, resolution, the repeatabilities): the reported figure's mean, standard deviation
  and 2.5 %/97.5 % quantiles;
- the fraction of trials where the procedure could not determine the item;

and per cell the session's length (``session_hours``) and segments. With targets (item → largest
acceptable value) :func:`cheapest_cell` names the shortest session that meets them all: ``mc_U95`` where the
item has a true value, else the reported figure's standard deviation. The JJF 2003 sweep's prediction (the
GUM of a JJF 2003 schedule) has no counterpart here: JJF 1535's nonlinearity, asymmetry and stability are
maxima and standard deviations of means, which the Monte Carlo describes and a first-order GUM does not
(docs/jjf1535.md).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable

import numpy as np
import xarray as xr

from plansim.estimate.jjf1535_items import ITEMS
from plansim.io.recording import plansim_version
from plansim.io.scenario_file import load_scenario
from plansim.planning.grid import Grid, cell_seed, parse_grid
from plansim.report.jjf1535 import SI_UNITS, cell_fields, compared_value, sweep_cells
from plansim.simulate.chunks import check_count
from plansim.simulate.overrides import jjf1535_settings

#: a grid key with this prefix sets the procedure (:class:`~plansim.schedule.jjf1535.Jjf1535Settings`)
PROCEDURE_PREFIX = "procedure."
#: per cell and item, SI
PER_ITEM = ("mean_error", "std_error", "mc_U95", "figure_mean", "figure_std", "figure_q025", "figure_q975",
            "undetermined")


def split_overrides(cell) -> tuple[list[str], list[str]]:
    """A cell's ``KEY=VALUE`` items split into the procedure's (prefix removed) and the unit scenario's."""
    procedure, unit = [], []
    for item in cell:
        key, _, value = item.partition("=")
        if key.strip().startswith(PROCEDURE_PREFIX):
            procedure.append(f"{key.strip()[len(PROCEDURE_PREFIX):]}={value}")
        else:
            unit.append(item)
    return procedure, unit


def jjf1535_cells(unit: str | os.PathLike, grid: Grid, unit_overrides=(), procedure_overrides=()):
    """Every cell's ``(index, overrides, unit scenario, settings)``, each loaded and checked (the procedure built and
    run past the unit's limits) before any work starts; a failing cell is named."""
    from plansim.uncertainty.jjf1535_monte_carlo import jjf1535_scenario

    out = []
    for index, cell in grid.cells():
        procedure_items, unit_items = split_overrides(cell)
        try:
            scenario = load_scenario(unit, [*unit_overrides, *unit_items])
            settings = jjf1535_settings([*procedure_overrides, *procedure_items])
            jjf1535_scenario(scenario, settings.procedure())
        except (ValueError, TypeError) as error:
            raise type(error)(f"sweep cell {'; '.join(cell)}: {error}") from None
        out.append((index, cell, scenario, settings))
    return out


def sweep_jjf1535(unit: str | os.PathLike = "jjf2003", grid: Grid | dict | None = None, *, unit_overrides=(),
                  procedure_overrides=(), trials: int = 1000, seed: int | None = None, path: str = "auto",
                  progress: Callable[[int, int], None] | None = None) -> xr.Dataset:
    """The JJF 1535 Monte Carlo in every cell of *grid* (module docstring).

    Parameters
    ----------
    unit : str or path
        The unit scenario (a built-in name or a TOML file): its unit, noise, effects and laboratory.
    grid : Grid or dict
        Keys ``procedure.KEY`` (a setting of the procedure) or dotted scenario fields (the unit's).
    unit_overrides, procedure_overrides : sequence of str
        ``KEY=VALUE`` set on the unit (``--set``) and on the procedure (``--procedure``) before each cell's own.
    trials : int
        Monte Carlo trials per cell (>= 2).
    seed : int, optional
        The base seed (default: the unit scenario's); each cell's is :func:`~plansim.planning.grid.cell_seed`.
    path : {"auto", "sample", "segment"}
        The simulation path.
    progress : callable, optional
        ``progress(cells_done, cells)``.

    Returns
    -------
    xarray.Dataset
        Dimensions: the grid's and ``item``; variables :data:`PER_ITEM` (SI, the item's unit in the ``item_unit``
        coordinate), ``session_hours``, ``segments``, ``seed``; provenance in ``attrs``.
    """
    from plansim.runner import jjf1535_run

    if isinstance(grid, dict):
        grid = parse_grid(grid, "(a grid given as a table)")
    if not isinstance(grid, Grid):
        raise TypeError(f"grid: expected a plansim Grid or a grid table, got {type(grid).__name__}")
    trials = check_count("trials", trials, 2)
    if path not in ("auto", "sample", "segment"):
        raise ValueError(f"path = {path!r}: allowed auto, sample, segment")
    base = load_scenario(unit, unit_overrides)
    seed = base.seed if seed is None else check_count("seed", seed, 0)
    cells = jjf1535_cells(unit, grid, unit_overrides, procedure_overrides)
    items = tuple(ITEMS)
    values = {name: np.full(grid.shape + (len(items),), math.nan) for name in PER_ITEM}
    hours, segments, seeds = (np.zeros(grid.shape), np.zeros(grid.shape, np.int64), np.zeros(grid.shape, np.int64))
    for done, (index, cell, scenario, settings) in enumerate(cells):
        s = cell_seed(seed, cell)
        procedure = settings.procedure()
        try:
            result = jjf1535_run(scenario, trials=trials, seed=s, procedure=procedure, path=path)
        except (ValueError, TypeError, ArithmeticError) as error:
            raise type(error)(f"sweep cell {'; '.join(cell)}: {error}") from None
        for row in result.summary():
            k, scale = items.index(row["item"]), ITEMS[row["item"]][3]
            for name in ("mean_error", "std_error", "mc_U95"):
                values[name][index + (k,)] = row.get(name, math.nan) * scale
            for name in ("mean", "std", "q025", "q975"):
                values[f"figure_{name}"][index + (k,)] = row.get(name, math.nan) * scale
            values["undetermined"][index + (k,)] = row["undetermined"]
        hours[index] = procedure.schedule.duration / 3600.0
        segments[index] = len(procedure.schedule)
        seeds[index] = s
        if progress is not None:
            progress(done + 1, len(cells))
    return _dataset(grid, items, values, hours, segments, seeds, unit, base, unit_overrides, procedure_overrides,
                    trials, seed, path)


def _dataset(grid, items, values, hours, segments, seeds, unit, base, unit_overrides, procedure_overrides, trials,
             seed, path) -> xr.Dataset:
    dims = tuple(d.name for d in grid.dimensions)
    coords = {}
    for d in grid.dimensions:
        coords[d.name] = (d.name, d.labels(0))
        for f, field in enumerate(d.fields):
            if field != d.name:
                coords[field] = (d.name, d.labels(f))
    coords["item"] = ("item", list(items))
    coords["item_unit"] = ("item", [SI_UNITS[ITEMS[i][2]] for i in items])
    coords["item_clause"] = ("item", [ITEMS[i][0] for i in items])
    long_names = {
        "mean_error": "mean of the error (reported - true value) over the trials",
        "std_error": "standard deviation of the error over the trials",
        "mc_U95": "95 % quantile of |error| over the trials",
        "figure_mean": "mean of the reported figure", "figure_std": "standard deviation of the reported figure",
        "figure_q025": "2.5 % quantile of the reported figure", "figure_q975": "97.5 % quantile of the reported figure",
        "undetermined": "fraction of trials in which the procedure could not determine the item"}
    data = {name: (dims + ("item",), values[name], {"long_name": long_names[name],
                                                    "units": "1" if name == "undetermined" else "item_unit (SI)"})
            for name in PER_ITEM}
    data["session_hours"] = (dims, hours, {"long_name": "length of the JJF 1535 session", "units": "h"})
    data["segments"] = (dims, segments, {"long_name": "segments of the session"})
    data["seed"] = (dims, seeds, {"long_name": "the cell's seed (plansim.planning.grid.cell_seed)"})
    return xr.Dataset(data, coords=coords, attrs={
        "title": "plansim sweep jjf1535", "procedure": "JJF 1535-2015", "unit_scenario": str(unit),
        "unit_description": base.description, "grid_source": grid.source, "trials_per_cell": trials, "seed": seed,
        "path": path, "unit_overrides": "; ".join(unit_overrides),
        "procedure_overrides": "; ".join(procedure_overrides),
        "fields": "; ".join(f for d in grid.dimensions for f in d.fields), "plansim_version": plansim_version()})


def cheapest_cell(ds: xr.Dataset, targets: dict) -> dict | None:
    """The shortest session among the cells meeting every target, or None.

    *targets*: item → the largest acceptable value, SI: compared with ``mc_U95`` where the item has a true value,
    else with the reported figure's standard deviation. Returns ``{"index", "overrides", "session_hours",
    "values"}`` (the compared values, SI).
    """
    items = list(ds["item"].values)
    for item in targets:
        if item not in items:
            raise ValueError(f"target {item!r}: not a JJF 1535 item; allowed: {', '.join(items)}")
    best = None
    for _, index, where in sweep_cells(ds):
        compared = {item: compared_value(ds, where, item)[0] for item in targets}
        if all(math.isfinite(compared[item]) and compared[item] <= limit for item, limit in targets.items()):
            hours = float(ds["session_hours"].isel(where))
            if best is None or hours < best["session_hours"]:
                best = {"index": index, "session_hours": hours, "values": compared, "fields": cell_fields(ds, index)}
    return best
