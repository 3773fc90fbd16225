"""The catalogue of candidate effects: each one's signature in the segment means of a fitted recording.

A signature is the change of every used segment's means per unit size of each component of the effect,
(S, 6, m), SI. Where the simulator has the effect, the signature is computed through the simulator's own
noise-free physics (:meth:`plansim.fit.model.MeanModel.means` with the kernel's effect arrays), at the fit's
solution θ̂: one model of the world, not two. The effects enter the kernel linearly in their size at a fixed
input, so one step gives the exact column (:data:`STEP` is only a scale).

=========================  =================================================  ======================
effect                     component / unit                                   scenario field
=========================  =================================================  ======================
gyro_scale_asymmetry       per gyro axis: (K+ − K−)/K, 1                       gyro_asymmetry
gyro_scale_nonlinearity    per gyro axis: quadratic 1/(rad/s), cubic 1/(rad/s)² gyro_nonlinearity_*
gyro_g2_sensitivity        gyro i × (f_j f_k): rad/s per (m/s²)²              gyro_g2_sensitivity
accel_quadratic            per accelerometer: K2, 1/(m/s²)                    accel_second_order
bias_drift                 per channel: a linear drift in time, SI/s; and,    (none)
                           where the segments' temperatures differ, a bias
                           linear in temperature, SI/°C (components ``gx_T``…)
lever_arm                  accelerometer i × axis k: m                        accel_lever_arm
=========================  =================================================  ======================

``saturation`` is a property of samples, not of segment means: the within-segment tests look for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plansim.fit.model import nominal_parameters
from plansim.kernels.layout import (
    CHANNELS,
    EFF_ACCEL_SECOND_ORDER,
    EFF_GYRO_ASYMMETRY,
    EFF_GYRO_CUBIC,
    EFF_GYRO_QUADRATIC,
)

#: the spread of the segments' temperatures (°C, largest − smallest) above which the drift has temperature
#: components: a thermometer's resolution is about 0.1 °C
TEMPERATURE_SPREAD = 0.1
#: size of the unit step each signature is taken with, relative to the effect's unit (the kernel is linear in it)
STEP = 1.0
#: the catalogue's effect names, in the order they are reported
EFFECTS = ("gyro_scale_asymmetry", "gyro_scale_nonlinearity", "gyro_g2_sensitivity", "accel_quadratic",
           "bias_drift", "lever_arm")
AXES = "xyz"


def column_name(effect: str, component: str) -> str:
    """The name of one component's column in a refit's extra parameters: ``effect[component]``."""
    return f"{effect}[{component}]"


def split_column_name(name: str) -> tuple[str, str]:
    """(effect, component) of a column named by :func:`column_name`."""
    effect, bracket, rest = name.partition("[")
    if not bracket or not rest.endswith("]"):
        raise ValueError(f"name = {name!r}: a candidate column is named 'effect[component]'")
    return effect, rest[:-1]


@dataclass(frozen=True)
class Signature:
    """One candidate effect's signature in the segment means of a fit."""

    effect: str
    components: tuple[str, ...]
    unit: str  # SI unit of one component's size
    columns: np.ndarray  # (S, 6, m)
    scenario_field: str | None
    description: str
    #: components in the same unit share a group (the excitation test compares like with like); default one group
    unit_groups: tuple[int, ...] | None = None
    #: (m,) the part of each component's column that the designed excitation (table rates, gravity; the Earth rate
    #: left out) gives, ‖x without the Earth rate‖/‖x‖: near 0 when only the Earth rate reaches the component (a
    #: gyro's asymmetry seen in static poses through 15 °/h), which, as in the fit's identifiability, does not
    #: count; None: 1 for every component
    designed: np.ndarray | None = None
    #: (S, 6, m) the columns of an ideal sensor (the nominal parameters, :func:`plansim.fit.model.nominal_parameters`)
    #: in the same poses: what the schedule's geometry excites, the same for every recording of one schedule (the
    #: excitation test reads it, so that a component reached only through the fitted cross-couplings does not
    #: flip between recordings); None: :attr:`columns`
    geometry: np.ndarray | None = None

    def groups(self) -> np.ndarray:
        return np.zeros(len(self.components), dtype=int) if self.unit_groups is None else np.asarray(self.unit_groups)


def _kernel_columns(fit, argument: str, entries) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Columns (S, 6, m) of the kernel's effect array *argument* at each (row, column) of *entries* at the fit's
    solution, (m,) the part of each that the designed excitation gives (:attr:`Signature.designed`), and (S, 6, m)
    the same columns for an ideal sensor in the same poses (:attr:`Signature.geometry`)."""
    model = fit.model

    def columns(theta, earth_enu=None) -> np.ndarray:
        draws = model.draws(theta, fit.nuisance)
        base = model.averaged(draws, earth_enu=earth_enu, effects=None)[0]
        out = []
        for index in entries:
            effects = model.effect_arguments()
            effects[argument][index] += STEP
            out.append((model.averaged(draws, earth_enu=earth_enu, effects={argument: effects[argument]})[0]
                        - base) / STEP)
        return np.stack(out, axis=-1)

    at_fit = columns(fit.theta)
    norm = np.linalg.norm(at_fit.reshape(-1, at_fit.shape[-1]), axis=0)
    without = np.linalg.norm(columns(fit.theta, np.zeros(3)).reshape(-1, at_fit.shape[-1]), axis=0)
    designed = np.where(norm > 0, without / np.where(norm > 0, norm, 1.0), 0.0)
    return at_fit, designed, columns(nominal_parameters())


def signatures(fit) -> tuple[Signature, ...]:
    """The catalogue's signatures in the segment means of *fit* (a :class:`plansim.fit.FitResult`)."""
    if fit.model is None or fit.theta is None:
        raise ValueError("fit: it carries no model (a FitResult from plansim.fit.fit_recording is needed)")
    S = fit.observed.shape[0]
    asymmetry = _kernel_columns(fit, "sensor", [(EFF_GYRO_ASYMMETRY, a) for a in range(3)])
    quadratic = _kernel_columns(fit, "sensor", [(EFF_GYRO_QUADRATIC, a) for a in range(3)])
    cubic = _kernel_columns(fit, "sensor", [(EFF_GYRO_CUBIC, a) for a in range(3)])
    g2 = _kernel_columns(fit, "S2", [(i, j) for i in range(3) for j in range(3)])
    k2 = _kernel_columns(fit, "sensor", [(EFF_ACCEL_SECOND_ORDER, a) for a in range(3)])
    out = [
        Signature("gyro_scale_asymmetry", tuple(AXES), "1", asymmetry[0], "gyro_asymmetry",
                  "the scale factor differs between positive and negative rates: (K+ − K−)/K per gyro",
                  designed=asymmetry[1], geometry=asymmetry[2]),
        Signature("gyro_scale_nonlinearity", tuple(f"{a}2" for a in AXES) + tuple(f"{a}3" for a in AXES),
                  "1/(rad/s) (x2 y2 z2), 1/(rad/s)^2 (x3 y3 z3)",
                  np.concatenate([quadratic[0], cubic[0]], axis=-1),
                  "gyro_nonlinearity_quadratic, gyro_nonlinearity_cubic",
                  "the gyro output has terms in ω² and ω³ of its own rate", (0, 0, 0, 1, 1, 1),
                  designed=np.concatenate([quadratic[1], cubic[1]]),
                  geometry=np.concatenate([quadratic[2], cubic[2]], axis=-1)),
        Signature("gyro_g2_sensitivity", tuple(f"{i}{j}" for i in AXES for j in AXES), "rad/s/(m/s^2)^2",
                  g2[0], "gyro_g2_sensitivity",
                  "the gyro output has terms in products of the specific-force components (g²-sensitivity)",
                  designed=g2[1], geometry=g2[2]),
        Signature("accel_quadratic", tuple(AXES), "1/(m/s^2)", k2[0], "accel_second_order",
                  "the accelerometer output has a term K2·f² in its own specific force", designed=k2[1],
                  geometry=k2[2]),
    ]
    times = np.asarray(fit.segment_times, dtype=float)
    temperatures = np.array([float(s.temperature) for s in fit.model.schedule.segments])
    # linear in temperature as well where the segments' temperatures differ (a temperature channel, or segments
    # logged at different temperatures): the "linear in time or temperature", the simulator's bias
    # temperature coefficient (gyro_bias_temperature_coefficient, accel_bias_temperature_coefficient)
    thermal = temperatures.size == S and np.ptp(temperatures) > TEMPERATURE_SPREAD
    drift = np.zeros((S, 6, 12 if thermal else 6))
    for c in range(6):
        drift[:, c, c] = times - times.mean()
        if thermal:
            drift[:, c, 6 + c] = temperatures - temperatures.mean()
    components = CHANNELS + (tuple(f"{c}_T" for c in CHANNELS) if thermal else ())
    unit = "rad/s/s (gyros), m/s^2/s (accelerometers)" + ("; rad/s/degC, m/s^2/degC (the _T components)"
                                                         if thermal else "")
    out.append(Signature("bias_drift", components, unit, drift, None,
                         "a bias that drifts linearly in time over the recording (per channel)"
                         + (", or in the temperature" if thermal else ""),
                         (0, 0, 0, 1, 1, 1) + ((2, 2, 2, 3, 3, 3) if thermal else ())))
    lever = _kernel_columns(fit, "lever", [(i, k) for i in range(3) for k in range(3)])
    out.append(Signature("lever_arm", tuple(f"{i}{k}" for i in AXES for k in AXES), "m", lever[0], "accel_lever_arm",
                         "accelerometer i sits off the turning axis: the centripetal acceleration ω×(ω×r)",
                         designed=lever[1], geometry=lever[2]))
    for signature in out:  # rows the fit does not fit (a hand turn's accelerometers) carry no signature
        signature.columns[~fit.fitted_rows] = 0.0
        if signature.geometry is not None:
            signature.geometry[~fit.fitted_rows] = 0.0
    return tuple(out)
