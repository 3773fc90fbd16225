"""Sample-level path: every raw sample generated, quantised and folded into its segment mean.

Numba kernels, parallel over trials; no trial × sample array is ever held (a recording of one
trial is the exception, on request). Orientation within a rate point follows the table angle
sample by sample, noise and drift are drawn per sample, saturation and quantisation act on each
raw sample exactly as a data acquisition would.

Array arguments (SI), built by :func:`plansim.simulate.arguments.kernel_arguments`:

- ``seg_*``: the nominal schedule (see engine.schedule_arrays);
- ``sensor`` (8, 3): effect coefficients, rows :data:`plansim.kernels.layout.EFFECT_ROWS`;
  ``S2`` (3, 3) g² sensitivity; ``lever`` (3, 3) accelerometer positions; ``t_ref`` (°C);
- ``acquisition`` (6,): gyro output range, accel output range, gyro step, accel step, gyro full
  scale, accel full scale;
- ``noise`` (6, 4) per channel gx…az: white density (N or VRW), bias-instability σ (Gauss–Markov),
  random-walk coefficient, Gauss–Markov drift σ; ``noise_times`` (3,): bias-instability
  correlation time, Gauss–Markov correlation time, drift update interval;
- ``smoothness``: relative σ of the table rate per sample; ``gravity``; ``earth_enu`` (3,).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.drift import advance_drift, drift_transition, noise_stream
from plansim.kernels.layout import (
    ACQ_FULL_SCALE,
    ACQ_RANGE,
    ACQ_STEP,
    N_TRUTH,
    NOISE_WHITE,
    TIME_DRIFT_UPDATE,
    draws_length,
)
from plansim.kernels.options import jit
from plansim.kernels.physics import (
    draw_systematic,
    geometry_buffers,
    rotated_inputs,
    segment_geometry,
    sensor_outputs,
    unpack_truth,
)
from plansim.kernels.quantiser import quantise
from plansim.kernels.random import normal

#: ``record`` argument of :func:`simulate_trial` from the chunk kernel: a numpy bool, not a Python
#: literal, so that the kernel and :func:`plansim.simulate.chunks.simulate_recording` share one
#: compiled copy
_NO_RECORDING = np.bool_(False)
#: index of the one-slot transition buffer of :func:`simulate_trial` (an int64 for the same reason)
_ONLY_TRANSITION = np.int64(0)


@jit
def simulate_trial(trial, key, draws,
                   seg_n, seg_dt, seg_gap, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                   sensor, S2, lever, t_ref, acquisition, noise, noise_times, smoothness, gravity, earth_enu,
                   means_out, samples_out, record):
    """One calibration, sample by sample, from its systematic *draws*; segment means into ``means_out`` (S, 6).

    If *record*, every raw sample is also written to ``samples_out`` (total samples, 6).
    """
    stream, drift = noise_stream(key, trial, noise)
    Kg, Bg, G, Ka, Ba, P = unpack_truth(draws[:N_TRUTH])
    u, g_b0, om_b0, perp, frames = geometry_buffers(draws)
    transition = np.empty((1, 2, 3, 6))  # one transition at a time
    w = np.empty(3)
    fc = np.empty(3)
    y = np.empty(6)
    acc = np.empty(6)
    white = np.empty(6)
    # per-channel saturation and quantiser (1/step precomputed: a multiplication per sample)
    out_range = np.empty(6)
    step = np.empty(6)
    inverse_step = np.empty(6)
    full_scale = np.empty(6)
    level = np.empty(6)  # total drift of each channel, held between drift updates
    for c in range(6):
        sensor_kind = 0 if c < 3 else 1
        out_range[c] = acquisition[ACQ_RANGE + sensor_kind]
        step[c] = acquisition[ACQ_STEP + sensor_kind]
        inverse_step[c] = 1.0 / step[c] if step[c] > 0.0 else 0.0
        full_scale[c] = acquisition[ACQ_FULL_SCALE + sensor_kind]
    offset = 0
    for s in range(seg_n.shape[0]):
        rate_act, phase = segment_geometry(draws, s, seg_C0, seg_rate, seg_axis, seg_axis_index, gravity,
                                           earth_enu, lever, g_b0, om_b0, u, perp, frames)
        rotating = seg_rate[s] != 0.0
        drift_transition(seg_gap[s], noise, noise_times, transition, _ONLY_TRANSITION)  # settling
        stream = advance_drift(transition, 0, drift, stream)
        dt = seg_dt[s]
        dT = seg_temp[s] - t_ref
        for c in range(6):
            white[c] = noise[c, NOISE_WHITE] / math.sqrt(dt)
            acc[c] = 0.0
        # drift processes are advanced every `hold` samples (exactly, over hold·dt) and held between
        hold = max(1, int(math.floor(noise_times[TIME_DRIFT_UPDATE] / dt + 0.5)))
        drift_transition(hold * dt, noise, noise_times, transition, _ONLY_TRANSITION)
        n = seg_n[s]
        if not rotating:  # at rest the deterministic part of every sample is the same
            for i in range(3):
                fc[i] = g_b0[i]
                w[i] = om_b0[i]
            sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, sensor, S2, y)
        # sin/cos of θ_k by recurrence (one rotation by ω·dt per sample)
        ct = math.cos(phase)
        st = math.sin(phase)
        cd = math.cos(rate_act * dt)
        sd = math.sin(rate_act * dt)
        start = 0
        while start < n:  # one hold interval of samples, then a drift update
            stop = min(start + hold, n)
            for c in range(6):
                level[c] = drift[0, c] + drift[1, c] + drift[2, c]
            for k in range(start, stop):
                if rotating:
                    rate_k = rate_act
                    if smoothness > 0.0:
                        z, stream = normal(stream)
                        rate_k = rate_act * (1.0 + smoothness * z)
                    rotated_inputs(ct, st, rate_k, u, g_b0, om_b0, w, fc)
                    sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, sensor, S2, y)
                    c_next = ct * cd - st * sd
                    st = st * cd + ct * sd
                    ct = c_next
                for c in range(6):
                    val = y[c] + level[c]
                    if white[c] > 0.0:
                        z, stream = normal(stream)
                        val += white[c] * z
                    val = quantise(val, out_range[c], step[c], inverse_step[c], full_scale[c])
                    acc[c] += val
                    if record:
                        samples_out[offset + k, c] = val
            if stop - start < hold:  # to the end of the recording: the last, partial hold interval
                drift_transition((stop - start) * dt, noise, noise_times, transition, _ONLY_TRANSITION)
            stream = advance_drift(transition, 0, drift, stream)
            start = stop
        for c in range(6):
            means_out[s, c] = acc[c] / n
        offset += n


@jit
def simulate_chunk(first_trial, key, truth_nominal, truth_spread, error_kind, error_scale,
                   seg_n, seg_dt, seg_gap, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                   sensor, S2, lever, t_ref, acquisition, noise, noise_times, smoothness, gravity, earth_enu,
                   means_out, truth_out):
    """Trials ``first_trial … first_trial + len(means_out) − 1`` (one random stream per trial).

    Serial and ``nogil``: the engine runs slices of a chunk on a thread pool.
    """
    no_samples = np.empty((0, 6))
    n_seg = seg_n.shape[0]
    for t in range(means_out.shape[0]):
        draws = np.empty(draws_length_jit(n_seg))
        draw_systematic(first_trial + t, key, truth_nominal, truth_spread, error_kind,
                        error_scale, n_seg, draws)
        for k in range(N_TRUTH):
            truth_out[t, k] = draws[k]
        simulate_trial(first_trial + t, key, draws,
                       seg_n, seg_dt, seg_gap, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                       sensor, S2, lever, t_ref, acquisition, noise, noise_times, smoothness, gravity, earth_enu,
                       means_out[t], no_samples, _NO_RECORDING)


draws_length_jit = jit(draws_length)
