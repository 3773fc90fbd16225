"""``plansim run jjf1537``'s report: the text table, the JSON object (SI) and the Bode figure (docs/dynamic.md)."""

from __future__ import annotations

import math
import os

import numpy as np

from plansim.report.plot import figure_format, pyplot, save
from plansim.units import DEG, STANDARD_GRAVITY


def _list(x) -> list:
    return [float(v) for v in np.ravel(x)]


def _number(x) -> float | None:
    """*x* as a float, None for nan or ±inf (JSON has neither; the flat sensor's bandwidth is inf)."""
    x = float(x)
    return x if math.isfinite(x) else None


def jjf1537_json(result, elapsed: float, version: str) -> dict:
    """The result as one JSON-able object, SI units (Hz, rad, rad/s); ratios dimensionless; nan as null."""
    s, sch, summary = result.settings, result.schedule, result.summary()
    return {
        "experiment": "jjf1537", "seed": result.seed, "trials": result.trials, "overrides": list(s.overrides),
        "plansim_version": version, "elapsed_s": elapsed,
        "units": "SI: Hz, rad, rad/s, s; ratios K_i = S_i/S_0 dimensionless",
        "settings": {
            "model": s.model, "natural_frequency": s.natural_frequency, "damping": s.damping,
            "drive_frequency": s.drive_frequency, "drive_damping": s.drive_damping, "gyro_range": s.gyro_range,
            "amplitude": sch.amplitude, "repeats": sch.repeats, "sample_rate": sch.sample_rate,
            "record_samples": [int(v) for v in sch.samples()], "expected_bandwidth": sch.expected_bandwidth,
            "grid": s.grid, "gyro_arw": s.gyro_arw, "quantisation": s.quantisation, "scale_factor": s.scale_factor,
            "bias": s.bias, "noise_sigma": s.noise_sigma, "odd_nonlinearity": s.odd_nonlinearity,
            "even_nonlinearity": s.even_nonlinearity, "vibration_bias_shift": s.vibration_bias_shift,
            "shock_bias_shift": s.shock_bias_shift, "shock_peak": s.shock_peak, "shock_duration": s.shock_duration,
            "shock_settle": s.shock_settle, "g_sensitivity": s.g_sensitivity,
            "table_amplitude_error": s.table_amplitude_error, "table_phase_error": s.table_phase_error,
            "gyro_rrw": s.gyro_rrw,
        },
        "frequencies": _list(sch.frequencies),
        "truth": {"ratio": _list(result.truth_ratio), "phase": _list(result.truth_phase),
                  "bandwidth": _number(result.truth_bandwidth)},
        "noise_free": {"ratio": _list(result.noise_free_ratio), "bandwidth": _number(result.noise_free_bandwidth),
                       "bandwidth_fit": _number(result.noise_free_bandwidth_fit)},
        "monte_carlo": {
            "ratio_mean": _list(summary["ratio_mean"]), "ratio_std": _list(summary["ratio_std"]),
            "ratio_bias": _list(summary["ratio_bias"]), "phase_mean": _list(summary["phase_mean"]),
            "phase_std": _list(summary["phase_std"]), "phase_bias": _list(summary["phase_bias"]),
            "bandwidth_mean": _number(summary["bandwidth_mean"]), "bandwidth_std": _number(summary["bandwidth_std"]),
            "bandwidth_bias": _number(summary["bandwidth_bias"]), "bandwidth_found": summary["bandwidth_found"],
            "bandwidth_fit_mean": _number(summary["bandwidth_fit_mean"]),
            "bandwidth_fit_std": _number(summary["bandwidth_fit_std"]),
            "bandwidth_fit_bias": _number(summary["bandwidth_fit_bias"]),
            "bandwidth_fit_found": summary["bandwidth_fit_found"],
        },
        "gum": {"ratio": _list(result.gum["ratio"]), "phase": _list(result.gum["phase"]),
                "bandwidth": _number(result.gum["bandwidth"]), "bandwidth_fit": _number(result.gum["bandwidth_fit"]),
                "amplitude": _list(result.gum["amplitude"])},
        "type_a_mean": {"ratio": _list(result.type_a["ratio"]), "phase": _list(result.type_a["phase"])},
        "vibration_shock": _vibration_shock_json(result.vibration_shock),
    }


def _vibration_shock_json(items) -> dict | None:
    """JJF 1537 7.2.4–7.2.7: the schedule and, per item, the truth and the MC figures (nan as null)."""
    if items is None:
        return None
    sch = items.schedule
    return {
        "frequency": sch.frequency, "amplitudes": _list(sch.amplitudes), "vibration_amplitude": sch.amplitude,
        "record_samples": sch.samples(sch.record_time), "vibration_samples": sch.samples(sch.vibration_time),
        "rest_samples": sch.rest_samples(), "shock_waveform_simulated": True,
        "shock_pulse_samples": sch.pulse_samples(), "shock_record_samples": sch.shock_samples(),
        "items": {name: {key: _number(value) for key, value in figures.items()}
                  for name, figures in items.summary().items()},
        "shock": {key: _number(value) for key, value in items.shock_summary().items()},
    }


def jjf1537_text(result, elapsed: float) -> str:
    """The text report: per frequency the truth, the MC mean, bias and scatter against the GUM; the bandwidth."""
    s, sch, summary = result.settings, result.schedule, result.summary()
    dyn = result.settings.dynamics()
    model = {"flat": "flat (ideal)",
             "second_order": f"second-order f_n {dyn.natural_frequency:g} Hz, zeta {dyn.damping:g}",
             "two_resonance": f"two resonances (JJF 1537 eq. (3)): sense {dyn.natural_frequency:g} Hz, zeta "
                              f"{dyn.damping:g}; drive {dyn.drive_frequency:g} Hz, zeta {dyn.drive_damping:g}"}[s.model]
    lines = [
        f"plansim run jjf1537: seed {result.seed}, {result.trials} trials, {elapsed:.1f} s",
        f"sensor: {model}; range {s.gyro_range / DEG:g} deg/s, ARW {s.gyro_arw / DEG * 60:g} deg/sqrt(h), "
        f"step {s.quantisation / DEG:.4g} deg/s",
        f"table: {sch.amplitude / DEG:g} deg/s amplitude, {sch.frequencies.size} frequencies ({s.grid} grid), "
        f"n = {sch.repeats}, {sch.sample_rate:g} Hz, {sch.samples().min()}-{sch.samples().max()} samples per record; "
        + (f"table errors {s.table_amplitude_error * 100:g} % in amplitude, {s.table_phase_error / DEG:g} deg in phase "
           "(standard deviations, once per setting)" if s.table_amplitude_error or s.table_phase_error
           else "a perfect table (--set table_amplitude_error=..., table_phase_error=...)"),
        "",
        "  f (Hz)   |H| truth   K noise-free   K MC mean   bias K      s(K) MC    u(K) GUM   "
        "phase truth (deg)   bias (deg)   s MC (deg)   u GUM (deg)",
    ]
    for i, f in enumerate(sch.frequencies):
        lines.append(
            f"{f:8.3f}   {result.truth_ratio[i]:9.6f}   {result.noise_free_ratio[i]:12.6f}   "
            f"{summary['ratio_mean'][i]:9.6f}   {summary['ratio_bias'][i]:+9.2e}   {summary['ratio_std'][i]:8.2e}   "
            f"{result.gum['ratio'][i]:8.2e}   {math.degrees(result.truth_phase[i]):17.4f}   "
            f"{math.degrees(summary['phase_bias'][i]):+10.2e}   {math.degrees(summary['phase_std'][i]):10.2e}   "
            f"{math.degrees(result.gum['phase'][i]):11.2e}")
    if summary["bandwidth_found"] == 0:
        bandwidth = (f"-3 dB bandwidth: truth {result.truth_bandwidth:.4f} Hz; not found in any trial: the response "
                     f"does not fall through -3.01 dB between {sch.frequencies[0]:g} and {sch.frequencies[-1]:g} Hz "
                     "(the bandwidth lies outside the measured band; --set expected_bandwidth=... or grid=jjf1537)")
    else:
        bandwidth = (
            f"-3 dB bandwidth: truth {result.truth_bandwidth:.4f} Hz; procedure without noise "
            f"{result.noise_free_bandwidth:.4f} Hz; MC mean {summary['bandwidth_mean']:.4f} Hz "
            f"(bias {summary['bandwidth_bias']:+.4f} Hz), s {summary['bandwidth_std']:.4f} Hz, GUM u "
            f"{result.gum['bandwidth']:.4f} Hz; found in {summary['bandwidth_found']}/{result.trials} trials")
    if summary["bandwidth_fit_found"] == 0:
        fitted = ("  read from a second-order curve fitted to K (JJF 1535 7.2.15.2): the fitted curve does not fall "
                  "through -3.01 dB inside the measured band in any trial")
    else:
        fitted = (
            f"  read from a second-order curve fitted to K (JJF 1535 7.2.15.2): without noise "
            f"{result.noise_free_bandwidth_fit:.4f} Hz; MC mean {summary['bandwidth_fit_mean']:.4f} Hz (bias "
            f"{summary['bandwidth_fit_bias']:+.4f} Hz), s {summary['bandwidth_fit_std']:.4f} Hz, GUM u "
            f"{result.gum['bandwidth_fit']:.4f} Hz; found in {summary['bandwidth_fit_found']}/{result.trials} trials")
    lines += [
        "",
        bandwidth + " (interpolated between the two points either side)",
        fitted,
        "K = S_i/S_0 with S_0 read at the lowest frequency (JJF 1537 eq. (9)); bias against the analytic |H|, "
        "arg H",
    ]
    if result.vibration_shock is not None:
        lines += ["", *_vibration_shock_text(result)]
    return "\n".join(lines)


#: the report's label of each 7.2.4–7.2.7 figure
_ITEM_LABELS = {"amplitude_nonlinearity": "7.2.4 amplitude nonlinearity (ppm)",
                "vibration_output_change": "7.2.5 output change in vibration (deg/h)",
                "bias_change_vibration": "7.2.6 bias change, vibration (deg/h)",
                "bias_change_shock": "7.2.7 bias change, shock (deg/h)"}


def _vibration_shock_text(result) -> list[str]:
    """The 7.2.4–7.2.7 table: per item the truth, the MC mean, bias and s, the mean Type A u, the GUM u and the
    coverage of ± 2 u_A; the nonlinearity in ppm, the changes in deg/h of output (S = 1: of rate)."""
    items, s = result.vibration_shock, result.settings
    sch = items.schedule
    shock, n = items.shock_summary(), items.estimates["shock_recovery_time"].size
    amplitudes = ", ".join(f"{a / DEG:g}" for a in sch.amplitudes)
    lines = [
        f"JJF 1537 7.2.4-7.2.7 at {sch.frequency:g} Hz: amplitudes {amplitudes} deg/s, n = {sch.repeats} x "
        f"{sch.samples(sch.record_time)} samples; vibration {sch.amplitude / DEG:g} deg/s, "
        f"{sch.samples(sch.vibration_time)} samples; 3 records at rest of {sch.rest_samples()} samples",
        f"sensor: odd nonlinearity c3 {s.odd_nonlinearity:g}, even c2 {s.even_nonlinearity:g} (g(v) = v + c2 v^2/R "
        f"+ c3 v^3/R^2); bias shift after vibration {s.vibration_bias_shift / DEG * 3600:g} deg/h, after the "
        f"shock {s.shock_bias_shift / DEG * 3600:g} deg/h; "
        + (f"the bias drifts as a rate random walk of {s.gyro_rrw / DEG * 3600 * 60:g} deg/h/sqrt(h) (the Type A u "
           "of the records does not see it; the GUM does)" if s.gyro_rrw else "no drift (--set gyro_rrw=...)"),
        f"shock: half-sine {s.shock_peak / STANDARD_GRAVITY:g} g, {1e3 * s.shock_duration:g} ms along the input "
        f"axis, read through a g-sensitivity of {s.g_sensitivity / DEG * STANDARD_GRAVITY:g} deg/s/g; the record "
        f"after it starts {shock['shock_record']:g} s after the pulse's start",
        f"  peak output {shock['peak_mean'] / DEG:.4g} deg/s (s {shock['peak_std'] / DEG:.2g}) against "
        f"{shock['peak_truth'] / DEG:.4g} deg/s without noise"
        + (" (the noise's own maximum over the record decides it)" if shock["peak_mean"] - shock["peak_truth"] >
           3 * shock["peak_std"] else ""),
        f"  saturated in {shock['saturated']}/{n} trials; output back within the noise after "
        f"{_ms(shock['recovery_median'])} (median), {_ms(shock['recovery_max'])} (max); "
        + (f"NOT settled when the record after the shock began in {shock['not_settled']}/{n} trials (noise alone: "
           "about 1 %): its bias change reads the ringing too (--set shock_settle=...)" if shock["not_settled"] else
           "settled before the record after the shock in every trial"),
        "",
        "  item                                       truth        MC mean      bias         s MC       "
        "mean u_A     u GUM      |err| <= 2u_A",
    ]
    for name, fig in items.summary().items():
        unit = 1e6 if name == "amplitude_nonlinearity" else 3600.0 / DEG
        cover = "" if math.isnan(fig["coverage"]) else f"{100 * fig['coverage']:.1f} %"
        u_a = "" if math.isnan(fig["type_a_mean"]) else f"{unit * fig['type_a_mean']:9.4g}"
        gum = "" if math.isnan(fig["gum"]) else f"{unit * fig['gum']:9.4g}"
        row = (f"  {_ITEM_LABELS[name]:<41}  {unit * fig['truth']:+10.4g}   {unit * fig['mean']:+10.4g}   "
               f"{unit * fig['bias']:+10.3g}   {unit * fig['std']:9.4g}   {u_a:>9}   {gum:>9}   {cover:>8}")
        lines.append(row.rstrip())
    return lines


def _ms(seconds: float) -> str:
    return "-" if math.isnan(seconds) else f"{1e3 * seconds:.3g} ms"


def bode_figure(result, path: str | os.PathLike, format: str | None = None) -> None:
    """The Bode diagram of the test.

    Left: gain (dB) and phase (deg) against frequency on a log axis, the analytic truth as a line, the MC mean
    of the estimates with ± one MC standard deviation as bars, the −3.01 dB line, the true bandwidth and the two
    estimated ones, interpolated and read from the fitted curve (MC mean ± s, shaded). Right: the same estimates
    minus the truth, where the bars can be seen (they are ~1e-4 of the gain), with the noise-free procedure's
    error (the method's bias) and ± the GUM standard uncertainty around it.
    """
    fmt = figure_format(path, format)
    plt = pyplot()
    sch, summary = result.schedule, result.summary()
    f = sch.frequencies
    dyn = result.settings.dynamics()
    grid = np.geomspace(f[0] / 2.0, f[-1] * 2.0, 400)
    H = dyn.response(grid)
    fig, axes = plt.subplots(2, 2, figsize=(12, 7), sharex=True)
    (gain, gain_err), (phase, phase_err) = axes
    gain.semilogx(grid, 20.0 * np.log10(np.abs(H)), "k-", lw=1, label="truth |H| (analytic)")
    mean = summary["ratio_mean"]
    db_err = 20.0 / math.log(10.0) * summary["ratio_std"] / mean
    gain.errorbar(f, 20.0 * np.log10(mean), yerr=db_err, fmt="o", color="tab:blue", ms=4, capsize=3,
                  label=f"estimate K_i, MC mean ± s ({result.trials} trials)")
    gain.axhline(-10.0 * math.log10(2.0), color="tab:red", ls="--", lw=1, label="−3.01 dB")
    if math.isfinite(result.truth_bandwidth):
        for ax in (gain, phase):
            ax.axvline(result.truth_bandwidth, color="k", ls=":", lw=1)
        gain.plot([], [], "k:", lw=1, label=f"true bandwidth {result.truth_bandwidth:.3f} Hz")
    if math.isfinite(summary["bandwidth_mean"]):
        gain.axvspan(summary["bandwidth_mean"] - summary["bandwidth_std"],
                     summary["bandwidth_mean"] + summary["bandwidth_std"], color="tab:blue", alpha=0.3,
                     label=f"interpolated {summary['bandwidth_mean']:.3f} ± {summary['bandwidth_std']:.3f} Hz")
    if math.isfinite(summary["bandwidth_fit_mean"]):
        gain.axvspan(summary["bandwidth_fit_mean"] - summary["bandwidth_fit_std"],
                     summary["bandwidth_fit_mean"] + summary["bandwidth_fit_std"], color="tab:green", alpha=0.3,
                     label=f"curve fit (JJF 1535 7.2.15.2) {summary['bandwidth_fit_mean']:.3f} ± "
                           f"{summary['bandwidth_fit_std']:.3f} Hz")
    gain.set_ylabel("gain 20 log10 K (dB)")
    gain.set_title("JJF 1537-2015: amplitude and phase response")
    phase.semilogx(grid, np.degrees(np.unwrap(np.angle(H))), "k-", lw=1, label="truth arg H (analytic)")
    # on the truth's unwrapped branch (a two-resonance response passes −180° within the band)
    phase_mean = np.unwrap(result.truth_phase) + summary["phase_bias"]
    phase.errorbar(f, np.degrees(phase_mean), yerr=np.degrees(summary["phase_std"]), fmt="o",
                   color="tab:blue", ms=4, capsize=3, label="estimate Δφ_i, MC mean ± s")
    phase.set_xlabel("frequency (Hz)")
    phase.set_ylabel("phase (deg)")

    method = result.noise_free_ratio - result.truth_ratio
    gain_err.fill_between(f, 1e6 * (method - result.gum["ratio"]), 1e6 * (method + result.gum["ratio"]),
                          color="tab:orange", alpha=0.3, label="noise-free procedure ± u GUM")
    gain_err.plot(f, 1e6 * method, "-", color="tab:orange", lw=1)
    gain_err.errorbar(f, 1e6 * summary["ratio_bias"], yerr=1e6 * summary["ratio_std"], fmt="o", color="tab:blue",
                      ms=4, capsize=3, label="MC mean ± s")
    gain_err.axhline(0.0, color="k", lw=0.5)
    gain_err.set_ylabel("K_i − |H(f_i)| (ppm)")
    gain_err.set_title("estimates minus the analytic truth")
    phase_err.fill_between(f, -np.degrees(result.gum["phase"]) * 1e3, np.degrees(result.gum["phase"]) * 1e3,
                           color="tab:orange", alpha=0.3, label="± u GUM")
    phase_err.errorbar(f, 1e3 * np.degrees(summary["phase_bias"]), yerr=1e3 * np.degrees(summary["phase_std"]),
                       fmt="o", color="tab:blue", ms=4, capsize=3, label="MC mean ± s")
    phase_err.axhline(0.0, color="k", lw=0.5)
    phase_err.set_ylabel("Δφ_i − arg H(f_i) (mdeg)")
    phase_err.set_xlabel("frequency (Hz)")
    for ax in axes.ravel():
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    save(fig, path, fmt, dpi=90)
