"""Statistics of a Monte Carlo run streamed block by block: what ``plansim run`` prints, without the per-trial arrays.

:class:`RunStatistics` takes the trials of a run in fixed, trial-aligned blocks
(:data:`plansim.simulate.chunks.REDUCTION_BLOCK` trials, whatever the chunk size) and keeps, per
parameter, in SI:

- moments: the mean of the truth, the mean and the standard deviation (ddof = 1) of the error
  ``estimate − truth``, its minimum and maximum. Each block's mean and sum of squared deviations
  are computed on the block alone and merged in trial order (Chan, Golub & LeVeque's pairwise
  update), so the result depends on the trial indices only, never on the chunk size;
- exact quantiles: the 2.5 % and 97.5 % points of the error and the 95 % point of ``|error|``,
  as :func:`numpy.quantile` (method ``linear``) gives them on all the trials. A linear quantile
  of *n* values needs only the two order statistics around position ``(n − 1)·q``, so only the
  tail beyond it is kept: the ``n − ⌊(n − 1)·q⌋ + 1`` largest values (``⌊(n − 1)·q⌋ + 2`` smallest
  for a lower quantile), about ``(1 − q)·n``, merged block by block with :func:`numpy.partition`.
  At the end the tail is padded back to *n* values with its own extreme (which leaves every
  order statistic of the tail where it was) and handed to :func:`numpy.quantile`, so the figure is
  numpy's own, not an approximation;
- the Appendix A comparison (:func:`plansim.uncertainty.compare_with_appendix_a`): per budget and
  parameter, the errors in the budget's primary reading unit (``errors_in_reading_units``), their
  moments, the 95 % point of their magnitude (kept as above, per parameter and pooled over the
  budget's parameters), and the count of ``|error| ≤ U`` (the printed U); and for every other
  reading of the budget's unit (``AppendixABudget.readings``) the errors converted in that reading
  block by block, exactly as the per-trial comparison converts them, with their pooled 95 % point
  (a kept tail) and their count of ``|error| ≤ U``. So the same numbers come out, in every reading.

Memory: the kept tails hold ``(2.5 % + 2.5 % + 5 %) × n × 39`` values for the parameters plus
``2 × 5 % × n`` per parameter of the Appendix A budgets (27 of them) and ``5 % × n`` per parameter
for each further reading (A.1: 1, A.2: 1, A.3: 2, A.5: 2), 8 bytes each, and at most as much again
waiting to be merged: :func:`summary_memory_bytes` bounds it by 211 MB at n = 10⁶, 29 MB of which
for the further readings.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
import xarray as xr

from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS
from plansim.uncertainty import (
    APPENDIX_A,
    AppendixABudget,
    ItemComparison,
    ParameterComparison,
    errors_in_reading_units,
    reading_unit_description,
    reading_unit_in_si,
)
from plansim.uncertainty.appendix_a import Reading
from plansim.uncertainty.appendix_a_comparison import item_comparison, reading_comparison

#: quantiles of the error kept for every parameter (the central 95 % interval)
ERROR_QUANTILES = (0.025, 0.975)
#: quantile of |error| (Appendix A's ``U95``; JCGM 100 6.3.3: k = 2 read as 95 %)
ABS_ERROR_QUANTILE = 0.95
#: rows that wait before a tail is merged, at least (a merge costs the tail's size)
_MIN_PENDING = 4096


def parameter_coordinates() -> dict:
    """The ``parameter`` coordinate and its companions (group, SI unit, display unit and factor, long name)."""
    return {
        "parameter": ("parameter", list(PARAMETER_NAMES), {"long_name": "JJF 2003 parameter symbol"}),
        "group": ("parameter", [p.group for p in PARAMETERS], {"long_name": "matrix of eq. (1)/(2)"}),
        "units": ("parameter", [p.si_unit for p in PARAMETERS], {"long_name": "SI unit of the parameter"}),
        "display_unit": ("parameter", [p.display_unit for p in PARAMETERS]),
        "display_factor": ("parameter", [p.display_factor for p in PARAMETERS],
                           {"long_name": "SI value / display_factor = value in display_unit"}),
        "long_name": ("parameter", [p.long_name for p in PARAMETERS]),
    }


def tail_size(n: int, q: float, upper: bool) -> int:
    """How many of the largest (*upper*) or smallest values of *n* fix numpy's linear *q*-quantile (one spare)."""
    below = math.floor((n - 1) * q)
    return min(n, n - below + 1) if upper else min(n, below + 2)


class _Largest:
    """The *k* largest values of each of *columns* streams, exactly (ties kept: only values matter)."""

    def __init__(self, k: int, columns: int):
        self.k = int(k)
        self._kept = np.empty((columns, 0))
        self._pending: list[np.ndarray] = []
        self._rows = 0

    def add(self, values: np.ndarray) -> None:
        """*values*: (rows, columns)."""
        self._pending.append(np.ascontiguousarray(values.T, dtype=float))
        self._rows += values.shape[0]
        if self._rows >= max(self.k, _MIN_PENDING):
            self._merge()

    def _merge(self) -> None:
        if not self._pending:
            return
        data = np.concatenate([self._kept, *self._pending], axis=1)
        self._pending, self._rows = [], 0
        if data.shape[1] > self.k:
            data = np.partition(data, data.shape[1] - self.k, axis=1)[:, data.shape[1] - self.k:]
        self._kept = np.ascontiguousarray(data)

    def values(self) -> np.ndarray:
        """(columns, ≤ k): the largest values seen, unordered."""
        self._merge()
        return self._kept


def _quantile_from_upper_tail(tail: np.ndarray, n: int, q: float) -> float:
    full = np.empty(n)
    full[:n - tail.size] = tail.min()
    full[n - tail.size:] = tail
    return float(np.quantile(full, q, overwrite_input=True))


def _quantile_from_lower_tail(tail: np.ndarray, n: int, q: float) -> float:
    full = np.empty(n)
    full[:tail.size] = tail
    full[tail.size:] = tail.max()
    return float(np.quantile(full, q, overwrite_input=True))


class _Moments:
    """Count, mean and sum of squared deviations of each column, merged block by block in order."""

    def __init__(self, columns: int):
        self.n = 0
        self.mean = np.zeros(columns)
        self.m2 = np.zeros(columns)

    def add(self, values: np.ndarray) -> None:
        """*values*: (rows, columns)."""
        x = np.ascontiguousarray(values.T, dtype=float)  # rows contiguous: numpy sums them pairwise
        count = x.shape[1]
        mean = x.mean(axis=1)
        deviation = x - mean[:, None]
        m2 = np.sum(deviation * deviation, axis=1)
        if self.n == 0:
            self.n, self.mean, self.m2 = count, mean, m2
            return
        total = self.n + count
        delta = mean - self.mean
        self.mean = self.mean + delta * (count / total)
        self.m2 = self.m2 + m2 + delta * delta * (self.n * count / total)
        self.n = total

    def std(self) -> np.ndarray:
        """Standard deviation, ddof = 1 (NaN with fewer than 2 values)."""
        if self.n < 2:
            return np.full_like(self.mean, np.nan)
        return np.sqrt(self.m2 / (self.n - 1))


class _ReadingStatistics:
    """A further reading of one Appendix A budget: the pooled |error| tail and the count of |error| ≤ U."""

    def __init__(self, budget: AppendixABudget, reading: Reading, scenario, trials: int):
        self.reading = reading
        count = len(budget.parameters)
        self.largest = _Largest(tail_size(trials * count, ABS_ERROR_QUANTILE, True), 1)
        self.covered = 0
        # a constant unit is the scenario's; the relative one (|truth|) is averaged over the trials
        self.units = None if reading.constant else _Moments(count)
        self.constant_units = (np.array([float(reading_unit_in_si(budget, name, scenario, reading=reading))
                                         for name in budget.parameters]) if reading.constant else None)

    def add(self, magnitude: np.ndarray, units: np.ndarray | None, expanded: float) -> None:
        self.largest.add(magnitude.reshape(-1, 1))
        self.covered += int(np.count_nonzero(magnitude <= expanded))
        if self.units is not None:
            self.units.add(units)

    def unit_in_si(self) -> np.ndarray:
        return self.constant_units if self.units is None else self.units.mean


class _BudgetStatistics:
    """One Appendix A budget: its parameters' errors in the budget's reading units, streamed."""

    def __init__(self, budget: AppendixABudget, scenario, trials: int):
        self.budget = budget
        self.scenario = scenario
        self.names = tuple(budget.parameters)
        self.columns = [PARAMETER_INDEX[name] for name in self.names]
        count = len(self.names)
        self.expanded = budget.printed_expanded_uncertainty
        self.moments = _Moments(count)
        self.pooled = _Moments(1)
        # one unit's SI size: the scenario's for a constant reading, averaged over the trials for the relative one
        primary = budget.readings[0]
        self.units = None if primary.constant else _Moments(count)
        self.constant_units = (np.array([float(reading_unit_in_si(budget, name, scenario)) for name in self.names])
                               if primary.constant else None)
        self.largest = _Largest(tail_size(trials, ABS_ERROR_QUANTILE, True), count)
        self.pooled_largest = _Largest(tail_size(trials * count, ABS_ERROR_QUANTILE, True), 1)
        self.covered = np.zeros(count, dtype=np.int64)
        self.readings = [_ReadingStatistics(budget, reading, scenario, trials) for reading in budget.readings[1:]]

    def add(self, start: int, truth: np.ndarray, estimate: np.ndarray, error: np.ndarray) -> None:
        rows = truth.shape[0]
        reading = np.empty((rows, len(self.names)))
        units = None if self.units is None else np.empty((rows, len(self.names)))
        for j, (name, k) in enumerate(zip(self.names, self.columns)):
            finite = np.isfinite(truth[:, k]) & np.isfinite(estimate[:, k])
            if not np.all(finite):
                bad = int(np.argmax(~finite))
                raise ValueError(f"parameter {name}: trial {start + bad} has truth {truth[bad, k]!r} and estimate "
                                 f"{estimate[bad, k]!r}; every value must be finite")
            reading[:, j] = errors_in_reading_units(self.budget, name, error[:, k], self.scenario, truth[:, k])
            if units is not None:
                units[:, j] = reading_unit_in_si(self.budget, name, self.scenario, truth[:, k])
        magnitude = np.abs(reading)
        self.moments.add(reading)
        self.pooled.add(reading.reshape(-1, 1))
        if self.units is not None:
            self.units.add(units)
        self.largest.add(magnitude)
        self.pooled_largest.add(magnitude.reshape(-1, 1))
        self.covered += np.count_nonzero(magnitude <= self.expanded, axis=0)
        for statistics in self.readings:
            other = np.empty((rows, len(self.names)))
            other_units = None if statistics.units is None else np.empty((rows, len(self.names)))
            for j, (name, k) in enumerate(zip(self.names, self.columns)):
                other[:, j] = errors_in_reading_units(self.budget, name, error[:, k], self.scenario, truth[:, k],
                                                      statistics.reading)
                if other_units is not None:
                    other_units[:, j] = reading_unit_in_si(self.budget, name, self.scenario, truth[:, k],
                                                           statistics.reading)
            statistics.add(np.abs(other), other_units, self.expanded)

    def reading_results(self, trials: int, primary: dict) -> list[dict]:
        """Per reading (the primary one first, from *primary* = :meth:`results`): its name, the pooled 95 %
        point of |error|, the count of |error| ≤ U and the SI size of one unit per parameter."""
        out = [{"reading": self.budget.readings[0].name, "U95": primary["U95"], "covered": primary["covered"],
                "unit_in_si": primary["reading_unit_in_si"]}]
        n = trials * len(self.names)
        for statistics in self.readings:
            out.append({"reading": statistics.reading.name,
                        "U95": _quantile_from_upper_tail(statistics.largest.values()[0], n, ABS_ERROR_QUANTILE),
                        "covered": statistics.covered, "unit_in_si": statistics.unit_in_si()})
        return out

    def results(self, trials: int) -> dict:
        largest = self.largest.values()
        return {
            "n": trials * len(self.names),
            "mean": float(self.pooled.mean[0]),
            "std": float(self.pooled.std()[0]),
            "U95": _quantile_from_upper_tail(self.pooled_largest.values()[0], trials * len(self.names),
                                             ABS_ERROR_QUANTILE),
            "covered": int(self.covered.sum()),
            "parameter_mean": self.moments.mean,
            "parameter_std": self.moments.std(),
            "parameter_U95": np.array([_quantile_from_upper_tail(largest[j], trials, ABS_ERROR_QUANTILE)
                                       for j in range(len(self.names))]),
            "parameter_covered": self.covered.copy(),
            "reading_unit_in_si": self.constant_units if self.units is None else self.units.mean,
        }


def check_budgets(budgets: Iterable[AppendixABudget]) -> tuple[AppendixABudget, ...]:
    """*budgets* as a tuple; TypeError naming an element that is not an :class:`AppendixABudget`."""
    budgets = tuple(budgets)
    for budget in budgets:
        if not isinstance(budget, AppendixABudget):
            raise TypeError(f"budgets: element {budget!r} is not an AppendixABudget "
                            "(e.g. an element of plansim.uncertainty.APPENDIX_A)")
    return budgets


def summary_memory_bytes(trials: int, budgets: Iterable[AppendixABudget] = APPENDIX_A) -> int:
    """Upper bound of what :class:`RunStatistics` holds for *trials* trials, bytes.

    A kept tail of *k* values per column holds at most ``2k + 4096`` rows (the tail and the rows
    waiting to be merged); a merge copies them once more for a moment, one tail at a time; at the
    end, one quantile at a time pads a tail back to all its values (``trials × parameters of the
    widest budget``).
    """
    def rows(k):
        return 2 * k + _MIN_PENDING

    tails = [(rows(tail_size(trials, q, q > 0.5)), N_PARAMETERS) for q in ERROR_QUANTILES]
    tails.append((rows(tail_size(trials, ABS_ERROR_QUANTILE, True)), N_PARAMETERS))
    widest = 1
    for budget in check_budgets(budgets):
        count = len(budget.parameters)
        widest = max(widest, count)
        tails.append((rows(tail_size(trials, ABS_ERROR_QUANTILE, True)), count))
        tails.extend([(rows(tail_size(trials * count, ABS_ERROR_QUANTILE, True)), 1)] * len(budget.readings))
    held = sum(r * c for r, c in tails)
    transient = max(max(r * c for r, c in tails), trials * widest)
    return 8 * (held + transient)


class RunStatistics:
    """Per-parameter statistics and the Appendix A comparison of a run, fed block by block.

    Parameters
    ----------
    scenario : plansim.config.Scenario
        For the Appendix A readings (full scales, reference gravity, ω² test rate).
    trials : int
        The number of trials that will be added (the kept tails are sized from it).
    budgets : iterable of AppendixABudget
        The Appendix A budgets to compare with (none with fewer than 2 trials: a standard
        deviation needs 2, as in :func:`plansim.uncertainty.compare_with_appendix_a`).
    """

    def __init__(self, scenario, trials: int, budgets: Iterable[AppendixABudget] = APPENDIX_A):
        self.trials = int(trials)
        self.added = 0
        self.truth = _Moments(N_PARAMETERS)
        self.error = _Moments(N_PARAMETERS)
        self.minimum = np.full(N_PARAMETERS, np.inf)
        self.maximum = np.full(N_PARAMETERS, -np.inf)
        self.upper = _Largest(tail_size(self.trials, ERROR_QUANTILES[1], True), N_PARAMETERS)
        self.lower = _Largest(tail_size(self.trials, ERROR_QUANTILES[0], False), N_PARAMETERS)  # of −error
        self.magnitude = _Largest(tail_size(self.trials, ABS_ERROR_QUANTILE, True), N_PARAMETERS)
        budgets = check_budgets(budgets) if self.trials >= 2 else ()
        self.budgets = [_BudgetStatistics(budget, scenario, self.trials) for budget in budgets]

    def add(self, start: int, truth: np.ndarray, estimate: np.ndarray) -> np.ndarray:
        """Add trials ``start … start + len(truth) − 1`` (in order); returns their error ``estimate − truth``."""
        if start != self.added:
            raise ValueError(f"start = {start}: trials must be added in order; expected {self.added}")
        if start + truth.shape[0] > self.trials:
            raise ValueError(f"trials {start}…{start + truth.shape[0] - 1}: more than the {self.trials} announced")
        error = estimate - truth
        self.truth.add(truth)
        self.error.add(error)
        np.minimum(self.minimum, error.min(axis=0), out=self.minimum)
        np.maximum(self.maximum, error.max(axis=0), out=self.maximum)
        self.upper.add(error)
        self.lower.add(-error)
        self.magnitude.add(np.abs(error))
        for budget in self.budgets:
            budget.add(start, truth, estimate, error)
        self.added += truth.shape[0]
        return error

    def dataset(self, attrs: dict) -> xr.Dataset:
        """The statistics as a small Dataset over ``parameter`` (and ``quantile``, ``item``), with *attrs*."""
        if self.added != self.trials:
            raise ValueError(f"{self.added} of the {self.trials} announced trials were added")
        n = self.trials
        upper, lower, magnitude = self.upper.values(), self.lower.values(), self.magnitude.values()
        quantiles = np.array([[_quantile_from_lower_tail(-lower[k], n, ERROR_QUANTILES[0]),
                               _quantile_from_upper_tail(upper[k], n, ERROR_QUANTILES[1])]
                              for k in range(N_PARAMETERS)])
        si = "SI (per parameter: see the 'units' coordinate)"
        coords = parameter_coordinates()
        coords["quantile"] = ("quantile", list(ERROR_QUANTILES), {"long_name": "probability of the quantile"})
        data = {
            "truth_mean": ("parameter", self.truth.mean, {"units": si, "long_name": "mean true parameter"}),
            "error_mean": ("parameter", self.error.mean,
                           {"units": si, "long_name": "mean error (estimate − truth): the estimator's bias"}),
            "error_std": ("parameter", self.error.std(),
                          {"units": si, "long_name": "standard deviation of the error (ddof = 1)"}),
            "error_min": ("parameter", self.minimum.copy(), {"units": si, "long_name": "smallest error"}),
            "error_max": ("parameter", self.maximum.copy(), {"units": si, "long_name": "largest error"}),
            "error_quantile": (("parameter", "quantile"), quantiles,
                               {"units": si, "long_name": "quantile of the error (numpy 'linear', exact)"}),
            "abs_error_q95": ("parameter",
                              np.array([_quantile_from_upper_tail(magnitude[k], n, ABS_ERROR_QUANTILE)
                                        for k in range(N_PARAMETERS)]),
                              {"units": si, "long_name": "95th percentile of |error| (numpy 'linear', exact)"}),
        }
        if self.budgets:
            self._add_appendix_a(coords, data)
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def _add_appendix_a(self, coords: dict, data: dict) -> None:
        items = [b.budget.item for b in self.budgets]
        shape = (len(items), N_PARAMETERS)
        per = {key: np.full(shape, np.nan) for key in ("mean", "std", "U95", "reading_unit_in_si")}
        covered = np.full(shape, -1, dtype=np.int64)
        pooled = {key: [] for key in ("n", "mean", "std", "U95", "covered")}
        readings = []
        for i, statistics in enumerate(self.budgets):
            r = statistics.results(self.trials)
            readings += [(statistics.budget.item, statistics.columns, entry)
                         for entry in statistics.reading_results(self.trials, r)]
            for key in pooled:
                pooled[key].append(r[key])
            for j, k in enumerate(statistics.columns):
                for key in per:
                    per[key][i, k] = r["reading_unit_in_si" if key == "reading_unit_in_si" else f"parameter_{key}"][j]
                covered[i, k] = r["parameter_covered"][j]
        reading = "reading unit of the item (see appendix_a_reading_unit)"
        coords["item"] = ("item", items, {"long_name": "JJF 2003 Appendix A budget"})
        coords["appendix_a_reading_unit"] = ("item", [reading_unit_description(b.budget, b.scenario)
                                                       for b in self.budgets])
        coords["appendix_a_U"] = ("item", [b.expanded for b in self.budgets],
                                  {"long_name": "expanded uncertainty U as printed", "units": reading})
        data.update({
            "appendix_a_n": ("item", np.array(pooled["n"], dtype=np.int64),
                             {"long_name": "pooled errors (trials × parameters of the budget)"}),
            "appendix_a_mean": ("item", np.array(pooled["mean"]), {"units": reading, "long_name": "mean error"}),
            "appendix_a_std": ("item", np.array(pooled["std"]),
                               {"units": reading, "long_name": "standard deviation of the errors (ddof = 1)"}),
            "appendix_a_U95": ("item", np.array(pooled["U95"]),
                               {"units": reading, "long_name": "95th percentile of |error| (exact)"}),
            "appendix_a_covered": ("item", np.array(pooled["covered"], dtype=np.int64),
                                   {"long_name": "errors with |error| <= U"}),
            "appendix_a_parameter_mean": (("item", "parameter"), per["mean"],
                                          {"units": reading, "long_name": "mean error (NaN: not in the budget)"}),
            "appendix_a_parameter_std": (("item", "parameter"), per["std"],
                                         {"units": reading, "long_name": "standard deviation of the errors"}),
            "appendix_a_parameter_U95": (("item", "parameter"), per["U95"],
                                         {"units": reading, "long_name": "95th percentile of |error|"}),
            "appendix_a_parameter_covered": (("item", "parameter"), covered,
                                             {"long_name": "trials with |error| <= U (-1: not in the budget)"}),
            "appendix_a_reading_unit_in_si": (("item", "parameter"), per["reading_unit_in_si"],
                                              {"long_name": "mean SI size of one reading unit"}),
        })
        # every reading of every item (the primary one first): the pooled 95 % point and coverage count
        units = np.full((len(readings), N_PARAMETERS), np.nan)
        for r, (_, columns, entry) in enumerate(readings):
            units[r, columns] = entry["unit_in_si"]
        of_the_reading = "units of the reading (see appendix_a_readings_unit)"
        coords["appendix_a_readings_item"] = ("appendix_a_readings", [item for item, _, _ in readings],
                                              {"long_name": "the Appendix A item read"})
        coords["appendix_a_readings_name"] = ("appendix_a_readings", [e["reading"] for _, _, e in readings],
                                              {"long_name": "name of the reading of the item's unit "
                                                            "(the item's first: its primary reading)"})
        budgets = {b.budget.item: b for b in self.budgets}
        coords["appendix_a_readings_unit"] = ("appendix_a_readings", [
            reading_unit_description(budgets[item].budget, budgets[item].scenario, e["reading"])
            for item, _, e in readings])
        data.update({
            "appendix_a_readings_U95": ("appendix_a_readings", np.array([e["U95"] for _, _, e in readings]),
                                        {"units": of_the_reading,
                                         "long_name": "95th percentile of the pooled |error| (exact)"}),
            "appendix_a_readings_covered": ("appendix_a_readings",
                                            np.array([e["covered"] for _, _, e in readings], dtype=np.int64),
                                            {"long_name": "pooled errors with |error| <= U in the reading"}),
            "appendix_a_readings_unit_in_si": (("appendix_a_readings", "parameter"), units,
                                               {"long_name": "mean SI size of one unit of the reading "
                                                             "(NaN: not in the item)"}),
        })


def appendix_a_comparisons(summary: xr.Dataset, scenario, budgets: Iterable[AppendixABudget] = APPENDIX_A
                           ) -> list[ItemComparison]:
    """The Appendix A comparison of a summary run, the same numbers as
    :func:`plansim.uncertainty.compare_with_appendix_a` gives on the run's per-trial arrays, in
    every reading of each budget's unit.

    Parameters
    ----------
    summary : xarray.Dataset
        From :func:`plansim.runner.run_summary`.
    scenario : plansim.config.Scenario
        The run's scenario (for the budgets' reading units).
    budgets : iterable of AppendixABudget
        Where the summary's items are looked up (default :data:`plansim.uncertainty.APPENDIX_A`).

    Returns
    -------
    list of ItemComparison
        One per item of the summary, in its order; empty if the run had fewer than 2 trials.
    """
    if "item" not in summary.dims:
        return []
    by_item = {b.item: b for b in budgets}
    trials = int(summary.attrs["trials"])
    reading_items = [str(v) for v in summary["appendix_a_readings_item"].values]
    reading_names = [str(v) for v in summary["appendix_a_readings_name"].values]
    comparisons = []
    for i, item in enumerate(summary["item"].values):
        budget = by_item[str(item)]
        expanded = budget.printed_expanded_uncertainty
        columns = [PARAMETER_INDEX[name] for name in budget.parameters]
        per_parameter = []
        for name, k in zip(budget.parameters, columns):
            unit = float(summary["appendix_a_reading_unit_in_si"].values[i, k])
            per_parameter.append(ParameterComparison(
                name=name, mean=float(summary["appendix_a_parameter_mean"].values[i, k]),
                std=float(summary["appendix_a_parameter_std"].values[i, k]),
                U95=float(summary["appendix_a_parameter_U95"].values[i, k]),
                coverage=int(summary["appendix_a_parameter_covered"].values[i, k]) / trials,
                reading_unit_in_si=unit, budget_U_si=expanded * unit))
        n = int(summary["appendix_a_n"].values[i])
        readings = tuple(
            reading_comparison(budget, budget.reading_named(reading_names[r]), scenario, n,
                               int(summary["appendix_a_readings_covered"].values[r]) / n,
                               float(summary["appendix_a_readings_U95"].values[r]),
                               summary["appendix_a_readings_unit_in_si"].values[r, columns])
            for r in range(len(reading_items)) if reading_items[r] == str(item))
        comparisons.append(item_comparison(
            budget, scenario, n, float(summary["appendix_a_mean"].values[i]),
            float(summary["appendix_a_std"].values[i]), float(summary["appendix_a_U95"].values[i]),
            int(summary["appendix_a_covered"].values[i]) / n, tuple(per_parameter), readings))
    return comparisons
