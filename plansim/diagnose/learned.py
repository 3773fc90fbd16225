"""``plansim diagnose --learned``: the world a recording showed, as a scenario document.

A diagnosis ends with a model of one unit: its 39 parameters with their standard uncertainties, its noise from
the data, the site, and the effects the closed testing added with their sizes. :func:`learned_document` writes
that into the TOML document of a scenario (:mod:`plansim.config.scenario`), on top of a base scenario (the lab's
``--scenario``, or the built-in ``jjf2003``) which gives what a recording cannot: the turntable, the acquisition,
the schedule and the reduction. ``plansim run``, ``validate`` and a planner then simulate that world.

What goes where (values written in SI with their unit, so that loading gives back the same numbers):

===============================  ======================================================================
``[environment]``                latitude and height of the fit's site (where known)
``[mimu.truth]``                 each identified parameter's estimate after the refit; the others keep the
                                 base scenario's value
``[mimu.truth_spread]``          each identified parameter's standard uncertainty after the refit (a
                                 simulated unit is drawn around the estimate by what the data leave
                                 unknown); the others keep the base scenario's spread
``[mimu.noise]``                 white noise, bias instability and rate random walk of each channel (Allan
                                 fit of the static segments, IEEE Std 952); a channel without static
                                 segments keeps the base value
``[mimu.effects]``               each selected effect's fitted components (the lever arm: added to the
                                 base scenario's, which the fit was told)
``description``                  what was learned from which recording, and what could not be written
                                 (``bias_drift`` in time has no scenario field; in temperature it is the
                                 ``*_bias_temperature_coefficient`` of ``[mimu.effects]``)
===============================  ======================================================================
"""

from __future__ import annotations

import copy
import math

import numpy as np

from plansim.diagnose.catalogue import TEMPERATURE_SPREAD
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETERS

#: the [mimu.effects] field of each catalogue effect's components, and the base value's role (replace or add)
EFFECT_FIELDS = {
    "gyro_scale_asymmetry": {f"{a}": ("gyro_asymmetry", i, None) for i, a in enumerate("xyz")},
    "gyro_scale_nonlinearity": {**{f"{a}2": ("gyro_nonlinearity_quadratic", i, None) for i, a in enumerate("xyz")},
                                **{f"{a}3": ("gyro_nonlinearity_cubic", i, None) for i, a in enumerate("xyz")}},
    "gyro_g2_sensitivity": {f"{a}{b}": ("gyro_g2_sensitivity", i, j) for i, a in enumerate("xyz")
                            for j, b in enumerate("xyz")},
    "accel_quadratic": {f"{a}": ("accel_second_order", i, None) for i, a in enumerate("xyz")},
    "lever_arm": {f"{a}{b}": ("accel_lever_arm", i, j) for i, a in enumerate("xyz") for j, b in enumerate("xyz")},
    # the drift's temperature components are the simulator's bias temperature coefficients; its time components
    # have no field
    "bias_drift": {**{f"{c}_T": ("gyro_bias_temperature_coefficient", i, None) for i, c in enumerate(CHANNELS[:3])},
                   **{f"{c}_T": ("accel_bias_temperature_coefficient", i, None) for i, c in enumerate(CHANNELS[3:])}},
}
#: the SI unit each [mimu.effects] field is written in
EFFECT_UNITS = {"gyro_asymmetry": "1", "gyro_nonlinearity_quadratic": "1/(rad/s)",
                "gyro_nonlinearity_cubic": "1/(rad/s)^2", "gyro_g2_sensitivity": "rad/s/(m/s^2)^2",
                "accel_second_order": "1/(m/s^2)", "accel_lever_arm": "m",
                "gyro_bias_temperature_coefficient": "rad/s/degC", "accel_bias_temperature_coefficient": "m/s^2/degC"}
#: the base scenario's value is the fit's known input for these fields (added to), a guess for the others
ADDED_TO_BASE = {"accel_lever_arm"}
#: [mimu.noise] keys from the data's noise per kind of channel: (white, bias instability, rate random walk)
NOISE_KEYS = {"gyro": ("gyro_angle_random_walk", "rad/sqrt(s)", "gyro_bias_instability", "rad/s",
                       "gyro_rate_random_walk", "rad/s/sqrt(s)"),
              "accel": ("accel_velocity_random_walk", "m/s/sqrt(s)", "accel_bias_instability", "m/s^2",
                        "accel_acceleration_random_walk", "m/s^2/sqrt(s)")}


def _si(value: float, unit: str) -> str | float:
    """*value* as the scenario file takes it: a number (dimensionless) or "repr unit" (SI; loads back exactly)."""
    return float(value) if unit in ("1", "") else f"{float(value)!r} {unit}"


def _base_values(scenario) -> dict:
    e = scenario.effects
    return {name: np.array(getattr(e, name), dtype=float) for name in EFFECT_UNITS}


def learned_document(diagnosis, base, recording_name: str = "the recording", temperatures=None) -> dict:
    """The scenario document (a dict for TOML) of the world *diagnosis* found, on top of scenario *base*.

    Parameters
    ----------
    diagnosis : plansim.diagnose.procedure.Diagnosis
    base : plansim.config.Scenario
        Gives the turntable, the acquisition, the schedule, the reduction and every value the recording does not
        identify.
    recording_name : str
        Named in the description (provenance).
    temperatures : sequence of float, optional
        The recording's segment temperatures, °C, in time order: where they differ by more than
        :data:`plansim.diagnose.catalogue.TEMPERATURE_SPREAD` (the spread above which the drift has temperature
        components), the schedule's ``temperature_start`` and ``temperature_end`` become the first
        and the last (a bias's temperature coefficient found in the data is then simulated over the range that
        showed it); otherwise the base scenario's stay.

    Returns
    -------
    dict
        Parse it with :func:`plansim.config.scenario.parse_scenario`; write it with
        :func:`plansim.io.scenario_file.save_scenario` (module docstring: what goes where).
    """
    after = diagnosis.after
    document = copy.deepcopy(base.document)
    site = after.site
    if math.isfinite(site.latitude) and math.isfinite(site.height):
        document.setdefault("environment", {})
        document["environment"]["latitude"] = _si(site.latitude, "rad")
        document["environment"]["height"] = _si(site.height, "m")
    mimu = document.setdefault("mimu", {})
    truth = mimu.setdefault("truth", {})
    spread = mimu.setdefault("truth_spread", {})
    estimate, u = np.asarray(after.joint.estimate, dtype=float), np.asarray(after.joint.u, dtype=float)
    learned = []
    for k, p in enumerate(PARAMETERS):
        if math.isfinite(estimate[k]) and math.isfinite(u[k]):
            truth[p.name] = _si(estimate[k], p.si_unit)
            spread[p.name] = _si(u[k], p.si_unit)
            learned.append(p.name)
    noise = mimu.setdefault("noise", {})
    for kind, channels in (("gyro", range(3)), ("accel", range(3, 6))):
        white_key, white_unit, b_key, b_unit, k_key, k_unit = NOISE_KEYS[kind]
        base_noise = base.noise
        base_arrays = {"gyro": (base_noise.gyro_angle_random_walk, base_noise.gyro_bias_instability,
                                base_noise.gyro_rate_random_walk),
                       "accel": (base_noise.accel_velocity_random_walk, base_noise.accel_bias_instability,
                                 base_noise.accel_acceleration_random_walk)}[kind]
        values = [np.array(a, dtype=float) for a in base_arrays]
        for axis, c in enumerate(channels):
            ch = after.noise.channels[c]
            for v, found in zip(values, (ch.white, ch.bias_instability, ch.rate_random_walk)):
                if math.isfinite(found):
                    v[axis] = found
        for key, unit, v in ((white_key, white_unit, values[0]), (b_key, b_unit, values[1]),
                             (k_key, k_unit, values[2])):
            noise[key] = [_si(x, unit) for x in v]
    effects = mimu.setdefault("effects", {})
    base_effects = _base_values(base)
    changed = {}
    skipped = []
    for effect in diagnosis.selected:
        size = diagnosis.sizes.get(effect)
        fields = EFFECT_FIELDS.get(effect, {})
        unwritten = [] if size is None else [c for c in size["components"] if c not in fields]
        if size is None or len(unwritten) == len(size["components"]):
            skipped.append(effect)
            continue
        if unwritten:
            skipped.append(f"{effect} ({' '.join(unwritten)})")
        for component, value in zip(size["components"], size["value"]):
            if component not in fields:
                continue
            name, i, j = fields[component]
            array = changed.setdefault(name, base_effects[name].copy())
            index = i if j is None else (i, j)
            array[index] = (array[index] + value) if name in ADDED_TO_BASE else value
    for name, array in changed.items():
        unit = EFFECT_UNITS[name]
        effects[name] = ([_si(x, unit) for x in array] if array.ndim == 1
                         else [[_si(x, unit) for x in row] for row in array])
    logged = np.asarray([] if temperatures is None else temperatures, dtype=float)
    logged = logged[np.isfinite(logged)]
    ramp = ""
    if logged.size and float(logged.max() - logged.min()) > TEMPERATURE_SPREAD:
        schedule = document.setdefault("schedule", {})
        schedule["temperature_start"] = _si(logged[0], "degC")
        schedule["temperature_end"] = _si(logged[-1], "degC")
        ramp = f" The schedule's temperature goes from {logged[0]:.3g} to {logged[-1]:.3g} °C, as the recording's did."
    found = ", ".join(diagnosis.selected) if diagnosis.selected else "no catalogue effect"
    note = (f"Learned by plansim diagnose from {recording_name}: {len(learned)} of 39 parameters identified "
            f"(truth = the estimate after the refit, truth_spread = its standard uncertainty), the noise of "
            f"{', '.join(c for c, ch in zip(CHANNELS, after.noise.channels) if math.isfinite(ch.white))} from the "
            f"data, the site; found: {found}.")
    if skipped:
        note += f" Not written (no scenario field): {', '.join(skipped)}."
    note += f" Turntable, acquisition, schedule and reduction from the base scenario {base.name!r}." + ramp
    document["description"] = note
    document["name"] = f"learned-{base.name}"
    return document
