"""The text report of ``plansim diagnose``: the verdict first, then the candidates, then before and after.

Residuals in °/h (gyros) and µg (accelerometers); parameters in their display units
(:mod:`plansim.model.parameters`); effect sizes in SI with their unit.
"""

from __future__ import annotations

import math

from plansim.diagnose.procedure import absorbed, levels
from plansim.diagnose.within import TESTS
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETERS
from plansim.report.fit import OUTPUT_UNITS, _g, _kind

#: what each family of the lack of fit's patterns is called in the report
_FAMILY_NAMES = {"step": "step", "change": "change in time", "outlier": "odd segment"}


def _display_unit(channel: str) -> tuple[str, float]:
    """The display unit of a channel's segment means (°/h, µg) and its size in SI."""
    return OUTPUT_UNITS[_kind(CHANNELS.index(channel))]


def _p(value: float) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value:.3g}"


def _change_text(c: dict) -> str:
    """A change of a parameter in time (the lack of fit's ``change``, a ``time_alternative``), in words."""
    if c.get("form") == "linear":
        return f"{c['parameter']} drifting steadily through the run (segments {c['between'][0]} to {c['between'][1]})"
    return (f"{c['parameter']} changing between segments {c['between'][0]} and {c['between'][1]} (at "
            f"{c['at_s'] / 60:.1f} min)")


def _rival_text(r: dict) -> str:
    """The lack of fit's step, change or odd segment that rivals a named effect (``attribution[].rival``), in words."""
    between = r.get("between", [None, None])
    if r["family"] == "change":
        return _change_text(r)
    if r["family"] == "step":
        return f"a step in {r['channel']} between segments {between[0]} and {between[1]} (at {r['at_s'] / 60:.1f} min)"
    return f"segment {between[0]} off in {r['channel']}"


def _within_lines(d) -> list[str]:
    """The within-segment findings, each with its pattern in display units."""
    w = d.within
    if not w.flagged:
        return [f"Within the {len(w.segments)} segments tested ({', '.join(TESTS)}): nothing "
                f"(smallest adjusted p = {_p(w.smallest_adjusted_p())}, level {w.alpha:g})."]
    lines = [f"UNEXPLAINED within segments (level {w.alpha:g}, family-wise over {len(w.segments)} segments, "
             f"6 channels and {len(TESTS)} tests): not named after any catalogue effect"]
    by_test = {test: sum(item["test"] == test for item in w.flagged) for test in TESTS}
    by_channel = {c: n for c in CHANNELS if (n := sum(item["channel"] == c for item in w.flagged))}
    lines.append(f"  {len(w.flagged)} finding(s) in {len({item['segment'] for item in w.flagged})} segment(s): "
                 + ", ".join(f"{test} {n}" for test, n in by_test.items() if n) + "; "
                 + ", ".join(f"{c} {n}" for c, n in by_channel.items()))
    held = [item for item in w.flagged if item["test"] == "scatter" and ", held (" in item["label"]]
    if held:
        lines.append(f"  {len(held)} of the 'noisier' findings are in poses the import found held by hand "
                     "(held_pose): a hand that shakes, as expected")
    for item in w.flagged[:12]:
        unit, factor = _display_unit(item["channel"])
        test = item["test"]
        if test == "trend":
            what = f"trend {item['slope'] / factor:+.3g} {unit}/s"
        elif test == "step":
            what = f"step of {item['size'] / factor:+.3g} {unit} at {item['at_s']:.1f} s"
        elif test == "periodic":
            what = f"periodic at {item['frequency_hz']:.4g} Hz, amplitude {item['amplitude'] / factor:.3g} {unit}"
        elif test == "transient":
            what = (f"transient from the segment's start: {item['size'] / factor:+.3g} {unit} decaying with a time "
                    f"constant of {item['time_constant_s']:.3g} s")
        elif test == "burst":
            what = f"burst from {item['from_s']:.1f} to {item['to_s']:.1f} s, sd {item['std'] / factor:.3g} {unit}"
        else:
            what = f"noisier than the other segments: sd {item['std'] / factor:.3g} {unit}"
        lines.append(f"  {item['channel']} segment {item['segment']} {item['label']}: {what} "
                     f"(adjusted p = {_p(item['adjusted_p_value'])})")
    if len(w.flagged) > 12:
        lines.append(f"  … and {len(w.flagged) - 12} more")
    return lines


def _stated_lines(d) -> list[str]:
    """The final model's segment means against the slow noise the lab states (plansim.diagnose.stated)."""
    test = d.stated_noise_after
    if test is None:
        return []
    head = (f"the slow noise stated in {test.source}, up to {test.margin:g} times in s.d.; level {test.level:g}, "
            f"Bonferroni over {len(test.channels)} channel(s)")
    if not test.flagged:
        return [f"The segment means are within the noise the lab states ({head}; p = {_p(test.p_value)})."]
    lines = [f"SCATTER BEYOND THE STATED NOISE ({head}; p = {_p(test.p_value)}): an effect the model lacks, or a "
             "unit noisier than stated; the lack-of-fit tests above weigh the residual against noise estimated from "
             "this recording, which takes both up"]
    for item in test.flagged_channels():
        lines.append(f"  {item['channel']}: its segment means scatter {item['sd_ratio']:.3g} times (s.d.) what the "
                     f"statement allows (chi2 {item['statistic']:.4g} on {item['dof']} dof, p = {_p(item['p_value'])}; "
                     f"stated: {item['stated']})")
    for item in d.unexplained.get("partial_match", []):
        lines.append(f"  {item['effect']}, named above, acts on {', '.join(item['channels'])} and leaves it beyond the "
                     "stated noise: the name may fit only part of what is there (an effect outside the catalogue "
                     "that shares part of its signature)")
    return lines


def diagnose_report(d) -> str:
    """The whole report of a :class:`plansim.diagnose.procedure.Diagnosis` as text."""
    lines = ["plansim diagnose — closing the loop (docs/closing-the-loop.md)", ""]
    lof = d.lack_of_fit
    lines.append(f"Lack of fit of the base model (segment means, simulated null): statistic {_g(lof.statistic, 5)}, "
                 f"p = {_p(lof.p_value)} -> {'FLAGGED' if lof.flagged else 'not flagged'} at "
                 f"{levels(d.alpha)['lack_of_fit']:g} (alpha = {d.alpha:g} for the whole diagnosis)")
    if lof.dof <= 0:
        lines.append(f"  not testable: the base model fits the {int(d.before.rows.sum())} fitted means (segments × "
                     "channels) exactly (no degrees of freedom left), so nothing at segment level can show; more "
                     "poses, or repeats of one, would leave some")
    if d.selected:
        lines.append(f"Found (closed testing, family-wise level {levels(d.alpha)['selections']:g}):")
        for effect in d.selected:
            size = d.sizes[effect]
            parts = ", ".join(f"{c} = {v:.4g} ± {u:.2g}" for c, v, u in zip(size["components"], size["value"],
                                                                              size["u"]))
            lines.append(f"  {effect}: {parts} ({size['unit']}; ± standard uncertainty)")
        for a in d.attribution:
            if a["runner_up"] is not None:
                lines.append(f"  {a['effect']} chosen over {a['runner_up']} (strongest 1-dof scores "
                             f"{a['statistic']:.1f} against {a['runner_up_statistic']:.1f}; their signatures' cosine "
                             f"{a['cosine']:.3f}: at this size the schedule tells them apart about "
                             f"{100 * a['probability_correct']:.0f} % of the time)")
            t = a.get("time_alternative")
            if t is not None:
                lines.append(f"  or, outside the catalogue: {_change_text(t)} looks like "
                             f"{a['effect']}"
                             f"[{t['component']}] with cosine {t['cosine']:.3f}: at this size the schedule tells "
                             f"them apart about {100 * t['probability_distinct']:.0f} % of the time"
                             + (" — this recording cannot say which" if t["cosine"] > 0.99 else ""))
            r = a.get("rival")
            if r is not None:
                lines.append(f"  the lack of fit's {_FAMILY_NAMES[r['family']]} is significant too: {_rival_text(r)} "
                             f"(statistic {r['family_statistic']:.1f} against {r['statistic']:.1f} for "
                             f"{a['effect']}[{r['component']}]; the effect stays named unless the "
                             f"{_FAMILY_NAMES[r['family']]} wins by more than {r['margin']:.1f}, what the best of its "
                             "columns gains on noise alone): another reading of this recording, outside the "
                             "catalogue")
    else:
        lines.append("Found: no catalogue effect is named.")
    for item in d.not_named:
        lines.append(f"  {item['effect']}[{item['component']}] was significant but is not named: the "
                     f"{_FAMILY_NAMES[item['family']]} below explains the residual "
                     f"clearly better (statistic {item['family_statistic']:.1f} against {item['statistic']:.1f}, "
                     f"more than the {item['margin']:.1f} its best column gains on noise alone)")
    after = d.lack_of_fit_after
    excess = d.unexplained.get("excess_scatter", [])
    if after.flagged:
        lines.append(f"UNEXPLAINED residual after the refit (p = {_p(after.p_value)}): not named after any "
                     "catalogue effect; where it sits:")
        for where in d.unexplained["where"]:
            unit, factor = _display_unit(where["channel"])
            segs = "; ".join(f"{s['segment']} {s['label']} ({s['residual'] / factor:+.3g} {unit}, z = {s['z']:+.1f})"
                             for s in where["segments"]) or "spread over the segments, none beyond 3u"
            lines.append(f"  {where['channel']} (p = {_p(where['p_value'])}): {segs}")
        step = d.unexplained.get("step")
        if step is not None:
            unit, factor = _display_unit(step["channel"])
            lines.append(f"  a step in {step['channel']} of {step['size'] / factor:+.3g} {unit} between segment "
                         f"{step['between'][0]} {step['labels'][0]} and {step['between'][1]} {step['labels'][1]} "
                         f"(at about {step['at_s']:.0f} s; p = {_p(step['p_value'])})")
        outlier = d.unexplained.get("outlier")
        if outlier is not None:
            unit, factor = _display_unit(outlier["channel"])
            lines.append(f"  one segment off in {outlier['channel']}: segment {outlier['segment']} {outlier['label']} "
                         f"by {outlier['size'] / factor:+.3g} {unit} (at about {outlier['at_s']:.0f} s; "
                         f"p = {_p(outlier['p_value'])}; the largest leave-one-segment-out residual, the "
                         "between-segment noise re-estimated without it)")
        change = d.unexplained.get("change")
        if change is not None:
            spec = next(q for q in PARAMETERS if q.name == change["parameter"])
            by = f"{change['size'] / spec.display_factor:+.3g} {spec.display_unit}"
            if change.get("form") == "linear":
                lines.append(f"  {change['parameter']} drifting steadily through the run, by {by} from segment "
                             f"{change['between'][0]} {change['labels'][0]} to {change['between'][1]} "
                             f"{change['labels'][1]} (p = {_p(change['p_value'])})")
            else:
                lines.append(f"  a change of {change['parameter']} by {by} between segment {change['between'][0]} "
                             f"{change['labels'][0]} and {change['between'][1]} {change['labels'][1]} (at about "
                             f"{change['at_s']:.0f} s; p = {_p(change['p_value'])})")
    elif excess:
        lines.append(f"No lack of fit is flagged at segment level (p = {_p(after.p_value)}), but the tests cannot "
                     "see a slow effect here:")
    elif d.unexplained.get("stated_noise"):
        lines.append(f"The lack of fit, weighed against the noise estimated from this recording, flags nothing at "
                     f"segment level (p = {_p(after.p_value)}); against the stated noise:")
    else:
        lines.append(f"Nothing unexplained remains at segment level (p = {_p(after.p_value)})."
                     if after.dof > 0 else "Nothing at segment level could be tested (no degrees of freedom).")
    for item in excess:
        unit, factor = _display_unit(item["channel"])
        lines.append(f"  EXCESS SCATTER in {item['channel']}: its segment means scatter {item['ratio']:.3g} times what "
                     f"its samples predict ({item['between_sd'] / factor:.3g} against "
                     f"{item['predicted_sd'] / factor:.3g} {unit}, correlated over {item['correlation_time_s']:g} s)")
    taus = {item["correlation_time_s"] > 0 for item in excess}
    # a drift in temperature is a candidate where the recording logged a temperature that varied
    thermal = any(c.endswith("_T") for s in d.candidates if s.effect == "bias_drift" for c in s.components)
    if True in taus:
        advice = "repeat a pose at the end of the run, or " + (
            "let the temperature move further" if thermal else "log the temperature") + ", to tell them apart"
        if thermal and "bias_drift" not in d.selected:
            advice = ("the bias's drift in the logged temperature was tested beside its drift in time (the candidates "
                      "above) and is not significant: " + advice)
        lines.append("  correlated in time, taken up as slow noise: slow noise and a slow effect (a bias that follows "
                     "the temperature, a warm-up, a drift) look alike in this recording; " + advice)
    if False in taus:
        lines.append("  independent from segment to segment (correlated over 0 s): an input that differs from pose to "
                     "pose and that the model gets wrong (the site's latitude or gravity; the table's errors larger "
                     "than its grade" + ("; a turn by hand whose angle in the segment table is not what the hand "
                                         "turned: the fit takes it as exact" if d.before.hand_axes else "")
                     + ") or noise the segments cannot show")
    lines += _stated_lines(d)
    lines += _within_lines(d)
    if d.undithered:
        lines.append(f"Note: the segment means of {', '.join(d.undithered)} are mostly a quantiser's error that the "
                     "noise does not dither: a fixed function of each level, nearly the same in every repetition. "
                     "The tests on them hold their false-alarm rate over a population of units, not over this "
                     "recording's noise (docs/closing-the-loop.md, \"Undithered channels\").")
    lines += ["", "Candidates (first round; adjusted p: Westfall–Young min-p over the identifiable ones)",
              f"{'effect':25s} {'identifiable':>12s} {'dof':>4s} {'statistic':>10s} {'p':>9s} {'adjusted p':>10s}  "
              "aliased with / would be separated by"]
    for s in d.candidates:
        note = ", ".join(s.aliased_with)
        if not s.identifiable:
            note = (f"aliased with {note}; " if note else "") + f"separate it with {s.separating}"
        lines.append(f"{s.effect:25s} {'yes' if s.identifiable else 'no':>12s} {s.dof:>4d} {_g(s.statistic, 4):>10s} "
                     f"{_p(s.p_value):>9s} {_p(s.adjusted_p_value):>10s}  {note}")
    lines += ["", "Before and after (residual r.m.s. per channel; gyros deg/h, accelerometers ug)",
              f"{'':22s} " + " ".join(f"{c:>10s}" for c in CHANNELS)]
    for label, fit, hold in (("residual, before", d.before, d.holdout["before"]),
                             ("residual, after", d.after, d.holdout["after"])):
        values = []
        holdout = []
        for c in range(6):
            rows = fit.fitted_rows[:, c]
            rms = math.sqrt(float((fit.residuals[rows, c] ** 2).mean())) if rows.any() else math.nan
            factor = OUTPUT_UNITS[_kind(c)][1]
            values.append(_g(rms / factor, 3))
            holdout.append(_g(hold["rms"][CHANNELS[c]] / factor, 3))
        lines.append(f"{label:22s} " + " ".join(f"{v:>10s}" for v in values))
        lines.append(f"{label.replace('residual', 'held out'):22s} " + " ".join(f"{v:>10s}" for v in holdout))
    for label, fit in (("before", d.before), ("after", d.after)):
        ratio = fit.chi2 / fit.chi2_dof if fit.chi2_dof > 0 else math.nan
        info = d.information[label]
        lines.append(f"chi2/dof {label}: {_g(ratio, 4)} (AIC {_g(info['aic'], 5)}, BIC {_g(info['bic'], 5)}: "
                     "information only)")
    lines.append("chi2/dof: against the predicted noise without the noise between segments, every static segment "
                 "at its channel's noise (plansim fit gives a segment that scatters more its own scatter, so its "
                 "chi2/dof differs where segments scatter unequally); the lack of fit above is the test")
    skipped, partial = d.holdout["before"]["skipped"], d.holdout["before"]["partial"]
    lines.append(f"held out: {d.holdout['after']['scheme']}" + (
        f"; {partial} of {d.before.observed.shape[0]} segments held out in part (a pose placed by hand, or the only "
        "segment to identify a combination)" if partial else "") + (
        f"; {skipped} of {d.before.observed.shape[0]} segments cannot be held out at all" if skipped else ""))
    moved = absorbed(d)
    if d.selected:
        lines += ["", "Parameters that absorbed the effect (moved by more than their u): "
                  + (", ".join(moved) if moved else "none"),
                  f"{'name':8s} {'unit':>14s} {'before':>14s} {'after':>14s} {'u after':>10s}"]
        for k, p in enumerate(PARAMETERS):
            if p.name not in moved:
                continue
            f = p.display_factor
            lines.append(f"{p.name:8s} {p.display_unit:>14s} {_g(d.before.joint.estimate[k] / f, 8):>14s} "
                         f"{_g(d.after.joint.estimate[k] / f, 8):>14s} {_g(d.after.joint.u[k] / f, 3):>10s}")
    weak = d.after.weakly_determined
    if weak:
        lines += ["", "Determined only weakly (identified, but u beyond what a data sheet already says; read them as "
                  "not determined): " + ", ".join(weak)]
    return "\n".join(lines)
