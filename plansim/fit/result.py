"""A fit's result as data: the ``--json`` object of ``plansim fit`` and the ``--out`` NetCDF Dataset.

Everything in SI, each number with its unit. The JSON object has exactly the keys of :data:`JSON_KEYS`
(docs/fitting.md).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from plansim.fit.identify import describe_conflict
from plansim.fit.joint import FitResult
from plansim.fit.noise import UNITS_SI, channel_kind
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS

JSON_KEYS = ("identified", "not_identified", "weakly_determined", "site", "turntable", "parameters", "noise",
             "residuals", "chi2_dof", "moves", "accelerometer_shear", "data_sheet_conflict", "notes")


def _number(value: float):
    """A float for JSON: NaN and infinity become None (JSON has neither)."""
    value = float(value)
    return value if math.isfinite(value) else None


def fit_json(result: FitResult) -> dict:
    """The ``plansim fit --json`` object (SI, units named)."""
    parameters = []
    for method in result.methods:
        for k, spec in enumerate(PARAMETERS):
            parameters.append({"name": spec.name, "unit": spec.si_unit, "estimate": _number(method.estimate[k]),
                               "u": _number(method.u[k]), "method": method.name})
    noise = []
    for ch in result.noise.channels:
        units = UNITS_SI[ch.kind]
        noise.append({"channel": ch.channel,
                      "white_noise_density": _number(ch.white), "white_noise_density_unit": units["white"],
                      "bias_instability": _number(ch.bias_instability),
                      "bias_instability_unit": units["bias_instability"],
                      "rate_random_walk": _number(ch.rate_random_walk),
                      "rate_random_walk_unit": units["rate_random_walk"],
                      "quantisation_step": _number(ch.quantisation_step), "quantisation_step_unit": units["mean"],
                      # the noise's correlation from sample to sample (a sensor's filter; docs/fitting.md)
                      "correlated_lags": int(ch.autocorrelation.size),
                      "lag_one_autocorrelation": _number(ch.autocorrelation[0]) if ch.autocorrelation.size else 0.0,
                      "allan_fit_from": _number(ch.allan_start), "allan_fit_from_unit": "s"})
    between = result.between_noise
    if between is not None:
        for c, entry in enumerate(noise):  # the segment means' noise beyond the within-segment model (docs/fitting.md)
            entry["between_segment_sd"] = _number(math.sqrt(between.variance[c]))
            entry["between_segment_sd_unit"] = UNITS_SI[channel_kind(c)]["mean"]
            entry["between_segment_correlation_time"] = _number(between.correlation_time[c])
            entry["between_segment_correlation_time_unit"] = "s"
            entry["between_segment_dof"] = _number(between.dof[c])
    residuals = []
    for s, k in enumerate(result.used):
        for c, channel in enumerate(CHANNELS):
            if not result.fitted_rows[s, c]:
                continue  # not fitted: a hand turn's accelerometer
            residuals.append({"segment": int(k), "label": result.labels[s], "channel": channel,
                              "residual": _number(result.residuals[s, c]),
                              "u": _number(result.residual_sd[s, c]),
                              "unit": UNITS_SI[channel_kind(c)]["mean"]})
    return {
        "identified": list(result.identified),
        "not_identified": [{"name": name, "reason": reason} for name, reason in result.not_identified.items()],
        "weakly_determined": [{"name": name, "reason": reason} for name, reason in result.weakly_determined.items()],
        "site": result.site.describe(),
        "turntable": result.turntable_source,
        "parameters": parameters,
        "noise": noise,
        "residuals": residuals,
        "chi2_dof": {"chi2": _number(result.chi2), "dof": int(result.chi2_dof),
                     "ratio": _number(result.chi2 / result.chi2_dof) if result.chi2_dof > 0 else None,
                     "verdict": result.chi2_verdict},
        "moves": _moves_json(result.moves),
        "accelerometer_shear": [{"name": item.name, "pair": [item.first, item.second],
                                 "estimate": _number(item.estimate), "u": _number(item.u), "unit": "1",
                                 "determined": item.determined} for item in result.shear],
        "data_sheet_conflict": [{"group": group, "statistic": _number(entry["statistic"]), "dof": int(entry["dof"]),
                                 "p_value": _number(entry["p_value"]), "contradicted": entry["contradicted"],
                                 "data_alone": [{"name": name, "unit": PARAMETERS[PARAMETER_INDEX[name]].si_unit,
                                                 "estimate": _number(estimate), "u": _number(u)}
                                                for name, (estimate, u) in entry.get("data_alone", {}).items()]}
                                for group, entry in result.data_sheet_conflict.items()],
        "notes": list(result.notes),
    }


def _moves_json(moves) -> dict | None:
    """The gravity sequence (``moves`` of ``plansim fit --json``); None when the recording has no two usable moves."""
    if moves is None:
        return None
    used = [{"from_segment": int(t.before), "to_segment": int(t.after), "segments": [int(k) for k in t.between],
             "duration": _number(moves.duration[m]), "duration_unit": "s",
             "angle": _number(moves.angle[m]), "residual": [_number(v) for v in moves.residual[m]],
             "u": [_number(v) for v in moves.residual_sd[m]], "unit": "rad"}
            for m, t in enumerate(moves.transitions)]
    return {"used": used,
            "not_used": [{"segments": where, "reason": reason} for where, reason in moves.unused.items()],
            "chi2_dof": {"chi2": _number(moves.chi2), "dof": int(moves.chi2_dof),
                         "ratio": _number(moves.chi2 / moves.chi2_dof) if moves.chi2_dof > 0 else None,
                         "verdict": moves.chi2_verdict},
            "between_sd": _number(moves.between_sd), "between_sd_unit": "rad",
            "relative_to_accelerometers": [{"name": name, "reason": reason} for name, reason in moves.relative.items()]}


def fit_dataset(result: FitResult) -> xr.Dataset:
    """The fit as a self-describing Dataset (``plansim fit --out fit.nc``): estimates, uncertainties,
    residuals, noise and the between-segment comparison, SI with units."""
    units = [p.si_unit for p in PARAMETERS]
    data = {}
    for method in result.methods:
        data[f"estimate_{method.name}"] = ("parameter", method.estimate,
                                           {"long_name": f"estimate by {method.name}"})
        data[f"u_{method.name}"] = ("parameter", method.u, {"long_name": f"standard uncertainty of {method.name}"})
        data[f"dof_{method.name}"] = ("parameter", method.dof,
                                      {"long_name": f"effective degrees of freedom of {method.name} (JCGM 100 G.4)"})
        for kind, values in method.contributions.items():
            data[f"u_{method.name}_{kind}"] = ("parameter", values,
                                               {"long_name": f"part of u_{method.name} from the {kind} inputs"})
    data["identified"] = ("parameter", np.array([n in result.identified for n in PARAMETER_NAMES], dtype=np.int8),
                          {"long_name": "1 when the recording's segments identify the parameter"})
    weak = result.weakly_determined
    data["weakly_determined"] = ("parameter", np.array([n in weak for n in PARAMETER_NAMES], dtype=np.int8),
                                 {"long_name": "1 when identified but with u beyond what a data sheet already says "
                                               "(plansim.fit.identify.UNINFORMATIVE_U) or mostly the data sheet "
                                               "prior's"})
    data["spec_bias"] = ("parameter", result.spec_bias,
                         {"long_name": "expected error of the specification's estimators at the joint estimate "
                                       "(the site's Earth rate and gravity; NaN when not computed)"})
    data["observed"] = (("segment", "channel"), result.observed, {"long_name": "segment mean, JJF 2003 eq. (3)"})
    data["fitted"] = (("segment", "channel"), result.fitted, {"long_name": "joint model's segment mean"})
    data["residual"] = (("segment", "channel"), result.residuals, {"long_name": "observed - fitted"})
    data["residual_u"] = (("segment", "channel"), result.residual_sd,
                          {"long_name": "predicted standard deviation of the residual"})
    data["within_std"] = (("segment", "channel"), result.noise.within_std,
                          {"long_name": "scatter of the samples within the segment"})
    data["mean_variance"] = (("segment", "channel"), result.noise.mean_variance,
                             {"long_name": "variance of the segment mean from the noise model"})
    for field, long_name in (("white", "white-noise density N"), ("bias_instability", "bias instability B"),
                             ("rate_random_walk", "rate random walk K"), ("quantisation_step", "quantisation step")):
        data[f"noise_{field}"] = ("channel", np.array([getattr(ch, field) for ch in result.noise.channels]),
                                  {"long_name": long_name,
                                   "units": "; ".join(f"{ch.channel}: {ch.units().get(field, ch.units()['mean'])}"
                                                      for ch in result.noise.channels)})
    data["noise_correlated_lags"] = ("channel", np.array([ch.autocorrelation.size for ch in result.noise.channels]),
                                     {"long_name": "lags over which the static noise is correlated from sample to "
                                                   "sample (a sensor's own filter; 0: white)", "units": "1"})
    data["noise_allan_fit_from"] = ("channel", np.array([ch.allan_start for ch in result.noise.channels]),
                                    {"long_name": "shortest tau of the Allan fit", "units": "s"})
    if result.between_noise is not None:
        data["between_noise_sd"] = ("channel", np.sqrt(result.between_noise.variance),
                                    {"long_name": "noise of the segment means beyond the within-segment model, "
                                                  "estimated from the residuals (0: none shown)", "units": "SI"})
        data["between_noise_correlation_time"] = ("channel", result.between_noise.correlation_time,
                                                  {"long_name": "its correlation time between segments (0: "
                                                                "independent)", "units": "s"})
    if result.between:
        for field in ("observed_sd", "predicted_sd", "predicted_noise_sd", "predicted_table_sd", "component_sd",
                      "ratio"):
            data[f"between_{field}"] = ("channel", np.array([getattr(b, field) for b in result.between]),
                                        {"long_name": f"repeated settings: {field.replace('_', ' ')}"})
    moves = result.moves
    if moves is not None:
        data["move_residual"] = (("move", "across_gravity"), moves.residual,
                                 {"long_name": "residual of each move between poses across gravity at its end "
                                               "(the gravity sequence)", "units": "rad"})
        data["move_residual_u"] = (("move", "across_gravity"), moves.residual_sd,
                                   {"long_name": "predicted standard deviation of that residual", "units": "rad"})
        data["move_angle"] = ("move", moves.angle, {"long_name": "angle turned by the move", "units": "rad"})
        data["move_duration"] = ("move", moves.duration, {"long_name": "duration of the move", "units": "s"})
    if result.placed:
        data["tilt"] = (("placed_segment", "tilt_axis"), result.tilts,
                        {"long_name": "fitted tilt of a pose placed by hand from its nominal pose", "units": "rad"})
    coords_extra = {"placed_segment": np.asarray(result.placed, dtype=np.int32), "tilt_axis": ["East", "North"]} \
        if result.placed else {}
    if moves is not None:
        coords_extra.update({"move": np.arange(len(moves.transitions), dtype=np.int32),
                             "move_from_segment": ("move", np.array([t.before for t in moves.transitions], np.int32)),
                             "move_to_segment": ("move", np.array([t.after for t in moves.transitions], np.int32)),
                             "across_gravity": ["first", "second"]})
    ds = xr.Dataset(data, coords={**coords_extra, "parameter": list(PARAMETER_NAMES), "channel": list(CHANNELS),
                                  "segment": np.asarray(result.used, dtype=np.int32),
                                  "parameter_unit": ("parameter", units),
                                  "segment_label": ("segment", list(result.labels))})
    for name in ("observed", "fitted", "residual", "residual_u", "within_std"):
        ds[name].attrs["units"] = "gx gy gz rad/s; ax ay az m/s^2"
    ds["mean_variance"].attrs["units"] = "gx gy gz (rad/s)^2; ax ay az (m/s^2)^2"
    ds.attrs.update({
        "title": "plansim fit of a recording",
        "site": result.site.describe(),
        "turntable": result.turntable_source,
        "chi2": result.chi2, "chi2_dof": result.chi2_dof, "chi2_verdict": result.chi2_verdict,
        "spec_note": result.spec_note,
        "not_identified": "; ".join(f"{k}: {v}" for k, v in result.not_identified.items()),
        "weakly_determined": "; ".join(f"{k}: {v}" for k, v in weak.items()),
        "moves": "none" if moves is None else (f"{len(moves.transitions)} used; chi2 {moves.chi2:.6g} on "
                                               f"{moves.chi2_dof} dof: {moves.chi2_verdict}"),
        "data_sheet_conflict": " | ".join(f"{group}: {describe_conflict(e)}"
                                          for group, e in result.data_sheet_conflict.items())
        or "the data sheet was not carried as a prior",
        "unused_segments": "; ".join(f"{k}: {v}" for k, v in result.unused.items()),
        "notes": " | ".join(result.notes),
    })
    for key, value in result.attrs.items():
        ds.attrs[f"recording_{key}"] = value if isinstance(value, (int, float, str)) else str(value)
    return ds
