"""The data acquisition's saturation and quantiser, and the exact moments of a quantised Gaussian.

:func:`quantise` acts on each raw sample of the sample-level path. The segment-statistics path
needs instead the mean and variance of ``Q(μ + σZ)`` (:func:`quantised_gaussian_moments`): by the
Fourier series of the quantisation error (a sawtooth) where σ ≥ 0.2 q, by threshold sums below
(Widrow and Kollár, *Quantization Noise*, 2008, ch. 4–6; Sheppard's correction for the dithered
limit). The series' coefficients depend only on (σ, q) and are computed once per channel
(:func:`fourier_damping`), then evaluated at many input levels (:func:`moments_from_damping`).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.options import inline_jit, jit

QUANTISER_WINDOW = 8.0  # thresholds within ±8σ (Φ(−8) ≈ 6e-16)
# int64, not a Python int: passed to kernels, a literal would compile a copy per value
_FIRST_ROW = np.int64(0)


@inline_jit
def quantise(y, output_range, step, inverse_step, full_scale):
    """Saturate at ± output range, then quantise to *step* (round half up), clipped at ± full scale.

    *inverse_step* = 1/step, precomputed: a multiplication per sample instead of a division.
    """
    if y > output_range:
        y = output_range
    elif y < -output_range:
        y = -output_range
    if step > 0.0:
        y = step * math.floor(y * inverse_step + 0.5)
        if y > full_scale:
            y = full_scale
        elif y < -full_scale:
            y = -full_scale
    return y


@jit
def fourier_damping(sigma, step, coefficients, row):
    """Series coefficients of :func:`quantised_gaussian_moments` for σ ≥ 0.2q into ``coefficients[row]`` (3, K):
    row 0: (−1)^{k+1} q/(πk) γ_k, row 1: (−1)^k q²/(π²k²) γ_k, row 2: (−1)^{k+1} γ_k, with
    γ_k = exp(−2π²k²σ²/q²) for k = 1… while γ_k ≥ 1e-16. Returns the count, 0 if σ < 0.2q.

    One exponential per call: γ_k = γ_1^{k²} = γ_{k−1}·γ_1^{2k−1}.
    """
    if sigma < 0.2 * step:
        return 0
    r = sigma / step
    kmax = min(int(math.ceil(1.366 / r)), coefficients.shape[2])
    g1 = math.exp(-2.0 * math.pi * math.pi * r * r)
    g1_squared = g1 * g1
    g = 1.0
    factor = g1  # γ_1^{2k−1}
    sign = 1.0
    for k in range(1, kmax + 1):
        g *= factor
        factor *= g1_squared
        coefficients[row, 0, k - 1] = sign * step / (math.pi * k) * g
        coefficients[row, 1, k - 1] = -sign * step * step / (math.pi * math.pi * k * k) * g
        coefficients[row, 2, k - 1] = sign * g
        sign = -sign
    return kmax


@inline_jit
def sin_cos_turns(turns):
    """``(sin 2πt, cos 2πt)`` for *t* in turns, to within 1e-15.

    Reduced to the nearest quarter turn (exact in binary), then Taylor polynomials on
    |x| ≤ π/4 (truncation below 2e-17). Twice as fast as libm's sincos, whose slow range
    reduction above |x| ≈ 2.4 the quantiser phases hit half the time.
    """
    quarter = math.floor(4.0 * turns + 0.5)
    x = 2.0 * math.pi * (turns - 0.25 * quarter)
    x2 = x * x
    s = x * (1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362880.0 + x2 * (
        -1.0 / 39916800.0 + x2 * (1.0 / 6227020800.0 + x2 * (-1.0 / 1307674368000.0))))))))
    c = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0 + x2 * (
        -1.0 / 3628800.0 + x2 * (1.0 / 479001600.0 + x2 * (-1.0 / 87178291200.0 + x2 * (1.0 / 20922789888000.0))))))))
    k = int(quarter) & 3
    if k == 0:
        return s, c
    if k == 1:
        return c, -s
    if k == 2:
        return -s, -c
    return -c, s


@inline_jit
def moments_from_damping(mu, sigma, step, coefficients, row, kmax):
    """The Fourier branch of :func:`quantised_gaussian_moments` with the coefficients ``coefficients[row]``
    of :func:`fourier_damping` (rows index, not views: a view is reference-counted per call)."""
    s1, c1 = sin_cos_turns(mu / step)  # α_1 = 2πμ/q
    ck, sk = c1, s1
    e1 = 0.0
    e2 = step * step / 12.0
    cov = 0.0
    for k in range(kmax):
        e1 += coefficients[row, 0, k] * sk
        e2 += coefficients[row, 1, k] * ck
        cov += coefficients[row, 2, k] * ck
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
    cov *= 2.0 * sigma * sigma
    return mu - e1, max(sigma * sigma + e2 - e1 * e1 - 2.0 * cov, 0.0)


@jit
def quantised_gaussian_moments(mu, sigma, step):
    """Mean and variance of ``Q(x) = step·floor(x/step + ½)`` for ``x = μ + σZ``, Z standard normal.

    For σ ≥ 0.2·step by the Fourier series of the quantisation error ε = x − Q(x) (a sawtooth),
    with γ_k = exp(−2π²k²σ²/q²) and α_k = 2πkμ/q (terms to γ_k < 1e-16):

        E[ε]  = Σ_k (−1)^{k+1} q/(πk) γ_k sin α_k
        E[ε²] = q²/12 + Σ_k (−1)^k q²/(π²k²) γ_k cos α_k
        Cov(x, ε) = 2σ² Σ_k (−1)^{k+1} γ_k cos α_k          (Stein's lemma)
        E[Q] = μ − E[ε],  Var Q = σ² + E[ε²] − E[ε]² − 2 Cov(x, ε);

    below that, by summing the threshold-crossing probabilities within ±8σ.
    """
    if sigma >= 0.2 * step:
        coefficients = np.empty((1, 3, 8))
        kmax = fourier_damping(sigma, step, coefficients, _FIRST_ROW)
        return moments_from_damping(mu, sigma, step, coefficients, 0, kmax)
    if sigma <= 0.0:
        return step * math.floor(mu / step + 0.5), 0.0
    low = math.floor((mu - QUANTISER_WINDOW * sigma) / step + 0.5)
    high = math.floor((mu + QUANTISER_WINDOW * sigma) / step + 0.5)
    s1 = 0.0  # E[S], S = number of thresholds below x
    s2 = 0.0  # E[S²] = Σ_j (2j + 1) P_j
    j = 0
    level = low
    while level < high:
        t = (level + 0.5) * step
        p = 0.5 * math.erfc((t - mu) / (sigma * math.sqrt(2.0)))
        s1 += p
        s2 += (2.0 * j + 1.0) * p
        level += 1.0
        j += 1
    return step * (low + s1), step * step * max(s2 - s1 * s1, 0.0)


@jit
def fourier_terms_needed(coefficients, row, kmax, sigma, bias_tolerance, variance_tolerance):
    """The fewest leading terms of the series in ``coefficients[row]`` (:func:`fourier_damping`, *kmax*
    of them) whose dropped tail moves the quantised mean by at most *bias_tolerance* and the variance
    by at most *variance_tolerance*.

    With A_k, B_k, C_k the three rows (|A_k| = q/(πk)γ_k, |B_k| = q²/(π²k²)γ_k, |C_k| = γ_k) and the
    tails a, b, c of their absolute values beyond the kept terms, the mean moves by at most a and
    the variance σ² + E[ε²] − E[ε]² − 2Cov by at most b + (2 Σ_k |A_k| + a)·a + 4σ²c
    (:func:`quantised_gaussian_moments`). γ_k = γ_1^{k²} falls so fast that for the default's
    gyros (σ = 0.41q) one term is enough where machine precision wanted four.
    """
    total = 0.0
    for k in range(kmax):
        total += abs(coefficients[row, 0, k])
    tail_a = 0.0
    tail_b = 0.0
    tail_c = 0.0
    kept = kmax
    while kept > 0:
        a = tail_a + abs(coefficients[row, 0, kept - 1])
        b = tail_b + abs(coefficients[row, 1, kept - 1])
        c = tail_c + abs(coefficients[row, 2, kept - 1])
        if a > bias_tolerance or b + (2.0 * total + a) * a + 4.0 * sigma * sigma * c > variance_tolerance:
            break
        tail_a, tail_b, tail_c = a, b, c
        kept -= 1
    return kept


@inline_jit
def channel_moments(mu, sigma, step, coefficients, row, kmax):
    """:func:`quantised_gaussian_moments` of a channel whose Fourier coefficients are
    ``coefficients[row]`` (*kmax* of them; 0: σ < 0.2q, threshold sums)."""
    if kmax > 0:
        return moments_from_damping(mu, sigma, step, coefficients, row, kmax)
    return quantised_gaussian_moments(mu, sigma, step)


#: terms of :func:`quantisation_series` between exact evaluations of a harmonic and its damping (the
#: recurrences in between lose about an ulp per term)
SERIES_RESEED = 32
#: the terms :func:`quantisation_series` needs are this over τ: exp(−2π²k²τ²) < exp(−46) ≈ 1e-20 beyond
_TERMS_PER_INVERSE_TAU = math.sqrt(46.0 / (2.0 * math.pi**2))
_PI_SQUARED = math.pi**2


@jit
def quantisation_series(fraction, damping, max_terms, out):
    """``out[i] = Σ_{k≥1} cos(2πk·f) exp(−2π²k²·d) / k²`` for ``f = fraction[i]``, ``d = damping[i]`` (τ² ≥ 0).

    The series of the covariance of a noisy quantiser's bias at two input levels
    (:func:`plansim.uncertainty.quantisation.quantisation_covariance`), summed term by term until the
    damping makes the terms negligible (exp(−46) ≈ 1e-20); where that would need more than
    *max_terms* terms, the undamped sum ``π²(x² − x + 1/6)`` (x = f mod 1, the Bernoulli polynomial
    B₂), whose error is O(τ). The harmonics by rotation (as :func:`moments_from_damping`) and the
    damping ``e_k`` by its ratio ``e_{k+1}/e_k = exp(−2π²(2k+1)d)``, both evaluated exactly every
    :data:`SERIES_RESEED` terms: within a few ulp of summing exactly evaluated terms, at a fraction
    of the cost.
    """
    for i in range(fraction.shape[0]):
        out[i] = _series_value(fraction[i], damping[i], max_terms)


@inline_jit
def _series_value(f, d, max_terms):
    """One value of :func:`quantisation_series`: ``Σ_{k≥1} cos(2πk·f) exp(−2π²k²·d) / k²``."""
    t = f - math.floor(f)
    tau = math.sqrt(max(d, 0.0))
    terms = math.ceil(_TERMS_PER_INVERSE_TAU / max(tau, 1e-300)) if tau > 0.0 else math.inf
    if terms > max_terms:
        return _PI_SQUARED * (t * t - t + 1.0 / 6.0)
    s1, c1 = sin_cos_turns(t)
    r2 = math.exp(-4.0 * math.pi * math.pi * d)  # the ratio of successive ratios
    total = 0.0
    ck, sk, e, g = 0.0, 0.0, 0.0, 0.0
    for k in range(1, int(terms) + 1):
        if (k - 1) % SERIES_RESEED == 0:
            sk, ck = sin_cos_turns(k * t)
            e = math.exp(-2.0 * math.pi * math.pi * k * k * d)
            g = math.exp(-2.0 * math.pi * math.pi * (2 * k + 1) * d)
        total += ck * e / (k * k)
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
        e *= g
        g *= r2
    return total


@inline_jit
def _at_least(x, low):
    """``np.maximum(x, low)`` (NaN kept)."""
    return x if (x >= low or x != x) else low


@inline_jit
def _at_most(x, high):
    """``np.minimum(x, high)`` (NaN kept)."""
    return x if (x <= high or x != x) else high


@jit
def quantisation_covariances(means, sigma, samples, offsets, with_offsets, needed, step, step_squared, scale, full,
                             max_terms, out):
    """``out[c]`` (S, S): the covariance of the quantisation errors of the segment means of channel *c*.

    The arithmetic of :func:`plansim.uncertainty.quantisation.quantisation_covariance`, operation for
    operation, for each pair s ≤ t: ``Var Δ = max((g_ss + g_tt) − 2g_st, 0)`` of ``g = offsets[c]``
    (0 unless *with_offsets*), the series (:func:`quantisation_series`) at ``(m_t − m_s)/q`` and
    ``(σ_s² + σ_t² + Var Δ)/q²`` times *scale* (``q²/2π²``); then the diagonal's averaged part,
    ``B + (full − B)/n_s`` with ``B = min(max(c_ss, 0), full)``. *step_squared*, *scale* and *full*
    are computed by the caller (``q**2``, ``q**2 / (2π**2)``, ``q**2 / 12``). ``means``, ``sigma``, ``needed``:
    (C, S); ``samples``: (S,); ``offsets``: (C, S, S). A pair s ≠ t of which one segment is not ``needed``
    is left 0.
    """
    n_seg = means.shape[1]
    for c in range(means.shape[0]):
        for s in range(n_seg):
            for t in range(s, n_seg):
                if t != s and (needed[c, s] == 0 or needed[c, t] == 0):
                    out[c, s, t] = 0.0
                    out[c, t, s] = 0.0
                    continue
                var_delta = 0.0
                if with_offsets:
                    var_delta = _at_least((offsets[c, s, s] + offsets[c, t, t]) - 2.0 * offsets[c, s, t], 0.0)
                fraction = (means[c, t] - means[c, s]) / step
                damping = (sigma[c, s] * sigma[c, s] + sigma[c, t] * sigma[c, t] + var_delta) / step_squared
                value = scale * _series_value(fraction, damping, max_terms)
                out[c, s, t] = value
                out[c, t, s] = value
        for s in range(n_seg):
            bias = _at_most(_at_least(out[c, s, s], 0.0), full)
            out[c, s, s] = bias + (full - bias) / samples[s]
