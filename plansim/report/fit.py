"""The text report of ``plansim fit``: identifiability, estimates, noise, residuals, χ²/dof, repeated settings.

Numbers in display units, each with its unit: parameters in their display units
(:mod:`plansim.model.parameters`), gyro outputs in °/h, accelerometer outputs in µg, white noise in
°/√h and µg/√Hz, bias instability in °/h and µg.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.fit.identify import DATA_SHEET_CONFLICT_ALPHA, describe_conflict
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETERS
from plansim.units import KINDS

#: display unit of a segment mean (and of a residual, a bias instability) per sensor kind, and its SI factor
OUTPUT_UNITS = {"gyro": ("deg/h", KINDS["angular_rate"]["deg/h"]), "accel": ("ug", KINDS["acceleration"]["ug"])}
#: a residual's u below this fraction of its segment mean's own u is a rounding error (the fit passes through the
#: row): the residual is not marked
EXACT_ROW = 1e-6
WHITE_UNITS = {"gyro": ("deg/sqrt(h)", KINDS["angle_random_walk"]["deg/sqrt(h)"]),
               "accel": ("ug/sqrt(Hz)", KINDS["velocity_random_walk"]["ug/sqrt(Hz)"])}


def _kind(channel: int) -> str:
    return "gyro" if channel < 3 else "accel"


def _g(value: float, digits: int = 4) -> str:
    return "nan" if value is None or not math.isfinite(value) else f"{value:.{digits}g}"


def _dof(value: float) -> str:
    """Effective degrees of freedom: beyond 10⁴ the t-factor equals the normal one to 1e-4, so '>1e4'."""
    return ">1e4" if value > 1e4 else _g(value, 3)


def fit_report(result, residuals: bool = True) -> str:
    """The whole report of a :class:`plansim.fit.joint.FitResult` as text."""
    attrs = result.attrs
    lines = [f"plansim fit — recording of {attrs.get('source', 'unknown')} data"
             + (f", scenario {attrs['scenario']!r} (seed {attrs.get('seed')}, trial {attrs.get('trial')})"
                if "scenario" in attrs else ""),
             f"site: {result.site.describe()}",
             f"turntable and fixture errors (Type B): {result.turntable_source}",
             f"segments: {len(result.used)} fitted, {len(result.unused)} not used"]
    for k, reason in result.unused.items():
        lines.append(f"  segment {k}: {reason}")
    lines += ["", f"Identified by the segments: {len(result.identified)} of {len(PARAMETERS)} parameters "
              f"(rank {result.identifiability.rank})",
              "  " + (" ".join(result.identified) if result.identified else "none")]
    if result.not_identified:
        lines.append("Not identified (reported as nan, never given a value):")
        by_reason: dict[str, list[str]] = {}
        for name, reason in result.not_identified.items():
            by_reason.setdefault(reason, []).append(name)
        for reason, names in by_reason.items():
            lines.append(f"  {' '.join(names)}: {reason}")

    weak = result.weakly_determined
    if weak:
        lines.append("Determined only weakly (estimate and u below, but read them as not determined):")
        for name, reason in weak.items():
            lines.append(f"  {name}: {reason}")

    lines += ["", "Parameters (display units; u = standard uncertainty, nu = effective degrees of freedom)"]
    head = f"{'name':6s} {'unit':>13s} {'joint WLS':>14s} {'u':>10s} {'nu':>7s}"
    if result.spec is not None:
        head += f" {'JJF 2003 eq.':>14s} {'u':>10s} {'spec bias':>10s}"
    moves = result.moves
    if moves is not None:
        head += f" {'moves':>14s} {'u':>10s} {'nu':>7s}"
    lines.append(head)
    for k, p in enumerate(PARAMETERS):
        f = p.display_factor
        row = (f"{p.name:6s} {p.display_unit:>13s} {_g(result.joint.estimate[k] / f, 8):>14s} "
               f"{_g(result.joint.u[k] / f, 3):>10s} {_dof(result.joint.dof[k]):>7s}")
        if result.spec is not None:
            bias = result.spec_bias[k]
            bias = 0.0 if abs(bias) < 1e-6 * result.spec.u[k] else bias  # rounding of (M·J − I)·θ
            row += (f" {_g(result.spec.estimate[k] / f, 8):>14s} {_g(result.spec.u[k] / f, 3):>10s} "
                    f"{_g(bias / f, 3):>10s}")
        if moves is not None:
            mark = "~" if p.name in moves.relative else " "
            row += (f" {_g(moves.method.estimate[k] / f, 8):>13s}{mark} {_g(moves.method.u[k] / f, 3):>10s} "
                    f"{_dof(moves.method.dof[k]):>7s}")
        lines.append(row)
    if result.spec is not None:
        lines.append(f"JJF 2003 eq.: the specification's estimators ({result.spec.note}); spec bias = their expected "
                     "error at the joint estimate (the site's Earth rate, which eq. (7) and (8) do not model)")
    else:
        lines.append(f"The specification's estimators: not run — {result.spec_note}")
    if moves is not None:
        lines.append("moves: the gyros from the moves between poses (the gravity sequence, Tedaldi et al. 2014; "
                     "below)" + ("; ~ = relative to the accelerometer triad (the frame where Ka is symmetric), not "
                                 "the case" if moves.relative else ""))
    if result.shear:
        lines += ["", "Accelerometer triad's shear (poses placed by hand): the symmetric part of each pair of Ka's "
                      "cross-couplings; the antisymmetric part is a rotation of the triad, which no hand-placed pose "
                      "fixes"]
        for item in result.shear:
            lines.append(f"  {item.name:18s} {_g(item.estimate, 6):>12s} u {_g(item.u, 3):>9s}"
                         if item.determined else
                         f"  {item.name:18s} held at 0, u {_g(item.u, 3)} (Type B: the poses, near their axes, do "
                         "not determine it)")
    budget = result.joint.contributions
    if budget:
        lines.append("The joint fit's u comes from these kinds of input: " + ", ".join(budget)
                     + " (each one's part per parameter in the --out file: u_joint_wls_<kind>)")

    lines += ["", "Noise from the data (Allan deviation of the static segments, IEEE Std 952 fit)"]
    for c, ch in enumerate(result.noise.channels):
        kind = _kind(c)
        wu, wf = WHITE_UNITS[kind]
        ou, of = OUTPUT_UNITS[kind]
        step = (f"quantisation step {_g(ch.quantisation_step / of, 4)} {ou}" if ch.quantisation_step > 0
                else "not quantised")
        lines.append(f"  {ch.channel}: white N = {_g(ch.white / wf, 3)} {wu}, bias instability B = "
                     f"{_g(ch.bias_instability / of, 3)} {ou}, rate random walk K = {_g(ch.rate_random_walk / of, 3)} "
                     f"{ou}/sqrt(s), {step} ({ch.static_segments} static segments)")

    if result.placed:
        lines += ["", "Poses placed by hand: fitted tilt from the nominal pose (about East, North; deg)"]
        for k, (east, north) in zip(result.placed, result.tilts):
            lines.append(f"  segment {k}: {math.degrees(east):+.3f} {math.degrees(north):+.3f}")

    if result.hand_axes:
        lines += ["", "Turns by hand: fitted misalignment of the turned axis (two small angles; deg)"]
        for axis, (first, second) in zip(result.hand_axes, result.axis_tilts):
            lines.append(f"  about {'xyz'[axis]}: {math.degrees(first):+.3f} {math.degrees(second):+.3f}")

    if moves is not None:
        lines += _moves_section(result, moves, residuals)

    between = result.between_noise
    if between is not None and np.any(between.variance > 0):
        lines += ["", "Noise between segments beyond the within-segment model (from the residuals; slow noise such "
                  "as a bias instability longer than a segment): a Type A input of every u above"]
        for c in np.flatnonzero(between.variance > 0):
            unit, factor = OUTPUT_UNITS[_kind(c)]
            tau = between.correlation_time[c]
            lines.append(f"  {CHANNELS[c]}: sd = {_g(math.sqrt(between.variance[c]) / factor, 3)} {unit}, "
                         + (f"correlated over {tau:g} s" if tau > 0 else "independent between segments")
                         + f", nu = {_dof(between.dof[c])}")

    ratio = result.chi2 / result.chi2_dof if result.chi2_dof > 0 else math.nan
    lines += ["", f"chi2/dof = {_g(result.chi2, 5)}/{result.chi2_dof} = {_g(ratio, 4)}: {result.chi2_verdict}"]
    if result.data_sheet_conflict:
        tested = len(result.data_sheet_conflict)
        lines += ["", "The data against the data sheet the fit carried as a prior, per group (the fall of the fit's "
                  "objective without that group's prior; contradicted where p < "
                  f"{DATA_SHEET_CONFLICT_ALPHA:g}/{tested})"]
        for group, entry in result.data_sheet_conflict.items():
            lines.append(f"  {group:3s} {describe_conflict(entry)}")
    if result.between:
        lines += ["", "Repeated settings (same up-axis and rate, any heading): scatter of the residuals between "
                  "segments, data against the prediction (noise model + per-setting Type B)",
                  f"{'channel':7s} {'groups':>6s} {'dof':>4s} {'data sd':>10s} {'predicted':>10s} {'noise':>10s} "
                  f"{'table':>10s} {'component':>10s} {'unit':>6s}  verdict"]
        for b in result.between:
            c = CHANNELS.index(b.channel)
            ou, of = OUTPUT_UNITS[_kind(c)]
            lines.append(f"{b.channel:7s} {b.groups:>6d} {b.dof:>4d} {_g(b.observed_sd / of, 3):>10s} "
                         f"{_g(b.predicted_sd / of, 3):>10s} {_g(b.predicted_noise_sd / of, 3):>10s} "
                         f"{_g(b.predicted_table_sd / of, 3):>10s} {_g(b.component_sd / of, 3):>10s} {ou:>6s}  "
                         f"{b.verdict}")
        lines.append("component = between-segment standard deviation in the data beyond the noise model; "
                     "table = what the turntable's per-setting errors predict")
    if residuals:
        gu, gf = OUTPUT_UNITS["gyro"]
        au, af = OUTPUT_UNITS["accel"]
        lines += ["", f"Residuals = observed − fitted segment mean (gyros {gu}, accelerometers {au}); "
                  "|r|/u > 3 marked *",
                  f"{'seg':>4s} {'label':34s} " + " ".join(f"{c:>10s}" for c in CHANNELS)]
        # a residual whose u is a rounding error of the mean's own (the fit leaves that row no degrees of freedom:
        # it passes through it) is not marked, however small the residual
        own = np.sqrt(np.maximum(np.diag(np.asarray(result.covariance, dtype=float)), 0.0)).reshape(
            result.residuals.shape) if result.covariance is not None else np.zeros(result.residuals.shape)
        for s, k in enumerate(result.used):
            cells = []
            for c in range(6):
                factor = gf if c < 3 else af
                r, u = result.residuals[s, c], result.residual_sd[s, c]
                u = u if u > EXACT_ROW * own[s, c] else 0.0
                if not result.fitted_rows[s, c]:
                    cells.append(f"{'-':>9s} ")  # not fitted (a hand turn's accelerometer)
                    continue
                mark = "*" if u > 0 and abs(r) > 3 * u else " "
                cells.append(f"{_g(r / factor, 3):>9s}{mark}")
            lines.append(f"{k:>4d} {result.labels[s][:34]:34s} " + " ".join(cells))
    if result.notes:
        lines += [""] + [f"note: {n}" for n in result.notes]
    return "\n".join(lines)


def _moves_section(result, moves, residuals: bool) -> list[str]:
    """The gravity sequence: which motions between poses were used, χ², the noise between moves, the residuals."""
    lines = ["", f"Moves between poses (the gyros from the gravity sequence): {len(moves.transitions)} used, "
             f"{len(moves.unused)} not"]
    for where, reason in moves.unused.items():
        lines.append(f"  {where}: {reason}")
    ratio = moves.chi2 / moves.chi2_dof if moves.chi2_dof > 0 else math.nan
    lines.append(f"  chi2/dof = {_g(moves.chi2, 5)}/{moves.chi2_dof} = {_g(ratio, 4)}: {moves.chi2_verdict}")
    if moves.between_sd > 0:
        lines.append(f"  noise between moves beyond the prediction (from their residuals): "
                     f"{_g(math.degrees(moves.between_sd), 3)} deg per component, a Type A input of every u")
    for name, reason in moves.relative.items():
        lines.append(f"  {name}: {reason}")
        break  # one sentence says it for all of them
    if residuals:
        lines += [f"  {'move':>4s} {'from':>5s} {'to':>5s} {'seconds':>8s} {'turned':>8s} "
                  f"{'residual across gravity':>25s} {'u':>15s}  (deg)"]
        for m, t in enumerate(moves.transitions):
            r = np.degrees(moves.residual[m])
            u = np.degrees(moves.residual_sd[m])
            flag = " *" if np.any(np.abs(moves.residual[m]) > 3 * moves.residual_sd[m]) else ""
            lines.append(f"  {m:>4d} {t.before:>5d} {t.after:>5d} {moves.duration[m]:8.2f} "
                         f"{math.degrees(moves.angle[m]):8.1f} {r[0]:+12.4f} {r[1]:+12.4f} {u[0]:7.4f} "
                         f"{u[1]:7.4f}{flag}")
    return lines
