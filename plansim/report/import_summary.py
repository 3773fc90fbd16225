"""What ``plansim import`` prints: the import's findings as text, every number with its unit.

The last part of ``plansim import`` (:mod:`plansim.io.log_table` reads the table, :mod:`plansim.io.log_pairing`
pairs two sensors sampled apart, :mod:`plansim.io.log_import` cuts it into segments and makes the recording).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.io.log_import import ImportResult, table_source
from plansim.io.recording_data import CHANNELS


def format_summary(result: ImportResult) -> str:
    """The import's findings as text, every number with its unit (what ``plansim import`` prints)."""
    table, timing, seg = result.table, result.timing, result.segmentation
    rec = result.recording
    lines = [f"plansim import {table.path.name}: {rec.samples.shape[0]} samples"]
    unit_text = ", ".join(dict.fromkeys(result.units))
    source = rec.schedule.import_notes.get("units_source", "")
    if source.startswith("the log's"):
        unit_text += f", as {source} writes them"
    if result.scale is not None:
        unit_text = "counts: " + ", ".join(f"{c:g}/{u}" for c, u in zip(result.scale, result.units))
        if result.offset is not None:
            unit_text += " after subtracting " + ", ".join(f"{c:g}" for c in result.offset) + " counts (--offset)"
    lines.append("  channels: " + " ".join(f"{c}={'-' if c in result.reversed_channels else ''}{n}"
                                           for c, n in zip(CHANNELS, table.names)) + f" ({unit_text})"
                 + (f"; ignored: {', '.join(table.ignored)}" if table.ignored else ""))
    for note in table.pairing:
        lines.append(f"  two logs: {note}")
    if not table.has_header:
        lines.append(f"  no header line: columns named by position, 1 for the first (first sample on line "
                     f"{table.first_line})")
    if table.decimal_comma:
        lines.append("  numbers with a decimal comma (0,123) read as such: the values are separated by ';' or tabs")
    if table.preamble:
        shown = "; ".join(table.preamble[:4]) + ("; …" if len(table.preamble) > 4 else "")
        where = f"the header (line {table.header_line})" if table.has_header else f"line {table.first_line}"
        lines.append(f"  before {where}: {len(table.preamble)} line(s) skipped, not read as data: {shown}")
    if table.clock_start is not None:
        lines.append(f"  time: column {table.time_column!r} holds clock times, read in seconds from the first "
                     f"({table.clock_start})")
    if table.time is None:
        lines.append(f"  sample rate: {timing.sample_rate:.6g} Hz (given; no time column: gaps and jitter cannot be "
                     "seen)")
    else:
        lines.append(f"  sample rate: {timing.sample_rate:.6g} Hz (from column {table.time_column!r}: "
                     f"{timing.estimated_rate:.6g} Hz); jitter {timing.jitter_rms:.3g} s RMS, "
                     f"{timing.jitter_max:.3g} s at most; {len(timing.gaps)} gap(s), {timing.missing_samples} "
                     "sample(s) missing")
    noise = seg.noise
    gyro = " ".join(f"{c} {math.degrees(v):.3g}" for c, v in zip(CHANNELS[:3], noise.sigma[:3]))
    accel = " ".join(f"{c} {v:.3g}" for c, v in zip(CHANNELS[3:], noise.sigma[3:]))
    density = " ".join(f"{c} {math.degrees(v) * 60.0 / math.sqrt(timing.sample_rate):.3g}"
                       for c, v in zip(CHANNELS[:3], noise.sigma[:3]))
    lines.append(f"  noise per sample (quiet stretch, lines {table.lines[noise.start]}-{table.lines[noise.stop - 1]}): "
                 f"{gyro} deg/s; {accel} m/s^2 (as white noise: {density} deg/sqrt(h))")
    correlated = [(name, rho) for name, rho in zip(CHANNELS, result.correlation) if len(rho)]
    if correlated:
        first = [float(rho[0]) for _, rho in correlated]
        lags = [len(rho) for _, rho in correlated]
        # a long mean's variance is (1 + 2 Σ ρ_k) times the white-noise figure from the per-sample sd
        factors = [1.0 + 2.0 * float(np.sum(rho)) for _, rho in correlated]
        cause = ("the part's own low-pass filter, or a log resampled by its host" if min(first) > 0 else
                 "negative: neighbouring samples partly cancel" if max(first) < 0 else
                 "positive: the part's low-pass filter or a resampling host; negative: neighbours partly cancel")
        verb = ("understate" if min(factors) > 1 else "overstate" if max(factors) < 1 else
                "understate or overstate")
        lines.append(f"  noise correlated from one sample to the next in {' '.join(n for n, _ in correlated)} (lag-one "
                     f"autocorrelation {min(first):.2g} to {max(first):.2g}, over {min(lags)} to {max(lags)} "
                     "sample(s), pooled over the static poses of the channel's quiet scatter, as plansim fit reads it: "
                     f"{cause}): the per-sample figures above {verb} a segment mean's noise (its variance "
                     f"{min(factors):.2g} to {max(factors):.2g} times theirs, 1 + 2 sum of the autocorrelations); "
                     "plansim fit models the correlation (docs/fitting.md)")
    rate = " ".join(f"{math.degrees(v):.3g}" for v in seg.rate_threshold)
    lines.append(f"  at rest: variance ratios <= {seg.variance_threshold[0]:.3g} (accelerometers), "
                 f"{seg.variance_threshold[1]:.3g} (gyros) over {seg.window} samples "
                 f"({seg.window / timing.sample_rate:.3g} s), for at least {seg.min_static / timing.sample_rate:.3g} "
                 f"s; a quiet stretch turning faster than {rate} deg/s (x y z) is a steady turn (--window, "
                 "--min-static and --rest-variance change these: a pose noisier than the quiet stretch above needs "
                 "--rest-variance)")
    counts = {kind: len(seg.of_kind(kind)) for kind in ("static", "rotation", "move")}
    lines.append(f"  segments: {counts['static']} static, {counts['rotation']} rotation, {counts['move']} move")
    lines.append(f"  {'#':>3}  {'test':8s}  {'lines':>13s}  {'duration':>9s}  label")
    for k, (span, segment) in enumerate(zip(seg.spans, rec.schedule.segments)):
        rows = f"{table.lines[span.start]}-{table.lines[span.stop - 1]}"
        lines.append(f"  {k:3d}  {segment.test:8s}  {rows:>13s}  {span.samples / timing.sample_rate:7.2f} s  "
                     f"{segment.label}")
    if rec.schedule.import_notes.get("poses") == "table":
        statics = [s for s in rec.schedule.segments if s.test == "static"]
        on_table = sum(s.orientation == "known" for s in statics)
        lines.append(f"  poses: set by a table (--poses table): orientation = known for {on_table} of the "
                     f"{len(statics)} static poses and for the turns about the vertical, to the table's grade; "
                     "heading = nan (not logged)")
    else:
        lines.append("  heading: not known (a plain log has no heading reference): heading = nan, orientation = "
                     "approximate for the static poses (placed by hand; --poses table if a table set them)")
    rotations = seg.of_kind("rotation")
    between = [r for r in rotations if not math.isfinite(r.steady_rate)]
    by_table = [r for r in between if math.isfinite(r.table_turned)]
    if by_table:
        lines.append(f"  rotations: angle = the table's turn from rest to rest ({table_source(table, 'angle')}, "
                     f"signed as the gyros measured the turn) for {len(by_table)} of {len(between)}; rate = nan")
    if len(by_table) < len(between):
        lines.append("  rotations: angle = the whole number of quarter turns nearest the measured integral (bias "
                     "removed); check it against what was done; rate = nan (not logged)")
    steady = [k for k, r in enumerate(seg.spans) if r.kind == "rotation" and math.isfinite(r.steady_rate)]
    given = [k for k in steady if math.isfinite(rec.schedule.segments[k].rate)]
    if given:
        lines.append(f"  steady turns: rate from {table_source(table)} (its mean over each segment, signed as the "
                     f"gyros measured the turn) for {len(given)} of {len(steady)}; angle = nan; the moves beside "
                     "them are the table's spin-up and stop")
    if len(given) < len(steady):
        lines.append("  steady turns: angle = nan and rate = nan (a table's rate is not in the log): give each one "
                     "the rate the table held for the fit to use it (in the segment table, rate_deg_s and "
                     "rate_rad_s, or one of them with the other column deleted); the moves beside them are the "
                     "table's spin-up and stop")
    for warning in result.warnings:
        lines.append(f"  warning [{warning.name}]: {warning.message}")
    return "\n".join(lines)

