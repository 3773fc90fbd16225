"""Drift processes of the sensor noise: Gauss–Markov bias instability and drift, rate random walk.

Every process is held over the drift update interval and advanced exactly at its end, on both
paths: sample by sample (:func:`drift_transition`, :func:`advance_drift`) and, on the
segment-statistics path, as the exact joint distribution of a segment's mean drift and its end
state (:func:`drift_coefficients`, :func:`segment_drift`). A first-order Gauss–Markov process with
stationary σ and correlation time τ has carry φ = exp(−Δt/τ) and kick σ√(1 − φ²); a random walk
with coefficient K has carry 1 and kick K√Δt (IEEE Std 952-1997, Annex C).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.layout import (
    NOISE_BIAS_INSTABILITY,
    NOISE_MARKOV,
    NOISE_RANDOM_WALK,
    STREAM_NOISE,
    TIME_BIAS_INSTABILITY,
    TIME_MARKOV,
)
from plansim.kernels.options import inline_jit, jit
from plansim.kernels.random import normal, seed_stream


@jit
def drift_transition(interval, noise, noise_times, transitions, k):
    """Exact update of the drift processes over *interval* s, as ``x ← carry·x + kick·z``.

    ``transitions[k]`` (2, 3, 6) receives ``carry`` and ``kick`` per process (GM bias instability,
    GM drift, random walk) and channel: a first-order Gauss–Markov process with stationary σ and
    correlation time τ has carry φ = exp(−Δt/τ) and kick σ√(1 − φ²); a random walk with
    coefficient K has carry 1 and kick K√Δt. A process that is off has kick 0. Computed once per
    interval length, so the per-sample loop pays no exp or sqrt.
    """
    phi_bi = math.exp(-interval / noise_times[TIME_BIAS_INSTABILITY]) if interval > 0.0 else 1.0
    phi_mk = math.exp(-interval / noise_times[TIME_MARKOV]) if interval > 0.0 else 1.0
    root = math.sqrt(max(interval, 0.0))
    for c in range(6):
        transitions[k, 0, 0, c] = phi_bi
        sigma_bi = noise[c, NOISE_BIAS_INSTABILITY]
        transitions[k, 1, 0, c] = sigma_bi * math.sqrt(1.0 - phi_bi * phi_bi) if sigma_bi > 0.0 else 0.0
        transitions[k, 0, 1, c] = phi_mk
        sigma_mk = noise[c, NOISE_MARKOV]
        transitions[k, 1, 1, c] = sigma_mk * math.sqrt(1.0 - phi_mk * phi_mk) if sigma_mk > 0.0 else 0.0
        transitions[k, 0, 2, c] = 1.0
        transitions[k, 1, 2, c] = noise[c, NOISE_RANDOM_WALK] * root if noise[c, NOISE_RANDOM_WALK] > 0.0 else 0.0


@inline_jit
def advance_drift(transitions, k, drift, stream):
    """Advance the drift states ``drift`` (3, 6) by the transition ``transitions[k]`` of
    :func:`drift_transition`; returns the stream."""
    for c in range(6):
        for p in range(3):
            if transitions[k, 1, p, c] > 0.0:
                z, stream = normal(stream)
                drift[p, c] = transitions[k, 0, p, c] * drift[p, c] + transitions[k, 1, p, c] * z
    return stream


@jit
def initial_drift(noise, stream):
    """Drift states at the start of the test, Gauss–Markov processes stationary and random walks
    at 0: ``(drift (3, 6), stream)``."""
    drift = np.zeros((3, 6))
    for c in range(6):
        if noise[c, NOISE_BIAS_INSTABILITY] > 0.0:
            z, stream = normal(stream)
            drift[0, c] = noise[c, NOISE_BIAS_INSTABILITY] * z
        if noise[c, NOISE_MARKOV] > 0.0:
            z, stream = normal(stream)
            drift[1, c] = noise[c, NOISE_MARKOV] * z
    return drift, stream


@jit
def noise_stream(key, trial, noise):
    """The trial's noise stream (stream 1) and its drift states at the start of the test:
    ``(stream, drift)``."""
    drift, stream = initial_drift(noise, seed_stream(key, trial, STREAM_NOISE))
    return stream, drift


@inline_jit
def segment_drift(drift, drift_coeffs, s, noise, stream, mean_out):
    """Draw the segment-mean drift per channel and move the states to the end of the recording;
    returns the stream.

    ``drift_coeffs[s]`` (3, 5): per process (GM bias instability, GM drift, random walk) the unit-σ
    coefficients a, c, L11, L21, L22 of mean = a·x0 + σ L11 z1, end = c·x0 + σ(L21 z1 + L22 z2).
    """
    for c in range(6):
        mean_out[c] = 0.0
        for p in range(3):
            if p == 0:
                sigma = noise[c, NOISE_BIAS_INSTABILITY]
            elif p == 1:
                sigma = noise[c, NOISE_MARKOV]
            else:
                sigma = noise[c, NOISE_RANDOM_WALK]
            if sigma <= 0.0:
                continue
            z1, stream = normal(stream)
            z2, stream = normal(stream)
            x0 = drift[p, c]
            mean_out[c] += drift_coeffs[s, p, 0] * x0 + sigma * drift_coeffs[s, p, 2] * z1
            drift[p, c] = drift_coeffs[s, p, 1] * x0 + sigma * (drift_coeffs[s, p, 3] * z1 + drift_coeffs[s, p, 4] * z2)
    return stream


@jit
def _later_block_sums(weight, phi, T, E):
    """The backward recursions of :func:`drift_coefficients`, from the last block (``T[B−1] = 0``, ``E[B−1] = 1``):
    ``T[i] = w[i+1] + φ[i+1]·T[i+1]`` and ``E[i] = φ[i+1]·E[i+1]`` (a loop over the segment's blocks)."""
    for i in range(T.shape[0] - 2, -1, -1):
        T[i] = weight[i + 1] + phi[i + 1] * T[i + 1]
        E[i] = phi[i + 1] * E[i + 1]


def drift_coefficients(n: int, dt: float, hold_interval: float, tau: float | None) -> np.ndarray:
    """Unit-σ coefficients (a, c, L11, L21, L22) of a held drift process over one recorded segment.

    The process is advanced (exactly) at the end of each block of ``hold`` samples, as the
    sample-level path does; ``tau=None`` means a random walk (φ = 1, increments √Δt). Returns the
    coefficients of ``mean = a·x0 + L11 z1`` and ``end = c·x0 + L21 z1 + L22 z2`` (z independent
    standard normals) for a process of unit σ (or unit random-walk coefficient).
    """
    hold = max(1, int(math.floor(hold_interval / dt + 0.5)))
    blocks = -(-n // hold)
    sizes = np.full(blocks, hold, dtype=float)
    sizes[-1] = n - (blocks - 1) * hold
    durations = sizes * dt
    if tau is None:
        phi = np.ones(blocks)
        q = np.sqrt(durations)
    else:
        phi = np.exp(-durations / tau)
        q = np.sqrt(1.0 - phi**2)
    weight = sizes / n
    A = np.concatenate([[1.0], np.cumprod(phi)])  # A_j = Π_{l<j} φ_l
    a = float(np.sum(weight * A[:-1]))
    c = float(A[-1])
    T = np.zeros(blocks)  # T_i = Σ_{j>i} w_j Π_{i<l<j} φ_l
    E = np.ones(blocks)  # E_i = Π_{i<l<B} φ_l
    _later_block_sums(weight, phi, T, E)
    b = q * T
    d = q * E
    cov = np.array([[b @ b, b @ d], [b @ d, d @ d]])
    L11 = math.sqrt(cov[0, 0])
    L21 = cov[0, 1] / L11 if L11 > 0 else 0.0
    L22 = math.sqrt(max(cov[1, 1] - L21**2, 0.0))
    return np.array([a, c, L11, L21, L22])


@jit
def held_process_covariance(coefficients, gaps, sigma, tau, cov_out):
    """Add the covariance (S, S) of the segment means of one held drift process to ``cov_out``.

    The exact state recursion over the segments: ``coefficients`` (S, 5) are the unit-σ
    ``a, c, L11, L21, L22`` of :func:`drift_coefficients` (``mean = a·x0 + σL11 z1``,
    ``end = c·x0 + σ(L21 z1 + L22 z2)``); ``gaps`` (S,) the settling before each segment, over which
    the state is advanced exactly (φ = exp(−Δ/τ); a random walk when ``tau`` ≤ 0). A Gauss–Markov
    process is stationary (variance σ²) at the start, a random walk starts at 0.
    """
    n_seg = gaps.shape[0]
    s2 = sigma * sigma
    variance = s2 if tau > 0.0 else 0.0
    with_means = np.zeros(n_seg)  # Cov(state, mean_j) for the segments done so far
    for s in range(n_seg):
        gap = gaps[s]
        if gap > 0.0:
            if tau <= 0.0:
                variance += s2 * gap
            else:
                phi = math.exp(-gap / tau)
                variance = phi * phi * variance + s2 * (1.0 - phi * phi)
                for t in range(s):
                    with_means[t] *= phi
        a = coefficients[s, 0]
        c = coefficients[s, 1]
        l11 = coefficients[s, 2]
        l21 = coefficients[s, 3]
        l22 = coefficients[s, 4]
        for t in range(s):
            cov_out[s, t] += a * with_means[t]
            cov_out[t, s] += a * with_means[t]
            with_means[t] *= c
        cov_out[s, s] += a * a * variance + s2 * (l11 * l11)
        with_means[s] = c * a * variance + s2 * l11 * l21
        variance = c * c * variance + s2 * (l21 * l21 + l22 * l22)
