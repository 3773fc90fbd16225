"""The JJF 1535-2015 Monte Carlo as a certificate-style text report and as JSON (``plansim run jjf1535``).

Both read :meth:`plansim.uncertainty.jjf1535_monte_carlo.Jjf1535MonteCarlo.summary`, whose rows are in the units
JJF 1535 reports in (:data:`plansim.estimate.jjf1535_items.ITEMS`): the text report prints them as they are, the
JSON converts them to SI (as ``plansim run --json`` is SI). The items are grouped as the certificate of JJF 1535
Appendix B groups them: the scale factor items, the bias items, the threshold, resolution and warm-up time, then
the items plansim does not simulate, each with the reason (docs/jjf1535.md, "What is not built").
"""

from __future__ import annotations

import math

import numpy as np

from plansim.estimate.jjf1535_items import ITEMS
from plansim.io.recording import plansim_version
from plansim.simulate.overrides import split_item
from plansim.uncertainty.jjf1535_monte_carlo import (
    ACQUISITION_BITS,
    POSITION_ACCURACY,
    TABLE_RATE_SMOOTHNESS,
    TABLE_RATE_UNCERTAINTY,
)
from plansim.units import ARCSEC, DEG, HOUR

#: the certificate's groups (JJF 1535 Appendix B) and the items of the Monte Carlo in each, in order
GROUPS = (
    ("Scale factor items", ("scale_factor", "nonlinearity", "asymmetry", "scale_repeatability",
                            "scale_temperature_sensitivity")),
    ("Bias items", ("bias", "bias_up_down", "bias_stability", "bias_repeatability", "g_sensitivity_x",
                    "g_sensitivity_y", "g_sensitivity_z", "g_sensitivity", "bias_temperature_sensitivity")),
    ("Threshold, resolution, warm-up time", ("threshold", "resolution", "warm_up_time")),
)

#: the name each item has in the text report
LABELS = {
    "scale_factor": "scale factor K",
    "nonlinearity": "nonlinearity",
    "asymmetry": "asymmetry",
    "scale_temperature_sensitivity": "SF temperature sensitivity",
    "bias": "bias B0 (axis up)",
    "bias_up_down": "bias (up/down mean)",
    "bias_stability": "bias stability",
    "g_sensitivity_x": "g-sensitivity along x",
    "g_sensitivity_y": "g-sensitivity along y",
    "g_sensitivity_z": "g-sensitivity along z",
    "g_sensitivity": "g-sensitivity (largest)",
    "bias_temperature_sensitivity": "bias temperature sensitivity",
    "scale_repeatability": "SF repeatability",
    "threshold": "threshold",
    "resolution": "resolution",
    "warm_up_time": "warm-up time",
    "bias_repeatability": "bias repeatability",
}

#: the SI unit of each JJF 1535 unit of :data:`~plansim.estimate.jjf1535_items.ITEMS` (its scale gives the factor)
SI_UNITS = {
    "(deg/s)/(deg/s)": "1",
    "ppm": "1",
    "ppm/degC": "1/K",
    "deg/h": "rad/s",
    "(deg/h)/g": "rad/s/(m/s^2)",
    "(deg/h)/degC": "rad/s/K",
    "deg/s": "rad/s",
    "s": "s",
}

#: the certificate's items this Monte Carlo does not simulate: (item, clause, where they are, or why not)
NOT_SIMULATED = (
    ("bandwidth", "7.2.15", "a dynamic test on an angular vibration table, simulated by its own Monte Carlo: "
                            "'plansim run jjf1537' (its default grid is 7.2.15.1 b)'s; the bandwidth interpolated and "
                            "read from 7.2.15.2's fitted curve; docs/dynamic.md)"),
)

#: the angle random walk's display unit and its SI value
ARW_UNIT, ARW_SCALE = "deg/sqrt(h)", DEG / math.sqrt(HOUR)

#: the keys of every entry of the JSON's ``items``, always present (null where the item has no such figure)
ITEM_KEYS = ("item", "clause", "equations", "unit", "truth", "mean_error", "std_error", "mc_U95", "budget",
             "budget_U", "mean_relative_error", "std_relative_error", "mc_U95_relative", "coverage", "figure",
             "undetermined")


def _number(x) -> float | None:
    """A JSON number: None for NaN or a missing figure."""
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else float(x)


def items_json(rows: list[dict]) -> list[dict]:
    """The summary rows (JJF 1535 units) as the JSON's ``items``, SI.

    Parameters
    ----------
    rows : list of dict
        :meth:`~plansim.uncertainty.jjf1535_monte_carlo.Jjf1535MonteCarlo.summary`.

    Returns
    -------
    list of dict
        One per row with the keys :data:`ITEM_KEYS`. ``unit`` is the SI unit; ``truth`` (mean true value),
        ``mean_error``, ``std_error`` and ``mc_U95`` (95 % quantile of |error|) in it, None for an item with no
        true value. ``figure`` is the distribution of the reported value ``{mean, std, q025, q975}`` (SI) for an
        item with no true value and for those of
        :data:`~plansim.uncertainty.jjf1535_monte_carlo.FIGURE_ALSO` (threshold, resolution, warm-up time, the
        repeatabilities), None otherwise. ``undetermined`` is the fraction of trials in which the procedure could
        not determine the item (0 for most; the statistics are over the others). ``budget`` (``"A.1"``,
        ``"A.2"``), ``budget_U`` (Appendix A's printed U, relative, k = 2), the relative error's
        ``mean_relative_error``, ``std_relative_error``, ``mc_U95_relative`` and the ``coverage`` (fraction of
        trials with |relative error| <= U) for the items Appendix A budgets, None for the others.
    """
    out = []
    for r in rows:
        scale = ITEMS[r["item"]][3]
        entry = dict.fromkeys(ITEM_KEYS)
        entry.update(item=r["item"], clause=r["clause"], equations=r["equations"], unit=SI_UNITS[r["unit"]])
        if "mean_error" in r:
            entry.update({k: r[k] * scale for k in ("truth", "mean_error", "std_error", "mc_U95")})
        if "mean" in r:
            entry["figure"] = {k: _number(r[k] * scale) for k in ("mean", "std", "q025", "q975")}
        entry["undetermined"] = r.get("undetermined", 0.0)
        if "budget" in r:
            entry.update({k: r[k] for k in ("budget", "budget_U", "mean_relative_error", "std_relative_error",
                                            "mc_U95_relative", "coverage")})
        out.append({k: (_number(v) if isinstance(v, float) else v) for k, v in entry.items()})
    return out


def not_simulated_json() -> list[dict]:
    """:data:`NOT_SIMULATED` as ``[{item, clause, reason}]``."""
    return [{"item": item, "clause": clause, "reason": reason} for item, clause, reason in NOT_SIMULATED]


def _g(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def items_table(rows: list[dict], arw: tuple[float, float] | None = None) -> str:
    """The certificate-style table: the scale factor items, the bias items, threshold, resolution and warm-up time,
    the items not simulated.

    Parameters
    ----------
    rows : list of dict
        :meth:`~plansim.uncertainty.jjf1535_monte_carlo.Jjf1535MonteCarlo.summary` (JJF 1535 units).
    arw : (float, float), optional
        7.2.13 on one session, ``(reported, simulated)`` rad/√s
        (:func:`plansim.runner.jjf1535_angle_random_walk`), printed after the bias items in °/√h.

    Returns
    -------
    str
        Per item with a true value: its unit, the mean true value, the mean and standard deviation of the error
        and the 95 % quantile of |error| (error = reported − true, per trial); for the items Appendix A budgets a
        second line with the relative error against the printed U (k = 2) and the coverage. Per item without a
        true value: the mean, standard deviation and 95 % interval of the reported figure.
    """
    by_item = {r["item"]: r for r in rows}
    head = (f"  {'item':30s} {'clause':14s} {'unit':16s} {'truth':>10s} {'mean error':>11s} {'std error':>10s} "
            f"{'95% |err|':>10s}")
    lines = ["error = reported − true value of the simulated unit, per trial; 95% |err| = the trials' 95 % quantile "
             "of |error|; Appendix A: printed U (k = 2), read relative; coverage = trials with |relative error| <= U"]
    for title, names in GROUPS:
        lines += ["", title, head]
        for name in names:
            r = by_item[name]
            start = f"  {LABELS[name]:30s} {r['clause']:14s} {r['unit']:16s}"
            figure = (f"reported figure: mean {_g(r['mean'], 3)}, std {_g(r['std'], 3)}, 95 % interval "
                      f"[{_g(r['q025'], 3)}, {_g(r['q975'], 3)}]" if "mean" in r else "")
            if r.get("undetermined"):
                figure += f"; undetermined in {100 * r['undetermined']:.1f} % of trials"
            if "mean_error" in r:
                lines.append(f"{start} {_g(r['truth'], 5):>10s} {_g(r['mean_error'], 3):>11s} "
                             f"{_g(r['std_error'], 3):>10s} {_g(r['mc_U95'], 3):>10s}")
                if figure:
                    lines.append(f"  {'':30s} {'':14s} {figure}")
            else:
                lines.append(f"{start} {'(none)':>10s} {figure}")
            if "budget" in r:
                lines.append(f"  {'':30s} {'':14s} Appendix {r['budget']} U = {r['budget_U']:.1e} (relative): "
                             f"relative error mean {r['mean_relative_error']:+.2e}, std {r['std_relative_error']:.2e}, "
                             f"95% |err| {r['mc_U95_relative']:.2e}; coverage {100 * r['coverage']:.1f} %")
        if title == "Bias items" and arw is not None:
            reported, simulated = arw
            lines.append(f"  {'angle random walk':30s} {'7.2.13':14s} {ARW_UNIT:16s} "
                         f"{_g(simulated / ARW_SCALE, 5):>10s} one session (trial 0), eq. (21)-(26): "
                         f"reported {_g(reported / ARW_SCALE, 4)} "
                         "(not in the Monte Carlo: it needs every sample)")
    lines += ["", "Not in this Monte Carlo"]
    lines += [f"  {item:30s} {clause:14s} {reason}" for item, clause, reason in NOT_SIMULATED]
    return "\n".join(lines)


def header(result, unit, procedure, elapsed: float | None = None) -> str:
    """The report's first lines: the unit scenario, trials, seed, path and the procedure.

    Parameters
    ----------
    result : plansim.uncertainty.jjf1535_monte_carlo.Jjf1535MonteCarlo
    unit : plansim.config.Scenario
        The unit scenario (its schedule, turntable and acquisition were replaced by JJF 1535's).
    procedure : plansim.schedule.jjf1535.Jjf1535Procedure
    elapsed : float, optional
        Wall time of the run, s.
    """
    schedule = procedure.schedule
    run = procedure.room_runs[0]
    rates = sorted(abs(schedule.segments[k].rate) / DEG for k in run.points)
    positive = sum(schedule.segments[k].rate > 0 for k in run.points)
    when = f" in {elapsed:.1f} s" if elapsed is not None else ""
    overrides = f"Overrides (--set): {'; '.join(unit.overrides)}\n" if unit.overrides else ""
    gyro = "xyz"[procedure.axis]
    table_u = f"{TABLE_RATE_UNCERTAINTY:.1e}".replace("e-0", "e-")  # 2.5e-4, as Appendix A prints it
    return (f"plansim {plansim_version()} — JJF 1535-2015 procedure on the unit of scenario {unit.name!r}: "
            f"{result.trials} trials, seed {result.seed}, {result.path} path{when}\n"
            f"{unit.description}\n{overrides}"
            f"The {gyro} gyro: {len(schedule)} segments, {schedule.duration / HOUR:.1f} h, Q = "
            f"{len(procedure.room_runs)} rate runs of {positive} + {len(run.points) - positive} points "
            f"(±{_g(rates[0])} to ±{_g(rates[-1])} °/s), bias averaging period P = "
            f"{_g(procedure.averaging_period)} s, temperatures {', '.join(_g(t) for t in procedure.temperatures)} °C; "
            f"JJF 1535 Table 2 rate table (u = {table_u} systematic, "
            f"{100 * TABLE_RATE_SMOOTHNESS:.2g} % smoothness), {_g(POSITION_ACCURACY / ARCSEC)}″ position table, "
            f"{ACQUISITION_BITS}-bit acquisition{_extras(procedure)}\n"
            f"{_effects_line(unit, procedure)}")


def _extras(procedure) -> str:
    """The threshold, resolution and warm-up tests of the header, '' for a procedure without them."""
    if not (procedure.threshold_runs and procedure.resolution_pairs and procedure.warm_up):
        return ""
    small = procedure.resolution_increments
    base = abs(procedure.schedule.segments[procedure.resolution_pairs[0][0][0]].rate)
    record = procedure.warm_up[0]
    return (f"; threshold rates and resolution increments ±{_g(small[-1] / DEG)} to ±{_g(small[0] / DEG)} °/s "
            f"(base rate {_g(base / DEG)} °/s); {len(procedure.warm_up)} warm-up records of "
            f"{_g(len(record) * procedure.averaging_period)} s from power-on, specified stability "
            f"{_g(procedure.specified_stability / (DEG / HOUR))} °/h; {len(procedure.power_on)} power-ons")


def _effects_line(unit, procedure) -> str:
    """The JJF 1535 effects of the gyro under test (plansim.model.jjf1535_effects), or that there are none."""
    e, i = unit.effects, procedure.axis
    if not e.jjf1535_effects_set():
        return "JJF 1535 effects of the unit: none (no dead zone, resolution, warm-up transient or turn-on bias)"
    return (f"JJF 1535 effects of the {'xyz'[i]} gyro: dead zone {_g(e.gyro_dead_zone[i] / DEG)} °/s, resolution "
            f"{_g(e.gyro_resolution[i] / DEG)} °/s, warm-up {_g(e.gyro_warm_up_amplitude[i] / (DEG / HOUR))} °/h × "
            f"exp(−t/{_g(e.gyro_warm_up_time_constant[i])} s), turn-on bias σ "
            f"{_g(e.gyro_turn_on_bias[i] / (DEG / HOUR))} °/h per power cycle")


# ------------------------------------------------------------------------------------------ plansim sweep jjf1535

#: the items the sweep's table shows when no target names others
SWEEP_ITEMS = ("scale_factor", "nonlinearity", "asymmetry", "scale_repeatability", "bias_up_down", "bias_stability")


def parse_targets(items) -> dict:
    """``--target ITEM=VALUE`` items as {item: value, SI}: VALUE in the item's JJF 1535 unit as the report prints
    it (:data:`plansim.estimate.jjf1535_items.ITEMS`; ppm, deg/h, …), optionally followed by that unit."""
    out = {}
    for text in items:
        name, value = split_item(text, ITEMS, "--target")
        unit, scale = ITEMS[name][2], ITEMS[name][3]
        number, _, given = value.partition(" ")
        if given.strip() and given.strip() != unit:
            raise ValueError(f"--target {text!r}: {name} is in {unit}; give the number in it (or '<number> {unit}')")
        try:
            number = float(number)
        except ValueError:
            raise ValueError(f"--target {text!r}: {number!r} is not a number") from None
        if not (number > 0 and math.isfinite(number)):
            raise ValueError(f"--target {text!r}: expected a positive number of {unit}")
        if name in out:
            raise ValueError(f"--target {text!r}: {name} is given twice")
        out[name] = number * scale
    return out


def sweep_cells(ds):
    """Yield ``(dims, index, {dim: index})`` of every cell of a JJF 1535 sweep Dataset, in C order."""
    dims = list(ds["session_hours"].dims)
    for index in np.ndindex(*ds["session_hours"].shape):
        yield dims, index, dict(zip(dims, index))


def compared_value(ds, where, item) -> tuple[float, str]:
    """The figure a target is compared with: the 95 % |error| where the item has a true value, else the spread."""
    u95 = float(ds["mc_U95"].isel(where).sel(item=item))
    if math.isfinite(u95):
        return u95, "U95"
    return float(ds["figure_std"].isel(where).sel(item=item)), "sd"


def sweep_jjf1535_table(ds, targets: dict, best: dict | None) -> str:
    """The sweep as text: per cell its fields, the session's hours and, per item, the 95 % |error| (U95) or the
    reported figure's standard deviation (sd), in the item's JJF 1535 unit; then the cheapest cell that meets
    the targets."""
    items = list(targets) or list(SWEEP_ITEMS)
    fields = ds.attrs["fields"].split("; ")
    head = [f"{f:>24s}" for f in fields] + [f"{'hours':>7s}"]
    kinds = {}
    for item in items:
        first = next(sweep_cells(ds))[2]
        kinds[item] = compared_value(ds, first, item)[1]
        head.append(f"{item + ' ' + kinds[item]:>26s}")
    lines = ["per item: U95 = 95 % quantile of |reported - true| over the trials; sd = standard deviation of the "
             "reported figure (no true value); in the item's unit: "
             + ", ".join(f"{i} {ITEMS[i][2]}" for i in items), " ".join(head)]
    for _, index, where in sweep_cells(ds):
        row = [f"{str(v):>24s}" for v in cell_fields(ds, index).values()]
        row.append(f"{float(ds['session_hours'].isel(where)):7.2f}")
        for item in items:
            value, _ = compared_value(ds, where, item)
            mark = ""
            if item in targets:
                mark = " ok" if math.isfinite(value) and value <= targets[item] else "   "
            row.append(f"{_g(value / ITEMS[item][3], 4):>23s}{mark}")
        lines.append(" ".join(row))
    if targets:
        wanted = ", ".join(f"{i} <= {_g(v / ITEMS[i][3])} {ITEMS[i][2]}" for i, v in targets.items())
        if best is None:
            lines.append(f"\nNo cell meets every target ({wanted}).")
        else:
            fields = "; ".join(f"{k} = {v}" for k, v in best["fields"].items())
            lines.append(f"\nShortest session meeting every target ({wanted}): {fields}, "
                         f"{best['session_hours']:.2f} h")
    return "\n".join(lines)


def sweep_jjf1535_json(ds, targets: dict, best: dict | None) -> dict:
    """The sweep as one JSON object, SI: ``cells`` [{fields, session_hours, segments, seed, items: [{item, unit,
    mean_error, std_error, mc_U95, figure: {mean, std, q025, q975}, undetermined}]}], ``targets`` and ``best``."""
    cells = []
    for _, index, where in sweep_cells(ds):
        entry = {"fields": cell_fields(ds, index),
                 "session_hours": float(ds["session_hours"].isel(where)),
                 "segments": int(ds["segments"].isel(where)), "seed": int(ds["seed"].isel(where)), "items": []}
        for item in ds["item"].values:
            v = {name: _number(float(ds[name].isel(where).sel(item=item))) for name in
                 ("mean_error", "std_error", "mc_U95", "figure_mean", "figure_std", "figure_q025", "figure_q975",
                  "undetermined")}
            entry["items"].append({"item": str(item), "unit": str(ds["item_unit"].sel(item=item).values),
                                   "mean_error": v["mean_error"], "std_error": v["std_error"], "mc_U95": v["mc_U95"],
                                   "figure": {k: v[f"figure_{k}"] for k in ("mean", "std", "q025", "q975")},
                                   "undetermined": v["undetermined"]})
        cells.append(entry)
    return {"procedure": "jjf1535", "unit_scenario": ds.attrs["unit_scenario"],
            "trials_per_cell": int(ds.attrs["trials_per_cell"]), "seed": int(ds.attrs["seed"]),
            "plansim_version": ds.attrs["plansim_version"], "cells": cells,
            "targets": [{"item": i, "value": v, "unit": SI_UNITS[ITEMS[i][2]],
                         "compared_with": "mc_U95 (95 % |error|), or the figure's std where there is no true value"}
                        for i, v in targets.items()],
            "best": None if best is None else {"fields": best["fields"], "session_hours": best["session_hours"],
                                               "values": best["values"]}}


def cell_fields(ds, index) -> dict:
    """The grid fields of the cell at *index* (of the dimensions of ``session_hours``), as the grid wrote them."""
    dims = list(ds["session_hours"].dims)
    out = {}
    for field in ds.attrs["fields"].split("; "):
        coordinate = ds[field]
        value = coordinate.values[index[dims.index(coordinate.dims[0])]]
        out[field] = value.item() if hasattr(value, "item") else value
    return out


# ------------------------------------------------------------------------------------------ claims on JJF 1535 items

def claims_table(rows: list[dict], source: str) -> str:
    """The claims of a certificate against the Monte Carlo (:func:`plansim.uncertainty.jjf1535_claims.
    judge_jjf1535_claims`), in each item's JJF 1535 unit (or relative)."""
    lines = [f"Claims ({source}) against the Monte Carlo: coverage = trials with |error| <= U (relative: |error/true| "
             "<= U); needed = the half-width the Monte Carlo needs for the claim's probability",
             f"  {'item':30s} {'unit':>16s} {'claimed U':>11s} {'k':>4s} {'needed':>11s} {'coverage':>9s}  verdict"]
    for r in rows:
        unit, scale = ("1 (relative)", 1.0) if r["relative"] else (ITEMS[r["item"]][2], ITEMS[r["item"]][3])
        lines.append(f"  {LABELS.get(r['item'], r['item']):30s} {unit:>16s} {_g(r['U'] / scale):>11s} {r['k']:>4g} "
                     f"{_g(r['needed'] / scale):>11s} {100 * r['coverage']:8.1f}%  {r['verdict']}")
    return "\n".join(lines)


def claims_json(rows: list[dict]) -> list[dict]:
    """The judged claims as the JSON's ``claims``, SI (``unit``: the item's SI unit, or ``1 (relative)``)."""
    out = []
    for r in rows:
        entry = {k: (_number(v) if isinstance(v, float) else v) for k, v in r.items()}
        entry["unit"] = "1 (relative)" if r["relative"] else SI_UNITS[ITEMS[r["item"]][2]]
        out.append(entry)
    return out
