"""The physics shared by both simulation paths (numba, plain SI arrays).

A trial is split into its *systematic draws* — the unit's truth and every table/fixture error, in
one flat vector (layout below) — and what follows deterministically from them: the orientation of
the MIMU in each segment and the noise-free sensor output at any table angle θ. Noise is added by
the path (sample by sample, or as exact segment statistics). Keeping the draws explicit lets a
caller fix any of them (e.g. the GUM sensitivities of :mod:`plansim.uncertainty`).

The draws vector's layout, and every other packed array's, is named in :mod:`plansim.kernels.layout`.

Physics (docs/model.md): ``C_nb(θ) = Tilt · PosErr · C_nb,nominal · C_fb · R(u_b, θ)``; the gyro
input is ``w = ω·u_b + R(u_b, −θ) Ω_b0`` and the specific force at the IMU centre
``f = R(u_b, −θ) g_b0``; accelerometer i at lever arm r_i adds ``−ω²(r_i − (r_i·u)u)``.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.layout import (
    BA_FIRST,
    BG_FIRST,
    EFF_ACCEL_BIAS_TEMPERATURE,
    EFF_ACCEL_SCALE_TEMPERATURE,
    EFF_ACCEL_SECOND_ORDER,
    EFF_GYRO_ASYMMETRY,
    EFF_GYRO_BIAS_TEMPERATURE,
    EFF_GYRO_CUBIC,
    EFF_GYRO_QUADRATIC,
    EFF_GYRO_SCALE_TEMPERATURE,
    ERR_AXIS_PERPENDICULARITY,
    ERR_FIXTURE_PERPENDICULARITY,
    ERR_PLATFORM_TILT,
    ERR_POSITION_ACCURACY,
    ERR_POSITION_REPEATABILITY,
    ERR_RATE_PER_POINT,
    ERR_RATE_SYSTEMATIC,
    FIXTURE_FIRST,
    G_FIRST,
    HEAD,
    KA_FIRST,
    KG_FIRST,
    N_TRUTH,
    P_ENTRIES,
    P_FIRST,
    PER_SEGMENT,
    PERPENDICULARITY_FIRST,
    RATE_SYSTEMATIC,
    SEG_PHASE,
    SEG_POSITION_ACCURACY,
    SEG_POSITION_REPEATABILITY,
    SEG_RATE_ERROR,
    STREAM_SYSTEMATIC,
    TILT_FIRST,
)
from plansim.kernels.options import inline_jit, jit
from plansim.kernels.random import draw_error, normal, seed_stream, uniform


@jit
def draw_systematic(trial, key, truth_nominal, truth_spread, error_kind, error_scale,
                    n_segments, draws):
    """Fill *draws* with trial *trial*'s truth and table errors (stream 0 of its random stream).

    ``error_kind``/``error_scale`` (7,): position accuracy, position repeatability, axis
    perpendicularity, platform tilt, fixture perpendicularity, rate error systematic, rate error
    per point (kind 0 = uniform ± scale, 1 = normal σ = scale).
    """
    stream = seed_stream(key, trial, STREAM_SYSTEMATIC)
    for k in range(N_TRUTH):
        z, stream = normal(stream)
        draws[k] = truth_nominal[k] + truth_spread[k] * z
    for k in range(3):
        draws[FIXTURE_FIRST + k], stream = draw_error(stream, error_kind[ERR_FIXTURE_PERPENDICULARITY],
                                                     error_scale[ERR_FIXTURE_PERPENDICULARITY])
    draws[TILT_FIRST], stream = draw_error(stream, error_kind[ERR_PLATFORM_TILT], error_scale[ERR_PLATFORM_TILT])
    draws[TILT_FIRST + 1], stream = draw_error(stream, error_kind[ERR_PLATFORM_TILT], error_scale[ERR_PLATFORM_TILT])
    draws[RATE_SYSTEMATIC], stream = draw_error(stream, error_kind[ERR_RATE_SYSTEMATIC],
                                                 error_scale[ERR_RATE_SYSTEMATIC])
    for k in range(6):
        draws[PERPENDICULARITY_FIRST + k], stream = draw_error(stream, error_kind[ERR_AXIS_PERPENDICULARITY],
                                                              error_scale[ERR_AXIS_PERPENDICULARITY])
    for s in range(n_segments):
        base = HEAD + PER_SEGMENT * s
        for axis in range(3):
            draws[base + SEG_POSITION_ACCURACY + 2 * axis], stream = draw_error(
                stream, error_kind[ERR_POSITION_ACCURACY], error_scale[ERR_POSITION_ACCURACY])
            draws[base + SEG_POSITION_REPEATABILITY + 2 * axis], stream = draw_error(
                stream, error_kind[ERR_POSITION_REPEATABILITY], error_scale[ERR_POSITION_REPEATABILITY])
        draws[base + SEG_RATE_ERROR], stream = draw_error(stream, error_kind[ERR_RATE_PER_POINT],
                                                       error_scale[ERR_RATE_PER_POINT])
        phase, stream = uniform(stream)
        draws[base + SEG_PHASE] = 2.0 * math.pi * phase


@inline_jit
def small_rotation(phi0, phi1, phi2, frames, k):
    """Exact rotation matrix of the rotation vector φ (Rodrigues), written into ``frames[k]`` (3×3).

    Kernels index slabs of one ``frames`` array instead of taking views: in numba every view is
    a reference-counted object, and an atomic count per view per segment cost 18 % of a trial.
    """
    angle = math.sqrt(phi0 * phi0 + phi1 * phi1 + phi2 * phi2)
    for i in range(3):
        for j in range(3):
            frames[k, i, j] = 1.0 if i == j else 0.0
    if angle == 0.0:
        return
    kx, ky, kz = phi0 / angle, phi1 / angle, phi2 / angle
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    frames[k, 0, 0] = c + kx * kx * v
    frames[k, 0, 1] = kx * ky * v - kz * s
    frames[k, 0, 2] = kx * kz * v + ky * s
    frames[k, 1, 0] = ky * kx * v + kz * s
    frames[k, 1, 1] = c + ky * ky * v
    frames[k, 1, 2] = ky * kz * v - kx * s
    frames[k, 2, 0] = kz * kx * v - ky * s
    frames[k, 2, 1] = kz * ky * v + kx * s
    frames[k, 2, 2] = c + kz * kz * v


@jit
def unpack_truth(p):
    """Flat parameter vector (order of plansim.model.parameters) -> new arrays ``Kg, Bg, G, Ka, Ba, P``."""
    Kg = np.empty((3, 3))
    G = np.empty((3, 3))
    Ka = np.empty((3, 3))
    P = np.empty((3, 3))
    Bg = np.empty(3)
    Ba = np.empty(3)
    for i in range(3):
        for j in range(3):
            Kg[i, j] = p[KG_FIRST + 3 * i + j]
            G[i, j] = p[G_FIRST + 3 * i + j]
            Ka[i, j] = p[KA_FIRST + 3 * i + j]
            P[i, j] = 0.0
        Bg[i] = p[BG_FIRST + i]
        Ba[i] = p[BA_FIRST + i]
    for k in range(6):
        P[P_ENTRIES[k][0], P_ENTRIES[k][1]] = p[P_FIRST + k]
    return Kg, Bg, G, Ka, Ba, P


@inline_jit
def _matmul3(frames, a, b, out):
    """``frames[out] = frames[a] · frames[b]`` (3×3 slabs of one array; see :func:`small_rotation`)."""
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for k in range(3):
                acc += frames[a, i, k] * frames[b, k, j]
            frames[out, i, j] = acc


#: *channel* of :func:`evaluate_outputs` for all six outputs (an int64, not a literal: one compiled copy)
ALL_CHANNELS = np.int64(-1)
#: *channel* of :func:`evaluate_outputs` for the three gyros' outputs, and for the three accelerometers'
GYRO_OUTPUTS = np.int64(-2)
ACCEL_OUTPUTS = np.int64(-3)

# slabs of the (6, 3, 3) ``frames`` array of :func:`geometry_buffers`
_FIXTURE, _TILT, _POSITION_ERROR, _NOMINAL, _PRODUCT, _ACTUAL = 0, 1, 2, 3, 4, 5


@jit
def geometry_buffers(draws):
    """Buffers for :func:`segment_geometry` — ``u, g_b0, om_b0, perp, frames`` — with the trial's
    frames already in ``frames`` (:func:`trial_frames`)."""
    frames = np.empty((6, 3, 3))
    trial_frames(draws, frames)
    return np.empty(3), np.empty(3), np.empty(3), np.empty((3, 3)), frames


@jit
def trial_frames(draws, frames):
    """Per-trial rotations into ``frames[0]`` (fixture: MIMU case in the fixture, C_fb) and
    ``frames[1]`` (platform tilt about East and North); call once before :func:`segment_geometry`."""
    small_rotation(draws[FIXTURE_FIRST], draws[FIXTURE_FIRST + 1], draws[FIXTURE_FIRST + 2], frames, _FIXTURE)
    small_rotation(draws[TILT_FIRST], draws[TILT_FIRST + 1], 0.0, frames, _TILT)


@jit
def segment_geometry(draws, s, seg_C0, seg_rate, seg_axis, seg_axis_index, gravity, earth_enu, lever,
                     g_b0, om_b0, u, perp, frames):
    """Orientation of segment *s* under the trial's errors.

    Writes the body-frame gravity reaction ``g_b0`` and Earth rate ``om_b0`` at θ = 0, the table
    axis ``u`` (body frame, unit) and the centripetal term ``perp`` (3×3: row i for accelerometer
    i); returns ``(rate_act, phase)``: the actual table rate (rad/s) and start angle (rad).
    ``frames`` (6, 3, 3) holds the trial's frames (:func:`trial_frames`) in ``frames[0:2]`` and is
    scratch space otherwise.
    """
    base = HEAD + PER_SEGMENT * s
    acc, rep = base + SEG_POSITION_ACCURACY, base + SEG_POSITION_REPEATABILITY  # + 2·axis
    small_rotation(draws[acc] + draws[rep], draws[acc + 2] + draws[rep + 2],
                   draws[acc + 4] + draws[rep + 4], frames, _POSITION_ERROR)
    for i in range(3):
        for j in range(3):
            frames[_NOMINAL, i, j] = seg_C0[s, i, j]
    _matmul3(frames, _POSITION_ERROR, _NOMINAL, _PRODUCT)
    _matmul3(frames, _PRODUCT, _FIXTURE, _ACTUAL)
    _matmul3(frames, _TILT, _ACTUAL, _PRODUCT)  # C_nb,actual
    for i in range(3):  # C_bn = C_nbᵀ: g_b0 = C_bn·(0, 0, g), Ω_b0 = C_bn·Ω_ie
        g_b0[i] = frames[_PRODUCT, 2, i] * gravity
        om_b0[i] = (frames[_PRODUCT, 0, i] * earth_enu[0] + frames[_PRODUCT, 1, i] * earth_enu[1]
                    + frames[_PRODUCT, 2, i] * earth_enu[2])
    # table axis: nominal (a coordinate axis of the fixture) tilted by the perpendicularity error
    # about the two other axes, expressed in the MIMU case frame (C_bf = C_fbᵀ)
    a = seg_axis_index[s]
    v0, v1, v2 = seg_axis[s, 0], seg_axis[s, 1], seg_axis[s, 2]
    first, second = draws[PERPENDICULARITY_FIRST + 2 * a], draws[PERPENDICULARITY_FIRST + 2 * a + 1]
    if abs(v0) > 0.5:
        v1 += first
        v2 += second
    elif abs(v1) > 0.5:
        v2 += first
        v0 += second
    else:
        v0 += first
        v1 += second
    norm = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    for i in range(3):
        u[i] = (frames[_FIXTURE, 0, i] * v0 + frames[_FIXTURE, 1, i] * v1 + frames[_FIXTURE, 2, i] * v2) / norm
    rate_act = seg_rate[s] * (1.0 + draws[RATE_SYSTEMATIC] + draws[base + SEG_RATE_ERROR])
    for i in range(3):  # centripetal acceleration of accelerometer i: −ω²(r_i − (r_i·u)u)
        ru = lever[i, 0] * u[0] + lever[i, 1] * u[1] + lever[i, 2] * u[2]
        for j in range(3):
            perp[i, j] = -rate_act * rate_act * (lever[i, j] - ru * u[j])
    return rate_act, draws[base + SEG_PHASE]


@inline_jit
def rotated_inputs(ct, st, rate, u, g_b0, om_b0, w, fc):
    """Gyro input *w* and specific force *fc* at table angle θ (given cos θ, sin θ) with table rate
    *rate*: Rodrigues with angle −θ, ``v cosθ − (u×v) sinθ + u (u·v)(1 − cosθ)``."""
    ug = u[0] * g_b0[0] + u[1] * g_b0[1] + u[2] * g_b0[2]
    uo = u[0] * om_b0[0] + u[1] * om_b0[1] + u[2] * om_b0[2]
    fc[0] = g_b0[0] * ct - (u[1] * g_b0[2] - u[2] * g_b0[1]) * st + u[0] * ug * (1.0 - ct)
    fc[1] = g_b0[1] * ct - (u[2] * g_b0[0] - u[0] * g_b0[2]) * st + u[1] * ug * (1.0 - ct)
    fc[2] = g_b0[2] * ct - (u[0] * g_b0[1] - u[1] * g_b0[0]) * st + u[2] * ug * (1.0 - ct)
    w[0] = rate * u[0] + om_b0[0] * ct - (u[1] * om_b0[2] - u[2] * om_b0[1]) * st + u[0] * uo * (1.0 - ct)
    w[1] = rate * u[1] + om_b0[1] * ct - (u[2] * om_b0[0] - u[0] * om_b0[2]) * st + u[1] * uo * (1.0 - ct)
    w[2] = rate * u[2] + om_b0[2] * ct - (u[0] * om_b0[1] - u[1] * om_b0[0]) * st + u[2] * uo * (1.0 - ct)


@inline_jit
def gyro_output(i, w, fc, dT, Kg, Bg, G, sensor, S2):
    """Noise-free output of gyro *i*: JJF 2003 eq. (1), row i, plus its effects (:func:`sensor_outputs`)."""
    val = Bg[i] + sensor[EFF_GYRO_BIAS_TEMPERATURE, i] * dT
    for j in range(3):
        val += Kg[i, j] * w[j] + G[i, j] * fc[j] + S2[i, j] * fc[j] * fc[j]
    wi = w[i]
    val += (Kg[i, i] * sensor[EFF_GYRO_SCALE_TEMPERATURE, i] * dT * wi + sensor[EFF_GYRO_QUADRATIC, i] * wi * wi
            + sensor[EFF_GYRO_CUBIC, i] * wi * wi * wi)
    val += 0.5 * sensor[EFF_GYRO_ASYMMETRY, i] * Kg[i, i] * abs(wi)
    return val


@inline_jit
def accel_output(i, w, fc, perp, dT, Ka, Ba, P, sensor):
    """Noise-free output of accelerometer *i* at its lever arm: JJF 2003 eq. (2), row i, plus its effects."""
    f0 = fc[0] + perp[i, 0]
    f1 = fc[1] + perp[i, 1]
    f2 = fc[2] + perp[i, 2]
    fi = f0 if i == 0 else (f1 if i == 1 else f2)
    val = Ba[i] + sensor[EFF_ACCEL_BIAS_TEMPERATURE, i] * dT
    val += Ka[i, 0] * f0 + Ka[i, 1] * f1 + Ka[i, 2] * f2
    val += P[i, 0] * w[0] * w[0] + P[i, 1] * w[1] * w[1] + P[i, 2] * w[2] * w[2]
    val += Ka[i, i] * sensor[EFF_ACCEL_SCALE_TEMPERATURE, i] * dT * fi + sensor[EFF_ACCEL_SECOND_ORDER, i] * fi * fi
    return val


@inline_jit
def sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, sensor, S2, y):
    """Noise-free outputs (6) for gyro input *w* and specific force *fc* at the IMU centre.

    JJF 2003 eq. (1)/(2) plus the effects in ``sensor`` (rows :data:`EFFECT_ROWS`) and ``S2``
    (g² sensitivity, 3×3); ``dT`` = temperature − reference temperature. Channel i reads row i of
    the truth's matrices and entry i of its biases alone (:func:`truth_channel`).
    """
    for i in range(3):  # gyros, eq. (1) + effects
        y[i] = gyro_output(i, w, fc, dT, Kg, Bg, G, sensor, S2)
    for i in range(3):  # accelerometers, eq. (2) + effects; accelerometer i sits at its lever arm
        y[3 + i] = accel_output(i, w, fc, perp, dT, Ka, Ba, P, sensor)


@inline_jit
def truth_channel(p):
    """The one output channel that entry *p* of the truth vector enters (:func:`sensor_outputs`).

    Row i of ``Kg`` and ``G`` and ``Bg[i]`` enter gyro i (eq. (1)); row i of ``Ka`` and ``P`` and
    ``Ba[i]`` accelerometer i (eq. (2)); the effects' terms use the diagonal of the same rows.
    """
    if p < BG_FIRST:
        return (p - KG_FIRST) // 3
    if p < G_FIRST:
        return p - BG_FIRST
    if p < KA_FIRST:
        return (p - G_FIRST) // 3
    if p < BA_FIRST:
        return 3 + (p - KA_FIRST) // 3
    if p < P_FIRST:
        return 3 + p - BA_FIRST
    return 3 + P_ENTRIES[p - P_FIRST][0]


@inline_jit
def evaluate_outputs(nodes, extra, cos_phase, sin_phase, rates, u, g_b0, om_b0, perp, dT, Kg, Bg, G, Ka, Ba, P, sensor,
                     S2, channel, out, scratch):
    """Noise-free outputs ``out[j]`` (6) at table angles θ_j = phase + 2πj/nodes (j < nodes) and, for
    j ≥ nodes (``extra`` more rows), at θ = phase, given ``cos phase`` and ``sin phase`` (a caller that
    evaluates many segments at the same angles computes them once); table rate ``rates[j]``. Angles
    by angle addition.

    *channel* :data:`ALL_CHANNELS` writes all six; a channel 0 … 5 writes ``out[j, channel]`` alone
    (the same number, for a caller that knows the others have not changed: :func:`truth_channel`);
    :data:`GYRO_OUTPUTS` or :data:`ACCEL_OUTPUTS` the three of that kind alone (the same numbers; each
    channel is computed on its own).
    ``scratch`` (3, 6) is work space (allocated once per trial by the caller). Pass *nodes*, *extra*
    and *channel* as int64 values, not int literals (one compiled copy; see :data:`STREAM_NOISE`).
    """
    w = scratch[0, :3]
    fc = scratch[1, :3]
    y = scratch[2]
    c0 = cos_phase
    s0 = sin_phase
    cd = math.cos(2.0 * math.pi / nodes)
    sd = math.sin(2.0 * math.pi / nodes)
    # what rotated_inputs computes of u, g_b0 and Ω_b0 alone, once for every angle (the same expressions)
    u0, u1, u2 = u[0], u[1], u[2]
    g0, g1, g2 = g_b0[0], g_b0[1], g_b0[2]
    o0, o1, o2 = om_b0[0], om_b0[1], om_b0[2]
    ug = u0 * g0 + u1 * g1 + u2 * g2
    uo = u0 * o0 + u1 * o1 + u2 * o2
    xg0, xg1, xg2 = u1 * g2 - u2 * g1, u2 * g0 - u0 * g2, u0 * g1 - u1 * g0
    xo0, xo1, xo2 = u1 * o2 - u2 * o1, u2 * o0 - u0 * o2, u0 * o1 - u1 * o0
    yg0, yg1, yg2 = u0 * ug, u1 * ug, u2 * ug
    yo0, yo1, yo2 = u0 * uo, u1 * uo, u2 * uo
    ct, st = c0, s0
    for j in range(nodes + extra):
        if j >= nodes:
            ct, st = c0, s0
        # rotated_inputs(ct, st, rates[j], u, g_b0, om_b0, w, fc), its invariant parts taken from above
        rate = rates[j]
        versine = 1.0 - ct
        fc[0] = g0 * ct - xg0 * st + yg0 * versine
        fc[1] = g1 * ct - xg1 * st + yg1 * versine
        fc[2] = g2 * ct - xg2 * st + yg2 * versine
        w[0] = rate * u0 + o0 * ct - xo0 * st + yo0 * versine
        w[1] = rate * u1 + o1 * ct - xo1 * st + yo1 * versine
        w[2] = rate * u2 + o2 * ct - xo2 * st + yo2 * versine
        if channel == ALL_CHANNELS:
            sensor_outputs(w, fc, perp, dT, Kg, Bg, G, Ka, Ba, P, sensor, S2, y)
            for c in range(6):
                out[j, c] = y[c]
        elif channel == GYRO_OUTPUTS:
            for i in range(3):
                out[j, i] = gyro_output(i, w, fc, dT, Kg, Bg, G, sensor, S2)
        elif channel == ACCEL_OUTPUTS:
            for i in range(3):
                out[j, 3 + i] = accel_output(i, w, fc, perp, dT, Ka, Ba, P, sensor)
        elif channel < 3:
            out[j, channel] = gyro_output(channel, w, fc, dT, Kg, Bg, G, sensor, S2)
        else:
            out[j, channel] = accel_output(channel - 3, w, fc, perp, dT, Ka, Ba, P, sensor)
        ct, st = ct * cd - st * sd, st * cd + ct * sd
