"""Systematic effects the JJF 2003 estimators do not correct, as a bias of each parameter (JCGM 100 3.2.3-3.2.4).

The Earth rate, the accelerometers' lever arm, a reference g other than the local g, the printed
sign of eq. (12)-(13), temperature coefficients and the sensor effects outside eq. (1)/(2): each
bias is the reduction of the noise-free segment means with the effect minus without it, at the
expectation of the inputs and averaged over the table start angle. JCGM 100 3.2.4 asks that
recognised systematic effects be corrected; plansim reports them next to ``u_c`` instead.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from plansim.config import Scenario
from plansim.estimate import reduce
from plansim.model.parameters import N_PARAMETERS
from plansim.simulate.arguments import noise_free_segment_means
from plansim.uncertainty.sensitivities import phase_grid_draws

__all__ = ["expected_error", "systematic_effects"]


def _phase_mean_estimate(scenario: Scenario, expected_means: np.ndarray | None = None) -> np.ndarray:
    """The reduction of the start-angle-averaged noise-free means at the nominal draws (39,)."""
    if expected_means is None:
        expected_means = noise_free_segment_means(scenario, phase_grid_draws(scenario)).mean(axis=0)
    return reduce(expected_means, scenario.schedule, scenario.reduction.reference_gravity,
                  scenario.reduction.omega_squared_sign)


def expected_error(scenario: Scenario, expected_means: np.ndarray | None = None) -> np.ndarray:
    """``y`` (39,): estimate − truth of every parameter at the expectation of the inputs, SI (GUM 4.1.4).

    The sum of the systematic effects the estimators do not correct (:func:`systematic_effects`
    splits it). *expected_means* (S, 6): the noise-free segment means at the nominal draws averaged
    over the table start angle, if the caller has them
    (:func:`plansim.uncertainty.budget_lines.model_lines` returns them).
    """
    return _phase_mean_estimate(scenario, expected_means) - scenario.truth_nominal


def systematic_effects(scenario: Scenario, expected_means: np.ndarray | None = None
                       ) -> tuple[np.ndarray, list[tuple[str, np.ndarray, str]]]:
    """The expected error of every parameter and its split into uncorrected systematic effects.

    Each effect's bias is the estimate with the effect minus the estimate without it (all else as
    in the scenario), both from the noise-free segment means at the nominal draws averaged over the
    table start angle. *expected_means*: as for :func:`expected_error`.

    Returns
    -------
    total : ndarray (39,)
        ``y``: estimate − truth at the expectation of the inputs, SI.
    effects : list of (name, bias (39,), note)
        Nonzero effects only; an ``"interaction of the effects"`` line closes the sum when needed.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    full = _phase_mean_estimate(scenario, expected_means)
    total = full - scenario.truth_nominal
    e = scenario.effects
    zero3 = np.zeros(3)
    candidates = []
    if scenario.environment.earth_rate:
        candidates.append(("Earth rate", dataclasses.replace(
            scenario, environment=dataclasses.replace(scenario.environment, earth_rate=False)),
            "not modelled by eq. (1); its vertical component flips with the up/down pairs of §7.2.2"))
    if np.any(e.accel_lever_arm != 0):
        candidates.append(("accelerometer lever arm", dataclasses.replace(
            scenario, effects=dataclasses.replace(e, accel_lever_arm=np.zeros((3, 3)))),
            "centripetal r·ω² follows the same ω² law as P (eq. (12)-(13))"))
    if scenario.reduction.reference_gravity != scenario.environment.gravity:
        candidates.append(("reference gravity", dataclasses.replace(
            scenario,
            reduction=dataclasses.replace(scenario.reduction, reference_gravity=scenario.environment.gravity)),
            f"matrix A uses g = {scenario.reduction.reference_gravity:.6f} m/s^2, local g = "
            f"{scenario.environment.gravity:.6f} m/s^2"))
    if scenario.reduction.omega_squared_sign != "model":
        candidates.append(("omega-squared sign as printed", dataclasses.replace(
            scenario, reduction=dataclasses.replace(scenario.reduction, omega_squared_sign="model")),
            "eq. (12)-(13) as printed return −p"))
    temperature = ("gyro_bias_temperature_coefficient", "gyro_scale_temperature_coefficient",
                   "accel_bias_temperature_coefficient", "accel_scale_temperature_coefficient")
    if any(np.any(getattr(e, name) != 0) for name in temperature):
        candidates.append(("temperature", dataclasses.replace(
            scenario, effects=dataclasses.replace(e, **{name: zero3 for name in temperature})),
            "temperature coefficients with the schedule's temperatures (not in eq. (1)/(2))"))
    others = {"gyro_nonlinearity_quadratic": zero3, "gyro_nonlinearity_cubic": zero3, "gyro_asymmetry": zero3,
              "accel_second_order": zero3, "gyro_g2_sensitivity": np.zeros((3, 3))}
    if any(np.any(getattr(e, name) != 0) for name in others):
        candidates.append(("sensor effects outside eq. (1)/(2)", dataclasses.replace(
            scenario, effects=dataclasses.replace(e, **others)),
            "nonlinearity, asymmetry, g² sensitivity, accelerometer second order"))
    effects = []
    explained = np.zeros(N_PARAMETERS)
    for name, without, note in candidates:
        bias = full - _phase_mean_estimate(without)
        explained += bias
        effects.append((name, bias, note))
    rest = total - explained
    scale = np.maximum(np.abs(scenario.truth_nominal), 1.0) * 1e-12
    if np.any(np.abs(rest) > scale):
        effects.append(("interaction of the effects", rest, "the effects above act together (not additive)"))
    return total, effects
