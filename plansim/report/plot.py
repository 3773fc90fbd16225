"""Figures: where a person would rather look than read."""

from __future__ import annotations

import math
import os

import numpy as np

from plansim.io.files import atomic_write
from plansim.uncertainty.appendix_a import APPENDIX_A, errors_in_reading_units

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def figure_format(path: str | os.PathLike, format: str | None = None) -> str:
    """The figure format of *path* (``"png"``, ``"pdf"`` or ``"svg"``): *format* if given, else its suffix.

    Raises
    ------
    ValueError
        The format (or the suffix) is not one of :data:`FIGURE_SUFFIXES`.
    """
    chosen = (format if format is not None else os.path.splitext(os.fspath(path))[1]).lower().lstrip(".")
    if f".{chosen}" not in FIGURE_SUFFIXES:
        given = f"format = {format!r}" if format is not None else f"figure {os.fspath(path)!r}"
        raise ValueError(f"{given}: the figure format must be one of {', '.join(s[1:] for s in FIGURE_SUFFIXES)}")
    return chosen


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend (imported only when a figure is drawn)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path: str | os.PathLike, format: str, dpi: int) -> None:
    """Write *fig* to *path* whole or not at all (:func:`plansim.io.files.atomic_write`), then close it."""
    try:
        atomic_write(path, lambda tmp: fig.savefig(tmp, format=format, dpi=dpi))
    finally:
        pyplot().close(fig)


def appendix_a_histograms(results, scenario, comparisons, path: str | os.PathLike, format: str | None = None) -> None:
    """Histogram of |error| of each Appendix A quantity (in its reading, log axis), the claimed U and the MC 95 % point.

    Parameters
    ----------
    results : xarray.Dataset
        A run's per-trial results (:func:`plansim.runner.run`), at least 2 trials.
    scenario : plansim.config.Scenario
        The run's scenario (the readings of A.2, A.3 and A.5 depend on its ranges).
    comparisons : list of plansim.uncertainty.ItemComparison
        The Appendix A comparison of the same results.
    path : str or os.PathLike
        The figure file, written whole or not at all (:func:`plansim.io.files.atomic_write`).
    format : {"png", "pdf", "svg"}, optional
        Default: from the suffix of *path*; give it when *path* is a temporary file
        (:class:`plansim.io.files.OutputSet`).
    """
    chosen = figure_format(path, format)
    plt = pyplot()

    by_item = {c.item: c for c in comparisons}
    fig, axes = plt.subplots(1, len(APPENDIX_A), figsize=(3.4 * len(APPENDIX_A), 3.4), constrained_layout=True)
    for ax, budget in zip(np.atleast_1d(axes), APPENDIX_A):
        c = by_item[budget.item]
        pooled = np.abs(np.concatenate([
            errors_in_reading_units(budget, name, results["error"].sel(parameter=name).values, scenario,
                                    truth=results["truth"].sel(parameter=name).values)
            for name in budget.parameters]))
        # |error| on a log axis: the claimed U and the achieved spread can differ by orders of magnitude
        positive = pooled[pooled > 0]
        low = min(positive.min() if positive.size else c.budget_U * 1e-3, c.budget_U) / 2
        high = max(pooled.max(), c.budget_U) * 2
        ax.hist(pooled, bins=np.geomspace(low, high, 60), color="0.6")
        ax.set_xscale("log")
        ax.axvline(c.budget_U, color="tab:red", ls="--", label="claimed U (k = 2)")
        ax.axvline(c.mc_U95, color="tab:blue", ls=":", label="MC: 95 % of |error| below")
        short = budget.quantity.split(" (")[0]
        ax.set_title(f"{budget.item} {short}\n{c.coverage:.1%} of |error| ≤ U; {c.verdict}", fontsize=8)
        ax.set_xlabel(f"|error| in {c.reading_unit.split(' (')[0]}", fontsize=8)
        ax.tick_params(labelsize=7)
    np.atleast_1d(axes)[0].set_ylabel("trials × parameters")
    np.atleast_1d(axes)[0].legend(fontsize=7, loc="upper left")
    fig.suptitle(f"plansim: {results.attrs['scenario']} — {results.attrs['trials']} trials, seed "
                 f"{results.attrs['seed']}: JJF 2003 Appendix A claims vs Monte Carlo", fontsize=10)
    save(fig, path, chosen, dpi=120)


def _residual_panels(fit, series, title: str):
    """A 2 × 6 grid of a fit's segment-mean residuals per channel: top row against the channel's own reading,
    bottom row against time. *series*: ``(residuals (S, 6) SI, error bar (S, 6) SI or None, label, style)``, drawn
    in order; the scale of each panel is set by the residuals, a bar far longer cut at 1.6 times the largest
    residual. Returns the figure."""
    from plansim.kernels.layout import CHANNELS
    from plansim.report.fit import OUTPUT_UNITS

    plt = pyplot()
    times = np.asarray(fit.segment_times, dtype=float)
    reading_units = {"gyro": ("deg/s", np.pi / 180.0), "accel": ("m/s^2", 1.0)}
    fig, axes = plt.subplots(2, 6, figsize=(19, 6.4), constrained_layout=True)
    rows_all = np.asarray(fit.fitted_rows, dtype=bool)
    for c, name in enumerate(CHANNELS):
        kind = "gyro" if c < 3 else "accel"
        unit, factor = OUTPUT_UNITS[kind]
        reading_unit, reading_factor = reading_units[kind]
        rows = rows_all[:, c]
        reading = np.asarray(fit.observed[:, c], dtype=float) / reading_factor
        for ax, x, label in ((axes[0, c], reading, f"{name} reading ({reading_unit})"),
                             (axes[1, c], times, "time (s)")):
            ax.axhline(0.0, color="0.7", lw=0.8)
            for residuals, bar, name_of, style in series:
                y = np.asarray(residuals)[rows, c] / factor
                if bar is None:
                    ax.plot(x[rows], y, "o", label=name_of, **style)
                else:
                    ax.errorbar(x[rows], y, yerr=np.asarray(bar)[rows, c] / factor, fmt="o", label=name_of,
                                **style)
            ax.set_xlabel(label, fontsize=8)
            ax.tick_params(labelsize=7)
            # the residuals set the scale; a bar far longer (a turn by hand, known only by its angle) is cut
            spread = np.nanmax(np.abs(np.concatenate([np.asarray(r)[rows, c] for r, *_ in series])),
                               initial=0.0) / factor
            if spread > 0:
                ax.set_ylim(-1.6 * spread, 1.6 * spread)
        axes[0, c].set_title(name, fontsize=9)
        axes[0, c].set_ylabel(f"residual ({unit})", fontsize=8)
        axes[1, c].set_ylabel(f"residual ({unit})", fontsize=8)
    axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(title, fontsize=10)
    return fig


def diagnosis_figure(diagnosis, path: str | os.PathLike, format: str | None = None) -> None:
    """Residuals of the segment means before and after the refit, per channel, against what effects depend on.

    Top row: against the channel's own reading (a gyro's segment mean is the rate ω it turns at, an
    accelerometer's the specific force f along it), where a scale asymmetry, a nonlinearity or a K2 term shows
    as a V, a curve or a parabola. Bottom row: against time, where a drift shows as a slope and a step as a
    jump. Residuals in °/h and µg (:data:`plansim.report.fit.OUTPUT_UNITS`), the bars ±2u of each segment
    mean (the fit's V: noise, quantisation, table errors, noise between segments), cut at 1.6 times the
    largest residual. Open grey: before; filled: after the selected
    effects (the same points when none is).

    Parameters
    ----------
    diagnosis : plansim.diagnose.procedure.Diagnosis
    path : str or os.PathLike
        The figure file, written whole or not at all (:func:`plansim.io.files.atomic_write`).
    format : {"png", "pdf", "svg"}, optional
        Default: from the suffix of *path*.
    """
    chosen = figure_format(path, format)
    before, after = diagnosis.before, diagnosis.after
    u = np.sqrt(np.maximum(np.diag(after.covariance), 0.0)).reshape(-1, 6)
    found = ", ".join(diagnosis.selected) if diagnosis.selected else "no catalogue effect"
    verdict = "unexplained residual remains" if diagnosis.unexplained.get("flagged") else "no lack of fit remains"
    fig = _residual_panels(before, [
        (before.residuals, None, "before", dict(mfc="none", mec="0.55", ms=4)),
        (after.residuals, 2.0 * u, "after (±2u)", dict(ms=3, color="tab:blue", ecolor="tab:blue", elinewidth=0.6,
                                                        alpha=0.8))],
        f"plansim diagnose: found {found}; {verdict} (family-wise alpha = {diagnosis.alpha:g})")
    save(fig, path, chosen, dpi=110)


def fit_figure(result, path: str | os.PathLike, format: str | None = None) -> None:
    """A fit's residuals (observed − fitted segment mean) per channel, with ±2 standard deviations of each
    residual (``residual_sd``: the noise model's prediction less what the fit itself takes up), against the
    channel's own reading (top: a scale asymmetry shows as a V, a nonlinearity as a curve, a K2 term as a
    parabola) and against time (bottom: a drift as a slope, a step as a jump, a warm-up as a decay). Points
    beyond 3 standard deviations are red, as the report marks them with ``*``. Residuals in °/h and µg.

    Parameters
    ----------
    result : plansim.fit.FitResult
    path : str or os.PathLike
        The figure file, written whole or not at all (:func:`plansim.io.files.atomic_write`).
    format : {"png", "pdf", "svg"}, optional
        Default: from the suffix of *path*.
    """
    chosen = figure_format(path, format)
    save(draw_fit(result), path, chosen, dpi=110)


def draw_fit(result):
    """The figure of :func:`fit_figure`, not saved."""
    sd = np.asarray(result.residual_sd, dtype=float)
    residuals = np.asarray(result.residuals, dtype=float)
    far = np.abs(residuals) > 3.0 * sd
    inside = np.where(far, np.nan, residuals)
    outside = np.where(far, residuals, np.nan)
    ratio = result.chi2 / result.chi2_dof if result.chi2_dof > 0 else math.nan
    return _residual_panels(result, [
        (inside, 2.0 * sd, "residual (±2 sd)", dict(ms=3, color="tab:blue", ecolor="tab:blue", elinewidth=0.6,
                                                      alpha=0.8)),
        (outside, 2.0 * sd, "beyond 3 sd", dict(ms=4, color="tab:red", ecolor="tab:red", elinewidth=0.6))],
        f"plansim fit: residual = observed - fitted segment mean; chi2/dof = {result.chi2:.5g}/{result.chi2_dof} "
        f"= {ratio:.4g} ({result.chi2_verdict})")


def sweep_figure(sweep, path: str | os.PathLike, format: str | None = None) -> None:
    """Uncertainty against table time, one panel per parameter group, the Pareto front marked.

    Each point is a cell of the sweep: its ``table_time_s`` (minutes) and ``u_group`` (the largest
    standard uncertainty of the group's parameters, in the group's display unit). Filled: the schedule
    follows JJF 2003 §7.2 (``compliant_jjf2003``); open: it does not. The Pareto front (``pareto``: no
    other cell is as short and as good, and better in one) is joined by a line, and its cells are
    labelled with their coordinates. With a Monte Carlo, grey bars are ±1 standard error of each u_mc
    (u/√(2(n−1)), n trials): where the group's u hardly changes across the grid, the front follows that
    scatter and says nothing.

    Parameters
    ----------
    sweep : xarray.Dataset
        The output of :func:`plansim.planning.sweep.sweep` (or its NetCDF file, opened).
    path : str or os.PathLike
        The figure file, written whole or not at all (:func:`plansim.io.files.atomic_write`).
    format : {"png", "pdf", "svg"}, optional
        Default: from the suffix of *path*.
    """
    from plansim.model.parameters import group_spec

    chosen = figure_format(path, format)
    plt = pyplot()

    grid_dims = [d for d in sweep["table_time_s"].dims]
    stacked = sweep[["table_time_s", "u_group", "pareto", "compliant_jjf2003"]].stack(cell=grid_dims) \
        if grid_dims else sweep.expand_dims(cell=[0])
    minutes = stacked["table_time_s"].values / 60.0
    compliant = stacked["compliant_jjf2003"].values.astype(bool)
    labels = []
    for k in range(stacked.sizes["cell"]):
        labels.append(", ".join(f"{d.split('.')[-1]}={stacked[d].values[k]}" for d in grid_dims))
    labels = [label.replace("positions=", "pos=") for label in labels]
    groups = [str(g) for g in sweep["group"].values]
    trials = int(sweep.attrs.get("trials_per_cell", 0))
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5), constrained_layout=True)
    for ax, group in zip(axes.ravel(), groups):
        spec = group_spec(group)
        unit, factor = spec.display_unit, spec.display_factor
        u = stacked["u_group"].sel(group=group).values / factor
        front = stacked["pareto"].sel(group=group).values.astype(bool)
        if trials > 1:  # the Monte Carlo's own scatter: the standard error of a standard deviation, u/√(2(n−1))
            ax.errorbar(minutes, u, yerr=u / np.sqrt(2.0 * (trials - 1)), fmt="none", ecolor="0.6", elinewidth=0.8)
        ax.plot(minutes[compliant], u[compliant], "o", color="tab:blue", ms=5, label="JJF 2003 §7.2 compliant")
        ax.plot(minutes[~compliant], u[~compliant], "o", mfc="none", mec="tab:blue", ms=5, label="not compliant")
        order = np.argsort(minutes[front])
        ax.plot(minutes[front][order], u[front][order], "-", color="tab:red", lw=1.2, label="Pareto front")
        ax.plot(minutes[front], u[front], "s", mfc="none", mec="tab:red", ms=8)
        for x, y, text in zip(minutes[front], u[front], np.array(labels, dtype=object)[front]):
            ax.annotate(text, (x, y), fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set_title(f"{group}: largest {'u_mc' if 'u_mc' in sweep else 'u_predicted'} of the group", fontsize=9)
        ax.set_xlabel("table time (min)", fontsize=8)
        ax.set_ylabel(f"u ({unit})", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(f"plansim sweep of {sweep.attrs.get('scenario', '?')}: "
                 + (f"{trials} Monte Carlo trials per cell" if trials > 1 else "the prediction (GUM) only"),
                 fontsize=10)
    save(fig, path, chosen, dpi=110)


def sweep_jjf1535_figure(sweep, path: str | os.PathLike, items=None, targets=None, format: str | None = None) -> None:
    """``plansim sweep jjf1535 --plot``: per item, its 95 % |error| (or the reported figure's standard deviation
    where it has no true value) against the session's length, one point per cell, labelled with the cell's fields;
    a target drawn as a dashed line.

    Parameters
    ----------
    sweep : xarray.Dataset
        :func:`plansim.planning.jjf1535_sweep.sweep_jjf1535`'s output (or its NetCDF file, opened).
    path : str or os.PathLike
        The figure file, written whole or not at all.
    items : list of str, optional
        The items drawn (default :data:`plansim.report.jjf1535.SWEEP_ITEMS`).
    targets : dict, optional
        item → target, SI.
    format : {"png", "pdf", "svg"}, optional
    """
    from plansim.estimate.jjf1535_items import ITEMS
    from plansim.report.jjf1535 import SWEEP_ITEMS, cell_fields, compared_value, sweep_cells

    chosen = figure_format(path, format)
    plt = pyplot()
    items = list(items or SWEEP_ITEMS)
    targets = targets or {}
    columns = min(3, len(items))
    rows = math.ceil(len(items) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.3 * columns, 3.4 * rows), constrained_layout=True,
                             squeeze=False)
    for ax, item in zip(axes.ravel(), items):
        scale, unit = ITEMS[item][3], ITEMS[item][2]
        hours, values, labels, kind = [], [], [], "U95"
        for _, index, where in sweep_cells(sweep):
            value, kind = compared_value(sweep, where, item)
            hours.append(float(sweep["session_hours"].isel(where)))
            values.append(value / scale)
            labels.append(", ".join(f"{f.split('.')[-1]}={v}" for f, v in cell_fields(sweep, index).items()
                                    if sweep[f].size > 1))  # the fields that vary
        ax.plot(hours, values, "o", color="tab:blue", ms=5)
        for x, y, text in zip(hours, values, labels):
            ax.annotate(text, (x, y), fontsize=6, xytext=(3, 3), textcoords="offset points")
        if item in targets:
            ax.axhline(targets[item] / scale, ls="--", color="tab:red", lw=1.0, label="target")
            ax.legend(fontsize=7)
        ax.set_title(f"{item} ({ITEMS[item][0]}): {'95 % |error|' if kind == 'U95' else 'sd of the figure'}",
                     fontsize=9)
        ax.set_xlabel("session (h)", fontsize=8)
        ax.set_ylabel(unit, fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes.ravel()[len(items):]:
        ax.set_visible(False)
    fig.suptitle(f"plansim sweep jjf1535 on {sweep.attrs.get('unit_scenario', '?')}: "
                 f"{sweep.attrs.get('trials_per_cell', '?')} trials per cell", fontsize=10)
    save(fig, path, chosen, dpi=110)


#: a recording of more samples than this is drawn as each channel's envelope (minimum and maximum) over bins
ENVELOPE_ABOVE = 20000
#: the shading of each kind of segment in :func:`recording_figure` (matplotlib colours)
SEGMENT_SHADES = {"static": "tab:green", "rotation": "tab:blue", "move": "0.6"}


def segment_kind(segment) -> str:
    """The shading kind of a recording's segment: ``"move"`` (the motion between poses, which no estimator uses),
    ``"rotation"`` (the table turns: a non-zero or unlogged rate) or ``"static"``."""
    if segment.test == "move":
        return "move"
    return "rotation" if segment.is_rotating else "static"


def draw_recording(recording, plt=None):
    """The figure of :func:`recording_figure`, not saved: returns ``(figure, (gyro_axes, accel_axes))``."""
    from matplotlib.patches import Patch

    from plansim.kernels.layout import CHANNELS

    plt = pyplot() if plt is None else plt
    time = np.asarray(recording.time, dtype=float)
    samples = np.asarray(recording.samples, dtype=float)
    fig, axes = plt.subplots(2, 1, figsize=(13, 6.4), sharex=True, constrained_layout=True)
    colours = ("tab:red", "tab:green", "tab:blue")
    for ax, channels, factor, unit in ((axes[0], range(3), 180.0 / math.pi, "deg/s"),
                                       (axes[1], range(3, 6), 1.0, "m/s^2")):
        for c, colour in zip(channels, colours):
            y = samples[:, c] * factor
            if y.size > ENVELOPE_ABOVE:  # each bin's minimum and maximum: nothing a spike does is hidden
                bins = math.ceil(y.size / (ENVELOPE_ABOVE // 2))
                cut = y.size // bins * bins
                t_bin = time[:cut].reshape(-1, bins).mean(axis=1)
                lo, hi = y[:cut].reshape(-1, bins).min(axis=1), y[:cut].reshape(-1, bins).max(axis=1)
                ax.fill_between(t_bin, lo, hi, color=colour, lw=0.4, alpha=0.8, label=CHANNELS[c])
            else:
                ax.plot(time, y, color=colour, lw=0.6, label=CHANNELS[c])
        ax.set_ylabel(f"{'gyros' if unit == 'deg/s' else 'accelerometers'} ({unit})", fontsize=9)
        ax.tick_params(labelsize=8)
    first = np.asarray(recording.first_sample)
    counts = {kind: 0 for kind in SEGMENT_SHADES}
    numbered = len(recording.schedule) <= 80  # beyond that the numbers overlap; the table has them
    for k, (start, segment) in enumerate(zip(first, recording.schedule.segments)):
        kind = segment_kind(segment)
        counts[kind] += 1
        stop = min(int(start) + segment.samples, time.size) - 1
        t0, t1 = float(time[int(start)]), float(time[stop])
        for ax in axes:
            ax.axvspan(t0, t1, color=SEGMENT_SHADES[kind], alpha=0.12 if kind != "move" else 0.08, lw=0)
        if numbered and kind != "move":
            axes[0].text(0.5 * (t0 + t1), 1.0, str(k), transform=axes[0].get_xaxis_transform(), ha="center",
                         va="bottom", fontsize=6, color=SEGMENT_SHADES[kind])
    axes[1].set_xlabel("time (s)", fontsize=9)
    lines = axes[0].legend(fontsize=8, loc="upper right", ncol=3)
    axes[0].add_artist(lines)
    axes[1].legend(fontsize=8, loc="upper right", ncol=3)
    shades = [Patch(color=SEGMENT_SHADES[k], alpha=0.3, label=f"{k} ({counts[k]})") for k in SEGMENT_SHADES]
    axes[0].legend(handles=shades, fontsize=8, loc="upper left", ncol=3)
    fig.suptitle(f"recording: {len(recording.schedule)} segments ({counts['static']} static, {counts['rotation']} "
                 f"rotation, {counts['move']} move), {time.size} samples; the numbers are the segment table's",
                 fontsize=10)
    return fig, tuple(axes)


def recording_figure(recording, path: str | os.PathLike, format: str | None = None) -> None:
    """A recording's samples against time with its segments shaded, for reviewing the segment table that
    ``plansim import`` found (docs/measured-data.md).

    Top: the gyros in °/s; bottom: the accelerometers in m/s². Static segments are shaded green, rotations
    blue, moves grey, each numbered as in the segment table (up to 80 segments). A recording of more than
    :data:`ENVELOPE_ABOVE` samples is drawn as each channel's minimum and maximum over bins of samples, so a
    spike or a rail still shows.

    Parameters
    ----------
    recording : plansim.io.recording_data.Recording
    path : str or os.PathLike
        The figure file, written whole or not at all (:func:`plansim.io.files.atomic_write`).
    format : {"png", "pdf", "svg"}, optional
        Default: from the suffix of *path*.
    """
    chosen = figure_format(path, format)
    fig, _axes = draw_recording(recording)
    save(fig, path, chosen, dpi=110)
