"""A sweep (:func:`plansim.planning.sweep.sweep`) as a text table and as JSON with stable keys."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import xarray as xr

from plansim.model.parameters import group_spec

#: the keys of ``plansim sweep --json`` and of each of its cells
JSON_KEYS = ("scenario", "scenario_source", "base_overrides", "grid", "trials_per_cell", "seed",
             "coverage_probability", "plansim_version", "groups", "cells")
CELL_KEYS = ("coordinates", "seed", "table_time_s", "compliant_jjf2003", "failed_rules", "max_rate_rad_s",
             "under_covered", "u_group", "pareto", "parameters")


def _grid_dims(ds: xr.Dataset) -> list[str]:
    return list(ds["table_time_s"].dims)


def _cells(ds: xr.Dataset):
    """Yield ``(coordinates dict, Dataset of the cell)`` in C order."""
    dims = _grid_dims(ds)
    shape = [ds.sizes[d] for d in dims]
    for index in np.ndindex(*shape):
        cell = ds.isel(dict(zip(dims, index)))
        coordinates = {}
        for d in dims:
            coordinates[d] = cell[d].item()
            for name, coord in ds.coords.items():  # the [zip] fields along their dimension
                if coord.dims == (d,) and name != d:
                    coordinates[name] = cell[name].item()
        yield coordinates, cell


def json_number(x) -> float | None:
    """*x* as a float for JSON, or None when it is not finite (JSON has no NaN or infinity)."""
    x = float(x)
    return x if math.isfinite(x) else None


def under_covered(ds: xr.Dataset, cell: xr.Dataset) -> list[str]:
    """The parameters of *cell* whose Monte Carlo coverage of ±U_predicted is below p by more than 3 binomial
    standard errors of the trial count (a predicted bias the estimators leave, or a GUM that does not hold)."""
    p = float(ds.attrs.get("coverage_probability", 0.95))
    trials = int(ds.attrs.get("trials_per_cell", 0))
    if "coverage" not in ds or trials < 2:
        return []
    floor = p - 3.0 * math.sqrt(p * (1.0 - p) / trials)
    return [str(n) for n, c in zip(ds["parameter"].values, cell["coverage"].values) if c < floor]


def _short(value) -> str:
    """A coordinate for a table: a list's TOML text longer than 24 characters as ``[n values: first … last]``."""
    text = str(value)
    if text.startswith("[") and len(text) > 24:
        try:
            items = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            return text
        return f"[{len(items)} values: {items[0]} … {items[-1]}]"
    return text


def sweep_table(ds: xr.Dataset) -> str:
    """One line per cell: its coordinates, table time, JJF 2003 compliance, the largest u of each parameter
    group in display units (``*``: on that group's Pareto front), and with a Monte Carlo the lowest coverage."""
    groups = [str(g) for g in ds["group"].values]
    simulated = "coverage" in ds
    rows = []
    for coordinates, cell in _cells(ds):
        row = ["; ".join(f"{k}={_short(v)}" for k, v in coordinates.items()),
               f"{float(cell['table_time_s']) / 60.0:.1f}",
               "yes" if bool(cell["compliant_jjf2003"]) else
               "no: " + ", ".join(str(r) for r, ok in zip(ds["rule"].values, cell["jjf2003_rule"].values) if not ok)]
        for g in groups:
            factor = group_spec(g).display_factor
            star = "*" if bool(cell["pareto"].sel(group=g)) else " "
            row.append(f"{float(cell['u_group'].sel(group=g)) / factor:.3g}{star}")
        if simulated:
            low = under_covered(ds, cell)
            row.append(", ".join(low[:4]) + (f" +{len(low) - 4}" if len(low) > 4 else "") if low else "none")
        rows.append(row)
    which = "u_mc" if simulated else "u_predicted"
    head = ["cell", "time (min)", "JJF 2003 §7.2"] + [f"{g} ({group_spec(g).display_unit})" for g in groups]
    if simulated:
        head.append("under-covered")
    widths = [max(len(r[k]) for r in [head, *rows]) for k in range(len(head))]
    lines = [f"Largest {which} per group (display units; * on the group's Pareto front of time against u)"]
    if simulated:
        lines[0] += ("; under-covered: parameters whose errors fall within ±U_predicted less often than "
                     f"p = {ds.attrs.get('coverage_probability', 0.95):g} allows (3 binomial standard errors)")
    lines.append("  ".join(h.ljust(w) if k < 3 else h.rjust(w) for k, (h, w) in enumerate(zip(head, widths))))
    for r in rows:
        lines.append("  ".join(c.ljust(w) if k < 3 else c.rjust(w) for k, (c, w) in enumerate(zip(r, widths))))
    return "\n".join(lines)


def sweep_json(ds: xr.Dataset) -> dict:
    """The sweep as a JSON-ready dict with the keys :data:`JSON_KEYS` (each cell: :data:`CELL_KEYS`), SI."""
    groups = [str(g) for g in ds["group"].values]
    per = [k for k in ("u_predicted", "bias_predicted", "U_predicted", "u_mc", "bias_mc", "coverage") if k in ds]
    cells = []
    for coordinates, cell in _cells(ds):
        cells.append({
            "coordinates": coordinates,
            "seed": int(cell["seed"]),
            "table_time_s": float(cell["table_time_s"]),
            "compliant_jjf2003": bool(cell["compliant_jjf2003"]),
            "failed_rules": [str(t) for t, ok in zip(ds["rule_text"].values, cell["jjf2003_rule"].values) if not ok],
            "max_rate_rad_s": float(cell["max_rate"]),
            "under_covered": under_covered(ds, cell),
            "u_group": {g: json_number(cell["u_group"].sel(group=g)) for g in groups},
            "pareto": {g: bool(cell["pareto"].sel(group=g)) for g in groups},
            "parameters": [{"name": str(name), "unit": str(unit),
                            **{k: json_number(cell[k].values[i]) for k in per}}
                           for i, (name, unit) in enumerate(zip(ds["parameter"].values, ds["unit"].values))],
        })
    dims = _grid_dims(ds)
    return {
        "scenario": ds.attrs.get("scenario"), "scenario_source": ds.attrs.get("scenario_source"),
        "base_overrides": [o for o in str(ds.attrs.get("base_overrides", "")).split("; ") if o],
        "grid": {d: [v.item() if hasattr(v, "item") else v for v in ds[d].values] for d in dims},
        "trials_per_cell": int(ds.attrs.get("trials_per_cell", 0)), "seed": int(ds.attrs.get("seed", 0)),
        "coverage_probability": float(ds.attrs.get("coverage_probability", 0.95)),
        "plansim_version": ds.attrs.get("plansim_version"),
        "groups": {g: str(u) for g, u in zip(groups, ds["group_unit"].values)},
        "cells": cells,
    }
