"""Numba kernels: the sample-level simulation of a whole calibration, parallel over trials.

Plain arrays and floats in SI only; no configuration objects, no xarray. Every raw sample is
generated (orientation within a rate point, sensor model, noise, saturation, quantisation) and
folded into its segment mean in the same pass, so no trial × sample array is ever held.

Physics (docs/model.md): at sample time t of a segment the MIMU body frame b is

    C_nb(t) = C_nb,actual · R(u_b, θ(t)),   θ(t) = θ0 + ω_act·t,

a rotation about the table axis u_b fixed in the body. Vectors known in the level frame n (gravity
``g·Up``, Earth rate Ω_ie) therefore appear in the body as ``R(u_b, −θ)·C_bn,actual·v``. The gyro
input is ``w = ω·u_b + R(u_b, −θ) Ω_b0``; the specific force at the IMU centre is
``f = R(u_b, −θ) g_b0`` and accelerometer i at lever arm r_i adds ``−ω²·(r_i − (r_i·u)u)``.

Sensor outputs follow JJF 2003 eq. (1)/(2) plus the optional effects:

    gyro_i  = Σ_j Kg_ij w_j (1 + κ_i ΔT [j = i]) + Bg_i + β_i ΔT + Σ_j G_ij f_j
              + n2_i w_i² + n3_i w_i³ + ½ α_i Kg_ii |w_i| + Σ_j S_ij f_j² + drift_i + white_i
    accel_i = Σ_j Ka_ij f_ij (1 + κ_i ΔT [j = i]) + Ba_i + β_i ΔT + Σ_j P_ij w_j²
              + k2_i f_ii² + drift_i + white_i

then saturation at ± output range and quantisation to the acquisition step (clipped at ± full
scale).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from plansim._jit import jit, parallel_jit
from plansim.simulate.random import draw_error, normal, seed_trial, uniform

# indices into the per-trial "table draw" vector (calibration-level errors)
STREAM_SYSTEMATIC = 0  # truth spread and table/fixture errors
STREAM_NOISE = 1  # sensor noise, drift and rate smoothness


@jit
def _small_rotation(phi0, phi1, phi2, out):
    """Exact rotation matrix of the rotation vector φ (Rodrigues), written into *out* (3×3)."""
    angle = math.sqrt(phi0 * phi0 + phi1 * phi1 + phi2 * phi2)
    for i in range(3):
        for j in range(3):
            out[i, j] = 1.0 if i == j else 0.0
    if angle == 0.0:
        return
    kx, ky, kz = phi0 / angle, phi1 / angle, phi2 / angle
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    out[0, 0] = c + kx * kx * v
    out[0, 1] = kx * ky * v - kz * s
    out[0, 2] = kx * kz * v + ky * s
    out[1, 0] = ky * kx * v + kz * s
    out[1, 1] = c + ky * ky * v
    out[1, 2] = ky * kz * v - kx * s
    out[2, 0] = kz * kx * v - ky * s
    out[2, 1] = kz * ky * v + kx * s
    out[2, 2] = c + kz * kz * v


@jit
def _unpack_truth(p, Kg, Bg, G, Ka, Ba, P):
    """Flat parameter vector (order of plansim.model.parameters) -> matrices."""
    for i in range(3):
        for j in range(3):
            Kg[i, j] = p[3 * i + j]
            G[i, j] = p[12 + 3 * i + j]
            Ka[i, j] = p[21 + 3 * i + j]
            P[i, j] = 0.0
        Bg[i] = p[9 + i]
        Ba[i] = p[30 + i]
    P[0, 1] = p[33]
    P[0, 2] = p[34]
    P[1, 0] = p[35]
    P[1, 2] = p[36]
    P[2, 0] = p[37]
    P[2, 1] = p[38]


@jit
def _quantise(y, output_range, step, full_scale):
    if y > output_range:
        y = output_range
    elif y < -output_range:
        y = -output_range
    if step > 0.0:
        y = step * math.floor(y / step + 0.5)
        if y > full_scale:
            y = full_scale
        elif y < -full_scale:
            y = -full_scale
    return y


@jit
def _gauss_markov_step(x, phi, sigma, state, zig_x, zig_ratio):
    """Exact first-order Gauss–Markov update over a step with φ = exp(−Δt/τ), stationary σ."""
    return phi * x + sigma * math.sqrt(1.0 - phi * phi) * normal(state, zig_x, zig_ratio)



@jit
def _advance_drift(interval, bi_state, mk_state, rw_state, bi_sigma, bi_tau, markov_sigma, markov_tau, rrw,
                   state, zig_x, zig_ratio):
    """Exact update of the drift processes over *interval* seconds (Gauss–Markov and random walk)."""
    if interval <= 0.0:
        return
    phi_bi = math.exp(-interval / bi_tau)
    phi_mk = math.exp(-interval / markov_tau)
    sq = math.sqrt(interval)
    for c in range(6):
        if bi_sigma[c] > 0.0:
            bi_state[c] = _gauss_markov_step(bi_state[c], phi_bi, bi_sigma[c], state, zig_x, zig_ratio)
        if markov_sigma[c] > 0.0:
            mk_state[c] = _gauss_markov_step(mk_state[c], phi_mk, markov_sigma[c], state, zig_x, zig_ratio)
        if rrw[c] > 0.0:
            rw_state[c] += rrw[c] * sq * normal(state, zig_x, zig_ratio)


@jit
def _sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, n2, n3, asym, S2, k2,
                    gyro_btc, gyro_stc, accel_btc, accel_stc, fi, y):
    """Noise-free outputs (6) for gyro input *w* and specific force *fc* at the IMU centre."""
    for i in range(3):  # gyros, eq. (1) + effects
        val = Bg[i] + gyro_btc[i] * dT
        for j in range(3):
            val += Kg[i, j] * w[j] + G[i, j] * fc[j] + S2[i, j] * fc[j] * fc[j]
        wi = w[i]
        val += Kg[i, i] * gyro_stc[i] * dT * wi + n2[i] * wi * wi + n3[i] * wi * wi * wi
        val += 0.5 * asym[i] * Kg[i, i] * abs(wi)
        y[i] = val
    for i in range(3):  # accelerometers, eq. (2) + effects; accelerometer i sits at its lever arm
        for j in range(3):
            fi[j] = fc[j] + perp[i, j]
        val = Ba[i] + accel_btc[i] * dT
        for j in range(3):
            val += Ka[i, j] * fi[j] + P[i, j] * w[j] * w[j]
        val += Ka[i, i] * accel_stc[i] * dT * fi[i] + k2[i] * fi[i] * fi[i]
        y[3 + i] = val

@jit
def simulate_trial(trial, key, zig_x, zig_ratio,
                   seg_n, seg_dt, seg_gap, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                   truth_nominal, truth_spread,
                   n2, n3, asym, S2, k2, gyro_btc, gyro_stc, accel_btc, accel_stc, t_ref, lever,
                   gyro_range, accel_range,
                   white_density, bi_sigma, bi_tau, rrw, markov_sigma, markov_tau, drift_interval,
                   step_gyro, step_accel, fs_gyro, fs_accel,
                   error_kind, error_scale, smoothness,
                   gravity, earth_enu,
                   means_out, truth_out, samples_out, record):
    """Simulate one calibration: segment means into ``means_out`` (S, 6), truth into ``truth_out`` (39).

    ``error_kind``/``error_scale`` (7,) hold the turntable errors in the order: position accuracy,
    position repeatability, axis perpendicularity, platform tilt, fixture perpendicularity, rate
    error systematic, rate error per point (kind 0 = uniform ± scale, 1 = normal σ = scale).
    If *record*, every raw sample is also written to ``samples_out`` (total samples, 6).
    """
    sys_state = np.empty(4, np.uint64)
    noise_state = np.empty(4, np.uint64)
    seed_trial(key, trial, STREAM_SYSTEMATIC, sys_state)
    seed_trial(key, trial, STREAM_NOISE, noise_state)

    # --- the unit's truth
    for k in range(truth_nominal.shape[0]):
        truth_out[k] = truth_nominal[k] + truth_spread[k] * normal(sys_state, zig_x, zig_ratio)
    Kg = np.empty((3, 3))
    G = np.empty((3, 3))
    Ka = np.empty((3, 3))
    P = np.empty((3, 3))
    Bg = np.empty(3)
    Ba = np.empty(3)
    _unpack_truth(truth_out, Kg, Bg, G, Ka, Ba, P)

    # --- calibration-level (systematic) table and fixture errors
    fixture = np.empty((3, 3))
    f0 = draw_error(sys_state, error_kind[4], error_scale[4], zig_x, zig_ratio)
    f1 = draw_error(sys_state, error_kind[4], error_scale[4], zig_x, zig_ratio)
    f2 = draw_error(sys_state, error_kind[4], error_scale[4], zig_x, zig_ratio)
    _small_rotation(f0, f1, f2, fixture)  # C_fb: MIMU case relative to the fixture
    tilt = np.empty((3, 3))
    t0 = draw_error(sys_state, error_kind[3], error_scale[3], zig_x, zig_ratio)
    t1 = draw_error(sys_state, error_kind[3], error_scale[3], zig_x, zig_ratio)
    _small_rotation(t0, t1, 0.0, tilt)  # platform tilt about East and North
    rate_systematic = draw_error(sys_state, error_kind[5], error_scale[5], zig_x, zig_ratio)
    axis_error = np.empty((3, 2))
    for a in range(3):
        axis_error[a, 0] = draw_error(sys_state, error_kind[2], error_scale[2], zig_x, zig_ratio)
        axis_error[a, 1] = draw_error(sys_state, error_kind[2], error_scale[2], zig_x, zig_ratio)

    # --- noise and drift states (stationary Gauss–Markov start; random walks start at 0)
    bi_state = np.zeros(6)
    mk_state = np.zeros(6)
    rw_state = np.zeros(6)
    for c in range(6):
        if bi_sigma[c] > 0.0:
            bi_state[c] = bi_sigma[c] * normal(noise_state, zig_x, zig_ratio)
        if markov_sigma[c] > 0.0:
            mk_state[c] = markov_sigma[c] * normal(noise_state, zig_x, zig_ratio)

    pos_err = np.empty((3, 3))
    c_actual = np.empty((3, 3))
    tmp = np.empty((3, 3))
    u = np.empty(3)
    g_b0 = np.empty(3)
    om_b0 = np.empty(3)
    w = np.empty(3)
    fc = np.empty(3)
    fi = np.empty(3)
    y = np.empty(6)
    acc = np.empty(6)
    perp = np.empty((3, 3))
    offset = 0

    for s in range(seg_n.shape[0]):
        # per-position errors: C_nb,actual = Tilt · PosErr · C_nb,nominal · C_fb
        e0 = draw_error(sys_state, error_kind[0], error_scale[0], zig_x, zig_ratio) \
            + draw_error(sys_state, error_kind[1], error_scale[1], zig_x, zig_ratio)
        e1 = draw_error(sys_state, error_kind[0], error_scale[0], zig_x, zig_ratio) \
            + draw_error(sys_state, error_kind[1], error_scale[1], zig_x, zig_ratio)
        e2 = draw_error(sys_state, error_kind[0], error_scale[0], zig_x, zig_ratio) \
            + draw_error(sys_state, error_kind[1], error_scale[1], zig_x, zig_ratio)
        rate_point = draw_error(sys_state, error_kind[6], error_scale[6], zig_x, zig_ratio)
        phase = 2.0 * math.pi * uniform(sys_state)
        _small_rotation(e0, e1, e2, pos_err)
        for i in range(3):
            for j in range(3):
                acc_ij = 0.0
                for k in range(3):
                    acc_ij += pos_err[i, k] * seg_C0[s, k, j]
                tmp[i, j] = acc_ij
        for i in range(3):
            for j in range(3):
                acc_ij = 0.0
                for k in range(3):
                    acc_ij += tmp[i, k] * fixture[k, j]
                c_actual[i, j] = acc_ij
        for i in range(3):
            for j in range(3):
                acc_ij = 0.0
                for k in range(3):
                    acc_ij += tilt[i, k] * c_actual[k, j]
                tmp[i, j] = acc_ij
        # body vectors at θ = 0: g_b0 = C_bn·(0, 0, g), Ω_b0 = C_bn·Ω_ie
        for i in range(3):
            g_b0[i] = tmp[2, i] * gravity
            om_b0[i] = tmp[0, i] * earth_enu[0] + tmp[1, i] * earth_enu[1] + tmp[2, i] * earth_enu[2]
        # table axis in the body: nominal (fixture frame) tilted by the axis perpendicularity error,
        # then expressed in the MIMU case frame (C_bf = C_fbᵀ)
        a = seg_axis_index[s]
        n0 = seg_axis[s, 0]
        n1 = seg_axis[s, 1]
        n2v = seg_axis[s, 2]
        # two unit vectors perpendicular to the nominal axis (it is a coordinate axis)
        ia = 0 if abs(n0) > 0.5 else (1 if abs(n1) > 0.5 else 2)
        ib = (ia + 1) % 3
        ic = (ia + 2) % 3
        v = np.zeros(3)
        v[0], v[1], v[2] = n0, n1, n2v
        v[ib] += axis_error[a, 0]
        v[ic] += axis_error[a, 1]
        norm = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        for i in range(3):
            u[i] = (fixture[0, i] * v[0] + fixture[1, i] * v[1] + fixture[2, i] * v[2]) / norm
        rate_act = seg_rate[s] * (1.0 + rate_systematic + rate_point)
        rotating = seg_rate[s] != 0.0
        # centripetal acceleration of each accelerometer: −ω²(r_i − (r_i·u)u)
        for i in range(3):
            ru = lever[i, 0] * u[0] + lever[i, 1] * u[1] + lever[i, 2] * u[2]
            for j in range(3):
                perp[i, j] = -rate_act * rate_act * (lever[i, j] - ru * u[j])

        # drift over the settling time before recording
        _advance_drift(seg_gap[s], bi_state, mk_state, rw_state, bi_sigma, bi_tau, markov_sigma, markov_tau,
                       rrw, noise_state, zig_x, zig_ratio)

        dt = seg_dt[s]
        dT = seg_temp[s] - t_ref
        white_sigma = np.empty(6)
        for c in range(6):
            white_sigma[c] = white_density[c] / math.sqrt(dt)
        # drift processes are advanced every `hold` samples (exactly, over hold·dt) and held between
        hold = max(1, int(math.floor(drift_interval / dt + 0.5)))
        for c in range(6):
            acc[c] = 0.0
        n = seg_n[s]
        if not rotating:
            # at rest the deterministic part of every sample is the same: compute it once
            for i in range(3):
                fc[i] = g_b0[i]
                w[i] = om_b0[i]
            _sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, n2, n3, asym, S2, k2,
                            gyro_btc, gyro_stc, accel_btc, accel_stc, fi, y)
        # sin/cos of θ_k by recurrence (one rotation by ω·dt per sample)
        ct = math.cos(phase)
        st = math.sin(phase)
        cd = math.cos(rate_act * dt)
        sd = math.sin(rate_act * dt)
        ug = u[0] * g_b0[0] + u[1] * g_b0[1] + u[2] * g_b0[2]
        uo = u[0] * om_b0[0] + u[1] * om_b0[1] + u[2] * om_b0[2]
        cg0 = u[1] * g_b0[2] - u[2] * g_b0[1]
        cg1 = u[2] * g_b0[0] - u[0] * g_b0[2]
        cg2 = u[0] * g_b0[1] - u[1] * g_b0[0]
        co0 = u[1] * om_b0[2] - u[2] * om_b0[1]
        co1 = u[2] * om_b0[0] - u[0] * om_b0[2]
        co2 = u[0] * om_b0[1] - u[1] * om_b0[0]
        for k in range(n):
            if rotating:
                # Rodrigues with angle −θ: v cosθ − (u×v) sinθ + u (u·v)(1 − cosθ)
                fc[0] = g_b0[0] * ct - cg0 * st + u[0] * ug * (1.0 - ct)
                fc[1] = g_b0[1] * ct - cg1 * st + u[1] * ug * (1.0 - ct)
                fc[2] = g_b0[2] * ct - cg2 * st + u[2] * ug * (1.0 - ct)
                rate_k = rate_act
                if smoothness > 0.0:
                    rate_k = rate_act * (1.0 + smoothness * normal(noise_state, zig_x, zig_ratio))
                w[0] = rate_k * u[0] + om_b0[0] * ct - co0 * st + u[0] * uo * (1.0 - ct)
                w[1] = rate_k * u[1] + om_b0[1] * ct - co1 * st + u[1] * uo * (1.0 - ct)
                w[2] = rate_k * u[2] + om_b0[2] * ct - co2 * st + u[2] * uo * (1.0 - ct)
                _sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, n2, n3, asym, S2, k2,
                                gyro_btc, gyro_stc, accel_btc, accel_stc, fi, y)
                c_next = ct * cd - st * sd
                st = st * cd + ct * sd
                ct = c_next
            for c in range(6):
                val = y[c] + bi_state[c] + mk_state[c] + rw_state[c]
                if white_sigma[c] > 0.0:
                    val += white_sigma[c] * normal(noise_state, zig_x, zig_ratio)
                if c < 3:
                    val = _quantise(val, gyro_range, step_gyro, fs_gyro)
                else:
                    val = _quantise(val, accel_range, step_accel, fs_accel)
                acc[c] += val
                if record:
                    samples_out[offset + k, c] = val
            if (k + 1) % hold == 0 and k + 1 < n:
                _advance_drift(hold * dt, bi_state, mk_state, rw_state, bi_sigma, bi_tau, markov_sigma,
                               markov_tau, rrw, noise_state, zig_x, zig_ratio)
        # to the end of the recording: the last (partial) hold interval
        tail = n % hold
        _advance_drift((tail if tail else hold) * dt, bi_state, mk_state, rw_state, bi_sigma, bi_tau,
                       markov_sigma, markov_tau, rrw, noise_state, zig_x, zig_ratio)
        for c in range(6):
            means_out[s, c] = acc[c] / n
        offset += n


@parallel_jit
def simulate_chunk(first_trial, key, zig_x, zig_ratio,
                   seg_n, seg_dt, seg_gap, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                   truth_nominal, truth_spread,
                   n2, n3, asym, S2, k2, gyro_btc, gyro_stc, accel_btc, accel_stc, t_ref, lever,
                   gyro_range, accel_range,
                   white_density, bi_sigma, bi_tau, rrw, markov_sigma, markov_tau, drift_interval,
                   step_gyro, step_accel, fs_gyro, fs_accel,
                   error_kind, error_scale, smoothness,
                   gravity, earth_enu,
                   means_out, truth_out):
    """Trials ``first_trial … first_trial + len(means_out) − 1`` in parallel (one stream per trial)."""
    no_samples = np.empty((0, 6))
    for t in numba.prange(means_out.shape[0]):
        simulate_trial(first_trial + t, key, zig_x, zig_ratio,
                       seg_n, seg_dt, seg_gap, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                       truth_nominal, truth_spread,
                       n2, n3, asym, S2, k2, gyro_btc, gyro_stc, accel_btc, accel_stc, t_ref, lever,
                       gyro_range, accel_range,
                       white_density, bi_sigma, bi_tau, rrw, markov_sigma, markov_tau, drift_interval,
                       step_gyro, step_accel, fs_gyro, fs_accel,
                       error_kind, error_scale, smoothness,
                       gravity, earth_enu,
                       means_out[t], truth_out[t], no_samples, False)
