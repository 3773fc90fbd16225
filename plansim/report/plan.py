"""A plan (:func:`plansim.planning.plan.plan`) as a text report and as JSON with stable keys."""

from __future__ import annotations

import math

from plansim.model.parameters import parameter
from plansim.report.sweep import json_number

#: the keys of ``plansim plan --json`` and of each of its targets
JSON_KEYS = ("scenario", "scenario_source", "overrides", "compliant_jjf2003", "table_time_s", "time_with_rules_s",
             "time_without_rules_s", "segments", "schedule", "trials", "rounds", "predictions", "all_met", "targets",
             "removal_breaks")
TARGET_KEYS = ("parameter", "unit", "target_U", "limit_U", "predicted_U", "monte_carlo_U", "monte_carlo_se", "met",
               "source")


def schedule_summary(schedule) -> dict:
    """The planned schedule in a few numbers: positions, each axis's rate points (deg/s), each test's dwells (s)."""
    out = {"positions": sum(s.test == "multi_position" for s in schedule.segments), "rate_points_deg_s": {},
           "dwell_s": {}}
    for axis in "xyz":
        rates = sorted(math.degrees(s.rate) for s in schedule.segments
                       if s.test == "rate" and s.rate_axis.lstrip("+-") == axis)
        out["rate_points_deg_s"][axis] = [round(r, 9) for r in rates]
    for test in ("multi_position", "rate", "omega_squared"):
        out["dwell_s"][test] = sorted({s.dwell for s in schedule.segments if s.test == test})
    return out


def plan_json(result) -> dict:
    """``plansim plan --json`` (:data:`JSON_KEYS`; each target :data:`TARGET_KEYS`), SI values."""
    mc = result.monte_carlo or {}
    met = result.met_in_monte_carlo() if result.monte_carlo is not None else {}
    targets = []
    for name, target in result.targets.items():
        U_mc, se = mc.get(name, (math.nan, math.nan))
        targets.append({"parameter": name, "unit": parameter(name).si_unit, "target_U": target.U,
                        "limit_U": result.limits[name], "predicted_U": result.predicted[name],
                        "monte_carlo_U": json_number(U_mc), "monte_carlo_se": json_number(se), "met": met.get(name),
                        "source": target.source})
    sc = result.scenario
    return {"scenario": sc.name, "scenario_source": sc.source, "overrides": list(sc.overrides),
            "compliant_jjf2003": result.compliant, "table_time_s": result.table_time,
            "time_with_rules_s": json_number(result.time_with_rules),
            "time_without_rules_s": json_number(result.time_without_rules), "segments": len(sc.schedule),
            "schedule": schedule_summary(sc.schedule), "trials": result.trials, "rounds": result.rounds,
            "predictions": result.predictions, "all_met": all(met.values()) if met else None, "targets": targets,
            "removal_breaks": [{"segment": s.label, "breaks": why}
                               for s, why in zip(sc.schedule.segments, result.removable)]}


def _display(name: str, value: float) -> str:
    if not math.isfinite(value):
        return "—"
    return f"{value / parameter(name).display_factor:.3g}"


def plan_report(result, default_time: float | None = None) -> str:
    """The plan as text: the schedule, its table time, per target the limit, predicted and Monte Carlo U (display
    units), the cost of compliance, and what removing each segment breaks (grouped)."""
    summary = schedule_summary(result.scenario.schedule)
    rules = "JJF 2003 §7.2 compliant" if result.compliant else "without the rules of JJF 2003 §7.2"
    lines = [f"Plan ({rules}): {len(result.scenario.schedule)} segments, table time {result.table_time:.0f} s"
             + (f" (the scenario's own schedule: {default_time:.0f} s)" if default_time is not None else ""),
             f"  positions: {summary['positions']}; dwell (s): "
             + ", ".join(f"{k} {'/'.join(f'{d:g}' for d in v)}" for k, v in summary["dwell_s"].items())]
    for axis, rates in summary["rate_points_deg_s"].items():
        lines.append(f"  rate points about {axis} (deg/s): {', '.join(f'{r:g}' for r in rates)}")
    lines.append(f"  compliance cost: {result.time_with_rules:.0f} s with the rules, "
                 f"{result.time_without_rules:.0f} s without")
    lines.append(f"  searched {result.predictions} predictions"
                 + (f", {result.rounds} round(s) of {result.trials}-trial Monte Carlo verification"
                    if result.trials else " (no Monte Carlo: --trials 0)"))
    lines.append("")
    mc = result.monte_carlo
    met = result.met_in_monte_carlo() if mc is not None else {}
    header = f"{'target':<8} {'unit':<16} {'U target':>10} {'predicted':>10} {'MC U':>10} {'± SE':>9}  met"
    lines += [header, "-" * len(header)]
    for name, target in result.targets.items():
        U_mc, se = mc[name] if mc is not None else (math.nan, math.nan)
        verdict = {True: "yes", False: "NO"}.get(met.get(name), "—")
        lines.append(f"{name:<8} {parameter(name).display_unit:<16} {_display(name, target.U):>10} "
                     f"{_display(name, result.predicted[name]):>10} {_display(name, U_mc):>10} "
                     f"{_display(name, se):>9}  {verdict}")
    lines.append("")
    counts: dict[str, int] = {}
    for why in result.removable:
        key = why.split(":")[0] if not why.startswith("JJF 2003") else "JJF 2003 compliance"
        counts[key] = counts.get(key, 0) + 1
    lines.append("Removing any one segment breaks: " + "; ".join(f"{k} ({n} segment{'s' * (n > 1)})"
                                                                  for k, n in counts.items()))
    return "\n".join(lines)
