"""The JJF 1535 effects (dead zone, resolution, warm-up, turn-on bias) added to a session's segment means.

The simulation kernels (JJF 2003's eq. (1)/(2) and effects) know neither these effects nor power cycles, and
refuse a scenario that sets one (:func:`plansim.simulate.arguments.kernel_arguments`). The JJF 1535 Monte Carlo
therefore simulates the unit without them (:func:`without_jjf1535_effects`) and adds them to the segment means of
the gyro under test, in closed form (:func:`apply_jjf1535_effects`; the formulas are
:mod:`plansim.model.jjf1535_effects`):

- **warm-up transient** ``A·exp(−t/τ)``, t since the last power-on of :attr:`Jjf1535Procedure.power_on`: its mean
  over each segment's samples, exact (:func:`~plansim.model.jjf1535_effects.exponential_segment_mean`);
- **turn-on bias**: one draw from N(0, σ_on²) per power cycle, held over the cycle: exact. The draws come from
  numpy's generator seeded with (seed, trial, :data:`TURN_ON_STREAM`), so they depend on the seed and the trial
  only, like the kernels' streams;
- **dead zone and resolution** act on the input rate w along the gyro's input axis; the segment mean gets
  ``f(response(w)) − f(w)``, f the gyro's response to its own axis (``Kg_ii·(1 + κ_i·ΔT)·w + n2·w² + n3·w³ +
  ½·α·Kg_ii·|w|``) and w the segment's *commanded* rate on that axis plus the Earth rate's component along it at the
  segment's nominal pose. Exact for a table with no rate, position or fixture errors (the zero-noise identity);
  on the JJF 1535 table the sensed rate differs from w by the table's rate error (2.5e-4 of the rate,
  systematic) and its 0.05 % smoothness per sample, which this correction leaves at their linear effect: the
  staircase and the dead zone are applied to w, not to each sample's actual rate. A rate within that 2.5e-4
  of a step of the staircase or of the dead zone's edge may be read on the wrong side of it.

The additions are made after the kernels' acquisition quantised and clipped the samples: with noise far above one
quantisation step (21 bits of 125 °/s: 0.43 °/h) the quantiser is dithered and the order does not matter to the
mean; the JJF 1535 schedule stays far inside the output range.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from plansim.config import Scenario
from plansim.config.scenario import JJF1535_EFFECTS
from plansim.model.jjf1535_effects import exponential_segment_mean, input_response, own_axis_response
from plansim.model.parameters import unpack
from plansim.schedule.jjf1535 import Jjf1535Procedure
from plansim.schedule.segments import axis_vector, body_to_level

#: the third word of the turn-on bias generator's seed (seed, trial, TURN_ON_STREAM): "JJF 1535 7.2.11"
TURN_ON_STREAM = 1535_7211


def without_jjf1535_effects(scenario: Scenario) -> Scenario:
    """*scenario* with every effect of :data:`~plansim.config.scenario.JJF1535_EFFECTS` at 0 (what the kernels
    simulate)."""
    zero = {name: np.zeros_like(np.asarray(getattr(scenario.effects, name), dtype=float)) for name in JJF1535_EFFECTS}
    return dataclasses.replace(scenario, effects=dataclasses.replace(scenario.effects, **zero))


def input_axis_rates(scenario: Scenario, procedure: Jjf1535Procedure) -> np.ndarray:
    """w per segment: the commanded table rate along the gyro's input axis plus the Earth rate's component along
    it at the segment's nominal pose (rad/s, shape (S,)). The procedure's rotations are about the vertical input
    axis, so the Earth rate's component along it stays that of the starting pose."""
    i = procedure.axis
    earth = np.asarray(scenario.environment.earth_rate_vector, dtype=float)
    out = np.empty(len(procedure.schedule))
    for k, segment in enumerate(procedure.schedule.segments):
        table = segment.rate * axis_vector(segment.rate_axis, "rate_axis")[i] if segment.is_rotating else 0.0
        out[k] = table + float((body_to_level(segment.up, segment.heading).T @ earth)[i])
    return out


def apply_jjf1535_effects(means: np.ndarray, truth, scenario: Scenario, procedure: Jjf1535Procedure, seed: int,
                          trial: int, rates: np.ndarray | None = None) -> np.ndarray:
    """*means* (S, 6) of one session with the gyro under test's JJF 1535 effects added (a new array).

    Parameters
    ----------
    means : (S, 6) array
        The segment means the kernels simulated for *scenario* without these effects.
    truth : (39,) array
        That trial's unit (:data:`plansim.model.parameters.PARAMETER_NAMES`, SI).
    scenario : Scenario
        The JJF 1535 world whose ``effects`` set them
        (:func:`~plansim.uncertainty.jjf1535_monte_carlo.jjf1535_scenario`).
    procedure : Jjf1535Procedure
        Its schedule and power cycles.
    seed, trial : int
        For the turn-on bias draws.
    rates : (S,) array, optional
        :func:`input_axis_rates` of the scenario and procedure, if the caller has them.
    """
    e, i = scenario.effects, procedure.axis
    out = np.array(means, dtype=float, copy=True)
    if not e.jjf1535_effects_set():
        return out
    dead_zone, resolution = float(e.gyro_dead_zone[i]), float(e.gyro_resolution[i])
    if dead_zone > 0 or resolution > 0:
        w = input_axis_rates(scenario, procedure) if rates is None else rates
        kg = float(unpack(np.asarray(truth, dtype=float))["Kg"][i, i])
        temperatures = np.array([s.temperature for s in procedure.schedule.segments])
        gain = kg * (1.0 + float(e.gyro_scale_temperature_coefficient[i]) * (temperatures - e.reference_temperature))
        shape = dict(kg=kg, quadratic=float(e.gyro_nonlinearity_quadratic[i]),
                     cubic=float(e.gyro_nonlinearity_cubic[i]), asymmetry=float(e.gyro_asymmetry[i]))
        out[:, i] += (own_axis_response(input_response(w, dead_zone, resolution), gain, **shape)
                      - own_axis_response(w, gain, **shape))
    cycle, since = procedure.power_cycles()
    amplitude = float(e.gyro_warm_up_amplitude[i])
    if amplitude != 0:
        segments = procedure.schedule.segments
        out[:, i] += exponential_segment_mean(since, [s.samples for s in segments],
                                              [1.0 / s.sample_rate for s in segments], amplitude,
                                              float(e.gyro_warm_up_time_constant[i]))
    sigma = float(e.gyro_turn_on_bias[i])
    if sigma > 0:
        draws = np.random.default_rng((seed, trial, TURN_ON_STREAM)).standard_normal(max(len(procedure.power_on), 1))
        out[:, i] += sigma * draws[cycle]
    return out
