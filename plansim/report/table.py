"""Readable text tables of a Monte Carlo run: parameters, and Appendix A claimed vs achieved."""

from __future__ import annotations

import numpy as np
import xarray as xr

from plansim.model.parameters import parameter


def _g(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def header(results: xr.Dataset, elapsed: float | None = None) -> str:
    a = results.attrs
    when = f" in {elapsed:.1f} s" if elapsed is not None else ""
    overrides = f"Overrides (--set): {a['scenario_overrides']}\n" if a.get("scenario_overrides") else ""
    return (f"plansim {a['plansim_version']} — scenario {a['scenario']!r}: {a['trials']} trials, seed {a['seed']}, "
            f"{a['simulation_path']} path{when}\n{a['scenario_description']}\n{overrides}"
            f"Reduction uses 1 g = {a['reference_gravity_m_s2']:.7f} m/s² ({a['reference_gravity_choice']}); "
            f"local gravity {a['local_gravity_m_s2']:.7f} m/s² at latitude {a['latitude_deg']:.4g}°")


def parameter_table(results: xr.Dataset) -> str:
    """Per parameter: mean truth, mean error (estimator bias) and standard deviation of the error."""
    lines = ["Parameters — error = estimate − truth over the trials (display units)",
             f"{'name':6s} {'unit':>14s} {'truth (mean)':>14s} {'mean error':>12s} {'std error':>12s}"]
    for row in parameter_summary(results):
        spec = parameter(row["name"])
        f = spec.display_factor
        lines.append(f"{row['name']:6s} {spec.display_unit:>14s} {_g(row['truth'] / f, 8):>14s} "
                     f"{_g(row['mean_error'] / f, 3):>12s} {_g(row['std_error'] / f, 3):>12s}")
    return "\n".join(lines)


def appendix_a_table(comparisons) -> str:
    """Claimed (Appendix A as printed) against achieved (Monte Carlo), in each budget's reading."""
    lines = ["Appendix A of JJF 2003-2022 (k = 2) — claimed vs achieved, in the reading named per item",
             f"{'item':4s} {'quantity':28s} {'claimed u_c':>11s} {'claimed U':>10s} {'MC u':>10s} {'MC U95':>10s} "
             f"{'MC bias':>10s} {'coverage':>8s}  verdict"]
    for c in comparisons:
        lines.append(f"{c.item:4s} {c.quantity[:28]:28s} {c.budget_uc:>11.3g} {c.budget_U:>10.3g} {c.mc_u:>10.3g} "
                     f"{c.mc_U95:>10.3g} {c.mc_bias:>10.3g} {c.coverage:>8.1%}  {c.verdict}")
    lines.append("readings: " + "; ".join(f"{c.item} {c.reading_unit}" for c in comparisons))
    by_reading = verdict_by_reading_table(comparisons)
    if by_reading:
        lines += ["", by_reading]
    return "\n".join(lines)


def verdict_by_reading_table(comparisons) -> str:
    """The verdict of each Appendix A item under every defensible reading of its unit, and whether it holds.

    One row per reading (``ItemComparison.readings``): the printed U read in that unit and the Monte
    Carlo U95, both converted to the parameters' display unit, and the verdict; the last column, on
    an item's first row, says ``holds: <kind>`` when every reading gives the same kind of verdict and
    ``DEPENDS on the reading`` otherwise. Empty when no comparison carries readings.
    """
    rows = [c for c in comparisons if c.readings]
    if not rows:
        return ""
    lines = ["Verdict by reading — the printed U is one number; read in each defensible unit it is a different "
             "amount (claimed U and MC U95 in display units)",
             f"{'item':4s} {'reading':18s} {'claimed U':>10s} {'MC U95':>10s} {'unit':12s} {'verdict':22s} "
             "every reading"]
    for c in rows:
        spec = parameter(c.parameters[0])
        f = spec.display_factor
        mark = (f"holds: {c.readings[0].verdict_kind}" if c.holds_under_every_reading
                else "DEPENDS on the reading")
        for i, r in enumerate(c.readings):
            lines.append(f"{c.item if i == 0 else '':4s} {r.reading:18s} {_g(r.mean_budget_U_si / f, 4):>10s} "
                         f"{_g(r.mc_U95_si / f, 4):>10s} {spec.display_unit:12s} {r.verdict:22s} "
                         f"{mark if i == 0 else ''}".rstrip())
    return "\n".join(lines)


def parameter_summary(results: xr.Dataset) -> list[dict]:
    """Per parameter: name, SI unit, mean truth, mean error and standard deviation of the error (ddof = 1;
    0 with one trial).

    *results* is either a run's per-trial Dataset (:func:`plansim.runner.run`) or its streamed summary
    (:func:`plansim.runner.run_summary`, recognised by its ``error_mean`` variable).
    """
    out = []
    if "error_mean" in results:
        for k, name in enumerate(results["parameter"].values):
            std = float(results["error_std"].values[k])
            out.append({
                "name": str(name),
                "unit": str(results["units"].values[k]),
                "truth": float(results["truth_mean"].values[k]),
                "mean_error": float(results["error_mean"].values[k]),
                "std_error": std if int(results.attrs["trials"]) > 1 else 0.0,
            })
        return out
    err = results["error"]
    for name in results["parameter"].values:
        e = err.sel(parameter=name).values
        out.append({
            "name": str(name),
            "unit": str(results["units"].sel(parameter=name).values),
            "truth": float(results["truth"].sel(parameter=name).mean()),
            "mean_error": float(np.mean(e)),
            "std_error": float(np.std(e, ddof=1)) if e.size > 1 else 0.0,
        })
    return out
