"""Segment-statistics path: each segment's mean drawn from its exact distribution, no raw samples.

The estimators only see segment means (JJF 2003 eq. (3)), so a calibration can be simulated from
the distribution of those means:

- **Deterministic part** (orientation within a rate point, every sensor effect): the output is a
  trigonometric polynomial of degree ≤ 3 in the table angle θ (eq. (1)/(2) are linear in the
  rotated vectors; the cubic nonlinearity is the highest power), so the average over the N samples
  ``θ_k = θ0 + kΔ`` equals ``Σ_j W_j f(θ0 + 2πj/J)`` over J = 7 nodes, with weights from the
  discrete averages ``D_m = (1/N) Σ_k e^{imkΔ}`` (:func:`arc_weights`). Exact, whole turns or not.
- **White noise**: the mean of N samples is normal with variance σ²/N.
- **Drift** (Gauss–Markov bias instability and drift, random walk), held over the drift update
  interval as in the sample-level path: the segment mean and the end state are jointly normal
  given the start state; their 2×2 covariance is factorised once per schedule.
- **Rate smoothness**: the per-sample rate jitter enters the gyros linearly; its segment mean is a
  common normal variable for the three gyros.
- **Quantisation** of a Gaussian sample ``Q(μ + σZ)``: where the noise dithers the quantiser
  (bias amplitude Σ_k q/(πk)·exp(−2π²k²σ²/q²) below the tolerance) the mean is unbiased and each
  sample adds q²/12 of variance (Sheppard; Widrow's quantisation theorem); otherwise the exact
  mean and variance of the quantised Gaussian (Fourier series for σ ≥ 0.2q, threshold sums below)
  are averaged over the segment's θ with as many nodes as the output's sweep requires.
  Tolerance: every such approximation stays below 0.1 % of the segment mean's own noise σ/√N
  (:data:`RELATIVE_TOLERANCE`): the Fourier series is cut where its dropped tail moves the mean by
  at most a tenth of that (and the variance by at most 0.01 % of σ², :func:`fourier_terms_needed`),
  and the average of the kept terms over θ takes the rest (:func:`_harmonics_needed`).

Two kernels, run one after the other on each slice of trials:

- :func:`simulate_chunk_nodes` — the deterministic half: systematic draws (the same as on the
  sample-level path), geometry, and the noise-free outputs at 7 table angles per segment
  (:func:`noise_free_nodes`), which fix the output at every angle of the segment;
- :func:`simulate_chunk_statistics` — the stochastic half: drift, white noise, rate jitter and the
  quantiser's moments, from those node values alone (no output model inside).

They are separate entry points so that, on a cold start, two processes compile them side by side
(:mod:`plansim.simulate.compilation`).

What is not exact, and the runner's checks (:func:`plansim.simulate.paths.segment_path_exactness`):
saturation (excluded), gyro asymmetry (|w| is not a polynomial; excluded), drift that moves a
non-dithered quantised output within a segment (excluded above 0.1σ), the cross-channel
correlation of the rate jitter inside non-dithered quantisers (dropped), and channels that no
estimator uses (returned without quantisation: e.g. the accelerometers during the rate test).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.drift import advance_drift, drift_transition, noise_stream, segment_drift
from plansim.kernels.layout import (
    ACQ_STEP,
    HEAD,
    N_TRUTH,
    NOISE_WHITE,
    PER_SEGMENT,
    PERPENDICULARITY_FIRST,
    RATE_SYSTEMATIC,
    SEG_RATE_ERROR,
    draws_length,
)
from plansim.kernels.options import inline_jit, jit
from plansim.kernels.physics import (
    ACCEL_OUTPUTS,
    ALL_CHANNELS,
    GYRO_OUTPUTS,
    draw_systematic,
    evaluate_outputs,
    geometry_buffers,
    segment_geometry,
    trial_frames,
    truth_channel,
    unpack_truth,
)
from plansim.kernels.quantiser import channel_moments, fourier_damping, fourier_terms_needed
from plansim.kernels.random import normal

# int64 scalars, not Python ints: passed to kernels, a literal would compile a copy per value
DETERMINISTIC_NODES = np.int64(7)  # degree ≤ 3 in θ -> 2·3 + 1 nodes
_ONE_NODE = np.int64(1)  # at rest: the output does not depend on θ
_NO_EXTRA = np.int64(0)
_JITTER_NODES = np.int64(2)  # θ0 at the rate ± h, for the response to rate jitter
_FIRST = np.int64(0)  # the first row of a work array
MAX_NODES = 401
#: every approximation of the quantiser stays below this fraction of the segment mean's noise σ/√N
RELATIVE_TOLERANCE = 1e-3
#: the share of that tolerance spent on cutting the quantiser's Fourier series (the rest goes to the
#: average over θ): :func:`fourier_terms_needed`, :func:`_harmonics_needed`
SERIES_SHARE = 0.1


_COS7 = np.cos(2.0 * np.pi * np.arange(7) / 7)
_SIN7 = np.sin(2.0 * np.pi * np.arange(7) / 7)


@jit
def arc_weights(J, delta, n, weights):
    """Weights with ``(1/n) Σ_{k<n} f(θ0 + kΔ) = Σ_{j<J} W_j f(θ0 + 2πj/J)`` for trigonometric
    polynomials f of degree ≤ M = (J − 1)/2 (J odd):

        W_j = (1/J)·[1 + 2 Re Σ_{m=1..M} D_m e^{−i m 2πj/J}],  D_m = (1/n) Σ_k e^{i m k Δ}
            = (1 − e^{i m n Δ}) / (n (1 − e^{i m Δ})).

    Powers by recurrence and the twiddles e^{−i m 2πj/J} from a constant table for J = 7, by angle
    addition otherwise: no allocation, and no trigonometric call inside the loops.
    """
    M = (J - 1) // 2
    for j in range(J):
        weights[j] = 1.0 / J
    c1, s1 = math.cos(delta), math.sin(delta)
    cn, sn = math.cos(n * delta), math.sin(n * delta)
    a_re, a_im = 1.0, 0.0  # e^{i m Δ}
    b_re, b_im = 1.0, 0.0  # e^{i m n Δ}
    cj, sj = 1.0, 0.0
    if J != DETERMINISTIC_NODES:  # the twiddles by angle addition (J = 7: the constant table)
        cj, sj = math.cos(2.0 * math.pi / J), math.sin(2.0 * math.pi / J)
    cm, sm = 1.0, 0.0  # cos, sin of m·2π/J
    for m in range(1, M + 1):
        a_re, a_im = a_re * c1 - a_im * s1, a_re * s1 + a_im * c1
        b_re, b_im = b_re * cn - b_im * sn, b_re * sn + b_im * cn
        cm, sm = cm * cj - sm * sj, sm * cj + cm * sj
        den_re = 1.0 - a_re
        den_im = -a_im
        den2 = den_re * den_re + den_im * den_im
        if den2 < 1e-24:  # e^{imΔ} = 1: every sample at the same phase
            d_re, d_im = 1.0, 0.0
        else:
            num_re = 1.0 - b_re
            num_im = -b_im
            d_re = (num_re * den_re + num_im * den_im) / (n * den2)
            d_im = (num_im * den_re - num_re * den_im) / (n * den2)
        if J == DETERMINISTIC_NODES:
            for j in range(J):
                k = (m * j) % J
                weights[j] += 2.0 / J * (d_re * _COS7[k] + d_im * _SIN7[k])  # Re(D_m e^{−i m φ_j})
        else:
            tc, ts = 1.0, 0.0  # cos, sin of m·2πj/J
            for j in range(J):
                weights[j] += 2.0 / J * (d_re * tc + d_im * ts)
                tc, ts = tc * cm - ts * sm, ts * cm + tc * sm


@jit
def trigonometric_coefficients(nodes, s, coefficients):
    """The trigonometric polynomial of degree 3 through segment *s*'s 7 node values, per channel.

    ``nodes[s, j, c]`` is the output at θ0 + φ_j, φ_j = 2πj/7 (:func:`noise_free_nodes`);
    ``coefficients[c]`` receives (a0, a1, b1, a2, b2, a3, b3) with
    ``y(θ0 + φ) = a0 + Σ_{m=1..3} a_m cos mφ + b_m sin mφ`` (the 7-point discrete Fourier
    transform: a0 = ȳ, a_m = (2/7) Σ_j y_j cos mφ_j, b_m = (2/7) Σ_j y_j sin mφ_j).
    """
    for c in range(6):
        total = 0.0
        for j in range(DETERMINISTIC_NODES):
            total += nodes[s, j, c]
        coefficients[c, 0] = total / DETERMINISTIC_NODES
        for m in range(1, 4):
            a = 0.0
            b = 0.0
            for j in range(DETERMINISTIC_NODES):
                k = (m * j) % DETERMINISTIC_NODES
                a += nodes[s, j, c] * _COS7[k]
                b += nodes[s, j, c] * _SIN7[k]
            coefficients[c, 2 * m - 1] = 2.0 * a / DETERMINISTIC_NODES
            coefficients[c, 2 * m] = 2.0 * b / DETERMINISTIC_NODES


@jit
def _harmonics_needed(spread, sigma, step, coefficients, row, kmax, tolerance):
    """Half the number of θ nodes for averaging a quantiser's moments while its input sweeps *spread*.

    The output's deterministic part has degree ≤ 3 in θ. In the Fourier regime (σ ≥ 0.2q) the
    quantiser's bias is Σ_k A_k sin(2πkμ/q) with A_k = q/(πk)·γ_k; with μ = μ̄ + δ(θ), |δ| ≤ spread,
    the Jacobi–Anger expansion bounds harmonic n of sin(2πkμ/q) by (πk·spread/q)^n / n!, so M is
    raised until Σ_k A_k (πk·spread/q)^{M+1}/(M+1)! ≤ tolerance (times 3 for the cubic's own
    degree). Below 0.2q (a sharp staircase) the Gaussian smoothing sets the bandwidth:
    M = 3·spread/σ + 4.
    """
    cap = (MAX_NODES - 1) // 2
    if kmax == 0:
        return int(min(math.ceil(3.0 * spread / max(sigma, 1e-300)) + 4, cap))
    # bound(M) = Σ_k A_k x_k^{M+1}/(M+1)!, x_k = πk·spread/q, A_k = q/(πk)·γ_k; with
    # P_M = Σ_k A_k k^{M+1}, bound(M) = (π·spread/q)^{M+1}/(M+1)! · P_M, both updated per M
    x = math.pi * spread / step
    scale = x * x * x * x / 24.0  # x^{M+1}/(M+1)! at M = 3
    for M in range(3, cap + 1):
        total = 0.0
        for k in range(1, kmax + 1):
            total += abs(coefficients[row, 0, k - 1]) * float(k) ** (M + 1)
        if scale * total <= tolerance:
            return min(3 * (M // 3 + 1), cap) if M > 3 else 3
        scale *= x / (M + 2)
    return cap


@inline_jit
def segment_node_outputs(rate, rate_act, cos_phase, sin_phase, dT, extra, channel, u, g_b0, om_b0, perp, Kg, Bg, G,
                         Ka, Ba, P, sensor, S2, rates, outputs, scratch):
    """The noise-free outputs of a segment whose geometry :func:`segment_geometry` has set.

    *rate* is the commanded rate (0: at rest), *rate_act* the actual rate :func:`segment_geometry`
    returned, *cos_phase* and *sin_phase* those of the start angle θ0 (the one it returned, or any
    other), ``dT`` the temperature offset.
    At rest, ``outputs[0]`` (6): the one output, whatever the table angle. Rotating, ``outputs[j]``
    for j < 7: the outputs at the table angles θ0 + 2πj/7 at the actual rate, then *extra* rows (0 or
    :data:`_JITTER_NODES`) at θ0 with the rate ± 1e-6 of itself (the rate-jitter response).
    *channel*: as for :func:`evaluate_outputs`. ``rates`` (7 + *extra*), ``outputs`` (7 + *extra*, 6)
    and ``scratch`` (3, 6) are work space. Inlined: one output model for :func:`noise_free_nodes`
    and :func:`noise_free_mean_derivatives`.
    """
    if rate == 0.0:
        rates[0] = 0.0
        evaluate_outputs(_ONE_NODE, _NO_EXTRA, 1.0, 0.0, rates, u, g_b0, om_b0, perp, dT, Kg, Bg, G, Ka, Ba, P,
                         sensor, S2, channel, outputs, scratch)
        return
    h = 1e-6 * abs(rate_act)
    for j in range(DETERMINISTIC_NODES):
        rates[j] = rate_act
    if extra > 0:
        rates[DETERMINISTIC_NODES] = rate_act + h
        rates[DETERMINISTIC_NODES + 1] = rate_act - h
    evaluate_outputs(DETERMINISTIC_NODES, extra, cos_phase, sin_phase, rates, u, g_b0, om_b0, perp, dT, Kg, Bg, G, Ka,
                     Ba, P, sensor, S2, channel, outputs, scratch)


@jit
def noise_free_nodes(draws, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp, sensor, S2, lever, t_ref,
                     smoothness, gravity, earth_enu, nodes_out, rates_out, jitter_out):
    """The deterministic part of one trial, segment by segment, from its systematic *draws*.

    Writes, for every segment s,

    - ``nodes_out[s]`` (7, 6): the noise-free outputs at the table angles θ0 + 2πj/7 (j < 7) at the
      actual rate. They determine the output at every angle of the segment: a trigonometric
      polynomial of degree ≤ 3 in θ is fixed by 7 equispaced values. At rest every row holds the
      one (θ-independent) output;
    - ``rates_out[s]``: the actual table rate, rad/s (0 at rest);
    - ``jitter_out[s]`` (6): the output's response to the rate smoothness, σ_rate·∂y/∂ω at θ0 per
      unit normal rate jitter (central difference, step 1e-6 of the rate); 0 at rest.
    """
    Kg, Bg, G, Ka, Ba, P = unpack_truth(draws[:N_TRUTH])
    u, g_b0, om_b0, perp, frames = geometry_buffers(draws)
    rates = np.empty(DETERMINISTIC_NODES + _JITTER_NODES)
    outputs = np.empty((DETERMINISTIC_NODES + _JITTER_NODES, 6))
    scratch = np.empty((3, 6))
    for s in range(seg_C0.shape[0]):
        rate_act, phase = segment_geometry(draws, s, seg_C0, seg_rate, seg_axis, seg_axis_index, gravity,
                                           earth_enu, lever, g_b0, om_b0, u, perp, frames)
        # the 7 nodes, then two more at θ0 with the rate ± h for the jitter response
        segment_node_outputs(seg_rate[s], rate_act, math.cos(phase), math.sin(phase), seg_temp[s] - t_ref,
                             _JITTER_NODES, ALL_CHANNELS, u, g_b0, om_b0, perp, Kg, Bg, G, Ka, Ba, P, sensor, S2, rates,
                             outputs, scratch)
        if seg_rate[s] == 0.0:
            rates_out[s] = 0.0
            for c in range(6):
                for j in range(DETERMINISTIC_NODES):
                    nodes_out[s, j, c] = outputs[0, c]
                jitter_out[s, c] = 0.0
            continue
        rates_out[s] = rate_act
        h = 1e-6 * abs(rate_act)
        for c in range(6):
            for j in range(DETERMINISTIC_NODES):
                nodes_out[s, j, c] = outputs[j, c]
            # the sample path jitters the gyro input w (so also P·w²), not the centripetal term
            jitter_out[s, c] = (smoothness * rate_act
                                * (outputs[DETERMINISTIC_NODES, c] - outputs[DETERMINISTIC_NODES + 1, c]) / (2.0 * h))


@inline_jit
def node_mean(nodes, s, c, weights):
    """``Σ_j weights[j]·nodes[s, j, c]`` over the 7 nodes: channel *c*'s mean over the segment's samples."""
    total = 0.0
    for j in range(DETERMINISTIC_NODES):
        total += weights[j] * nodes[s, j, c]
    return total


@inline_jit
def weighted_mean_and_spread(nodes, s, weights, mean_out, spread_out):
    """``mean_out`` (6): :func:`node_mean` of every channel; ``spread_out`` (6): max − min of the node values."""
    for c in range(6):
        mean_out[c] = node_mean(nodes, s, c, weights)
        low = nodes[s, 0, c]
        high = low
        for j in range(DETERMINISTIC_NODES):
            y = nodes[s, j, c]
            low = min(low, y)
            high = max(high, y)
        spread_out[c] = high - low


@jit
def segment_mean_and_spread(nodes, s, rate, dt, n, weights, mean_out, spread_out):
    """Exact noise-free mean over the segment's *n* samples (``mean_out``, 6) and the spread
    max − min of the node values (``spread_out``, 6), from :func:`noise_free_nodes`'s ``nodes``.

    *weights* (7) is work space (it receives :func:`arc_weights`); at rest (*rate* 0) the mean is
    the output itself and the spread 0.
    """
    if rate == 0.0:
        for c in range(6):
            mean_out[c] = nodes[s, 0, c]
            spread_out[c] = 0.0
        return
    arc_weights(DETERMINISTIC_NODES, rate * dt, n, weights)
    weighted_mean_and_spread(nodes, s, weights, mean_out, spread_out)


@jit
def noise_free_means(draws, seg_n, seg_dt, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp,
                     sensor, S2, lever, t_ref, gravity, earth_enu, means_out):
    """Exact noise-free segment means (n, S, 6) of many draws vectors (n, D): the average over the samples.

    Serial on purpose: it serves the GUM sensitivities (few vectors), and a parallel kernel would
    add seconds of compilation to every cold start.
    """
    n_seg = seg_n.shape[0]
    nodes = np.empty((n_seg, DETERMINISTIC_NODES, 6))
    rates = np.empty(n_seg)
    jitter = np.empty((n_seg, 6))
    weights = np.empty(DETERMINISTIC_NODES)
    spread = np.empty(6)
    for t in range(draws.shape[0]):
        noise_free_nodes(draws[t], seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp, sensor, S2, lever, t_ref,
                         0.0, gravity, earth_enu, nodes, rates, jitter)
        for s in range(n_seg):
            segment_mean_and_spread(nodes, s, rates[s], seg_dt[s], seg_n[s], weights, means_out[t, s], spread)


@inline_jit
def _segment_reads(index, s, seg_rate, seg_axis_index):
    """Whether the noise-free means of segment *s* depend on component *index* of the draws vector.

    Every segment reads the truth, the fixture and the tilt; only a rotating segment reads the
    systematic rate error and the perpendicularity of its own rate axis (at rest the table axis
    and the rate enter the outputs multiplied by exact zeros); a segment reads its own position
    errors, and, rotating, its own rate error (:func:`plansim.kernels.physics.segment_geometry`).
    """
    if index < RATE_SYSTEMATIC:
        return True
    rotating = seg_rate[s] != 0.0
    if index < HEAD:
        return rotating and (index == RATE_SYSTEMATIC
                             or seg_axis_index[s] == (index - PERPENDICULARITY_FIRST) // 2)
    if (index - HEAD) // PER_SEGMENT != s:
        return False
    return rotating or (index - HEAD) % PER_SEGMENT < SEG_RATE_ERROR


#: what :func:`_save_geometry` keeps of a segment: the actual rate, u, g_b0, Ω_b0 (3 each), perp (3×3), the arc weights
_SAVED_GEOMETRY = 1 + 9 + 9 + DETERMINISTIC_NODES


@inline_jit
def _save_geometry(rate_act, u, g_b0, om_b0, perp, weights, saved, s):
    """Keep segment *s*'s orientation (:func:`segment_geometry`) and arc weights in ``saved[s]``."""
    saved[s, 0] = rate_act
    for i in range(3):
        saved[s, 1 + i] = u[i]
        saved[s, 4 + i] = g_b0[i]
        saved[s, 7 + i] = om_b0[i]
        for j in range(3):
            saved[s, 10 + 3 * i + j] = perp[i, j]
    for j in range(DETERMINISTIC_NODES):
        saved[s, 19 + j] = weights[j]


@inline_jit
def _restore_geometry(saved, s, u, g_b0, om_b0, perp, weights):
    """The inverse of :func:`_save_geometry`: segment *s*'s orientation and arc weights back; returns its rate."""
    for i in range(3):
        u[i] = saved[s, 1 + i]
        g_b0[i] = saved[s, 4 + i]
        om_b0[i] = saved[s, 7 + i]
        for j in range(3):
            perp[i, j] = saved[s, 10 + 3 * i + j]
    for j in range(DETERMINISTIC_NODES):
        weights[j] = saved[s, 19 + j]
    return saved[s, 0]


@inline_jit
def _evaluated(code, c):
    """Whether :func:`plansim.kernels.physics.evaluate_outputs` with *channel* = *code* writes channel *c*."""
    if code == ALL_CHANNELS:
        return True
    if code == GYRO_OUTPUTS:
        return c < 3
    if code == ACCEL_OUTPUTS:
        return c >= 3
    return c == code


@inline_jit
def _outputs_needed(channel, needed, s):
    """The *channel* argument of :func:`plansim.kernels.physics.evaluate_outputs` for the outputs of segment *s*
    that a component moving *channel* (:data:`ALL_CHANNELS` or one channel) changes and ``needed[s]`` asks for;
    −9 if none."""
    if channel >= 0:
        return channel if needed[s, channel] != 0 else -9
    gyros = needed[s, 0] != 0 or needed[s, 1] != 0 or needed[s, 2] != 0
    accels = needed[s, 3] != 0 or needed[s, 4] != 0 or needed[s, 5] != 0
    if gyros and accels:
        return ALL_CHANNELS
    if gyros:
        return GYRO_OUTPUTS
    if accels:
        return ACCEL_OUTPUTS
    return -9


@jit
def noise_free_mean_derivatives(base, phases, indices, steps, needed, seg_n, seg_dt, seg_C0, seg_rate, seg_axis,
                                seg_axis_index, seg_temp, sensor, S2, lever, t_ref, gravity, earth_enu,
                                phase_means_out, first_out, second_out):
    """Central differences of the noise-free segment means in components of the draws vector, over start angles.

    With every segment's start angle at ``phases[j]`` (J angles):

    - ``phase_means_out`` (J, S, 6): the means at *base* (D,), as :func:`noise_free_means` gives them
      for the J draws vectors; their average over the angles is the centre ``m̄``;
    - ``first_out``, ``second_out`` (K, S, 6): ``(m̄₊ − m̄₋)/(2h)`` and ``(m̄₊ + m̄₋ − 2m̄)/h²``, where
      ``m̄±`` are the averages with ``base[indices[k]] ± h``, ``h = steps[k]``.

    Averages are summed in the order of the angles, then divided by J: numpy's mean over the angle
    axis of the same values, and the differences are numpy's expressions, so the result is that of
    evaluating every perturbed draws vector with :func:`noise_free_means` and differencing with
    numpy, bit for bit. Only what a component enters is evaluated: only the segments that read it
    (:func:`_segment_reads`: a position error of one segment moves that segment alone), and of a
    truth component only the one channel it enters (:func:`plansim.kernels.physics.truth_channel`),
    with the orientation and arc weights of base (the truth moves neither); the others' differences
    are exact zeros (m̄₊ = m̄₋ = m̄). At rest a segment is evaluated at one angle (it does not depend
    on it); rotating, its orientation and arc weights once for all angles. *indices* must not be
    start angles (``SEG_PHASE``): those are set from *phases*.

    ``needed`` (S, 6) is nonzero where the caller uses the derivatives of segment s's channel c (where the
    reduction reads that mean); elsewhere they are left exact zeros and, if no channel of that kind (gyros,
    accelerometers) of the segment is needed, not evaluated. Those needed are the same numbers whatever
    ``needed`` is (each channel's output is computed on its own). ``phase_means_out`` is always complete.
    """
    n_seg = seg_n.shape[0]
    n_phases = phases.shape[0]
    draws = base.copy()
    Kg, Bg, G, Ka, Ba, P = unpack_truth(draws[:N_TRUTH])
    u, g_b0, om_b0, perp, frames = geometry_buffers(draws)
    rates = np.empty(DETERMINISTIC_NODES)
    outputs = np.empty((DETERMINISTIC_NODES, 6))
    nodes = outputs.reshape((1, DETERMINISTIC_NODES, 6))
    scratch = np.empty((3, 6))
    weights = np.empty(DETERMINISTIC_NODES)
    phase_means = np.empty((n_phases, 6))
    cos_phases = np.empty(n_phases)  # the start angles are the same for every segment and component
    sin_phases = np.empty(n_phases)
    for j in range(n_phases):
        cos_phases[j] = math.cos(phases[j])
        sin_phases[j] = math.sin(phases[j])
    centre = np.empty((n_seg, 6))
    plus = np.empty((n_seg, 6))  # m̄₊ of the component at hand
    saved = np.empty((n_seg, _SAVED_GEOMETRY))  # each segment's orientation and arc weights at base
    for k in range(-1, indices.shape[0]):  # k = −1: the means at base, into phase_means_out and centre
        index = indices[k] if k >= 0 else -1
        channel = truth_channel(index) if 0 <= index < N_TRUTH else ALL_CHANNELS
        h = steps[k] if k >= 0 else 0.0
        for sign in range(2 if k >= 0 else 1):
            if k >= 0:
                draws[index] = base[index] + h if sign == 0 else base[index] - h
                if index < N_TRUTH:
                    Kg, Bg, G, Ka, Ba, P = unpack_truth(draws[:N_TRUTH])
                elif index < RATE_SYSTEMATIC:
                    trial_frames(draws, frames)
            for s in range(n_seg):
                if k >= 0 and sign == 1:
                    for c in range(6):
                        first_out[k, s, c] = 0.0
                        second_out[k, s, c] = 0.0
                if k >= 0 and not _segment_reads(index, s, seg_rate, seg_axis_index):
                    continue
                code = channel if k < 0 else _outputs_needed(channel, needed, s)  # the outputs to evaluate
                if code == -9:
                    continue
                # the segment's mean at every start angle (its orientation and arc weights do not depend on it;
                # a truth component leaves them as they are at base, so they are kept from there)
                if channel >= 0:
                    rate_act = _restore_geometry(saved, s, u, g_b0, om_b0, perp, weights)
                else:
                    rate_act, _ = segment_geometry(draws, s, seg_C0, seg_rate, seg_axis, seg_axis_index, gravity,
                                                   earth_enu, lever, g_b0, om_b0, u, perp, frames)
                    if seg_rate[s] != 0.0:
                        arc_weights(DETERMINISTIC_NODES, rate_act * seg_dt[s], seg_n[s], weights)
                    if k < 0:
                        _save_geometry(rate_act, u, g_b0, om_b0, perp, weights, saved, s)
                dT = seg_temp[s] - t_ref
                if seg_rate[s] == 0.0:  # at rest: one evaluation, whatever the angle
                    segment_node_outputs(seg_rate[s], rate_act, 1.0, 0.0, dT, _NO_EXTRA, code, u, g_b0, om_b0, perp,
                                         Kg, Bg, G, Ka, Ba, P, sensor, S2, rates, outputs, scratch)
                    for j in range(n_phases):
                        for c in range(6):
                            phase_means[j, c] = outputs[0, c]
                else:
                    for j in range(n_phases):
                        segment_node_outputs(seg_rate[s], rate_act, cos_phases[j], sin_phases[j], dT, _NO_EXTRA,
                                             code, u, g_b0, om_b0, perp, Kg, Bg, G, Ka, Ba, P, sensor, S2, rates,
                                             outputs, scratch)
                        for c in range(6):
                            if _evaluated(code, c):
                                phase_means[j, c] = node_mean(nodes, _FIRST, c, weights)
                if k < 0:
                    for j in range(n_phases):
                        for c in range(6):
                            phase_means_out[j, s, c] = phase_means[j, c]
                for c in range(6):
                    if not _evaluated(code, c) or (k >= 0 and needed[s, c] == 0):
                        continue  # a truth component moves one channel: the others' differences are zero
                    # the average over the angles, summed in their order (numpy's mean over a leading axis)
                    total = phase_means[0, c]
                    for j in range(1, n_phases):
                        total += phase_means[j, c]
                    mean = total / n_phases
                    if k < 0:
                        centre[s, c] = mean
                    elif sign == 0:
                        plus[s, c] = mean
                    else:
                        first_out[k, s, c] = (plus[s, c] - mean) / (2.0 * h)
                        second_out[k, s, c] = (plus[s, c] + mean - 2.0 * centre[s, c]) / (h * h)
            if k >= 0:
                draws[index] = base[index]
        if 0 <= index < N_TRUTH:
            Kg, Bg, G, Ka, Ba, P = unpack_truth(draws[:N_TRUTH])
        elif 0 <= index < RATE_SYSTEMATIC:
            trial_frames(draws, frames)


@jit
def simulate_chunk_nodes(first_trial, key, truth_nominal, truth_spread, error_kind, error_scale,
                         seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp, sensor, S2, lever, t_ref, smoothness,
                         gravity, earth_enu, truth_out, nodes_out, rates_out, jitter_out):
    """The deterministic half of trials ``first_trial …`` on the segment-statistics path.

    Each trial's systematic draws (the same as on the sample-level path), its truth into
    ``truth_out`` (T, 39) and :func:`noise_free_nodes` into ``nodes_out`` (T, S, 7, 6),
    ``rates_out`` (T, S), ``jitter_out`` (T, S, 6), for :func:`simulate_chunk_statistics`.
    Serial and ``nogil``: the engine runs slices of a chunk on a thread pool.
    """
    n_seg = seg_C0.shape[0]
    draws = np.empty(_draws_length(n_seg))
    for t in range(truth_out.shape[0]):
        draw_systematic(first_trial + t, key, truth_nominal, truth_spread, error_kind, error_scale, n_seg, draws)
        for k in range(N_TRUTH):
            truth_out[t, k] = draws[k]
        noise_free_nodes(draws, seg_C0, seg_rate, seg_axis, seg_axis_index, seg_temp, sensor, S2, lever, t_ref,
                         smoothness, gravity, earth_enu, nodes_out[t], rates_out[t], jitter_out[t])


@jit
def simulate_chunk_statistics(first_trial, key, nodes, rates, jitter, seg_n, seg_dt, seg_gap, seg_rate,
                              acquisition, noise, noise_times, smoothness, drift_coeffs, needed, means_out):
    """The stochastic half of trials ``first_trial …``: noise, drift and quantisation of the segment means.

    ``nodes`` (T, S, 7, 6), ``rates`` (T, S), ``jitter`` (T, S, 6) come from
    :func:`simulate_chunk_nodes`; the segment means go to ``means_out`` (T, S, 6). Each trial's
    numbers come from its own noise stream (stream 1), so they do not depend on the chunking.
    Where a quantiser's moments are averaged over more nodes than the 7, the output at the extra
    angles is the trigonometric interpolation of the 7 node values (exact: degree ≤ 3 in θ).
    Serial and ``nogil``: the engine runs slices of a chunk on a thread pool.
    """
    n_seg = seg_n.shape[0]
    settling = np.empty((n_seg, 2, 3, 6))  # the drift transition over each settling gap, for every trial
    for s in range(n_seg):
        drift_transition(seg_gap[s], noise, noise_times, settling, s)
    det = np.empty(6)
    spread = np.empty(6)
    dbar = np.empty(6)
    w7 = np.empty(DETERMINISTIC_NODES)
    wj = np.empty(MAX_NODES)
    coefficients = np.empty((6, DETERMINISTIC_NODES))  # a0, a1, b1, a2, b2, a3, b3 per channel
    z_all = np.empty(6)
    white_all = np.empty(6)
    sigma_all = np.empty(6)
    mbar = np.empty(6)
    vbar = np.empty(6)
    mode = np.empty(6, np.int64)
    gammas_all = np.empty((6, 3, 8))
    kmax_all = np.zeros(6, np.int64)
    series_sigma = np.full(6, -1.0)  # (σ, n) for which gammas_all[c], kmax_all[c], dithered[c] hold
    series_n = np.zeros(6, np.int64)
    dithered = np.zeros(6, np.bool_)
    for t in range(means_out.shape[0]):
        stream, drift = noise_stream(key, first_trial + t, noise)
        trial_nodes = nodes[t]
        for s in range(n_seg):
            rotating = seg_rate[s] != 0.0
            stream = advance_drift(settling, s, drift, stream)
            stream = segment_drift(drift, drift_coeffs, s, noise, stream, dbar)
            n = seg_n[s]
            dt = seg_dt[s]
            rate_act = rates[t, s]
            segment_mean_and_spread(trial_nodes, s, rate_act, dt, n, w7, det, spread)
            zbar = 0.0
            if rotating and smoothness > 0.0:
                zbar, stream = normal(stream)
                zbar /= math.sqrt(n)
            # per channel: 0 linear (no quantiser, or no estimator uses it), 1 dithered, 2 quantised
            # with a constant mean, 3 quantised while the output sweeps across it (average over θ)
            J = np.int64(0)  # not a literal 0 (see DETERMINISTIC_NODES)
            for c in range(6):
                z_all[c], stream = normal(stream)
                white_all[c] = noise[c, NOISE_WHITE] / math.sqrt(dt)
                step = acquisition[ACQ_STEP] if c < 3 else acquisition[ACQ_STEP + 1]
                sigma_all[c] = math.sqrt(white_all[c] * white_all[c] + jitter[t, s, c] * jitter[t, s, c])
                if step <= 0.0 or needed[s, c] == 0:
                    mode[c] = 0
                    continue
                tolerance = RELATIVE_TOLERANCE * sigma_all[c] / math.sqrt(n)
                # the series and whether the noise dithers depend on (σ, n) only; at rest σ is the
                # white noise alone, the same in every segment and trial: set up once, then reused
                if sigma_all[c] != series_sigma[c] or n != series_n[c]:
                    series_sigma[c] = sigma_all[c]
                    series_n[c] = n
                    terms = fourier_damping(sigma_all[c], step, gammas_all, c)
                    # bias of the quantised mean: Σ_k q/(πk) γ_k (the first term when γ_1 is small)
                    bias_amplitude = 0.0
                    for k in range(terms):
                        bias_amplitude += abs(gammas_all[c, 0, k])  # q/(πk)·γ_k
                    dithered[c] = terms > 0 and bias_amplitude <= tolerance
                    # a tenth of the tolerance for cutting the series (its tail falls as γ_1^{k²}), the
                    # rest for averaging what is kept over θ (there the node count jumps in steps of 6)
                    if terms > 0 and not dithered[c]:
                        terms = fourier_terms_needed(gammas_all, c, terms, sigma_all[c], SERIES_SHARE * tolerance,
                                                     SERIES_SHARE * RELATIVE_TOLERANCE * sigma_all[c] * sigma_all[c])
                    kmax_all[c] = terms
                if dithered[c]:
                    mode[c] = 1
                    continue
                if spread[c] == 0.0:
                    mode[c] = 2
                else:
                    mode[c] = 3
                    half = _harmonics_needed(spread[c], sigma_all[c], step, gammas_all, c, kmax_all[c],
                                             (1.0 - SERIES_SHARE) * tolerance)
                    J = max(J, 2 * half + 1)
            if J > 0:
                if J == DETERMINISTIC_NODES:
                    for j in range(J):
                        wj[j] = w7[j]
                else:
                    arc_weights(J, rate_act * dt, n, wj)
                    trigonometric_coefficients(trial_nodes, s, coefficients)
                    # node j at θ0 + 2πj/J: cos/sin of m·2πj/J by angle addition
                    cd = math.cos(2.0 * math.pi / J)
                    sd = math.sin(2.0 * math.pi / J)
                for c in range(6):
                    if mode[c] != 3:
                        continue
                    step = acquisition[ACQ_STEP] if c < 3 else acquisition[ACQ_STEP + 1]
                    mean_sum = 0.0
                    variance_sum = 0.0
                    c1, s1 = 1.0, 0.0
                    for j in range(J):
                        if J == DETERMINISTIC_NODES:
                            y = trial_nodes[s, j, c]
                        else:
                            c2 = c1 * c1 - s1 * s1
                            s2 = 2.0 * c1 * s1
                            c3 = c2 * c1 - s2 * s1
                            s3 = s2 * c1 + c2 * s1
                            y = (coefficients[c, 0] + coefficients[c, 1] * c1 + coefficients[c, 2] * s1
                                 + coefficients[c, 3] * c2 + coefficients[c, 4] * s2
                                 + coefficients[c, 5] * c3 + coefficients[c, 6] * s3)
                            c1, s1 = c1 * cd - s1 * sd, s1 * cd + c1 * sd
                        m, v = channel_moments(y + dbar[c], sigma_all[c], step, gammas_all, c, kmax_all[c])
                        mean_sum += wj[j] * m
                        variance_sum += wj[j] * v
                    mbar[c] = mean_sum
                    vbar[c] = variance_sum
            for c in range(6):
                base = det[c] + dbar[c]
                step = acquisition[ACQ_STEP] if c < 3 else acquisition[ACQ_STEP + 1]
                if mode[c] == 0:
                    means_out[t, s, c] = base + white_all[c] / math.sqrt(n) * z_all[c] + jitter[t, s, c] * zbar
                elif mode[c] == 1:  # dithered: unbiased, each sample adds q²/12 of independent variance
                    means_out[t, s, c] = (base + math.sqrt((white_all[c] * white_all[c] + step * step / 12.0) / n)
                                          * z_all[c] + jitter[t, s, c] * zbar)
                elif mode[c] == 2:
                    m, v = channel_moments(base, sigma_all[c], step, gammas_all, c, kmax_all[c])
                    means_out[t, s, c] = m + math.sqrt(v / n) * z_all[c]
                else:
                    means_out[t, s, c] = mbar[c] + math.sqrt(max(vbar[c], 0.0) / n) * z_all[c]


_draws_length = jit(draws_length)


