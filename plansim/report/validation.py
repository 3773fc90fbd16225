"""The report of ``plansim validate``: the text, the JSON object and the progress line.

The computation is :func:`plansim.uncertainty.validation.validate`; this module only shapes its
:class:`~plansim.uncertainty.validation.ValidationReport` for people (:func:`format_report`) and
for programs (:func:`validation_json`, strict JSON).
"""

from __future__ import annotations

import math
import time

import numpy as np

from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX, PARAMETER_NAMES, parameter
from plansim.report.progress import progress_writer
from plansim.uncertainty.budget import ParameterBudget
from plansim.uncertainty.jjf1535_validation import Jjf1535ValidationReport
from plansim.uncertainty.metrology.coverage import COVERAGE_Z
from plansim.uncertainty.validation import ValidationReport

__all__ = ["format_jjf1535_report", "format_report", "jjf1535_json", "stderr_block_progress", "validate_progress",
           "validation_json"]


def validation_json(report: ValidationReport) -> dict:
    """The report as one JSON-ready dictionary (strict JSON: ``inf`` as the string ``"inf"``, ``nan`` as ``null``).

    Keys: ``scenario``, ``description``, ``claims``, ``mcm`` (trials, blocks, trials_per_block, seed,
    digits, tolerance_fraction, converged, path), ``parameters``, ``appendix_a``, ``joint_Kg``,
    ``correlation`` (names, mcm, gum) and ``gum_budgets`` (docs/uncertainty.md).
    """
    gum_corr = report.gum.correlation()
    mc = report.mcm
    return _json_ready({
        "scenario": report.scenario,
        "description": report.description,
        "claims": report.claims_source,
        "mcm": _mcm_json(mc, report.digits, report.tolerance_fraction, mc.path),
        "parameters": [p.as_dict() for p in report.parameters],
        "appendix_a": [c.as_dict() for c in report.appendix_items],
        "joint_Kg": report.joint.as_dict(),
        "correlation": {"names": list(PARAMETER_NAMES), "mcm": np.round(report.mcm_correlation, 6).tolist(),
                        "gum": np.round(gum_corr, 6).tolist()},
        "gum_budgets": [b.as_dict() for b in report.gum.budgets],
    })


def _mcm_json(mc, digits: int, tolerance_fraction: float, path: str) -> dict:
    """The ``mcm`` object of both validations' JSON: the adaptive Monte Carlo's size, seed, tolerance and path."""
    return {"trials": mc.trials, "blocks": mc.blocks, "trials_per_block": mc.trials_per_block, "seed": mc.seed,
            "digits": digits, "tolerance_fraction": tolerance_fraction, "converged": mc.converged, "path": path}


def jjf1535_json(report: Jjf1535ValidationReport) -> dict:
    """``plansim validate jjf1535 --json``: the report as one strict-JSON dictionary, SI.

    Keys: ``procedure`` ("jjf1535"), ``unit_scenario``, ``description``, ``mcm`` (as :func:`validation_json`),
    ``items`` (per item: the GUM y, u_c, ν_eff, k, U95; the MCM y, u, 95 % interval; JCGM 101 8's δ, d_low, d_high,
    validated; ``u_ratio`` = MCM u / GUM u_c, its tolerance and ``scatter_agrees``; the coverage of the truth by
    the GUM U95 and its verdict), ``gum_budgets`` (each item's inputs, ``u_i`` SI) and ``not_propagated`` (the
    items with a true value whose GUM is not built, and why).
    """
    mc = report.mcm
    return _json_ready({
        "procedure": "jjf1535",
        "unit_scenario": report.unit_scenario,
        "description": report.description,
        "mcm": _mcm_json(mc, report.digits, report.tolerance_fraction, report.path),
        "items": [c.as_dict() for c in report.items],
        "gum_budgets": [report.gum.item(c.item) for c in report.items],
        "not_propagated": report.not_propagated,
    })


def format_jjf1535_report(report: Jjf1535ValidationReport, details: bool = True) -> str:
    """The text report of ``plansim validate jjf1535``: per item GUM against MCM in the item's JJF 1535 unit,
    then (with *details*) each item's budget, then the items whose GUM is not built."""
    mc = report.mcm
    out = [
        f"plansim validate jjf1535 — unit scenario {report.unit_scenario!r}: {report.description}",
        f"GUM (JCGM 100) of the JJF 1535-2015 items from the procedure's reduction; adaptive Monte Carlo "
        f"(JCGM 101 7.9.4): {mc.blocks} blocks × {mc.trials_per_block} = {mc.trials} trials ({report.path} path, "
        f"seed {mc.seed}), n_dig = {report.digits}, run to {report.tolerance_fraction:g}·δ of the GUM u_c "
        "(JCGM 101 8.2): " + ("reached" if mc.converged else "NOT reached (max trials)"),
        "Output quantity: the error E = reported − true of each item, in its JJF 1535 unit (JSON: SI).",
        "",
        "Summary (JCGM 101 8: validated if d_low and d_high ≤ δ; u ratio = MCM u / GUM u_c, agrees if within "
        f"{COVERAGE_Z:g} standard errors of 1; coverage = fraction of trials with |E| ≤ GUM U95)",
        f"{'item':16s} {'unit':>10s} {'mean error':>11s} {'std error':>10s} {'GUM y':>10s} {'GUM u_c':>10s} "
        f"{'ν_eff':>7s} {'GUM U95':>10s} {'MCM low':>11s} {'MCM high':>11s} {'δ':>8s} {'d_low':>8s} "
        f"{'d_high':>8s} {'valid':>5s} {'u ratio':>13s} {'cov GUM':>7s}  verdict",
    ]
    for c in report.items:
        f = c.unit_si
        out.append(
            f"{c.item:16s} {c.unit:>10s} {c.mcm_y / f:>11.4g} {c.mcm_u / f:>10.4g} {c.gum_y / f:>10.4g} "
            f"{c.gum_u / f:>10.4g} {_fmt(c.gum_dof, 2):>7s} {c.gum_U95 / f:>10.4g} {c.mcm_low / f:>11.4g} "
            f"{c.mcm_high / f:>11.4g} {c.delta / f:>8.2g} {c.d_low / f:>8.2g} {c.d_high / f:>8.2g} "
            f"{'yes' if c.validated else 'NO':>5s} {c.u_ratio:>6.3f}±{c.u_ratio_tolerance:<6.3f} "
            f"{c.coverage_gum:>7.1%}  {c.coverage_verdict}")
    failed = [c.item for c in report.items if not c.validated]
    disagree = [c.item for c in report.items if not c.scatter_agrees]
    out.append(f"GUM framework validated for {len(report.items) - len(failed)} of {len(report.items)} items"
               + (f"; not for {', '.join(failed)}" if failed else "")
               + "; the GUM u_c agrees with the Monte Carlo's scatter for "
               + ("every item" if not disagree else f"all but {', '.join(disagree)}"))
    for c in report.items if details else ():
        budget = report.gum.item(c.item)
        f = c.unit_si
        out += ["", f"== {c.item} (JJF 1535 {c.clause}) [{c.unit}]: u_c = {_fmt(c.gum_u / f)}, "
                    f"MCM u = {_fmt(c.mcm_u / f)}; inputs (u_i(y) in {c.unit}, share of u_c²):"]
        for line in budget["inputs"]:
            out.append(f"  {line['name'][:30]:30s} {line['type']:2s} {_fmt(line['u_i'] / f, 3):>10s} "
                       f"{(line['u_i'] / c.gum_u) ** 2:>6.1%}")
    out += ["", "Not propagated (a true value, but no GUM built for it):"]
    out += [f"  {item}: {why}" for item, why in report.not_propagated.items()]
    return "\n".join(out)


def _json_ready(value):
    """Recursively: numpy scalars to Python, ``nan`` to None, ``±inf`` to ``"inf"``/``"-inf"`` (strict JSON)."""
    if isinstance(value, dict):
        return {k: _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        if math.isnan(value):
            return None
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
    return value



def _fmt(x, digits: int = 4) -> str:
    if x is None:
        return "—"
    if isinstance(x, float) and math.isnan(x):
        return "—"
    if isinstance(x, float) and math.isinf(x):
        return "∞"
    return f"{x:.{digits}g}"


def _scaled(x, factor: float):
    return None if x is None else x / factor


def _budget_table(budget: ParameterBudget, factor: float = 1.0, unit: str | None = None) -> list[str]:
    """The budget's lines; the output side (c_i, u_i(y), u_c, U, y, biases) divided by *factor*, i.e. in
    *unit* (the parameter's display unit; default SI, ``budget.unit``)."""
    unit = budget.unit if unit is None else unit
    lines = [f"  {'input':30s} {'type':4s} {'u(x_i)':>10s} {'unit':>7s} {'c_i':>10s} {'u_i(y)':>10s} {'share':>6s} "
             f"{'ν_i':>8s}  distribution"]
    uc = budget.combined_standard_uncertainty
    for line in budget.inputs:
        share = (line.contribution / uc) ** 2 if uc > 0 else math.nan
        input_unit = line.input_unit if len(line.input_unit) <= 7 else "SI"
        lines.append(f"  {line.name[:30]:30s} {line.evaluation:4s} {_fmt(line.standard_uncertainty, 3):>10s} "
                     f"{input_unit:>7s} {_fmt(_scaled(line.sensitivity, factor), 3):>10s} "
                     f"{_fmt(_scaled(line.contribution, factor), 3):>10s} "
                     f"{share:>6.1%} {_fmt(line.dof, 3):>8s}  {line.distribution}")
    lines.append(f"  u_c = {_fmt(uc / factor)} {unit}, ν_eff = {_fmt(budget.effective_dof, 3)}, "
                 f"k({budget.coverage_probability:.0%}) = {budget.coverage_factor:.3f}, "
                 f"U95 = {_fmt(budget.expanded_uncertainty / factor)} {unit}"
                 f"   [largest 2nd-order term {_fmt(_scaled(budget.largest_second_order, factor), 2)}]")
    if budget.systematic_effects:
        parts = [f"{e.name} {e.bias / factor:+.3g}" + (f" ({e.bias / uc:+.2g} u_c)" if uc > 0 else "")
                 for e in budget.systematic_effects]
        lines.append(f"  not corrected (bias; GUM 3.2.4 asks to correct): y = {budget.estimate / factor:+.4g} "
                     f"{unit} = " + "; ".join(parts))
    return lines


def format_report(report: ValidationReport, details: bool = True) -> str:
    """The text report of ``plansim validate``: summary, Appendix A, JCGM 102, per-parameter budgets."""
    mc = report.mcm
    out = [
        f"plansim validate — scenario {report.scenario!r}: {report.description}",
        f"GUM (JCGM 100) budgets derived from the schedule; adaptive Monte Carlo (JCGM 101 7.9.4): "
        f"{mc.blocks} blocks × {mc.trials_per_block} = {mc.trials} trials ({mc.path} path, seed {mc.seed}), "
        f"n_dig = {report.digits}, run to {report.tolerance_fraction:g}·δ of the GUM u_c (JCGM 101 8.2): "
        + ("reached" if mc.converged else "NOT reached (max trials)"),
        f"Output quantity: the error E = estimate − truth of each parameter, in the display units of "
        f"`plansim run` (JSON: SI). Claims: {report.claims_source}.",
        "",
        "Summary (JCGM 101 8: validated if d_low and d_high ≤ δ; coverage = fraction of trials with |E| ≤ U);",
        "mean error and std error are the MCM y and u of E, as `plansim run` prints them",
        f"{'name':6s} {'unit':>14s} {'mean error':>11s} {'std error':>10s} {'GUM y':>10s} {'GUM u_c':>10s} "
        f"{'ν_eff':>7s} {'GUM U95':>10s} {'MCM low':>11s} {'MCM high':>11s} {'δ':>8s} {'d_low':>8s} {'d_high':>8s} "
        f"{'valid':>5s} {'cov GUM':>7s} {'claimed U':>10s} {'cov claim':>9s}  claim verdict",
    ]
    for p in report.parameters:
        spec = parameter(p.name)
        f = spec.display_factor
        claimed = None if p.claimed_U is None else p.claimed_U / f
        out.append(
            f"{p.name:6s} {spec.display_unit:>14s} {p.mcm_y / f:>11.3g} {p.mcm_u / f:>10.3g} {p.gum_y / f:>10.3g} "
            f"{p.gum_u / f:>10.3g} {_fmt(p.gum_dof, 2):>7s} {p.gum_U95 / f:>10.3g} "
            f"{p.mcm_low / f:>11.3g} {p.mcm_high / f:>11.3g} {p.delta / f:>8.2g} {p.d_low / f:>8.2g} "
            f"{p.d_high / f:>8.2g} "
            f"{'yes' if p.validated else 'NO':>5s} {p.coverage_gum:>7.1%} {_fmt(claimed, 3):>10s} "
            f"{'—' if p.coverage_claimed is None else format(p.coverage_claimed, '.1%'):>9s}  "
            f"{p.claim_verdict or '—'}")
    failed = [p for p in report.parameters if not p.validated]
    out.append(f"GUM framework validated for {N_PARAMETERS - len(failed)} of {N_PARAMETERS} parameters"
               + (f"; not for {', '.join(p.name for p in failed)}" if failed else ""))

    if report.appendix_items:
        out += ["", "Appendix A of JJF 2003-2022 — claimed and achieved (reading units; k = 2)"]
        for c in report.appendix_items:
            out.append(f"{c.item} {c.quantity} — reading: {c.reading_unit}")
            out.append(f"    printed u_c {c.printed_uc:g}, U {c.printed_U:g}; recomputed k·u_c {c.arithmetic_U:.4g}; "
                       f"the same inputs by the GUM: u_c {c.same_inputs_gum_uc:.3g}, U {c.same_inputs_gum_U:.3g}")
            for slip in c.slips:
                out.append(f"    ! {slip}")
            gum_list = ", ".join(f"{n} {v:.3g}" for n, v in zip(c.parameters, c.gum_U95))
            mcm_list = ", ".join(f"{n} {v:.3g}" for n, v in zip(c.parameters, c.mcm_U95))
            out.append(f"    achieved by this schedule: GUM U95 {gum_list}")
            out.append(f"                               MCM U95 {mcm_list}")
            out.append(f"    claimed U {c.claimed_U:g} covers the truth in {c.coverage:.2%} of the trials: {c.verdict}")
            if len(c.readings) == 1:
                out.append(f"    {c.item} has one reading of its unit ({c.readings[0].reading}): the verdict holds")
            elif c.readings:
                spec = parameter(c.parameters[0])
                display = "dimensionless" if spec.display_unit == "1" else f"in {spec.display_unit}"
                out.append(f"    the number {c.claimed_U:g} in each reading of its unit ({c.reading_dependence}; "
                           f"U and the MCM's |E| quantile {display}):")
                for r in c.readings:
                    out.append(f"        {r.reading:18s} U = {_fmt(r.mean_budget_U_si / spec.display_factor, 4):>9s}, "
                               f"MCM {_fmt(r.mc_U95_si / spec.display_factor, 4):>9s}: covers {r.coverage:.2%}, "
                               f"{r.verdict}")

    j = report.joint
    out += ["", f"Several outputs at once (JCGM 102): {', '.join(j.parameters)}",
            f"    inside the {j.coverage_probability:.0%} ellipsoid χ²_{j.dimension}({j.coverage_probability:g}) = "
            f"{j.chi2_quantile:.3g}: {j.fraction_in_ellipsoid:.2%} of the trials (MCM k_p = {j.mc_k:.3g}, "
            f"√χ² = {math.sqrt(j.chi2_quantile):.3g}); GUM ellipsoid about the truth: "
            f"{j.gum_fraction_in_ellipsoid:.2%}",
            f"    all {len(j.parameters)} inside their marginal k = {j.marginal_k:g} intervals: "
            f"{j.fraction_all_marginal:.2%}; box for a joint {j.coverage_probability:.0%}: k = {j.box_k:.3g}",
            f"    {'! ' if j.misleading else ''}{j.message}"]
    corr = report.mcm_correlation
    idx = [PARAMETER_INDEX[n] for n in j.parameters]
    pairs = sorted(((abs(corr[a, b]), a, b) for ai, a in enumerate(idx) for b in idx[ai + 1:]), reverse=True)[:3]
    if pairs:
        out.append("    strongest correlations: " + ", ".join(
            f"r({PARAMETER_NAMES[a]}, {PARAMETER_NAMES[b]}) = {corr[a, b]:+.3f}" for _, a, b in pairs))

    gum_corr = report.gum.correlation()
    pairs = sorted(((abs(corr[a, b]), a, b) for a in range(N_PARAMETERS) for b in range(a + 1, N_PARAMETERS)),
                   reverse=True)[:8]
    out.append("Correlation of the estimated parameters (JCGM 102; Kg, G, Ka, P come from shared fits), "
               "strongest pairs, MCM (GUM):")
    out.append("    " + ", ".join(f"r({PARAMETER_NAMES[a]}, {PARAMETER_NAMES[b]}) = {corr[a, b]:+.3f} "
                                  f"({gum_corr[a, b]:+.3f})" for _, a, b in pairs))

    if details:
        for p, budget in zip(report.parameters, report.gum.budgets):
            spec = parameter(p.name)
            f = spec.display_factor
            out += ["", f"== {p.name}: {spec.long_name} [{spec.display_unit}; SI {p.unit}]"
                    + (f" — Appendix A {p.appendix_item}" if p.appendix_item else "")]
            out.append(f"GUM budget (JCGM 100 5.1.2; output: the error E of the parameter, in {spec.display_unit}; "
                       "c_i in that unit per unit of x_i)")
            out += _budget_table(budget, f, spec.display_unit)
            out.append(f"MCM: y = {p.mcm_y / f:.4g}, u = {p.mcm_u / f:.4g}, {mc.coverage_probability:.0%} interval "
                       f"[{p.mcm_low / f:.4g}, {p.mcm_high / f:.4g}] "
                       f"(shortest [{p.mcm_shortest_low / f:.4g}, {p.mcm_shortest_high / f:.4g}]) {spec.display_unit}")
            out.append(f"Validation (JCGM 101 8): δ = {p.delta / f:.2g}, d_low = {p.d_low / f:.2g}, "
                       f"d_high = {p.d_high / f:.2g} {spec.display_unit} → "
                       f"GUM framework validated: {'yes' if p.validated else 'no'}")
            for reason in p.reasons:
                out.append(f"    because {reason}")
            line = f"Coverage of the truth: GUM U95 {p.coverage_gum:.2%}"
            if p.claimed_U is not None:
                line += (f"; claimed U = {p.claimed_U / f:.4g} {spec.display_unit} ({p.claim_source}) "
                         f"{p.coverage_claimed:.2%} → {p.claim_verdict} (U needed for {p.claim_probability:.0%}: "
                         f"{p.claimed_U / p.claim_factor / f:.3g} {spec.display_unit})")
            out.append(line)
            if budget.appendix_a is not None:
                a = budget.appendix_a
                out.append(f"Appendix A {a.item} in its reading unit (1 unit = {a.reading_unit_si / f:.4g} "
                           f"{spec.display_unit}): "
                           f"printed u1 {a.printed_u[0]:g}, u2 {a.printed_u[1]:g}, u3 {a.printed_u[2]:g} → "
                           f"u_c {a.printed_uc:g}, "
                           f"U {a.printed_U:g} (same inputs by the GUM: U {a.same_inputs_gum_U:.3g}); this schedule: "
                           f"table {a.plansim_u[0]:.3g}, acquisition {a.plansim_u[1]:.3g}, repeatability "
                           f"{a.plansim_u[2]:.3g} → u_c {a.plansim_uc:.3g}, U95 {a.plansim_U95:.3g}")
    return "\n".join(out)



def validate_progress(label: str, quiet: bool):
    """``plansim validate``'s progress: None if *quiet*, else :func:`stderr_block_progress` (*label*), whose line
    on a terminal stays open until the report starts (:func:`plansim.report.progress.progress_writer`)."""
    return None if quiet else stderr_block_progress(label)


def stderr_block_progress(label: str):
    """A progress line on stderr for the adaptive Monte Carlo after each block
    (:func:`plansim.report.progress.progress_writer`: redrawn in place on a terminal, whole lines elsewhere).

    Returns ``report(trials_done, blocks, worst)``, ``worst`` the largest ``2s/δ`` (stop at ≤ 1).
    """
    start = time.perf_counter()
    write = progress_writer()

    def report(done: int, blocks: int, worst: float) -> None:
        elapsed = time.perf_counter() - start
        write(f"{label}: {blocks} blocks, {done} trials, max 2s/δ = {worst:.3g} ({elapsed:.0f} s)")

    return report
