"""Quantisation of the acquisition (JJF 2003-2022 Appendix A eq. (A.3)) as the GUM needs it for segment means.

Appendix A models the acquisition as one rectangular reading, ``u2 = δ/√3`` with ``δ = 1/2^N`` of
full scale (A.1.2.2): with the step ``q = 2·FS/2^N`` that is ``q/√12``. A segment mean averages
``n`` samples of a quantiser with Gaussian noise at its input, and segments of one channel share
the quantiser and its unknown offset, so

- :func:`quantisation_variance` gives the variance of one segment mean (the part the noise does
  not average, and the rest divided by ``n``);
- :func:`quantisation_covariance` gives the covariance of the segment means of one channel
  (JCGM 100 5.2.2: correlated input quantities).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.quantiser import quantisation_covariances

__all__ = ["quantisation_covariance", "quantisation_variance"]


def quantisation_variance(step: float, sigma: float, samples: int) -> tuple[float, float]:
    """Variance of the quantisation error of a segment mean, and the part the noise does not average.

    The error of one reading ``Q(x) − x`` of ``x = μ + σZ`` is a sawtooth; with the offset μ
    unknown (uniform modulo q, the state of knowledge behind Appendix A's rectangular model) it is
    rectangular ±q/2 whatever σ, variance q²/12. Its conditional mean given μ — the part common to
    all samples of a segment — has the Fourier series Σ_k (−1)^{k+1} q/(πk) γ_k sin(2πkμ/q) with
    γ_k = exp(−2π²k²σ²/q²) (Widrow's quantisation theorem; :mod:`plansim.kernels.quantiser`),
    hence variance ``B = (q²/2π²) Σ_k γ_k²/k²``; the rest, ``q²/12 − B``, varies from sample to
    sample independently (given μ the samples are independent) and is averaged over the ``n``
    samples; the cross term with the noise averages to zero over μ.

    Parameters
    ----------
    step : float
        Quantisation step q (> 0).
    sigma : float
        Standard deviation of the white noise of one sample at the quantiser input (≥ 0).
    samples : int
        Samples n in the segment mean.

    Returns
    -------
    variance : float
        ``B + (q²/12 − B)/n``: ``q²/12`` without noise (Appendix A, u = q/√12 = δ/√3 in its
        notation), ``q²/(12n)`` with full dither.
    undithered_fraction : float
        ``B/(q²/12)``: 1 without dither, 0 with full dither.
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: the quantisation step must be finite and > 0")
    if not (math.isfinite(sigma) and sigma >= 0):
        raise ValueError(f"sigma = {sigma!r}: the noise standard deviation must be finite and >= 0")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ValueError(f"samples = {samples!r}: expected a whole number >= 1")
    full = step**2 / 12.0
    r = sigma / step
    if r == 0.0:
        fraction = 1.0
    else:
        # γ_k² = exp(−4π²k²r²) < 1e-40 beyond k_max; cap the terms and add the tail Σ_{k>K} 1/k² ≈ 1/K
        k_max = int(math.ceil(math.sqrt(92.0) / (2.0 * math.pi * r))) + 1
        cap = 1_000_000
        k = np.arange(1, min(k_max, cap) + 1, dtype=float)
        series = float(np.sum(np.exp(-4.0 * math.pi**2 * k**2 * r**2) / k**2))
        if k_max > cap:
            series += 1.0 / cap
        fraction = min(series * 6.0 / math.pi**2, 1.0)
    bias = fraction * full
    return bias + (full - bias) / int(samples), fraction


#: Most terms of the quantisation series summed term by term (beyond: the undamped closed form).
_MAX_TERMS = 2000


def quantisation_covariance(step: float, means: np.ndarray, sigma: np.ndarray, samples: np.ndarray,
                            offset_covariance: np.ndarray | None = None, needed: np.ndarray | None = None
                            ) -> np.ndarray:
    """Covariance (S, S) of the quantisation errors of the segment means of one channel (or of several).

    Appendix A's rectangular model per reading, with the correlation GUM 5.2 requires between
    segments of one channel: they share the quantiser and the unknown offset of the channel's
    output (uniform modulo q, the state of knowledge behind the rectangular model), and differ by
    the nominal output differences ``Δ_st = means[t] − means[s]``, themselves uncertain with
    variance ``Var(Δ_st)`` from *offset_covariance* (table errors, unit spread, drift). With the
    bias of a noisy quantiser ``b(μ) = Σ_k (−1)^{k+1} q/(πk) γ_k(σ) sin(2πkμ/q)``
    (:func:`quantisation_variance`) the covariance is, exactly for jointly normal offsets,

        Cov(b_s, b_t) = (q²/2π²) Σ_k cos(2πkΔ_st/q) exp(−2π²k²(σ_s² + σ_t² + Var Δ_st)/q²) / k²,

    and the diagonal adds the part the noise averages, ``(q²/12 − B_s)/n_s``. Two segments reading
    the same code without dither are fully correlated; segments far apart in output, or with
    dither, are independent (Appendix A's assumption).

    Parameters
    ----------
    step : float
        Quantisation step q (> 0).
    means : (S,) or (C, S) array
        Nominal (noise-free) segment means of the channel (of each of C channels with the same step).
    sigma : (S,) or (C, S) array
        White noise σ of one sample at the quantiser input (rate jitter included).
    samples : (S,) array
        Samples per segment.
    offset_covariance : (S, S) or (C, S, S) array, optional
        Covariance of the segment means' deviations from nominal other than white noise.
    needed : (S,) or (C, S) array of bool, optional
        The segments whose covariances the caller uses (e.g. where the estimator matrix is not zero):
        a pair with another segment is left 0 (the diagonal is always given). Default: all.

    Returns
    -------
    (S, S) or (C, S, S) ndarray
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: the quantisation step must be finite and > 0")
    means = np.asarray(means, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    samples = np.asarray(samples, dtype=float)
    n_seg = means.shape[-1]
    if means.ndim not in (1, 2) or sigma.shape != means.shape or samples.shape != (n_seg,):
        raise ValueError(f"means, sigma, samples: shapes {means.shape}, {sigma.shape}, {samples.shape}; "
                         "expected one value per segment (and channel)")
    if offset_covariance is None:
        g = np.zeros((1, 1, 1))
    else:
        g = np.asarray(offset_covariance, dtype=float)
        if g.shape != means.shape + (n_seg,):
            raise ValueError(f"offset_covariance: shape {g.shape}; expected {means.shape + (n_seg,)}")
    # every pair s ≤ t and the diagonal's averaged part in one kernel call (the arithmetic of the numpy
    # expressions it replaced, operation for operation)
    needed = (np.ones(means.shape, dtype=np.int64) if needed is None
              else np.asarray(needed, dtype=np.int64))
    if needed.shape != means.shape:
        raise ValueError(f"needed: shape {needed.shape}; expected {means.shape}")
    cov = np.empty(means.shape + (n_seg,))
    channels = (1, n_seg) if means.ndim == 1 else means.shape
    quantisation_covariances(np.ascontiguousarray(means.reshape(channels)),
                             np.ascontiguousarray(sigma.reshape(channels)), samples,
                             np.ascontiguousarray(g).reshape((-1,) + g.shape[-2:]), offset_covariance is not None,
                             np.ascontiguousarray(needed.reshape(channels)),
                             step, step**2, step**2 / (2.0 * np.pi**2), step**2 / 12.0, _MAX_TERMS,
                             cov.reshape(channels + (n_seg,)))
    return cov
