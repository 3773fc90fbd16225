"""``plansim run vibration_g2``'s report: the text table, the JSON object (SI) and the figure (docs/dynamic.md)."""

from __future__ import annotations

import os

import numpy as np

from plansim.model.vibration import G2_PER_HZ, MONOMIALS
from plansim.report.plot import figure_format, pyplot, save
from plansim.units import DEG, HOUR, STANDARD_GRAVITY

DEG_H = DEG / HOUR
#: the paper's figures (its Tables 1 and 2), °/h
PAPER = {"shift": 60.0, "before": 75.39, "after": 30.94}
#: the compensations, in the order reported
MODELS = {"static": "static model (2)", "g2": "+ g² terms (3)", "g2_g3": "+ g² and g³ terms (3)"}


def _list(x) -> list:
    return [float(v) for v in np.ravel(x)]


def vibration_json(result, elapsed: float, version: str) -> dict:
    """The result as one JSON-able object, SI units (rad/s, m/s², Hz; the PSDs per Hz)."""
    s = result.settings
    r = result.record
    profile = s.psd_profile()
    return {
        "experiment": "vibration_g2", "seed": result.seed, "overrides": list(s.overrides),
        "plansim_version": version, "elapsed_s": elapsed,
        "units": "SI: rad/s, m/s^2, (m/s^2)^2/Hz, (rad/s)^2/Hz, Hz, s; g2 coefficients rad/s/(m/s^2)^2, g3 "
                 "rad/s/(m/s^2)^3",
        "settings": {
            "profile": s.profile, "profile_frequencies_Hz": _list(profile.frequencies),
            "profile_levels": _list(profile.levels), "profile_rms": profile.rms(),
            "generated_rms": float(np.sqrt(r.variance.max())), "vibration_axes": s.vibration_axes,
            "sample_interval": s.sample_interval, "internal_rate_Hz": s.internal_rate,
            "before": s.before, "during": s.during, "after": s.after,
        },
        "rate_true": _list(r.rate),
        "shift": {"measured": _list(result.shift), "predicted": _list(result.predicted_shift)},
        "accel_power": {"generated": _list(r.variance), "sampled": _list(result.accel_power_sampled)},
        "truth": {"dynamic": result.truth.dynamic.tolist(), "columns": list(MONOMIALS)},
        "fitted": {name: c.tolist() for name, c in result.coefficients.items()},
        "errors": {name: {k: _list(v) for k, v in e.items()} for name, e in result.errors.items()},
        "predicted": None if result.predicted is None else {
            "sampled_variance": result.predicted["sampled_variance"], "g2_ratio": result.predicted["g2_ratio"],
            "static": _list(result.predicted["static"]), "g2": _list(result.predicted["g2"])},
        "paper_deg_per_h": PAPER,
    }


def vibration_text(result, elapsed: float) -> str:
    """The text report: the shift against the closed form, the errors before and after compensation (°/h)."""
    s = result.settings
    r = result.record
    profile = s.psd_profile()
    lines = [
        f"plansim run vibration_g2: seed {result.seed}, {elapsed:.1f} s",
        f"vibration along {s.vibration_axes}: {s.profile} profile, {profile.rms() / STANDARD_GRAVITY:.3f} g r.m.s. "
        f"({profile.variance() / G2_PER_HZ:.2f} g^2; generated {r.variance.max() / G2_PER_HZ:.2f} g^2), "
        f"{s.before:g} s still, {s.during:g} s vibration, {s.after:g} s still, {s.sample_interval * 1e3:g} ms "
        f"sampling (simulated at {s.internal_rate:g} Hz)",
        f"sampled accelerometer power during vibration: "
        f"{', '.join(f'{v / G2_PER_HZ:.2f}' for v in result.accel_power_sampled)} g^2 (x, y, z)",
        "",
        "deg/h                                          x gyro    y gyro    z gyro",
        f"{'output shift, measured':42s}" + _row(result.shift),
        f"{'output shift, closed form':42s}" + _row(result.predicted_shift),
    ]
    for name, label in MODELS.items():
        lines.append(f"{'mean error, ' + label:42s}" + _row(result.errors[name]["mean"]))
    for name, label in MODELS.items():
        lines.append(f"{'r.m.s. of 1 s means, ' + label:42s}" + _row(result.errors[name]["rms_averaged"]))
    if result.predicted is not None:
        p = result.predicted
        lines += [
            f"{'predicted mean error, ' + MODELS['static']:42s}" + _row(p["static"]),
            f"{'predicted mean error, ' + MODELS['g2']:42s}" + _row(p["g2"]),
            "",
            f"fitted g² coefficient / truth: "
            f"{', '.join(f'{c:.2f}' for c in result.coefficients['g2'][:, 2] / result.truth.S2[:, 2])} (x, y, z); "
            f"predicted {p['g2_ratio']:.2f} (the 2.5 ms samples see {p['sampled_variance'] / G2_PER_HZ:.2f} of "
            f"{r.variance[2] / G2_PER_HZ:.2f} g^2; predictions without noise or calibration errors)",
        ]
    lines += ["", f"the paper: shift ≈ {PAPER['shift']:g} deg/h, compensation {PAPER['before']} -> {PAPER['after']} "
                  "deg/h (docs/dynamic.md compares)"]
    return "\n".join(lines)


def _row(x) -> str:
    return "".join(f"{v / DEG_H:10.2f}" for v in x)


def vibration_figure(result, path: str | os.PathLike, format: str | None = None) -> None:
    """Left: the Welch PSD of the vibrated axis's gyro output and of the accelerometer against the profile.
    Right: the gyro's 1 s means, static compensation against dynamic compensation, with the vibration shaded."""
    fmt = figure_format(path, format)
    plt = pyplot()
    s = result.settings
    r = result.record
    axis = s.axes()[-1]
    name = "xyz"[axis]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    f = result.psd["frequency"]
    keep = f > 0
    left.loglog(f[keep], result.psd["accel"][keep, axis] / G2_PER_HZ, color="tab:blue",
                label=f"accelerometer {name}, sampled (g²/Hz)")
    left.loglog(f[keep], np.maximum(result.psd["profile"][keep], 1e-30) / G2_PER_HZ, "k--", lw=1,
                label="requested profile (g²/Hz)")
    left.set_xlabel("frequency (Hz)")
    left.set_ylabel("acceleration PSD (g²/Hz)")
    left.set_ylim(1e-4, 1.0)
    twin = left.twinx()
    twin.loglog(f[keep], result.psd["gyro"][keep, axis] / DEG_H**2, color="tab:red", alpha=0.8,
                label=f"gyro {name} output ((°/h)²/Hz)")
    twin.set_ylabel("gyro output PSD ((°/h)²/Hz)")
    gyro_psd = result.psd["gyro"][keep, axis] / DEG_H**2
    twin.set_ylim(np.median(gyro_psd) / 30.0, np.median(gyro_psd) * 10.0)
    handles = left.get_legend_handles_labels()
    handles2 = twin.get_legend_handles_labels()
    left.legend(handles[0] + handles2[0], handles[1] + handles2[1], loc="lower left", fontsize=8)
    left.set_title("Welch PSD during vibration")

    average = s.samples(1.0)
    t = r.t[: (r.t.size // average) * average].reshape(-1, average).mean(axis=1)
    for key, colour, label in (("static", "tab:orange", "static model"), ("g2_g3", "tab:green", "+ g², g³")):
        e = result.rate_estimates[key][:, axis] - r.rate[axis]
        e = e[: (e.size // average) * average].reshape(-1, average).mean(axis=1)
        right.plot(t, e / DEG_H, color=colour, lw=1, label=label)
    right.axvspan(s.before, s.before + s.during, color="0.9", zorder=0, label="vibration")
    right.axhline(0.0, color="k", lw=0.5)
    right.set_xlabel("time (s)")
    right.set_ylabel(f"gyro {name} error, 1 s means (°/h)")
    right.legend(fontsize=8)
    right.set_title("compensated output minus the Earth rate")
    fig.tight_layout()
    save(fig, path, fmt, dpi=90)


def _stats_json(stats: dict) -> dict:
    return {k: _list(v) for k, v in stats.items()}


def vibration_mc_json(mc, elapsed: float, version: str) -> dict:
    """``plansim run vibration_g2 --trials N --json``: per record and summarised over the records, SI (rad/s)."""
    s = mc.settings
    return {
        "experiment": "vibration_g2", "trials": mc.trials, "seeds": [mc.seed, mc.seed + mc.trials - 1],
        "overrides": list(s.overrides), "plansim_version": version, "elapsed_s": elapsed,
        "units": "SI: rad/s; g2_ratio 1", "vibration_axes": s.vibration_axes,
        "shift": {"per_record": mc.shift.tolist(), "summary": _stats_json(mc.summary(mc.shift)),
                  "predicted": _list(mc.predicted_shift)},
        "mean_error": {m: {"per_record": v.tolist(), "summary": _stats_json(mc.summary(v))}
                       for m, v in mc.mean_error.items()},
        "rms_averaged": {m: {"per_record": v.tolist(), "summary": _stats_json(mc.summary(v))}
                         for m, v in mc.rms_averaged.items()},
        "g2_ratio": {"per_record": mc.g2_ratio.tolist(), "summary": _stats_json(mc.summary(mc.g2_ratio))},
        "predicted": None if mc.predicted is None else {
            "g2_ratio": mc.predicted["g2_ratio"], "static": _list(mc.predicted["static"]),
            "g2": _list(mc.predicted["g2"])},
        "paper_deg_per_h": PAPER,
    }


def vibration_mc_text(mc, elapsed: float) -> str:
    """The Monte Carlo over records as text, °/h: mean ± sd and the 95 % range of each figure, per gyro."""
    s = mc.settings

    def row(label, values, scale=DEG_H, digits=2):
        st = mc.summary(values)
        cells = "".join(f"{st['mean'][a] / scale:9.{digits}f} ± {st['std'][a] / scale:<6.{digits}f}"
                        f"[{st['q025'][a] / scale:.{digits}f}, {st['q975'][a] / scale:.{digits}f}]  "
                        for a in range(3))
        return f"{label:44s}{cells}"

    lines = [f"plansim run vibration_g2 --trials {mc.trials}: seeds {mc.seed}–{mc.seed + mc.trials - 1}, "
             f"{elapsed:.1f} s (vibration along {s.vibration_axes})",
             "", "deg/h: mean ± sd [95 % range] over the records" + " " * 14 + "x gyro" + " " * 26 + "y gyro"
             + " " * 26 + "z gyro",
             row("output shift", mc.shift),
             f"{'output shift, closed form':44s}" + "".join(f"{v / DEG_H:9.2f}{'':30s}" for v in mc.predicted_shift)]
    for m, label in MODELS.items():
        lines.append(row("mean error, " + label, mc.mean_error[m]))
    for m, label in MODELS.items():
        lines.append(row("r.m.s. of 1 s means, " + label, mc.rms_averaged[m]))
    lines.append(row("fitted g² / truth (shaken axis)", mc.g2_ratio, scale=1.0))
    if mc.predicted is not None:
        lines.append(f"predicted: g² ratio {mc.predicted['g2_ratio']:.2f}; mean error "
                     + ", ".join(f"{MODELS[m]} {mc.predicted[m][2] / DEG_H:.2f}" for m in ("static", "g2"))
                     + " deg/h (z gyro; without noise or calibration errors)")
    static_z = mc.summary(mc.mean_error["static"])
    after_z = mc.summary(mc.mean_error["g2_g3"])
    lines += ["", f"the paper: shift ≈ {PAPER['shift']:g} deg/h, compensation {PAPER['before']} -> {PAPER['after']} "
                  f"deg/h; here, z gyro: {static_z['mean'][2] / DEG_H:.1f} ± {static_z['std'][2] / DEG_H:.1f} -> "
                  f"{after_z['mean'][2] / DEG_H:.1f} ± {after_z['std'][2] / DEG_H:.1f} deg/h"]
    return "\n".join(lines)


def vibration_mc_figure(mc, path: str | os.PathLike, format: str | None = None) -> None:
    """Per gyro, the distribution over the records of the mean error during vibration, static model against the
    g² (and g³) compensation, with the paper's figures marked (°/h)."""
    chosen = figure_format(path, format)
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), constrained_layout=True)
    for a, ax in enumerate(axes):
        for m, color in (("static", "tab:red"), ("g2", "tab:orange"), ("g2_g3", "tab:blue")):
            ax.hist(mc.mean_error[m][:, a] / DEG_H, bins=max(5, mc.trials // 3), alpha=0.5, color=color,
                    label=MODELS[m])
        if a == 2:
            for key, style in (("before", "--"), ("after", ":")):
                ax.axvline(PAPER[key], color="k", ls=style, lw=1.0, label=f"paper, {key}: {PAPER[key]} deg/h")
        ax.set_title(f"{'xyz'[a]} gyro: mean error during vibration", fontsize=9)
        ax.set_xlabel("deg/h", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[2].legend(fontsize=6)
    fig.suptitle(f"plansim run vibration_g2 --trials {mc.trials} (seeds {mc.seed}–{mc.seed + mc.trials - 1})",
                 fontsize=10)
    save(fig, path, chosen, dpi=110)
