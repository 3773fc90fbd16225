"""Which simulation path a scenario takes: the segment-statistics path only where it is exact.

The sample-level path is exact for every scenario; the segment-statistics path
(:mod:`plansim.kernels.segment_path`) draws each segment mean from its exact distribution, which
holds only without gyro asymmetry and saturation, and, for quantisers the noise does not dither,
with drift small against the noise (:func:`segment_path_exactness`).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.config import Scenario
from plansim.kernels import segment_path
from plansim.kernels.layout import CHANNELS, NOISE_BIAS_INSTABILITY, NOISE_MARKOV, NOISE_RANDOM_WALK, NOISE_WHITE
from plansim.model.parameters import unpack
from plansim.simulate.arguments import kernel_arguments, needed_channels

PATHS = ("auto", "sample", "segment")
PATH_NAMES = {"sample": "sample-level", "segment": "segment-statistics"}


def output_bound(scenario: Scenario) -> np.ndarray:
    """A conservative bound on |noise-free output| per channel (gx…az, SI) over the whole schedule.

    Every coefficient is taken at |nominal| + 6 × its unit-to-unit spread and every input at its
    largest magnitude: rate r = max |table rate| + Ω_ie, specific force f = g + r²·|lever arm|,
    temperature offset the largest |T − T_ref|. Plain NumPy (no kernel to compile).
    """
    e = scenario.effects
    m = unpack(np.abs(scenario.truth_nominal) + 6 * np.abs(scenario.truth_spread))
    segments = scenario.schedule.segments
    r = max(abs(s.rate) for s in segments) + float(np.linalg.norm(scenario.environment.earth_rate_vector))
    dT = max(abs(s.temperature - e.reference_temperature) for s in segments)
    g = scenario.environment.gravity
    f = g + r * r * np.linalg.norm(e.accel_lever_arm, axis=1).max()
    kg_diag = np.diag(m["Kg"])
    gyro = (m["Kg"].sum(1) * r + m["Bg"] + np.abs(e.gyro_bias_temperature_coefficient) * dT + m["G"].sum(1) * f
            + np.abs(e.gyro_g2_sensitivity).sum(1) * f * f
            + kg_diag * np.abs(e.gyro_scale_temperature_coefficient) * dT * r
            + np.abs(e.gyro_nonlinearity_quadratic) * r**2 + np.abs(e.gyro_nonlinearity_cubic) * r**3
            + 0.5 * np.abs(e.gyro_asymmetry) * kg_diag * r)
    ka_diag = np.diag(m["Ka"])
    accel = (m["Ka"].sum(1) * f + m["Ba"] + np.abs(e.accel_bias_temperature_coefficient) * dT + m["P"].sum(1) * r * r
             + ka_diag * np.abs(e.accel_scale_temperature_coefficient) * dT * f + np.abs(e.accel_second_order) * f * f)
    return np.concatenate([gyro, accel])


def segment_path_exactness(scenario: Scenario) -> list[str]:
    """Reasons the segment-statistics path would not be exact for *scenario* (empty list: it is).

    Checks, each stated in :mod:`plansim.kernels.segment_path`: no gyro asymmetry; no
    saturation (:func:`output_bound` plus 6σ of white noise and drift inside the output range and
    the acquisition full scale); for quantised channels that the noise does not dither, drift small
    against the noise (≤ 0.1σ) so that its variation within a segment does not move the quantiser;
    and some white noise on every quantised channel an estimator reads while the table turns.
    """
    reasons = []
    e, a = scenario.effects, scenario.acquisition
    if np.any(e.gyro_asymmetry != 0):
        reasons.append("gyro asymmetry is on: |ω| is not a polynomial in the table angle")
    noise = kernel_arguments(scenario)["noise"]
    sample_dt = min(1.0 / s.sample_rate for s in scenario.schedule.segments)
    white = noise[:, NOISE_WHITE] / math.sqrt(sample_dt)
    drift_sigma = np.sqrt(noise[:, NOISE_BIAS_INSTABILITY] ** 2 + noise[:, NOISE_MARKOV] ** 2
                          + noise[:, NOISE_RANDOM_WALK] ** 2 * scenario.schedule.duration)
    bound = output_bound(scenario) + 6 * (white + drift_sigma)
    limits = np.array([e.gyro_output_range] * 3 + [e.accel_output_range] * 3)
    if a.bits:
        limits = np.minimum(limits, [a.gyro_full_scale] * 3 + [a.accel_full_scale] * 3)
    for c in np.flatnonzero(bound >= limits):
        reasons.append(f"channel {CHANNELS[c]} may saturate: bound {bound[c]:.4g} >= limit {limits[c]:.4g} (SI)")
    if a.bits:
        steps = np.array([a.gyro_step] * 3 + [a.accel_step] * 3)
        n_max = max(seg.samples for seg in scenario.schedule.segments)
        bias = steps / np.pi * np.exp(-2 * np.pi**2 * white**2 / steps**2)
        dithered = bias <= segment_path.RELATIVE_TOLERANCE * white / math.sqrt(n_max)
        for c in np.flatnonzero(~dithered & (drift_sigma > 0.1 * np.maximum(white, 1e-300))):
            reasons.append(f"channel {CHANNELS[c]}: drift σ {drift_sigma[c]:.3g} > 0.1 × white σ {white[c]:.3g} "
                           "in a quantiser the noise does not dither")
        # without noise a quantiser's output is a staircase in the table angle while the table turns,
        # which an average over θ at nodes cannot catch (at rest it is plain rounding, which is exact)
        rotating = np.array([seg.rate != 0.0 for seg in scenario.schedule.segments])
        needed_turning = needed_channels(scenario.schedule)[rotating].any(axis=0)
        for c in np.flatnonzero((white == 0.0) & needed_turning):
            reasons.append(f"channel {CHANNELS[c]} is quantised without white noise while the table turns: its "
                           "output is a staircase in the table angle, not a smooth function to average")
    return reasons


def choose_path(scenario: Scenario, path: str = "auto") -> tuple[str, list[str]]:
    """``(path, reasons)``: *auto* takes the segment-statistics path only where it is exact."""
    if path not in PATHS:
        raise ValueError(f"path = {path!r}; allowed: {', '.join(PATHS)}")
    if path == "sample":
        return "sample", []
    reasons = segment_path_exactness(scenario)
    if path == "auto":
        return ("sample" if reasons else "segment"), reasons
    return "segment", reasons
